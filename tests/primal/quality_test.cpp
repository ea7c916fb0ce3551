// Known-answer tests of the Verdict hex and quad metrics (primal/quality.hpp). Every expected
// value is worked out by hand in the comments of its case.
#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <geode/primal/detail/scaled_jacobian_paths.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace {

using geode::primal::HexCorners;
using geode::primal::HexMetric;
using geode::primal::Point;
using geode::primal::QuadCorners;
namespace gp = geode::primal;

constexpr double kNotChecked = std::numeric_limits<double>::quiet_NaN();
constexpr double kHuge = gp::kDegenerateMetric;

HexCorners unit_cube() {
  HexCorners p;
  for (int c = 0; c < 8; ++c) {
    const auto& x = gp::topology::kHexCornerCoords[c];
    p[c] = Point(x[0], x[1], x[2]);
  }
  return p;
}

// Order of the expected values: the registry order (edge ratio, aspect ratio, skew, taper,
// volume, stretch, diagonal, dimension, jacobian, scaled jacobian, condition, shape).
struct HexCase {
  const char* name;
  HexCorners corners;
  std::array<double, 12> expected;
};

std::vector<HexCase> hex_cases() {
  std::vector<HexCase> cases;

  // Unit cube: every ratio is 1 and every deviation 0. Diagonals sqrt(3), so stretch
  // sqrt(3) * 1 / sqrt(3) = 1. Principal axes 4 e_i: centre Jacobian 64 / 64 = 1. Dimension: V = 1,
  // dV/dx_c has 3 components of magnitude 1/4, so sum |grad|^2 = 8 * 3 / 16 = 3/2 and
  // sqrt(0.5 / 1.5) = 1/sqrt(3).
  cases.push_back(
      {"unit cube", unit_cube(), {1, 1, 0, 0, 1, 1, 1, 1 / std::sqrt(3.0), 1, 1, 1, 1}});

  // Sheared: the top face of the unit cube moved by (1, 0, 0). A parallelepiped with edge
  // vectors u = (1,0,0), v = (0,1,0), w = (1,0,1), |w| = sqrt 2.
  //  edge ratio sqrt2; principal axes 4u, 4v, 4w: aspect ratio sqrt2; skew |u.w|/|w| = 1/sqrt2;
  //  taper 0 (no cross derivative in an affine map); volume det(u,v,w) = 1;
  //  diagonals: 0-6 = u+v+w = (2,1,1) -> sqrt6, 1-7 = -u+v+w = (0,1,1) -> sqrt2, 2-4 -> sqrt2,
  //  3-5 -> sqrt6: diagonal ratio 1/sqrt3, stretch sqrt3 * 1 / sqrt6 = 1/sqrt2.
  //  Dimension of an affine hex x = M xi is 1 / |M^-1|_F (the sum over the 8 corner sign vectors
  //  s s^T is 8 I); M^-1 = [[1,0,-1],[0,1,0],[0,0,1]], |.|_F^2 = 4: 1/2.
  //  Jacobian: corner det 1, centre 64/64 = 1. Scaled: 1 / (1 * 1 * sqrt2) at corners and centre.
  //  Condition: |A|_F^2 = 4, |adj A|_F^2 = |u x v|^2 + |v x w|^2 + |w x u|^2 = 1 + 2 + 1 = 4,
  //  sqrt(16) / 1 / 3 = 4/3. Shape 3 * 1 / 4 = 0.75.
  {
    HexCorners p = unit_cube();
    for (int c = 4; c < 8; ++c) p[c].x() += 1.0;
    const double r2 = std::sqrt(2.0);
    cases.push_back(
        {"sheared",
         p,
         {r2, r2, 1 / r2, 0, 1, 1 / r2, 1 / std::sqrt(3.0), 0.5, 1, 1 / r2, 4.0 / 3.0, 0.75}});
  }

  // Tapered: bottom 2 x 2 square, top 1 x 1 square centred above it, height 1 (a frustum).
  //  Edges 2 (bottom), 1 (top), sqrt(1.5) (sides): edge ratio 2.
  //  X1 = (6,0,0), X2 = (0,6,0), X3 = (0,0,4): aspect ratio 6/4 = 1.5, skew 0.
  //  X12 = 0, X13 = (-2,0,0), X23 = (0,-2,0): taper 2 / min(6, 4) = 0.5.
  //  Volume h/3 (A1 + A2 + sqrt(A1 A2)) = (4 + 1 + 2) / 3 = 7/3.
  //  All 4 diagonals (1.5,1.5,1) long: diagonal 1, stretch sqrt3 * 1 / sqrt(5.5).
  //  Corner 0: A = [(2,0,0), (0,2,0), (.5,.5,1)], det 4; corner 4: A = [(0,1,0), (1,0,0),
  //  (-.5,-.5,-1)], det 1; centre 6*6*4/64 = 2.25: jacobian 1.
  //  Scaled: 4 / (2*2*sqrt1.5) = 1 / (1*1*sqrt1.5) = sqrt(2/3) at every corner; centre 1.
  //  Condition at corner 0: |A|^2 = 9.5, |adj|^2 = 16 + 5 + 5 = 26, sqrt(247)/4/3 = 1.309686;
  //  corner 4: |A|^2 = 3.5, |adj|^2 = 1 + 1.25 + 1.25 = 3.5, 3.5/3 = 1.1667: max 1.309686.
  //  Shape: corner 0: 3 * 4^(2/3) / 9.5 = 0.795739; corner 4: 3 / 3.5 = 0.857: min 0.795739.
  //  Dimension not worked by hand (see the 24-tet and finite-difference checks below).
  {
    HexCorners p;
    p[0] = {0, 0, 0}, p[1] = {2, 0, 0}, p[2] = {2, 2, 0}, p[3] = {0, 2, 0};
    p[4] = {0.5, 0.5, 1}, p[5] = {1.5, 0.5, 1}, p[6] = {1.5, 1.5, 1}, p[7] = {0.5, 1.5, 1};
    cases.push_back({"tapered",
                     p,
                     {2, 1.5, 0, 0.5, 7.0 / 3.0, std::sqrt(3.0 / 5.5), 1, kNotChecked, 1,
                      std::sqrt(2.0 / 3.0), std::sqrt(247.0) / 12.0, 3.0 * std::cbrt(16.0) / 9.5}});
  }

  // Flat: the top face of the unit cube laid into z = 0 and moved by (1,0,0), so that every
  // edge keeps length 1 but the hex has no volume. u = (1,0,0), v = (0,1,0), w = (1,0,0).
  //  edge ratio 1, aspect 1 (|X| all 4), skew |u.w| = 1, taper 0 (affine), volume 0;
  //  diagonals 0-6 = (2,1,0) sqrt5, 1-7 = (0,1,0) 1, 2-4 1, 3-5 sqrt5: diagonal 1/sqrt5,
  //  stretch sqrt3/sqrt5; dimension 0 (V = 0); every determinant 0: jacobian 0, scaled 0;
  //  condition has no inverse: Verdict's huge value; shape 0.
  {
    HexCorners p = unit_cube();
    for (int c = 4; c < 8; ++c) p[c] += Point(1, 0, -1);
    cases.push_back(
        {"flat", p, {1, 1, 1, 0, 0, std::sqrt(3.0 / 5.0), 1 / std::sqrt(5.0), 0, 0, 0, kHuge, 0}});
  }

  // Inverted: the unit cube with its bottom and top faces swapped (a mirror image). Lengths,
  // angles and ratios are those of the cube; every determinant is -1 (centre 4*4*(-4)/64):
  // volume -1, jacobian -1, scaled -1, condition huge, shape 0. Dimension uses V^2: 1/sqrt3.
  {
    HexCorners p = unit_cube();
    for (int c = 0; c < 8; ++c) p[c].z() = 1.0 - p[c].z();
    cases.push_back({"inverted", p, {1, 1, 0, 0, -1, 1, 1, 1 / std::sqrt(3.0), -1, -1, kHuge, 0}});
  }
  return cases;
}

// An independent volume: 24 tets, each face split into 4 triangles through its centroid and
// joined to the cell centroid (the rule of newer Verdict versions).
double volume_24_tets(const HexCorners& p) {
  Point centre = Point::Zero();
  for (const auto& x : p) centre += x / 8.0;
  double v = 0.0;
  for (const auto& f : gp::topology::kHexFaceCorners) {
    const Point fc = (p[f[0]] + p[f[1]] + p[f[2]] + p[f[3]]) / 4.0;
    for (int i = 0; i < 4; ++i) {
      const Point& a = p[f[i]];
      const Point& b = p[f[(i + 1) % 4]];
      // Outward face, so the tet (a, b, fc, centre) is negatively oriented seen from outside.
      v += (a - centre).dot((b - centre).cross(fc - centre)) / 6.0;
    }
  }
  return v;
}

HexCorners warped_hex() {
  HexCorners p = unit_cube();
  p[1] += Point(0.2, -0.1, 0.15);
  p[2] += Point(0.3, 0.25, -0.2);
  p[5] += Point(-0.1, 0.05, 0.3);
  p[6] += Point(0.4, 0.1, 0.2);
  p[7] += Point(-0.2, 0.3, -0.1);
  return p;
}

}  // namespace

TEST_CASE("hex metrics: known answers (unit cube, sheared, tapered, flat, inverted)") {
  const auto metrics = gp::hex_metrics();
  REQUIRE(metrics.size() == 12);
  for (const auto& c : hex_cases()) {
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      if (std::isnan(c.expected[m])) continue;
      CAPTURE(c.name);
      CAPTURE(std::string(metrics[m].name));
      const double got = metrics[m].evaluate(c.corners);
      CHECK(got == doctest::Approx(c.expected[m]).epsilon(1e-12).scale(1.0));
    }
  }
}

TEST_CASE("hex volume equals the 24-tet split and dimension matches its definition") {
  const HexCorners p = warped_hex();
  CHECK(gp::hex_volume(p) == doctest::Approx(volume_24_tets(p)).epsilon(1e-13));
  for (const auto& c : hex_cases()) {
    CAPTURE(c.name);
    CHECK(gp::hex_volume(c.corners) == doctest::Approx(volume_24_tets(c.corners)).scale(1.0));
  }
  // Dimension = sqrt(V^2 / (2 |grad V|^2)); gradient by central differences of hex_volume.
  for (const HexCorners& q : {warped_hex(), hex_cases()[2].corners}) {
    double g2 = 0.0;
    const double h = 1e-6;
    for (int c = 0; c < 8; ++c) {
      for (int i = 0; i < 3; ++i) {
        HexCorners a = q, b = q;
        a[c][i] += h;
        b[c][i] -= h;
        const double d = (gp::hex_volume(a) - gp::hex_volume(b)) / (2 * h);
        g2 += d * d;
      }
    }
    const double v = gp::hex_volume(q);
    CHECK(gp::hex_dimension(q) == doctest::Approx(std::sqrt(0.5 * v * v / g2)).epsilon(1e-7));
  }
}

TEST_CASE("hex scaled jacobian takes the minimum over 8 corners and the centre") {
  // Tapered (see its case above): corners sqrt(2/3), centre 1.
  const auto q = gp::hex_scaled_jacobians(hex_cases()[2].corners);
  CHECK(q[8] == doctest::Approx(1.0));
  for (int c = 0; c < 8; ++c) CHECK(q[c] == doctest::Approx(std::sqrt(2.0 / 3.0)));

  // Tilted top: p5, p6 raised to z = 3, so the top r-edges are (1,0,2) and the t-edges
  // (0,0,1), (0,0,3), (0,0,3), (0,0,1). Principal axes X1 = 2(1,0,0) + 2(1,0,2) = (4,0,4),
  // X2 = (0,4,0), X3 = (0,0,8): centre det 128 / (4 sqrt2 * 4 * 8) = 1/sqrt2.
  // Corner 0: identity frame, 1. Corner 1: (0,1,0), (-1,0,0), (0,0,3): det 3 / 3 = 1.
  // Corner 4: e_r = p7 - p4 = (0,1,0), e_s = p5 - p4 = (1,0,2), e_t = p0 - p4 = (0,0,-1):
  // (1,0,2) x (0,0,-1) = (0,1,0), det 1, scaled 1 / sqrt5.
  HexCorners p = unit_cube();
  p[5].z() = 3.0;
  p[6].z() = 3.0;
  const auto t = gp::hex_scaled_jacobians(p);
  CHECK(t[0] == doctest::Approx(1.0));
  CHECK(t[1] == doctest::Approx(1.0));
  CHECK(t[4] == doctest::Approx(1 / std::sqrt(5.0)));
  CHECK(t[8] == doctest::Approx(1 / std::sqrt(2.0)));
  CHECK(gp::hex_scaled_jacobian(p) == doctest::Approx(1 / std::sqrt(5.0)));
  // Jacobians: corner 1 det 3, centre 128 / 64 = 2.
  const auto j = gp::hex_jacobians(p);
  CHECK(j[1] == doctest::Approx(3.0));
  CHECK(j[8] == doctest::Approx(2.0));
}

TEST_CASE("hex scaled jacobian: the same number as the nine values' minimum, bit for bit") {
  // Smoothing, verification and the reports compare hex_scaled_jacobian's values with
  // hex_scaled_jacobians' and the bounded form's (a hex above 0 has positive corners), so they
  // must be the same doubles, not just close. Skewed, flat, inverted and collapsed hexes, at
  // scales from 1e-4 to 1e4.
  const auto paths = gp::detail::scaled_jacobian_paths();
  std::uint64_t state = 12345;
  auto uniform = [&state] {  // 53-bit LCG draws in [0, 1): the same on every platform
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int trial = 0; trial < 20000; ++trial) {
    HexCorners p = unit_cube();
    const double spread = trial % 4 == 0 ? 1.5 : 0.3;
    const double scale = std::pow(10.0, trial % 9 - 4);
    for (auto& x : p) {
      for (int i = 0; i < 3; ++i) x[i] += spread * (uniform() - 0.5);
      x *= scale;
    }
    if (trial % 50 == 0) p[6] = p[5];  // a collapsed edge: 0 at its corners
    const auto q = gp::hex_scaled_jacobians(p);
    const double lowest = *std::min_element(q.begin(), q.end());
    CHECK(gp::hex_scaled_jacobian(p) == lowest);
    // Both implementations (AVX2 where the processor has it, and SSE2), whichever runs.
    CHECK(paths.fastest(p) == lowest);
    CHECK(paths.portable(p) == lowest);
    CHECK(gp::hex_scaled_jacobian_bounded(p, -std::numeric_limits<double>::infinity()) == lowest);
    CHECK(paths.fastest_bounded(p, -std::numeric_limits<double>::infinity()) == lowest);
    CHECK(paths.portable_bounded(p, -std::numeric_limits<double>::infinity()) == lowest);
    // With a bound: exact above it, at or below it otherwise.
    const double bound = uniform() - 0.5;
    for (const double bounded : {gp::hex_scaled_jacobian_bounded(p, bound),
                                 paths.fastest_bounded(p, bound), paths.portable_bounded(p, bound)})
      CHECK((lowest > bound ? bounded == lowest : bounded <= bound));
  }
}

TEST_CASE("quad jacobian and scaled jacobian") {
  const Point z(0, 0, 1);
  struct QuadCase {
    const char* name;
    QuadCorners p;
    double jac, sj;      // Verdict: sign from the element's own centre normal
    double jac_z, sj_z;  // sign relative to +z
  };
  const double s3 = std::sqrt(3.0);
  const std::vector<QuadCase> cases = {
      // Square of side 2: every corner area 4, scaled 1.
      {"square", {Point(0, 0, 0), Point(2, 0, 0), Point(2, 2, 0), Point(0, 2, 0)}, 4, 1, 4, 1},
      // Rhombus with 60 degree angles, side 1: corner area sin 60 = sqrt3/2 at all corners.
      {"rhombus",
       {Point(0, 0, 0), Point(1, 0, 0), Point(1.5, s3 / 2, 0), Point(0.5, s3 / 2, 0)},
       s3 / 2,
       s3 / 2,
       s3 / 2,
       s3 / 2},
      // The square traversed clockwise: fine for Verdict (its own normal is -z), inverted for +z.
      {"clockwise", {Point(0, 0, 0), Point(0, 2, 0), Point(2, 2, 0), Point(2, 0, 0)}, 4, 1, -4, -1},
      // Arrow (non-convex): corner 2 at (0.5, 0.5) is reflex. Its edges a = p3 - p2 = (-.5, 1.5),
      // b = p1 - p2 = (1.5, -.5): a x b = .25 - 2.25 = -2, scaled -2 / 2.5 = -0.8. Centre normal
      // (p2 - p0) x (p3 - p1) = (.5,.5) x (-2,2) = +2 z.
      {"arrow",
       {Point(0, 0, 0), Point(2, 0, 0), Point(0.5, 0.5, 0), Point(0, 2, 0)},
       -2,
       -0.8,
       -2,
       -0.8},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    CHECK(gp::quad_jacobian(c.p) == doctest::Approx(c.jac));
    CHECK(gp::quad_scaled_jacobian(c.p) == doctest::Approx(c.sj));
    CHECK(gp::quad_jacobian(c.p, z) == doctest::Approx(c.jac_z));
    CHECK(gp::quad_scaled_jacobian(c.p, z) == doctest::Approx(c.sj_z));
  }
}

TEST_CASE("hex metric registry: lookup by id, key and name; unknown names are rejected") {
  for (const auto& m : gp::hex_metrics()) {
    CHECK(&gp::hex_metric_info(m.metric) == &m);
    CHECK(&gp::hex_metric_info(m.key) == &m);
    CHECK(&gp::hex_metric_info(m.name) == &m);
    CHECK(m.acceptable_min < m.acceptable_max);
  }
  const bool same_fn =
      gp::hex_metric_info(HexMetric::kScaledJacobian).evaluate == &gp::hex_scaled_jacobian;
  CHECK(same_fn);
  CHECK_THROWS_AS(gp::hex_metric_info("warpage"), geode::InvalidInput);
  CHECK_THROWS_WITH(gp::hex_metric_info("warpage"), doctest::Contains("warpage"));
}

TEST_CASE("hex_corners and quad_corners reject bad indices with the element named") {
  gp::HexMesh mesh;
  const auto cube = unit_cube();
  mesh.points.assign(cube.begin(), cube.end());
  mesh.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  mesh.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 9});
  CHECK(gp::hex_corners(mesh, 0)[6] == Point(1, 1, 1));
  CHECK_THROWS_WITH(gp::hex_corners(mesh, 1), doctest::Contains("hex 1 corner 7"));
  CHECK_THROWS_AS(gp::hex_corners(mesh, 2), geode::InvalidInput);
  gp::QuadMesh quads;
  quads.points = {Point(0, 0, 0), Point(1, 0, 0), Point(1, 1, 0)};
  quads.quads.push_back({0, 1, 2, 3});
  CHECK_THROWS_WITH(gp::quad_corners(quads, 0), doctest::Contains("quad 0 corner 3"));
}
