// Tangencies away from any vertex: two sheets that merely touch give no curve at all, so
// nothing but an explicit search notices them. Each configuration below is meshed silently
// unless the engine looks; near misses on both sides must not be flagged.
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
using test::sphere;

// The TopologyError's message, or "" when the arrangement dualizes into a valid mesh (with
// its element count in `elements`).
std::string diagnosis(const std::vector<stc::Sheet>& s, const stc::Domain& d, std::size_t& elements,
                      int resolution) {
  elements = 0;
  try {
    stc::ArrangementOptions o;
    o.seed_resolution = resolution;
    const auto D = stc::dualize(stc::compute_arrangement(s, d, o));
    if (d.dim == 3) {
      elements = D.hex.hexes.size();
      const auto r = primal::check_validity(D.hex);
      return r.ok() ? "" : "invalid mesh: " + r.summary();
    }
    elements = D.quad.quads.size();
    const auto r = primal::check_validity(D.quad);
    return r.ok() ? "" : "invalid mesh: " + r.summary();
  } catch (const TopologyError& e) {
    return e.what();
  }
}

const stc::Domain kBox(Point(0, 0, 0), Point(1, 1, 1), 3);
const stc::Domain kSquare(Point(0, 0, 0), Point(1, 1, 0), 2);

// Three planes (2D: two lines) near c, slightly tilted, and a ball around c cut by them into
// octants: the dual is a cube inside a cube (7 hexes; in 2D 5 quads). The sheets under test
// are added to it.
// `flip` mirrors the offsets, so that two crosses side by side have their planes apart.
std::vector<stc::Sheet> ball_in_cross(const Point& c, double r, int dim,
                                      const std::string& tag = "", double flip = 1.0) {
  std::vector<stc::Sheet> s{plane(c + flip * Point(-0.02, 0, 0), Point(1, 0.02, 0.01), "x" + tag),
                            plane(c + flip * Point(0, -0.03, 0), Point(-0.01, 1, 0.02), "y" + tag)};
  if (dim == 3) s.push_back(plane(c + flip * Point(0, 0, 0.03), Point(0.02, -0.01, 1), "z" + tag));
  s.push_back(sphere(c, r, "ball" + tag));
  return s;
}

// As ball_in_cross, with the y plane exactly y = 0.47.
const double kRho = std::sqrt(0.3 * 0.3 - 0.03 * 0.03);
std::vector<stc::Sheet> curve_cross(const Point& c) {
  auto s = ball_in_cross(c, 0.3, 3);
  s[1] = plane(Point(0, 0.47, 0), Point(0, 1, 0), "y");
  return s;
}

struct Case {
  std::string name;
  int dim;
  std::vector<stc::Sheet> sheets;
  const char* expect;        // in the diagnosis; "" for a valid mesh
  std::size_t elements = 0;  // of the valid mesh
  bool in_cell = false;      // in kCell instead of the unit box
};

// A skewed, tapered hexahedron around the unit box whose top face is the box's (z = 1): the
// engine works on the composed fields, where a touching must still be found.
const stc::Domain kCell = stc::Domain::hexahedron(
    {Point(-0.2, -0.1, 0), Point(1.1, -0.2, 0), Point(1.2, 1.1, 0), Point(-0.1, 1.0, 0),
     Point(0, 0, 1), Point(1, 0, 1), Point(1, 1, 1), Point(0, 1, 1)});

std::vector<stc::Sheet> with(std::vector<stc::Sheet> a, const std::vector<stc::Sheet>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

TEST_CASE("tangency: sheets that touch away from any vertex are diagnosed, near misses are not") {
  const Point c(0.5, 0.5, 0.5);
  // The ball around c has radius 0.3: the plane x = 0.8 touches it at (0.8, 0.5, 0.5), 0.04
  // from the nearest vertex (where that plane meets the y and z planes); a second ball of
  // radius 0.1, with its own cross, touches a ball of radius 0.3 at (0.75, 0.5, 0.5).
  // Element counts of the valid meshes, by hand: a ball in its cross is 7 hexes (the planes'
  // vertex, and the 3 lines where two planes meet crossing the sphere twice each), 5 quads
  // in 2D. A plane beyond the ball adds its vertex with the cross's other two planes (8; 2D:
  // 6); cutting the ball instead it adds that vertex and its crossings of the 2 circles where
  // the cross meets the sphere, 2 each (12; 2D: it adds its vertex and 2 crossings, 8). Two
  // balls with crosses 0.06 apart: 8 vertices of three planes, one of each direction; each
  // ball is crossed twice by the 8 lines where two of its neighbouring planes meet (16 + 16).
  const Point left(0.45, 0.5, 0.5), far(0.85, 0.5, 0.5);  // balls of radius 0.3 and 0.1
  const Point c2(0.5, 0.5, 0.0);                          // 2D fields are evaluated at z = 0
  const std::vector<Case> cases{
      {"sphere touching plane", 3,
       with(ball_in_cross(c, 0.3, 3), {plane(Point(0.8, 0, 0), Point(1, 0, 0), "p")}), "touch"},
      {"sphere 1e-2 short of plane", 3,
       with(ball_in_cross(c, 0.3, 3), {plane(Point(0.81, 0, 0), Point(1, 0, 0), "p")}), "", 8},
      {"sphere cutting plane in a circle", 3,
       with(ball_in_cross(c, 0.3, 3), {plane(Point(0.7, 0, 0), Point(1, 0, 0), "p")}), "", 12},
      {"two spheres touching", 3,
       with(ball_in_cross(left, 0.3, 3), ball_in_cross(far, 0.1, 3, "'", -1.0)), "touch"},
      {"two spheres 1e-2 apart", 3,
       with(ball_in_cross(left, 0.3, 3), ball_in_cross(Point(0.86, 0.5, 0.5), 0.1, 3, "'", -1.0)),
       "", 40},
      {"circle touching line", 2,
       with(ball_in_cross(c2, 0.3, 2), {plane(Point(0.8, 0, 0), Point(1, 0, 0), "p")}), "touch"},
      {"circle 1e-2 short of line", 2,
       with(ball_in_cross(c2, 0.3, 2), {plane(Point(0.81, 0, 0), Point(1, 0, 0), "p")}), "", 6},
      {"circle cutting line", 2,
       with(ball_in_cross(c2, 0.3, 2), {plane(Point(0.7, 0, 0), Point(1, 0, 0), "p")}), "", 8},
      // The circle where the plane y = 0.47 (untilted here) meets the ball has radius
      // rho = sqrt(0.3^2 - 0.03^2): the plane x = 0.5 + rho touches it, and crosses the ball.
      {"curve touching a third sheet", 3,
       with(curve_cross(c), {plane(Point(0.5 + kRho, 0, 0), Point(1, 0, 0), "p")}),
       "touches sheet"},
      {"curve 1e-2 short of a third sheet", 3,
       with(curve_cross(c), {plane(Point(0.51 + kRho, 0, 0), Point(1, 0, 0), "p")}), "", 8},
      {"curve crossing a third sheet twice, 1e-2 deep", 3,
       with(curve_cross(c), {plane(Point(0.49 + kRho, 0, 0), Point(1, 0, 0), "p")}), "", 12},
      {"sphere touching a box face", 3, ball_in_cross(Point(0.5, 0.5, 0.7), 0.3, 3), "touch"},
      {"sphere 1e-2 short of a box face", 3, ball_in_cross(Point(0.5, 0.5, 0.69), 0.3, 3), "", 7},
      {"in a hexahedron: sphere touching plane", 3,
       with(ball_in_cross(c, 0.3, 3), {plane(Point(0.8, 0, 0), Point(1, 0, 0), "p")}), "touch", 0,
       true},
      {"in a hexahedron: sphere 1e-2 short of plane", 3,
       with(ball_in_cross(c, 0.3, 3), {plane(Point(0.81, 0, 0), Point(1, 0, 0), "p")}), "", 8,
       true},
      {"in a hexahedron: sphere touching its top face", 3,
       ball_in_cross(Point(0.5, 0.5, 0.7), 0.3, 3), "touches the domain boundary (face 5)", 0,
       true},
      {"in a hexahedron: sphere 1e-2 short of its top face", 3,
       ball_in_cross(Point(0.5, 0.5, 0.69), 0.3, 3), "", 7, true},
      {"circle touching a square side", 2, ball_in_cross(Point(0.5, 0.7, 0), 0.3, 2), "touch"},
      {"circle 1e-2 short of a square side", 2, ball_in_cross(Point(0.5, 0.69, 0), 0.3, 2), "", 5},
  };
  // At the coarsest and finest seeding grids of the supported range too: the search must not
  // depend on where the grid's nodes happen to fall.
  for (int resolution : {12, 13, 17, 24, 31, 37, 48})
    for (const Case& k : cases) {
      CAPTURE(resolution);
      CAPTURE(k.name);
      std::size_t elements = 0;
      const std::string msg = diagnosis(k.sheets,
                                        k.in_cell    ? kCell
                                        : k.dim == 3 ? kBox
                                                     : kSquare,
                                        elements, resolution);
      CAPTURE(msg);
      if (*k.expect) {
        CHECK(msg.find(k.expect) != std::string::npos);
      } else {
        CHECK(msg.empty());
        CHECK(elements == k.elements);
      }
    }
}
