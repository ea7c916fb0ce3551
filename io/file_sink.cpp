#include <geode/io/file_sink.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include <geode/primal/errors.hpp>

namespace geode::io {

namespace {
constexpr std::size_t kBufferBytes = std::size_t{1} << 20;
// Written bytes handed to the disk this many at a time while writing goes on, so that close()'s
// fsync waits for the last of them only (a 150 MB .msh: its whole writeback, 60-80 ms, else).
constexpr std::size_t kWritebackBytes = std::size_t{8} << 20;
}  // namespace

FileSink::FileSink(const std::filesystem::path& file, std::string target)
    : target_(std::move(target)), buffer_(kBufferBytes) {
  static_assert(kThrough <= kBufferBytes, "text shorter than kThrough must fit the buffer");
  fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) fail("cannot open for writing", errno);
}

FileSink::~FileSink() {
  if (fd_ >= 0) ::close(fd_);
}

void FileSink::fail(const std::string& what, int err) const {
  throw InvalidInput(target_ + ": " + what + ": " + std::strerror(err) +
                     (err == ENOSPC || err == EDQUOT ? " (the disk is full)" : ""));
}

void FileSink::flush() {
  write_all(buffer_.data(), used_);
  used_ = 0;
}

void FileSink::write_through(std::string_view s) {
  flush();
  write_all(s.data(), s.size());
}

void FileSink::write_all(const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed", errno);
    }
    if (n == 0) fail("write failed", EIO);
    done += static_cast<std::size_t>(n);
  }
  written_ += done;
  if (written_ - handed_ >= kWritebackBytes) {
    // A request only (Linux): close() still syncs, and reports what failed.
    (void)::sync_file_range(fd_, static_cast<off_t>(handed_),
                            static_cast<off_t>(written_ - handed_), SYNC_FILE_RANGE_WRITE);
    handed_ = written_;
  }
}

void FileSink::integer(std::int64_t x) {
  if (buffer_.size() - used_ < 24) flush();
  const auto r = std::to_chars(buffer_.data() + used_, buffer_.data() + buffer_.size(), x);
  used_ = static_cast<std::size_t>(r.ptr - buffer_.data());
}

void FileSink::real(double x) {
  if (buffer_.size() - used_ < 32) flush();
  const auto r = std::to_chars(buffer_.data() + used_, buffer_.data() + buffer_.size(), x);
  used_ = static_cast<std::size_t>(r.ptr - buffer_.data());
}

void FileSink::close() {
  flush();
  // Errors of delayed writes (NFS, some full file systems) show at fsync or close.
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS) {
    const int err = errno;
    ::close(fd_);
    fd_ = -1;
    fail("write failed", err);
  }
  const int status = ::close(fd_);
  fd_ = -1;
  if (status != 0) fail("write failed", errno);
}

}  // namespace geode::io
