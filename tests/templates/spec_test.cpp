// Arrangements as files (templates/spec.hpp): known-answer specs, every shape against its
// closed form, the built-in templates through their specs, and bad specs named by JSON path.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include <geode/primal/errors.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/refine.hpp>
#include <geode/templates/spec.hpp>
#include "support/isomorphism.hpp"

using namespace geode;
using nlohmann::json;
using primal::Point;

namespace {

json plane(const char* name, Point p, Point n) {
  return {{"name", name},
          {"plane", {{"point", {p.x(), p.y(), p.z()}}, {"normal", {n.x(), n.y(), n.z()}}}}};
}

// The unit box cut by the three mid planes, plus `extra` sheets.
json three_planes(const std::vector<json>& extra = {}) {
  json j = {{"dim", 3}, {"domain", {{"box", {{0, 0, 0}, {1, 1, 1}}}}}};
  j["sheets"] = {plane("x", {0.5, 0.5, 0.5}, {1, 0, 0}), plane("y", {0.5, 0.5, 0.5}, {0, 1, 0}),
                 plane("z", {0.5, 0.5, 0.5}, {0, 0, 1})};
  for (const auto& e : extra) j["sheets"].push_back(e);
  return j;
}

templates::Template build(const json& j) {
  return templates::build_template(templates::parse_spec(j, "test.json"));
}

std::string error_of(const json& j) {
  try {
    templates::parse_spec(j, "spec.json");
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("spec: three planes give one hex") {
  const auto t = build(three_planes());
  CHECK(t.hex.hexes.size() == 1);
  CHECK(t.hex.points.size() == 8);
  CHECK(primal::check_validity(t.hex).ok());
}

TEST_CASE("spec: three planes and a sphere around their crossing give the pillowed hex of 7") {
  const json sphere = {{"name", "s"}, {"sphere", {{"center", {0.5, 0.5, 0.5}}, {"radius", 0.3}}}};
  auto t = build(three_planes({sphere}));
  CHECK(t.hex.hexes.size() == 7);  // the centre hex, and one over each of its 6 faces
  CHECK(t.hex.points.size() == 16);
  templates::smooth_template(t, true);  // the first guess need not be untangled
  CHECK(primal::check_validity(t.hex).ok());
  // Pillowing: every hex but one has the sphere among its sheets.
  int with_sphere = 0;
  for (const auto& s : t.element_sheets) with_sphere += s.back() == 3 ? 1 : 0;
  CHECK(with_sphere == 6);
}

TEST_CASE("spec: two lines and a circle in a rectangle give the pillowed quad of 5") {
  const json j = {{"dim", 2},
                  {"domain", {{"box", {{0, 0}, {2, 1}}}}},
                  {"sheets",
                   {{{"name", "a"}, {"line", {{"point", {1, 0.5}}, {"normal", {1, 0}}}}},
                    {{"name", "b"}, {"line", {{"point", {1, 0.5}}, {"normal", {0, 1}}}}},
                    {{"name", "c"}, {"circle", {{"center", {1, 0.5}}, {"radius", 0.3}}}}}}};
  auto t = build(j);
  CHECK(t.dim == 2);
  CHECK(t.quad.quads.size() == 5);
  CHECK(t.quad.points.size() == 8);
  templates::smooth_template(t, true);
  CHECK(primal::check_validity(t.quad).ok());
}

TEST_CASE("spec: each shape is the field it documents") {
  const json j = json::parse(R"({
    "dim": 3,
    "domain": {"box": [[-2, -2, -2], [2, 2, 2]]},
    "sheets": [
      {"name": "e", "ellipsoid": {"center": [0, 0, 0], "radii": [1, 0.5, 0.25]}},
      {"name": "r", "ellipsoid": {"center": [0, 0, 0], "radii": [1, 0.5, 0.25], "axes": [[0, 1, 0], [1, 0, 0]]}},
      {"name": "c", "cylinder": {"point": [0, 0, 0], "axis": [0, 0, 1], "radius": 0.5}},
      {"name": "q", "superquadric": {"center": [0, 0, 0], "radii": [1, 1, 1], "exponent": 4}},
      {"name": "t", "tunnel": {"point": [0, -1, 0], "along": [0, 0, 1], "half_width": 0.5, "height": 2}},
      {"name": "d", "dome": {"vertex": [0, 1, 0], "radius": 0.5, "depth": 0.25}},
      {"name": "u", "union": [{"sphere": {"center": [-1, 0, 0], "radius": 0.5}},
                              {"sphere": {"center": [1, 0, 0], "radius": 0.5}}]},
      {"name": "i", "intersection": [{"sphere": {"center": [-0.2, 0, 0], "radius": 0.5}},
                                     {"sphere": {"center": [0.2, 0, 0], "radius": 0.5}}]},
      {"name": "o", "offset": {"of": {"plane": {"point": [0, 0, 0], "normal": [0, 0, 2]}}, "by": 0.5}},
      {"name": "f", "kind": "flipped", "scaled": {"of": {"plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}}, "by": -1}}
    ]})");
  const auto spec = templates::parse_spec(j, "shapes.json");
  const auto s = templates::spec_sheets(spec);
  REQUIRE(s.size() == 10);
  const auto f = [&](std::size_t i, Point x) { return s[i].field(x); };
  CHECK(f(0, Point(0.5, 0, 0)) == doctest::Approx(0.25 - 1));
  CHECK(f(0, Point(0, 0, 0.25)) == doctest::Approx(0.0));
  CHECK(f(1, Point(0, 1, 0)) == doctest::Approx(0.0));    // rotated: the long axis along y
  CHECK(f(2, Point(0.5, 0, 7)) == doctest::Approx(0.0));  // infinite along its axis
  CHECK(f(3, Point(0.5, 0.5, 0)) == doctest::Approx(2 * 0.0625 - 1));
  CHECK(f(4, Point(0.5, -1, 3)) == doctest::Approx(0.0));  // the tunnel's foot
  CHECK(f(4, Point(0, 1, 0)) == doctest::Approx(0.0));     // its roof
  CHECK(f(5, Point(0, 0.75, 0)) == doctest::Approx(0.0));  // the dome's depth below its vertex
  CHECK(f(5, Point(0.5, 1, 0)) == doctest::Approx(0.0));
  CHECK(f(6, Point(-1, 0, 0)) < 0);
  CHECK(f(6, Point(1, 0, 0)) < 0);
  CHECK(f(6, Point(0, 0, 0)) > 0);
  CHECK(f(7, Point(0, 0, 0)) < 0);
  CHECK(f(7, Point(-0.5, 0, 0)) > 0);
  CHECK(f(8, Point(0, 0, 0.5)) == doctest::Approx(0.0));
  CHECK(f(9, Point(1, 0, 0)) == doctest::Approx(-1.0));
  CHECK(s[9].kind == "flipped");
  CHECK(s[0].kind == "ellipsoid");
  // Written and read back: the same spec.
  const json written = templates::spec_json(spec);
  CHECK(templates::spec_json(templates::parse_spec(json::parse(templates::format_spec(written)),
                                                   "again")) == written);
}

TEST_CASE("spec: the built-in templates are specs, and read back to the same template") {
  for (int variant = 0; variant < 3; ++variant) {
    CAPTURE(variant);
    templates::GeodeOptions o;
    if (variant == 2) o.split = templates::TopSplit::kFourTriangles;
    const int dim = variant == 1 ? 2 : 3;
    const auto text = templates::format_spec(templates::spec_json(templates::geode_spec(o, dim)));
    const auto read = templates::parse_spec(json::parse(text), "geode.json");
    const auto a = dim == 3 ? templates::build_geode3d(o) : templates::build_geode2d(o);
    const auto b = templates::build_template(read);
    if (dim == 3) {
      CHECK(a.hex.hexes == b.hex.hexes);
      REQUIRE(a.hex.points.size() == b.hex.points.size());
      for (std::size_t i = 0; i < a.hex.points.size(); ++i)
        CHECK((a.hex.points[i] - b.hex.points[i]).norm() < 1e-9);
    } else {
      CHECK(a.quad.quads == b.quad.quads);
      CHECK(a.quad.quads.size() == 5);
    }
    CHECK(a.element_sheets == b.element_sheets);
  }
}

TEST_CASE("spec: the geode's tunnels and domes written out as shapes give the geode") {
  // The completion's sheets, each written as the tunnel or dome shape it is, in the 24 x 14 x 24
  // box: the arrangement is the geode's (26 hexes, isomorphic).
  const templates::GeodeOptions o;
  const auto G = templates::geode_arrangement(o, 3);
  const auto domes =
      templates::complete_domes(G.tet_side, 1.0, o.push.dome_depth, o.push.dome_radius);
  json j = {{"dim", 3}, {"domain", {{"box", {{-12, -7, -12}, {12, 7, 12}}}}}};
  j["sheets"].push_back(
      {{"name", "tunnel x"},
       {"tunnel",
        {{"point", {0, -7, 0}}, {"along", {1, 0, 0}}, {"half_width", 6}, {"height", 0.85 * 14}}}});
  j["sheets"].push_back(
      {{"name", "tunnel z"},
       {"tunnel",
        {{"point", {0, -7, 0}}, {"along", {0, 0, 1}}, {"half_width", 6}, {"height", 0.6 * 14}}}});
  for (const auto& d : domes) {
    const Point v = G.tet_side.points[primal::index_cast<std::size_t>(d.vertex)];
    j["sheets"].push_back({{"name", "dome " + std::to_string(d.vertex)},
                           {"dome",
                            {{"vertex", {12 * v.x(), 7, 12 * v.z()}},
                             {"radius", 12 * d.radius},
                             {"depth", 0.9 * 14}}}});
  }
  const auto t = build(j);
  const auto geode = templates::build_geode3d(o);
  CHECK(t.hex.hexes.size() == 26);
  CHECK(test::find_isomorphism(t.hex, geode.hex).has_value());
  CHECK(t.checks.ok());  // the paper's conditions read the tunnel and dome kinds
}

TEST_CASE("spec: hexahedral and quadrilateral domains") {
  json j = three_planes();
  j["domain"] = {{"hexahedron",
                  {{0, 0, 0},
                   {1, 0, 0},
                   {1, 1, 0},
                   {0, 1, 0},
                   {0, 0, 1},
                   {1.2, 0, 1},
                   {1.2, 1, 1},
                   {0, 1, 1}}}};
  const auto spec = templates::parse_spec(j, "hex.json");
  REQUIRE(spec.domain.corners.has_value());
  CHECK(templates::build_template(spec).hex.hexes.size() == 1);
  CHECK(templates::spec_json(templates::parse_spec(templates::spec_json(spec), "again")) ==
        templates::spec_json(spec));
  j["domain"] = {{"hexahedron",
                  {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}}}};
  CHECK(error_of(j).find("spec.json: domain.hexahedron: must be 8 corners") == 0);
  const json q = {{"dim", 2},
                  {"domain", {{"quadrilateral", {{0, 0}, {1, 0}, {1.3, 1}, {0, 1}}}}},
                  {"sheets",
                   {{{"name", "a"}, {"line", {{"point", {0.5, 0.5}}, {"normal", {1, 0}}}}},
                    {{"name", "b"}, {"line", {{"point", {0.5, 0.5}}, {"normal", {0, 1}}}}}}}};
  CHECK(build(q).quad.quads.size() == 1);
}

TEST_CASE("spec: bad specs name the file, the JSON path and the sheet") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const json sphere = {{"name", "s"}, {"sphere", {{"center", {0.5, 0.5, 0.5}}, {"radius", 0.3}}}};
  struct Case {
    const char* what;
    json spec;
    const char* message;
  };
  json unknown = three_planes(), missing = three_planes(), nan_radius = three_planes({sphere}),
       zero_normal = three_planes(), wrong_dim = three_planes(), negative = three_planes({sphere}),
       two_d_shape = three_planes(), typo = three_planes(), no_dim = three_planes(),
       duplicate = three_planes();
  unknown["sheets"][1] = {{"name", "y"}, {"sphear", {{"center", {0, 0, 0}}, {"radius", 1}}}};
  missing["sheets"][2]["plane"].erase("normal");
  nan_radius["sheets"][3]["sphere"]["radius"] = nan;
  zero_normal["sheets"][0]["plane"]["normal"] = {0, 0, 0};
  wrong_dim["sheets"][2]["plane"]["point"] = {0.5, 0.5};
  negative["sheets"][3]["sphere"]["radius"] = -1;
  two_d_shape["sheets"][0] = {{"name", "c"}, {"circle", {{"center", {0, 0}}, {"radius", 1}}}};
  typo["domian"] = typo["domain"];
  json nested = three_planes();
  nested["sheets"][0] = json::parse(
      R"({"name": "u", "union": [{"sphere": {"center": [0, 0, 0], "radius": 1}, "centre": 1},
                                                             {"plane": {"point": [0, 0, 0], "normal": [1, 0, 0]}}]})");
  no_dim.erase("dim");
  duplicate["sheets"][1]["name"] = "x";
  const std::vector<Case> cases = {
      {"unknown sheet kind", unknown, "spec.json: sheets[1].sphear: unknown key (sheet 'y')"},
      {"missing field", missing, "spec.json: sheets[2].plane.normal: missing"},
      {"NaN", nan_radius, "spec.json: sheets[3].sphere.radius: must be finite"},
      {"zero normal", zero_normal, "spec.json: sheets[0].plane.normal: must not be zero"},
      {"wrong dim", wrong_dim,
       "spec.json: sheets[2].plane.point: must be 3 numbers (the spec's dim)"},
      {"negative radius", negative, "spec.json: sheets[3].sphere.radius: must be > 0"},
      {"2D shape in 3D", two_d_shape,
       "spec.json: sheets[0].circle: is a 2D shape; the spec's dim is 3"},
      {"unknown top-level key", typo, "spec.json: domian: unknown key"},
      {"no dim", no_dim, "spec.json: dim: missing"},
      {"unknown key in a nested shape", nested,
       "spec.json: sheets[0].union[0].centre: unknown key"},
      {"duplicate name", duplicate, "spec.json: sheets[1] (x): a second sheet of this name"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.what);
    CHECK(error_of(c.spec) == c.message);
  }
}

TEST_CASE("spec: sweeps set numbers by path") {
  const auto a = templates::parse_sweep_option("push.high_roof=0.4:0.6:5");
  CHECK(a.path == "push.high_roof");
  REQUIRE(a.values.size() == 5);
  CHECK(a.values[1] == doctest::Approx(0.45));
  CHECK(a.values[4] == doctest::Approx(0.6));
  CHECK(templates::parse_sweep_option("sheets[3].sphere.radius=0.1,0.2").values ==
        std::vector<double>{0.1, 0.2});
  CHECK_THROWS_AS(templates::parse_sweep_option("push.high_roof=0.4:x:5"), InvalidInput);
  json j =
      three_planes({{{"name", "s"}, {"sphere", {{"center", {0.5, 0.5, 0.5}}, {"radius", 0.3}}}}});
  templates::set_spec_number(j, "sheets[3].sphere.radius", 0.2, "s.json");
  CHECK(j["sheets"][3]["sphere"]["radius"] == 0.2);
  CHECK_THROWS_WITH_AS(templates::set_spec_number(j, "sheets[3].sphere.centre", 0.2, "s.json"),
                       "s.json: sweep: 'sheets[3].sphere.centre' is not a number in the spec",
                       InvalidInput);
  j["sweep"] = {{"sheets[3].sphere.radius", {{"from", 0.1}, {"to", 0.3}, {"count", 3}}},
                {"sheets[0].plane.point[0]", {0.4, 0.6}}};
  const auto axes = templates::spec_sweep(j, "s.json");
  REQUIRE(axes.size() == 2);
  CHECK(axes[1].values.size() == 3);
  j["sweep"]["sheets[9].plane.point[0]"] = {0.5};
  CHECK_THROWS_AS(templates::parse_spec(j, "s.json"), InvalidInput);
}

TEST_CASE(
    "spec: the wider dome family's values are read, written back, and named by JSON path when "
    "bad") {
  templates::GeodeOptions o;
  o.split = templates::TopSplit::kFourTriangles;
  o.push.dome_exponent = 3;
  o.push.centre_exponent = 1.5;
  o.push.dome_offset = 0.25;
  o.push.centre_offset = {0.1, -0.2};
  const json written = templates::spec_json(templates::geode_spec(o, 3));
  CHECK(written["push"]["dome_exponent"] == 3.0);
  CHECK(written["push"]["centre_offset"] == json{0.1, -0.2});
  const auto read =
      templates::parse_spec(json::parse(templates::format_spec(written)), "domes.json");
  REQUIRE(read.completion.has_value());
  CHECK(read.completion->push.centre_exponent == 1.5);
  CHECK(read.completion->push.dome_offset == 0.25);
  CHECK(read.completion->push.centre_offset[1] == -0.2);
  // Defaults are not written: the built-in specs keep their text.
  CHECK_FALSE(
      templates::spec_json(templates::geode_spec(templates::GeodeOptions{}, 3))["push"].contains(
          "dome_exponent"));

  struct Case {
    const char* key;
    json value;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"dome_exponent", 0.5,
       "domes.json: push.dome_exponent: dome exponent must be in [1, 20] (2: spheroids)"},
      {"dome_exponent", "2", "domes.json: push.dome_exponent: must be a number"},
      {"centre_exponent", 30,
       "domes.json: push.centre_exponent: centre dome exponent must be 0 (as the corner domes) or "
       "in [1, 20]"},
      {"dome_offset", -0.1,
       "domes.json: push.dome_offset: dome offset must be in [0, 1) (a fraction of the way to the "
       "tet side's centre)"},
      {"centre_offset", json{0.0, 1.0},
       "domes.json: push.centre_offset[1]: centre dome offsets must be in (-1, 1) (fractions of "
       "the half-width)"},
      {"centre_offset", json{0.5},
       "domes.json: push.centre_offset: must be [x, z] (fractions of the half-width)"},
      {"centre_offset", json{0.5, "a"}, "domes.json: push.centre_offset[1]: must be a number"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.key);
    json j = written;
    j["push"][c.key] = c.value;
    std::string message = "no error";
    try {
      templates::parse_spec(j, "domes.json");
    } catch (const InvalidInput& e) {
      message = e.what();
    }
    CHECK(message == c.message);
  }
}

TEST_CASE(
    "spec: a faces block prescribes boundary cells as given, and a different boundary is an "
    "error") {
  // Three mid planes of the unit box: one hex whose bottom face is the box's bottom.
  json j = three_planes();
  j["faces"]["bottom"] = {{"points", {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}},
                          {"cells", {{0, 1, 2, 3}}}};
  const auto spec = templates::parse_spec(j, "faces.json");
  REQUIRE(spec.bottom_face.has_value());
  CHECK_FALSE(spec.top_face.has_value());
  CHECK(templates::spec_json(spec)["faces"] == j["faces"]);
  const auto t = templates::build_template(spec);
  REQUIRE(t.hex.hexes.size() == 1);
  int on_bottom = 0;
  for (const auto& p : t.hex.points) on_bottom += p.y() == 0.0;
  CHECK(on_bottom == 4);

  // Two quads where the dual has one: the boundary is not the prescribed one.
  json two = three_planes();
  two["faces"]["bottom"] = {
      {"points", {{0, 0, 0}, {0.5, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0.5, 0, 1}, {0, 0, 1}}},
      {"cells", {{0, 1, 4, 5}, {1, 2, 3, 4}}}};
  CHECK_THROWS_AS(build(two), TopologyError);
  try {
    build(two);
  } catch (const TopologyError& e) {
    CHECK(std::string(e.what()).find("faces.bottom") != std::string::npos);
  }

  // Part of the cells (each a face of the dual, every node given) or one given twice: not
  // exactly the dual's cells there (a hunt's refine3 spec with 1 of its 9 bottom quads built).
  const json refine = templates::spec_json(templates::refine_spec({}, 3));
  REQUIRE(refine["faces"]["bottom"]["cells"].size() == 9);
  json part = refine, twice = refine;
  part["faces"]["bottom"]["cells"] = {refine["faces"]["bottom"]["cells"][0]};
  twice["faces"]["bottom"]["cells"][1] = refine["faces"]["bottom"]["cells"][0];
  CHECK_NOTHROW(build(refine));
  CHECK_THROWS_WITH_AS(build(part),
                       doctest::Contains("faces.bottom: 1 cells given, the template has 9 there"),
                       TopologyError);
  CHECK_THROWS_WITH_AS(build(twice), doctest::Contains("a faces.bottom cell is given twice"),
                       TopologyError);

  json triangle = three_planes(), off_face = three_planes(),
       with_completion =
           json::parse(templates::format_spec(templates::spec_json(templates::geode_spec({}, 3))));
  triangle["faces"]["top"] = {{"points", {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}}},
                              {"cells", {{0, 1, 2}}}};
  off_face["faces"]["bottom"] = {{"points", {{0, 0.5, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}}},
                                 {"cells", {{0, 1, 2, 3}}}};
  with_completion["faces"] = j["faces"];
  CHECK(error_of(triangle) == "spec.json: faces.top.cells[0]: must be 4 point indices (a quad)");
  CHECK(error_of(off_face) ==
        "spec.json: faces.bottom.points[0]: must lie on the domain's low-y face (y = 0.000000)");
  CHECK(error_of(with_completion) ==
        "spec.json: faces: a completion block prescribes both faces already");
}
