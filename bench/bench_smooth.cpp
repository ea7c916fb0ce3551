// Time and iterations of the smoother on the paper's Appendix A geode (24 x 14 x 24 box) in
// both boundary modes, with the resulting min/max scaled Jacobian and the Table-1-style report.
// Usage: bench_smooth [repeats]   (reads notebooks-data/appendix-a through tests/support)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/smooth.hpp>
#include "support/fixtures.hpp"

namespace gp = geode::primal;

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  const gp::HexMesh paper = geode::test::appendix_a_geode();
  const gp::Point lo(-12, -7, -12), hi(12, 7, 12);
  struct Mode {
    const char* name;
    std::array<bool, 6> fixed;
  } modes[] = {{"faces slide", {}}, {"top+bottom fixed", {false, false, true, true, false, false}}};
  for (const auto& mode : modes) {
    double best = 1e300, total = 0.0;
    gp::SmoothResult r;
    gp::HexMesh mesh;
    for (int i = 0; i < repeats; ++i) {
      mesh = paper;
      const auto c = gp::box_constraints(mesh.points, lo, hi, mode.fixed);
      r = gp::smooth_hex_mesh(mesh, c);
      best = std::min(best, r.seconds);
      total += r.seconds;
    }
    double min_sj = 1.0, max_sj = -1.0;
    for (gp::Index h = 0; h < static_cast<gp::Index>(mesh.hexes.size()); ++h) {
      const double q = gp::hex_scaled_jacobian(gp::hex_corners(mesh, h));
      min_sj = std::min(min_sj, q), max_sj = std::max(max_sj, q);
    }
    std::printf("%-17s min SJ %.4f -> %.4f, per-hex SJ range [%.4f, %.4f] (paper 0.26-0.53)\n",
                mode.name, r.initial_min_scaled_jacobian, r.final_min_scaled_jacobian, min_sj,
                max_sj);
    std::printf("%-17s iterations %d untangle + %d shape, time best %.3f s mean %.3f s (%d runs)\n",
                "", r.untangle_iterations, r.shape_iterations, best, total / repeats, repeats);
    std::printf("%s\n", gp::format_quality_table(gp::hex_quality_report(mesh)).c_str());
  }
  return 0;
}
