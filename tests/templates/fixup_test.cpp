// The fix-up driver on the four-triangle variant (the paper's Section 5): its plain dual has
// pinched corners, so no placement untangles it; pillowing removes them, keeps the cell's
// boundary (12 diced-triangle quads on the tet side, 4 on the hex side, the 2D geode on each
// side) and the result smooths to a usable template.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <geode/primal/boundary.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/validity.hpp>
#include <geode/templates/fixup.hpp>
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using namespace geode;
using templates::GeodeOptions;

namespace {

// Boundary quads as sorted position lists, so that two meshes' boundaries compare by geometry.
std::multiset<std::vector<std::array<long, 3>>> boundary_geometry(const primal::HexMesh& m) {
  std::multiset<std::vector<std::array<long, 3>>> s;
  for (const auto& f : primal::unique_faces(m)) {
    if (f.uses.size() != 1) continue;
    std::vector<std::array<long, 3>> q;
    for (auto n : f.nodes) {
      const auto& p = m.points[primal::index_cast<std::size_t>(n)];
      q.push_back({std::lround(p.x() * 1e6), std::lround(p.y() * 1e6), std::lround(p.z() * 1e6)});
    }
    std::sort(q.begin(), q.end());
    s.insert(q);
  }
  return s;
}

GeodeOptions four_triangles() {
  GeodeOptions o;
  o.split = templates::TopSplit::kFourTriangles;
  return o;
}

}  // namespace

TEST_CASE("fix_up: the four-triangle dual's pinched corners are pillowed away, the boundary kept") {
  auto T = templates::build_geode3d(four_triangles());
  const auto plain = T;
  primal::RealizabilityOptions ro;
  ro.node_faces = T.node_faces;
  const auto before = primal::find_obstructions(T.hex, ro);
  REQUIRE_FALSE(before.empty());
  const auto r = templates::fix_up(T);
  CHECK(r.obstructions_before == primal::index_cast<int>(before.size()));
  CHECK(r.obstructions_after == 0);
  CHECK_FALSE(r.steps.empty());
  ro.node_faces = T.node_faces;
  CHECK(primal::find_obstructions(T.hex, ro).empty());
  CHECK(T.hex.hexes.size() > plain.hex.hexes.size());
  CHECK(T.node_faces.size() == T.hex.points.size());
  CHECK(T.node_signs.size() == T.hex.points.size());
  CHECK(T.element_sheets.size() == T.hex.hexes.size());
  CHECK(T.sheets.size() == plain.sheets.size() + r.steps.size());  // a sheet per pillowing
  for (const auto& s : T.element_sheets) CHECK(s.size() == 3);     // every hex is a sheet triple
  // Each node's signs: its side of every sheet, the new ones included.
  for (const auto& sg : T.node_signs) CHECK(sg.size() == T.sheets.size());
  // and every sheet of a hex passes through it: its corners lie on both sides.
  for (std::size_t h = 0; h < T.hex.hexes.size(); ++h)
    for (int sheet : T.element_sheets[h]) {
      int plus = 0, minus = 0;
      for (auto n : T.hex.hexes[h])
        (T.node_signs[primal::index_cast<std::size_t>(n)][primal::index_cast<std::size_t>(sheet)] >
                 0
             ? plus
             : minus)++;
      CAPTURE(h);
      CHECK((plus == 4 && minus == 4));
    }
  CHECK(boundary_geometry(T.hex) == boundary_geometry(plain.hex));
  const auto v = primal::check_validity(T.hex);
  CHECK(v.euler == 1);
  CHECK(v.boundary.closed);
  CHECK(v.overshared_faces.empty());
  CHECK(v.nonmanifold_edges.empty());
  CHECK(v.nonmanifold_vertices.empty());
}

TEST_CASE("fix_up: the fixed-up four-triangle template smooths to min scaled Jacobian >= 0.2") {
  auto T = templates::build_geode3d(four_triangles());
  templates::fix_up(T);
  const auto boundary_before = boundary_geometry(T.hex);
  const auto s =
      templates::smooth_template(T, false);  // tet and hex faces fixed where dicing puts them
  CHECK(s.untangled);
  MESSAGE("geode4tri fixed up: " << T.hex.hexes.size() << " hexes, min scaled Jacobian "
                                 << s.final_min_scaled_jacobian);
  CHECK(s.final_min_scaled_jacobian >= 0.2);
  CHECK(primal::check_validity(T.hex).ok());
  // Tet and hex faces stay; the sides are the 2D geode (nodes slide in them).
  const auto on_face = [](int axis, double value) {
    return [=](const primal::Point& p) { return std::abs(p[axis] - value) < 1e-9; };
  };
  const auto top = test::boundary_quads(T.hex, on_face(1, 7.0)),
             bottom = test::boundary_quads(T.hex, on_face(1, -7.0));
  CHECK(top.quads.size() == 12);
  CHECK(bottom.quads.size() == 4);
  const auto top_and_bottom = [](const auto& quads) {
    std::multiset<std::vector<std::array<long, 3>>> s;
    for (const auto& q : quads)
      if (std::all_of(q.begin(), q.end(), [&](const auto& p) {
            return p[1] == q.front()[1] && std::abs(p[1]) == 7000000;
          }))
        s.insert(q);
    return s;
  };
  CHECK(top_and_bottom(boundary_geometry(T.hex)) == top_and_bottom(boundary_before));
  CHECK(top_and_bottom(boundary_before).size() == 16);
  const auto T2 = templates::build_geode2d(GeodeOptions{});
  for (int axis : {0, 2})
    for (double side : {-12.0, 12.0})
      CHECK(test::find_isomorphism(test::boundary_quads(T.hex, on_face(axis, side)), T2.quad)
                .has_value());
}

TEST_CASE("fix_up: the geode has nothing to fix") {
  auto T = templates::build_geode3d(GeodeOptions{});
  const auto hexes = T.hex.hexes;
  const auto r = templates::fix_up(T);
  CHECK(r.obstructions_before == 0);
  CHECK(r.steps.empty());
  CHECK(T.hex.hexes == hexes);
}

TEST_CASE(
    "fix_up: a centre dome of its own depth and radius needs one pillowing and smooths to >= 0.3") {
  auto o = four_triangles();
  o.push.dome_depth = 0.95;
  o.push.dome_radius = 0.8;
  o.push.centre_depth = 0.45;
  o.push.centre_radius = 0.15;
  auto T = templates::build_geode3d(o);
  const auto r = templates::fix_up(T);
  CHECK(r.obstructions_before == 1);
  CHECK(r.obstructions_after == 0);
  const auto s = templates::smooth_template(T, false);
  CHECK(s.untangled);
  MESSAGE("geode4tri, own centre dome: " << T.hex.hexes.size() << " hexes, min scaled Jacobian "
                                         << s.final_min_scaled_jacobian);
  CHECK(s.final_min_scaled_jacobian >= 0.3);
  CHECK(primal::check_validity(T.hex).ok());
}
