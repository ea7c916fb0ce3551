// Why the four-triangle variant fails the paper's first condition with our completion (the
// paper's open question, Section 5), checked on the computed arrangements rather than argued
// only on paper.
//
// Domes are ellipsoids f = (r / R)^2 + ((1 - v) / depth)^2 - 1 with one depth for all
// (templates/completion.hpp), so where three domes meet the depth term cancels and
// r_a / R_a = r_b / R_b = r_c / R_c. For the triangle (corner a, corner b, centre c) the
// point lies, by symmetry, on the perpendicular from the centre to the side ab, at distance t
// from the centre (reference cell, half-width 1) with
//     sqrt(1 + (1 - t)^2) / R_corner = t / R_centre.
// Both tunnels' footprints are |u| < 1/2 and |w| < 1/2 (a quarter of the quad's side from its
// chord), so "inside both tunnels" needs t < 1/2, i.e. R_corner / R_centre > sqrt(5) (the
// left side is sqrt(5/4) at t = 1/2). But the diced nodes bound the radii: a corner's circle
// must leave the centre vertex out (R_corner < sqrt 2) and the centre's circle must enclose the
// midpoints of its edges (R_centre > sqrt(2) / 2), so R_corner / R_centre < 2 < sqrt(5). No
// push of this family (any roof heights, depth, radius blend) can meet condition 1; a template
// from the four-triangle split needs domes that are not all of one depth (or not centred on
// their vertices), or a different tunnel completion.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "primal/errors.hpp"
#include "stc/arrangement.hpp"
#include "templates/completion.hpp"
#include "templates/geode.hpp"

using namespace geode;
using primal::Point;
using templates::GeodeOptions;

namespace {

double planar(const Point& p, const Point& q) { return std::hypot(p.x() - q.x(), p.z() - q.z()); }

// The admissible radius interval of the circle around patch vertex v: above the farthest
// diced node it must enclose, below the nearest it must leave out (as complete_domes reads it).
std::pair<double, double> radius_bounds(const templates::InterfacePatch& patch, int v) {
  const auto diced = templates::dice_patch(patch);
  double inside = 0.0, outside = 1e300;
  for (std::size_t n = 0; n < diced.nodes.size(); ++n) {
    const double d = planar(diced.nodes[n], patch.points[static_cast<std::size_t>(v)]);
    const auto& own = diced.owners[n];
    if (std::find(own.begin(), own.end(), v) != own.end())
      inside = std::max(inside, d);
    else
      outside = std::min(outside, d);
  }
  return {inside, outside};
}

}  // namespace

TEST_CASE("geode4tri: the diced nodes cap R_corner / R_centre below sqrt(5)") {
  GeodeOptions o;
  o.split = templates::TopSplit::FourTriangles;
  const auto G = templates::geode_arrangement(o, 3);
  REQUIRE(G.tet_side.points.size() == 5);
  const int centre = 4;  // the added vertex (0, 1, 0)
  REQUIRE(planar(G.tet_side.points[centre], Point(0, 1, 0)) < 1e-12);
  const auto [centre_in, centre_out] = radius_bounds(G.tet_side, centre);
  CHECK(centre_in == doctest::Approx(std::sqrt(2.0) / 2));  // its edges' midpoints
  CHECK(centre_out == doctest::Approx(1.0));                // the side midpoints
  for (int corner = 0; corner < 4; ++corner) {
    CAPTURE(corner);
    const auto [in, out] = radius_bounds(G.tet_side, corner);
    CHECK(in == doctest::Approx(std::sqrt(10.0) / 3));  // its triangles' centroids
    CHECK(out == doctest::Approx(std::sqrt(2.0)));      // the centre vertex
    // The largest ratio any admissible pair of radii reaches, against the pocket's need.
    CHECK(out / centre_in < std::sqrt(5.0));
  }
}

TEST_CASE("geode4tri: the triple-dome points sit where the ratio says, outside the pocket") {
  int runs_with_points = 0;
  for (double blend : {0.1, 0.3, 0.6, 0.9})
    for (double depth : {0.6, 0.9}) {
      CAPTURE(blend);
      CAPTURE(depth);
      GeodeOptions o;
      o.split = templates::TopSplit::FourTriangles;
      o.push.dome_radius = blend;
      o.push.dome_depth = depth;
      const auto G = templates::geode_arrangement(o, 3);
      const auto domes = templates::complete_domes(G.tet_side, 1.0, depth, blend);
      REQUIRE(domes.size() == 5);
      const std::size_t first_dome = G.sheets.size() - domes.size();
      double r_corner = 0.0, r_centre = 0.0;
      for (const auto& d : domes) (d.vertex == 4 ? r_centre : r_corner) = d.radius;
      // Predicted distance t* of the triple point from the centre: the root of
      // g(t) = sqrt(1 + (1 - t)^2) / R_corner - t / R_centre, decreasing on [0, 1].
      double lo = 0.0, hi = 1.0;
      for (int i = 0; i < 100; ++i) {
        const double t = 0.5 * (lo + hi);
        (std::sqrt(1.0 + (1.0 - t) * (1.0 - t)) / r_corner - t / r_centre > 0 ? lo : hi) = t;
      }
      const double predicted = 0.5 * (lo + hi);
      CHECK(predicted > 0.5);

      // Some pushes are out of general position (a 1-cell without a vertex): nothing to check.
      stc::Arrangement A;
      try {
        A = stc::compute_arrangement(G.sheets, G.domain, o.arrangement);
      } catch (const TopologyError&) {
        continue;
      }
      int points = 0;
      for (const auto& v : A.vertices) {
        if (!std::all_of(v.sheets.begin(), v.sheets.end(),
                         [&](int s) { return static_cast<std::size_t>(s) >= first_dome; }))
          continue;
        ++points;
        // Equal r / R over the three domes: the depth term cancelled.
        std::vector<double> ratio;
        for (int s : v.sheets) {
          const auto& d = domes[static_cast<std::size_t>(s) - first_dome];
          ratio.push_back(planar(v.x, G.tet_side.points[static_cast<std::size_t>(d.vertex)]) / d.radius);
        }
        CHECK(ratio[1] == doctest::Approx(ratio[0]).epsilon(1e-6));
        CHECK(ratio[2] == doctest::Approx(ratio[0]).epsilon(1e-6));
        // On the perpendicular to a side, at the predicted distance, outside |u|, |w| < 1/2.
        const double t = std::max(std::abs(v.x.x()), std::abs(v.x.z()));
        CHECK(std::min(std::abs(v.x.x()), std::abs(v.x.z())) < 1e-6);
        CHECK(t == doctest::Approx(predicted).epsilon(1e-6));
        CHECK(t > 0.5);
      }
      runs_with_points += points > 0;
    }
  CHECK(runs_with_points >= 6);  // 7 of the 8 pushes compute today
}
