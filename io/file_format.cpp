#include <geode/io/file_format.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <geode/primal/errors.hpp>

namespace geode::io {

namespace {

bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

std::string_view skip_space(std::string_view s) {
  if (starts_with(s, "\xEF\xBB\xBF")) s.remove_prefix(3);  // UTF-8 byte-order mark
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  return s;
}

// The system's reason a stream did not open (libstdc++ opens with open(2), which sets errno):
// ": Permission denied", or nothing where none was left.
std::string open_reason() { return errno ? std::string(": ") + std::strerror(errno) : ""; }

}  // namespace

bool looks_like_exodus(std::string_view head) {
  for (std::string_view cdf : {std::string_view("CDF\x01", 4), std::string_view("CDF\x02", 4),
                               std::string_view("CDF\x05", 4)})
    if (starts_with(head, cdf)) return true;
  constexpr std::string_view kHdf5("\x89HDF\r\n\x1a\n", 8);
  for (std::size_t offset : {0u, 512u, 1024u, 2048u})
    if (head.size() >= offset + kHdf5.size() && head.substr(offset, kHdf5.size()) == kHdf5)
      return true;
  return false;
}

// Gmsh itself reads $Comments sections anywhere, also before $MeshFormat.
bool looks_like_gmsh(std::string_view head) {
  const std::string_view text = skip_space(head);
  return starts_with(text, "$MeshFormat") || starts_with(text, "$Comments");
}

bool looks_like_vtk(std::string_view head) {
  return starts_with(skip_space(head), "# vtk DataFile Version");
}

bool looks_like_vtu(std::string_view head) {
  const std::string_view text = skip_space(head);
  return starts_with(text, "<VTKFile") ||
         (starts_with(text, "<?xml") && text.find("<VTKFile") != std::string_view::npos);
}

MeshFileFormat sniff_mesh_format(std::string_view head) {
  if (looks_like_exodus(head)) return MeshFileFormat::kExodus;
  if (looks_like_gmsh(head)) return MeshFileFormat::kGmsh;
  if (looks_like_vtk(head)) return MeshFileFormat::kVtk;
  if (looks_like_vtu(head)) return MeshFileFormat::kVtu;
  return MeshFileFormat::kUnknown;
}

MeshFileFormat mesh_format_from_extension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (e == ".msh") return MeshFileFormat::kGmsh;
  if (e == ".exo" || e == ".e") return MeshFileFormat::kExodus;
  if (e == ".vtu") return MeshFileFormat::kVtu;
  if (e == ".vtk") return MeshFileFormat::kVtk;
  return MeshFileFormat::kUnknown;
}

const char* mesh_format_name(MeshFileFormat format) {
  switch (format) {
    case MeshFileFormat::kGmsh:
      return "Gmsh .msh";
    case MeshFileFormat::kExodus:
      return "Exodus II";
    case MeshFileFormat::kVtu:
      return "VTK XML .vtu";
    case MeshFileFormat::kVtk:
      return "legacy VTK .vtk";
    case MeshFileFormat::kUnknown:
      break;
  }
  return "unknown";
}

std::string read_file_head(const std::filesystem::path& path, std::size_t max_bytes) {
  std::error_code ec;
  // exists() fails for a reason of its own (a name longer than the system takes, a directory
  // that may not be searched): that reason, not "no such file".
  if (!std::filesystem::exists(path, ec))
    throw InvalidInput(path.string() + ": " + (ec ? ec.message() : std::string("no such file")));
  if (!std::filesystem::is_regular_file(path, ec))
    throw InvalidInput(path.string() + ": not a regular file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInput(path.string() + ": cannot open for reading" + open_reason());
  std::string head(max_bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(max_bytes));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

std::string read_file_bytes(const std::filesystem::path& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInput(path.string() + ": cannot open for reading" + open_reason());
  std::string bytes;
  char buf[1 << 16];
  while (in.read(buf, sizeof buf) || in.gcount() > 0)
    bytes.append(buf, static_cast<std::size_t>(in.gcount()));
  if (in.bad()) throw InvalidInput(path.string() + ": read error");
  return bytes;
}

void check_mesh_format(const std::filesystem::path& path, MeshFileFormat expected) {
  const std::string head = read_file_head(path);
  const MeshFileFormat found = sniff_mesh_format(head);
  if (found == expected) return;
  std::string what = path.string() + ": not in " + mesh_format_name(expected) + " format";
  if (head.empty())
    what += " (the file is empty)";
  else if (found != MeshFileFormat::kUnknown)
    what += std::string(" (its content is ") + mesh_format_name(found) + ")";
  else if (expected == MeshFileFormat::kGmsh)
    what += " (it does not start with $MeshFormat; Gmsh scripts are not read)";
  else if (expected == MeshFileFormat::kExodus)
    what += " (no netCDF or HDF5 signature)";
  throw InvalidInput(what);
}

}  // namespace geode::io
