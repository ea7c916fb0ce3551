// The paper's own version of Schneiders' pyramid (Section 4), measured for docs/templates.md
// next to its 512 hexes / 0.033, two ways. (1) The paper's: Schneiders' 16 quads as the hex
// side of the geode transition with tets inside, 512 hexes as the paper counts, its boundary
// Schneiders' surface diced once more (64 quads). (2) The pyramid as two tets over its base quad
// on a hex, the buffer layer carved from the tets: 26 + 8 hexes, its boundary 36 quads (each
// triangle carries the buffer hex's 5-quad side and the shrunk tet's 3). Neither boundary is
// the 16 quads themselves, so neither converts a pyramid of a diced hybrid mesh in place.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

#include <geode/conform/conform.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/topology.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/pyramid.hpp>

#include "support/temp_dir.hpp"

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
  for (Index h = 0; h < primal::index_cast(pyramid.hexes.size()); ++h) {
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

TEST_CASE("conform's default on one pyramid over a hex: split, the geode in the hex below") {
  // What `--pyramids split` gives the equilateral pyramid, for the comparison with a filling of
  // Schneiders' surface (Gmsh's 88 hexes: 0.160): the pyramid's two tets diced (8 hexes) and the
  // geode in the buffer hex carved from the hex under its base.
  primal::Model m;
  const Point base[4] = {Point(-1, 0, -1), Point(-1, 0, 1), Point(1, 0, 1), Point(1, 0, -1)};
  for (const Point& p : base) m.points.push_back(p - Point(0, 2, 0));
  for (const Point& p : base) m.points.push_back(p);
  m.points.emplace_back(0, std::sqrt(2.0), 0);
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  m.pyramids.push_back({4, 5, 6, 7, 8});
  const conform::ConformResult r = conform::conform(m);
  CHECK(r.input_pyramids == 1);
  CHECK(r.buffer_side == conform::BufferSide::kHex);
  CHECK(r.geode_hexes == 26);
  CHECK(r.diced_tet_hexes == 8);
  CHECK(r.validity.ok());
  double lo = 1.0, pyramid_lo = 1.0;
  primal::HexMesh all{r.model.points, r.model.hexes, {}};
  for (Index h = 0; h < primal::index_cast(all.hexes.size()); ++h) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(all, h));
    lo = std::min(lo, sj);
    if (h >= r.diced_hexes + r.geode_hexes) pyramid_lo = std::min(pyramid_lo, sj);
  }
  MESSAGE("one pyramid split: min scaled Jacobian " << lo << " (the pyramid's 8 hexes "
                                                    << pyramid_lo << ")");
  CHECK(lo > 0.3);  // 0.36 measured: above Gmsh's 0.160 on the same pyramid
}

namespace {

// The tets TetGen makes of the pyramid bounded by Schneiders' 16 quads, each split along its
// diagonal through a pyramid corner (or the apex) and the quad's centre node (the base's
// centre, a triangle's centroid), with no node added (-pY): 24 tets, positively oriented.
std::vector<std::array<Index, 4>> tetgen_pyramid(const primal::QuadMesh& s) {
  test::TempDir dir;
  const auto smesh = dir.path / "p.smesh";
  {
    std::ofstream f(smesh);
    f.precision(17);
    f << s.points.size() << " 3 0 0\n";
    for (std::size_t k = 0; k < s.points.size(); ++k)
      f << k << ' ' << s.points[k].x() << ' ' << s.points[k].y() << ' ' << s.points[k].z() << '\n';
    f << 2 * s.quads.size() << " 0\n";
    for (const auto& q : s.quads)
      f << "3 " << q[0] << ' ' << q[1] << ' ' << q[2] << "\n3 " << q[0] << ' ' << q[2] << ' '
        << q[3] << '\n';
    f << "0\n0\n";
  }
  REQUIRE(std::system(("tetgen -pYQ " + smesh.string() + " > /dev/null").c_str()) == 0);
  std::ifstream nodes(dir.path / "p.1.node"), ele(dir.path / "p.1.ele");
  std::size_t n = 0, t = 0, k = 0;
  nodes >> n;
  REQUIRE(n == s.points.size());  // no Steiner point
  ele >> t >> k >> k;
  std::vector<std::array<Index, 4>> tets(t);
  for (auto& a : tets) {
    ele >> k >> a[0] >> a[1] >> a[2] >> a[3];
    const auto& p = s.points;
    auto at = [&](int i) {
      return p[primal::index_cast<std::size_t>(a[primal::index_cast<std::size_t>(i)])];
    };
    if ((at(1) - at(0)).cross(at(2) - at(0)).dot(at(3) - at(0)) < 0) std::swap(a[0], a[1]);
  }
  REQUIRE(ele.good());
  return tets;
}

}  // namespace

TEST_CASE("the paper's 512: Schneiders' 16 quads as the hex side of the geode, tets inside") {
  // Section 4 meshes Schneiders' surface "after dicing the surface mesh" with the geode
  // algorithm. Read as conform does it: each of the 16 quads is an interface quad with the hex
  // side outside (a shell of 16 hexes out to the surface scaled by 1.5 about an inside point)
  // and the tet side inside (the pyramid in TetGen's 24 tets), the buffer layer carved from the
  // tets. The pyramid then holds 16 geodes and 24 diced tets: 16 x 26 + 24 x 4 = 512, the
  // paper's count, and its boundary is Schneiders' surface diced once more (64 quads), not the
  // 16 quads themselves.
  const double h = std::sqrt(2.0);
  const auto s = templates::schneiders_surface(
      {Point(-1, 0, -1), Point(-1, 0, 1), Point(1, 0, 1), Point(1, 0, -1), Point(0, h, 0)});
  const auto tets = tetgen_pyramid(s);
  CHECK(tets.size() == 24);
  primal::Model m;
  m.points = s.points;
  const Point inside(0, h / 4, 0);
  for (const Point& p : s.points) m.points.push_back(inside + 1.5 * (p - inside));
  const Index n = primal::index_cast(s.points.size());
  for (const auto& q : s.quads)  // counter-clockwise seen from outside: the shell's hexes
    m.hexes.push_back({q[0], q[1], q[2], q[3], q[0] + n, q[1] + n, q[2] + n, q[3] + n});
  m.tets = tets;
  m.hex_block.assign(m.hexes.size(), 1);
  m.tet_block.assign(m.tets.size(), 2);
  conform::ConformOptions o;
  o.buffer.side = conform::BufferSide::kTet;
  o.buffer_fallback = false;
  const conform::ConformResult r = conform::conform(m, o);
  CHECK(r.interface_quads == 16);
  CHECK(r.geode_hexes == 16 * 26);
  CHECK(r.diced_tet_hexes == 24 * 4);
  REQUIRE(r.diced_hexes == 16 * 8);
  primal::HexMesh pyramid{
      r.model.points, {r.model.hexes.begin() + r.diced_hexes, r.model.hexes.end()}, {}};
  REQUIRE(pyramid.hexes.size() == 512);
  const auto v = primal::check_validity(pyramid);
  CHECK(v.ok());
  CHECK(v.boundary.faces.size() == 64);
  CHECK(primal::check_validity(primal::HexMesh{r.model.points, r.model.hexes, {}}).ok());
  double lo = 1.0, sum = 0.0;
  for (Index k = 0; k < primal::index_cast(pyramid.hexes.size()); ++k) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(pyramid, k));
    lo = std::min(lo, sj);
    sum += sj;
  }
  MESSAGE("the paper's construction: "
          << pyramid.hexes.size() << " hexes, min scaled Jacobian " << lo << ", mean "
          << sum / 512.0 << ", " << primal::find_obstructions(pyramid).size() << " obstructions");
  CHECK(lo > 0.1);  // 0.144 measured; the paper's 0.033
  // Smoothing kept the boundary on the pyramid's five faces (it slides only in their planes).
  const std::array<std::array<int, 3>, 5> faces{
      {{0, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}};
  double off = 0.0;
  for (const auto& f : v.boundary.faces) {
    for (Index node : f.nodes) {
      const Point& x = pyramid.points[primal::index_cast<std::size_t>(node)];
      double d = 1e300;
      for (const auto& t : faces) {
        const Point a = s.points[primal::index_cast<std::size_t>(t[0])];
        const Point nrm = (s.points[primal::index_cast<std::size_t>(t[1])] - a)
                              .cross(s.points[primal::index_cast<std::size_t>(t[2])] - a)
                              .normalized();
        d = std::min(d, std::abs(nrm.dot(x - a)));
      }
      off = std::max(off, d);
    }
  }
  CHECK(off < 1e-9);
}
