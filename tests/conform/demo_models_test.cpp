// conform() on the realistic demo models (Gmsh Delaunay tets, alternating and random
// interface diagonals, a concave L-shaped interface, a curved cylinder, a convex nugget, the
// nugget with circles imprinted on three faces after Fulcher): the
// result is a valid all-hex mesh (every interior face shared by two hexes, closed manifold
// boundary, Euler characteristic of a ball) with every scaled Jacobian positive, without
// smoothing and with the defaults.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <string>

#include "conform/conform.hpp"
#include "conform/demo_models.hpp"
#include "primal/interface.hpp"
#include "primal/quality.hpp"
#include "primal/validity.hpp"

using namespace geode;

namespace {

void check_valid(const conform::ConformResult& r) {
  const primal::HexMesh mesh = primal::hex_part(r.model);
  const primal::HexValidityReport v = primal::check_validity(mesh);
  INFO(v.summary());
  CHECK(v.ok());
  CHECK(v.overshared_faces.empty());
  CHECK(v.boundary.closed);
  CHECK(v.boundary.manifold);
  CHECK(v.euler == 1);
  CHECK(v.boundary.euler == 2);
  CHECK(primal::min_scaled_jacobian(mesh) > 0.0);
  CHECK(r.warnings.empty());
  CHECK(r.geode_hexes == 26 * r.interface_quads);
}

}  // namespace

TEST_CASE("realistic models, no smoothing: valid and untangled by the placement alone") {
  conform::ConformOptions o;
  o.smooth = conform::ConformSmooth::kNone;
  // The curved cylinder and the convex nugget meet neighbouring buffer hexes at an angle: their
  // shared side faces must take the same nodes from both templates.
  const struct {
    const char* name;
    primal::Index quads;
  } models[] = {{"delaunay", 9}, {"delaunay-random", 9}, {"lshape", 18}, {"nugget", 96}, {"cylinder", 146}};
  for (const auto& [name, quads] : models) {
    CAPTURE(name);
    const primal::Model m = conform::demo_model(name, 3);
    REQUIRE(!m.tets.empty());
    const auto r = conform::conform(m, o);
    CHECK(r.interface_quads == quads);
    check_valid(r);
  }
}

TEST_CASE("realistic models, default options: valid and untangled") {
  const struct {
    const char* name;
    int n;
  } models[] = {{"delaunay-random", 2}, {"cylinder", 2}, {"fulcher", 4}};
  for (const auto& [name, n] : models) {
    CAPTURE(name);
    const auto r = conform::conform(conform::demo_model(name, n));
    check_valid(r);
    // The yardstick is measured on the input itself: Delaunay tets are far from the diced
    // Kuhn cube's 0.29, the swept hexes of the cylinder and the imprinted faces far from 1.
    CHECK(r.input_diced_tet_min_scaled_jacobian < 0.2);
    CHECK(r.input_diced_tet_min_scaled_jacobian > 0.0);
  }
}

TEST_CASE("fulcher demo: circles imprinted on three nugget faces, the parts conforming node-wise") {
  const int n = 4;
  const primal::Model m = conform::demo_fulcher(n);
  // The parts fill the box: nugget [-1,1]^3 of tets, the 26 blocks around it of hexes.
  double tet_volume = 0, hex_volume = 0;
  for (const auto& t : m.tets) {
    const double v = primal::tet_volume(m.points[t[0]], m.points[t[1]], m.points[t[2]], m.points[t[3]]);
    CHECK(v > 0);
    tet_volume += v;
  }
  for (const auto& h : m.hexes) {
    primal::HexCorners c;
    for (std::size_t i = 0; i < 8; ++i) c[i] = m.points[static_cast<std::size_t>(h[i])];
    CHECK(primal::hex_volume(c) > 0);
    hex_volume += primal::hex_volume(c);
  }
  CHECK(tet_volume == doctest::Approx(8.0));
  CHECK(hex_volume == doctest::Approx(56.0));
  // Every nugget face is interface: n x n quads on the three plain faces, unstructured quads
  // with the circle of radius r as a chain of quad corners on the faces x, y, z = 1.
  const primal::Interface in = primal::find_interface(m);
  std::array<int, 6> quads_on_face{};
  for (const auto& q : in.quads) {
    primal::Point c = primal::Point::Zero();
    for (primal::Index v : q.corners) c += m.points[static_cast<std::size_t>(v)] / 4.0;
    int axis = 0;
    c.cwiseAbs().maxCoeff(&axis);
    CHECK(std::abs(std::abs(c[axis]) - 1.0) < 1e-9);
    ++quads_on_face[static_cast<std::size_t>(2 * axis + (c[axis] > 0 ? 1 : 0))];
  }
  const double radii[3] = {0.3, 0.5, 0.7};
  for (int axis = 0; axis < 3; ++axis) {
    CAPTURE(axis);
    CHECK(quads_on_face[static_cast<std::size_t>(2 * axis)] == n * n);
    CHECK(quads_on_face[static_cast<std::size_t>(2 * axis + 1)] > 0);
    int on_circle = 0;
    for (primal::Index v : in.nodes) {
      const primal::Point& p = m.points[static_cast<std::size_t>(v)];
      const double u = p[(axis + 1) % 3], w = p[(axis + 2) % 3];
      if (std::abs(p[axis] - 1.0) < 1e-9 && std::abs(std::hypot(u, w) - radii[axis]) < 1e-6) ++on_circle;
    }
    CHECK(on_circle >= 8);
  }
  // The outer box: 2n x 2n quads per face but for the three swept slabs' ends, which repeat
  // their imprinted faces.
  REQUIRE(m.side_sets.size() == 1);
  CHECK(m.side_sets[0].sides.size() ==
        static_cast<std::size_t>(21 * n * n + quads_on_face[1] + quads_on_face[3] + quads_on_face[5]));
}
