// conform() on the realistic demo models (Gmsh Delaunay tets, alternating and random
// interface diagonals, a concave L-shaped interface, a curved cylinder, a convex nugget): the
// result is a valid all-hex mesh (every interior face shared by two hexes, closed manifold
// boundary, Euler characteristic of a ball) with every scaled Jacobian positive, without
// smoothing and with the defaults.
#include <doctest/doctest.h>

#include <string>

#include "conform/conform.hpp"
#include "conform/demo_models.hpp"
#include "primal/quality.hpp"
#include "primal/validity.hpp"

using namespace geode;

namespace {

void check_valid(const conform::ConformResult& r) {
  const primal::HexMesh mesh = primal::hex_part(r.model);
  const primal::HexValidityReport v = primal::check_validity(mesh);
  INFO(v.summary());
  CHECK(v.ok());
  CHECK(v.overshared_faces.empty());
  CHECK(v.boundary.closed);
  CHECK(v.boundary.manifold);
  CHECK(v.euler == 1);
  CHECK(v.boundary.euler == 2);
  CHECK(primal::min_scaled_jacobian(mesh) > 0.0);
  CHECK(r.warnings.empty());
  CHECK(r.geode_hexes == 26 * r.interface_quads);
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
    check_valid(r);
  }
}

TEST_CASE("realistic models, default options: valid and untangled") {
  for (const char* name : {"delaunay-random", "cylinder"}) {
    CAPTURE(name);
    const auto r = conform::conform(conform::demo_model(name, 2));
    check_valid(r);
    // The yardstick is measured on the input itself: Delaunay tets are far from the diced
    // Kuhn cube's 0.29, the swept hexes of the cylinder far from 1.
    CHECK(r.input_diced_tet_min_scaled_jacobian < 0.2);
    CHECK(r.input_diced_tet_min_scaled_jacobian > 0.0);
  }
}
