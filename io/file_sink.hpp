#pragma once
// A buffered output file whose every failure is reported: each write(2) and the final close are
// checked, and a failure (ENOSPC on a full disk, EFBIG past a file size limit, EIO) throws
// InvalidInput naming the file the user asked for (not the temporary one) and the system's
// reason. The writers that format their own bytes (.msh) use it instead of iostreams, whose
// errors carry no cause, and it formats numbers with std::to_chars (shortest text that reads
// back to the same double).
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace geode::io {

class FileSink {
 public:
  // Opens `file` for writing (truncating it); `target` names it in messages.
  FileSink(const std::filesystem::path& file, std::string target);
  ~FileSink();
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;

  void text(std::string_view s) {
    if (s.size() >= kThrough) return write_through(s);
    if (buffer_.size() - used_ < s.size()) flush();
    s.copy(buffer_.data() + used_, s.size());
    used_ += s.size();
  }
  void ch(char c) {
    if (used_ == buffer_.size()) flush();
    buffer_[used_++] = c;
  }
  void integer(std::int64_t x);
  void real(double x);
  // Little-endian machine bytes of a trivially copyable value (binary .msh is native order,
  // with the integer 1 written first so that readers can tell).
  template <class T>
  void raw(const T& x) {
    if (buffer_.size() - used_ < sizeof(T)) flush();
    std::memcpy(buffer_.data() + used_, &x, sizeof(T));
    used_ += sizeof(T);
  }
  // Writes what is buffered and closes the file; throws on any failure.
  void close();

 private:
  // Text this long (a writer's chunk of formatted lines) is written as it is, after what is
  // buffered, instead of copied into the buffer first (150 MB for a million-hex ASCII .msh);
  // anything shorter fits the emptied buffer (1 MiB).
  static constexpr std::size_t kThrough = std::size_t{64} << 10;
  void write_through(std::string_view s);
  void write_all(const char* data, std::size_t n);
  void flush();
  [[noreturn]] void fail(const std::string& what, int err) const;

  int fd_ = -1;
  std::string target_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  std::size_t written_ = 0, handed_ = 0;  // bytes written; of them, handed to the disk
};

}  // namespace geode::io
