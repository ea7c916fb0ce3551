#pragma once
// Element partitioning by METIS (Debian libmetis-dev): the dual graph of a model's elements
// (primal/element_graph.hpp: two elements adjacent when they share a face, 3 nodes), cut into
// parts balanced by the hexes each element dices into (8 per hex, 4 per tet, 6 per wedge, 8 per
// pyramid), or as the caller weighs them and shares them out. Past 64 clusters a part, METIS cuts
// the graph of clusters of ~16 connected elements (edges weighted by the faces they share) and a
// greedy pass over the elements smooths the cut.
#include <array>
#include <span>
#include <vector>

#include <geode/primal/element_graph.hpp>
#include <geode/primal/model.hpp>

namespace geode::parallel {

struct PartitionOptions {
  // Per flat element its weight (at least 1); empty: the hexes it dices into.
  std::vector<primal::Index> weight;
  // Per part the share of the total weight it is given (positive, summing to 1); empty: equal.
  std::vector<double> share;
  // The elements' graph, when the caller has it (geode_mpi: from the read-time check's face
  // pairs, graph_of_pairs); empty: primal::element_graph's.
  primal::ElementGraph graph;
};

// The graph whose edges are `pairs` (flat element numbers below `elements`, each pair once; both
// directions are listed), each element's neighbours in the order of the pairs.
primal::ElementGraph graph_of_pairs(std::size_t elements,
                                    std::span<const std::array<primal::Index, 2>> pairs);

// Per flat element (primal::element_offsets): its part in [0, parts). Deterministic for a given
// model, part count and options (METIS seeded, the rest sequential). parts == 1: all zero.
std::vector<int> partition_elements(const primal::Model& model, int parts,
                                    PartitionOptions options = {});

// A partition the input carries (io/file_partition.hpp: a partitioned .msh, a Nemesis set) of
// `parts` parts, as ranks: the parts themselves when parts == ranks; with more parts than
// ranks, part p to rank p * ranks / parts (consecutive parts joined, each rank parts / ranks of
// them, one more or less); with fewer, empty (the caller partitions with METIS instead).
std::vector<int> ranks_of_parts(const std::vector<int>& part, int parts, int ranks);

}  // namespace geode::parallel
