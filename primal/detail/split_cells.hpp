#pragma once
// What splitting cells into tets shares (split_wedges.cpp, split_hexes.cpp): the triangles of the
// tets a model has, the diagonal they give a quad face, the lowest-node diagonal where they give
// none (so that cells split on both sides of a face agree: Dompierre et al., IMR 1999), and a
// copy of the model ready to take the new tets after its own.
#include <algorithm>
#include <array>
#include <cstdint>

#include <geode/primal/key_map.hpp>
#include <geode/primal/model.hpp>

namespace geode::primal::detail {

// Every face of the tets of `model`, by its nodes, to the first tet that has it.
inline KeyMap<4> tet_triangles(const Model& model) {
  KeyMap<4> triangles(4 * model.tets.size());
  for (std::size_t i = 0; i < model.tets.size(); ++i)
    for (const auto& f : topology::kTetFaceCorners) {
      const auto& t = model.tets[i];
      const std::array<Index, 3> tri{t[index_cast<std::size_t>(f[0])],
                                     t[index_cast<std::size_t>(f[1])],
                                     t[index_cast<std::size_t>(f[2])]};
      triangles.try_emplace(face_key(tri), index_cast(i));
    }
  return triangles;
}

// The diagonal the tets of `triangles` give quad face v (its nodes in cyclic order): 0 through
// v[0] and v[2], 1 through v[1] and v[3], -1 when no two of them cover it.
inline int tets_diagonal(const KeyMap<4>& triangles, const std::array<Index, 4>& v) {
  auto has = [&](Index a, Index b, Index c) {
    return triangles.find(face_key(std::array<Index, 3>{a, b, c})) != nullptr;
  };
  if (has(v[0], v[1], v[2]) && has(v[0], v[2], v[3])) return 0;
  if (has(v[0], v[1], v[3]) && has(v[1], v[2], v[3])) return 1;
  return -1;
}

// The diagonal through quad face v's lowest node: 0 (v[0] or v[2] lowest) or 1.
inline int lowest_node_diagonal(const std::array<Index, 4>& v) {
  return index_cast<int>(std::min_element(v.begin(), v.end()) - v.begin()) % 2;
}

// `m` (a copy of a model) with a block and a file id for each of its tets (the tet default
// block, ids 1..n, where it had none), so that tets split from other cells can follow them.
inline void tets_with_blocks_and_ids(Model& m) {
  if (m.tet_block.empty()) m.tet_block.assign(m.tets.size(), default_block(ElementKind::kTet));
  if (m.tet_ids.empty())
    for (std::size_t t = 0; t < m.tets.size(); ++t)
      m.tet_ids.push_back(static_cast<std::int64_t>(t) + 1);
}

}  // namespace geode::primal::detail
