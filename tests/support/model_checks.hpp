#pragma once
// Checks on models shared by the tests: two models with the same cells (points, every kind's
// connectivity and blocks, and the block names, field by field, so that a failure names the
// field), and a tet's signed volume.
#include <doctest/doctest.h>

#include <array>

#include <geode/primal/model.hpp>

namespace geode::test {

inline void check_same_cells(const primal::Model& a, const primal::Model& b) {
  CHECK(a.points == b.points);
  CHECK(a.hexes == b.hexes);
  CHECK(a.tets == b.tets);
  CHECK(a.pyramids == b.pyramids);
  CHECK(a.wedges == b.wedges);
  CHECK(a.hex_block == b.hex_block);
  CHECK(a.tet_block == b.tet_block);
  CHECK(a.pyramid_block == b.pyramid_block);
  CHECK(a.wedge_block == b.wedge_block);
  CHECK(a.block_names == b.block_names);
}

// The signed volume of tet `t` (node numbers) of `m`.
inline double tet_volume(const primal::Model& m, const std::array<primal::Index, 4>& t) {
  auto p = [&](std::size_t k) { return m.points[primal::index_cast<std::size_t>(t[k])]; };
  return primal::tet_volume(p(0), p(1), p(2), p(3));
}

}  // namespace geode::test
