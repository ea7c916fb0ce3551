// The floor for `geode conform` (issue 27): the least any program must do to turn a hex + tet
// model into an all-hex mesh of the same resolution. It reads the binary .msh (geode's reader,
// io::read_gmsh), dices every hex into 8 and every tet into 4 hexes sharing the edge and face
// nodes of neighbouring cells, and writes the result as Exodus II with libexodus: no interface,
// no transition template, no smoothing, no verification, one thread. bench_conform_vs_gmsh runs
// it beside geode and gmsh on the same file; geode's time over this one is how far conform is
// from the floor.
//
// Edge and face nodes are found through per-node tables, not a hash map: an edge is listed at
// its smaller node with its other end, a face at its smallest node with its other nodes (sorted),
// and a node's list is searched linearly (a few dozen entries at most in a tet mesh). Each
// cell's 27 (hex) or 15 (tet) nodes are looked up once and its children read off a table.
//
// Usage: bench_floor model.msh out.exo   (prints the seconds of each stage and the counts)
#include <exodusII.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <geode/io/gmsh.hpp>
#include <geode/primal/detail/node_table.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/model.hpp>

namespace gp = geode::primal;
using gp::Index;
using gp::Point;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The unit cube's 3 x 3 x 3 grid (i + 3 j + 9 k, each in 0..2) against the hex's corners
// (VTK order): grid point g is made of the corners that agree with it on every axis where it is
// not 1 (1 corner: the corner, 2: an edge midpoint, 4: a face centre, 8: the centre).
struct HexTables {
  std::array<std::vector<int>, 27> corners_of;
  std::array<std::array<int, 8>, 8> child;  // child c (at corner c): its 8 grid points, VTK order
  HexTables() {
    constexpr std::array<std::array<int, 3>, 8> kAt{
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
    for (int g = 0; g < 27; ++g) {
      const std::array<int, 3> x{g % 3, (g / 3) % 3, g / 9};
      for (int c = 0; c < 8; ++c) {
        bool agrees = true;
        for (int a = 0; a < 3; ++a) agrees = agrees && (x[a] == 1 || x[a] == 2 * kAt[c][a]);
        if (agrees) corners_of[g].push_back(c);
      }
    }
    for (int c = 0; c < 8; ++c)
      for (int k = 0; k < 8; ++k) {
        std::array<int, 3> x{};
        for (int a = 0; a < 3; ++a) x[a] = kAt[c][a] + kAt[k][a];
        child[c][k] = x[0] + 3 * x[1] + 9 * x[2];
      }
  }
};

// A tet's 15 nodes: 0-3 corners, 4-9 edges, 10-13 faces, 14 the centre, each a set of corners;
// child c is the hex at corner c, its frame (c, a, b, d) an even permutation of (0, 1, 2, 3) so
// that it keeps the tet's orientation.
struct TetTables {
  std::array<std::vector<int>, 15> corners_of;
  std::array<std::array<int, 8>, 4> child;
  TetTables() {
    std::vector<std::vector<int>> sets;
    for (int c = 0; c < 4; ++c) sets.push_back({c});
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sets.push_back({a, b});
    for (int skip = 3; skip >= 0; --skip) {
      std::vector<int> f;
      for (int c = 0; c < 4; ++c)
        if (c != skip) f.push_back(c);
      sets.push_back(f);
    }
    sets.push_back({0, 1, 2, 3});
    for (int i = 0; i < 15; ++i) corners_of[i] = sets[i];
    auto id = [&](std::vector<int> s) {
      std::sort(s.begin(), s.end());
      return static_cast<int>(std::find(sets.begin(), sets.end(), s) - sets.begin());
    };
    constexpr std::array<std::array<int, 4>, 4> kFrame{
        {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}}};
    for (int c = 0; c < 4; ++c) {
      const auto [o, a, b, d] = kFrame[c];
      child[c] = {id({o}),    id({o, a}),    id({o, a, b}),    id({o, b}),
                  id({o, d}), id({o, a, d}), id({0, 1, 2, 3}), id({o, b, d})};
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_floor model.msh out.exo\n");
    return 2;
  }
  const auto t_read = Clock::now();
  gp::Model model;
  try {
    model = geode::io::read_gmsh(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_floor: %s\n", e.what());
    return 2;
  }
  const double read_s = since(t_read);

  const auto t_dice = Clock::now();
  const std::size_t V = model.points.size();
  // Room per node: every edge (face) use whose smallest node it is.
  std::vector<Index> edge_uses(V, 0), face_uses(V, 0);
  static const HexTables hex_t;
  static const TetTables tet_t;
  auto count = [&](const auto& cell, const auto& corners_of) {
    for (const auto& set : corners_of) {
      if (set.size() != 2 && set.size() != 3 && set.size() != 4) continue;
      if (set.size() == 4 && cell.size() == 4) continue;  // a tet's centre
      Index a = cell[set[0]];
      for (int c : set) a = std::min(a, cell[c]);
      ++(set.size() == 2 ? edge_uses : face_uses)[a];
    }
  };
  for (const auto& h : model.hexes) count(h, hex_t.corners_of);
  for (const auto& t : model.tets) count(t, tet_t.corners_of);
  gp::detail::NodeTable<1> edges(edge_uses);
  gp::detail::NodeTable<3> faces(face_uses);
  edge_uses = {}, face_uses = {};

  std::vector<Point> points = model.points;
  points.reserve(V * 8);
  std::vector<std::array<int, 8>> conn;  // 1-based, Exodus order (= VTK for HEX8)
  conn.reserve(8 * model.hexes.size() + 4 * model.tets.size());
  auto add = [&](const Point& p) {
    points.push_back(p);
    return geode::primal::index_cast(points.size() - 1);
  };
  // The node of a set of the cell's corners (1, 2, 3 or 4 corners; 8 or 4 for the centre).
  auto node_of = [&](const auto& cell, const std::vector<int>& set, bool centre) -> Index {
    if (set.size() == 1) return cell[set[0]];
    Point sum = Point::Zero();
    for (int c : set) sum += model.points[cell[c]];
    const Point at = sum / static_cast<double>(set.size());
    if (centre) return add(at);
    std::array<Index, 4> v{gp::kInvalidIndex, gp::kInvalidIndex, gp::kInvalidIndex,
                           gp::kInvalidIndex};
    for (std::size_t i = 0; i < set.size(); ++i) v[i] = cell[set[i]];
    std::sort(v.begin(), v.begin() + static_cast<long>(set.size()));
    if (set.size() == 2) return edges.find_or_add(v[0], {v[1]}, [&] { return add(at); });
    return faces.find_or_add(v[0], {v[1], v[2], set.size() == 4 ? v[3] : gp::kInvalidIndex},
                             [&] { return add(at); });
  };
  std::array<Index, 27> local{};
  for (const auto& h : model.hexes) {
    for (int g = 0; g < 27; ++g)
      local[g] = node_of(h, hex_t.corners_of[g], hex_t.corners_of[g].size() == 8);
    for (const auto& ch : hex_t.child) {
      std::array<int, 8>& c = conn.emplace_back();
      for (int k = 0; k < 8; ++k) c[k] = local[ch[k]] + 1;
    }
  }
  const std::size_t hex_children = conn.size();
  for (const auto& t : model.tets) {
    for (int g = 0; g < 15; ++g) local[g] = node_of(t, tet_t.corners_of[g], g == 14);
    for (const auto& ch : tet_t.child) {
      std::array<int, 8>& c = conn.emplace_back();
      for (int k = 0; k < 8; ++k) c[k] = local[ch[k]] + 1;
    }
  }
  edges = gp::detail::NodeTable<1>({}), faces = gp::detail::NodeTable<3>({});
  const double dice_s = since(t_dice);

  const auto t_write = Clock::now();
  int cpu = 8, io = 8;
  ex_opts(EX_VERBOSE);
  const int exo = ex_create(argv[2], EX_CLOBBER, &cpu, &io);
  if (exo < 0) {
    std::fprintf(stderr, "bench_floor: cannot create %s\n", argv[2]);
    return 2;
  }
  const std::size_t tet_children = conn.size() - hex_children;
  const int blocks = (hex_children ? 1 : 0) + (tet_children ? 1 : 0);
  std::size_t nodes = 0;
  bool ok = ex_put_init(exo, "floor", 3, geode::primal::index_cast<int64_t>(points.size()),
                        geode::primal::index_cast<int64_t>(conn.size()), blocks, 0, 0) >= 0;
  {
    std::vector<double> x(points.size()), y(points.size()), z(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      x[i] = points[i].x(), y[i] = points[i].y(), z[i] = points[i].z();
    nodes = points.size();
    points = {};
    ok = ok && ex_put_coord(exo, x.data(), y.data(), z.data()) >= 0;
  }
  int id = 0;
  for (const auto& [first, n] :
       {std::pair{std::size_t{0}, hex_children}, std::pair{hex_children, tet_children}}) {
    if (n == 0) continue;
    ++id;
    ok = ok &&
         ex_put_block(exo, EX_ELEM_BLOCK, id, "HEX8", static_cast<int64_t>(n), 8, 0, 0, 0) >= 0;
    ok = ok && ex_put_conn(exo, EX_ELEM_BLOCK, id, conn[first].data(), nullptr, nullptr) >= 0;
  }
  ok = ex_close(exo) >= 0 && ok;
  const double write_s = since(t_write);
  if (!ok) {
    std::fprintf(stderr, "bench_floor: writing %s failed\n", argv[2]);
    return 2;
  }
  std::printf(
      "floor: read %.3f s, dice %.3f s, write %.3f s; %zu hexes + %zu tets -> %zu hexes, %zu "
      "nodes\n",
      read_s, dice_s, write_s, model.hexes.size(), model.tets.size(), conn.size(), nodes);
  return 0;
}
