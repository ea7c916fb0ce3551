// Node sets given as nodes only (primal/node_set_pieces.hpp): a set on the boundary that turns
// a corner keeps to the boundary when diced; a set with a node inside, or with pieces of its
// own, is left to the rule without pieces.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <vector>

#include <geode/primal/dice_model.hpp>
#include <geode/primal/node_set_pieces.hpp>

namespace {

using namespace geode::primal;

// The unit cube as Kuhn's six tets around the diagonal 0-6 (corners as a hex's), and its
// centre as a ninth node on none of them.
Model kuhn_cube() {
  Model m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},      {0, 0, 1},
              {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, 0.5, 0.5}};
  m.tets = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  for (auto& t : m.tets) {  // positively oriented
    const Point a = m.points[t[0]], b = m.points[t[1]], c = m.points[t[2]], d = m.points[t[3]];
    if ((b - a).cross(c - a).dot(d - a) < 0) std::swap(t[1], t[2]);
  }
  m.tet_block.assign(m.tets.size(), 1);
  return m;
}

// The set's diced nodes: (on the cube's boundary, inside).
std::pair<int, int> diced_set(const Model& m) {
  const DicedModel diced = dice_model(m);
  std::vector<Index> identity(diced.points.size());
  for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = index_cast(i);
  const auto sets = diced_node_sets(m, diced, identity);
  int boundary = 0, inside = 0;
  for (Index v : sets.at(0).nodes) {
    const Point& p = diced.points[index_cast<std::size_t>(v)];
    const bool on = std::any_of(p.data(), p.data() + 3, [](double x) { return x == 0 || x == 1; });
    (on ? boundary : inside) += 1;
  }
  return {boundary, inside};
}

}  // namespace

TEST_CASE("node set pieces: a boundary set given as nodes keeps to the boundary when diced") {
  // The skin (all 8 corners): the 12 boundary triangles become its pieces. Without them the
  // interior faces (every node on the skin) and the diagonal 0-6 gave their centres to the set.
  Model m = kuhn_cube();
  m.node_sets = {{1, "skin", {0, 1, 2, 3, 4, 5, 6, 7}}};
  const auto [boundary_before, inside_before] = diced_set(m);
  CHECK(inside_before > 0);
  infer_boundary_node_set_pieces(m);
  CHECK(m.node_sets[0].pieces.size() == 12);
  const auto [boundary, inside] = diced_set(m);
  CHECK(inside == 0);
  // On the skin: 8 corners, 18 boundary edges' midpoints, 12 triangles' centres.
  CHECK(boundary == 8 + 18 + 12);
  CHECK(boundary == boundary_before);

  // Two faces meeting at an edge (x = 0 and y = 0): their 4 triangles, and nothing inside.
  Model two = kuhn_cube();
  std::vector<Index> on_two;
  for (std::size_t v = 0; v < 8; ++v)
    if (two.points[v].x() == 0 || two.points[v].y() == 0) on_two.push_back(index_cast(v));
  two.node_sets = {{2, "x0 y0", on_two}};
  infer_boundary_node_set_pieces(two);
  CHECK(two.node_sets[0].pieces.size() == 4);
  CHECK(diced_set(two).second == 0);
}

TEST_CASE("node set pieces: sets with a node inside or with pieces are left as they are") {
  Model m = kuhn_cube();
  m.tets = {{0, 1, 3, 4}};  // one tet, so that node 8 is a node of none: not on the boundary
  m.tet_block = {1};
  m.node_sets = {{1, "with an interior node", {0, 1, 8}},
                 {2, "with pieces", {0, 1, 3}, {{0, 1}, {3}}}};
  const auto before = m.node_sets;
  infer_boundary_node_set_pieces(m);
  CHECK(m.node_sets[0].pieces == before[0].pieces);
  CHECK(m.node_sets[1].pieces == before[1].pieces);
}
