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
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <variant>

#include <geode/io/atomic_file.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/text_chunks.hpp>
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

// What the writers emit is read in place from the mesh, a slice at a time, and every large
// array's text or base64 is made in parallel chunks (text_chunks.hpp): a copy of the points and
// connectivity put a million-hex conform's .vtu peak 33 MiB above its .exo's, and formatting
// and quality were most of the writers' time.

// Cells of one VTK type: the mesh's own array, in its own corner order.
using CellSpan =
    std::variant<std::span<const std::array<Index, 4>>, std::span<const std::array<Index, 5>>,
                 std::span<const std::array<Index, 6>>, std::span<const std::array<Index, 8>>>;
struct CellRun {
  CellSpan cells;
  int type = 0;
  std::size_t count = 0, corners = 0;  // cells, corners per cell
  std::size_t first_cell = 0;          // its cells' numbers in the file
  std::size_t first_corner = 0;        // its corners' place in the connectivity
  // Wedges: written in VTK's corner order (topology::kVtkWedgeOrder), measured in the model's.
  bool mirrored = false;
};

// The cells of a file: runs of one type each, written in order.
struct Cells {
  std::vector<CellRun> runs;
  std::size_t size = 0, corners = 0;

  template <std::size_t N>
  void add(const std::vector<std::array<Index, N>>& cells, int type, bool mirrored = false) {
    runs.push_back({std::span<const std::array<Index, N>>(cells), type, cells.size(), N, size,
                    corners, mirrored});
    size += cells.size();
    corners += cells.size() * N;
  }
  // Calls f(run, cell, k) on cells [begin, end) in order, `cell` the mesh's std::array and k
  // its number within the run.
  template <class F>
  void for_each(std::size_t begin, std::size_t end, F&& f) const {
    for (const CellRun& run : runs) {
      const std::size_t lo = std::max(begin, run.first_cell);
      const std::size_t hi = std::min(end, run.first_cell + run.count);
      if (lo >= hi) continue;
      std::visit(
          [&](auto span) {
            for (std::size_t c = lo; c < hi; ++c)
              f(run, span[c - run.first_cell], c - run.first_cell);
          },
          run.cells);
    }
  }
  // The cell holding connectivity entry j (j < corners).
  std::size_t cell_of_corner(std::size_t j) const {
    for (const CellRun& run : runs)
      if (j < run.first_corner + run.count * run.corners)
        return run.first_cell + (j - run.first_corner) / run.corners;
    return size;
  }
};

// Corner k of a cell in VTK's order.
template <std::size_t N>
Index vtk_corner(const CellRun& run, const std::array<Index, N>& cell, std::size_t k) {
  if constexpr (N == 6)
    if (run.mirrored) return cell[index_cast<std::size_t>(topology::kVtkWedgeOrder[k])];
  return cell[k];
}

// An array written a slice at a time: fill(begin, end, out) puts values [begin, end) in out.
template <class T>
struct Slices {
  std::size_t size = 0;
  std::function<void(std::size_t begin, std::size_t end, T* out)> fill;
};

// Values of an array, in place.
template <class T, class V>
Slices<T> slices_of(std::span<const V> v) {
  return {v.size(), [v](std::size_t begin, std::size_t end, T* out) {
            std::copy(v.begin() + index_cast<std::ptrdiff_t>(begin),
                      v.begin() + index_cast<std::ptrdiff_t>(end), out);
          }};
}
template <class T, class V>
Slices<T> slices_of(const std::vector<V>& v) {
  return slices_of<T, V>(std::span<const V>(v));
}

// What a file holds beside points and cells: the cell arrays (standard, then the caller's) and
// a Model's block names and sets as field data (node indices; (cell index, face) pairs).
// The arrays' slices refer to the Output itself: it stays where it was made.
struct Output {
  Output() = default;
  Output(const Output&) = delete;
  Output& operator=(const Output&) = delete;

  const std::vector<Point>* points = nullptr;
  Cells cells;
  std::vector<std::pair<std::string, Slices<double>>> doubles;
  std::vector<std::pair<std::string, Slices<std::int64_t>>> ints;
  std::map<int, std::string> block_names;
  std::vector<std::pair<std::string, std::vector<Index>>> node_sets, side_sets;
};

void check_points(const std::string& file, const std::vector<Point>& points) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw InvalidInput(file + ": node " + std::to_string(i + 1) + " has a non-finite coordinate");
    }
  }
}

// Node numbers in range, named 1-based in messages by the cell's number in its run.
void check_cells(const std::string& file, const Cells& cells, std::size_t np) {
  cells.for_each(0, cells.size, [&](const CellRun& run, const auto& cell, std::size_t c) {
    for (Index v : cell) {
      if (v < 0 || index_cast<std::size_t>(v) >= np) {
        throw InvalidInput(file + ": " + cell_type_name(run.type) + " " + std::to_string(c + 1) +
                           ": node " + std::to_string(v + 1) + " out of range [1, " +
                           std::to_string(np) + "]");
      }
    }
  });
}

// Names and lengths of the cell arrays.
void check_arrays(const Output& out, const std::string& file) {
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
    if (size != out.cells.size) {
      throw InvalidInput(file + ": cell array '" + name + "' has " + std::to_string(size) +
                         " values for " + std::to_string(out.cells.size) + " cells");
    }
  };
  for (const auto& [name, v] : out.doubles) check(name, v.size);
  for (const auto& [name, v] : out.ints) check(name, v.size);
}

double hex_sj(const std::array<Point, 8>& p) { return hex_scaled_jacobian(p); }
double tet_sj(const std::array<Point, 4>& p) { return tet_scaled_jacobian(p[0], p[1], p[2], p[3]); }
double quad_sj(const std::array<Point, 4>& p) { return quad_scaled_jacobian(p); }

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

// [Verdict] scaled Jacobian per cell (hex, tet, quad, pyramid, wedge), computed as written.
Slices<double> scaled_jacobians(const Output& out) {
  return {out.cells.size, [&out](std::size_t begin, std::size_t end, double* sj) {
            const auto& pts = *out.points;
            out.cells.for_each(begin, end, [&](const CellRun& run, const auto& cell, std::size_t) {
              constexpr std::size_t kCorners = std::tuple_size_v<std::decay_t<decltype(cell)>>;
              std::array<Point, kCorners> p;
              for (std::size_t k = 0; k < kCorners; ++k)
                p[k] = pts[index_cast<std::size_t>(cell[k])];
              if constexpr (kCorners == 8) *sj++ = hex_sj(p);
              if constexpr (kCorners == 4) *sj++ = run.type == kVtkQuad ? quad_sj(p) : tet_sj(p);
              if constexpr (kCorners == 5) *sj++ = pyramid_sj(p);
              if constexpr (kCorners == 6) *sj++ = wedge_sj(p);
            });
          }};
}

// The standard arrays ("scaled_jacobian", `block` unless empty), then the caller's.
void add_arrays(Output& out, const std::vector<int>& block, const VtkCellData& extra) {
  out.doubles.emplace_back("scaled_jacobian", scaled_jacobians(out));
  if (!block.empty()) out.ints.emplace_back("block", slices_of<std::int64_t>(block));
  for (const auto& [name, v] : extra.doubles) out.doubles.emplace_back(name, slices_of<double>(v));
  for (const auto& [name, v] : extra.ints) out.ints.emplace_back(name, slices_of<std::int64_t>(v));
}

// A mesh of one cell type.
template <std::size_t N>
void describe_single_type(Output& out, const std::filesystem::path& path,
                          const std::vector<Point>& points,
                          const std::vector<std::array<Index, N>>& cells, int type,
                          const std::vector<int>& block, const VtkCellData& extra) {
  const std::string file = path.string();
  out.points = &points;
  out.cells.add(cells, type);
  check_points(file, points);
  check_cells(file, out.cells, points.size());
  add_arrays(out, block, extra);
  check_arrays(out, file);
}

// What to write of a mesh, checked; `out` refers to the mesh and `extra`.
void describe(Output& out, const std::filesystem::path& path, const HexMesh& m,
              const VtkCellData& extra) {
  describe_single_type(out, path, m.points, m.hexes, kVtkHexahedron, m.block, extra);
}

void describe(Output& out, const std::filesystem::path& path, const TetMesh& m,
              const VtkCellData& extra) {
  describe_single_type(out, path, m.points, m.tets, kVtkTetra, m.block, extra);
}

void describe(Output& out, const std::filesystem::path& path, const QuadMesh& m,
              const VtkCellData& extra) {
  describe_single_type(out, path, m.points, m.quads, kVtkQuad, {}, extra);
}

// A model: hexes, tets, pyramids, then wedges (VTK's corner order), each with its element
// block (block_of).
void describe(Output& out, const std::filesystem::path& path, const Model& m,
              const VtkCellData& extra, std::span<const double> given_sj = {}) {
  const std::string file = path.string();
  validate(m, file);
  out.points = &m.points;
  out.cells.add(m.hexes, kVtkHexahedron);
  out.cells.add(m.tets, kVtkTetra);
  out.cells.add(m.pyramids, kVtkPyramid);
  out.cells.add(m.wedges, kVtkWedge, true);
  check_points(file, m.points);
  check_cells(file, out.cells, m.points.size());
  const Slices<std::int64_t> block{
      element_count(m), [&m, &out](std::size_t begin, std::size_t end, std::int64_t* b) {
        for (std::size_t r = 0; r < out.cells.runs.size(); ++r) {
          const CellRun& run = out.cells.runs[r];
          const ElementKind kind = kElementKinds[r];  // one run per kind, in their order
          const std::vector<int>& blocks = element_blocks(m, kind);
          const std::size_t lo = std::max(begin, run.first_cell);
          const std::size_t hi = std::min(end, run.first_cell + run.count);
          for (std::size_t c = lo; c < hi; ++c)
            *b++ = blocks.empty() ? default_block(kind) : blocks[c - run.first_cell];
        }
      }};
  if (given_sj.size() == element_count(m))  // the caller's, as scaled_jacobians() makes them
    out.doubles.emplace_back("scaled_jacobian", slices_of<double, double>(given_sj));
  else
    out.doubles.emplace_back("scaled_jacobian", scaled_jacobians(out));
  // The block again as "mat_id", the cell array of material ids Python solvers read (SfePy's
  // name; meshio hands it on), so that they find the materials without knowing ours.
  if (block.size > 0) out.ints.emplace_back("block", block);
  out.ints.emplace_back("mat_id", block);
  for (const auto& [name, v] : extra.doubles) out.doubles.emplace_back(name, slices_of<double>(v));
  for (const auto& [name, v] : extra.ints) out.ints.emplace_back(name, slices_of<std::int64_t>(v));
  check_arrays(out, file);
  for (const auto& [id, name] : m.block_names) out.block_names[id] = sanitize_name(name);
  // Sets by the written cells' numbers: hexes, then tets, pyramids and wedges.
  std::array<Index, 4> first{};
  for (std::size_t k = 1; k < kElementKinds.size(); ++k)
    first[k] = first[k - 1] + index_cast(element_count(m, kElementKinds[k - 1]));
  for (const NodeSet& set : m.node_sets)
    out.node_sets.emplace_back(std::to_string(set.id) + ":" + sanitize_name(set.name), set.nodes);
  for (const SideSet& set : m.side_sets) {
    std::vector<Index> pairs;
    for (const Side& side : set.sides)
      pairs.insert(pairs.end(),
                   {first[static_cast<std::size_t>(side.element.kind)] + side.element.index,
                    index_cast(side.face)});
    out.side_sets.emplace_back(std::to_string(set.id) + ":" + sanitize_name(set.name),
                               std::move(pairs));
  }
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

// Values per chunk of text, and bytes per chunk of base64 (whole 3-byte groups, so that the
// chunks' base64 put together is the whole's).
constexpr std::size_t kTextChunk = 8192;
constexpr std::size_t kBinaryChunk = 3 * 16384;

void write_chunks(std::ostream& os, std::size_t n, std::size_t chunk,
                  const std::function<void(std::size_t, std::size_t, std::string&)>& make) {
  write_in_chunks(n, chunk, make, [&os](std::string_view bytes) {
    os.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

// Values [0, v.size) in rows of `per_line` (the value after `indent` or a space, a newline
// after each row's last and after the very last).
template <typename T>
void write_rows(std::ostream& os, const Slices<T>& v, std::size_t per_line, const char* indent) {
  const std::size_t indent_size = std::strlen(indent);
  write_chunks(os, v.size, kTextChunk, [&](std::size_t begin, std::size_t end, std::string& text) {
    std::vector<T> values(end - begin);
    v.fill(begin, end, values.data());
    text.resize((end - begin) *
                (indent_size + (std::is_floating_point_v<T> ? kRealText : kIntegerText) + 2));
    char* at = text.data();
    for (std::size_t i = begin; i < end; ++i) {
      if (i % per_line == 0)
        at = std::copy_n(indent, indent_size, at);
      else
        *at++ = ' ';
      at = put_number(at, values[i - begin]);
      if (i % per_line == per_line - 1 || i + 1 == v.size) *at++ = '\n';
    }
    text.resize(index_cast<std::size_t>(at - text.data()));
  });
}

// Base64 (RFC 4648) of a byte string, as VTK's XML "binary" format wants it, appended.
void append_base64(std::string& out, std::string_view bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::size_t at = out.size();
  out.resize(at + (bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const auto b = (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16) |
                   (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8) |
                   static_cast<unsigned char>(bytes[i + 2]);
    out[at++] = kDigits[(b >> 18) & 63], out[at++] = kDigits[(b >> 12) & 63];
    out[at++] = kDigits[(b >> 6) & 63], out[at++] = kDigits[b & 63];
  }
  if (i < bytes.size()) {
    auto b = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (i + 1 < bytes.size())
      b |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out[at++] = kDigits[(b >> 18) & 63], out[at++] = kDigits[(b >> 12) & 63];
    out[at++] = i + 1 < bytes.size() ? kDigits[(b >> 6) & 63] : '=';
    out[at++] = '=';
  }
}

// One DataArray: ASCII rows of `per_line`, or (binary) base64 of a UInt64 byte count followed
// by the little-endian values, the layout VTK writes for uncompressed inline binary data.
template <typename Out, typename T>
void write_data_array(std::ostream& os, VtkEncoding encoding, const char* type,
                      const std::string& attributes, const Slices<T>& v, std::size_t per_line) {
  static_assert(std::endian::native == std::endian::little, "binary .vtu is written little-endian");
  os << "        <DataArray type=\"" << type << "\"" << attributes << " format=\""
     << (encoding == VtkEncoding::kAscii ? "ascii" : "binary") << "\">\n";
  if (encoding == VtkEncoding::kAscii) {
    write_rows(os, v, per_line, "          ");
  } else {
    // The stream's bytes [begin, end) of each chunk: those of the values that overlap it, cut.
    constexpr std::size_t kHeader = sizeof(std::uint64_t), kSize = sizeof(Out);
    const std::uint64_t count = v.size * kSize;
    os << "          ";
    write_chunks(os, kHeader + count, kBinaryChunk,
                 [&](std::size_t begin, std::size_t end, std::string& text) {
                   const std::size_t first = begin < kHeader ? 0 : (begin - kHeader) / kSize;
                   const std::size_t last =
                       end <= kHeader ? 0 : (end - kHeader + kSize - 1) / kSize;
                   const std::size_t from = begin < kHeader ? 0 : kHeader + first * kSize;
                   std::string bytes(begin < kHeader ? kHeader : 0, '\0');
                   std::memcpy(bytes.data(), &count, bytes.size());
                   std::vector<T> values(last > first ? last - first : 0);
                   v.fill(first, first + values.size(), values.data());
                   bytes.resize(bytes.size() + values.size() * kSize);
                   char* at = bytes.data() + (begin < kHeader ? kHeader : 0);
                   for (const T& x : values) {
                     const auto value = static_cast<Out>(x);
                     std::memcpy(at, &value, kSize);
                     at += kSize;
                   }
                   append_base64(text, std::string_view(bytes).substr(begin - from, end - begin));
                 });
    os << "\n";
  }
  os << "        </DataArray>\n";
}

// The point coordinates x, y, z per point.
Slices<double> coordinates(const std::vector<Point>& pts) {
  return {3 * pts.size(), [&pts](std::size_t begin, std::size_t end, double* out) {
            for (std::size_t j = begin; j < end; ++j)
              *out++ = pts[j / 3][index_cast<Eigen::Index>(j % 3)];
          }};
}

// The connectivity (VTK corner order), cell ends and types.
Slices<std::int64_t> connectivity(const Cells& cells) {
  return {cells.corners, [&cells](std::size_t begin, std::size_t end, std::int64_t* out) {
            if (begin == end) return;
            cells.for_each(cells.cell_of_corner(begin), cells.cell_of_corner(end - 1) + 1,
                           [&](const CellRun& run, const auto& cell, std::size_t c) {
                             const std::size_t at = run.first_corner + c * run.corners;
                             for (std::size_t k = 0; k < cell.size(); ++k)
                               if (at + k >= begin && at + k < end)
                                 *out++ = vtk_corner(run, cell, k);
                           });
          }};
}

Slices<std::int64_t> offsets(const Cells& cells) {
  return {cells.size, [&cells](std::size_t begin, std::size_t end, std::int64_t* out) {
            cells.for_each(begin, end, [&](const CellRun& run, const auto&, std::size_t c) {
              *out++ = index_cast<std::int64_t>(run.first_corner + (c + 1) * run.corners);
            });
          }};
}

Slices<std::int64_t> types(const Cells& cells) {
  return {cells.size, [&cells](std::size_t begin, std::size_t end, std::int64_t* out) {
            cells.for_each(begin, end, [&](const CellRun& run, const auto&, std::size_t) {
              *out++ = run.type;
            });
          }};
}

void write_vtu_output(std::ostream& os, const Output& o, VtkEncoding encoding) {
  const auto& pts = *o.points;
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\""
     << (encoding == VtkEncoding::kAscii ? "" : " header_type=\"UInt64\"") << ">\n"
     << "  <UnstructuredGrid>\n";
  // Block names, which the cell array "block" cannot carry: one-value field arrays
  // "block:NAME" holding the block id (ParaView lists them under Field Data); node sets as
  // "node_set:ID:NAME" (point indices), side sets as "side_set:ID:NAME" (2 components: cell
  // index, face number of primal/topology.hpp).
  if (!o.block_names.empty() || !o.node_sets.empty() || !o.side_sets.empty()) {
    os << "    <FieldData>\n";
    for (const auto& [id, name] : o.block_names)
      os << "      <DataArray type=\"Int32\" Name=\"block:" << xml_escape(name)
         << "\" NumberOfTuples=\"1\" format=\"ascii\">" << id << "</DataArray>\n";
    for (const auto* sets : {&o.node_sets, &o.side_sets})
      for (const auto& [name, values] : *sets) {
        const bool sides = sets == &o.side_sets;
        os << "      <DataArray type=\"Int32\" Name=\"" << (sides ? "side_set:" : "node_set:")
           << xml_escape(name) << "\" NumberOfComponents=\"" << (sides ? 2 : 1)
           << "\" NumberOfTuples=\"" << values.size() / (sides ? 2 : 1) << "\" format=\"ascii\">\n";
        write_values(os, values, 12, "          ", [](Index v) { return v; });
        os << "      </DataArray>\n";
      }
    os << "    </FieldData>\n";
  }
  os << "    <Piece NumberOfPoints=\"" << pts.size() << "\" NumberOfCells=\"" << o.cells.size
     << "\">\n"
     << "      <Points>\n";
  write_data_array<double>(os, encoding, "Float64", " NumberOfComponents=\"3\"", coordinates(pts),
                           3);
  os << "      </Points>\n"
     << "      <Cells>\n";
  // Int32 like Index: node numbers fit, and half the bytes of Int64.
  write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"connectivity\"",
                                 connectivity(o.cells), 8);
  write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"offsets\"", offsets(o.cells), 10);
  write_data_array<std::uint8_t>(os, encoding, "UInt8", " Name=\"types\"", types(o.cells), 20);
  os << "      </Cells>\n"
     << "      <CellData Scalars=\"scaled_jacobian\">\n";
  for (const auto& [name, v] : o.doubles)
    write_data_array<double>(os, encoding, "Float64", " Name=\"" + xml_escape(name) + "\"", v, 6);
  for (const auto& [name, v] : o.ints)
    write_data_array<std::int32_t>(os, encoding, "Int32", " Name=\"" + xml_escape(name) + "\"", v,
                                   10);
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

// Legacy VTK's binary values: each one's big-endian bytes (VTK's file-format manual, "Binary
// Files").
template <typename T>
char* put_big_endian(char* at, T x) {
  static_assert(std::is_trivially_copyable_v<T> && (sizeof(T) == 4 || sizeof(T) == 8));
  using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  Bits bits;
  std::memcpy(&bits, &x, sizeof bits);
  for (int k = static_cast<int>(sizeof bits) - 1; k >= 0; --k)
    *at++ = static_cast<char>(bits >> (8 * k));
  return at;
}

// A legacy .vtk file's sections, ASCII or BINARY: the keyword lines are text either way; a
// binary array's values follow the line that announces it, big-endian, and end with a newline.
class LegacyWriter {
 public:
  LegacyWriter(std::ostream& os, VtkEncoding encoding)
      : os_(os), binary_(encoding == VtkEncoding::kBinary) {}

  void header() {
    os_ << "# vtk DataFile Version 4.2\n"
        << "geode mesh\n"
        << (binary_ ? "BINARY\n" : "ASCII\n") << "DATASET UNSTRUCTURED_GRID\n";
  }

  // Values as `Wire` (std::int32_t for "int", double), `per_line` to a line in ASCII.
  template <typename Wire, typename T>
  void values(const Slices<T>& v, std::size_t per_line) {
    if (!binary_) return write_rows(os_, v, per_line, "");
    write_chunks(os_, v.size, kTextChunk,
                 [&](std::size_t begin, std::size_t end, std::string& bytes) {
                   std::vector<T> values(end - begin);
                   v.fill(begin, end, values.data());
                   bytes.resize((end - begin) * sizeof(Wire));
                   char* at = bytes.data();
                   for (const T& x : values) at = put_big_endian(at, static_cast<Wire>(x));
                 });
    os_ << '\n';
  }

  void points(const std::vector<Point>& pts) {
    write_chunks(os_, pts.size(), binary_ ? kTextChunk : kTextChunk / 4,
                 [&](std::size_t begin, std::size_t end, std::string& text) {
                   text.resize((end - begin) * 3 * (binary_ ? sizeof(double) : kRealText + 1));
                   char* at = text.data();
                   for (std::size_t i = begin; i < end; ++i)
                     for (int c = 0; c < 3; ++c) {
                       if (binary_) {
                         at = put_big_endian(at, pts[i][c]);
                       } else {
                         at = put_number(at, pts[i][c]);
                         *at++ = c < 2 ? ' ' : '\n';
                       }
                     }
                   text.resize(index_cast<std::size_t>(at - text.data()));
                 });
    if (binary_) os_ << '\n';
  }

  // The classic layout: per cell its corner count, then its corners.
  void cells(const Cells& cells) {
    write_chunks(
        os_, cells.size, binary_ ? kTextChunk : kTextChunk / 8,
        [&](std::size_t begin, std::size_t end, std::string& text) {
          text.resize((end - begin) * 9 * (binary_ ? sizeof(std::int32_t) : kIntegerText + 1));
          char* at = text.data();
          cells.for_each(begin, end, [&](const CellRun& run, const auto& cell, std::size_t) {
            for (std::size_t k = 0; k <= cell.size(); ++k) {  // the count, then the corners
              const Index v = k == 0 ? index_cast(cell.size()) : vtk_corner(run, cell, k - 1);
              if (binary_) {
                at = put_big_endian(at, std::int32_t{v});
              } else {
                at = put_number(at, std::int64_t{v});
                *at++ = k < cell.size() ? ' ' : '\n';
              }
            }
          });
          text.resize(index_cast<std::size_t>(at - text.data()));
        });
    if (binary_) os_ << '\n';
  }

 private:
  std::ostream& os_;
  bool binary_;
};

void write_vtk_output(std::ostream& os, const Output& o, VtkEncoding encoding) {
  const std::size_t ncells = o.cells.size;
  LegacyWriter w(os, encoding);
  w.header();
  // Block names and sets as in .vtu (write_vtu_output), as dataset field data; array names with
  // VTK's own escapes (%XX for white space, '%', '"' and non-ASCII bytes, as vtkDataWriter).
  const std::size_t fields = o.block_names.size() + o.node_sets.size() + o.side_sets.size();
  if (fields > 0) {
    os << "FIELD FieldData " << fields << '\n';
    for (const auto& [id, name] : o.block_names) {
      os << legacy_name("block:" + name) << " 1 1 int\n";
      const std::vector<int> value{id};
      w.values<std::int32_t>(slices_of<std::int64_t>(value), 12);
    }
    for (const auto* sets : {&o.node_sets, &o.side_sets})
      for (const auto& [name, values] : *sets) {
        const bool sides = sets == &o.side_sets;
        os << legacy_name((sides ? "side_set:" : "node_set:") + name) << ' ' << (sides ? 2 : 1)
           << ' ' << values.size() / (sides ? 2 : 1) << " int\n";
        w.values<std::int32_t>(slices_of<std::int64_t>(values), 12);
      }
  }
  os << "POINTS " << o.points->size() << " double\n";
  w.points(*o.points);
  os << "CELLS " << ncells << ' ' << ncells + o.cells.corners << '\n';
  w.cells(o.cells);
  os << "CELL_TYPES " << ncells << '\n';
  w.values<std::int32_t>(types(o.cells), 1);
  os << "CELL_DATA " << ncells << '\n';
  for (const auto& [name, v] : o.doubles) {
    os << "SCALARS " << name << " double 1\nLOOKUP_TABLE default\n";
    w.values<double>(v, 6);
  }
  for (const auto& [name, v] : o.ints) {
    os << "SCALARS " << name << " int 1\nLOOKUP_TABLE default\n";
    w.values<std::int32_t>(v, 10);
  }
}

}  // namespace

// ---- Writers ----------------------------------------------------------------------------------

#define GEODE_VTK_WRITERS(Mesh)                                                                  \
  void write_vtu(const std::filesystem::path& path, const Mesh& mesh, const VtkCellData& extra,  \
                 VtkEncoding encoding) {                                                         \
    Output out;                                                                                  \
    describe(out, path, mesh, extra);                                                            \
    write_file_atomically(path, [&](std::ostream& os) { write_vtu_output(os, out, encoding); }); \
  }                                                                                              \
  void write_vtk(const std::filesystem::path& path, const Mesh& mesh, const VtkCellData& extra,  \
                 VtkEncoding encoding) {                                                         \
    Output out;                                                                                  \
    describe(out, path, mesh, extra);                                                            \
    write_file_atomically(path, [&](std::ostream& os) { write_vtk_output(os, out, encoding); }); \
  }
GEODE_VTK_WRITERS(HexMesh)
GEODE_VTK_WRITERS(TetMesh)
GEODE_VTK_WRITERS(QuadMesh)
#undef GEODE_VTK_WRITERS

void write_vtu(const std::filesystem::path& path, const Model& model, const VtkCellData& extra,
               VtkEncoding encoding, std::span<const double> scaled_jacobians) {
  Output out;
  describe(out, path, model, extra, scaled_jacobians);
  write_file_atomically(path, [&](std::ostream& os) { write_vtu_output(os, out, encoding); });
}

void write_vtk(const std::filesystem::path& path, const Model& model, const VtkCellData& extra,
               VtkEncoding encoding, std::span<const double> scaled_jacobians) {
  Output out;
  describe(out, path, model, extra, scaled_jacobians);
  write_file_atomically(path, [&](std::ostream& os) { write_vtk_output(os, out, encoding); });
}

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
