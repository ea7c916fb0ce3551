// Materials never move: conform's smoothing, in every mode, keeps each output block's volume
// (the analyst's materials) to 1e-9 relative, on a curved interface (cylinder), at convex and
// concave edges and corners (nugget), and around six parts in potting; the nodes on the
// interfaces still slide where they are flat, and the tet blocks keep the input tets' volume.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>

#include <geode/conform/conform.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/quality.hpp>
#include "support/conform_checks.hpp"

using namespace geode;
using primal::Index;

TEST_CASE("materials never move: every smoothing mode keeps each block's volume to 1e-9") {
  const struct {
    const char* name;
    int n;
  } models[] = {{"cylinder", 3}, {"nugget", 2}, {"potting", 2}};
  for (const auto& model : models) {
    const std::string model_name = model.name;
    CAPTURE(model_name);
    const primal::Model input = demo::demo_model(model.name, model.n);
    conform::ConformOptions none;
    none.smooth = conform::ConformSmooth::kNone;
    const conform::ConformResult base = conform::conform(input, none);
    test::check_conform_result(base);
    const auto reference = test::hex_block_volumes(base.model);
    for (const auto& [id_, volume] : test::tet_block_volumes(input)) {
      // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
      const auto& id = id_;
      CAPTURE(id);
      REQUIRE(reference.count(id));
      CHECK(std::abs(reference.at(id) - volume) <= 1e-9 * volume);
    }
    // The nodes on the model boundary and between blocks, in the output's numbering (the same
    // in every mode: smoothing moves nodes, never renumbers them).
    primal::HexMesh mesh = primal::hex_part(base.model);
    std::vector<char> on_surface(mesh.points.size(), 0);
    for (const auto& q : primal::material_surface_quads(mesh))
      for (Index v : q.nodes) on_surface[primal::index_cast<std::size_t>(v)] = 1;
    const struct {
      const char* label;
      conform::ConformSmooth smooth;
      double target;
    } modes[] = {{"local (defaults)", conform::ConformSmooth::kLocal, 0.0},
                 {"local, target 0.5", conform::ConformSmooth::kLocal, 0.5},
                 {"global", conform::ConformSmooth::kGlobal, 0.0}};
    for (const auto& mode : modes) {
      const std::string mode_label = mode.label;
      CAPTURE(mode_label);
      conform::ConformOptions o;
      o.smooth = mode.smooth;
      o.smooth_target = mode.target;
      const conform::ConformResult r = conform::conform(input, o);
      test::check_conform_result(r);
      REQUIRE(r.model.points.size() == base.model.points.size());
      const auto volumes = test::hex_block_volumes(r.model);
      REQUIRE(volumes.size() == reference.size());
      for (const auto& [id_, volume] : reference) {
        // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
        const auto& id = id_;
        CAPTURE(id);
        CHECK(std::abs(volumes.at(id) - volume) <= 1e-9 * volume);
      }
      Index moved = 0, slid = 0;
      for (std::size_t v = 0; v < mesh.points.size(); ++v) {
        const bool m = (r.model.points[v] - base.model.points[v]).norm() > 1e-6;
        moved += m;
        slid += m && on_surface[v];
      }
      // Where smoothing works at all, it moves nodes on the flat interfaces too (in them).
      if (mode.target > 0.0 || mode.smooth == conform::ConformSmooth::kGlobal) {
        CHECK(moved > 0);
        CHECK(slid > 0);
      }
      MESSAGE(model.name << " " << mode.label << ": " << moved << " nodes moved, " << slid
                         << " of them sliding on a material surface");
    }
  }
}
