#pragma once
// Keys made of node numbers, each listed at its smallest node: one array with room for every
// use counted beforehand (compressed rows), a node's few entries searched linearly. Cells of a
// mesher's output meet their edges and faces in an order that follows the node numbering, so
// the lists they touch lie near each other in memory, where a hash table's slots are spread
// over all of it, and take half the memory (dicing's edge and face numbering of the n = 36
// Delaunay bench's tets: 0.10 s against 0.14 s with primal::KeyMap, whose two tables of a
// million slots took 40 MB there, against 22 MB for these; the floor program in bench/ numbers
// its nodes with these tables too).
#include <array>
#include <cstddef>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal::detail {

// R: how many nodes a key has besides its smallest (1 for an edge, 3 for a face, padded with
// kInvalidIndex).
template <std::size_t R>
class NodeTable {
 public:
  using Rest = std::array<Index, R>;

  // uses[a]: how many times find_or_add will be called at node a (at most).
  explicit NodeTable(const std::vector<Index>& uses) : start_(uses.size() + 1, 0) {
    for (std::size_t v = 0; v < uses.size(); ++v) start_[v + 1] = start_[v] + uses[v];
    size_.assign(uses.size(), 0);
    entries_.resize(index_cast<std::size_t>(start_.back()));
  }

  // A hint that node a's list is wanted soon: its memory fetched meanwhile.
  void prefetch(Index a) const {
    __builtin_prefetch(entries_.data() + start_[index_cast<std::size_t>(a)]);
  }

  // The value listed for the key (a, rest); the first time, make() gives it.
  template <class Make>
  Index find_or_add(Index a, const Rest& rest, Make&& make) {
    Entry* first = entries_.data() + start_[index_cast<std::size_t>(a)];
    Entry* last = first + size_[index_cast<std::size_t>(a)];
    for (Entry* e = first; e != last; ++e)
      if (same(e->rest, rest)) return e->value;
    last->rest = rest;
    last->value = make();
    ++size_[index_cast<std::size_t>(a)];
    return last->value;
  }

 private:
  struct Entry {
    Rest rest;
    Index value;
  };
  // Entry by entry: std::array's operator== is a call of memcmp.
  static bool same(const Rest& x, const Rest& y) {
    for (std::size_t k = 0; k < R; ++k)
      if (x[k] != y[k]) return false;
    return true;
  }
  std::vector<Index> start_, size_;
  std::vector<Entry> entries_;
};

}  // namespace geode::primal::detail
