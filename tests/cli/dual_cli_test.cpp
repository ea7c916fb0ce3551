// The `geode dual` command end to end: the sheet report of a mesh file, the rebuild through
// the arrangement engine read back and compared by isomorphism, and refusals with exit codes.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include <geode/io/formats.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using primal::Point;
using test::geode_cli;
using test::temp_path;

namespace {

// A 3 x 2 x 2 grid with its interior nodes moved (kinked sheets), still filling its box.
primal::HexMesh moved_grid() {
  primal::HexMesh g = test::structured_hex_grid(3, 2, 2);
  for (std::size_t n = 0; n < g.points.size(); ++n) {
    Point& p = g.points[n];
    const bool interior =
        p.x() > 0 && p.x() < 3 && p.y() > 0 && p.y() < 2 && p.z() > 0 && p.z() < 2;
    if (interior) p += 0.2 * Point(std::sin(1.0 * n), std::cos(2.0 * n), std::sin(3.0 * n));
  }
  return g;
}

}  // namespace

TEST_CASE("geode dual: sheets and triples of a grid, and its rebuild") {
  const auto in = temp_path("grid.vtu"), out = temp_path("grid-rebuilt.vtu");
  const primal::HexMesh g = moved_grid();
  io::write_vtu(in, g);
  const auto r = geode_cli("dual " + in.string() +
                           " --format json --vtu-encoding ascii --rebuild " + out.string());
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["cells"] == 12);
  CHECK(j["sheets"].size() == 3 + 2 + 2);
  CHECK(j["intersections"].size() == 3 * 2 * 2);  // every (x, y, z) triple, once each
  for (const auto& t : j["intersections"]) CHECK(t["cells"] == 1);
  CHECK(j["rebuild"]["same_counts"] == true);
  const primal::HexMesh back = io::to_hex_mesh(io::read_vtu(out));
  const auto m = test::find_isomorphism(back, g);
  CHECK(m.has_value());
  std::filesystem::remove(in);
  std::filesystem::remove(out);
}

TEST_CASE("geode dual: a quad mesh gives chords, in text") {
  const auto in = temp_path("quads.vtk");
  io::write_vtk(in, test::structured_quad_grid(4, 3));
  const auto r = geode_cli("dual " + in.string());
  REQUIRE(r.code == 0);
  CHECK(r.out.find("20 nodes, 12 quads, 7 chords") != std::string::npos);
  std::filesystem::remove(in);
}

TEST_CASE("geode dual: refusals name the file and write nothing") {
  SUBCASE("no such file") {
    CHECK(geode_cli("dual " + temp_path("missing.vtu").string()).code == 2);
  }
  SUBCASE("a model with tets") {
    // Every reader alike (.vtu's gave the first cell that is not a hex).
    for (const std::string ext : {".msh", ".vtu"}) {
      CAPTURE(ext);
      const auto in = temp_path("mixed" + ext);
      io::write_model(primal::grid_model({2, 1, 1}, 1.0, [](int i, int, int) { return i == 1; }),
                      in);
      const auto r = geode_cli("dual " + in.string(), true);
      CHECK(r.code == 2);
      CHECK(r.out.find(in.string() + ": holds 6 tets; expected an all-hex mesh") !=
            std::string::npos);
      std::filesystem::remove(in);
    }
  }
  SUBCASE("a mesh whose dual cannot be read: named by the file, its numbering said") {
    // It said "geode: topology error: edge 2-6 lies on 4 boundary quads, not 2" (a hunt's).
    const auto in = temp_path("pinched.vtu");
    primal::HexMesh m = test::structured_hex_grid(2, 1, 1);
    m.hexes[1][0] = m.hexes[1][1];  // a hex listing a node twice
    io::write_vtu(in, m);
    const auto r = geode_cli("dual " + in.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find(in.string() + ": hex 1: node ") != std::string::npos);
    CHECK(r.out.find("(hexes and nodes numbered from 0 in the file's order)") != std::string::npos);
    std::filesystem::remove(in);
  }
  SUBCASE("a rebuild the fields cannot represent (the printed Appendix A positions fold 8 hexes)") {
    const auto in = temp_path("appendix.vtu"), out = temp_path("appendix-rebuilt.vtu");
    io::write_vtu(in, test::appendix_a_geode());
    const auto r = geode_cli("dual " + in.string() + " --rebuild " + out.string(), true);
    CHECK(r.code == 2);
    CHECK(r.out.find(in.string() + ": cannot rebuild: sheet_fields: hex") != std::string::npos);
    CHECK(r.out.find("is inverted or flat") != std::string::npos);
    CHECK(r.out.find("(hexes and nodes numbered from 0 in the file's order)") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out));
    // Without --rebuild the same file is reported: the dual is read off the connectivity.
    const auto ok = geode_cli("dual " + in.string() + " --format json");
    REQUIRE(ok.code == 0);
    CHECK(nlohmann::json::parse(ok.out)["sheets"].size() == 6);
    std::filesystem::remove(in);
  }
}

TEST_CASE("geode dual: its stages on stderr as they end, none with --quiet, the report the same") {
  test::TempDir dir;
  const auto in = dir.path / "grid.vtu", report = dir.path / "r.json";
  io::write_vtu(in, moved_grid());
  const auto r = geode_cli("dual " + in.string() + " -o " + report.string(), true);
  REQUIRE(r.code == 0);
  test::check_stage_lines(r.out, {"read " + in.string() + ": 12 hexes, 36 nodes", "dual: 7 sheets",
                                  "report: 12 sheet triples"});
  const auto j = nlohmann::json::parse(std::ifstream(report));
  const auto quiet = geode_cli("dual " + in.string() + " -o " + report.string() + " --quiet", true);
  REQUIRE(quiet.code == 0);
  CHECK(quiet.out.empty());
  CHECK(nlohmann::json::parse(std::ifstream(report)) == j);
  // With --rebuild: the sheet fields, the rebuilt mesh and its validity too.
  const auto grid = dir.path / "plain.vtu", rebuilt = dir.path / "rebuilt.vtu";
  io::write_vtu(grid, test::structured_hex_grid(3, 2, 2));
  const auto b = geode_cli(
      "dual " + grid.string() + " -o " + report.string() + " --rebuild " + rebuilt.string(), true);
  REQUIRE(b.code == 0);
  test::check_stage_lines(b.out, {"read ", "dual: 7 sheets", "sheet fields", "rebuilt: 12 hexes",
                                  "report: ", "validity of the rebuilt mesh: valid"});
  const auto q = geode_cli("dual " + grid.string() + " -o " + report.string() + " --rebuild " +
                               rebuilt.string() + " --quiet",
                           true);
  REQUIRE(q.code == 0);
  CHECK(q.out.empty());
}
