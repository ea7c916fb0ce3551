// The worst-first local smoother (primal/local_smooth.hpp) on conform's output before smoothing:
// CPU milliseconds per buffer hex, patches, min scaled Jacobian per block before and after, with
// 1 thread and with TBB's default; then the same machinery over every hex (global).
// Usage: bench_local_smooth [half-block n] [nugget n] [target] [max_visits] [max_iterations]
//        (defaults 8, 4 and LocalSmoothOptions' own)
#include <ctime>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "conform/conform.hpp"
#include "conform/demo_models.hpp"
#include "primal/local_smooth.hpp"
#include "primal/quality.hpp"

namespace {

using namespace geode;

std::map<int, double> block_minima(const primal::HexMesh& m) {
  std::map<int, double> out;
  for (primal::Index h = 0; h < static_cast<primal::Index>(m.hexes.size()); ++h) {
    const double q = primal::hex_scaled_jacobian(primal::hex_corners(m, h));
    auto [it, fresh] = out.emplace(m.block[h], q);
    if (!fresh) it->second = std::min(it->second, q);
  }
  return out;
}

void print_blocks(const char* label, const std::map<int, double>& b) {
  std::printf("    %-7s min SJ", label);
  for (const auto& [id, q] : b) std::printf("  block %d: %.4f", id, q);
  std::printf("\n");
}

void run(const char* name, const primal::Model& input, const primal::LocalSmoothOptions& base) {
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  const conform::ConformResult r = conform::conform(input, o);
  primal::HexMesh mesh;
  mesh.points = r.model.points;
  mesh.hexes = r.model.hexes;
  mesh.block = r.model.hex_block;
  const double buffer = static_cast<double>(r.geode_hexes) / 26.0;
  std::vector<primal::Index> geode;
  for (primal::Index h = 0; h < static_cast<primal::Index>(mesh.hexes.size()); ++h)
    if (mesh.block[h] == conform::kGeodeBlock) geode.push_back(h);
  const auto seeds = primal::hexes_around(mesh, geode);
  const auto cons = primal::boundary_slide_constraints(mesh);
  const primal::TriMesh surface = primal::boundary_triangulation(mesh);
  std::printf("%s: %zu tets, %zu input hexes -> %zu hexes, %.0f buffer hexes, %zu seeds\n", name,
              input.tets.size(), input.hexes.size(), mesh.hexes.size(), buffer, seeds.size());
  print_blocks("before", block_minima(mesh));
  struct Mode {
    const char* label;
    bool global;
    int threads;
  } modes[] = {{"local, 1 thread", false, 1}, {"local, default threads", false, 0},
               {"global, default threads", true, 0}};
  for (const Mode& m : modes) {
    primal::HexMesh work = mesh;
    primal::LocalSmoothOptions lo = base;
    lo.threads = m.threads;
    const std::clock_t c0 = std::clock();
    const auto res = primal::smooth_hexes_local(work, cons, &surface,
                                                m.global ? std::span<const primal::Index>{} : seeds, lo);
    const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    std::printf("  %-24s %.3f ms CPU per buffer hex (%.3f s CPU, %.3f s wall), %d patches, %d rounds,"
                " %ld iterations, inverted %d -> %d\n",
                m.label, 1e3 * cpu / buffer, cpu, res.seconds, res.patches, res.rounds, res.iterations,
                res.initial_inverted, res.final_inverted);
    print_blocks("after", block_minima(work));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int half = argc > 1 ? std::atoi(argv[1]) : 8;
  const int nugget = argc > 2 ? std::atoi(argv[2]) : 4;
  primal::LocalSmoothOptions o;
  if (argc > 3) o.target = std::atof(argv[3]);
  if (argc > 4) o.max_visits = std::atoi(argv[4]);
  if (argc > 5) o.max_iterations = std::atoi(argv[5]);
  std::printf("target %.2f, max_visits %d, max_iterations %d\n", o.target, o.max_visits, o.max_iterations);
  run(("half block " + std::to_string(half)).c_str(), conform::demo_half_block(half), o);
  run(("nugget " + std::to_string(nugget)).c_str(), conform::demo_nugget(nugget), o);
  return 0;
}
