#pragma once
// A whole input file as bytes without copying it into memory: mapped read-only (mmap), so that
// a reader of a multi-GiB file holds only the pages it is reading and what it builds, not a
// second copy of the file. Falls back to reading when the file cannot be mapped.
#include <filesystem>
#include <string>
#include <string_view>

namespace geode::io {

class MappedFile {
 public:
  // InvalidInput naming the file when it cannot be opened or read.
  explicit MappedFile(const std::filesystem::path& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view bytes() const { return view_; }

 private:
  void* map_ = nullptr;
  std::size_t size_ = 0;
  std::string copy_;  // when not mapped
  std::string_view view_;
};

}  // namespace geode::io
