#pragma once
// What a netCDF file (Exodus II) claims, checked before the netCDF library opens it.
//
// Classic netCDF (CDF-1, CDF-2 64-bit offset, CDF-5) has a small header of our own to parse
// whole: every count (dimensions, attributes, variables, names, values) is bounded by the bytes
// left in the file, every dimension id must exist, every type be known, and every variable's
// data (begin + its size, the records' numrecs x record size) lie inside the file. A file that
// passes describes only what it holds, and the library then reads offsets inside it.
//
// netCDF-4 is HDF5, whose structure (B-trees, heaps, object headers, filters) is too large to
// validate before libhdf5 sees it: here only the superblock (version, sizes of offsets and
// lengths, the end-of-file address against the file's size: a truncated file is said as such),
// and the file is then read in a child process of its own (isolated.hpp).
#include <filesystem>
#include <string>

namespace geode::io {

enum class NetcdfKind { kClassic, kHdf5 };

// InvalidInput naming `source` and what is inconsistent (corrupt or truncated file).
NetcdfKind screen_netcdf(const std::filesystem::path& path, const std::string& source);

}  // namespace geode::io
