// Pyramid domains: the hexahedron whose top face is the apex. Planes and spheres inside one
// must dualize as in a box, with the region around the apex placed at the apex; a sheet through
// the apex and a badly ordered base are refused by name.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/validity.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include "support/sheets.hpp"

using namespace geode;
using stc::Point;

namespace {

using test::plane;

// The equilateral pyramid: base [-1, 1]^2 at y = 0, counter-clockwise seen from the apex, every
// edge 2 long.
std::array<Point, 5> equilateral() {
  return {Point(-1, 0, -1), Point(-1, 0, 1), Point(1, 0, 1), Point(1, 0, -1),
          Point(0, std::sqrt(2.0), 0)};
}

stc::Sheet squared_sphere(const Point& c, double r, const std::string& name) {
  return {name, [c, r](const Point& x) { return (x - c).squaredNorm() / (r * r) - 1.0; }, "sphere"};
}

}  // namespace

TEST_CASE("pyramid domain: three planes give one hex, its apex node at the apex") {
  const auto P = equilateral();
  const stc::Domain d = stc::Domain::pyramid(P);
  CHECK(d.is_pyramid);
  const Point c(0.1, 0.45, 0.13);
  const auto A = stc::compute_arrangement(
      {plane(c, Point::UnitX(), "x"), plane(c, Point::UnitY(), "y"), plane(c, Point::UnitZ(), "z")},
      d);
  const auto D = stc::dualize(A);
  REQUIRE(D.hex.hexes.size() == 1);
  REQUIRE(D.hex.points.size() == 8);
  int at_apex = 0, base_corners = 0;
  for (std::size_t n = 0; n < D.hex.points.size(); ++n) {
    if ((D.hex.points[n] - P[4]).norm() < 1e-12) {
      ++at_apex;
      CHECK(((D.node_faces[n] >> stc::box_face(2, true)) & 1u) == 1u);
    }
    for (int b = 0; b < 4; ++b)
      base_corners += (D.hex.points[n] - P[primal::index_cast<std::size_t>(b)]).norm() < 1e-12;
  }
  CHECK(at_apex == 1);
  CHECK(base_corners == 4);
  // Topologically one hex (its first-guess nodes on the lateral edges need not be convex).
  const auto report = primal::check_validity(D.hex);
  CHECK(report.euler == 1);
  CHECK(report.boundary.closed);
}

TEST_CASE("pyramid domain: three planes and a sphere around their crossing give the pillowed hex") {
  const auto P = equilateral();
  const Point c(0.05, 0.5, -0.04);
  const auto A =
      stc::compute_arrangement({plane(c, Point::UnitX(), "x"), plane(c, Point::UnitY(), "y"),
                                plane(c, Point::UnitZ(), "z"), squared_sphere(c, 0.3, "s")},
                               stc::Domain::pyramid(P));
  const auto D = stc::dualize(A);
  CHECK(D.hex.hexes.size() == 7);
  CHECK(D.hex.points.size() == 16);
  const auto report = primal::check_validity(D.hex);
  CHECK(report.euler == 1);
  CHECK(report.boundary.closed);
  CHECK(report.boundary.faces.size() == 6);
}

TEST_CASE("pyramid domain: a sheet through the apex and a clockwise base are refused") {
  const auto P = equilateral();
  const Point c(0.1, 0.45, 0.13);
  try {
    stc::compute_arrangement({plane(P[4], Point(1, 0, 0.2), "through-apex"),
                              plane(c, Point::UnitY(), "y"), plane(c, Point::UnitZ(), "z")},
                             stc::Domain::pyramid(P));
    FAIL("a sheet through the apex was accepted");
  } catch (const TopologyError& e) {
    const std::string what = e.what();
    CHECK(what.find("'through-apex'") != std::string::npos);
    CHECK(what.find("apex") != std::string::npos);
  }
  auto flipped = P;
  std::swap(flipped[1], flipped[3]);
  CHECK_THROWS_AS(stc::Domain::pyramid(flipped), InvalidInput);
  auto flat = P;
  flat[4] = Point(0, 0, 0);
  CHECK_THROWS_AS(stc::Domain::pyramid(flat), InvalidInput);
}
