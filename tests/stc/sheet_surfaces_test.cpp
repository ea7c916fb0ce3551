// Sheets as surfaces: contours of fields (marching tetrahedra / triangles) land on the zero set,
// close up where the zero set does, and are oriented towards the positive side; a mesh's dual
// surfaces pass through the mid-edge points of exactly its layer of cells.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/sheet_surfaces.hpp>
#include <geode/templates/geode.hpp>
#include "support/fixtures.hpp"

using namespace geode;
using primal::Index;
using primal::Point;

namespace {

double area(const primal::TriMesh& m) {
  double a = 0;
  for (const auto& t : m.tris)
    a += 0.5 * (m.points[primal::index_cast<std::size_t>(t[1])] -
                m.points[primal::index_cast<std::size_t>(t[0])])
                   .cross(m.points[primal::index_cast<std::size_t>(t[2])] -
                          m.points[primal::index_cast<std::size_t>(t[0])])
                   .norm();
  return a;
}

// Uses of each undirected edge, and V - E + F.
std::map<std::pair<Index, Index>, int> edge_uses(const primal::TriMesh& m) {
  std::map<std::pair<Index, Index>, int> uses;
  for (const auto& t : m.tris)
    for (int i = 0; i < 3; ++i) {
      Index a = t[primal::index_cast<std::size_t>(i)],
            b = t[primal::index_cast<std::size_t>((i + 1) % 3)];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  return uses;
}

}  // namespace

TEST_CASE(
    "contour_sheets: a sphere comes out closed, on the sphere, with its area, normals outwards") {
  const double r = 0.63;
  stc::Sheet s{"sphere", [r](const Point& x) { return x.norm() - r; }, "test"};
  const stc::Domain box(Point(-1, -1, -1), Point(1, 1, 1));
  const auto m = stc::contour_sheets({s}, box)[0];
  REQUIRE(!m.tris.empty());
  for (const auto& p : m.points) CHECK(std::abs(p.norm() - r) < 1e-9);  // refined onto the zero set
  const double exact = 4 * M_PI * r * r;
  CHECK(std::abs(area(m) - exact) / exact < 0.01);
  const auto uses = edge_uses(m);
  for (const auto& [e, n] : uses) CHECK(n == 2);  // watertight
  CHECK(static_cast<long>(m.points.size()) - static_cast<long>(uses.size()) +
            static_cast<long>(m.tris.size()) ==
        2);
  for (const auto& t : m.tris) {
    const Point a = m.points[primal::index_cast<std::size_t>(t[0])],
                b = m.points[primal::index_cast<std::size_t>(t[1])],
                c = m.points[primal::index_cast<std::size_t>(t[2])];
    CHECK((b - a).cross(c - a).dot(a + b + c) >= 0);  // towards the positive (outer) side
  }
}

TEST_CASE(
    "contour_sheets: a slanted plane through a hexahedral domain is cut by the domain's faces") {
  // A sheared hexahedron; the plane x + 0.2 y = 0.5 meets it in a planar polygon.
  const auto dom =
      stc::Domain::hexahedron({Point(0, 0, 0), Point(1, 0, 0), Point(1.2, 1, 0), Point(0.2, 1, 0),
                               Point(0, 0, 1), Point(1, 0, 1), Point(1.2, 1, 1), Point(0.2, 1, 1)});
  stc::Sheet s{"plane", [](const Point& x) { return x.x() + 0.2 * x.y() - 0.5; }, "test"};
  const auto m = stc::contour_sheets({s}, dom, {.resolution = 12})[0];
  REQUIRE(!m.tris.empty());
  for (const auto& p : m.points) {
    CHECK(std::abs(p.x() + 0.2 * p.y() - 0.5) < 1e-9);
    CHECK(p.z() >= -1e-12);
    CHECK(p.z() <= 1 + 1e-12);
  }
  // The section is a 1 x 1 parallelogram in (y, z) with x = 0.5 - 0.2 y: area sqrt(1 + 0.04).
  CHECK(std::abs(area(m) - std::sqrt(1.04)) < 1e-9);
}

TEST_CASE("contour_curves: a circle in a rectangle is one closed loop on the circle") {
  stc::Sheet s{"circle", [](const Point& x) { return (x - Point(0.5, 0.4, 0)).norm() - 0.3; },
               "test"};
  const stc::Domain rect(Point(0, 0, 0), Point(1, 0.8, 0), 2);
  const auto c = stc::contour_curves({s}, rect)[0];
  REQUIRE(!c.segments.empty());
  std::map<Index, int> degree;
  double length = 0;
  for (const auto& e : c.segments) {
    ++degree[e[0]], ++degree[e[1]];
    length += (c.points[primal::index_cast<std::size_t>(e[1])] -
               c.points[primal::index_cast<std::size_t>(e[0])])
                  .norm();
  }
  for (const auto& [v, d] : degree) CHECK(d == 2);
  for (const auto& p : c.points) CHECK(std::abs((p - Point(0.5, 0.4, 0)).norm() - 0.3) < 1e-9);
  CHECK(std::abs(length - 2 * M_PI * 0.3) / (2 * M_PI * 0.3) < 0.01);
}

TEST_CASE("dual_surfaces: a grid's sheets are its mid-planes, through exactly their layers") {
  const primal::HexMesh g = test::structured_hex_grid(3, 2, 2);
  const auto dual = stc::mesh_dual(g);
  const auto surfaces = stc::dual_surfaces(g, dual);
  const auto layers = stc::sheet_layers(dual);
  REQUIRE(surfaces.size() == 7);
  std::multiset<std::size_t> sizes;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const auto& m = surfaces[s];
    sizes.insert(layers[s].size());
    CHECK(m.tris.size() == 2 * layers[s].size());  // one quad per cell of the layer
    // All points on one mid-plane x = i + 1/2 (or y, z): one coordinate constant, half-integer.
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
      bool flat = true;
      for (const auto& p : m.points) flat = flat && std::abs(p[a] - m.points[0][a]) < 1e-12;
      if (flat) axis = a;
    }
    REQUIRE(axis >= 0);
    CHECK(std::abs(m.points[0][axis] - std::floor(m.points[0][axis]) - 0.5) < 1e-12);
    const auto uses = edge_uses(m);
    int boundary = 0;
    for (const auto& [e, n] : uses) boundary += n == 1;
    CHECK(boundary > 0);  // a plane ends on the box
    CHECK(std::abs(area(m) - static_cast<double>(layers[s].size())) < 1e-12);  // unit cells
  }
  // 3 sheets across x with 4 cells each, 2 across y and 2 across z with 6 each.
  CHECK(sizes == std::multiset<std::size_t>{4, 4, 4, 6, 6, 6, 6});
}

TEST_CASE("dual_surfaces and dual_curves of the derived geodes: every cell in three (two) layers") {
  templates::GeodeOptions o;
  const auto T = templates::build_geode3d(o);
  const auto dual = stc::mesh_dual(T.hex);
  const auto layers = stc::sheet_layers(dual);
  std::size_t total = 0;
  for (const auto& l : layers) total += l.size();
  CHECK(layers.size() == T.sheets.size());
  CHECK(total == 3 * T.hex.hexes.size());  // no sheet of the geode crosses itself
  const auto surfaces = stc::dual_surfaces(T.hex, dual);
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    CHECK(surfaces[s].tris.size() == 2 * layers[s].size());

  const auto T2 = templates::build_geode2d(o);
  const auto dual2 = stc::mesh_dual(T2.quad);
  const auto curves = stc::dual_curves(T2.quad, dual2);
  std::size_t segments = 0;
  for (const auto& c : curves) segments += c.segments.size();
  CHECK(segments == 2 * T2.quad.quads.size());
}

TEST_CASE("dual_surfaces and dual_curves tell their progress, cell by cell up to the last") {
  // Told every 2^14 cells and at the end, ascending, the total the cells; the result the same.
  const auto check_told = [](const std::vector<std::pair<std::size_t, std::size_t>>& calls,
                             std::size_t cells) {
    REQUIRE(calls.size() >= 3);  // 0, 2^14, the end
    CHECK(calls.front().first == 0);
    CHECK(calls.back().first == cells);
    for (std::size_t i = 0; i < calls.size(); ++i) {
      CHECK(calls[i].second == cells);
      if (i > 0) CHECK(calls[i].first > calls[i - 1].first);
    }
  };
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  stc::DualSurfaceOptions options;
  options.progress = [&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); };
  const primal::HexMesh g = test::structured_hex_grid(30, 30, 20);  // 18000 hexes
  const auto dual = stc::mesh_dual(g);
  const auto surfaces = stc::dual_surfaces(g, dual, options);
  check_told(calls, g.hexes.size());
  const auto plain = stc::dual_surfaces(g, dual);
  REQUIRE(surfaces.size() == plain.size());
  for (std::size_t s = 0; s < plain.size(); ++s) CHECK(surfaces[s].tris == plain[s].tris);
  calls.clear();
  const primal::QuadMesh q = test::structured_quad_grid(200, 100);  // 20000 quads
  const auto curves = stc::dual_curves(q, stc::mesh_dual(q), options);
  check_told(calls, q.quads.size());
  CHECK(curves.size() == 300);
}
