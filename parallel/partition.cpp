#include <geode/parallel/partition.hpp>

#include <metis.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include <geode/primal/element_graph.hpp>
#include <geode/primal/submodel.hpp>

namespace geode::parallel {

namespace {

static_assert(std::is_same_v<idx_t, primal::Index>, "METIS built with 64-bit indices");

// Elements per cluster: METIS then partitions a graph 16 times smaller than the elements' (its
// coarsening of that graph, with the dual graph METIS_PartMeshDual built from the element list,
// was most of the time); larger clusters leave a more ragged cut for the refinement to mend
// (measured on the half demo, n = 64: 16 cuts 1.06 to 1.23 times the faces METIS cuts on the
// elements' graph, 64 1.3 times).
constexpr std::int64_t kClusterSize = 16;
// METIS's default balance tolerance (ufactor 30): a part at most 3 % over the mean.
constexpr std::int64_t kBalancePercent = 103;
constexpr int kRefinePasses = 8;

// A METIS index as a position.
std::size_t at(idx_t i) { return primal::index_cast<std::size_t>(i); }

// A graph as METIS takes it: compressed rows, vertex weights, edge weights (empty: all 1).
struct Graph {
  std::vector<idx_t> xadj, adjncy, adjwgt, vwgt;
  std::size_t size() const { return xadj.size() - 1; }
  idx_t edge_weight(idx_t k) const { return adjwgt.empty() ? 1 : adjwgt[at(k)]; }
};

// The elements, weighted by the hexes each dices into (8, 4, 6; a pyramid as its two tets, 8)
// unless `weight` says otherwise, joined across their faces.
Graph element_level(const primal::Model& model, primal::ElementGraph eg,
                    const std::vector<idx_t>& weight) {
  if (eg.offset.empty()) eg = primal::element_graph(model);
  Graph g;
  g.xadj.reserve(eg.offset.size());
  for (std::size_t o : eg.offset) g.xadj.push_back(primal::index_cast<idx_t>(o));
  g.adjncy = std::move(eg.neighbour);
  if (!weight.empty()) {
    g.vwgt = weight;
    return g;
  }
  g.vwgt.reserve(g.size());
  for (primal::ElementKind kind : primal::kElementKinds)
    g.vwgt.insert(g.vwgt.end(), primal::element_count(model, kind),
                  kind == primal::ElementKind::kPyramid
                      ? 8
                      : primal::index_cast<idx_t>(primal::cell_topology(kind).corners));
  return g;
}

// Clusters of connected vertices weighing about kClusterSize mean vertices, grown breadth
// first, each seeded where the last one stopped growing (its unclaimed frontier), so that they
// tile the graph in one sweep instead of leaving slivers between balls grown from scattered
// seeds; a vertex that would take a cluster past 1.5 times its aim is left for another. Per
// vertex its cluster, numbered from 0 in order of growth; `count` clusters.
std::vector<idx_t> grow_clusters(const Graph& g, idx_t& count) {
  const std::size_t n = g.size();
  std::int64_t total = 0;
  for (idx_t w : g.vwgt) total += w;
  const std::int64_t aim = total * kClusterSize / primal::index_cast<std::int64_t>(n),
                     cap = aim + aim / 2;
  std::vector<idx_t> cluster(n, -1), queued(n, -1);  // queued: the cluster that queued it
  std::vector<idx_t> frontier, queue;
  std::size_t frontier_head = 0, scan = 0;
  count = 0;
  for (;;) {
    idx_t seed = -1;
    while (frontier_head < frontier.size() && seed < 0)
      if (const idx_t v = frontier[frontier_head++]; cluster[at(v)] < 0) seed = v;
    while (seed < 0 && scan < n)
      if (cluster[scan++] < 0) seed = primal::index_cast<idx_t>(scan - 1);
    if (seed < 0) break;
    const idx_t c = count++;
    queue.assign(1, seed);
    queued[at(seed)] = c;
    std::int64_t weight = 0;
    std::size_t head = 0;
    for (; head < queue.size() && weight < aim; ++head) {
      const std::size_t v = at(queue[head]);
      if (cluster[v] >= 0 || (weight > 0 && weight + g.vwgt[v] > cap)) continue;
      cluster[v] = c;
      weight += g.vwgt[v];
      for (idx_t k = g.xadj[v]; k < g.xadj[v + 1]; ++k) {
        const idx_t o = g.adjncy[at(k)];
        if (cluster[at(o)] < 0 && queued[at(o)] != c) {
          queued[at(o)] = c;
          queue.push_back(o);
        }
      }
    }
    frontier.insert(frontier.end(), queue.begin() + primal::index_cast<std::ptrdiff_t>(head),
                    queue.end());
  }
  return cluster;
}

// The clusters' graph: vertex weights summed, an edge per pair of neighbouring clusters
// weighted by the edges between them (the faces they share).
Graph contract(const Graph& g, const std::vector<idx_t>& cluster, idx_t count) {
  const std::size_t nc = at(count);
  std::vector<idx_t> start(nc + 1, 0), member(g.size());
  for (idx_t c : cluster) ++start[at(c) + 1];
  for (std::size_t c = 0; c < nc; ++c) start[c + 1] += start[c];
  {
    std::vector<idx_t> fill(start.begin(), start.end() - 1);
    for (std::size_t v = 0; v < g.size(); ++v)
      member[at(fill[at(cluster[v])]++)] = primal::index_cast<idx_t>(v);
  }
  Graph q;
  q.xadj.reserve(nc + 1);
  q.xadj.push_back(0);
  q.vwgt.assign(nc, 0);
  std::vector<idx_t> mark(nc, -1), slot(nc, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const idx_t self = primal::index_cast<idx_t>(c);
    for (idx_t m = start[c]; m < start[c + 1]; ++m) {
      const std::size_t v = at(member[at(m)]);
      q.vwgt[c] += g.vwgt[v];
      for (idx_t k = g.xadj[v]; k < g.xadj[v + 1]; ++k) {
        const idx_t o = cluster[at(g.adjncy[at(k)])];
        if (o == self) continue;
        if (mark[at(o)] != self) {
          mark[at(o)] = self;
          slot[at(o)] = primal::index_cast<idx_t>(q.adjncy.size());
          q.adjncy.push_back(o);
          q.adjwgt.push_back(0);
        }
        q.adjwgt[at(slot[at(o)])] += g.edge_weight(k);
      }
    }
    q.xadj.push_back(primal::index_cast<idx_t>(q.adjncy.size()));
  }
  return q;
}

// Greedy k-way refinement of the elements' partition, METIS's own last step, which partitioning
// the clusters skips (the cut METIS finds follows their ragged borders): passes over the border
// vertices in order, moving one to the neighbouring part it shares most edges with when that
// cuts fewer (or as many, towards a part lighter than its own after the move), within the
// balance bound; each pass visits the vertices around the last one's moves.
void refine(const Graph& g, const std::vector<double>& share, std::vector<idx_t>& part) {
  std::vector<std::int64_t> load(share.size(), 0), bound(share.size());
  std::int64_t total = 0;
  for (std::size_t v = 0; v < g.size(); ++v) {
    load[at(part[v])] += g.vwgt[v];
    total += g.vwgt[v];
  }
  for (std::size_t p = 0; p < share.size(); ++p)
    bound[p] = static_cast<std::int64_t>(static_cast<double>(total) * share[p] *
                                         static_cast<double>(kBalancePercent) / 100.0);
  std::vector<idx_t> visit, moved;
  for (std::size_t v = 0; v < g.size(); ++v)
    for (idx_t k = g.xadj[v]; k < g.xadj[v + 1]; ++k)
      if (part[at(g.adjncy[at(k)])] != part[v]) {
        visit.push_back(primal::index_cast<idx_t>(v));
        break;
      }
  std::vector<std::pair<idx_t, std::int64_t>> towards;  // (part, edge weight to it)
  for (int pass = 0; pass < kRefinePasses && !visit.empty(); ++pass) {
    moved.clear();
    for (idx_t vi : visit) {
      const std::size_t v = at(vi);
      const idx_t own = part[v];
      std::int64_t inside = 0;
      towards.clear();
      for (idx_t k = g.xadj[v]; k < g.xadj[v + 1]; ++k) {
        const idx_t q = part[at(g.adjncy[at(k)])];
        if (q == own) {
          inside += g.edge_weight(k);
          continue;
        }
        auto it = std::find_if(towards.begin(), towards.end(),
                               [q](const auto& t) { return t.first == q; });
        if (it == towards.end())
          towards.push_back({q, g.edge_weight(k)});
        else
          it->second += g.edge_weight(k);
      }
      const std::int64_t w = g.vwgt[v];
      idx_t best = -1;
      std::int64_t best_gain = 0;
      for (const auto& [q, joined] : towards) {
        const std::int64_t gain = joined - inside;
        if (load[at(q)] + w > bound[at(q)] || gain < best_gain) continue;
        if (gain == best_gain && !(best >= 0 ? load[at(q)] < load[at(best)]
                                             : gain > 0 || load[at(q)] + w < load[at(own)] - w))
          continue;
        best = q;
        best_gain = gain;
      }
      if (best < 0) continue;
      load[at(own)] -= w;
      load[at(best)] += w;
      part[v] = best;
      moved.push_back(vi);
    }
    visit.clear();
    for (idx_t v : moved) {
      visit.push_back(v);
      for (idx_t k = g.xadj[at(v)]; k < g.xadj[at(v) + 1]; ++k) visit.push_back(g.adjncy[at(k)]);
    }
    std::sort(visit.begin(), visit.end());
    visit.erase(std::unique(visit.begin(), visit.end()), visit.end());
  }
}

}  // namespace

std::vector<int> partition_elements(const primal::Model& model, int parts,
                                    PartitionOptions options) {
  const std::size_t n = primal::element_offsets(model).back();
  std::vector<int> result(n, 0);
  if (parts <= 1 || n == 0) return result;
  if (!options.weight.empty() && options.weight.size() != n)
    throw std::invalid_argument("partition_elements: " + std::to_string(options.weight.size()) +
                                " weights for " + std::to_string(n) + " elements");
  if (!options.share.empty() && options.share.size() != at(parts))
    throw std::invalid_argument("partition_elements: " + std::to_string(options.share.size()) +
                                " shares for " + std::to_string(parts) + " parts");
  std::vector<double> share = options.share;
  if (share.empty()) share.assign(at(parts), 1.0 / parts);
  std::vector<real_t> tpwgts(share.begin(), share.end());
  if (!options.graph.offset.empty() && options.graph.offset.size() != n + 1)
    throw std::invalid_argument("partition_elements: a graph of " +
                                std::to_string(options.graph.offset.size() - 1) + " elements for " +
                                std::to_string(n));
  Graph elements = element_level(model, std::move(options.graph), options.weight);
  // Small models (under 64 clusters a part) are partitioned element by element: fast anyway,
  // and clusters would leave the balance coarse.
  const bool cluster = primal::index_cast<std::int64_t>(n) >= kClusterSize * 64 * parts;
  idx_t count = primal::index_cast<idx_t>(n);
  const std::vector<idx_t> element_cluster =
      cluster ? grow_clusters(elements, count) : std::vector<idx_t>();
  Graph clusters = cluster ? contract(elements, element_cluster, count) : Graph();
  Graph& g = cluster ? clusters : elements;
  idx_t ncon = 1, np = parts, objval = 0;
  idx_t metis[METIS_NOPTIONS];
  METIS_SetDefaultOptions(metis);
  metis[METIS_OPTION_SEED] = 1;
  std::vector<idx_t> part(g.size(), 0);
  const int status =
      METIS_PartGraphKway(&count, &ncon, g.xadj.data(), g.adjncy.data(), g.vwgt.data(), nullptr,
                          g.adjwgt.empty() ? nullptr : g.adjwgt.data(), &np, tpwgts.data(), nullptr,
                          metis, &objval, part.data());
  if (status != METIS_OK)
    throw std::runtime_error("METIS_PartGraphKway failed (status " + std::to_string(status) + ")");
  if (cluster) {
    std::vector<idx_t> element_part(n);
    for (std::size_t e = 0; e < n; ++e) element_part[e] = part[at(element_cluster[e])];
    part = std::move(element_part);
    refine(elements, share, part);
  }
  for (std::size_t e = 0; e < n; ++e) result[e] = part[e];
  return result;
}

primal::ElementGraph graph_of_pairs(std::size_t elements,
                                    std::span<const std::array<primal::Index, 2>> pairs) {
  primal::ElementGraph g;
  g.offset.assign(elements + 1, 0);
  for (const auto& [a, b] : pairs) {
    if (a < 0 || b < 0 || primal::index_cast<std::size_t>(a) >= elements ||
        primal::index_cast<std::size_t>(b) >= elements)
      throw std::invalid_argument("graph_of_pairs: a pair (" + std::to_string(a) + ", " +
                                  std::to_string(b) + ") beyond " + std::to_string(elements) +
                                  " elements");
    ++g.offset[primal::index_cast<std::size_t>(a) + 1];
    ++g.offset[primal::index_cast<std::size_t>(b) + 1];
  }
  for (std::size_t e = 0; e < elements; ++e) g.offset[e + 1] += g.offset[e];
  g.neighbour.resize(g.offset.back());
  std::vector<std::size_t> fill(g.offset.begin(), g.offset.end() - 1);
  for (const auto& [a, b] : pairs) {
    g.neighbour[fill[primal::index_cast<std::size_t>(a)]++] = b;
    g.neighbour[fill[primal::index_cast<std::size_t>(b)]++] = a;
  }
  return g;
}

std::vector<int> ranks_of_parts(const std::vector<int>& part, int parts, int ranks) {
  if (parts < ranks || ranks < 1) return {};
  std::vector<int> rank(part.size());
  for (std::size_t e = 0; e < part.size(); ++e)
    rank[e] = static_cast<int>(static_cast<std::int64_t>(part[e]) * ranks / parts);
  return rank;
}

}  // namespace geode::parallel
