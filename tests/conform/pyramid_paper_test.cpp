// The paper's own version of Schneiders' pyramid (Section 4): the pyramid as two tets over its
// base quad, a hex under the base, and the transition as conform builds it, with the buffer
// layer carved from the tets so that the whole transition lies inside the pyramid. Measured for
// the README's pyramid table next to the paper's 512 hexes / 0.033: what fills the pyramid is
// the geode and the diced tets, 26 + 8 hexes, but its boundary is not Schneiders' 16 quads
// (each triangle carries the buffer hex's 5-quad side and the shrunk tet's 3 quads).
#include <doctest/doctest.h>

#include <cmath>
#include <map>

#include <geode/conform/conform.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>

using namespace geode;
using primal::Index;
using primal::Point;

TEST_CASE(
    "pyramid as two tets over a hex, transition carved from the tets: 34 hexes in the pyramid") {
  primal::Model m;
  // Base counter-clockwise seen from the apex (+y); every pyramid edge 2 long; the hex below.
  const Point base[4] = {Point(-1, 0, -1), Point(-1, 0, 1), Point(1, 0, 1), Point(1, 0, -1)};
  for (const Point& p : base) m.points.push_back(p - Point(0, 2, 0));
  for (const Point& p : base) m.points.push_back(p);
  m.points.emplace_back(0, std::sqrt(2.0), 0);
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  m.tets.push_back({4, 5, 6, 8});
  m.tets.push_back({4, 6, 7, 8});
  conform::ConformOptions o;
  o.buffer.side = conform::BufferSide::kTet;
  o.geode_block = "geode";
  const conform::ConformResult r = conform::conform(m, o);
  CHECK(r.buffer_side == conform::BufferSide::kTet);
  CHECK(r.geode_hexes == 26);
  CHECK(r.diced_tet_hexes == 8);
  REQUIRE(r.model.hexes.size() == 42);
  primal::HexMesh all{r.model.points, r.model.hexes, {}};
  CHECK(primal::check_validity(all).ok());
  // The pyramid's hexes: all but the 8 diced from the hex below.
  primal::HexMesh pyramid{r.model.points, {r.model.hexes.begin() + 8, r.model.hexes.end()}, {}};
  double lo = 1.0, sum = 0.0;
  for (Index h = 0; h < static_cast<Index>(pyramid.hexes.size()); ++h) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(pyramid, h));
    lo = std::min(lo, sj);
    sum += sj;
  }
  MESSAGE("pyramid as two tets, conform's transition: 34 hexes, min scaled Jacobian "
          << lo << ", mean " << sum / 34.0);
  // Far above the paper's 0.033; 0.29 since smoothing keeps the model boundary and the block
  // interface on their surfaces (0.38 when it could move them).
  CHECK(lo > 0.25);
  const auto v = primal::check_validity(pyramid);
  CHECK(v.ok());
  CHECK(v.boundary.faces.size() == 4 + 4 * (5 + 3));  // not Schneiders' 16
  CHECK(primal::find_obstructions(pyramid).empty());
}
