#include <geode/io/vtk.hpp>

#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <geode/io/detail/vtk_read_text.hpp>
#include <geode/io/file_format.hpp>
#include <geode/io/mapped_file.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io {

using namespace primal;
using detail::check_cells;
using detail::fail;
using detail::parse_double;
using detail::parse_int;
using detail::point_from;

// ---- Legacy .vtk reader -----------------------------------------------------------------------

namespace {

// Token stream over the body of a legacy file (after the 3 header lines).
class Tokens {
 public:
  Tokens(std::string_view text, int first_line, std::string file)
      : s_(text), line_(first_line), file_(std::move(file)) {}
  bool done() {
    skip_space();
    return pos_ >= s_.size();
  }
  int line() {
    skip_space();
    return line_;
  }
  std::string_view next(const std::string& what) {
    if (done())
      fail(file_, line_, "unexpected end of file while reading " + what + " (truncated file?)");
    const std::size_t start = pos_;
    while (pos_ < s_.size() && !detail::ascii_space(s_[pos_])) ++pos_;
    token_line_ = line_;
    return s_.substr(start, pos_ - start);
  }
  std::string_view peek() const {
    std::size_t start = pos_;
    while (start < s_.size() && detail::ascii_space(s_[start])) ++start;
    std::size_t end = start;
    while (end < s_.size() && !detail::ascii_space(s_[end])) ++end;
    return s_.substr(start, end - start);
  }
  // Skips up to the next blank line (VTK's METADATA blocks end there).
  void skip_to_blank_line() {
    while (pos_ < s_.size()) {
      const std::size_t eol = s_.find('\n', pos_);
      if (eol == std::string_view::npos) {
        pos_ = s_.size();
        return;
      }
      pos_ = eol + 1;
      ++line_;
      std::size_t p = pos_;
      while (p < s_.size() && s_[p] != '\n' && detail::ascii_space(s_[p])) ++p;
      if (p >= s_.size() || s_[p] == '\n') return;
    }
  }
  int line_before() const { return token_line_; }
  // Binary legacy files (big-endian, VTK's file format manual): the values of one array follow
  // the line that announces it. begin_array(type) switches integer() and real() to those bytes
  // until end_array(); in ASCII files both do nothing.
  void set_binary(bool binary) { binary_ = binary; }
  void begin_array(std::string_view type, const std::string& what) {
    if (!binary_) return;
    const std::string t = lower(type);
    if (t == "float")
      size_ = 4, real_ = true;
    else if (t == "double")
      size_ = 8, real_ = true;
    else if (t == "char" || t == "unsigned_char" || t == "bit")
      size_ = 1, real_ = false;
    else if (t == "short" || t == "unsigned_short")
      size_ = 2, real_ = false;
    else if (t == "int" || t == "unsigned_int" || t == "vtktypeint32")
      size_ = 4, real_ = false;
    else if (t == "long" || t == "unsigned_long" || t == "vtktypeint64" || t == "vtktypeuint64" ||
             t == "vtkidtype")
      size_ = 8, real_ = false;
    else
      fail(file_, line_, what + ": binary type '" + std::string(type) + "' is not supported");
    unsigned_ = t.rfind("unsigned", 0) == 0 || t == "vtktypeuint64";
    const std::size_t eol = s_.find('\n', pos_);
    if (eol == std::string_view::npos)
      fail(file_, line_, what + ": no binary data (truncated file?)");
    pos_ = eol + 1;
    ++line_;
    in_array_ = true;
  }
  void end_array() {
    if (!in_array_) return;
    in_array_ = false;
    // The bytes may hold '\n': count none of them as lines.
  }
  long long integer(const std::string& what) {
    if (in_array_) {
      if (real_) fail(file_, line_, what + ": floating-point data where integers are expected");
      const std::uint64_t bits = raw_bits(what);
      if (unsigned_ || size_ == 8) {
        if (unsigned_ && bits > static_cast<std::uint64_t>(std::numeric_limits<long long>::max()))
          fail(file_, line_, what + ": " + std::to_string(bits) + " is out of range");
        return static_cast<long long>(bits);
      }
      const std::uint64_t sign = std::uint64_t{1} << (8 * size_ - 1);
      return static_cast<long long>(bits ^ sign) - static_cast<long long>(sign);
    }
    const auto t = next(what);
    return parse_int(file_, line_before(), t);
  }
  double real(const std::string& what) {
    if (in_array_) return raw(what);
    const auto t = next(what);
    return parse_double(file_, line_before(), t);
  }
  // An integer that must fit an int (node numbers, cell types, int arrays).
  int int32(const std::string& what) {
    const long long v = integer(what);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      fail(file_, line_before(), what + ": " + std::to_string(v) + " is out of range");
    return static_cast<int>(v);
  }
  std::size_t count(const std::string& what) {
    const long long n = integer(what);
    if (n < 0) fail(file_, line_before(), what + " is negative");
    return index_cast<std::size_t>(n);
  }
  void expect(std::string_view word, const std::string& what) {
    const auto t = next(what);
    if (t != word) {
      fail(file_, line_before(),
           "expected " + std::string(word) + ", found '" + std::string(t) + "'");
    }
  }

 private:
  std::string_view s_;
  std::size_t pos_ = 0;
  int line_ = 1, token_line_ = 1;
  std::string file_;
  bool binary_ = false, in_array_ = false, real_ = false, unsigned_ = false;
  std::size_t size_ = 4;

  static std::string lower(std::string_view s) {
    std::string l(s);
    for (auto& c : l) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return l;
  }
  void skip_space() {
    if (in_array_) return;
    while (pos_ < s_.size() && detail::ascii_space(s_[pos_])) line_ += s_[pos_++] == '\n';
  }
  // One big-endian value of the current array type, as its bits.
  std::uint64_t raw_bits(const std::string& what) {
    if (s_.size() - pos_ < size_)
      fail(file_, line_, what + ": binary data cut short (truncated file?)");
    std::uint64_t bits = 0;
    for (std::size_t k = 0; k < size_; ++k)
      bits = bits << 8 | static_cast<unsigned char>(s_[pos_ + k]);
    pos_ += size_;
    return bits;
  }
  // The same as a double (integer arrays read as reals: converted exactly up to 2^53).
  double raw(const std::string& what) {
    const std::uint64_t bits = raw_bits(what);
    if (real_) {
      if (size_ == 4) {
        const auto b32 = static_cast<std::uint32_t>(bits);
        float f;
        std::memcpy(&f, &b32, 4);
        return f;
      }
      double d;
      std::memcpy(&d, &bits, 8);
      return d;
    }
    if (unsigned_) return static_cast<double>(bits);
    if (size_ == 8) return static_cast<double>(static_cast<std::int64_t>(bits));
    const std::uint64_t sign = std::uint64_t{1} << (8 * size_ - 1);
    return static_cast<double>(static_cast<std::int64_t>(bits ^ sign) -
                               static_cast<std::int64_t>(sign));
  }
};

std::string upper(std::string_view s) {
  std::string u(s);
  for (auto& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

// VTK's legacy array name escapes (%XX, vtkDataReader::DecodeString).
std::string decode_legacy_name(std::string_view token) {
  std::string out;
  for (std::size_t i = 0; i < token.size(); ++i) {
    const auto hex = [](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) ? c - '0'
             : (c >= 'A' && c <= 'F')                    ? c - 'A' + 10
             : (c >= 'a' && c <= 'f')                    ? c - 'a' + 10
                                                         : -1;
    };
    if (token[i] == '%' && i + 2 < token.size() && hex(token[i + 1]) >= 0 &&
        hex(token[i + 2]) >= 0) {
      out += static_cast<char>(hex(token[i + 1]) * 16 + hex(token[i + 2]));
      i += 2;
    } else {
      out += token[i];
    }
  }
  return out;
}

}  // namespace

VtkGrid read_vtk(const std::filesystem::path& path) {
  check_mesh_format(path, MeshFileFormat::kVtk);
  return parse_vtk(MappedFile(path).bytes(), path.string());
}

VtkGrid parse_vtk(std::string_view content, const std::string& source) {
  VtkGrid g;
  g.source = source;
  const std::string& file = g.source;
  const std::string_view text = content;
  // Header: 3 lines.
  std::size_t pos = 0;
  std::array<std::string, 3> header;
  for (int l = 0; l < 3; ++l) {
    const auto e = text.find('\n', pos);
    if (e == std::string::npos)
      fail(file, l + 1, "unexpected end of file in the header (truncated file?)");
    header[l] = std::string(text.substr(pos, e - pos));
    if (!header[l].empty() && header[l].back() == '\r') header[l].pop_back();
    pos = e + 1;
  }
  if (header[0].rfind("# vtk DataFile Version", 0) != 0) {
    fail(file, 1, "not a legacy VTK file (expected '# vtk DataFile Version')");
  }
  const bool binary = upper(header[2]).rfind("BINARY", 0) == 0;
  if (!binary && upper(header[2]).rfind("ASCII", 0) != 0)
    fail(file, 3, "'" + header[2] + "' is neither ASCII nor BINARY");
  Tokens t(text.substr(pos), 4, file);
  t.set_binary(binary);
  t.expect("DATASET", "the DATASET line");
  if (const auto type = t.next("the dataset type"); upper(type) != "UNSTRUCTURED_GRID") {
    fail(file, t.line_before(),
         "dataset " + std::string(type) + " is not supported (UNSTRUCTURED_GRID only)");
  }
  std::vector<int> cell_line, type_line;
  std::size_t nc = 0;
  bool have_points = false, have_cells = false, have_types = false;
  while (!t.done()) {
    const std::string key = upper(t.next("a section keyword"));
    const int key_line = t.line_before();
    // Each section once: a repeated one would append to arrays already checked against others.
    if ((key == "POINTS" && have_points) || (key == "CELLS" && have_cells) ||
        (key == "CELL_TYPES" && have_types))
      fail(file, key_line, key + " given twice");
    if (key == "POINTS") {
      const std::size_t np = t.count("the number of points");
      t.begin_array(t.next("the point type"), "POINTS");
      for (std::size_t i = 0; i < np; ++i) {
        const std::string what = "point " + std::to_string(i);
        const double x = t.real(what);
        const int line = t.line_before();
        const double y = t.real(what), z = t.real(what);
        g.points.push_back(point_from(file, line, i, x, y, z));
      }
      t.end_array();
      have_points = true;
    } else if (key == "CELLS") {
      nc = t.count("the number of cells");
      const std::size_t size = t.count("the CELLS size");
      if (upper(t.peek()) ==
          "OFFSETS") {  // 5.1 layout: OFFSETS type (n+1 values) CONNECTIVITY type
        t.next("OFFSETS");
        t.begin_array(t.next("the offsets type"), "OFFSETS");
        if (nc == 0) fail(file, key_line, "CELLS: 5.1 layout needs at least one offset");
        std::vector<std::size_t> offsets;
        for (std::size_t i = 0; i < nc; ++i)
          offsets.push_back(t.count("offset " + std::to_string(i)));
        t.end_array();
        t.expect("CONNECTIVITY", "the CONNECTIVITY keyword");
        t.begin_array(t.next("the connectivity type"), "CONNECTIVITY");
        nc -= 1;  // the 5.1 header counts offsets
        for (std::size_t c = 0; c < nc; ++c) {
          if (offsets[c + 1] < offsets[c] || offsets[c + 1] > size) {
            fail(file, key_line, "OFFSETS: cell " + std::to_string(c) + " has bad offsets");
          }
          std::vector<Index> cell;
          cell_line.push_back(t.line());
          for (std::size_t i = offsets[c]; i < offsets[c + 1]; ++i) {
            cell.push_back((t.int32("cell " + std::to_string(c))));
          }
          g.cells.push_back(std::move(cell));
        }
        t.end_array();
      } else {
        std::size_t read = 0;
        t.begin_array("int", "CELLS");
        for (std::size_t c = 0; c < nc; ++c) {
          const std::string what = "cell " + std::to_string(c);
          const std::size_t n = t.count(what);
          cell_line.push_back(t.line_before());
          std::vector<Index> cell;
          for (std::size_t i = 0; i < n; ++i) cell.push_back((t.int32(what)));
          read += n + 1;
          g.cells.push_back(std::move(cell));
        }
        t.end_array();
        if (read != size) {
          fail(file, key_line,
               "CELLS: size " + std::to_string(size) + " but the cells hold " +
                   std::to_string(read) + " values");
        }
      }
      have_cells = true;
    } else if (key == "CELL_TYPES") {
      const std::size_t n = t.count("the number of cell types");
      if (!have_cells || n != nc) {
        fail(file, key_line,
             "CELL_TYPES " + std::to_string(n) + " does not follow CELLS " + std::to_string(nc));
      }
      t.begin_array("int", "CELL_TYPES");
      for (std::size_t c = 0; c < n; ++c) {
        g.cell_types.push_back((t.int32("the type of cell " + std::to_string(c))));
        type_line.push_back(t.line_before());
      }
      t.end_array();
      have_types = true;
    } else if (key == "CELL_DATA" || key == "POINT_DATA") {
      const bool cell = key == "CELL_DATA";
      const std::size_t n = t.count("the " + key + " count");
      if (cell && (!have_types || n != nc)) {
        fail(file, key_line,
             "CELL_DATA " + std::to_string(n) + " does not match " + std::to_string(nc) + " cells");
      }
      // Attribute sections until the next dataset-level keyword.
      while (!t.done()) {
        const std::string kind = upper(t.peek());
        if (kind == "CELL_DATA" || kind == "POINT_DATA") break;
        t.next("an attribute");
        if (kind == "METADATA") {
          t.skip_to_blank_line();
          continue;
        }
        const int attr_line = t.line_before();
        std::vector<std::pair<std::string, std::string>> arrays;  // name, type
        std::vector<std::size_t> comps;
        if (kind == "SCALARS") {
          const std::string name(t.next("the SCALARS name"));
          const std::string type(t.next("the SCALARS type"));
          std::size_t nco = 1;
          if (upper(t.peek()) != "LOOKUP_TABLE") nco = t.count("the SCALARS component count");
          t.expect("LOOKUP_TABLE", "LOOKUP_TABLE");
          t.next("the lookup table name");
          arrays.emplace_back(name, type);
          comps.push_back(nco);
        } else if (kind == "FIELD") {
          t.next("the FIELD name");
          const std::size_t k = t.count("the FIELD array count");
          for (std::size_t a = 0; a < k; ++a) {
            const std::string name(t.next("a FIELD array name"));
            const std::size_t nco = t.count("the component count of " + name);
            const std::size_t tuples = t.count("the tuple count of " + name);
            const std::string type(t.next("the type of " + name));
            if (tuples != n)
              fail(file, t.line_before(),
                   "FIELD array " + name + ": " + std::to_string(tuples) + " tuples, expected " +
                       std::to_string(n));
            // FIELD arrays are read one by one (values follow each header).
            const bool is_real = upper(type) == "FLOAT" || upper(type) == "DOUBLE";
            std::vector<double> dv;
            std::vector<int> iv;
            t.begin_array(type, "FIELD array " + name);
            for (std::size_t i = 0; i < n * nco; ++i) {
              if (is_real)
                dv.push_back(t.real("array " + name));
              else
                iv.push_back((t.int32("array " + name)));
            }
            t.end_array();
            if (cell && nco == 1) {
              if (is_real)
                g.cell_data.doubles.emplace_back(name, std::move(dv));
              else
                g.cell_data.ints.emplace_back(name, std::move(iv));
            }
          }
          continue;
        } else if (kind == "VECTORS" || kind == "NORMALS") {
          arrays.emplace_back(std::string(t.next("the array name")),
                              std::string(t.next("the array type")));
          comps.push_back(3);
        } else {
          fail(file, attr_line, "unsupported attribute section '" + kind + "'");
        }
        for (std::size_t a = 0; a < arrays.size(); ++a) {
          const auto& [name, type] = arrays[a];
          const bool is_real = upper(type) == "FLOAT" || upper(type) == "DOUBLE";
          std::vector<double> dv;
          std::vector<int> iv;
          t.begin_array(type, "array " + name);
          for (std::size_t i = 0; i < n * comps[a]; ++i) {
            if (is_real)
              dv.push_back(t.real("array " + name));
            else
              iv.push_back((t.int32("array " + name)));
          }
          t.end_array();
          if (cell && comps[a] == 1) {
            if (is_real)
              g.cell_data.doubles.emplace_back(name, std::move(dv));
            else
              g.cell_data.ints.emplace_back(name, std::move(iv));
          }
        }
      }
    } else if (key == "FIELD") {
      // Dataset field data (block names, sets: write_vtk); integer arrays kept, others read
      // past. Values are read one by one, so a count larger than the file only ends early.
      t.next("the FIELD name");
      const std::size_t k = t.count("the FIELD array count");
      for (std::size_t a = 0; a < k; ++a) {
        const std::string name = decode_legacy_name(t.next("a FIELD array name"));
        const std::size_t components = t.count("the component count of " + name);
        const std::size_t tuples = t.count("the tuple count of " + name);
        const std::string type(t.next("the type of " + name));
        if (components < 1 || components > 16)
          fail(file, t.line_before(),
               "FIELD array " + name + ": " + std::to_string(components) + " components");
        const bool is_real = upper(type) == "FLOAT" || upper(type) == "DOUBLE";
        VtkGrid::FieldArray array{name, components, {}};
        t.begin_array(type, "FIELD array " + name);
        for (std::size_t i = 0; i < tuples; ++i)
          for (std::size_t c = 0; c < components; ++c) {
            if (is_real)
              (void)t.real("array " + name);
            else
              array.values.push_back(t.int32("array " + name));
          }
        t.end_array();
        if (!is_real) g.field_data.push_back(std::move(array));
      }
    } else if (key == "METADATA") {
      // VTK 8+ writes METADATA blocks (array information) that end at a blank line.
      t.skip_to_blank_line();
    } else {
      fail(file, key_line, "unknown or unsupported section '" + key + "'");
    }
  }
  if (!have_points) fail(file, t.line(), "no POINTS section (truncated file?)");
  if (!have_cells) fail(file, t.line(), "no CELLS section (truncated file?)");
  if (!have_types) fail(file, t.line(), "no CELL_TYPES section (truncated file?)");
  check_cells(g, [&](std::size_t c, bool type) { return type ? type_line[c] : cell_line[c]; });
  return g;
}

VtkGrid read_vtk_file(const std::filesystem::path& path) {
  switch (mesh_format_from_extension(path)) {  // the one place that decides (any case)
    case MeshFileFormat::kVtu:
      return read_vtu(path);
    case MeshFileFormat::kVtk:
      return read_vtk(path);
    default:
      throw InvalidInput(path.string() + ": unknown extension '" + path.extension().string() +
                         "' (expected .vtu or .vtk)");
  }
}

}  // namespace geode::io
