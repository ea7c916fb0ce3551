// Realizability obstructions on meshes built so that the answer is known: clean grids and the
// Appendix A geode have none; a doublet column, a face cut open at a tet split's centre, a
// hex with two faces on one plane, each made on purpose, are found exactly where they were put.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/validity.hpp>
#include "support/fixtures.hpp"

using namespace geode::primal;
using geode::test::structured_hex_grid;
using geode::test::structured_quad_grid;

namespace {

using Kind = ObstructionKind;

std::vector<Obstruction> of_kind(const std::vector<Obstruction>& all, Kind k) {
  std::vector<Obstruction> out;
  std::copy_if(all.begin(), all.end(), std::back_inserter(out),
               [k](const Obstruction& o) { return o.kind == k; });
  return out;
}

// Node (i,j,k) of structured_hex_grid(nx, ny, nz).
Index grid_node(int nx, int ny, int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); }

// A 3 x 3 x 3 grid whose central column of hexes is split, layer by layer, into two hexes
// through a new vertical edge on the column's axis: each new edge is in only two hexes.
struct DoubletColumn {
  HexMesh mesh;
  std::array<Index, 4> axis{};                  // the new nodes, bottom to top
  std::array<std::array<Index, 2>, 3> pairs{};  // the two hexes of each layer
};

DoubletColumn doublet_column() {
  DoubletColumn d;
  d.mesh = structured_hex_grid(3, 3, 3);
  for (int k = 0; k <= 3; ++k) {
    d.axis[k] = index_cast(d.mesh.points.size());
    d.mesh.points.emplace_back(1.6, 1.4, k);  // off the diagonal: the split is not symmetric
  }
  for (int k = 0; k < 3; ++k) {
    const Index h = 1 + 3 * (1 + 3 * k);  // hex (1, 1, k)
    const auto c = d.mesh.hexes[h];
    REQUIRE(c[0] == grid_node(3, 3, 1, 1, k));
    const Index e = d.axis[k], f = d.axis[k + 1];
    d.mesh.hexes[h] = {c[0], c[1], c[2], e, c[4], c[5], c[6], f};
    d.mesh.hexes.push_back({c[0], e, c[2], c[3], c[4], f, c[6], c[7]});
    d.pairs[k] = {h, index_cast(d.mesh.hexes.size() - 1)};
  }
  return d;
}

// A tetrahedron split into four hexes (one per vertex: the vertex, three edge midpoints, three
// face centres, the centroid), positively oriented.
struct TetSplit {
  HexMesh mesh;
  Index centroid = 0;
  std::array<Index, 4> vertex_hex{};
  std::array<std::array<Index, 4>, 4> mid{};  // mid[i][j]: midpoint of edge ij
  std::array<Index, 4> face{};                // face[l]: centre of the face opposite vertex l
};

TetSplit tet_split() {
  TetSplit t;
  const std::array<Point, 4> v{Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0), Point(0, 0, 1)};
  auto add = [&](const Point& p) {
    t.mesh.points.push_back(p);
    return index_cast(t.mesh.points.size() - 1);
  };
  std::array<Index, 4> corner{};
  for (int i = 0; i < 4; ++i) corner[i] = add(v[i]);
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) t.mid[i][j] = t.mid[j][i] = add(0.5 * (v[i] + v[j]));
  for (int l = 0; l < 4; ++l) {
    Point c = Point::Zero();
    for (int i = 0; i < 4; ++i)
      if (i != l) c += v[i] / 3.0;
    t.face[l] = add(c);
  }
  t.centroid = add(0.25 * (v[0] + v[1] + v[2] + v[3]));
  for (int i = 0; i < 4; ++i) {
    std::array<int, 3> o{};
    for (int k = 0, n = 0; k < 4; ++k)
      if (k != i) o[n++] = k;
    const Point a = v[o[0]] - v[i], b = v[o[1]] - v[i], c = v[o[2]] - v[i];
    if (a.cross(b).dot(c) < 0) std::swap(o[0], o[1]);
    const int j = o[0], k = o[1], l = o[2];
    // Corners 1, 3, 4 along ij, ik, il; 2, 5, 7 the face centres between them; 6 the centroid.
    t.mesh.hexes.push_back({corner[i], t.mid[i][j], t.face[l], t.mid[i][k], t.mid[i][l], t.face[k],
                            t.centroid, t.face[j]});
    t.vertex_hex[i] = index_cast(t.mesh.hexes.size() - 1);
  }
  return t;
}

}  // namespace

TEST_CASE("realizability: kind names") {
  CHECK(to_string(Kind::kDoublet) == "doublet");
  CHECK(to_string(Kind::kPinchedCorner) == "pinched-corner");
  CHECK(to_string(Kind::kTwoFacesOnBoundaryFace) == "two-faces-on-boundary-face");
  CHECK(to_string(Kind::kFlatCorner) == "flat-corner");
  CHECK(to_string(Kind::kTwoQuadBoundaryNode) == "two-quad-boundary-node");
}

TEST_CASE("realizability: clean grids, a tet split and the Appendix A geode have none") {
  CHECK(find_obstructions(structured_hex_grid(3, 2, 2)).empty());
  CHECK(find_obstructions(structured_hex_grid(1, 1, 1)).empty());
  CHECK(find_obstructions(structured_quad_grid(4, 3)).empty());
  CHECK(find_obstructions(structured_quad_grid(1, 1)).empty());
  const TetSplit t = tet_split();
  REQUIRE(check_validity(t.mesh).ok());
  CHECK(find_obstructions(t.mesh).empty());
  const HexMesh a = geode::test::appendix_a_geode();
  CHECK(find_obstructions(a).empty());
}

TEST_CASE(
    "realizability: a doublet column gives one doublet per layer and two-quad nodes at its ends") {
  const DoubletColumn d = doublet_column();
  const auto v = check_validity(d.mesh);
  CHECK(v.boundary.closed);
  CHECK(v.nonmanifold_edges.empty());
  CHECK(v.nonmanifold_vertices.empty());
  CHECK(v.euler == 1);
  const auto all = find_obstructions(d.mesh);
  const auto doublets = of_kind(all, Kind::kDoublet);
  REQUIRE(doublets.size() == 3);
  for (int k = 0; k < 3; ++k) {
    CHECK(doublets[k].hexes == std::vector<Index>{d.pairs[k][0], d.pairs[k][1]});
    CHECK(doublets[k].nodes == std::vector<Index>{d.axis[k], d.axis[k + 1]});
  }
  const auto nodes = of_kind(all, Kind::kTwoQuadBoundaryNode);
  REQUIRE(nodes.size() == 2);
  CHECK(nodes[0].nodes == std::vector<Index>{d.axis[0]});
  CHECK(nodes[0].hexes == std::vector<Index>{d.pairs[0][0], d.pairs[0][1]});
  CHECK(nodes[1].nodes == std::vector<Index>{d.axis[3]});
  // The pinched corners at the doublet edges' ends are the doublets themselves: not repeated.
  CHECK(all.size() == 5);
}

TEST_CASE("realizability: progress from 0 to the whole search, the findings the same") {
  std::vector<std::size_t> told;
  RealizabilityOptions o;
  o.progress = [&told](std::size_t done, std::size_t total) {
    CHECK(total == 100);
    told.push_back(done);
  };
  const HexMesh m = doublet_column().mesh;
  const auto found = find_obstructions(m, o);
  CHECK(found.size() == find_obstructions(m).size());
  CHECK(!found.empty());
  REQUIRE(told.size() >= 3);
  CHECK(told.front() == 0);
  CHECK(told.back() == 100);
  CHECK(std::is_sorted(told.begin(), told.end()));
}

TEST_CASE("realizability: a face cut open at a tet split's centre pinches the centre") {
  // The face between the hexes at vertices 0 and 1 loses its contact: hex 1 gets its own copy
  // of the edge midpoint 01, at the same place. Both copies of the face are tangent to the same
  // plane at the centroid: the mesh still has positive Jacobians, but its boundary overlaps
  // itself there, so no embedding exists.
  TetSplit t = tet_split();
  const Index m = t.mid[0][1];
  const Index copy = index_cast(t.mesh.points.size());
  t.mesh.points.push_back(t.mesh.points[m]);
  auto& h1 = t.mesh.hexes[t.vertex_hex[1]];
  std::replace(h1.begin(), h1.end(), m, copy);
  const auto v = check_validity(t.mesh);
  CHECK(v.boundary.closed);
  CHECK(v.inverted_hexes.empty());
  const auto all = find_obstructions(t.mesh);
  REQUIRE(all.size() == 1);
  CHECK(all[0].kind == Kind::kPinchedCorner);
  CHECK(all[0].hexes == std::vector<Index>{t.vertex_hex[0], t.vertex_hex[1]});
  // The centroid, then the centres of the two faces containing edge 01 (opposite 2 and 3).
  CHECK(all[0].nodes == std::vector<Index>{t.centroid, std::min(t.face[2], t.face[3]),
                                           std::max(t.face[2], t.face[3])});
}

TEST_CASE("realizability: a hex with two faces on one plane, and a flat corner") {
  // In the (x, y) plane: quad A sits on the bottom side y = 0 with two edges (p0 p1, p1 p2),
  // B and C fill the square [0, 2]^2 above it; extruded one layer along z.
  QuadMesh q;
  q.points = {Point(0, 0, 0), Point(1, 0, 0), Point(2, 0, 0), Point(1, 1, 0),
              Point(0, 2, 0), Point(1, 2, 0), Point(2, 2, 0)};
  q.quads = {{0, 1, 2, 3}, {2, 6, 5, 3}, {0, 3, 5, 4}};
  REQUIRE(check_validity(q).inverted_quads == std::vector<Index>{0});
  const auto q_all = find_obstructions(q);
  REQUIRE(q_all.size() == 1);
  CHECK(q_all[0].kind == Kind::kTwoFacesOnBoundaryFace);
  CHECK(q_all[0].hexes == std::vector<Index>{0});
  CHECK(q_all[0].nodes == std::vector<Index>{0, 1, 2});

  HexMesh h;
  const auto n = index_cast(q.points.size());
  for (int layer = 0; layer < 2; ++layer)
    for (const auto& p : q.points) h.points.push_back(p + Point(0, 0, layer));
  for (const auto& c : q.quads)
    h.hexes.push_back({c[0], c[1], c[2], c[3], c[0] + n, c[1] + n, c[2] + n, c[3] + n});
  const auto h_all = find_obstructions(h);
  REQUIRE(h_all.size() == 1);
  CHECK(h_all[0].kind == Kind::kTwoFacesOnBoundaryFace);
  CHECK(h_all[0].hexes == std::vector<Index>{0});
  CHECK(h_all[0].nodes == std::vector<Index>{0, 1, 2, n, n + 1, n + 2});

  // A single hex whose corner 0 and its three neighbours (1, 3, 4) are declared on face 0:
  // the three edge vectors at corner 0 would lie in one plane.
  HexMesh cube = structured_hex_grid(1, 1, 1);
  RealizabilityOptions o;
  o.node_faces.assign(8, 0u);
  for (int c : {0, 1, 3, 4}) o.node_faces[index_cast<std::size_t>(cube.hexes[0][c])] = 1u;
  const auto c_all = find_obstructions(cube, o);
  REQUIRE(c_all.size() == 1);
  CHECK(c_all[0].kind == Kind::kFlatCorner);
  CHECK(c_all[0].nodes ==
        std::vector<Index>{cube.hexes[0][0], cube.hexes[0][1], cube.hexes[0][3], cube.hexes[0][4]});
  o.node_faces.pop_back();
  CHECK_THROWS_AS(find_obstructions(cube, o), geode::InvalidInput);
}

TEST_CASE("realizability: a quad doublet inside a grid") {
  // The centre quad of a 3 x 3 grid is split through a new node into two quads sharing both
  // edges at it.
  QuadMesh q = structured_quad_grid(3, 3);
  const Index e = index_cast(q.points.size());
  q.points.emplace_back(1.6, 1.4, 0.0);
  const auto c = q.quads[4];
  q.quads[4] = {c[0], c[1], c[2], e};
  q.quads.push_back({c[0], e, c[2], c[3]});
  const auto v = check_validity(q);
  CHECK(v.euler == 1);
  CHECK(v.nonmanifold_vertices.empty());
  const auto all = find_obstructions(q);
  REQUIRE(all.size() == 1);
  CHECK(all[0].kind == Kind::kDoublet);
  CHECK(all[0].hexes == std::vector<Index>{4, 9});
  CHECK(all[0].nodes == std::vector<Index>{e, std::min(c[0], c[2]), std::max(c[0], c[2])});
}

TEST_CASE("realizability: out-of-range nodes are named") {
  HexMesh m = structured_hex_grid(1, 1, 1);
  m.hexes[0][5] = 99;
  CHECK_THROWS_WITH_AS(find_obstructions(m), "hex 0: node 99 out of range [0, 8)",
                       geode::InvalidInput);
}
