#pragma once
// Two models with the same cells: points, every kind's connectivity and blocks, and the block
// names, field by field (so that a failure names the field).
#include <doctest/doctest.h>

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

}  // namespace geode::test
