#include <geode/stc/mesh_dual.hpp>

#include <geode/primal/disjoint_sets.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>

#include <geode/primal/errors.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/topology.hpp>

namespace geode::stc {
namespace {

using primal::Index;
namespace topo = primal::topology;

// Reference-cell tables per dimension (primal/topology.hpp).
template <int Dim>
using Ref = topo::CellTopology<Dim>;

// Local hex edge joining two corners, from the edge table; -1 when they are not joined.
int local_hex_edge(int a, int b) {
  for (int e = 0; e < topo::kHexEdges; ++e) {
    const auto& ec = topo::kHexEdgeCorners[e];
    if ((ec[0] == a && ec[1] == b) || (ec[0] == b && ec[1] == a)) return e;
  }
  return -1;
}

// 3D traces: every boundary quad links, for each of its two pairs of opposite edges, the two
// edges of that pair (they belong to one sheet: a face's opposite edges are parallel in its
// hex). On a closed 2-manifold boundary each boundary edge has exactly two links, so the links
// of one sheet form disjoint loops: walk them.
void build_traces(const std::vector<std::array<Index, 8>>&, MeshDual<3>& dual) {
  struct Link {
    Index a, b;
    CellFacet facet;
  };
  std::vector<Link> links;
  for (const CellFacet& f : dual.boundary) {
    const auto& fc = topo::kHexFaceCorners[f.local];
    std::array<Index, 4> side{};  // global edges of the face's sides (c0c1, c1c2, c2c3, c3c0)
    for (int k = 0; k < 4; ++k) {
      const int e = local_hex_edge(fc[k], fc[(k + 1) % 4]);
      assert(e >= 0);
      side[k] = dual.cell_edges[f.cell][e];
    }
    links.push_back({side[0], side[2], f});
    links.push_back({side[1], side[3], f});
  }
  std::vector<std::vector<Index>> at(dual.edges.size());  // links at each edge
  for (std::size_t l = 0; l < links.size(); ++l) {
    at[links[l].a].push_back(primal::index_cast(l));
    at[links[l].b].push_back(primal::index_cast(l));
  }
  for (std::size_t e = 0; e < at.size(); ++e) {
    if (!at[e].empty() && at[e].size() != 2) {
      throw TopologyError("edge " + std::to_string(dual.edges[e][0]) + "-" +
                          std::to_string(dual.edges[e][1]) + " lies on " +
                          std::to_string(at[e].size()) +
                          " boundary quads, not 2: the boundary is not a closed 2-manifold");
    }
  }
  std::vector<char> used(links.size(), 0);
  for (MeshSheet& sheet : dual.sheets) {
    for (Index start : sheet.edges) {
      if (at[start].empty() || used[at[start][0]]) continue;
      TraceCurve curve;
      curve.closed = true;
      Index cur = start;
      for (;;) {
        Index next_link = -1;
        for (Index l : at[cur])
          if (!used[l]) next_link = l;
        if (next_link < 0) break;  // back at the start: both links of `start` are used
        used[next_link] = 1;
        const Link& lk = links[next_link];
        curve.edges.push_back(cur);
        curve.facets.push_back(lk.facet);
        cur = lk.a == cur ? lk.b : lk.a;
      }
      assert(cur == start);
      sheet.trace.push_back(std::move(curve));
    }
  }
}

void build_traces(const std::vector<std::array<Index, 4>>&, MeshDual<2>& dual) {
  // A chord ends where it crosses a boundary edge; the boundary facet is that edge.
  for (const CellFacet& f : dual.boundary) {
    const Index e = dual.cell_edges[f.cell][f.local];
    dual.sheets[dual.edge_sheet[e]].trace.push_back(TraceCurve{{e}, {f}, false});
  }
}

// MeshDualOptions::progress over build()'s kMeshDualPasses passes over the cells: at(c) in
// each pass (told every kEvery cells), next() between passes, end() once all is done.
class PassProgress {
 public:
  PassProgress(const MeshDualOptions& options, std::size_t cells)
      : f_(options.progress), cells_(cells) {}
  void at(Index c) const {
    const auto i = primal::index_cast<std::size_t>(c);
    if (f_ && i % kEvery == 0) f_(pass_ * cells_ + i, kMeshDualPasses * cells_);
  }
  void next() { ++pass_; }
  void end() const {
    if (f_) f_(kMeshDualPasses * cells_, kMeshDualPasses * cells_);
  }

 private:
  static constexpr std::size_t kEvery = 1 << 14;
  const std::function<void(std::size_t, std::size_t)>& f_;
  std::size_t cells_, pass_ = 0;
};

template <int Dim>
MeshDual<Dim> build(std::size_t n_nodes,
                    const std::vector<std::array<Index, Ref<Dim>::kCorners>>& cells,
                    const MeshDualOptions& options) {
  using R = Ref<Dim>;
  MeshDual<Dim> dual;
  const Index n_cells = primal::index_cast(cells.size());
  PassProgress progress(options, cells.size());

  // Validate the cells and number the edges in the order they first appear. The occurrences
  // (slots c * kEdges + e) are bucketed by their lower node (a counting sort) and each node's
  // few sorted by the upper one, so that an edge's occurrences are one run: a hash map of the
  // edges took a third of a large mesh's dual, and a sort of all the occurrences half of that.
  constexpr std::size_t kEdges = MeshDual<Dim>::kCellEdges;
  const auto ends = [&cells](std::size_t slot) {
    const auto& cell = cells[slot / kEdges];
    const auto& corners = R::kEdgeTable[slot % kEdges];
    const Index a = cell[corners[0]], b = cell[corners[1]];
    return a < b ? std::array<Index, 2>{a, b} : std::array<Index, 2>{b, a};
  };
  std::vector<std::size_t> start(n_nodes + 1, 0);  // the buckets' bounds in by_lower
  for (Index c = 0; c < n_cells; ++c) {
    progress.at(c);
    const auto& cell = cells[c];
    // Made for an error only, not for each of millions of cells.
    const auto name = [c] { return std::string(R::kCellName) + " " + std::to_string(c); };
    for (int k = 0; k < R::kCorners; ++k) {
      if (cell[k] < 0 || primal::index_cast<std::size_t>(cell[k]) >= n_nodes)
        throw InvalidInput(name() + ": corner " + std::to_string(k) + " = " +
                           std::to_string(cell[k]) + " is not a node (mesh has " +
                           std::to_string(n_nodes) + ")");
      for (int j = 0; j < k; ++j)
        if (cell[j] == cell[k])
          throw InvalidInput(name() + ": node " + std::to_string(cell[k]) + " is corner " +
                             std::to_string(j) + " and " + std::to_string(k));
    }
    for (std::size_t e = 0; e < kEdges; ++e) {
      const Index lower = ends(primal::index_cast<std::size_t>(c) * kEdges + e)[0];
      ++start[primal::index_cast<std::size_t>(lower) + 1];
    }
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  const std::size_t n_slots = cells.size() * kEdges;
  std::vector<std::size_t> by_lower(n_slots);
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (std::size_t slot = 0; slot < n_slots; ++slot)
      by_lower[next[primal::index_cast<std::size_t>(ends(slot)[0])]++] = slot;
  }
  // Each run an edge, numbered for now in bucket order (run_of: per slot), then renumbered in
  // the order of first appearance.
  std::vector<Index> run_of(n_slots);
  std::vector<std::array<Index, 2>> run_edge;
  for (std::size_t v = 0; v < n_nodes; ++v) {
    const auto first = by_lower.begin() + static_cast<std::ptrdiff_t>(start[v]),
               last = by_lower.begin() + static_cast<std::ptrdiff_t>(start[v + 1]);
    std::sort(first, last, [&ends](std::size_t x, std::size_t y) {
      return std::pair(ends(x)[1], x) < std::pair(ends(y)[1], y);
    });
    for (auto it = first; it != last; ++it) {
      const auto edge = ends(*it);
      if (it == first || ends(*(it - 1))[1] != edge[1]) run_edge.push_back(edge);
      run_of[*it] = primal::index_cast(run_edge.size() - 1);
    }
  }
  primal::release(by_lower, start);
  dual.cell_edges.resize(n_cells);
  dual.edges.reserve(run_edge.size());
  std::vector<Index> id_of_run(run_edge.size(), -1);
  for (std::size_t slot = 0; slot < n_slots; ++slot) {
    Index& id = id_of_run[primal::index_cast<std::size_t>(run_of[slot])];
    if (id < 0) {
      id = primal::index_cast(dual.edges.size());
      dual.edges.push_back(run_edge[primal::index_cast<std::size_t>(run_of[slot])]);
    }
    dual.cell_edges[slot / kEdges][slot % kEdges] = id;
  }
  // Freed before the progress says done: freeing takes a while.
  primal::release(run_of, run_edge, id_of_run);

  // Sheets: within a cell the edges of one class are equivalent.
  progress.next();
  primal::DisjointSets uf(dual.edges.size());
  for (Index c = 0; c < n_cells; ++c) {
    progress.at(c);
    const auto& ce = dual.cell_edges[c];
    for (int e = 0; e < MeshDual<Dim>::kCellEdges; ++e)
      for (int f = e + 1; f < MeshDual<Dim>::kCellEdges; ++f)
        if (R::edge_class(e) == R::edge_class(f)) uf.unite(ce[e], ce[f]);
  }
  progress.next();
  std::vector<Index> sheet_of_root(dual.edges.size(), -1);
  dual.cell_sheets.resize(n_cells);
  for (Index c = 0; c < n_cells; ++c) {
    progress.at(c);
    for (int e = 0; e < MeshDual<Dim>::kCellEdges; ++e) {
      Index& s = sheet_of_root[uf.find(dual.cell_edges[c][e])];
      if (s < 0) {
        s = primal::index_cast(dual.sheets.size());
        dual.sheets.emplace_back();
      }
      dual.cell_sheets[c][R::edge_class(e)] = s;
    }
  }
  dual.edge_sheet.resize(dual.edges.size());
  for (std::size_t e = 0; e < dual.edges.size(); ++e) {
    dual.edge_sheet[e] = sheet_of_root[uf.find(primal::index_cast(e))];
    dual.sheets[dual.edge_sheet[e]].edges.push_back(primal::index_cast(e));
  }
  progress.next();
  // The intersections counted in a sorted list and put in the map in order (a map lookup per
  // cell was a fifth of a large mesh's dual).
  std::vector<std::array<Index, Dim>> tuples(cells.size());
  for (Index c = 0; c < n_cells; ++c) {
    progress.at(c);
    auto& tuple = tuples[primal::index_cast<std::size_t>(c)] = dual.cell_sheets[c];
    for (Index s : tuple) dual.sheets[s].cells.push_back(c);
    std::sort(tuple.begin(), tuple.end());
    for (int k = 1; k < Dim; ++k)
      if (tuple[k] == tuple[k - 1]) dual.sheets[tuple[k]].self_intersecting = true;
  }
  std::sort(tuples.begin(), tuples.end());
  for (std::size_t i = 0, j = 0; i < tuples.size(); i = j) {
    for (j = i + 1; j < tuples.size() && tuples[j] == tuples[i]; ++j) {}
    dual.intersections.emplace_hint(dual.intersections.end(), tuples[i], primal::index_cast(j - i));
  }
  primal::release(tuples);

  // Boundary facets: used by one cell only. Every facet with its sorted nodes, bucketed by its
  // lowest node (a counting sort) and each bucket sorted: a facet's users are one run (a hash
  // map of facet lists was half of a large mesh's dual, a sort of all the facets a sixth).
  progress.next();
  struct Facet {
    std::array<Index, R::kFacetSize> key;
    CellFacet at;
  };
  const auto facet = [&cells](Index c, int f) {
    Facet x;
    for (int k = 0; k < R::kFacetSize; ++k) x.key[k] = cells[c][R::kFacetTable[f][k]];
    std::sort(x.key.begin(), x.key.end());
    x.at = {c, f};
    return x;
  };
  std::vector<std::size_t> first_of(n_nodes + 1, 0);
  for (Index c = 0; c < n_cells; ++c)
    for (int f = 0; f < R::kFacets; ++f) {
      Index lowest = cells[c][R::kFacetTable[f][0]];  // the bucket: no need of the sorted key
      for (int k = 1; k < R::kFacetSize; ++k)
        lowest = std::min(lowest, cells[c][R::kFacetTable[f][k]]);
      ++first_of[primal::index_cast<std::size_t>(lowest) + 1];
    }
  std::partial_sum(first_of.begin(), first_of.end(), first_of.begin());
  std::vector<Facet> facets(cells.size() * R::kFacets);
  {
    std::vector<std::size_t> next(first_of.begin(), first_of.end() - 1);
    for (Index c = 0; c < n_cells; ++c) {
      progress.at(c);
      for (int f = 0; f < R::kFacets; ++f) {
        const Facet x = facet(c, f);
        facets[next[primal::index_cast<std::size_t>(x.key[0])]++] = x;
      }
    }
  }
  for (std::size_t v = 0; v < n_nodes; ++v)
    std::sort(facets.begin() + static_cast<std::ptrdiff_t>(first_of[v]),
              facets.begin() + static_cast<std::ptrdiff_t>(first_of[v + 1]),
              [](const Facet& a, const Facet& b) {
                return std::tie(a.key, a.at.cell, a.at.local) <
                       std::tie(b.key, b.at.cell, b.at.local);
              });
  primal::release(first_of);
  progress.next();
  // A facet on more than two cells: the first in cell order is named, as a scan of the cells
  // would meet it.
  std::optional<CellFacet> crowded;
  std::size_t crowd = 0;
  for (std::size_t i = 0, j = 0; i < facets.size(); i = j) {
    for (j = i + 1; j < facets.size() && facets[j].key == facets[i].key; ++j) {}
    progress.at(primal::index_cast(i / R::kFacets));
    const CellFacet& first = facets[i].at;  // the run's lowest cell, then facet
    if (j - i == 1) dual.boundary.push_back(first);
    if (j - i > 2 &&
        (!crowded || std::tie(first.cell, first.local) < std::tie(crowded->cell, crowded->local)))
      crowded = first, crowd = j - i;
  }
  if (crowded)
    throw TopologyError(std::string(R::kCellName) + " " + std::to_string(crowded->cell) +
                        ": facet " + std::to_string(crowded->local) + " is shared by " +
                        std::to_string(crowd) + " cells");
  primal::release(facets);
  std::sort(dual.boundary.begin(), dual.boundary.end(), [](const CellFacet& a, const CellFacet& b) {
    return std::tie(a.cell, a.local) < std::tie(b.cell, b.local);
  });

  build_traces(cells, dual);
  progress.end();
  return dual;
}

template <int Dim>
std::vector<std::vector<TraceCurve>> split(const MeshDual<Dim>& dual, Index sheet,
                                           const FacetClassifier& classify, int regions) {
  if (sheet < 0 || primal::index_cast<std::size_t>(sheet) >= dual.sheets.size())
    throw InvalidInput("trace_by_region: no sheet " + std::to_string(sheet));
  std::vector<std::vector<TraceCurve>> out(regions);
  for (const TraceCurve& curve : dual.sheets[sheet].trace) {
    const std::size_t n = curve.facets.size();
    std::vector<int> region(n);
    for (std::size_t i = 0; i < n; ++i) {
      region[i] = classify(curve.facets[i]);
      if (region[i] < 0 || region[i] >= regions)
        throw InvalidInput("trace_by_region: sheet " + std::to_string(sheet) + ", " +
                           (Dim == 3 ? "hex " : "quad ") + std::to_string(curve.facets[i].cell) +
                           " facet " + std::to_string(curve.facets[i].local) + " is in region " +
                           std::to_string(region[i]) + ", outside [0, " + std::to_string(regions) +
                           ")");
    }
    if (n == 0) continue;
    if (std::all_of(region.begin(), region.end(), [&](int r) { return r == region[0]; })) {
      out[region[0]].push_back(curve);
      continue;
    }
    // Start a closed curve at a change of region so that no run wraps around.
    std::size_t first = 0;
    if (curve.closed)
      while (region[first] == region[(first + n - 1) % n]) ++first;
    const std::size_t ne = curve.edges.size();
    for (std::size_t done = 0; done < n;) {
      const std::size_t i = (first + done) % n;
      TraceCurve piece;
      piece.edges.push_back(curve.edges[i]);
      std::size_t k = done;
      while (k < n && region[(first + k) % n] == region[i]) {
        const std::size_t j = (first + k) % n;
        piece.facets.push_back(curve.facets[j]);
        piece.edges.push_back(curve.edges[(j + 1) % ne]);
        ++k;
      }
      out[region[i]].push_back(std::move(piece));
      done = k;
    }
  }
  return out;
}

template <typename Cell>
FacetClassifier box_classifier(const std::vector<primal::Point>& points,
                               const std::vector<Cell>& cells, const auto& facet_table, int axes,
                               const primal::Point& lo, const primal::Point& hi, double tol) {
  return [&points, &cells, &facet_table, axes, lo, hi, tol](const CellFacet& f) {
    for (int axis = 0; axis < axes; ++axis)
      for (int high = 0; high < 2; ++high) {
        const double plane = high ? hi[axis] : lo[axis];
        const bool on =
            std::all_of(facet_table[f.local].begin(), facet_table[f.local].end(), [&](int corner) {
              return std::abs(points[cells[f.cell][corner]][axis] - plane) <= tol;
            });
        if (on) return 2 * axis + high;
      }
    return -1;
  };
}

}  // namespace

HexDual mesh_dual(const primal::HexMesh& mesh, const MeshDualOptions& options) {
  return build<3>(mesh.points.size(), mesh.hexes, options);
}

QuadDual mesh_dual(const primal::QuadMesh& mesh, const MeshDualOptions& options) {
  return build<2>(mesh.points.size(), mesh.quads, options);
}

std::vector<std::vector<TraceCurve>> trace_by_region(const HexDual& dual, Index sheet,
                                                     const FacetClassifier& classify, int regions) {
  return split(dual, sheet, classify, regions);
}

std::vector<std::vector<TraceCurve>> trace_by_region(const QuadDual& dual, Index sheet,
                                                     const FacetClassifier& classify, int regions) {
  return split(dual, sheet, classify, regions);
}

FacetClassifier box_face_classifier(const primal::HexMesh& mesh, const primal::Point& lo,
                                    const primal::Point& hi, double tol) {
  return box_classifier(mesh.points, mesh.hexes, topo::kHexFaceCorners, 3, lo, hi, tol);
}

FacetClassifier box_face_classifier(const primal::QuadMesh& mesh, const primal::Point& lo,
                                    const primal::Point& hi, double tol) {
  return box_classifier(mesh.points, mesh.quads, topo::kQuadEdgeCorners, 2, lo, hi, tol);
}

}  // namespace geode::stc
