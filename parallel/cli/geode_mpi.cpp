// geode_mpi conform INPUT -o OUT.exo [--join]: conform under MPI (parallel/distributed_conform),
// one Nemesis-partitioned Exodus file per rank, and on request one joined file. Run as
// `mpirun -np N geode_mpi conform ...`. A separate executable so that the serial `geode` needs
// neither MPI nor its runtime (an MPI program started without mpirun still initializes MPI).
#include <malloc.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <mpi.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <geode/conform/buffer_layer.hpp>
#include <geode/io/atomic_file.hpp>
#include <geode/io/nemesis_set.hpp>
#include <geode/io/read_model.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/parallel/distributed_conform.hpp>
#include <geode/parallel/machine_cpus.hpp>
#include <geode/parallel/nemesis.hpp>

#include <geode/parallel/partition.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/unfold.hpp>
#include "cli/conventions.hpp"

namespace {

using namespace geode;

// A progress line on stderr in one write: lines of two ranks (rank 0's stages, the zone rank's
// conform) reach mpirun's stderr whole; written piece by piece they interleaved mid-line.
void say_line(const std::string& line) {
  const std::string s = line + "\n";
  std::cerr.flush();
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, s.data(), s.size());
}

double peak_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// Test hook (tests/parallel/mpi_verify_test.sh, docs/cli.md): GEODE_TEST_FAIL_RANK=R:STAGE
// makes rank R alone fail at STAGE (read: after reading, while the others go on into the
// conform's collectives; write: before writing its piece, after the others wrote theirs).
void fail_for_test(int rank, const std::string& stage) {
  const char* v = std::getenv("GEODE_TEST_FAIL_RANK");
  if (v && std::string(v) == std::to_string(rank) + ":" + stage)
    throw InvalidInput("rank " + std::to_string(rank) + ": GEODE_TEST_FAIL_RANK is set (" + stage +
                       ")");
}

// How long a rank that failed waits for the others to agree before it aborts the run: errors
// every rank meets alike (the input, the zone, an invalid result) reach the agreement within
// moments of each other; one that waits this long is not coming.
constexpr double kAgreeSeconds = 10.0;

MPI_Comm agreement = MPI_COMM_NULL;  // MPI_COMM_WORLD's duplicate for agree() (main)

// The ranks' exit codes agreed by a non-blocking all-reduce, and the failure told once: by the
// lowest rank that failed (every rank fails alike on a bad input: rank 0 then). A rank that
// failed alone (its own piece of the file, its memory, its write) while the others wait in a
// collective it will never join cannot be waited for: after kAgreeSeconds it says its failure
// and aborts the run with its code (mpirun exits with it and stops the other ranks, whose
// temporaries their signal handlers remove), instead of leaving every rank waiting forever.
int agree(int code, const std::string& failure, int rank, const std::function<void()>& discard) {
  int worst = 0;
  MPI_Request request;
  // On a communicator of its own (made by every rank at the start): a rank that failed early
  // posts it while the others are still in the run's collectives, which it must not match.
  MPI_Iallreduce(&code, &worst, 1, MPI_INT, MPI_MAX, agreement, &request);
  if (code == 0) {
    parallel::wait_quietly(request);
  } else {
    const double deadline = MPI_Wtime() + kAgreeSeconds;
    for (int done = 0;;) {
      MPI_Test(&request, &done, MPI_STATUS_IGNORE);
      if (done) break;
      if (MPI_Wtime() > deadline) {
        std::cerr << failure << " (rank " << rank << " alone; the run is aborted)" << std::endl;
        discard();  // its temporaries: MPI_Abort runs no destructor
        MPI_Abort(MPI_COMM_WORLD, code);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  // The lowest failing rank says why (the ranks are all here: a blocking reduction).
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int mine = code != 0 ? rank : size;
  int lowest = size;
  MPI_Allreduce(&mine, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (rank == lowest) std::cerr << failure << "\n";
  return worst;
}

// What rank 0 prints of a run that got as far as every rank's hexes (valid or not): the run's
// line, each rank's stages and peak; and the warnings (on stderr, see run()).
struct Summary {
  std::string head, line;
  std::vector<std::string> warnings;
};

// Collective (after agree()): the ranks' lines gathered to rank 0 and printed there, when every
// rank has one.
void print_summary(const Summary& summary, int rank, int size) {
  const int has = summary.line.empty() ? 0 : 1;
  int all_have = 0;
  MPI_Allreduce(&has, &all_have, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all_have) return;
  const std::string& text = summary.line;
  int n = primal::index_cast<int>(text.size());
  std::vector<int> counts(primal::index_cast<std::size_t>(size)), displs(counts.size());
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::exclusive_scan(counts.begin(), counts.end(), displs.begin(), 0);
  std::string all(rank == 0 ? primal::index_cast<std::size_t>(displs.back() + counts.back()) : 0,
                  ' ');
  MPI_Gatherv(text.data(), n, MPI_CHAR, all.data(), counts.data(), displs.data(), MPI_CHAR, 0,
              MPI_COMM_WORLD);
  if (rank != 0) return;
  std::cout << summary.head;
  for (std::size_t r = 0; r < counts.size(); ++r)
    std::cout << "  "
              << all.substr(primal::index_cast<std::size_t>(displs[r]),
                            primal::index_cast<std::size_t>(counts[r]))
              << "\n";
}

// Every rank reads the input (a .msh whole): the reader's warnings, the same on every rank, were
// printed once per rank. Collected instead, and printed by rank 0, also when the read then fails.
struct RankZeroReadWarnings {
  explicit RankZeroReadWarnings(int r) : rank(r) {}
  RankZeroReadWarnings(const RankZeroReadWarnings&) = delete;
  RankZeroReadWarnings& operator=(const RankZeroReadWarnings&) = delete;
  int rank;
  io::ReadWarnings collected;
  ~RankZeroReadWarnings() {
    if (rank == 0)
      for (const auto& w : collected.messages()) std::cerr << "geode_mpi: warning: " << w << "\n";
  }
};

// The outputs, before any work: Exodus pieces OUT.exo.N.r (and OUT.exo with --join) in a
// writable directory, none of them the input or a piece of the input's Nemesis set (geode_mpi
// has no --force: it would overwrite what it reads).
void check_outputs(const std::string& output, const std::string& input, int size, bool join) {
  if (output.empty() || output == "-")
    throw InvalidInput("-o '" + output + "': the pieces are Exodus files: give -o OUT.exo");
  cli::check_output_path(output);
  cli::check_output_path(parallel::rank_file(output, size, size - 1));  // pieces: names alike
  cli::output_format(output, "", {"exo"}, "");
  std::vector<std::string> inputs{input};
  if (const auto set = io::find_nemesis_set(input))
    for (const auto& f : set->files) inputs.push_back(f.string());
  for (const std::string& in : inputs) {
    if (join) cli::check_not_input(output, in);
    for (int r = 0; r < size; ++r) cli::check_not_input(parallel::rank_file(output, size, r), in);
  }
}

int run(int argc, char** argv, int rank, int size) {
  CLI::App app{"geode conform under MPI: mpirun -np N geode_mpi conform INPUT -o OUT.exo"};
  app.require_subcommand(1);
  app.set_version_flag("--version", cli::version_text(), "print the version and exit");
  CLI::App* conform = app.add_subcommand("conform", "conform a hex + tet model, partitioned");
  std::string input, output, smooth = "local", side, verify = "local";  // side: automatic
  bool join = false, quiet = false, unfold = false;
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
  conform
      ->add_option("--buffer-side", side,
                   "the part the buffer layer is carved from: hex or tet; not given, as for geode "
                   "conform: hex, or tet where the hex cells at the interface are thin, or both "
                   "tried where they are nearly so")
      ->check(CLI::IsMember({"hex", "tet"}));
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
  conform->add_option("--threads", threads, "TBB threads per rank (default 1: one core each)")
      ->check(CLI::Range(1, 4096));
  conform
      ->add_option(
          "--zone-threads", zone_threads,
          "TBB threads of the transition zone's conform on the last rank (default 0: one per CPU "
          "the ranks on its machine were given; they wait for the zone without spinning once their "
          "own dicing is done); the result is the same for any count")
      ->check(CLI::Range(0, 4096));
  std::vector<std::string> join_blocks;
  cli::add_join_blocks_option(conform, join_blocks);
  cli::add_unfold_option(conform, unfold);
  conform->add_flag("-q,--quiet", quiet, "no progress or summary");
  try {
    cli::refuse_empty_arguments(argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {  // --help, --version
      if (rank == 0) app.exit(e);
      return 0;
    }
    // One line, as geode's (cli/main.cpp), from the first rank only.
    const std::string cmd = app.get_subcommands().empty() ? "geode_mpi" : "geode_mpi conform";
    if (rank == 0)
      std::cerr << cmd << ": usage error: " << cli::one_line(e.what()) << " (see " << cmd
                << " --help)\n";
    return 2;
  }
  // The rank's own work runs in an arena of `threads`; the zone's conform in one of its own,
  // which may take every CPU of the machine (DistributedOptions::zone_threads): the process's
  // limit is the larger (TBB's default is the CPUs mpirun bound the rank to).
  const int cpus = std::max(static_cast<int>(std::thread::hardware_concurrency()), 1);
  tbb::global_control threads_limit(
      tbb::global_control::max_allowed_parallelism,
      primal::index_cast<std::size_t>(std::max({threads, zone_threads, cpus, 1})));
  // The outputs this rank writes (published by commit() after the agreement), and the one line
  // its failure says (printed by the lowest rank that failed: agree()).
  cli::OutputFiles files;
  std::string failure;
  Summary summary;  // filled once the rank has its hexes, printed by rank 0 (print_summary)
  // Progress: rank 0 says each stage as it ends, with its seconds (the other ranks' stages are
  // in the summary).
  const bool say_progress = rank == 0 && !quiet;
  double said_at = 0;
  const auto say = [&](const std::string& line, bool timed) {
    if (!say_progress) return;
    say_line("geode_mpi: " + (timed ? cli::stage_line(line, MPI_Wtime() - said_at) : line));
    said_at = MPI_Wtime();
  };
  // Everything after the options, in the rank's arena.
  const auto conform_in_arena = [&]() -> int {
    try {
      cli::check_buffer_thickness(thickness, side);
      check_outputs(output, input, size, join);
      const double t0 = MPI_Wtime();
      said_at = t0;
      parallel::DistributedOptions options;
      options.conform.smooth = conform::parse_conform_smooth(smooth);
      conform::set_buffer_side(options.conform, side);
      options.conform.buffer.thickness = thickness;
      options.conform.verify = conform::parse_conform_verify(verify);
      options.rings = rings;
      options.zone_threads = zone_threads;
      // Rank 0's stages; it waits in "zone shared" while the last rank conforms the zone.
      if (say_progress) options.progress = [&](const std::string& line) { say(line, false); };
      // The zone's conform says its own stages on the rank that runs it (the last).
      if (!quiet)
        options.zone_progress = [](const std::string& line) {
          say_line("geode_mpi: zone: " + line);
        };
      // Each rank frees the input once it has its piece, and reads it again only if the zone
      // grows after that (the read-time check passed already).
      // With --unfold (as geode conform's): read without the geometry check, then every rank
      // mends the same folds in its whole copy (unfold is deterministic).
      primal::ReadOptions read;
      read.check_geometry = !unfold;
      if (!unfold) read.inverted_hint = primal::inverted_hint("--unfold");
      options.reload = [&] {
        io::ReadWarnings said_at_the_first_read;
        primal::Model again = io::read_model(input, read, false);
        cli::join_block_lists(again, join_blocks, input);
        if (unfold) primal::unfold(again);
        return again;
      };
      io::FilePartition file_partition;
      // The check's face pairs make rank 0's partition graph (DistributedOptions).
      std::vector<std::array<primal::Index, 2>> element_pairs;
      options.element_pairs = &element_pairs;
      primal::Model model = [&] {
        RankZeroReadWarnings warnings(rank);
        primal::InputCheckOptions check = parallel::shared_input_check(MPI_COMM_WORLD);
        check.element_pairs = &element_pairs;
        if (!unfold) check.fold_hint = primal::fold_hint("--unfold");
        return io::read_model(input, read, !unfold, &file_partition, check);
      }();
      // Joined before unfold, as geode conform does: a node between the blocks joined may move.
      cli::join_block_lists(model, join_blocks, input);
      say("read " + input + ": " + std::to_string(primal::element_count(model)) + " elements",
          true);
      if (unfold) {
        const primal::UnfoldResult u = primal::unfold(model);
        say(cli::unfold_stage(u), true);
        if (rank == 0 && u.unfolded())  // the analyst's mesh changed: said whatever -q says
          std::cerr << "geode_mpi: warning: " << input << ": " << cli::unfold_warning(model, u)
                    << "\n";
        primal::check_geometry(model, input);
        // The shared check even where unfold ran its own: its face pairs are the partition's.
        primal::InputCheckOptions check = parallel::shared_input_check(MPI_COMM_WORLD);
        check.element_pairs = &element_pairs;
        primal::require_single_covering(model, input, check);
      }
      fail_for_test(rank, "read");
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
      // The joined file (rank 0 gathers: collective) and each rank's piece, to temporaries
      // published only once every rank has written its own (agree(), then commit()): a rank
      // failing to write leaves no set with a piece missing, and none waiting for it.
      if (report.valid && join) {
        if (rank == 0)
          files.write(files.add(output, [&](const std::filesystem::path& temp) {
            parallel::write_joined(mesh, temp, MPI_COMM_WORLD);
          }));
        else
          parallel::write_joined(mesh, {}, MPI_COMM_WORLD);
      }
      if (report.valid) {
        const std::size_t piece = files.add(parallel::rank_file(output, size, rank),
                                            [&](const std::filesystem::path& temp) {
                                              parallel::write_nemesis(mesh, temp, size, rank);
                                            });
        fail_for_test(rank, "write");
        files.write(piece);
        say(join ? "wrote the joined file and rank 0's piece" : "wrote rank 0's piece", true);
      }
      const double t_all = MPI_Wtime() - t0;
      // Per rank: time per stage and peak memory, gathered to rank 0 after the agreement.
      std::ostringstream line;
      line << "rank " << rank << ": " << mesh.model.hexes.size() << " hexes (" << report.zone_hexes
           << " of the transition zone, " << report.diced_hexes << " diced), read " << t_read
           << " s, conform " << t_conform << " s (";
      for (const auto& [stage, s] : report.seconds) line << stage << " " << s << " s, ";
      line << "), write " << t_all - t_read - t_conform << " s, total " << t_all << " s, peak "
           << peak_mib() << " MiB";
      std::ostringstream head;
      head << "geode_mpi: " << size << " ranks, " << mesh.global_hexes << " hexes, "
           << mesh.global_nodes << " nodes, transition zone " << report.zone_cells
           << " input elements (" << report.rings << " rings), partition: " << partitioned_by
           << ", " << (report.valid ? "valid" : "INVALID") << ", " << t_all << " s\n";
      summary = {head.str(), line.str(), report.warnings};
      if (!report.valid) {
        for (const auto& w : report.warnings) std::cerr << "geode_mpi: " << w << "\n";
        failure = "geode_mpi: invalid result, nothing written";
        return 4;
      }
      return 0;
    } catch (const InvalidInput& e) {  // the kinds geode's own lines name (cli/main.cpp)
      failure = "geode_mpi: error: " + std::string(e.what());
      return 2;
    } catch (const TopologyError& e) {
      failure = "geode_mpi: topology error: " + std::string(e.what());
      return 3;
    } catch (const std::bad_alloc&) {
      // As the serial command (cli/main.cpp): one line and exit 2.
      failure = "geode_mpi conform (rank " + std::to_string(rank) +
                "): error: out of memory: " + cli::out_of_memory_reason() + " (nothing written)";
      return 2;
    } catch (const std::exception& e) {
      failure = "geode_mpi (rank " + std::to_string(rank) + "): " + e.what();
      return 4;
    }
  };
  tbb::task_arena arena(std::max(threads, 1));
  int code = 0;
  arena.execute([&] { code = conform_in_arena(); });
  const int worst = agree(code, failure, rank, [&] { files.discard(); });
  if (!quiet) print_summary(summary, rank, size);
  // Warnings of a valid result go to stderr, -q or not, as the serial command's do (an invalid
  // one's are in its error): those of the zone's conform (every rank has them) among them.
  if (worst == 0 && rank == 0)
    for (const auto& w : summary.warnings) std::cerr << "geode_mpi: warning: " << w << "\n";
  if (worst != 0) return worst;
  // Rank 0's summary lost (its standard output closed, a full disk behind `> log`): no rank
  // publishes, where OutputFiles::commit refusing on rank 0 alone would leave a set with its
  // piece missing. Every rank is past agree(): a blocking broadcast.
  std::string lost = rank == 0 ? cli::standard_output_failure() : std::string();
  int lost_flag = lost.empty() ? 0 : 1;
  MPI_Bcast(&lost_flag, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (lost_flag) {
    if (rank == 0) std::cerr << "geode_mpi conform: error: " << lost << " (nothing written)\n";
    return 2;  // the temporaries go with `files`
  }
  // Test hook (tests/parallel/mpi_verify_test.sh, docs/cli.md): GEODE_TEST_PAUSE_BEFORE_COMMIT=S
  // makes every rank wait S seconds with its pieces written, before publishing them.
  if (const char* pause = std::getenv("GEODE_TEST_PAUSE_BEFORE_COMMIT"); pause && *pause)
    std::this_thread::sleep_for(std::chrono::duration<double>(std::atof(pause)));
  try {
    files.commit();  // every rank wrote its piece: all published
  } catch (const std::exception& e) {
    std::cerr << "geode_mpi (rank " << rank << "): " << e.what() << "\n";
    return 2;
  }
  return 0;
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
  MPI_Comm_dup(MPI_COMM_WORLD, &agreement);
  // An interrupted rank removes its hidden temporaries (io/atomic_file.hpp), as geode does:
  // mpirun passes SIGINT and SIGTERM on to the ranks as SIGTERM, after a SIGCONT a second
  // earlier, which is taken as the abort.
  io::install_signal_cleanup();
  io::install_launcher_abort_cleanup();
  const int code = run(argc, argv, rank, size);  // every rank's worst (agree())
  MPI_Comm_free(&agreement);
  MPI_Finalize();
  return code;
}
