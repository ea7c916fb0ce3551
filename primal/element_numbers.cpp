#include <geode/primal/element_numbers.hpp>

#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace geode::primal {

std::vector<std::int64_t> hex_numbers(std::span<const int> block, std::span<const Index> hexes,
                                      ElementNumbering numbering) {
  for (Index h : hexes)
    if (h < 0 || index_cast<std::size_t>(h) >= block.size())
      throw std::out_of_range("hex_numbers: hex " + std::to_string(h) + " of " +
                              std::to_string(block.size()));
  std::vector<std::int64_t> out(hexes.size());
  if (numbering.order == ElementOrder::kAsGiven) {
    for (std::size_t i = 0; i < hexes.size(); ++i) out[i] = numbering.base + hexes[i];
    return out;
  }
  if (hexes.empty()) return out;
  // A block's hexes come in runs: the run's end from its start.
  const auto run_end = [&block](std::size_t h) {
    std::size_t end = h + 1;
    while (end < block.size() && block[end] == block[h]) ++end;
    return end;
  };
  // Each block's first number: the hexes of the blocks below it.
  std::map<int, std::int64_t> next;
  for (std::size_t h = 0; h < block.size();) {
    const std::size_t end = run_end(h);
    next[block[h]] += index_cast<std::int64_t>(end - h);
    h = end;
  }
  std::int64_t first = numbering.base;
  for (auto& [id, count] : next) first += std::exchange(count, first);
  // Then the asked hexes in ascending index, each its block's next number, runs at a time up to
  // the highest asked.
  std::vector<std::size_t> asked(hexes.size());
  std::iota(asked.begin(), asked.end(), std::size_t{0});
  std::sort(asked.begin(), asked.end(),
            [&hexes](std::size_t a, std::size_t b) { return hexes[a] < hexes[b]; });
  std::size_t k = 0;
  for (std::size_t h = 0; k < asked.size();) {
    const std::size_t end = run_end(h);
    std::int64_t& number = next[block[h]];
    for (; k < asked.size() && index_cast<std::size_t>(hexes[asked[k]]) < end; ++k)
      out[asked[k]] =
          number + index_cast<std::int64_t>(index_cast<std::size_t>(hexes[asked[k]]) - h);
    number += index_cast<std::int64_t>(end - h);
    h = end;
  }
  return out;
}

}  // namespace geode::primal
