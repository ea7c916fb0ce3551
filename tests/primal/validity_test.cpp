// Validity reports: a structured block and a solid torus are valid with the Euler
// characteristics topology predicts; each kind of defect is built on purpose and must be found
// exactly where it was put. Covering: embedded meshes (flat, curved, concave and irregular
// boundaries) cover every node once; fans wrapping two or three times around a node with every
// corner positive are named at exactly the wrapped nodes, with their solid angles.
#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>

#include <geode/primal/boundary.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include "support/ball_checks.hpp"
#include "support/fixtures.hpp"

using namespace geode::primal;
using geode::test::appendix_a_geode;
using geode::test::structured_hex_grid;
using geode::test::structured_quad_grid;

namespace {

// Keeps the hexes (by index) that `keep` selects; nodes are not renumbered.
HexMesh keep_hexes(HexMesh m, const std::vector<Index>& keep) {
  std::vector<std::array<Index, 8>> hexes;
  for (Index h : keep) hexes.push_back(m.hexes[h]);
  m.hexes = hexes;
  return m;
}

QuadMesh keep_quads(QuadMesh m, const std::vector<Index>& keep) {
  std::vector<std::array<Index, 4>> quads;
  for (Index q : keep) quads.push_back(m.quads[q]);
  m.quads = quads;
  return m;
}

// Node (i,j,k) of structured_hex_grid(nx, ny, nz).
Index grid_node(int nx, int ny, int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); }

double signed_area(const QuadMesh& m, const std::vector<Index>& loop) {
  double a = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Point& p = m.points[loop[i]];
    const Point& q = m.points[loop[(i + 1) % loop.size()]];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return a / 2;
}

}  // namespace

TEST_CASE("validity: 3x3x3 block is a valid ball") {
  const HexMesh m = structured_hex_grid(3, 3, 3);
  const auto r = check_validity(m);
  INFO(r.summary());
  CHECK(r.ok());
  // By hand: V = 4^3; E = 3 directions x 3 segments x 4^2 lines; F = 3 x 4 planes x 3^2;
  // C = 27. V - E + F - C = 64 - 144 + 108 - 27 = 1, a ball.
  CHECK(r.num_vertices == 64);
  CHECK(r.num_edges == 144);
  CHECK(r.num_faces == 108);
  CHECK(r.num_cells == 27);
  CHECK(r.euler == 1);
  // Boundary: 6 x 9 quads on the 64 - 8 = 56 non-interior nodes, a sphere (chi = 2).
  CHECK(r.boundary.faces.size() == 54);
  CHECK(r.boundary.vertex_node.size() == 56);
  CHECK(r.boundary.closed);
  CHECK(r.boundary.manifold);
  CHECK(r.boundary.euler == 2);
  CHECK(r.boundary.rejected.empty());
  CHECK(r.summary().find("valid") != std::string::npos);
}

TEST_CASE("validity: progress rises to the whole work, and the report is the one without it") {
  // 40^3 hexes: many of the check's parallel chunks (4096 hexes or nodes), so calls come from
  // several threads and the count must still never go down.
  HexMesh m = structured_hex_grid(40, 40, 40);
  std::swap(m.hexes[100][0], m.hexes[100][1]);  // a finding, so that the reports say something
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  const auto r = check_validity(
      m, [&calls](std::size_t done, std::size_t total) { calls.emplace_back(done, total); });
  const auto plain = check_validity(m);
  CHECK(r.summary() == plain.summary());
  CHECK(r.inverted_hexes == plain.inverted_hexes);
  REQUIRE(calls.size() >= 3);
  const std::size_t total = calls.front().second;
  CHECK(total > 0);
  for (std::size_t i = 0; i < calls.size(); ++i) {
    CAPTURE(i);
    CHECK(calls[i].second == total);
    CHECK(calls[i].first <= total);
    if (i > 0) CHECK(calls[i].first >= calls[i - 1].first);
  }
  CHECK(calls.back().first == total);
  CHECK(calls[calls.size() / 2].first < total);  // not only told at the end
}

TEST_CASE("boundary_quads: outward, one per boundary face, with hex and local face") {
  const HexMesh m = structured_hex_grid(3, 3, 3);
  const auto quads = boundary_quads(m);
  REQUIRE(quads.size() == 54);
  for (const auto& q : quads) {
    const auto& hex = m.hexes[q.hex];
    for (int i = 0; i < 4; ++i) {
      CHECK(q.nodes[i] == hex[topology::kHexFaceCorners[q.local_face][i]]);
    }
    Point hex_centre = Point::Zero(), face_centre = Point::Zero();
    for (Index v : hex) hex_centre += m.points[v] / 8;
    for (Index v : q.nodes) face_centre += m.points[v] / 4;
    const Point n = (m.points[q.nodes[1]] - m.points[q.nodes[0]])
                        .cross(m.points[q.nodes[3]] - m.points[q.nodes[0]]);
    CHECK(n.dot(face_centre - hex_centre) > 0);  // outward
    // A boundary face of the block lies on the box.
    const bool on_box = std::ranges::any_of(
        std::array{0, 1, 2}, [&](int d) { return face_centre[d] == 0.0 || face_centre[d] == 3.0; });
    CHECK(on_box);
  }
  const auto faces = unique_faces(m);
  CHECK(faces.size() == 108);
  CHECK(std::ranges::count_if(faces, [](const UniqueFace& f) { return f.uses.size() == 2; }) ==
        108 - 54);
  CHECK(unique_edges(m).size() == 144);
  CHECK(edge_key(7, 3) == EdgeKey{3, 7});
  CHECK(face_key(std::array<Index, 4>{9, 2, 5, 1}) == FaceKey{1, 2, 5, 9});
  CHECK(face_key(std::array<Index, 3>{9, 2, 5}) == FaceKey{2, 5, 9, kInvalidIndex});
}

TEST_CASE("validity: a ring of 8 hexes is a solid torus") {
  // 3x3x1 block without its centre hex (index 4).
  const HexMesh m = keep_hexes(structured_hex_grid(3, 3, 1), {0, 1, 2, 3, 5, 6, 7, 8});
  const auto r = check_validity(m);
  INFO(r.summary());
  CHECK(r.ok());
  // By hand: V = 2 x 16; E = 2 x 24 in-plane + 16 vertical; F = 2 x 8 horizontal + 24
  // vertical; C = 8: 32 - 64 + 40 - 8 = 0. Boundary torus: 8 top + 8 bottom + 12 outer +
  // 4 inner = 32 quads, 4 x 32 / 2 = 64 edges, all 32 nodes: 32 - 64 + 32 = 0.
  CHECK(r.euler == 0);
  CHECK(r.num_edges == 64);
  CHECK(r.num_faces == 40);
  CHECK(r.boundary.closed);
  CHECK(r.boundary.manifold);
  CHECK(r.boundary.faces.size() == 32);
  CHECK(r.boundary.euler == 0);
}

// Each defect is made on purpose; the report must name exactly it.
struct HexDefectCase {
  const char* name;
  std::function<HexMesh()> make;
  std::vector<Index> out_of_range, repeated, inverted, nonmanifold_vertices;
  std::vector<EdgeKey> nonmanifold_edges;
  std::vector<FaceKey> overshared, misoriented;
  bool boundary_closed, boundary_manifold;
};

TEST_CASE("validity: each hex defect is found where it was put") {
  // 2x2x1 grid: nodes i + 3 j + 9 k. Hexes 0 = (0,0) and 3 = (1,1) share only the vertical
  // edge {4, 13} at (1,1).
  const EdgeKey shared_edge = edge_key(grid_node(2, 2, 1, 1, 0), grid_node(2, 2, 1, 1, 1));
  // 2x2x2 grid: hexes 0 = (0,0,0) and 7 = (1,1,1) share only the centre node 13.
  const Index centre = grid_node(2, 2, 1, 1, 1);
  // 2x1x1 grid: nodes i + 3 j + 6 k; hexes 0 and 1 share face {1, 4, 7, 10}.
  const FaceKey shared_face{1, 4, 7, 10};

  const std::vector<HexDefectCase> cases{
      {"edge-only contact",
       [] {
         return keep_hexes(structured_hex_grid(2, 2, 1), {0, 3});
       },
       {},
       {},
       {},
       {shared_edge.begin(), shared_edge.end()},
       {shared_edge},
       {},
       {},
       /*closed: the edge has 4 boundary quads*/ false,
       false},
      {"vertex-only contact",
       [] {
         return keep_hexes(structured_hex_grid(2, 2, 2), {0, 7});
       },
       {},
       {},
       {},
       {centre},
       {},
       {},
       {},
       true,
       false},
      {"face shared by three hexes",
       [] {
         HexMesh m = structured_hex_grid(2, 1, 1);
         // A third hex on face {1, 4, 7, 10} of hex 0, folded back over hex 1 with new far
         // corners (topology does not care about the overlap).
         auto h = m.hexes[1];
         for (int c = 0; c < 8; ++c) {
           if (topology::kHexCornerCoords[c][0] == 1) {
             m.points.push_back(m.points[h[c]] + Point(0.5, 0.0, 0.25));
             h[c] = index_cast(m.points.size() - 1);
           }
         }
         m.hexes.push_back(h);
         return m;
       },
       {},
       {},
       {},
       {1, 4, 7, 10},
       {{1, 4}, {1, 7}, {4, 10}, {7, 10}},
       {shared_face},
       {},
       /*closed: each edge of the face has 3 boundary quads*/ false,
       false},
      {"flipped hex",
       [] {
         HexMesh m = structured_hex_grid(2, 1, 1);
         auto& h = m.hexes[1];
         std::swap_ranges(h.begin(), h.begin() + 4, h.begin() + 4);  // top <-> bottom
         return m;
       },
       {},
       {},
       {1},
       {},
       {},
       {},
       {shared_face},
       true,
       false},
      {"repeated node",
       [] {
         HexMesh m = structured_hex_grid(2, 1, 1);
         m.hexes[0][6] = m.hexes[0][5];
         return m;
       },
       {},
       {0},
       {0},
       {},
       {},
       {},
       {},
       true,
       true},
      {"node out of range",
       [] {
         HexMesh m = structured_hex_grid(2, 1, 1);
         m.hexes[1][2] = 99;
         return m;
       },
       {1},
       {},
       {},
       {},
       {},
       {},
       {},
       true,
       true},
  };
  for (const auto& c : cases) {
    const HexMesh m = c.make();
    const auto r = check_validity(m);
    const std::string name = c.name;
    CAPTURE(name);
    INFO(r.summary());
    CHECK_FALSE(r.ok());
    CHECK(r.out_of_range_hexes == c.out_of_range);
    CHECK(r.repeated_node_hexes == c.repeated);
    CHECK(r.inverted_hexes == c.inverted);
    auto sorted = [](auto v) {
      std::ranges::sort(v);
      return v;
    };
    CHECK(sorted(r.nonmanifold_vertices) == sorted(c.nonmanifold_vertices));
    CHECK(sorted(r.nonmanifold_edges) == sorted(c.nonmanifold_edges));
    CHECK(r.overshared_faces == c.overshared);
    CHECK(r.misoriented_faces == c.misoriented);
    CHECK(r.boundary.closed == c.boundary_closed);
    CHECK(r.boundary.manifold == c.boundary_manifold);
  }
}

TEST_CASE("validity: summary names the offenders") {
  const auto r = check_validity(keep_hexes(structured_hex_grid(2, 2, 2), {0, 7}));
  const std::string s = r.summary();
  CHECK(s.find("INVALID") != std::string::npos);
  CHECK(s.find("non-manifold vertices: 1 (13)") != std::string::npos);
}

TEST_CASE("validity: NaN coordinates are reported") {
  HexMesh m = structured_hex_grid(1, 1, 1);
  m.points[5].y() = std::numeric_limits<double>::quiet_NaN();
  const auto r = check_validity(m);
  CHECK_FALSE(r.ok());
  CHECK(r.non_finite_nodes == std::vector<Index>{5});
}

// ---- Planar quad meshes ----------------------------------------------------------------------

TEST_CASE("validity: 3x3 quad grid is a disk with one counter-clockwise loop") {
  const QuadMesh m = structured_quad_grid(3, 3);
  const auto r = check_validity(m);
  INFO(r.summary());
  CHECK(r.ok());
  // V - E + F = 16 - 24 + 9 = 1.
  CHECK(r.num_vertices == 16);
  CHECK(r.num_edges == 24);
  CHECK(r.num_faces == 9);
  CHECK(r.euler == 1);
  REQUIRE(r.boundary_loops.size() == 1);
  CHECK(r.boundary_loops[0].size() == 12);
  CHECK(signed_area(m, r.boundary_loops[0]) == doctest::Approx(9.0));
}

TEST_CASE("validity: quad annulus has an outer and a hole loop") {
  const QuadMesh m = keep_quads(structured_quad_grid(3, 3), {0, 1, 2, 3, 5, 6, 7, 8});
  const auto r = check_validity(m);
  INFO(r.summary());
  CHECK(r.ok());
  CHECK(r.euler == 0);  // 16 - 24 + 8
  REQUIRE(r.boundary_loops.size() == 2);
  auto loops = r.boundary_loops;
  std::ranges::sort(loops, {}, [](const auto& l) { return l.size(); });
  CHECK(loops[0].size() == 4);
  CHECK(loops[1].size() == 12);
  CHECK(signed_area(m, loops[0]) == doctest::Approx(-1.0));  // the hole runs clockwise
  CHECK(signed_area(m, loops[1]) == doctest::Approx(9.0));
  CHECK(std::ranges::is_permutation(loops[0], std::vector<Index>{5, 6, 9, 10}));
}

TEST_CASE("validity: each quad defect is found where it was put") {
  SUBCASE("bow tie: two quads sharing only a vertex") {
    const auto r = check_validity(keep_quads(structured_quad_grid(2, 2), {0, 3}));
    CHECK_FALSE(r.ok());
    CHECK(r.nonmanifold_vertices == std::vector<Index>{4});
    CHECK(r.overshared_edges.empty());
  }
  SUBCASE("edge shared by three quads") {
    QuadMesh m = structured_quad_grid(2, 1);  // nodes i + 3 j; quads share edge {1, 4}
    m.points.emplace_back(1.5, 0.2, 0.0);
    m.points.emplace_back(1.5, 0.8, 0.0);
    m.quads.push_back({1, 6, 7, 4});
    const auto r = check_validity(m);
    CHECK_FALSE(r.ok());
    CHECK(r.overshared_edges == std::vector<EdgeKey>{{1, 4}});
    CHECK(r.nonmanifold_vertices == std::vector<Index>{1, 4});
  }
  SUBCASE("clockwise quad") {
    QuadMesh m = structured_quad_grid(2, 1);
    std::ranges::reverse(m.quads[1]);
    const auto r = check_validity(m);
    CHECK_FALSE(r.ok());
    CHECK(r.inverted_quads == std::vector<Index>{1});
    CHECK(r.misoriented_edges == std::vector<EdgeKey>{{1, 4}});
  }
  SUBCASE("not planar") {
    QuadMesh m = structured_quad_grid(2, 1);
    m.points[4].z() = 0.1;
    const auto r = check_validity(m);
    CHECK_FALSE(r.planar);
    CHECK_FALSE(r.ok());
  }
  SUBCASE("plane x = 0 with normal +x") {
    QuadMesh m = structured_quad_grid(2, 2);
    // (x, y, z) -> (z, x, y) is a rotation taking +z to +x, so orientation is kept.
    for (auto& p : m.points) p = Point(p.z(), p.x(), p.y());
    CHECK(check_validity(m, Point::UnitX()).ok());
    CHECK_FALSE(check_validity(m, -Point::UnitX()).ok());  // seen from -x: all clockwise
    CHECK_FALSE(check_validity(m).planar);
  }
}

// ---- Local covering -------------------------------------------------------------------------

namespace {

constexpr double kPi = std::numbers::pi;

// A fan of 4 * turns quads around node 0 (the hub), each a parallelogram hub, spoke i, outer
// node, spoke i + 1, the spokes a quarter turn apart: turns = 1 is a valid disk, turns = 2
// wraps twice around the hub with every corner positive, edges shared by two quads and the
// hub's quads connected, i.e. nothing but the covering is wrong. Spoke radii grow by turn so
// that no two nodes coincide. Nodes: hub, spokes 1 .. 4 turns, outer nodes after them.
QuadMesh wrapped_star(int turns) {
  QuadMesh m;
  const int n = 4 * turns;
  m.points.emplace_back(0.0, 0.0, 0.0);
  for (int i = 0; i < n; ++i) {
    const double r = 1.0 + 0.5 * (i / 4), a = kPi / 2 * i;
    m.points.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
  }
  for (int i = 0; i < n; ++i) {
    const Index s = 1 + i, t = 1 + (i + 1) % n;
    m.points.push_back(m.points[s] + m.points[t]);
    m.quads.push_back({0, s, index_cast(1 + n + i), t});
  }
  return m;
}

// `layers` layers of hexes over a planar quad mesh (counter-clockwise from +z), one unit
// thick; node v of layer k is v + k * (number of quad nodes).
HexMesh extrude(const QuadMesh& q, int layers) {
  HexMesh m;
  const auto n = index_cast(q.points.size());
  for (int k = 0; k <= layers; ++k)
    for (const Point& p : q.points) m.points.push_back(p + Point(0, 0, k));
  for (int k = 0; k < layers; ++k)
    for (const auto& f : q.quads)
      m.hexes.push_back({f[0] + k * n, f[1] + k * n, f[2] + k * n, f[3] + k * n, f[0] + (k + 1) * n,
                         f[1] + (k + 1) * n, f[2] + (k + 1) * n, f[3] + (k + 1) * n});
  return m;
}

// Interior nodes of a structured grid moved by up to `amount` in each coordinate.
HexMesh jittered_grid(int n, double amount) {
  HexMesh m = structured_hex_grid(n, n, n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-amount, amount);
  for (auto& p : m.points)
    if (p.minCoeff() > 0.0 && p.maxCoeff() < n) p += Point(d(rng), d(rng), d(rng));
  return m;
}

// A 4 x 4 x 2 grid bent into three quarters of a thick-walled tube (radii 1 to 2): curved
// boundaries, convex outside and concave inside.
HexMesh bent_grid() {
  HexMesh m = structured_hex_grid(4, 4, 2);
  for (auto& p : m.points) {
    const double r = 1.0 + p.x() / 4, a = 1.5 * kPi * p.y() / 4;
    p = Point(r * std::cos(a), r * std::sin(a), p.z() / 2);
  }
  return m;
}

// A Kuhn-split 2 x 2 x 2 grid of tets, diced into 4 hexes each.
HexMesh kuhn_diced() {
  const Model model = grid_model({2, 2, 2}, 1.0, [](int, int, int) { return true; });
  return dice(tet_part(model)).mesh;
}

// The paper's Appendix A geode (tangled as printed) smoothed with its box faces sliding.
HexMesh smoothed_geode() {
  HexMesh m = appendix_a_geode();
  smooth_hex_mesh(m, box_constraints(m.points, Point(-12, -7, -12), Point(12, 7, 12)));
  return m;
}

std::vector<Index> nodes_of(const std::vector<NodeCoverage>& c) {
  std::vector<Index> out;
  for (const auto& x : c) out.push_back(x.node);
  return out;
}

}  // namespace

TEST_CASE("covering: embedded meshes cover every node once, on the boundary too") {
  // Boundary nodes on flat faces, convex and concave edges and corners (the block without an
  // octant has a node whose inside is 7/8 of space), curved walls, and the irregular corners
  // of diced tets; an interior node with 5 or 7 hexes comes with dicing.
  const std::vector<std::pair<const char*, std::function<HexMesh()>>> cases{
      {"3 x 3 x 3 grid", [] { return structured_hex_grid(3, 3, 3); }},
      {"ring of 8 hexes",
       [] {
         return keep_hexes(structured_hex_grid(3, 3, 1), {0, 1, 2, 3, 5, 6, 7, 8});
       }},
      {"2 x 2 x 2 block without an octant",
       [] {
         return keep_hexes(structured_hex_grid(2, 2, 2), {0, 1, 2, 3, 4, 5, 6});
       }},
      {"jittered 4 x 4 x 4 grid", [] { return jittered_grid(4, 0.3); }},
      {"bent tube", bent_grid},
      {"Kuhn-diced 2 x 2 x 2 tets", kuhn_diced},
      {"Appendix A geode, smoothed", smoothed_geode},
      {"fan of 4 hexes, 2 layers", [] { return extrude(wrapped_star(1), 2); }},
  };
  for (const auto& [name_, make] : cases) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& name = name_;
    CAPTURE(std::string(name));
    const HexMesh m = make();
    REQUIRE(min_scaled_jacobian(m) > 0.0);  // every node is judged
    const auto r = check_validity(m);
    INFO(r.summary());
    CHECK(r.ok());
    CHECK(r.overlapping_nodes.empty());
  }
}

TEST_CASE("covering: hexes wrapping twice around nodes are found there, all corners positive") {
  struct Case {
    const char* name;
    HexMesh mesh;
    std::vector<Index> overlapping;
    double angle_at_first;  // sum of the corner solid angles at the first overlapping node
    double expected_at_first;
  };
  // The extruded twice-wrapped fan: its hub line (nodes 0, 17, 34 in layers 0, 1, 2) has 16
  // quarter-space corners around the middle node (8 pi, not 4 pi) and 8 at the ends, which lie
  // on the flat bottom and top (4 pi, not the half-space's 2 pi).
  // Without one hex per layer (and its outer node: 16 nodes a layer) the hub line is on the
  // boundary, in a 270 degree notch: 14 corners at the middle node (7 pi) where the notch
  // leaves 3 pi.
  QuadMesh notched = wrapped_star(2);
  notched.quads.pop_back();
  notched.points.pop_back();  // its outer node
  const std::vector<Case> cases{
      {"fan wrapping twice", extrude(wrapped_star(2), 2), {0, 17, 34}, 4 * kPi, 2 * kPi},
      {"fan wrapping three times", extrude(wrapped_star(3), 1), {0, 25}, 6 * kPi, 2 * kPi},
      {"notched fan wrapping twice", extrude(notched, 2), {0, 16, 32}, 3.5 * kPi, 1.5 * kPi},
  };
  for (const auto& c : cases) {
    CAPTURE(std::string(c.name));
    REQUIRE(min_scaled_jacobian(c.mesh) > 0.0);
    const auto r = check_validity(c.mesh);
    INFO(r.summary());
    CHECK_FALSE(r.ok());
    // Only the covering is wrong.
    geode::test::check_combinatorial_ball(r);
    CHECK(r.inverted_hexes.empty());
    CHECK(nodes_of(r.overlapping_nodes) == c.overlapping);
    REQUIRE(!r.overlapping_nodes.empty());
    CHECK(r.overlapping_nodes[0].angle == doctest::Approx(c.angle_at_first));
    CHECK(r.overlapping_nodes[0].expected == doctest::Approx(c.expected_at_first));
  }
  const auto r = check_validity(extrude(wrapped_star(2), 2));
  REQUIRE(r.overlapping_nodes.size() == 3);
  CHECK(r.overlapping_nodes[1].angle == doctest::Approx(8 * kPi));
  CHECK(r.overlapping_nodes[1].expected == doctest::Approx(4 * kPi));
  CHECK(r.summary().find("nodes the hexes cover more than once (corner solid angles): 3 (0: 4 pi, "
                         "not 2 pi, 17: 8 pi, "
                         "not 4 pi, 34: 4 pi, not 2 pi)") != std::string::npos);
}

TEST_CASE("covering: the same where the counting probe runs along the wrapped edge") {
  // Interior nodes are judged by counting the cones around the probe direction; turned so that
  // the hub line runs along it, the probe is on faces of every hub corner and the solid angles
  // decide, with the same answer.
  const Eigen::Quaterniond turn =
      Eigen::Quaterniond::FromTwoVectors(Point::UnitZ(), coverage_probe());
  for (int turns : {1, 2}) {
    CAPTURE(turns);
    HexMesh m = extrude(wrapped_star(turns), 2);
    for (auto& p : m.points) p = turn * p;
    const auto r = check_validity(m);
    INFO(r.summary());
    CHECK(r.ok() == (turns == 1));
    const Index per_layer = index_cast(m.points.size() / 3);
    CHECK(nodes_of(r.overlapping_nodes) ==
          (turns == 1 ? std::vector<Index>{} : std::vector<Index>{0, per_layer, 2 * per_layer}));
    if (turns == 2) {
      REQUIRE(r.overlapping_nodes.size() == 3);
      CHECK(r.overlapping_nodes[1].angle == doctest::Approx(8 * kPi));
    }
  }
}

TEST_CASE("covering: quad meshes, planar") {
  QuadMesh notched = wrapped_star(2);
  notched.quads.pop_back();
  notched.points.pop_back();  // its outer node
  QuadMesh jittered = structured_quad_grid(4, 4);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  for (auto& p : jittered.points)
    if (p.x() > 0 && p.x() < 4 && p.y() > 0 && p.y() < 4) p += Point(d(rng), d(rng), 0.0);
  struct Case {
    const char* name;
    QuadMesh mesh;
    std::vector<Index> overlapping;
    double angle, expected;  // at the first overlapping node
  };
  const std::vector<Case> cases{
      {"3 x 3 grid", structured_quad_grid(3, 3), {}, 0, 0},
      {"annulus", keep_quads(structured_quad_grid(3, 3), {0, 1, 2, 3, 5, 6, 7, 8}), {}, 0, 0},
      {"L", keep_quads(structured_quad_grid(2, 2), {0, 1, 2}), {}, 0, 0},
      {"jittered 4 x 4 grid", jittered, {}, 0, 0},
      {"fan of 4", wrapped_star(1), {}, 0, 0},
      {"fan wrapping twice", wrapped_star(2), {0}, 4 * kPi, 2 * kPi},
      {"notched fan wrapping twice", notched, {0}, 3.5 * kPi, 1.5 * kPi},
  };
  for (const auto& c : cases) {
    CAPTURE(std::string(c.name));
    const auto r = check_validity(c.mesh);
    INFO(r.summary());
    CHECK(r.inverted_quads.empty());
    CHECK(r.nonmanifold_vertices.empty());
    CHECK(r.ok() == c.overlapping.empty());
    CHECK(nodes_of(r.overlapping_nodes) == c.overlapping);
    if (r.overlapping_nodes.empty()) continue;
    CHECK(r.overlapping_nodes[0].angle == doctest::Approx(c.angle));
    CHECK(r.overlapping_nodes[0].expected == doctest::Approx(c.expected));
  }
}
