#pragma once
// Freeing a container's storage now, where a stage is done with it. `v = {}` does not free a
// std::vector: it picks the initializer_list assignment, which empties it and keeps its
// capacity (the memory stays resident until the vector itself goes).
#include <utility>

namespace geode::primal {

template <class Container>
void release(Container& c) {
  Container().swap(c);
}

template <class First, class... Rest>
void release(First& first, Rest&... rest) {
  release(first);
  (release(rest), ...);
}

}  // namespace geode::primal
