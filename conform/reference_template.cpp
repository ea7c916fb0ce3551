#include <geode/conform/reference_template.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stop_token>
#include <tuple>

#include <tbb/parallel_invoke.h>
#include <tbb/task_group.h>

#include <geode/primal/errors.hpp>
#include <geode/primal/patch_match.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/topology.hpp>
#include <geode/templates/side_faces.hpp>
#include <geode/templates/template_table.hpp>

namespace geode::conform {
namespace {

using primal::Index;
using primal::Point;
namespace topo = primal::topology;
using templates::Diagonal;
using templates::GeodeOptions;
using templates::smooth_template;

// Buffer hex side faces 0..3 (topology order: s-min, r-max, s-max, r-min) as template side
// faces (templates::side_faces order x-, x+, z-, z+) under r = z, s = x, t = y
// (conform/buffer_layer.hpp); the top and bottom as box-face bits (bit 2*axis + high).
constexpr std::array<int, 4> kSideFace{0, 3, 1, 2};
constexpr int kBottomBit = 2, kTopBit = 3;
// The same side faces as box-face bits: x-, z+, x+, z-.
constexpr std::array<int, 4> kSideBit{0, 5, 1, 4};

int corner_at(int r, int s, int t) {
  for (int c = 0; c < 8; ++c)
    if (topo::kHexCornerCoords[c] == std::array<int, 3>{r, s, t}) return c;
  return -1;
}

// The diced node of a four-triangle top at (r, s) as buffer hex corners (kCentreCorner for the
// centre): a corner, an edge midpoint, the centre, a centre-corner midpoint or the centroid of
// a triangle (corner, next corner, centre); empty when (r, s) is none of them.
std::vector<int> four_triangle_key(double r, double s, double tol) {
  constexpr std::array<int, 4> kTop{4, 5, 6, 7};  // at (r, s) = (0,0), (1,0), (1,1), (0,1)
  std::vector<std::vector<int>> keys{{kCentreCorner}};
  for (int i = 0; i < 4; ++i) {
    const int a = kTop[i], b = kTop[(i + 1) % 4];
    keys.push_back({a}), keys.push_back({a, b}), keys.push_back({a, kCentreCorner});
    keys.push_back({a, b, kCentreCorner});
  }
  for (const auto& key : keys) {
    double cr = 0, cs = 0;
    for (int c : key) {
      cr += c == kCentreCorner ? 0.5 : topo::kHexCornerCoords[c][0];
      cs += c == kCentreCorner ? 0.5 : topo::kHexCornerCoords[c][1];
    }
    const double n = static_cast<double>(key.size());
    if (std::abs(cr / n - r) < tol && std::abs(cs / n - s) < tol) return key;
  }
  return {};
}

// A template node's reference coordinates in the buffer hex (r = z, s = x, t = y), and back.
Point reference_coordinates(const Point& p, const Eigen::Vector3d& box) {
  return {p.z() / box.z() + 0.5, p.x() / box.x() + 0.5, p.y() / box.y() + 0.5};
}
Point box_position(const Point& rst, const Eigen::Vector3d& box) {
  return {(rst.y() - 0.5) * box.x(), (rst.z() - 0.5) * box.y(), (rst.x() - 0.5) * box.z()};
}

// A smoothed template with two nodes at one place would glue the model together there.
void check_distinct(const std::vector<Point>& pts, const Eigen::Vector3d& box) {
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (std::size_t j = i + 1; j < pts.size(); ++j)
      if ((pts[i] - pts[j]).norm() < 1e-6 * box.norm()) {
        std::ostringstream m;
        m << "the smoothed geode template in a " << box.x() << " x " << box.y() << " x " << box.z()
          << " box has nodes " << i << " and " << j << " at one place (" << pts[i].transpose()
          << "); choose other template proportions";
        throw TopologyError(m.str());
      }
}

RefTemplate make_reference(const Eigen::Vector3d& box, std::array<int, 2> diagonal,
                           templates::TopSplit split = templates::TopSplit::kTwoTriangles) {
  RefTemplate ref;
  const bool four = split == templates::TopSplit::kFourTriangles;
  // Which template fills this interface cell, and with what push, is the template table's
  // (templates/template_table.hpp; for four triangles the superquadric-dome class found free
  // of obstructions: 44 hexes, no fix-up needed).
  const templates::TemplateEntry& entry = templates::conform_template(
      four ? templates::ConformUse::kFourTriangles : templates::ConformUse::kTwoTriangles);
  GeodeOptions o = entry.defaults.geode;
  o.box = box;
  o.diagonal = diagonal == std::array<int, 2>{5, 7} ? Diagonal::kMain : Diagonal::kAnti;
  o.push = entry.conform_push;
  ref.tpl = entry.build(templates::template_options(entry, o, {}));
  // This class has no obstruction to untangling (primal/realizability.hpp), so it needs no
  // fix-up; a box that gave it one would be refused here rather than pillowed silently.
  if (four && !templates::template_obstructions(ref.tpl).empty())
    throw TopologyError("the four-triangle template in a " + std::to_string(box.x()) + " x " +
                        std::to_string(box.y()) + " x " + std::to_string(box.z()) +
                        " box has obstructions to untangling");
  // The geode's four side faces become one shared mesh (templates/side_faces.hpp); the
  // four-triangle template takes the geode's afterwards (impose_geode_sides).
  ref.min_scaled_jacobian =
      four ? smooth_template(ref.tpl, false).final_min_scaled_jacobian
           : templates::smooth_template_shared_sides(ref.tpl).final_min_scaled_jacobian;
  const auto& pts = ref.tpl.hex.points;
  const std::size_t n = pts.size();
  check_distinct(pts, box);
  ref.rst.resize(n);
  ref.key_corners.resize(n);
  constexpr double kTol = 1e-6;
  auto third = [&](double v) -> int {  // 0, 1, 2 for 0, 1/2, 1; -1 otherwise
    for (int k = 0; k < 3; ++k)
      if (std::abs(v - 0.5 * k) < kTol) return k;
    return -1;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = pts[i];
    const Point q = reference_coordinates(p, box);
    ref.rst[i] = q;
    const unsigned f = ref.tpl.node_faces[i];
    const bool bottom = f & (1u << kBottomBit), top = f & (1u << kTopBit);
    if (!bottom && !top) continue;
    const int t = top ? 1 : 0;
    const int a = third(q.x()), b = third(q.y());
    std::vector<int>& key = ref.key_corners[i];
    if (four && top) {
      key = four_triangle_key(q.x(), q.y(), kTol);
    } else if (a >= 0 && b >= 0 && a != 1 && b != 1) {
      key = {corner_at(a / 2, b / 2, t)};
    } else if (a == 1 && b >= 0 && b != 1) {
      key = {corner_at(0, b / 2, t), corner_at(1, b / 2, t)};
    } else if (b == 1 && a >= 0 && a != 1) {
      key = {corner_at(a / 2, 0, t), corner_at(a / 2, 1, t)};
    } else if (a == 1 && b == 1) {
      if (bottom)
        key = {0, 1, 2, 3};
      else
        key = {diagonal[0], diagonal[1]};
    } else if (top) {
      // A triangle centroid: the triangle of the split top face containing the point.
      const bool d46 = diagonal == std::array<int, 2>{4, 6};
      if (d46)
        key = q.x() > q.y() ? std::vector<int>{4, 5, 6} : std::vector<int>{4, 6, 7};
      else
        key = q.x() + q.y() < 1 ? std::vector<int>{4, 5, 7} : std::vector<int>{5, 6, 7};
      double cr = 0, cs = 0;
      for (int c : key) cr += topo::kHexCornerCoords[c][0], cs += topo::kHexCornerCoords[c][1];
      if (std::abs(cr / 3 - q.x()) > kTol || std::abs(cs / 3 - q.y()) > kTol) key.clear();
    }
    if (key.empty() || std::find(key.begin(), key.end(), -1) != key.end()) {
      std::ostringstream m;
      m << "geode template node " << i << " at (" << p.transpose() << ") lies on the "
        << (top ? "tet" : "hex")
        << " side but at no diced position (corner, edge midpoint, face centre)";
      throw TopologyError(m.str());
    }
  }
  const auto faces = templates::side_faces(ref.tpl);
  for (int k = 0; k < 4; ++k) {
    ref.side_nodes[k] = faces[kSideFace[k]].nodes;
    ref.side_quads[k] = faces[kSideFace[k]].quads;
  }
  // The box-face bit of each buffer hex face: sides, bottom, top.
  std::array<unsigned, 6> bit{};
  for (int k = 0; k < 4; ++k) bit[k] = 1u << kSideBit[k];
  bit[4] = 1u << kBottomBit, bit[5] = 1u << kTopBit;
  ref.side_corners.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned f = ref.tpl.node_faces[i];
    if (!ref.key_corners[i].empty() || f == 0) continue;
    std::array<int, 8> count{};  // per corner: the side faces holding the node that hold it
    int sides = 0;
    for (int k = 0; k < 4; ++k)
      if (f & bit[k]) {
        ++sides;
        for (int c : topo::kHexFaceCorners[k]) ++count[c];
      }
    for (int c = 0; c < 8; ++c)
      if (sides > 0 && count[c] == sides) ref.side_corners[i].push_back(c);
  }
  const auto& hexes = ref.tpl.hex.hexes;
  for (std::size_t h = 0; h < hexes.size(); ++h)
    for (int lf = 0; lf < 6; ++lf)
      for (int face = 0; face < 6; ++face) {
        bool on = true;
        for (int c : topo::kHexFaceCorners[lf])
          on = on && (ref.tpl.node_faces[hexes[h][c]] & bit[face]);
        if (on) ref.faces_on[face].push_back({primal::index_cast<int>(h), lf});
      }
  return ref;
}

// Gives `four`'s side faces the reference positions of `geode`'s (node by node as match_side pairs
// them, face k with face k, starting from the nodes both have on the tet and hex sides) and smooths
// its other nodes with every box face fixed: a four-triangle template then meets a geode
// across a side face as two geodes meet, instead of at positions of its own.
void impose_geode_sides(RefTemplate& four, const RefTemplate& geode, const Eigen::Vector3d& box) {
  // The tet/hex-side nodes of both as shared ids, by their (sorted) key corners.
  std::map<std::vector<int>, Index> id_of;
  auto ids = [&](const RefTemplate& t) {
    std::vector<Index> g(t.key_corners.size(), -1);
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (t.key_corners[i].empty()) continue;
      std::vector<int> key = t.key_corners[i];
      std::sort(key.begin(), key.end());
      g[i] = id_of.try_emplace(key, primal::index_cast(id_of.size())).first->second;
    }
    return g;
  };
  const std::vector<Index> g4 = ids(four), gg = ids(geode);
  auto& pts = four.tpl.hex.points;
  for (int k = 0; k < 4; ++k)
    for (const auto& [a, b] :
         match_side(four, k, g4, geode, k, gg, "the four-triangle template and the geode"))
      if (four.key_corners[a].empty()) pts[a] = box_position(geode.rst[b], box);
  const Point lo = -0.5 * box, hi = 0.5 * box;
  const auto constraints =
      primal::box_constraints(pts, lo, hi, {true, true, true, true, true, true});
  four.min_scaled_jacobian =
      primal::smooth_hex_mesh(four.tpl.hex, constraints).final_min_scaled_jacobian;
  check_distinct(pts, box);
  for (std::size_t i = 0; i < pts.size(); ++i) four.rst[i] = reference_coordinates(pts[i], box);
}

}  // namespace

const RefTemplate& reference_template(const Eigen::Vector3d& given_box,
                                      std::array<int, 2> diagonal) {
  // Only the box's proportions matter (the templates are kept in reference coordinates): build
  // them with the largest side 24, the scale the arrangement engine and smoother were tuned at,
  // so that --template-box 1e6x1e6x1e6 gives what 24x24x24 does.
  const Eigen::Vector3d box = given_box * (24.0 / given_box.maxCoeff());
  // One slot per box and diagonal (kCentreCorner: the four-triangle template), built once;
  // the lock only finds the slot, so that different templates are built at the same time
  // (conform builds both diagonals in parallel). std::map nodes never move.
  struct Slot {
    std::once_flag once;
    std::unique_ptr<RefTemplate> value;
  };
  static std::mutex mutex;
  static std::map<std::tuple<double, double, double, int>, Slot> cache;
  Slot* slot = nullptr;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    slot = &cache[{box.x(), box.y(), box.z(), diagonal[0]}];
  }
  std::call_once(slot->once, [&] {
    if (diagonal[0] != kCentreCorner) {
      slot->value = std::make_unique<RefTemplate>(make_reference(box, diagonal));
      return;
    }
    const RefTemplate& geode = reference_template(box, {4, 6});
    // Smoothed in a flatter box than the geode's: the four-triangle template has more hexes
    // across the thickness; shapes smoothed at the flatter proportion keep its mapped
    // hexes positive where the geode's box does not. Only reference coordinates are kept, so the
    // sides still match the geode's.
    const Eigen::Vector3d four_box(box.x(), 0.7 * box.y(), box.z());
    auto four = std::make_unique<RefTemplate>(
        make_reference(four_box, {4, 6}, templates::TopSplit::kFourTriangles));
    impose_geode_sides(*four, geode, four_box);
    slot->value = std::move(four);
  });
  return *slot->value;
}

double template_ceiling(const Eigen::Vector3d& given_box, std::array<int, 2> diagonal,
                        const Eigen::Vector3d& cell) {
  const Eigen::Vector3d box = given_box * (24.0 / given_box.maxCoeff());
  Eigen::Vector3d sides(24.0, 24.0, 24.0);  // a degenerate cell: measured as the box's own
  if (cell.minCoeff() >= 0.0 && cell.maxCoeff() > 0.0)
    for (int k = 0; k < 3; ++k)
      sides[k] = std::max(3.0, std::ceil(cell[k] * 24.0 / cell.maxCoeff() - 1e-9));
  if ((sides.array() >= box.array()).all())
    return reference_template(box, diagonal).min_scaled_jacobian;
  return reference_template(sides, diagonal).min_scaled_jacobian;
}

std::jthread build_reference_templates_ahead(const Eigen::Vector3d& box) {
  return std::jthread([box](const std::stop_token& stop) {
    // Nothing may leave the thread (std::terminate): not a failed build, which conform()
    // repeats and reports, nor TBB's failure to start its workers or allocate its tasks when
    // memory is short (tests/io/bombs_test.sh), which conform() meets again and reports. (A
    // tbb::task_group cannot be used here: when its run() cannot allocate, its destructor
    // cancels, which allocates, and that second bad_alloc during unwinding terminated.)
    try {
      tbb::task_group_context context;
      // A caller that no longer needs them (its input was refused) is not kept waiting for
      // them: the handle's destruction requests a stop, which cancels the tasks; the smoother
      // then throws out of the unfinished template, which is not cached (std::call_once).
      // Short of memory even to cancel, the build just runs to its end.
      const std::stop_callback cancel(stop, [&context]() noexcept {
        try {
          context.cancel_group_execution();
        } catch (...) {}
      });
      tbb::parallel_invoke(
          [&] {
            reference_template(box, {4, 6});
          },
          [&] {
            reference_template(box, {5, 7});
          },
          context);
    } catch (...) {}
  });
}

const RefTemplate& reference_template_four_triangles(const Eigen::Vector3d& box) {
  return reference_template(box, {kCentreCorner, kCentreCorner});
}

std::unordered_map<int, int> match_side(const RefTemplate& A, int ka, const std::vector<Index>& ga,
                                        const RefTemplate& B, int kb, const std::vector<Index>& gb,
                                        const std::string& where) {
  auto fail = [&](const std::string& why) {
    throw TopologyError("side faces of " + where + " do not correspond: " + why);
  };
  // Seeds: the tet- and hex-side nodes the two templates share (the same global node).
  std::unordered_map<Index, int> b_of_global;
  for (int b : B.side_nodes[kb])
    if (gb[b] >= 0) b_of_global[gb[b]] = b;
  std::vector<std::pair<int, int>> seeds;
  for (int a : A.side_nodes[ka])
    if (ga[a] >= 0) {
      const auto it = b_of_global.find(ga[a]);
      if (it == b_of_global.end()) fail("a tet/hex-side node of one is not on the other");
      seeds.emplace_back(a, it->second);
    }
  primal::PatchMatch m = primal::match_quad_patches(A.side_quads[ka], B.side_quads[kb], seeds);
  if (!m.ok()) fail(m.error);
  return std::move(m.map);
}

}  // namespace geode::conform
