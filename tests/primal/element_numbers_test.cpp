// hex_numbers: the numbers a file gives an all-hex model's hexes, by blocks in ascending id
// (Exodus, .msh) or as given (VTK); tests/io/formats_test.cpp checks them against the writers.
#include <doctest/doctest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include <geode/primal/element_numbers.hpp>

using namespace geode::primal;

TEST_CASE("hex_numbers: by block, a block's runs joined in model order; as given, index + base") {
  struct Case {
    std::vector<int> block;
    std::vector<Index> asked;
    ElementNumbering numbering;
    std::vector<std::int64_t> expected;
  };
  const std::vector<int> mixed{3, 3, 1, 2, 2, 1, 3, 1};  // 1: hexes 2 5 7; 2: 3 4; 3: 0 1 6
  const std::vector<Case> cases{
      {mixed, {0, 1, 2, 3, 4, 5, 6, 7}, {}, {6, 7, 1, 4, 5, 2, 8, 3}},
      {mixed, {7, 0, 4}, {}, {3, 6, 5}},  // any order, answered in it
      {mixed, {6, 6}, {ElementOrder::kByBlock, 0}, {7, 7}},
      {mixed, {7, 0, 4}, {ElementOrder::kAsGiven, 0}, {7, 0, 4}},
      {mixed, {7, 0, 4}, {ElementOrder::kAsGiven, 1}, {8, 1, 5}},
      {{5, 5, 5}, {2, 0}, {}, {3, 1}},  // one block: index + 1
      {mixed, {}, {}, {}},
  };
  for (const Case& c : cases) CHECK(hex_numbers(c.block, c.asked, c.numbering) == c.expected);
  CHECK_THROWS_AS(hex_numbers(mixed, std::vector<Index>{8}, {}), std::out_of_range);
  CHECK_THROWS_AS(hex_numbers(mixed, std::vector<Index>{-1}, {}), std::out_of_range);
}
