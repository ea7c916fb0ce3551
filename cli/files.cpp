// File-name helpers shared by the commands (cli/commands.hpp).
#include <algorithm>
#include <cctype>
#include <iostream>

#include "cli/commands.hpp"
#include "io/atomic_file.hpp"
#include "primal/errors.hpp"
#include "io/file_format.hpp"
#include "io/exodus.hpp"
#include "io/gmsh.hpp"
#include "io/vtk.hpp"
#include "io/read_model.hpp"

namespace geode::cli {

namespace fs = std::filesystem;

std::string file_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

primal::Model read_model(const fs::path& path) { return io::read_model(path); }

MeshFile read_mesh_file(const fs::path& path) {
  if (!fs::exists(path)) throw InvalidInput(path.string() + ": no such file");
  const io::MeshFileFormat format = io::mesh_format_from_extension(path);
  if (format == io::MeshFileFormat::kUnknown)
    throw InvalidInput(path.string() + ": unknown input format '" + file_extension(path) +
                       "' (expected .vtu, .vtk, .msh, .exo or .e)");
  MeshFile m;
  if (format == io::MeshFileFormat::kVtu || format == io::MeshFileFormat::kVtk) {
    const io::VtkGrid g = io::read_vtk_file(path);
    const bool quads = !g.cell_types.empty() && std::all_of(g.cell_types.begin(), g.cell_types.end(),
                                                             [](int t) { return t == io::kVtkQuad; });
    if (quads) {
      m.dim = 2;
      m.quad = io::to_quad_mesh(g);
      for (std::size_t n = 0; n < m.quad.points.size(); ++n)
        if (m.quad.points[n].z() != 0.0)
          throw InvalidInput(path.string() + ": node " + std::to_string(n) +
                             " has z != 0: a quad mesh must lie in the plane z = 0");
    } else {
      m.hex = io::to_hex_mesh(g);  // names the first cell that is not a hex
    }
    return m;
  }
  const primal::Model model = read_model(path);
  for (primal::ElementKind kind : {primal::ElementKind::Tet, primal::ElementKind::Pyramid, primal::ElementKind::Wedge})
    if (const std::size_t n = primal::element_count(model, kind))
      throw InvalidInput(path.string() + ": holds " + std::to_string(n) + " " + primal::element_kind_name(kind) +
                         "s; expected an all-hex mesh (use `geode conform` first)");
  m.hex = primal::hex_part(model);
  m.index_base = 1;
  return m;
}

void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty() || path == "-") {
    write(std::cout);
    return;
  }
  io::write_file_atomically(path, write);
}

}  // namespace geode::cli
