#include <geode/stc/surface_chords.hpp>

#include <algorithm>
#include <map>
#include <string>

#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>

namespace geode::stc {

std::vector<SurfaceChord> surface_chords(const std::vector<std::array<primal::Index, 4>>& quads) {
  using primal::Index;
  // Edges numbered by first appearance; each must be in two quads.
  std::map<std::pair<Index, Index>, Index> edge_id;
  std::vector<int> uses;
  std::vector<std::array<Index, 4>> quad_edges(quads.size());
  for (std::size_t q = 0; q < quads.size(); ++q)
    for (std::size_t e = 0; e < 4; ++e) {
      const Index a = quads[q][e], b = quads[q][(e + 1) % 4];
      const auto key = std::minmax(a, b);
      auto [it, fresh] =
          edge_id.emplace(std::make_pair(key.first, key.second), primal::index_cast(uses.size()));
      if (fresh) uses.push_back(0);
      ++uses[primal::index_cast<std::size_t>(it->second)];
      quad_edges[q][e] = it->second;
    }
  for (const auto& [key, id] : edge_id)
    if (uses[primal::index_cast<std::size_t>(id)] != 2)
      throw TopologyError("surface chords: edge " + std::to_string(key.first) + "-" +
                          std::to_string(key.second) + " is in " +
                          std::to_string(uses[primal::index_cast<std::size_t>(id)]) +
                          " quads (expected 2)");
  primal::DisjointSets chords(uses.size());
  for (const auto& e : quad_edges) {
    chords.unite(e[0], e[2]);
    chords.unite(e[1], e[3]);
  }
  // Chords numbered by first appearance over (quad, pass).
  std::map<Index, std::size_t> number;
  std::vector<SurfaceChord> out;
  auto chord_of = [&](Index edge) {
    auto [it, fresh] = number.emplace(chords.find(edge), out.size());
    if (fresh) out.emplace_back();
    return it->second;
  };
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const std::size_t a = chord_of(quad_edges[q][0]);
    out[a].quads.push_back(primal::index_cast(q));
    const std::size_t b = chord_of(quad_edges[q][1]);
    out[b].quads.push_back(primal::index_cast(q));
    if (a == b) out[a].self_crossings.push_back(primal::index_cast(q));
  }
  for (Index e = 0; e < primal::index_cast(uses.size()); ++e) ++out[chord_of(e)].edges;
  return out;
}

}  // namespace geode::stc
