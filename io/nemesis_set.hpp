#pragma once
// Nemesis input sets: the per-rank Exodus II files of a partitioned mesh (geode_mpi's output,
// named as SEACAS decomp names them: IN.exo.N.r, r = 0..N-1 zero-padded to the digits of N, each
// with node and element number maps holding global ids and Nemesis I global counts), read as the
// one model they cut, with each element's piece as its partition.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <geode/io/file_partition.hpp>
#include <geode/primal/model.hpp>

namespace geode::io {

struct NemesisSet {
  std::filesystem::path base;                // IN.exo
  std::vector<std::filesystem::path> files;  // IN.exo.N.0 .. IN.exo.N.(N-1)
  // "IN.exo.N.*": how messages about the joined model name the set (IN.exo itself is usually
  // absent, or another file, such as geode_mpi --join's).
  std::string name() const { return base.string() + "." + std::to_string(files.size()) + ".*"; }
};

// The set `path` names: a piece itself (IN.exo.N.r), or IN.exo when no such file exists and
// pieces IN.exo.N.r lie beside it (an existing IN.exo, such as geode_mpi --join's, is read as
// the plain file it is). nullopt when `path` names no set. Throws InvalidInput naming the file:
// pieces of two sets beside a missing IN.exo (IN.exo.2.* and IN.exo.4.*), a missing piece, more
// pieces than kMaxNemesisPieces.
inline constexpr int kMaxNemesisPieces = 1 << 16;
std::optional<NemesisSet> find_nemesis_set(const std::filesystem::path& path);

// Every piece read by read_exodus_piece (each screened and read as any Exodus file); nodes
// joined by their global ids (1..global nodes, the model's node order), elements by kind in
// ascending global id, blocks and node and side sets merged by id; file ids are the global
// ids; `partition` (when not null) gets each element's piece. Throws InvalidInput naming the
// piece and the node or element by its global id: a piece without Nemesis I counts, or with a
// processor count or global counts other than the set's, an id out of range, a node given at
// two places, an element in two pieces, a global node or element in no piece, a block or set
// named differently by two pieces. Then check_geometry (model.hpp) unless options say
// otherwise.
primal::Model read_nemesis_set(const NemesisSet& set, const primal::ReadOptions& options = {},
                               FilePartition* partition = nullptr);

}  // namespace geode::io
