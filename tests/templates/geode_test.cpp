// The geode templates come out of their sheet arrangements: compare them with the paper's
// Appendix A by graph isomorphism, check validity, the prescribed boundary and the paper's
// two interleaving conditions.
#include <doctest/doctest.h>

#include <cmath>
#include <set>

#include <geode/primal/errors.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/geode.hpp>
#include "support/ball_checks.hpp"
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using templates::GeodeOptions;

namespace {

// Labels: which box faces (top, bottom, sides) a node lies on, so that the isomorphism must
// map the tet side to the tet side and the hex side to the hex side.
int side_label(const primal::Point& p, const Eigen::Vector3d& box) {
  const double eps = 1e-6 * box.norm();
  int l = 0;
  if (std::abs(p.y() - 0.5 * box.y()) < eps) l |= 1;
  if (std::abs(p.y() + 0.5 * box.y()) < eps) l |= 2;
  if (std::abs(std::abs(p.x()) - 0.5 * box.x()) < eps ||
      std::abs(std::abs(p.z()) - 0.5 * box.z()) < eps)
    l |= 4;
  return l;
}

test::NodeLabels labels(const primal::HexMesh& a, const primal::HexMesh& b,
                        const Eigen::Vector3d& box) {
  test::NodeLabels L;
  for (const auto& p : a.points) L.first.push_back(side_label(p, box));
  for (const auto& p : b.points) L.second.push_back(side_label(p, box));
  return L;
}

primal::QuadMesh side_face(const primal::HexMesh& m, int axis, double value) {
  return test::boundary_quads(
      m, [=](const primal::Point& p) { return std::abs(p[axis] - value) < 1e-9; });
}

}  // namespace

TEST_CASE("geode3d: the derived template is isomorphic to the paper's Appendix A") {
  const GeodeOptions o;
  const auto T = templates::build_geode3d(o);
  CHECK(T.hex.hexes.size() == 26);
  CHECK(T.hex.points.size() == 48);
  const primal::HexMesh ref = test::appendix_a_geode();
  const auto m = test::find_isomorphism(T.hex, ref, labels(T.hex, ref, o.box));
  REQUIRE(m.has_value());
  CHECK(test::is_isomorphism(T.hex, ref, *m, labels(T.hex, ref, o.box)));
  CHECK(T.checks.ok());
  CHECK(T.checks.triple_dome_points == 2);
  CHECK(T.checks.dome_curves_on_tet_face == 1);
  // Six sheets: two tunnels and four domes.
  int tunnels = 0, domes = 0;
  for (const auto& s : T.sheets) (s.kind == "tunnel" ? tunnels : domes) += 1;
  CHECK(tunnels == 2);
  CHECK(domes == 4);
}

TEST_CASE("geode3d: tet-side and hex-side nodes sit exactly where dicing puts them") {
  const GeodeOptions o;
  const auto T = templates::build_geode3d(o);
  std::set<std::pair<long, long>> top, bottom;
  for (const auto& p : T.hex.points) {
    auto key = std::make_pair(std::lround(p.x() * 1000), std::lround(p.z() * 1000));
    if (std::abs(p.y() - 7) < 1e-9) top.insert(key);
    if (std::abs(p.y() + 7) < 1e-9) bottom.insert(key);
  }
  // Diced quad: 3 x 3 grid at -12, 0, 12.
  std::set<std::pair<long, long>> expect_bottom;
  for (int i : {-12, 0, 12})
    for (int j : {-12, 0, 12}) expect_bottom.insert({i * 1000, j * 1000});
  CHECK(bottom == expect_bottom);
  // Diced triangles (main diagonal (-12,12)-(12,-12)): corners, edge midpoints, the diagonal's
  // midpoint and the two centroids (+-4, +-4).
  std::set<std::pair<long, long>> expect_top = expect_bottom;
  expect_top.insert({4000, 4000});
  expect_top.insert({-4000, -4000});
  CHECK(top == expect_top);
}

TEST_CASE("geode3d: other boxes, diagonals and tunnel orders give the same template") {
  const primal::HexMesh ref = test::appendix_a_geode();
  struct Case {
    Eigen::Vector3d box;
    templates::Diagonal d;
    templates::Higher h;
  };
  for (const Case& c : {Case{{24, 14, 24}, templates::Diagonal::kAnti, templates::Higher::kX},
                        Case{{24, 14, 24}, templates::Diagonal::kMain, templates::Higher::kZ},
                        Case{{10, 30, 16}, templates::Diagonal::kMain, templates::Higher::kX}}) {
    GeodeOptions o;
    o.box = c.box;
    o.diagonal = c.d;
    o.higher = c.h;
    const auto T = templates::build_geode3d(o);
    CAPTURE(c.box.transpose());
    CHECK(test::find_isomorphism(T.hex, ref).has_value());
  }
}

TEST_CASE("geode2d: the 2D geode has five quads and is each side face of the 3D geode") {
  GeodeOptions o;
  const auto T2 = templates::build_geode2d(o);
  CHECK(T2.quad.quads.size() == 5);
  CHECK(T2.quad.points.size() == 9);
  const auto T3 = templates::build_geode3d(o);
  for (int axis : {0, 2})
    for (double s : {-12.0, 12.0}) {
      const primal::QuadMesh side = side_face(T3.hex, axis, s);
      CAPTURE(axis);
      CAPTURE(s);
      CHECK(side.quads.size() == 5);
      CHECK(test::find_isomorphism(side, T2.quad).has_value());
    }
}

TEST_CASE("geode: pushing the arrangements too little is diagnosed, not meshed") {
  GeodeOptions o;
  o.push.dome_depth = 0.3;  // domes stay above the tunnels: dome-tunnel curves with no vertex
  CHECK_THROWS_AS(templates::build_geode3d(o), TopologyError);
}

TEST_CASE("geode: bad options are rejected") {
  GeodeOptions o;
  o.push.high_roof = 1.2;
  CHECK_THROWS_AS(templates::build_geode3d(o), InvalidInput);
  CHECK_THROWS_AS(templates::parse_box("24x14x"), InvalidInput);
  CHECK_THROWS_AS(templates::parse_box("24x-1x3"), InvalidInput);
  CHECK(templates::parse_box("24x14x24") == Eigen::Vector3d(24, 14, 24));
}

using test::check_combinatorial_ball;

TEST_CASE("geode3d: the smoothed template is a valid mesh of the box") {
  for (bool slide : {false, true}) {
    CAPTURE(slide);
    auto T = templates::build_geode3d(GeodeOptions{});
    const auto before = primal::check_validity(T.hex);
    check_combinatorial_ball(before);
    const auto r = templates::smooth_template(T, slide);
    CHECK(r.untangled);
    const auto after = primal::check_validity(T.hex);
    check_combinatorial_ball(after);
    CHECK(after.inverted_hexes.empty());
    CHECK(after.ok());
    // Issue target: the paper reached 0.26; ours must reach 0.40 in both modes.
    CHECK(r.final_min_scaled_jacobian >= 0.40);
  }
}

TEST_CASE("geode2d: the smoothed 2D geode is a valid quad mesh of the rectangle") {
  auto T = templates::build_geode2d(GeodeOptions{});
  const auto r = templates::smooth_template(T, false);
  CHECK(r.untangled);
  const auto v = primal::check_validity(T.quad);
  CHECK(v.ok());
  CHECK(v.euler == 1);
  CHECK(v.boundary_loops.size() == 1);
  CHECK(v.boundary_loops.front().size() == 6);  // 2 diced edges top and bottom, 1 per side
}

// The paper's open question (Section 5): split the tet-side quad into four triangles. What we
// found (see README): the arrangement (2 tunnels, 5 domes) dualizes to a combinatorially valid
// 36-hex mesh with the prescribed boundary and 2D-geode sides, but it fails the paper's first
// condition: the four points where three domes meet lie outside the tunnels' pocket (why:
// tests/templates/four_triangle_test.cpp), and the smoother does not untangle it.
TEST_CASE("geode4tri: what the four-triangle variant yields") {
  GeodeOptions o;
  o.split = templates::TopSplit::kFourTriangles;
  auto T = templates::build_geode3d(o);
  CHECK(T.hex.hexes.size() == 36);
  CHECK(T.sheets.size() == 7);
  check_combinatorial_ball(primal::check_validity(T.hex));
  CHECK(T.checks.triple_dome_points == 4);
  CHECK_FALSE(T.checks.triple_domes_in_pocket);
  const auto T2 = templates::build_geode2d(GeodeOptions{});
  for (int axis : {0, 2})
    for (double s : {-12.0, 12.0})
      CHECK(test::find_isomorphism(side_face(T.hex, axis, s), T2.quad).has_value());
}

TEST_CASE(
    "geode4tri: superquadric domes over a shallow centre dome give an obstruction-free 44-hex "
    "template") {
  // The same push with spheroid domes (p = 2) has a pinched corner and fails condition 1; with
  // p = 3 for every dome the triple-dome points fall inside both tunnels and the dual has no
  // obstruction, so the plain dual (no fix-up) smooths to positive Jacobians.
  GeodeOptions o;
  o.split = templates::TopSplit::kFourTriangles;
  o.push.centre_depth = 0.45;
  o.push.dome_radius = 0.8;
  o.push.centre_radius = 0.6;
  const auto spheroids = templates::build_geode3d(o);
  CHECK(spheroids.hex.hexes.size() == 40);
  CHECK_FALSE(spheroids.checks.triple_domes_in_pocket);
  CHECK(templates::template_obstructions(spheroids).size() == 1);

  o.push.dome_exponent = 3;
  auto T = templates::build_geode3d(o);
  CHECK(T.hex.hexes.size() == 44);
  check_combinatorial_ball(primal::check_validity(T.hex));
  CHECK(T.checks.ok());
  CHECK(T.checks.triple_dome_points == 4);
  CHECK(templates::template_obstructions(T).empty());
  // The prescribed boundary: 12 diced-triangle quads on the tet side, 4 on the hex side, and
  // each side face the 2D geode, so it sits beside ordinary geodes.
  CHECK(side_face(T.hex, 1, 7.0).quads.size() == 12);
  CHECK(side_face(T.hex, 1, -7.0).quads.size() == 4);
  const auto T2 = templates::build_geode2d(GeodeOptions{});
  for (int axis : {0, 2})
    for (double s : {-12.0, 12.0})
      CHECK(test::find_isomorphism(side_face(T.hex, axis, s), T2.quad).has_value());
  const auto r = templates::smooth_template(T, false);
  CHECK(r.untangled);
  CHECK(primal::check_validity(T.hex).ok());
  MESSAGE("geode4tri, p = 3 domes: min scaled Jacobian " << r.final_min_scaled_jacobian
                                                         << " (faces fixed)");
  CHECK(r.final_min_scaled_jacobian >= 0.4);
}
