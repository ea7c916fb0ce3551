// The round trip of issue 3: a mesh -> its dual sheets (stc/mesh_dual) -> those sheets as
// fields (stc/mesh_fields) -> arrangement -> dualize must give back an isomorphic mesh, in 2D
// and 3D, on structured grids (straight and with moved nodes) and on the paper's geode.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <geode/primal/dice.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/validity.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/mesh_fields.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using primal::HexMesh;
using primal::Index;
using primal::Point;
using primal::QuadMesh;
namespace gt = geode::test;

namespace {

stc::DualMesh round_trip(const HexMesh& m) {
  const auto in = stc::sheet_fields(m);
  return stc::dualize(stc::compute_arrangement(in.sheets, in.domain));
}
stc::DualMesh round_trip(const QuadMesh& m) {
  const auto in = stc::sheet_fields(m);
  return stc::dualize(stc::compute_arrangement(in.sheets, in.domain));
}

// Interior nodes moved by a fixed pseudo-random amount (up to `amount` cell sizes per axis),
// boundary nodes along their face only: the sheets become kinked, the box stays a box.
template <class Mesh>
void jiggle(Mesh& m, int dim, double amount) {
  Point lo = m.points.front(), hi = m.points.front();
  for (const Point& p : m.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (std::size_t n = 0; n < m.points.size(); ++n) {
    Point& p = m.points[n];
    for (int a = 0; a < dim; ++a) {
      if (std::abs(p[a] - lo[a]) < 1e-12 || std::abs(p[a] - hi[a]) < 1e-12) continue;
      p[a] += amount * std::sin(12.9898 * static_cast<double>(n) + 78.233 * a + 1.0);
    }
  }
}

// Every corner and centre Jacobian of the reference positions positive: sheet_fields needs
// a placed mesh, and the printed Appendix A positions give eight inverted hexes.
HexMesh placed_appendix_a() {
  HexMesh g = gt::appendix_a_geode();
  const auto constraints = primal::box_constraints(g.points, Point(-12, -7, -12), Point(12, 7, 12),
                                                   {true, true, true, true, true, true});
  const auto r = primal::smooth_hex_mesh(g, constraints);
  REQUIRE(r.untangled);
  return g;
}

}  // namespace

TEST_CASE("round trip: structured hex grids, straight and with moved nodes") {
  struct Case {
    int nx, ny, nz;
    double jiggle;
  };
  for (const Case c : {Case{1, 1, 1, 0.0}, Case{3, 2, 2, 0.0}, Case{4, 3, 2, 0.0},
                       Case{3, 3, 3, 0.2}, Case{4, 2, 3, 0.3}}) {
    CAPTURE(c.nx);
    CAPTURE(c.ny);
    CAPTURE(c.nz);
    CAPTURE(c.jiggle);
    HexMesh g = gt::structured_hex_grid(c.nx, c.ny, c.nz);
    jiggle(g, 3, c.jiggle);
    const auto D = round_trip(g);
    CHECK(D.hex.hexes.size() == g.hexes.size());
    CHECK(D.hex.points.size() == g.points.size());
    const auto m = gt::find_isomorphism(D.hex, g);
    REQUIRE(m.has_value());
    CHECK(gt::is_isomorphism(D.hex, g, *m));
    CHECK(primal::check_validity(D.hex).ok());
    // Each rebuilt hex sits at the centre of the hex it maps to: the triple point of the
    // sheets' mid-surfaces is the centre of the multilinear map.
    for (std::size_t h = 0; h < D.hex.hexes.size(); ++h) {
      const auto& orig = g.hexes[primal::index_cast<std::size_t>(m->cell_map[h])];
      Point centre = Point::Zero();
      for (Index n : orig) centre += g.points[primal::index_cast<std::size_t>(n)] / 8.0;
      CHECK((D.element_centres[h] - centre).norm() < 1e-6);
    }
  }
}

TEST_CASE("round trip: structured quad grids, straight and with moved nodes") {
  for (const auto& [nx_, ny_, amount] :
       {std::tuple{1, 1, 0.0}, std::tuple{3, 2, 0.0}, std::tuple{5, 4, 0.25}}) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& nx = nx_;
    const auto& ny = ny_;
    CAPTURE(nx);
    CAPTURE(ny);
    QuadMesh g = gt::structured_quad_grid(nx, ny);
    jiggle(g, 2, amount);
    const auto D = round_trip(g);
    CHECK(D.quad.quads.size() == g.quads.size());
    const auto m = gt::find_isomorphism(D.quad, g);
    REQUIRE(m.has_value());
    CHECK(gt::is_isomorphism(D.quad, g, *m));
  }
}

TEST_CASE("round trip: the Appendix A geode (2 tunnels, 4 domes) comes back") {
  const HexMesh g = placed_appendix_a();
  const auto in = stc::sheet_fields(g);
  CHECK(in.sheets.size() == 6);
  CHECK((in.domain.lo - Point(-12, -7, -12)).norm() < 1e-12);
  CHECK((in.domain.hi - Point(12, 7, 12)).norm() < 1e-12);
  const auto D = stc::dualize(stc::compute_arrangement(in.sheets, in.domain));
  CHECK(D.hex.hexes.size() == 26);
  CHECK(D.hex.points.size() == 48);
  // Nodes labelled by the box face they lie on (top / bottom / the four sides are not
  // interchangeable): the rebuilt nodes by their regions' faces, the fixture by position.
  auto face_label = [](unsigned faces) { return static_cast<int>(faces); };
  std::vector<int> rebuilt, fixture;
  for (unsigned f : D.node_faces) rebuilt.push_back(face_label(f));
  for (const Point& p : g.points) {
    unsigned f = 0;
    for (int a = 0; a < 3; ++a) {
      const double h = a == 1 ? 7.0 : 12.0;
      if (std::abs(p[a] + h) < 1e-9) f |= 1u << (2 * a);
      if (std::abs(p[a] - h) < 1e-9) f |= 1u << (2 * a + 1);
    }
    fixture.push_back(face_label(f));
  }
  const gt::NodeLabels labels{rebuilt, fixture};
  const auto m = gt::find_isomorphism(D.hex, g, labels);
  REQUIRE(m.has_value());
  CHECK(gt::is_isomorphism(D.hex, g, *m, labels));
  // The element of each triple point is the hex whose three sheets meet there.
  const auto dual = stc::mesh_dual(g);
  for (std::size_t h = 0; h < D.hex.hexes.size(); ++h) {
    auto want = dual.cell_sheets[primal::index_cast<std::size_t>(m->cell_map[h])];
    std::sort(want.begin(), want.end());
    CHECK(std::vector<Index>(want.begin(), want.end()) ==
          std::vector<Index>(D.element_sheets[h].begin(), D.element_sheets[h].end()));
  }
}

TEST_CASE("round trip: each side of the geode (the 2D geode) comes back") {
  const HexMesh g = placed_appendix_a();
  // The x = -12 side seen from outside, laid into the plane z = 0 as (z, y), which keeps it
  // counter-clockwise.
  QuadMesh side = gt::boundary_quads(g, [](const Point& p) { return std::abs(p.x() + 12) < 1e-9; });
  for (Point& p : side.points) p = Point(p.z(), p.y(), 0.0);
  REQUIRE(side.quads.size() == 5);
  const auto D = round_trip(side);
  CHECK(D.quad.quads.size() == 5);
  const auto m = gt::find_isomorphism(D.quad, side);
  REQUIRE(m.has_value());
  CHECK(gt::is_isomorphism(D.quad, side, *m));
}

TEST_CASE("round trip: diced tet meshes (closed and hemispherical dome sheets) come back") {
  // Kuhn-split cubes diced into 4 hexes per tet: every interior vertex of the tet mesh is
  // surrounded by a closed sheet, every boundary vertex by a hemisphere ending on the box.
  for (int n : {1, 2}) {
    CAPTURE(n);
    const primal::TetMesh tets =
        primal::tet_part(primal::grid_model({n, n, n}, 1.0, [](int, int, int) { return true; }));
    const HexMesh g = primal::dice(tets).mesh;
    const auto dual = stc::mesh_dual(g);
    CHECK(dual.sheets.size() ==
          primal::index_cast<std::size_t>((n + 1) * (n + 1) * (n + 1)));  // one per tet vertex
    const auto D = round_trip(g);
    CHECK(D.hex.hexes.size() == g.hexes.size());
    const auto m = gt::find_isomorphism(D.hex, g);
    REQUIRE(m.has_value());
    CHECK(gt::is_isomorphism(D.hex, g, *m));
  }
}

TEST_CASE("round trip: meshes the fields cannot represent are refused with the reason") {
  SUBCASE("a mesh that does not fill its bounding box") {
    HexMesh l = gt::structured_hex_grid(2, 2, 1);
    l.hexes.pop_back();  // an L: one boundary face inside the box
    CHECK_THROWS_WITH_AS(stc::sheet_fields(l),
                         doctest::Contains("lies on no face of the bounding box"), InvalidInput);
  }
  SUBCASE("an inverted hex") {
    HexMesh g = gt::structured_hex_grid(2, 1, 1);
    g.points[1] = Point(2.5, 0.0, 0.0);  // (1,0,0) pushed past (2,0,0): the second hex folds
    CHECK_THROWS_WITH_AS(stc::sheet_fields(g),
                         doctest::Contains("is inverted or flat at its corner"), InvalidInput);
  }
  SUBCASE("a chord that does not separate (an annulus: a 3 x 3 grid without its centre)") {
    QuadMesh ring = gt::structured_quad_grid(3, 3);
    ring.quads.erase(ring.quads.begin() + 4);  // quad (1, 1)
    CHECK_THROWS_WITH_AS(stc::sheet_fields(ring), doctest::Contains("does not separate the mesh"),
                         TopologyError);
  }
  SUBCASE("a self-intersecting chord") {
    // The band of tests/stc/mesh_dual_test.cpp: chord 0 crosses itself in quad 0. Topology is
    // checked before geometry, so the (unplaceable) band is refused for its chord.
    QuadMesh band;
    band.points.assign(6, Point::Zero());
    band.quads = {{0, 1, 2, 3}, {2, 1, 4, 5}, {5, 4, 0, 1}};
    CHECK_THROWS_WITH_AS(stc::sheet_fields(band),
                         doctest::Contains("sheet 0 crosses itself (in quad 0 "), TopologyError);
    // With the self-crossing quad last, it is the one named (the sheet's first cell was: a
    // hunt's "quad 0" for a crossing in quad 184).
    band.quads = {{2, 1, 4, 5}, {5, 4, 0, 1}, {0, 1, 2, 3}};
    CHECK_THROWS_WITH_AS(stc::sheet_fields(band), doctest::Contains("crosses itself (in quad 2 "),
                         TopologyError);
  }
}
