#include <geode/io/read_model.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <string_view>

#include <geode/io/exodus.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/names.hpp>
#include <geode/io/nemesis_set.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/node_set_pieces.hpp>

namespace geode::io {

using namespace primal;

namespace {

// "ID:NAME" after a field array's prefix: a positive id; the name may hold ':' itself.
std::pair<int, std::string> id_and_name(std::string_view rest, const std::string& where) {
  const auto colon = rest.find(':');
  int id = 0;
  const auto digits = rest.substr(0, colon);
  const auto res = std::from_chars(digits.data(), digits.data() + digits.size(), id);
  if (colon == std::string_view::npos || res.ec != std::errc() ||
      res.ptr != digits.data() + digits.size() || id <= 0)
    throw InvalidInput(where + ": expected a positive id and a name ('ID:NAME') after the prefix");
  return {id, std::string(rest.substr(colon + 1))};
}

// Block names and sets from the field arrays write_vtu stores (vtk.hpp); `cells` maps the
// file's cell indices to the model's elements (none for its triangles and quads).
void read_field_data(const VtkGrid& grid, const std::vector<std::optional<ElementRef>>& cells,
                     Model& model) {
  for (const VtkGrid::FieldArray& a : grid.field_data) {
    const std::string where = grid.source + ": field array '" + a.name + "'";
    const std::string_view name = a.name;
    if (name.rfind("block:", 0) == 0) {
      if (a.components != 1 || a.values.size() != 1 || a.values[0] <= 0 || a.values[0] > INT_MAX)
        throw InvalidInput(where + ": expected one positive block id");
      model.block_names[static_cast<int>(a.values[0])] = std::string(name.substr(6));
    } else if (name.rfind("node_set:", 0) == 0) {
      auto [id, set_name] = id_and_name(name.substr(9), where);
      if (a.components != 1) throw InvalidInput(where + ": expected 1 component");
      NodeSet set{id, std::move(set_name), {}};
      for (std::size_t i = 0; i < a.values.size(); ++i) {
        if (a.values[i] < 0 || index_cast<std::size_t>(a.values[i]) >= grid.points.size())
          throw InvalidInput(where + ": entry " + std::to_string(i) + " refers to point " +
                             std::to_string(a.values[i]) + ", out of range [0, " +
                             std::to_string(grid.points.size()) + ")");
        set.nodes.push_back(index_cast(a.values[i]));
      }
      model.node_sets.push_back(std::move(set));
    } else if (name.rfind("side_set:", 0) == 0) {
      auto [id, set_name] = id_and_name(name.substr(9), where);
      if (a.components != 2) throw InvalidInput(where + ": expected 2 components (cell, face)");
      SideSet set{id, std::move(set_name), {}};
      for (std::size_t i = 0; i + 1 < a.values.size(); i += 2) {
        const long long cell = a.values[i], face = a.values[i + 1];
        const std::string entry = where + ": entry " + std::to_string(i / 2);
        if (cell < 0 || index_cast<std::size_t>(cell) >= cells.size() ||
            !cells[index_cast<std::size_t>(cell)])
          throw InvalidInput(entry + " refers to cell " + std::to_string(cell) +
                             ", not a volume cell of the file");
        const ElementRef element = *cells[index_cast<std::size_t>(cell)];
        const int faces = cell_topology(element.kind).faces;
        if (face < 0 || face >= faces)
          throw InvalidInput(entry + ": cell " + std::to_string(cell) + ": face " +
                             std::to_string(face) + " out of range [0, " + std::to_string(faces) +
                             ")");
        set.sides.push_back({element, static_cast<int>(face)});
      }
      model.side_sets.push_back(std::move(set));
    }
  }
}

// Points, lines and faces listed as cells (vtk_boundary_cell). Gmsh's legacy .vtk tags each
// with its physical group (CellEntityIds; Gmsh saves only the elements of physical groups unless
// Mesh.SaveAll is set), meshio's files too (gmsh:physical, 0 for none): they become sets as the
// .msh reader makes them from the same groups, vertices and lines node sets (each cell a piece)
// and triangles and quads side sets of the volume cells they are faces of, by tag in ascending
// (dimension, tag). Such cells in other files (geode's writers keep sets in field data and write
// none) are left out, with one warning.
void read_tagged_boundary_cells(const VtkGrid& grid, const std::string& block_array,
                                const std::vector<int>* tags, Model& model) {
  const bool tagged = tags && (block_array == "CellEntityIds" || block_array == "gmsh:physical");
  std::map<std::pair<int, int>, std::vector<std::size_t>> groups;  // (dim, tag) -> cells
  std::size_t untagged = 0;
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const int type = grid.cell_types[c];
    if (!vtk_boundary_cell(type)) continue;
    if (!tagged || (*tags)[c] <= 0) {
      ++untagged;
      continue;
    }
    const int dim = type == kVtkVertex ? 0 : type == kVtkLine ? 1 : 2;
    groups[{dim, (*tags)[c]}].push_back(c);
  }
  if (untagged > 0)
    read_warning(grid.source + ": " + std::to_string(untagged) +
                 " vertex, line, triangle or quad cells carry no set tag (a CellEntityIds or "
                 "gmsh:physical cell array): they are not read");
  std::vector<TaggedCells> sets;
  for (const auto& [key, members] : groups) {
    TaggedCells t{key.first, key.second, {}, {}, {}};
    for (std::size_t c : members) {
      t.cells.push_back(grid.cells[c]);
      t.cell_ids.push_back(static_cast<std::int64_t>(c));
    }
    sets.push_back(std::move(t));
  }
  const auto moved = separate_node_set_ids(sets, grid.source);
  warn_moved_node_sets(sets, moved, grid.source, "line cells tagged", "vertex cells tagged");
  add_tagged_sets(model, sets, grid.source, "cell");
}

}  // namespace

Model model_from_vtk(const VtkGrid& grid, const ReadOptions& options) {
  Model model;
  model.points = grid.points;
  for (std::size_t n = 0; n < grid.points.size(); ++n)
    model.node_ids.push_back(static_cast<std::int64_t>(n));
  const std::vector<int>* blocks = nullptr;
  std::string block_array;
  constexpr std::array<const char*, 4> kBlockArrays{"block", "gmsh:physical", "CellEntityIds",
                                                    "mat_id"};
  for (const char* name : kBlockArrays)
    if ((blocks = grid.cell_data.find_int(name))) {
      block_array = name;
      break;
    }
  // A material array under another name (meshio writes cell_data as named) would be lost
  // without a word: the blocks then follow the cell kinds.
  if (!blocks && !grid.cell_data.ints.empty()) {
    std::string names;
    for (const auto& [name, values] : grid.cell_data.ints)
      if (name != "gmsh:geometrical")
        names += (names.empty() ? "'" : ", '") + sanitize_name(name) + "'";
    std::string known;
    for (const char* name : kBlockArrays) known += (known.empty() ? "" : ", ") + std::string(name);
    if (!names.empty())
      read_warning(grid.source + ": integer cell array " + names +
                   " not read as blocks (only one named " + known +
                   " is): the blocks are the cell kinds'");
  }
  // meshio's gmsh:physical is 0 for a cell in no physical group: numbered as the .msh reader
  // numbers such elements, by its entity (gmsh:geometrical; else the kind's default block),
  // above every physical tag of a volume cell where some cell has one.
  const bool physical = block_array == "gmsh:physical";
  const std::vector<int>* entities =
      physical ? grid.cell_data.find_int("gmsh:geometrical") : nullptr;
  std::int64_t top = 0;
  for (std::size_t c = 0; physical && c < grid.cells.size(); ++c)
    if (!vtk_boundary_cell(grid.cell_types[c])) top = std::max<std::int64_t>(top, (*blocks)[c]);
  std::vector<std::optional<ElementRef>> cells(grid.cells.size());
  for (std::size_t c = 0; c < grid.cells.size(); ++c) {
    const int type = grid.cell_types[c];
    if (vtk_boundary_cell(type)) continue;  // sets, below
    const auto it = std::find(kVtkCellTypes.begin(), kVtkCellTypes.end(), type);
    if (it == kVtkCellTypes.end())
      throw InvalidInput(grid.source + ": cell " + std::to_string(c) + ": VTK cell type " +
                         std::to_string(type) +
                         " is not supported; only hexahedra (12), tetrahedra (10), wedges (13) and "
                         "pyramids (14) are");
    const ElementKind kind = kElementKinds[index_cast<std::size_t>(it - kVtkCellTypes.begin())];
    int block = blocks ? (*blocks)[c] : default_block(kind);
    if (physical && block == 0) {
      const int entity = entities && (*entities)[c] > 0 ? (*entities)[c] : default_block(kind);
      if (top + entity > INT32_MAX)
        throw InvalidInput(grid.source + ": cell " + std::to_string(c) +
                           ": in no physical group, and its entity " + std::to_string(entity) +
                           " above the highest physical tag " + std::to_string(top) +
                           " is out of range for a block id");
      block = static_cast<int>(top + entity);
    }
    if (block <= 0)
      throw InvalidInput(grid.source + ": cell " + std::to_string(c) + ": block id " +
                         std::to_string(block) + " (cell array '" + block_array +
                         "') is not positive");
    std::array<Index, 8> corners{};
    const auto& cell = grid.cells[c];
    for (std::size_t k = 0; k < cell.size() && k < 8; ++k)
      corners[k] =
          cell[kind == ElementKind::kWedge ? index_cast<std::size_t>(topology::kVtkWedgeOrder[k])
                                           : k];
    cells[c] = ElementRef{kind, static_cast<Index>(element_count(model, kind))};
    add_element(model, kind, corners, block, static_cast<std::int64_t>(c));
  }
  read_field_data(grid, cells, model);
  read_tagged_boundary_cells(grid, block_array, blocks, model);
  sanitize_names(model);
  validate(model, grid.source);
  options.check_geometry ? check_geometry(model, grid.source, options.inverted_hint)
                         : check_points(model, grid.source);
  return model;
}

InvalidInput out_of_memory_reading(const std::filesystem::path& path) {
  // Every count is bounded by the file's size, but a model a file can describe may still not
  // fit; the memory the reader took is given back by the time this message is made.
  std::error_code ec;
  return InvalidInput(path.string() + ": out of memory reading it (a file of " +
                      std::to_string(std::filesystem::file_size(path, ec)) +
                      " bytes): its model needs more memory than this process may use");
}

bool read_forks(const std::filesystem::path& path) {
  if (find_nemesis_set(path)) return true;
  const MeshFormat* format = reader_for(path);
  return format && format->reads_in_child;
}

Model read_model(const std::filesystem::path& path, const ReadOptions& options, bool check_covering,
                 FilePartition* partition, const primal::InputCheckOptions& covering) {
  if (partition) *partition = {};
  if (const auto set = find_nemesis_set(path)) {
    try {
      Model model = read_nemesis_set(*set, options, partition);
      primal::infer_boundary_node_set_pieces(model);
      if (options.check_geometry && check_covering)
        require_single_covering(model, set->name(), covering);
      return model;
    } catch (const std::bad_alloc&) {
      throw out_of_memory_reading(set->files.front());
    }
  }
  const MeshFormat* format = reader_for(path);
  if (!format) {
    (void)read_file_head(path);  // a missing file is named as such first
    throw InvalidInput(path.string() + ": unknown input format '" + path.extension().string() +
                       "' (expected " + extension_list(FormatRole::kRead) + ")");
  }
  check_signature(path, *format);
  try {
    Model model = partition && format->read == read_gmsh
                      ? read_gmsh_partitioned(path, options, partition)
                  : format->read == read_exodus && covering.shares > 1
                      ? read_exodus_shared(path, options, covering)
                      : format->read(path, options);
    // Node sets given as nodes only (Exodus) on the boundary: dicing keeps them there.
    primal::infer_boundary_node_set_pieces(model);
    if (options.check_geometry && check_covering)
      require_single_covering(model, path.string(), covering);
    return model;
  } catch (const std::bad_alloc&) {
    throw out_of_memory_reading(path);
  }
}

}  // namespace geode::io
