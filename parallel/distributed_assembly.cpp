// conform_distributed's last stages (detail/distributor.hpp): each rank's piece assembled from
// its share of the zone and its diced elements, and verified around the cut.
#include <geode/parallel/detail/distributor.hpp>

namespace geode::parallel::detail {

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
    std::array<Index, 8>& x = o.hexes[place(primal::index_cast<std::int64_t>(h))];
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
  std::vector<int> every = gather_all(ids, comm_);
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
  // Hexes and nodes by their global ids (+ 1: the element and node ids of the files written).
  if (!piece)
    rep_.warnings.push_back(
        "rank " + std::to_string(rank_) + ": " +
        primal::findings(
            v, [&](Index h) { return out_.hex_gid[primal::index_cast<std::size_t>(h)] + 1; },
            [&](Index n) { return node_gid(n) + 1; }));
  if (!dicing_.ok())
    rep_.warnings.push_back("rank " + std::to_string(rank_) + ": " + dicing_.summary());
  const bool zone_ok = piece_ok(rep_.zone.validity, {});
  if (!zone_ok) {
    const auto own = [](Index i) { return std::int64_t{i} + 1; };
    rep_.warnings.push_back("the transition zone (numbered in its own output): " +
                            primal::findings(rep_.zone.validity, own, own));
  }
  int mine = piece && dicing_.ok() && zone_ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, comm_);
  rep_.valid = all == 1;
}

}  // namespace geode::parallel::detail
