#pragma once
// Face uses (or any records keyed by node numbers) in order, sorted by their lowest node first:
// counted out per node, each record written once into place, then each node's few sorted. One
// sort of them all gives the same order with passes over the whole array; this way the cost is
// a scatter and many tiny sorts, in parallel (the read-time covering check, the interface
// search's tet triangles and duplicate check, the boundary quads of a hex mesh).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cstddef>
#include <tuple>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal::detail {

// A use of a key of N node numbers (ascending), and its place in the caller's order: the record
// most callers sort, grouped by key, first use first.
template <std::size_t N>
struct KeyedUse {
  std::array<Index, N> key;
  std::size_t at;
  bool operator<(const KeyedUse& o) const { return std::tie(key, at) < std::tie(o.key, o.at); }
};

// The records `each(visit)` visits, ordered by lowest(record) (a node number below `nodes`),
// then by Record's operator<, which must be a total order: `each` may call visit from several
// threads at once (it is called twice, to count and to place), and the result does not depend
// on them. `start` receives each node's first record, and the record count at the end.
// `count(visit)` calls visit(node) with the lowest node of each record `each` visits (in any
// order, from any thread): where a record costs more to make than its lowest node, the counting
// pass need not make it.
template <class Record, class Count, class Each, class Lowest>
std::vector<Record> sort_by_lowest_node(std::size_t nodes, Count&& count, Each&& each,
                                        Lowest&& lowest, std::vector<std::size_t>& start) {
  auto slot = [&](std::vector<std::size_t>& v, std::size_t node) {
    return std::atomic_ref<std::size_t>(v[node]);
  };
  start.assign(nodes + 1, 0);
  count([&](Index node) {
    slot(start, index_cast<std::size_t>(node) + 1).fetch_add(1, std::memory_order_relaxed);
  });
  for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  std::vector<Record> out(start.back());
  std::vector<std::size_t> next(start.begin(), start.end() - 1);
  each([&](const Record& r) {
    out[slot(next, index_cast<std::size_t>(lowest(r))).fetch_add(1, std::memory_order_relaxed)] = r;
  });
  // `count` and `each` must visit the same lowest nodes: every node's slots exactly filled.
  assert(std::equal(next.begin(), next.end(), start.begin() + 1));
  // Within a node the threads' order varies; the sort fixes it.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t v = r.begin(); v != r.end(); ++v)
                        std::sort(out.begin() + static_cast<std::ptrdiff_t>(start[v]),
                                  out.begin() + static_cast<std::ptrdiff_t>(start[v + 1]));
                    });
  return out;
}

template <class Record, class Each, class Lowest>
std::vector<Record> sort_by_lowest_node(std::size_t nodes, Each&& each, Lowest&& lowest,
                                        std::vector<std::size_t>& start) {
  auto count = [&](auto&& visit) { each([&](const Record& r) { visit(lowest(r)); }); };
  return sort_by_lowest_node<Record>(nodes, count, each, lowest, start);
}

// The runs of equal records (same(i, j) on their positions) in sort_by_lowest_node's result:
// f(begin, end) once per run, nodes' records in parallel (a run never spans two nodes, its
// records sharing their lowest node), so f may write what its run owns.
template <class Same, class F>
void for_each_run(const std::vector<std::size_t>& start, Same&& same, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, start.size() - 1, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      const std::size_t end = start[r.end()];
                      for (std::size_t k = start[r.begin()]; k < end;) {
                        std::size_t next = k + 1;
                        while (next < end && same(k, next)) ++next;
                        f(k, next);
                        k = next;
                      }
                    });
}

}  // namespace geode::primal::detail
