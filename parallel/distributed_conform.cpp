#include <geode/parallel/distributed_conform.hpp>

#include <geode/parallel/detail/distributor.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <thread>

#include <geode/conform/reference_template.hpp>
#include <geode/conform/report.hpp>

namespace geode::parallel {
namespace detail {

// Diced children the yardstick measures in the time the zone's two reference templates take to
// build (bench_mpi half 68: 0.26 s for them, 0.104 us a child with the scaled Jacobian four
// corners at a time; 900,000 at 0.29 us before, which left the zone rank waiting for rank 0).
constexpr double kReferenceChildren = 2500000.0;

// The serial run's yardstick is the lowest element of each kind diced alone over the whole
// model: each rank measures a run of the elements (a contiguous one: no partition is needed
// yet, and neighbours share nodes in memory), and the lowest of each kind and block outside the
// rings selected before (select_rings) join the zone. conform's aims measure against the lowest
// element over its model, tets as relaxed near the transition: the zone's own (its rings hold
// every tet the relaxation moves) and, outside it, as given. With the lowest overall instead,
// the zone's aims were higher than the serial run's where the lowest tet as relaxed lay outside
// the rings (Gmsh's 7-block ball in tet potting, n = 4, four rings: 0.1312 against 0.1212, one
// node smoothed 3e-5 elsewhere). A zone grown later, or by inverted elements (which the serial
// run smooths wherever they are: they seed the zone), holds them still, and what lies outside
// it is no lower.
//
// The zone rank builds the reference templates its zone's conform will take from their cache
// (conform/reference_template.hpp) here, beside its share, and measures that many children fewer
// than the others: they are the one stage of its critical path that does not wait for the zone
// (with 2 ranks, rank 0 then waits that much less for it).
void Distributor::yardstick() {
  // Per kind and block: conform compares each block's minimum with its own elements diced alone
  // (where a hex part's transition spoils a block, the tets' layer is tried), so the zone holds
  // the lowest of each block too. The blocks, ascending, are the same on every rank.
  struct Low {
    double value;
    int cell;
  };
  std::array<std::vector<int>, 3> blocks;
  const std::array<ElementKind, 3> kinds{ElementKind::kHex, ElementKind::kTet, ElementKind::kWedge};
  std::array<const std::vector<int>*, 3> ids{};  // per kind, each element's block (empty: default)
  for (std::size_t k = 0; k < 3; ++k) {
    const auto kind = kinds[k];
    ids[k] = &primal::element_blocks(m(), kind);
    if (ids[k]->empty() && primal::element_count(m(), kind) > 0)
      blocks[k].push_back(primal::default_block(kind));
    for (int id : *ids[k])  // a block's elements come in runs: few to sort
      if (blocks[k].empty() || blocks[k].back() != id) blocks[k].push_back(id);
    std::sort(blocks[k].begin(), blocks[k].end());
    blocks[k].erase(std::unique(blocks[k].begin(), blocks[k].end()), blocks[k].end());
  }
  std::array<std::size_t, 4> first{};  // kind k's slots: [first[k], first[k + 1])
  for (std::size_t k = 0; k < 3; ++k) first[k + 1] = first[k] + blocks[k].size();
  std::vector<Low> low(first[3], Low{2.0, std::numeric_limits<int>::max()}), all(first[3]);
  std::vector<int> inverted;
  // Element i of kind k, diced alone: v.
  const auto consider = [&](std::size_t k, std::size_t i, double v) {
    const std::size_t c = offsets_[static_cast<std::size_t>(kinds[k])] + i;
    const int cell = primal::index_cast<int>(c);
    if (level_[c] < 0) {
      const int block = ids[k]->empty() ? blocks[k].front() : (*ids[k])[i];
      Low& l = low[first[k] + static_cast<std::size_t>(
                                  std::lower_bound(blocks[k].begin(), blocks[k].end(), block) -
                                  blocks[k].begin())];
      if (v < l.value) l = {v, cell};  // in order: ties to the first
    }
    if (v <= 0.0) inverted.push_back(cell);
  };
  const std::size_t nh = m().hexes.size(), nt = m().tets.size(), nw = m().wedges.size();
  // Ranks [0, r) measure this fraction of each kind's elements.
  std::vector<double> before(primal::index_cast<std::size_t>(size_) + 1, 0.0);
  std::jthread references_built;  // joined before the ranks meet below
  {
    const double children = 8.0 * static_cast<double>(nh) + 4.0 * static_cast<double>(nt) +
                            6.0 * static_cast<double>(nw);
    const bool references = size_ > 1 && nt > 0 && nh + nw > 0;
    // At least a tenth of an even share, so that a small model stays shared.
    const double zone_share = references
                                  ? std::max(1.0 / size_ - kReferenceChildren * (size_ - 1) /
                                                               size_ / std::max(children, 1.0),
                                             0.1 / size_)
                                  : 1.0 / size_;
    for (int r = 0; r < size_; ++r)
      before[primal::index_cast<std::size_t>(r) + 1] =
          r + 1 == size_ ? 1.0 : (r + 1) * (1.0 - zone_share) / (size_ - 1);
    // A failed build is left to the zone's conform, which raises it as a zone failure on
    // every rank.
    if (references && rank_ == zone_rank())
      references_built = conform::build_reference_templates_ahead(options_.conform.template_box);
  }
  const auto share = [&](std::size_t n, int r) {
    return r >= size_
               ? n
               : std::min(n, static_cast<std::size_t>(static_cast<double>(n) *
                                                      before[primal::index_cast<std::size_t>(r)]));
  };
  {
    const std::size_t a = share(nh, rank_), b = share(nh, rank_ + 1);
    const auto h =
        primal::diced_scaled_jacobian_per_cell(m().points, std::span(m().hexes.data() + a, b - a));
    for (std::size_t i = 0; i < h.size(); ++i) consider(0, a + i, h[i]);
  }
  {
    const std::size_t a = share(nt, rank_), b = share(nt, rank_ + 1);
    const auto t =
        primal::diced_scaled_jacobian_per_cell(m().points, std::span(m().tets.data() + a, b - a));
    for (std::size_t i = 0; i < t.size(); ++i) consider(1, a + i, t[i]);
  }
  for (std::size_t i = share(nw, rank_); i < share(nw, rank_ + 1); ++i)
    consider(2, i,
             primal::diced_wedge_min_scaled_jacobian(m().points, std::span(&m().wedges[i], 1)));
  if (references_built.joinable()) references_built.join();
  MPI_Allreduce(low.data(), all.data(), primal::index_cast<int>(low.size()), MPI_DOUBLE_INT,
                MPI_MINLOC, comm_);
  for (const auto& a : all)
    if (a.value <= 1.5) lowest_.push_back(primal::index_cast<std::size_t>(a.cell));
  const std::vector<int> every = gather_all(inverted, comm_);
  inverted_.assign(every.begin(), every.end());
  std::sort(inverted_.begin(), inverted_.end());
}

// The elements within `rings` node rings of the seeds (level_): nodes used by a hex and a tet,
// inverted elements' nodes (once the yardstick found them) and wedges'. The same on every rank.
void Distributor::select_rings(int rings) {
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
}

// The zone: the rings and the lowest elements (in_zone_), its outer two rings (band_) and its
// nodes (zone_node_). The same on every rank.
void Distributor::finish_zone() {
  const std::size_t nv = m().points.size();
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
  rep_.zone_cells =
      primal::index_cast<std::int64_t>(std::count(in_zone_.begin(), in_zone_.end(), 1));
  rep_.rings = rings_;
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
      if (options_.zone_progress) zone_options.progress = options_.zone_progress;
      // The zone's tets split from the input's pyramids come after its own (the split model's
      // order, which extract_submodel keeps): conform's volume warning counts them as pyramids.
      const auto& zone_tets = zone.element[static_cast<std::size_t>(ElementKind::kTet)];
      zone_options.split_tets_from = primal::index_cast(
          std::find_if(zone_tets.begin(), zone_tets.end(),
                       [&](Index t) {
                         const auto i = primal::index_cast<std::size_t>(t);
                         return i < tet_pyramid_.size() && tet_pyramid_[i] != kInvalidIndex;
                       }) -
          zone_tets.begin());
      conform::ConformResult r;
      run_on_cpus(zone_cpus_, options_.zone_threads,
                  [&] { r = conform::conform(std::move(zone.model), zone_options); });
      // The band diced alone must be found in the zone's output, node for node (its points, all
      // distinct, looked for among the zone's).
      const primal::Submodel b = primal::extract_submodel(m(), band_);
      const std::vector<Point> diced = primal::dice_model(b.model).points;
      PointBitsMap band(diced.size());
      for (std::size_t i = 0; i < diced.size(); ++i) band.emplace(bits(diced[i]), i);
      std::vector<char> found(diced.size(), 0);
      std::size_t missing = band.size();
      for (const Point& p : r.model.points)
        if (const std::size_t* i = band.find(bits(p)); i && !found[*i]) found[*i] = 1, --missing;
      if (missing == 0) {
        zone_out_ = std::move(r.model);
        zone_first_ = 0, zone_last_ = zone_out_.hexes.size();
        // Its findings name the zone's own output, numbered as written; none where the zone
        // holds as a piece (verify()): its cut alone is not closed or manifold (--verify full).
        if (piece_ok(r.validity, {}) && r.dicing.ok() &&
            conform::output_min_scaled_jacobian(r) > 0.0) {
          r.warnings.erase(r.warnings.begin(),
                           r.warnings.begin() + static_cast<std::ptrdiff_t>(r.findings));
          r.findings = 0;
        }
        for (std::size_t i = 0; i < r.findings; ++i)
          r.warnings[i] = "in the transition zone (numbered in its own output): " + r.warnings[i];
        rep_.zone = std::move(r);
        rep_.zone.model = {};
        return;
      }
      if (rings_ * 2 > options_.max_rings)
        throw TopologyError("geode_mpi: the transition reaches past " + std::to_string(rings_) +
                            " rings of elements around the interface");
      select_rings(rings_ * 2);
      finish_zone();
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
// cut and writing on one rank. Tuned on half 68, 2 ranks: rank 0 waits 0.19-0.29 s for the zone
// rank with 1.8 and 0.07-0.17 s with 2.6, for the same wall time (the zone's conform, on both
// cores while rank 0 partitions and dices, is what it waits for), so it balances the ranks'
// peaks instead: 1.8, 2.2, 2.6 and 3.4 gave 562 / 515, 576 / 498, 587 / 483 and 617 / 457 MiB
// (rank 0 / the zone rank; 0.6 x the serial peak is 590).
constexpr double kZoneLoad = 1.8;

// Every rank's face pairs to rank 0, in rank order (each rank's are the faces whose lowest node
// is in its run: every interior face once), as flat elements of the model the stages read: a
// pyramid split in two tets stands as its first, the two joined. When every rank has them and
// their count fits MPI's ints.
void Distributor::gather_pairs() {
  using Pair = std::array<Index, 2>;
  std::vector<Pair> none, &mine = options_.element_pairs ? *options_.element_pairs : none;
  if (!options_.partition.empty() || size_ == 1) return primal::release(mine);
  const std::int64_t given[2] = {options_.element_pairs ? 1 : 0,
                                 primal::index_cast<std::int64_t>(mine.size())};
  std::vector<std::int64_t> all(2 * primal::index_cast<std::size_t>(size_));
  MPI_Allgather(given, 2, MPI_INT64_T, all.data(), 2, MPI_INT64_T, comm_);
  std::int64_t total = 0;
  bool every = true;
  for (int r = 0; r < size_; ++r) {
    every = every && all[2 * primal::index_cast<std::size_t>(r)] == 1;
    total += all[2 * primal::index_cast<std::size_t>(r) + 1];
  }
  if (every && total <= std::numeric_limits<int>::max()) {
    MPI_Datatype pair;
    MPI_Type_contiguous(static_cast<int>(sizeof(Pair)), MPI_BYTE, &pair);
    MPI_Type_commit(&pair);
    std::vector<int> counts(primal::index_cast<std::size_t>(size_)),
        displs(primal::index_cast<std::size_t>(size_));
    for (int r = 0, at = 0; r < size_; ++r) {
      counts[primal::index_cast<std::size_t>(r)] =
          static_cast<int>(all[2 * primal::index_cast<std::size_t>(r) + 1]);
      displs[primal::index_cast<std::size_t>(r)] = at;
      at += counts[primal::index_cast<std::size_t>(r)];
    }
    if (rank_ == 0) pairs_.resize(primal::index_cast<std::size_t>(total));
    MPI_Gatherv(mine.data(), static_cast<int>(mine.size()), pair, pairs_.data(), counts.data(),
                displs.data(), pair, 0, comm_);
    MPI_Type_free(&pair);
  }
  primal::release(mine);
  if (pairs_.empty() || tet_pyramid_.empty()) return;
  // The input's flat numbers (pyramids among them) as the split model's.
  const auto in = primal::element_offsets(input_);
  std::vector<Index> first_tet(input_.pyramids.size(), kInvalidIndex);
  for (std::size_t t = 0; t < tet_pyramid_.size(); ++t)
    if (const Index p = tet_pyramid_[t]; p != kInvalidIndex) {
      Index& first = first_tet[primal::index_cast<std::size_t>(p)];
      const Index cell =
          primal::index_cast(offsets_[static_cast<std::size_t>(ElementKind::kTet)] + t);
      if (first == kInvalidIndex)
        first = cell;
      else
        pairs_.push_back({first, cell});
    }
  const auto split = [&](Index f) {
    const auto i = primal::index_cast<std::size_t>(f);
    for (ElementKind kind : {ElementKind::kHex, ElementKind::kTet, ElementKind::kWedge})
      if (i >= in[static_cast<std::size_t>(kind)] && i < in[static_cast<std::size_t>(kind) + 1])
        return primal::index_cast(offsets_[static_cast<std::size_t>(kind)] + i -
                                  in[static_cast<std::size_t>(kind)]);
    return first_tet[i - in[static_cast<std::size_t>(ElementKind::kPyramid)]];
  };
  const std::size_t given_pairs = primal::index_cast<std::size_t>(total);
  for (std::size_t k = 0; k < given_pairs; ++k)
    for (Index& e : pairs_[k]) e = split(e);
}

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
      if (!pairs_.empty()) po.graph = graph_of_pairs(cells(), pairs_);
      primal::release(pairs_);
      part_ = partition_elements(m(), size_, std::move(po));
    } catch (const std::exception& e) {
      partition_failure_ = e.what();
      part_.assign(cells(), -1);
    }
    MPI_Isend(part_.data(), count, MPI_INT, zone_rank(), 0, comm_, &partition_sent_);
  }
  if (rank_ == zone_rank()) {
    MPI_Recv(part_.data(), count, MPI_INT, 0, 0, comm_, MPI_STATUS_IGNORE);
  } else {  // the ranks before it: from rank 0, without waiting for the zone rank
    MPI_Request received;
    MPI_Ibcast(part_.data(), count, MPI_INT, 0, others_, &received);
    wait_quietly(received);
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
  rep_.cells = primal::index_cast<std::int64_t>(std::count(mine.begin(), mine.end(), 1));
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

}  // namespace detail

RankMesh conform_distributed(const primal::Model& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report) {
  DistributedReport local;
  return detail::Distributor(input, options, comm, report ? *report : local).run();
}

RankMesh conform_distributed(primal::Model&& input, const DistributedOptions& options,
                             MPI_Comm comm, DistributedReport* report) {
  DistributedReport local;
  return detail::Distributor(input, options, comm, report ? *report : local, &input).run();
}

std::vector<char> all_gather_bytes(const std::vector<char>& mine, MPI_Comm comm,
                                   std::size_t round) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  const auto n = static_cast<std::uint64_t>(mine.size());
  std::vector<std::uint64_t> sizes(primal::index_cast<std::size_t>(ranks));
  MPI_Allgather(&n, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, comm);
  std::vector<std::size_t> base(sizes.size() + 1, 0);
  for (std::size_t r = 0; r < sizes.size(); ++r) base[r + 1] = base[r] + sizes[r];
  std::vector<char> all(base.back());
  std::vector<int> counts(sizes.size()), displs(sizes.size());
  // A round's counts add up in an int too.
  constexpr auto kIntMax = static_cast<std::size_t>(std::numeric_limits<int>::max());
  round = std::clamp<std::size_t>(round, 1, kIntMax / sizes.size());
  const std::size_t largest = *std::ranges::max_element(sizes);
  if (largest <= round && base.back() <= kIntMax) {  // one call, in place
    for (std::size_t r = 0; r < sizes.size(); ++r)
      counts[r] = static_cast<int>(sizes[r]), displs[r] = static_cast<int>(base[r]);
    MPI_Allgatherv(mine.data(), static_cast<int>(n), MPI_CHAR, all.data(), counts.data(),
                   displs.data(), MPI_CHAR, comm);
    return all;
  }
  std::vector<char> part;
  for (std::size_t from = 0; from < largest; from += round) {
    int total = 0;
    for (std::size_t r = 0; r < sizes.size(); ++r) {
      counts[r] = static_cast<int>(std::min(round, sizes[r] - std::min(sizes[r], from)));
      displs[r] = total, total += counts[r];
    }
    part.resize(primal::index_cast<std::size_t>(total));
    const std::size_t own = std::min(round, mine.size() - std::min(mine.size(), from));
    MPI_Allgatherv(mine.data() + std::min(mine.size(), from), static_cast<int>(own), MPI_CHAR,
                   part.data(), counts.data(), displs.data(), MPI_CHAR, comm);
    for (std::size_t r = 0; r < sizes.size(); ++r)
      std::copy_n(part.data() + displs[r], counts[r],
                  all.data() + base[r] + std::min<std::size_t>(from, sizes[r]));
  }
  return all;
}

primal::Shares rank_shares(MPI_Comm comm) {
  primal::Shares s;
  MPI_Comm_rank(comm, &s.share);
  MPI_Comm_size(comm, &s.shares);
  s.exchange = [comm](const std::vector<char>& mine) { return all_gather_bytes(mine, comm); };
  return s;
}

primal::InputCheckOptions shared_input_check(MPI_Comm comm) {
  primal::InputCheckOptions o;
  static_cast<primal::Shares&>(o) = rank_shares(comm);
  return o;
}

}  // namespace geode::parallel
