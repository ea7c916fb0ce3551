#pragma once
// Union-find over 0..n-1 with path halving. The root of a set is its smallest member, so
// labels derived from roots do not depend on the order of unions.
#include <cstddef>
#include <numeric>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

class DisjointSets {
 public:
  DisjointSets() = default;
  explicit DisjointSets(std::size_t n) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), Index{0});
  }

  // Back to n singletons, reusing the storage (for many small problems in a row).
  void reset(std::size_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), Index{0});
  }

  // Adds a singleton set and returns its element.
  Index add() {
    parent_.push_back(index_cast(parent_.size()));
    return parent_.back();
  }
  Index find(Index x) {
    while (parent_[index_cast<std::size_t>(x)] != x)
      x = parent_[index_cast<std::size_t>(x)] =
          parent_[index_cast<std::size_t>(parent_[index_cast<std::size_t>(x)])];
    return x;
  }
  void unite(Index a, Index b) {
    a = find(a), b = find(b);
    if (a < b) parent_[index_cast<std::size_t>(b)] = a;
    if (b < a) parent_[index_cast<std::size_t>(a)] = b;
  }
  std::size_t size() const { return parent_.size(); }
  // Number of sets.
  std::size_t count() {
    std::size_t n = 0;
    for (std::size_t i = 0; i < parent_.size(); ++i) n += find(index_cast(i)) == index_cast(i);
    return n;
  }

 private:
  std::vector<Index> parent_;
};

}  // namespace geode::primal
