// dualize's ball check: a region that is not a ball, or that meets the domain boundary in more
// than one piece, has no node (its hexes would not form a ball around it) and is reported.
// Two checks: every node's link (the faces of its hexes away from it) must be one sphere (one
// disk on the boundary), and the whole dual must be a ball whose boundary nodes are the
// regions touching the domain boundary.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include "support/sheets.hpp"

using namespace geode;
using stc::Point;

namespace {

using test::sphere;

std::string diagnosis(const std::vector<stc::Sheet>& s) {
  const stc::Domain box{Point(0, 0, 0), Point(1, 1, 1), 3};
  try {
    stc::dualize(stc::compute_arrangement(s, box));
  } catch (const TopologyError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("dualize: a region meeting the boundary in two pieces is refused") {
  // A tube along x (faces x = 0 and x = 1), halved by the plane y = 0.5; two small spheres on
  // the tube's wall give every curve its vertices. Each half-tube is a ball but meets the
  // boundary in two half-disks: its link is an annulus.
  const std::vector<stc::Sheet> s{
      {"tube", [](const Point& x) { return std::hypot(x[1] - 0.5, x[2] - 0.5) - 0.2; }, "tube"},
      {"y", [](const Point& x) { return x[1] - 0.5 - 0.01 * x[0]; }, "plane"},
      sphere(Point(0.5, 0.5, 0.7), 0.1, "s1"),
      sphere(Point(0.5, 0.5, 0.3), 0.1, "s2")};
  const std::string d = diagnosis(s);
  CHECK(d.find("is not a half-ball meeting the boundary in one disk") != std::string::npos);
  CHECK(d.find("Euler characteristic") != std::string::npos);
  CHECK(d.find("tube-") != std::string::npos);  // the region inside the tube is named
}

TEST_CASE("dualize: a solid torus is not a ball") {
  // A torus around the vertical axis through the box centre, halved by a plane through its
  // middle; small spheres on its outer and inner equators give every curve its vertices. Each
  // half of the solid torus is still a solid torus.
  const double R = 0.25, r = 0.1;
  const std::vector<stc::Sheet> s{
      {"torus",
       [R, r](const Point& x) {
         const double q = std::hypot(x[0] - 0.5, x[1] - 0.5) - R;
         return std::hypot(q, x[2] - 0.5) - r;
       },
       "torus"},
      {"z", [](const Point& x) { return x[2] - 0.5 - 0.01 * x[0]; }, "plane"},
      sphere(Point(0.5 + R + r, 0.5, 0.505), 0.05, "outer"),
      sphere(Point(0.5 + R - r, 0.5, 0.505), 0.05, "inner")};
  // Regions are joined along 1-cells only, and no curve joins the outer and inner equators'
  // groups of vertices: each half of the solid torus comes out as two nodes that look like
  // balls. The global check sees what is left: the dual has Euler characteristic 0.
  const std::string d = diagnosis(s);
  CHECK(d.find("the dual of the arrangement is not a ball (V - E + F - C = 0") !=
        std::string::npos);
}

TEST_CASE("dualize: the same sheets cut into balls dualize") {
  // Control: cutting the tube across (x = 0.5) as well makes every region a ball meeting the
  // boundary at most once, so the tube example above fails for its topology, not its sheets.
  const std::vector<stc::Sheet> s{
      {"tube", [](const Point& x) { return std::hypot(x[1] - 0.5, x[2] - 0.5) - 0.2; }, "tube"},
      {"y", [](const Point& x) { return x[1] - 0.5 - 0.01 * x[0]; }, "plane"},
      {"x", [](const Point& x) { return x[0] - 0.5 - 0.01 * x[2]; }, "plane"},
      {"z", [](const Point& x) { return x[2] - 0.5 - 0.01 * x[1]; }, "plane"}};
  CHECK(diagnosis(s) == "");
}
