#pragma once
// The partition an input file carries: a Gmsh-partitioned .msh 4.1 (each volume element's
// partitioned entity, gmsh.hpp) or a Nemesis file set (each element's piece, nemesis_set.hpp).
// geode_mpi takes it instead of partitioning the elements itself (parallel/partition.hpp).
#include <vector>

namespace geode::io {

struct FilePartition {
  int parts = 0;          // 0: the file carries no partition (part is then empty)
  std::vector<int> part;  // per flat element (primal::element_offsets order): in [0, parts)
};

}  // namespace geode::io
