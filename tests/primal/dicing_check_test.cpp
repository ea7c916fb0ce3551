// check_dicing: a diced model read against the dicing tables. An intact dicing of models made
// as users make them (Gmsh's hex and tet volumes, an extruded wedge layer) passes; a
// deliberately broken one (a child's corners out of order, a crack, a shared centre, a child of
// another parent's node) is caught, naming the child or the node.
#include <doctest/doctest.h>

#include <algorithm>

#include <geode/demo/demo_models.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/split_pyramids.hpp>
#include "support/cli_run.hpp"
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::Index;

namespace {

primal::DicedModel diced(const primal::Model& m) { return primal::dice_model(m); }

bool has(const std::vector<Index>& v, Index x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

}  // namespace

TEST_CASE("an intact dicing is what its tables make") {
  const test::TempDir dir;
  for (const char* name : {"delaunay", "boundary-layer", "hybrid"}) {
    CAPTURE(name);
    primal::Model m = test::demo_input(name, 2, dir);
    if (!m.pyramids.empty()) m = primal::split_pyramids(m).model;
    const primal::DicedModel d = diced(m);
    const primal::DicingCheck c = primal::check_dicing(m, d);
    CHECK(c.ok());
    CHECK(c.summary().find("NOT") == std::string::npos);
  }
}

TEST_CASE("a broken dicing is caught") {
  const primal::Model m = demo::demo_model("delaunay", 2);
  const test::TempDir dir;
  const primal::Model w = test::demo_input("boundary-layer", 2, dir);
  REQUIRE(!w.wedges.empty());
  SUBCASE("a hex child with two corners swapped") {
    primal::DicedModel d = diced(m);
    std::swap(d.hex_children[9][1], d.hex_children[9][3]);
    const auto c = primal::check_dicing(m, d);
    CHECK(!c.ok());
    CHECK(c.wrong_hex_children == std::vector<Index>{9});
  }
  SUBCASE("a crack: a tet child's edge node made twice") {
    primal::DicedModel d = diced(m);
    auto& child = d.tet_children[5];
    const Index edge_node = child[1];  // corner 1 of a tet child: an edge midpoint
    const Index twin = d.add_node(d.points[primal::index_cast<std::size_t>(edge_node)],
                                  d.origin[primal::index_cast<std::size_t>(edge_node)]);
    child[1] = twin;
    const auto c = primal::check_dicing(m, d);
    CHECK(!c.ok());
    CHECK(has(c.duplicated_nodes, edge_node));
    CHECK(has(c.duplicated_nodes, twin));
    CHECK(c.wrong_tet_children.empty());  // the child itself names the right origin
  }
  SUBCASE("two hexes' children on one centre") {
    primal::DicedModel d = diced(m);
    // Child corner 6 of a hex child is its parent's centre; hex 0's children take hex 1's.
    const Index own_centre = d.hex_children[0][6], other_centre = d.hex_children[8][6];
    for (int ch = 0; ch < 8; ++ch)
      for (Index& v : d.hex_children[primal::index_cast<std::size_t>(ch)])
        if (v == own_centre) v = other_centre;
    const auto c = primal::check_dicing(m, d);
    CHECK(!c.ok());
    CHECK(has(c.duplicated_nodes, other_centre));
  }
  SUBCASE("a wedge child on a node of another wedge") {
    primal::DicedModel d = diced(w);
    d.wedge_children[0][1] = d.wedge_children[0][6];  // an edge midpoint -> the wedge's centre
    const auto c = primal::check_dicing(w, d);
    CHECK(!c.ok());
    CHECK(has(c.wrong_wedge_children, 0));
  }
  SUBCASE("children missing") {
    primal::DicedModel d = diced(m);
    d.tet_children.pop_back();
    d.tet_parent.pop_back();
    auto c = primal::check_dicing(m, d);
    CHECK(c.missing_children == 1);
    CHECK(c.wrong_tet_children.size() == 3);  // the parent's other children
    d.tet_children.resize(d.tet_children.size() - 3);
    d.tet_parent.resize(d.tet_parent.size() - 3);
    c = primal::check_dicing(m, d);
    CHECK(c.missing_children == 4);
    CHECK(!c.ok());
  }
}

TEST_CASE("normalized_origin: node numbers ascending, then kInvalidIndex") {
  // Every key of four entries from a small alphabet (repeats and kInvalidIndex anywhere)
  // against a sort that puts kInvalidIndex last.
  const std::array<primal::Index, 5> values{primal::kInvalidIndex, 0, 1, 2, 2147483647};
  for (std::size_t code = 0; code < 625; ++code) {
    primal::FaceKey key{};
    for (std::size_t i = 0, c = code; i < 4; ++i, c /= 5) key[i] = values[c % 5];
    primal::FaceKey expected = key;
    std::sort(expected.begin(), expected.end(), [](primal::Index a, primal::Index b) {
      if (a == primal::kInvalidIndex) return false;
      return b == primal::kInvalidIndex || a < b;
    });
    CAPTURE(code);
    CHECK(primal::normalized_origin(key) == expected);
  }
}
