#pragma once
// Running a library on an untrusted file in a child process of its own, so that whatever the
// library does on a corrupt file (a crash, an allocation of all memory, an endless loop) ends
// that child and becomes one InvalidInput in the caller, never the caller's crash.
//
// Why a process and not checks before the call: libhdf5 (through which netCDF reads netCDF-4
// Exodus files) parses B-trees, heaps and object headers that no cheap check before it can
// validate whole, and it is not hardened against corrupt files (fuzzing finds SEGVs in it
// within seconds). A forked child under resource limits contains all of that, whatever the
// library version. The child only runs the library and returns raw bytes; everything that
// interprets them runs in the caller, where sanitizers and fuzzers see it.
#include <cstdint>
#include <functional>
#include <string>

namespace geode::io {

struct IsolationLimits {
  // Address space the child may add to what it inherits (RLIMIT_AS; not applied in sanitizer
  // builds, whose shadow memory is outside any such budget).
  std::uint64_t memory_bytes = std::uint64_t{2} << 30;
  // CPU seconds for the child (RLIMIT_CPU): an endless loop on a corrupt file ends.
  unsigned cpu_seconds = 300;
  // Seconds of wall-clock time the caller waits for the child's answer before killing it: a
  // child that waits for ever spends no CPU time (a lock held, at the fork, by another thread
  // of the caller's: the CLI builds templates on a thread while it reads).
  unsigned wall_seconds = 600;
  // The most bytes the child may return (its answer is bounded like any input).
  std::uint64_t max_result_bytes = std::uint64_t{1} << 34;
};

// Runs `work` in a forked child and returns the bytes it returned. In the child, an
// InvalidInput (or std::bad_alloc, or any other exception) becomes the same InvalidInput in
// the caller; a child killed by a signal or out of its limits (killed at its wall-clock limit)
// becomes InvalidInput "`source`: `what` failed: <how>", and so does a child that ends without
// its answer (the library calling exit, or a sanitizer's heap check on the library's own
// corruption in sanitizer builds). The child never returns into the caller's code: it ends
// with _exit; its output goes to /dev/null (outside sanitizer builds). An exception in the
// child other than InvalidInput and std::bad_alloc is a fault of ours: std::runtime_error, so
// that tests and fuzzers report it.
std::string run_isolated(const std::function<std::string()>& work, const std::string& source,
                         const std::string& what, const IsolationLimits& limits = {});

}  // namespace geode::io
