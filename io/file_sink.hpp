#pragma once
// A buffered output file whose every failure is reported: each write(2) and the final close are
// checked, and a failure (ENOSPC on a full disk, EFBIG past a file size limit, EIO) throws
// InvalidInput naming the file the user asked for (not the temporary one) and the system's
// reason. The writers that format their own bytes (.msh) use it instead of iostreams, whose
// errors carry no cause, and it formats numbers as text_chunks.hpp's put_number does
// (the shortest text that reads back to the same double).
//
// The bytes go to the disk directly (O_DIRECT, where the file system takes it), a buffer at a
// time from a thread of the sink's own while the writer fills the next one: a 150 MB ASCII .msh
// copied into the page cache cost the writer's thread most of its time (the kernel's copy into
// newly allocated pages), and close()'s fsync then waited for its writeback. Where direct I/O
// is refused (at open, or by a write), the sink goes on through the page cache.
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

namespace geode::io {

class FileSink {
 public:
  // Opens `file` for writing (truncating it); `target` names it in messages.
  FileSink(const std::filesystem::path& file, std::string target);
  ~FileSink();
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;

  void text(std::string_view s) {
    while (s.size() > kBufferBytes - used_) {
      const std::size_t n = kBufferBytes - used_;
      std::memcpy(active() + used_, s.data(), n);
      used_ += n;
      s.remove_prefix(n);
      flush();
    }
    std::memcpy(active() + used_, s.data(), s.size());
    used_ += s.size();
  }
  void ch(char c) {
    if (used_ == kBufferBytes) flush();
    active()[used_++] = c;
  }
  void integer(std::int64_t x);
  void real(double x);
  // Little-endian machine bytes of a trivially copyable value (binary .msh is native order,
  // with the integer 1 written first so that readers can tell).
  template <class T>
  void raw(const T& x) {
    if (kBufferBytes - used_ < sizeof(T)) flush();
    std::memcpy(active() + used_, &x, sizeof(T));
    used_ += sizeof(T);
  }
  // Writes what is buffered and closes the file; throws on any failure.
  void close();

 private:
  // Two buffers, each a whole number of kAlign blocks: the writer fills one while the sink's
  // thread writes the other.
  static constexpr std::size_t kBufferBytes = std::size_t{4} << 20;
  // What direct I/O asks of addresses, lengths and offsets (a device's logical block, 512 or
  // 4096 bytes).
  static constexpr std::size_t kAlign = 4096;

  char* active() { return buffers_.get() + kBufferBytes * current_; }
  // Hands the whole blocks of the active buffer to the sink's thread and goes on in the other
  // buffer, the bytes past those blocks moved to its start.
  void flush();
  // The sink's thread: writes each buffer handed to it, in order.
  void run();
  // Waits until no buffer is being written; rethrows a write's failure.
  void wait_written();
  // Writes [data, data + n) at the file's end (direct where the file is); 0 or the errno.
  int write_all(const char* data, std::size_t n);
  [[noreturn]] void fail(const std::string& what, int err) const;

  int fd_ = -1;
  bool direct_ = false;
  std::string target_;
  struct Free {
    void operator()(char* p) const;
  };
  std::unique_ptr<char, Free> buffers_;
  int current_ = 0;        // the buffer being filled
  std::size_t used_ = 0;   // bytes in it
  std::size_t total_ = 0;  // bytes handed on before it (the file's length so far)

  // Between the writer and the sink's thread: one buffer at most being written.
  std::mutex mutex_;
  std::condition_variable changed_;
  const char* pending_ = nullptr;  // the buffer to write, or null
  std::size_t pending_bytes_ = 0;
  bool stop_ = false;
  int error_ = 0;                         // a write's errno, kept for the writer
  std::size_t written_ = 0, handed_ = 0;  // bytes written; of them, handed to the disk
  std::thread thread_;
};

}  // namespace geode::io
