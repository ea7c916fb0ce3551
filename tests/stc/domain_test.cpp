// General hexahedral (quadrilateral) domains: the engine computes on the fields composed with
// the trilinear map, and everything it reports is physical. Three planes through a cell's
// centre must give the 2 x 2 x 2 grid whatever the cell's shape, with the grid's corner nodes
// on the cell's corners; a cell equal to a box must give exactly the box's mesh.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/templates/geode.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"
#include "support/sheets.hpp"

using namespace geode;
using stc::Point;

namespace {

using test::plane;

using Corners = std::array<Point, 8>;

Corners unit_cube(const Point& lo, const Point& hi) {
  Corners P;
  for (std::size_t c = 0; c < 8; ++c) {
    const auto& rc = primal::topology::kHexCornerCoords[c];
    for (std::size_t a = 0; a < 3; ++a)
      P[c][static_cast<Eigen::Index>(a)] =
          rc[a] ? hi[static_cast<Eigen::Index>(a)] : lo[static_cast<Eigen::Index>(a)];
  }
  return P;
}

// Local coordinates of x in the domain: Newton on domain_point (independent of the engine's
// own inverse, which it does not have).
Point local_of(const stc::Domain& d, const Point& x) {
  Point r = Point::Constant(0.5);
  if (d.dim == 2) r[2] = 0.0;
  for (int it = 0; it < 50; ++it) {
    const Point f = stc::domain_point(d, r) - x;
    Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
    for (int a = 0; a < d.dim; ++a) {
      Point e = r;
      e[a] += 1e-7;
      J.col(a) = (stc::domain_point(d, e) - stc::domain_point(d, r)) / 1e-7;
    }
    r -= J.colPivHouseholderQr().solve(f);
    if (d.dim == 2) r[2] = 0.0;
  }
  return r;
}

// A plane through p with normal n.
// k planes across each local axis, through the points at local coordinate i / (k + 1) on
// the line through the cell's centre, each roughly parallel to a pair of opposite faces
// (normal along the line joining their centres, tilted a little so none is special). In 2D
// the line through the two edge points of local coordinate i / (k + 1) (the bilinear map's
// iso-lines are straight), tilted a little: in a skewed quadrilateral a line across the
// centre's direction would leave through the wrong edges.
std::vector<stc::Sheet> cell_planes(const stc::Domain& d, int k) {
  if (d.dim == 2) {
    std::vector<stc::Sheet> s;
    for (int a = 0; a < 2; ++a)
      for (int i = 1; i <= k; ++i) {
        Point r0 = Point::Zero(), r1 = Point::Zero();
        r0[a] = r1[a] = static_cast<double>(i) / (k + 1);
        r1[1 - a] = 1.0;
        const Point q0 = stc::domain_point(d, r0), q1 = stc::domain_point(d, r1);
        const Point t = q1 - q0;
        const Point n = Point(-t.y(), t.x(), 0.0) + 0.03 * t;
        s.push_back(plane(0.5 * (q0 + q1), n, std::string(1, "rs"[a]) + std::to_string(i)));
      }
    return s;
  }
  std::vector<stc::Sheet> s;
  for (int a = 0; a < d.dim; ++a) {
    Point lo = Point::Constant(0.5), hi = Point::Constant(0.5);
    if (d.dim == 2) lo[2] = hi[2] = 0.0;
    lo[a] = 0.0, hi[a] = 1.0;
    Point n = stc::domain_point(d, hi) - stc::domain_point(d, lo);
    n[(a + 1) % d.dim] += 0.05 * n.norm();
    for (int i = 1; i <= k; ++i) {
      Point r = lo;
      r[a] = static_cast<double>(i) / (k + 1);
      s.push_back(plane(stc::domain_point(d, r), n, std::string(1, "rst"[a]) + std::to_string(i)));
    }
  }
  return s;
}

struct CellCase {
  std::string name;
  Corners corners;
};

std::vector<CellCase> hexahedra() {
  std::vector<CellCase> v;
  // Sheared: a parallelepiped leaning 40 degrees in x and 20 in z.
  Corners sheared = unit_cube(Point(0, 0, 0), Point(2, 1, 1.5));
  for (std::size_t c = 4; c < 8; ++c) sheared[c] += Point(0.84, 0, 0.36);
  for (std::size_t c : {2, 3, 6, 7}) sheared[c] += Point(0.3, 0, 0);
  v.push_back({"sheared", sheared});
  // Tapered: a frustum, the top 0.4 times the bottom and off-centre.
  Corners tapered = unit_cube(Point(-1, -1, 0), Point(1, 1, 1));
  for (std::size_t c = 4; c < 8; ++c)
    tapered[c] = Point(0.4 * tapered[c].x() + 0.3, 0.4 * tapered[c].y(), 1.2);
  v.push_back({"tapered", tapered});
  // Twisted: the top face turned 30 degrees, so the side faces are not planar.
  Corners twisted = unit_cube(Point(-1, -1, 0), Point(1, 1, 2));
  const double a = 0.5236;
  for (std::size_t c = 4; c < 8; ++c) {
    const Point p = twisted[c];
    twisted[c] = Point(std::cos(a) * p.x() - std::sin(a) * p.y(),
                       std::sin(a) * p.x() + std::cos(a) * p.y(), p.z());
  }
  v.push_back({"twisted", twisted});
  return v;
}

}  // namespace

TEST_CASE("domain: planes in a hexahedron dualize to the structured grid inside it") {
  // k planes per direction: (k + 1)^3 regions, k^3 vertices, the k x k x k grid. For k = 1
  // the single hex is the domain cell itself: its 8 regions each hold one corner.
  for (const CellCase& cc : hexahedra())
    for (int k : {1, 2}) {
      CAPTURE(cc.name);
      CAPTURE(k);
      const stc::Domain d = stc::Domain::hexahedron(cc.corners);
      const auto sheets = cell_planes(d, k);
      const auto A = stc::compute_arrangement(sheets, d);
      REQUIRE(A.vertices.size() == primal::index_cast<std::size_t>(k * k * k));
      if (k == 1) {
        // At the cell's centre where the three planes meet: reported in physical space, with
        // its local coordinates.
        CHECK((A.vertices[0].x - stc::domain_point(d, Point(0.5, 0.5, 0.5))).norm() < 1e-9);
        CHECK((A.vertices[0].local - Point(0.5, 0.5, 0.5)).norm() < 1e-9);
      }
      for (const auto& v : A.vertices) CHECK((stc::domain_point(d, v.local) - v.x).norm() < 1e-12);
      const auto D = stc::dualize(A);
      CHECK(D.hex.hexes.size() == primal::index_cast<std::size_t>(k * k * k));
      CHECK(D.hex.points.size() == primal::index_cast<std::size_t>((k + 1) * (k + 1) * (k + 1)));
      CHECK(test::find_isomorphism(D.hex, test::structured_hex_grid(k, k, k)).has_value());
      const auto report = primal::check_validity(D.hex);
      CHECK_MESSAGE(report.ok(), report.summary());  // includes every corner Jacobian > 0
      int corner_nodes = 0;
      for (std::size_t n = 0; n < D.hex.points.size(); ++n) {
        const Point r = local_of(d, D.hex.points[n]);
        CAPTURE(n);
        CHECK(r.minCoeff() > -1e-9);
        CHECK(r.maxCoeff() < 1 + 1e-9);
        // A node on three faces is on a corner of the hexahedron: the one the face bits name.
        const unsigned f = D.node_faces[n];
        if (__builtin_popcount(f) != 3) continue;
        ++corner_nodes;
        std::array<int, 3> rc{(f >> 1) & 1u ? 1 : 0, (f >> 3) & 1u ? 1 : 0, (f >> 5) & 1u ? 1 : 0};
        for (std::size_t c = 0; c < 8; ++c)
          if (primal::topology::kHexCornerCoords[c] == rc)
            CHECK((D.hex.points[n] - cc.corners[c]).norm() < 1e-12);
      }
      CHECK(corner_nodes == 8);
      // Curve polylines and 1-cell ends are physical too: on both of their planes.
      for (const auto& c : A.curves)
        for (const Point& p : c.polyline)
          for (int s : c.sheets)
            CHECK(std::abs(sheets[primal::index_cast<std::size_t>(s)].field(p)) < 1e-8);
      for (const auto& e : A.edges)
        for (int s : e.sheets)
          for (const Point& p : {e.a.x, e.b.x})
            CHECK(std::abs(sheets[primal::index_cast<std::size_t>(s)].field(p)) < 1e-8);
    }
}

TEST_CASE("domain: lines in a quadrilateral dualize to the structured grid inside it") {
  struct Case {
    std::string name;
    std::array<Point, 4> corners;
  };
  for (const Case& c :
       {Case{"sheared", {Point(0, 0, 0), Point(2, 0, 0), Point(2.8, 1, 0), Point(0.8, 1, 0)}},
        Case{"tapered", {Point(-1, 0, 0), Point(1, 0, 0), Point(0.6, 1.5, 0), Point(-0.2, 1.5, 0)}},
        Case{"kite", {Point(0, 0, 0), Point(3, 1, 0), Point(2, 2, 0), Point(0.5, 1.8, 0)}}}) {
    for (int k : {1, 2, 3}) {
      CAPTURE(c.name);
      CAPTURE(k);
      const stc::Domain d = stc::Domain::quadrilateral(c.corners);
      const auto D = stc::dualize(stc::compute_arrangement(cell_planes(d, k), d));
      CHECK(D.quad.quads.size() == primal::index_cast<std::size_t>(k * k));
      CHECK(test::find_isomorphism(D.quad, test::structured_quad_grid(k, k)).has_value());
      const auto report = primal::check_validity(D.quad);
      CHECK_MESSAGE(report.ok(), report.summary());
      int corner_nodes = 0;
      for (std::size_t n = 0; n < D.quad.points.size(); ++n) {
        const Point r = local_of(d, D.quad.points[n]);
        CHECK(r.minCoeff() > -1e-9);
        CHECK(r.maxCoeff() < 1 + 1e-9);
        const unsigned f = D.node_faces[n];
        if (__builtin_popcount(f) != 2) continue;
        ++corner_nodes;
        // Local (r, s) of the corner; quad corner k is hex corner k.
        std::array<int, 3> rc{(f >> 1) & 1u ? 1 : 0, (f >> 3) & 1u ? 1 : 0, 0};
        for (std::size_t k = 0; k < 4; ++k)
          if (primal::topology::kHexCornerCoords[k] == rc)
            CHECK((D.quad.points[n] - c.corners[k]).norm() < 1e-12);
      }
      CHECK(corner_nodes == 4);
    }
  }
}

TEST_CASE("domain: a hexahedron equal to a box gives the box's mesh") {
  // The geode's own arrangement, in its reference box (-1, 0, -1)..(1, 1, 1), and in the
  // hexahedron with that box's corners: same elements, same numbering, same positions.
  for (int dim : {3, 2}) {
    CAPTURE(dim);
    const templates::GeodeArrangement G = templates::geode_arrangement({}, dim);
    const stc::Domain& box = G.domain;
    Corners P = unit_cube(box.lo, box.hi);
    const stc::Domain cell = dim == 3 ? stc::Domain::hexahedron(P)
                                      : stc::Domain::quadrilateral({P[0], P[1], P[2], P[3]});
    const auto a = stc::dualize(stc::compute_arrangement(G.sheets, box));
    const auto b = stc::dualize(stc::compute_arrangement(G.sheets, cell));
    const auto& pa = dim == 3 ? a.hex.points : a.quad.points;
    const auto& pb = dim == 3 ? b.hex.points : b.quad.points;
    CHECK(a.hex.hexes == b.hex.hexes);
    CHECK(a.quad.quads == b.quad.quads);
    CHECK(a.node_faces == b.node_faces);
    CHECK(a.node_signs == b.node_signs);
    REQUIRE(pa.size() == pb.size());
    CHECK(pa.size() == (dim == 3 ? 48u : 9u));
    for (std::size_t i = 0; i < pa.size(); ++i) CHECK((pa[i] - pb[i]).norm() < 1e-9);
  }
}

TEST_CASE("domain: an inverted or flat hexahedron is refused, naming the corner") {
  const Corners cube = unit_cube(Point(0, 0, 0), Point(1, 1, 1));
  struct Case {
    const char* name;
    Corners corners;
    const char* expect;
  };
  Corners mirrored = cube;  // top and bottom swapped: every corner Jacobian negative
  for (std::size_t c = 0; c < 4; ++c) std::swap(mirrored[c], mirrored[c + 4]);
  Corners dented = cube;  // corner 6 pushed through the cell: only its own frame turns over
  dented[6] = Point(0.3, 0.3, 0.3);
  Corners flat = cube;  // the top on the bottom
  for (std::size_t c = 4; c < 8; ++c) flat[c][2] = 0.0;
  for (const Case& c : {Case{"mirrored", mirrored, "corner 0 "},
                        Case{"dented", dented, "corner 6 "}, Case{"flat", flat, "corner 0 "}}) {
    CAPTURE(c.name);
    std::string msg;
    try {
      stc::Domain::hexahedron(c.corners);
    } catch (const InvalidInput& e) {
      msg = e.what();
    }
    CAPTURE(msg);
    CHECK(msg.find(c.expect) != std::string::npos);
    CHECK(msg.find("Jacobian is not positive") != std::string::npos);
  }
  // Clockwise quadrilateral.
  CHECK_THROWS_WITH_AS(
      stc::Domain::quadrilateral({Point(0, 0, 0), Point(0, 1, 0), Point(1, 1, 0), Point(1, 0, 0)}),
      doctest::Contains("corner 0 "), InvalidInput);
  // Corners filled in by hand are checked by the engine as well.
  stc::Domain d;
  d.corners = mirrored;
  CHECK_THROWS_AS(stc::compute_arrangement(cell_planes(stc::Domain::hexahedron(cube), 1), d),
                  InvalidInput);
}
