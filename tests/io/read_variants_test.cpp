// Readers against files other programs write: VTK's own writer (every .vtu encoding: ascii,
// binary base64, appended raw and base64, zlib-compressed, UInt64 headers; legacy .vtk),
// meshio (.exo, .msh 2.2 ASCII and binary, .vtu, .vtk) and Gmsh's own writer (.msh 2.2 and 4.1,
// ASCII and binary). Each must read back the mesh that was written, point for point.
#include <doctest/doctest.h>

#include <gmsh.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <geode/demo/gmsh_session.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

// A 3 x 2 x 2 hex grid with moved interior nodes (coordinates that are not round numbers) and
// two blocks.
HexMesh sample_hexes() {
  HexMesh m = test::structured_hex_grid(3, 2, 2);
  for (std::size_t n = 0; n < m.points.size(); ++n)
    m.points[n] += 0.01 * Point(std::sin(1.0 * n), std::cos(2.0 * n), 0.3);
  m.block.assign(m.hexes.size(), 1);
  for (std::size_t h = 0; h < m.hexes.size() / 2; ++h) m.block[h] = 7;
  return m;
}

void run_script(const std::string& kind, const fs::path& source, const fs::path& dir) {
  const std::string script = std::string(GEODE_SOURCE_DIR) + "/tests/io/write_variants.py";
  const std::string cmd = "/usr/bin/python3 '" + script + "' " + kind + " '" + source.string() +
                          "' '" + dir.string() + "'";
  const int status = std::system(cmd.c_str());
  // The Python packages are required (scripts/common.sh): a missing one fails the test.
  REQUIRE_MESSAGE(status == 0, cmd);
}

// sample_hexes() written by us as ASCII .vtu, then by write_variants.py `kind` into `dir`.
HexMesh write_variants(const std::string& kind, const fs::path& dir) {
  const HexMesh m = sample_hexes();
  write_vtu(dir / "source.vtu", m);
  run_script(kind, dir / "source.vtu", dir);
  return m;
}

void check_points(const std::vector<Point>& a, const std::vector<Point>& b, double tol) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) CHECK((a[i] - b[i]).norm() <= tol);
}

}  // namespace

TEST_CASE("VTK's own writer: every .vtu encoding and legacy .vtk read back the same mesh") {
  test::TempDir dir;
  const HexMesh m = write_variants("vtk", dir.path);
  for (const std::string name :
       {"ascii.vtu", "binary.vtu", "binary-zlib.vtu", "appended-raw.vtu", "appended-base64.vtu",
        "appended-raw-zlib.vtu", "binary-zlib-uint64.vtu", "appended-base64-zlib-uint64.vtu",
        "legacy-ascii.vtk", "legacy-binary.vtk"}) {
    CAPTURE(name);
    const VtkGrid g = read_vtk_file(dir.path / name);
    const HexMesh back = to_hex_mesh(g);
    // Float64 throughout: exact, but for VTK's legacy text writer, which prints fewer digits.
    check_points(back.points, m.points, name.ends_with(".vtk") ? 1e-10 : 0.0);
    CHECK(back.hexes == m.hexes);
    CHECK(back.block == m.block);
    REQUIRE(g.cell_data.find_double("scaled_jacobian") != nullptr);
    // The same file as a model: blocks from the "block" array, VTK's 0-based ids.
    const Model model = read_model(dir.path / name);
    CHECK(model.hexes == m.hexes);
    CHECK(model.hex_block == m.block);
    CHECK(describe_node(model, 0).rfind("node 0 (", 0) == 0);
  }
}

TEST_CASE("meshio's files: .exo, .msh 2.2 ASCII and binary, .vtu, .vtk read as models") {
  test::TempDir dir;
  const HexMesh m = write_variants("meshio", dir.path);
  for (const std::string name : {"meshio.exo", "meshio-22-ascii.msh", "meshio-22-binary.msh",
                                 "meshio.vtu", "meshio-ascii.vtu", "meshio.vtk"}) {
    CAPTURE(name);
    const Model model = read_model(dir.path / name);
    // meshio's text formats print fewer digits than a double holds.
    check_points(model.points, m.points, 1e-10);
    CHECK(model.hexes == m.hexes);
    CHECK(model.tets.empty());
  }
}

TEST_CASE("meshio's .vtu and .vtk with materials as mat_id: the blocks") {
  test::TempDir dir;
  const HexMesh m = write_variants("meshio", dir.path);
  for (const std::string name : {"meshio-matid.vtu", "meshio-matid.vtk"}) {
    CAPTURE(name);
    const Model model = read_model(dir.path / name);
    REQUIRE(model.hexes == m.hexes);
    for (std::size_t h = 0; h < m.hexes.size(); ++h)
      CHECK(block_of(model, {ElementKind::kHex, index_cast(h)}) == m.block[h]);
  }
}

TEST_CASE("meshio's .vtu with materials under another name: not read, said") {
  // The blocks then follow the cell kinds; the array was left out without a word (found by a
  // fault hunt).
  test::TempDir dir;
  write_variants("meshio", dir.path);
  ReadWarnings warnings;
  const Model model = read_model(dir.path / "meshio-material.vtu");
  CHECK(!model.hexes.empty());
  REQUIRE(warnings.messages().size() == 1);
  CHECK(warnings.messages().front().find(
            "meshio-material.vtu: integer cell array 'material' not read as blocks (only one "
            "named block, gmsh:physical, CellEntityIds, mat_id is)") != std::string::npos);
}

TEST_CASE("meshio's .exo with node sets numbered from 0: the sets numbered by position") {
  // The old reader refused the file ("node set 0 'ns_bottom': id is not positive") although it
  // renumbers meshio's block ids from 0 the same way.
  test::TempDir dir;
  const HexMesh m = write_variants("meshio", dir.path);
  ReadWarnings warnings;
  const Model model = read_model(dir.path / "meshio-sets.exo");
  // Said, since options naming blocks (--join-blocks) and the output use the new ids.
  CHECK(std::any_of(warnings.messages().begin(), warnings.messages().end(), [](const auto& w) {
    return w.find(
               "meshio-sets.exo: node set ids 0, 1 are not all positive: read as 1, 2, in the "
               "file's order") != std::string::npos;
  }));
  REQUIRE(model.node_sets.size() == 2);
  CHECK(model.node_sets[0].id == 1);
  CHECK(model.node_sets[0].name == "ns_bottom");
  CHECK(model.node_sets[1].id == 2);
  CHECK(model.node_sets[1].name == "ns_top");
  double low = m.points.front().z();
  for (const Point& p : m.points) low = std::min(low, p.z());
  std::size_t bottom = 0;
  for (const Point& p : m.points) bottom += p.z() < low + 1e-9;
  CHECK(bottom >= 4);
  CHECK(model.node_sets[0].nodes.size() == bottom);
  for (Index v : model.node_sets[0].nodes)
    CHECK(model.points[index_cast<std::size_t>(v)].z() < low + 1e-9);
}

TEST_CASE("meshio's .exo of a Gmsh mesh: its blocks of vertices and faces left out, warned") {
  // meshio writes the physical points and surfaces of a mesh it read from Gmsh as SPHERE, QUAD4
  // and TRI3 blocks; the reader refused the file at the first ("element type 'SPHERE' with 1
  // nodes is not supported").
  test::TempDir dir;
  const HexMesh m = write_variants("meshio", dir.path);
  ReadWarnings warnings;
  const Model model = read_model(dir.path / "meshio-surfaces.exo");
  CHECK(model.hexes == m.hexes);
  REQUIRE(warnings.messages().size() == 2);
  CHECK(warnings.messages()[0].find("element block ids 0, 1, ") != std::string::npos);
  CHECK(warnings.messages()[1].find("element blocks of points, lines or faces, not volume cells, "
                                    "are not read (block id, type, elements): 0 (SPHERE, 1), 1 "
                                    "(QUAD4, ") != std::string::npos);
  // The hexes keep their file numbers after the blocks left out: 1 vertex and the quads first.
  CHECK(element_id(model, {ElementKind::kHex, 0}) > 1);
}

TEST_CASE("Gmsh's own writer: .msh 2.2 and 4.1, ASCII and binary, read back the same model") {
  test::TempDir dir;
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.points[4] += Point(0.01, -0.02, 0.03);
  m.block_names[1] = "steel";
  m.side_sets.push_back(
      {21, "outside", {{{ElementKind::kHex, 0}, 4}, {{ElementKind::kTet, 0}, 3}}});
  const fs::path ours = dir.path / "ours.msh";
  write_gmsh(m, ours);
  for (const double version : {2.2, 4.1})
    for (const int binary : {0, 1}) {
      CAPTURE(version);
      CAPTURE(binary);
      const fs::path file =
          dir.path / ("gmsh-" + std::to_string(version) + "-" + std::to_string(binary) + ".msh");
      {
        demo::GmshSession session;
        gmsh::open(ours.string());  // our own file, written above: never a user's
        gmsh::option::setNumber("Mesh.MshFileVersion", version);
        gmsh::option::setNumber("Mesh.Binary", binary);
        // Version 2.2 with SaveAll writes every element with physical tag 0; without it, every
        // element of a physical group (all of ours are) with the group's tag.
        gmsh::option::setNumber("Mesh.SaveAll", version > 4 ? 1 : 0);
        gmsh::write(file.string());
      }
      const Model back = read_gmsh(file);
      check_points(back.points, m.points, 0.0);
      CHECK(back.hexes == m.hexes);
      CHECK(back.tets == m.tets);
      CHECK(back.hex_block == std::vector<int>(m.hexes.size(), 1));
      CHECK(back.block_names == m.block_names);
      REQUIRE(back.side_sets.size() == 1);
      CHECK(back.side_sets[0].id == 21);
      CHECK(back.side_sets[0].sides == m.side_sets[0].sides);
      // Tags are the file ids: our writer numbers from 1 and Gmsh keeps that in 4.1 (in 2.2 it
      // renumbers elements its own way).
      CHECK(back.node_ids.front() == 1);
      if (version > 4) CHECK(back.hex_ids.front() == 1);
      std::vector<std::int64_t> ids = back.hex_ids;
      ids.insert(ids.end(), back.tet_ids.begin(), back.tet_ids.end());
      std::sort(ids.begin(), ids.end());
      CHECK(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
      CHECK(ids.front() >= 1);
    }
}
