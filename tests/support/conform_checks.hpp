#pragma once
// What the conform tests share: the checks every conform() result must pass, and the volumes
// per block that say materials never move.
#include <doctest/doctest.h>

#include <map>

#include <geode/conform/conform.hpp>
#include <geode/primal/model.hpp>
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

// Per hex block of `m`: its hexes' volume (each the exact volume of its trilinear map).
inline std::map<int, double> hex_block_volumes(const primal::Model& m) {
  std::map<int, double> v;
  for (std::size_t h = 0; h < m.hexes.size(); ++h) {
    primal::HexCorners c;
    for (std::size_t k = 0; k < 8; ++k)
      c[k] = m.points[primal::index_cast<std::size_t>(m.hexes[h][k])];
    v[m.hex_block.empty() ? 0 : m.hex_block[h]] += primal::hex_volume(c);
  }
  return v;
}

// Per tet block of `m`: its tets' volume.
inline std::map<int, double> tet_block_volumes(const primal::Model& m) {
  std::map<int, double> v;
  for (std::size_t t = 0; t < m.tets.size(); ++t) {
    const auto& n = m.tets[t];
    const auto& p = m.points;
    v[m.tet_block.empty() ? 0 : m.tet_block[t]] += primal::tet_volume(
        p[primal::index_cast<std::size_t>(n[0])], p[primal::index_cast<std::size_t>(n[1])],
        p[primal::index_cast<std::size_t>(n[2])], p[primal::index_cast<std::size_t>(n[3])]);
  }
  return v;
}

}  // namespace geode::test
