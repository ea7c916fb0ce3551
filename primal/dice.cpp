#include <geode/primal/dice.hpp>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstddef>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <geode/primal/detail/node_table.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace topo = topology;

namespace {

// A child corner is the centroid of a subset of its parent's corners (a bit mask over the
// parent's local corners): one corner, an edge, a face or the whole element.
using Support = unsigned;

template <std::size_t NChildren, std::size_t NCorners>
using ChildTable = std::array<std::array<Support, NCorners>, NChildren>;

// Hex (dim 3) or quad (dim 2) at parent corner c: child corner k sits at c + k on the doubled
// grid {0,1,2}^dim; its support is the parent corners that agree with it on every axis where
// it is not at 1 (the middle). Corner coordinates come from topology::kHexCornerCoords, whose
// first four entries are the quad's counter-clockwise corners.
template <int Dim>
ChildTable<(1u << Dim), (1u << Dim)> tensor_children() {
  constexpr int kN = 1 << Dim;
  ChildTable<kN, kN> t{};
  for (int c = 0; c < kN; ++c) {
    for (int k = 0; k < kN; ++k) {
      Support s = 0;
      for (int q = 0; q < kN; ++q) {
        bool agrees = true;
        for (int d = 0; d < Dim; ++d) {
          const int p = topo::kHexCornerCoords[c][d] + topo::kHexCornerCoords[k][d];
          if (p != 1 && topo::kHexCornerCoords[q][d] != p / 2) agrees = false;
        }
        if (agrees) s |= 1u << q;
      }
      t[c][k] = s;
    }
  }
  return t;
}

// Simplex (Dim + 1 corners) -> Dim-cube children. Child at corner i uses the other corners
// (a, b[, c]) in an order making (i, a, b[, c]) an even permutation of (0, 1, ...), so that
// the child's axes a - i, b - i[, c - i] have the parent's orientation. Child corner k with
// cube coordinates (r, s[, t]) is the centroid of {i} + {a if r} + {b if s} + {c if t}.
template <int Dim>
ChildTable<Dim + 1, (1u << Dim)> simplex_children() {
  constexpr int kN = Dim + 1;
  ChildTable<kN, (1u << Dim)> t{};
  for (int i = 0; i < kN; ++i) {
    std::array<int, kN> order{};
    order[0] = i;
    for (int j = 0, m = 1; j < kN; ++j) {
      if (j != i) order[m++] = j;
    }
    int inversions = 0;
    for (int x = 0; x < kN; ++x) {
      for (int y = x + 1; y < kN; ++y) inversions += order[x] > order[y];
    }
    if (inversions % 2) std::swap(order[kN - 2], order[kN - 1]);
    for (int k = 0; k < (1 << Dim); ++k) {
      Support s = 1u << i;
      for (int d = 0; d < Dim; ++d) {
        if (topo::kHexCornerCoords[k][d]) s |= 1u << order[d + 1];
      }
      t[i][k] = s;
    }
  }
  return t;
}

template <typename ChildArray>
struct Diced {
  std::vector<Point> points;
  std::vector<ChildArray> elements;
  std::vector<NodeOrigin> origin;
  std::vector<Index> parent;
};

// The dicing engine shared by the four element types, without points: the edge and face
// supports numbered, the children in dice()'s node numbers (V corners, E edges, F faces, C
// centres). `what` names the element kind in messages; `room`: dice_cells'.
template <std::size_t NP, std::size_t NChildren, std::size_t NC>
DicedCellsOf<NC> dice_topology(Index nv, const std::vector<std::array<Index, NP>>& elements,
                               const ChildTable<NChildren, NC>& table, const char* what,
                               std::size_t room = 0) {
  for (std::size_t e = 0; e < elements.size(); ++e) {
    for (std::size_t c = 0; c < NP; ++c) {
      const Index v = elements[e][c];
      if (v < 0 || v >= nv) {
        throw InvalidInput(std::string("dice: ") + what + " " + std::to_string(e) + " corner " +
                           std::to_string(c) + ": node " + std::to_string(v) +
                           " out of range [0, " + std::to_string(nv) + ")");
      }
    }
  }
  constexpr Support kAll = (1u << NP) - 1;

  // The distinct edge and face supports of one element, in order of first appearance over the
  // table (children in order, corners in order), and each child corner's slot among them.
  std::vector<Support> supports;
  std::array<std::array<int, NC>, NChildren> slot_of{};
  for (std::size_t ch = 0; ch < NChildren; ++ch)
    for (std::size_t k = 0; k < NC; ++k) {
      const Support s = table[ch][k];
      slot_of[ch][k] = -1;
      if (std::popcount(s) == 1 || s == kAll) continue;
      auto it = std::find(supports.begin(), supports.end(), s);
      slot_of[ch][k] = static_cast<int>(it - supports.begin());
      if (it == supports.end()) supports.push_back(s);
    }
  const std::size_t ns = supports.size();

  // Pass 1: number edges and faces in order of first appearance; remember each element's.
  // Edges and faces are numbered apart (their numbers are independent), side by side (TBB):
  // each pass reads every element, so one alone was the serial half of a conform run's dicing.
  DicedCellsOf<NC> out;
  // Per slot: an edge (true) or a face, and its position among the element's edges or faces.
  std::vector<char> is_edge(ns);
  std::vector<std::size_t> rank(ns);
  std::size_t n_edge = 0, n_face = 0;
  for (std::size_t i = 0; i < ns; ++i) {
    is_edge[i] = std::popcount(supports[i]) == 2;
    rank[i] = is_edge[i] ? n_edge++ : n_face++;
  }
  // Per element and edge (face) slot: its edge (face) id.
  std::vector<Index> edge_ids(elements.size() * n_edge), face_ids(elements.size() * n_face);
  // The keys of one kind numbered through a table of per-node lists (R: 1 for edges, 3 for
  // faces), into `keys` and `ids`.
  auto number = [&]<std::size_t R>(bool edges, std::vector<FaceKey>& keys, std::vector<Index>& ids,
                                   std::size_t per_element) {
    // Room in the per-node table: each use at its smallest node.
    std::vector<Index> uses(index_cast<std::size_t>(nv), 0);
    for (const auto& elem : elements)
      for (std::size_t i = 0; i < ns; ++i) {
        if (static_cast<bool>(is_edge[i]) != edges) continue;
        Index low = std::numeric_limits<Index>::max();
        for (std::size_t q = 0; q < NP; ++q)
          if (supports[i] & (1u << q)) low = std::min(low, elem[q]);
        ++uses[index_cast<std::size_t>(low)];
      }
    detail::NodeTable<R> table(uses);
    release(uses);
    // The lists an element `kAhead` further on will search, fetched while this one searches
    // (their slots are spread over the table as its nodes are over the mesh).
    constexpr std::size_t kAhead = 8;
    for (std::size_t e = 0; e < elements.size(); ++e) {
      if (e + kAhead < elements.size())
        for (Index v : elements[e + kAhead]) table.prefetch(v);
      for (std::size_t i = 0; i < ns; ++i) {
        if (static_cast<bool>(is_edge[i]) != edges) continue;
        std::array<Index, 4> nodes{};
        std::size_t n = 0;
        for (std::size_t q = 0; q < NP; ++q)
          if (supports[i] & (1u << q)) nodes[n++] = elements[e][q];
        const FaceKey k = n == 2
                              ? FaceKey{std::min(nodes[0], nodes[1]), std::max(nodes[0], nodes[1]),
                                        kInvalidIndex, kInvalidIndex}
                              : face_key(std::span<const Index>(nodes.data(), n));
        typename detail::NodeTable<R>::Rest rest;
        for (std::size_t r = 0; r < R; ++r) rest[r] = k[r + 1];
        ids[e * per_element + rank[i]] = table.find_or_add(k[0], rest, [&] {
          keys.push_back(k);
          return index_cast(keys.size() - 1);
        });
      }
    }
  };
  tbb::parallel_invoke([&] { number.template operator()<1>(true, out.edges, edge_ids, n_edge); },
                       [&] { number.template operator()<3>(false, out.faces, face_ids, n_face); });
  const auto ne = index_cast(out.edges.size());
  const auto nf = index_cast(out.faces.size());

  // Pass 2: children, elements in parallel (each writes its own). Per table entry its support's
  // size, read once (std::popcount is a library call on the baseline x86-64).
  std::array<std::array<int, NC>, NChildren> count_of{};
  for (std::size_t ch = 0; ch < NChildren; ++ch)
    for (std::size_t k = 0; k < NC; ++k) count_of[ch][k] = std::popcount(table[ch][k]);
  out.children.reserve(elements.size() * NChildren + room);
  out.children.resize(elements.size() * NChildren);
  out.parent.resize(elements.size() * NChildren);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, elements.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t e = r.begin(); e != r.end(); ++e) {
                        const auto& elem = elements[e];
                        for (std::size_t ch = 0; ch < NChildren; ++ch) {
                          std::array<Index, NC>& c = out.children[e * NChildren + ch];
                          for (std::size_t k = 0; k < NC; ++k) {
                            const Support s = table[ch][k];
                            const int count = count_of[ch][k];
                            if (count == 1) {
                              c[k] = elem[index_cast<std::size_t>(std::countr_zero(s))];
                            } else if (s == kAll) {
                              c[k] = nv + ne + nf + index_cast(e);
                            } else {
                              const std::size_t i = index_cast<std::size_t>(slot_of[ch][k]);
                              c[k] = count == 2 ? nv + edge_ids[e * n_edge + rank[i]]
                                                : nv + ne + face_ids[e * n_face + rank[i]];
                            }
                          }
                          out.parent[e * NChildren + ch] = index_cast(e);
                        }
                      }
                    });
  return out;
}

// dice_topology with the nodes placed: input points as they are, each edge, face and element
// node at the centroid of its origin (origin_centroid, corner_centroid).
template <std::size_t NP, std::size_t NChildren, std::size_t NC>
Diced<std::array<Index, NC>> dice_elements(const std::vector<Point>& points,
                                           const std::vector<std::array<Index, NP>>& elements,
                                           const ChildTable<NChildren, NC>& table,
                                           const char* what) {
  const auto nv = index_cast(points.size());
  DicedCellsOf<NC> cells = dice_topology(nv, elements, table, what);
  Diced<std::array<Index, NC>> out;
  const std::size_t total =
      points.size() + cells.edges.size() + cells.faces.size() + elements.size();
  out.points.reserve(total);
  out.origin.reserve(total);
  out.points = points;
  out.origin.resize(points.size());
  for (Index v = 0; v < nv; ++v) out.origin[v].nodes[0] = v;
  for (const auto& k : cells.edges) {
    out.points.push_back(origin_centroid(points, k));
    out.origin.push_back(NodeOrigin{NodeOriginKind::kEdge, k, kInvalidIndex});
  }
  for (const auto& k : cells.faces) {
    out.points.push_back(origin_centroid(points, k));
    out.origin.push_back(NodeOrigin{NodeOriginKind::kFace, k, kInvalidIndex});
  }
  for (std::size_t e = 0; e < elements.size(); ++e) {
    out.points.push_back(corner_centroid(points, elements[e]));
    NodeOrigin o;
    o.kind = NodeOriginKind::kCell;
    o.element = index_cast(e);
    out.origin.push_back(o);
  }
  out.elements = std::move(cells.children);
  out.parent = std::move(cells.parent);
  return out;
}

template <typename Result, typename Diced>
Result finish(Diced&& d, const std::vector<int>& block) {
  Result r;
  r.origin = std::move(d.origin);
  r.parent = std::move(d.parent);
  r.mesh.points = std::move(d.points);
  if constexpr (std::is_same_v<Result, DicedHexMesh>) {
    r.mesh.hexes = std::move(d.elements);
    if (!block.empty()) {
      for (Index p : r.parent) r.mesh.block.push_back(block.at(index_cast<std::size_t>(p)));
    }
  } else {
    r.mesh.quads = std::move(d.elements);
  }
  return r;
}

void check_block(std::size_t block, std::size_t elements, const char* what) {
  if (block != 0 && block != elements) {
    throw InvalidInput(std::string("dice: ") + what + " mesh has " + std::to_string(elements) +
                       " elements but " + std::to_string(block) + " block tags");
  }
}

}  // namespace

const DicingTable8& hex_dicing_table() {
  static const DicingTable8 table = tensor_children<3>();
  return table;
}

const DicingTable4& tet_dicing_table() {
  static const DicingTable4 table = simplex_children<3>();
  return table;
}

Point corner_centroid(std::span<const Point> points, std::span<const Index> corners) {
  Point p = Point::Zero();
  for (Index v : corners) p += points[index_cast<std::size_t>(v)];
  return p / static_cast<double>(corners.size());
}

Point origin_centroid(std::span<const Point> points, const FaceKey& key) {
  const auto n = std::find(key.begin(), key.end(), kInvalidIndex) - key.begin();
  return corner_centroid(points, std::span<const Index>(key.data(), index_cast<std::size_t>(n)));
}

DicedCells dice_cells(Index nodes, const std::vector<std::array<Index, 8>>& hexes,
                      std::size_t room) {
  return dice_topology(nodes, hexes, hex_dicing_table(), "hex", room);
}

DicedCells dice_cells(Index nodes, const std::vector<std::array<Index, 4>>& tets,
                      std::size_t room) {
  return dice_topology(nodes, tets, tet_dicing_table(), "tet", room);
}

DicedHexMesh dice(const HexMesh& mesh) {
  check_block(mesh.block.size(), mesh.hexes.size(), "hex");
  return finish<DicedHexMesh>(dice_elements(mesh.points, mesh.hexes, hex_dicing_table(), "hex"),
                              mesh.block);
}

DicedHexMesh dice(const TetMesh& mesh) {
  check_block(mesh.block.size(), mesh.tets.size(), "tet");
  return finish<DicedHexMesh>(dice_elements(mesh.points, mesh.tets, tet_dicing_table(), "tet"),
                              mesh.block);
}

DicedQuadMesh dice(const QuadMesh& mesh) {
  static const auto table = tensor_children<2>();
  return finish<DicedQuadMesh>(dice_elements(mesh.points, mesh.quads, table, "quad"), {});
}

DicedQuadMesh dice(const TriMesh& mesh) {
  static const auto table = simplex_children<2>();
  return finish<DicedQuadMesh>(dice_elements(mesh.points, mesh.tris, table, "triangle"), {});
}

namespace {

// Each child corner of a diced reference element as the element corners it averages, read
// off dice() itself so that this follows the dicing's node placement and corner order.
template <class Mesh, std::size_t N>
std::vector<std::array<std::vector<int>, 8>> child_weights() {
  Mesh ref;
  std::array<Index, N> cell{};
  for (std::size_t i = 0; i < N; ++i) ref.points.push_back(Point::Zero()), cell[i] = index_cast(i);
  if constexpr (N == 4)
    ref.tets.push_back(cell);
  else
    ref.hexes.push_back(cell);
  const DicedHexMesh d = dice(ref);
  std::vector<std::array<std::vector<int>, 8>> children;
  for (const auto& h : d.mesh.hexes) {
    std::array<std::vector<int>, 8> w;
    for (int c = 0; c < 8; ++c) {
      const NodeOrigin& o = d.origin[index_cast<std::size_t>(h[c])];
      if (o.kind == NodeOriginKind::kCell) {
        for (std::size_t i = 0; i < N; ++i) w[c].push_back(static_cast<int>(i));
      } else {
        for (Index v : o.nodes)
          if (v != kInvalidIndex) w[c].push_back(static_cast<int>(v));
      }
    }
    children.push_back(w);
  }
  return children;
}

// The children's corners of a diced reference element as its distinct corner subsets (15 for a
// tet: its corners, edges, faces and centre; 27 for a hex), each child corner naming one: a
// cell's child corners are then placed once each, not once per child using them (a tet's 32
// child corners, a hex's 64).
struct ChildCorners {
  std::vector<std::vector<int>> subset;  // distinct, as child_weights lists them
  std::vector<std::array<int, 8>> child;
};

template <class Mesh, std::size_t N>
ChildCorners child_corners() {
  ChildCorners t;
  for (const auto& w : child_weights<Mesh, N>()) {
    std::array<int, 8> at{};
    for (int c = 0; c < 8; ++c) {
      std::vector<int> key = w[c];
      std::sort(key.begin(), key.end());
      auto it = std::find_if(t.subset.begin(), t.subset.end(), [&](const std::vector<int>& s) {
        std::vector<int> k = s;
        std::sort(k.begin(), k.end());
        return k == key;
      });
      if (it == t.subset.end()) it = t.subset.insert(t.subset.end(), w[c]);
      at[c] = static_cast<int>(it - t.subset.begin());
    }
    t.child.push_back(at);
  }
  return t;
}

// The lowest scaled Jacobian among one cell's children, each corner placed as dice() places
// it: the centroid of its edge's or face's nodes in ascending order (origin_centroid's key),
// of the cell's corners in their order. So the figure is, bit for bit, the minimum over the
// children a dicing of the same points and numbers makes (conform reads it off them).
template <std::size_t N>
double diced_cell_min(std::span<const Point> points, const std::array<Index, N>& cell,
                      const ChildCorners& table) {
  std::array<Point, 27> place;
  for (std::size_t s = 0; s < table.subset.size(); ++s) {
    const std::vector<int>& w = table.subset[s];
    std::array<Index, N> nodes{};
    const std::size_t n = w.size();
    for (std::size_t i = 0; i < n; ++i) nodes[i] = cell[index_cast<std::size_t>(w[i])];
    if (n < N) std::sort(nodes.begin(), nodes.begin() + static_cast<std::ptrdiff_t>(n));
    place[s] = corner_centroid(points, std::span<const Index>(nodes.data(), n));
  }
  double lowest = 1.0;
  for (const auto& at : table.child) {
    HexCorners p;
    for (int c = 0; c < 8; ++c) p[c] = place[index_cast<std::size_t>(at[c])];
    lowest = std::min(lowest, hex_scaled_jacobian(p));
  }
  return lowest;
}

// Cells in parallel (TBB): a minimum does not depend on the order it is taken in.
template <class Mesh, std::size_t N>
double diced_min(std::span<const Point> points, std::span<const std::array<Index, N>> cells) {
  static const auto children = child_corners<Mesh, N>();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, cells.size(), 4096), 1.0,
      [&](const tbb::blocked_range<std::size_t>& range, double lowest) {
        for (std::size_t k = range.begin(); k != range.end(); ++k)
          lowest = std::min(lowest, diced_cell_min(points, cells[k], children));
        return lowest;
      },
      [](double a, double b) { return std::min(a, b); });
}

// Per cell, in parallel.
template <class Mesh, std::size_t N>
std::vector<double> diced_each(std::span<const Point> points,
                               std::span<const std::array<Index, N>> cells) {
  static const auto children = child_corners<Mesh, N>();
  std::vector<double> out(cells.size(), 1.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k)
                        out[k] = diced_cell_min(points, cells[k], children);
                    });
  return out;
}

}  // namespace

std::vector<double> diced_scaled_jacobian_per_cell(std::span<const Point> points,
                                                   std::span<const std::array<Index, 4>> tets) {
  return diced_each<TetMesh, 4>(points, tets);
}

std::vector<double> diced_scaled_jacobian_per_cell(std::span<const Point> points,
                                                   std::span<const std::array<Index, 8>> hexes) {
  return diced_each<HexMesh, 8>(points, hexes);
}

// The same children as weights on the four corners (a corner, an edge's midpoint, a face's or
// the tet's centre), for a caller that evaluates one tet many times (relax_tet_nodes): each
// distinct child corner (4 corners, 6 edges, 4 faces, the centre) computed once per call.
double diced_tet_min_scaled_jacobian(const std::array<Point, 4>& corners) {
  int first = 0;
  return diced_tet_min_scaled_jacobian(corners, -2.0, &first);
}

double diced_tet_min_scaled_jacobian(const std::array<Point, 4>& corners, double bound,
                                     int* first) {
  constexpr std::size_t kDistinct = 15;  // 4 corners, 6 edges, 4 faces, the centre
  struct Table {
    std::vector<std::array<double, 4>> weights;      // per distinct child corner
    std::array<std::array<std::size_t, 8>, 4> at{};  // child, corner -> its weights
  };
  static const Table table = [] {
    Table t;
    const auto children = child_weights<TetMesh, 4>();
    for (std::size_t h = 0; h < 4; ++h)
      for (std::size_t c = 0; c < 8; ++c) {
        std::array<double, 4> w{};
        for (int i : children[h][c])
          w[index_cast<std::size_t>(i)] = 1.0 / static_cast<double>(children[h][c].size());
        auto it = std::find(t.weights.begin(), t.weights.end(), w);
        t.at[h][c] = static_cast<std::size_t>(it - t.weights.begin());
        if (it == t.weights.end()) t.weights.push_back(w);
      }
    assert(t.weights.size() == kDistinct);
    return t;
  }();
  std::array<Point, kDistinct> x;
  for (std::size_t k = 0; k < kDistinct; ++k) {
    const auto& w = table.weights[k];
    x[k] = w[0] * corners[0] + w[1] * corners[1] + w[2] * corners[2] + w[3] * corners[3];
  }
  // The minimum does not depend on the children's order (the value below the bound is any).
  double lowest = 1.0;
  const int from = *first;
  for (int j = 0; j < 4 && lowest > bound; ++j) {
    const int h = (from + j) % 4;
    const auto& child = table.at[index_cast<std::size_t>(h)];
    HexCorners p;
    for (std::size_t c = 0; c < 8; ++c) p[c] = x[child[c]];
    lowest = std::min(lowest, hex_scaled_jacobian_bounded(p, bound));
    if (lowest <= bound) *first = h;
  }
  return lowest;
}

double diced_min_scaled_jacobian(std::span<const Point> points,
                                 std::span<const std::array<Index, 4>> tets) {
  return diced_min<TetMesh, 4>(points, tets);
}

double diced_min_scaled_jacobian(std::span<const Point> points,
                                 std::span<const std::array<Index, 8>> hexes) {
  return diced_min<HexMesh, 8>(points, hexes);
}

}  // namespace geode::primal
