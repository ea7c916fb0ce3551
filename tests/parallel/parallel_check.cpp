// parallel_check same SERIAL.exo JOINED.exo: the two models (either may be a Nemesis set, named
// by a piece) identical after the canonical
// ordering (parallel/nemesis.hpp canonical()): coordinates bit for bit, hexes corner for corner
// in each block, block names, node and side sets with ids and names.
// parallel_check ranks OUT.exo N: the per-rank files OUT.exo.N.r read by libexodusII, their
// Nemesis data consistent (processor counts, global counts against the joined OUT.exo, node
// maps covering the global ids once per owner, each communication map matched by its
// neighbour's on the same global ids and coordinates) and their hexes together the joined
// file's. Prints the first difference and exits 1.
// parallel_check count FILE.exo: prints its number of hexes.
// mpirun -np N parallel_check gather: parallel::all_gather_bytes, in one call and in rounds.
#include <exodusII.h>
#include <mpi.h>

#include <array>
#include <iostream>
#include <map>
#include <set>
#include <vector>

#include <geode/io/exodus.hpp>
#include <geode/io/read_model.hpp>
#include <geode/parallel/distributed_conform.hpp>
#include <geode/parallel/nemesis.hpp>

namespace {

using namespace geode;
using primal::Model;

int fail(const std::string& what) {
  std::cerr << "parallel_check: " << what << "\n";
  return 1;
}

int same(const std::string& a_path, const std::string& b_path) {
  // read_model: either may name a Nemesis set (io/nemesis_set.hpp), read joined.
  const Model a = parallel::canonical(io::read_model(a_path));
  const Model b = parallel::canonical(io::read_model(b_path));
  if (a.points.size() != b.points.size())
    return fail("nodes: " + std::to_string(a.points.size()) + " vs " +
                std::to_string(b.points.size()));
  for (std::size_t v = 0; v < a.points.size(); ++v)
    if (a.points[v] != b.points[v])
      return fail("node " + std::to_string(v) + ": " + primal::point_text(a.points[v]) + " vs " +
                  primal::point_text(b.points[v]));
  if (a.hexes.size() != b.hexes.size())
    return fail("hexes: " + std::to_string(a.hexes.size()) + " vs " +
                std::to_string(b.hexes.size()));
  for (std::size_t h = 0; h < a.hexes.size(); ++h)
    if (a.hexes[h] != b.hexes[h] || a.hex_block[h] != b.hex_block[h])
      return fail("hex " + std::to_string(h) + " differs (block " + std::to_string(a.hex_block[h]) +
                  " vs " + std::to_string(b.hex_block[h]) + ")");
  if (a.block_names != b.block_names) return fail("block names differ");
  if (a.node_sets.size() != b.node_sets.size()) return fail("node set counts differ");
  for (std::size_t s = 0; s < a.node_sets.size(); ++s)
    if (a.node_sets[s].id != b.node_sets[s].id || a.node_sets[s].name != b.node_sets[s].name ||
        a.node_sets[s].nodes != b.node_sets[s].nodes)
      return fail("node set " + std::to_string(a.node_sets[s].id) + " differs (" +
                  std::to_string(a.node_sets[s].nodes.size()) + " vs " +
                  std::to_string(b.node_sets[s].nodes.size()) + " nodes)");
  if (a.side_sets.size() != b.side_sets.size()) return fail("side set counts differ");
  for (std::size_t s = 0; s < a.side_sets.size(); ++s)
    if (a.side_sets[s].id != b.side_sets[s].id || a.side_sets[s].name != b.side_sets[s].name ||
        a.side_sets[s].sides != b.side_sets[s].sides)
      return fail("side set " + std::to_string(a.side_sets[s].id) + " differs (" +
                  std::to_string(a.side_sets[s].sides.size()) + " vs " +
                  std::to_string(b.side_sets[s].sides.size()) + " sides)");
  std::cout << "same: " << a.hexes.size() << " hexes, " << a.points.size() << " nodes, "
            << a.node_sets.size() << " node sets, " << a.side_sets.size() << " side sets\n";
  return 0;
}

struct RankFile {
  Model model;
  std::vector<int> node_map, elem_map;
  std::map<int, std::vector<int>> cmaps;  // neighbour -> 1-based local nodes
  std::int64_t nodes_g = 0, elems_g = 0, blocks_g = 0, node_sets_g = 0, side_sets_g = 0;
  std::int64_t int_nodes = 0, bor_nodes = 0, ext_nodes = 0, int_elems = 0, bor_elems = 0;
};

RankFile read_rank(const std::string& path, int ranks, int rank) {
  RankFile f;
  f.model = io::read_exodus(path);
  int cpu = 8, io_size = 0;
  float version = 0;
  const int exo = ex_open(path.c_str(), EX_READ, &cpu, &io_size, &version);
  if (exo < 0) throw std::runtime_error(path + ": not opened by libexodusII");
  int procs = 0, in_file = 0;
  char type[2] = {};
  if (ex_get_init_info(exo, &procs, &in_file, type) < 0 || procs != ranks || in_file != 1 ||
      type[0] != 'p')
    throw std::runtime_error(path + ": Nemesis init info wrong");
  int g[5];
  if (ex_get_init_global(exo, &g[0], &g[1], &g[2], &g[3], &g[4]) < 0)
    throw std::runtime_error(path + ": no Nemesis global counts");
  f.nodes_g = g[0], f.elems_g = g[1], f.blocks_g = g[2], f.node_sets_g = g[3], f.side_sets_g = g[4];
  int lb[7];
  if (ex_get_loadbal_param(exo, &lb[0], &lb[1], &lb[2], &lb[3], &lb[4], &lb[5], &lb[6], rank) < 0)
    throw std::runtime_error(path + ": no Nemesis load balance");
  f.int_nodes = lb[0], f.bor_nodes = lb[1], f.ext_nodes = lb[2], f.int_elems = lb[3],
  f.bor_elems = lb[4];
  f.node_map.resize(f.model.points.size());
  f.elem_map.resize(f.model.hexes.size());
  ex_get_id_map(exo, EX_NODE_MAP, f.node_map.data());
  ex_get_id_map(exo, EX_ELEM_MAP, f.elem_map.data());
  if (lb[5] > 0) {
    std::vector<int> ids(primal::index_cast<std::size_t>(lb[5])), counts(ids.size());
    if (ex_get_cmap_params(exo, ids.data(), counts.data(), nullptr, nullptr, rank) < 0)
      throw std::runtime_error(path + ": no communication map sizes");
    for (std::size_t k = 0; k < ids.size(); ++k) {
      std::vector<int> nodes(primal::index_cast<std::size_t>(counts[k])), procs_(nodes.size());
      if (ex_get_node_cmap(exo, ids[k], nodes.data(), procs_.data(), rank) < 0)
        throw std::runtime_error(path + ": no communication map " + std::to_string(ids[k]));
      f.cmaps[ids[k]] = nodes;
    }
  }
  ex_close(exo);
  return f;
}

int ranks(const std::string& out, int n) {
  const Model joined = io::read_exodus(out);
  std::vector<RankFile> files;
  for (int r = 0; r < n; ++r) files.push_back(read_rank(parallel::rank_file(out, n, r), n, r));
  std::set<int> node_ids, elem_ids;
  std::int64_t elems = 0;
  std::multiset<std::array<double, 24>> from_ranks, from_joined;
  const auto corners = [](const Model& m, std::size_t h) {
    std::array<double, 24> x{};
    for (int c = 0; c < 8; ++c)
      for (int d = 0; d < 3; ++d) x[3 * c + d] = m.points[m.hexes[h][c]][d];
    return x;
  };
  for (int r = 0; r < n; ++r) {
    const RankFile& f = files[primal::index_cast<std::size_t>(r)];
    const std::string name = parallel::rank_file(out, n, r).string();
    if (f.nodes_g != primal::index_cast<std::int64_t>(joined.points.size()) ||
        f.elems_g != primal::index_cast<std::int64_t>(joined.hexes.size()))
      return fail(name + ": global counts " + std::to_string(f.nodes_g) + " nodes, " +
                  std::to_string(f.elems_g) + " hexes; the joined file has " +
                  std::to_string(joined.points.size()) + ", " +
                  std::to_string(joined.hexes.size()));
    if (f.node_sets_g != primal::index_cast<std::int64_t>(joined.node_sets.size()) ||
        f.side_sets_g != primal::index_cast<std::int64_t>(joined.side_sets.size()))
      return fail(name + ": global set counts differ from the joined file's");
    if (f.int_nodes + f.bor_nodes != primal::index_cast<std::int64_t>(f.model.points.size()) ||
        f.ext_nodes != 0 ||
        f.int_elems + f.bor_elems != primal::index_cast<std::int64_t>(f.model.hexes.size()))
      return fail(name + ": load balance counts do not add up to the file's");
    if (n > 1 && f.cmaps.empty()) return fail(name + ": no communication map");
    for (int g : f.node_map) node_ids.insert(g);
    for (int g : f.elem_map)
      if (!elem_ids.insert(g).second)
        return fail(name + ": element id " + std::to_string(g) + " also on another rank");
    elems += primal::index_cast<std::int64_t>(f.model.hexes.size());
    for (std::size_t h = 0; h < f.model.hexes.size(); ++h) from_ranks.insert(corners(f.model, h));
    for (const auto& [q, nodes] : f.cmaps) {
      if (q < 0 || q >= n || q == r)
        return fail(name + ": communication map to rank " + std::to_string(q));
      const RankFile& o = files[primal::index_cast<std::size_t>(q)];
      const auto back = o.cmaps.find(r);
      if (back == o.cmaps.end() || back->second.size() != nodes.size())
        return fail(name + ": its map to rank " + std::to_string(q) + " is not matched there");
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        const auto a = primal::index_cast<std::size_t>(nodes[k] - 1);
        const auto b = primal::index_cast<std::size_t>(back->second[k] - 1);
        if (f.node_map[a] != o.node_map[b] || f.model.points[a] != o.model.points[b])
          return fail(name + ": shared node " + std::to_string(k) + " with rank " +
                      std::to_string(q) + " differs there");
      }
    }
  }
  if (primal::index_cast<std::int64_t>(node_ids.size()) != files[0].nodes_g ||
      *node_ids.begin() != 1 || *node_ids.rbegin() != files[0].nodes_g)
    return fail("the ranks' node ids are not 1..global nodes");
  if (elems != files[0].elems_g) return fail("the ranks' hexes do not add up to the global count");
  for (std::size_t h = 0; h < joined.hexes.size(); ++h) from_joined.insert(corners(joined, h));
  if (from_ranks != from_joined) return fail("the ranks' hexes are not the joined file's");
  std::cout << "ranks: " << n << " files, " << elems << " hexes, " << node_ids.size()
            << " nodes, communication maps matched\n";
  return 0;
}

}  // namespace

// Under mpirun: parallel::all_gather_bytes of rank-dependent sizes (one rank with none), in one
// call and in rounds of 16 and 1000 bytes, against the concatenation every rank can compute.
int gather(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const auto bytes_of = [](int r) {
    std::vector<char> b(r == 1 ? 0 : static_cast<std::size_t>(r) * 37 + 11);
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<char>((r * 131 + i) & 0xff);
    return b;
  };
  std::vector<char> expected;
  for (int r = 0; r < ranks; ++r) {
    const std::vector<char> b = bytes_of(r);
    expected.insert(expected.end(), b.begin(), b.end());
  }
  int bad = 0;
  for (std::size_t round : {std::size_t{16}, std::size_t{1000}, std::size_t{1} << 28})
    bad |= parallel::all_gather_bytes(bytes_of(rank), MPI_COMM_WORLD, round) != expected;
  int any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0) std::cout << "gather on " << ranks << " ranks: " << (any ? "WRONG" : "ok") << "\n";
  MPI_Finalize();
  return any;
}

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "gather" && argc == 2) return gather(argc, argv);
    if (mode == "same" && argc == 4) return same(argv[2], argv[3]);
    if (mode == "ranks" && argc == 4) return ranks(argv[2], std::stoi(argv[3]));
    if (mode == "count" && argc == 3) {
      std::cout << io::read_exodus(argv[2]).hexes.size() << "\n";
      return 0;
    }
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  std::cerr << "usage: parallel_check same A.exo B.exo | ranks OUT.exo N | count FILE.exo | "
               "gather (under mpirun)\n";
  return 2;
}
