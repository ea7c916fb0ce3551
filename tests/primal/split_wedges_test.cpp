// Wedges as three tets (primal/split_wedges.hpp): the six ways of splitting one, the two diagonal
// choices no three tets follow, side sets moved onto the tets, two wedges sharing a quad split
// alike, and the realistic case it is for: Gmsh's layer of hexes beside wedges on tets
// (demo layer-mixed), which find_interface refuses whole and lists with `joining`.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>

#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/split_wedges.hpp>
#include "support/demo_input.hpp"
#include "support/model_checks.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::ElementKind;
using primal::Index;
using primal::Point;

namespace {

// Two wedges sharing the quad (1, 2, 5, 4): a right prism over the unit triangle and its mirror
// image across the square's diagonal, one unit high, skewed so that no tet is degenerate by
// symmetry.
primal::Model two_wedges() {
  primal::Model m;
  m.points = {{0, 0, 0},   {1, 0, 0},   {0, 1, 0}, {0.1, 0, 1},
              {1.1, 0, 1}, {0.1, 1, 1}, {1, 1, 0}, {1.1, 1, 1}};
  primal::add_element(m, ElementKind::kWedge, std::array<Index, 6>{0, 1, 2, 3, 4, 5}, 4, 11);
  primal::add_element(m, ElementKind::kWedge, std::array<Index, 6>{1, 6, 2, 4, 7, 5}, 4, 12);
  return m;
}

bool has_edge(const std::array<std::array<Index, 4>, 3>& tets, Index a, Index b) {
  return std::any_of(tets.begin(), tets.end(), [&](const auto& t) {
    return std::count(t.begin(), t.end(), a) && std::count(t.begin(), t.end(), b);
  });
}

// The triangles of the tets on the nodes of `quad`.
std::set<std::array<Index, 4>> triangles_on(const primal::Model& m, std::array<Index, 4> quad) {
  std::set<std::array<Index, 4>> out;
  for (const auto& t : m.tets)
    for (const auto& f : primal::topology::kTetFaceCorners) {
      std::array<Index, 3> tri{t[static_cast<std::size_t>(f[0])], t[static_cast<std::size_t>(f[1])],
                               t[static_cast<std::size_t>(f[2])]};
      if (std::all_of(tri.begin(), tri.end(),
                      [&](Index v) { return std::count(quad.begin(), quad.end(), v) > 0; }))
        out.insert(primal::face_key(tri));
    }
  return out;
}

}  // namespace

TEST_CASE(
    "wedge_tets: six splits, each three positive tets filling the wedge along its diagonals") {
  const primal::Model m = two_wedges();
  const auto& faces = primal::cell_topology(ElementKind::kWedge).face;
  const auto& w = m.wedges[0];
  // The wedge's volume: its tets in any valid split add up to it; the prism's is base x height.
  const double expected = 0.5 * 1.0;
  int valid = 0;
  for (int bits = 0; bits < 8; ++bits) {
    const std::array<int, 3> diagonal{bits & 1, (bits >> 1) & 1, (bits >> 2) & 1};
    CAPTURE(bits);
    try {
      const auto tets = primal::wedge_tets(m, 0, diagonal);
      ++valid;
      double sum = 0.0;
      for (const auto& t : tets) {
        CHECK(test::tet_volume(m, t) > 0.0);
        sum += test::tet_volume(m, t);
      }
      CHECK(sum == doctest::Approx(expected));
      for (std::size_t q = 0; q < 3; ++q) {
        const auto& f = faces[q].corners;
        auto node = [&](int k) {
          return w[static_cast<std::size_t>(f[static_cast<std::size_t>(k)])];
        };
        CHECK(has_edge(tets, node(0), node(2)) == (diagonal[q] == 0));
        CHECK(has_edge(tets, node(1), node(3)) == (diagonal[q] == 1));
      }
    } catch (const TopologyError& e) {  // the two choices going round the wedge
      CHECK(std::string(e.what()).find("wedge 11") != std::string::npos);
    }
  }
  CHECK(valid == 6);
}

TEST_CASE("split_wedges: shared quads split alike, kept wedges renumbered, sides moved") {
  primal::Model m = two_wedges();
  // Side set: wedge 0's quad face 0 and its bottom triangle (face 3), wedge 1's top (face 4).
  m.side_sets.push_back({7,
                         "sides",
                         {{{ElementKind::kWedge, 0}, 0},
                          {{ElementKind::kWedge, 0}, 3},
                          {{ElementKind::kWedge, 1}, 4}}});
  SUBCASE("one of the two") {
    const primal::Model s = primal::split_wedges(m, std::vector<Index>{0});
    REQUIRE(s.tets.size() == 3);
    REQUIRE(s.wedges.size() == 1);
    CHECK(s.wedges[0] == m.wedges[1]);
    CHECK(s.wedge_ids == std::vector<std::int64_t>{12});
    CHECK(s.tet_ids == std::vector<std::int64_t>{11, 11, 11});
    CHECK(s.tet_block == std::vector<int>{4, 4, 4});
    for (const auto& t : s.tets) CHECK(test::tet_volume(s, t) > 0.0);
    // The quad both wedges share, split through its lowest node (1): triangles (1,2,5), (1,5,4).
    CHECK(triangles_on(s, {1, 2, 5, 4}) ==
          std::set<std::array<Index, 4>>{primal::face_key(std::array<Index, 3>{1, 2, 5}),
                                         primal::face_key(std::array<Index, 3>{1, 5, 4})});
    const auto& sides = s.side_sets.front().sides;
    REQUIRE(sides.size() == 4);  // 2 on the quad, 1 on the triangle, the kept wedge's top
    int on_tets = 0;
    for (const primal::Side& side : sides) {
      if (side.element.kind == ElementKind::kWedge) {
        CHECK(side == primal::Side{{ElementKind::kWedge, 0}, 4});
        continue;
      }
      ++on_tets;
      const auto nodes = primal::element_face(s, side);
      const bool on_quad = std::all_of(
          nodes.begin(), nodes.end(), [](Index v) { return v == 0 || v == 1 || v == 4 || v == 3; });
      const bool on_bottom =
          std::all_of(nodes.begin(), nodes.end(), [](Index v) { return v <= 2; });
      CHECK((on_quad || on_bottom));
    }
    CHECK(on_tets == 3);
  }
  SUBCASE("both: the tets of either side of the shared quad meet on the same two triangles") {
    const primal::Model s = primal::split_wedges(m, std::vector<Index>{0, 1});
    CHECK(s.wedges.empty());
    REQUIRE(s.tets.size() == 6);
    CHECK(triangles_on(s, {1, 2, 5, 4}).size() == 2);
    const primal::InputCheckResult c = primal::check_input(s);
    CHECK(c.ok());
  }
  SUBCASE("a quad with tets on it keeps their diagonal") {
    // Two tets on wedge 1's outer quad (6, 2, 5, 7), split along 6-5, not through node 2.
    m.points.push_back({1.5, 1.5, 0.5});
    const Index apex = primal::index_cast(m.points.size() - 1);
    primal::add_element(m, ElementKind::kTet, std::array<Index, 4>{6, 2, 5, apex}, 2, 1);
    primal::add_element(m, ElementKind::kTet, std::array<Index, 4>{6, 5, 7, apex}, 2, 2);
    const primal::Model s = primal::split_wedges(m, std::vector<Index>{1});
    const auto tris = triangles_on(s, {6, 2, 5, 7});
    CHECK(tris.count(primal::face_key(std::array<Index, 3>{6, 5, 2})) == 1);
    CHECK(tris.count(primal::face_key(std::array<Index, 3>{6, 7, 5})) == 1);
    CHECK(tris.size() == 2);
  }
}

TEST_CASE("wedge_pieces: the wedges joined through shared faces, whole pieces only") {
  primal::Model m = two_wedges();
  // A third wedge apart, the first two's shape moved 5 along x: no face shared with them.
  const Index base = primal::index_cast(m.points.size());
  for (Index v = 0; v < 6; ++v)
    m.points.push_back(m.points[primal::index_cast<std::size_t>(v)] + Point(5, 0, 0));
  primal::add_element(m, ElementKind::kWedge,
                      std::array<Index, 6>{base, base + 1, base + 2, base + 3, base + 4, base + 5},
                      4, 13);
  CHECK(primal::wedge_pieces(m, std::vector<Index>{0}) == std::vector<Index>{0, 1});
  CHECK(primal::wedge_pieces(m, std::vector<Index>{1}) == std::vector<Index>{0, 1});
  CHECK(primal::wedge_pieces(m, std::vector<Index>{2}) == std::vector<Index>{2});
  CHECK(primal::wedge_pieces(m, std::vector<Index>{2, 0}) == std::vector<Index>{0, 1, 2});
  CHECK(primal::wedge_pieces(m, std::vector<Index>{}).empty());
}

TEST_CASE("split_wedges: Gmsh's layer of hexes beside wedges on tets, refused whole, split") {
  test::TempDir dir;
  const primal::Model in = test::demo_input("layer-mixed", 3, dir);
  REQUIRE(!in.wedges.empty());
  REQUIRE(!in.hexes.empty());
  const primal::Model m = primal::split_pyramids(in).model;
  CHECK_THROWS_AS(primal::find_interface(m), TopologyError);
  std::vector<Index> joining;
  primal::find_interface(m, 1e-6, &joining);
  REQUIRE(!joining.empty());
  CHECK(std::is_sorted(joining.begin(), joining.end()));
  // The wedges are one layer, one piece: all of them go.
  const std::vector<Index> pieces = primal::wedge_pieces(m, joining);
  CHECK(pieces.size() == m.wedges.size());
  const primal::Model s = primal::split_wedges(m, pieces);
  CHECK(s.wedges.empty());
  CHECK(s.tets.size() == m.tets.size() + 3 * m.wedges.size());
  for (const auto& t : s.tets) CHECK(test::tet_volume(s, t) > 0.0);
  CHECK(primal::check_input(s).ok());
  // The hexes' quads the wedges covered are now interface quads too.
  const primal::Interface itf = primal::find_interface(s);
  CHECK(itf.quads.size() > in.pyramids.size());  // Gmsh's one pyramid per quad, and more
}
