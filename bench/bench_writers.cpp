// Every output writer on one model (issue 27: each output format within 10 % of .exo's time):
// wall time, CPU time and peak RSS of each write, each in a child process (fork) so that its
// figures are the writer's own. The parent holds the model, so a child's peak includes it: the
// "nothing" row is that floor. The files are left in the output folder to compare (cmp) with
// another build's.
//
// Usage: bench_writers model out_dir [repeats] [writer]
//   model: any input geode reads (a `geode conform` output .exo: the writers' real load);
//   writer: one of exo, msh, msh-binary, vtu, vtu-ascii, vtk (default: all), best of repeats.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include <geode/io/formats.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>

namespace fs = std::filesystem;
using namespace geode;

namespace {

struct Run {
  double wall = 0, cpu = 0, mib = 0;
};

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; }

Run in_child(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    f();
    std::_Exit(0);
  }
  int status = 0;
  struct rusage ru {};
  wait4(pid, &status, 0, &ru);
  const auto wall = std::chrono::steady_clock::now() - start;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) std::printf("  child failed\n");
  return {std::chrono::duration<double>(wall).count(), seconds(ru.ru_utime) + seconds(ru.ru_stime),
          static_cast<double>(ru.ru_maxrss) / 1024};
}

}  // namespace

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
  ascii.vtu_encoding = io::VtuEncoding::kAscii;
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
    Run best{1e30, 0, 0};
    for (int r = 0; r < repeats; ++r) {
      const Run run = in_child([&] { w.write(file); });
      if (run.wall < best.wall) best = run;
    }
    std::printf("%-10s %7.3f s wall %7.3f s CPU %7.1f MiB peak\n", w.name, best.wall, best.cpu,
                best.mib);
    std::fflush(stdout);
  }
  return 0;
}
