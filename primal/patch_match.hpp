#pragma once
// Correspondence between two quad patches that should be the same surface mesh (a side face of
// one template and the same face of its neighbour, or two faces of one template), found
// topologically from a few nodes known to correspond: positions may differ, connectivity may not.
#include <array>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>

namespace geode::primal {

struct PatchMatch {
  std::unordered_map<int, int> map;  // node of patch A -> node of patch B
  std::string error;                 // empty when the patches correspond
  bool ok() const { return error.empty(); }
};

// Starting from `seeds` (A node, B node), a quad of A with an edge whose two ends are matched
// corresponds to the one unmatched quad of B that has their images as an edge and agrees with
// every match made so far; a quad with several candidates waits for more matches. The result
// is an error when the patches differ in node or quad count, a seed contradicts another, or
// propagation leaves nodes unmatched (seeds too few, or the meshes differ).
PatchMatch match_quad_patches(std::span<const std::array<int, 4>> a,
                              std::span<const std::array<int, 4>> b,
                              std::span<const std::pair<int, int>> seeds);

}  // namespace geode::primal
