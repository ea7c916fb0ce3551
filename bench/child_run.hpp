#pragma once
// Timing work in a child process, so that its peak RSS and CPU time are its own and not the
// bench's: wall time from fork to wait4, user + system CPU and peak RSS from the child's
// rusage. Shared by the bench programs; not part of any library.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>

namespace geode::bench {

struct ChildRun {
  double seconds = 0.0;      // wall time, fork to wait4
  double cpu_seconds = 0.0;  // user + system
  double peak_mib = 0.0;
  int status = 0;  // wait status; 0 when the child exited 0
};

// Waits for `pid`, forked at `start`.
inline ChildRun wait_child(pid_t pid, std::chrono::steady_clock::time_point start) {
  int status = 0;
  rusage ru{};
  if (::wait4(pid, &status, 0, &ru) != pid) {
    std::perror("wait4");
    std::exit(2);
  }
  const auto cpu = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  ChildRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cpu_seconds = cpu(ru.ru_utime) + cpu(ru.ru_stime);
  r.peak_mib = static_cast<double>(ru.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
  r.status = status;
  return r;
}

// Runs `work` in a forked child, which ends without running the parent's destructors.
inline ChildRun run_in_child(const std::function<void()>& work) {
  std::fflush(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) {
    std::perror("fork");
    std::exit(2);
  }
  if (pid == 0) {
    work();
    std::_Exit(0);
  }
  ChildRun r = wait_child(pid, start);
  if (r.status != 0) std::printf("  child failed (wait status %d)\n", r.status);
  return r;
}

}  // namespace geode::bench
