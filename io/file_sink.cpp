#include <geode/io/file_sink.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <new>

#include <geode/io/text_chunks.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

namespace {
// Through the page cache, written bytes are handed to the disk this many at a time while
// writing goes on, so that close()'s fsync waits for the last of them only.
constexpr std::size_t kWritebackBytes = std::size_t{8} << 20;
}  // namespace

void FileSink::Free::operator()(char* p) const { std::free(p); }

FileSink::FileSink(const std::filesystem::path& file, std::string target)
    : target_(std::move(target)) {
  static_assert(kBufferBytes % kAlign == 0, "whole blocks per buffer");
  fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_DIRECT, 0666);
  direct_ = fd_ >= 0;
  if (fd_ < 0 && errno == EINVAL)  // a file system without direct I/O (older tmpfs)
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0) fail("cannot open for writing", errno);
  buffers_.reset(static_cast<char*>(std::aligned_alloc(kAlign, 2 * kBufferBytes)));
  if (!buffers_) {
    ::close(fd_);
    fd_ = -1;
    throw std::bad_alloc();
  }
  thread_ = std::thread([this] { run(); });
}

FileSink::~FileSink() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
}

void FileSink::fail(const std::string& what, int err) const {
  throw InvalidInput(target_ + ": " + what + ": " + std::strerror(err) +
                     (err == ENOSPC || err == EDQUOT ? " (the disk is full)" : ""));
}

int FileSink::write_all(const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EINVAL && direct_ && done == 0) {
      // Direct I/O refused for this file after all (an alignment the device asks more of):
      // the page cache from here on.
      if (::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_DIRECT) != 0) return errno;
      direct_ = false;
      continue;
    }
    if (n < 0) return errno;
    if (n == 0) return EIO;
    done += static_cast<std::size_t>(n);
  }
  written_ += done;
  if (!direct_ && written_ - handed_ >= kWritebackBytes) {
    // A request only (Linux): close() still syncs, and reports what failed.
    (void)::sync_file_range(fd_, static_cast<off_t>(handed_),
                            static_cast<off_t>(written_ - handed_), SYNC_FILE_RANGE_WRITE);
    handed_ = written_;
  }
  return 0;
}

void FileSink::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return pending_ || stop_; });
    if (!pending_) return;  // stopped with nothing left to write
    const char* data = pending_;
    const std::size_t n = pending_bytes_;
    lock.unlock();
    const int err = error_ ? 0 : write_all(data, n);  // error_ is only set by this thread
    lock.lock();
    if (err) error_ = err;
    pending_ = nullptr;
    changed_.notify_all();
  }
}

void FileSink::wait_written() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return !pending_; });
  if (error_) fail("write failed", error_);
}

void FileSink::flush() {
  const std::size_t whole = used_ / kAlign * kAlign;
  if (whole == 0) return;  // less than a block: it stays (the buffer has room, being whole blocks)
  wait_written();          // the other buffer is free once its bytes are written
  {
    std::lock_guard lock(mutex_);
    pending_ = active();
    pending_bytes_ = whole;
  }
  changed_.notify_all();
  total_ += whole;
  const char* rest = active() + whole;
  current_ = 1 - current_;
  used_ -= whole;
  std::memcpy(active(), rest, used_);
}

void FileSink::integer(std::int64_t x) {
  if (kBufferBytes - used_ < kIntegerText) flush();
  char* at = active();
  used_ = static_cast<std::size_t>(put_number(at + used_, x) - at);
}

void FileSink::real(double x) {
  if (kBufferBytes - used_ < kRealText) flush();
  char* at = active();
  used_ = static_cast<std::size_t>(put_number(at + used_, x) - at);
}

void FileSink::close() {
  flush();
  wait_written();
  // The last partial block: written whole (zeros after the bytes, where the file is direct)
  // and the file cut back to its length.
  const std::size_t length = total_ + used_;
  const std::size_t padded = direct_ ? (used_ + kAlign - 1) / kAlign * kAlign : used_;
  std::memset(active() + used_, 0, padded - used_);
  if (const int err = write_all(active(), padded)) fail("write failed", err);
  if (padded != used_ && ::ftruncate(fd_, static_cast<off_t>(length)) != 0)
    fail("write failed", errno);
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
