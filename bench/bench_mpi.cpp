// conform under MPI against the serial run: wall time and peak memory (per rank) of
//   geode conform IN -o OUT.exo                      (serial, its TBB threads on every core)
//   mpirun -np 1 geode_mpi conform IN -o OUT.exo     (one rank, one thread)
//   mpirun -np 2 geode_mpi conform IN -o OUT.exo     (two ranks, one thread each)
// on a demo model built with Gmsh (demo/demo_models), written as Exodus first. Targets (issue
// 26): 2 ranks >= 1.7 x faster than 1 rank on 10^7 output hexes, memory per rank <= 0.6 x the
// serial peak. Strong scaling only: one model, 1 and 2 ranks (this machine has 2 cores).
// Usage: bench_mpi [model] [n] [workdir]   (default half 64 /tmp/geode_bench_mpi; half 64 makes
// ~8.5 million output hexes)
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <geode/demo/demo_models.hpp>
#include <geode/io/exodus.hpp>

namespace {

// Runs a shell command, its output to `log`; wall seconds and the largest child's peak (MiB).
std::pair<double, double> run(const std::string& command, const std::string& log) {
  const auto t0 = std::chrono::steady_clock::now();
  const int status = std::system((command + " > " + log + " 2>&1").c_str());
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status != 0) {
    std::cerr << "bench_mpi: failed (" << status << "): " << command << "\n";
    std::exit(1);
  }
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return {s, static_cast<double>(u.ru_maxrss) / 1024.0};
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string model = argc > 1 ? argv[1] : "half";
  const int n = argc > 2 ? std::atoi(argv[2]) : 64;
  const std::filesystem::path dir = argc > 3 ? argv[3] : "/tmp/geode_bench_mpi";
  std::filesystem::create_directories(dir);
  const std::string in = (dir / "in.exo").string();
  {
    const auto m = geode::demo::demo_model(model, n);
    geode::io::write_exodus(m, in);
    std::printf("model %s n=%d: %zu hexes, %zu tets, %zu pyramids, %zu wedges\n", model.c_str(), n,
                m.hexes.size(), m.tets.size(), m.pyramids.size(), m.wedges.size());
  }
  setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);  // OpenMPI refuses root unless told
  setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  const std::string geode = GEODE_CLI_PATH, geode_mpi = GEODE_MPI_PATH, mpiexec = GEODE_MPIEXEC;
  // The serial run first: RUSAGE_CHILDREN keeps the largest child's peak, so it is its own.
  const auto [serial_s, serial_mib] =
      run(geode + " conform " + in + " -o " + (dir / "serial.exo").string() + " --quiet",
          (dir / "serial.log").string());
  std::printf("serial geode conform: %.2f s, peak %.0f MiB\n", serial_s, serial_mib);
  for (int ranks : {1, 2}) {
    const std::string log = (dir / ("mpi" + std::to_string(ranks) + ".log")).string();
    const auto [s, mib] = run(mpiexec + " --oversubscribe -np " + std::to_string(ranks) + " " +
                                  geode_mpi + " conform " + in + " -o " +
                                  (dir / ("out" + std::to_string(ranks) + ".exo")).string(),
                              log);
    std::printf("mpirun -np %d geode_mpi: %.2f s wall\n%s", ranks, s, slurp(log).c_str());
  }
  return 0;
}
