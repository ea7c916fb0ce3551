#pragma once
// Element partitioning by METIS (Debian libmetis-dev): the dual graph of a model's elements
// (two elements adjacent when they share a face, 3 nodes), cut into parts balanced by the hexes
// each element dices into (8 per hex, 4 per tet, 6 per wedge).
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::parallel {

// Per flat element (primal::element_offsets): its part in [0, parts). Deterministic for a given
// model and part count (METIS seeded). parts == 1: all zero.
std::vector<int> partition_elements(const primal::Model& model, int parts);

}  // namespace geode::parallel
