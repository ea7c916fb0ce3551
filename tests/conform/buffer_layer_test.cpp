// Buffer layer, carved from either part: corner conventions, positive elements, the other part
// untouched, and no gap or overlap: the volumes of hex part + buffer hexes + tets add up to the
// volume of the original block. Each
// element's volume is its boundary flux with every face triangulated the same way from both
// sides (buffer tops along their diagonal, other quads from their smallest node), so shared
// faces cancel and the sum is the flux through the outer boundary, which the layer must not move.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include <geode/conform/buffer_layer.hpp>
#include <geode/demo/demo_models.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

using namespace geode;
using namespace geode::primal;
using namespace geode::conform;

namespace {

double tri_flux(const std::vector<Point>& p, Index a, Index b, Index c) {
  return p[index_cast<std::size_t>(a)].dot(
             p[index_cast<std::size_t>(b)].cross(p[index_cast<std::size_t>(c)])) /
         6.0;
}

// Quad (outward, counter-clockwise) split along corners (k, k+2).
double quad_flux(const std::vector<Point>& p, std::array<Index, 4> q, int k) {
  auto at = [&](int i) { return q[index_cast<std::size_t>((i + k) % 4)]; };
  return tri_flux(p, at(0), at(1), at(2)) + tri_flux(p, at(0), at(2), at(3));
}

int canonical_split(const std::array<Index, 4>& q) {
  return static_cast<int>(std::min_element(q.begin(), q.end()) - q.begin()) % 2;
}

double hex_flux_volume(const std::vector<Point>& p, const std::array<Index, 8>& h,
                       int top_split = -1) {
  double v = 0;
  for (int f = 0; f < 6; ++f) {
    std::array<Index, 4> q{};
    for (std::size_t i = 0; i < 4; ++i)
      q[i] = h[index_cast<std::size_t>(topology::kHexFaceCorners[index_cast<std::size_t>(f)][i])];
    // Face 5 is 4 5 6 7: split 0 joins 4-6, split 1 joins 5-7.
    v += quad_flux(p, q, f == 5 && top_split >= 0 ? top_split : canonical_split(q));
  }
  return v;
}

struct Case {
  const char* name;
  std::array<int, 3> cells;
  std::function<bool(int, int, int)> is_tet;
  std::size_t quads;
};

constexpr std::array<BufferSide, 2> kSides{BufferSide::kHex, BufferSide::kTet};

BufferLayerOptions on_side(BufferSide side) {
  BufferLayerOptions o;
  o.side = side;  // thickness 0: default_buffer_thickness(side)
  return o;
}

void check_layer(const Case& c, BufferSide side) {
  CAPTURE(c.name);
  CAPTURE(static_cast<int>(side));
  const Model m = grid_model(c.cells, 1.0, c.is_tet);
  const Interface itf = find_interface(m);
  REQUIRE(itf.quads.size() == c.quads);
  const BufferLayer layer = insert_buffer_layer(m, itf, on_side(side));
  const auto& p = layer.model.points;
  REQUIRE(p.size() == m.points.size() + itf.nodes.size());
  REQUIRE(layer.hexes.size() == itf.quads.size());
  CHECK(layer.model.hexes == m.hexes);
  // The part the layer is not carved from keeps every corner where it was; squashed hexes
  // keep their share of quality.
  if (side == BufferSide::kHex) {
    for (std::size_t t = 0; t < m.tets.size(); ++t)
      for (std::size_t i = 0; i < 4; ++i)
        CHECK(p[index_cast<std::size_t>(layer.model.tets[t][i])] ==
              m.points[index_cast<std::size_t>(m.tets[t][i])]);
    for (const auto& h : m.hexes) {
      HexCorners before, after;
      for (std::size_t i = 0; i < 8; ++i) {
        before[i] = m.points[index_cast<std::size_t>(h[i])];
        after[i] = p[index_cast<std::size_t>(h[i])];
      }
      CHECK(hex_scaled_jacobian(after) >=
            BufferLayerOptions{}.min_hex_quality_ratio * hex_scaled_jacobian(before));
    }
  } else {
    for (const auto& h : m.hexes)
      for (Index v : h)
        CHECK(p[index_cast<std::size_t>(v)] == m.points[index_cast<std::size_t>(v)]);
  }

  double total = 0;
  for (const auto& h : m.hexes) total += hex_flux_volume(p, h);
  for (std::size_t b = 0; b < layer.hexes.size(); ++b) {
    const BufferHex& bh = layer.hexes[b];
    const InterfaceQuad& q = itf.quads[index_cast<std::size_t>(bh.quad)];
    CHECK(bh.quad == index_cast(b));
    for (std::size_t i = 0; i < 4; ++i) {
      CHECK(bh.corners[i] == q.corners[i]);  // hex side
      CHECK(bh.corners[i + 4] ==
            layer.top_node[index_cast<std::size_t>(q.corners[i])]);  // tet side
    }
    CHECK(bh.diagonal == (q.diagonal == 0 ? std::array<int, 2>{4, 6} : std::array<int, 2>{5, 7}));
    // The top triangles along the diagonal are faces of the two (renumbered) tets.
    const auto& k = bh.corners;
    const std::array<std::array<Index, 3>, 2> top =
        q.diagonal == 0
            ? std::array<std::array<Index, 3>, 2>{{{k[4], k[5], k[6]}, {k[4], k[6], k[7]}}}
            : std::array<std::array<Index, 3>, 2>{{{k[4], k[5], k[7]}, {k[5], k[6], k[7]}}};
    for (std::size_t i = 0; i < 2; ++i) {
      const auto& t = layer.model.tets[index_cast<std::size_t>(q.tets[i])];
      std::set<Index> face;
      for (int cc : topology::kTetFaceCorners[index_cast<std::size_t>(q.tet_faces[i])])
        face.insert(t[index_cast<std::size_t>(cc)]);
      CHECK(face == std::set<Index>(top[i].begin(), top[i].end()));
    }
    HexCorners corners;
    for (std::size_t i = 0; i < 8; ++i) corners[i] = p[index_cast<std::size_t>(k[i])];
    CHECK(hex_scaled_jacobian(corners) > 0.0);
    const double v = hex_flux_volume(p, k, q.diagonal);
    CHECK(v > 0.0);
    total += v;
  }
  for (const auto& t : layer.model.tets) {
    const double v = tet_volume(p[index_cast<std::size_t>(t[0])], p[index_cast<std::size_t>(t[1])],
                                p[index_cast<std::size_t>(t[2])], p[index_cast<std::size_t>(t[3])]);
    CHECK(v > 0.0);
    total += v;
  }
  CHECK(total == doctest::Approx(c.cells[0] * c.cells[1] * c.cells[2]).epsilon(1e-12));
  CHECK(layer.report.min_scaled_jacobian > 0.0);
  CHECK(layer.report.min_volume_ratio > 0.0);
}

}  // namespace

TEST_CASE("insert_buffer_layer: valid, gap-free layers on convex and concave interfaces") {
  const Case cases[] = {
      {"one hex, tets on one face", {1, 1, 2}, [](int, int, int k) { return k == 1; }, 1},
      {"half block (interface meets the outer boundary)",
       {2, 2, 2},
       [](int i, int, int) { return i == 1; },
       4},
      {"L-shaped interface (concave edge)",
       {2, 2, 1},
       [](int i, int j, int) { return i == 1 && j == 1; },
       2},
      {"tets around a hex edge (convex edge)",
       {2, 2, 1},
       [](int i, int j, int) { return i == 1 || j == 1; },
       2},
      {"tets around a hex corner (convex corner)",
       {2, 2, 2},
       [](int i, int j, int k) { return i == 1 || j == 1 || k == 1; },
       3},
      {"hex block around an L-shaped tet region",
       {4, 4, 3},
       [](int i, int j, int k) {
         return k == 1 && ((i == 1 && (j == 1 || j == 2)) || (i == 2 && j == 1));
       },
       14},
      {"enclosed tet nugget (hex block with a tet cavity)",
       {3, 3, 3},
       [](int i, int j, int k) { return i == 1 && j == 1 && k == 1; },
       6},
      {"one layer of hexes between two tet layers",
       {2, 2, 3},
       [](int, int, int k) { return k != 1; },
       8},
      {"one layer of tets between two hex layers",
       {2, 2, 3},
       [](int, int, int k) { return k == 1; },
       8},
      {"enclosed hex nugget (a hex inside tets)",
       {3, 3, 3},
       [](int i, int j, int k) { return !(i == 1 && j == 1 && k == 1); },
       6},
  };
  for (const BufferSide side : kSides)
    for (const Case& c : cases) check_layer(c, side);
}

TEST_CASE("insert_buffer_layer: one hex under tets, positions by hand") {
  const Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
  for (const BufferSide side : kSides) {
    CAPTURE(static_cast<int>(side));
    BufferLayerOptions o = on_side(side);
    o.thickness = 0.25;
    const BufferLayer layer = insert_buffer_layer(m, find_interface(m), o);
    // Each interface node sits on an outer crease of either part (two outer faces), so its
    // moving copy slides along the crease, by thickness 0.25 x shortest edge 1: the hex side's
    // down (-z) from the interface at z = 1, the tet side's up.
    for (const BufferHex& b : layer.hexes)
      for (std::size_t i = 0; i < 4; ++i) {
        const Point& bottom = layer.model.points[index_cast<std::size_t>(b.corners[i])];
        const Point& top = layer.model.points[index_cast<std::size_t>(b.corners[i + 4])];
        CHECK((top - bottom - Point(0, 0, 0.25)).norm() < 1e-14);
        CHECK((side == BufferSide::kHex ? top : bottom).z() == 1.0);
      }
    CHECK(layer.report.min_step == doctest::Approx(0.25));
    CHECK(layer.report.max_step == doctest::Approx(0.25));
    CHECK(layer.report.min_scaled_jacobian == doctest::Approx(1.0));
    CHECK(layer.report.halvings == 0);
    CHECK(buffer_hex_mesh(layer).hexes.size() == 1);
  }
}

TEST_CASE("insert_buffer_layer: the nugget's corners move along the cavity diagonal") {
  const Model m =
      grid_model({3, 3, 3}, 1.0, [](int i, int j, int k) { return i == 1 && j == 1 && k == 1; });
  // Corner (1,1,1) of the cavity: three faces with normals +x, +y, +z towards the tets; the
  // best direction is the diagonal, into the tets (tet side) or the hexes (hex side); the
  // shortest edge there is 1, so the height is the thickness (0.25: thicker, the hex touching
  // the cavity at that node alone would keep less than min_hex_quality_ratio of its scaled
  // Jacobian and the step be halved), and the mitred step puts the moving copy at that height
  // from each of the three faces.
  const Index v = 1 + 4 * (1 + 4 * 1);
  for (const BufferSide side : kSides) {
    CAPTURE(static_cast<int>(side));
    BufferLayerOptions o = on_side(side);
    o.thickness = 0.25;
    o.feature_thickness = 1.0;  // one height everywhere (the thinner corner: its own test below)
    const BufferLayer layer = insert_buffer_layer(m, find_interface(m), o);
    CHECK(layer.report.halvings == 0);
    const auto& p = layer.model.points;
    const Point& hex_copy = p[index_cast<std::size_t>(v)];
    const Point& tet_copy = p[index_cast<std::size_t>(layer.top_node[index_cast<std::size_t>(v)])];
    const double height = o.thickness;
    const Point moved = side == BufferSide::kHex ? Point(Point(1, 1, 1) - height * Point(1, 1, 1))
                                                 : Point(Point(1, 1, 1) + height * Point(1, 1, 1));
    CHECK(((side == BufferSide::kHex ? hex_copy : tet_copy) - moved).norm() < 1e-12);
    CHECK((side == BufferSide::kHex ? tet_copy : hex_copy) == Point(1, 1, 1));
  }
}

TEST_CASE(
    "insert_buffer_layer: buffer tops parallel to their bottoms at convex and concave edges and "
    "corners") {
  // Kuhn-split tets and unit hexes: the shortest edge is 1 at every interface node, so the
  // layer has one height, thickness x 1, and every buffer hex's moving corners lie that far
  // from the plane of its face on the part that stays (tet side: tops above the bottom quad;
  // hex side: bottoms below the top quad), also where two or three interface faces meet (a
  // step along the averaged normal alone would leave edge and corner copies at height / sqrt 2
  // or / sqrt 3, the faces tilted towards the edge and folded along their diagonals against the
  // neighbours'). Thickness 0.25 on both sides: the hexes touching the cavity at one corner
  // node keep 0.44 of their scaled Jacobian; thicker, they would fall below
  // min_hex_quality_ratio (0.4) and the layer be halved there.
  const Case cases[] = {
      {"tet cavity (convex edges and corners seen from the tets)",
       {4, 4, 4},
       [](int i, int j, int k) { return i >= 1 && i <= 2 && j >= 1 && j <= 2 && k >= 1 && k <= 2; },
       24},
      {"hex block inside tets (concave edges and corners seen from the tets)",
       {4, 4, 4},
       [](int i, int j, int k) {
         return !(i >= 1 && i <= 2 && j >= 1 && j <= 2 && k >= 1 && k <= 2);
       },
       24},
      {"L-shaped tet region in a hex block (a concave edge)",
       {4, 4, 3},
       [](int i, int j, int k) {
         return k == 1 && ((i == 1 && (j == 1 || j == 2)) || (i == 2 && j == 1));
       },
       14},
  };
  const double height = 0.25;
  for (const BufferSide side : kSides)
    for (const Case& c : cases) {
      CAPTURE(c.name);
      CAPTURE(static_cast<int>(side));
      const Model m = grid_model(c.cells, 1.0, c.is_tet);
      const Interface itf = find_interface(m);
      REQUIRE(itf.quads.size() == c.quads);
      BufferLayerOptions o = on_side(side);
      o.thickness = height;
      o.feature_thickness = 1.0;  // one height everywhere
      const BufferLayer layer = insert_buffer_layer(m, itf, o);
      CHECK(layer.report.halvings == 0);
      const auto& p = layer.model.points;
      for (const BufferHex& b : layer.hexes) {
        auto at = [&](int i) -> const Point& {
          return p[index_cast<std::size_t>(b.corners[index_cast<std::size_t>(i)])];
        };
        if (side == BufferSide::kTet) {
          const Point n = (at(1) - at(0)).cross(at(3) - at(0)).normalized();  // into the tet side
          for (int i = 4; i < 8; ++i)
            CHECK(n.dot(at(i) - at(0)) == doctest::Approx(height).epsilon(1e-12));
        } else {
          const Point n = (at(5) - at(4)).cross(at(7) - at(4)).normalized();  // into the tet side
          for (int i = 0; i < 4; ++i)
            CHECK(n.dot(at(4) - at(i)) == doctest::Approx(height).epsilon(1e-12));
        }
      }
      CHECK(layer.report.min_scaled_jacobian > 0.0);
    }
}

TEST_CASE("insert_buffer_layer: a thinner layer at corners where the moving part is convex only") {
  // A 2 x 2 x 2 hex block inside tets (hex side: the hexes are convex at the block's corners)
  // and the same cavity as tets inside hexes (hex side: concave there). The corner copies stand
  // feature_thickness x the height from each of their three faces where the moving part is
  // convex, the full height where it is concave.
  const double height = 0.25;
  for (const bool block : {true, false}) {
    CAPTURE(block);
    const Model m = grid_model({4, 4, 4}, 1.0, [block](int i, int j, int k) {
      const bool inside = i >= 1 && i <= 2 && j >= 1 && j <= 2 && k >= 1 && k <= 2;
      return block ? !inside : inside;
    });
    BufferLayerOptions o = on_side(BufferSide::kHex);
    o.thickness = height;
    const BufferLayer layer = insert_buffer_layer(m, find_interface(m), o);
    const auto& p = layer.model.points;
    int corners = 0;
    for (int x : {1, 3})
      for (int y : {1, 3})
        for (int z : {1, 3}) {
          const Index v = x + 5 * (y + 5 * z);
          const Point d = (p[index_cast<std::size_t>(layer.top_node[index_cast<std::size_t>(v)])] -
                           p[index_cast<std::size_t>(v)])
                              .cwiseAbs();
          const double expected = block ? o.feature_thickness * height : height;
          for (int a = 0; a < 3; ++a) CHECK(d[a] == doctest::Approx(expected).epsilon(1e-12));
          ++corners;
        }
    CHECK(corners == 8);
    CHECK(layer.report.min_scaled_jacobian > 0.0);
  }
}

TEST_CASE("insert_buffer_layer: one short tet edge does not twist the buffer tops around it") {
  // Tets above a 3 x 3 quad interface at z = 1; the tet node above interface node (1,1,1) is
  // lowered to z = 1.5, so the shortest edge there is 0.5 and thickness x shortest edge 0.15,
  // against 0.3 at every other node: the four buffer hexes at that node would have tops
  // twisted by 0.15 over edges of length 1. Graded, the node is raised towards its neighbours
  // and no two neighbours differ by more than smooth_rate x their edge; the tets stay positive.
  Model m = grid_model({3, 3, 2}, 1.0, [](int, int, int k) { return k == 1; });
  auto node = [](int i, int j, int k) { return index_cast<std::size_t>(i + 4 * (j + 4 * k)); };
  m.points[node(1, 1, 2)].z() = 1.5;
  const Interface itf = find_interface(m);
  REQUIRE(itf.quads.size() == 9);
  const BufferLayerOptions o = on_side(BufferSide::kTet);
  const BufferLayer layer = insert_buffer_layer(m, itf, o);
  auto height = [&](Index v) {
    return layer.model.points[index_cast<std::size_t>(layer.top_node[index_cast<std::size_t>(v)])]
               .z() -
           1.0;
  };
  CHECK(height(index_cast(node(1, 1, 1))) >
        default_buffer_thickness(BufferSide::kTet) * 0.5 + 0.05);
  for (const InterfaceQuad& q : itf.quads)
    for (std::size_t i = 0; i < 4; ++i)
      CHECK(std::abs(height(q.corners[i]) - height(q.corners[(i + 1) % 4])) <=
            o.smooth_rate * 1.0 + 1e-12);
  CHECK(layer.report.min_volume_ratio > 0.2);
  CHECK(layer.report.min_scaled_jacobian > 0.9);
}

TEST_CASE("insert_buffer_layer: no layer where no direction sees all interface faces") {
  // Simplified Figure 9 right: two tet cells of a 2x2x2 block meeting the centre node
  // (1,1,1) = node 13 from opposite octants, (1,0,0) and (0,1,1). The interface faces at node
  // 13 face +x, -y, -z (first cell) and -x, +y, +z (second): no direction is above all six.
  const Model m = grid_model({2, 2, 2}, 1.0, [](int i, int j, int k) {
    return (i == 1 && j == 0 && k == 0) || (i == 0 && j == 1 && k == 1);
  });
  const Interface itf = find_interface(m);
  CHECK(itf.quads.size() == 6);
  CHECK_THROWS_WITH_AS(insert_buffer_layer(m, itf),
                       doctest::Contains("node 14 (1, 1, 1): no direction"), TopologyError);
}

TEST_CASE("Gmsh demo models: conforming interface and a valid buffer layer") {
  SUBCASE("half block, structured hexes | transfinite tets") {
    const int n = 3;
    const Model m = demo::demo_half_block(n);
    CHECK(m.hexes.size() == index_cast<std::size_t>(n * n * n));
    CHECK(m.tets.size() == index_cast<std::size_t>(6 * n * n * n));
    CHECK(m.points.size() ==
          index_cast<std::size_t>((2 * n + 1) * (n + 1) * (n + 1)));  // interface merged
    const Interface itf = find_interface(m);
    CHECK(itf.quads.size() == index_cast<std::size_t>(n * n));
    CHECK(itf.nodes.size() == index_cast<std::size_t>((n + 1) * (n + 1)));
    for (const InterfaceQuad& q : itf.quads)
      for (Index v : q.corners)
        CHECK(m.points[index_cast<std::size_t>(v)].x() == doctest::Approx(1.0));
    const BufferLayer layer = insert_buffer_layer(m, itf);
    CHECK(layer.report.min_scaled_jacobian > 0.5);  // a flat interface: near-box buffer hexes
    for (const auto& t : layer.model.tets)
      CHECK(tet_volume(layer.model.points[index_cast<std::size_t>(t[0])],
                       layer.model.points[index_cast<std::size_t>(t[1])],
                       layer.model.points[index_cast<std::size_t>(t[2])],
                       layer.model.points[index_cast<std::size_t>(t[3])]) > 0);
  }
  SUBCASE("tet nugget inside sweepable hex blocks (Figure 8, simplified)") {
    const int n = 4;
    const Model m = demo::demo_nugget(n);
    // 26 blocks on a 4 x 4 x 4 structured grid of cells of size 0.5 minus the nugget's 4^3.
    CHECK(m.hexes.size() == index_cast<std::size_t>(8 * 8 * 8 - 4 * 4 * 4));
    CHECK(m.side_sets.at(0).sides.size() == index_cast<std::size_t>(6 * 8 * 8));
    const Interface itf = find_interface(m);
    CHECK(itf.quads.size() == index_cast<std::size_t>(6 * n * n));
    CHECK(itf.nodes.size() == index_cast<std::size_t>(6 * n * n + 2));  // closed surface: V = F + 2
    const BufferLayer layer = insert_buffer_layer(m, itf);
    CHECK(layer.report.min_scaled_jacobian > 0.0);
    CHECK(layer.report.min_volume_ratio > 0.0);
    MESSAGE("nugget demo: ", m.tets.size(), " tets, buffer min scaled Jacobian ",
            layer.report.min_scaled_jacobian, ", min volume ratio of the moved hexes ",
            layer.report.min_volume_ratio, ", halvings ", layer.report.halvings);
  }
}

TEST_CASE("insert_buffer_layer: a thickness beyond the side's bound is refused by name") {
  const Model m = grid_model({1, 1, 2}, 1.0, [](int, int, int k) { return k == 1; });
  const Interface itf = find_interface(m);
  for (const BufferSide side : kSides) {
    CAPTURE(static_cast<int>(side));
    BufferLayerOptions o = on_side(side);
    o.thickness = max_buffer_thickness(side);
    CHECK_NOTHROW(insert_buffer_layer(m, itf, o));
    o.thickness = max_buffer_thickness(side) + 0.01;
    const std::string words = std::string("from the ") + buffer_side_name(side) + " part";
    CHECK_THROWS_WITH_AS(insert_buffer_layer(m, itf, o), doctest::Contains(words.c_str()),
                         InvalidInput);
  }
  CHECK(parse_buffer_side("hex") == BufferSide::kHex);
  CHECK(parse_buffer_side("tet") == BufferSide::kTet);
  CHECK_THROWS_AS(parse_buffer_side("both"), InvalidInput);
}
