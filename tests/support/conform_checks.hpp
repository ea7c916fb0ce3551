#pragma once
// A doctest check shared by the conform tests: what every conform() result must satisfy.
#include <doctest/doctest.h>

#include <geode/conform/conform.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity.hpp>
#include "support/ball_checks.hpp"

namespace geode::test {

// The hex part is a valid all-hex ball (check_validity: faces matched, manifold, sphere
// boundary, every corner positive, every node covered once) with positive scaled Jacobians,
// `geode_hexes` geode hexes (default: 26 per interface quad), and `warnings` warnings (none).
inline void check_conform_result(const conform::ConformResult& r, primal::Index geode_hexes = -1,
                                 std::size_t warnings = 0) {
  const primal::HexMesh mesh = primal::hex_part(r.model);
  const primal::HexValidityReport v = primal::check_validity(mesh);
  INFO(v.summary());
  CHECK(v.ok());
  check_combinatorial_ball(v);
  CHECK(v.inverted_hexes.empty());
  CHECK(v.overlapping_nodes.empty());
  CHECK(primal::min_scaled_jacobian(mesh) > 0.0);
  CHECK(r.geode_hexes == (geode_hexes < 0 ? 26 * r.interface_quads : geode_hexes));
  CHECK(r.model.hexes.size() ==
        primal::index_cast<std::size_t>(r.diced_hexes + r.geode_hexes + r.diced_tet_hexes +
                                        r.diced_wedge_hexes));
  CHECK(r.warnings.size() == warnings);
}

}  // namespace geode::test
