// Interface detection between the hex and tet parts of a model. Known answers are counted by
// hand on small grids built by grid_model (Kuhn tets: every cell face is split along the
// diagonal from its lowest to its highest corner).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/topology.hpp>
#include "support/fixtures.hpp"

using namespace geode;
using namespace geode::primal;

namespace {

// Appends b's points and elements to a (no sets), shifting b by `offset`.
void append(Model& a, const Model& b, const Point& offset) {
  const auto base = index_cast(a.points.size());
  for (const Point& p : b.points) a.points.push_back(p + offset);
  for (auto h : b.hexes) {
    for (Index& v : h) v += base;
    a.hexes.push_back(h);
    a.hex_block.push_back(1);
  }
  for (auto t : b.tets) {
    for (Index& v : t) v += base;
    a.tets.push_back(t);
    a.tet_block.push_back(2);
  }
}

// Every interface quad's triangles are the named faces of the named tets, its hex face is the
// named face of the named hex, and its diagonal is the lowest-to-highest corner pair (the Kuhn
// split), which is corners 0-2 or 1-3 by position.
void check_consistent(const Model& m, const Interface& itf) {
  for (const InterfaceQuad& q : itf.quads) {
    for (std::size_t i = 0; i < 4; ++i)
      CHECK(q.corners[i] == m.hexes[index_cast<std::size_t>(q.hex)][index_cast<std::size_t>(
                                topology::kHexFaceCorners[index_cast<std::size_t>(q.face)][i])]);
    const auto tris = interface_triangles(q);
    for (std::size_t i = 0; i < 2; ++i) {
      std::set<Index> face;
      for (int c : topology::kTetFaceCorners[index_cast<std::size_t>(q.tet_faces[i])])
        face.insert(m.tets[index_cast<std::size_t>(q.tets[i])][index_cast<std::size_t>(c)]);
      CHECK(face == std::set<Index>(tris[i].begin(), tris[i].end()));
    }
    // Kuhn diagonal: from the corner with the smallest coordinate sum to the largest.
    auto sum = [&](Index v) { return m.points[index_cast<std::size_t>(v)].sum(); };
    const auto lo = std::min_element(q.corners.begin(), q.corners.end(),
                                     [&](Index a, Index b) { return sum(a) < sum(b); });
    const auto lo_pos = lo - q.corners.begin();
    CHECK(q.diagonal == lo_pos % 2);
  }
}

}  // namespace

TEST_CASE("find_interface: known counts on small grids") {
  struct Row {
    const char* name;
    std::array<int, 3> cells;
    std::function<bool(int, int, int)> is_tet;
    std::size_t quads, nodes;
  };
  const Row rows[] = {
      // One hex with a cube of 6 tets on its top face: 1 quad, its 4 corners.
      {"one hex, tets on top", {1, 1, 2}, [](int, int, int k) { return k == 1; }, 1, 4},
      // Half/half block 2x2x2: the x = 1 plane, 2x2 quads, 3x3 nodes.
      {"half block", {2, 2, 2}, [](int i, int, int) { return i == 1; }, 4, 9},
      // L-shaped hex part around one tet cell in a 2x2x1 block: two perpendicular quads
      // sharing the concave edge: 6 nodes.
      {"L-shaped", {2, 2, 1}, [](int i, int j, int) { return i == 1 && j == 1; }, 2, 6},
      // Tet cell wrapped around a hex corner: 3 tet cells of a 2x2x1 block -> the hex cell's
      // two inner faces, convex seen from the tets: 2 quads, 6 nodes.
      {"convex edge", {2, 2, 1}, [](int i, int j, int) { return i == 1 || j == 1; }, 2, 6},
      // A tet nugget in the middle of a 3x3x3 block: the 6 faces of the cavity, 8 corners.
      {"enclosed nugget",
       {3, 3, 3},
       [](int i, int j, int k) { return i == 1 && j == 1 && k == 1; },
       6,
       8},
  };
  for (const Row& row : rows) {
    CAPTURE(row.name);
    const Model m = grid_model(row.cells, 1.0, row.is_tet);
    const Interface itf = find_interface(m);
    CHECK(itf.quads.size() == row.quads);
    CHECK(itf.nodes.size() == row.nodes);
    check_consistent(m, itf);
  }
}

TEST_CASE("find_interface: one hex under tets, the face and diagonal by hand") {
  const Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
  const Interface itf = find_interface(m);
  REQUIRE(itf.quads.size() == 1);
  const InterfaceQuad& q = itf.quads[0];
  CHECK(q.hex == 0);
  CHECK(q.face == 5);  // top face (t-max), corners 4 5 6 7 = nodes 4 5 7 6 of the grid
  CHECK(q.corners == std::array<Index, 4>{4, 5, 7, 6});
  // Kuhn split of the tet cell joins (0,0,1) = node 4 and (1,1,1) = node 7: corners 0 and 2.
  CHECK(q.diagonal == 0);
  CHECK(itf.nodes == std::vector<Index>{4, 5, 6, 7});
}

TEST_CASE("find_interface: a quad split into four triangles around a tet node") {
  // One hex; its top face 4 5 7 6 (counter-clockwise seen from above) in four triangles
  // around node 8, each under a tet with apex 9; the centre is off the quad's middle.
  Model m = test::four_tet_fan({0.4, 0.55, 1.0}, {0.5, 0.5, 2.0});
  const std::array<Index, 4> top{4, 5, 7, 6};
  const Interface itf = find_interface(m);
  REQUIRE(itf.quads.size() == 1);
  const InterfaceQuad& q = itf.quads[0];
  CHECK(q.centre == 8);
  CHECK(q.triangle_count() == 4);
  CHECK(q.corners == top);
  // The centre is a tet node, not an interface node (it has no hex-side twin).
  CHECK(itf.nodes == std::vector<Index>{4, 5, 6, 7});
  const auto tris = interface_triangles(q);
  REQUIRE(tris.size() == 4);
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(tris[i] == std::array<Index, 3>{top[i], top[(i + 1) % 4], 8});
    std::set<Index> face;
    for (int c : topology::kTetFaceCorners[index_cast<std::size_t>(q.tet_faces[i])])
      face.insert(m.tets[index_cast<std::size_t>(q.tets[i])][index_cast<std::size_t>(c)]);
    CHECK(face == std::set<Index>(tris[i].begin(), tris[i].end()));
  }
  SUBCASE("three of the four triangles: refused as a hanging node") {
    m.tets.pop_back();
    m.tet_block.pop_back();
    CHECK_THROWS_WITH_AS(find_interface(m), doctest::Contains("lies on hex 1"), TopologyError);
  }
}

TEST_CASE("find_interface: rejects non-conforming interfaces, naming the face or node") {
  SUBCASE("a quad matched by one triangle only") {
    Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
    const Interface itf = find_interface(m);
    const Index gone = itf.quads[0].tets[1];
    m.tets.erase(m.tets.begin() + gone);
    m.tet_block.erase(m.tet_block.begin() + gone);
    CHECK_THROWS_WITH_AS(
        find_interface(m),
        doctest::Contains(
            "hex 1 (centre (0.5, 0.5, 0.5)) face (nodes 5 6 8 7) is matched by only one triangle"),
        TopologyError);
  }
  SUBCASE("a hanging tet node in the middle of a hex face edge") {
    Model m = grid_model({1, 1, 1}, 1.0, [](int, int, int) { return false; });
    m.points.emplace_back(0.5, 0.0, 1.0);  // node 8: midpoint of top edge 4-5
    m.points.emplace_back(0.5, 0.5, 2.0);  // node 9: apex
    // The top face (4 5 7 6 counter-clockwise seen from above) in three triangles.
    for (const std::array<Index, 3>& tri : {std::array<Index, 3>{4, 8, 6}, {8, 5, 7}, {8, 7, 6}}) {
      m.tets.push_back({tri[0], tri[1], tri[2], 9});
      m.tet_block.push_back(2);
    }
    for (const auto& t : m.tets)
      REQUIRE(tet_volume(m.points[index_cast<std::size_t>(t[0])],
                         m.points[index_cast<std::size_t>(t[1])],
                         m.points[index_cast<std::size_t>(t[2])],
                         m.points[index_cast<std::size_t>(t[3])]) > 0);
    CHECK_THROWS_WITH_AS(find_interface(m),
                         doctest::Contains("node 9 (0.5, 0, 1) of the tet part (tet 1 (centre "
                                           "(0.25, 0.375, 1.25))) lies on hex 1"),
                         TopologyError);
  }
  SUBCASE("a four-triangle centre that is a hex node too") {
    Model m = test::four_tet_fan({0.5, 0.5, 1.0}, {0.5, 0.5, 2.0});
    // A hex below the first one using node 8 as a corner (nonsense geometry, topology only).
    const auto base = index_cast(m.points.size());
    for (int k = 0; k < 7; ++k) m.points.emplace_back(0.1 * k, -1.0, -1.0 - 0.1 * k);
    m.hexes.push_back({base, base + 1, base + 2, base + 3, base + 4, base + 5, base + 6, 8});
    m.hex_block.push_back(1);
    CHECK_THROWS_WITH_AS(find_interface(m), doctest::Contains("a node of the hex part too"),
                         TopologyError);
  }
  SUBCASE("a finer hex side under one coarse tet cell") {
    Model m = grid_model({2, 2, 1}, 0.5, [](int, int, int) { return false; });
    append(m, grid_model({1, 1, 1}, 1.0, [](int, int, int) { return true; }), Point(0, 0, 0.5));
    CHECK(merge_coincident_nodes(m, 1e-9) == 4);
    // Hex-side node (0.5, 0, 0.5) = grid node 1 lies on the edge of a coarse triangle.
    CHECK_THROWS_WITH_AS(find_interface(m), doctest::Contains("of the hex part"), TopologyError);
  }
  SUBCASE("a triangle shared by three tets, named with the three") {
    Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
    // A third tet on the face the first two share.
    std::vector<Index> shared;
    for (Index v : m.tets[0])
      if (std::find(m.tets[1].begin(), m.tets[1].end(), v) != m.tets[1].end()) shared.push_back(v);
    REQUIRE(shared.size() == 3);
    m.points.emplace_back(0.5, 0.5, 5.0);
    m.tets.push_back({shared[0], shared[1], shared[2], index_cast(m.points.size() - 1)});
    m.tet_block.push_back(2);
    CHECK_THROWS_WITH_AS(find_interface(m),
                         doctest::Contains("is a face of more than two tets (tet 1 (centre"),
                         TopologyError);
    CHECK_THROWS_WITH_AS(
        find_interface(m),
        doctest::Contains(("tet " + std::to_string(m.tets.size()) + " (centre").c_str()),
        TopologyError);
  }
  SUBCASE("away from the hex part, a triangle of three tets is check_input's") {
    // The search pairs only tet faces with a hex-part node (conform's input passed check_input,
    // which refuses this one).
    Model m = grid_model({1, 1, 3}, 1.0, [](int, int, int k) { return k >= 1; });
    std::vector<Index> shared;  // a face two tets of the top layer share, off the hex nodes
    for (std::size_t a = 0; a < m.tets.size() && shared.empty(); ++a)
      for (std::size_t b = a + 1; b < m.tets.size() && shared.empty(); ++b) {
        std::vector<Index> common;
        for (Index v : m.tets[a])
          if (std::find(m.tets[b].begin(), m.tets[b].end(), v) != m.tets[b].end())
            common.push_back(v);
        if (common.size() == 3 && std::all_of(common.begin(), common.end(), [&](Index v) {
              return m.points[index_cast<std::size_t>(v)].z() > 1.5;
            }))
          shared = common;
      }
    REQUIRE(shared.size() == 3);
    m.points.emplace_back(0.5, 0.5, 9.0);
    m.tets.push_back({shared[0], shared[1], shared[2], index_cast(m.points.size() - 1)});
    m.tet_block.push_back(2);
    CHECK(find_interface(m).quads.size() == 1);
    const InputCheckResult r = check_input(m);
    REQUIRE(!r.ok());
    CHECK(r.findings[0].fault == InputFault::kOversharedFace);
  }
  SUBCASE("a tet given twice, named with its first copy") {
    Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
    m.tets.push_back(m.tets[2]);
    m.tet_block.push_back(2);
    CHECK_THROWS_WITH_AS(
        find_interface(m),
        doctest::Contains(("tet " + std::to_string(m.tets.size()) + " (centre").c_str()),
        TopologyError);
    CHECK_THROWS_WITH_AS(find_interface(m), doctest::Contains("has the same nodes as tet 3"),
                         TopologyError);
  }
  SUBCASE("parts touching along an edge only") {
    // No interface quad: nothing to start a buffer layer from, and dicing conforms along the
    // edge (conform dices each part; the read-time check refuses this boundary, non-manifold).
    Model m = grid_model({1, 1, 1}, 1.0, [](int, int, int) { return false; });
    append(m, grid_model({1, 1, 1}, 1.0, [](int, int, int) { return true; }), Point(1, 1, 0));
    CHECK(merge_coincident_nodes(m, 1e-9) == 2);
    CHECK(find_interface(m).quads.empty());
    // Beside an interface quad (a tet cube on the hex's +x face), the edge's nodes are named.
    Model n = grid_model({2, 1, 1}, 1.0, [](int i, int, int) { return i == 1; });
    append(n, grid_model({1, 1, 1}, 1.0, [](int, int, int) { return true; }), Point(-1, 1, 0));
    CHECK(merge_coincident_nodes(n, 1e-9) == 2);
    CHECK_THROWS_WITH_AS(find_interface(n), doctest::Contains("lies on no interface quad"),
                         TopologyError);
  }
}

TEST_CASE(
    "merge_coincident_nodes: a zero tolerance merges exact copies only; bad ones are refused") {
  Model m = grid_model({1, 1, 1}, 1.0, [](int, int, int) { return false; });
  append(m, grid_model({1, 1, 1}, 1.0, [](int, int, int) { return false; }), Point(1, 0, 0));
  m.points.push_back(Point(1e6, 1e6, 1e-300));  // far away and tiny: no overflow in the grid
  CHECK(merge_coincident_nodes(m, 0.0) == 4);   // the shared face's four nodes
  CHECK_THROWS_WITH_AS(merge_coincident_nodes(m, -1.0), doctest::Contains("tolerance"),
                       InvalidInput);
  CHECK_THROWS_AS(merge_coincident_nodes(m, std::nan("")), InvalidInput);
}

TEST_CASE(
    "find_interface: wedge quads meeting tet triangles, and the side of each cell at a node") {
  // A hex cell beside a tet cell, the hex cell split into two wedges standing on its bottom
  // face's triangles: one wedge quad (x = 1) meets the tets' two triangles.
  Model m = grid_model({2, 1, 1}, 1.0, [](int i, int, int) { return i == 1; });
  const auto h = m.hexes.front();
  m.hexes.clear();
  m.hex_block.clear();
  m.wedges.push_back({h[0], h[1], h[2], h[4], h[5], h[6]});
  m.wedges.push_back({h[0], h[2], h[3], h[4], h[6], h[7]});
  const Interface itf = find_interface(m);
  REQUIRE(itf.quads.size() == 1);
  const InterfaceQuad& q = itf.quads.front();
  CHECK(q.owner() == ElementRef{ElementKind::kWedge, 0});
  CHECK(q.corners == std::array<Index, 4>{h[1], h[2], h[6], h[5]});
  CHECK(itf.nodes.size() == 4);
  // Around the quad's nodes: the first wedge (the quad's owner) on the hex side, every tet
  // there on the tet side (the tets of a cell share faces), the second wedge at the nodes it
  // has (h[2], h[6]) joined to the first through their diagonal quad: the hex side.
  std::size_t tets = 0;
  for (const InterfaceNodeUse& u : itf.uses) {
    CAPTURE(u.node);
    CHECK(std::binary_search(itf.nodes.begin(), itf.nodes.end(), u.node));
    if (u.cell.kind == ElementKind::kTet) {
      CHECK(u.side == InterfaceSide::kTet);
      ++tets;
    } else {
      CHECK(u.side == InterfaceSide::kHex);
    }
  }
  CHECK(tets > 0);
  CHECK(std::count_if(itf.uses.begin(), itf.uses.end(), [](const InterfaceNodeUse& u) {
          return u.cell == ElementRef{ElementKind::kWedge, 1};
        }) == 2);

  // A wedge on the tets' top face at the interface's top edge (beside a hex cell, not above
  // it): joined to the tets by its bottom triangle, it is on the tet side at those nodes.
  Model w = grid_model({2, 1, 1}, 1.0, [](int i, int, int) { return i == 1; });
  std::array<Index, 3> tri{-1, -1, -1};
  for (const auto& t : w.tets)
    for (const auto& f : topology::kTetFaceCorners) {
      const std::array<Index, 3> c{t[index_cast<std::size_t>(f[0])],
                                   t[index_cast<std::size_t>(f[1])],
                                   t[index_cast<std::size_t>(f[2])]};
      int at_edge = 0;
      bool top = true;
      for (Index v : c) {
        top = top && w.points[index_cast<std::size_t>(v)].z() > 1.0 - 1e-12;
        at_edge += w.points[index_cast<std::size_t>(v)].x() < 1.0 + 1e-12;
      }
      if (top && at_edge == 2) tri = c;
    }
  REQUIRE(tri[0] >= 0);
  std::array<Index, 6> wedge{tri[0], tri[1], tri[2], 0, 0, 0};
  for (std::size_t k = 0; k < 3; ++k) {
    wedge[3 + k] = index_cast(w.points.size());
    w.points.push_back(w.points[index_cast<std::size_t>(tri[k])] + Point(0, 0, 0.5));
  }
  w.wedges.push_back(wedge);
  const Interface wi = find_interface(w);
  std::size_t wedge_uses = 0;
  for (const InterfaceNodeUse& u : wi.uses)
    if (u.cell.kind == ElementKind::kWedge) {
      CHECK(u.side == InterfaceSide::kTet);
      ++wedge_uses;
    }
  CHECK(wedge_uses == 2);  // the edge's two nodes
}
