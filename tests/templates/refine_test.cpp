// The 3-refinement transition templates come out of their sheet arrangements (two tunnels over
// the paired outer fine chords, two middle planes, one layer; 2D: one of each): valid, the
// prescribed boundary (one coarse quad on top, 3 x 3 fine quads below), untangled after
// smoothing, and side faces that let neighbouring cells match.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/refine.hpp>
#include <geode/templates/spec.hpp>
#include "support/ball_checks.hpp"
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using primal::Point;
using templates::RefineOptions;

namespace {

constexpr double kTol = 1e-9;

primal::QuadMesh face_of(const primal::HexMesh& m, int axis, double value) {
  return test::boundary_quads(m, [=](const Point& p) { return std::abs(p[axis] - value) < kTol; });
}

// The positions of a face's nodes in the face's own (across, y) coordinates, rounded so that
// two faces can be compared as sets.
std::set<std::pair<long, long>> face_positions(const primal::QuadMesh& f, int across) {
  std::set<std::pair<long, long>> s;
  for (const auto& p : f.points) s.insert({std::lround(p[across] * 1e7), std::lround(p.y() * 1e7)});
  return s;
}

// Every node of `face` is one of the k x k grid's nodes over [-hx, hx] x [-hz, hz] and every
// grid node is used.
void check_grid(const primal::QuadMesh& face, int k, double hx, double hz) {
  std::set<std::pair<long, long>> want, got;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j <= k; ++j)
      want.insert(
          {std::lround((-hx + 2 * hx * i / k) * 1e7), std::lround((-hz + 2 * hz * j / k) * 1e7)});
  for (const auto& p : face.points)
    got.insert({std::lround(p.x() * 1e7), std::lround(p.z() * 1e7)});
  CHECK(got == want);
}

double min_quad_sj(const primal::QuadMesh& m) {
  double lo = 1e300;
  for (std::size_t q = 0; q < m.quads.size(); ++q)
    lo = std::min(lo, primal::quad_scaled_jacobian(primal::quad_corners(m, primal::index_cast(q)),
                                                   Point::UnitZ()));
  return lo;
}

}  // namespace

TEST_CASE("refine3-2d: one coarse edge over three fine ones, four quads, untangled") {
  RefineOptions o;
  auto T = templates::build_refine3_2d(o);
  CHECK(T.quad.quads.size() == 4);
  CHECK(T.quad.points.size() == 8);
  const auto before = primal::check_validity(T.quad);
  CHECK(before.euler == 1);
  CHECK(before.overshared_edges.empty());
  REQUIRE(before.boundary_loops.size() == 1);
  CHECK(before.boundary_loops.front().size() == 6);  // 3 fine below, 1 coarse above, 1 per side
  std::set<long> bottom, top;
  for (const auto& p : T.quad.points) {
    if (std::abs(p.y() + 7) < kTol) bottom.insert(std::lround(p.x() * 1e7));
    if (std::abs(p.y() - 7) < kTol) top.insert(std::lround(p.x() * 1e7));
  }
  CHECK(bottom ==
        std::set<long>{std::lround(-12e7), std::lround(-4e7), std::lround(4e7), std::lround(12e7)});
  CHECK(top == std::set<long>{std::lround(-12e7), std::lround(12e7)});
  const auto r = templates::smooth_refine3(T, o);
  CHECK(r.untangled);
  CHECK(primal::check_validity(T.quad).ok());
  MESSAGE("refine3-2d min scaled Jacobian " << min_quad_sj(T.quad));
  CHECK(min_quad_sj(T.quad) >= 0.5);
}

TEST_CASE(
    "refine3: the dual of two tunnels, two middle planes and a layer is a valid 13-hex cell") {
  RefineOptions o;
  const auto T = templates::build_refine3(o);
  // Sheet triples by hand: the tunnels' two crossing curves meet the middle plane across them
  // once each and the layer twice each (2 + 4); each tunnel meets the two planes along it and the
  // layer and its roof line meets the other middle plane (2 x 3); the two middle planes and the
  // layer meet once.
  CHECK(T.hex.hexes.size() == 13);
  CHECK(T.sheets.size() == 5);
  test::check_combinatorial_ball(primal::check_validity(T.hex));
  // Coarse side: one undiced quad on the box's top corners; fine side: the 3 x 3 grid.
  const auto top = face_of(T.hex, 1, 7.0), bottom = face_of(T.hex, 1, -7.0);
  CHECK(top.quads.size() == 1);
  check_grid(top, 1, 12, 12);
  CHECK(bottom.quads.size() == 9);
  check_grid(bottom, 3, 12, 12);
}

TEST_CASE("refine3: every side face is the 2D refinement template") {
  RefineOptions o;
  o.box = Eigen::Vector3d(20, 10, 30);
  const auto T = templates::build_refine3(o);
  auto o2 = o;
  const auto T2 = templates::build_refine3_2d(o2);
  for (int axis : {0, 2})
    for (double s : {-1.0, 1.0}) {
      CAPTURE(axis);
      CAPTURE(s);
      const auto side = face_of(T.hex, axis, s * 0.5 * o.box[axis]);
      CHECK(side.quads.size() == 4);
      CHECK(test::find_isomorphism(side, T2.quad).has_value());
    }
}

TEST_CASE("refine3: smoothed, untangled, and neighbouring cells match on their side faces") {
  // Targets per box: the geode's box, and a flat, stretched one (the fixed side faces cost
  // quality there: they are the 2D optimum, not the 3D one).
  const std::pair<Eigen::Vector3d, double> cases[] = {{Eigen::Vector3d(24, 14, 24), 0.4},
                                                      {Eigen::Vector3d(20, 10, 30), 0.25}};
  for (const auto& [box_, target] : cases) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& box = box_;
    CAPTURE(box.transpose());
    RefineOptions o;
    o.box = box;
    auto T = templates::build_refine3(o);
    const auto r = templates::smooth_refine3(T, o);
    CHECK(r.untangled);
    const auto v = primal::check_validity(T.hex);
    test::check_combinatorial_ball(v);
    CHECK(v.ok());
    MESSAGE("refine3 " << box.transpose() << ": min scaled Jacobian "
                       << r.final_min_scaled_jacobian);
    CHECK(r.final_min_scaled_jacobian >= target);
    // Fine and coarse sides stay where the refinement puts them.
    check_grid(face_of(T.hex, 1, 0.5 * box.y()), 1, 0.5 * box.x(), 0.5 * box.z());
    check_grid(face_of(T.hex, 1, -0.5 * box.y()), 3, 0.5 * box.x(), 0.5 * box.z());
    // A copy translated by one cell along x (z) meets this one on the face x = +w/2 (z = +d/2)
    // with its face x = -w/2 (z = -d/2): the two faces' nodes must coincide.
    for (int axis : {0, 2}) {
      const int across = 2 - axis;
      const auto lo = face_of(T.hex, axis, -0.5 * box[axis]),
                 hi = face_of(T.hex, axis, 0.5 * box[axis]);
      CHECK(face_positions(lo, across) == face_positions(hi, across));
      CHECK(lo.quads.size() == 4);
    }
    // Where the width equals the depth, a copy turned by 90 degrees matches too.
    if (box.x() == box.z())
      CHECK(face_positions(face_of(T.hex, 0, -0.5 * box.x()), 2) ==
            face_positions(face_of(T.hex, 2, -0.5 * box.z()), 0));
  }
}

TEST_CASE("refine3: heights out of order are rejected") {
  RefineOptions o;
  o.layer = 0.8;  // above both roofs
  CHECK_THROWS_AS(templates::build_refine3(o), InvalidInput);
  o = RefineOptions{};
  o.low_roof = 0.8;  // above the high roof
  CHECK_THROWS_AS(templates::build_refine3(o), InvalidInput);
  o = RefineOptions{};
  o.box.y() = 0;
  CHECK_THROWS_AS(templates::build_refine3_2d(o), InvalidInput);
}

TEST_CASE(
    "refine3: the templates are arrangement specs (faces block and shapes), read back exactly") {
  for (int dim : {2, 3}) {
    CAPTURE(dim);
    RefineOptions o;
    o.box = Eigen::Vector3d(20, 10, 30);
    const auto spec = templates::refine_spec(o, dim);
    // The prescribed faces: the 3-refinement below, the coarse cell above, as given (undiced).
    REQUIRE(spec.bottom_face.has_value());
    REQUIRE(spec.top_face.has_value());
    CHECK(spec.bottom_face->cells.size() == (dim == 3 ? 9u : 3u));
    CHECK(spec.top_face->cells.size() == 1);
    CHECK_FALSE(spec.completion.has_value());
    CHECK(spec.sheets.size() == (dim == 3 ? 5u : 3u));
    const auto text = templates::format_spec(templates::spec_json(spec));
    const auto read = templates::parse_spec(nlohmann::json::parse(text), "refine.json");
    const auto a = dim == 3 ? templates::build_refine3(o) : templates::build_refine3_2d(o);
    const auto b = templates::build_template(read);
    CHECK(a.element_sheets == b.element_sheets);
    if (dim == 3) {
      CHECK(a.hex.hexes == b.hex.hexes);
      CHECK(a.hex.points == b.hex.points);
    } else {
      CHECK(a.quad.quads == b.quad.quads);
      CHECK(a.quad.points == b.quad.points);
    }
  }
}

// The --box range `geode template --help` states, 1e-6 to 1e6: refine3 failed below 2e-4.
TEST_CASE("refine3: boxes down to the documented 1e-6 build the same templates") {
  for (double s : {1e-3, 1e-4, 1e-6}) {
    CAPTURE(s);
    templates::RefineOptions o;
    o.box = Eigen::Vector3d(s, s, s);
    const auto T2 = templates::build_refine3_2d(o);
    CHECK(T2.quad.quads.size() == 4);
    const auto T3 = templates::build_refine3(o);
    CHECK(T3.hex.hexes.size() == 13);
    CHECK(primal::check_validity(T3.hex).euler == 1);
  }
}

// Slabs and needles: with the tracing step a fraction of the diagonal, curves in the short
// directions were stepped over (exit 3 at aspect 80 and more); the step is now at most 32 times
// the shortest side's fraction.
TEST_CASE("refine3: slabs and needles up to aspect 200 build the template, valid") {
  for (const Eigen::Vector3d& box : {Eigen::Vector3d(1, 200, 1), Eigen::Vector3d(200, 1, 200),
                                     Eigen::Vector3d(0.14, 24, 0.14), Eigen::Vector3d(1, 100, 1)}) {
    CAPTURE(box.transpose());
    templates::RefineOptions o;
    o.box = box;
    const auto T3 = templates::build_refine3(o);
    CHECK(T3.hex.hexes.size() == 13);
    CHECK(primal::check_validity(T3.hex).ok());
  }
}
