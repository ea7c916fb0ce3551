#include <geode/io/read_model.hpp>

#include <algorithm>
#include <string>

#include <geode/io/file_format.hpp>
#include <geode/io/formats.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>

namespace geode::io {

using namespace primal;

Model model_from_vtk(const VtkGrid& grid, const ReadOptions& options) {
  Model model;
  model.points = grid.points;
  for (std::size_t n = 0; n < grid.points.size(); ++n)
    model.node_ids.push_back(static_cast<std::int64_t>(n));
  const std::vector<int>* blocks = nullptr;
  std::string block_array;
  for (const char* name : {"block", "gmsh:physical", "CellEntityIds"})
    if ((blocks = grid.cell_data.find_int(name))) {
      block_array = name;
      break;
    }
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const int type = grid.cell_types[c];
    if (type == kVtkTriangle || type == kVtkQuad) continue;
    const auto it = std::find(kVtkCellTypes.begin(), kVtkCellTypes.end(), type);
    if (it == kVtkCellTypes.end())
      throw InvalidInput(grid.source + ": cell " + std::to_string(c) + ": VTK cell type " +
                         std::to_string(type) +
                         " is not supported; only hexahedra (12), tetrahedra (10), wedges (13) and "
                         "pyramids (14) are");
    const ElementKind kind = kElementKinds[static_cast<std::size_t>(it - kVtkCellTypes.begin())];
    const int block = blocks ? (*blocks)[c] : default_block(kind);
    if (block <= 0)
      throw InvalidInput(grid.source + ": cell " + std::to_string(c) + ": block id " +
                         std::to_string(block) + " (cell array '" + block_array +
                         "') is not positive");
    std::array<Index, 8> corners{};
    const auto& cell = grid.cells[c];
    for (std::size_t k = 0; k < cell.size() && k < 8; ++k)
      corners[k] =
          cell[kind == ElementKind::Wedge ? static_cast<std::size_t>(topology::kVtkWedgeOrder[k])
                                          : k];
    add_element(model, kind, corners, block, static_cast<std::int64_t>(c));
  }
  validate(model, grid.source);
  options.check_geometry ? check_geometry(model, grid.source) : check_points(model, grid.source);
  return model;
}

Model read_model(const std::filesystem::path& path, const ReadOptions& options,
                 bool check_covering) {
  const MeshFormat* format = reader_for(path);
  if (!format) {
    (void)read_file_head(path);  // a missing file is named as such first
    throw InvalidInput(path.string() + ": unknown input format '" + path.extension().string() +
                       "' (expected " + extension_list(FormatRole::kRead) + ")");
  }
  check_signature(path, *format);
  Model model = format->read(path, options);
  if (options.check_geometry && check_covering) require_single_covering(model, path.string());
  return model;
}

}  // namespace geode::io
