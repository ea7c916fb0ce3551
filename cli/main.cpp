// geode: all-hex meshing through the dual (the Spatial Twist Continuum).
#include <execinfo.h>
#include <malloc.h>

#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <system_error>

#include <tbb/global_control.h>

#include <geode/io/atomic_file.hpp>
#include <geode/primal/errors.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"

namespace {

using geode::cli::one_line;

// A worker thread that could not be started: TBB reports pthread_create's failure as a
// std::runtime_error ("pthread_create has failed: Resource temporarily unavailable"), std::thread
// as a std::system_error. Under a memory cap (ulimit -v) it is the new thread's stack that does
// not fit, like an allocation that fails.
bool thread_start_failed(const std::exception& e) {
  if (const auto* s = dynamic_cast<const std::system_error*>(&e);
      s && s->code() == std::errc::resource_unavailable_try_again)
    return true;
  return std::string_view(e.what()).find("pthread_create") != std::string_view::npos;
}

// "geode conform" for the deepest sub-command given, for the --help hint.
std::string command_path(const CLI::App& app) {
  std::string path = "geode";
  const CLI::App* a = &app;
  while (true) {
    const auto subs = a->get_subcommands();
    if (subs.empty()) break;
    a = subs.front();
    path += " " + a->get_name();
  }
  return path;
}

// What a command printed on standard output went out whole, or the run fails (exit 2 unless it
// failed already): a full disk or a closed descriptor behind `geode check m.exo > report.txt`
// lost the report while the command exited 0.
int check_standard_output(int code, const std::string& command) {
  const std::string failure = geode::cli::standard_output_failure();
  if (failure.empty()) return code;
  std::cerr << command << ": error: " << failure << "\n";
  return code != 0 ? code : 2;
}

}  // namespace

int main(int argc, char** argv) {
  // glibc unwinds through its own frames with libgcc_s, which it loads on first need; an
  // exception thrown for want of memory (ulimit -v) could then find no memory to load it and
  // abort ("libgcc_s.so.1 must be installed for unwinding to work"). backtrace() loads it now.
  {
    void* frame[1];
    (void)backtrace(frame, 1);
  }
  // Arrays of a MiB or more get pages of their own, given back to the system when freed.
  // glibc's default threshold rises to 32 MiB after the first such array is freed, and the
  // arrays a stage frees then stay resident through the next: 14 MB of the peak on the
  // n = 36 Delaunay model (docs/results.md, "Memory").
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  CLI::App app{
      "geode: all-hex transition templates derived from completed dual sheet arrangements, and "
      "the\n"
      "geode algorithm that conforms a diced hex mesh to a diced tet mesh with them.\n"
      "Exit codes: 0 done, 2 usage or input error, 3 topology refusal, 4 invalid result."};
  // A write to a closed pipe or FIFO (SIGPIPE) or past a file size limit (ulimit -f: SIGXFSZ)
  // fails as an error the command reports in one line (exit 2), its outputs rolled back, instead
  // of killing it mid-publish: a FIFO output whose reader left ended the run by SIGPIPE with the
  // report already replaced and the mesh not.
  ::signal(SIGPIPE, SIG_IGN);
  ::signal(SIGXFSZ, SIG_IGN);
  // An interrupted run removes its hidden temporary files (io/atomic_file.hpp).
  geode::io::install_signal_cleanup();
  // Building the commands allocates too: inside the try, so that running out of memory there
  // is the one-line exit 2 as well.
  int code = 0;
  try {
    app.require_subcommand(1);
    app.set_version_flag("--version", geode::cli::version_text(), "print the version and exit");
    // --threads before or after the command: subcommands pass options they do not know to here
    // (fallthrough, inherited by the commands added below). Its callback runs before any command's.
    // The --threads limit is never destroyed: lifting it would start TBB's worker threads on the
    // way out, which fails (and aborts, a destructor throwing) when the run ended for want of
    // memory. Held by a static pointer, it stays reachable until exit (no leak to LeakSanitizer).
    static tbb::global_control* threads = nullptr;
    app.fallthrough();
    app.add_option_function<int>(
           "--threads",
           [](int n) {
             delete threads;
             threads = new tbb::global_control(tbb::global_control::max_allowed_parallelism,
                                               geode::primal::index_cast<std::size_t>(n));
           },
           "worker threads (default: every core), for every command, given before or after it;\n"
           "every result is the same for any number")
        ->check(CLI::Range(1, 4096));
    geode::cli::add_template_command(app);
    geode::cli::add_study_commands(app);
    geode::cli::add_conform_commands(app);
    geode::cli::add_dual_command(app);
    geode::cli::add_check_command(app);
    geode::cli::add_arrange_command(app);
    geode::cli::add_view_command(app);
    geode::cli::add_formats_command(app);
    geode::cli::refuse_empty_arguments(argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0)  // --help, --version
      return check_standard_output(app.exit(e), command_path(app));
    std::string cmd = command_path(app);
    // An unknown command word: CLI11 says a subcommand is required, as if none were given.
    std::string word;
    for (int i = 1; i < argc && word.empty(); ++i) {
      const std::string_view arg = argv[i];
      if (arg == "--threads")
        ++i;  // the global option's value
      else if (!arg.empty() && arg[0] != '-')
        word = arg;
    }
    const auto named = app.get_subcommands([&](CLI::App* s) { return s->check_name(word); });
    // Refused before parsing (refuse_empty_arguments): the command word still names the help.
    if (cmd == "geode" && named.size() == 1) cmd += " " + named.front()->get_name();
    if (cmd == "geode" && !word.empty() && named.empty())
      std::cerr << "geode: usage error: '" << word << "' is not a command (see geode --help)\n";
    else
      std::cerr << cmd << ": usage error: " << one_line(e.what()) << " (see " << cmd
                << " --help)\n";
    code = 2;
  } catch (const geode::InvalidInput& e) {
    std::cerr << "geode: error: " << one_line(e.what()) << "\n";
    code = 2;
  } catch (const geode::TopologyError& e) {
    std::cerr << "geode: topology error: " << one_line(e.what()) << "\n";
    code = 3;
  } catch (const geode::cli::InvalidResult& e) {
    std::cerr << "geode: invalid result: " << one_line(e.what()) << "\n";
    code = 4;
  } catch (const std::bad_alloc&) {
    // An input whose model does not fit: still one line and exit 2, not a crash.
    std::cerr << command_path(app)
              << ": error: out of memory: " << geode::cli::out_of_memory_reason()
              << " (nothing written)\n";
    code = 2;
  } catch (const std::length_error& e) {
    std::cerr << command_path(app)
              << ": error: the input asks for a container larger than memory can hold ("
              << one_line(e.what()) << "; nothing written)\n";
    code = 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the command could not resolve or reach: the user's, so exit 2 as any bad path
    // (the message names it), not 1, which no documented case uses.
    std::cerr << command_path(app) << ": error: " << one_line(e.what()) << " (nothing written)\n";
    code = 2;
  } catch (const std::exception& e) {
    if (thread_start_failed(e)) {
      std::cerr << command_path(app) << ": error: cannot start a worker thread ("
                << one_line(e.what())
                << "): the process may not take the memory (or the processes) one more thread "
                   "needs; --threads 1 runs without them (nothing written)\n";
      code = 2;
    } else {
      std::cerr << "geode: error: " << one_line(e.what()) << "\n";
      code = 1;
    }
  }
  return check_standard_output(code, command_path(app));
}
