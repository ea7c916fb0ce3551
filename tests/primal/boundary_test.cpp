// Boundary extraction from several threads at once. Templates are built in parallel, so the
// first extraction in a process (the first use of OpenMesh's error stream, which OpenMesh sets up
// without a lock) can come from several threads together: this file sorts first in primal_tests
// so that, under AddressSanitizer, a race there can show as a leaked stream target (it did, in
// 1 of 20 runs, before the fix). Each thread's surface must equal the one extracted alone, and
// OpenMesh's error stream must be left as found.
#include <doctest/doctest.h>

#include <OpenMesh/Core/System/omstream.hh>

#include <latch>
#include <thread>
#include <vector>

#include <geode/primal/boundary.hpp>
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
