// conform_distributed's exchange stages (detail/distributor.hpp): the zone's points, sets and
// hexes shared out from the zone rank, and the global node and hex ids.
#include <geode/parallel/detail/distributor.hpp>

#include <cstdint>
#include <numeric>

namespace geode::parallel::detail {
namespace {

// MPI_Bcast of n values of `type` from `root`, in pieces an int can count.
void broadcast(void* data, std::size_t n, MPI_Datatype type, std::size_t size, int root,
               MPI_Comm comm) {
  constexpr std::size_t kPiece = std::size_t{1} << 28;
  for (std::size_t i = 0; i < n; i += kPiece)
    MPI_Bcast(static_cast<char*>(data) + i * size, primal::index_cast<int>(std::min(kPiece, n - i)),
              type, root, comm);
}

}  // namespace

// From the zone rank to every rank: the zone's depth, outcome and warnings, its points (for
// matching the diced nodes on the cut), block names and sets. A rank that diced a zone since grown
// dices again.
void Distributor::share_zone() {
  const int root = zone_rank();
  primal::detail::BytePacket packet;
  if (rank_ == root) {
    packet.put(zone_failure_kind_);
    packet.put(zone_failure_);
    packet.put(rings_);
    packet.put(rep_.zone.warnings.size());
    for (const std::string& w : rep_.zone.warnings) packet.put(w);
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
  // Every rank here once its dicing is done, the zone rank last as a rule: the others wait for
  // its packet's size without spinning, so that the zone's conform can use their cores.
  std::uint64_t bytes = packet.bytes().size();
  MPI_Request sized;
  MPI_Ibcast(&bytes, 1, MPI_UINT64_T, root, comm_, &sized);
  wait_quietly(sized);
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
  // The zone's conform warnings (the buffer layer carved from the other part, across faces
  // between blocks so that they do not keep their volumes; wedges split) are the run's, as the
  // serial run's are: every rank's report holds them, so the rank that prints has them.
  for (auto n = packet.get<std::size_t>(); n > 0; --n) rep_.warnings.push_back(packet.get_string());
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
      select_rings(rings);
      finish_zone();
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
    std::vector<std::size_t> zone_made;
    for (std::size_t i = 0; i < nd; ++i) {
      const FaceKey& o = diced_.origin[i];
      bool in_zone = o[0] != kInvalidIndex;  // not a cell centre
      for (std::size_t k = 0; k < 4 && o[k] != kInvalidIndex && in_zone; ++k)
        in_zone = zone_node_[primal::index_cast<std::size_t>(
            own_.node[primal::index_cast<std::size_t>(o[k])])];
      if (in_zone) zone_made.push_back(i);
    }
    PointBitsMap on_zone(zone_made.size());
    for (std::size_t i : zone_made) on_zone.emplace(bits(diced_.points[i]), i);
    for (std::size_t z = 0; z < zone_out_.points.size() && on_zone.size() > 0; ++z)
      if (const std::size_t* i = on_zone.find(bits(zone_out_.points[z])))
        diced_gid_[*i] = primal::index_cast<std::int64_t>(z);
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
    send_counts[primal::index_cast<std::size_t>(q)] = primal::index_cast<int>(c.size() * 4);
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

}  // namespace geode::parallel::detail
