#pragma once
// Write a file so that readers never see it half-written: the content goes to a temporary file
// in the same directory (so that the final rename stays on one file system and is atomic under
// POSIX), which replaces the target only once it has been written, flushed and synced.
//
// Every temporary is registered while it exists, and install_signal_cleanup() (called once by
// the `geode` command) makes the signals that end a process (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
// a CPU limit's SIGXCPU, ...) unlink the registered ones before the signal takes its default
// action: an interrupted run leaves no hidden file behind.
//
// The target is followed through symbolic links: a link is written through to the file it
// names (and stays a link). A target that is not a regular file (a device such as /dev/full, a
// FIFO) gets the finished content copied into it, a failed write (a full device) being an error.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace geode::io {

// Calls `write` with a stream on a temporary file next to `path`, then renames it over `path`.
// If `write` throws or the stream fails, the temporary file is removed, `path` is left as it
// was, and the exception propagates (a failed write becomes geode::InvalidInput naming `path`
// and the system's reason; io/file_sink.hpp writes the bytes).
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

// The same for libraries that write by file name (Exodus II, Gmsh): `write` gets the path of a
// fresh, empty temporary file next to `path` (ending in `suffix`, for writers that choose the
// format by extension) and must fill it; an empty file afterwards counts as a failed write.
void write_path_atomically(const std::filesystem::path& path, const std::string& suffix,
                           const std::function<void(const std::filesystem::path& temp)>& write);

// Where output `path` really goes: symbolic links followed to the file they name (which need not
// exist yet); `regular` is false for an existing target that is not a regular file (a device, a
// FIFO), which is written by copying into it instead of renaming over it.
struct OutputTarget {
  std::filesystem::path file;
  bool regular = true;
};
OutputTarget resolve_output(const std::filesystem::path& path);

// A fresh temporary file name for `target`: hidden, next to the file (the system's temporary
// directory for a target that is not a regular file), with the pid, a counter and `suffix`;
// created empty (O_EXCL) and registered for removal on signals. InvalidInput when it cannot be.
std::filesystem::path create_temporary(const OutputTarget& target, const std::string& suffix);

// Moves a finished temporary to its target (rename, or copy into a non-regular target and remove
// the temporary); InvalidInput naming `shown` (the path the user gave) when that fails.
void publish_temporary(const std::filesystem::path& temp, const OutputTarget& target,
                       const std::filesystem::path& shown);

// Several finished temporaries published as one (a mesh and its report: both or neither).
// Each regular target that exists is first given a hidden hard link ("..NAME.old-PID-N") and
// registered with it for signals; then the temporaries are renamed (regular targets first,
// copies into devices last). If a rename or copy fails, or SIGINT / SIGTERM / SIGHUP / SIGQUIT
// arrives before the last one is done, every target already replaced gets its former content
// back (a target that did not exist is removed): never one output without the other, never a
// former output lost. InvalidInput naming the target that failed ("...; nothing written").
// Test hook: GEODE_TEST_SIGNAL_BETWEEN_RENAMES=N raises signal N right after the first rename
// of two or more (tests/cli/outputs_test.cpp).
struct Publication {
  std::filesystem::path temp;
  OutputTarget target;
  std::filesystem::path shown;  // the path the user gave, for messages
};
void publish_together(const std::vector<Publication>& items);

// Removes a temporary (if it is still there) and forgets it.
void remove_temporary(const std::filesystem::path& temp);

// Registers / forgets a path to unlink on a signal (create_temporary registers its own;
// publish_temporary and remove_temporary forget them). At most 64 at once; more are not
// cleaned up on signals (they are still removed on every ordinary exit path).
void register_temporary(const std::filesystem::path& temp);
void unregister_temporary(const std::filesystem::path& temp);

// Installs the handlers for SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXCPU, SIGXFSZ, SIGALRM,
// SIGVTALRM, SIGPROF, SIGUSR1, SIGUSR2 and SIGPIPE (unless ignored when the process started):
// unlink every registered temporary (async-signal-safe: a fixed table, unlink), then re-raise
// with the default action.
void install_signal_cleanup();

// For a process run by a parallel launcher: there an abort (the launcher's own SIGINT or
// SIGTERM, or another rank's failure) reaches a rank as SIGCONT at once, SIGTERM only a second
// later (OpenMPI's odls_base_sigkill_timeout; Slurm's scancel alike) and SIGKILL a few
// milliseconds after that: a rank that waited for SIGTERM went on publishing its outputs in
// that second, or was killed mid-cleanup. A SIGCONT that does not end a stop is therefore taken
// as that SIGTERM. A stop is told by a heartbeat thread's last tick (every 50 ms): a process
// resumed after a stop of kLauncherStopSeconds or more (Ctrl-Z then fg, a scheduler's suspend)
// sees it stale and goes on.
inline constexpr double kLauncherStopSeconds = 0.5;
void install_launcher_abort_cleanup();

}  // namespace geode::io
