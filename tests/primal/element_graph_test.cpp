// element_graph against its definition, METIS's dual graph with ncommon = 3 (two elements joined
// when they share 3 nodes or more), found by comparing every pair of elements: on a grid of hexes
// beside tets (quads meeting two triangles) and on Gmsh's hexdominant model (pyramids, wedges).
#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include <geode/primal/element_graph.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/submodel.hpp>
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::Index;

namespace {

void check_against_pairs(const primal::Model& m) {
  std::vector<std::vector<Index>> corners;
  for (primal::ElementKind kind : primal::kElementKinds)
    for (std::size_t e = 0; e < primal::element_count(m, kind); ++e) {
      const auto c = primal::element_corners(m, {kind, primal::index_cast(e)});
      corners.emplace_back(c.begin(), c.end());
      std::sort(corners.back().begin(), corners.back().end());
    }
  const primal::ElementGraph g = primal::element_graph(m);
  REQUIRE(g.offset.size() == corners.size() + 1);
  std::size_t edges = 0;
  for (std::size_t a = 0; a < corners.size(); ++a) {
    std::vector<Index> expected;
    for (std::size_t b = 0; b < corners.size(); ++b) {
      std::vector<Index> common;
      std::set_intersection(corners[a].begin(), corners[a].end(), corners[b].begin(),
                            corners[b].end(), std::back_inserter(common));
      if (a != b && common.size() >= 3) expected.push_back(primal::index_cast(b));
    }
    std::vector<Index> got(
        g.neighbour.begin() + primal::index_cast<std::ptrdiff_t>(g.offset[a]),
        g.neighbour.begin() + primal::index_cast<std::ptrdiff_t>(g.offset[a + 1]));
    std::sort(got.begin(), got.end());
    CAPTURE(a);
    CHECK(got == expected);
    edges += expected.size();
  }
  CHECK(edges > 0);
}

}  // namespace

TEST_CASE("element_graph joins the elements sharing a face, a quad its two triangles") {
  // Tets in a checkerboard of cells: every hex face inside meets a hex or two tet triangles.
  check_against_pairs(
      primal::grid_model({3, 3, 2}, 1.0, [](int i, int j, int k) { return (i + j + k) % 2 == 1; }));
}

TEST_CASE("element_graph on pyramids and wedges (Gmsh's hexdominant model)") {
  const test::TempDir dir;
  const primal::Model m = test::demo_input("hexdominant", 2, dir);
  REQUIRE(!m.pyramids.empty());
  REQUIRE(!m.wedges.empty());
  check_against_pairs(m);
}
