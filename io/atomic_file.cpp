#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

#include "primal/errors.hpp"

namespace geode::io {

namespace {

std::string reason(int err) { return std::strerror(err); }

// Removes the temporary file unless released, so that every exit path cleans up.
class TempFileGuard {
 public:
  explicit TempFileGuard(std::filesystem::path p) : path_(std::move(p)) {}
  ~TempFileGuard() {
    if (!path_.empty()) {
      std::error_code ec;
      std::filesystem::remove(path_, ec);
    }
  }
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;
  void release() { path_.clear(); }

 private:
  std::filesystem::path path_;
};

void write_atomically(const std::filesystem::path& path, const std::string& suffix,
                      const std::function<void(const std::filesystem::path& temp)>& write,
                      bool require_content) {
  if (path.filename().empty()) throw InvalidInput(path.string() + ": not a file name");
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
  // O_CREAT|O_EXCL with a per-process counter gives a name no concurrent writer of the same
  // target uses; the kernel applies the umask to mode 0666 like for any new file.
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = dir / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++) + suffix);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    throw InvalidInput(path.string() + ": cannot create a temporary file in " + dir.string() +
                       ": " + reason(errno));
  }
  TempFileGuard guard(tmp);
  ::close(fd);  // the writer reopens it by name; the name stays ours until renamed or removed
  write(tmp);
  std::error_code ec;
  if (require_content && (std::filesystem::file_size(tmp, ec) == 0 || ec))
    throw InvalidInput(path.string() + ": the writer left the temporary file " + tmp.string() + " empty");
  // Sync the data before the rename so that a crash cannot leave an empty file under the name.
  const int sfd = ::open(tmp.c_str(), O_RDONLY);
  if (sfd >= 0) {
    ::fsync(sfd);
    ::close(sfd);
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw InvalidInput(path.string() + ": cannot rename temporary file: " + ec.message());
  guard.release();
}

}  // namespace

void write_path_atomically(const std::filesystem::path& path, const std::string& suffix,
                           const std::function<void(const std::filesystem::path& temp)>& write) {
  write_atomically(path, suffix, write, true);
}

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  write_atomically(path, "", [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InvalidInput(path.string() + ": cannot open temporary file " + tmp.string());
    write(out);
    out.flush();
    if (!out) throw InvalidInput(path.string() + ": write failed (disk full?)");
  }, false);
}

}  // namespace geode::io
