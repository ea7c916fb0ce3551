// Pillowing: the shrink set's boundary becomes a layer of new hexes, the mesh stays valid, its
// boundary keeps its quads, and a doublet (an interior edge in two hexes) is removed when one
// of its hexes is pillowed.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <set>

#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/pillow.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include "support/fixtures.hpp"

using namespace geode;
using primal::Index;
using primal::Point;

namespace {

std::set<primal::FaceKey> boundary_keys(const primal::HexMesh& m) {
  std::set<primal::FaceKey> s;
  for (const auto& f : primal::unique_faces(m))
    if (f.uses.size() == 1) s.insert(f.key);
  return s;
}

// Interior edges (on no boundary face) and how many hexes use each.
std::map<primal::EdgeKey, int> interior_edge_valence(const primal::HexMesh& m) {
  std::set<primal::EdgeKey> on_boundary;
  for (const auto& f : primal::unique_faces(m))
    if (f.uses.size() == 1)
      for (int i = 0; i < 4; ++i)
        on_boundary.insert(primal::edge_key(f.nodes[primal::index_cast<std::size_t>(i)],
                                            f.nodes[primal::index_cast<std::size_t>((i + 1) % 4)]));
  std::map<primal::EdgeKey, int> v;
  for (const auto& h : m.hexes)
    for (const auto& e : primal::topology::kHexEdgeCorners) {
      const auto k = primal::edge_key(h[primal::index_cast<std::size_t>(e[0])],
                                      h[primal::index_cast<std::size_t>(e[1])]);
      if (!on_boundary.count(k)) ++v[k];
    }
  return v;
}

}  // namespace

TEST_CASE("pillow: one hex becomes a hex wrapped in six, the boundary kept") {
  const auto grid = test::structured_hex_grid(1, 1, 1);
  const std::vector<Index> set{0};
  const auto r = primal::pillow(grid, set);
  CHECK(r.mesh.hexes.size() == 7);
  CHECK(r.layer.size() == 6);
  CHECK(r.copy_of.size() == 8);
  const auto v = primal::check_validity(r.mesh);
  CHECK(v.ok());
  CHECK(v.euler == 1);
  CHECK(boundary_keys(r.mesh) == boundary_keys(grid));
}

TEST_CASE("pillow: shrink sets inside and on the boundary of a grid") {
  const auto grid = test::structured_hex_grid(3, 3, 3);
  // Hex (i, j, k) is i + 3 (j + 3 k).
  const std::vector<std::vector<Index>> sets{
      {13}, {0, 1, 3, 4}, {4, 13, 22}, {0, 1, 2, 3, 4, 5, 6, 7, 8}};
  for (const auto& set : sets) {
    CAPTURE(set.size());
    const auto r = primal::pillow(grid, set);
    // One new hex per face of the set not shared by two of its hexes.
    std::map<primal::FaceKey, int> uses;
    for (Index h : set)
      for (const auto& f : primal::topology::kHexFaceCorners) {
        std::array<Index, 4> n{};
        for (int i = 0; i < 4; ++i)
          n[primal::index_cast<std::size_t>(i)] =
              grid.hexes[primal::index_cast<std::size_t>(h)]
                        [primal::index_cast<std::size_t>(f[primal::index_cast<std::size_t>(i)])];
        ++uses[primal::face_key(n)];
      }
    const auto surface =
        std::count_if(uses.begin(), uses.end(), [](const auto& u) { return u.second == 1; });
    CHECK(r.layer.size() == primal::index_cast<std::size_t>(surface));
    CHECK(r.mesh.hexes.size() == grid.hexes.size() + r.layer.size());
    const auto v = primal::check_validity(r.mesh);
    CAPTURE(v.summary());
    CHECK(v.ok());
    CHECK(v.euler == 1);
    CHECK(boundary_keys(r.mesh) == boundary_keys(grid));
    // Every copy lies strictly inside the unit cubes' box: new nodes are interior.
    for (std::size_t i = grid.points.size(); i < r.mesh.points.size(); ++i) {
      const Point& p = r.mesh.points[i];
      CHECK((p.minCoeff() > 0 && p.maxCoeff() < 3));
    }
  }
}

TEST_CASE("pillow: pillowing one hex of a doublet removes it") {
  // A unit square split through an interior node m into two quads that share the edges c0-m
  // and m-c2 (m is an interior node of valence 2), extruded one layer: the two hexes share two
  // faces and the vertical edge through m is an interior edge in only two hexes.
  primal::HexMesh m;
  const Point base[] = {Point(0, 0, 0), Point(1, 0, 0), Point(1, 1, 0), Point(0, 1, 0),
                        Point(0.5, 0.5, 0)};
  for (double z : {0.0, 1.0})
    for (const auto& p : base) m.points.push_back(p + Point(0, 0, z));
  m.hexes = {{0, 1, 2, 4, 5, 6, 7, 9}, {2, 3, 0, 4, 7, 8, 5, 9}};
  auto doublets = [](const primal::HexMesh& mesh) {
    int n = 0;
    for (const auto& [edge, valence] : interior_edge_valence(mesh)) n += valence == 2;
    return n;
  };
  REQUIRE(doublets(m) == 1);
  const std::vector<Index> set{0};
  const auto r = primal::pillow(m, set);
  CHECK(doublets(r.mesh) == 0);
  const auto v = primal::check_validity(r.mesh);
  CHECK(v.overshared_faces.empty());
  CHECK(v.misoriented_faces.empty());
  CHECK(v.nonmanifold_edges.empty());
  CHECK(v.euler == 1);
  CHECK(v.boundary.closed);
  CHECK(boundary_keys(r.mesh) == boundary_keys(m));
}

TEST_CASE("pillow: bad shrink sets are rejected") {
  const auto grid = test::structured_hex_grid(2, 1, 1);
  CHECK_THROWS_AS(primal::pillow(grid, std::vector<Index>{}), InvalidInput);
  CHECK_THROWS_AS(primal::pillow(grid, std::vector<Index>{2}), InvalidInput);
  CHECK_THROWS_AS(primal::pillow(grid, std::vector<Index>{0, 0}), InvalidInput);
  primal::PillowOptions o;
  o.shrink = 1.5;
  CHECK_THROWS_AS(primal::pillow(grid, std::vector<Index>{0}, o), InvalidInput);
}
