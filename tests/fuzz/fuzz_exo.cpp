// libFuzzer target: the Exodus II reader (io/exodus.cpp) on arbitrary bytes. The netCDF and
// Exodus libraries read by file name, so each input goes to one scratch file of this process
// first. What is under test is our side: the signature check and the bounds on every header
// count (checked against the file's size before the netCDF library allocates anything) and
// on every entry; InvalidInput is the expected answer to bad bytes; any other exception, a
// crash, an allocation over libFuzzer's -rss_limit_mb or a sanitizer report is a finding.
// Built with -DGEODE_FUZZ=ON (clang), run by scripts/test.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <geode/io/exodus.hpp>
#include <geode/primal/errors.hpp>

namespace {
void remove_scratch();
const std::string& scratch() {
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("geode-fuzz-exo-" + std::to_string(::getpid()) + ".exo"))
                                      .string();
  // Removed when the run ends (libFuzzer exits through exit() after -runs or -max_total_time):
  // every run left its file in the temporary directory before. Registered after `path` is
  // made, so that it runs before `path` is destroyed.
  static const bool removed_at_exit = std::atexit(remove_scratch) == 0;
  (void)removed_at_exit;
  return path;
}
void remove_scratch() { std::remove(scratch().c_str()); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    (void)geode::io::read_exodus(scratch());
  } catch (const geode::InvalidInput&) {}
  return 0;
}
