// libFuzzer target: the .vtu reader (ASCII, binary, appended, zlib) and its conversion to a
// model, on arbitrary bytes. InvalidInput is the expected answer to bad bytes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <geode/io/read_model.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto grid = geode::io::parse_vtu(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.vtu");
    (void)geode::io::model_from_vtk(grid);
  } catch (const geode::InvalidInput&) {}
  return 0;
}
