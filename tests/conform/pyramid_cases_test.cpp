// The pyramid placements a hybrid mesh can hold, each conformed with the defaults and checked
// valid with every hex positive (--pyramids split: each pyramid as the two tets of its better
// base diagonal, primal/split_pyramids.hpp): a pyramid with its base on the model boundary, two
// pyramids on one base quad, two pyramids sharing a triangle over two hexes. (Pyramids on hex
// and wedge quads as Gmsh makes them: tests/demo/hybrid_models_test.cpp.)
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/split_pyramids.hpp>

using namespace geode;
using primal::Index;
using primal::Point;

namespace {

struct PyramidCase {
  std::string name;
  primal::Model model;
  Index interface_quads;  // what conform finds
  Index output_hexes;
};

// A unit square's corners at height z, counter-clockwise seen from +z.
void add_square(primal::Model& m, double z) {
  for (const Point& p : {Point(0, 0, z), Point(1, 0, z), Point(1, 1, z), Point(0, 1, z)})
    m.points.push_back(p);
}

std::vector<PyramidCase> cases() {
  std::vector<PyramidCase> out;
  {  // A pyramid alone: its base quad is the model's boundary; nothing to transition to.
    primal::Model m;
    add_square(m, 0);
    m.points.emplace_back(0.5, 0.5, 0.7);
    m.pyramids.push_back({0, 1, 2, 3, 4});
    out.push_back({"base on the boundary", m, 0, 8});
  }
  {  // An octahedron: two pyramids on one base quad, apexes on either side. One diagonal must
     // serve both, or the four tets do not meet face to face across the base.
    primal::Model m;
    add_square(m, 0);
    m.points.emplace_back(0.5, 0.5, 0.7);
    m.points.emplace_back(0.5, 0.5, -0.7);
    m.pyramids.push_back({0, 1, 2, 3, 4});
    m.pyramids.push_back({3, 2, 1, 0, 5});  // its base counter-clockwise seen from its apex
    out.push_back({"two on one base", m, 0, 16});
  }
  {  // Two hexes side by side with a pyramid on each top quad and one apex above the edge the
     // quads share, so that the pyramids share the triangle on that edge: two interface quads.
    primal::Model m;
    for (int z = 0; z < 2; ++z)  // a 3 x 2 grid of nodes per level: node 6 z + 3 y + x
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) m.points.emplace_back(x, y, z);
    m.hexes.push_back({0, 1, 4, 3, 6, 7, 10, 9});
    m.hexes.push_back({1, 2, 5, 4, 7, 8, 11, 10});
    m.points.emplace_back(1.0, 0.5, 1.8);  // 12: the apex both share
    m.pyramids.push_back({6, 7, 10, 9, 12});
    m.pyramids.push_back({7, 8, 11, 10, 12});
    out.push_back({"two sharing a triangle, over two hexes", m, 2, 16 + 2 * 26 + 2 * 8});
  }
  return out;
}

}  // namespace

TEST_CASE("pyramid placements: each split, conformed, valid, every hex positive") {
  for (const PyramidCase& c : cases()) {
    CAPTURE(c.name);
    const primal::PyramidSplit split = primal::split_pyramids(c.model);
    CHECK(split.model.pyramids.empty());
    CHECK(split.model.tets.size() == 2 * c.model.pyramids.size());
    const conform::ConformResult r = conform::conform(c.model);
    CHECK(r.input_pyramids == primal::index_cast(c.model.pyramids.size()));
    CHECK(r.interface_quads == c.interface_quads);
    CHECK(primal::index_cast(r.model.hexes.size()) == c.output_hexes);
    CHECK(r.validity.ok());
    primal::HexMesh all{r.model.points, r.model.hexes, {}};
    double lowest = 1.0;
    for (Index h = 0; h < primal::index_cast(all.hexes.size()); ++h)
      lowest = std::min(lowest, primal::hex_scaled_jacobian(primal::hex_corners(all, h)));
    CHECK(lowest > 0.0);
    // At least the input's tets diced alone (all there is without an interface), and where
    // there is one, as far as the geode template gets: its own minimum (0.33) is below these
    // tets' 0.41 in the two-hex case.
    const double yardstick = r.input_diced_tet_min_scaled_jacobian;
    const double reach =
        r.interface_quads > 0 ? std::min(yardstick, r.template_min_scaled_jacobian) : yardstick;
    CHECK(reach > 0.3);
    CHECK(lowest >= reach - 1e-12);
  }
}

TEST_CASE("two pyramids on one base quad take the same diagonal") {
  const primal::Model octahedron = cases()[1].model;
  const primal::PyramidSplit split = primal::split_pyramids(octahedron);
  REQUIRE(split.diagonal.size() == 2);
  // The same base diagonal in node numbers: pyramid 1 lists the base reversed (3 2 1 0), so
  // its diagonal 0 (corners 0-2) is nodes 3-1 and its diagonal 1 (corners 1-3) nodes 2-0.
  CHECK(split.diagonal[0] != split.diagonal[1]);
}
