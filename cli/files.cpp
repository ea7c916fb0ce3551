// File-name helpers shared by the commands (cli/commands.hpp).
#include <algorithm>
#include <cctype>
#include <iostream>
#include <utility>

#include <geode/io/atomic_file.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/stc/mesh_dual.hpp>
#include "cli/commands.hpp"

namespace geode::cli {

namespace fs = std::filesystem;

std::string file_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

primal::Model read_model(const fs::path& path) { return io::read_model(path); }

MeshFile read_mesh_file(const fs::path& path, bool other_cells) {
  const io::MeshFormat* format = nullptr;
  io::PlainMesh plain = io::read_plain_mesh(path, &format, other_cells);
  MeshFile m;
  m.dim = plain.dim;
  m.hex = std::move(plain.hex);
  m.quad = std::move(plain.quad);
  m.model = std::move(plain.model);
  m.index_base = format->index_base;
  if (m.dim == 2)
    for (std::size_t n = 0; n < m.quad.points.size(); ++n)
      if (m.quad.points[n].z() != 0.0)
        throw InvalidInput(path.string() + ": node " + std::to_string(n) +
                           " has z != 0: a quad mesh must lie in the plane z = 0");
  return m;
}

std::string read_line(const std::string& path, const MeshFile& m) {
  const bool hexes = m.dim == 3;
  return "read " + path + ": " + std::to_string(hexes ? m.hex.hexes.size() : m.quad.quads.size()) +
         (hexes ? " hexes, " : " quads, ") +
         std::to_string(hexes ? m.hex.points.size() : m.quad.points.size()) + " nodes";
}

std::string dual_step(int dim) {
  return std::string(dim == 3 ? "hex" : "quad") + " visits of the dual (" +
         std::to_string(stc::kMeshDualPasses) + " per " + (dim == 3 ? "hex" : "quad") + ")";
}

void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty() || path == "-") {
    write(std::cout);
    return;
  }
  io::write_file_atomically(path, write);
}

}  // namespace geode::cli
