#pragma once
// What the validity and realizability checks (validity.cpp, validity_local.cpp,
// realizability.cpp) ask first of a cell's node numbers: all of them nodes of the mesh, none
// twice.
#include <algorithm>
#include <array>
#include <cstddef>

#include <geode/primal/mesh.hpp>

namespace geode::primal::detail {

// Every node number in [0, n).
template <std::size_t N>
bool in_range(const std::array<Index, N>& a, std::size_t n) {
  return std::all_of(a.begin(), a.end(),
                     [n](Index v) { return v >= 0 && index_cast<std::size_t>(v) < n; });
}

// Some node number twice.
template <std::size_t N>
bool has_repeated(const std::array<Index, N>& a) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j)
      if (a[i] == a[j]) return true;
  return false;
}

}  // namespace geode::primal::detail
