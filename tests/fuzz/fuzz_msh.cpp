// libFuzzer target: the .msh reader (io/gmsh_read.cpp) on arbitrary bytes. InvalidInput
// is the expected answer to bad bytes; any other exception, a crash or a sanitizer report is a
// finding. Built with -DGEODE_FUZZ=ON (clang), run by scripts/test.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <geode/io/gmsh.hpp>
#include <geode/primal/errors.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)geode::io::parse_gmsh(std::string_view(reinterpret_cast<const char*>(data), size),
                                "fuzz.msh");
  } catch (const geode::InvalidInput&) {}
  return 0;
}
