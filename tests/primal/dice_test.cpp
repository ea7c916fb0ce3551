// Dicing: node counts V' = V + E + F + C counted by hand, conformity and orientation through the
// validity report, exact volume preservation element by element (the children of a hex are
// its trilinear map restricted to the 8 sub-cubes), and the node-origin map.
#include <geode/primal/dice.hpp>

#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode::primal;
using geode::test::structured_hex_grid;
using geode::test::structured_quad_grid;

namespace {

double tet_signed_volume(const TetMesh& m, const std::array<Index, 4>& t) {
  const Point& a = m.points[t[0]];
  return (m.points[t[1]] - a).dot((m.points[t[2]] - a).cross(m.points[t[3]] - a)) / 6.0;
}

// Kuhn (Freudenthal) split of an n^3 grid: each cube into the 6 tets along its (0,0,0)-(1,1,1)
// diagonal, one per permutation of the axes. The same diagonal direction in every cube makes
// the face diagonals of neighbouring cubes agree, so the tet mesh is conforming. Odd
// permutations give negative tets and get two corners swapped.
TetMesh kuhn_grid(int n) {
  const HexMesh g = structured_hex_grid(n, n, n);
  TetMesh m;
  m.points = g.points;
  auto id = [n](int i, int j, int k) { return index_cast(i + (n + 1) * (j + (n + 1) * k)); };
  std::array<int, 3> perm{0, 1, 2};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        std::ranges::sort(perm);
        do {
          std::array<int, 3> p{i, j, k};
          std::array<Index, 4> t{};
          t[0] = id(p[0], p[1], p[2]);
          for (int s = 0; s < 3; ++s) {
            ++p[perm[s]];
            t[s + 1] = id(p[0], p[1], p[2]);
          }
          if (tet_signed_volume(m, t) < 0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
        } while (std::ranges::next_permutation(perm).found);
      }
  return m;
}

// Deterministic small displacement so that elements are not affine (volume checks then test
// the trilinear subdivision, not just cube arithmetic).
void jitter(std::vector<Point>& points, double amount) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double t = static_cast<double>(i);
    points[i] +=
        amount * Point(std::sin(1.3 * t + 0.1), std::sin(2.1 * t + 0.7), std::sin(0.7 * t + 1.9));
  }
}

std::map<NodeOriginKind, int> count_kinds(const std::vector<NodeOrigin>& origin) {
  std::map<NodeOriginKind, int> n;
  for (const auto& o : origin) ++n[o.kind];
  return n;
}

// Every new node is the centroid of what it came from.
template <typename Mesh, typename Elements>
void check_origin_positions(const std::vector<Point>& input_points, const Elements& input_elements,
                            const Mesh& diced, const std::vector<NodeOrigin>& origin) {
  REQUIRE(origin.size() == diced.points.size());
  for (std::size_t v = 0; v < origin.size(); ++v) {
    Point expected = Point::Zero();
    if (origin[v].kind == NodeOriginKind::kCell) {
      const auto& e = input_elements[origin[v].element];
      for (Index c : e) expected += input_points[c] / static_cast<double>(e.size());
    } else {
      int n = 0;
      for (Index c : origin[v].nodes) {
        if (c == kInvalidIndex) break;
        expected += input_points[c];
        ++n;
      }
      expected /= n;
    }
    CHECK((diced.points[v] - expected).norm() < 1e-14);
  }
}

}  // namespace

TEST_CASE("dice: 3x3x3 hex block -> the 6x6x6 block") {
  const HexMesh m = structured_hex_grid(3, 3, 3);
  const auto d = dice(m);
  // V' = V + E + F + C = 64 + 144 + 108 + 27 = 343 = 7^3.
  CHECK(d.mesh.points.size() == 343);
  CHECK(d.mesh.hexes.size() == 8 * 27);
  const auto kinds = count_kinds(d.origin);
  CHECK(kinds.at(NodeOriginKind::kNode) == 64);
  CHECK(kinds.at(NodeOriginKind::kEdge) == 144);
  CHECK(kinds.at(NodeOriginKind::kFace) == 108);
  CHECK(kinds.at(NodeOriginKind::kCell) == 27);
  check_origin_positions(m.points, m.hexes, d.mesh, d.origin);

  const auto r = check_validity(d.mesh);
  INFO(r.summary());
  CHECK(r.ok());  // conforming (no internal face seen once), manifold, all corners positive
  CHECK(r.euler == 1);
  CHECK(boundary_quads(d.mesh).size() == 6 * 36);

  // Combinatorially and geometrically the 6x6x6 grid scaled by 1/2.
  HexMesh fine = structured_hex_grid(6, 6, 6);
  const auto iso = geode::test::find_isomorphism(d.mesh, fine);
  REQUIRE(iso);
  for (std::size_t v = 0; v < d.mesh.points.size(); ++v) {
    CHECK((2.0 * d.mesh.points[v] - fine.points[iso->node_map[v]]).norm() < 1e-12);
  }
  // Parent map: child c of hex h contains parent corner c.
  for (std::size_t h = 0; h < d.mesh.hexes.size(); ++h) {
    CHECK(d.parent[h] == index_cast(h / 8));
    CHECK(d.mesh.hexes[h][h % 8] == m.hexes[h / 8][h % 8]);
  }
}

TEST_CASE("dice: first new node of a single hex is the midpoint of edge {0, 1}") {
  const auto d = dice(structured_hex_grid(1, 1, 1));
  // Child 0's corner 1 is the first non-corner support met: edge 0-1 (hand: (0.5, 0, 0)).
  REQUIRE(d.mesh.points.size() == 8 + 12 + 6 + 1);
  CHECK(d.origin[8].kind == NodeOriginKind::kEdge);
  CHECK(d.origin[8].nodes == FaceKey{0, 1, kInvalidIndex, kInvalidIndex});
  CHECK(d.mesh.points[8] == Point(0.5, 0, 0));
  CHECK(d.origin[26].kind == NodeOriginKind::kCell);
  CHECK(d.origin[26].element == 0);
  CHECK(d.mesh.points[26] == Point(0.5, 0.5, 0.5));
  // Child 0 is the sub-cube at corner 0: [0, 0.5]^3, corners in the parent's order.
  for (int c = 0; c < 8; ++c) {
    const auto& rc = topology::kHexCornerCoords[c];
    CHECK(d.mesh.points[d.mesh.hexes[0][c]] == Point(0.5 * rc[0], 0.5 * rc[1], 0.5 * rc[2]));
  }
}

TEST_CASE("dice: distorted hexes keep their volume child by child and stay positive") {
  HexMesh m = structured_hex_grid(3, 3, 3);
  jitter(m.points, 0.15);
  m.block.assign(m.hexes.size(), 0);
  for (std::size_t h = 0; h < m.hexes.size(); ++h) m.block[h] = static_cast<int>(h % 3) + 1;
  REQUIRE(check_validity(m).ok());
  const auto d = dice(m);
  const auto r = check_validity(d.mesh);
  INFO(r.summary());
  CHECK(r.ok());
  std::vector<double> sum(m.hexes.size(), 0.0);
  for (std::size_t h = 0; h < d.mesh.hexes.size(); ++h) {
    sum[d.parent[h]] += hex_volume(hex_corners(d.mesh, index_cast(h)));
    CHECK(d.mesh.block[h] == m.block[d.parent[h]]);
  }
  for (std::size_t h = 0; h < m.hexes.size(); ++h) {
    CHECK(sum[h] == doctest::Approx(hex_volume(hex_corners(m, index_cast(h)))).epsilon(1e-12));
  }
}

TEST_CASE("dice: 48-tet Kuhn grid -> 192 positive hexes, conforming") {
  TetMesh m = kuhn_grid(2);
  jitter(m.points, 0.04);
  REQUIRE(m.tets.size() == 48);
  double total = 0.0;
  for (const auto& t : m.tets) {
    REQUIRE(tet_signed_volume(m, t) > 0);
    total += tet_signed_volume(m, t);
  }
  const auto d = dice(m);
  // By hand for the 2x2x2 Kuhn grid: V = 27; E = 54 axis + 36 face-diagonal + 8 body-diagonal
  // = 98; F = (4 x 48 + 48 boundary triangles) / 2 = 120; T = 48. (V - E + F - T = 1.)
  // V' = 27 + 98 + 120 + 48 = 293.
  CHECK(d.mesh.points.size() == 293);
  CHECK(d.mesh.hexes.size() == 4 * 48);
  const auto kinds = count_kinds(d.origin);
  CHECK(kinds.at(NodeOriginKind::kNode) == 27);
  CHECK(kinds.at(NodeOriginKind::kEdge) == 98);
  CHECK(kinds.at(NodeOriginKind::kFace) == 120);
  CHECK(kinds.at(NodeOriginKind::kCell) == 48);
  check_origin_positions(m.points, m.tets, d.mesh, d.origin);
  for (const auto& o : d.origin) {
    if (o.kind == NodeOriginKind::kFace) CHECK(o.nodes[3] == kInvalidIndex);  // triangles
  }

  const auto r = check_validity(d.mesh);
  INFO(r.summary());
  CHECK(r.ok());
  CHECK(r.euler == 1);
  CHECK(r.boundary.euler == 2);
  CHECK(boundary_quads(d.mesh).size() == 3 * 48);  // 3 quads per boundary triangle

  // The 4 hexes of a tet tile it: their trilinear volumes add up to the tet's.
  std::vector<double> sum(m.tets.size(), 0.0);
  double diced_total = 0.0;
  for (std::size_t h = 0; h < d.mesh.hexes.size(); ++h) {
    const double v = hex_volume(hex_corners(d.mesh, index_cast(h)));
    sum[d.parent[h]] += v;
    diced_total += v;
  }
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    CHECK(sum[t] == doctest::Approx(tet_signed_volume(m, m.tets[t])).epsilon(1e-12));
  }
  CHECK(diced_total == doctest::Approx(total).epsilon(1e-12));
  // Child c's corner 0 is tet corner c.
  for (std::size_t h = 0; h < d.mesh.hexes.size(); ++h) {
    CHECK(d.mesh.hexes[h][0] == m.tets[h / 4][h % 4]);
  }
}

TEST_CASE("dice: quads -> 4 and triangles -> 3, counter-clockwise, conforming") {
  SUBCASE("3x3 quad grid") {
    const QuadMesh m = structured_quad_grid(3, 3);
    const auto d = dice(m);
    CHECK(d.mesh.points.size() == 16 + 24 + 9);  // 7^2
    CHECK(d.mesh.quads.size() == 36);
    check_origin_positions(m.points, m.quads, d.mesh, d.origin);
    const auto r = check_validity(d.mesh);
    INFO(r.summary());
    CHECK(r.ok());
    REQUIRE(r.boundary_loops.size() == 1);
    CHECK(r.boundary_loops[0].size() == 24);
    const auto iso = geode::test::find_isomorphism(d.mesh, structured_quad_grid(6, 6));
    CHECK(iso);
  }
  SUBCASE("3x3 grid of squares split into 18 triangles") {
    const QuadMesh g = structured_quad_grid(3, 3);
    TriMesh m;
    m.points = g.points;
    for (const auto& q : g.quads) {  // diagonal 0-2; both triangles counter-clockwise
      m.tris.push_back({q[0], q[1], q[2]});
      m.tris.push_back({q[0], q[2], q[3]});
    }
    const auto d = dice(m);
    // V + E + F = 16 + (24 + 9 diagonals) + 18 = 67.
    CHECK(d.mesh.points.size() == 67);
    CHECK(d.mesh.quads.size() == 54);
    const auto kinds = count_kinds(d.origin);
    CHECK(kinds.at(NodeOriginKind::kEdge) == 33);
    CHECK(kinds.at(NodeOriginKind::kCell) == 18);
    CHECK(kinds.count(NodeOriginKind::kFace) == 0);
    check_origin_positions(m.points, m.tris, d.mesh, d.origin);
    const auto r = check_validity(d.mesh);
    INFO(r.summary());
    CHECK(r.ok());
    CHECK(r.euler == 1);
    REQUIRE(r.boundary_loops.size() == 1);
    CHECK(r.boundary_loops[0].size() == 24);
  }
}

TEST_CASE("dice: bad input") {
  HexMesh m = structured_hex_grid(2, 1, 1);
  m.hexes[1][3] = 40;
  CHECK_THROWS_WITH_AS(dice(m), "dice: hex 1 corner 3: node 40 out of range [0, 12)",
                       geode::InvalidInput);
  HexMesh b = structured_hex_grid(2, 1, 1);
  b.block = {1};
  CHECK_THROWS_AS(dice(b), geode::InvalidInput);
}

TEST_CASE("diced_min_scaled_jacobian: the minimum over dice()'s hexes, without dicing") {
  // Per cell too, bit for bit: conform and geode_mpi compare these figures with those read off
  // the diced children, so they must be the same doubles (the children's corners placed as
  // dice() places them).
  const auto children_min = [](const HexMesh& diced, std::size_t cell, std::size_t per) {
    double m = 1.0;
    for (std::size_t k = cell * per; k < (cell + 1) * per; ++k)
      m = std::min(m, hex_scaled_jacobian(hex_corners(diced, index_cast(k))));
    return m;
  };
  for (double amount : {0.0, 0.08, 0.2}) {
    CAPTURE(amount);
    TetMesh t = kuhn_grid(3);
    jitter(t.points, amount);
    HexMesh h = structured_hex_grid(3, 2, 2);
    jitter(h.points, amount);
    const double tets = diced_min_scaled_jacobian(t.points, t.tets);
    const double hexes = diced_min_scaled_jacobian(h.points, h.hexes);
    CHECK(tets == doctest::Approx(min_scaled_jacobian(dice(t).mesh)).epsilon(1e-12));
    CHECK(hexes == doctest::Approx(min_scaled_jacobian(dice(h).mesh)).epsilon(1e-12));
    if (amount == 0.0)
      CHECK(hexes == doctest::Approx(1.0));
    else
      CHECK(tets < diced_min_scaled_jacobian(kuhn_grid(3).points, kuhn_grid(3).tets));
    const auto each_tet = diced_scaled_jacobian_per_cell(t.points, t.tets);
    const auto each_hex = diced_scaled_jacobian_per_cell(h.points, h.hexes);
    const HexMesh dt = dice(t).mesh, dh = dice(h).mesh;
    REQUIRE(dt.hexes.size() == 4 * t.tets.size());
    REQUIRE(dh.hexes.size() == 8 * h.hexes.size());
    for (std::size_t k = 0; k < t.tets.size(); ++k) CHECK(each_tet[k] == children_min(dt, k, 4));
    for (std::size_t k = 0; k < h.hexes.size(); ++k) CHECK(each_hex[k] == children_min(dh, k, 8));
  }
  CHECK(diced_min_scaled_jacobian(std::vector<Point>{}, std::vector<std::array<Index, 4>>{}) ==
        1.0);
}
