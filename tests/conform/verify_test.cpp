// Local verification (ConformVerify::kLocal: the full check around the transition, the diced
// parts through the dicer's tables) against the full check of the whole output: the same
// verdict on every demo model, as Gmsh meshes them, and a fault in the transition caught.
#include <doctest/doctest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity_local.hpp>
#include "support/cli_run.hpp"
#include "support/demo_input.hpp"
#include "support/sanitized.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::Index;

namespace {}  // namespace

TEST_CASE("local verification gives the full check's verdict on every demo model") {
  const test::TempDir dir;
  // The sanitized build takes one model of each kind of input (64 s there for all 17): hexes
  // and tets, a curved interface, pyramids, wedges, split wedges, parts in potting.
  const std::vector<std::string> names =
      test::kSanitized ? std::vector<std::string>{"half",        "nugget",      "hybrid",
                                                  "hexdominant", "layer-mixed", "potting"}
                       : demo::demo_model_names();
  for (const std::string& name : names) {
    CAPTURE(name);
    const primal::Model m = test::demo_input(name, 2, dir);
    conform::ConformOptions local, full;
    local.verify = conform::ConformVerify::kLocal;
    full.verify = conform::ConformVerify::kFull;
    // The potting at n = 2 as conform leaves it, carved from the tets, without the run from the
    // hex part that finds it (test time; the local yardstick test checks that choice).
    if (name == "potting") {
      conform::set_buffer_side(local, "tet");
      conform::set_buffer_side(full, "tet");
    }
    const auto a = conform::conform(m, local);
    const auto b = conform::conform(m, full);
    CHECK(a.verified == conform::ConformVerify::kLocal);
    CHECK(b.verified == conform::ConformVerify::kFull);
    CHECK(a.dicing.ok());
    CHECK(conform::result_valid(a) == conform::result_valid(b));
    CHECK(a.validity.ok() == b.validity.ok());
    CHECK(a.validity.inverted_hexes == b.validity.inverted_hexes);
    // The same mesh either way: verification only reads it.
    CHECK(a.model.points == b.model.points);
    CHECK(a.model.hexes == b.model.hexes);
  }
}

TEST_CASE("local verification reads the transition's surroundings, not the whole output") {
  conform::ConformOptions local;
  local.verify = conform::ConformVerify::kLocal;
  const auto r = conform::conform(demo::demo_model("delaunay", 4), local);
  CHECK(conform::result_valid(r));
  CHECK(r.verified == conform::ConformVerify::kLocal);
  CHECK(r.verified_hexes >= r.geode_hexes);
  CHECK(r.verified_hexes < primal::index_cast(r.model.hexes.size()));
  conform::ConformOptions global = local;
  global.smooth = conform::ConformSmooth::kGlobal;  // moves every node: verified whole
  const auto g = conform::conform(demo::demo_model("delaunay", 2), global);
  CHECK(g.verified == conform::ConformVerify::kFull);
  CHECK(g.verified_hexes == primal::index_cast(g.model.hexes.size()));
}

TEST_CASE(
    "the region check finds a torn transition, a flipped hex anywhere, and agrees when whole") {
  const auto r = conform::conform(demo::demo_model("delaunay", 2));
  REQUIRE(conform::result_valid(r));
  CHECK(r.verified == conform::ConformVerify::kLocal);  // the default
  primal::HexMesh mesh = primal::hex_part(r.model);
  const Index first_geode = r.diced_hexes;
  std::vector<Index> geode(primal::index_cast<std::size_t>(r.geode_hexes));
  for (Index i = 0; i < r.geode_hexes; ++i)
    geode[primal::index_cast<std::size_t>(i)] = first_geode + i;

  // Seeded by every hex, the region is the whole mesh: check_validity's verdict and counts.
  std::vector<Index> all(mesh.hexes.size());
  for (std::size_t h = 0; h < all.size(); ++h) all[h] = primal::index_cast(h);
  const auto whole = primal::check_validity_around(mesh, all);
  const auto reference = primal::check_validity(mesh);
  CHECK(whole.ok());
  CHECK(whole.num_cells == reference.num_cells);
  CHECK(whole.euler == reference.euler);
  CHECK(whole.boundary.faces.size() == reference.boundary.faces.size());
  CHECK(primal::check_validity_around(mesh, geode).ok());

  SUBCASE("a geode hex's node replaced by another geode node: found as the full check finds it") {
    primal::HexMesh torn = mesh;
    auto& h = torn.hexes[primal::index_cast<std::size_t>(first_geode)];
    Index v = primal::kInvalidIndex;
    for (Index k = first_geode + 1; v == primal::kInvalidIndex; ++k)
      for (Index x : torn.hexes[primal::index_cast<std::size_t>(k)])
        if (std::find(h.begin(), h.end(), x) == h.end()) {
          v = x;
          break;
        }
    h[6] = v;
    const auto full = primal::check_validity(torn);
    const auto local = primal::check_validity_around(torn, geode);
    CHECK(!full.ok());
    CHECK(!local.ok());
    CHECK(!full.nonmanifold_vertices.empty());
    CHECK(local.nonmanifold_vertices == full.nonmanifold_vertices);
    CHECK(local.nonmanifold_edges == full.nonmanifold_edges);
    CHECK(local.overshared_faces == full.overshared_faces);
    CHECK(local.misoriented_faces == full.misoriented_faces);
    CHECK(local.inverted_hexes == full.inverted_hexes);
    CHECK(local.overlapping_nodes.size() == full.overlapping_nodes.size());
  }
  SUBCASE("a diced hex far from the transition turned inside out: its Jacobians") {
    primal::HexMesh flipped = mesh;
    auto& h = flipped.hexes.front();  // the first diced hex, a corner of the hex part
    std::swap(h[0], h[4]), std::swap(h[1], h[5]), std::swap(h[2], h[6]), std::swap(h[3], h[7]);
    const auto found = primal::check_validity_around(flipped, geode);
    CHECK(!found.ok());
    CHECK(found.inverted_hexes == std::vector<Index>{0});
    // With the signs of the scaled Jacobians handed in, the hexes above 0 are not measured
    // again: the same.
    primal::RegionValidityOptions o;
    const std::vector<double> sj = primal::scaled_jacobian_per_hex(flipped);
    std::vector<char> positive(sj.size());
    for (std::size_t h = 0; h < sj.size(); ++h) positive[h] = sj[h] > 0.0;
    o.positive = positive;
    CHECK(primal::check_validity_around(flipped, geode, o).inverted_hexes == std::vector<Index>{0});
    // The same on the mesh's arrays, as conform hands them over from its output model.
    CHECK(primal::check_validity_around(flipped.points, flipped.hexes, geode, o).inverted_hexes ==
          std::vector<Index>{0});
    // Measured ahead by corner_jacobians_positive (as geode_mpi's ranks do while they wait):
    // 0 for the flipped hex alone, 1 wherever the scaled Jacobian is above 0, and the same
    // finding when handed in.
    const std::vector<char> ahead =
        primal::corner_jacobians_positive(flipped.points, flipped.hexes);
    REQUIRE(ahead.size() == sj.size());
    CHECK(ahead[0] == 0);
    for (std::size_t h = 1; h < sj.size(); ++h)
      if (sj[h] > 0.0) REQUIRE(ahead[h] == 1);
    o.positive = ahead;
    CHECK(primal::check_validity_around(flipped, geode, o).inverted_hexes == std::vector<Index>{0});
    // A hex with a node out of range is not taken as positive (the check names it).
    primal::HexMesh broken = flipped;
    broken.hexes[1][3] = primal::index_cast(broken.points.size());
    CHECK(primal::corner_jacobians_positive(broken.points, broken.hexes)[1] == 0);
  }
}

TEST_CASE("write_ahead gets the final model once, beside verification or after it") {
  const primal::Model input = demo::demo_model("delaunay", 3);
  const auto plain = conform::conform(input);
  REQUIRE(conform::result_valid(plain));
  struct Case {
    conform::ConformVerify verify;
    int threads;
  };
  // Local verification on two threads writes beside the check; full verification, or one
  // thread, after it: the model handed over and the result are the same in every case.
  for (const Case c :
       {Case{conform::ConformVerify::kLocal, 2}, Case{conform::ConformVerify::kLocal, 1},
        Case{conform::ConformVerify::kFull, 2}}) {
    CAPTURE(c.threads);
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(c.threads));
    for (const bool with_sj : {false, true}) {
      CAPTURE(with_sj);
      conform::ConformOptions o;
      o.verify = c.verify;
      o.write_ahead_scaled_jacobians = with_sj;
      int calls = 0;
      std::vector<primal::Point> points;
      std::vector<std::array<Index, 8>> hexes;
      std::map<int, std::string> names;
      std::vector<double> sj;
      o.write_ahead = [&](const primal::Model& m, std::span<const double> given) {
        ++calls;
        points = m.points, hexes = m.hexes, names = m.block_names;
        sj.assign(given.begin(), given.end());
      };
      const auto r = conform::conform(input, o);
      CHECK(calls == 1);
      // Asked for, the scaled Jacobians handed on are those of the hexes handed on, bit for bit.
      if (with_sj) {
        REQUIRE(sj.size() == hexes.size());
        for (std::size_t h = 0; h < hexes.size(); ++h) {
          primal::HexCorners p;
          for (std::size_t k = 0; k < 8; ++k)
            p[k] = points[primal::index_cast<std::size_t>(hexes[h][k])];
          REQUIRE(sj[h] == primal::hex_scaled_jacobian(p));
        }
      } else {
        CHECK(sj.empty());
      }
      CHECK(conform::result_valid(r));
      CHECK(r.validity.ok() == plain.validity.ok());
      CHECK(points == plain.model.points);
      CHECK(hexes == plain.model.hexes);
      CHECK(names == plain.model.block_names);
      CHECK(r.model.hexes == plain.model.hexes);
      CHECK(r.quality.size() == plain.quality.size());
    }
  }
  // A writer's failure reaches the caller once verification is done.
  conform::ConformOptions failing;
  failing.write_ahead = [](const primal::Model&, std::span<const double>) {
    throw InvalidInput("disk full");
  };
  CHECK_THROWS_WITH_AS(conform::conform(input, failing), "disk full", InvalidInput);
}
