// Tests of the mesh isomorphism checker (primal/isomorphism.hpp), which the tests of every layer
// and the Python module use to compare meshes against references such as Appendix A.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using geode::primal::HexMesh;
using geode::primal::Index;
using geode::primal::QuadMesh;
namespace topo = geode::primal::topology;
namespace gt = geode::test;

namespace {

// A copy of `cells` over `n_nodes` nodes with nodes renumbered, cells shuffled and the corners
// of every cell permuted by a symmetry drawn from `syms`: the same mesh, differently written.
template <typename Cell, typename Sym>
std::vector<Cell> scramble(std::size_t n_nodes, const std::vector<Cell>& cells,
                           const std::vector<Sym>& syms, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Index> perm(n_nodes);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<Cell> out;
  for (const auto& cell : cells) {
    const auto& s = syms[std::uniform_int_distribution<std::size_t>(0, syms.size() - 1)(rng)];
    Cell c{};
    for (std::size_t k = 0; k < c.size(); ++k) c[k] = perm[cell[s[k]]];
    out.push_back(c);
  }
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

HexMesh scrambled(const HexMesh& m, unsigned seed) {
  std::vector<std::array<int, 8>> rotations;
  for (const auto& s : gt::hex_symmetries())
    if (gt::is_rotation(s)) rotations.push_back(s);
  HexMesh out;
  out.points.assign(m.points.size(), geode::primal::Point::Zero());
  out.hexes = scramble(m.points.size(), m.hexes, rotations, seed);
  return out;
}

QuadMesh scrambled(const QuadMesh& m, unsigned seed) {
  QuadMesh out;
  out.points.assign(m.points.size(), geode::primal::Point::Zero());
  out.quads = scramble(m.points.size(), m.quads, gt::quad_symmetries(), seed);
  return out;
}

// A closed ring of n hexes: cross-section i is the square of nodes 4i..4i+3, hex i joins
// sections i and i+1 (mod n). Every node lies in two hexes, on the boundary, with degree 4.
HexMesh hex_ring(int n, Index first_node = 0) {
  HexMesh m;
  m.points.assign(4 * n, geode::primal::Point::Zero());
  for (int i = 0; i < n; ++i) {
    const Index p = first_node + 4 * i, q = first_node + 4 * ((i + 1) % n);
    m.hexes.push_back({p, p + 1, p + 2, p + 3, q, q + 1, q + 2, q + 3});
  }
  return m;
}

}  // namespace

TEST_CASE("cube and square symmetries come from the topology tables") {
  const auto& hs = gt::hex_symmetries();
  CHECK(hs.size() == 48);  // |O_h| = 48
  CHECK(std::set<std::array<int, 8>>(hs.begin(), hs.end()).size() == 48);
  CHECK(hs.front() == std::array<int, 8>{0, 1, 2, 3, 4, 5, 6, 7});
  CHECK(std::count_if(hs.begin(), hs.end(), gt::is_rotation) == 24);  // |O| = 24
  // Every symmetry sends faces to faces (it was only required to keep edges).
  std::set<std::set<int>> faces;
  for (const auto& f : topo::kHexFaceCorners) faces.insert({f[0], f[1], f[2], f[3]});
  for (const auto& s : hs)
    for (const auto& f : topo::kHexFaceCorners)
      CHECK(faces.count({s[f[0]], s[f[1]], s[f[2]], s[f[3]]}) == 1);
  // Swapping the two corners of an edge is a reflection only for a square, never for a cube.
  CHECK(std::find(hs.begin(), hs.end(), std::array<int, 8>{1, 0, 2, 3, 4, 5, 6, 7}) == hs.end());
  CHECK(gt::quad_symmetries().size() == 8);  // dihedral group of the square
}

TEST_CASE("a hex mesh is isomorphic to itself renumbered with rotated hexes") {
  struct Case {
    const char* name;
    HexMesh mesh;
  };
  const std::vector<Case> cases{{"1x1x1", gt::structured_hex_grid(1, 1, 1)},
                                {"4x3x2", gt::structured_hex_grid(4, 3, 2)},
                                {"appendix A", gt::appendix_a_geode()},
                                {"10x10x10", gt::structured_hex_grid(10, 10, 10)}};
  for (const auto& c : cases) {
    CAPTURE(c.name);
    for (unsigned seed : {1u, 2u, 3u}) {
      const HexMesh other = scrambled(c.mesh, seed);
      const auto m = gt::find_isomorphism(c.mesh, other);
      REQUIRE(m.has_value());
      CHECK(gt::is_isomorphism(c.mesh, other, *m));
      const auto back = gt::find_isomorphism(other, c.mesh);
      REQUIRE(back.has_value());
      CHECK(gt::is_isomorphism(other, c.mesh, *back));
    }
  }
}

TEST_CASE("a hex mesh with one hex modified is not isomorphic") {
  for (const HexMesh& base : {gt::structured_hex_grid(3, 2, 2), gt::appendix_a_geode()}) {
    // (a) One hex twisted: corners 4 and 5 swapped. Node-hex incidence as sets is unchanged;
    // only the cube structure tells the meshes apart.
    HexMesh twisted = base;
    std::swap(twisted.hexes[1][4], twisted.hexes[1][5]);
    CHECK_FALSE(gt::find_isomorphism(base, twisted).has_value());
    CHECK_FALSE(gt::find_isomorphism(base, scrambled(twisted, 7)).has_value());
    // (b) One corner of one hex moved to a node the hex did not use.
    HexMesh moved = base;
    auto& hex = moved.hexes.back();
    for (Index n = 0; n < geode::primal::index_cast(base.points.size()); ++n)
      if (std::find(hex.begin(), hex.end(), n) == hex.end()) {
        hex[6] = n;
        break;
      }
    CHECK_FALSE(gt::find_isomorphism(base, moved).has_value());
  }
  // The mapping check itself rejects a twisted image.
  const HexMesh cube = gt::structured_hex_grid(1, 1, 1);
  HexMesh twisted = cube;
  std::swap(twisted.hexes[0][0], twisted.hexes[0][1]);
  gt::MeshMapping identity{{0, 1, 2, 3, 4, 5, 6, 7}, {0}};
  CHECK(gt::is_isomorphism(cube, cube, identity));
  CHECK_FALSE(gt::is_isomorphism(cube, twisted, identity));
}

TEST_CASE("different meshes with equal counts are not isomorphic") {
  // A row of three hexes and an L of three hexes: 16 nodes, 3 hexes each.
  const HexMesh row = gt::structured_hex_grid(3, 1, 1);
  HexMesh ell = gt::structured_hex_grid(2, 2, 1);
  ell.hexes.pop_back();  // drops hex (1,1); nodes (2,2,0) and (2,2,1) become unused
  std::vector<Index> keep;
  for (Index n = 0; n < 18; ++n)
    if (n != 8 && n != 17) keep.push_back(n);
  std::vector<Index> renumber(18, -1);
  for (std::size_t i = 0; i < keep.size(); ++i) renumber[keep[i]] = geode::primal::index_cast(i);
  HexMesh ell16;
  for (Index n : keep) ell16.points.push_back(ell.points[n]);
  for (auto h : ell.hexes) {
    for (auto& n : h) n = renumber[n];
    ell16.hexes.push_back(h);
  }
  REQUIRE(ell16.points.size() == row.points.size());
  CHECK_FALSE(gt::find_isomorphism(row, ell16).has_value());

  // A ring of six hexes against two rings of three: every node looks alike locally (two hexes,
  // boundary, degree 4), so colour refinement cannot tell them apart and the search must.
  const HexMesh ring6 = hex_ring(6);
  HexMesh two_rings = hex_ring(3);
  const HexMesh second = hex_ring(3, 12);
  two_rings.points.resize(24, geode::primal::Point::Zero());
  two_rings.hexes.insert(two_rings.hexes.end(), second.hexes.begin(), second.hexes.end());
  CHECK_FALSE(gt::find_isomorphism(ring6, two_rings).has_value());
  CHECK_FALSE(gt::find_isomorphism(two_rings, ring6).has_value());
  // A ring of six closed with a quarter twist: same components, same local look everywhere,
  // but its four corner lines join into one loop of 24 edges instead of four loops of 6.
  HexMesh twisted = ring6;
  twisted.hexes.back() = {20, 21, 22, 23, 1, 2, 3, 0};
  CHECK_FALSE(gt::find_isomorphism(ring6, twisted).has_value());
  CHECK_FALSE(gt::find_isomorphism(twisted, ring6).has_value());
  CHECK(gt::find_isomorphism(twisted, scrambled(twisted, 9)).has_value());
  // ... while each is isomorphic to a scrambled copy of itself (several components work).
  CHECK(gt::find_isomorphism(two_rings, scrambled(two_rings, 5)).has_value());
  CHECK(gt::find_isomorphism(ring6, scrambled(ring6, 5)).has_value());
}

TEST_CASE("node labels restrict the mapping") {
  const HexMesh cube = gt::structured_hex_grid(1, 1, 1);
  // Label the bottom face (z = 0: nodes 0..3) in the first mesh.
  const std::vector<int> bottom{1, 1, 1, 1, 0, 0, 0, 0};
  // The face x = 1 of the same cube (nodes 1, 3, 5, 7): a face, so a symmetry exists.
  const std::vector<int> right{0, 1, 0, 1, 0, 1, 0, 1};
  const auto m = gt::find_isomorphism(cube, cube, {bottom, right});
  REQUIRE(m.has_value());
  CHECK(gt::is_isomorphism(cube, cube, *m, {bottom, right}));
  for (Index n : {0, 1, 2, 3}) CHECK(right[m->node_map[n]] == 1);
  // Four corners that are not a face (the rectangle through edges 0-1 and 6-7): none.
  const std::vector<int> slab{1, 1, 0, 0, 0, 0, 1, 1};
  CHECK_FALSE(gt::find_isomorphism(cube, cube, {bottom, slab}).has_value());
  CHECK_THROWS_AS(gt::find_isomorphism(cube, cube, {bottom, {}}), geode::InvalidInput);
}

TEST_CASE("quad meshes: renumbered copies match, different shapes do not") {
  const QuadMesh grid = gt::structured_quad_grid(3, 2);
  for (unsigned seed : {1u, 2u}) {
    const QuadMesh other = scrambled(grid, seed);
    const auto m = gt::find_isomorphism(grid, other);
    REQUIRE(m.has_value());
    CHECK(gt::is_isomorphism(grid, other, *m));
  }
  // Row of three quads vs an L of three quads: 8 nodes, 3 quads each.
  const QuadMesh row = gt::structured_quad_grid(3, 1);
  QuadMesh ell;
  ell.points.assign(8, geode::primal::Point::Zero());
  // 6 7        L: quads (0,0) (1,0) (0,1) of a 2x2 grid, nodes renumbered 0..7.
  // 3 4 5
  // 0 1 2
  ell.quads = {{0, 1, 4, 3}, {1, 2, 5, 4}, {3, 4, 7, 6}};
  CHECK_FALSE(gt::find_isomorphism(row, ell).has_value());
  // A quad with two corners swapped (a bow-tie) is not the same square.
  QuadMesh bow = grid;
  std::swap(bow.quads[2][0], bow.quads[2][1]);
  CHECK_FALSE(gt::find_isomorphism(grid, bow).has_value());
}

TEST_CASE("bad input names the mesh and the cell") {
  HexMesh bad = gt::structured_hex_grid(2, 1, 1);
  bad.hexes[1][3] = 99;
  CHECK_THROWS_WITH_AS(gt::find_isomorphism(bad, bad), doctest::Contains("cell 1"),
                       geode::InvalidInput);
  HexMesh repeated = gt::structured_hex_grid(1, 1, 1);
  repeated.hexes[0][7] = repeated.hexes[0][0];
  CHECK_THROWS_AS(gt::find_isomorphism(repeated, repeated), geode::InvalidInput);
  HexMesh fan = gt::structured_hex_grid(1, 1, 1);
  for (int i = 0; i < 2; ++i) {  // three hexes on the bottom face of the cube
    const Index base = geode::primal::index_cast(fan.points.size());
    fan.points.resize(fan.points.size() + 4, geode::primal::Point::Zero());
    fan.hexes.push_back({base, base + 1, base + 2, base + 3, 0, 1, 2, 3});
  }
  CHECK_THROWS_AS(gt::find_isomorphism(fan, fan), geode::TopologyError);
}
