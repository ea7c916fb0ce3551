#include <geode/io/atomic_file.hpp>

#include <fcntl.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>

#include <geode/io/file_sink.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

namespace fs = std::filesystem;

namespace {

std::string reason(int err) { return std::strerror(err); }

// What a signal must undo: a fixed table (no allocation, no locks), each slot free (0), being
// filled (1) or holding a path to remove (2) or a target to restore from its backup (3).
// std::atomic<int> is lock-free here, so the handler may read it.
constexpr int kSlots = 64;
constexpr std::size_t kPathBytes = 4096;
struct Slot {
  std::atomic<int> state{0};
  char path[kPathBytes];
  char backup[kPathBytes];  // state 3: the target's former content ("" when it had none)
};
Slot g_slots[kSlots];
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void unlink_temporaries_and_reraise(int sig) {
  for (Slot& s : g_slots) {
    const int state = s.state.load();
    if (state == 2 || (state == 3 && s.backup[0] == '\0')) ::unlink(s.path);
    if (state == 3 && s.backup[0] != '\0') {
      ::rename(s.backup, s.path);  // a no-op when both still name the same file
      ::unlink(s.backup);
    }
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Claims a slot for `path` (and `backup`, state 3); -1 when none is free or a path is too long.
int claim_slot(const std::string& path, const std::string* backup) {
  if (path.size() >= kPathBytes || (backup && backup->size() >= kPathBytes)) return -1;
  for (int i = 0; i < kSlots; ++i) {
    Slot& slot = g_slots[i];
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot.path, path.c_str(), path.size() + 1);
    if (backup) std::memcpy(slot.backup, backup->c_str(), backup->size() + 1);
    slot.state.store(backup ? 3 : 2);
    return i;
  }
  return -1;
}

// Removes the temporary file unless released, so that every exit path cleans up.
class TempFileGuard {
 public:
  explicit TempFileGuard(fs::path p) : path_(std::move(p)) {}
  ~TempFileGuard() {
    if (!path_.empty()) remove_temporary(path_);
  }
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;
  void release() { path_.clear(); }

 private:
  fs::path path_;
};

// Copies a finished file into a target that is not a regular file (a device, a FIFO): what a
// write to it says (ENOSPC from /dev/full) is the error.
void copy_into(const fs::path& from, const fs::path& to, const fs::path& shown) {
  const int in = ::open(from.c_str(), O_RDONLY);
  if (in < 0)
    throw InvalidInput(shown.string() + ": cannot reopen the temporary file: " + reason(errno));
  const int out = ::open(to.c_str(), O_WRONLY | O_TRUNC);
  if (out < 0) {
    const int e = errno;
    ::close(in);
    throw InvalidInput(shown.string() + ": cannot open " + to.string() +
                       " for writing: " + reason(e));
  }
  char buf[1 << 16];
  int failure = 0;
  for (;;) {
    const ssize_t n = ::read(in, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      failure = errno;
      break;
    }
    if (n == 0) break;
    for (ssize_t done = 0; done < n;) {
      const ssize_t w = ::write(out, buf + done, static_cast<std::size_t>(n - done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        failure = w < 0 ? errno : EIO;
        break;
      }
      done += w;
    }
    if (failure) break;
  }
  ::close(in);
  if (::close(out) != 0 && !failure) failure = errno;
  if (failure) throw InvalidInput(shown.string() + ": write failed: " + reason(failure));
}

void write_atomically(const fs::path& path, const std::string& suffix,
                      const std::function<void(const fs::path& temp)>& write,
                      bool require_content) {
  if (path.filename().empty()) throw InvalidInput(path.string() + ": not a file name");
  const OutputTarget target = resolve_output(path);
  const fs::path tmp = create_temporary(target, suffix);
  TempFileGuard guard(tmp);
  write(tmp);
  std::error_code ec;
  if (require_content && (fs::file_size(tmp, ec) == 0 || ec))
    throw InvalidInput(path.string() + ": the writer left its temporary file empty");
  // Sync the data before the rename so that a crash cannot leave an empty file under the name.
  const int sfd = ::open(tmp.c_str(), O_RDONLY);
  if (sfd >= 0) {
    ::fsync(sfd);
    ::close(sfd);
  }
  publish_temporary(tmp, target, path);
  guard.release();
}

}  // namespace

void register_temporary(const fs::path& temp) { (void)claim_slot(temp.native(), nullptr); }

void unregister_temporary(const fs::path& temp) {
  for (Slot& slot : g_slots)
    if (slot.state.load() == 2 && temp.native() == slot.path) {
      slot.state.store(0);
      return;
    }
}

void install_signal_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = unlink_temporaries_and_reraise;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  // Every signal whose default action ends the process and that a user or the system sends a
  // running command: a CPU limit (ulimit -t: SIGXCPU), a timer, a script's SIGUSR1 left the
  // temporaries behind. SIGPIPE is the caller's to ignore (geode does: a write to a closed
  // pipe is then an error it reports).
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGXCPU, SIGXFSZ, SIGALRM, SIGVTALRM, SIGPROF,
                  SIGUSR1, SIGUSR2, SIGPIPE}) {
    struct sigaction old {};
    // A signal ignored by whoever started us (nohup) stays ignored.
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

namespace {

std::atomic<std::int64_t> g_heartbeat_ns{0};  // CLOCK_MONOTONIC of the last tick
static_assert(std::atomic<std::int64_t>::is_always_lock_free);

std::int64_t monotonic_ns() {  // async-signal-safe (clock_gettime is)
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

extern "C" void abort_on_unstopped_continue(int) {
  const auto since = monotonic_ns() - g_heartbeat_ns.load();
  if (since < static_cast<std::int64_t>(kLauncherStopSeconds * 1e9))
    unlink_temporaries_and_reraise(SIGTERM);
}

}  // namespace

void install_launcher_abort_cleanup() {
  g_heartbeat_ns.store(monotonic_ns());
  std::thread([] {
    while (true) {
      g_heartbeat_ns.store(monotonic_ns());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }).detach();
  struct sigaction sa {};
  sa.sa_handler = abort_on_unstopped_continue;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  ::sigaction(SIGCONT, &sa, nullptr);
}

OutputTarget resolve_output(const fs::path& path) {
  std::error_code ec;
  // A device or FIFO is written where the path leads, however it gets there: /dev/stdout on a
  // pipe is a link to "pipe:[N]", which names nothing in the file system.
  if (const fs::file_status st = fs::status(path, ec);
      !ec && fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st))
    return OutputTarget{path, false};
  fs::path p = path;
  int hops = 0;
  while (fs::is_symlink(p, ec)) {
    if (++hops > 40) throw InvalidInput(path.string() + ": too many levels of symbolic links");
    const fs::path link = fs::read_symlink(p, ec);
    if (ec) throw InvalidInput(path.string() + ": cannot read the symbolic link: " + ec.message());
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
  OutputTarget t{p, true};
  const fs::file_status st = fs::status(p, ec);
  if (!ec && fs::exists(st)) {
    if (fs::is_directory(st))
      throw InvalidInput(path.string() + ": is a directory, not an output file");
    t.regular = fs::is_regular_file(st);
  }
  return t;
}

fs::path create_temporary(const OutputTarget& target, const std::string& suffix) {
  std::error_code ec;
  const fs::path dir = !target.regular                 ? fs::temp_directory_path(ec)
                       : target.file.has_parent_path() ? target.file.parent_path()
                                                       : fs::path(".");
  // O_CREAT|O_EXCL with a per-process counter gives a name no concurrent writer of the same
  // target uses; the kernel applies the umask to mode 0666 like for any new file.
  static std::atomic<unsigned> counter{0};
  // The target's name cut to leave room for the rest within a name's 255 bytes (a temporary of
  // a temporary included): a legal long output name was refused after the work.
  std::string name = target.file.filename().string();
  if (name.size() > 160) name.resize(160);
  fs::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = dir / ("." + name + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++) + suffix);
    // Registered before it exists: a signal between open and registration cannot leave it.
    register_temporary(tmp);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
    if (fd < 0) unregister_temporary(tmp);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0)
    throw InvalidInput(target.file.string() + ": cannot create a temporary file in " +
                       dir.string() + ": " + reason(errno));
  ::close(fd);  // the writer reopens it by name; the name stays ours until renamed or removed
  return tmp;
}

void publish_temporary(const fs::path& temp, const OutputTarget& target, const fs::path& shown) {
  if (!target.regular) {
    copy_into(temp, target.file, shown);
    remove_temporary(temp);
    return;
  }
  std::error_code ec;
  fs::rename(temp, target.file, ec);
  if (ec)
    throw InvalidInput(shown.string() + ": cannot rename the temporary file: " + ec.message());
  unregister_temporary(temp);
}

void publish_together(const std::vector<Publication>& items) {
  // Regular targets first (each can be undone), then the others (a device copied into cannot).
  std::vector<const Publication*> order;
  for (const Publication& p : items)
    if (p.target.regular) order.push_back(&p);
  for (const Publication& p : items)
    if (!p.target.regular) order.push_back(&p);
  struct Undo {
    fs::path target, backup;  // backup empty: the target did not exist
    int slot = -1;
  };
  std::vector<Undo> undo;
  // Puts every renamed target back as it was and frees the slots; also when none was renamed.
  const auto roll_back = [&undo] {
    std::error_code ec;
    for (const Undo& u : undo) {
      if (u.backup.empty())
        fs::remove(u.target, ec);
      else
        fs::rename(u.backup, u.target, ec);
      if (u.slot >= 0) g_slots[u.slot].state.store(0);
    }
    undo.clear();
  };
  static std::atomic<unsigned> counter{0};
  std::size_t renamed = 0;
  for (const Publication* p : order) {
    if (p->target.regular && items.size() > 1) {
      // The former content under a hidden hard link, registered with the target before the
      // rename: a signal from here on restores it (or removes a target that was new).
      Undo u{p->target.file, {}, -1};
      const fs::path backup = p->target.file.parent_path() /
                              ("." + p->target.file.filename().string() + ".old-" +
                               std::to_string(::getpid()) + "-" + std::to_string(counter++));
      if (::link(p->target.file.c_str(), backup.c_str()) == 0) u.backup = backup;
      const std::string backup_text = u.backup.native();
      u.slot = claim_slot(u.target.native(), &backup_text);
      undo.push_back(u);
    }
    try {
      publish_temporary(p->temp, p->target, p->shown);
    } catch (const InvalidInput& x) {
      if (p->target.regular && !undo.empty()) {
        // This target was not replaced: its backup (if any) is only a second link to it.
        std::error_code ec;
        if (!undo.back().backup.empty()) fs::remove(undo.back().backup, ec);
        if (undo.back().slot >= 0) g_slots[undo.back().slot].state.store(0);
        undo.pop_back();
      }
      roll_back();
      throw InvalidInput(std::string(x.what()) + "; nothing written");
    }
    if (p->target.regular) ++renamed;
    // Test hook (tests/cli): a signal between two renames, where both or neither must stand.
    if (renamed == 1 && items.size() > 1)
      if (const char* sig = std::getenv("GEODE_TEST_SIGNAL_BETWEEN_RENAMES"); sig && *sig)
        ::raise(std::atoi(sig));
  }
  std::error_code ec;
  for (const Undo& u : undo) {
    if (!u.backup.empty()) fs::remove(u.backup, ec);
    if (u.slot >= 0) g_slots[u.slot].state.store(0);
  }
}

void remove_temporary(const fs::path& temp) {
  std::error_code ec;
  fs::remove(temp, ec);
  unregister_temporary(temp);
}

void write_path_atomically(const fs::path& path, const std::string& suffix,
                           const std::function<void(const fs::path& temp)>& write) {
  write_atomically(path, suffix, write, true);
}

namespace {

// An ostream's bytes through a FileSink: its checked writes (a failure names the file and the
// system's reason, "No space left on device") and its direct I/O, for the writers that format
// through iostreams (.vtu, .vtk, reports, the viewer's page).
class SinkBuffer : public std::streambuf {
 public:
  explicit SinkBuffer(FileSink& sink) : sink_(sink) { setp(put_, put_ + sizeof put_); }

 protected:
  int_type overflow(int_type c) override {
    pass_on();
    if (!traits_type::eq_int_type(c, traits_type::eof())) sink_.ch(traits_type::to_char_type(c));
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    pass_on();
    sink_.text(std::string_view(s, static_cast<std::size_t>(n)));
    return n;
  }
  int sync() override {
    pass_on();
    return 0;
  }

 private:
  void pass_on() {
    sink_.text(std::string_view(pbase(), static_cast<std::size_t>(pptr() - pbase())));
    setp(put_, put_ + sizeof put_);
  }
  FileSink& sink_;
  char put_[1 << 12];  // numbers formatted by the stream land here first, a character at a time
};

}  // namespace

void write_file_atomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  write_atomically(
      path, "",
      [&](const fs::path& tmp) {
        FileSink sink(tmp, path.string());
        SinkBuffer buffer(sink);
        std::ostream out(&buffer);
        out.exceptions(std::ios::badbit);  // the sink's InvalidInput, not a silent bad stream
        write(out);
        out.flush();
        sink.close();
      },
      false);
}

}  // namespace geode::io
