#include <geode/parallel/distributed_conform.hpp>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <utility>

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

namespace geode::parallel {
namespace {

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
struct PointBitsHash {
  std::size_t operator()(const PointBits& p) const {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t x : p.b) h = (h ^ x) * 0x100000001b3ull, h ^= h >> 29;
    return primal::index_cast<std::size_t>(h);
  }
};
PointBits bits(const Point& p) {
  PointBits r;
  for (int i = 0; i < 3; ++i) std::memcpy(&r.b[primal::index_cast<std::size_t>(i)], &p[i], 8);
  return r;
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
    stage("yardstick", [&] { yardstick(); });
    stage("zone selection", [&] { select_zone(options_.rings); });
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
  template <typename F>
  void stage(const std::string& name, F&& f) {
    const auto t0 = Clock::now();
    f();
    rep_.seconds[name] += std::chrono::duration<double>(Clock::now() - t0).count();
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
  void select_zone(int rings);
  void conform_zone();
  void partition();
  void dice();
  void share_zone();
  void share_zone_hexes();
  void number();
  void assemble();
  void break_for_test();
  void verify();
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
  Model split_;
  Model reloaded_;        // the input read again (options_.reload) for a zone grown after trimming
  bool trimmed_ = false;  // the model's arrays freed before dicing (trim_model)
  std::vector<Index> tet_pyramid_;  // per tet of split_: its pyramid of the input, or invalid
  std::vector<Mask> node_users_;    // per model node: the ranks whose elements outside Z use it
  const Model* model_ = nullptr;
  std::array<std::size_t, 5> offsets_{};
  std::vector<int> part_;              // per flat element
  std::vector<std::size_t> lowest_;    // elements setting the yardstick (one per kind)
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

// The serial run's yardstick is the lowest element of each kind diced alone over the whole
// model: each rank measures a run of the elements (a contiguous one: no partition is needed
// yet, and neighbours share nodes in memory), the lowest of each kind join the zone so that
// conform measures the same minimum there. Inverted elements are smoothed by the serial run
// wherever they are: they seed the zone.
void Distributor::yardstick() {
  struct {
    double value;
    int cell;
  } low[3], all[3];
  for (auto& l : low) l = {2.0, std::numeric_limits<int>::max()};
  std::vector<int> inverted;
  const auto consider = [&](int k, std::size_t c, double v) {
    if (v < low[k].value || (v == low[k].value && static_cast<int>(c) < low[k].cell))
      low[k] = {v, static_cast<int>(c)};
    if (v <= 0.0) inverted.push_back(static_cast<int>(c));
  };
  const auto share = [&](std::size_t n, int r) {
    return n * primal::index_cast<std::size_t>(r) / primal::index_cast<std::size_t>(size_);
  };
  const std::size_t nh = m().hexes.size(), nt = m().tets.size(), nw = m().wedges.size();
  const auto cell_of = [&](ElementKind kind, std::size_t i) {
    return offsets_[static_cast<std::size_t>(kind)] + i;
  };
  {
    const std::size_t a = share(nh, rank_), b = share(nh, rank_ + 1);
    const auto h =
        primal::diced_scaled_jacobian_per_cell(m().points, std::span(m().hexes.data() + a, b - a));
    for (std::size_t i = 0; i < h.size(); ++i) consider(0, cell_of(ElementKind::kHex, a + i), h[i]);
  }
  {
    const std::size_t a = share(nt, rank_), b = share(nt, rank_ + 1);
    const auto t =
        primal::diced_scaled_jacobian_per_cell(m().points, std::span(m().tets.data() + a, b - a));
    for (std::size_t i = 0; i < t.size(); ++i) consider(1, cell_of(ElementKind::kTet, a + i), t[i]);
  }
  for (std::size_t i = share(nw, rank_); i < share(nw, rank_ + 1); ++i)
    consider(2, cell_of(ElementKind::kWedge, i),
             primal::diced_wedge_min_scaled_jacobian(m().points, std::span(&m().wedges[i], 1)));
  MPI_Allreduce(low, all, 3, MPI_DOUBLE_INT, MPI_MINLOC, comm_);
  for (const auto& a : all)
    if (a.value <= 1.5) lowest_.push_back(primal::index_cast<std::size_t>(a.cell));
  int n = primal::index_cast<int>(inverted.size());
  std::vector<int> counts(primal::index_cast<std::size_t>(size_)), displs(counts.size());
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
  std::vector<int> every(primal::index_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(inverted.data(), n, MPI_INT, every.data(), counts.data(), displs.data(), MPI_INT,
                 comm_);
  inverted_.assign(every.begin(), every.end());
  std::sort(inverted_.begin(), inverted_.end());
}

// The zone `rings` deep (in_zone_), its outer two rings (band_) and its nodes (zone_node_): the
// same on every rank.
void Distributor::select_zone(int rings) {
  rings_ = rings;
  const std::size_t nv = m().points.size();
  std::vector<char> used_by_hex(nv, 0), used_by_tet(nv, 0), marked(nv, 0);
  for (const auto& h : m().hexes)
    for (Index v : h) used_by_hex[primal::index_cast<std::size_t>(v)] = 1;
  for (const auto& t : m().tets)
    for (Index v : t) used_by_tet[primal::index_cast<std::size_t>(v)] = 1;
  for (std::size_t v = 0; v < nv; ++v) marked[v] = used_by_hex[v] && used_by_tet[v];
  for (std::size_t c : inverted_)
    for (Index v : primal::element_corners(m(), ref(c)))
      marked[primal::index_cast<std::size_t>(v)] = 1;
  // Wedges seed the zone too: dice_model places a wedge's edge and face nodes by summing over
  // the corners of the first wedge making them, so their bits depend on which wedges a run
  // dices; inside the zone they are the serial run's (its elements in the same order).
  for (const auto& w : m().wedges)
    for (Index v : w) marked[primal::index_cast<std::size_t>(v)] = 1;
  level_.assign(cells(), -1);
  for (int ring = 0; ring <= rings; ++ring) {
    std::vector<std::size_t> reached;
    for (std::size_t c = 0; c < cells(); ++c) {
      if (level_[c] >= 0) continue;
      for (Index v : primal::element_corners(m(), ref(c)))
        if (marked[primal::index_cast<std::size_t>(v)]) {
          reached.push_back(c);
          break;
        }
    }
    for (std::size_t c : reached) {
      level_[c] = static_cast<signed char>(ring);
      for (Index v : primal::element_corners(m(), ref(c)))
        marked[primal::index_cast<std::size_t>(v)] = 1;
    }
  }
  in_zone_.assign(cells(), 0);
  for (std::size_t c = 0; c < cells(); ++c) in_zone_[c] = level_[c] >= 0;
  for (std::size_t c : lowest_) in_zone_[c] = 1;
  // The band: the zone's elements within two rings of the cut (the nodes it shares with the
  // elements outside); none when the zone is the whole model.
  std::vector<char> outside(nv, 0), near(nv, 0);
  band_.assign(cells(), 0);
  for (std::size_t c = 0; c < cells(); ++c)
    if (!in_zone_[c])
      for (Index v : primal::element_corners(m(), ref(c)))
        outside[primal::index_cast<std::size_t>(v)] = 1;
  for (int ring = 0; ring < 2; ++ring) {
    for (std::size_t c = 0; c < cells(); ++c) {
      if (!in_zone_[c]) continue;
      for (Index v : primal::element_corners(m(), ref(c)))
        if (outside[primal::index_cast<std::size_t>(v)]) band_[c] = 1;
    }
    for (std::size_t c = 0; c < cells(); ++c)
      if (band_[c])
        for (Index v : primal::element_corners(m(), ref(c)))
          near[primal::index_cast<std::size_t>(v)] = 1;
    outside.swap(near);
  }
  zone_node_.assign(nv, 0);
  for (std::size_t c = 0; c < cells(); ++c)
    if (in_zone_[c])
      for (Index v : primal::element_corners(m(), ref(c)))
        zone_node_[primal::index_cast<std::size_t>(v)] = 1;
  rep_.zone_cells = static_cast<std::int64_t>(std::count(in_zone_.begin(), in_zone_.end(), 1));
  rep_.rings = rings;
}

// On the zone rank: the zone conformed, grown (rings doubled) until its outer two rings come out
// as plain dicing, bit for bit. A failure is kept for share_zone to raise on every rank alike.
void Distributor::conform_zone() {
  try {
    for (;;) {
      primal::Submodel zone = primal::extract_submodel(m(), in_zone_);
      // Verified as the options say. Local verification's premise holds on the zone, a part of
      // an input that passed the read-time check: its faces are shared by at most two cells and
      // it covers its region once (its cut, unlike a model's boundary, may be non-manifold, which
      // piece_ok does not judge); verify() checks around the cut whole.
      conform::ConformOptions zone_options = options_.conform;
      conform::ConformResult r = conform::conform(std::move(zone.model), zone_options);
      // The band diced alone must be found in the zone's output, node for node (its points, all
      // distinct, looked for among the zone's).
      const primal::Submodel b = primal::extract_submodel(m(), band_);
      std::unordered_set<PointBits, PointBitsHash> band;
      for (const Point& p : primal::dice_model(b.model).points) band.insert(bits(p));
      for (const Point& p : r.model.points) band.erase(bits(p));
      if (band.empty()) {
        zone_out_ = std::move(r.model);
        zone_first_ = 0, zone_last_ = zone_out_.hexes.size();
        rep_.zone = std::move(r);
        rep_.zone.model = {};
        return;
      }
      if (rings_ * 2 > options_.max_rings)
        throw TopologyError("geode_mpi: the transition reaches past " + std::to_string(rings_) +
                            " rings of elements around the interface");
      select_zone(rings_ * 2);
    }
  } catch (const InvalidInput& e) {
    zone_failure_kind_ = 1, zone_failure_ = e.what();
  } catch (const TopologyError& e) {
    zone_failure_kind_ = 2, zone_failure_ = e.what();
  } catch (const std::exception& e) {
    zone_failure_kind_ = 3, zone_failure_ = e.what();
  }
}

// The zone rank's load per child of a zone element, against 1 per diced hex elsewhere: the
// zone's output per child (1.2 on bench_mpi's half 68) with its conform, the check around the
// cut and writing on one rank. Tuned on half 68, 2 ranks: rank 0 waits about 0.6-0.7 s for the
// zone rank whether this is 1.8 or 2.6 (the zone's conform, 1.9 s, is what it waits for; the
// same wall time), so it balances the ranks' peaks instead: 1.8, 2.0, 2.3 and 2.6 gave
// 572 / 536, 595 / 556, 605 / 544 and 617 / 537 MiB (rank 0 / the zone rank).
constexpr double kZoneLoad = 1.8;

// Per flat element its rank: the input's own partition, or METIS's on rank 0 (the elements
// weighted by the hexes they dice into, the zone's elements only 1: the zone rank's share made
// smaller by the zone's load), sent to the others; the zone rank takes it after the zone.
void Distributor::partition() {
  part_.assign(cells(), 0);
  if (!options_.partition.empty()) {  // the input's own, per input element
    const auto in = primal::element_offsets(input_);
    if (options_.partition.size() != in.back())
      throw std::invalid_argument("conform_distributed: a partition of " +
                                  std::to_string(options_.partition.size()) +
                                  " elements for a model of " + std::to_string(in.back()));
    for (int r : options_.partition)
      if (r < 0 || r >= size_)
        throw std::invalid_argument("conform_distributed: rank " + std::to_string(r) +
                                    " in a partition for " + std::to_string(size_) + " ranks");
    // The split model: hexes, tets (the input's, then two per pyramid), wedges.
    const auto of = [&](ElementKind kind, std::size_t i) {
      return options_.partition[in[static_cast<std::size_t>(kind)] + i];
    };
    for (std::size_t c = 0; c < cells(); ++c) {
      const auto r = ref(c);
      const auto i = primal::index_cast<std::size_t>(r.index);
      part_[c] =
          r.kind == ElementKind::kTet && i < tet_pyramid_.size() && tet_pyramid_[i] != kInvalidIndex
              ? of(ElementKind::kPyramid, primal::index_cast<std::size_t>(tet_pyramid_[i]))
              : of(r.kind, i);
    }
    return;
  }
  if (size_ == 1) return;
  const int count = primal::index_cast<int>(part_.size());
  if (rank_ == 0) {
    PartitionOptions po;
    po.weight.resize(cells());
    double diced = 0.0, zone = 0.0;
    for (std::size_t c = 0; c < cells(); ++c) {
      const ElementKind kind = ref(c).kind;
      const Index children = primal::index_cast(primal::cell_topology(kind).corners);
      po.weight[c] = in_zone_[c] ? 1 : children;
      (in_zone_[c] ? zone : diced) += children;
    }
    // The zone rank's share of the diced weight: what its zone leaves of the mean load, at least
    // 2 % of it, and never more than an even share (where the zone is nearly the whole model,
    // that floor alone would ask for more than there is to dice: METIS refuses such shares).
    const double load = (diced + kZoneLoad * zone) / size_;
    const double zone_share =
        diced > 0.0 ? std::min(std::max(load - kZoneLoad * zone, 0.02 * load) / diced, 1.0 / size_)
                    : 1.0 / size_;
    po.share.assign(primal::index_cast<std::size_t>(size_), (1.0 - zone_share) / (size_ - 1));
    po.share.back() = zone_share;
    // A failure here is sent as a partition of -1s, so that no rank waits for one that will not
    // come: every rank then throws.
    try {
      if (std::getenv("GEODE_TEST_FAIL_PARTITION"))  // tests/parallel/mpi_verify_test.sh
        throw std::runtime_error("GEODE_TEST_FAIL_PARTITION is set");
      part_ = partition_elements(m(), size_, po);
    } catch (const std::exception& e) {
      partition_failure_ = e.what();
      part_.assign(cells(), -1);
    }
    MPI_Isend(part_.data(), count, MPI_INT, zone_rank(), 0, comm_, &partition_sent_);
  }
  if (rank_ == zone_rank()) {
    MPI_Recv(part_.data(), count, MPI_INT, 0, 0, comm_, MPI_STATUS_IGNORE);
  } else {  // the ranks before it: from rank 0, without waiting for the zone rank
    MPI_Bcast(part_.data(), count, MPI_INT, 0, others_);
  }
  if (count > 0 && part_[0] < 0) {
    if (partition_sent_ != MPI_REQUEST_NULL) MPI_Wait(&partition_sent_, MPI_STATUS_IGNORE);
    throw std::runtime_error(rank_ == 0 ? "the partition failed: " + partition_failure_
                                        : "the partition failed on rank 0");
  }
}

void Distributor::dice() {
  // The file's ids are for messages, and input elements are named only by the zone's conform,
  // done by now (a grown zone is conformed again within it): the model's ids are dropped (where
  // it is this rank's to change) and the piece's, 8 bytes a node and an element beside the
  // dicing (the half 68 bench: rank 0's peak 604 -> 572 MiB).
  drop_ids(changeable());
  std::vector<char> mine(cells(), 0);
  for (std::size_t c = 0; c < cells(); ++c) mine[c] = part_[c] == rank_ && !in_zone_[c];
  own_ = primal::extract_submodel(m(), mine);
  drop_ids(&own_.model);
  // What the numbering reads of the model; then, with a way to have it again, the model goes
  // before dicing (the half 68 bench: 61 MiB freed on rank 0, whose peak, 572 -> 561 MiB, is
  // now in the numbering and assembly).
  node_users_.assign(m().points.size(), 0);
  for (std::size_t c = 0; c < cells(); ++c)
    if (!in_zone_[c])
      for (Index v : primal::element_corners(m(), ref(c)))
        node_users_[primal::index_cast<std::size_t>(v)] |= Mask{1} << part_[c];
  if (options_.reload && changeable()) {
    trim_model();
    trimmed_ = true;
  }
  // The tet children with room for this rank's other output hexes: assembly may make them the
  // output's hex array where they are.
  const std::size_t room =
      zone_last_ - zone_first_ + 8 * own_.model.hexes.size() + 6 * own_.model.wedges.size();
  // The zone rank's points get room for the zone's nodes its zone hexes use, which assembly
  // puts beside them (at most the zone's nodes): a copy of them all, at its peak, otherwise.
  diced_ = primal::dice_model(own_.model, {}, room,
                              zone_out_.hexes.empty() ? 0 : zone_out_.points.size());
  rep_.cells = static_cast<std::int64_t>(std::count(mine.begin(), mine.end(), 1));
  break_for_test();
  // Local verification reads the children against the tables while the dicing data exist.
  if (options_.conform.verify == conform::ConformVerify::kLocal) {
    dicing_ = primal::check_dicing(own_.model, diced_);
    // And the children's corner Jacobians, measured now rather than in verify(): a rank other
    // than the zone rank waits for the zone after dicing, and this fills part of that wait (the
    // half 68 bench, 2 ranks: rank 0 waited 0.81 s, then verified for 0.85 s).
    diced_positive_.clear();
    for (const auto* part : {&diced_.hex_children, &diced_.tet_children, &diced_.wedge_children}) {
      const std::vector<char> p = primal::corner_jacobians_positive(diced_.points, *part);
      diced_positive_.insert(diced_positive_.end(), p.begin(), p.end());
    }
  }
}

// MPI_Bcast of n values of `type` from `root`, in pieces an int can count.
void broadcast(void* data, std::size_t n, MPI_Datatype type, std::size_t size, int root,
               MPI_Comm comm) {
  constexpr std::size_t kPiece = std::size_t{1} << 28;
  for (std::size_t i = 0; i < n; i += kPiece)
    MPI_Bcast(static_cast<char*>(data) + i * size, primal::index_cast<int>(std::min(kPiece, n - i)),
              type, root, comm);
}

// From the zone rank to every rank: the zone's depth and outcome, its points (for matching the
// diced nodes on the cut), block names and sets. A rank that diced a zone since grown dices again.
void Distributor::share_zone() {
  const int root = zone_rank();
  primal::detail::BytePacket packet;
  if (rank_ == root) {
    packet.put(zone_failure_kind_);
    packet.put(zone_failure_);
    packet.put(rings_);
    packet.put(zone_out_.hexes.size());
    packet.put(zone_out_.points.size());
    packet.put(zone_out_.block_names.size());
    for (const auto& [id, name] : zone_out_.block_names) packet.put(id), packet.put(name);
    packet.put(zone_out_.node_sets.size());
    for (const primal::NodeSet& ns : zone_out_.node_sets) {
      packet.put(ns.id), packet.put(ns.name), packet.put(ns.nodes.size());
      for (Index v : ns.nodes) packet.put(v);
    }
    packet.put(zone_out_.side_sets.size());
    for (const primal::SideSet& ss : zone_out_.side_sets) packet.put(ss.id), packet.put(ss.name);
  }
  std::size_t bytes = packet.bytes().size();
  MPI_Bcast(&bytes, 1, MPI_UINT64_T, root, comm_);
  packet.bytes().resize(bytes);
  broadcast(packet.bytes().data(), bytes, MPI_CHAR, 1, root, comm_);
  // Every rank's share of the partition is with it by now.
  MPI_Wait(&partition_sent_, MPI_STATUS_IGNORE);
  const int kind = packet.get<int>();
  const std::string failure = packet.get_string();
  if (kind == 1) throw InvalidInput(failure);
  if (kind == 2) throw TopologyError(failure);
  if (kind != 0) throw std::runtime_error(failure);
  const int rings = packet.get<int>();
  zone_hexes_ = packet.get<std::size_t>();
  const auto points = packet.get<std::size_t>();
  if (rank_ != root) {
    zone_out_.points.resize(points);
    for (auto n = packet.get<std::size_t>(); n > 0; --n) {
      const int id = packet.get<int>();
      zone_out_.block_names[id] = packet.get_string();
    }
    for (auto n = packet.get<std::size_t>(); n > 0; --n) {
      primal::NodeSet ns;
      ns.id = packet.get<int>(), ns.name = packet.get_string();
      ns.nodes.resize(packet.get<std::size_t>());
      for (Index& v : ns.nodes) v = packet.get<Index>();
      zone_out_.node_sets.push_back(std::move(ns));
    }
    for (auto n = packet.get<std::size_t>(); n > 0; --n) {
      primal::SideSet ss;
      ss.id = packet.get<int>(), ss.name = packet.get_string();
      zone_out_.side_sets.push_back(std::move(ss));
    }
  }
  broadcast(zone_out_.points.data(), 3 * points, MPI_DOUBLE, sizeof(double), root, comm_);
  for (int r = options_.rings; r < rings; r *= 2)
    rep_.warnings.push_back("transition zone grown to " + std::to_string(2 * r) + " rings");
  // Grown on the zone rank: this rank's dicing was of a smaller zone. A rank that cannot dice
  // again (its input read again failing) stops every rank, none left waiting for it.
  std::string again;
  if (rank_ != root && rings != rings_) {
    try {
      if (trimmed_) {  // the model was freed before dicing: read again
        reloaded_ = options_.reload();
        take_model(reloaded_);
        if (primal::element_offsets(m()) != offsets_)
          throw std::runtime_error("it is not the model conformed");
        trimmed_ = false;
      }
      select_zone(rings);
      diced_ = primal::DicedModel(), dicing_ = primal::DicingCheck(), own_ = {};
      primal::release(diced_positive_);
      dice();
    } catch (const std::exception& e) {
      again = e.what();
    }
  }
  int failed = again.empty() ? 0 : 1, any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, comm_);
  if (failed)
    throw std::runtime_error("dicing again for a zone grown to " + std::to_string(rings) +
                             " rings: " + again);
  if (any) throw std::runtime_error("another rank could not dice again for the grown zone");
}

// The zone's hexes shared out: each rank but the zone rank, in rank order, takes a run of them
// up to the mean output per rank (none where the zone is small against the diced part, since
// the partition gave the zone rank less to dice), the zone rank the rest; with their blocks and
// their sides in the zone's side sets.
void Distributor::share_zone_hexes() {
  const int root = zone_rank();
  const auto diced = primal::index_cast<std::int64_t>(
      diced_.hex_children.size() + diced_.tet_children.size() + diced_.wedge_children.size());
  std::vector<std::int64_t> every(primal::index_cast<std::size_t>(size_));
  MPI_Allgather(&diced, 1, MPI_INT64_T, every.data(), 1, MPI_INT64_T, comm_);
  const auto nz = primal::index_cast<std::int64_t>(zone_hexes_);
  const std::int64_t mean =
      (std::accumulate(every.begin(), every.end(), std::int64_t{0}) + nz) / size_;
  std::vector<std::size_t> first(every.size() + 1, 0);
  for (std::size_t r = 0; r < every.size(); ++r) {
    const std::int64_t left = nz - primal::index_cast<std::int64_t>(first[r]);
    const std::int64_t take = primal::index_cast<int>(r) == root
                                  ? left
                                  : std::clamp<std::int64_t>(mean - every[r], 0, left);
    first[r + 1] = first[r] + primal::index_cast<std::size_t>(take);
  }
  const auto me = primal::index_cast<std::size_t>(rank_);
  zone_first_ = first[me], zone_last_ = first[me + 1];
  if (rank_ != root) zone_base_ = zone_first_;
  if (first[every.size() - 1] == 0) return;  // all the zone rank's
  // Per rank: its hexes (8 corners), their blocks, and its sides as (set, hex, face).
  std::vector<int> hex_counts(every.size()), side_counts(every.size());
  std::vector<int> hex_displs(every.size()), side_displs(every.size());
  std::vector<Index> sides;
  if (rank_ == root) {
    std::vector<std::vector<Index>> per(every.size());
    for (std::size_t set = 0; set < zone_out_.side_sets.size(); ++set)
      for (const primal::Side& side : zone_out_.side_sets[set].sides) {
        const auto h = primal::index_cast<std::size_t>(side.element.index);
        const auto r = primal::index_cast<std::size_t>(
            std::upper_bound(first.begin(), first.end(), h) - first.begin() - 1);
        per[r].insert(per[r].end(), {primal::index_cast(set), side.element.index, side.face});
      }
    for (std::size_t r = 0; r < every.size(); ++r) {
      hex_counts[r] = primal::index_cast<int>(first[r + 1] - first[r]);
      hex_displs[r] = primal::index_cast<int>(first[r]);
      side_counts[r] = primal::index_cast<int>(per[r].size());
      side_displs[r] = primal::index_cast<int>(sides.size());
      sides.insert(sides.end(), per[r].begin(), per[r].end());
    }
  }
  const int mine = primal::index_cast<int>(zone_last_ - zone_first_);
  std::vector<std::array<Index, 8>> hexes(rank_ == root ? 0 : zone_last_ - zone_first_);
  std::vector<int> blocks(hexes.size());
  MPI_Datatype hex_type;
  MPI_Type_contiguous(8, MPI_INT, &hex_type);
  MPI_Type_commit(&hex_type);
  MPI_Scatterv(zone_out_.hexes.data(), hex_counts.data(), hex_displs.data(), hex_type,
               rank_ == root ? MPI_IN_PLACE : hexes.data(), mine, hex_type, root, comm_);
  MPI_Type_free(&hex_type);
  MPI_Scatterv(zone_out_.hex_block.data(), hex_counts.data(), hex_displs.data(), MPI_INT,
               rank_ == root ? MPI_IN_PLACE : blocks.data(), mine, MPI_INT, root, comm_);
  int count = 0;
  MPI_Scatter(side_counts.data(), 1, MPI_INT, &count, 1, MPI_INT, root, comm_);
  std::vector<Index> got(primal::index_cast<std::size_t>(count));
  MPI_Scatterv(sides.data(), side_counts.data(), side_displs.data(), MPI_INT,
               rank_ == root ? MPI_IN_PLACE : got.data(), count, MPI_INT, root, comm_);
  if (rank_ == root) return;
  zone_out_.hexes = std::move(hexes);
  zone_out_.hex_block = std::move(blocks);
  for (std::size_t k = 0; k < got.size(); k += 3)
    zone_out_.side_sets[primal::index_cast<std::size_t>(got[k])].sides.push_back(
        {{ElementKind::kHex, got[k + 1]}, static_cast<int>(got[k + 2])});
}

// Test hook (docs/cli.md): GEODE_TEST_BREAK_DICED_HEX=N swaps the first two corners of this
// rank's N-th diced hex (1-based; hex children, then tet and wedge children), as a faulty
// dicing would: both --verify modes must find it on every rank that has one
// (tests/parallel/mpi_verify_test.sh).
void Distributor::break_for_test() {
  const char* text = std::getenv("GEODE_TEST_BREAK_DICED_HEX");
  if (!text || !*text) return;
  const long n = std::strtol(text, nullptr, 10);
  std::size_t k = n >= 1 ? static_cast<std::size_t>(n - 1) : ~std::size_t{0};
  for (auto* part : {&diced_.hex_children, &diced_.tet_children, &diced_.wedge_children}) {
    if (k < part->size()) {
      std::swap((*part)[k][0], (*part)[k][1]);
      return;
    }
    k -= std::min(k, part->size());
  }
}

// Global ids: see the header.
void Distributor::number() {
  const std::int64_t zone_nodes = primal::index_cast<std::int64_t>(zone_out_.points.size());
  zone_nodes_ = zone_nodes;
  // Per model node: the ranks whose elements outside the zone use it (dice() made it).
  const std::vector<Mask> uses = std::move(node_users_);
  trim_model();
  const std::size_t nd = diced_.points.size();
  diced_gid_.assign(nd, -1);
  diced_shared_.clear();
  // Origins in model numbers (own_.node ascends, so normalized keys stay sorted), made when
  // read: only the candidates' are read again (a copy of them all was 16 B a diced node at the
  // numbering's peak).
  const auto key = [&](std::size_t i) {
    FaceKey r = primal::kNoOrigin;
    const FaceKey& o = diced_.origin[i];
    for (std::size_t k = 0; k < 4 && o[k] != kInvalidIndex; ++k)
      r[k] = own_.node[primal::index_cast<std::size_t>(o[k])];
    return r;
  };
  // A diced node made from zone nodes alone takes the zone's node at its position: those few
  // (the cut's) by position, the zone's points looked up among them.
  {
    std::unordered_map<PointBits, std::size_t, PointBitsHash> on_zone;
    for (std::size_t i = 0; i < nd; ++i) {
      const FaceKey& o = diced_.origin[i];
      bool in_zone = o[0] != kInvalidIndex;  // not a cell centre
      for (std::size_t k = 0; k < 4 && o[k] != kInvalidIndex && in_zone; ++k)
        in_zone = zone_node_[primal::index_cast<std::size_t>(
            own_.node[primal::index_cast<std::size_t>(o[k])])];
      if (in_zone) on_zone.emplace(bits(diced_.points[i]), i);
    }
    for (std::size_t z = 0; z < zone_out_.points.size() && !on_zone.empty(); ++z)
      if (const auto it = on_zone.find(bits(zone_out_.points[z])); it != on_zone.end())
        diced_gid_[it->second] = primal::index_cast<std::int64_t>(z);
  }
  // The zone's points: the zone rank's and those holding zone hexes need them for assembly.
  if (zone_last_ == zone_first_) primal::release(zone_out_.points);
  std::vector<std::vector<std::size_t>> candidates(primal::index_cast<std::size_t>(size_));
  for (std::size_t i = 0; i < nd; ++i) {
    const FaceKey& o = diced_.origin[i];
    if (o[0] == kInvalidIndex || diced_gid_[i] >= 0) continue;  // a cell centre; the zone's
    Mask holders = ~Mask{0};
    for (std::size_t k = 0; k < 4 && o[k] != kInvalidIndex; ++k)
      holders &=
          uses[primal::index_cast<std::size_t>(own_.node[primal::index_cast<std::size_t>(o[k])])];
    holders &= ~(Mask{1} << rank_);
    for (int q = 0; q < size_; ++q)
      if (holders >> q & 1) candidates[primal::index_cast<std::size_t>(q)].push_back(i);
  }
  // Exchange the candidates' origins with each rank that may hold them; the nodes in both lists
  // are the ones shared.
  const auto key_less = [&](std::size_t a, std::size_t b) { return key(a) < key(b); };
  std::vector<int> send_counts(primal::index_cast<std::size_t>(size_)),
      recv_counts(send_counts.size());
  std::vector<Index> send;
  for (int q = 0; q < size_; ++q) {
    auto& c = candidates[primal::index_cast<std::size_t>(q)];
    std::sort(c.begin(), c.end(), key_less);
    for (std::size_t i : c) {
      const FaceKey k = key(i);
      send.insert(send.end(), k.begin(), k.end());
    }
    send_counts[primal::index_cast<std::size_t>(q)] = static_cast<int>(c.size() * 4);
  }
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm_);
  std::vector<int> sd(send_counts.size()), rd(send_counts.size());
  std::exclusive_scan(send_counts.begin(), send_counts.end(), sd.begin(), 0);
  std::exclusive_scan(recv_counts.begin(), recv_counts.end(), rd.begin(), 0);
  std::vector<Index> recv(primal::index_cast<std::size_t>(rd.back() + recv_counts.back()));
  MPI_Alltoallv(send.data(), send_counts.data(), sd.data(), MPI_INT, recv.data(),
                recv_counts.data(), rd.data(), MPI_INT, comm_);
  std::vector<std::vector<std::size_t>> shared(primal::index_cast<std::size_t>(size_));
  for (int q = 0; q < size_; ++q) {
    const auto& c = candidates[primal::index_cast<std::size_t>(q)];
    const Index* theirs = recv.data() + rd[primal::index_cast<std::size_t>(q)];
    const std::size_t n =
        primal::index_cast<std::size_t>(recv_counts[primal::index_cast<std::size_t>(q)]) / 4;
    std::size_t j = 0;
    for (std::size_t i : c) {
      const FaceKey mine = key(i);
      FaceKey k{};
      while (j < n && (std::copy_n(theirs + 4 * j, 4, k.begin()), k < mine)) ++j;
      if (j < n && k == mine) {
        shared[primal::index_cast<std::size_t>(q)].push_back(i);
        diced_shared_.emplace_back(i, Mask{1} << q);
      }
    }
  }
  join_holders(diced_shared_);
  for (auto& [i, mask] : diced_shared_) mask |= Mask{1} << rank_;
  const auto owner = [&](std::size_t i) {  // a shared node's lowest holder
    return std::countr_zero(
        std::lower_bound(diced_shared_.begin(), diced_shared_.end(), std::pair{i, Mask{0}})
            ->second);
  };
  // This rank's own diced nodes (not the zone's, lowest holder here) numbered in diced order;
  // those a lower rank numbers are marked, to take its ids below.
  constexpr std::int64_t kTheirs = -2;
  for (const auto& [i, mask] : diced_shared_)
    if (std::countr_zero(mask) != rank_) diced_gid_[i] = kTheirs;
  const std::int64_t owned = std::count(diced_gid_.begin(), diced_gid_.end(), -1);
  std::int64_t first = 0, total = 0;
  MPI_Exscan(&owned, &first, 1, MPI_INT64_T, MPI_SUM, comm_);
  if (rank_ == 0) first = 0;
  MPI_Allreduce(&owned, &total, 1, MPI_INT64_T, MPI_SUM, comm_);
  out_.global_nodes = zone_nodes + total;
  std::int64_t next = zone_nodes + first;
  owned_first_ = next, owned_ = owned;
  for (std::int64_t& g : diced_gid_)
    if (g == -1) g = next++;
  // The owners send the ids of the shared nodes (numbered here by now), in the shared lists'
  // order.
  std::vector<std::int64_t> ids;
  for (int q = 0; q < size_; ++q) {
    std::size_t n = 0;
    for (std::size_t i : shared[primal::index_cast<std::size_t>(q)])
      if (diced_gid_[i] >= 0) ids.push_back(diced_gid_[i]), ++n;
    send_counts[primal::index_cast<std::size_t>(q)] = static_cast<int>(n);
  }
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm_);
  std::exclusive_scan(send_counts.begin(), send_counts.end(), sd.begin(), 0);
  std::exclusive_scan(recv_counts.begin(), recv_counts.end(), rd.begin(), 0);
  std::vector<std::int64_t> got(primal::index_cast<std::size_t>(rd.back() + recv_counts.back()));
  MPI_Alltoallv(ids.data(), send_counts.data(), sd.data(), MPI_INT64_T, got.data(),
                recv_counts.data(), rd.data(), MPI_INT64_T, comm_);
  for (int q = 0; q < size_; ++q) {
    std::size_t j = primal::index_cast<std::size_t>(rd[primal::index_cast<std::size_t>(q)]);
    for (std::size_t i : shared[primal::index_cast<std::size_t>(q)])
      if (diced_gid_[i] == kTheirs && owner(i) == q) diced_gid_[i] = got[j++];
  }
  // Zone nodes: held by the ranks owning a zone hex on them or a diced node at them.
  zone_holders_.assign(primal::index_cast<std::size_t>(zone_nodes), 0);
  for (std::size_t h = zone_first_; h < zone_last_; ++h)
    for (Index v : zone_out_.hexes[h - zone_base_])
      zone_holders_[primal::index_cast<std::size_t>(v)] |= Mask{1} << rank_;
  for (std::size_t i = 0; i < nd; ++i)
    if (diced_gid_[i] >= 0 && diced_gid_[i] < zone_nodes)
      zone_holders_[primal::index_cast<std::size_t>(diced_gid_[i])] |= Mask{1} << rank_;
  MPI_Allreduce(MPI_IN_PLACE, zone_holders_.data(), primal::index_cast<int>(zone_holders_.size()),
                MPI_UINT64_T, MPI_BOR, comm_);
  // Hexes: the zone's first, then the diced ones rank by rank.
  const std::int64_t zone_hexes = primal::index_cast<std::int64_t>(zone_hexes_);
  const std::int64_t diced_hexes = static_cast<std::int64_t>(
      diced_.hex_children.size() + diced_.tet_children.size() + diced_.wedge_children.size());
  std::int64_t hex_first = 0, hex_total = 0;
  MPI_Exscan(&diced_hexes, &hex_first, 1, MPI_INT64_T, MPI_SUM, comm_);
  if (rank_ == 0) hex_first = 0;
  MPI_Allreduce(&diced_hexes, &hex_total, 1, MPI_INT64_T, MPI_SUM, comm_);
  diced_hex_first_ = zone_hexes + hex_first;
  out_.global_hexes = zone_hexes + hex_total;
  rep_.zone_hexes = static_cast<std::int64_t>(zone_last_ - zone_first_);
  rep_.diced_hexes = diced_hexes;
}

// This rank's hexes (its zone hexes and its diced ones) over its nodes, ascending global id.
// Memory: the dicing data are released as the output takes them over (points and origins once
// the output's points and node sets are made, each part's children once its hexes are placed),
// so that the dicing and the output are never whole side by side.
void Distributor::assemble() {
  const std::size_t nd = diced_.points.size();
  const std::int64_t zone_nodes = zone_nodes_;
  // The nodes: the diced ones and the zone's that this rank's zone hexes use and no diced node
  // here took; the diced points get room for the latter now, before the output's arrays exist
  // (they become the output's points in place).
  std::vector<char> zone_only(
      zone_last_ > zone_first_ ? primal::index_cast<std::size_t>(zone_nodes) : 0, 0);
  for (std::size_t h = zone_first_; h < zone_last_; ++h)
    for (Index v : zone_out_.hexes[h - zone_base_])
      zone_only[primal::index_cast<std::size_t>(v)] = 1;
  if (!zone_only.empty())
    for (std::int64_t g : diced_gid_)
      if (g < zone_nodes) zone_only[primal::index_cast<std::size_t>(g)] = 0;
  const auto extra =
      primal::index_cast<std::size_t>(std::count(zone_only.begin(), zone_only.end(), 1));
  diced_.points.reserve(nd + extra);
  // The local nodes, ascending global id: those below the run this rank numbered (the zone's
  // and lower ranks'), the run, those above it (higher ranks'). Only those outside the run are
  // listed here; the whole list waits for list_node_ids, past assembly's and verification's
  // peak.
  const std::int64_t run_end = owned_first_ + owned_;
  for (std::int64_t g : diced_gid_)
    if (g < owned_first_)
      low_ids_.push_back(g);
    else if (g >= run_end)
      high_ids_.push_back(g);
  for (std::size_t v = 0; v < zone_only.size(); ++v)
    if (zone_only[v]) low_ids_.push_back(primal::index_cast<std::int64_t>(v));
  primal::release(zone_only);
  for (auto* ids : {&low_ids_, &high_ids_}) {
    std::sort(ids->begin(), ids->end());
    ids->erase(std::unique(ids->begin(), ids->end()), ids->end());
  }
  const std::vector<std::int64_t>&low = low_ids_, &high = high_ids_;
  zone_locals_ = primal::index_cast<std::size_t>(
      std::lower_bound(low.begin(), low.end(), zone_nodes) - low.begin());
  const std::size_t nl = low.size() + primal::index_cast<std::size_t>(owned_) + high.size();
  // A global id's local number: the zone's through a table, the run by offset, the few others
  // by search.
  std::vector<Index> zone_local(primal::index_cast<std::size_t>(zone_nodes), kInvalidIndex);
  for (std::size_t l = 0; l < zone_locals_; ++l)
    zone_local[primal::index_cast<std::size_t>(low[l])] = primal::index_cast(l);
  const auto local = [&](std::int64_t g) {
    if (g < zone_nodes) return zone_local[primal::index_cast<std::size_t>(g)];
    if (g < owned_first_)
      return primal::index_cast(std::lower_bound(low.begin(), low.end(), g) - low.begin());
    if (g < run_end) return primal::index_cast(low.size() + (g - owned_first_));
    return primal::index_cast(low.size() + owned_ +
                              (std::lower_bound(high.begin(), high.end(), g) - high.begin()));
  };
  Model& o = out_.model;
  std::vector<Index> diced_local(nd);
  for (std::size_t i = 0; i < nd; ++i) diced_local[i] = local(diced_gid_[i]);
  primal::release(diced_gid_);
  // The diced points become the output's in place. The run this rank numbered keeps the diced
  // order (it was numbered in it), shifted by the nodes numbered elsewhere (the zone's, other
  // ranks'): those few are set aside, then the run is moved from the last node back where the
  // shift is forward and from the first on where it is backward (the shift only falls along
  // the run), so that no point is overwritten before it moves and each is read once, in order.
  o.points = std::move(diced_.points);
  o.points.resize(nl);
  {
    const Index run_first = primal::index_cast(low.size()),
                run_last = primal::index_cast(low.size() + owned_);
    const auto in_run = [&](std::size_t i) {
      return diced_local[i] >= run_first && diced_local[i] < run_last;
    };
    std::vector<std::pair<Index, Point>> aside;
    std::size_t backward = nd;  // the first node of the run that moves backward
    for (std::size_t i = 0; i < nd; ++i)
      if (!in_run(i))
        aside.emplace_back(diced_local[i], o.points[i]);
      else if (backward == nd && primal::index_cast<std::size_t>(diced_local[i]) < i)
        backward = i;
    for (std::size_t i = backward; i-- > 0;)
      if (in_run(i)) o.points[primal::index_cast<std::size_t>(diced_local[i])] = o.points[i];
    for (std::size_t i = backward; i < nd; ++i)
      if (in_run(i)) o.points[primal::index_cast<std::size_t>(diced_local[i])] = o.points[i];
    for (const auto& [l, p] : aside) o.points[primal::index_cast<std::size_t>(l)] = p;
  }
  if (!zone_out_.points.empty())  // the zone nodes no diced node took (the same bits where one did)
    for (std::size_t l = 0; l < zone_locals_; ++l)
      o.points[l] = zone_out_.points[primal::index_cast<std::size_t>(low[l])];
  primal::release(zone_out_.points);  // consumed
  // Shared nodes per neighbour, from the holders of the local nodes other ranks hold too.
  std::vector<std::pair<Index, Mask>> holders;
  for (const auto& [i, mask] : diced_shared_) holders.emplace_back(diced_local[i], mask);
  primal::release(diced_shared_);
  for (std::size_t l = 0; l < zone_locals_; ++l)
    if (const Mask mask = zone_holders_[primal::index_cast<std::size_t>(low[l])];
        mask & ~(Mask{1} << rank_))
      holders.emplace_back(primal::index_cast(l), mask);
  join_holders(holders);
  for (const auto& [l, mask] : holders)
    for (int q = 0; q < size_; ++q)
      if (q != rank_ && (mask >> q & 1)) out_.shared_nodes[q].push_back(l);
  // Sets read the diced numbering: made before the children move, the origins freed after.
  const Model& om = own_.model;
  const std::size_t nh = diced_.hex_children.size(), nt = diced_.tet_children.size();
  const auto diced_sides =
      primal::diced_side_sets(om, diced_, 0, primal::index_cast(nh), primal::index_cast(nh + nt));
  const auto diced_nodes = primal::diced_node_sets(om, diced_, diced_local);
  primal::release(diced_.origin);
  // Hexes in a first order (zone, then diced hex, tet, wedge children), ids ascending in it;
  // placed by block (a stable counting sort: by block, then by id), each written once into the
  // output arrays, with no copy of the hexes beside them.
  const std::size_t first_diced = zone_last_ - zone_first_;
  const std::size_t total = first_diced + nh + nt + diced_.wedge_children.size();
  std::vector<int> block(total);
  for (std::size_t k = 0; k < first_diced; ++k)
    block[k] = zone_out_.hex_block[zone_first_ - zone_base_ + k];
  for (std::size_t k = 0; k < nh; ++k)
    block[first_diced + k] = primal::block_of(om, {ElementKind::kHex, diced_.hex_parent[k]});
  for (std::size_t k = 0; k < nt; ++k)
    block[first_diced + nh + k] = primal::block_of(om, {ElementKind::kTet, diced_.tet_parent[k]});
  for (std::size_t k = 0; k < diced_.wedge_children.size(); ++k)
    block[first_diced + nh + nt + k] =
        primal::block_of(om, {ElementKind::kWedge, diced_.wedge_parent[k]});
  primal::release(diced_.hex_parent, diced_.tet_parent, diced_.wedge_parent);
  std::map<int, Index> next;  // per block: its next output position
  for (int b : block) ++next[b];
  Index start = 0;
  for (auto& [b, n] : next) start += std::exchange(n, start);
  // The output positions of the hexes the side sets name (by their first order, ascending):
  // those only, not a position per hex.
  std::vector<std::size_t> sided;
  for (const primal::SideSet& z : zone_out_.side_sets)
    for (const primal::Side& side : z.sides)
      if (const auto h = primal::index_cast<std::size_t>(side.element.index);
          h >= zone_first_ && h < zone_last_)
        sided.push_back(h - zone_first_);
  for (const primal::SideSet& d : diced_sides)
    for (const primal::Side& side : d.sides)
      sided.push_back(first_diced + primal::index_cast<std::size_t>(side.element.index));
  std::sort(sided.begin(), sided.end());
  sided.erase(std::unique(sided.begin(), sided.end()), sided.end());
  std::vector<Index> sided_at(sided.size());
  const auto position = [&](std::size_t k) {
    return sided_at[primal::index_cast<std::size_t>(
        std::lower_bound(sided.begin(), sided.end(), k) - sided.begin())];
  };
  // Where every tet child is in one block, their output positions are one run: the tet children
  // become the output's hex array, renumbered where they are, the other hexes put around them
  // in the room dicing left (as the serial path does), so the largest part is never copied.
  const bool in_place =
      nt > 0 && std::all_of(block.begin() + static_cast<std::ptrdiff_t>(first_diced + nh),
                            block.begin() + static_cast<std::ptrdiff_t>(first_diced + nh + nt),
                            [&](int b) { return b == block[first_diced + nh]; });
  if (in_place) {
    const int tet_block = block[first_diced + nh];
    std::size_t lo = primal::index_cast<std::size_t>(next[tet_block]);
    for (std::size_t j = 0; j < first_diced + nh; ++j) lo += block[j] == tet_block;
    for (auto& child : diced_.tet_children)
      for (Index& v : child) v = diced_local[primal::index_cast<std::size_t>(v)];
    std::vector<std::array<Index, 8>> hexes = std::move(diced_.tet_children);
    hexes.insert(hexes.begin(), lo, std::array<Index, 8>{});  // within dicing's room
    hexes.resize(total);
    o.hexes = std::move(hexes);
  } else {
    o.hexes.resize(total);
  }
  o.hex_block.resize(total);
  out_.hex_gid.resize(total);
  std::size_t k = 0, sk = 0;  // in the first order; in sided
  auto place = [&](std::int64_t gid) {
    const Index at = next[block[k]]++;
    if (sk < sided.size() && sided[sk] == k) sided_at[sk++] = at;
    ++k;
    const auto p = primal::index_cast<std::size_t>(at);
    o.hex_block[p] = block[k - 1];
    out_.hex_gid[p] = gid;
    return p;
  };
  for (std::size_t h = zone_first_; h < zone_last_; ++h) {
    std::array<Index, 8>& x = o.hexes[place(static_cast<std::int64_t>(h))];
    for (int c = 0; c < 8; ++c) x[c] = local(zone_out_.hexes[h - zone_base_][c]);
  }
  primal::release(zone_out_.hexes);  // consumed, before the children are placed
  for (auto* part : {&diced_.hex_children, &diced_.tet_children, &diced_.wedge_children}) {
    for (const auto& child : *part) {
      std::array<Index, 8>& x =
          o.hexes[place(diced_hex_first_ + static_cast<std::int64_t>(k - first_diced))];
      for (int c = 0; c < 8; ++c) x[c] = diced_local[primal::index_cast<std::size_t>(child[c])];
    }
    primal::release(*part);                        // consumed
    if (part == &diced_.hex_children && in_place)  // the tet children are in place already
      for (std::size_t j = 0; j < nt; ++j)
        place(diced_hex_first_ + static_cast<std::int64_t>(k - first_diced));
  }
  primal::release(block, diced_local, zone_local);
  diced_ = primal::DicedModel();
  o.block_names = m().block_names;
  o.block_names.insert(zone_out_.block_names.begin(), zone_out_.block_names.end());
  // Sets: the zone's (on this rank's nodes and hexes) and the diced ones, by id.
  for (std::size_t s = 0; s < zone_out_.node_sets.size(); ++s) {
    const primal::NodeSet& z = zone_out_.node_sets[s];
    primal::NodeSet ns{z.id, z.name, {}};
    for (Index v : z.nodes) {  // zone nodes: in low's first zone_locals_
      const auto end = low.begin() + static_cast<std::ptrdiff_t>(zone_locals_);
      const auto it = std::lower_bound(low.begin(), end, std::int64_t{v});
      if (it != end && *it == v) ns.nodes.push_back(primal::index_cast(it - low.begin()));
    }
    for (const primal::NodeSet& d : diced_nodes)
      if (d.id == z.id) ns.nodes.insert(ns.nodes.end(), d.nodes.begin(), d.nodes.end());
    std::sort(ns.nodes.begin(), ns.nodes.end());
    ns.nodes.erase(std::unique(ns.nodes.begin(), ns.nodes.end()), ns.nodes.end());
    o.node_sets.push_back(std::move(ns));
  }
  for (std::size_t s = 0; s < zone_out_.side_sets.size(); ++s) {
    const primal::SideSet& z = zone_out_.side_sets[s];
    primal::SideSet ss{z.id, z.name, {}};
    for (const primal::Side& side : z.sides) {
      const auto h = primal::index_cast<std::size_t>(side.element.index);
      if (h >= zone_first_ && h < zone_last_)
        ss.sides.push_back({{ElementKind::kHex, position(h - zone_first_)}, side.face});
    }
    for (const primal::SideSet& d : diced_sides)
      if (d.id == z.id)
        for (const primal::Side& side : d.sides)
          ss.sides.push_back(
              {{ElementKind::kHex,
                position(first_diced + primal::index_cast<std::size_t>(side.element.index))},
               side.face});
    std::sort(ss.sides.begin(), ss.sides.end());
    o.side_sets.push_back(std::move(ss));
  }
  // The global counts.
  std::map<int, std::int64_t> blocks;
  for (int b : o.hex_block) ++blocks[b];
  std::vector<int> ids;
  for (const auto& [id, name] : o.block_names) ids.push_back(id);
  for (int b : zone_out_.hex_block) ids.push_back(b);
  for (const auto& b : own_.model.hex_block) ids.push_back(b);
  for (const auto& b : own_.model.tet_block) ids.push_back(b);
  for (const auto& b : own_.model.wedge_block) ids.push_back(b);
  // Every rank must list the same blocks: the union over ranks.
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  int n = primal::index_cast<int>(ids.size());
  std::vector<int> counts(primal::index_cast<std::size_t>(size_)), displs(counts.size());
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
  std::vector<int> every(primal::index_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(ids.data(), n, MPI_INT, every.data(), counts.data(), displs.data(), MPI_INT,
                 comm_);
  std::sort(every.begin(), every.end());
  every.erase(std::unique(every.begin(), every.end()), every.end());
  std::vector<std::int64_t> local_counts, global_counts(every.size());
  for (int b : every) local_counts.push_back(blocks.count(b) ? blocks[b] : 0);
  MPI_Allreduce(local_counts.data(), global_counts.data(), primal::index_cast<int>(every.size()),
                MPI_INT64_T, MPI_SUM, comm_);
  for (std::size_t k = 0; k < every.size(); ++k)
    out_.global_block_hexes[every[k]] = global_counts[k];
  // A node set's nodes counted once, by their lowest holder.
  std::vector<std::int64_t> set_counts;
  for (const primal::NodeSet& ns : o.node_sets) {
    std::int64_t c = 0;
    for (Index v : ns.nodes) {
      const auto it = std::lower_bound(holders.begin(), holders.end(), std::pair{v, Mask{0}});
      c += it == holders.end() || it->first != v || std::countr_zero(it->second) == rank_;
    }
    set_counts.push_back(c);
  }
  out_.global_node_set_nodes.resize(set_counts.size());
  MPI_Allreduce(set_counts.data(), out_.global_node_set_nodes.data(),
                primal::index_cast<int>(set_counts.size()), MPI_INT64_T, MPI_SUM, comm_);
  set_counts.clear();
  for (const primal::SideSet& ss : o.side_sets)
    set_counts.push_back(primal::index_cast<std::int64_t>(ss.sides.size()));
  out_.global_side_set_sides.resize(set_counts.size());
  MPI_Allreduce(set_counts.data(), out_.global_side_set_sides.data(),
                primal::index_cast<int>(set_counts.size()), MPI_INT64_T, MPI_SUM, comm_);
}

// What holds piece by piece of a hex mesh: nodes in range and finite, no repeated corner, no
// face of three hexes, none seen twice in one order, no corner Jacobian <= 0, the covering at
// the nodes not `exempt`. The boundary, the Euler characteristic and manifoldness are the whole
// mesh's, not a piece's (two pieces may meet at an edge).
bool piece_ok(const primal::HexValidityReport& v, const std::vector<char>& exempt) {
  std::size_t overlapping = 0;
  for (const auto& c : v.overlapping_nodes)
    overlapping += exempt.empty() || !exempt[primal::index_cast<std::size_t>(c.node)];
  return v.out_of_range_hexes.empty() && v.non_finite_nodes.empty() &&
         v.repeated_node_hexes.empty() && v.overshared_faces.empty() &&
         v.misoriented_faces.empty() && v.inverted_hexes.empty() && overlapping == 0;
}

// Every rank's hexes checked as a piece (piece_ok, its shared nodes exempt from the covering),
// and the zone as its conform checked it, as a piece too (its cut is not the model's boundary).
// --verify local (the default), as the serial run verifies: the zone by its conform (locally),
// the diced children against the dicing tables (dice()), the whole check around the hexes on
// the cut (zone nodes a diced hex uses or another rank holds: where nodes were matched by
// position) and every hex's corner Jacobians; --verify full: the zone by its conform and every
// hex of the piece, whole.
// The joined file (--join) can be checked whole with `geode check`.
void Distributor::verify() {
  primal::HexMesh mesh;  // borrowed, not copied
  mesh.points = std::move(out_.model.points);
  mesh.hexes = std::move(out_.model.hexes);
  primal::HexValidityReport v;
  if (options_.conform.verify == conform::ConformVerify::kLocal) {
    // The cut: zone nodes that a diced hex here uses or that another rank holds too.
    const auto zone_hexes = primal::index_cast<std::int64_t>(zone_hexes_);
    std::vector<char> cut(mesh.points.size(), 0);
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
      if (out_.hex_gid[h] >= zone_hexes)
        for (Index n : mesh.hexes[h]) cut[primal::index_cast<std::size_t>(n)] = 1;
    for (const auto& [q, nodes] : out_.shared_nodes)
      for (Index n : nodes) cut[primal::index_cast<std::size_t>(n)] = 1;
    std::fill(cut.begin() + static_cast<std::ptrdiff_t>(zone_locals_), cut.end(), 0);  // zone's
    std::vector<Index> seeds;
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
      for (Index n : mesh.hexes[h])
        if (cut[primal::index_cast<std::size_t>(n)]) {
          seeds.push_back(primal::index_cast(h));
          break;
        }
    // Hexes whose corner Jacobians are known above 0 are not measured again: the diced
    // children measured in dice(), and on the zone rank the zone's hexes when its conform found
    // none inverted (its local verification measured every one; their points keep their bits).
    std::vector<char> positive(mesh.hexes.size(), 0);
    const auto diced = primal::index_cast<std::int64_t>(diced_positive_.size());
    const bool zone_positive = rank_ == zone_rank() && zone_failure_kind_ == 0 &&
                               rep_.zone.validity.inverted_hexes.empty();
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
      const std::int64_t gid = out_.hex_gid[h], d = gid - diced_hex_first_;
      if (d >= 0 && d < diced)
        positive[h] = diced_positive_[primal::index_cast<std::size_t>(d)];
      else if (gid < zone_hexes)
        positive[h] = zone_positive ? 1 : 0;
    }
    primal::release(diced_positive_);
    // The seeds are every hex at a cut node, and what can be wrong there is only how the
    // nodes were matched (nothing near the cut moved: the zone's band came out as plain
    // dicing), so the check at the seeds' own nodes (0 rings) sees every face, edge and
    // covering at a cut node. (Two rings, what smoothing needs, cost the zone rank 0.26 s of
    // its 0.69 s here on the half 68 bench.)
    v = primal::check_validity_around(mesh, seeds, {.rings = 0, .positive = positive});
  } else {
    v = primal::check_validity(mesh);
  }
  out_.model.points = std::move(mesh.points);
  out_.model.hexes = std::move(mesh.hexes);
  std::vector<char> shared(out_.model.points.size(), 0);
  for (const auto& [q, nodes] : out_.shared_nodes)
    for (Index n : nodes) shared[primal::index_cast<std::size_t>(n)] = 1;
  const bool piece = piece_ok(v, shared);
  if (!piece) rep_.warnings.push_back("rank " + std::to_string(rank_) + ": " + v.summary());
  if (!dicing_.ok())
    rep_.warnings.push_back("rank " + std::to_string(rank_) + ": " + dicing_.summary());
  const bool zone_ok = piece_ok(rep_.zone.validity, {});
  if (!zone_ok) rep_.warnings.push_back("the transition zone: " + rep_.zone.validity.summary());
  int mine = piece && dicing_.ok() && zone_ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, comm_);
  rep_.valid = all == 1;
}

}  // namespace

RankMesh conform_distributed(const primal::Model& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report) {
  DistributedReport local;
  return Distributor(input, options, comm, report ? *report : local).run();
}

RankMesh conform_distributed(primal::Model&& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report) {
  DistributedReport local;
  return Distributor(input, options, comm, report ? *report : local, &input).run();
}

primal::InputCheckOptions shared_input_check(MPI_Comm comm) {
  primal::InputCheckOptions o;
  MPI_Comm_rank(comm, &o.share);
  MPI_Comm_size(comm, &o.shares);
  o.exchange = [comm, shares = o.shares](const std::vector<char>& mine) {
    // Faces used once and findings: the boundary, far below 2 GiB (an int's count) in all;
    // past it every rank throws alike.
    constexpr std::int64_t kMax = std::numeric_limits<int>::max();
    const int n = std::cmp_less_equal(mine.size(), kMax) ? static_cast<int>(mine.size()) : -1;
    std::vector<int> counts(primal::index_cast<std::size_t>(shares)), displs(counts.size());
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
    std::int64_t total = 0;
    for (std::size_t r = 0; r < counts.size(); ++r) {
      if (counts[r] < 0 || total + counts[r] > kMax)
        throw std::runtime_error("the covering check's pairing exceeds 2 GiB across the ranks");
      displs[r] = static_cast<int>(total), total += counts[r];
    }
    std::vector<char> all(primal::index_cast<std::size_t>(total));
    MPI_Allgatherv(mine.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR,
                   comm);
    return all;
  };
  return o;
}

}  // namespace geode::parallel
