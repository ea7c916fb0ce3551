// Boundary extraction from several threads at once. Templates are built in parallel, so the
// first extraction in a process (the first use of OpenMesh's error stream, which OpenMesh sets up
// without a lock) can come from several threads together: this file sorts first in primal_tests
// so that, under AddressSanitizer, a race there can show as a leaked stream target (it did, in
// 1 of 20 runs, before the fix). Each thread's surface must equal the one extracted alone, and
// OpenMesh's error stream must be left as found.
#include <doctest/doctest.h>

#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <latch>
#include <thread>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include "support/fixtures.hpp"

using namespace geode::primal;
using geode::test::structured_hex_grid;

namespace {

// Hexes (0,0) and (1,1) of a 2x2x1 grid: they touch along one edge only, so OpenMesh refuses
// some of their boundary quads (a complex edge) and writes to its error stream about it.
HexMesh edge_contact() {
  HexMesh m = structured_hex_grid(2, 2, 1);
  m.hexes = {m.hexes[0], m.hexes[3]};
  return m;
}

}  // namespace

TEST_CASE(
    "extract_boundary: several threads at once, the first use of OpenMesh's error stream too") {
  const HexMesh m = edge_contact();
  constexpr int kThreads = 8;
  std::vector<BoundarySurface> got(kThreads);
  {
    std::latch start(kThreads);
    std::vector<std::jthread> threads;
    for (int t = 0; t < kThreads; ++t)
      threads.emplace_back([&, t] {
        start.arrive_and_wait();
        got[t] = extract_boundary(m);
      });
  }
  CHECK(omerr().is_enabled());

  const BoundarySurface alone = extract_boundary(m);
  REQUIRE_FALSE(alone.rejected.empty());
  CHECK_FALSE(alone.manifold);
  for (const auto& b : got) {
    CHECK(b.rejected.size() == alone.rejected.size());
    CHECK(b.faces.size() == alone.faces.size());
    CHECK(b.vertex_node.size() == alone.vertex_node.size());
    CHECK(b.euler == alone.euler);
    CHECK(b.manifold == alone.manifold);
  }

  // A caller who silenced the stream keeps it silenced.
  omerr().disable();
  (void)extract_boundary(m);
  CHECK_FALSE(omerr().is_enabled());
  omerr().enable();
}

TEST_CASE(
    "surface_quads_at: the model's boundary and block interface quads at flagged nodes, from "
    "the hexes around them alone") {
  // A 4 x 4 x 3 grid in three blocks (x < 2; x >= 2 below z = 2; x >= 2 above): boundary quads,
  // block interface quads in two planes, and quads inside each block. The flagged nodes are
  // those of seed hexes at a corner, inside, and where the three blocks meet.
  HexMesh mesh = structured_hex_grid(4, 4, 3);
  for (const auto& h : mesh.hexes) {
    Point c = Point::Zero();
    for (Index v : h) c += mesh.points[index_cast<std::size_t>(v)] / 8.0;
    mesh.block.push_back(c.x() < 2.0 ? 1 : c.z() < 2.0 ? 2 : 3);
  }
  std::vector<BoundaryQuad> all = boundary_quads(mesh);
  const std::vector<BoundaryQuad> between = block_interface_quads(mesh);
  REQUIRE(!between.empty());
  all.insert(all.end(), between.begin(), between.end());
  for (const std::vector<Index>& seeds :
       std::vector<std::vector<Index>>{{0}, {21}, {0, 21, 22, 47}, {}}) {
    std::vector<char> at(mesh.points.size(), 0);
    for (Index s : seeds)
      for (Index v : mesh.hexes[index_cast<std::size_t>(s)]) at[index_cast<std::size_t>(v)] = 1;
    std::vector<Index> around;  // every hex holding a flagged node, ascending
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
      if (std::any_of(mesh.hexes[h].begin(), mesh.hexes[h].end(),
                      [&](Index v) { return at[index_cast<std::size_t>(v)] != 0; }))
        around.push_back(index_cast(h));
    std::vector<BoundaryQuad> want;
    for (const BoundaryQuad& q : all)
      if (std::any_of(q.nodes.begin(), q.nodes.end(),
                      [&](Index v) { return at[index_cast<std::size_t>(v)] != 0; }))
        want.push_back(q);
    const std::vector<BoundaryQuad> got = surface_quads_at(mesh, around, at);
    CAPTURE(seeds.size());
    REQUIRE(got.size() == want.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      CHECK(got[i].hex == want[i].hex);
      CHECK(got[i].local_face == want[i].local_face);
      CHECK(got[i].nodes == want[i].nodes);
    }
    if (!seeds.empty()) CHECK(!got.empty());
  }
  CHECK_THROWS_AS(surface_quads_at(mesh, {}, std::vector<char>(3, 0)), geode::InvalidInput);
  const std::vector<Index> outside{index_cast(mesh.hexes.size())};
  CHECK_THROWS_AS(surface_quads_at(mesh, outside, std::vector<char>(mesh.points.size(), 1)),
                  geode::InvalidInput);
}
