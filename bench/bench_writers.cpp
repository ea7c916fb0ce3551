// Every output writer on one model (issue 27: each output format within 10 % of .exo's time):
// wall time, CPU time and peak RSS of each write, each in a child process (fork) so that its
// figures are the writer's own. The parent holds the model, so a child's peak includes it: the
// "nothing" row is that floor. The files are left in the output folder to compare (cmp) with
// another build's.
//
// Usage: bench_writers model out_dir [repeats] [writer]
//   model: any input geode reads (a `geode conform` output .exo: the writers' real load);
//   writer: one of exo, msh, msh-binary, vtu, vtu-ascii, vtk (default: all), best of repeats.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "child_run.hpp"

#include <geode/io/formats.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>

namespace fs = std::filesystem;
using namespace geode;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_writers model out_dir [repeats] [writer]\n");
    return 2;
  }
  const fs::path dir = argv[2];
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 3;
  const std::string only = argc > 4 ? argv[4] : "";
  const primal::Model model = io::read_model(argv[1], {}, false);
  std::printf("%zu nodes, %zu elements\n", model.points.size(), primal::element_count(model));
  fs::create_directories(dir);
  io::WriteOptions ascii;
  ascii.vtk_encoding = io::VtkEncoding::kAscii;
  struct Writer {
    const char* name;
    std::function<void(const fs::path&)> write;
    const char* extension;
  };
  const Writer writers[] = {
      {"nothing", [](const fs::path&) {}, ""},
      {"exo", [&](const fs::path& p) { io::write_model(model, p, "exo"); }, ".exo"},
      {"msh", [&](const fs::path& p) { io::write_model(model, p, "msh"); }, ".msh"},
      {"msh-binary", [&](const fs::path& p) { io::write_gmsh(model, p, io::GmshFormat::kBinary); },
       ".msh"},
      {"vtu", [&](const fs::path& p) { io::write_model(model, p, "vtu"); }, ".vtu"},
      {"vtu-ascii", [&](const fs::path& p) { io::write_model(model, p, "vtu", ascii); }, ".vtu"},
      {"vtk", [&](const fs::path& p) { io::write_model(model, p, "vtk"); }, ".vtk"},
  };
  for (const Writer& w : writers) {
    if (!only.empty() && only != w.name) continue;
    const fs::path file = dir / (std::string("bench-") + w.name + w.extension);
    bench::ChildRun best;
    best.seconds = 1e30;
    for (int r = 0; r < repeats; ++r) {
      const bench::ChildRun run = bench::run_in_child([&] { w.write(file); });
      if (run.seconds < best.seconds) best = run;
    }
    std::printf("%-10s %7.3f s wall %7.3f s CPU %7.1f MiB peak\n", w.name, best.seconds,
                best.cpu_seconds, best.peak_mib);
    std::fflush(stdout);
  }
  return 0;
}
