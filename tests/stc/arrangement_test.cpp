// The arrangement engine: planes dualize to structured grids, the result does not depend on
// the sampling resolution or step, and configurations out of general position are
// diagnosed, never meshed.
#include <doctest/doctest.h>

#include <string>

#include <geode/primal/errors.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/templates/geode.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using stc::Point;

namespace {

stc::Sheet plane(int axis, double c, const std::string& name) {
  return {name, [axis, c](const Point& x) { return x[axis] - c; }, "plane"};
}

// Planes x = 0.2, 0.5, 0.7 (tilted a little so nothing is axis-aligned by accident),
// y = 0.3, 0.6, z = 0.4, 0.8 in the unit box.
std::vector<stc::Sheet> plane_family() {
  std::vector<stc::Sheet> s;
  for (double c : {0.2, 0.5, 0.7})
    s.push_back({"x", [c](const Point& x) { return x[0] - c + 0.05 * x[1]; }, "plane"});
  for (double c : {0.3, 0.6})
    s.push_back({"y", [c](const Point& x) { return x[1] - c - 0.04 * x[2]; }, "plane"});
  for (double c : {0.4, 0.8})
    s.push_back({"z", [c](const Point& x) { return x[2] - c + 0.03 * x[0]; }, "plane"});
  return s;
}

std::string diagnosis(const std::vector<stc::Sheet>& s, const stc::Domain& d) {
  try {
    stc::dualize(stc::compute_arrangement(s, d));
  } catch (const TopologyError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("arrangement: planes dualize to the structured grid, and back") {
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  const auto D = stc::dualize(stc::compute_arrangement(plane_family(), box));
  CHECK(D.hex.hexes.size() == 12);
  CHECK(D.hex.points.size() == 36);
  const auto grid = test::structured_hex_grid(3, 2, 2);
  CHECK(test::find_isomorphism(D.hex, grid).has_value());
  // Round trip: the dual of the result has the 3 + 2 + 2 sheets we started from.
  CHECK(stc::mesh_dual(D.hex).sheets.size() == 7);
  // Every hex positively oriented by construction: its centre Jacobian is positive at the
  // first-guess positions of a planar arrangement.
  for (const auto& h : D.hex.hexes) {
    const Point a = D.hex.points[h[1]] - D.hex.points[h[0]],
                b = D.hex.points[h[3]] - D.hex.points[h[0]],
                c = D.hex.points[h[4]] - D.hex.points[h[0]];
    CHECK(a.cross(b).dot(c) > 0);
  }
}

TEST_CASE("arrangement: lines in a rectangle dualize to the quad grid") {
  const stc::Domain rect{Point(0, 0, 0), Point(2, 1, 0), 2};
  std::vector<stc::Sheet> s;
  for (double c : {0.3, 0.9, 1.5, 1.8}) s.push_back(plane(0, c, "x"));
  for (double c : {0.25, 0.5, 0.75})
    s.push_back({"y", [c](const Point& x) { return x[1] - c - 0.05 * x[0]; }, "line"});
  const auto D = stc::dualize(stc::compute_arrangement(s, rect));
  CHECK(D.quad.quads.size() == 12);
  CHECK(test::find_isomorphism(D.quad, test::structured_quad_grid(4, 3)).has_value());
}

TEST_CASE("arrangement: the geode's mesh does not depend on sampling resolution or step") {
  // Reference: default options, through the template builder's own sheets.
  const auto ref = templates::build_geode3d({});
  struct Case {
    int resolution;
    double step;
  };
  for (const Case c : {Case{12, 0.004}, Case{16, 0.004}, Case{32, 0.004}, Case{48, 0.004},
                       Case{24, 0.002}, Case{24, 0.008}}) {
    CAPTURE(c.resolution);
    CAPTURE(c.step);
    templates::GeodeOptions o;
    o.arrangement.seed_resolution = c.resolution;
    o.arrangement.step = c.step;
    const auto T = templates::build_geode3d(o);
    CHECK(T.hex.hexes == ref.hex.hexes);  // same numbering, not just isomorphic
    REQUIRE(T.hex.points.size() == ref.hex.points.size());
    for (std::size_t i = 0; i < T.hex.points.size(); ++i)
      CHECK((T.hex.points[i] - ref.hex.points[i]).norm() < 1e-6);
  }
}

TEST_CASE("arrangement: configurations out of general position are diagnosed") {
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  SUBCASE("four sheets through one point") {
    auto s = plane_family();
    // A fourth plane through the vertex where x = 0.5, y = 0.6 and z = 0.4 meet: a combination
    // of their fields vanishes there.
    s.push_back({"slanted",
                 [f0 = s[1].field, f1 = s[4].field, f2 = s[5].field](const Point& x) {
                   return f0(x) + 0.5 * f1(x) + 0.7 * f2(x);
                 },
                 "plane"});
    CHECK(diagnosis(s, box).find("pass through one point") != std::string::npos);
  }
  SUBCASE("three sheets meeting tangentially") {
    // f's gradient at (0.5, 0.4, 0.5) is (1, 0, 1): in the span of the two planes' normals.
    std::vector<stc::Sheet> s{plane(0, 0.5, "x"),
                              plane(2, 0.5, "z"),
                              plane(1, 0.8, "y"),
                              {"cubic",
                               [](const Point& x) {
                                 const double t = x[1] - 0.4;
                                 return (x[0] - 0.5) + (x[2] - 0.5) + t * t * t;
                               },
                               "cubic"}};
    CHECK(diagnosis(s, box).find("tangen") != std::string::npos);
  }
  SUBCASE("a vertex on the boundary") {
    std::vector<stc::Sheet> s{
        plane(0, 0.5, "x"),
        plane(1, 0.5, "y"),
        {"z", [](const Point& x) { return x[2] - 0.5 * (x[0] + x[1]) + 0.5; }, "plane"}};
    // z = 0.5 (x + y) - 0.5 meets x = y = 0.5 at z = 0: on the bottom face.
    CHECK(diagnosis(s, box).find("meet on the domain boundary") != std::string::npos);
  }
  SUBCASE("a curve with no vertex") {
    std::vector<stc::Sheet> s{plane(0, 0.5, "x"), plane(1, 0.5, "y"), plane(0, 0.7, "x2")};
    CHECK(diagnosis(s, box).find("no vertex") != std::string::npos);
  }
  SUBCASE("bad domain") {
    CHECK_THROWS_AS(
        stc::compute_arrangement(plane_family(), stc::Domain{Point(0, 0, 0), Point(1, 0, 1), 3}),
        InvalidInput);
  }
}

TEST_CASE("arrangement: sheets composed with the field algebra") {
  // x = 0.2 and x = 0.7 as one sheet (the union of the half-spaces x < 0.2 and x > 0.7), x = 0.5
  // as an offset plane with its sides flipped; y and z planes as before: still the 3 x 2 x 2 grid.
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  auto s = plane_family();
  const stc::Field left = [](const Point& x) { return x[0] - 0.2; };
  const stc::Field right = [](const Point& x) { return 0.7 - x[0]; };
  std::vector<stc::Sheet> sheets{
      {"x outer pair", stc::field_union(left, right), "union"},
      {"x middle",
       stc::field_scaled(stc::field_offset([](const Point& x) { return x[0]; }, 0.5), -1.0),
       "offset"}};
  sheets.insert(sheets.end(), s.begin() + 3, s.end());  // the y and z planes
  const auto D = stc::dualize(stc::compute_arrangement(sheets, box));
  CHECK(D.hex.hexes.size() == 12);
  CHECK(test::find_isomorphism(D.hex, test::structured_hex_grid(3, 2, 2)).has_value());
  // The intersection of the two half-spaces is the slab between the planes: the same zero set.
  sheets[0].field = stc::field_intersection([](const Point& x) { return 0.2 - x[0]; },
                                            [](const Point& x) { return x[0] - 0.7; });
  CHECK(stc::dualize(stc::compute_arrangement(sheets, box)).hex.hexes.size() == 12);
}

// The octant samples at a vertex stepped along the raw gradients, nearly along the steeper
// sheet: on boxes 1e-4 across refine3's arch put them on its other side ("one region joins
// octants of different sign vectors").
TEST_CASE("arrangement: the result does not depend on the domain's scale or the fields' scaling") {
  // refine3-2d's sheets: a unit-gradient plane and line meet an arch whose gradient grows as
  // 1 / size. Same regions at every size in the supported range.
  for (double s : {1e6, 1.0, 1e-3, 1e-4, 1e-6}) {
    CAPTURE(s);
    const double a = s / 3, h = 0.75 * s, foot = -0.5 * s, layer = foot + 0.35 * s;
    std::vector<stc::Sheet> sh{{"tunnel",
                                [=](const Point& x) {
                                  const double u = x.x() / a, v = (x.y() - foot) / h;
                                  return u * u + v * v - 1.0;
                                },
                                "tunnel"},
                               plane(0, 0.0, "middle"),
                               plane(1, layer, "layer")};
    const auto A = stc::compute_arrangement(
        sh, stc::Domain(Point(-s / 2, -s / 2, 0), Point(s / 2, s / 2, 0), 2));
    CHECK(A.vertices.size() == 4);
    CHECK(A.region_count == 8);
    CHECK(stc::dualize(A).quad.quads.size() == 4);
  }
}

// A sheet on which no curve is traced (inside one octant, or across the box's corners only)
// vanished from the dual without a word: exit 0, one sheet fewer.
TEST_CASE("arrangement: a sheet that meets no other sheet is refused by name") {
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  auto sphere = [](Point c, double r) {
    return stc::Sheet{"s", [c, r](const Point& x) { return (x - c).squaredNorm() / (r * r) - 1; },
                      "sphere"};
  };
  std::vector<stc::Sheet> planes{plane(0, 0.5, "x"), plane(1, 0.5, "y"), plane(2, 0.5, "z")};
  for (const auto& s : {sphere(Point(0.25, 0.25, 0.25), 0.1),  // inside one octant
                        sphere(Point(0.5, 0.5, 0.5), 0.8)}) {  // cuts only the box's corners
    auto all = planes;
    all.push_back(s);
    const std::string d = diagnosis(all, box);
    CHECK(d.find("sheet 's'") != std::string::npos);
    CHECK(d.find("meets no other sheet") != std::string::npos);
  }
  // A sheet wholly outside the domain still changes nothing.
  auto all = planes;
  all.push_back(sphere(Point(3, 3, 3), 0.5));
  CHECK(stc::dualize(stc::compute_arrangement(all, box)).hex.hexes.size() == 1);
}

// One sheet of two pieces: a sphere around the centre, crossed by the three planes, and a small
// one inside an octant (the field the product of theirs). The second piece vanished from the dual
// without a word where the first was crossed.
TEST_CASE("arrangement: a second piece of a sheet that meets no other sheet is refused by name") {
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  const std::vector<stc::Sheet> planes{plane(0, 0.5, "x"), plane(1, 0.5, "y"), plane(2, 0.5, "z")};
  const auto ball = [](const Point& x, const Point& c, double r) { return (x - c).norm() - r; };
  auto with = [&](stc::Sheet s) {
    auto all = planes;
    all.push_back(std::move(s));
    return all;
  };
  const Point centre(0.5, 0.5, 0.5), off(0.2, 0.2, 0.2);
  // The control: the crossed piece alone is a valid arrangement.
  const auto one = with({"s", [&](const Point& x) { return ball(x, centre, 0.3); }, "sphere"});
  CHECK(stc::dualize(stc::compute_arrangement(one, box)).hex.hexes.size() > 0);
  const auto two = with(
      {"s", [&](const Point& x) { return ball(x, centre, 0.3) * ball(x, off, 0.08); }, "spheres"});
  const std::string d = diagnosis(two, box);
  CHECK(d.find("sheet 's'") != std::string::npos);
  CHECK(d.find("that piece of it meets no other sheet") != std::string::npos);
}
