#include "conform/reference_template.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <tuple>

#include "primal/errors.hpp"
#include "primal/patch_match.hpp"
#include "primal/topology.hpp"
#include "templates/side_faces.hpp"

namespace geode::conform {
namespace {

using primal::Index;
using primal::Point;
namespace topo = primal::topology;
using templates::build_geode3d;
using templates::Diagonal;
using templates::GeodeOptions;

// Buffer hex side faces 0..3 (topology order: s-min, r-max, s-max, r-min) as template box-face
// bits (templates/geode.hpp: bit 2*axis + high) under r = z, s = x, t = y
// (primal/buffer_layer.hpp).
constexpr std::array<int, 4> kSideBit{0, 5, 1, 4};
constexpr int kBottomBit = 2, kTopBit = 3;

int corner_at(int r, int s, int t) {
  for (int c = 0; c < 8; ++c)
    if (topo::kHexCornerCoords[c] == std::array<int, 3>{r, s, t}) return c;
  return -1;
}

RefTemplate make_reference(const Eigen::Vector3d& box, std::array<int, 2> diagonal) {
  RefTemplate ref;
  GeodeOptions o;
  o.box = box;
  o.diagonal = diagonal == std::array<int, 2>{5, 7} ? Diagonal::Main : Diagonal::Anti;
  ref.tpl = build_geode3d(o);
  ref.min_scaled_jacobian = templates::smooth_template_shared_sides(ref.tpl).final_min_scaled_jacobian;
  const auto& pts = ref.tpl.hex.points;
  const std::size_t n = pts.size();
  // A smoothed template with two nodes at one place would glue the model together there.
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((pts[i] - pts[j]).norm() < 1e-6 * box.norm()) {
        std::ostringstream m;
        m << "the smoothed geode template in a " << box.x() << " x " << box.y() << " x "
          << box.z() << " box has nodes " << i << " and " << j << " at one place ("
          << pts[i].transpose() << "); choose other template proportions";
        throw TopologyError(m.str());
      }
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
    const Point q{p.z() / box.z() + 0.5, p.x() / box.x() + 0.5, p.y() / box.y() + 0.5};
    ref.rst[i] = q;
    const unsigned f = ref.tpl.node_faces[i];
    for (int k = 0; k < 4; ++k)
      if (f & (1u << kSideBit[k])) ref.side_nodes[k].push_back(static_cast<int>(i));
    const bool bottom = f & (1u << kBottomBit), top = f & (1u << kTopBit);
    if (!bottom && !top) continue;
    const int t = top ? 1 : 0;
    const int a = third(q.x()), b = third(q.y());
    std::vector<int>& key = ref.key_corners[i];
    if (a >= 0 && b >= 0 && a != 1 && b != 1) {
      key = {corner_at(a / 2, b / 2, t)};
    } else if (a == 1 && b >= 0 && b != 1) {
      key = {corner_at(0, b / 2, t), corner_at(1, b / 2, t)};
    } else if (b == 1 && a >= 0 && a != 1) {
      key = {corner_at(a / 2, 0, t), corner_at(a / 2, 1, t)};
    } else if (a == 1 && b == 1) {
      if (bottom) key = {0, 1, 2, 3};
      else key = {diagonal[0], diagonal[1]};
    } else if (top) {
      // A triangle centroid: the triangle of the split top face containing the point.
      const bool d46 = diagonal == std::array<int, 2>{4, 6};
      if (d46) key = q.x() > q.y() ? std::vector<int>{4, 5, 6} : std::vector<int>{4, 6, 7};
      else key = q.x() + q.y() < 1 ? std::vector<int>{4, 5, 7} : std::vector<int>{5, 6, 7};
      double cr = 0, cs = 0;
      for (int c : key) cr += topo::kHexCornerCoords[c][0], cs += topo::kHexCornerCoords[c][1];
      if (std::abs(cr / 3 - q.x()) > kTol || std::abs(cs / 3 - q.y()) > kTol) key.clear();
    }
    if (key.empty() || std::find(key.begin(), key.end(), -1) != key.end()) {
      std::ostringstream m;
      m << "geode template node " << i << " at (" << p.transpose()
        << ") lies on the " << (top ? "tet" : "hex")
        << " side but at no diced position (corner, edge midpoint, face centre)";
      throw TopologyError(m.str());
    }
  }
  for (int k = 0; k < 4; ++k) {
    const unsigned bit = 1u << kSideBit[k];
    for (const auto& h : ref.tpl.hex.hexes)
      for (const auto& fc : topo::kHexFaceCorners) {
        std::array<int, 4> q{};
        bool on = true;
        for (int j = 0; j < 4; ++j) {
          q[j] = h[fc[j]];
          on = on && (ref.tpl.node_faces[q[j]] & bit);
        }
        if (on) ref.side_quads[k].push_back(q);
      }
  }
  return ref;
}

}  // namespace

const RefTemplate& reference_template(const Eigen::Vector3d& box, std::array<int, 2> diagonal) {
  static std::mutex mutex;
  static std::map<std::tuple<double, double, double, int>, std::unique_ptr<RefTemplate>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{box.x(), box.y(), box.z(), diagonal[0]}];
  if (!slot) slot = std::make_unique<RefTemplate>(make_reference(box, diagonal));
  return *slot;
}

std::unordered_map<int, int> match_side(const RefTemplate& A, int ka,
                                        const std::vector<Index>& ga, const RefTemplate& B,
                                        int kb, const std::vector<Index>& gb,
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
