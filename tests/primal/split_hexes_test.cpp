// Hexes as tets (primal/split_hexes.hpp): a grid split whole conforms and fills it, its sides
// moved onto the tets; by the lowest-node rule alone every hex splits on its corners whatever its
// numbering; diagonals no triangulation of the cube has (tets on its faces force them) get the
// hex's centre as a node, unless the tets are pyramids', which then take the other diagonal; a
// face under four tet triangles (no split follows it) is refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/split_hexes.hpp>
#include "support/model_checks.hpp"

using namespace geode;
using primal::ElementKind;
using primal::Index;
using primal::Point;

namespace {

// The model's nodes renumbered by a random permutation (so the lowest-node rule picks other
// diagonals), its points slightly moved so that no tet is degenerate by symmetry.
primal::Model shuffled(primal::Model m, unsigned seed) {
  std::vector<Index> to(m.points.size());
  std::iota(to.begin(), to.end(), Index{0});
  std::mt19937 rng(seed);
  std::shuffle(to.begin(), to.end(), rng);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  std::vector<Point> points(m.points.size());
  for (std::size_t v = 0; v < m.points.size(); ++v)
    points[primal::index_cast<std::size_t>(to[v])] =
        m.points[v] + Point(jitter(rng), jitter(rng), jitter(rng));
  m.points = points;
  for (auto& h : m.hexes)
    for (Index& v : h) v = to[primal::index_cast<std::size_t>(v)];
  return m;
}

// A unit cube with two tets on each face split along its corners 0-2 (kHexFaceCorners):
// every corner on one or two diagonals, none on three, and none of the cube's 74
// triangulations has those six. `pyramids`: each face's two tets share an apex outside it (a
// pyramid, which may as well be split along the other diagonal); else each has its own, above
// its triangle, and the diagonal is the tets' for good.
primal::Model cube_with_forced_faces(bool pyramids) {
  primal::Model m;
  for (const auto& c : primal::topology::kHexCornerCoords)
    m.points.push_back(Point(c[0], c[1], c[2]));
  primal::add_element(m, ElementKind::kHex, std::array<Index, 8>{0, 1, 2, 3, 4, 5, 6, 7}, 1, 1);
  const Point centre(0.5, 0.5, 0.5);
  std::int64_t id = 1;
  for (const auto& fc : primal::topology::kHexFaceCorners) {
    const auto v = [&](int i) { return primal::index_cast(fc[static_cast<std::size_t>(i)]); };
    const auto at = [&](int i) {
      return m.points[static_cast<std::size_t>(fc[static_cast<std::size_t>(i)])];
    };
    const Point mid = (at(0) + at(1) + at(2) + at(3)) / 4.0;
    std::array<Index, 2> apex{};
    for (std::size_t k = 0; k < 2; ++k) {
      // Above the face's middle, or above each triangle's centroid.
      const Point below =
          pyramids ? mid : (k == 0 ? at(0) + at(1) + at(2) : at(0) + at(2) + at(3)) / 3.0;
      if (k == 0 || !pyramids) m.points.push_back(below + (mid - centre));
      apex[k] = primal::index_cast(m.points.size() - 1);
    }
    primal::add_element(m, ElementKind::kTet, std::array<Index, 4>{v(0), v(1), v(2), apex[0]}, 2,
                        id++);
    primal::add_element(m, ElementKind::kTet, std::array<Index, 4>{v(0), v(2), v(3), apex[1]}, 2,
                        id++);
  }
  return m;
}

// The triangles of `m`'s tets' faces named by its side sets, each sorted.
std::multiset<std::array<Index, 3>> sided_triangles(const primal::Model& m) {
  std::multiset<std::array<Index, 3>> out;
  for (const primal::SideSet& set : m.side_sets)
    for (const primal::Side& side : set.sides) {
      const auto f = primal::element_face(m, side);
      std::array<Index, 3> t{f[0], f[1], f[2]};
      std::sort(t.begin(), t.end());
      out.insert(t);
    }
  return out;
}

// `m` with a side set on every face of its tets on the model's boundary (once among them, not
// all the hex's nodes): the pyramids' side triangles.
primal::Model with_side_triangles(primal::Model m) {
  std::map<std::array<Index, 3>, std::vector<primal::Side>> faces;
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const primal::Side side{{ElementKind::kTet, primal::index_cast(t)}, f};
      const auto nodes = primal::element_face(m, side);
      std::array<Index, 3> key{nodes[0], nodes[1], nodes[2]};
      std::sort(key.begin(), key.end());
      faces[key].push_back(side);
    }
  primal::SideSet set{4, "sides", {}};
  for (const auto& [key, sides] : faces)
    if (sides.size() == 1 && key[2] >= 8) set.sides.push_back(sides.front());
  m.side_sets.push_back(set);
  return m;
}

}  // namespace

TEST_CASE("split_hexes: a grid split whole conforms, fills it and keeps its sides, on corners") {
  const primal::Model grid =
      primal::grid_model({3, 2, 2}, 1.0, [](int, int, int) { return false; });
  REQUIRE(grid.hexes.size() == 12);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    CAPTURE(seed);
    primal::Model m = shuffled(grid, seed);
    double given = 0.0;
    for (const auto& h : m.hexes) {
      primal::HexCorners c;
      for (std::size_t k = 0; k < 8; ++k) c[k] = m.points[primal::index_cast<std::size_t>(h[k])];
      given += primal::hex_volume(c);
    }
    m.side_sets.push_back(
        {3, "bottom", {{{ElementKind::kHex, 0}, 4}, {{ElementKind::kHex, 5}, 1}}});
    std::vector<Index> all(m.hexes.size());
    std::iota(all.begin(), all.end(), Index{0});
    const primal::Model s = primal::split_hexes(m, all);
    CHECK(s.hexes.empty());
    CHECK(s.points.size() == m.points.size());  // no centre: the lowest corner always fits
    CHECK(s.tets.size() >= 5 * m.hexes.size());
    CHECK(s.tets.size() <= 6 * m.hexes.size());
    double sum = 0.0;
    for (const auto& t : s.tets) {
      CHECK(test::tet_volume(s, t) > 0.0);
      sum += test::tet_volume(s, t);
    }
    // The jittered hexes' faces are not planar: their tets fill what the triangles bound.
    CHECK(sum == doctest::Approx(given).epsilon(0.02));
    CHECK(primal::check_input(s).ok());  // conforming, covering its domain once
    REQUIRE(s.side_sets.size() == 1);
    CHECK(s.side_sets.front().sides.size() == 4);  // two quads, two triangles each
    for (const primal::Side& side : s.side_sets.front().sides)
      CHECK(side.element.kind == ElementKind::kTet);
    CHECK(std::all_of(s.tet_block.begin(), s.tet_block.end(),
                      [&](int b) { return b == grid.hex_block.front(); }));
  }
}

TEST_CASE("split_hexes: diagonals no triangulation of the cube has give the hex its centre") {
  primal::Model m = cube_with_forced_faces(false);
  const Point centre(0.5, 0.5, 0.5);
  for (const auto& t : m.tets) REQUIRE(test::tet_volume(m, t) > 0.0);
  REQUIRE(primal::check_input(m).ok());
  // File ids 10, 20, ..., not in order: the centre takes the next past the highest.
  for (std::size_t v = 0; v < m.points.size(); ++v)
    m.node_ids.push_back(10 * static_cast<std::int64_t>(m.points.size() - v));
  const primal::Model s = primal::split_hexes(m, std::vector<Index>{0});
  REQUIRE(s.points.size() == m.points.size() + 1);
  CHECK(s.points.back() == centre);
  REQUIRE(s.node_ids.size() == s.points.size());
  CHECK(s.node_ids.back() == 10 * static_cast<std::int64_t>(m.points.size()) + 1);
  REQUIRE(s.tets.size() == 12 + 12);
  double sum = 0.0;
  for (std::size_t t = 12; t < s.tets.size(); ++t) {
    CHECK(s.tets[t][3] == primal::index_cast(m.points.size()));
    CHECK(test::tet_volume(s, s.tets[t]) > 0.0);
    sum += test::tet_volume(s, s.tets[t]);
  }
  CHECK(sum == doctest::Approx(1.0));
  CHECK(primal::check_input(s).ok());
}

TEST_CASE("split_hexes: a pyramid on a face is split along the diagonal its hex's split needs") {
  // The same six diagonals, each given by a pyramid's two tets: some pyramids take the other
  // diagonal (their side triangles kept, the sides on them moved), so the hex splits on its
  // corners, no centre.
  const primal::Model m = with_side_triangles(cube_with_forced_faces(true));
  for (const auto& t : m.tets) REQUIRE(test::tet_volume(m, t) > 0.0);
  REQUIRE(primal::check_input(m).ok());
  REQUIRE(m.side_sets.front().sides.size() == 6 * 4);
  const primal::Model s = primal::split_hexes(m, std::vector<Index>{0});
  CHECK(s.points.size() == m.points.size());  // on its corners
  CHECK(s.tets.size() >= 12 + 5);
  CHECK(s.tets.size() <= 12 + 6);
  int flipped = 0;
  for (std::size_t t = 0; t < 12; ++t) flipped += s.tets[t] != m.tets[t];
  CHECK(flipped >= 2);  // at least one pyramid, both its tets
  CHECK(flipped % 2 == 0);
  double sum = 0.0;
  for (std::size_t t = 0; t < s.tets.size(); ++t) {
    CHECK(test::tet_volume(s, s.tets[t]) > 0.0);
    if (t >= 12) sum += test::tet_volume(s, s.tets[t]);
  }
  CHECK(sum == doctest::Approx(1.0));
  CHECK(primal::check_input(s).ok());  // conforming: each pyramid's tets meet the hex's
  CHECK(sided_triangles(s) == sided_triangles(m));  // every side on its triangle, once
}

TEST_CASE("split_hexes: a pyramid with a side on its base keeps its split") {
  // A side set on each pyramid's base triangles (the hex's faces, from the tets' side): half a
  // quad has no counterpart along the other diagonal, so the pyramids keep theirs, and the
  // hex, on six diagonals no triangulation has, gets its centre.
  primal::Model m = cube_with_forced_faces(true);
  primal::SideSet base{5, "base", {}};
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const auto nodes = primal::element_face(m, {{ElementKind::kTet, primal::index_cast(t)}, f});
      if (std::all_of(nodes.begin(), nodes.end(), [](Index v) { return v < 8; }))
        base.sides.push_back({{ElementKind::kTet, primal::index_cast(t)}, f});
    }
  REQUIRE(base.sides.size() == 12);
  m.side_sets.push_back(base);
  const primal::Model s = primal::split_hexes(m, std::vector<Index>{0});
  CHECK(s.points.size() == m.points.size() + 1);  // the centre
  for (std::size_t t = 0; t < 12; ++t) CHECK(s.tets[t] == m.tets[t]);
  for (const auto& t : s.tets) CHECK(test::tet_volume(s, t) > 0.0);
  CHECK(primal::check_input(s).ok());
  CHECK(sided_triangles(s) == sided_triangles(m));
}

TEST_CASE("split_hexes: a face under four tet triangles around a node is refused by name") {
  // No split of the hex follows the fan of four triangles on its top face: without the refusal
  // its tets would leave that face unmatched.
  primal::Model m;
  for (const auto& c : primal::topology::kHexCornerCoords)
    m.points.push_back(Point(c[0], c[1], c[2]));
  primal::add_element(m, ElementKind::kHex, std::array<Index, 8>{0, 1, 2, 3, 4, 5, 6, 7}, 1, 1);
  m.points.push_back(Point(0.5, 0.5, 1.0));  // the fan's centre, on the top face
  m.points.push_back(Point(0.5, 0.5, 1.5));  // an apex above it
  const std::array<Index, 4> top{4, 5, 6, 7};
  for (std::size_t i = 0; i < 4; ++i)
    primal::add_element(m, ElementKind::kTet, std::array<Index, 4>{top[i], top[(i + 1) % 4], 8, 9},
                        2, static_cast<std::int64_t>(i) + 1);
  for (const auto& t : m.tets) REQUIRE(test::tet_volume(m, t) > 0.0);
  REQUIRE(primal::check_input(m).ok());
  CHECK_THROWS_WITH_AS(
      primal::split_hexes(m, std::vector<Index>{0}),
      doctest::Contains("hex 1 (centre (0.5, 0.5, 0.5)): its face of nodes 5 6 7 8 "
                        "lies under four tet triangles around node 9"),
      TopologyError);
}

TEST_CASE("split_hexes: a column's faces between its cells follow the diagonal forced on its end") {
  // Two cells 0.1 high over a unit square whose corners 1 and 3 are 0.15 higher than 0 and 2 (a
  // warped layer, as a curved one's cells are): two tets, each from an apex above its
  // triangle (not a pyramid, which could take the other diagonal), force the top face's low
  // diagonal, 0-2. The face between the cells has its lowest node at corner 1, as where the
  // extruded surface's nodes come first: its lowest-node diagonal, 1-3, lies above the top's,
  // so no split of the upper cell, nor its centre's, had positive tets on those two.
  const double height = 0.1, warp = 0.15;
  primal::Model m;
  // Nodes: the top level's corners 0-3, then the middle's 1, 2, 3, 0, then the bottom's 0-3.
  const std::array<std::array<int, 4>, 3> order{{{0, 1, 2, 3}, {1, 2, 3, 0}, {0, 1, 2, 3}}};
  std::array<std::array<Index, 4>, 3> node{};  // per level (bottom first), per corner
  for (std::size_t level : {2, 1, 0})
    for (int c : order[2 - level]) {
      const auto& xy = primal::topology::kHexCornerCoords[static_cast<std::size_t>(c)];
      node[level][static_cast<std::size_t>(c)] = primal::index_cast(m.points.size());
      m.points.push_back(
          Point(xy[0], xy[1], height * static_cast<double>(level) + (c % 2 ? warp : 0.0)));
    }
  for (std::size_t level = 0; level < 2; ++level) {
    std::array<Index, 8> h{};
    for (std::size_t c = 0; c < 4; ++c) h[c] = node[level][c], h[c + 4] = node[level + 1][c];
    primal::add_element(m, ElementKind::kHex, h, 1, primal::index_cast(level) + 1);
  }
  const auto& top = node[2];
  const std::array<std::array<Index, 3>, 2> triangles{
      {{top[0], top[1], top[2]}, {top[0], top[2], top[3]}}};
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& t = triangles[k];
    Point above = Point::Zero();
    for (Index v : t) above += m.points[primal::index_cast<std::size_t>(v)] / 3.0;
    m.points.push_back(above + Point(0.0, 0.0, 0.5));
    primal::add_element(
        m, ElementKind::kTet,
        std::array<Index, 4>{t[0], t[1], t[2], primal::index_cast(m.points.size() - 1)}, 2,
        primal::index_cast(k) + 1);
  }
  for (const auto& t : m.tets) REQUIRE(test::tet_volume(m, t) > 0.0);
  REQUIRE(primal::check_input(m).ok());
  REQUIRE(std::min({node[1][0], node[1][1], node[1][2], node[1][3]}) == node[1][1]);
  const primal::Model s = primal::split_hexes(m, std::vector<Index>{0, 1});
  CHECK(s.hexes.empty());
  CHECK(s.points.size() == m.points.size());  // on their corners
  for (const auto& t : s.tets) CHECK(test::tet_volume(s, t) > 0.0);
  CHECK(primal::check_input(s).ok());  // conforming: the top face's two triangles kept
}
