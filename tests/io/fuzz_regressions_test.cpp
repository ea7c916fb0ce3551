// Inputs the fuzzers (tests/fuzz) once broke the readers with, kept in tests/fuzz/regressions:
// each must now be read or refused with InvalidInput, nothing else (under scripts/test's ASan +
// UBSan build, also without a sanitizer report).
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include <geode/io/exodus.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

TEST_CASE("fuzz regressions: every input the fuzzers found is read or refused with InvalidInput") {
  const fs::path dir = fs::path(GEODE_SOURCE_DIR) / "tests/fuzz/regressions";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path path = entry.path();
    CAPTURE(path.string());
    const std::string bytes = read_file_bytes(path);
    const std::string source = path.filename().string();
    const MeshFileFormat format = mesh_format_from_extension(path);
    REQUIRE(format != MeshFileFormat::kUnknown);
    ++files;
    try {
      if (format == MeshFileFormat::kGmsh) (void)parse_gmsh(bytes, source);
      if (format == MeshFileFormat::kVtu) (void)model_from_vtk(parse_vtu(bytes, source));
      if (format == MeshFileFormat::kVtk) (void)model_from_vtk(parse_vtk(bytes, source));
      if (format == MeshFileFormat::kExodus) (void)read_exodus(path);
    } catch (const InvalidInput& e) {
      // The message names the file first (the Exodus reader by its path).
      CHECK((std::string(e.what()).find(source) == 0 ||
             std::string(e.what()).find(path.string()) == 0));
    }
  }
  CHECK(files > 0);
}
