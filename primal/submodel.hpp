#pragma once
// A model restricted to some of its elements: the nodes they use, renumbered in ascending order
// of their numbers in the model (so that any computation ordered by node number, such as dicing's
// centroids summed over sorted origin keys, gives the same bits on the submodel), the elements
// in their order, blocks, names, node sets and side sets restricted to them.
#include <array>
#include <span>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

// Flat element numbers over every kind: hexes first, then tets, pyramids, wedges
// (kElementKinds order).
std::array<std::size_t, 5> element_offsets(const Model& model);

struct Submodel {
  Model model;
  std::vector<Index> node;                    // per submodel node: its model node (ascending)
  std::array<std::vector<Index>, 4> element;  // per kind: submodel element -> model element
};

// `keep` per flat element number (element_offsets).
Submodel extract_submodel(const Model& model, std::span<const char> keep);

}  // namespace geode::primal
