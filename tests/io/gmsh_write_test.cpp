// Our .msh writers (io/gmsh_write.cpp): every version and encoding read back by our reader and
// by Gmsh itself (libgmsh, at test time: its physical groups, names and element counts), the
// physical tags distinct across dimensions, names made safe, and write errors reported.
#include <doctest/doctest.h>

#include <gmsh.h>
#include <signal.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <geode/demo/gmsh_session.hpp>
#include <geode/io/exodus.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/names.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/model_checks.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

using geode::test::slurp;

// 2 x 2 x 1 cells: hexes (block 1 "steel") and Kuhn tets (block 2 "rubber"), a node set, a
// side set with hex and tet faces.
Model written_model() {
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.points[4] += Point(0.01, -0.02, 0.03);
  m.block_names[1] = "steel";
  m.block_names[2] = "rubber";
  NodeSet bottom{11, "bottom", {}};
  for (Index v = 0; v < 9; ++v) bottom.nodes.push_back(v);
  m.node_sets.push_back(bottom);
  SideSet outside{21, "outside", {}};
  outside.sides.push_back({{ElementKind::kHex, 0}, 4});
  outside.sides.push_back({{ElementKind::kHex, 1}, 5});
  outside.sides.push_back({{ElementKind::kTet, 0}, 3});
  m.side_sets.push_back(outside);
  return m;
}

struct Variant {
  GmshFormat format;
  GmshVersion version;
  const char* name;
};
constexpr Variant kVariants[] = {
    {GmshFormat::kAscii, GmshVersion::k41, "41-ascii"},
    {GmshFormat::kBinary, GmshVersion::k41, "41-binary"},
    {GmshFormat::kAscii, GmshVersion::k22, "22-ascii"},
    {GmshFormat::kBinary, GmshVersion::k22, "22-binary"},
};

// What Gmsh sees in a file: per physical group (dim, tag), its name and element count.
std::map<std::pair<int, int>, std::pair<std::string, std::size_t>> gmsh_groups(
    const fs::path& file) {
  demo::GmshSession session;
  gmsh::open(file.string());
  std::map<std::pair<int, int>, std::pair<std::string, std::size_t>> out;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    std::size_t count = 0;
    for (int e : entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> tags, nodes;
      gmsh::model::mesh::getElements(types, tags, nodes, dim, e);
      for (const auto& t : tags) count += t.size();
    }
    out[{dim, tag}] = {name, count};
  }
  return out;
}

}  // namespace

TEST_CASE("write_gmsh: every version and encoding reads back the same model") {
  const test::TempDir dir;
  const Model m = written_model();
  for (const Variant& v : kVariants) {
    CAPTURE(v.name);
    const fs::path file = dir.path / (std::string(v.name) + ".msh");
    write_gmsh(m, file, v.format, v.version);
    const std::string text = slurp(file);
    const std::string header = text.substr(text.find('\n') + 1, 5);
    CHECK(header == std::string(v.version == GmshVersion::k41 ? "4.1 " : "2.2 ") +
                        (v.format == GmshFormat::kBinary ? "1" : "0"));
    const Model r = read_gmsh(file);
    CHECK(r.points == m.points);  // shortest round-trip text or raw doubles: exact
    CHECK(r.hexes == m.hexes);
    CHECK(r.tets == m.tets);
    CHECK(r.hex_block == std::vector<int>(m.hexes.size(), 1));
    CHECK(r.tet_block == std::vector<int>(m.tets.size(), 2));
    CHECK(r.block_names == m.block_names);
    REQUIRE(r.node_sets.size() == 1);
    CHECK(r.node_sets[0].id == 11);
    CHECK(r.node_sets[0].name == "bottom");
    CHECK(r.node_sets[0].nodes == m.node_sets[0].nodes);
    REQUIRE(r.side_sets.size() == 1);
    CHECK(r.side_sets[0].id == 21);
    CHECK(r.side_sets[0].name == "outside");
    CHECK(r.side_sets[0].sides == m.side_sets[0].sides);
  }
}

TEST_CASE("write_gmsh: Gmsh itself lists every physical group with its name and elements") {
  // The old writer (libgmsh with Mesh.SaveAll) wrote physical tag 0 on every element of a
  // .msh 2.2 file: Gmsh then listed no physical group at all.
  const test::TempDir dir;
  const Model m = written_model();
  for (const Variant& v : kVariants) {
    CAPTURE(v.name);
    const fs::path file = dir.path / (std::string(v.name) + ".msh");
    write_gmsh(m, file, v.format, v.version);
    const auto groups = gmsh_groups(file);
    REQUIRE(groups.size() == 4);
    CHECK(groups.at({3, 1}) == std::pair<std::string, std::size_t>{"steel", m.hexes.size()});
    CHECK(groups.at({3, 2}) == std::pair<std::string, std::size_t>{"rubber", m.tets.size()});
    CHECK(groups.at({2, 21}) == std::pair<std::string, std::size_t>{"outside", 3});
    CHECK(groups.at({0, 11}) == std::pair<std::string, std::size_t>{"bottom", 9});
  }
}

TEST_CASE("write_gmsh: block, side set and node set physical tags are distinct") {
  // Legal in .msh (tags are per dimension), but GetFEM keeps one region per tag and renumbers
  // a tag used twice: a set whose id is a block's moves by 10^k above every id.
  const test::TempDir dir;
  Model m = written_model();
  m.node_sets[0].id = 1;
  m.side_sets[0].id = 1;
  const fs::path file = dir.path / "shared.msh";
  write_gmsh(m, file);
  const Model r = read_gmsh(file);
  CHECK(r.side_sets.at(0).id == 11);  // 1 is block 1's
  CHECK(r.node_sets.at(0).id == 21);  // 1 and 11 are taken
  CHECK(r.side_sets[0].name == "outside");
  CHECK(r.node_sets[0].name == "bottom");
}

TEST_CASE("names with quotes, newlines, control characters and bad UTF-8 never break an output") {
  const test::TempDir dir;
  Model m = written_model();
  m.block_names[1] = "st\"e\nel\x01 \xff";
  m.side_sets[0].name = "out\rside\t\"x\"";
  const std::string block = "st'e el  \xEF\xBF\xBD", side = "out side 'x'";
  CHECK(sanitize_name(m.block_names[1]) == block);
  CHECK(sanitize_name("caf\xC3\xA9 \xE2\x82\xAC") ==
        "caf\xC3\xA9 \xE2\x82\xAC");                               // valid UTF-8 kept
  CHECK(sanitize_name("\xC0\x80") == "\xEF\xBF\xBD\xEF\xBF\xBD");  // overlong NUL
  for (const Variant& v : kVariants) {
    CAPTURE(v.name);
    const fs::path file = dir.path / (std::string(v.name) + ".msh");
    write_gmsh(m, file, v.format, v.version);
    const Model r = read_gmsh(file);
    CHECK(r.block_names.at(1) == block);
    CHECK(r.side_sets.at(0).name == side);
  }
  const fs::path exo = dir.path / "names.exo";
  write_exodus(m, exo);
  CHECK(read_exodus(exo).block_names.at(1) == block);
  const fs::path vtu = dir.path / "names.vtu";
  write_vtu(vtu, m);
  const std::string xml = slurp(vtu);
  CHECK(xml.find('\x01') == std::string::npos);
  CHECK(xml.find("block:st&quot;") == std::string::npos);
  CHECK_NOTHROW((void)read_vtu(vtu));
}

TEST_CASE(
    "a write that fails (full disk, file size limit) says so, naming the output, and leaves "
    "nothing") {
  // RLIMIT_FSIZE makes write(2) fail with EFBIG past the limit, as ENOSPC does on a full disk;
  // the old .msh writer (libgmsh) ignored such errors and left a truncated file with exit 0.
  const test::TempDir dir;
  const Model m = grid_model({12, 12, 12}, 0.1, [](int i, int, int) { return i >= 6; });
  struct rlimit old {};
  REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
  const auto old_handler = ::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 20000;
  REQUIRE(setrlimit(RLIMIT_FSIZE, &small) == 0);
  std::vector<std::string> messages;
  for (const Variant& v : kVariants) {
    const fs::path file = dir.path / (std::string(v.name) + ".msh");
    try {
      write_gmsh(m, file, v.format, v.version);
      messages.push_back("no error");
    } catch (const InvalidInput& e) {
      messages.push_back(e.what());
    }
  }
  std::string exo_message = "no error";
  try {
    write_exodus(m, dir.path / "full.exo");
  } catch (const InvalidInput& e) {
    exo_message = e.what();
  }
  setrlimit(RLIMIT_FSIZE, &old);
  ::signal(SIGXFSZ, old_handler);
  for (std::size_t i = 0; i < messages.size(); ++i) {
    CAPTURE(messages[i]);
    const std::string file = (dir.path / (std::string(kVariants[i].name) + ".msh")).string();
    CHECK(messages[i].rfind(file + ": write failed: File too large", 0) == 0);
  }
  CAPTURE(exo_message);
  CHECK(exo_message.rfind((dir.path / "full.exo").string() + ": ", 0) == 0);
  CHECK(exo_message.find("File too large") != std::string::npos);
  CHECK(exo_message.find(".tmp") == std::string::npos);
  CHECK(fs::is_empty(dir.path));  // no output, no temporary file
}

TEST_CASE(
    "write_gmsh: pyramids and wedges (every cell kind of the model) read back, by us and by Gmsh") {
  Model m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1},              // pyramid
              {2, 0, 0}, {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {3, 0, 1},     {2, 1, 1}};  // wedge
  m.pyramids.push_back({0, 1, 2, 3, 4});
  m.wedges.push_back({5, 6, 7, 8, 9, 10});
  m.pyramid_block = {3};
  m.wedge_block = {4};
  m.block_names = {{3, "pyramid"}, {4, "wedge"}};
  m.side_sets.push_back(
      {7, "bases", {{{ElementKind::kPyramid, 0}, 4}, {{ElementKind::kWedge, 0}, 3}}});
  const test::TempDir dir;
  for (const Variant& v : kVariants) {
    CAPTURE(v.name);
    const fs::path file = dir.path / (std::string(v.name) + ".msh");
    write_gmsh(m, file, v.format, v.version);
    const Model r = read_gmsh(file);
    test::check_same_cells(r, m);
    REQUIRE(r.side_sets.size() == 1);
    CHECK(r.side_sets[0].sides == m.side_sets[0].sides);
    const auto groups = gmsh_groups(file);
    CHECK(groups.at({3, 3}) == std::pair<std::string, std::size_t>{"pyramid", 1});
    CHECK(groups.at({3, 4}) == std::pair<std::string, std::size_t>{"wedge", 1});
    CHECK(groups.at({2, 7}) == std::pair<std::string, std::size_t>{"bases", 2});
  }
}
