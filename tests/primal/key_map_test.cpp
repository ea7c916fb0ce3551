// primal::KeyMap against std::map on the same keys: through several rehashes, with repeated
// keys (first value kept), keys differing only in order or padding, and absent keys.
#include <doctest/doctest.h>

#include <map>

#include <geode/primal/key_map.hpp>

using namespace geode::primal;

TEST_CASE("KeyMap agrees with std::map through rehashes") {
  KeyMap<4> map;  // starts at 16 slots: grows many times below
  std::map<std::array<Index, 4>, Index> reference;
  Index next = 0;
  for (Index a = 0; a < 40; ++a)
    for (Index b = 0; b < 40; ++b) {
      // Face-like keys (padded with kInvalidIndex) and their permutations are distinct keys.
      for (const std::array<Index, 4> k :
           {std::array<Index, 4>{a, b, a + b, kInvalidIndex},
            std::array<Index, 4>{b, a, a + b, kInvalidIndex},
            std::array<Index, 4>{a, b, kInvalidIndex, kInvalidIndex}}) {
        const auto [slot, inserted] = map.try_emplace(k, next);
        const auto [it, ref_inserted] = reference.try_emplace(k, next);
        CHECK(inserted == ref_inserted);
        CHECK(*slot == it->second);  // a repeated key keeps its first value
        ++next;
      }
    }
  CHECK(map.size() == reference.size());
  for (const auto& [k, v] : reference) {
    const Index* found = map.find(k);
    REQUIRE(found != nullptr);
    CHECK(*found == v);
  }
  CHECK(map.find({41, 0, 41, kInvalidIndex}) == nullptr);
  CHECK(map.find({0, 0, 1, 2}) == nullptr);
  // Values can be updated through the returned slot.
  *map.find({1, 2, 3, kInvalidIndex}) = -7;
  CHECK(*map.find({1, 2, 3, kInvalidIndex}) == -7);
}

TEST_CASE("KeyMap with a size hint never needs to grow for that many keys") {
  KeyMap<2> map(1000);
  for (Index i = 0; i < 1000; ++i) CHECK(map.try_emplace({i, i + 1}, i).second);
  for (Index i = 0; i < 1000; ++i) CHECK(*map.find({i, i + 1}) == i);
  CHECK(map.size() == 1000);
}
