#include <geode/io/isolated.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <new>
#include <stdexcept>

#include <geode/primal/errors.hpp>

// AddressSanitizer builds (GEODE_SANITIZE, GEODE_FUZZ): gcc says __SANITIZE_ADDRESS__, clang
// __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define GEODE_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GEODE_ASAN 1
#endif
#endif
#ifndef GEODE_ASAN
#define GEODE_ASAN 0
#endif
#if GEODE_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

namespace geode::io {

namespace {

constexpr bool kSanitized = GEODE_ASAN;

// The child's answer: one status byte, the length (8 bytes, little-endian), the bytes.
constexpr char kResult = 'R', kInvalid = 'E', kOutOfMemory = 'M', kOther = 'X';

// The address space this process holds now (the child inherits it all).
std::uint64_t address_space() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

void write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) ::_exit(3);
    p += w;
    n -= static_cast<std::size_t>(w);
  }
}

// The child's address space: what it inherits and limits.memory_bytes more, unless this process
// may use less (ulimit -v): then that, which a child of root could otherwise exceed.
struct AddressLimit {
  std::uint64_t bytes = 0;
  bool own = false;  // this process's own limit, lower than the reader's allowance
};
AddressLimit address_limit(const IsolationLimits& limits, std::uint64_t inherited) {
  const std::uint64_t wanted = inherited + limits.memory_bytes;
  rlimit current{};
  if (::getrlimit(RLIMIT_AS, &current) == 0 && current.rlim_cur != RLIM_INFINITY &&
      current.rlim_cur < wanted)
    return {current.rlim_cur, true};
  return {wanted, false};
}

[[noreturn]] void run_child(int fd, const std::function<std::string()>& work,
                            const IsolationLimits& limits, AddressLimit address) {
  // Default actions: a crash ends the child (not a fuzzer's or sanitizer's handler reporting
  // it as ours), and the parent's signal cleanup (atomic_file.hpp) is the parent's alone.
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTRAP, SIGSYS, SIGINT, SIGTERM,
                  SIGHUP, SIGQUIT, SIGPIPE, SIGXCPU})
    ::signal(sig, SIG_DFL);
  // What the library prints (libexodusII's "EXODUS: Error: ..." lines) is not for the user,
  // who gets one line from the caller. In sanitizer builds too: the child runs only the
  // library, so a sanitizer's report there is the library's fault on a corrupt file (libhdf5's
  // overlapping memcpy), and it ends the child, which the caller reports in its one line.
  // The answer's pipe off the standard descriptors first: a caller started with 1 or 2 closed
  // got the pipe there, and /dev/null put over it swallowed the answer ("the library reading it
  // ended its process ... a corrupt or truncated file?").
  if (fd <= STDERR_FILENO) fd = ::fcntl(fd, F_DUPFD_CLOEXEC, STDERR_FILENO + 1);
  if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) {
    ::dup2(null, STDERR_FILENO);
    ::dup2(null, STDOUT_FILENO);
    ::close(null);
  }
#if GEODE_ASAN
  // A sanitizer's report in the child ends the child, not a fuzzer's run: no death callback
  // (libFuzzer's would save the input as a crash of the caller's).
  __sanitizer_set_death_callback(nullptr);
#endif
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  const rlimit cpu{limits.cpu_seconds, limits.cpu_seconds + 5};
  ::setrlimit(RLIMIT_CPU, &cpu);
  if (!kSanitized) {
    const rlimit as{address.bytes, address.bytes};
    ::setrlimit(RLIMIT_AS, &as);
  }
  char status = kResult;
  std::string body;
  try {
    body = work();
  } catch (const InvalidInput& e) {
    status = kInvalid;
    body = e.what();
  } catch (const std::bad_alloc&) {
    status = kOutOfMemory;
    body.clear();
  } catch (const std::exception& e) {
    status = kOther;
    body = e.what();
  } catch (...) {
    status = kOther;
    body = "unknown exception";
  }
  char header[9];
  header[0] = status;
  for (int i = 0; i < 8; ++i)
    header[1 + i] = static_cast<char>((static_cast<std::uint64_t>(body.size()) >> (8 * i)) & 0xFF);
  write_all(fd, header, sizeof header);
  write_all(fd, body.data(), body.size());
  ::close(fd);
  ::_exit(0);  // no destructors, atexit handlers or buffered output of the parent's
}

// Kills and reaps the child unless it was reaped: every exit path of the parent leaves none.
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  int wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {}
    pid_ = -1;
    return status;
  }

 private:
  pid_t pid_;
};

std::string signal_name(int sig) {
  const char* d = ::sigdescr_np(sig);
  return std::string("signal ") + std::to_string(sig) + (d ? std::string(", ") + d : "");
}

}  // namespace

std::string run_isolated(const std::function<std::string()>& work, const std::string& source,
                         const std::string& what, const IsolationLimits& limits) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw InvalidInput(source + ": " + what + ": cannot create a pipe: " + std::strerror(errno));
  const AddressLimit address = address_limit(limits, address_space());
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw InvalidInput(source + ": " + what +
                       ": cannot start a reader process: " + std::strerror(e));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], work, limits, address);
  }
  ::close(fds[1]);
  // A larger pipe (the most an unprivileged process may ask for, 1 MiB by default) than its
  // 64 KiB: fewer switches between the two processes on a large answer. Refused, it stays.
  ::fcntl(fds[0], F_SETPIPE_SZ, 1 << 20);
  Child child(pid);
  // The answer is read where it ends up: the header first, then the body straight into a
  // string of the length the header gives (a 56 MB answer appended through a buffer was copied
  // twice more and its string grown by doubling).
  std::string answer(9, '\0');
  std::size_t got = 0;
  bool overlong = false, late = false;
  {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::seconds(limits.wall_seconds);
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) {
        late = true;
        break;
      }
      pollfd ready{fds[0], POLLIN, 0};
      const int polled = ::poll(&ready, 1, static_cast<int>(std::min<long long>(left, 1 << 30)));
      if (polled < 0 && errno == EINTR) continue;
      if (polled == 0) continue;               // the deadline is checked above
      if (got == answer.size() && got >= 9) {  // all the header promised: only the end is left
        char extra;
        const ssize_t n = ::read(fds[0], &extra, 1);
        if (n < 0 && errno == EINTR) continue;
        if (n > 0) overlong = true;
        break;
      }
      const ssize_t n = ::read(fds[0], answer.data() + got, answer.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
      if (got == 9 && answer.size() == 9) {
        std::uint64_t length = 0;
        for (int i = 0; i < 8; ++i)
          length |= static_cast<std::uint64_t>(static_cast<unsigned char>(answer[1 + i]))
                    << (8 * i);
        if (length > limits.max_result_bytes) {
          overlong = true;
          break;
        }
        answer.resize(9 + length);
      }
    }
  }
  answer.resize(got);
  ::close(fds[0]);
  if (late)
    throw InvalidInput(source + ": " + what + " failed: it took more than " +
                       std::to_string(limits.wall_seconds) + " s (corrupt file?)");
  if (overlong)
    throw std::runtime_error(source + ": " + what + ": the reader process said too much");
  const int status = child.wait();
  const std::string failed = source + ": " + what + " failed: ";
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGXCPU)
      throw InvalidInput(failed + "it took more than " + std::to_string(limits.cpu_seconds) +
                         " s of CPU time (corrupt file?)");
    if (sig == SIGKILL)
      throw InvalidInput(failed + "the reader process was killed (out of memory or time?)");
    throw InvalidInput(failed + "the library reading it crashed (" + signal_name(sig) +
                       "): a corrupt or truncated file?");
  }
  // An exit without its answer: the library ended the process (glibc's or a sanitizer's heap
  // checks on libhdf5's own corruption, in sanitizer builds; exit() inside the library).
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || answer.size() < 9)
    throw InvalidInput(failed + "the library reading it ended its process (exit status " +
                       std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : status) +
                       "): a corrupt or truncated file?");
  std::uint64_t length = 0;
  for (int i = 0; i < 8; ++i)
    length |= static_cast<std::uint64_t>(static_cast<unsigned char>(answer[1 + i])) << (8 * i);
  if (length != answer.size() - 9)
    throw std::runtime_error(failed + "the reader process's answer is cut short");
  const char kind = answer[0];
  answer.erase(0, 9);
  switch (kind) {
    case kResult:
      return answer;
    case kInvalid:
      throw InvalidInput(answer);
    case kOutOfMemory:
      if (address.own)  // the user's limit, not the file, ran out
        throw InvalidInput(failed + "out of memory: this process may use " +
                           std::to_string(address.bytes >> 20) +
                           " MiB of address space (ulimit -v), too little to read it");
      throw InvalidInput(failed + "it needs more than " +
                         std::to_string(limits.memory_bytes >> 20) +
                         " MiB of memory (corrupt file?)");
    default:
      throw std::runtime_error(failed + answer);
  }
}

}  // namespace geode::io
