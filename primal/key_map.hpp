#pragma once
// A flat hash map from an edge / face key (std::array<Index, N>, primal/boundary.hpp) to an
// Index: open addressing with linear probing in two plain arrays. It replaces
// std::unordered_map where millions of keys are looked up (dicing, interface detection,
// conform's merge by node origin): no allocation per entry and one probe sequence in
// contiguous memory instead of a bucket list. Keys whose first entry is kInvalidIndex cannot
// be stored (that value marks an empty slot). No erase.
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

template <std::size_t N>
class KeyMap {
 public:
  using Key = std::array<Index, N>;

  explicit KeyMap(std::size_t expected = 0) { rehash(capacity_for(expected)); }

  std::size_t size() const { return size_; }

  // Inserts (key, value) unless key is present; returns the stored value's slot and whether it
  // was inserted.
  std::pair<Index*, bool> try_emplace(const Key& key, Index value) {
    assert(key[0] != kInvalidIndex);
    if (2 * (size_ + 1) > keys_.size()) rehash(2 * keys_.size());
    std::size_t i = slot(key);
    while (keys_[i][0] != kInvalidIndex) {
      if (same(keys_[i], key)) return {&values_[i], false};
      i = (i + 1) & mask_;
    }
    keys_[i] = key;
    values_[i] = value;
    ++size_;
    return {&values_[i], true};
  }

  // The value stored for key, or nullptr.
  const Index* find(const Key& key) const {
    std::size_t i = slot(key);
    while (keys_[i][0] != kInvalidIndex) {
      if (same(keys_[i], key)) return &values_[i];
      i = (i + 1) & mask_;
    }
    return nullptr;
  }
  Index* find(const Key& key) {
    return const_cast<Index*>(static_cast<const KeyMap&>(*this).find(key));
  }

 private:
  // Entry by entry: std::array's operator== compiles to a call of memcmp, which was 3 % of a
  // conform run's CPU.
  static bool same(const Key& a, const Key& b) {
    for (std::size_t k = 0; k < N; ++k)
      if (a[k] != b[k]) return false;
    return true;
  }

  static std::size_t capacity_for(std::size_t n) {
    std::size_t c = 16;
    while (c < 2 * n) c *= 2;
    return c;
  }

  std::size_t slot(const Key& key) const {
    // Multiply-xorshift mixing of the packed entries (splitmix64's finaliser).
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (Index v : key) {
      h ^= static_cast<std::uint32_t>(v);
      h *= 0xbf58476d1ce4e5b9ull;
      h ^= h >> 31;
    }
    h *= 0x94d049bb133111ebull;
    h ^= h >> 29;
    return index_cast<std::size_t>(h) & mask_;
  }

  void rehash(std::size_t capacity) {
    std::vector<Key> old_keys = std::move(keys_);
    std::vector<Index> old_values = std::move(values_);
    Key empty;
    empty.fill(kInvalidIndex);
    keys_.assign(capacity, empty);
    values_.assign(capacity, kInvalidIndex);
    mask_ = capacity - 1;
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i)
      if (old_keys[i][0] != kInvalidIndex) {
        std::size_t j = slot(old_keys[i]);
        while (keys_[j][0] != kInvalidIndex) j = (j + 1) & mask_;
        keys_[j] = old_keys[i];
        values_[j] = old_values[i];
        ++size_;
      }
  }

  std::vector<Key> keys_;
  std::vector<Index> values_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace geode::primal
