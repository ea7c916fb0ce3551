#pragma once
// conform (conform/conform.hpp) under MPI, with a result that does not depend on the number of
// ranks: the output of every rank joined is the serial run's, node for node and hex for hex.
//
// Every rank holds the whole input (inputs are ~25x smaller than outputs; geode_mpi reads a single
// Exodus file in shares, io/exodus.hpp read_exodus_shared). The transition zone
// Z, every element within `rings` node rings of a node used by both a hex and a tet (plus the
// elements setting the yardstick and any inverted element, which the serial run also smooths),
// is conformed once, on the last rank (the zone rank), while rank 0 partitions the elements by
// METIS (parallel/partition.hpp; the zone rank given less to dice, by the zone's load) or as the
// input file was (options.partition), and the others wait for the partition. conform reads
// nothing outside Z but the yardstick, which the lowest elements carry in. Wedges seed the zone
// as well (their diced nodes' bits depend on which wedge makes them first), so a model of many
// wedges is mostly zone. The result is checked: the outer two rings of Z must come out as plain
// dicing, bit for bit (the smoothing and the buffer layer stopped short of the cut), else Z is
// grown (rings doubled) and conformed again. Everything else is plain dicing
// (primal/dice_model.hpp): each rank dices only its own elements outside Z, and dicing depends
// only on an element and its nodes, so a rank's hexes are the serial run's (a rank that diced
// before the zone grew dices again). The zone rank then sends every rank Z's points, sets and
// block names, and Z's hexes are shared out: each other rank takes a run of them up to the mean
// output per rank (none when the partition left the zone rank room for them), the zone rank the
// rest.
//
// Global ids (0-based): Z's output nodes and hexes first in Z's output order (the same on every
// rank count); then the diced nodes and hexes, rank by rank, each owned by the lowest rank
// holding it. A diced node on the cut takes Z's node at its position (the same bits: the same
// formula over the same nodes). Diced nodes shared by ranks are found by their origin (the
// sorted input nodes they are made from) exchanged between the ranks whose elements hold all of
// them.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <mpi.h>

#include <geode/conform/conform.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/shares.hpp>

namespace geode::parallel {

struct DistributedOptions {
  conform::ConformOptions conform;
  int rings = 4;       // depth of the transition zone, doubled until the check passes
  int max_rings = 64;  // TopologyError past this
  // Per flat element of the input (primal::element_offsets), its rank: used instead of METIS
  // when not empty (the input's own partition, parallel/partition.hpp ranks_of_parts); the same
  // on every rank. Only the load balance depends on it, not the result.
  std::vector<int> partition;
  // The input again, as it was given (geode_mpi reads its file again). With it, a rank of
  // conform_distributed(Model&&) frees the input as soon as it has taken its piece, before
  // dicing, and asks for it again only where the zone grows after that (rare: the zone rank
  // sends the depth it needed once the other ranks have diced). Without it a rank holds the
  // input until its numbering.
  std::function<primal::Model()> reload;
  // TBB threads of the zone's conform on the zone rank: 0 for one per CPU of the ranks on its
  // machine (parallel/machine_cpus.hpp), whose other ranks wait for the zone without spinning
  // once their own dicing is done. The caller's tbb::global_control must allow that many. The
  // result is the same for any count (conform's is).
  int zone_threads = 0;
  // This rank's pairs of elements sharing a face, as the read-time check gave them
  // (primal::InputCheckOptions::element_pairs, with shared_input_check): rank 0 partitions the
  // graph they make, gathered, instead of pairing every face again (half 68: 0.46 s of its
  // 1.05 s partition). Used when every rank gives them; the partition stage takes them (the
  // vectors are left empty). Only the load balance depends on them, not the result.
  std::vector<std::array<primal::Index, 2>>* element_pairs = nullptr;
  // Called on this rank with one line per stage as it ends ("dicing (3.2 s)"), for the command
  // line's progress output (geode_mpi gives it on rank 0 only); may be empty. The stages are
  // DistributedReport::seconds's (a stage that runs twice is told twice, by a label of its own).
  std::function<void(const std::string&)> progress;
  // Called on the rank that conforms the transition zone with the zone's conform stage lines
  // (ConformOptions::progress), the longest stage, while rank 0 waits for it; may be empty.
  std::function<void(const std::string&)> zone_progress;
};

// One rank's share of the output.
struct RankMesh {
  primal::Model model;  // hexes only, by block in ascending id then by global id
  std::vector<std::int64_t> node_gid, hex_gid;  // per local node / hex
  // Per other rank sharing nodes with this one: those local nodes, in ascending global id.
  std::map<int, std::vector<primal::Index>> shared_nodes;
  std::int64_t global_nodes = 0, global_hexes = 0;
  std::map<int, std::int64_t> global_block_hexes;  // per block id: hexes over all ranks
  std::vector<std::int64_t> global_node_set_nodes, global_side_set_sides;  // per set
};

struct DistributedReport {
  conform::ConformResult zone;  // on the zone rank: the zone's conform (its model moved out)
  int rings = 0;                // the depth that passed the check
  std::int64_t zone_cells = 0, cells = 0, zone_hexes = 0, diced_hexes = 0;  // this rank's diced
  bool valid = true;  // the zone and every rank's piece valid (distributed_assembly.cpp)
  std::vector<std::string> warnings;
  std::map<std::string, double> seconds;  // per stage, this rank
};

// Collective over `comm`. Throws InvalidInput / TopologyError as conform does, on every rank
// alike (the zone rank sends its outcome to all); InvalidInput for --smooth global (it moves every
// node) and a named geode block.
RankMesh conform_distributed(const primal::Model& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report = nullptr);
// The same on a model the caller gives up: freed but its block names once this rank has taken
// its piece (options.reload given) or diced it, so that dicing (with a reload), the numbering,
// assembly and verification hold it no more. Afterwards, or after an exception, it may be
// emptied.
RankMesh conform_distributed(primal::Model&& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report = nullptr);

// Every rank's bytes, concatenated in rank order, on every rank: one MPI_Allgatherv, or, when a
// rank has more than `round` bytes or all have more than 2 GiB (MPI's counts are ints), rounds
// of at most `round` bytes a rank, each copied into place. Collective.
std::vector<char> all_gather_bytes(const std::vector<char>& mine, MPI_Comm comm,
                                   std::size_t round = std::size_t{1} << 28);

// The ranks of `comm` as primal::Shares: this rank's number, their count, and all_gather_bytes
// as the exchange.
primal::Shares rank_shares(MPI_Comm comm);

// The read-time covering check (primal/input_check.hpp) shared among the ranks of `comm`, for
// io::read_model: each rank pairs its share of the faces, the exchange joins the pairings, and
// every rank reaches the same verdict; with them the read of a single Exodus file (each rank
// reads its run of the nodes and elements; io/exodus.hpp read_exodus_shared). Collective: every
// rank must read the same file with it.
primal::InputCheckOptions shared_input_check(MPI_Comm comm);

}  // namespace geode::parallel
