#include <geode/parallel/nemesis.hpp>

#include <exodusII.h>

#include <algorithm>
#include <numeric>

#include <geode/io/exodus.hpp>
#include <geode/primal/errors.hpp>

namespace geode::parallel {
namespace {

using primal::Index;
using primal::Model;
using primal::Point;

void check(int status, const std::filesystem::path& path, const std::string& what) {
  if (status < 0)
    throw InvalidInput(path.string() + ": " + what + " failed: " + io::exodus_error_cause());
}

// Ids as libexodusII's int API takes them: 1-based, within int (checked).
std::vector<int> one_based(const std::vector<std::int64_t>& ids, const std::filesystem::path& p) {
  std::vector<int> r;
  r.reserve(ids.size());
  for (std::int64_t g : ids) {
    if (g + 1 > std::numeric_limits<int>::max())
      throw InvalidInput(p.string() + ": a global id past the 32-bit range");
    r.push_back(static_cast<int>(g + 1));
  }
  return r;
}

}  // namespace

std::filesystem::path rank_file(const std::filesystem::path& output, int ranks, int rank) {
  const std::string n = std::to_string(ranks);
  std::string r = std::to_string(rank);
  r.insert(0, n.size() - r.size(), '0');
  return output.string() + "." + n + "." + r;
}

void write_nemesis(const RankMesh& mesh, const std::filesystem::path& file, int ranks, int rank) {
  // Load balance: internal / border nodes and elements (1-based local numbers).
  std::vector<char> border(mesh.model.points.size(), 0);
  for (const auto& [q, shared] : mesh.shared_nodes)
    for (Index v : shared) border[primal::index_cast<std::size_t>(v)] = 1;
  std::size_t border_nodes = 0, border_hexes = 0;
  for (char b : border) border_nodes += b != 0;
  for (const auto& hex : mesh.model.hexes)
    border_hexes += std::any_of(hex.begin(), hex.end(), [&](Index v) {
      return border[primal::index_cast<std::size_t>(v)];
    });
  const std::size_t internal_nodes = border.size() - border_nodes,
                    internal_hexes = mesh.model.hexes.size() - border_hexes;
  // Nemesis's definitions made with the model's, before any bulk data (io/exodus.hpp): made on
  // the finished file they had netCDF move all of it. Its maps written after the model's data,
  // in file order. Each map is made just before its write and freed after it, so that no two
  // are held beside the model and the writer's buffers.
  const auto define = [&](int exo) {
    char type[] = "p";
    check(ex_put_init_info(exo, ranks, 1, type), file, "Nemesis init info");
    check(ex_put_init_global(exo, mesh.global_nodes, mesh.global_hexes,
                             primal::index_cast<int64_t>(mesh.global_block_hexes.size()),
                             primal::index_cast<int64_t>(mesh.model.node_sets.size()),
                             primal::index_cast<int64_t>(mesh.model.side_sets.size())),
          file, "Nemesis global counts");
    std::vector<int> ids, counts;
    for (const auto& [id, n] : mesh.global_block_hexes)
      ids.push_back(id), counts.push_back(static_cast<int>(n));
    if (!ids.empty())
      check(ex_put_eb_info_global(exo, ids.data(), counts.data()), file, "global blocks");
    ids.clear(), counts.clear();
    for (std::size_t s = 0; s < mesh.model.node_sets.size(); ++s)
      ids.push_back(mesh.model.node_sets[s].id),
          counts.push_back(static_cast<int>(mesh.global_node_set_nodes[s]));
    std::vector<int> zeros(std::max(ids.size(), mesh.model.side_sets.size()), 0);
    if (!ids.empty())
      check(ex_put_ns_param_global(exo, ids.data(), counts.data(), zeros.data()), file,
            "global node sets");
    ids.clear(), counts.clear();
    for (std::size_t s = 0; s < mesh.model.side_sets.size(); ++s)
      ids.push_back(mesh.model.side_sets[s].id),
          counts.push_back(static_cast<int>(mesh.global_side_set_sides[s]));
    if (!ids.empty())
      check(ex_put_ss_param_global(exo, ids.data(), counts.data(), zeros.data()), file,
            "global side sets");
    check(ex_put_loadbal_param(exo, primal::index_cast<int64_t>(internal_nodes),
                               primal::index_cast<int64_t>(border_nodes), 0,
                               primal::index_cast<int64_t>(internal_hexes),
                               primal::index_cast<int64_t>(border_hexes),
                               primal::index_cast<int64_t>(mesh.shared_nodes.size()), 0, rank),
          file, "Nemesis load balance");
    if (!mesh.shared_nodes.empty()) {
      std::vector<int> map_ids, map_counts;
      for (const auto& [q, shared] : mesh.shared_nodes)
        map_ids.push_back(q), map_counts.push_back(primal::index_cast<int>(shared.size()));
      check(ex_put_cmap_params(exo, map_ids.data(), map_counts.data(), nullptr, nullptr, rank),
            file, "Nemesis communication map sizes");
    }
  };
  const auto write_maps = [&](int exo) {
    // The number maps (defined by their first write), then the data of what is defined.
    if (!mesh.node_gid.empty())
      check(ex_put_id_map(exo, EX_NODE_MAP, one_based(mesh.node_gid, file).data()), file,
            "node map");
    if (!mesh.hex_gid.empty())
      check(ex_put_id_map(exo, EX_ELEM_MAP, one_based(mesh.hex_gid, file).data()), file,
            "element map");
    {
      std::vector<int> internal, bordering;
      internal.reserve(internal_nodes), bordering.reserve(border_nodes);
      for (std::size_t v = 0; v < border.size(); ++v)
        (border[v] ? bordering : internal).push_back(primal::index_cast<int>(v + 1));
      check(ex_put_processor_node_maps(exo, internal.data(), bordering.data(), nullptr, rank), file,
            "Nemesis node maps");
    }
    {
      std::vector<int> internal, bordering;
      internal.reserve(internal_hexes), bordering.reserve(border_hexes);
      for (std::size_t h = 0; h < mesh.model.hexes.size(); ++h) {
        bool on = false;
        for (Index v : mesh.model.hexes[h]) on = on || border[primal::index_cast<std::size_t>(v)];
        (on ? bordering : internal).push_back(primal::index_cast<int>(h + 1));
      }
      check(ex_put_processor_elem_maps(exo, internal.data(), bordering.data(), rank), file,
            "Nemesis element maps");
    }
    for (const auto& [q, shared] : mesh.shared_nodes) {
      std::vector<int> local, procs(shared.size(), q);
      for (Index v : shared) local.push_back(v + 1);
      check(ex_put_node_cmap(exo, q, local.data(), procs.data(), rank), file,
            "Nemesis node communication map to rank " + std::to_string(q));
    }
  };
  io::write_exodus(mesh.model, file, define, write_maps);
}

Model canonical(const Model& model) {
  const std::size_t n = model.points.size();
  std::vector<Index> order(n);
  std::iota(order.begin(), order.end(), 0);
  const auto less = [&](Index a, Index b) {
    const Point &p = model.points[primal::index_cast<std::size_t>(a)],
                &q = model.points[primal::index_cast<std::size_t>(b)];
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<Index> renumber(n);
  for (std::size_t k = 0; k < n; ++k)
    renumber[primal::index_cast<std::size_t>(order[k])] = primal::index_cast(k);
  Model c;
  c.block_names = model.block_names;
  for (Index v : order) c.points.push_back(model.points[primal::index_cast<std::size_t>(v)]);
  std::vector<std::pair<int, std::array<Index, 8>>> hexes;
  for (std::size_t h = 0; h < model.hexes.size(); ++h) {
    std::array<Index, 8> x = model.hexes[h];
    for (Index& v : x) v = renumber[primal::index_cast<std::size_t>(v)];
    hexes.push_back({model.hex_block.empty() ? 1 : model.hex_block[h], x});
  }
  std::vector<std::size_t> hex_order(hexes.size());
  std::iota(hex_order.begin(), hex_order.end(), 0);
  std::sort(hex_order.begin(), hex_order.end(),
            [&](std::size_t a, std::size_t b) { return hexes[a] < hexes[b]; });
  std::vector<Index> hex_renumber(hexes.size());
  for (std::size_t k = 0; k < hex_order.size(); ++k) {
    hex_renumber[hex_order[k]] = primal::index_cast(k);
    c.hexes.push_back(hexes[hex_order[k]].second);
    c.hex_block.push_back(hexes[hex_order[k]].first);
  }
  for (const auto& ns : model.node_sets) {
    primal::NodeSet o{ns.id, ns.name, {}};
    for (Index v : ns.nodes) o.nodes.push_back(renumber[primal::index_cast<std::size_t>(v)]);
    std::sort(o.nodes.begin(), o.nodes.end());
    c.node_sets.push_back(std::move(o));
  }
  for (const auto& ss : model.side_sets) {
    primal::SideSet o{ss.id, ss.name, {}};
    for (const auto& s : ss.sides)
      o.sides.push_back({{primal::ElementKind::kHex,
                          hex_renumber[primal::index_cast<std::size_t>(s.element.index)]},
                         s.face});
    std::sort(o.sides.begin(), o.sides.end());
    c.side_sets.push_back(std::move(o));
  }
  std::sort(c.node_sets.begin(), c.node_sets.end(),
            [](const auto& a, const auto& b) { return a.id < b.id; });
  std::sort(c.side_sets.begin(), c.side_sets.end(),
            [](const auto& a, const auto& b) { return a.id < b.id; });
  return c;
}

namespace {

// Gathers `local` (count per rank) to rank 0.
template <typename T>
std::vector<T> gather(const std::vector<T>& local, MPI_Datatype type, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int n = primal::index_cast<int>(local.size());
  std::vector<int> counts(primal::index_cast<std::size_t>(size)), displs(counts.size());
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
  std::vector<T> all(rank == 0 ? primal::index_cast<std::size_t>(displs.back() + counts.back())
                               : 0);
  MPI_Gatherv(local.data(), n, type, all.data(), counts.data(), displs.data(), type, 0, comm);
  return all;
}

}  // namespace

void write_joined(const RankMesh& mesh, const std::filesystem::path& output, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Model& m = mesh.model;
  // Nodes: global id and coordinates; hexes: block then global node ids; sets: global ids.
  std::vector<std::int64_t> node_ids = mesh.node_gid;
  std::vector<double> xyz;
  xyz.reserve(3 * m.points.size());
  for (const Point& p : m.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  std::vector<std::int64_t> hexes;
  hexes.reserve(10 * m.hexes.size());
  for (std::size_t h = 0; h < m.hexes.size(); ++h) {
    hexes.push_back(mesh.hex_gid[h]);
    hexes.push_back(m.hex_block[h]);
    for (Index v : m.hexes[h]) hexes.push_back(mesh.node_gid[primal::index_cast<std::size_t>(v)]);
  }
  std::vector<std::int64_t> sets;  // per set: its nodes' global ids / (hex gid, face) pairs
  for (const auto& ns : m.node_sets)
    for (Index v : ns.nodes)
      sets.push_back(ns.id), sets.push_back(mesh.node_gid[primal::index_cast<std::size_t>(v)]);
  std::vector<std::int64_t> sides;
  for (const auto& ss : m.side_sets)
    for (const auto& s : ss.sides)
      sides.insert(sides.end(),
                   {ss.id, mesh.hex_gid[primal::index_cast<std::size_t>(s.element.index)], s.face});
  const auto all_ids = gather(node_ids, MPI_INT64_T, comm);
  const auto all_xyz = gather(xyz, MPI_DOUBLE, comm);
  const auto all_hexes = gather(hexes, MPI_INT64_T, comm);
  const auto all_sets = gather(sets, MPI_INT64_T, comm);
  const auto all_sides = gather(sides, MPI_INT64_T, comm);
  if (rank != 0) return;
  Model j;
  j.block_names = m.block_names;
  j.points.resize(primal::index_cast<std::size_t>(mesh.global_nodes));
  for (std::size_t k = 0; k < all_ids.size(); ++k)
    j.points[primal::index_cast<std::size_t>(all_ids[k])] =
        Point(all_xyz[3 * k], all_xyz[3 * k + 1], all_xyz[3 * k + 2]);
  j.hexes.resize(primal::index_cast<std::size_t>(mesh.global_hexes));
  j.hex_block.resize(j.hexes.size());
  for (std::size_t k = 0; k < all_hexes.size(); k += 10) {
    const auto h = primal::index_cast<std::size_t>(all_hexes[k]);
    j.hex_block[h] = static_cast<int>(all_hexes[k + 1]);
    for (int c = 0; c < 8; ++c) j.hexes[h][c] = primal::index_cast(all_hexes[k + 2 + c]);
  }
  for (const auto& ns : m.node_sets) j.node_sets.push_back({ns.id, ns.name, {}});
  for (const auto& ss : m.side_sets) j.side_sets.push_back({ss.id, ss.name, {}});
  const auto set_of = [](auto& list, std::int64_t id) -> auto& {
    return *std::find_if(list.begin(), list.end(), [&](const auto& s) { return s.id == id; });
  };
  for (std::size_t k = 0; k < all_sets.size(); k += 2)
    set_of(j.node_sets, all_sets[k]).nodes.push_back(primal::index_cast(all_sets[k + 1]));
  for (auto& ns : j.node_sets) {
    std::sort(ns.nodes.begin(), ns.nodes.end());
    ns.nodes.erase(std::unique(ns.nodes.begin(), ns.nodes.end()), ns.nodes.end());
  }
  for (std::size_t k = 0; k < all_sides.size(); k += 3)
    set_of(j.side_sets, all_sides[k])
        .sides.push_back({{primal::ElementKind::kHex, primal::index_cast(all_sides[k + 1])},
                          static_cast<int>(all_sides[k + 2])});
  io::write_exodus(canonical(j), output);
}

}  // namespace geode::parallel
