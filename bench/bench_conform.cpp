// Time and peak memory of templates::conform on a box half structured hexes, half Kuhn tets
// (primal::grid_model, n x n x n cells, cells with i >= n/2 split into 6 tets each).
// Usage: bench_conform [n] [local|global|none]   (default n = 4, local)
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <geode/conform/conform.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/quality.hpp>

int main(int argc, char** argv) {
  using namespace geode;
  const int n = argc > 1 ? std::atoi(argv[1]) : 4;
  const std::string mode = argc > 2 ? argv[2] : "local";
  if (n < 2) {
    std::fprintf(stderr, "bench_conform: n must be >= 2\n");
    return 2;
  }
  const primal::Model m =
      primal::grid_model({n, n, n}, 1.0, [n](int i, int, int) { return i >= n / 2; });
  conform::ConformOptions o;
  try {
    o.smooth = conform::parse_conform_smooth(mode);
  } catch (const InvalidInput& e) {
    std::fprintf(stderr, "bench_conform: %s\n", e.what());
    return 2;
  }
  o.progress = [](const std::string& s) { std::fprintf(stderr, "  %s\n", s.c_str()); };
  const auto t0 = std::chrono::steady_clock::now();
  const conform::ConformResult r = conform::conform(m, o);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("n %d: %zu hexes + %zu tets, %d interface quads -> %zu hexes, valid %s\n", n,
              m.hexes.size(), m.tets.size(), r.interface_quads, r.model.hexes.size(),
              r.validity.ok() ? "yes" : "NO");
  for (const auto& b : r.quality)
    for (const auto& q : b.report.metrics)
      if (q.metric == primal::HexMetric::kScaledJacobian)
        std::printf("  %-10s %8d hexes, min scaled Jacobian %.3f\n", b.name.c_str(),
                    b.report.num_hexes, q.minimum);
  std::printf("time %.2f s (smoothing %.2f s), peak RSS %.1f MB\n", s, r.smoothing.seconds,
              ru.ru_maxrss / 1024.0);
  return r.validity.ok() ? 0 : 1;
}
