// geode_mpi conform INPUT -o OUT.exo [--join]: conform under MPI (parallel/distributed_conform),
// one Nemesis-partitioned Exodus file per rank, and on request one joined file. Run as
// `mpirun -np N geode_mpi conform ...`. A separate executable so that the serial `geode` needs
// neither MPI nor its runtime (an MPI program started without mpirun still initializes MPI).
#include <malloc.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <thread>

#include <mpi.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <geode/conform/buffer_layer.hpp>
#include <geode/io/read_model.hpp>
#include <geode/parallel/distributed_conform.hpp>
#include <geode/parallel/nemesis.hpp>

#include <geode/parallel/partition.hpp>
#include <geode/primal/errors.hpp>
#include "cli/conventions.hpp"

namespace {

using namespace geode;

double peak_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

int run(int argc, char** argv, int rank, int size) {
  CLI::App app{"geode conform under MPI: mpirun -np N geode_mpi conform INPUT -o OUT.exo"};
  app.require_subcommand(1);
  CLI::App* conform = app.add_subcommand("conform", "conform a hex + tet model, partitioned");
  std::string input, output, smooth = "local", side = "hex", verify = "local";
  bool join = false, quiet = false;
  int rings = 4, threads = 1, zone_threads = 0;
  double thickness = 0;
  conform
      ->add_option("input", input,
                   "input mesh (.msh, .exo, .vtk, .vtu; a partitioned .msh 4.1 or a Nemesis set "
                   "IN.exo.N.r: its partition instead of METIS)")
      ->required();
  conform
      ->add_option("-o,--output", output,
                   "OUT.exo: writes OUT.exo.N.r per rank (Nemesis; N ranks, r = 0..N-1)")
      ->required();
  conform->add_flag("--join", join, "also write OUT.exo itself, every rank's hexes joined");
  conform->add_option("--smooth", smooth, "local or none (global moves every node: not here)")
      ->check(CLI::IsMember({"local", "none"}))
      ->capture_default_str();
  conform->add_option("--buffer-side", side, "the part the buffer layer is carved from: hex or tet")
      ->check(CLI::IsMember({"hex", "tet"}))
      ->capture_default_str();
  // As geode conform's (cli/conform_command.cpp): [0.01, 0.9], and at most the side's maximum.
  const double thickest = conform::max_buffer_thickness(conform::BufferSide::kHex);
  conform
      ->add_option(
          "--buffer-thickness", thickness,
          "as for geode conform: how far that part shrinks off the interface, as a fraction of "
          "the shortest edge at each interface node; default 0.5 with --buffer-side hex (at most "
          "0.9), 0.3 with tet (at most 0.45)")
      ->check(cli::number_check(0.01, thickest));
  conform
      ->add_option(
          "--verify", verify,
          "local (default): each rank's diced hexes against the dicing tables, the whole "
          "check around the transition zone's hexes and every hex's corner Jacobians; "
          "full: the whole check on every hex of each rank (2.6x local's time on bench_mpi's "
          "10^7-hex model)")
      ->check(CLI::IsMember({"local", "full"}));
  const int max_rings = parallel::DistributedOptions{}.max_rings;
  conform
      ->add_option("--rings", rings,
                   "depth of the transition zone, conformed once on the last rank (grown as "
                   "needed, to at most " +
                       std::to_string(max_rings) + ")")
      ->check(CLI::Range(1, max_rings))
      ->capture_default_str();
  conform->add_option("--threads", threads, "TBB threads per rank (default 1: one core each)");
  conform
      ->add_option(
          "--zone-threads", zone_threads,
          "TBB threads of the transition zone's conform on the last rank (default 0: one per CPU "
          "the ranks on its machine were given; they wait for the zone without spinning once their "
          "own dicing is done); the result is the same for any count")
      ->check(CLI::Range(0, 4096));
  conform->add_flag("-q,--quiet", quiet, "no progress or summary");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (rank == 0) app.exit(e);
    return e.get_exit_code() == 0 ? 0 : 2;
  }
  // The rank's own work runs in an arena of `threads`; the zone's conform in one of its own,
  // which may take every CPU of the machine (DistributedOptions::zone_threads): the process's
  // limit is the larger (TBB's default is the CPUs mpirun bound the rank to).
  const int cpus = std::max(static_cast<int>(std::thread::hardware_concurrency()), 1);
  tbb::global_control threads_limit(
      tbb::global_control::max_allowed_parallelism,
      primal::index_cast<std::size_t>(std::max({threads, zone_threads, cpus, 1})));
  // Everything after the options, in the rank's arena.
  const auto conform_in_arena = [&]() -> int {
    try {
      cli::check_buffer_thickness(thickness, side);
      const double t0 = MPI_Wtime();
      parallel::DistributedOptions options;
      options.conform.smooth = conform::parse_conform_smooth(smooth);
      options.conform.buffer.side = conform::parse_buffer_side(side);
      options.conform.buffer.thickness = thickness;
      options.conform.verify = conform::parse_conform_verify(verify);
      options.rings = rings;
      options.zone_threads = zone_threads;
      // Each rank frees the input once it has its piece, and reads it again only if the zone
      // grows after that (the read-time check passed already).
      options.reload = [&input] { return io::read_model(input, {}, false); };
      io::FilePartition file_partition;
      primal::Model model = io::read_model(input, {}, true, &file_partition,
                                           parallel::shared_input_check(MPI_COMM_WORLD));
      // The input's own partition (a partitioned .msh, a Nemesis set) unless it has fewer parts
      // than there are ranks: then METIS (parallel/partition.hpp).
      std::string partitioned_by = size > 1 ? "METIS" : "one rank";
      if (file_partition.parts > 0) {
        options.partition =
            parallel::ranks_of_parts(file_partition.part, file_partition.parts, size);
        std::string parts = "the input's " + std::to_string(file_partition.parts) + " parts";
        if (file_partition.parts > size)
          parts += " joined on " + std::to_string(size) + (size == 1 ? " rank" : " ranks");
        partitioned_by =
            options.partition.empty() ? "METIS (" + parts + " are fewer than the ranks)" : parts;
      }
      file_partition = {};
      const double t_read = MPI_Wtime() - t0;
      parallel::DistributedReport report;
      const parallel::RankMesh mesh =
          parallel::conform_distributed(std::move(model), options, MPI_COMM_WORLD, &report);
      const double t_conform = MPI_Wtime() - t0 - t_read;
      if (report.valid) parallel::write_nemesis(mesh, output, size, rank);
      const double t_write = MPI_Wtime() - t0 - t_read - t_conform;
      if (report.valid && join) parallel::write_joined(mesh, output, MPI_COMM_WORLD);
      const double t_all = MPI_Wtime() - t0;
      // Per rank: time per stage and peak memory, gathered to rank 0.
      std::ostringstream line;
      line << "rank " << rank << ": " << mesh.model.hexes.size() << " hexes (" << report.zone_hexes
           << " of the transition zone, " << report.diced_hexes << " diced), read " << t_read
           << " s, conform " << t_conform << " s (";
      for (const auto& [stage, s] : report.seconds) line << stage << " " << s << " s, ";
      line << "), write " << t_write << " s, total " << t_all << " s, peak " << peak_mib()
           << " MiB";
      const std::string text = line.str();
      int n = primal::index_cast<int>(text.size());
      std::vector<int> counts(primal::index_cast<std::size_t>(size)), displs(counts.size());
      MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
      std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
      std::string all(
          rank == 0 ? primal::index_cast<std::size_t>(displs.back() + counts.back()) : 0, ' ');
      MPI_Gatherv(text.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR, 0,
                  MPI_COMM_WORLD);
      if (rank == 0 && !quiet) {
        std::cout << "geode_mpi: " << size << " ranks, " << mesh.global_hexes << " hexes, "
                  << mesh.global_nodes << " nodes, transition zone " << report.zone_cells
                  << " input elements (" << report.rings << " rings), partition: " << partitioned_by
                  << ", " << (report.valid ? "valid" : "INVALID") << ", " << t_all << " s\n";
        for (int r = 0; r < size; ++r)
          std::cout << "  "
                    << all.substr(primal::index_cast<std::size_t>(
                                      displs[primal::index_cast<std::size_t>(r)]),
                                  primal::index_cast<std::size_t>(
                                      counts[primal::index_cast<std::size_t>(r)]))
                    << "\n";
        for (const auto& w : report.warnings) std::cout << "  warning: " << w << "\n";
      }
      if (!report.valid) {
        for (const auto& w : report.warnings) std::cerr << "geode_mpi: " << w << "\n";
        if (rank == 0) std::cerr << "geode_mpi: invalid result, nothing written\n";
        return 4;
      }
      return 0;
    } catch (const InvalidInput& e) {
      if (rank == 0) std::cerr << "geode_mpi: " << e.what() << "\n";
      return 2;
    } catch (const TopologyError& e) {
      if (rank == 0) std::cerr << "geode_mpi: " << e.what() << "\n";
      return 3;
    } catch (const std::bad_alloc&) {
      // As the serial command (cli/main.cpp): one line and exit 2, from the rank that ran out.
      std::cerr << "geode_mpi conform (rank " << rank
                << "): error: out of memory: the input needs more memory than this machine "
                << "gives (nothing written)\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "geode_mpi (rank " << rank << "): " << e.what() << "\n";
      return 4;
    }
  };
  tbb::task_arena arena(std::max(threads, 1));
  int code = 0;
  arena.execute([&] { code = conform_in_arena(); });
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  // As the serial command (cli/main.cpp): arrays of a MiB or more get pages of their own, given
  // back to the system when freed, not kept resident through the next stage.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int code = run(argc, argv, rank, size);
  // The same errors arise on every rank (the input and the zone are the same everywhere); a
  // rank failing alone (its file) must not leave the others waiting.
  int worst = 0;
  MPI_Allreduce(&code, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return worst;
}
