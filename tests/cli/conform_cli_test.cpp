// The `geode conform` command end to end: a small hex + tet model written as .msh and as .exo
// is conformed into an Exodus file that is read back (all hex, valid, counts as in the JSON
// report); bad input exits non-zero, names the file and writes nothing.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include <geode/conform/conform.hpp>
#include <geode/io/exodus.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity.hpp>
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"

using namespace geode;
namespace fs = std::filesystem;

namespace {

using test::TempDir;
using Run = test::CliRun;

// Standard output and standard error together: the messages are checked.
Run run_geode(const std::string& args) { return test::geode_cli(args, true); }

}  // namespace

TEST_CASE("geode conform: .msh and .exo input -> valid all-hex Exodus matching the report") {
  TempDir dir;
  const primal::Model model = test::small_hybrid_model();
  REQUIRE(model.hexes.size() == 8);
  REQUIRE(model.tets.size() == 48);
  io::write_gmsh(model, dir.path / "in.msh");
  io::write_exodus(model, dir.path / "in.exo");

  for (const char* input : {"in.msh", "in.exo"}) {
    CAPTURE(input);
    const fs::path out = dir.path / (std::string(input) + ".out.exo");
    const fs::path report = dir.path / (std::string(input) + ".json");
    const Run r = run_geode("conform " + (dir.path / input).string() + " -o " + out.string() +
                            " --report " + report.string() + " --quiet");
    INFO(r.out);
    REQUIRE(r.code == 0);
    CHECK(r.out.empty());  // --quiet

    const primal::Model result = io::read_exodus(out);
    CHECK(result.tets.empty());
    const primal::HexValidityReport v = primal::check_validity(primal::hex_part(result));
    INFO(v.summary());
    CHECK(v.ok());
    CHECK(v.boundary.euler == 2);  // the box stays a ball

    std::ifstream is(report);
    const nlohmann::json j = nlohmann::json::parse(is);  // throws (fails the test) if malformed
    CHECK(j.at("input").at("hexes") == 8);
    CHECK(j.at("input").at("tets") == 48);
    CHECK(j.at("input").at("interface_quads") == 4);
    // 8 hexes * 8 + 4 buffer hexes * 26 + 48 tets * 4.
    const auto& o = j.at("output");
    CHECK(o.at("diced_hexes") == 64);
    CHECK(o.at("geode_hexes") == 104);
    CHECK(o.at("diced_tet_hexes") == 192);
    CHECK(o.at("hexes") == 360);
    CHECK(o.at("hexes").get<std::size_t>() == result.hexes.size());
    CHECK(o.at("nodes").get<std::size_t>() == result.points.size());
    CHECK(j.at("valid") == true);
    // The input's blocks (1: hexes, 2: tets, by default): the geode hexes join the hexes' (the
    // buffer layer is carved from the hex part).
    auto in_block = [&](int b) {
      return std::count(result.hex_block.begin(), result.hex_block.end(), b);
    };
    CHECK(in_block(1) == 64 + 104);
    CHECK(in_block(2) == 192);
    std::size_t block_hexes = 0;
    for (const auto& b : j.at("blocks"))
      block_hexes += b.at("quality").at("num_hexes").get<std::size_t>();
    CHECK(block_hexes == 360);
  }
}

TEST_CASE("geode conform: a hex-only model has no transition to make and is simply diced") {
  TempDir dir;
  const primal::Model hexes =
      primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; });
  io::write_gmsh(hexes, dir.path / "hexes.msh");
  const fs::path report = dir.path / "r.json";
  const Run r =
      run_geode("conform " + (dir.path / "hexes.msh").string() + " -o " +
                (dir.path / "out.exo").string() + " --report " + report.string() + " --quiet");
  INFO(r.out);
  REQUIRE(r.code == 0);
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  CHECK(j.at("valid").get<bool>());
  CHECK(j.at("output").at("hexes").get<std::size_t>() == 64);
  CHECK(j.at("output").at("geode_hexes").get<std::size_t>() == 0);
  // A minimum over nothing is null: no tets, no wedges, no template, no geode hexes.
  const nlohmann::json& alone = j.at("input_diced_alone_min_scaled_jacobian");
  CHECK(alone.at("hexes").get<double>() == 1.0);
  CHECK(alone.at("tets").is_null());
  CHECK(alone.at("wedges").is_null());
  for (const char* key : {"template_min_scaled_jacobian", "buffer_layer_min_scaled_jacobian",
                          "local_yardstick_ratio", "capped_local_ratio"})
    CHECK_MESSAGE(j.at(key).is_null(), key);
}

TEST_CASE("geode conform: bad input exits non-zero, names the file and writes nothing") {
  TempDir dir;
  const fs::path out = dir.path / "out.exo";
  const fs::path report = dir.path / "r.json";
  auto check_refused = [&](const fs::path& input, const std::string& why) {
    CAPTURE(input);
    const Run r = run_geode("conform " + input.string() + " -o " + out.string() + " --report " +
                            report.string() + " --quiet");
    INFO(r.out);
    CHECK(r.code != 0);
    CHECK(r.out.find(input.string()) != std::string::npos);
    CHECK(r.out.find(why) != std::string::npos);
    CHECK_FALSE(fs::exists(out));
    CHECK_FALSE(fs::exists(report));
  };

  SUBCASE("a file that does not exist") { check_refused(dir.path / "missing.msh", "no such file"); }
  SUBCASE("a hex part and a tet part against each other without shared nodes") {
    // Two hex cells beside two tet cells, the tets on copies of every node: parts meshed
    // separately and not merged.
    io::write_exodus(test::unmerged_parts({4, 1, 1}), dir.path / "unmerged.exo");
    check_refused(dir.path / "unmerged.exo", "lie against each other");
  }
  // Nothing half-written left behind either.
  for (const auto& e : fs::directory_iterator(dir.path))
    if (e.path().filename() != "unmerged.exo")
      FAIL_CHECK("left behind: " << e.path().filename().string());
}

TEST_CASE("geode conform: a hex part and a tet part that do not touch are each diced, warned") {
  // Separate bodies (a bolt beside a bracket) in one file: two hex cells, a gap cell and two
  // tet cells. There is no transition to make; each part is diced alone, as a body apart from
  // the interface is in a model that has one, and a warning says so.
  TempDir dir;
  primal::Model apart = primal::grid_model({5, 1, 1}, 1.0, [](int i, int, int) { return i >= 3; });
  apart.hexes.erase(apart.hexes.begin() + 2);
  apart.hex_block.erase(apart.hex_block.begin() + 2);
  io::write_exodus(apart, dir.path / "apart.exo");
  const fs::path report = dir.path / "r.json";
  const Run r =
      run_geode("conform " + (dir.path / "apart.exo").string() + " -o " +
                (dir.path / "out.exo").string() + " --report " + report.string() + " --quiet");
  INFO(r.out);
  REQUIRE(r.code == 0);
  CHECK(r.out ==
        "geode: warning: the hex part and the tet part share no interface quad: each is diced "
        "alone, with no transition between them\n");
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  CHECK(j.at("valid").get<bool>());
  CHECK(j.at("output").at("hexes").get<std::size_t>() == 2 * 8 + 2 * 6 * 4);
  CHECK(j.at("output").at("geode_hexes").get<std::size_t>() == 0);
  const primal::Model out = io::read_exodus(dir.path / "out.exo");
  CHECK(out.hexes.size() == 2 * 8 + 2 * 6 * 4);
  CHECK(primal::check_validity(primal::hex_part(out)).ok());
  // The summary names the kinds the input holds, and no geode hexes where there are none.
  const Run summary = run_geode("conform " + (dir.path / "apart.exo").string() + " -o " +
                                (dir.path / "again.exo").string());
  INFO(summary.out);
  CHECK(summary.out.find("input diced alone: min scaled Jacobian 1 (hexes), ") !=
        std::string::npos);
  CHECK(summary.out.find("geode hexes") == std::string::npos);
  primal::Model tets = apart;
  tets.hexes.clear();
  tets.hex_block.clear();
  io::write_exodus(tets, dir.path / "tets.exo");
  const fs::path tets_report = dir.path / "tets.json";
  const Run only_tets =
      run_geode("conform " + (dir.path / "tets.exo").string() + " -o " +
                (dir.path / "tets_out.exo").string() + " --report " + tets_report.string());
  INFO(only_tets.out);
  CHECK(only_tets.code == 0);
  CHECK(only_tets.out.find("input diced alone: min scaled Jacobian 0.") != std::string::npos);
  CHECK(only_tets.out.find("(hexes)") == std::string::npos);
  // The JSON report too: the tets' minimum, null for the kinds the input lacks.
  const nlohmann::json t = nlohmann::json::parse(std::ifstream(tets_report));
  const nlohmann::json& alone = t.at("input_diced_alone_min_scaled_jacobian");
  CHECK(alone.at("hexes").is_null());
  CHECK(alone.at("wedges").is_null());
  CHECK(alone.at("tets").get<double>() > 0.0);
  CHECK(alone.at("tets").get<double>() < 1.0);
  CHECK(t.at("local_yardstick_ratio").is_null());
}

TEST_CASE("geode conform: a warning reaches stderr with --quiet, and the report names the side") {
  // A tet cell alone on a hex block's top: no layer can be carved from the hex part there (its
  // nodes on the block's flat top cannot move below the interface), so conform carves it from
  // the tet part and warns.
  TempDir dir;
  io::write_gmsh(test::tet_cell_on_hex_top(), dir.path / "in.msh");
  const fs::path report = dir.path / "r.json";
  const Run r =
      run_geode("conform " + (dir.path / "in.msh").string() + " -o " +
                (dir.path / "out.exo").string() + " --report " + report.string() + " --quiet");
  CHECK(r.code == 0);
  // Nothing but the warning, on one line.
  CHECK(r.out.rfind("geode: warning: buffer layer carved from the tet part, not the hex part", 0) ==
        0);
  CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  std::ifstream is(report);
  const nlohmann::json j = nlohmann::json::parse(is);
  CHECK(j.at("buffer_side") == "tet");
  CHECK(j.at("warnings").size() == 1);
  CHECK(j.at("valid") == true);
}

TEST_CASE("geode conform: a layer of hexes beside wedges on tets is split, warned and counted") {
  // Gmsh's layer-mixed demo as a user saves it: the wedges join the two sides of the interface,
  // where the run exited 3; now every wedge of the layer becomes three tets, a warning names one
  // by the file's id, the buffer is carved from the tets (the hex layer's first cells are thin)
  // and the report counts the split wedges among the input's.
  TempDir dir;
  const fs::path in = dir.path / "mixed.msh", report = dir.path / "r.json";
  REQUIRE(run_geode("demo --model layer-mixed -n 3 --quiet --save-input " + in.string()).code == 0);
  const Run r = run_geode("conform " + in.string() + " -o " + (dir.path / "out.exo").string() +
                          " --report " + report.string() + " --quiet");
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("geode: warning: 132 wedges split into three tets each: the layer of wedge ") !=
        std::string::npos);
  CHECK(r.out.find("geode: warning: buffer layer carved from the tet part, not the hex part") !=
        std::string::npos);
  std::ifstream is(report);
  const nlohmann::json j = nlohmann::json::parse(is);
  CHECK(j.at("input").at("wedges") == 132);
  CHECK(j.at("input").at("wedges_split") == 132);
  CHECK(j.at("output").at("diced_wedge_hexes") == 0);
  CHECK(j.at("buffer_side") == "tet");
  CHECK(j.at("valid") == true);
  CHECK(j.at("output_min_scaled_jacobian").get<double>() >=
        j.at("input_diced_alone_min_scaled_jacobian").at("tets").get<double>());
}

TEST_CASE("geode conform: the report and exit 4 name hexes as the written file numbers them") {
  // The hex part in block 9 and the tet part in block 7: the output holds the hex part's hexes
  // first, and Exodus and .msh number block 7's first (VTK keeps the model's order, from 0).
  TempDir dir;
  primal::Model model = test::small_hybrid_model();
  model.hex_block.assign(model.hexes.size(), 9);
  model.tet_block.assign(model.tets.size(), 7);
  const fs::path in = dir.path / "in.exo";
  io::write_exodus(model, in);
  for (const char* ext : {".exo", ".msh", ".vtu"}) {
    CAPTURE(ext);
    const fs::path out = dir.path / (std::string("out") + ext);
    const fs::path report = dir.path / (std::string("out") + ext + ".json");
    const Run r = run_geode("conform " + in.string() + " -o " + out.string() + " --report " +
                            report.string() + " --quiet");
    INFO(r.out);
    REQUIRE(r.code == 0);
    const primal::Model result = io::read_model(out);
    const primal::HexMesh mesh = primal::hex_part(result);
    // The file's id -> the hex.
    std::map<std::int64_t, std::size_t> by_id;
    for (std::size_t k = 0; k < result.hexes.size(); ++k)
      by_id[primal::element_id(result, {primal::ElementKind::kHex, primal::index_cast(k)})] = k;
    std::ifstream is(report);
    const nlohmann::json j = nlohmann::json::parse(is);
    CHECK(j.at("numbering").at("index_base") == (std::string(ext) == ".vtu" ? 0 : 1));
    CHECK(j.at("numbering").at("element_order") ==
          (std::string(ext) == ".vtu" ? "as given" : "by block"));
    REQUIRE(j.at("blocks").size() == 2);
    for (const auto& b : j.at("blocks")) {
      const int id = b.at("id");
      CAPTURE(id);
      for (const auto& m : b.at("quality").at("metrics")) {
        if (m.at("key") != "scaled_jacobian") continue;
        for (const char* at : {"min_hex", "max_hex"}) {
          CAPTURE(at);
          const auto hex = by_id.find(m.at(at).get<std::int64_t>());
          REQUIRE(hex != by_id.end());
          CHECK(result.hex_block[hex->second] == id);
          const double sj = primal::hex_scaled_jacobian(
              primal::hex_corners(mesh, primal::index_cast(hex->second)));
          CHECK(sj ==
                doctest::Approx(m.at(std::string(at) == "min_hex" ? "min" : "max").get<double>()));
        }
      }
    }
  }
  // The first output hex (a diced hex of block 9) inverted by the test hook: the message names
  // it as the written file does.
  test::ScopedEnv hook("GEODE_TEST_INVERT_OUTPUT_HEX", "1");
  for (const char* ext : {".exo", ".vtu"}) {
    CAPTURE(ext);
    const fs::path out = dir.path / (std::string("bad") + ext);
    const Run r = run_geode("conform " + in.string() + " -o " + out.string() +
                            " --write-invalid --smooth none --quiet");
    INFO(r.out);
    REQUIRE(r.code == 4);
    // As the file holds it (its geometry checked, the reader would refuse the inverted hex).
    primal::ReadOptions plain;
    plain.check_geometry = false;
    const primal::Model result = io::read_model(out, plain);
    const primal::HexMesh mesh = primal::hex_part(result);
    // Verification's finding and the measured list both name it first.
    for (const std::string words : {"hexes inverted (a corner Jacobian <= 0), hexes: ",
                                    "hexes with scaled Jacobian <= 0: "}) {
      CAPTURE(words);
      const std::size_t at = r.out.find(words);
      REQUIRE(at != std::string::npos);
      const std::int64_t named = std::stoll(r.out.substr(at + words.size()));
      // Not the hex's index in the output model: in .exo block 7's hexes (the diced tets) come
      // first, then hex 1 of block 9.
      const auto block_7 = std::count(result.hex_block.begin(), result.hex_block.end(), 7);
      REQUIRE(block_7 > 0);
      CHECK(named == (std::string(ext) == ".vtu" ? 0 : block_7 + 1));
      bool found = false;
      for (std::size_t k = 0; k < result.hexes.size(); ++k)
        if (primal::element_id(result, {primal::ElementKind::kHex, primal::index_cast(k)}) ==
            named) {
          found = true;
          CHECK(result.hex_block[k] == 9);
          CHECK(primal::hex_scaled_jacobian(primal::hex_corners(mesh, primal::index_cast(k))) <=
                0.0);
        }
      CHECK(found);
    }
  }
}
