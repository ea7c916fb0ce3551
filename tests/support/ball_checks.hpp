#pragma once
// A doctest check shared by the template tests: the mesh is a combinatorial ball.
#include <doctest/doctest.h>

#include <geode/primal/validity.hpp>

namespace geode::test {

// Combinatorial validity (orientation aside): a complex whose faces are shared by at most two
// hexes, consistently oriented, manifold, a ball (Euler characteristic 1) with a closed
// manifold sphere boundary (Euler characteristic 2).
inline void check_combinatorial_ball(const primal::HexValidityReport& r) {
  CHECK(r.out_of_range_hexes.empty());
  CHECK(r.repeated_node_hexes.empty());
  CHECK(r.overshared_faces.empty());
  CHECK(r.misoriented_faces.empty());
  CHECK(r.nonmanifold_edges.empty());
  CHECK(r.nonmanifold_vertices.empty());
  CHECK(r.unused_nodes == 0);
  CHECK(r.euler == 1);
  CHECK(r.boundary.closed);
  CHECK(r.boundary.manifold);
  CHECK(r.boundary.euler == 2);
}

}  // namespace geode::test
