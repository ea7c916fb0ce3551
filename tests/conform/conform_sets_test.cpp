// Node and side sets through conform (conform/conform_sets.cpp): a set on the hex/tet interface
// stays on it, and a set on a surface or curve crossing the interface takes the buffer layer's
// part of it, whichever part the layer is carved from.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/topology.hpp>
#include "support/temp_dir.hpp"

namespace geode {

namespace {

using primal::Index;
using primal::Point;

bool near(double a, double b) { return std::abs(a - b) < 1e-12; }

// A node set as a Gmsh physical curve gives it: its nodes, and its segments as pieces.
primal::NodeSet curve_set(const primal::Model& m, int id,
                          const std::function<bool(const Point&)>& on, int along) {
  primal::NodeSet s{id, "curve " + std::to_string(id), {}, {}};
  for (std::size_t v = 0; v < m.points.size(); ++v)
    if (on(m.points[v])) s.nodes.push_back(primal::index_cast(v));
  std::vector<Index> sorted = s.nodes;
  std::sort(sorted.begin(), sorted.end(), [&](Index a, Index b) {
    return m.points[primal::index_cast<std::size_t>(a)][along] <
           m.points[primal::index_cast<std::size_t>(b)][along];
  });
  for (std::size_t i = 0; i + 1 < sorted.size(); ++i)
    s.pieces.push_back({sorted[i], sorted[i + 1]});
  return s;
}

// The sides of every element face whose nodes all satisfy `on`.
primal::SideSet face_set(const primal::Model& m, int id,
                         const std::function<bool(const Point&)>& on) {
  primal::SideSet s{id, "faces " + std::to_string(id), {}};
  for (primal::ElementKind kind : primal::kElementKinds) {
    const auto& t = primal::cell_topology(kind);
    for (std::size_t e = 0; e < primal::element_count(m, kind); ++e)
      for (int f = 0; f < t.faces; ++f) {
        const primal::Side side{{kind, primal::index_cast(e)}, f};
        bool all = true;
        for (Index v : primal::element_face(m, side))
          all = all && on(m.points[primal::index_cast<std::size_t>(v)]);
        if (all) s.sides.push_back(side);
      }
  }
  return s;
}

// The half-block demo (Gmsh: a transfinite hex box [0,1]^3 beside a tet box [1,2] x [0,1]^2,
// the interface x = 1) with the sets a user gives: the interface from the hex side (side set
// 1), the face y = 0 of both boxes (side set 2), the interface's edge on y = 0 (node set 3), the
// edge y = z = 0 across both boxes (node set 4) and the interface's corner (1, 1, 1) (node set 5).
primal::Model half_with_sets(int n) {
  primal::Model m = demo::demo_half_block(n);
  m.side_sets.push_back(face_set(m, 1, [](const Point& p) { return near(p.x(), 1); }));
  m.side_sets[0].sides.erase(
      std::remove_if(
          m.side_sets[0].sides.begin(), m.side_sets[0].sides.end(),
          [](const primal::Side& s) { return s.element.kind != primal::ElementKind::kHex; }),
      m.side_sets[0].sides.end());
  m.side_sets.push_back(face_set(m, 2, [](const Point& p) { return near(p.y(), 0); }));
  m.node_sets.push_back(curve_set(
      m, 3, [](const Point& p) { return near(p.x(), 1) && near(p.y(), 0); }, 2));
  m.node_sets.push_back(curve_set(
      m, 4, [](const Point& p) { return near(p.y(), 0) && near(p.z(), 0); }, 0));
  m.node_sets.push_back(curve_set(
      m, 5, [](const Point& p) { return near(p.x(), 1) && near(p.y(), 1) && near(p.z(), 1); }, 0));
  return m;
}

struct OutputFaces {
  std::map<primal::FaceKey, std::vector<Index>> hexes;  // each face: the output hexes on it
};

OutputFaces output_faces(const primal::Model& out) {
  OutputFaces o;
  for (std::size_t h = 0; h < out.hexes.size(); ++h)
    for (const auto& f : primal::topology::kHexFaceCorners) {
      std::array<Index, 4> q{};
      for (int k = 0; k < 4; ++k) q[k] = out.hexes[h][f[k]];
      o.hexes[primal::face_key(q)].push_back(primal::index_cast(h));
    }
  return o;
}

std::set<primal::FaceKey> side_keys(const primal::Model& out, const primal::SideSet& s) {
  std::set<primal::FaceKey> keys;
  for (const primal::Side& side : s.sides)
    keys.insert(primal::face_key(primal::element_face(out, side)));
  return keys;
}

std::set<Index> nodes_where(const primal::Model& out, const std::function<bool(const Point&)>& on) {
  std::set<Index> nodes;
  for (std::size_t v = 0; v < out.points.size(); ++v)
    if (on(out.points[v])) nodes.insert(primal::index_cast(v));
  return nodes;
}

}  // namespace

TEST_CASE("sets on the interface stay on it; sets across it take the buffer layer's part") {
  const primal::Model in = half_with_sets(4);
  struct Case {
    const char* name;
    conform::BufferSide side;
    const char* geode_block;
  };
  for (const Case& c : {Case{"hex side", conform::BufferSide::kHex, ""},
                        Case{"tet side", conform::BufferSide::kTet, ""},
                        Case{"hex side, geode block", conform::BufferSide::kHex, "geode"}}) {
    CAPTURE(c.name);
    conform::ConformOptions o;
    o.buffer.side = c.side;
    o.geode_block = c.geode_block;
    const conform::ConformResult r = conform::conform(in, o);
    const primal::Model& out = r.model;
    REQUIRE(out.side_sets.size() == 2);
    REQUIRE(out.node_sets.size() == 3);
    const OutputFaces faces = output_faces(out);
    const auto block = [&](Index h) {
      return primal::block_of(out, {primal::ElementKind::kHex, h});
    };
    // The hex block's face towards the others: the tet block, or the geode block.
    const int other = *c.geode_block ? out.block_names.rbegin()->first : 2;
    std::set<primal::FaceKey> between;
    for (const auto& [key, hs] : faces.hexes)
      if (hs.size() == 2 && std::min(block(hs[0]), block(hs[1])) == 1 &&
          std::max(block(hs[0]), block(hs[1])) == other)
        between.insert(key);
    CHECK(!between.empty());
    CHECK(side_keys(out, out.side_sets[0]) == between);
    CHECK(out.side_sets[0].sides.size() == between.size());
    if (!*c.geode_block)
      for (const auto& key : between)
        for (Index v : key)
          if (v != primal::kInvalidIndex)
            CHECK(near(out.points[primal::index_cast<std::size_t>(v)].x(), 1));
    // The face y = 0: every boundary face of the output there.
    std::set<primal::FaceKey> front;
    for (const auto& [key, hs] : faces.hexes) {
      bool all = hs.size() == 1;
      for (Index v : key)
        if (v != primal::kInvalidIndex)
          all = all && near(out.points[primal::index_cast<std::size_t>(v)].y(), 0);
      if (all) front.insert(key);
    }
    CHECK(side_keys(out, out.side_sets[1]) == front);
    // Node sets: the output's nodes on their curves, as many as there are.
    const auto set_of = [&](std::size_t i) {
      return std::set<Index>(out.node_sets[i].nodes.begin(), out.node_sets[i].nodes.end());
    };
    if (!*c.geode_block)
      CHECK(set_of(0) ==
            nodes_where(out, [](const Point& p) { return near(p.x(), 1) && near(p.y(), 0); }));
    CHECK(set_of(1) ==
          nodes_where(out, [](const Point& p) { return near(p.y(), 0) && near(p.z(), 0); }));
    CHECK(set_of(2) == nodes_where(out, [](const Point& p) {
            return near(p.x(), 1) && near(p.y(), 1) && near(p.z(), 1);
          }));
    CHECK(set_of(2).size() == 1);
  }
}

namespace {

// tests/conform/sets_models.py's model `name` (made by Gmsh at test time, written as .msh and
// read back as a user's file is).
primal::Model gmsh_model(const std::string& name, const test::TempDir& dir) {
  const std::string model = (dir.path / (name + ".msh")).string();
  const std::string cmd = "/usr/bin/python3 '" + std::string(GEODE_SOURCE_DIR) +
                          "/tests/conform/sets_models.py' " + name + " '" + model + "'";
  // python3-gmsh is a required package (scripts/common.sh): a missing one fails the test.
  REQUIRE_MESSAGE(std::system(cmd.c_str()) == 0, cmd);
  return io::read_model(model);
}

// conform of `in` with every smoothing mode (none, local, global), each valid output to `check`.
void in_every_smoothing(const primal::Model& in,
                        const std::function<void(const primal::Model&)>& check) {
  for (const auto smooth : {conform::ConformSmooth::kNone, conform::ConformSmooth::kLocal,
                            conform::ConformSmooth::kGlobal}) {
    CAPTURE(static_cast<int>(smooth));
    conform::ConformOptions o;
    o.smooth = smooth;
    const conform::ConformResult r = conform::conform(in, o);
    REQUIRE(r.validity.ok());
    check(r.model);
  }
}

}  // namespace

// Sets inside a block and on part of a face stay where the user put them, whatever the
// smoothing: a Gmsh model (tests/conform/sets_models.py embedded) with a physical surface
// embedded in the tets beside the interface, one on a patch of the tet box's top face, a
// physical point and a physical curve embedded there too. Global smoothing moved the embedded
// surface off its plane (z 0.487-0.506) and its rim and the patch's in their planes (the
// sheet's x from 1.04 to 1.039), and the curve's and the point's nodes with the tets.
TEST_CASE("sets inside a block and on part of a face keep their place and extent") {
  test::TempDir dir;
  const primal::Model in = gmsh_model("embedded", dir);
  struct Rectangle {
    int id;
    Point low, high;  // the corners of an axis-aligned rectangle
  };
  const Rectangle sheet{3, {1.04, 0.15, 0.5}, {1.64, 0.75, 0.5}},
      patch{4, {1.1, 0.2, 1.0}, {1.6, 0.7, 1.0}};
  in_every_smoothing(in, [&](const primal::Model& out) {
    const auto side_set = [&](int id) -> const primal::SideSet& {
      const auto it = std::find_if(out.side_sets.begin(), out.side_sets.end(),
                                   [&](const primal::SideSet& s) { return s.id == id; });
      REQUIRE(it != out.side_sets.end());
      return *it;
    };
    const auto node_set = [&](int id) -> const primal::NodeSet& {
      const auto it = std::find_if(out.node_sets.begin(), out.node_sets.end(),
                                   [&](const primal::NodeSet& s) { return s.id == id; });
      REQUIRE(it != out.node_sets.end());
      return *it;
    };
    for (const Rectangle& rect : {sheet, patch}) {
      CAPTURE(rect.id);
      const primal::SideSet& s = side_set(rect.id);
      REQUIRE(!s.sides.empty());
      double area = 0.0;
      int outside = 0;
      for (const primal::Side& side : s.sides) {
        const std::vector<Index> f = primal::element_face(out, side);
        REQUIRE(f.size() == 4);
        std::array<Point, 4> x;
        for (int k = 0; k < 4; ++k) {
          x[k] = out.points[primal::index_cast<std::size_t>(f[k])];
          for (int d = 0; d < 3; ++d)
            if (x[k][d] < rect.low[d] - 1e-12 || x[k][d] > rect.high[d] + 1e-12) ++outside;
        }
        area += 0.5 * (x[2] - x[0]).cross(x[3] - x[1]).norm();
      }
      CHECK(outside == 0);
      const Point size = rect.high - rect.low;
      CHECK(area == doctest::Approx(size.x() * size.y()).epsilon(1e-9));
    }
    const primal::NodeSet& point = node_set(5);
    REQUIRE(point.nodes.size() == 1);
    CHECK((out.points[primal::index_cast<std::size_t>(point.nodes[0])] - Point(1.7, 0.8, 0.3))
              .norm() < 1e-12);
    const primal::NodeSet& line = node_set(6);
    REQUIRE(line.nodes.size() >= 2);
    double low = 1.0, high = 0.0;
    for (Index v : line.nodes) {
      const Point& x = out.points[primal::index_cast<std::size_t>(v)];
      CHECK(std::abs(x.x() - 1.2) < 1e-12);
      CHECK(std::abs(x.y() - 0.9) < 1e-12);
      low = std::min(low, x.z()), high = std::max(high, x.z());
    }
    CHECK(low == doctest::Approx(0.1));
    CHECK(high == doctest::Approx(0.9));
  });
}

// A node set's node slides only within its own set: a physical point on the interface where
// two physical curves and an inner physical surface meet (tests/conform/sets_models.py points)
// stays where it is under every smoothing; the curves' nodes stay on their lines, which keep
// their ends. Global smoothing moved the point along one curve (y 1 -> 1.0057): the nodes of
// all sets were judged as one.
TEST_CASE("a point set stays where curves and surfaces through it would let it slide") {
  test::TempDir dir;
  const primal::Model in = gmsh_model("points", dir);
  struct Line {
    int id;
    Point from, to;
  };
  in_every_smoothing(in, [&](const primal::Model& out) {
    const auto nodes_of = [&](int id) {
      const auto it = std::find_if(out.node_sets.begin(), out.node_sets.end(),
                                   [&](const primal::NodeSet& s) { return s.id == id; });
      REQUIRE(it != out.node_sets.end());
      std::vector<Point> x;
      for (Index v : it->nodes) x.push_back(out.points[primal::index_cast<std::size_t>(v)]);
      return x;
    };
    for (const auto& [id, at] : {std::pair{6, Point(1, 1, 1)}, std::pair{8, Point(2, 1, 1)}}) {
      CAPTURE(id);
      const std::vector<Point> x = nodes_of(id);
      REQUIRE(x.size() == 1);
      CHECK((x[0] - at).norm() == 0.0);
    }
    for (const Line& l : {Line{7, {1, 1, 0}, {1, 1, 2}}, Line{9, {2, 0, 1}, {2, 2, 1}},
                          Line{10, {0, 1, 1}, {2, 1, 1}}}) {
      CAPTURE(l.id);
      const Point u = (l.to - l.from).normalized();
      bool from = false, to = false;
      for (const Point& x : nodes_of(l.id)) {
        CHECK((x - l.from).cross(u).norm() < 1e-12);  // on the line
        const double t = (x - l.from).dot(u);
        CHECK(t > -1e-12);
        CHECK(t < (l.to - l.from).norm() + 1e-12);
        from = from || (x - l.from).norm() == 0.0;
        to = to || (x - l.to).norm() == 0.0;
      }
      CHECK(from);
      CHECK(to);
    }
  });
}

TEST_CASE("a named geode block labels the mesh the run without it makes") {
  // Smoothing took the geode block's faces for material interfaces and kept them: on Gmsh's
  // hexdominant model 0.178 -> 0.149, on quads-only layers exit 4 where the run without the
  // name was valid (found by a fault hunt). Now only the labels differ.
  const primal::Model input = demo::demo_model("hexdominant", 4);
  const conform::ConformResult plain = conform::conform(input);
  conform::ConformOptions o;
  o.geode_block = "geode hexes";
  const conform::ConformResult named = conform::conform(input, o);
  REQUIRE(conform::result_valid(plain));
  REQUIRE(conform::result_valid(named));
  CHECK(named.model.points == plain.model.points);
  CHECK(named.model.hexes == plain.model.hexes);
  const int id = named.model.block_names.rbegin()->first;
  CHECK(named.model.block_names.at(id) == "geode hexes");
  std::map<int, Index> counts;
  for (std::size_t h = 0; h < named.model.hexes.size(); ++h) {
    ++counts[named.model.hex_block[h]];
    // Outside the geode hexes the blocks are the plain run's.
    if (named.model.hex_block[h] != id) CHECK(named.model.hex_block[h] == plain.model.hex_block[h]);
  }
  CHECK(counts.at(id) == named.geode_hexes);
}

}  // namespace geode
