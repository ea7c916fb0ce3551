#include "support/fixtures.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>

namespace geode::test {
namespace {

[[noreturn]] void fail(const std::string& file, int line, const std::string& why) {
  throw InvalidInput(file + ":" + std::to_string(line) + ": " + why);
}

// Splits one CSV line on commas; each field must parse completely as a number.
std::vector<double> parse_row(const std::string& text, const std::string& file, int line,
                              std::size_t fields) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string field;
  while (std::getline(ss, field, ',')) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(field, &used);
    } catch (const std::exception&) {
      fail(file, line, "field '" + field + "' is not a number");
    }
    while (used < field.size() && (field[used] == ' ' || field[used] == '\r')) ++used;
    if (used != field.size()) fail(file, line, "field '" + field + "' is not a number");
    out.push_back(value);
  }
  if (out.size() != fields) {
    fail(file, line,
         "expected " + std::to_string(fields) + " fields, got " + std::to_string(out.size()));
  }
  return out;
}

std::vector<std::vector<double>> read_rows(const std::string& file, std::size_t fields) {
  std::ifstream in(file);
  if (!in) throw InvalidInput(file + ": cannot open");
  std::string text;
  std::vector<std::vector<double>> rows;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (line == 1) continue;  // header
    if (text.find_first_not_of(" \r\t") == std::string::npos) continue;
    rows.push_back(parse_row(text, file, line, fields));
    // Rows are numbered 1..N in order; the number is the first field.
    if (rows.back()[0] != static_cast<double>(rows.size())) {
      fail(file, line,
           "row number " + std::to_string(rows.back()[0]) + ", expected " +
               std::to_string(rows.size()));
    }
  }
  return rows;
}

}  // namespace

primal::HexMesh read_hex_csv(const std::string& nodes_csv, const std::string& hexes_csv) {
  primal::HexMesh mesh;
  for (const auto& r : read_rows(nodes_csv, 4)) mesh.points.emplace_back(r[1], r[2], r[3]);
  const auto rows = read_rows(hexes_csv, 9);
  for (std::size_t h = 0; h < rows.size(); ++h) {
    std::array<primal::Index, 8> hex{};
    for (int c = 0; c < 8; ++c) {
      const double n = rows[h][c + 1];
      if (n != static_cast<double>(static_cast<long>(n)) || n < 1 ||
          n > static_cast<double>(mesh.points.size())) {
        fail(hexes_csv, static_cast<int>(h) + 2,
             "hex " + std::to_string(h + 1) + " corner n" + std::to_string(c + 1) +
                 " is not a node number in 1.." + std::to_string(mesh.points.size()));
      }
      hex[c] = static_cast<primal::Index>(n) - 1;  // paper order is VTK order; see header
    }
    mesh.hexes.push_back(hex);
  }
  return mesh;
}

primal::HexMesh appendix_a_geode() {
  const std::string dir = std::string(GEODE_SOURCE_DIR) + "/notebooks-data/appendix-a/";
  return read_hex_csv(dir + "nodes.csv", dir + "hexes.csv");
}

primal::HexMesh structured_hex_grid(int nx, int ny, int nz) {
  primal::HexMesh mesh;
  auto id = [&](int i, int j, int k) {
    return primal::index_cast(i + (nx + 1) * (j + (ny + 1) * k));
  };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) mesh.points.emplace_back(i, j, k);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        std::array<primal::Index, 8> hex{};
        // Corner c sits at the offsets of its unit-cube coordinates (topology table).
        for (int c = 0; c < 8; ++c) {
          const auto& rc = primal::topology::kHexCornerCoords[c];
          hex[c] = id(i + rc[0], j + rc[1], k + rc[2]);
        }
        mesh.hexes.push_back(hex);
      }
  return mesh;
}

primal::QuadMesh structured_quad_grid(int nx, int ny) {
  primal::QuadMesh mesh;
  auto id = [&](int i, int j) { return primal::index_cast(i + (nx + 1) * j); };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.points.emplace_back(i, j, 0.0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      mesh.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return mesh;
}

primal::QuadMesh boundary_quads(const primal::HexMesh& mesh,
                                const std::function<bool(const primal::Point&)>& keep) {
  // primal::boundary_quads gives them in first-appearance order, outward: keep, renumber.
  primal::QuadMesh out;
  std::vector<primal::Index> renumber(mesh.points.size(), primal::kInvalidIndex);
  for (const primal::BoundaryQuad& b : primal::boundary_quads(mesh)) {
    const auto& f = b.nodes;
    if (!std::all_of(f.begin(), f.end(), [&](primal::Index n) { return keep(mesh.points[n]); }))
      continue;
    std::array<primal::Index, 4> q{};
    for (int c = 0; c < 4; ++c) {
      if (renumber[f[c]] == primal::kInvalidIndex) {
        renumber[f[c]] = primal::index_cast(out.points.size());
        out.points.push_back(mesh.points[f[c]]);
      }
      q[c] = renumber[f[c]];
    }
    out.quads.push_back(q);
  }
  return out;
}

primal::Model four_tet_fan(const primal::Point& centre, const primal::Point& apex) {
  primal::Model m = primal::grid_model({1, 1, 1}, 1.0, [](int, int, int) { return false; });
  m.points.push_back(centre);  // node 8
  m.points.push_back(apex);    // node 9
  const std::array<primal::Index, 4> top{4, 5, 7, 6};
  for (std::size_t i = 0; i < 4; ++i) {
    m.tets.push_back({top[i], top[(i + 1) % 4], 8, 9});
    m.tet_block.push_back(2);
  }
  return m;
}

primal::Model tet_cell_on_hex_top() {
  primal::Model m = primal::grid_model(
      {2, 2, 2}, 1.0, [](int i, int j, int k) { return i == 0 && j == 0 && k == 1; });
  std::erase_if(m.hexes, [&](const auto& h) {
    return m.points[primal::index_cast<std::size_t>(h[0])].z() > 0.5;
  });
  m.hex_block.assign(m.hexes.size(), 1);
  return m;
}

primal::Model unmerged_parts(std::array<int, 3> cells) {
  const int half = cells[0] / 2;
  primal::Model m = primal::grid_model(cells, 1.0, [&](int i, int, int) { return i >= half; });
  const auto first_copy = primal::index_cast<primal::Index>(m.points.size());
  m.points.insert(m.points.end(), m.points.begin(), m.points.end());
  for (auto& t : m.tets)
    for (auto& v : t) v += first_copy;
  return m;
}

primal::Model small_hybrid_model() {
  return primal::grid_model({4, 2, 2}, 1.0, [](int i, int, int) { return i >= 2; });
}

}  // namespace geode::test
