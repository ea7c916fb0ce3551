#pragma once
// What the two VTK readers (vtu_read.cpp: XML; vtk_read.cpp: legacy) share: the line-numbered
// failure, the check of cells against their types and the points, and numbers parsed from text
// (std::from_chars, every token whole, the file and line named on failure).
#include <charconv>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <geode/io/detail/ascii_space.hpp>
#include <geode/io/vtk.hpp>
#include <geode/io/vtk_cells.hpp>
#include <geode/primal/errors.hpp>

namespace geode::io::detail {

[[noreturn]] inline void fail(const std::string& file, int line, const std::string& what) {
  throw InvalidInput(file + ":" + std::to_string(line) + ": " + what);
}

// Checks cell types, node counts and node ranges; `line_of_cell` gives the line to report.
template <typename LineOf>
void check_cells(const VtkGrid& g, LineOf&& line_of_cell) {
  if (g.cell_types.size() != g.cells.size())  // named at the first cell or type without a partner
    fail(g.source,
         g.cell_types.size() > g.cells.size() ? line_of_cell(g.cells.size(), true)
                                              : line_of_cell(g.cell_types.size(), false),
         std::to_string(g.cells.size()) + " cells but " + std::to_string(g.cell_types.size()) +
             " cell types");
  for (std::size_t c = 0; c < g.cells.size(); ++c) {
    const int type = g.cell_types[c];
    const char* name = vtk_cells::cell_type_name(type);
    if (!name) {
      fail(g.source, line_of_cell(c, true),
           "cell " + std::to_string(c) + ": " +
               (vtk_cells::higher_order(type)
                    ? "cell type " + std::to_string(type) +
                          " is a higher-order cell (quadratic, "
                          "cubic or Lagrange); only linear cells are "
                          "read"
                    : "unknown or unsupported cell type " + std::to_string(type)) +
               " (supported: " + vtk_cells::supported_cell_types() + ")");
    }
    if (primal::index_cast<int>(g.cells[c].size()) != vtk_cells::cell_type_size(type)) {
      fail(g.source, line_of_cell(c, false),
           "cell " + std::to_string(c) + ": type " + std::to_string(type) + " (" + name +
               ") needs " + std::to_string(vtk_cells::cell_type_size(type)) + " nodes, has " +
               std::to_string(g.cells[c].size()));
    }
    for (primal::Index v : g.cells[c]) {
      if (v < 0 || primal::index_cast<std::size_t>(v) >= g.points.size()) {
        fail(g.source, line_of_cell(c, false),
             "cell " + std::to_string(c) + ": node " + std::to_string(v) + " out of range [0, " +
                 std::to_string(g.points.size()) + ")");
      }
    }
  }
}

// Numbers of a text block with the line each starts on.
struct Numbers {
  std::vector<std::string_view> tokens;
  std::vector<int> lines;
  std::shared_ptr<const std::string> storage;  // the tokens' text when decoded from binary
};

inline Numbers split_numbers(std::string_view text, int first_line) {
  Numbers n;
  int line = first_line;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '\n') ++line;
    if (ascii_space(text[i])) {
      ++i;
      continue;
    }
    const std::size_t start = i;
    while (i < text.size() && !ascii_space(text[i])) ++i;
    n.tokens.push_back(text.substr(start, i - start));
    n.lines.push_back(line);
  }
  return n;
}

inline double parse_double(const std::string& file, int line, std::string_view tok) {
  double x = 0.0;
  const char* b = tok.data();
  const char* e = tok.data() + tok.size();
  if (!tok.empty() && *b == '+') ++b;
  const auto res = std::from_chars(b, e, x);
  if (res.ec != std::errc() || res.ptr != e)
    fail(file, line, "'" + std::string(tok) + "' is not a number");
  return x;
}

inline long long parse_int(const std::string& file, int line, std::string_view tok) {
  long long x = 0;
  const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), x);
  if (res.ec != std::errc() || res.ptr != tok.data() + tok.size()) {
    fail(file, line, "'" + std::string(tok) + "' is not an integer");
  }
  return x;
}

inline int parse_int32(const std::string& file, int line, std::string_view tok) {
  const long long v = parse_int(file, line, tok);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(file, line, "'" + std::string(tok) + "' is out of range");
  return static_cast<int>(v);
}

inline primal::Point point_from(const std::string& file, int line, std::size_t index, double x,
                                double y, double z) {
  const primal::Point p(x, y, z);
  if (!p.allFinite()) {
    fail(file, line, "point " + std::to_string(index) + ": non-finite coordinate (NaN or inf)");
  }
  return p;
}

}  // namespace geode::io::detail
