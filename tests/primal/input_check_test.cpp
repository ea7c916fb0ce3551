// check_input on cells whose faces could be mistaken for a neighbour's: the pairing of a quad
// with four triangles around a centre must not take the quad's own element's triangles; and
// hexes that overlap where every crossing falls on a quad's diagonal or in one plane.
#include <doctest/doctest.h>

#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/topology.hpp>

using namespace geode;
using namespace geode::primal;

namespace {

// A pyramid over the unit square, apex at (0.5, 0.5, h).
Model lone_pyramid(double h) {
  Model m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, h}};
  m.pyramids.push_back({0, 1, 2, 3, 4});
  return m;
}

}  // namespace

TEST_CASE("check_input: a lone pyramid's sides are its boundary, not a cover of its base") {
  // Its four triangles meet at the apex around its base as four tets over a quad would: they
  // were paired with the base, and the apex taken for a centre on the quad ("the elements
  // around node 1 cover its neighbourhood 0.0417 times ... folds over itself"; found by a
  // fault hunt).
  for (const double h : {0.5, 1.0, 3.0}) {
    CAPTURE(h);
    const InputCheckResult r = check_input(lone_pyramid(h));
    CHECK(r.ok());
    CHECK(r.boundary_faces == 5);
    CHECK(r.interface_quads == 0);
  }
  // Beside a hex, the pyramid's base is still paired with the hex's quad.
  Model m = lone_pyramid(0.5);
  for (const Point& p : {Point(0, 0, -1), Point(1, 0, -1), Point(1, 1, -1), Point(0, 1, -1)})
    m.points.push_back(p);
  m.hexes.push_back({5, 6, 7, 8, 0, 1, 2, 3});
  const InputCheckResult r = check_input(m);
  CHECK(r.ok());
  CHECK(r.boundary_faces == 9);
}

TEST_CASE("check_input: hexes overlapping by exactly half a cell are found") {
  // Every edge of one crosses the other's boundary through a quad's centre line (on both of its
  // triangles' edges) or lies in its faces' planes: no crossing was found, and conform wrote the
  // two overlapping (a fault hunt's). Touching face to face without shared nodes stays a gap,
  // touching along an edge passes.
  struct Case {
    Point shift;
    bool ok;
    InputFault fault;
  };
  for (const Case& c :
       {Case{{0.5, 0.5, 0.5}, false, InputFault::kCrossingFaces},
        Case{{0.5, 0, 0}, false, InputFault::kCrossingFaces},
        Case{{0.5, 0.5, 0}, false, InputFault::kCrossingFaces},
        Case{{0, 0.25, 0.5}, false, InputFault::kCrossingFaces},
        Case{{1, 0, 0}, false, InputFault::kGap}, Case{{1, 1, 0}, true, InputFault::kGap}}) {
    CAPTURE(c.shift.transpose());
    Model m;
    for (const Point& offset : {Point(0, 0, 0), c.shift})
      for (const auto& k : topology::kHexCornerCoords)
        m.points.push_back(Point(k[0], k[1], k[2]) + offset);
    m.hexes = {{0, 1, 2, 3, 4, 5, 6, 7}, {8, 9, 10, 11, 12, 13, 14, 15}};
    const InputCheckResult r = check_input(m);
    CHECK(r.ok() == c.ok);
    if (!c.ok) {
      REQUIRE(!r.findings.empty());
      CHECK(r.findings.front().fault == c.fault);
    }
  }
}
