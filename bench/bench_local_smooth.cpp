// The worst-first local smoother (primal/local_smooth.hpp) on conform's output before smoothing,
// for every demo model (demo/demo_models.hpp): CPU milliseconds per buffer hex, patches, min
// scaled Jacobian per block before and after, with 1 thread and with TBB's default; then the
// same machinery over every hex (conform's global options, without the defect passes that
// follow it in conform's global mode); then the whole conform
// with its default options (smoothing seeded at the defects, conform's local options), timed.
// Usage: bench_local_smooth [--defaults] [n] [target] [max_visits] [max_iterations] [model...]
//        (defaults 4, LocalSmoothOptions' own, every demo model); --defaults: only the whole
//        conform with its default options.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <string>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/quality.hpp>

namespace {

using namespace geode;

std::map<int, double> block_minima(const primal::HexMesh& m) {
  std::map<int, double> out;
  for (primal::Index h = 0; h < primal::index_cast(m.hexes.size()); ++h) {
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

void run(const std::string& name, const primal::Model& input,
         const primal::LocalSmoothOptions& base) {
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  o.geode_block = "geode";  // reported apart from the diced tets' block
  const conform::ConformResult r = conform::conform(input, o);
  primal::HexMesh mesh;
  mesh.points = r.model.points;
  mesh.hexes = r.model.hexes;
  mesh.block = r.model.hex_block;
  const double buffer = static_cast<double>(r.interface_quads);
  std::vector<primal::Index> geode;
  // conform's output order: diced hexes, geode hexes, diced tets.
  for (primal::Index h = r.diced_hexes; h < r.diced_hexes + r.geode_hexes; ++h) geode.push_back(h);
  const auto seeds = primal::hexes_around(mesh, geode);
  const auto cons = primal::boundary_slide_constraints(mesh);  // boundary and block interfaces kept
  std::printf("%s: %zu tets, %zu input hexes -> %zu hexes, %.0f buffer hexes, %zu seeds\n",
              name.c_str(), input.tets.size(), input.hexes.size(), mesh.hexes.size(), buffer,
              seeds.size());
  print_blocks("before", block_minima(mesh));
  const double yardstick = r.yardstick();
  std::printf(
      "    --smooth none: valid %s, min SJ %.4f; input diced alone %.4f (hexes) %.4f (tets): %.2f "
      "x the lower\n",
      r.validity.ok() && primal::min_scaled_jacobian(mesh) > 0 ? "yes" : "NO",
      primal::min_scaled_jacobian(mesh), r.input_diced_hex_min_scaled_jacobian,
      r.input_diced_tet_min_scaled_jacobian, primal::min_scaled_jacobian(mesh) / yardstick);
  struct Mode {
    const char* label;
    bool global;
    int threads;
  } modes[] = {{"local, 1 thread", false, 1},
               {"local, default threads", false, 0},
               {"global, default threads", true, 0}};
  for (const Mode& m : modes) {
    primal::HexMesh work = mesh;
    primal::LocalSmoothOptions lo = base;
    if (m.global) lo.target = conform::ConformOptions{}.global_smooth_options.target;
    lo.threads = m.threads;
    const auto res = primal::smooth_hexes_local(
        work, cons, nullptr, m.global ? std::span<const primal::Index>{} : seeds, lo);
    const double cpu = res.cpu_seconds;
    std::printf(
        "  %-24s %.3f ms CPU per buffer hex (%.3f s CPU, %.3f s wall), %d patches, %d rounds,"
        " %ld iterations, inverted %d -> %d\n",
        m.label, 1e3 * cpu / buffer, cpu, res.seconds, res.patches, res.rounds, res.iterations,
        res.initial_inverted, res.final_inverted);
    print_blocks("after", block_minima(work));
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool defaults_only = argc > 1 && std::string(argv[1]) == "--defaults";
  if (defaults_only) --argc, ++argv;
  const int n = argc > 1 ? std::atoi(argv[1]) : 4;
  std::vector<std::string> models(argv + std::min(argc, 5), argv + argc);
  const auto names = demo::demo_model_names();
  const bool known = std::all_of(models.begin(), models.end(), [&](const std::string& m) {
    return std::find(names.begin(), names.end(), m) != names.end();
  });
  if (n < 1 || n > 64 || !known) {
    std::fprintf(stderr,
                 "usage: bench_local_smooth [--defaults] [n 1..64] [target] [max_visits] "
                 "[max_iterations] [model...]\n");
    return 2;
  }
  primal::LocalSmoothOptions o;
  if (argc > 2) o.target = std::atof(argv[2]);
  if (argc > 3) o.max_visits = std::atoi(argv[3]);
  if (argc > 4) o.max_iterations = std::atoi(argv[4]);
  if (models.empty()) models = names;
  if (defaults_only)
    std::printf("n %d, conform's default options\n", n);
  else
    std::printf("n %d, target %.2f, max_visits %d, max_iterations %d\n", n, o.target, o.max_visits,
                o.max_iterations);
  for (const std::string& name : models) {
    const primal::Model input = demo::demo_model(name, n);
    if (defaults_only)
      std::printf("%s %d:\n", name.c_str(), n);
    else
      run(name + " " + std::to_string(n), input, o);
    conform::ConformOptions co;  // conform's own defaults (seeding at the defects)
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    const conform::ConformResult r = conform::conform(input, co);
    const double yardstick = r.yardstick();
    const double buffer = static_cast<double>(r.interface_quads);
    std::printf(
        "  whole conform (defaults): %.3f s CPU, %.3f s wall, valid %s, min SJ %.4f = %.2f x the "
        "input diced alone;"
        " its smoothing %.3f s wall, %.3f s CPU = %.2f ms CPU per buffer hex, %d patches\n",
        static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
        r.validity.ok() ? "yes" : "NO", r.smoothing.final_min_scaled_jacobian,
        r.smoothing.final_min_scaled_jacobian / yardstick, r.smoothing.seconds,
        r.smoothing.cpu_seconds, 1e3 * r.smoothing.cpu_seconds / buffer, r.smoothing.patches);
  }
  return 0;
}
