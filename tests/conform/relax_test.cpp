// conform's tet relaxation (ConformOptions::relax) on Gmsh's hybrid meshes: the output stays
// valid (block volumes: materials_test), the reported yardsticks are the input's own cells as given
// (the same with and without relaxation), and where Gmsh's pyramids are flat the transition is
// better with it than without.
#include <doctest/doctest.h>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity.hpp>
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"

using namespace geode;

TEST_CASE("conform relaxes the tets beside the hex part, judged against the input as given") {
  test::TempDir dir;
  for (const std::string name : {"hexdominant", "hybrid-cylinder"}) {
    CAPTURE(name);
    const primal::Model in = test::demo_input(name, 4, dir);
    conform::ConformOptions none;
    none.relax = conform::ConformRelax::kNone;
    const conform::ConformResult a = conform::conform(in);
    const conform::ConformResult b = conform::conform(in, none);
    // (hexdominant's buffer layer is carved from the tets, with a warning: validity alone.)
    for (const conform::ConformResult* r : {&a, &b}) {
      const primal::HexValidityReport v = primal::check_validity(primal::hex_part(r->model));
      INFO(v.summary());
      CHECK(v.ok());
      CHECK(conform::result_valid(*r));
    }
    CHECK(a.relaxation.nodes_moved > 0);
    CHECK(b.relaxation.nodes_moved == 0);
    CHECK(a.relaxation.min_after > a.relaxation.min_before);
    // The yardsticks are the input's cells, whatever conform moved.
    CHECK(a.yardstick() == b.yardstick());
    CHECK(a.local_yardstick == b.local_yardstick);
    REQUIRE(a.quality.size() == b.quality.size());
    for (std::size_t k = 0; k < a.quality.size(); ++k)
      CHECK(a.quality[k].input_diced_min_scaled_jacobian ==
            b.quality[k].input_diced_min_scaled_jacobian);
    const double with = primal::min_scaled_jacobian(primal::hex_part(a.model));
    const double without = primal::min_scaled_jacobian(primal::hex_part(b.model));
    MESSAGE(name << ": min scaled Jacobian " << without << " without relaxation, " << with
                 << " with; yardstick " << a.yardstick());
    CHECK(with >= a.yardstick());
    CHECK(with > without);
  }
}
