#pragma once
// Output of a distributed run: one Exodus II file per rank with the Nemesis I load-balance and
// communication maps that parallel solvers read (the layout SEACAS decomp writes and epu joins:
// OUT.exo.N.r, r = 0..N-1 zero-padded to the digits of N), and on request one joined file.
//
// Per rank: the rank's hexes (parallel/distributed_conform.hpp) with node and element number
// maps holding their 1-based global ids; Nemesis: init info (N processors, 1 per file, "p"),
// the global counts (nodes, hexes, blocks, node and side sets with their global sizes), the
// load balance (internal nodes: held by this rank alone; border nodes: shared; no external
// nodes, every node a rank's hexes use is in its file; border elements: those on a border
// node), one nodal communication map per neighbouring rank (its shared nodes, ascending global
// id, on both sides) and no elemental ones.
#include <filesystem>
#include <string>

#include <mpi.h>

#include <geode/parallel/distributed_conform.hpp>

namespace geode::parallel {

// "OUT.exo.4.0" ... "OUT.exo.4.3" (epu's naming).
std::filesystem::path rank_file(const std::filesystem::path& output, int ranks, int rank);

// Writes this rank's piece to `file` (rank_file(OUT, ranks, rank), or a temporary the caller
// renames to it once every rank has written its own). Throws InvalidInput naming `file` when
// libexodusII fails.
void write_nemesis(const RankMesh& mesh, const std::filesystem::path& file, int ranks, int rank);

// The model in a canonical order, independent of how it was numbered: nodes by coordinates
// (x, then y, then z), hexes by block, then by their corners' new numbers; sets sorted.
primal::Model canonical(const primal::Model& model);

// Collective: rank 0 gathers every rank's hexes and writes `output` (canonical order; the other
// ranks' `output` is not used).
void write_joined(const RankMesh& mesh, const std::filesystem::path& output, MPI_Comm comm);

}  // namespace geode::parallel
