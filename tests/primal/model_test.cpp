// The cell-kind table (topology::kCellKinds) checked on reference cells: every face outward
// (its area vector points away from the centre, and they sum to zero: a closed surface), every
// edge on exactly two faces, Euler's V - E + F = 2; the corner frames right-handed; and the
// read-time geometry checks refusing inverted wedges and pyramids by their file ids.
#include <geode/primal/model.hpp>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

using namespace geode::primal;
namespace topo = geode::primal::topology;

namespace {

// Reference cells in the table's corner order, positively oriented.
std::vector<Point> reference_corners(ElementKind kind) {
  switch (kind) {
    case ElementKind::kHex: {
      std::vector<Point> p;
      for (const auto& c : topo::kHexCornerCoords) p.emplace_back(c[0], c[1], c[2]);
      return p;
    }
    case ElementKind::kTet:
      return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    case ElementKind::kPyramid:
      return {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}};
    case ElementKind::kWedge:
      return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  }
  return {};
}

Model one_cell(ElementKind kind, std::vector<Point> points) {
  Model m;
  m.points = std::move(points);
  std::vector<Index> c(m.points.size());
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = index_cast(i);
  switch (kind) {
    case ElementKind::kHex:
      m.hexes.push_back({c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]});
      m.hex_ids = {41};
      break;
    case ElementKind::kTet:
      m.tets.push_back({c[0], c[1], c[2], c[3]});
      m.tet_ids = {42};
      break;
    case ElementKind::kPyramid:
      m.pyramids.push_back({c[0], c[1], c[2], c[3], c[4]});
      m.pyramid_ids = {43};
      break;
    case ElementKind::kWedge:
      m.wedges.push_back({c[0], c[1], c[2], c[3], c[4], c[5]});
      m.wedge_ids = {44};
      break;
  }
  return m;
}

}  // namespace

TEST_CASE("cell kinds: faces outward and closed, edges on two faces, Euler") {
  for (ElementKind kind : kElementKinds) {
    const auto& t = cell_topology(kind);
    const auto p = reference_corners(kind);
    CAPTURE(t.name);
    REQUIRE(index_cast<int>(p.size()) == t.corners);
    Point centre = Point::Zero();
    for (const Point& x : p) centre += x / static_cast<double>(p.size());
    Point total = Point::Zero();
    std::vector<int> edge_uses(index_cast<std::size_t>(t.edges), 0);
    for (int f = 0; f < t.faces; ++f) {
      const auto& face = t.face[index_cast<std::size_t>(f)];
      Point area = Point::Zero(), fc = Point::Zero();
      for (int k = 0; k < face.size; ++k) {
        const Point& a = p[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(k)])];
        const Point& b =
            p[index_cast<std::size_t>(face.corners[index_cast<std::size_t>((k + 1) % face.size)])];
        area += a.cross(b) / 2.0;
        fc += a / face.size;
        const auto [lo, hi] =
            std::minmax(face.corners[index_cast<std::size_t>(k)],
                        face.corners[index_cast<std::size_t>((k + 1) % face.size)]);
        int found = 0;
        for (int e = 0; e < t.edges; ++e) {
          const auto& ed = t.edge[index_cast<std::size_t>(e)];
          if (std::min(ed[0], ed[1]) == lo && std::max(ed[0], ed[1]) == hi)
            ++edge_uses[index_cast<std::size_t>(e)], ++found;
        }
        CHECK(found == 1);
      }
      CHECK(area.dot(fc - centre) > 0.0);
      total += area;
    }
    CHECK(total.norm() < 1e-12);
    for (int u : edge_uses) CHECK(u == 2);
    CHECK(t.corners - t.edges + t.faces == 2);
  }
  CHECK(topo::kCellKinds[0].face[3].corners ==
        std::array<int, 4>{3, 0, 4, 7});  // the hex table agrees
  for (int f = 0; f < 6; ++f)
    for (int k = 0; k < 4; ++k)
      CHECK(topo::kCellKinds[0]
                .face[index_cast<std::size_t>(f)]
                .corners[index_cast<std::size_t>(k)] ==
            topo::kHexFaceCorners[index_cast<std::size_t>(f)][index_cast<std::size_t>(k)]);
}

TEST_CASE("cell kinds: wedge and tet corner frames are right-handed on the reference cells") {
  const auto w = reference_corners(ElementKind::kWedge);
  for (std::size_t c = 0; c < 6; ++c) {
    const auto& n = topo::kWedgeCornerNeighbors[c];
    CHECK(tet_volume(w[c], w[index_cast<std::size_t>(n[0])], w[index_cast<std::size_t>(n[1])],
                     w[index_cast<std::size_t>(n[2])]) > 0.0);
  }
  const auto t = reference_corners(ElementKind::kTet);
  for (std::size_t c = 0; c < 4; ++c) {
    const auto& n = topo::kTetCornerNeighbors[c];
    CHECK(tet_volume(t[c], t[index_cast<std::size_t>(n[0])], t[index_cast<std::size_t>(n[1])],
                     t[index_cast<std::size_t>(n[2])]) > 0.0);
  }
}

TEST_CASE("model: accessors, blocks and ids per kind") {
  Model m = one_cell(ElementKind::kWedge, reference_corners(ElementKind::kWedge));
  CHECK(element_count(m) == 1);
  CHECK(block_of(m, {ElementKind::kWedge, 0}) == default_block(ElementKind::kWedge));
  CHECK(element_id(m, {ElementKind::kWedge, 0}) == 44);
  CHECK(describe_element(m, {ElementKind::kWedge, 0}).rfind("wedge 44 (centre", 0) == 0);
  CHECK(element_face(m, {{ElementKind::kWedge, 0}, 4}) == std::vector<Index>{3, 4, 5});
  CHECK_NOTHROW(validate(m, "w.msh"));
  CHECK_NOTHROW(check_geometry(m, "w.msh"));
  m.wedge_block = {0};
  CHECK_THROWS_WITH_AS(validate(m, "w.msh"), doctest::Contains("wedge 44: block id 0"),
                       geode::InvalidInput);
  m.wedge_block = {};
  m.side_sets.push_back({1, "s", {{{ElementKind::kWedge, 0}, 5}}});
  CHECK_THROWS_WITH_AS(validate(m, "w.msh"), doctest::Contains("face 6 out of range [1, 5]"),
                       geode::InvalidInput);
}

TEST_CASE("model: a corner out of range found in any cell, named by the first offender's id") {
  // validate scans runs of cells four node numbers at a time, then a tail; every kind (4 to 8
  // corners), offenders first, last and in the middle of a run, below 0 and past the last node.
  for (const ElementKind kind : kElementKinds) {
    for (const std::size_t bad : {std::size_t{0}, std::size_t{300}, std::size_t{1002}}) {
      for (const Index value : {Index{-1}, Index{10}, Index{1 << 30}}) {
        Model m;
        m.points.assign(10, Point::Zero());
        const auto corners = index_cast<std::size_t>(cell_topology(kind).corners);
        for (std::size_t e = 0; e < 1003; ++e) {  // pyramids, wedges: a tail of 3, 2 numbers
          std::array<Index, 8> c{};
          for (std::size_t k = 0; k < corners; ++k) c[k] = index_cast((e + k) % 10);
          add_element(m, kind, c, default_block(kind), static_cast<std::int64_t>(e + 1));
        }
        CHECK_NOTHROW(validate(m, "big.msh"));
        auto set_corner = [&](auto& cells) { cells[bad][corners - 1] = value; };
        with_cells(m, kind, set_corner);
        CAPTURE(element_kind_name(kind));
        CAPTURE(bad);
        CAPTURE(value);
        const std::string expected = std::string(element_kind_name(kind)) + " " +
                                     std::to_string(bad + 1) + ": corner " +
                                     std::to_string(corners);
        CHECK_THROWS_WITH_AS(validate(m, "big.msh"), doctest::Contains(expected.c_str()),
                             geode::InvalidInput);
      }
    }
  }
}

TEST_CASE("model: a merge tolerance as long as some element's edge is refused, naming it") {
  // Each kind in turn: its reference cell scaled by 0.01 (every kind's shortest edge is 1).
  for (const ElementKind kind : kElementKinds) {
    auto p = reference_corners(kind);
    for (Point& x : p) x *= 0.01;
    const Model m = one_cell(kind, p);
    CAPTURE(element_kind_name(kind));
    CHECK_NOTHROW(check_merge_tolerance(m, 0.009, "--merge-tolerance"));
    const std::string named = std::string(element_kind_name(kind)) + " " +
                              std::to_string(element_id(m, {kind, 0})) + " (centre";
    CHECK_THROWS_WITH_AS(check_merge_tolerance(m, 0.01, "--merge-tolerance"),
                         doctest::Contains(named.c_str()), geode::InvalidInput);
    CHECK_THROWS_WITH_AS(check_merge_tolerance(m, 0.5, "merge_tolerance="),
                         doctest::Contains("merge_tolerance=0.5 is not below the shortest"),
                         geode::InvalidInput);
  }
}

TEST_CASE("model: inverted wedges and pyramids refused by their file ids") {
  auto w = reference_corners(ElementKind::kWedge);
  std::swap(w[1], w[2]), std::swap(w[4], w[5]);  // VTK's order read as ours: mirrored
  CHECK_THROWS_WITH_AS(check_geometry(one_cell(ElementKind::kWedge, w), "in.vtu"),
                       doctest::Contains("in.vtu: wedge 44 (centre"), geode::InvalidInput);
  auto p = reference_corners(ElementKind::kPyramid);
  CHECK_NOTHROW(check_geometry(one_cell(ElementKind::kPyramid, p), "in.msh"));
  p[4].z() = -1.0;  // apex below the base
  CHECK_THROWS_WITH_AS(check_geometry(one_cell(ElementKind::kPyramid, p), "in.msh"),
                       doctest::Contains("in.msh: pyramid 43 (centre"), geode::InvalidInput);
  // A non-convex base: one diagonal still gives two positive tets, so it is accepted.
  p = reference_corners(ElementKind::kPyramid);
  p[2] = Point(0.3, 0.3, 0.0);
  CHECK_NOTHROW(check_geometry(one_cell(ElementKind::kPyramid, p), "in.msh"));
}

TEST_CASE("model: an element listing a node twice is said so, with no hint to unfold it") {
  // A flat cell's refusal suggests --unfold, which moves nodes and cannot mend a repeated one
  // (found by a fault hunt: "tet 138 is flat ... --unfold mends such cells").
  for (const ElementKind kind : kElementKinds) {
    CAPTURE(static_cast<int>(kind));
    Model m = one_cell(kind, reference_corners(kind));
    with_cells(m, kind, [](auto& cells) { cells[0][1] = cells[0][0]; });
    const std::string hint = " (--unfold mends such cells)";
    try {
      check_geometry(m, "in.msh", hint);
      FAIL("not refused");
    } catch (const geode::InvalidInput& e) {
      const std::string text = e.what();
      CHECK(text.find(" lists node 1 (0, 0, 0) twice (nodes 1 1 ") != std::string::npos);
      CHECK(text.find(hint) == std::string::npos);
    }
  }
}

TEST_CASE("model: a non-finite node is refused, and said to be unused where no element uses it") {
  Model m = one_cell(ElementKind::kTet, reference_corners(ElementKind::kTet));
  m.points.push_back(Point(std::nan(""), 0.0, 0.0));
  m.node_ids = {11, 12, 13, 14, 15};
  CHECK_THROWS_WITH_AS(
      check_points(m, "in.msh"),
      "in.msh: node 15 (nan, 0, 0) has a non-finite coordinate (no element uses it)",
      geode::InvalidInput);
  m.points[1].y() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH_AS(check_points(m, "in.msh"),
                       "in.msh: node 12 (1, inf, 0) has a non-finite coordinate",
                       geode::InvalidInput);
}

TEST_CASE("model: a node set's node that no element uses is refused by its file id") {
  // As a Gmsh file saved without the elements of a volume in no physical group: the volume's
  // physical point stays, its elements do not.
  Model m = one_cell(ElementKind::kTet, reference_corners(ElementKind::kTet));
  m.points.push_back(Point(5.0, 0.0, 0.0));
  m.node_ids = {11, 12, 13, 14, 15};
  m.node_sets.push_back({7, "corner", {0}});
  CHECK_NOTHROW(check_geometry(m, "in.msh"));
  m.node_sets.push_back({8, "lost", {1, 4}});
  CHECK_THROWS_WITH_AS(check_geometry(m, "in.msh"),
                       doctest::Contains("in.msh: node set 8 'lost': node 15 (5, 0, 0) belongs to "
                                         "no element"),
                       geode::InvalidInput);
}

TEST_CASE("model: join_blocks puts the listed blocks' elements into the first") {
  // Two wedges (one in the default block 4) and a hex in block 7 "steel", a tet in 9 "tets".
  Model m = one_cell(ElementKind::kWedge, reference_corners(ElementKind::kWedge));
  m.wedges.push_back(m.wedges.front());
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 0, 1});  // structure only: join_blocks reads blocks
  m.hex_block = {7};
  m.tets.push_back({0, 1, 2, 3});
  m.tet_block = {9};
  m.block_names = {{7, "steel"}, {9, "tets"}, {4, "layer"}};
  const std::vector<int> steel{7, 9, 4};
  join_blocks(m, steel, "m.exo");
  CHECK(m.hex_block == std::vector<int>{7});
  CHECK(m.tet_block == std::vector<int>{7});
  CHECK(m.wedge_block == std::vector<int>{7, 7});  // the default block, written out
  CHECK(m.block_names == std::map<int, std::string>{{7, "steel"}});
  const std::vector<int> missing{7, 9}, twice{7, 7}, one{7};
  CHECK_THROWS_WITH_AS(join_blocks(m, missing, "m.exo"),
                       "m.exo: joining blocks 7,9: no element is in block 9", geode::InvalidInput);
  CHECK_THROWS_WITH_AS(join_blocks(m, twice, "m.exo"),
                       "m.exo: joining blocks 7,7: block 7 is listed twice", geode::InvalidInput);
  CHECK_THROWS_WITH_AS(join_blocks(m, one, "m.exo"),
                       "m.exo: joining blocks 7: give two blocks or more", geode::InvalidInput);
}
