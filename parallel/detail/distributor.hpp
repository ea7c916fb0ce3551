#pragma once
// conform_distributed's private class, not part of the API: its stages are the methods of
// Distributor, defined by topic in distributed_conform.cpp (the yardstick, the transition zone
// and its conform, the partition, dicing), distributed_exchange.cpp (the zone shared out, global
// ids) and distributed_assembly.cpp (each rank's piece assembled and verified).
#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <mpi.h>

#include <geode/parallel/distributed_conform.hpp>
#include <geode/parallel/machine_cpus.hpp>
#include <geode/parallel/partition.hpp>
#include <geode/primal/detail/byte_packet.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/dice_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/key_map.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/submodel.hpp>
#include <geode/primal/validity.hpp>
#include <geode/primal/validity_local.hpp>

namespace geode::parallel::detail {

// What holds piece by piece of a hex mesh (distributed_assembly.cpp): all but the boundary,
// the Euler characteristic and manifoldness, and the covering at the nodes `exempt`.
bool piece_ok(const primal::HexValidityReport& v, const std::vector<char>& exempt);

using primal::ElementKind;
using primal::FaceKey;
using primal::Index;
using primal::kInvalidIndex;
using primal::Model;
using primal::Point;
using Clock = std::chrono::steady_clock;
using Mask = std::uint64_t;  // ranks, one bit each (at most 64)

// A point's exact bits, for matching diced nodes with the zone's nodes made by the same formula.
struct PointBits {
  std::array<std::uint64_t, 3> b;
  bool operator==(const PointBits&) const = default;
};
// Every word mixed whole (murmur3's 64-bit finalizer) into the hash, whose low bits pick the
// slot. Points of a structured part of round size (coordinates k / 64: the half 64 bench) differ
// in their doubles' top bits only, which a multiply never carries down: with a multiply-xorshift
// per word, half 64's numbering took 2.85 s instead of 0.24 s on one rank and its zone 2.33 s
// instead of 1.46 s, all in probing.
struct PointBitsHash {
  static std::uint64_t mix(std::uint64_t x) {
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ull;
    return x ^ (x >> 33);
  }
  std::size_t operator()(const PointBits& p) const {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t x : p.b) h = mix(h ^ x);
    return primal::index_cast<std::size_t>(h);
  }
};
inline PointBits bits(const Point& p) {
  PointBits r;
  for (int i = 0; i < 3; ++i) std::memcpy(&r.b[primal::index_cast<std::size_t>(i)], &p[i], 8);
  return r;
}

// Points (by their bits) to an index: open addressing with linear probing in two flat arrays,
// sized for its keys up front. The zone's checks look up a million zone points among hundreds
// of thousands of diced ones; std::unordered_set's node per entry made the zone rank's band
// check 0.18 s of its 0.24 s (bench_mpi half 68).
class PointBitsMap {
 public:
  explicit PointBitsMap(std::size_t keys) {
    std::size_t capacity = 16;
    while (capacity < 2 * keys) capacity *= 2;
    keys_.resize(capacity);
    values_.assign(capacity, kEmpty);
    mask_ = capacity - 1;
  }
  // Stores (key, value) unless key is there; at most the `keys` given to the constructor.
  void emplace(const PointBits& key, std::size_t value) {
    std::size_t i = PointBitsHash()(key) & mask_;
    for (; values_[i] != kEmpty; i = (i + 1) & mask_)
      if (keys_[i] == key) return;
    keys_[i] = key;
    values_[i] = value;
    ++size_;
  }
  // The value stored for key, or nullptr.
  const std::size_t* find(const PointBits& key) const {
    for (std::size_t i = PointBitsHash()(key) & mask_; values_[i] != kEmpty; i = (i + 1) & mask_)
      if (keys_[i] == key) return &values_[i];
    return nullptr;
  }
  std::size_t size() const { return size_; }

 private:
  static constexpr std::size_t kEmpty = static_cast<std::size_t>(-1);
  std::vector<PointBits> keys_;
  std::vector<std::size_t> values_;
  std::size_t mask_ = 0, size_ = 0;
};

// Every rank's `mine`, concatenated in rank order (all_gather_bytes of their bytes).
inline std::vector<int> gather_all(const std::vector<int>& mine, MPI_Comm comm) {
  std::vector<char> bytes(mine.size() * sizeof(int));
  if (!mine.empty()) std::memcpy(bytes.data(), mine.data(), bytes.size());
  const std::vector<char> all = all_gather_bytes(bytes, comm);
  std::vector<int> every(all.size() / sizeof(int));
  if (!every.empty()) std::memcpy(every.data(), all.data(), every.size() * sizeof(int));
  return every;
}

// (node, holders) entries sorted by node, each node once with its holders joined.
template <typename Node>
void join_holders(std::vector<std::pair<Node, Mask>>& entries) {
  std::sort(entries.begin(), entries.end());
  std::size_t w = 0;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    if (w > 0 && entries[w - 1].first == entries[k].first)
      entries[w - 1].second |= entries[k].second;
    else
      entries[w++] = entries[k];
  }
  entries.resize(w);
}

// conform_distributed's stages, in the order run() calls them.
class Distributor {
 public:
  // `spare`: the input itself when the caller gives it up (freed once no stage reads it).
  Distributor(const Model& input, const DistributedOptions& options, MPI_Comm comm,
              DistributedReport& report, Model* spare = nullptr)
      : options_(options), comm_(comm), rep_(report), input_(input), spare_(spare) {
    MPI_Comm_rank(comm, &rank_);
    MPI_Comm_size(comm, &size_);
    // The ranks but the zone rank, for what they share while it conforms the zone.
    MPI_Comm_split(comm, rank_ == zone_rank() ? MPI_UNDEFINED : 0, rank_, &others_);
    zone_cpus_ = machine_cpus(comm);
    take_model(input);
  }

  ~Distributor() {
    if (others_ != MPI_COMM_NULL) MPI_Comm_free(&others_);
  }
  Distributor(const Distributor&) = delete;
  Distributor& operator=(const Distributor&) = delete;

  RankMesh run() {
    const auto& opt = options_.conform;
    if (size_ > 64) throw InvalidInput("geode_mpi: at most 64 ranks");
    if (opt.smooth == conform::ConformSmooth::kGlobal)
      throw InvalidInput("--smooth global moves every node: not available under MPI");
    if (!opt.geode_block.empty())
      throw InvalidInput("a named geode block is not available under MPI");
    offsets_ = primal::element_offsets(m());
    // The rings before the yardstick, which takes the lowest elements outside them; again after
    // it where it found inverted elements, which seed the zone too.
    stage(
        "zone selection", [&] { select_rings(options_.rings); }, "zone selection: rings");
    stage("yardstick", [&] { yardstick(); });
    stage(
        "zone selection",
        [&] {
          if (!inverted_.empty()) select_rings(options_.rings);
          finish_zone();
        },
        "zone selection: closed");
    // Here, before the zone rank leaves for the zone: rank 0 gathers the face pairs.
    stage(
        "partition", [&] { gather_pairs(); }, "partition: face pairs gathered");
    // The zone rank conforms the zone while rank 0 partitions and the others wait for it.
    if (rank_ == zone_rank()) stage("zone", [&] { conform_zone(); });
    stage("partition", [&] { partition(); });
    if (zone_failure_kind_ == 0) stage("dicing", [&] { dice(); });
    stage("zone shared", [&] {
      share_zone();
      share_zone_hexes();
    });
    stage("global ids", [&] { number(); });
    stage("assembly", [&] { assemble(); });
    release();  // what only the stages before needed: the verification's room
    stage("verification", [&] { verify(); });
    list_node_ids();
    return std::move(out_);
  }

 private:
  // `name`: the report's stage (its seconds summed over the calls); `label`: the progress line's,
  // told apart where one stage is run in two steps.
  template <typename F>
  void stage(const std::string& name, F&& f, const std::string& label = {}) {
    const auto t0 = Clock::now();
    f();
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    rep_.seconds[name] += seconds;
    if (options_.progress) {
      std::ostringstream line;
      line << (label.empty() ? name : label) << " (" << std::fixed << std::setprecision(1)
           << seconds << " s)";
      options_.progress(line.str());
    }
  }
  const Model& m() const { return *model_; }
  // The model the stages read: `input` itself, or its pyramids split as conform's own first
  // step does, element by element (the same tets).
  void take_model(const Model& input) {
    if (input.pyramids.empty()) {
      model_ = &input;
      return;
    }
    auto split = primal::split_pyramids(input);
    split_ = std::move(split.model);
    tet_pyramid_ = std::move(split.tet_pyramid);
    model_ = &split_;
  }
  std::size_t cells() const { return offsets_.back(); }
  primal::ElementRef ref(std::size_t c) const {
    std::size_t k = 0;
    while (c >= offsets_[k + 1]) ++k;
    return {primal::kElementKinds[k], primal::index_cast(c - offsets_[k])};
  }
  // The rank conforming the zone: the last, so that rank 0 can partition meanwhile.
  int zone_rank() const { return size_ - 1; }

  void yardstick();
  void select_rings(int rings);
  void finish_zone();
  void conform_zone();
  void gather_pairs();
  void partition();
  void dice();
  void share_zone();
  void share_zone_hexes();
  void number();
  void assemble();
  void break_for_test();
  void verify();
  // Local node n's global id, as list_node_ids lists it (before it does: verify()'s messages).
  std::int64_t node_gid(Index n) const {
    const auto i = primal::index_cast<std::size_t>(n), low = low_ids_.size();
    const auto owned = primal::index_cast<std::size_t>(owned_);
    if (i < low) return low_ids_[i];
    if (i < low + owned) return owned_first_ + primal::index_cast<std::int64_t>(i - low);
    return high_ids_[i - low - owned];
  }
  // The local nodes' global ids, whole (assembly lists those outside the rank's run).
  void list_node_ids() {
    auto& ids = out_.node_gid;
    ids = std::move(low_ids_);
    ids.reserve(ids.size() + primal::index_cast<std::size_t>(owned_) + high_ids_.size());
    for (std::int64_t g = owned_first_; g < owned_first_ + owned_; ++g) ids.push_back(g);
    ids.insert(ids.end(), high_ids_.begin(), high_ids_.end());
    primal::release(high_ids_);
  }
  // The stages after the global ids' first step read the model's block names only, and no
  // rank dices again (share_zone's grown zone is behind): the model this rank may change (the
  // caller's given up, or the pyramids split) freed but those, before the numbering, assembly
  // and verification add their own (the half 68 bench: about 90 MiB a rank).
  void trim_model() {
    Model* m = changeable();
    if (!m) return;
    primal::release(m->points, m->hexes, m->tets, m->pyramids, m->wedges, m->hex_block,
                    m->tet_block, m->pyramid_block, m->wedge_block, m->node_sets, m->side_sets);
    drop_ids(m);
  }
  // The model the stages read, when this rank may change it (the caller's given up, the
  // pyramids split, or read again); else null.
  Model* changeable() {
    if (model_ == &split_) return &split_;
    if (model_ == &reloaded_) return &reloaded_;
    return model_ == spare_ ? spare_ : nullptr;
  }
  static void drop_ids(Model* m) {
    if (m) primal::release(m->node_ids, m->hex_ids, m->tet_ids, m->pyramid_ids, m->wedge_ids);
  }
  void release() {
    own_ = {};
    primal::release(level_, in_zone_, band_, part_, zone_node_, diced_gid_, diced_shared_,
                    zone_holders_, tet_pyramid_);
    split_ = {}, reloaded_ = {}, zone_out_ = {};
  }

  const DistributedOptions& options_;
  MPI_Comm comm_, others_ = MPI_COMM_NULL;
  DistributedReport& rep_;
  const Model& input_;
  Model* spare_;
  int rank_ = 0, size_ = 1;
  cpu_set_t zone_cpus_;  // what the zone's conform may run on: the CPUs of this machine's ranks
  Model split_;
  Model reloaded_;        // the input read again (options_.reload) for a zone grown after trimming
  bool trimmed_ = false;  // the model's arrays freed before dicing (trim_model)
  std::vector<Index> tet_pyramid_;  // per tet of split_: its pyramid of the input, or invalid
  std::vector<Mask> node_users_;    // per model node: the ranks whose elements outside Z use it
  const Model* model_ = nullptr;
  std::array<std::size_t, 5> offsets_{};
  std::vector<int> part_;  // per flat element
  // On rank 0, gathered by gather_pairs: every rank's face pairs (options_.element_pairs), by
  // flat element of the model the stages read; none when a rank gave none (rank 0 then pairs
  // the faces itself).
  std::vector<std::array<Index, 2>> pairs_;
  // Per kind and block the element diced alone lowest of those outside the zone's first rings
  // (the zone takes them: the serial run's yardstick, its aims and each block's own figure are
  // the lowest over the whole model).
  std::vector<std::size_t> lowest_;
  std::vector<std::size_t> inverted_;  // elements diced with a scaled Jacobian <= 0
  std::vector<signed char> level_;     // per flat element: ring in the zone, -1 outside
  std::vector<char> in_zone_, band_;   // per flat element: in the zone, in its outer two rings
  int rings_ = 0;                      // the depth in_zone_ was selected at
  MPI_Request partition_sent_ = MPI_REQUEST_NULL;  // rank 0's partition to the zone rank
  std::string partition_failure_;                  // on rank 0, why METIS gave no partition
  // The zone conformed: the whole of it on the zone rank; elsewhere its points, sets (the side
  // sets without sides) and block names, the rest being the zone rank's alone.
  Model zone_out_;
  std::size_t zone_hexes_ = 0;  // the zone's output hexes (on every rank)
  // On the zone rank, when the zone could not be conformed: the error's kind and message.
  std::string zone_failure_;
  int zone_failure_kind_ = 0;
  std::vector<char> zone_node_;                 // per model node: used by a zone element
  std::size_t zone_first_ = 0, zone_last_ = 0;  // this rank's zone hexes, in the zone's numbers
  std::size_t zone_base_ = 0;  // the zone's number of zone_out_.hexes[0] (this rank's first)
  primal::Submodel own_;       // this rank's elements outside the zone
  primal::DicedModel diced_;
  primal::DicingCheck dicing_;  // diced_ against the dicing tables (local verification)
  // Per diced child (hex, tet, then wedge children, as their global ids run): its corner
  // Jacobians all above 0 (local verification).
  std::vector<char> diced_positive_;
  std::int64_t zone_nodes_ = 0;          // the zone's output nodes: global ids below this
  std::vector<std::int64_t> diced_gid_;  // per diced node
  // Per diced node that other ranks hold too (not the zone's), ascending: every rank holding it.
  // Listed, not a mask per node: nearly all diced nodes are this rank's alone.
  std::vector<std::pair<std::size_t, Mask>> diced_shared_;
  std::vector<Mask> zone_holders_;            // per zone output node
  std::int64_t diced_hex_first_ = 0;          // global id of this rank's first diced hex
  std::int64_t owned_first_ = 0, owned_ = 0;  // the global ids this rank numbered: a run
  // The local nodes' global ids below and above that run, and how many of the first are the
  // zone's.
  std::vector<std::int64_t> low_ids_, high_ids_;
  std::size_t zone_locals_ = 0;
  RankMesh out_;
};

}  // namespace geode::parallel::detail
