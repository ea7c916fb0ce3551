// conform() on the realistic demo models (Gmsh Delaunay tets, alternating and random
// interface diagonals, a concave L-shaped interface): the result is a valid all-hex mesh
// (every interior face shared by two hexes, closed manifold boundary, Euler characteristic of
// a ball) with every scaled Jacobian positive, without smoothing and with the defaults.
#include <doctest/doctest.h>

#include <string>

#include "conform/conform.hpp"
#include "conform/demo_models.hpp"
#include "support/conform_checks.hpp"

using namespace geode;

TEST_CASE("realistic models, no smoothing: valid and untangled by the placement alone") {
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  for (const std::string name : {"delaunay", "delaunay-random", "lshape"}) {
    CAPTURE(name);
    const primal::Model m = conform::demo_model(name, 3);
    REQUIRE(!m.tets.empty());
    const auto r = conform::conform(m, o);
    CHECK(r.interface_quads == (name == "lshape" ? 18 : 9));
    test::check_conform_result(r);
  }
}

TEST_CASE("realistic model, default options: valid and untangled") {
  const auto r = conform::conform(conform::demo_model("delaunay-random", 2));
  CHECK(r.interface_quads == 4);
  test::check_conform_result(r);
}
