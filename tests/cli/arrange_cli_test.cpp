// The `geode arrange` command end to end: the shipped specs (notebooks-data/specs/) are what
// `geode template NAME --format spec` writes and arrange to the built-in templates; known
// answers; bad specs exit 2 naming the JSON path, arrangements that do not dualize exit 3.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/cli_run.hpp"
#include "support/isomorphism.hpp"
#include "support/sanitized.hpp"

using namespace geode;
using test::geode_cli;
using test::temp_path;

namespace {

using geode::test::slurp;

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// The mesh of a `--format json` output (1-based cells), as a hex or quad mesh.
struct JsonMesh {
  int dim = 3;
  primal::HexMesh hex;
  primal::QuadMesh quad;
};
JsonMesh mesh_of(const nlohmann::json& j) {
  JsonMesh m;
  m.dim = j.contains("hexes") ? 3 : 2;
  std::vector<primal::Point> pts;
  for (const auto& p : j["nodes"])
    pts.emplace_back(p[0].get<double>(), p[1].get<double>(), m.dim == 3 ? p[2].get<double>() : 0.0);
  if (m.dim == 3) {
    m.hex.points = pts;
    for (const auto& h : j["hexes"]) {
      std::array<primal::Index, 8> c{};
      for (std::size_t i = 0; i < 8; ++i) c[i] = h[i].get<primal::Index>() - 1;
      m.hex.hexes.push_back(c);
    }
  } else {
    m.quad.points = pts;
    for (const auto& q : j["quads"]) {
      std::array<primal::Index, 4> c{};
      for (std::size_t i = 0; i < 4; ++i) c[i] = q[i].get<primal::Index>() - 1;
      m.quad.quads.push_back(c);
    }
  }
  return m;
}

const std::string kPlanes =
    R"("sheets": [{"name": "x", "plane": {"point": [0.5, 0.5, 0.5], "normal": [1, 0, 0]}},
                  {"name": "y", "plane": {"point": [0.5, 0.5, 0.5], "normal": [0, 1, 0]}},
                  {"name": "z", "plane": {"point": [0.5, 0.5, 0.5], "normal": [0, 0, 1]}})";

std::string three_planes_and(const std::string& extra) {
  return R"({"dim": 3, "domain": {"box": [[0, 0, 0], [1, 1, 1]]}, )" + kPlanes + extra + "]}";
}

}  // namespace

TEST_CASE("geode arrange: the shipped specs are the built-in templates") {
  for (const std::string name : {"geode3d", "geode2d", "geode4tri", "refine3", "refine3-2d"}) {
    CAPTURE(name);
    const std::filesystem::path shipped =
        std::filesystem::path(GEODE_SOURCE_DIR) / "notebooks-data/specs" / (name + ".json");
    const auto spec = geode_cli("template " + name + " --format spec");
    REQUIRE(spec.code == 0);
    CHECK(spec.out == slurp(shipped));  // regenerate with the command when this fails

    // The plain dual: the arrangement has no fix-up. Unsmoothed it may be invalid (exit 4, both
    // alike: one validity check), so both are written on request.
    const auto built =
        geode_cli("template " + name + " --no-smooth --no-fixup --write-invalid --format json");
    const auto arranged =
        geode_cli("arrange " + shipped.string() + " --write-invalid --format json");
    REQUIRE((built.code == 0 || built.code == 4));
    REQUIRE(arranged.code == built.code);
    const auto a = nlohmann::json::parse(built.out), b = nlohmann::json::parse(arranged.out);
    CHECK(a["sheets"] == b["sheets"]);
    CHECK(a["intersections"] == b["intersections"]);
    const JsonMesh ma = mesh_of(a), mb = mesh_of(b);
    const auto& pa = ma.dim == 3 ? ma.hex.points : ma.quad.points;
    const auto& pb = mb.dim == 3 ? mb.hex.points : mb.quad.points;
    REQUIRE(pa.size() == pb.size());
    CHECK(ma.hex.hexes.size() == mb.hex.hexes.size());
    CHECK(ma.quad.quads.size() == mb.quad.quads.size());
    CHECK((ma.dim == 3 ? test::find_isomorphism(ma.hex, mb.hex).has_value()
                       : test::find_isomorphism(ma.quad, mb.quad).has_value()));
    for (std::size_t i = 0; i < pa.size(); ++i) CHECK((pa[i] - pb[i]).norm() < 1e-9);
  }
}

// --fixup pillows the plain dual's obstructions as `geode template geode4tri` does: the
// four-triangle specs, whose pinched corners no placement untangles (exit 4 with --smooth
// alone), give a valid template, geode4tri.json the built-in one (isomorphic, the same nodes).
// Skipped in the sanitized build (103 s there): templates/fixup_test.cpp fixes up the same
// four-triangle dual under the sanitizers; this one checks the command's output is the built-in.
TEST_CASE("geode arrange --fixup: the four-triangle specs become valid templates" *
          doctest::skip(test::kSanitized)) {
  const std::filesystem::path specs =
      std::filesystem::path(GEODE_SOURCE_DIR) / "notebooks-data/specs";
  for (const std::string name : {"geode4tri", "geode4tri-domes"}) {
    CAPTURE(name);
    const std::string spec = (specs / (name + ".json")).string();
    CHECK(geode_cli("arrange " + spec + " --smooth --format json").code == 4);
    const auto fixed = geode_cli("arrange " + spec + " --fixup --smooth --format json");
    REQUIRE(fixed.code == 0);
    const auto j = nlohmann::json::parse(fixed.out);
    CHECK(j["obstructions"].empty());
    if (name != "geode4tri") continue;
    const auto built = geode_cli("template geode4tri --format json");
    REQUIRE(built.code == 0);
    const JsonMesh ma = mesh_of(nlohmann::json::parse(built.out)), mb = mesh_of(j);
    REQUIRE(ma.hex.points.size() == mb.hex.points.size());
    CHECK(ma.hex.hexes.size() == mb.hex.hexes.size());
    CHECK(test::find_isomorphism(ma.hex, mb.hex).has_value());
    for (std::size_t i = 0; i < ma.hex.points.size(); ++i)
      CHECK((ma.hex.points[i] - mb.hex.points[i]).norm() < 1e-9);
  }
}

TEST_CASE("geode arrange: --fixup of a 2D spec refused by name; --seed-resolution, same mesh") {
  const std::filesystem::path specs =
      std::filesystem::path(GEODE_SOURCE_DIR) / "notebooks-data/specs";
  const std::string flat = (specs / "geode2d.json").string();
  const auto refused = geode_cli("arrange " + flat + " --fixup", true);
  CHECK(refused.code == 2);
  CHECK(refused.out ==
        "geode: error: " + flat + ": --fixup: only 3D templates are fixed up (this spec is 2D)\n");
  // A finer seeding grid finds the same arrangement: the same mesh, its nodes to rounding.
  const std::string spec = (specs / "geode3d.json").string();
  const auto coarse = geode_cli("arrange " + spec + " --smooth --format json");
  const auto fine = geode_cli("arrange " + spec + " --smooth --format json --seed-resolution 48");
  REQUIRE(coarse.code == 0);
  REQUIRE(fine.code == 0);
  const JsonMesh a = mesh_of(nlohmann::json::parse(coarse.out)),
                 b = mesh_of(nlohmann::json::parse(fine.out));
  CHECK(a.hex.hexes == b.hex.hexes);
  REQUIRE(a.hex.points.size() == b.hex.points.size());
  for (std::size_t i = 0; i < a.hex.points.size(); ++i)
    CHECK((a.hex.points[i] - b.hex.points[i]).norm() < 1e-9);
  CHECK(geode_cli("arrange " + spec + " --seed-resolution 3", true).code == 2);
}

TEST_CASE("geode arrange: the README's examples, the pillowed hex and the pillowed quad") {
  const auto specs = std::filesystem::path(GEODE_SOURCE_DIR) / "notebooks-data/specs";
  const auto out = temp_path("pillow-out.json");
  const auto r = geode_cli("arrange " + (specs / "pillow.json").string() +
                           " --smooth --format json -o " + out.string());
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(slurp(out));
  CHECK(j["hexes"].size() == 7);  // three planes and a sphere around their crossing
  CHECK(j["nodes"].size() == 16);
  CHECK(j["sheets"].size() == 4);
  CHECK(j["sheets"][3]["kind"] == "sphere");
  CHECK(j["template"] == "pillow");
  std::filesystem::remove(out);

  const auto q = geode_cli("arrange " + (specs / "pillow2d.json").string() + " --format json");
  REQUIRE(q.code == 0);
  CHECK(nlohmann::json::parse(q.out)["quads"].size() == 5);  // two lines and a circle
  // Its sweep block grows the circle through the rectangle's long sides: 5 quads, a tangency, 3.
  const auto s = geode_cli("study interleave --spec " + (specs / "pillow2d.json").string());
  REQUIRE(s.code == 0);
  CHECK(s.out.find("valid,5,V1,1,\"\",0.4\n") != std::string::npos);
  CHECK(s.out.find("error,0,E1,,\"arrangement: sheets 'a', 'c' meet on the domain boundary") !=
        std::string::npos);
  CHECK(s.out.find("valid,3,V2,1,\"\",0.6\n") != std::string::npos);
  // The summary names each class's example by its swept values.
  const auto summary = temp_path("pillow2d-summary.csv");
  REQUIRE(geode_cli("study interleave --quiet --spec " + (specs / "pillow2d.json").string() +
                    " --summary " + summary.string())
              .code == 0);
  const std::string table = slurp(summary);
  CHECK(table.find(",usable,\"example_sheets[2].circle.radius\"\n") != std::string::npos);
  CHECK(table.find(",1,0.6\n") != std::string::npos);  // V2, usable, first seen at radius 0.6
  std::filesystem::remove(summary);
}

TEST_CASE("geode arrange: bad specs exit 2 naming the JSON path, non-dualizing ones exit 3") {
  const auto spec = temp_path("bad.json");
  const auto out = temp_path("bad-out.json");
  struct Case {
    std::string what;
    std::string text;
    int code;
    const char* message;
  };
  std::vector<Case> cases = {
      {"zero normal",
       three_planes_and(R"(, {"name": "w", "plane": {"point": [0, 0, 0], "normal": [0, 0, 0]}})"),
       2, ": sheets[3].plane.normal: must not be zero"},
      {"too large for a double",
       three_planes_and(
           R"(, {"name": "s", "sphere": {"center": [0.5, 0.5, 0.5], "radius": 1e999}})"),
       2, ": not valid JSON: [json.exception.out_of_range.406] number overflow"},
      {"NaN is not JSON",
       three_planes_and(R"(, {"name": "s", "sphere": {"center": [0.5, 0.5, 0.5], "radius": NaN}})"),
       2, ": not valid JSON"},
      {"wrong dim", R"({"dim": 4, "domain": {"box": [[0, 0], [1, 1]]}, "sheets": []})", 2,
       ": dim: must be 2 or 3"},
      {"sphere through the box faces' crossing",
       three_planes_and(R"(, {"name": "s", "sphere": {"center": [0.5, 0.5, 0.5], "radius": 0.5}})"),
       3, "arrangement: sheets 'x', 'y', 's' meet on the domain boundary"},
  };
  // One sheet over the limit (documented in docs/specs.md): refused while the JSON is parsed.
  std::string many;
  for (int i = 0; i < 254; ++i)
    many += R"(, {"name": "p)" + std::to_string(i) + R"(", "plane": {"point": [0.)" +
            std::to_string(100 + i) + R"(, 0, 0], "normal": [1, 0, 0]}})";
  cases.push_back({"257 sheets", three_planes_and(many), 2, ": sheets: more than 256 sheets"});
  for (const auto& c : cases) {
    CAPTURE(c.what);
    write_text(spec, c.text);
    const auto r =
        geode_cli("arrange " + spec.string() + " --format json -o " + out.string(), true);
    CHECK(r.code == c.code);
    CHECK(r.out.find(c.message) != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    CHECK_FALSE(std::filesystem::exists(out));
  }
  CHECK(geode_cli("arrange " + temp_path("missing.json").string()).code == 2);
  std::filesystem::remove(spec);
}

// Skipped in the sanitized build (55 s there): templates/study_test.cpp runs the study's pushes
// under the sanitizers; this one compares two command lines' tables.
TEST_CASE(
    "geode study interleave --spec: a spec swept by path classifies as the built-in study does" *
    doctest::skip(test::kSanitized)) {
  const std::string shipped =
      (std::filesystem::path(GEODE_SOURCE_DIR) / "notebooks-data/specs/geode3d.json").string();
  const auto swept = geode_cli("study interleave --spec " + shipped +
                               " --sweep push.high_roof=0.75,0.85 --sweep push.low_roof=0.6:0.8:2");
  const auto builtin =
      geode_cli("study interleave --high 0.75 0.85 --low 0.6 0.8 --depth 0.9 --radius 0.6");
  REQUIRE(swept.code == 0);
  REQUIRE(builtin.code == 0);
  // The same rows (0.75 / 0.8 is skipped by both: low above high), plus the swept columns.
  std::istringstream a(swept.out), b(builtin.out);
  std::string la, lb;
  int rows = 0;
  while (std::getline(b, lb)) {
    REQUIRE(std::getline(a, la));
    if (rows++ == 0) {
      CHECK(la == lb + R"(,"push.high_roof","push.low_roof")");
      continue;
    }
    CHECK(la.rfind(lb + ",", 0) == 0);
  }
  CHECK(rows == 4);

  // A sheet's radius swept in a plain spec: the pillow, then a sphere through the box's faces.
  const auto spec = temp_path("sweep.json");
  write_text(spec,
             R"({"dim": 3, "domain": {"box": [[0, 0, 0], [1, 1, 1]]},
                       "sweep": {"sheets[3].sphere.radius": [0.3, 0.5]}, )" +
                 kPlanes +
                 R"(, {"name": "s", "sphere": {"center": [0.5, 0.5, 0.5], "radius": 0.3}}]})");
  const auto r = geode_cli("study interleave --spec " + spec.string());
  REQUIRE(r.code == 0);
  CHECK(r.out.find("valid,7,V1,1,\"\",0.3\n") != std::string::npos);
  CHECK(r.out.find("error,0,E1,,") != std::string::npos);
  CHECK(geode_cli("study interleave --spec " + spec.string() +
                  " --sweep sheets[3].sphere.radios=1:2:2")
            .code == 2);
  std::filesystem::remove(spec);
}
