// Sheets and chords read off meshes (stc/mesh_dual.hpp): structured grids with hand-counted
// answers, a hand-built self-intersecting chord, the paper's Appendix A geode, and conformed
// Gmsh models against the definitions read the plain way.
#include <doctest/doctest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include <geode/stc/mesh_dual.hpp>
#include "support/demo_input.hpp"
#include "support/fixtures.hpp"
#include "support/isomorphism.hpp"

using geode::primal::HexMesh;
using geode::primal::Index;
using geode::primal::Point;
using geode::primal::QuadMesh;
namespace stc = geode::stc;
namespace topo = geode::primal::topology;
namespace gt = geode::test;

namespace {

// Box faces as numbered by stc::box_face: 2 * axis + high.
constexpr int kXMin = 0, kXMax = 1, kYMin = 2, kYMax = 3, kZMin = 4, kZMax = 5;

std::set<std::pair<Index, int>> facet_set(const stc::TraceCurve& c) {
  std::set<std::pair<Index, int>> out;
  for (const auto& f : c.facets) out.insert({f.cell, f.local});
  return out;
}

// Trace pieces are walked correctly: consecutive edges are opposite sides of the facet between
// them, and every edge belongs to the sheet.
template <int Dim, typename Mesh>
void check_trace_walk(const Mesh& mesh, const stc::MeshDual<Dim>& dual) {
  for (std::size_t s = 0; s < dual.sheets.size(); ++s) {
    for (const auto& curve : dual.sheets[s].trace) {
      for (Index e : curve.edges) CHECK(dual.edge_sheet[e] == geode::primal::index_cast(s));
      if constexpr (Dim == 3) {
        REQUIRE(curve.closed);
        REQUIRE(curve.facets.size() == curve.edges.size());
        for (std::size_t i = 0; i < curve.facets.size(); ++i) {
          const auto& f = curve.facets[i];
          const auto& fc = topo::kHexFaceCorners[f.local];
          std::set<Index> face;
          for (int k : fc) face.insert(mesh.hexes[f.cell][k]);
          const auto& a = dual.edges[curve.edges[i]];
          const auto& b = dual.edges[curve.edges[(i + 1) % curve.edges.size()]];
          // Opposite sides of a quad: together they hold all four corners.
          CHECK(std::set<Index>{a[0], a[1], b[0], b[1]} == face);
        }
      } else {
        CHECK(curve.edges.size() == 1);
        CHECK(curve.facets.size() == 1);
      }
    }
  }
}

}  // namespace

TEST_CASE("hex grids: nx + ny + nz planar sheets, every cross triple meets once") {
  struct Case {
    int n[3];
  };
  for (const Case& c : {Case{{1, 1, 1}}, Case{{2, 3, 4}}, Case{{3, 1, 2}}}) {
    const int nx = c.n[0], ny = c.n[1], nz = c.n[2];
    CAPTURE(nx);
    CAPTURE(ny);
    CAPTURE(nz);
    const HexMesh mesh = gt::structured_hex_grid(nx, ny, nz);
    const auto dual = stc::mesh_dual(mesh);
    REQUIRE(dual.sheets.size() == geode::primal::index_cast<std::size_t>(nx + ny + nz));
    // Edges of an nx x ny x nz grid: nx(ny+1)(nz+1) + ... (one term per direction).
    CHECK(dual.edges.size() ==
          geode::primal::index_cast<std::size_t>(
              nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz));
    // Class k of hex (i,j,k) is the sheet of slab index[k] along axis k (class k = edges along
    // local axis k = grid axis k for structured_hex_grid): equal slab <=> equal sheet.
    const int idx_n[3] = {nx, ny, nz};
    for (int axis = 0; axis < 3; ++axis) {
      std::map<int, std::set<Index>> sheets_of_slab;
      for (int h = 0; h < nx * ny * nz; ++h) {
        const int ijk[3] = {h % nx, (h / nx) % ny, h / (nx * ny)};
        sheets_of_slab[ijk[axis]].insert(dual.cell_sheets[h][axis]);
      }
      std::set<Index> all;
      for (const auto& [slab, sheets] : sheets_of_slab) {
        CHECK(sheets.size() == 1);
        all.insert(*sheets.begin());
      }
      CHECK(all.size() == geode::primal::index_cast<std::size_t>(idx_n[axis]));
      // A sheet across axis a crosses the (n_b * n_c) hexes of its slab and leaves one loop
      // around the box crossing 2 (n_b + n_c) boundary edges.
      const int nb = idx_n[(axis + 1) % 3], nc = idx_n[(axis + 2) % 3];
      for (Index s : all) {
        const auto& sheet = dual.sheets[s];
        CHECK(sheet.cells.size() == geode::primal::index_cast<std::size_t>(nb * nc));
        CHECK_FALSE(sheet.self_intersecting);
        REQUIRE(sheet.trace.size() == 1);
        CHECK(sheet.trace[0].closed);
        CHECK(sheet.trace[0].edges.size() == geode::primal::index_cast<std::size_t>(2 * (nb + nc)));
      }
    }
    // One hex per triple, and only triples with one sheet of each family.
    CHECK(dual.intersections.size() == geode::primal::index_cast<std::size_t>(nx * ny * nz));
    for (const auto& [triple, count] : dual.intersections) {
      CHECK(count == 1);
      CHECK(triple[0] != triple[1]);
      CHECK(triple[1] != triple[2]);
    }
    CHECK(dual.boundary.size() ==
          geode::primal::index_cast<std::size_t>(2 * (nx * ny + ny * nz + nz * nx)));
    check_trace_walk<3>(mesh, dual);
  }
}

TEST_CASE("quad grids: nx + ny chords with two ends each, crossing once") {
  for (auto [nx_, ny_] : {std::pair{1, 1}, std::pair{4, 3}, std::pair{5, 1}}) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& nx = nx_;
    const auto& ny = ny_;
    CAPTURE(nx);
    CAPTURE(ny);
    const QuadMesh mesh = gt::structured_quad_grid(nx, ny);
    const auto dual = stc::mesh_dual(mesh);
    REQUIRE(dual.sheets.size() == geode::primal::index_cast<std::size_t>(nx + ny));
    std::size_t along_y = 0;  // chords of the x-edges (class 0) cross the ny quads of a column
    for (const auto& chord : dual.sheets) {
      CHECK_FALSE(chord.self_intersecting);
      CHECK(chord.trace.size() == 2);  // two ends on the boundary
      CHECK((chord.cells.size() == geode::primal::index_cast<std::size_t>(ny) ||
             chord.cells.size() == geode::primal::index_cast<std::size_t>(nx)));
    }
    for (int q = 0; q < nx * ny; ++q)
      if (dual.cell_sheets[q][0] == dual.cell_sheets[0][0]) ++along_y;
    CHECK(along_y == geode::primal::index_cast<std::size_t>(ny));
    CHECK(dual.intersections.size() == geode::primal::index_cast<std::size_t>(nx * ny));
    for (const auto& [pair, count] : dual.intersections) {
      CHECK(count == 1);
      CHECK(pair[0] != pair[1]);
    }
    CHECK(dual.boundary.size() == geode::primal::index_cast<std::size_t>(2 * (nx + ny)));
    check_trace_walk<2>(mesh, dual);
  }
}

TEST_CASE("a chord crossing itself, and its extrusion: a self-intersecting sheet") {
  // Three quads around node 1 (not planar, a band): Q = 0123, P1 = 2145, P2 = 5401.
  // Classes: Q {01, 23} {12, 30}; P1 {21, 45} {14, 52}; P2 {54, 01} {40, 15}. Joining them:
  // A = {01, 23, 45, 12, 30} holds both classes of Q, B = {14, 52}, C = {40, 15}.
  QuadMesh band;
  band.points.assign(6, Point::Zero());
  band.quads = {{0, 1, 2, 3}, {2, 1, 4, 5}, {5, 4, 0, 1}};
  const auto dual = stc::mesh_dual(band);
  REQUIRE(dual.sheets.size() == 3);  // numbered by first appearance: A = 0, B = 1, C = 2
  CHECK(dual.sheets[0].self_intersecting);
  CHECK(dual.sheets[0].cells == std::vector<Index>{0, 0, 1, 2});
  CHECK(dual.sheets[0].edges.size() == 5);
  CHECK(dual.sheets[0].trace.size() == 2);  // ends at the boundary edges 23 and 30
  CHECK_FALSE(dual.sheets[1].self_intersecting);
  CHECK(dual.sheets[1].cells == std::vector<Index>{1});
  CHECK(dual.sheets[2].cells == std::vector<Index>{2});
  CHECK(dual.intersections ==
        std::map<std::array<Index, 2>, Index>{{{0, 0}, 1}, {{0, 1}, 1}, {{0, 2}, 1}});
  check_trace_walk<2>(band, dual);

  // Extruded into hexes (quad nodes below, +6 above): the chords become sheets and the
  // vertical edges one more sheet D, numbered A = 0, D = 1, B = 2, C = 3.
  HexMesh slab;
  slab.points.assign(12, Point::Zero());
  for (const auto& q : band.quads)
    slab.hexes.push_back({q[0], q[1], q[2], q[3], q[0] + 6, q[1] + 6, q[2] + 6, q[3] + 6});
  const auto hd = stc::mesh_dual(slab);
  REQUIRE(hd.sheets.size() == 4);
  CHECK(hd.sheets[0].self_intersecting);
  CHECK(hd.sheets[0].cells == std::vector<Index>{0, 0, 1, 2});
  CHECK(hd.sheets[1].cells == std::vector<Index>{0, 1, 2});
  CHECK(hd.intersections ==
        std::map<std::array<Index, 3>, Index>{{{0, 0, 1}, 1}, {{0, 1, 2}, 1}, {{0, 1, 3}, 1}});
  // All 10 edges of A are horizontal, on the top or bottom: all on its trace.
  std::size_t trace_edges = 0;
  for (const auto& c : hd.sheets[0].trace) trace_edges += c.edges.size();
  CHECK(trace_edges == 10);
  check_trace_walk<3>(slab, hd);
}

TEST_CASE("Appendix A fixture: paper corner order is VTK order") {
  const HexMesh g = gt::appendix_a_geode();
  REQUIRE(g.points.size() == 48);
  REQUIRE(g.hexes.size() == 26);
  // Every interior face is seen in opposite cyclic orders by its two hexes.
  std::map<std::array<Index, 4>, std::vector<std::array<Index, 4>>> faces;
  for (const auto& h : g.hexes)
    for (const auto& fc : topo::kHexFaceCorners) {
      std::array<Index, 4> f{h[fc[0]], h[fc[1]], h[fc[2]], h[fc[3]]};
      auto key = f;
      std::sort(key.begin(), key.end());
      faces[key].push_back(f);
    }
  std::size_t boundary = 0;
  for (const auto& [key, uses] : faces) {
    REQUIRE(uses.size() <= 2);
    if (uses.size() == 1) {
      ++boundary;
      continue;
    }
    auto rev = uses[1];
    std::reverse(rev.begin(), rev.end());
    bool opposite = false;
    for (int r = 0; r < 4; ++r) {
      std::rotate(rev.begin(), rev.begin() + 1, rev.end());
      opposite = opposite || rev == uses[0];
    }
    CHECK(opposite);
  }
  // Boundary by hand: 6 quads on top (two diced triangles), 4 on the bottom (a diced quad),
  // 5 on each side (the 2D geode).
  CHECK(boundary == 6 + 4 + 4 * 5);
  // Outward-oriented boundary (kHexFaceCorners faces point out of a positive hex): the
  // divergence theorem over the planar box faces gives the box volume 24 * 14 * 24 = 8064.
  const auto dual = stc::mesh_dual(g);
  double volume = 0.0;
  for (const auto& f : dual.boundary) {
    const auto& fc = topo::kHexFaceCorners[f.local];
    const Point p0 = g.points[g.hexes[f.cell][fc[0]]];
    for (int k = 1; k < 3; ++k) {
      const Point p1 = g.points[g.hexes[f.cell][fc[k]]];
      const Point p2 = g.points[g.hexes[f.cell][fc[k + 1]]];
      volume += p0.dot(p1.cross(p2)) / 6.0;
    }
  }
  CHECK(volume == doctest::Approx(8064.0));
}

TEST_CASE("Appendix A geode: two tunnels and four domes") {
  const HexMesh g = gt::appendix_a_geode();
  const auto dual = stc::mesh_dual(g);
  const auto classify = stc::box_face_classifier(g, Point(-12, -7, -12), Point(12, 7, 12), 1e-9);
  check_trace_walk<3>(g, dual);
  for (const auto& f : dual.boundary) REQUIRE(classify(f) >= 0);  // the boundary is the box

  REQUIRE(dual.sheets.size() == 6);
  std::size_t crossings = 0;
  for (const auto& s : dual.sheets) {
    CHECK_FALSE(s.self_intersecting);
    CHECK(s.trace.size() == 1);  // one loop on the boundary sphere
    crossings += s.cells.size();
  }
  CHECK(crossings == 3 * 26);

  // Name each sheet by its trace per box face (geode-specific, hence here and not in stc/).
  // Tunnel: trace on the bottom (hex side) and on two opposite sides, none on top; its axis
  // is the axis of those sides. Dome: trace on the top (tet side), none on the bottom; its
  // corner is the pair of sides it touches.
  struct Named {
    std::string kind;    // "tunnel" or "dome"
    int axis = -1;       // tunnel: 0 (x) or 2 (z)
    int sx = 0, sz = 0;  // dome: corner signs
    std::vector<std::vector<stc::TraceCurve>> pieces;
  };
  std::vector<Named> names;
  for (Index s = 0; s < 6; ++s) {
    Named n;
    n.pieces = stc::trace_by_region(dual, s, classify, 6);
    const auto& p = n.pieces;
    CAPTURE(s);
    if (!p[kYMin].empty()) {
      n.kind = "tunnel";
      CHECK(p[kYMax].empty());
      const bool x = !p[kXMin].empty() && !p[kXMax].empty() && p[kZMin].empty() && p[kZMax].empty();
      const bool z = !p[kZMin].empty() && !p[kZMax].empty() && p[kXMin].empty() && p[kXMax].empty();
      CHECK(x != z);
      n.axis = x ? 0 : 2;
    } else {
      n.kind = "dome";
      CHECK_FALSE(p[kYMax].empty());
      CHECK(p[kXMin].empty() != p[kXMax].empty());
      CHECK(p[kZMin].empty() != p[kZMax].empty());
      n.sx = p[kXMax].empty() ? -1 : 1;
      n.sz = p[kZMax].empty() ? -1 : 1;
    }
    names.push_back(n);
  }
  std::vector<Index> tunnels, domes;
  for (Index s = 0; s < 6; ++s) (names[s].kind == "tunnel" ? tunnels : domes).push_back(s);
  REQUIRE(tunnels.size() == 2);
  REQUIRE(domes.size() == 4);
  CHECK(names[tunnels[0]].axis != names[tunnels[1]].axis);

  SUBCASE("tunnels: 16 hexes, feet two parallel chords of the diced bottom quad") {
    std::map<std::pair<Index, int>, int> bottom_hits;
    for (Index t : tunnels) {
      CHECK(dual.sheets[t].cells.size() == 16);
      const auto& feet = names[t].pieces[kYMin];
      REQUIRE(feet.size() == 2);
      std::set<std::pair<Index, int>> covered;
      for (const auto& chord : feet) {
        CHECK(chord.facets.size() == 2);  // across the 2 x 2 bottom grid
        for (const auto& f : facet_set(chord)) {
          covered.insert(f);
          ++bottom_hits[f];
        }
      }
      CHECK(covered.size() == 4);  // parallel: disjoint, together all four bottom quads
      // Each entrance (side face) is one arch.
      const int lo = names[t].axis == 0 ? kXMin : kZMin;
      CHECK(names[t].pieces[lo].size() == 1);
      CHECK(names[t].pieces[lo + 1].size() == 1);
    }
    // The two tunnels cross each other: each bottom quad has a foot of both.
    CHECK(bottom_hits.size() == 4);
    for (const auto& [f, hits] : bottom_hits) CHECK(hits == 2);
  }

  SUBCASE("domes: one per top corner; 14 hexes at the diagonal's ends, 9 at the others") {
    // The diagonal of the diced top face ends at the top corners lying on two top quads.
    std::map<Index, int> top_quads_at;
    for (const auto& f : dual.boundary)
      if (classify(f) == kYMax)
        for (int k : topo::kHexFaceCorners[f.local]) ++top_quads_at[g.hexes[f.cell][k]];
    std::set<std::pair<int, int>> corners;
    for (Index d : domes) {
      const Named& n = names[d];
      corners.insert({n.sx, n.sz});
      Index corner = -1;
      for (Index v = 0; v < 48; ++v)
        if (g.points[v] == Point(12.0 * n.sx, 7.0, 12.0 * n.sz)) corner = v;
      REQUIRE(corner >= 0);
      const bool on_diagonal = top_quads_at[corner] == 2;
      CAPTURE(d);
      CHECK(dual.sheets[d].cells.size() == (on_diagonal ? 14u : 9u));
      // Its circle on the top face crosses the diced quads of the triangles at its corner.
      REQUIRE(n.pieces[kYMax].size() == 1);
      CHECK(n.pieces[kYMax][0].facets.size() == (on_diagonal ? 4u : 2u));
    }
    CHECK(corners.size() == 4);
  }

  SUBCASE("triple intersections") {
    // Paper figures: 26 hexes, 16 distinct triples, ten in 2 hexes and six in 1.
    CHECK(dual.intersections.size() == 16);
    std::map<Index, int> histogram;
    for (const auto& [triple, count] : dual.intersections) ++histogram[count];
    CHECK(histogram == std::map<Index, int>{{1, 6}, {2, 10}});
    auto meet = [&](Index a, Index b, Index c) {
      std::array<Index, 3> t{a, b, c};
      std::sort(t.begin(), t.end());
      const auto it = dual.intersections.find(t);
      return it == dual.intersections.end() ? Index{0} : it->second;
    };
    auto diagonal = [&](Index d) {  // the dome's corner is an end of the top diagonal
      return dual.sheets[d].cells.size() == 14;
    };
    // Both tunnels and any dome: 2 hexes (the pocket where the tunnels cross).
    for (Index d : domes) CHECK(meet(tunnels[0], tunnels[1], d) == 2);
    // Three domes: the paper's two triple points of the diced-tet surfaces (Figure 6), each
    // through both diagonal domes; the two off-diagonal domes never meet.
    int dome_triples = 0;
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j)
        for (std::size_t k = j + 1; k < 4; ++k) {
          const Index n = meet(domes[i], domes[j], domes[k]);
          if (n == 0) continue;
          ++dome_triples;
          CHECK(n == 1);
          const int on_diag = diagonal(domes[i]) + diagonal(domes[j]) + diagonal(domes[k]);
          CHECK(on_diag == 2);
        }
    CHECK(dome_triples == 2);
    // A tunnel and two domes (computed from the data): the off-diagonal pair never; two
    // domes at the same entrance of the tunnel (same coordinate along its axis) once; the
    // others (same coordinate across it, or the diagonal pair) twice.
    int tunnel_dome_dome = 0;
    for (Index t : tunnels)
      for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t j = i + 1; j < 4; ++j) {
          const Named& a = names[domes[i]];
          const Named& b = names[domes[j]];
          const int along_a = names[t].axis == 0 ? a.sx : a.sz;
          const int along_b = names[t].axis == 0 ? b.sx : b.sz;
          const bool off_diagonal = !diagonal(domes[i]) && !diagonal(domes[j]);
          const Index expected = off_diagonal ? 0 : along_a == along_b ? 1 : 2;
          CAPTURE(t);
          CAPTURE(i);
          CAPTURE(j);
          CHECK(meet(t, domes[i], domes[j]) == expected);
          tunnel_dome_dome += expected > 0;
        }
    CHECK(tunnel_dome_dome == 10);  // 4 + 2 + 10 = 16 triples
    // Per hex: three distinct sheets.
    for (const auto& t : dual.cell_sheets) CHECK(std::set<Index>(t.begin(), t.end()).size() == 3);
  }
}

TEST_CASE("Appendix A geode: the four sides are the same 2D geode") {
  const HexMesh g = gt::appendix_a_geode();
  const auto on = [](int axis, double value) {
    return [axis, value](const Point& p) { return std::abs(p[axis] - value) < 1e-9; };
  };
  struct Side {
    int face;
    QuadMesh mesh;
  };
  const std::vector<Side> sides{{kXMin, gt::boundary_quads(g, on(0, -12))},
                                {kXMax, gt::boundary_quads(g, on(0, 12))},
                                {kZMin, gt::boundary_quads(g, on(2, -12))},
                                {kZMax, gt::boundary_quads(g, on(2, 12))}};
  // Labels: tet side (y = +7) up, hex side (y = -7) down; the mapping must keep them.
  auto labels = [](const QuadMesh& m) {
    std::vector<int> out;
    for (const auto& p : m.points) out.push_back(p.y() == 7.0 ? 1 : p.y() == -7.0 ? -1 : 0);
    return out;
  };
  for (const auto& s : sides) {
    CHECK(s.mesh.quads.size() == 5);
    CHECK(s.mesh.points.size() == 9);
  }
  for (std::size_t i = 0; i < sides.size(); ++i)
    for (std::size_t j = i + 1; j < sides.size(); ++j) {
      CAPTURE(i);
      CAPTURE(j);
      const gt::NodeLabels lab{labels(sides[i].mesh), labels(sides[j].mesh)};
      const auto m = gt::find_isomorphism(sides[i].mesh, sides[j].mesh, lab);
      REQUIRE(m.has_value());
      CHECK(gt::is_isomorphism(sides[i].mesh, sides[j].mesh, *m, lab));
    }

  // The chords of each side are exactly the pieces of the 3D traces on that face.
  const auto dual = stc::mesh_dual(g);
  const auto classify = stc::box_face_classifier(g, Point(-12, -7, -12), Point(12, 7, 12), 1e-9);
  for (const auto& s : sides) {
    const auto side_dual = stc::mesh_dual(s.mesh);
    std::multiset<std::size_t> chord_sizes, piece_sizes;
    for (const auto& c : side_dual.sheets) {
      CHECK_FALSE(c.self_intersecting);
      CHECK(c.trace.size() == 2);
      chord_sizes.insert(c.cells.size());
    }
    for (Index sh = 0; sh < 6; ++sh) {
      const auto pieces = stc::trace_by_region(dual, sh, classify, 6);
      for (const auto& piece : pieces[s.face]) piece_sizes.insert(piece.facets.size());
    }
    CHECK(chord_sizes == piece_sizes);
    // The 2D geode: the tunnel's arch across 4 quads, two dome curves across 3.
    CHECK(chord_sizes == std::multiset<std::size_t>{3, 3, 4});
  }
}

TEST_CASE("bad input is reported with the element") {
  HexMesh bad = gt::structured_hex_grid(2, 1, 1);
  bad.hexes[1][2] = 40;
  CHECK_THROWS_WITH_AS(stc::mesh_dual(bad), doctest::Contains("hex 1"), geode::InvalidInput);
  QuadMesh twice = gt::structured_quad_grid(1, 1);
  twice.quads[0][3] = twice.quads[0][1];
  CHECK_THROWS_WITH_AS(stc::mesh_dual(twice), doctest::Contains("quad 0"), geode::InvalidInput);
  HexMesh fan = gt::structured_hex_grid(1, 1, 1);
  for (int i = 0; i < 2; ++i) {  // three hexes on one face
    const Index base = geode::primal::index_cast(fan.points.size());
    fan.points.resize(fan.points.size() + 4, Point::Zero());
    fan.hexes.push_back({base, base + 1, base + 2, base + 3, 0, 1, 2, 3});
  }
  CHECK_THROWS_AS(stc::mesh_dual(fan), geode::TopologyError);
  // Two cubes sharing only an edge: that edge lies on four boundary quads.
  HexMesh pinched = gt::structured_hex_grid(2, 2, 1);
  pinched.hexes.erase(pinched.hexes.begin() + 1, pinched.hexes.begin() + 3);  // keep (0,0), (1,1)
  CHECK_THROWS_AS(stc::mesh_dual(pinched), geode::TopologyError);
  // A classifier answering outside the regions.
  const HexMesh cube = gt::structured_hex_grid(1, 1, 1);
  const auto d = stc::mesh_dual(cube);
  CHECK_THROWS_AS(stc::trace_by_region(
                      d, 0, [](const stc::CellFacet&) { return 7; }, 6),
                  geode::InvalidInput);
  CHECK_THROWS_AS(stc::trace_by_region(
                      d, 5, [](const stc::CellFacet&) { return 0; }, 6),
                  geode::InvalidInput);
}

TEST_CASE("the fixture reader names the file and the line of a bad row") {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("geode_fixture_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string nodes = write("nodes.csv", "node,x,y,z\n1,0,0,0\n2,1,0,0\n");
  const std::string good = write("good.csv", "hex,n1,n2,n3,n4,n5,n6,n7,n8\n");
  CHECK(gt::read_hex_csv(nodes, good).points.size() == 2);
  const std::string range = write("range.csv", "hex,n1,n2,n3,n4,n5,n6,n7,n8\n1,1,2,3,4,5,6,7,8\n");
  CHECK_THROWS_WITH_AS(gt::read_hex_csv(nodes, range), doctest::Contains("range.csv:2"),
                       geode::InvalidInput);
  const std::string text = write("text.csv", "node,x,y,z\n1,0,zero,0\n");
  CHECK_THROWS_WITH_AS(gt::read_hex_csv(text, good), doctest::Contains("text.csv:2"),
                       geode::InvalidInput);
  const std::string gap = write("gap.csv", "node,x,y,z\n1,0,0,0\n3,0,0,0\n");
  CHECK_THROWS_WITH_AS(gt::read_hex_csv(gap, good), doctest::Contains("gap.csv:3"),
                       geode::InvalidInput);
  fs::remove_all(dir);
}

namespace {

// Every call of a progress callback, in order.
struct Told {
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  std::function<void(std::size_t, std::size_t)> callback() {
    return [this](std::size_t done, std::size_t total) { calls.emplace_back(done, total); };
  }
};

// Told from 0 to `total` and never back, the total fixed, with calls between the ends (the
// mesh has more cells than the callback's interval): what a progress bar needs.
void check_told(const Told& told, std::size_t total) {
  REQUIRE(told.calls.size() >= 3);
  CHECK(told.calls.front().first == 0);
  CHECK(told.calls.back().first == total);
  for (std::size_t i = 0; i < told.calls.size(); ++i) {
    CHECK(told.calls[i].second == total);
    if (i > 0) CHECK(told.calls[i].first >= told.calls[i - 1].first);
  }
  CHECK(std::any_of(told.calls.begin(), told.calls.end(),
                    [&](const auto& c) { return c.first > 0 && c.first < total; }));
}

}  // namespace

TEST_CASE("mesh_dual tells its progress through every pass, and the dual is the same") {
  SUBCASE("hexes") {
    const HexMesh g = gt::structured_hex_grid(30, 30, 20);  // 18000 hexes: past 2^14
    Told told;
    stc::MeshDualOptions options;
    options.progress = told.callback();
    const auto dual = stc::mesh_dual(g, options);
    check_told(told, stc::kMeshDualPasses * g.hexes.size());
    const auto plain = stc::mesh_dual(g);
    CHECK(dual.edge_sheet == plain.edge_sheet);
    CHECK(dual.cell_sheets == plain.cell_sheets);
    CHECK(dual.intersections == plain.intersections);
    CHECK(dual.sheets.size() == 80);
  }
  SUBCASE("quads") {
    const QuadMesh g = gt::structured_quad_grid(200, 100);  // 20000 quads
    Told told;
    stc::MeshDualOptions options;
    options.progress = told.callback();
    const auto dual = stc::mesh_dual(g, options);
    check_told(told, stc::kMeshDualPasses * g.quads.size());
    CHECK(dual.sheets.size() == 300);
  }
}

// The dual as its definitions read, written the plain way (maps, one pass each): edges numbered
// in order of first appearance, sheets the classes of edges joined by parallel edges within a
// cell, boundary facets those of one cell. mesh_dual reaches the same by sorting and bucketing.
TEST_CASE("mesh_dual of conformed Gmsh models equals its definitions read the plain way") {
  geode::test::TempDir dir;
  for (const char* model : {"hexdominant", "potting", "fulcher"}) {
    CAPTURE(model);
    const auto out = dir.path / (std::string(model) + ".vtu");
    const auto run = geode::test::geode_cli(
        std::string("demo --model ") + model + " -n 2 --quiet -o " + out.string(), true);
    INFO(run.out);
    REQUIRE(run.code == 0);
    const auto m = geode::io::read_model(out);
    const HexMesh mesh{m.points, m.hexes, {}};
    REQUIRE(mesh.hexes.size() > 1000);
    const auto dual = stc::mesh_dual(mesh);

    std::map<std::pair<Index, Index>, Index> edge_id;
    std::vector<std::array<Index, 2>> edges;
    std::vector<std::array<Index, 12>> cell_edges(mesh.hexes.size());
    for (std::size_t c = 0; c < mesh.hexes.size(); ++c)
      for (int e = 0; e < 12; ++e) {
        Index a = mesh.hexes[c][topo::kHexEdgeCorners[e][0]],
              b = mesh.hexes[c][topo::kHexEdgeCorners[e][1]];
        if (a > b) std::swap(a, b);
        const auto [it, added] = edge_id.emplace(std::pair(a, b), Index(edges.size()));
        if (added) edges.push_back({a, b});
        cell_edges[c][e] = it->second;
      }
    CHECK(dual.edges == edges);
    CHECK(dual.cell_edges == cell_edges);

    // Sheets: parallel edges of a cell (kHexEdgeCorners lists the 4 edges of each direction
    // together) in one class; numbered in order of first appearance, cell by cell.
    geode::primal::DisjointSets classes(edges.size());
    for (const auto& ce : cell_edges)
      for (int e = 0; e < 12; ++e) classes.unite(ce[e], ce[4 * (e / 4)]);
    std::map<Index, Index> sheet_of_class;
    std::vector<std::array<Index, 3>> cell_sheets(mesh.hexes.size());
    std::map<std::array<Index, 3>, Index> intersections;
    for (std::size_t c = 0; c < mesh.hexes.size(); ++c) {
      for (int e = 0; e < 12; ++e) {
        const auto [it, added] =
            sheet_of_class.emplace(classes.find(cell_edges[c][e]), Index(sheet_of_class.size()));
        cell_sheets[c][e / 4] = it->second;
      }
      auto sorted = cell_sheets[c];
      std::sort(sorted.begin(), sorted.end());
      ++intersections[sorted];
    }
    CHECK(dual.sheets.size() == sheet_of_class.size());
    CHECK(dual.cell_sheets == cell_sheets);
    CHECK(dual.intersections == intersections);

    std::map<std::array<Index, 4>, std::vector<stc::CellFacet>> users;
    for (std::size_t c = 0; c < mesh.hexes.size(); ++c)
      for (int f = 0; f < 6; ++f) {
        std::array<Index, 4> key;
        for (int k = 0; k < 4; ++k) key[k] = mesh.hexes[c][topo::kHexFaceCorners[f][k]];
        std::sort(key.begin(), key.end());
        users[key].push_back({Index(c), f});
      }
    std::vector<stc::CellFacet> boundary;
    std::size_t crowded = 0;  // facets of three cells or more: none in a valid output
    for (const auto& [key, list] : users) {
      crowded += list.size() > 2;
      if (list.size() == 1) boundary.push_back(list[0]);
    }
    CHECK(crowded == 0);
    std::sort(boundary.begin(), boundary.end(), [](const auto& a, const auto& b) {
      return std::pair(a.cell, a.local) < std::pair(b.cell, b.local);
    });
    CHECK(dual.boundary == boundary);
  }
}
