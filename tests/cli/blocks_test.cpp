// Materials survive `geode conform`: a model whose hex part is the physical volume "steel"
// (id 7) and whose tet part is "rubber" (id 9), with a node set and a side set, comes out with
// the same block ids and names in .exo, .msh and .vtu: diced hexes and geode hexes in steel
// (the buffer layer is carved from the hex part), diced tets in rubber (or the geode hexes in a
// block of their own with --geode-block); the
// sets carried with their ids and names; Exodus coordinate names x, y, z.
#include <doctest/doctest.h>
#include <exodusII.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include <geode/io/exodus.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>
#include "support/cli_run.hpp"

using namespace geode;
namespace fs = std::filesystem;

namespace {

using test::slurp;

// 4 x 2 x 2 unit cells, i >= 2 split into tets: 8 steel hexes, 48 rubber tets, 4 interface
// quads. Node set 3 "clamp": the nodes at x = 0; side set 5 "load": the tet faces at x = 4.
primal::Model steel_rubber() {
  primal::Model m = primal::grid_model({4, 2, 2}, 1.0, [](int i, int, int) { return i >= 2; });
  m.hex_block.assign(m.hexes.size(), 7);
  m.tet_block.assign(m.tets.size(), 9);
  m.block_names = {{7, "steel"}, {9, "rubber"}};
  primal::NodeSet clamp{3, "clamp", {}};
  for (std::size_t v = 0; v < m.points.size(); ++v)
    if (m.points[v].x() == 0.0) clamp.nodes.push_back(primal::index_cast(v));
  m.node_sets = {clamp};
  primal::SideSet load{5, "load", {}};
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      bool on = true;
      for (int c : primal::topology::kTetFaceCorners[primal::index_cast<std::size_t>(f)])
        on =
            on &&
            m.points[primal::index_cast<std::size_t>(m.tets[t][primal::index_cast<std::size_t>(c)])]
                    .x() == 4.0;
      if (on) load.sides.push_back({{primal::ElementKind::kTet, primal::index_cast(t)}, f});
    }
  m.side_sets = {load};
  return m;
}

std::map<int, std::size_t> block_counts(const std::vector<int>& block) {
  std::map<int, std::size_t> n;
  for (int b : block) ++n[b];
  return n;
}

// 8 hexes * 8 diced + 4 buffer hexes * 26 geode; 48 tets * 4 diced.
const std::map<int, std::size_t> kExpected{{7, 64 + 104}, {9, 192}};

// Blocks, names and both sets as conform must carry them for steel_rubber().
void check_carried(const primal::Model& o, const primal::Model& input) {
  CHECK(block_counts(o.hex_block) == kExpected);
  CHECK(o.block_names == input.block_names);
  REQUIRE(o.node_sets.size() == 1);
  CHECK(o.node_sets[0].id == 3);
  CHECK(o.node_sets[0].name == "clamp");
  CHECK(o.node_sets[0].nodes.size() == 25);  // the 5 x 5 diced nodes of the face x = 0
  REQUIRE(o.side_sets.size() == 1);
  CHECK(o.side_sets[0].id == 5);
  CHECK(o.side_sets[0].name == "load");
  CHECK(o.side_sets[0].sides.size() == 24);  // 3 quads per triangle
}

}  // namespace

TEST_CASE("conform carries blocks and sets: steel and rubber keep their ids and names") {
  test::TempDir dir;
  const primal::Model model = steel_rubber();
  REQUIRE(model.node_sets[0].nodes.size() == 9);
  REQUIRE(model.side_sets[0].sides.size() == 8);
  const fs::path in = dir.path / "in.msh";
  io::write_gmsh(model, in);

  SUBCASE(".exo") {
    const fs::path out = dir.path / "out.exo", report = dir.path / "r.json";
    const test::CliRun r = test::geode_cli("conform " + in.string() + " -o " + out.string() +
                                               " --report " + report.string() + " --quiet",
                                           true);
    INFO(r.out);
    REQUIRE(r.code == 0);
    check_carried(io::read_exodus(out), model);
    // The report speaks per output block.
    std::ifstream is(report);
    const nlohmann::json j = nlohmann::json::parse(is);
    REQUIRE(j.at("blocks").size() == 2);
    CHECK(j.at("blocks")[0].at("id") == 7);
    CHECK(j.at("blocks")[0].at("name") == "steel");
    CHECK(j.at("blocks")[1].at("name") == "rubber");
    CHECK(j.at("blocks")[0].at("quality").at("num_hexes") == 168);
    CHECK(j.at("blocks")[1].at("quality").at("num_hexes") == 192);
    // Coordinate names.
    int cpu = 8, io = 0;
    float version = 0;
    const int exo = ex_open(out.string().c_str(), EX_READ, &cpu, &io, &version);
    REQUIRE(exo >= 0);
    char x[MAX_STR_LENGTH + 1] = {}, y[MAX_STR_LENGTH + 1] = {}, z[MAX_STR_LENGTH + 1] = {};
    char* names[] = {x, y, z};
    CHECK(ex_get_coord_names(exo, names) >= 0);
    ex_close(exo);
    CHECK(std::string(x) == "x");
    CHECK(std::string(y) == "y");
    CHECK(std::string(z) == "z");
  }
  SUBCASE(".msh: physical volumes, a physical surface for the side set, physical points") {
    const fs::path out = dir.path / "out.msh";
    REQUIRE(test::geode_cli("conform " + in.string() + " -o " + out.string() + " --quiet").code ==
            0);
    check_carried(io::read_gmsh(out), model);
  }
  SUBCASE("binary .msh, 4.1 and 2.2 (--msh-encoding binary): what the ASCII file holds") {
    const fs::path text = dir.path / "text.msh";
    REQUIRE(test::geode_cli("conform " + in.string() + " -o " + text.string() + " --quiet").code ==
            0);
    const primal::Model ascii = io::read_gmsh(text);
    for (const char* version : {"msh", "msh22"}) {
      CAPTURE(version);
      const fs::path out = dir.path / (std::string(version) + ".msh");
      REQUIRE(test::geode_cli("conform " + in.string() + " --msh-encoding binary --format " +
                              version + " -o " + out.string() + " --quiet")
                  .code == 0);
      const std::string head = slurp(out).substr(0, 20);
      CHECK(head ==
            (version == std::string("msh") ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n2.2 1 8\n"));
      const primal::Model binary = io::read_gmsh(out);
      check_carried(binary, model);
      CHECK(binary.points == ascii.points);  // the text is exact (shortest round trip)
      CHECK(binary.hexes == ascii.hexes);
    }
  }
  SUBCASE(".vtu: the block cell array and the names as field data") {
    const fs::path out = dir.path / "out.vtu";
    REQUIRE(test::geode_cli("conform " + in.string() + " --vtu-encoding ascii -o " + out.string() +
                            " --quiet")
                .code == 0);
    const io::VtkGrid g = io::read_vtu(out);
    REQUIRE(g.cell_data.find_int("block") != nullptr);
    CHECK(block_counts(*g.cell_data.find_int("block")) == kExpected);
    const std::string xml = slurp(out);
    CHECK(xml.find("Name=\"block:steel\" NumberOfTuples=\"1\" format=\"ascii\">7<") !=
          std::string::npos);
    CHECK(xml.find("Name=\"block:rubber\" NumberOfTuples=\"1\" format=\"ascii\">9<") !=
          std::string::npos);
  }
  SUBCASE("--geode-block: the geode hexes in a block of their own") {
    const fs::path out = dir.path / "out.exo";
    REQUIRE(test::geode_cli("conform " + in.string() + " --geode-block transition -o " +
                            out.string() + " --quiet")
                .code == 0);
    const primal::Model o = io::read_exodus(out);
    CHECK(block_counts(o.hex_block) == std::map<int, std::size_t>{{7, 64}, {9, 192}, {10, 104}});
    CHECK(o.block_names.at(10) == "transition");
    CHECK(o.block_names.at(7) == "steel");
  }
  SUBCASE("--geode-block with the input's block ids at the top of the range: refused") {
    primal::Model top = model;
    top.tet_block.assign(top.tets.size(), 2147483647);
    const fs::path high = dir.path / "high.msh", out = dir.path / "never.exo";
    io::write_gmsh(top, high);
    const test::CliRun r = test::geode_cli(
        "conform " + high.string() + " --geode-block transition -o " + out.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find("block ids reach 2147483647: no id above them is left") != std::string::npos);
    CHECK(!fs::exists(out));
  }
  SUBCASE("--buffer-side tet: the geode hexes fill the rubber's space and join it") {
    const fs::path out = dir.path / "out.exo";
    REQUIRE(test::geode_cli("conform " + in.string() + " --buffer-side tet -o " + out.string() +
                            " --quiet")
                .code == 0);
    const primal::Model o = io::read_exodus(out);
    CHECK(block_counts(o.hex_block) == std::map<int, std::size_t>{{7, 64}, {9, 104 + 192}});
  }
}

TEST_CASE("conform: an unnamed block stays unnamed in the report, as in the file") {
  // The report named it "block 9" where the written file had no name (found by a fault hunt).
  test::TempDir dir;
  primal::Model model = steel_rubber();
  model.block_names.erase(9);
  const fs::path in = dir.path / "in.msh", out = dir.path / "out.exo", report = dir.path / "r.json";
  io::write_gmsh(model, in);
  const test::CliRun r = test::geode_cli(
      "conform " + in.string() + " -o " + out.string() + " --report " + report.string(), true);
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(io::read_exodus(out).block_names.count(9) == 0);
  std::ifstream is(report);
  const nlohmann::json j = nlohmann::json::parse(is);
  REQUIRE(j.at("blocks").size() == 2);
  CHECK(j.at("blocks")[0].at("name") == "steel");
  CHECK(j.at("blocks")[1].at("id") == 9);
  CHECK(j.at("blocks")[1].at("name") == "");
  CHECK(r.out.find("block 7 \"steel\": ") != std::string::npos);
  CHECK(r.out.find("block 9: ") != std::string::npos);
}

TEST_CASE("conform: parts meshed separately get a hint, and --merge-tolerance joins them") {
  test::TempDir dir;
  // The tet part on nodes of its own: every interface node duplicated at the same place.
  primal::Model m = primal::grid_model({4, 2, 2}, 1.0, [](int i, int, int) { return i >= 2; });
  const std::size_t n = m.points.size();
  for (std::size_t v = 0; v < n; ++v) m.points.push_back(m.points[v]);
  for (auto& t : m.tets)
    for (auto& v : t) v += primal::index_cast(n);
  const fs::path in = dir.path / "in.exo", out = dir.path / "out.exo";
  io::write_exodus(m, in);
  const test::CliRun r =
      test::geode_cli("conform " + in.string() + " -o " + out.string() + " --quiet", true);
  INFO(r.out);
  CHECK((r.code == 2 || r.code == 3));
  CHECK(r.out.find("nodes lie at the same place as others") != std::string::npos);
  CHECK(r.out.find("--merge-tolerance") != std::string::npos);
  CHECK(!fs::exists(out));
  const test::CliRun merged = test::geode_cli(
      "conform " + in.string() + " --merge-tolerance 1e-9 -o " + out.string() + " --quiet", true);
  INFO(merged.out);
  CHECK(merged.code == 0);
  CHECK(io::read_exodus(out).hexes.size() == 360);
}

TEST_CASE("conform --join-blocks: tets and pyramids kept apart in the file are one material") {
  // Gmsh's layer-side model (a wedge layer whose side quads meet tets; Gmsh puts pyramids there,
  // in the tet volume's block 5), written as Cubit writes such a volume: its pyramids in a block
  // of their own (99). Apart, the two are materials whose shared faces smoothing must keep;
  // joined, the run is the .msh's, block for block.
  test::TempDir dir;
  const fs::path msh = dir.path / "ls.msh", exo = dir.path / "cubit.exo";
  const test::CliRun made = test::geode_cli(
      "demo --model layer-side -n 3 --save-input " + msh.string() + " --quiet", true);
  INFO(made.out);
  REQUIRE(made.code == 0);
  primal::Model m = io::read_model(msh);
  REQUIRE(!m.pyramids.empty());
  REQUIRE(block_counts(m.pyramid_block) == std::map<int, std::size_t>{{5, m.pyramids.size()}});
  m.pyramid_block.assign(m.pyramids.size(), 99);
  m.block_names[99] = "tet slab pyramids";
  io::write_exodus(m, exo);
  const auto blocks = [&](const std::string& input, const std::string& options) {
    const fs::path report = dir.path / "r.json";
    const test::CliRun r = test::geode_cli(
        "conform " + input + " " + options + " --report " + report.string() + " --quiet", true);
    INFO(r.out);
    REQUIRE(r.code == 0);
    std::ifstream is(report);
    const nlohmann::json j = nlohmann::json::parse(is);
    std::map<int, std::pair<std::string, double>> out;  // id -> name, minimum
    for (const auto& b : j.at("blocks"))
      out[b.at("id")] = {b.at("name"), b.at("quality").at("metrics")[0].at("min")};
    return out;
  };
  const auto from_msh = blocks(msh.string(), "");
  const auto apart = blocks(exo.string(), ""), joined = blocks(exo.string(), "--join-blocks 5,99");
  CHECK(from_msh.size() == 3);  // tet, boundary layer, tet slab
  CHECK(apart.count(99) == 1);
  CHECK(joined == from_msh);
  CHECK(joined.count(99) == 0);
  CHECK(joined.at(5).second >= apart.at(99).second);
  // A block no element has, or a list of one, is refused naming the file; nothing written.
  const fs::path out = dir.path / "never.exo";
  for (const char* list : {"5,98", "5"}) {
    CAPTURE(list);
    const test::CliRun r = test::geode_cli(
        "conform " + exo.string() + " --join-blocks " + std::string(list) + " -o " + out.string(),
        true);
    CHECK(r.code == 2);
    CHECK(r.out.find("--join-blocks") + r.out.find("joining blocks") != 2 * std::string::npos);
    CHECK(!fs::exists(out));
  }
  // A block an earlier list joined away is named as joined (its material is the other block's
  // now), not as a block with no element.
  const test::CliRun twice = test::geode_cli(
      "conform " + exo.string() + " --join-blocks 5,99 --join-blocks 99,4 -o " + out.string(),
      true);
  INFO(twice.out);
  CHECK(twice.code == 2);
  CHECK(twice.out.find(exo.string() + ": joining blocks 99,4: block 99 was joined into block 5 "
                                      "by --join-blocks 5,99") != std::string::npos);
  CHECK(!fs::exists(out));
}
