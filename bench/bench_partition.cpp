// geode_mpi's partition stage (parallel::partition_elements) on a demo model: seconds, the parts'
// weights (the hexes each part's elements dice into, the balance METIS is asked for) and the
// edge cut (element faces between parts, primal::element_graph) for 2, 3 and 4 parts; then as
// geode_mpi's rank 0 partitions, on the graph of the read-time check's face pairs: what keeping
// the pairs adds to the check, the graph made of them, and its 2-part partition.
// Usage: bench_partition [model] [n] [workdir]   (default half 64 /tmp/geode_bench_partition;
// the model is built with Gmsh once and kept there as MODEL-N.exo, read back as geode_mpi does)
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include <geode/demo/demo_models.hpp>
#include <geode/io/exodus.hpp>
#include <geode/io/read_model.hpp>
#include <geode/parallel/partition.hpp>
#include <geode/primal/element_graph.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/submodel.hpp>

namespace gp = geode::primal;

namespace {

// Wall and CPU seconds since a start (the machine is shared: CPU is the steadier figure).
struct Clock {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  std::clock_t cpu = std::clock();
  double wall_s() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  }
  double cpu_s() const { return static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC; }
};

// The hexes each flat element dices into, as partition_elements weighs them.
std::vector<long> dicing_weights(const gp::Model& m) {
  std::vector<long> w;
  for (gp::ElementKind kind : gp::kElementKinds)
    w.insert(w.end(), gp::element_count(m, kind),
             kind == gp::ElementKind::kPyramid ? 8 : gp::cell_topology(kind).corners);
  return w;
}

// Connected pieces of the parts (1 per part when every part is connected).
std::size_t pieces(const gp::ElementGraph& g, const std::vector<int>& part) {
  std::vector<char> seen(part.size(), 0);
  std::vector<gp::Index> stack;
  std::size_t count = 0;
  for (std::size_t s = 0; s < part.size(); ++s) {
    if (seen[s]) continue;
    ++count;
    seen[s] = 1;
    stack.assign(1, gp::index_cast(s));
    while (!stack.empty()) {
      const auto e = gp::index_cast<std::size_t>(stack.back());
      stack.pop_back();
      for (std::size_t k = g.offset[e]; k < g.offset[e + 1]; ++k) {
        const auto o = gp::index_cast<std::size_t>(g.neighbour[k]);
        if (!seen[o] && part[o] == part[e]) seen[o] = 1, stack.push_back(g.neighbour[k]);
      }
    }
  }
  return count;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string name = argc > 1 ? argv[1] : "half";
  const int n = argc > 2 ? std::atoi(argv[2]) : 64;
  const std::filesystem::path dir = argc > 3 ? argv[3] : "/tmp/geode_bench_partition";
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::filesystem::create_directories(dir);
  const auto file = dir / (name + "-" + std::to_string(n) + ".exo");
  if (!std::filesystem::exists(file))
    geode::io::write_exodus(geode::demo::demo_model(name, n), file);
  const gp::Model m = geode::io::read_model(file);
  std::printf("%s n=%d: %zu hexes, %zu tets, %zu pyramids, %zu wedges, %zu nodes\n", name.c_str(),
              n, m.hexes.size(), m.tets.size(), m.pyramids.size(), m.wedges.size(),
              m.points.size());
  Clock t0;
  const gp::ElementGraph g = gp::element_graph(m);
  std::printf("element graph: %.2f s (%.2f s CPU), %zu shared faces\n", t0.wall_s(), t0.cpu_s(),
              g.neighbour.size() / 2);
  const auto weight = dicing_weights(m);
  for (int parts : {2, 3, 4}) {
    const Clock t;
    const auto part = geode::parallel::partition_elements(m, parts);
    const double s = t.wall_s(), cpu = t.cpu_s();
    std::vector<long> sum(gp::index_cast<std::size_t>(parts), 0);
    for (std::size_t e = 0; e < part.size(); ++e)
      sum[gp::index_cast<std::size_t>(part[e])] += weight[e];
    long total = 0;
    for (long w : sum) total += w;
    std::size_t cut = 0;
    for (std::size_t e = 0; e < part.size(); ++e)
      for (std::size_t k = g.offset[e]; k < g.offset[e + 1]; ++k)
        cut += part[gp::index_cast<std::size_t>(g.neighbour[k])] != part[e];
    std::printf("%d parts: %.2f s (%.2f s CPU), weights", parts, s, cpu);
    for (long w : sum) std::printf(" %ld", w);
    std::printf(" (max/mean %.4f), edge cut %zu faces, %zu connected pieces\n",
                static_cast<double>(*std::max_element(sum.begin(), sum.end())) * parts /
                    static_cast<double>(total),
                cut / 2, pieces(g, part));
  }
  // geode_mpi's way: the check keeps its face pairs, rank 0 makes the graph of them.
  {
    const Clock plain;
    const bool ok = gp::check_input(m).ok();
    const double check_s = plain.cpu_s();
    std::vector<std::array<gp::Index, 2>> pairs;
    gp::InputCheckOptions o;
    o.element_pairs = &pairs;
    const Clock kept;
    const bool ok_kept = gp::check_input(m, o).ok();
    const double kept_s = kept.cpu_s();
    const Clock made;
    geode::parallel::PartitionOptions po;
    po.graph = geode::parallel::graph_of_pairs(gp::element_offsets(m).back(), pairs);
    std::printf(
        "check %.2f s CPU, keeping its face pairs %.2f s CPU (%s); their graph %.3f s "
        "(%zu pairs)\n",
        check_s, kept_s, ok && ok_kept ? "passed" : "FAILED", made.wall_s(), pairs.size());
    const Clock t;
    const auto part = geode::parallel::partition_elements(m, 2, std::move(po));
    std::size_t cut = 0;
    for (std::size_t e = 0; e < part.size(); ++e)
      for (std::size_t k = g.offset[e]; k < g.offset[e + 1]; ++k)
        cut += part[gp::index_cast<std::size_t>(g.neighbour[k])] != part[e];
    std::printf("2 parts of that graph: %.2f s (%.2f s CPU), edge cut %zu faces\n", t.wall_s(),
                t.cpu_s(), cut / 2);
  }
  return 0;
}
