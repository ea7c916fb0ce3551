#include <geode/io/vtk.hpp>

#include <geode/io/names.hpp>

#include <geode/io/vtk_cells.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>

#include <geode/io/atomic_file.hpp>
#include <geode/io/file_format.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>

namespace geode::io {

using namespace primal;

using vtk_cells::cell_type_name;
using vtk_cells::cell_type_size;

const std::vector<double>* VtkCellData::find_double(const std::string& name) const {
  for (const auto& [n, v] : doubles) {
    if (n == name) return &v;
  }
  return nullptr;
}

const std::vector<int>* VtkCellData::find_int(const std::string& name) const {
  for (const auto& [n, v] : ints) {
    if (n == name) return &v;
  }
  return nullptr;
}

namespace {

// What the writers emit, built once per call from the mesh: cells of one or more types.
struct Grid {
  const std::vector<Point>* points = nullptr;
  std::vector<std::uint8_t> types;  // per cell
  std::vector<Index> offsets;       // per cell: one past its last corner in `connectivity`
  std::vector<Index> connectivity;  // corners per cell, flattened
  VtkCellData data;
  std::map<int, std::string> block_names;  // written as field data (a Model's named blocks)
  // A Model's sets as field data: node indices; (cell index, face) pairs.
  std::vector<std::pair<std::string, std::vector<Index>>> node_sets, side_sets;
  std::size_t cells() const { return types.size(); }
};

// Appends `cells` of VTK type `type`, checking node numbers (named 1-based in messages).
template <std::size_t N>
void add_cells(Grid& g, const std::string& file, const std::vector<std::array<Index, N>>& cells,
               int type) {
  const std::size_t np = g.points->size();
  for (std::size_t c = 0; c < cells.size(); ++c) {
    for (Index v : cells[c]) {
      if (v < 0 || index_cast<std::size_t>(v) >= np) {
        throw InvalidInput(file + ": " + cell_type_name(type) + " " + std::to_string(c + 1) +
                           ": node " + std::to_string(v + 1) + " out of range [1, " +
                           std::to_string(np) + "]");
      }
      g.connectivity.push_back(v);
    }
    g.types.push_back(static_cast<std::uint8_t>(type));
    g.offsets.push_back(index_cast(g.connectivity.size()));
  }
}

Grid start_grid(const std::string& file, const std::vector<Point>& points) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw InvalidInput(file + ": node " + std::to_string(i + 1) + " has a non-finite coordinate");
    }
  }
  Grid g;
  g.points = &points;
  return g;
}

// The standard arrays, then the caller's; names and lengths checked.
void finish_grid(Grid& g, const std::string& file, std::vector<double> scaled_jacobian,
                 const std::vector<int>& block, const VtkCellData& extra) {
  g.data.doubles.emplace_back("scaled_jacobian", std::move(scaled_jacobian));
  if (!block.empty()) g.data.ints.emplace_back("block", block);
  for (const auto& a : extra.doubles) g.data.doubles.push_back(a);
  for (const auto& a : extra.ints) g.data.ints.push_back(a);

  std::vector<std::string> names;
  auto check = [&](const std::string& name, std::size_t size) {
    if (name.empty() || std::any_of(name.begin(), name.end(), [](unsigned char ch) {
          return std::isspace(ch) || !std::isprint(ch);
        })) {
      throw InvalidInput(file + ": cell array name '" + name +
                         "' must be non-empty printable text without spaces");
    }
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      throw InvalidInput(file + ": cell array '" + name + "' given twice");
    }
    names.push_back(name);
    if (size != g.cells()) {
      throw InvalidInput(file + ": cell array '" + name + "' has " + std::to_string(size) +
                         " values for " + std::to_string(g.cells()) + " cells");
    }
  };
  for (const auto& [name, v] : g.data.doubles) check(name, v.size());
  for (const auto& [name, v] : g.data.ints) check(name, v.size());
}

// Verdict scaled Jacobian per cell, 0 for a cell with a node out of range (reported later).
template <std::size_t N, class F>
void append_quality(std::vector<double>& sj, const std::vector<Point>& pts,
                    const std::vector<std::array<Index, N>>& cells, F&& metric) {
  for (const auto& c : cells) {
    const bool in_range = std::all_of(c.begin(), c.end(), [&](Index v) {
      return v >= 0 && index_cast<std::size_t>(v) < pts.size();
    });
    if (!in_range) {
      sj.push_back(0.0);
      continue;
    }
    std::array<Point, N> p;
    for (std::size_t k = 0; k < N; ++k) p[k] = pts[index_cast<std::size_t>(c[k])];
    sj.push_back(metric(p));
  }
}

double hex_sj(const std::array<Point, 8>& p) { return hex_scaled_jacobian(p); }
double tet_sj(const std::array<Point, 4>& p) { return tet_scaled_jacobian(p[0], p[1], p[2], p[3]); }
double quad_sj(const std::array<Point, 4>& p) { return quad_scaled_jacobian(p); }

// A mesh of one cell type.
template <std::size_t N, class Metric>
Grid single_type_grid(const std::filesystem::path& path, const std::vector<Point>& points,
                      const std::vector<std::array<Index, N>>& cells, int type, Metric&& metric,
                      const std::vector<int>& block, const VtkCellData& extra) {
  const std::string file = path.string();
  Grid g = start_grid(file, points);
  add_cells(g, file, cells, type);
  std::vector<double> sj;
  append_quality(sj, points, cells, metric);
  finish_grid(g, file, std::move(sj), block, extra);
  return g;
}

Grid grid_of(const std::filesystem::path& path, const HexMesh& m, const VtkCellData& extra) {
  return single_type_grid(path, m.points, m.hexes, kVtkHexahedron, hex_sj, m.block, extra);
}

Grid grid_of(const std::filesystem::path& path, const TetMesh& m, const VtkCellData& extra) {
  return single_type_grid(path, m.points, m.tets, kVtkTetra, tet_sj, m.block, extra);
}

Grid grid_of(const std::filesystem::path& path, const QuadMesh& m, const VtkCellData& extra) {
  return single_type_grid(path, m.points, m.quads, kVtkQuad, quad_sj, {}, extra);
}

// The scaled Jacobian of a pyramid or wedge: its corner frames' least det(e1, e2, e3) /
// (|e1| |e2| |e3|) (topology.hpp's frames; a pyramid's base corners, with the apex as third
// edge), the definition Verdict applies to hexes and tets.
double frame_sj(const Point& o, const Point& a, const Point& b, const Point& c) {
  const Point e1 = a - o, e2 = b - o, e3 = c - o;
  const double n = e1.norm() * e2.norm() * e3.norm();
  return n > 0.0 ? e1.cross(e2).dot(e3) / n : 0.0;
}
double pyramid_sj(const std::array<Point, 5>& p) {
  double s = 1.0;
  for (std::size_t k = 0; k < 4; ++k)
    s = std::min(s, frame_sj(p[k], p[(k + 1) % 4], p[(k + 3) % 4], p[4]));
  return s;
}
double wedge_sj(const std::array<Point, 6>& p) {
  double s = 1.0;
  for (std::size_t k = 0; k < 6; ++k) {
    const auto& n = topology::kWedgeCornerNeighbors[k];
    s = std::min(s, frame_sj(p[k], p[index_cast<std::size_t>(n[0])],
                             p[index_cast<std::size_t>(n[1])], p[index_cast<std::size_t>(n[2])]));
  }
  return s;
}

// A model: hexes, tets, pyramids, then wedges (VTK's corner order), each with its element
// block (block_of).
Grid grid_of(const std::filesystem::path& path, const Model& m, const VtkCellData& extra) {
  const std::string file = path.string();
  validate(m, file);
  Grid g = start_grid(file, m.points);
  std::vector<std::array<Index, 6>> vtk_wedges(m.wedges.size());
  for (std::size_t w = 0; w < m.wedges.size(); ++w)
    for (std::size_t k = 0; k < 6; ++k)
      vtk_wedges[w][k] = m.wedges[w][index_cast<std::size_t>(topology::kVtkWedgeOrder[k])];
  add_cells(g, file, m.hexes, kVtkHexahedron);
  add_cells(g, file, m.tets, kVtkTetra);
  add_cells(g, file, m.pyramids, kVtkPyramid);
  add_cells(g, file, vtk_wedges, kVtkWedge);
  std::vector<double> sj;
  append_quality(sj, m.points, m.hexes, hex_sj);
  append_quality(sj, m.points, m.tets, tet_sj);
  append_quality(sj, m.points, m.pyramids, pyramid_sj);
  append_quality(sj, m.points, m.wedges, wedge_sj);
  std::vector<int> block;
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(m, kind); ++e)
      block.push_back(block_of(m, {kind, index_cast(e)}));
  // The block again as "mat_id", the cell array of material ids Python solvers read (SfePy's
  // name; meshio hands it on), so that they find the materials without knowing ours.
  VtkCellData data = extra;
  data.ints.insert(data.ints.begin(), {"mat_id", block});
  finish_grid(g, file, std::move(sj), block, data);
  for (const auto& [id, name] : m.block_names) g.block_names[id] = sanitize_name(name);
  // Sets by the written cells' numbers: hexes, then tets, pyramids and wedges.
  std::array<Index, 4> first{};
  for (std::size_t k = 1; k < kElementKinds.size(); ++k)
    first[k] = first[k - 1] + index_cast(element_count(m, kElementKinds[k - 1]));
  for (const NodeSet& set : m.node_sets)
    g.node_sets.emplace_back(std::to_string(set.id) + ":" + sanitize_name(set.name), set.nodes);
  for (const SideSet& set : m.side_sets) {
    std::vector<Index> pairs;
    for (const Side& side : set.sides)
      pairs.insert(pairs.end(),
                   {first[static_cast<std::size_t>(side.element.kind)] + side.element.index,
                    index_cast(side.face)});
    g.side_sets.emplace_back(std::to_string(set.id) + ":" + sanitize_name(set.name),
                             std::move(pairs));
  }
  return g;
}

// Shortest text that reads back to the same double.
std::string format_double(double x) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Values in rows of `per_line`.
template <typename T, typename F>
void write_values(std::ostream& os, const std::vector<T>& v, std::size_t per_line,
                  const char* indent, F&& fmt) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    os << (i % per_line == 0 ? indent : " ") << fmt(v[i]);
    if (i % per_line == per_line - 1 || i + 1 == v.size()) os << '\n';
  }
}

// Base64 (RFC 4648) of a byte string, as VTK's XML "binary" format wants it.
std::string base64(std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const auto b = (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16) |
                   (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8) |
                   static_cast<unsigned char>(bytes[i + 2]);
    out += kDigits[(b >> 18) & 63], out += kDigits[(b >> 12) & 63];
    out += kDigits[(b >> 6) & 63], out += kDigits[b & 63];
  }
  if (i < bytes.size()) {
    auto b = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (i + 1 < bytes.size())
      b |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out += kDigits[(b >> 18) & 63], out += kDigits[(b >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(b >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// One DataArray: ASCII rows of `per_line`, or (binary) base64 of a UInt64 byte count followed
// by the little-endian values, the layout VTK writes for uncompressed inline binary data.
template <typename Out, typename T, typename F>
void write_data_array(std::ostream& os, VtuEncoding encoding, const char* type,
                      const std::string& attributes, const std::vector<T>& v, std::size_t per_line,
                      F&& fmt) {
  static_assert(std::endian::native == std::endian::little, "binary .vtu is written little-endian");
  os << "        <DataArray type=\"" << type << "\"" << attributes << " format=\""
     << (encoding == VtuEncoding::kAscii ? "ascii" : "binary") << "\">\n";
  if (encoding == VtuEncoding::kAscii) {
    write_values(os, v, per_line, "          ", fmt);
  } else {
    // Encoded a chunk at a time: base64 of whole 3-byte groups, concatenated, is the base64 of
    // the whole, and neither the array's bytes nor their text are held at once (on a
    // million-hex output those were the run's peak).
    constexpr std::size_t kChunk = 3 * 16384;
    std::string bytes;
    bytes.reserve(kChunk + sizeof(std::uint64_t));
    auto put = [&](const auto& x) {
      const auto at = bytes.size();
      bytes.resize(at + sizeof x);
      std::memcpy(bytes.data() + at, &x, sizeof x);
      if (bytes.size() >= kChunk) {
        const std::size_t whole = bytes.size() / 3 * 3;
        os << base64(std::string_view(bytes).substr(0, whole));
        bytes.erase(0, whole);
      }
    };
    os << "          ";
    put(std::uint64_t{v.size() * sizeof(Out)});
    for (const T& value : v) put(static_cast<Out>(value));
    os << base64(bytes) << "\n";
  }
  os << "        </DataArray>\n";
}

void write_vtu_grid(std::ostream& os, const Grid& g, VtuEncoding encoding) {
  const auto& pts = *g.points;
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\""
     << (encoding == VtuEncoding::kAscii ? "" : " header_type=\"UInt64\"") << ">\n"
     << "  <UnstructuredGrid>\n";
  // Block names, which the cell array "block" cannot carry: one-value field arrays
  // "block:NAME" holding the block id (ParaView lists them under Field Data); node sets as
  // "node_set:ID:NAME" (point indices), side sets as "side_set:ID:NAME" (2 components: cell
  // index, face number of primal/topology.hpp).
  if (!g.block_names.empty() || !g.node_sets.empty() || !g.side_sets.empty()) {
    os << "    <FieldData>\n";
    for (const auto& [id, name] : g.block_names)
      os << "      <DataArray type=\"Int32\" Name=\"block:" << xml_escape(name)
         << "\" NumberOfTuples=\"1\" format=\"ascii\">" << id << "</DataArray>\n";
    for (const auto* sets : {&g.node_sets, &g.side_sets})
      for (const auto& [name, values] : *sets) {
        const bool sides = sets == &g.side_sets;
        os << "      <DataArray type=\"Int32\" Name=\"" << (sides ? "side_set:" : "node_set:")
           << xml_escape(name) << "\" NumberOfComponents=\"" << (sides ? 2 : 1)
           << "\" NumberOfTuples=\"" << values.size() / (sides ? 2 : 1) << "\" format=\"ascii\">\n";
        write_values(os, values, 12, "          ", [](Index v) { return v; });
        os << "      </DataArray>\n";
      }
    os << "    </FieldData>\n";
  }
  os << "    <Piece NumberOfPoints=\"" << pts.size() << "\" NumberOfCells=\"" << g.cells()
     << "\">\n"
     << "      <Points>\n";
  std::vector<double> xyz;
  xyz.reserve(3 * pts.size());
  for (const auto& p : pts) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  write_data_array<double>(os, encoding, "Float64", " NumberOfComponents=\"3\"", xyz, 3,
                           format_double);
  os << "      </Points>\n"
     << "      <Cells>\n";
  auto integer = [](auto v) { return static_cast<long long>(v); };
  // Int32 like Index: node numbers fit, and half the bytes of Int64.
  write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"connectivity\"", g.connectivity, 8,
                                 integer);
  write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"offsets\"", g.offsets, 10,
                                 integer);
  write_data_array<std::uint8_t>(os, encoding, "UInt8", " Name=\"types\"", g.types, 20, integer);
  os << "      </Cells>\n"
     << "      <CellData Scalars=\"scaled_jacobian\">\n";
  for (const auto& [name, v] : g.data.doubles)
    write_data_array<double>(os, encoding, "Float64", " Name=\"" + xml_escape(name) + "\"", v, 6,
                             format_double);
  for (const auto& [name, v] : g.data.ints)
    write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"" + xml_escape(name) + "\"", v,
                                   10, integer);
  os << "      </CellData>\n"
     << "    </Piece>\n"
     << "  </UnstructuredGrid>\n"
     << "</VTKFile>\n";
}

// A legacy array name: one token, VTK's %XX escapes for bytes outside '!'..'~' and '%', '"'.
std::string legacy_name(const std::string& name) {
  std::string out;
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (c <= ' ' || c > '~' || c == '%' || c == '"') {
      static constexpr char kHex[] = "0123456789ABCDEF";
      out += {'%', kHex[c >> 4], kHex[c & 15]};
    } else {
      out += ch;
    }
  }
  return out;
}

void write_vtk_grid(std::ostream& os, const Grid& g) {
  const auto& pts = *g.points;
  const std::size_t ncells = g.cells();
  os << "# vtk DataFile Version 4.2\n"
     << "geode mesh\n"
     << "ASCII\n"
     << "DATASET UNSTRUCTURED_GRID\n";
  // Block names and sets as in .vtu (write_vtu_grid), as dataset field data; array names with
  // VTK's own escapes (%XX for white space, '%', '"' and non-ASCII bytes, as vtkDataWriter).
  const std::size_t fields = g.block_names.size() + g.node_sets.size() + g.side_sets.size();
  if (fields > 0) {
    os << "FIELD FieldData " << fields << '\n';
    for (const auto& [id, name] : g.block_names)
      os << legacy_name("block:" + name) << " 1 1 int\n" << id << '\n';
    for (const auto* sets : {&g.node_sets, &g.side_sets})
      for (const auto& [name, values] : *sets) {
        const bool sides = sets == &g.side_sets;
        os << legacy_name((sides ? "side_set:" : "node_set:") + name) << ' ' << (sides ? 2 : 1)
           << ' ' << values.size() / (sides ? 2 : 1) << " int\n";
        write_values(os, values, 12, "", [](Index v) { return v; });
      }
  }
  os << "POINTS " << pts.size() << " double\n";
  for (const auto& p : pts) {
    os << format_double(p.x()) << ' ' << format_double(p.y()) << ' ' << format_double(p.z())
       << '\n';
  }
  os << "CELLS " << ncells << ' ' << ncells + g.connectivity.size() << '\n';
  Index begin = 0;
  for (std::size_t c = 0; c < ncells; ++c) {
    os << g.offsets[c] - begin;
    for (Index k = begin; k < g.offsets[c]; ++k)
      os << ' ' << g.connectivity[index_cast<std::size_t>(k)];
    os << '\n';
    begin = g.offsets[c];
  }
  os << "CELL_TYPES " << ncells << '\n';
  for (std::size_t c = 0; c < ncells; ++c) os << static_cast<int>(g.types[c]) << '\n';
  os << "CELL_DATA " << ncells << '\n';
  for (const auto& [name, v] : g.data.doubles) {
    os << "SCALARS " << name << " double 1\nLOOKUP_TABLE default\n";
    write_values(os, v, 6, "", format_double);
  }
  for (const auto& [name, v] : g.data.ints) {
    os << "SCALARS " << name << " int 1\nLOOKUP_TABLE default\n";
    write_values(os, v, 10, "", [](int x) { return x; });
  }
}

}  // namespace

// ---- Writers ----------------------------------------------------------------------------------

#define GEODE_VTK_WRITERS(Mesh)                                                                   \
  void write_vtu(const std::filesystem::path& path, const Mesh& mesh, const VtkCellData& extra,   \
                 VtuEncoding encoding) {                                                          \
    const Grid g = grid_of(path, mesh, extra);                                                    \
    write_file_atomically(path, [&](std::ostream& os) { write_vtu_grid(os, g, encoding); });      \
  }                                                                                               \
  void write_vtk(const std::filesystem::path& path, const Mesh& mesh, const VtkCellData& extra) { \
    const Grid g = grid_of(path, mesh, extra);                                                    \
    write_file_atomically(path, [&](std::ostream& os) { write_vtk_grid(os, g); });                \
  }
GEODE_VTK_WRITERS(HexMesh)
GEODE_VTK_WRITERS(TetMesh)
GEODE_VTK_WRITERS(QuadMesh)
GEODE_VTK_WRITERS(Model)
#undef GEODE_VTK_WRITERS

// ---- Typed meshes -----------------------------------------------------------------------------

namespace {

template <std::size_t N>
std::vector<std::array<Index, N>> typed_cells(const VtkGrid& g, int type) {
  std::vector<std::array<Index, N>> out;
  for (std::size_t c = 0; c < g.cells.size(); ++c) {
    if (g.cell_types[c] != type || g.cells[c].size() != N) {
      const char* have = cell_type_name(g.cell_types[c]);
      throw InvalidInput(g.source + ": cell " + std::to_string(c) + " is VTK type " +
                         std::to_string(g.cell_types[c]) + " (" + (have ? have : "unknown") +
                         "), expected " + std::to_string(type) + " (" + cell_type_name(type) + ")");
    }
    std::array<Index, N> a{};
    std::copy(g.cells[c].begin(), g.cells[c].end(), a.begin());
    out.push_back(a);
  }
  return out;
}

std::vector<int> block_of(const VtkGrid& g) {
  const auto* b = g.cell_data.find_int("block");
  return b ? *b : std::vector<int>{};
}

}  // namespace

HexMesh to_hex_mesh(const VtkGrid& g) {
  HexMesh m;
  m.points = g.points;
  m.hexes = typed_cells<8>(g, kVtkHexahedron);
  m.block = block_of(g);
  return m;
}

TetMesh to_tet_mesh(const VtkGrid& g) {
  TetMesh m;
  m.points = g.points;
  m.tets = typed_cells<4>(g, kVtkTetra);
  m.block = block_of(g);
  return m;
}

QuadMesh to_quad_mesh(const VtkGrid& g) {
  QuadMesh m;
  m.points = g.points;
  m.quads = typed_cells<4>(g, kVtkQuad);
  return m;
}

}  // namespace geode::io
