#pragma once
// The third nodes of triangles, by edge: the candidate centres of a quad split into four
// triangles around one node (the interface search, find_interface, and the input check's
// quad-triangle matching). A sorted list rather than a hash map of vectors (an allocation per
// edge); an edge's third nodes keep the order their triangles were added in.
#include <algorithm>
#include <span>
#include <vector>

#include <geode/primal/boundary.hpp>

namespace geode::primal::detail {

class EdgeThirds {
 public:
  struct Entry {
    EdgeKey edge;
    Index node;
  };

  void add(Index a, Index b, Index c) {
    entries_.push_back({edge_key(a, b), c});
    entries_.push_back({edge_key(b, c), a});
    entries_.push_back({edge_key(a, c), b});
  }
  // After the last add(), before on().
  void sort() { std::stable_sort(entries_.begin(), entries_.end(), by_edge); }
  // The entries on edge (a, b), in the order their triangles were added.
  std::span<const Entry> on(Index a, Index b) const {
    const auto [first, last] =
        std::equal_range(entries_.begin(), entries_.end(), Entry{edge_key(a, b), 0}, by_edge);
    return {first, last};
  }

 private:
  static bool by_edge(const Entry& x, const Entry& y) { return x.edge < y.edge; }
  std::vector<Entry> entries_;
};

}  // namespace geode::primal::detail
