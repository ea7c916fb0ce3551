// Hex parts in a TetGen potting, made as a user makes one: the parts' structured hexes, their
// boundary quads each split into two triangles as the surface TetGen must keep (-Y), a box
// around them, and TetGen's quality tets in between (tetgen -pq1.4a0.01Y: no point added on
// the surface, 200 to 1,400 inside). A box, an L-shaped part (concave edges and a concave
// corner), two boxes (one raised, so their faces are not coplanar) and a sheared box: conform
// with the defaults is valid at or above the yardstick, each block keeps its volume to 1e-9
// relative through smoothing, and the geode hexes are above 0.12 (measured 0.145 to 0.201 at
// n = 3 to 6).
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/conform/report.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality.hpp>
#include "support/conform_checks.hpp"
#include "support/sanitized.hpp"
#include "support/temp_dir.hpp"
#include "support/tetgen_files.hpp"

using namespace geode;
using primal::ElementKind;
using primal::Index;
using primal::Point;

namespace {

using Cell = std::array<int, 3>;

// The hex part's cells on an integer grid of spacing 1/n (a plate: one layer, 2n x 2n).
std::set<Cell> part_cells(const std::string& shape, int n) {
  std::set<Cell> cells;
  for (int i = 0; i < 2 * n; ++i)
    for (int j = 0; j < 2 * n; ++j)
      for (int k = 0; k < n; ++k) {
        const bool box = i < n && j < n;
        if (shape == "plate") {
          if (k == 0) cells.insert({i, j, k});
          continue;
        }
        if (shape == "lshape" ? (i < n || j < n) : box) cells.insert({i, j, k});
        if (shape == "two" && box) cells.insert({i + n + 2, j, k + 1});
      }
  return cells;
}

// The model: the part's hexes (block 1; sheared with `shear`), then TetGen's tets (block 2)
// filling the box 0.8 beyond the part, its faces given as 10 x 10 grids of triangles (with the
// surface kept, TetGen adds no point inside when they are single quads).
primal::Model tetgen_potting(const std::string& shape, int n, bool shear,
                             const test::TempDir& dir) {
  primal::Model m;
  std::map<Cell, Index> node_of;
  auto node = [&](const Cell& c) {
    auto [it, added] = node_of.try_emplace(c, primal::index_cast(m.points.size()));
    if (added) {
      Point p = Point(c[0], c[1], c[2]) / n;
      if (shear) p += Point(0.3 * p.z(), 0.15 * p.z() * p.x(), 0.0);
      if (shape == "plate") p.z() *= 0.37;  // its cells 0.37 as high as wide: thin
      m.points.push_back(p);
    }
    return it->second;
  };
  // Hexes, and the faces no two hexes share: the part's surface.
  constexpr int kFace[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                               {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::map<std::array<Index, 4>, std::array<Index, 4>> faces;  // sorted nodes -> the face
  std::int64_t id = 0;
  for (const auto& [i, j, k] : part_cells(shape, n)) {
    std::array<Index, 8> h{};
    const Cell c[8] = {{i, j, k},     {i + 1, j, k},     {i + 1, j + 1, k},     {i, j + 1, k},
                       {i, j, k + 1}, {i + 1, j, k + 1}, {i + 1, j + 1, k + 1}, {i, j + 1, k + 1}};
    for (int v = 0; v < 8; ++v) h[static_cast<std::size_t>(v)] = node(c[v]);
    primal::add_element(m, ElementKind::kHex, h, 1, ++id);
    for (const auto& f : kFace) {
      std::array<Index, 4> q{};
      for (int v = 0; v < 4; ++v)
        q[static_cast<std::size_t>(v)] = h[static_cast<std::size_t>(f[v])];
      std::array<Index, 4> key = q;
      std::sort(key.begin(), key.end());
      if (!faces.erase(key)) faces.emplace(key, q);
    }
  }
  // The .poly: the surface's nodes (TetGen keeps them first, in order), the box's grids.
  std::vector<Index> surface;
  std::map<Index, int> poly_of;
  for (const auto& [key, q] : faces)
    for (Index v : q)
      if (poly_of.try_emplace(v, static_cast<int>(surface.size())).second) surface.push_back(v);
  Point lo = m.points[0], hi = m.points[0];
  for (const Point& p : m.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  lo.array() -= 0.8, hi.array() += 0.8;
  constexpr int kGrid = 10;
  std::vector<Point> outer;
  std::map<std::tuple<long, long, long>, int> outer_of;
  std::vector<std::array<int, 3>> triangles;
  auto outer_node = [&](const Point& p) {
    const auto key = std::make_tuple(std::lround(p.x() * 1e9), std::lround(p.y() * 1e9),
                                     std::lround(p.z() * 1e9));
    auto [it, added] = outer_of.try_emplace(key, static_cast<int>(surface.size() + outer.size()));
    if (added) outer.push_back(p);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      auto at = [&](int a, int b) {
        Point p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = lo[u] + (hi[u] - lo[u]) * a / kGrid;
        p[w] = lo[w] + (hi[w] - lo[w]) * b / kGrid;
        return outer_node(p);
      };
      for (int a = 0; a < kGrid; ++a)
        for (int b = 0; b < kGrid; ++b) {
          triangles.push_back({at(a, b), at(a + 1, b), at(a + 1, b + 1)});
          triangles.push_back({at(a, b), at(a + 1, b + 1), at(a, b + 1)});
        }
    }
  for (const auto& [key, q] : faces) {  // each quad split along one of its diagonals
    std::array<int, 4> p{};
    for (int v = 0; v < 4; ++v)
      p[static_cast<std::size_t>(v)] = poly_of.at(q[static_cast<std::size_t>(v)]);
    if ((q[0] + q[1] + q[2] + q[3]) % 2)
      triangles.push_back({p[0], p[1], p[2]}), triangles.push_back({p[0], p[2], p[3]});
    else
      triangles.push_back({p[0], p[1], p[3]}), triangles.push_back({p[1], p[2], p[3]});
  }
  const auto poly = dir.path / (shape + ".poly");
  {
    std::ofstream f(poly);
    f.precision(17);
    f << surface.size() + outer.size() << " 3 0 0\n";
    int k = 0;
    for (Index v : surface) {
      const Point& p = m.points[primal::index_cast<std::size_t>(v)];
      f << k++ << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
    for (const Point& p : outer) f << k++ << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
    f << triangles.size() << " 0\n";
    for (const auto& t : triangles) f << "1\n3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    // A hole in each part: the centre of one of its hexes.
    const std::vector<Index> holes = {0, primal::index_cast(m.hexes.size()) - 1};
    f << holes.size() << "\n";
    for (std::size_t i = 0; i < holes.size(); ++i) {
      Point c = Point::Zero();
      for (Index v : m.hexes[primal::index_cast<std::size_t>(holes[i])])
        c += m.points[primal::index_cast<std::size_t>(v)] / 8.0;
      f << i << " " << c.x() << " " << c.y() << " " << c.z() << "\n";
    }
  }
  const std::string cmd = "cd " + dir.path.string() + " && tetgen -pq1.4a0.01YQ " +
                          poly.filename().string() + " > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  // TetGen keeps the surface's nodes first, in order (the .poly numbers from 0).
  const std::vector<Point> tetgen = test::read_tetgen_nodes(dir.path / (shape + ".1.node"));
  REQUIRE(tetgen.size() >= surface.size() + outer.size());
  std::vector<Index> model_of(tetgen.size());
  for (std::size_t i = 0; i < tetgen.size(); ++i) {
    if (i < surface.size()) {  // the surface kept, node for node
      REQUIRE((tetgen[i] - m.points[primal::index_cast<std::size_t>(surface[i])]).norm() < 1e-12);
      model_of[i] = surface[i];
    } else {
      model_of[i] = primal::index_cast(m.points.size());
      m.points.push_back(tetgen[i]);
    }
  }
  for (std::array<Index, 4> t : test::read_tetgen_tets(dir.path / (shape + ".1.ele"), 0, tetgen)) {
    for (Index& v : t) v = model_of[primal::index_cast<std::size_t>(v)];
    primal::add_element(m, ElementKind::kTet, t, 2, ++id);
  }
  for (std::size_t i = 0; i < m.points.size(); ++i)
    m.node_ids.push_back(static_cast<std::int64_t>(i + 1));
  m.block_names = {{1, "part"}, {2, "potting"}};
  return m;
}

}  // namespace

// Both skipped in the sanitized build (tests/support/sanitized.hpp): the materials and local
// yardstick tests run the same paths there on the potting demo.
TEST_CASE("hex parts in a TetGen potting: valid, at or above the yardstick, volumes kept" *
          doctest::skip(test::kSanitized)) {
  const test::TempDir dir;
  for (const auto& [shape, shear] : {std::pair{"box", false}, std::pair{"lshape", false},
                                     std::pair{"two", false}, std::pair{"box", true}}) {
    const std::string name = std::string(shape) + (shear ? " (sheared)" : "");
    CAPTURE(name);
    const primal::Model input = tetgen_potting(shape, 3, shear, dir);
    REQUIRE(input.tets.size() > 1000);
    // The defaults, and the part given (--buffer-side hex) on the boxes. From the part, its
    // corners' geode hexes reached 0.69 to 0.73 x their capped local yardstick (0.150 to 0.200, the
    // part's block as low); from the potting 0.78 to 0.90 x (0.197 to 0.215), the output's minimum
    // the same, the part's block 0.78 to 0.90: the defaults keep the potting's layer on all four.
    for (const std::string side : {"", "hex"}) {
      // The part given: on the box and the sheared box (its non-planar quads' volume said).
      if (side == "hex" && std::string(shape) != "box") continue;
      CAPTURE(side);
      conform::ConformOptions o;
      conform::set_buffer_side(o, side);
      const conform::ConformResult r = conform::conform(input, o);
      const bool from_part = r.buffer_side == conform::BufferSide::kHex;
      CHECK(from_part == (side == "hex"));
      // Without smoothing, carved from the same part.
      conform::ConformOptions none;
      none.smooth = conform::ConformSmooth::kNone;
      conform::set_buffer_side(none, conform::buffer_side_name(r.buffer_side));
      const conform::ConformResult unsmoothed = conform::conform(input, none);
      // The sheared part's non-planar quads: a warning, the carved block's volume change
      // (below); carved from the potting by conform's choice, a warning says why.
      test::check_conform_result(r, -1, (shear ? 1 : 0) + (from_part ? 0 : 1));
      test::check_conform_result(unsmoothed, -1, shear ? 1 : 0);
      if (!from_part)
        CHECK(r.warnings.front().find("at the hex part's convex corners") != std::string::npos);
      CHECK(conform::output_min_scaled_jacobian(r) >= r.yardstick());
      // The block not carved keeps its input space exactly; the carved one (the geode hexes')
      // too where the part's quads are planar; whatever the shear, smoothing moves neither
      // (the sheared part's quads are not planar, so its hexes' trilinear volume is not what
      // the triangles TetGen kept enclose: the geode hexes fill up to the faces of the part
      // they were not carved from).
      const auto out = test::hex_block_volumes(r.model);
      const auto placed = test::hex_block_volumes(unsmoothed.model);
      const auto part = test::hex_block_volumes(input), potting = test::tet_block_volumes(input);
      const auto given = [&](int block) { return block == 1 ? part.at(1) : potting.at(2); };
      const int kept = from_part ? 2 : 1, carved = from_part ? 1 : 2;
      REQUIRE(out.size() == 2);
      CHECK(std::abs(out.at(kept) - given(kept)) <= 1e-9 * given(kept));
      for (int block : {1, 2}) {
        CAPTURE(block);
        CHECK(std::abs(out.at(block) - placed.at(block)) <= 1e-9 * placed.at(block));
      }
      if (!shear) CHECK(std::abs(out.at(carved) - given(carved)) <= 1e-9 * given(carved));
      if (shear) {
        // It says how much.
        const std::string& w = r.warnings.back();
        CAPTURE(w);
        const double change = out.at(carved) - given(carved);
        const std::string head = std::string(from_part ? "block 1 'part' " : "block 2 'potting' ") +
                                 (change > 0 ? "gains " : "loses ");
        const auto at = w.find(head);
        REQUIRE(at != std::string::npos);
        CHECK(std::abs(std::stod(w.substr(at + head.size())) - std::abs(change)) <=
              1e-5 * std::abs(change));
      }
      for (const conform::BlockQuality& b : r.quality) {
        if (b.geode_hexes > 0) CHECK(b.geode_min_scaled_jacobian > (from_part ? 0.14 : 0.19));
        // Each block at least half its own input diced alone (issue 22) from the potting.
        if (!from_part)
          CHECK(b.report.metrics[0].minimum >= 0.5 * b.input_diced_min_scaled_jacobian);
      }
    }
  }
}

TEST_CASE("a thin plate across two tet blocks: the hex part's layer keeps every block's volume" *
          doctest::skip(test::kSanitized)) {
  // A plate of thin cells (0.37 as high as wide) in TetGen potting split into two blocks
  // across it: the tets' layer is thicker (0.285 of the quads' edge against 0.128 from the hex
  // part), but crosses the faces between their blocks, and the hex part's output is at the
  // yardstick (0.0683): the hex part's is kept, every block's volume with it. The tets' was
  // taken: its blocks 0.0039 off (found by a fault hunt on such a model: 0.3 % of a block).
  // Where the hex part's output is below the yardstick (this plate 0.3 as high as wide: 0.056
  // against 0.071) the tets' layer is taken after all, with a warning that blocks move.
  const test::TempDir dir;
  primal::Model input = tetgen_potting("plate", 3, false, dir);
  for (std::size_t t = 0; t < input.tets.size(); ++t) {
    Point c = Point::Zero();
    for (Index v : input.tets[t]) c += input.points[primal::index_cast<std::size_t>(v)] / 4.0;
    if (c.x() > 1.0) input.tet_block[t] = 3;
  }
  input.block_names[3] = "potting b";
  const conform::ConformResult r = conform::conform(input);
  test::check_conform_result(r);
  CHECK(r.buffer_side == conform::BufferSide::kHex);
  CHECK(conform::output_min_scaled_jacobian(r) >= r.yardstick());
  const auto out = test::hex_block_volumes(r.model);
  const auto part = test::hex_block_volumes(input), potting = test::tet_block_volumes(input);
  REQUIRE(out.size() == 3);
  CHECK(std::abs(out.at(1) - part.at(1)) <= 1e-9 * part.at(1));
  for (int block : {2, 3}) {
    CAPTURE(block);
    CHECK(std::abs(out.at(block) - potting.at(block)) <= 1e-9 * potting.at(block));
  }
}
