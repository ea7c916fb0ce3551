// io::screen_netcdf (io/netcdf_screen.hpp) on the fuzz corpus's Exodus files and on cut or
// altered copies: consistent files pass as what they are, inconsistent ones are refused naming
// the file before the netCDF library sees them, and read_exodus reads what passes.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <geode/io/exodus.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/netcdf_screen.hpp>
#include <geode/primal/errors.hpp>
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::io;

namespace {

const fs::path kCorpus = fs::path(GEODE_SOURCE_DIR) / "tests/fuzz/corpus/exo";

fs::path written(const fs::path& dir, const std::string& name, const std::string& bytes) {
  const fs::path p = dir / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

}  // namespace

TEST_CASE("screen_netcdf: classic and netCDF-4 Exodus files pass; cut or altered ones do not") {
  const test::TempDir dir;
  const std::string classic = read_file_bytes(kCorpus / "classic.exo");
  const std::string hdf5 = read_file_bytes(kCorpus / "meshio-netcdf4.exo");
  CHECK(screen_netcdf(kCorpus / "classic.exo", "c.exo") == NetcdfKind::kClassic);
  CHECK(screen_netcdf(kCorpus / "meshio-netcdf4.exo", "h.exo") == NetcdfKind::kHdf5);
  CHECK(read_exodus(kCorpus / "classic.exo").hexes.size() > 0);
  CHECK(read_exodus(kCorpus / "meshio-netcdf4.exo").hexes.size() > 0);

  // The data of the last variables cut off: refused before netCDF reads past the end.
  const fs::path cut = written(dir.path, "cut.exo", classic.substr(0, classic.size() - 40));
  CHECK_THROWS_WITH_AS(screen_netcdf(cut, "cut.exo"),
                       doctest::Contains("cut.exo: not a consistent netCDF classic file"),
                       InvalidInput);
  CHECK_THROWS_WITH_AS(read_exodus(cut), doctest::Contains("past the end"), InvalidInput);
  // The header cut inside its lists.
  const fs::path header = written(dir.path, "header.exo", classic.substr(0, 60));
  CHECK_THROWS_WITH_AS(screen_netcdf(header, "header.exo"),
                       doctest::Contains("header.exo: not a consistent netCDF classic file"),
                       InvalidInput);
  // The dimension count (bytes 12..15 of a CDF-2 header) made huge.
  std::string counted = classic;
  counted[12] = '\x10';
  const fs::path count = written(dir.path, "count.exo", counted);
  CHECK_THROWS_WITH_AS(screen_netcdf(count, "count.exo"),
                       doctest::Contains("more than the header can hold"), InvalidInput);
  // An unknown attribute type or dimension id anywhere is refused, never read as another one.
  int refused = 0;
  for (std::size_t at = 4; at < 400; at += 4) {
    std::string altered = classic;
    altered[at + 3] = static_cast<char>(altered[at + 3] ^ 0x40);
    const fs::path p = written(dir.path, "altered.exo", altered);
    try {
      (void)screen_netcdf(p, "altered.exo");
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()).rfind("altered.exo: ", 0) == 0);
      ++refused;
    }
  }
  CHECK(refused > 10);

  // netCDF-4: a truncated HDF5 file is said to be truncated (its superblock's end-of-file).
  const fs::path short_hdf5 = written(dir.path, "short.exo", hdf5.substr(0, hdf5.size() / 2));
  CHECK_THROWS_WITH_AS(read_exodus(short_hdf5),
                       doctest::Contains("short.exo: not a consistent netCDF-4 (HDF5) file"),
                       InvalidInput);
  CHECK_THROWS_WITH_AS(read_exodus(short_hdf5), doctest::Contains("the file is truncated"),
                       InvalidInput);
  std::string versioned = hdf5;
  versioned[8] = '\x07';
  CHECK_THROWS_WITH_AS(read_exodus(written(dir.path, "version.exo", versioned)),
                       doctest::Contains("superblock version 7"), InvalidInput);
}
