#pragma once
// The dual graph of a model's elements: two elements adjacent when they share a face (its 3 or 4
// nodes), or where a quad of one meets a triangle on 3 of its nodes (a hex part facing a tet part
// without pyramids: the quad split in two triangles). What METIS_PartMeshDual builds with
// ncommon = 3, found by filing every face under its lowest node and sorting each node's few
// faces (a KeyMap of every face costs four times as much on large models: its table outgrows the
// cache) instead of counting the nodes shared by every pair of elements around a node.
#include <cstddef>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

// Compressed rows over flat element numbers (element_offsets): the neighbours of element e are
// neighbour[offset[e] .. offset[e + 1]), one per shared face, in the order of e's local faces (a
// quad's triangles after them). A face used by more than two elements (an invalid model) joins
// them two by two.
struct ElementGraph {
  std::vector<std::size_t> offset;  // element count + 1
  std::vector<Index> neighbour;
};

ElementGraph element_graph(const Model& model);

}  // namespace geode::primal
