// VTK I/O: exact round trips (.vtu and legacy .vtk) for hex, tet and quad meshes with cell
// arrays; each kind of bad input rejected with the file, the line and the reason; atomic
// writes; and, when python3-vtk9 is installed, VTK's own readers open what we write.
#include <geode/io/vtk.hpp>

#include <doctest/doctest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>

#include <geode/io/atomic_file.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

using namespace geode::primal;
using namespace geode::io;
namespace fs = std::filesystem;

namespace {

using geode::test::slurp;

using geode::test::TempDir;  // a fresh directory per test case, removed afterwards

void spit(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

void jitter(std::vector<Point>& points) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double t = static_cast<double>(i);
    points[i] += 0.1 * Point(std::sin(1.3 * t), std::sin(2.1 * t + 0.7), std::sin(0.7 * t + 1.9));
  }
}

HexMesh test_hexes() {
  HexMesh m = geode::test::structured_hex_grid(2, 2, 1);
  jitter(m.points);
  m.block = {1, 1, 2, 7};
  return m;
}

TetMesh test_tets() {  // two positive tets sharing face {1, 2, 3}
  TetMesh m;
  m.points = {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0), Point(0, 0, 1), Point(1, 1, 1)};
  m.tets = {{0, 1, 2, 3}, {1, 4, 2, 3}};
  m.block = {3, 4};
  return m;
}

QuadMesh test_quads() {  // a 2x1 grid tilted into 3D space
  QuadMesh m = geode::test::structured_quad_grid(2, 1);
  for (auto& p : m.points) p = Point(p.x(), p.y() * 0.6, p.y() * 0.8 + 0.1 * p.x() * p.x());
  return m;
}

VtkCellData extra_arrays(std::size_t n) {
  VtkCellData d;
  std::vector<double> third(n);
  std::vector<int> tag(n);
  for (std::size_t i = 0; i < n; ++i) {
    third[i] = static_cast<double>(i) / 3.0;  // not exactly representable in decimal
    tag[i] = -5 + static_cast<int>(i);
  }
  d.doubles.emplace_back("one_third", third);
  d.ints.emplace_back("tag", tag);
  return d;
}

// Writes then reads `mesh` in both formats, ASCII and binary, and checks everything came back
// bit for bit.
template <typename Mesh, typename Cells, typename ToMesh>
void check_round_trip(const Mesh& mesh, const Cells& cells, int type,
                      const std::vector<double>& scaled_jacobian, ToMesh&& to_mesh) {
  TempDir dir;
  for (const char* ext : {".vtu", ".vtk"})
    for (const VtkEncoding encoding : {VtkEncoding::kAscii, VtkEncoding::kBinary}) {
      const bool binary = encoding == VtkEncoding::kBinary;
      CAPTURE(ext);
      CAPTURE(binary);
      const fs::path file = dir.path / (std::string(binary ? "binary" : "ascii") + ext);
      const VtkCellData extra = extra_arrays(cells.size());
      if (std::string(ext) == ".vtu")
        write_vtu(file, mesh, extra, encoding);
      else
        write_vtk(file, mesh, extra, encoding);
      if (std::string(ext) == ".vtk")  // the header says which
        CHECK(slurp(file).find(binary ? "\nBINARY\n" : "\nASCII\n") != std::string::npos);
      const VtkGrid g = read_vtk_file(file);
      CHECK(g.points == mesh.points);  // shortest round-trip decimal: exact
      REQUIRE(g.cells.size() == cells.size());
      for (std::size_t c = 0; c < cells.size(); ++c) {
        CHECK(g.cell_types[c] == type);
        CHECK(std::equal(g.cells[c].begin(), g.cells[c].end(), cells[c].begin(), cells[c].end()));
      }
      REQUIRE(g.cell_data.find_double("scaled_jacobian"));
      CHECK(*g.cell_data.find_double("scaled_jacobian") == scaled_jacobian);
      REQUIRE(g.cell_data.find_double("one_third"));
      CHECK(*g.cell_data.find_double("one_third") == extra.doubles[0].second);
      REQUIRE(g.cell_data.find_int("tag"));
      CHECK(*g.cell_data.find_int("tag") == extra.ints[0].second);
      const Mesh back = to_mesh(g);
      CHECK(back.points == mesh.points);
      if constexpr (requires { mesh.block; }) CHECK(back.block == mesh.block);
    }
}

}  // namespace

TEST_CASE("io_vtk: hex, tet and quad meshes round-trip exactly through .vtu and .vtk") {
  SUBCASE("hexes") {
    const HexMesh m = test_hexes();
    std::vector<double> sj;
    for (Index h = 0; h < 4; ++h) sj.push_back(hex_scaled_jacobian(hex_corners(m, h)));
    check_round_trip(m, m.hexes, kVtkHexahedron, sj, to_hex_mesh);
    const HexMesh back = [&] {
      TempDir dir;
      write_vtu(dir.path / "m.vtu", m);
      return to_hex_mesh(read_vtu(dir.path / "m.vtu"));
    }();
    CHECK(back.hexes == m.hexes);
  }
  SUBCASE("tets") {
    const TetMesh m = test_tets();
    // Hand values: tet 0 is the corner of the unit cube: 6V = 1, edge products at corner 0 =
    // 1, at the others sqrt(2) sqrt(2) 1 = 2 -> sqrt(2) / 2. Tet 1 = (1,0,0) (1,1,1) (0,1,0)
    // (0,0,1) is regular-ish? 6V = det((0,1,1), (-1,1,0), (-1,0,1)) = 2; all six edges are
    // sqrt(2) except |p1 - p0| = sqrt(2) too -> regular, scaled Jacobian 1.
    CHECK(tet_scaled_jacobian(m.points[0], m.points[1], m.points[2], m.points[3]) ==
          doctest::Approx(std::sqrt(2.0) / 2));
    CHECK(tet_scaled_jacobian(m.points[1], m.points[4], m.points[2], m.points[3]) ==
          doctest::Approx(1.0));
    CHECK(tet_scaled_jacobian(m.points[0], m.points[2], m.points[1], m.points[3]) ==
          doctest::Approx(-std::sqrt(2.0) / 2));  // inverted
    std::vector<double> sj;
    for (const auto& t : m.tets) {
      sj.push_back(
          tet_scaled_jacobian(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]));
    }
    check_round_trip(m, m.tets, kVtkTetra, sj, to_tet_mesh);
  }
  SUBCASE("quads in 3D space") {
    const QuadMesh m = test_quads();
    std::vector<double> sj;
    for (Index q = 0; q < 2; ++q) sj.push_back(quad_scaled_jacobian(quad_corners(m, q)));
    check_round_trip(m, m.quads, kVtkQuad, sj, to_quad_mesh);
  }
}

TEST_CASE("io_vtk: a model's scaled Jacobians handed in are written as computed ones are") {
  // conform hands the writers the scaled Jacobians it has measured (WriteOptions); the files
  // must be the very bytes the writers make computing them, in both encodings; a list of the
  // wrong length is not used.
  const HexMesh hexes = test_hexes();
  Model m;
  m.points = hexes.points;
  m.hexes = hexes.hexes;
  std::vector<double> sj;
  for (Index h = 0; h < index_cast(m.hexes.size()); ++h)
    sj.push_back(hex_scaled_jacobian(hex_corners(hexes, h)));
  const std::vector<double> wrong(sj.size() + 1, 0.5);
  TempDir dir;
  for (const VtkEncoding e : {VtkEncoding::kAscii, VtkEncoding::kBinary}) {
    write_vtu(dir.path / "a.vtu", m, {}, e);
    write_vtu(dir.path / "b.vtu", m, {}, e, sj);
    write_vtu(dir.path / "c.vtu", m, {}, e, wrong);
    CHECK(slurp(dir.path / "a.vtu") == slurp(dir.path / "b.vtu"));
    CHECK(slurp(dir.path / "a.vtu") == slurp(dir.path / "c.vtu"));
    write_vtk(dir.path / "a.vtk", m, {}, e);
    write_vtk(dir.path / "b.vtk", m, {}, e, sj);
    CHECK(slurp(dir.path / "a.vtk") == slurp(dir.path / "b.vtk"));
  }
  // Other values are written as given: the writer does not measure again.
  std::vector<double> halves(sj.size(), 0.5);
  write_vtu(dir.path / "h.vtu", m, {}, VtkEncoding::kAscii, halves);
  const VtkGrid g = read_vtu(dir.path / "h.vtu");
  const auto* written = g.cell_data.find_double("scaled_jacobian");
  REQUIRE(written);
  CHECK(*written == halves);
}

TEST_CASE("io_vtk: a grid of another cell type is refused by the typed conversion") {
  TempDir dir;
  write_vtk(dir.path / "h.vtk", test_hexes());
  const VtkGrid g = read_vtk(dir.path / "h.vtk");
  CHECK_THROWS_WITH_AS(
      to_tet_mesh(g),
      doctest::Contains("h.vtk: cell 0 is VTK type 12 (hexahedron), expected 10 (tetra)"),
      geode::InvalidInput);
  CHECK_THROWS_AS(read_vtk_file(dir.path / "h.obj"), geode::InvalidInput);
  // Extensions in any case, as everywhere else (io/file_format.hpp).
  write_vtu(dir.path / "H.VTU", test_hexes());
  write_vtk(dir.path / "H.VTK", test_hexes());
  CHECK(read_vtk_file(dir.path / "H.VTU").cell_types.size() == test_hexes().hexes.size());
  CHECK(read_vtk_file(dir.path / "H.VTK").cell_types.size() == test_hexes().hexes.size());
}

namespace {

// Replaces the `n`-th (0-based) line for which `select(line_text)` holds by `edit(line_text)`;
// returns the new text and the 1-based number of the edited line.
std::pair<std::string, int> edit_line(const std::string& text,
                                      const std::function<bool(const std::string&)>& select,
                                      const std::function<std::string(const std::string&)>& edit,
                                      int n = 0) {
  std::istringstream in(text);
  std::string line, out;
  int number = 0, edited = 0, seen = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!edited && select(line) && seen++ == n) {
      line = edit(line);
      edited = number;
    }
    out += line + "\n";
  }
  REQUIRE(edited > 0);
  return {out, edited};
}

// Line number (1-based) of the first line after the one containing `marker`.
std::function<bool(const std::string&)> after(const std::string& marker) {
  auto armed = std::make_shared<int>(0);
  return [marker, armed](const std::string& line) {
    if (*armed == 1) {
      *armed = 2;
      return true;
    }
    if (*armed == 0 && line.find(marker) != std::string::npos) *armed = 1;
    return false;
  };
}

std::string replace_first_token(const std::string& line, const std::string& by) {
  const auto b = line.find_first_not_of(' ');
  const auto e = line.find(' ', b);
  return line.substr(0, b) + by + (e == std::string::npos ? "" : line.substr(e));
}

}  // namespace

TEST_CASE("io_vtk: bad input names the file, the line and the reason") {
  TempDir dir;
  // One hex mesh, both formats; each case breaks one thing in the text.
  const HexMesh m = test_hexes();
  write_vtu(dir.path / "good.vtu", m);
  write_vtk(dir.path / "good.vtk", m);
  const std::string vtu = slurp(dir.path / "good.vtu");
  const std::string vtk = slurp(dir.path / "good.vtk");
  REQUIRE_NOTHROW(read_vtu(dir.path / "good.vtu"));
  REQUIRE_NOTHROW(read_vtk(dir.path / "good.vtk"));

  struct Case {
    const char* name;
    std::string text;
    int line;  // 0: any line
    std::string reason;
  };
  std::vector<Case> cases;
  auto add = [&](const char* name, std::pair<std::string, int> edited, const std::string& reason) {
    cases.push_back({name, edited.first, edited.second, reason});
  };
  auto nan_point = [](const std::string& l) { return replace_first_token(l, "nan"); };
  // .vtu: the 4th point is on the 4th line after the Points DataArray tag.
  add("vtu NaN coordinate", edit_line(vtu, after("NumberOfComponents=\"3\""), nan_point),
      "point 0: non-finite coordinate");
  add("vtu unknown cell type",
      edit_line(vtu, after("Name=\"types\""),
                [](const std::string& l) { return replace_first_token(l, "42"); }),
      "cell 0: unknown or unsupported cell type 42");
  add("vtu node out of range",
      edit_line(vtu, after("Name=\"connectivity\""),
                [](const std::string& l) { return replace_first_token(l, "999"); }),
      "cell 0: node 999 out of range [0, 18)");
  cases.push_back({"vtu truncated", vtu.substr(0, vtu.size() / 2), 0, "unexpected end of file"});
  cases.push_back({"vtu truncated inside a tag", vtu.substr(0, vtu.find("Name=\"offsets\"") + 8), 0,
                   "(truncated file?)"});
  add("vtu binary DataArray holding text",
      edit_line(
          vtu, [](const std::string& l) { return l.find("Name=\"offsets\"") != std::string::npos; },
          [](const std::string& l) { return l.substr(0, l.find("ascii")) + "binary\">"; }),
      "base64: the text ends inside a quantum");
  // Legacy: POINTS line, then one point per line.
  add("vtk NaN coordinate", edit_line(vtk, after("POINTS"), nan_point),
      "point 0: non-finite coordinate");
  add("vtk unknown cell type",
      edit_line(vtk, after("CELL_TYPES"), [](const std::string&) { return std::string("42"); }),
      "cell 0: unknown or unsupported cell type 42 (supported: 1 vertex, 3 line, 5 triangle, 9 "
      "quad, 10 tetra, 12 hexahedron, 13 wedge, 14 pyramid)");
  // A mesher's second-order output: named as such (meshio writes Gmsh's 27-node hexes as 29).
  add("vtk higher-order cell type",
      edit_line(vtk, after("CELL_TYPES"), [](const std::string&) { return std::string("29"); }),
      "cell 0: cell type 29 is a higher-order cell (quadratic, cubic or Lagrange); only linear "
      "cells are read (supported: 1 vertex");
  add("vtk node out of range",
      edit_line(vtk, after("CELLS"),
                [](const std::string&) { return std::string("8 0 1 4 3 9 10 13 -1"); }),
      "cell 0: node -1 out of range [0, 18)");
  {
    // Reported at the cell's connectivity line (the line after "CELLS").
    const auto edited =
        edit_line(vtk, after("CELL_TYPES"), [](const std::string&) { return std::string("10"); });
    const auto cells_line = edit_line(vtk, after("CELLS"), [](const std::string& l) { return l; });
    cases.push_back({"vtk wrong node count", edited.first, cells_line.second,
                     "cell 0: type 10 (tetra) needs 4 nodes, has 8"});
  }
  cases.push_back({"vtk truncated", vtk.substr(0, vtk.find("CELL_TYPES") + 14), 0,
                   "unexpected end of file while reading the type of cell"});
  cases.push_back({"vtk truncated header", "# vtk DataFile Version 4.2\ngeode\n", 3,
                   "unexpected end of file in the header"});

  for (const auto& c : cases) {
    const std::string name = c.name;
    CAPTURE(name);
    const fs::path file = dir.path / (name.substr(0, 3) == "vtu" ? "bad.vtu" : "bad.vtk");
    spit(file, c.text);
    std::string message;
    try {
      read_vtk_file(file);
    } catch (const geode::InvalidInput& e) {
      message = e.what();
    }
    CAPTURE(message);
    REQUIRE(!message.empty());
    CHECK(message.rfind(file.string() + ":", 0) == 0);  // names the file first
    if (c.line > 0) CHECK(message.find(":" + std::to_string(c.line) + ": ") != std::string::npos);
    CHECK(message.find(c.reason) != std::string::npos);
  }
}

TEST_CASE("io_vtk: writes are atomic and check their input") {
  TempDir dir;
  const fs::path file = dir.path / "out.vtu";
  const HexMesh m = test_hexes();
  write_vtu(file, m);
  const std::string before = slurp(file);
  REQUIRE(dir.entries() == 1);

  SUBCASE("a writer that fails midway leaves the old file and no temporary") {
    CHECK_THROWS_AS(write_file_atomically(file,
                                          [](std::ostream& os) {
                                            os << "half a file";
                                            throw std::runtime_error("disk on fire");
                                          }),
                    std::runtime_error);
    CHECK(slurp(file) == before);
    CHECK(dir.entries() == 1);
  }
  SUBCASE("bad arrays are refused before anything is written") {
    VtkCellData bad;
    bad.doubles.emplace_back("short", std::vector<double>{1.0});
    CHECK_THROWS_WITH_AS(write_vtu(file, m, bad),
                         doctest::Contains("cell array 'short' has 1 values for 4 cells"),
                         geode::InvalidInput);
    VtkCellData spaced;
    spaced.ints.emplace_back("two words", std::vector<int>(4, 0));
    CHECK_THROWS_AS(write_vtk(file, m, spaced), geode::InvalidInput);
    VtkCellData twice;
    twice.ints.emplace_back("block", std::vector<int>(4, 0));  // "block" is written already
    CHECK_THROWS_WITH_AS(write_vtk(file, m, twice), doctest::Contains("'block' given twice"),
                         geode::InvalidInput);
    CHECK(slurp(file) == before);
    CHECK(dir.entries() == 1);
  }
  SUBCASE("bad meshes are refused") {
    HexMesh nan = m;
    nan.points[2].x() = std::nan("");
    CHECK_THROWS_WITH_AS(write_vtu(file, nan), doctest::Contains("node 3 has a non-finite"),
                         geode::InvalidInput);
    HexMesh out = m;
    out.hexes[3][5] = 77;
    CHECK_THROWS_WITH_AS(write_vtk(file, out),
                         doctest::Contains("hexahedron 4: node 78 out of range"),
                         geode::InvalidInput);
    CHECK(slurp(file) == before);
  }
  SUBCASE("an unwritable place is an error naming it") {
    const fs::path nowhere = dir.path / "no" / "such" / "dir" / "x.vtu";
    CHECK_THROWS_WITH_AS(write_vtu(nowhere, m), doctest::Contains(nowhere.string().c_str()),
                         geode::InvalidInput);
  }
}

TEST_CASE("io_vtk: VTK's own readers (ParaView's) open what we write") {
  // python3-vtk9 is a required package (scripts/common.sh): without it this check would prove
  // nothing, so it fails instead of skipping.
  REQUIRE_MESSAGE(std::system("/usr/bin/python3 -c 'import vtk' >/dev/null 2>&1") == 0,
                  "/usr/bin/python3 cannot import vtk (apt-get install python3-vtk9)");
  TempDir dir;
  const std::string script = std::string(GEODE_SOURCE_DIR) + "/tests/io/vtk_reader_check.py";
  auto check = [&](const fs::path& file, std::size_t cells) {
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + file.string() + "' " +
                            std::to_string(cells) + " --compare-scaled-jacobian";
    CAPTURE(cmd);
    CHECK(std::system(cmd.c_str()) == 0);
  };
  // A diced distorted block: many distinct scaled Jacobians to compare with vtkMeshQuality.
  const HexMesh hexes = dice(test_hexes()).mesh;
  write_vtu(dir.path / "hex.vtu", hexes);
  write_vtk(dir.path / "hex.vtk", hexes);
  write_vtk(dir.path / "hex-binary.vtk", hexes, {}, VtkEncoding::kBinary);
  check(dir.path / "hex.vtu", hexes.hexes.size());
  check(dir.path / "hex.vtk", hexes.hexes.size());
  check(dir.path / "hex-binary.vtk", hexes.hexes.size());
  write_vtu(dir.path / "tet.vtu", test_tets());
  check(dir.path / "tet.vtu", 2);
  write_vtu(dir.path / "quad.vtu", test_quads());
  write_vtk(dir.path / "quad.vtk", test_quads());
  write_vtk(dir.path / "quad-binary.vtk", test_quads(), {}, VtkEncoding::kBinary);
  check(dir.path / "quad.vtu", 2);
  check(dir.path / "quad.vtk", 2);
  check(dir.path / "quad-binary.vtk", 2);
}

TEST_CASE("io_vtk: meshio's gmsh:physical 0 (no group) numbered above the physical tags") {
  // A hex in physical volume 2 (entity 1) and a tet in none (entity 2), as meshio converts a
  // Gmsh file: the tet's 0 was refused as a block id; it is block 2 + its entity 2, as the .msh
  // reader numbers it, not the hex's block 2.
  const std::string vtu =
      "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>\n"
      "<Piece NumberOfPoints=\"12\" NumberOfCells=\"2\">\n"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1 3 0 0 4 0 0 3 1 0 3 0 1\n"
      "</DataArray></Points>\n<Cells>\n"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7 8 9 10 "
      "11</DataArray>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">8 12</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">12 10</DataArray>\n</Cells>\n"
      "<CellData>\n"
      "<DataArray type=\"Int32\" Name=\"gmsh:physical\" format=\"ascii\">2 0</DataArray>\n"
      "<DataArray type=\"Int32\" Name=\"gmsh:geometrical\" format=\"ascii\">1 2</DataArray>\n"
      "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  const TempDir dir;
  const fs::path file = dir.path / "meshio.vtu";
  spit(file, vtu);
  const Model m = read_model(file);
  CHECK(m.hex_block == std::vector<int>{2});
  CHECK(m.tet_block == std::vector<int>{4});
}
