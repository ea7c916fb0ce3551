// io::run_isolated (io/isolated.hpp): whatever the work in the child does (a crash, an endless
// loop, all memory, an exception), the caller gets one InvalidInput naming the file, or the
// child's answer, and no child is left behind.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <geode/io/isolated.hpp>
#include <geode/primal/errors.hpp>

using geode::InvalidInput;
using geode::io::IsolationLimits;
using geode::io::run_isolated;

namespace {

// No child of this process is left to reap.
bool no_children() { return ::waitpid(-1, nullptr, WNOHANG) < 0 && errno == ECHILD; }

}  // namespace

TEST_CASE("run_isolated: the child's bytes come back, its failures become InvalidInput") {
  std::string big(3 << 20, 'x');  // more than a pipe holds at once
  big[12345] = '\0';
  CHECK(run_isolated([&] { return big; }, "f.exo", "reading") == big);
  CHECK(run_isolated([] { return std::string(); }, "f.exo", "reading").empty());
  CHECK_THROWS_WITH_AS(
      run_isolated([]() -> std::string { throw InvalidInput("f.exo: node 3 is out of range"); },
                   "f.exo", "reading"),
      "f.exo: node 3 is out of range", InvalidInput);
  CHECK_THROWS_WITH_AS(run_isolated(
                           []() -> std::string {
                             ::raise(SIGSEGV);
                             return {};
                           },
                           "f.exo", "reading the netCDF-4 file"),
                       doctest::Contains("f.exo: reading the netCDF-4 file failed: the library "
                                         "reading it crashed (signal 11"),
                       InvalidInput);
  CHECK_THROWS_WITH_AS(
      run_isolated([]() -> std::string { throw std::bad_alloc(); }, "f.exo", "reading"),
      doctest::Contains("f.exo: reading failed: it needs more than 2048 MiB of memory"),
      InvalidInput);
  IsolationLimits one_second;
  one_second.cpu_seconds = 1;
  CHECK_THROWS_WITH_AS(run_isolated(
                           []() -> std::string {
                             std::atomic<unsigned long> spins{0};
                             for (;;) spins.fetch_add(1, std::memory_order_relaxed);
                           },
                           "f.exo", "reading", one_second),
                       doctest::Contains("f.exo: reading failed: it took more than 1 s of CPU"),
                       InvalidInput);
  // A child that never answers and spends no CPU time (waiting on a lock another thread held
  // at the fork) is killed at the wall-clock limit.
  IsolationLimits one_wall_second;
  one_wall_second.wall_seconds = 1;
  CHECK_THROWS_WITH_AS(run_isolated(
                           []() -> std::string {
                             for (;;) ::pause();
                           },
                           "f.exo", "reading", one_wall_second),
                       doctest::Contains("f.exo: reading failed: it took more than 1 s"),
                       InvalidInput);
  // An exception that is not about the file is a fault of ours, not a refusal of the input.
  CHECK_THROWS_AS(
      run_isolated([]() -> std::string { throw std::logic_error("bug"); }, "f.exo", "reading"),
      std::runtime_error);
  CHECK(no_children());
}

#if !defined(__SANITIZE_ADDRESS__)
TEST_CASE("run_isolated: the child's address space is capped") {
  IsolationLimits small;
  small.memory_bytes = std::uint64_t{256} << 20;
  CHECK_THROWS_WITH_AS(run_isolated(
                           []() -> std::string {
                             std::vector<char> v(std::size_t{1} << 30, 'x');
                             return std::string(1, v[12345]);
                           },
                           "f.exo", "reading", small),
                       doctest::Contains("needs more than 256 MiB"), InvalidInput);
  CHECK(no_children());
}

TEST_CASE("run_isolated: under the caller's own lower cap (ulimit -v) the child keeps it") {
  // In a process of its own: the cap would hold the test binary too. Its child, allowed 2 GiB
  // by default, must neither exceed the caller's limit (root could raise it) nor blame the
  // file for running out under it.
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    std::ifstream statm("/proc/self/statm");
    std::uint64_t pages = 0;
    statm >> pages;
    const std::uint64_t cap =
        pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)) + (std::uint64_t{256} << 20);
    const rlimit limit{cap, cap};
    if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(3);
    try {
      run_isolated(
          []() -> std::string {
            std::vector<char> v(std::size_t{1} << 30, 'x');  // within 2 GiB, beyond the cap
            return std::string(1, v[12345]);
          },
          "f.exo", "reading");
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      ::_exit(what.find("f.exo: reading failed: out of memory: this process may use") == 0 &&
                      what.find("(ulimit -v)") != std::string::npos
                  ? 0
                  : 1);
    }
    ::_exit(2);  // the child's read succeeded: it was not capped
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);  // 1: another message; 2: not capped; 3: setrlimit failed
}
#endif
