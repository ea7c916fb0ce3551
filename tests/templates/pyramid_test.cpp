// Schneiders' pyramid: the 16-quad surface, the certificate that no arrangement of embedded
// sheets has it as boundary, and the comparison the issue asks for: Gmsh's all-hex subdivision
// of one pyramid (generated here through libgmsh's RefineMesh, never copied), measured against
// the surface: its hex count, validity, boundary, scaled Jacobians, sheets and obstructions;
// and, pyramid by pyramid on the Gmsh-made hybrid demos, against what conform's split gives.
#include <doctest/doctest.h>
#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <geode/demo/gmsh_session.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/boundary.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/primal/split_pyramids.hpp>
#include <geode/primal/validity.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/surface_chords.hpp>
#include <geode/templates/pyramid.hpp>
#include <geode/templates/spec.hpp>

#include "support/cli_run.hpp"
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::Index;
using primal::Point;

namespace {

// Every edge 2 long, base [-1, 1]^2 at y = 0, counter-clockwise seen from the apex.
std::array<Point, 5> equilateral() {
  return {Point(-1, 0, -1), Point(-1, 0, 1), Point(1, 0, 1), Point(1, 0, -1),
          Point(0, std::sqrt(2.0), 0)};
}

// One pyramid refined by Gmsh's all-hex subdivision (Mesh.SubdivisionAlgorithm = 2, the
// RefineMesh of `gmsh -refine`): hexes in Gmsh's order (VTK's for linear hexes).
primal::HexMesh gmsh_pyramid_filling(const std::array<Point, 5>& c) {
  demo::GmshSession session;
  gmsh::model::add("pyramid");
  const int volume = gmsh::model::addDiscreteEntity(3);
  std::vector<double> xyz;
  for (const Point& p : c) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  gmsh::model::mesh::addNodes(3, volume, {1, 2, 3, 4, 5}, xyz);
  gmsh::model::mesh::addElementsByType(volume, 7, {1}, {1, 2, 3, 4, 5});  // 7: 5-node pyramid
  gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 2);
  gmsh::model::mesh::refine();
  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, true, false);
  primal::HexMesh m;
  std::map<std::size_t, Index> id;
  for (std::size_t i = 0; i < tags.size(); ++i) {
    id[tags[i]] = primal::index_cast(m.points.size());
    m.points.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
  }
  std::vector<std::size_t> elements, nodes;
  gmsh::model::mesh::getElementsByType(5, elements, nodes);  // 5: 8-node hexahedron
  for (std::size_t e = 0; e < elements.size(); ++e) {
    std::array<Index, 8> h{};
    for (std::size_t k = 0; k < 8; ++k) h[k] = id.at(nodes[8 * e + k]);
    m.hexes.push_back(h);
  }
  return m;
}

// The boundary quads of `mesh` are the surface's quads: every boundary node within `tol` of a
// surface node (Gmsh puts a triangle's face node at its centroid to single precision, 7e-7 off).
bool boundary_is(const primal::HexMesh& mesh, const primal::QuadMesh& surface, double tol = 1e-5) {
  const auto b = primal::extract_boundary(mesh);
  if (b.faces.size() != surface.quads.size()) return false;
  auto nearest = [&](const Point& x) {
    for (std::size_t n = 0; n < surface.points.size(); ++n)
      if ((surface.points[n] - x).norm() < tol) return primal::index_cast(n);
    return primal::kInvalidIndex;
  };
  std::set<std::vector<Index>> want, got;
  for (const auto& q : surface.quads) {
    std::vector<Index> k(q.begin(), q.end());
    std::sort(k.begin(), k.end());
    want.insert(k);
  }
  for (const auto& f : b.faces) {
    std::vector<Index> k;
    for (Index n : f.nodes) k.push_back(nearest(mesh.points[primal::index_cast<std::size_t>(n)]));
    std::sort(k.begin(), k.end());
    got.insert(k);
  }
  return got == want;
}

}  // namespace

TEST_CASE("pyramid: Schneiders' surface has 16 quads and a chord crossing itself 8 times") {
  const auto s = templates::schneiders_surface(equilateral());
  CHECK(s.points.size() == 18);
  CHECK(s.quads.size() == 16);
  const auto chords = stc::surface_chords(s.quads);
  REQUIRE(chords.size() == 2);
  std::multiset<std::size_t> passes, crossings;
  for (const auto& c : chords)
    passes.insert(c.quads.size()), crossings.insert(c.self_crossings.size());
  CHECK(passes == std::multiset<std::size_t>{8, 24});  // 8 around the apex, 24 = 16 + 8
  CHECK(crossings == std::multiset<std::size_t>{0, 8});
  const auto cert = templates::pyramid_certificate(equilateral());
  CHECK(cert.self_crossing_chords == 1);
  CHECK(cert.statement.find("no arrangement") != std::string::npos);
  // Every quad counter-clockwise seen from outside (the centroid is inside).
  Point centre = Point::Zero();
  for (int i = 0; i < 5; ++i) centre += s.points[primal::index_cast<std::size_t>(i)] / 5.0;
  for (const auto& q : s.quads) {
    const Point n = (s.points[primal::index_cast<std::size_t>(q[2])] -
                     s.points[primal::index_cast<std::size_t>(q[0])])
                        .cross(s.points[primal::index_cast<std::size_t>(q[3])] -
                               s.points[primal::index_cast<std::size_t>(q[1])]);
    CHECK(n.dot(s.points[primal::index_cast<std::size_t>(q[0])] - centre) > 0);
  }
  CHECK_THROWS_AS(stc::surface_chords({{0, 1, 2, 3}}), TopologyError);
}

TEST_CASE("pyramid: Gmsh's all-hex subdivision of one pyramid, measured") {
  const auto P = equilateral();
  const primal::HexMesh g = gmsh_pyramid_filling(P);
  CHECK(g.hexes.size() == 88);
  CHECK(g.points.size() == 105);
  const auto v = primal::check_validity(g);
  CHECK(v.ok());
  CHECK(v.inverted_hexes.empty());
  CHECK(boundary_is(g, templates::schneiders_surface(P)));
  double lo = 1.0, sum = 0.0;
  for (Index h = 0; h < primal::index_cast(g.hexes.size()); ++h) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(g, h));
    lo = std::min(lo, sj);
    sum += sj;
  }
  MESSAGE("gmsh 88-hex pyramid: min scaled Jacobian " << lo << ", mean " << sum / g.hexes.size());
  CHECK(lo > 0.155);
  CHECK(lo < 0.165);  // the issue's 0.160
  // Its sheets: 5, two of them self-intersecting (the issue's count), as the surface demands.
  const auto dual = stc::mesh_dual(g);
  CHECK(dual.sheets.size() == 5);
  CHECK(std::count_if(dual.sheets.begin(), dual.sheets.end(),
                      [](const auto& s) { return s.self_intersecting; }) == 2);
  CHECK(primal::find_obstructions(g).empty());
  // Gmsh's own reference pyramid (base [-1, 1]^2, height 1): the issue's 0.117.
  const primal::HexMesh r = gmsh_pyramid_filling(
      {Point(-1, -1, 0), Point(1, -1, 0), Point(1, 1, 0), Point(-1, 1, 0), Point(0, 0, 1)});
  double rlo = 1.0;
  for (Index h = 0; h < primal::index_cast(r.hexes.size()); ++h)
    rlo = std::min(rlo, primal::hex_scaled_jacobian(primal::hex_corners(r, h)));
  MESSAGE("gmsh 88-hex pyramid, height 1: min scaled Jacobian " << rlo);
  CHECK(rlo > 0.11);
  CHECK(rlo < 0.125);
}

TEST_CASE("pyramid: specs take a pyramid domain and write it back") {
  const nlohmann::json j = nlohmann::json::parse(R"({"dim": 3,
    "domain": {"pyramid": [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1], [0, 1.5, 0]]},
    "sheets": [{"name": "x", "plane": {"point": [0.1, 0.4, 0.13], "normal": [1, 0, 0]}},
               {"name": "y", "plane": {"point": [0.1, 0.4, 0.13], "normal": [0, 1, 0]}},
               {"name": "z", "plane": {"point": [0.1, 0.4, 0.13], "normal": [0, 0, 1]}}]})");
  const auto spec = templates::parse_spec(j, "p.json");
  CHECK(spec.domain.is_pyramid);
  REQUIRE(spec.domain.corners);
  CHECK(((*spec.domain.corners)[7] - Point(0, 1.5, 0)).norm() == 0.0);
  const auto back = templates::spec_json(spec);
  CHECK(back["domain"] == j["domain"]);
  CHECK(templates::parse_spec(back, "back.json").domain.is_pyramid);
  nlohmann::json bad = j;
  bad["domain"]["pyramid"].erase(4);
  try {
    templates::parse_spec(bad, "p.json");
    FAIL("four corners accepted");
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).find("domain.pyramid") != std::string::npos);
  }
  bad = j;
  std::swap(bad["domain"]["pyramid"][1], bad["domain"]["pyramid"][3]);  // clockwise base
  CHECK_THROWS_AS(templates::parse_spec(bad, "p.json"), InvalidInput);
}

TEST_CASE("pyramid: on the Gmsh-made hybrid demos, splitting beats Gmsh's 88 at every pyramid") {
  // What a filling of Schneiders' surface would have to beat to be chosen per pyramid in
  // conform: the split (the better diagonal's two tets, diced alone, as primal::split_pyramids
  // chooses). Gmsh's 88 hexes are placed in each pyramid by Gmsh itself (RefineMesh of that one
  // pyramid), unsmoothed.
  // Each model built by the command in a process of its own and read back (Gmsh 4.8's pyramid
  // relocation trips an Eigen assertion inside libgmsh on a later generate(3) of one process;
  // tests/demo/hybrid_models_test.cpp does the same).
  test::TempDir dir;
  std::vector<std::pair<std::string, primal::Model>> models;
  for (const std::string name : {"hybrid", "hybrid-cylinder"}) {
    models.emplace_back(name, test::demo_input(name, 0, dir));
  }
  for (const auto& [name, m] : models) {
    REQUIRE(!m.pyramids.empty());
    double split_lo = 1.0, gmsh_lo = 1.0;
    int gmsh_better = 0;
    for (const auto& p : m.pyramids) {
      double split = -1.0;
      for (int d = 0; d < 2; ++d) {
        const auto t = primal::pyramid_tets(p, d);
        split = std::max(split, primal::diced_min_scaled_jacobian(m.points, t));
      }
      std::array<Point, 5> c;
      for (std::size_t k = 0; k < 5; ++k) c[k] = m.points[primal::index_cast<std::size_t>(p[k])];
      const primal::HexMesh g = gmsh_pyramid_filling(c);
      REQUIRE(g.hexes.size() == 88);
      double lo = 1.0;
      for (Index h = 0; h < 88; ++h)
        lo = std::min(lo, primal::hex_scaled_jacobian(primal::hex_corners(g, h)));
      split_lo = std::min(split_lo, split);
      gmsh_lo = std::min(gmsh_lo, lo);
      gmsh_better += lo > split;
    }
    MESSAGE(name << ": " << m.pyramids.size() << " pyramids, split min scaled Jacobian " << split_lo
                 << ", Gmsh's 88 " << gmsh_lo << ", Gmsh's better at " << gmsh_better);
    CHECK(gmsh_better == 0);
    CHECK(gmsh_lo < split_lo);
  }
}

TEST_CASE("pyramid: Gmsh's 88 hexes smoothed by ours, the boundary at the diced positions") {
  // How far Gmsh's connectivity is from its placement's 0.160 on the equilateral pyramid: the
  // optimization smoother (primal/smooth.hpp) with every boundary node fixed.
  primal::HexMesh g = gmsh_pyramid_filling(equilateral());
  std::vector<primal::NodeConstraint> fix(g.points.size());
  for (const auto& f : primal::extract_boundary(g).faces)
    for (Index n : f.nodes)
      fix[primal::index_cast<std::size_t>(n)] = primal::NodeConstraint::fixed();
  const primal::SmoothResult r = primal::smooth_hex_mesh(g, fix);
  double lo = 1.0, sum = 0.0;
  for (Index h = 0; h < 88; ++h) {
    const double sj = primal::hex_scaled_jacobian(primal::hex_corners(g, h));
    lo = std::min(lo, sj);
    sum += sj;
  }
  MESSAGE("gmsh 88-hex pyramid smoothed: min scaled Jacobian "
          << lo << ", mean " << sum / 88.0 << " (" << r.iterations << " iterations)");
  CHECK(r.untangled);
  CHECK(primal::check_validity(g).ok());
  CHECK(lo > 0.155);
}
