#pragma once
// What a mesh file is, from its first bytes, checked before any reader or library sees it:
// a file named .msh that holds a Gmsh script, or a .exo that is not netCDF, is refused here and
// never reaches a parser that could run or misread it.
//
// Signatures: Gmsh "$MeshFormat" (after white space); Exodus II is netCDF, classic "CDF\1",
// 64-bit offset "CDF\2", CDF-5 "CDF\5", or netCDF-4 / HDF5 "\x89HDF\r\n\x1a\n" at byte 0, 512,
// 1024 or 2048 (HDF5 user blocks); VTK XML "<?xml" or "<VTKFile" (after a UTF-8 byte-order mark
// and white space); legacy VTK "# vtk DataFile Version".
#include <filesystem>
#include <string>
#include <string_view>

namespace geode::io {

enum class MeshFileFormat { kUnknown, kGmsh, kExodus, kVtu, kVtk };

// The format the content starts like (kUnknown for anything else).
MeshFileFormat sniff_mesh_format(std::string_view head);
// Each signature alone (the format table, formats.hpp, holds them per format).
bool looks_like_gmsh(std::string_view head);
bool looks_like_exodus(std::string_view head);
bool looks_like_vtu(std::string_view head);
bool looks_like_vtk(std::string_view head);
// By extension, case-insensitive: .msh, .exo / .e, .vtu, .vtk; kUnknown for others.
MeshFileFormat mesh_format_from_extension(const std::filesystem::path& path);
// "Gmsh .msh", "Exodus II", "VTK XML .vtu", "legacy VTK .vtk", "unknown".
const char* mesh_format_name(MeshFileFormat format);

// The file's first bytes (up to `max_bytes`); InvalidInput naming the file when it is missing,
// not a regular file or unreadable.
std::string read_file_head(const std::filesystem::path& path, std::size_t max_bytes = 4096);
// The whole file; InvalidInput naming the file when it cannot be read.
std::string read_file_bytes(const std::filesystem::path& path);
// InvalidInput naming the file when its content is not `expected` (saying what it looks like).
void check_mesh_format(const std::filesystem::path& path, MeshFileFormat expected);

}  // namespace geode::io
