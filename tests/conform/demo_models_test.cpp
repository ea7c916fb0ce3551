// conform() on the realistic demo models (Gmsh Delaunay tets, alternating and random
// interface diagonals, a concave L-shaped interface, a curved cylinder, a convex nugget): the
// result is a valid all-hex mesh (every interior face shared by two hexes, closed manifold
// boundary, Euler characteristic of a ball) with every scaled Jacobian positive, without
// smoothing and with the defaults; and a mixed interface of two- and four-triangle quads.
#include <doctest/doctest.h>

#include <string>

#include "conform/conform.hpp"
#include "conform/demo_models.hpp"
#include "conform/reference_template.hpp"
#include "primal/interface.hpp"
#include "support/conform_checks.hpp"

using namespace geode;
using primal::Index;

namespace {

// The geode hexes conform() must make for the model: 26 per two-triangle interface quad, the
// four-triangle template's count per four-triangle one (checked to be some but not all quads).
Index mixed_geode_hexes(const primal::Model& m) {
  const primal::Interface itf = primal::find_interface(m);
  const auto quads = static_cast<Index>(itf.quads.size());
  Index four = 0;
  for (const auto& q : itf.quads) four += q.centre != primal::kInvalidIndex;
  CHECK(four > 0);
  CHECK(four < quads);
  const auto per_four = static_cast<Index>(
      conform::reference_template_four_triangles(conform::ConformOptions{}.template_box).tpl.hex.hexes.size());
  return 26 * (quads - four) + per_four * four;
}

}  // namespace

TEST_CASE("realistic models, no smoothing: valid and untangled by the placement alone") {
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  // The curved cylinder and the convex nugget meet neighbouring buffer hexes at an angle: their
  // shared side faces must take the same nodes from both templates.
  const struct {
    const char* name;
    primal::Index quads;
  } models[] = {{"delaunay", 9}, {"delaunay-random", 9}, {"lshape", 18}, {"nugget", 96}, {"cylinder", 146}};
  for (const auto& [name, quads] : models) {
    CAPTURE(name);
    const primal::Model m = conform::demo_model(name, 3);
    REQUIRE(!m.tets.empty());
    const auto r = conform::conform(m, o);
    CHECK(r.interface_quads == quads);
    test::check_conform_result(r);
  }
}

TEST_CASE("realistic models, default options: valid and untangled") {
  for (const char* name : {"delaunay-random", "cylinder"}) {
    CAPTURE(name);
    const auto r = conform::conform(conform::demo_model(name, 2));
    test::check_conform_result(r);
    // The yardstick is measured on the input itself: Delaunay tets are far from the diced
    // Kuhn cube's 0.29, the swept hexes of the cylinder far from 1.
    CHECK(r.input_diced_tet_min_scaled_jacobian < 0.2);
    CHECK(r.input_diced_tet_min_scaled_jacobian > 0.0);
  }
}

// A mixed interface: Delaunay tets whose interface quads are split into two triangles (random
// diagonals) or four around a centre node; the four-triangle ones get the fixed-up
// four-triangle template, its side faces merged with the neighbouring geodes'.
TEST_CASE("mixed two- and four-triangle interface: valid and untangled") {
  const primal::Model m = conform::demo_model("fourtri", 3);
  const Index geode_hexes = mixed_geode_hexes(m);
  for (const auto smooth : {conform::ConformSmooth::kNone, conform::ConformSmooth::kLocal}) {
    CAPTURE(static_cast<int>(smooth));
    conform::ConformOptions o;
    o.smooth = smooth;
    const auto r = conform::conform(m, o);
    CHECK(r.interface_quads == 9);
    test::check_conform_result(r, geode_hexes);
  }
}

// The same on a curved, unstructured interface (the hex cylinder's recombined caps and swept
// sides in a Delaunay tet box), where, as for the two-triangle cylinder, smoothing is needed.
// Skipped in the sanitized Debug build, where smoothing its 126 buffer hexes takes most of a
// minute; that build runs the same code on the planar mixed model above.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
TEST_CASE("mixed interface on a curved cylinder, default options: valid and untangled" *
          doctest::skip(kSanitized)) {
  const primal::Model m = conform::demo_model("fourtri-cylinder", 2);
  test::check_conform_result(conform::conform(m), mixed_geode_hexes(m));
}
