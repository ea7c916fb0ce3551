// Gmsh .msh input/output: node order checked on a hand-written file, round trips in ASCII and
// binary, and bad input rejected with messages that name the file, the element and the reason.
#include <doctest/doctest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <geode/io/gmsh.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

// One directory for the whole test program, removed at exit.
const fs::path& scratch_dir() {
  static const geode::test::TempDir dir;
  return dir.path;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// One unit hex [0,1]^3 and one tet on its x = 1 face, in Gmsh's own corner order (reference
// manual, "Node ordering": hexahedron v0..v3 the bottom face counter-clockwise seen from
// above, v4..v7 above them; tetrahedron v0 v1 v2 v3 with v3 above the counter-clockwise
// triangle v0 v1 v2). Node tags are scrambled so that tag order differs from file order.
// Tag -> point: 1 (1,0,0) 2 (0,0,0) 3 (0,1,0) 4 (1,1,0) 5 (1,0,1) 6 (0,0,1) 7 (0,1,1)
// 8 (1,1,1) 9 (2,0,0).
std::string hand_written_msh(const std::string& volume_elements) {
  return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
         "$PhysicalNames\n3\n0 5 \"corner\"\n2 3 \"top\"\n3 4 \"solid\"\n$EndPhysicalNames\n"
         "$Entities\n1 0 1 1\n"
         "1 0 0 1 1 5\n"
         "1 0 0 1 1 1 1 1 3 0\n"
         "1 0 0 0 2 1 1 1 4 0\n"
         "$EndEntities\n"
         "$Nodes\n1 9 1 9\n3 1 0 9\n2\n1\n4\n3\n6\n5\n8\n7\n9\n"
         "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n2 0 0\n$EndNodes\n"
         "$Elements\n4 4 1 4\n"
         "0 1 15 1\n1 6\n"
         "2 1 3 1\n2 6 5 8 7\n" +
         volume_elements + "$EndElements\n";
}

const std::string kHexAndTet = "3 1 5 1\n3 2 1 4 3 6 5 8 7\n3 1 4 1\n4 1 9 4 5\n";

void check_same(const Model& a, const Model& b) {
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i)
    CHECK((a.points[i] - b.points[i]).norm() <= 1e-14 * (1.0 + a.points[i].norm()));
  CHECK(a.hexes == b.hexes);
  CHECK(a.tets == b.tets);
  CHECK(a.hex_block == b.hex_block);
  CHECK(a.tet_block == b.tet_block);
  CHECK(a.block_names == b.block_names);
  REQUIRE(a.node_sets.size() == b.node_sets.size());
  for (std::size_t s = 0; s < a.node_sets.size(); ++s) {
    CHECK(a.node_sets[s].id == b.node_sets[s].id);
    CHECK(a.node_sets[s].name == b.node_sets[s].name);
    CHECK(a.node_sets[s].nodes == b.node_sets[s].nodes);
  }
  REQUIRE(a.side_sets.size() == b.side_sets.size());
  for (std::size_t s = 0; s < a.side_sets.size(); ++s) {
    CHECK(a.side_sets[s].id == b.side_sets[s].id);
    CHECK(a.side_sets[s].name == b.side_sets[s].name);
    CHECK(a.side_sets[s].sides == b.side_sets[s].sides);
  }
}

// 2 x 2 x 1 cells: x < 1 hexes (block 1 "steel"), x >= 1 Kuhn tets (block 2); a node set on
// the z = 0 face and a side set with hex and tet faces on the outside, both sorted as the
// Gmsh reader returns them.
Model gmsh_model() {
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.points[4] += Point(0.01, -0.02, 0.03);  // coordinates that are not all round numbers
  m.block_names[1] = "steel";
  NodeSet bottom{11, "bottom", {}};
  for (Index v = 0; v < 9; ++v) bottom.nodes.push_back(v);
  m.node_sets.push_back(bottom);
  SideSet outside{21, "outside", {}};
  outside.sides.push_back({{ElementKind::kHex, 0}, 4});  // z = 0 face of hex 0
  outside.sides.push_back({{ElementKind::kHex, 1}, 5});  // z = 1 face of hex 1
  outside.sides.push_back({{ElementKind::kTet, 0}, 3});
  m.side_sets.push_back(outside);
  return m;
}

}  // namespace

TEST_CASE("read_gmsh converts Gmsh's hex and tet corner order to VTK order") {
  const fs::path file = scratch_dir() / "hand.msh";
  write_text(file, hand_written_msh(kHexAndTet));
  const Model m = read_gmsh(file);
  REQUIRE(m.points.size() == 9);
  // Nodes are numbered by ascending tag: index = tag - 1.
  CHECK(m.points[0] == Point(1, 0, 0));
  CHECK(m.points[8] == Point(2, 0, 0));
  REQUIRE(m.hexes.size() == 1);
  REQUIRE(m.tets.size() == 1);
  // VTK corner c of the unit hex sits at its unit-cube coordinates.
  for (int c = 0; c < 8; ++c) {
    const auto& rst = topology::kHexCornerCoords[index_cast<std::size_t>(c)];
    CHECK(m.points[index_cast<std::size_t>(m.hexes[0][index_cast<std::size_t>(c)])] ==
          Point(rst[0], rst[1], rst[2]));
  }
  const auto& t = m.tets[0];
  // Translated reference tet: volume +1/6 in the VTK convention.
  CHECK(tet_volume(m.points[index_cast<std::size_t>(t[0])], m.points[index_cast<std::size_t>(t[1])],
                   m.points[index_cast<std::size_t>(t[2])],
                   m.points[index_cast<std::size_t>(t[3])]) == doctest::Approx(1.0 / 6.0));
  CHECK(m.hex_block == std::vector<int>{4});
  CHECK(m.tet_block == std::vector<int>{4});
  CHECK(m.block_names.at(4) == "solid");
  REQUIRE(m.side_sets.size() == 1);
  CHECK(m.side_sets[0].id == 3);
  CHECK(m.side_sets[0].name == "top");
  REQUIRE(m.side_sets[0].sides.size() == 1);
  CHECK(m.side_sets[0].sides[0] == Side{{ElementKind::kHex, 0}, 5});  // top face z = 1
  REQUIRE(m.node_sets.size() == 1);
  CHECK(m.node_sets[0].id == 5);
  CHECK(m.node_sets[0].name == "corner");
  CHECK(m.node_sets[0].nodes == std::vector<Index>{5});  // tag 6 = (0,0,1)
}

TEST_CASE("read_gmsh: sparse node tags, and one entity's elements in two runs") {
  // Tag 3000000000 makes the tags too sparse for a table (the reader's hash map); entity 1's
  // tets come before and after entity 2's, so each run's block is found again.
  const fs::path file = scratch_dir() / "sparse_tags.msh";
  write_text(file,
             "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
             "$PhysicalNames\n2\n3 1 \"a\"\n3 2 \"b\"\n$EndPhysicalNames\n"
             "$Entities\n0 0 0 2\n1 0 0 0 1 1 1 1 1 0\n2 0 0 0 1 1 1 1 2 0\n$EndEntities\n"
             "$Nodes\n1 6 4 3000000000\n3 1 0 6\n7\n12\n3000000000\n5\n9\n4\n"
             "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n1 1 0\n$EndNodes\n"
             "$Elements\n3 3 1 3\n"
             "3 1 4 1\n1 7 12 3000000000 5\n"
             "3 2 4 1\n2 12 9 3000000000 5\n"
             "3 1 4 1\n3 12 4 3000000000 9\n"
             "$EndElements\n");
  const Model m = read_gmsh(file);
  CHECK(m.node_ids == std::vector<std::int64_t>{4, 5, 7, 9, 12, 3000000000});
  CHECK(m.points[5] == Point(0, 1, 0));
  REQUIRE(m.tets.size() == 3);
  CHECK(m.tet_block == std::vector<int>{1, 1, 2});  // by block, file order within one
  CHECK(m.tet_ids == std::vector<std::int64_t>{1, 3, 2});
  CHECK(m.block_names.at(1) == "a");
  CHECK(m.block_names.at(2) == "b");
  // Tet 2 (file id 3) on tags 12 4 3000000000 9: indices 4 0 5 3 as read (VTK order is Gmsh's
  // for tets).
  CHECK(m.tets[1] == std::array<Index, 4>{4, 0, 5, 3});
}

TEST_CASE("write_gmsh then read_gmsh gives the same model (ASCII and binary)") {
  const Model m = gmsh_model();
  REQUIRE(m.hexes.size() == 2);
  REQUIRE(m.tets.size() == 12);
  for (GmshFormat format : {GmshFormat::kAscii, GmshFormat::kBinary}) {
    CAPTURE(static_cast<int>(format));
    const fs::path file =
        scratch_dir() / (format == GmshFormat::kAscii ? "rt_ascii.msh" : "rt_bin.msh");
    write_gmsh(m, file, format);
    // Gmsh writes "4.1 <file-type>": 0 for ASCII, 1 for binary.
    std::ifstream in(file, std::ios::binary);
    std::string line;
    std::getline(in, line);
    std::getline(in, line);
    CHECK(line.rfind(format == GmshFormat::kAscii ? "4.1 0" : "4.1 1", 0) == 0);
    check_same(m, read_gmsh(file));
  }
}

TEST_CASE("read_gmsh rejects bad input naming the file, element and reason") {
  const fs::path dir = scratch_dir();
  SUBCASE("missing file") {
    const fs::path file = dir / "does-not-exist.msh";
    CHECK_THROWS_WITH_AS(read_gmsh(file), doctest::Contains(file.string().c_str()), InvalidInput);
  }
  SUBCASE("truncated file") {
    const std::string full = hand_written_msh(kHexAndTet);
    const fs::path file = dir / "truncated.msh";
    write_text(file, full.substr(0, full.find("1 1 0\n0 1 0")));  // cut inside $Nodes
    CHECK_THROWS_WITH_AS(read_gmsh(file), doctest::Contains(file.string().c_str()), InvalidInput);
  }
  SUBCASE("$ParametricNodes (Gmsh 2.2, Mesh.SaveParametric=1) and $Nodes before $MeshFormat") {
    const fs::path file = dir / "parametric.msh";
    write_text(file,
               "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$ParametricNodes\n1\n1 0 0 0 0 1\n"
               "$EndParametricNodes\n");
    CHECK_THROWS_WITH_AS(read_gmsh(file),
                         doctest::Contains("line 4: $ParametricNodes (Gmsh 2.2 saved with "
                                           "Mesh.SaveParametric=1) is not read"),
                         InvalidInput);
    write_text(file, "$Comments\n$EndComments\n$Nodes\n1\n1 0 0 0\n$EndNodes\n");
    CHECK_THROWS_WITH_AS(read_gmsh(file), doctest::Contains("$Nodes before $MeshFormat"),
                         InvalidInput);
  }
  SUBCASE("unsupported element type: a 10-node tetrahedron (Gmsh type 11)") {
    const fs::path file = dir / "tet10.msh";
    write_text(file, hand_written_msh("3 1 11 1\n3 1 2 3 4 5 6 7 8 9 10\n3 1 4 1\n4 1 9 4 5\n"));
    try {
      (void)read_gmsh(file);
      FAIL("no exception");
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      CHECK(what.find(file.string()) != std::string::npos);
      CHECK(what.find("element 3") != std::string::npos);
      CHECK(what.find("not supported") != std::string::npos);
    }
  }
  SUBCASE("a physical curve of 3-node lines (Gmsh type 8) beside linear volumes") {
    // As Gmsh saves a curve meshed at order 2 in a group: its middle node belongs to no
    // volume element, and the line's type is the reason to give, by the element's tag.
    const fs::path file = dir / "line3.msh";
    write_text(file,
               "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
               "$PhysicalNames\n2\n1 20 \"edge\"\n3 1 \"solid\"\n$EndPhysicalNames\n"
               "$Nodes\n9\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0 0 1\n6 1 0 1\n7 1 1 1\n"
               "8 0 1 1\n9 0.5 0 0\n$EndNodes\n"
               "$Elements\n2\n7 8 2 20 1 1 2 9\n8 5 2 1 1 1 2 3 4 5 6 7 8\n$EndElements\n");
    CHECK_THROWS_WITH_AS(
        read_gmsh(file),
        doctest::Contains("node set 20 'edge': element 7: 3-node line (Gmsh type 8) is not "
                          "supported"),
        InvalidInput);
  }
  SUBCASE("side-set quad that is no element face") {
    const fs::path file = dir / "badside.msh";
    std::string text = hand_written_msh(kHexAndTet);
    text.replace(text.find("2 6 5 8 7"), 9, "2 6 5 8 9");
    write_text(file, text);
    CHECK_THROWS_WITH_AS(read_gmsh(file), doctest::Contains("element 2 is not a face"),
                         InvalidInput);
  }
}

TEST_CASE("write_gmsh is atomic and validates indices") {
  const fs::path file = scratch_dir() / "atomic.msh";
  write_text(file, "previous content");
  Model bad = gmsh_model();
  bad.hexes[1][6] = 999;  // out of range
  CHECK_THROWS_WITH_AS(write_gmsh(bad, file),
                       doctest::Contains("hex 2: corner 7 refers to node index 999"), InvalidInput);
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  CHECK(text.str() == "previous content");
  // No temporary file left behind.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(file.parent_path()))
    entries += e.path().filename().string().find("geode-tmp") != std::string::npos;
  CHECK(entries == 0);
}
