#include <geode/primal/isomorphism.hpp>

#include <algorithm>
#include <map>
#include <numeric>
#include <set>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {
namespace {

namespace topo = topology;

// All corner permutations p of a reference cell with N corners that send every edge to an
// edge. Filtering N! permutations is cheap for N <= 8 and obviously complete.
template <std::size_t N, std::size_t E>
std::vector<std::array<int, N>> edge_preserving_permutations(
    const std::array<std::array<int, 2>, E>& edges) {
  std::set<std::pair<int, int>> edge_set;
  for (const auto& e : edges) edge_set.insert({std::min(e[0], e[1]), std::max(e[0], e[1])});
  std::array<int, N> p{};
  std::iota(p.begin(), p.end(), 0);  // identity first: next_permutation starts from sorted
  std::vector<std::array<int, N>> out;
  do {
    const bool keeps = std::all_of(edges.begin(), edges.end(), [&](const auto& e) {
      return edge_set.count({std::min(p[e[0]], p[e[1]]), std::max(p[e[0]], p[e[1]])}) == 1;
    });
    if (keeps) out.push_back(p);
  } while (std::next_permutation(p.begin(), p.end()));
  return out;
}

// Reference-cell data for the generic search: facets (faces of a hex, edges of a quad) are
// what neighbouring cells share, edges give node degrees.
template <int N>
struct Kind;

template <>
struct Kind<8> : topo::CellTopology<3> {
  static const std::vector<std::array<int, 8>>& symmetries() { return hex_symmetries(); }
};

template <>
struct Kind<4> : topo::CellTopology<2> {
  static const std::vector<std::array<int, 4>>& symmetries() { return quad_symmetries(); }
};

template <int N>
using Cells = std::vector<std::array<Index, N>>;

// Incidence data of one mesh.
template <int N>
struct Complex {
  using K = Kind<N>;
  const Cells<N>* cells = nullptr;
  Index n_nodes = 0;
  std::vector<std::vector<Index>> node_cells;
  std::vector<std::array<Index, K::kFacets>> neighbor;  // cell across each facet, or -1
  std::vector<char> boundary;                           // node on a facet of one cell only
  std::vector<std::vector<Index>> node_neighbors;       // distinct nodes joined by an edge
};

template <int N>
Complex<N> build_complex(std::size_t n_nodes, const Cells<N>& cells, const char* which) {
  using K = Kind<N>;
  Complex<N> cx;
  cx.cells = &cells;
  cx.n_nodes = index_cast(n_nodes);
  cx.node_cells.resize(n_nodes);
  cx.node_neighbors.resize(n_nodes);
  cx.boundary.assign(n_nodes, 0);
  cx.neighbor.resize(cells.size());
  std::map<std::array<Index, K::kFacetSize>, std::vector<std::pair<Index, int>>> facets;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const auto& cell = cells[i];
    const std::string name = std::string(which) + " mesh, cell " + std::to_string(i);
    for (int c = 0; c < N; ++c) {
      if (cell[c] < 0 || cell[c] >= cx.n_nodes)
        throw InvalidInput(name + ": corner " + std::to_string(c) + " = " +
                           std::to_string(cell[c]) + " is not a node");
      for (int d = 0; d < c; ++d)
        if (cell[c] == cell[d])
          throw InvalidInput(name + ": node " + std::to_string(cell[c]) + " repeated");
      cx.node_cells[cell[c]].push_back(index_cast(i));
    }
    for (const auto& e : K::kEdgeTable) {
      cx.node_neighbors[cell[e[0]]].push_back(cell[e[1]]);
      cx.node_neighbors[cell[e[1]]].push_back(cell[e[0]]);
    }
    for (int f = 0; f < K::kFacets; ++f) {
      std::array<Index, K::kFacetSize> key{};
      for (int k = 0; k < K::kFacetSize; ++k) key[k] = cell[K::kFacetTable[f][k]];
      std::sort(key.begin(), key.end());
      facets[key].push_back({index_cast(i), f});
    }
    cx.neighbor[i].fill(-1);
  }
  for (const auto& [key, users] : facets) {
    if (users.size() > 2)
      throw TopologyError(std::string(which) + " mesh, cell " + std::to_string(users[0].first) +
                          ": a facet is shared by " + std::to_string(users.size()) + " cells");
    if (users.size() == 2) {
      cx.neighbor[users[0].first][users[0].second] = users[1].first;
      cx.neighbor[users[1].first][users[1].second] = users[0].first;
    } else {
      for (Index n : key) cx.boundary[n] = 1;
    }
  }
  for (auto& nb : cx.node_neighbors) {
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }
  return cx;
}

// Colour refinement run on both meshes with one shared dictionary, so that equal colours mean
// equal invariants across the meshes. Refinement only splits classes: stop when the number of
// classes stops growing.
template <int N>
std::pair<std::vector<int>, std::vector<int>> refine_colors(const Complex<N>& a,
                                                            const Complex<N>& b,
                                                            const NodeLabels& labels) {
  std::vector<std::vector<long>> keys_a(a.n_nodes), keys_b(b.n_nodes);
  auto initial = [&](const Complex<N>& cx, const std::vector<int>& lab, Index n) {
    return std::vector<long>{static_cast<long>(cx.node_cells[n].size()), cx.boundary[n],
                             static_cast<long>(cx.node_neighbors[n].size()),
                             lab.empty() ? 0L : static_cast<long>(lab[n])};
  };
  for (Index n = 0; n < a.n_nodes; ++n) keys_a[n] = initial(a, labels.first, n);
  for (Index n = 0; n < b.n_nodes; ++n) keys_b[n] = initial(b, labels.second, n);
  std::vector<int> ca(a.n_nodes), cb(b.n_nodes);
  std::size_t classes = 0;
  for (;;) {
    std::map<std::vector<long>, int> dict;
    for (auto* keys : {&keys_a, &keys_b})
      for (const auto& k : *keys) dict.emplace(k, 0);
    int next = 0;
    for (auto& [k, id] : dict) id = next++;
    for (Index n = 0; n < a.n_nodes; ++n) ca[n] = dict[keys_a[n]];
    for (Index n = 0; n < b.n_nodes; ++n) cb[n] = dict[keys_b[n]];
    if (dict.size() == classes) break;
    classes = dict.size();
    auto rekey = [](const Complex<N>& cx, const std::vector<int>& col,
                    std::vector<std::vector<long>>& keys) {
      for (Index n = 0; n < cx.n_nodes; ++n) {
        std::vector<long> k{col[n]};
        for (Index m : cx.node_neighbors[n]) k.push_back(col[m]);
        std::sort(k.begin() + 1, k.end());
        keys[n] = std::move(k);
      }
    };
    rekey(a, ca, keys_a);
    rekey(b, cb, keys_b);
  }
  return {ca, cb};
}

template <int N>
std::array<int, N> signature(const std::array<Index, N>& cell, const std::vector<int>& color) {
  std::array<int, N> s{};
  for (int c = 0; c < N; ++c) s[c] = color[cell[c]];
  std::sort(s.begin(), s.end());
  return s;
}

template <int N>
std::optional<MeshMapping> search(std::size_t na_nodes, const Cells<N>& a_cells,
                                  std::size_t nb_nodes, const Cells<N>& b_cells,
                                  const NodeLabels& labels) {
  using K = Kind<N>;
  if (!labels.first.empty() || !labels.second.empty()) {
    if (labels.first.size() != na_nodes || labels.second.size() != nb_nodes)
      throw InvalidInput("node labels: need one label per node of each mesh");
  }
  const Complex<N> a = build_complex<N>(na_nodes, a_cells, "first");
  const Complex<N> b = build_complex<N>(nb_nodes, b_cells, "second");
  if (na_nodes != nb_nodes || a_cells.size() != b_cells.size()) return std::nullopt;
  // Named members, not structured bindings: lambdas below capture them (clang 14 refuses
  // capturing a structured binding).
  const auto colors = refine_colors(a, b, labels);
  const auto& ca = colors.first;
  const auto& cb = colors.second;
  {
    auto ha = ca, hb = cb;
    std::sort(ha.begin(), ha.end());
    std::sort(hb.begin(), hb.end());
    if (ha != hb) return std::nullopt;
  }
  const Index n_cells = index_cast(a_cells.size());

  // Cells of b by signature (seed candidates); cells of a ordered breadth-first through
  // facets, each component seeded at the cell whose signature is rarest.
  std::map<std::array<int, N>, std::vector<Index>> b_by_sig;
  for (Index i = 0; i < n_cells; ++i) b_by_sig[signature<N>(b_cells[i], cb)].push_back(i);
  std::map<std::array<int, N>, Index> a_sig_count;
  for (Index i = 0; i < n_cells; ++i) ++a_sig_count[signature<N>(a_cells[i], ca)];
  std::vector<Index> by_rarity(n_cells);
  std::iota(by_rarity.begin(), by_rarity.end(), 0);
  std::stable_sort(by_rarity.begin(), by_rarity.end(), [&](Index x, Index y) {
    return a_sig_count[signature<N>(a_cells[x], ca)] < a_sig_count[signature<N>(a_cells[y], ca)];
  });
  std::vector<Index> order;                   // cells of a in search order
  std::vector<std::pair<Index, int>> parent;  // (parent cell, its facet) or (-1, -1)
  {
    std::vector<char> seen(n_cells, 0);
    for (Index seed : by_rarity) {
      if (seen[seed]) continue;
      seen[seed] = 1;
      std::size_t head = order.size();
      order.push_back(seed);
      parent.push_back({-1, -1});
      for (; head < order.size(); ++head) {
        const Index c = order[head];
        for (int f = 0; f < K::kFacets; ++f) {
          const Index nb = a.neighbor[c][f];
          if (nb < 0 || seen[nb]) continue;
          seen[nb] = 1;
          order.push_back(nb);
          parent.push_back({c, f});
        }
      }
    }
  }

  // Face-connected components must pair up: a seed may only go to a component of b with the
  // same size and cell signatures. This rejects e.g. one ring of hexes against two shorter
  // rings at once, which colour refinement cannot tell apart.
  auto components = [&](const Complex<N>& cx, const std::vector<int>& col) {
    std::vector<Index> comp(n_cells, -1);
    std::vector<std::vector<std::array<int, N>>> keys;
    for (Index s = 0; s < n_cells; ++s) {
      if (comp[s] >= 0) continue;
      const Index id = index_cast(keys.size());
      std::vector<Index> queue{s};
      comp[s] = id;
      for (std::size_t h = 0; h < queue.size(); ++h)
        for (Index nb : cx.neighbor[queue[h]])
          if (nb >= 0 && comp[nb] < 0) comp[nb] = id, queue.push_back(nb);
      std::vector<std::array<int, N>> key;
      for (Index c : queue) key.push_back(signature<N>((*cx.cells)[c], col));
      std::sort(key.begin(), key.end());
      keys.push_back(std::move(key));
    }
    return std::pair{comp, keys};
  };
  const auto components_a = components(a, ca);
  const auto components_b = components(b, cb);
  const auto& comp_a = components_a.first;
  const auto& keys_a = components_a.second;
  const auto& comp_b = components_b.first;
  const auto& keys_b = components_b.second;
  {
    auto ka = keys_a, kb = keys_b;
    std::sort(ka.begin(), ka.end());
    std::sort(kb.begin(), kb.end());
    if (ka != kb) return std::nullopt;
  }

  std::vector<Index> map(na_nodes, -1), inv(nb_nodes, -1);
  std::vector<Index> cell_map(n_cells, -1);
  std::vector<char> used(n_cells, 0);
  const auto& syms = K::symmetries();

  struct Frame {
    std::vector<Index> cands;
    std::size_t ci = 0, si = 0;  // next (candidate, symmetry) to try
    Index chosen = -1;
    std::vector<Index> assigned;  // nodes of a mapped by the current choice
  };
  auto candidates = [&](std::size_t pos) {
    std::vector<Index> out;
    const auto [pc, pf] = parent[pos];
    if (pc < 0) {
      auto it = b_by_sig.find(signature<N>(a_cells[order[pos]], ca));
      const auto& key = keys_a[comp_a[order[pos]]];
      if (it != b_by_sig.end())
        for (Index c : it->second)
          if (!used[c] && keys_b[comp_b[c]] == key) out.push_back(c);
      return out;
    }
    // The image of the shared facet is known: the candidate is the other b cell on it.
    std::array<Index, K::kFacetSize> img{};
    for (int k = 0; k < K::kFacetSize; ++k) img[k] = map[a_cells[pc][K::kFacetTable[pf][k]]];
    for (Index c : b.node_cells[img[0]]) {
      if (used[c]) continue;
      const auto& bc = b_cells[c];
      if (std::all_of(img.begin(), img.end(),
                      [&](Index n) { return std::find(bc.begin(), bc.end(), n) != bc.end(); }))
        out.push_back(c);
    }
    return out;
  };

  std::vector<Frame> frames(order.size());
  std::size_t pos = 0;
  if (!order.empty()) frames[0].cands = candidates(0);
  while (pos < order.size()) {
    Frame& fr = frames[pos];
    // Undo the previous choice at this level.
    if (fr.chosen >= 0) {
      for (Index n : fr.assigned) inv[map[n]] = -1, map[n] = -1;
      fr.assigned.clear();
      used[fr.chosen] = 0;
      cell_map[order[pos]] = -1;
      fr.chosen = -1;
    }
    const auto& ac = a_cells[order[pos]];
    bool placed = false;
    while (!placed && fr.ci < fr.cands.size()) {
      const auto& bc = b_cells[fr.cands[fr.ci]];
      while (fr.si < syms.size()) {
        const auto& s = syms[fr.si++];  // on backtracking, resume after this symmetry
        bool ok = true;
        for (int c = 0; c < N && ok; ++c) {
          const Index x = ac[c], y = bc[s[c]];
          ok = ca[x] == cb[y] && (map[x] >= 0 ? map[x] == y : inv[y] < 0);
        }
        if (!ok) continue;
        for (int c = 0; c < N; ++c) {
          const Index x = ac[c], y = bc[s[c]];
          if (map[x] < 0) map[x] = y, inv[y] = x, fr.assigned.push_back(x);
        }
        fr.chosen = fr.cands[fr.ci];
        used[fr.chosen] = 1;
        cell_map[order[pos]] = fr.chosen;
        placed = true;
        break;
      }
      if (!placed) ++fr.ci, fr.si = 0;
    }
    if (placed) {
      ++pos;
      if (pos < order.size()) frames[pos] = Frame{candidates(pos), 0, 0, -1, {}};
    } else {
      if (pos == 0) return std::nullopt;
      --pos;
    }
  }

  // Nodes in no cell: pair them up colour by colour (their colour carries the label).
  std::map<int, std::vector<Index>> free_b;
  for (Index y = 0; y < index_cast(nb_nodes); ++y)
    if (inv[y] < 0) free_b[cb[y]].push_back(y);
  for (Index x = 0; x < index_cast(na_nodes); ++x) {
    if (map[x] >= 0) continue;
    auto& pool = free_b[ca[x]];
    if (pool.empty()) return std::nullopt;
    map[x] = pool.back();
    inv[pool.back()] = x;
    pool.pop_back();
  }
  return MeshMapping{std::move(map), std::move(cell_map)};
}

template <int N>
bool check(std::size_t na_nodes, const Cells<N>& a_cells, std::size_t nb_nodes,
           const Cells<N>& b_cells, const MeshMapping& m, const NodeLabels& labels) {
  const auto& syms = Kind<N>::symmetries();
  if (na_nodes != nb_nodes || a_cells.size() != b_cells.size()) return false;
  if (m.node_map.size() != na_nodes || m.cell_map.size() != a_cells.size()) return false;
  auto is_bijection = [](const std::vector<Index>& f, std::size_t n) {
    std::vector<char> hit(n, 0);
    for (Index y : f) {
      if (y < 0 || index_cast<std::size_t>(y) >= n || hit[y]) return false;
      hit[y] = 1;
    }
    return true;
  };
  if (!is_bijection(m.node_map, nb_nodes) || !is_bijection(m.cell_map, b_cells.size()))
    return false;
  if (!labels.first.empty() || !labels.second.empty()) {
    if (labels.first.size() != na_nodes || labels.second.size() != nb_nodes) return false;
    for (std::size_t x = 0; x < na_nodes; ++x)
      if (labels.first[x] != labels.second[m.node_map[x]]) return false;
  }
  for (std::size_t i = 0; i < a_cells.size(); ++i) {
    const auto& ac = a_cells[i];
    const auto& bc = b_cells[m.cell_map[i]];
    const bool same = std::any_of(syms.begin(), syms.end(), [&](const auto& s) {
      for (int c = 0; c < N; ++c)
        if (m.node_map[ac[c]] != bc[s[c]]) return false;
      return true;
    });
    if (!same) return false;
  }
  return true;
}

}  // namespace

const std::vector<std::array<int, 8>>& hex_symmetries() {
  static const auto syms = edge_preserving_permutations<8>(topo::kHexEdgeCorners);
  return syms;
}

const std::vector<std::array<int, 4>>& quad_symmetries() {
  static const auto syms = edge_preserving_permutations<4>(topo::kQuadEdgeCorners);
  return syms;
}

bool is_rotation(const std::array<int, 8>& s) {
  // The frame at corner 0 must land on the frame at s[0] up to an even (cyclic) permutation.
  const auto& from = topo::kHexCornerNeighbors[0];
  const auto& to = topo::kHexCornerNeighbors[s[0]];
  for (int shift = 0; shift < 3; ++shift) {
    bool match = true;
    for (int k = 0; k < 3; ++k) match = match && s[from[k]] == to[(k + shift) % 3];
    if (match) return true;
  }
  return false;
}

std::optional<MeshMapping> find_isomorphism(const HexMesh& a, const HexMesh& b,
                                            const NodeLabels& labels) {
  return search<8>(a.points.size(), a.hexes, b.points.size(), b.hexes, labels);
}

std::optional<MeshMapping> find_isomorphism(const QuadMesh& a, const QuadMesh& b,
                                            const NodeLabels& labels) {
  return search<4>(a.points.size(), a.quads, b.points.size(), b.quads, labels);
}

bool is_isomorphism(const HexMesh& a, const HexMesh& b, const MeshMapping& m,
                    const NodeLabels& labels) {
  return check<8>(a.points.size(), a.hexes, b.points.size(), b.hexes, m, labels);
}

bool is_isomorphism(const QuadMesh& a, const QuadMesh& b, const MeshMapping& m,
                    const NodeLabels& labels) {
  return check<4>(a.points.size(), a.quads, b.points.size(), b.quads, m, labels);
}

}  // namespace geode::primal
