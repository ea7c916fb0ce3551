#include <geode/primal/relax_tets.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <geode/primal/dice.hpp>

namespace geode::primal {
namespace {

// The relaxation's state: per free node its tets (compressed rows), the points moved in place.
class Relaxer {
 public:
  Relaxer(std::vector<Point>& points, std::span<const std::array<Index, 4>> tets,
          std::span<const Index> free_nodes)
      : points_(points), tets_(tets), free_(free_nodes.begin(), free_nodes.end()) {
    std::vector<Index> slot(points.size(), kInvalidIndex);
    for (std::size_t k = 0; k < free_.size(); ++k)
      slot[index_cast<std::size_t>(free_[k])] = index_cast(k);
    first_.assign(free_.size() + 1, 0);
    for (const auto& t : tets)
      for (Index v : t)
        if (slot[index_cast<std::size_t>(v)] != kInvalidIndex)
          ++first_[index_cast<std::size_t>(slot[index_cast<std::size_t>(v)]) + 1];
    std::partial_sum(first_.begin(), first_.end(), first_.begin());
    around_.resize(first_.back());
    std::vector<std::size_t> fill(first_.begin(), first_.end() - 1);
    for (std::size_t c = 0; c < tets.size(); ++c) {
      bool near = false;
      for (Index v : tets[c])
        if (const Index k = slot[index_cast<std::size_t>(v)]; k != kInvalidIndex)
          around_[fill[index_cast<std::size_t>(k)]++] = index_cast(c), near = true;
      if (near) near_.push_back(index_cast(c));
    }
  }

  std::size_t size() const { return free_.size(); }

  // Tet around_[at] diced: its lowest child, exact when above `bound`, some value at or below it
  // otherwise; `child`: the child to try first, left at the one that failed.
  double tet_value(std::size_t at, double bound, int* child) const {
    const auto& t = tets_[index_cast<std::size_t>(around_[at])];
    std::array<Point, 4> c;
    for (std::size_t q = 0; q < 4; ++q) c[q] = points_[index_cast<std::size_t>(t[q])];
    return diced_tet_min_scaled_jacobian(c, bound, child);
  }

  // Every free node's lowest diced scaled Jacobian over its tets at the points as they are,
  // into `low`: each tet around them measured once (most have several free nodes), then per
  // node the minimum over its row in order. The tets' figures are kept (per_tet_) and kept
  // current by every search, which moves only its node and leaves its row's figures where it
  // stops: later searches and lowest_of_rows() read them instead of measuring again.
  void lowest_all(std::vector<double>& low) {
    per_tet_.resize(tets_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, near_.size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i) {
                          const auto t = index_cast<std::size_t>(near_[i]);
                          std::array<Point, 4> c;
                          for (std::size_t q = 0; q < 4; ++q)
                            c[q] = points_[index_cast<std::size_t>(tets_[t][q])];
                          per_tet_[t] = diced_tet_min_scaled_jacobian(c);
                        }
                      });
    lowest_of_rows(low);
  }

  // Every free node's lowest tet figure, from per_tet_ (current: see lowest_all).
  void lowest_of_rows(std::vector<double>& low) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, size(), 256),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t k = range.begin(); k != range.end(); ++k) {
                          double m = 1.0;
                          for (std::size_t i = first_[k]; i < first_[k + 1]; ++i)
                            m = std::min(m, per_tet_[index_cast<std::size_t>(around_[i])]);
                          low[k] = m;
                        }
                      });
  }

  double shortest_edge(std::size_t k) const {
    const Point& p = points_[index_cast<std::size_t>(free_[k])];
    double s = std::numeric_limits<double>::infinity();
    for (std::size_t i = first_[k]; i < first_[k + 1]; ++i)
      for (Index v : tets_[index_cast<std::size_t>(around_[i])])
        if (v != free_[k]) s = std::min(s, (points_[index_cast<std::size_t>(v)] - p).norm());
    return s;
  }

  // Compass search at free node k; true when it moved. A trial position wins when every tet
  // around the node dices above the best so far: it fails at the first tet that does not,
  // and the tets are tried in an order that finds that one soon (the lowest where the node
  // stands first, the last to fail a trial moved to the front; each tet's failing child first
  // too). The order changes the trials' cost, not their outcome: a winning trial measures every
  // tet exactly, and its minimum is taken in the row's order.
  bool search(std::size_t k, const RelaxTetsOptions& o) {
    Point& p = points_[index_cast<std::size_t>(free_[k])];
    const std::size_t b = first_[k], n = first_[k + 1] - b;
    std::vector<double> value(n), trial(n);
    std::vector<int> child(n, 0);
    std::vector<std::size_t> order(n);
    // Where the node stands, its tets' figures are per_tet_'s (the same computation: the tets
    // of a search's row are no other search's in its round).
    for (std::size_t i = 0; i < n; ++i)
      value[i] = per_tet_[index_cast<std::size_t>(around_[b + i])];
    auto sort_order = [&] {
      std::iota(order.begin(), order.end(), std::size_t{0});
      std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
        return value[x] != value[y] ? value[x] < value[y] : x < y;
      });
    };
    sort_order();
    auto row_min = [&](const std::vector<double>& v) {
      double m = 1.0;
      for (double x : v) m = std::min(m, x);
      return m;
    };
    double best = row_min(value);
    double step = o.initial_step * shortest_edge(k);
    bool moved = false;
    for (int halving = 0; halving <= o.halvings;) {
      bool improved = false;
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          const double sign = side == 0 ? 1.0 : -1.0;
          const Point old = p;
          p[axis] += sign * step;
          const double bound = best + kMinGain;
          bool wins = true;
          for (std::size_t j = 0; j < n && wins; ++j) {
            const std::size_t i = order[j];
            trial[i] = tet_value(b + i, bound, &child[i]);
            if (trial[i] <= bound) {
              wins = false;
              std::rotate(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(j),
                          order.begin() + static_cast<std::ptrdiff_t>(j) + 1);
            }
          }
          if (wins) {
            value.swap(trial);
            best = row_min(value);
            sort_order();
            improved = moved = true;
          } else {
            p = old;
          }
        }
      if (!improved) step *= 0.5, ++halving;
    }
    for (std::size_t i = 0; i < n; ++i)
      per_tet_[index_cast<std::size_t>(around_[b + i])] = value[i];
    return moved;
  }

  Index node(std::size_t k) const { return free_[k]; }

  // Every node of free node k's tets (itself included, repeatedly).
  template <class F>
  void for_each_neighbour(std::size_t k, F&& f) const {
    for (std::size_t i = first_[k]; i < first_[k + 1]; ++i)
      for (Index v : tets_[index_cast<std::size_t>(around_[i])]) f(v);
  }

 private:
  static constexpr double kMinGain = 1e-9;  // a rise below rounding is not a move
  std::vector<Point>& points_;
  std::span<const std::array<Index, 4>> tets_;
  std::vector<Index> free_;
  std::vector<std::size_t> first_;
  std::vector<Index> around_;
  std::vector<Index> near_;      // the tets with a free node, ascending
  std::vector<double> per_tet_;  // per tet (set for near_'s): its lowest diced child as it stands
};

}  // namespace

RelaxTetsResult relax_tet_nodes(std::vector<Point>& points,
                                std::span<const std::array<Index, 4>> tets,
                                std::span<const Index> free_nodes,
                                const RelaxTetsOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  RelaxTetsResult r;
  Relaxer relax(points, tets, free_nodes);
  const std::size_t n = relax.size();
  std::vector<char> moved(n, 0);
  std::vector<double> low(n);
  relax.lowest_all(low);
  r.min_before = n ? *std::min_element(low.begin(), low.end()) : 1.0;
  std::vector<char> touched(points.size(), 0);
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    // Worst first; ties by node number (free_nodes ascending keeps k in node order).
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < n; ++k)
      if (low[k] < options.good) order.push_back(k);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return low[a] != low[b] ? low[a] < low[b] : a < b;
    });
    // Rounds: in order, each node that shares no tet with one already taken in the round is
    // taken, and a round's nodes search in parallel (none reads another's position), so the
    // result does not depend on the thread count.
    std::atomic<bool> any = false;
    while (!order.empty()) {
      std::vector<std::size_t> round, rest;
      for (std::size_t k : order) {
        if (touched[index_cast<std::size_t>(relax.node(k))]) {
          rest.push_back(k);
          continue;
        }
        round.push_back(k);
        relax.for_each_neighbour(k, [&](Index v) { touched[index_cast<std::size_t>(v)] = 1; });
      }
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, round.size(), 16),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i)
                            if (relax.search(round[i], options)) moved[round[i]] = 1, any = true;
                        });
      for (std::size_t k : round)
        relax.for_each_neighbour(k, [&](Index v) { touched[index_cast<std::size_t>(v)] = 0; });
      order.swap(rest);
    }
    relax.lowest_of_rows(low);
    if (!any) break;
  }
  r.min_after = n ? *std::min_element(low.begin(), low.end()) : 1.0;
  r.nodes_moved = index_cast(std::count(moved.begin(), moved.end(), 1));
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::vector<Index> tet_nodes_to_relax(const Model& model, int rings, std::span<const Index> seeds) {
  const std::size_t n = model.points.size();
  // Nodes any other kind uses, a node set names or a side set's face holds (a surface
  // embedded in the tets stays where the user put it): fixed.
  std::vector<char> fixed(n, 0);
  for (const auto& h : model.hexes)
    for (Index v : h) fixed[index_cast<std::size_t>(v)] = 1;
  for (const auto& w : model.wedges)
    for (Index v : w) fixed[index_cast<std::size_t>(v)] = 1;
  for (const auto& p : model.pyramids)
    for (Index v : p) fixed[index_cast<std::size_t>(v)] = 1;
  for (const NodeSet& s : model.node_sets)
    for (Index v : s.nodes) fixed[index_cast<std::size_t>(v)] = 1;
  for (const SideSet& s : model.side_sets)
    for (const Side& side : s.sides)
      for (Index v : element_face(model, side)) fixed[index_cast<std::size_t>(v)] = 1;
  // The region: rings of tets out from the quads of hexes and wedges whose four corners are
  // all tet nodes (the quads a transition is made on: two or four tet triangles on them), not
  // from every node tets share with them (a wedge layer's base lies on tet faces too).
  std::vector<char> tet_node(n, 0), near(n, 0), in_region(model.tets.size(), 0);
  // Passes over the tets in parallel: each tet its own slot, or nodes flagged 1 by any.
  auto each_tet = [&](auto&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, model.tets.size(), 8192),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t t = r.begin(); t != r.end(); ++t) f(t);
                      });
  };
  auto flag = [](std::vector<char>& flags, Index v) {
    std::atomic_ref<char>(flags[index_cast<std::size_t>(v)]).store(1, std::memory_order_relaxed);
  };
  each_tet([&](std::size_t t) {
    for (Index v : model.tets[t]) flag(tet_node, v);
  });
  for (const ElementKind kind : {ElementKind::kHex, ElementKind::kWedge}) {
    const auto& topo = cell_topology(kind);
    for (std::size_t c = 0; c < element_count(model, kind); ++c) {
      const auto corners = element_corners(model, {kind, index_cast(c)});
      for (int f = 0; f < topo.faces; ++f) {
        const auto& face = topo.face[index_cast<std::size_t>(f)];
        if (face.size != 4) continue;
        bool covered = true;
        for (int i = 0; i < 4; ++i)
          covered &=
              tet_node[index_cast<std::size_t>(
                  corners[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(i)])])] != 0;
        if (covered)
          for (int i = 0; i < 4; ++i)
            near[index_cast<std::size_t>(
                corners[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(i)])])] = 1;
      }
    }
  }
  for (Index v : seeds) near[index_cast<std::size_t>(v)] = 1;
  for (int ring = 0; ring < rings; ++ring) {
    each_tet([&](std::size_t t) {
      for (Index v : model.tets[t])
        if (near[index_cast<std::size_t>(v)]) in_region[t] = 1;
    });
    each_tet([&](std::size_t t) {
      if (in_region[t])
        for (Index v : model.tets[t]) flag(near, v);
    });
  }
  // Per candidate node its tets' faces through it, as the other two nodes: an interior node
  // has each such face twice (its star is closed), all in one block.
  std::vector<std::size_t> first(n + 1, 0);
  for (const auto& t : model.tets)
    for (Index v : t)
      if (near[index_cast<std::size_t>(v)] && !fixed[index_cast<std::size_t>(v)])
        first[index_cast<std::size_t>(v) + 1] += 3;
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<std::array<Index, 2>> faces(first.back());
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  std::vector<int> block(n, 0);
  for (std::size_t t = 0; t < model.tets.size(); ++t) {
    const auto& c = model.tets[t];
    if (std::none_of(c.begin(), c.end(), [&](Index v) {
          return near[index_cast<std::size_t>(v)] && !fixed[index_cast<std::size_t>(v)];
        }))
      continue;
    const int b = block_of(model, {ElementKind::kTet, index_cast(t)});
    for (std::size_t i = 0; i < 4; ++i) {
      const std::size_t v = index_cast<std::size_t>(c[i]);
      if (!near[v] || fixed[v]) continue;
      if (block[v] == 0) block[v] = b;
      if (block[v] != b) fixed[v] = 1;
      // The three faces through corner i: the other three corners taken in pairs.
      const std::array<Index, 3> o{c[(i + 1) % 4], c[(i + 2) % 4], c[(i + 3) % 4]};
      for (std::size_t j = 0; j < 3; ++j) {
        const Index x = o[j], y = o[(j + 1) % 3];
        faces[fill[v]++] = {std::min(x, y), std::max(x, y)};
      }
    }
  }
  // Each candidate's star judged on its own (in parallel), then listed in node order.
  std::vector<char> relaxable(n, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t v = r.begin(); v != r.end(); ++v) {
                        if (!near[v] || fixed[v] || first[v] == first[v + 1]) continue;
                        auto b = faces.begin() + static_cast<std::ptrdiff_t>(first[v]);
                        auto e = faces.begin() + static_cast<std::ptrdiff_t>(first[v + 1]);
                        std::sort(b, e);
                        bool closed = (e - b) % 2 == 0;
                        for (auto it = b; closed && it != e; it += 2)
                          closed = *it == *(it + 1) && (it + 2 == e || *(it + 2) != *it);
                        relaxable[v] = closed;
                      }
                    });
  std::vector<Index> out;
  for (std::size_t v = 0; v < n; ++v)
    if (relaxable[v]) out.push_back(index_cast(v));
  return out;
}

}  // namespace geode::primal
