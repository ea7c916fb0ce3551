// Time and peak memory of the geode pipeline's stages, against the targets of the issues:
//  (a) compute + dualize the 6-sheet geode arrangement   target < 50 ms
//  (b) build_geode3d end to end                            target < 100 ms
//  (c) smooth_template (tet/hex-side fixed, and sliding)   target < 1 s
// Each stage is repeated; min and median wall-clock times are printed. Peak memory is the
// process's maximum resident set size (getrusage ru_maxrss) after each stage, so it is
// cumulative: a stage's own peak shows only if it exceeds the earlier ones.
// Usage: bench_arrangement [repeats]   (default 20; smoothing runs max(3, repeats / 4) times)
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/templates/geode.hpp>

namespace gt = geode::templates;
using geode::primal::Point;

namespace {

long peak_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;  // KiB on Linux
}

struct Timing {
  double min = 0, median = 0;
};

Timing time_it(int repeats, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return {t.front(), t[t.size() / 2]};
}

void report(const char* what, const Timing& t, double target, int repeats) {
  std::printf(
      "%-44s min %8.2f ms  median %8.2f ms  (%2d runs)  target < %6.0f ms  %s  peak RSS %ld KiB\n",
      what, 1e3 * t.min, 1e3 * t.median, repeats, 1e3 * target, t.median < target ? "ok  " : "SLOW",
      peak_kib());
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20;
  const int smooth_repeats = std::max(3, repeats / 4);
  std::printf("peak RSS at start: %ld KiB\n", peak_kib());

  // The geode's six sheets exactly as build_geode3d makes them (default options).
  const gt::GeodeArrangement G = gt::geode_arrangement(gt::GeodeOptions{}, 3);
  const auto& sheets = G.sheets;
  const geode::stc::Domain& dom = G.domain;
  std::size_t hexes = 0, vertices = 0;
  const Timing arr = time_it(
      repeats, [&] { vertices = geode::stc::compute_arrangement(sheets, dom).vertices.size(); });
  report("(a1) compute_arrangement (6 sheets)", arr, 0.050, repeats);
  const auto A = geode::stc::compute_arrangement(sheets, dom);
  const Timing dual = time_it(repeats, [&] { hexes = geode::stc::dualize(A).hex.hexes.size(); });
  report("(a2) dualize", dual, 0.050, repeats);
  const Timing both = time_it(repeats, [&] {
    hexes = geode::stc::dualize(geode::stc::compute_arrangement(sheets, dom)).hex.hexes.size();
  });
  report("(a) compute_arrangement + dualize", both, 0.050, repeats);
  std::printf("    %zu sheets, %zu vertices, %zu hexes\n", sheets.size(), vertices, hexes);

  const Timing build =
      time_it(repeats, [&] { hexes = gt::build_geode3d(gt::GeodeOptions{}).hex.hexes.size(); });
  report("(b) build_geode3d end to end", build, 0.100, repeats);
  std::printf("    %zu hexes\n", hexes);

  const gt::Template T0 = gt::build_geode3d(gt::GeodeOptions{});
  for (bool slide : {false, true}) {
    double sj = 0;
    int it = 0;
    const Timing s = time_it(smooth_repeats, [&] {
      gt::Template T = T0;
      const auto r = gt::smooth_template(T, slide);
      sj = r.final_min_scaled_jacobian, it = r.iterations;
    });
    report(slide ? "(c) smooth_template (tet/hex side slides)"
                 : "(c) smooth_template (tet/hex side fixed)",
           s, 1.0, smooth_repeats);
    std::printf("    min scaled Jacobian %.4f after %d iterations\n", sj, it);
  }
  return 0;
}
