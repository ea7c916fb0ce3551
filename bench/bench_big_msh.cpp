// Memory of reading a large .msh (io/gmsh_read.cpp through io/mapped_file.hpp): the file is
// mapped, so a read holds the model and the pages being scanned, never a copy of the file.
// Two files in the temporary directory, each read by read_model in a child process whose
// address space is capped (RLIMIT_AS) at the file's size + a budget: a reader that copied the
// file, or whose memory grew with the file rather than with the model, could not finish.
//  1. "6 GiB, small model": a hex and a tet, then a 6 GiB section the reader skips (sparse: no
//     disk used), which it scans byte by byte for its $End line;
//  2. "N MiB of nodes": a real model, N MiB of node lines (a grid's points, 24 bytes of
//     coordinates each in memory) and one hex.
// Printed per file: size, the cap, result, wall time, peak resident memory (VmHWM: the file's
// pages touched included) and that peak beyond the file's size (the reader's own memory at
// most), per node for the second file; the model's own bytes (points, ids: 32 per node).
// Usage: bench_big_msh [N MiB of nodes (default 512)]; budgets: 768 MiB, and 768 MiB + 256
// bytes per node for the second.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <geode/io/read_model.hpp>
#include <geode/primal/errors.hpp>

namespace fs = std::filesystem;

namespace {

const std::string kModelTail =
    "$Elements\n2 2 1 2\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n3 1 4 1\n2 2 9 3 6\n$EndElements\n";

// A hex and a tet on nodes 1..9 (as tests/cli/bad_input_test.cpp), then `skipped` bytes of a
// section the reader does not know (holes), then nothing else.
void write_small_model(const fs::path& path, std::uint64_t skipped) {
  {
    std::ofstream f(path, std::ios::binary);
    f << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 9 1 9\n3 1 0 9\n";
    for (int i = 1; i <= 9; ++i) f << i << "\n";
    f << "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n2 0 0\n$EndNodes\n"
      << kModelTail << "$GeodeBench\n";
  }
  fs::resize_file(path, fs::file_size(path) + skipped);
  std::ofstream(path, std::ios::binary | std::ios::app) << "\n$EndGeodeBench\n";
}

// About `bytes` of node lines (one entity), the unit hex on nodes 1..8, the rest unused.
std::size_t write_nodes_model(const fs::path& path, std::uint64_t bytes) {
  const std::size_t n = geode::primal::index_cast<std::size_t>(bytes / 48);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fprintf(f, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 %zu 1 %zu\n3 1 0 %zu\n", n, n,
               n);
  for (std::size_t i = 1; i <= n; ++i) std::fprintf(f, "%zu\n", i);
  const double unit[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                             {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (std::size_t i = 0; i < n; ++i) {
    if (i < 8)
      std::fprintf(f, "%g %g %g\n", unit[i][0], unit[i][1], unit[i][2]);
    else
      std::fprintf(f, "%.9f %.9f %.9f\n", 2.0 + static_cast<double>(i % 1000) * 1e-3,
                   static_cast<double>(i / 1000 % 1000) * 1e-3,
                   static_cast<double>(i / 1000000) * 1e-3);
  }
  std::fprintf(f, "$EndNodes\n$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n$EndElements\n");
  std::fclose(f);
  return n;
}

long status_kib(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size());
  return -1;
}

void measure(const char* label, const fs::path& path, std::uint64_t budget) {
  const std::uint64_t size = fs::file_size(path);
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipe_fds[0]);
    const rlim_t cap = size + budget;
    const rlimit as{cap, cap};
    ::setrlimit(RLIMIT_AS, &as);
    std::string result;
    try {
      const geode::primal::Model m = geode::io::read_model(path);
      const long beyond = status_kib("VmHWM:") - static_cast<long>(size >> 10);
      result = "read, " + std::to_string(m.points.size()) + " nodes, model " +
               std::to_string((m.points.size() * 32) >> 20) + " MiB, peak beyond the file " +
               std::to_string(beyond >> 10) + " MiB (" +
               std::to_string(beyond * 1024 / static_cast<long>(m.points.size())) +
               " bytes per node)";
    } catch (const std::exception& e) {
      result = std::string("refused: ") + e.what();
    }
    result += "; peak " + std::to_string(status_kib("VmHWM:") >> 10) + " MiB, anonymous " +
              std::to_string(status_kib("RssAnon:") >> 10) + " MiB at the end";
    (void)!::write(pipe_fds[1], result.data(), result.size());
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  std::string answer;
  char buf[4096];
  for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) > 0;)
    answer.append(buf, geode::primal::index_cast<std::size_t>(n));
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%-24s %8.0f MiB  cap %8.0f MiB  %6.1f s  %s%s\n", label,
              static_cast<double>(size) / (1 << 20), static_cast<double>(size + budget) / (1 << 20),
              s, answer.c_str(), WIFSIGNALED(status) ? " (killed by a signal)" : "");
}

}  // namespace

int main(int argc, char** argv) {
  const std::uint64_t node_mib = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 512;
  const fs::path dir = fs::temp_directory_path();
  const fs::path small = dir / ("geode-bench-big-" + std::to_string(::getpid()) + ".msh");
  const fs::path nodes = dir / ("geode-bench-nodes-" + std::to_string(::getpid()) + ".msh");
  write_small_model(small, std::uint64_t{6} << 30);
  measure("6 GiB, small model", small, std::uint64_t{768} << 20);
  fs::remove(small);
  const std::size_t n = write_nodes_model(nodes, node_mib << 20);
  std::printf("(%zu nodes written)\n", n);
  // The reader's own cost per node (points, ids, the tag index, growth) is what this measures.
  measure("nodes", nodes, (std::uint64_t{768} << 20) + 256 * static_cast<std::uint64_t>(n));
  fs::remove(nodes);
  return 0;
}
