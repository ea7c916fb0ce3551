#include <geode/primal/node_set_pieces.hpp>

#include <algorithm>
#include <array>

#include <geode/primal/boundary.hpp>
#include <geode/primal/key_map.hpp>

namespace geode::primal {

void infer_boundary_node_set_pieces(Model& model) {
  for (NodeSet& ns : model.node_sets) {
    if (ns.nodes.empty() ||
        std::any_of(ns.pieces.begin(), ns.pieces.end(), [](const auto& p) { return p.size() > 1; }))
      continue;
    std::vector<char> in(model.points.size(), 0);
    for (Index v : ns.nodes) in[index_cast<std::size_t>(v)] = 1;
    const auto set = [&](Index v) { return in[index_cast<std::size_t>(v)] != 0; };
    // The faces with a node in the set, each once with its uses and its nodes (first use's
    // order), read off the topology table: the whole input's faces pass here, so no face is
    // copied or hashed unless it touches the set.
    struct Face {
      int uses = 0;
      int size = 0;
      std::array<Index, 4> nodes{};
    };
    std::vector<Face> faces;
    KeyMap<4> index;
    for (ElementKind kind : kElementKinds) {
      const auto& topo = cell_topology(kind);
      for (std::size_t e = 0; e < element_count(model, kind); ++e) {
        const auto corners = element_corners(model, {kind, index_cast(e)});
        for (int f = 0; f < topo.faces; ++f) {
          const topology::CellFace& cf = topo.face[index_cast<std::size_t>(f)];
          std::array<Index, 4> nodes{};
          bool touches = false;
          for (int k = 0; k < cf.size; ++k) {
            nodes[index_cast<std::size_t>(k)] =
                corners[index_cast<std::size_t>(cf.corners[index_cast<std::size_t>(k)])];
            touches = touches || set(nodes[index_cast<std::size_t>(k)]);
          }
          if (!touches) continue;
          const std::span<const Index> face(nodes.data(), index_cast<std::size_t>(cf.size));
          const auto [slot, added] = index.try_emplace(face_key(face), index_cast(faces.size()));
          if (added) faces.push_back({0, cf.size, nodes});
          ++faces[index_cast<std::size_t>(*slot)].uses;
        }
      }
    }
    std::vector<char> on_boundary(model.points.size(), 0), covered(model.points.size(), 0);
    std::vector<std::vector<Index>> pieces;
    for (const Face& face : faces) {  // in order of first use: deterministic
      if (face.uses != 1) continue;
      const std::span<const Index> nodes(face.nodes.data(), index_cast<std::size_t>(face.size));
      for (Index v : nodes) on_boundary[index_cast<std::size_t>(v)] = 1;
      if (std::all_of(nodes.begin(), nodes.end(), set)) {
        pieces.emplace_back(nodes.begin(), nodes.end());
        for (Index v : nodes) covered[index_cast<std::size_t>(v)] = 1;
      }
    }
    if (std::any_of(ns.nodes.begin(), ns.nodes.end(),
                    [&](Index v) { return !on_boundary[index_cast<std::size_t>(v)]; }))
      continue;
    for (Index v : ns.nodes)
      if (!covered[index_cast<std::size_t>(v)]) pieces.push_back({v});
    ns.pieces = std::move(pieces);
  }
}

}  // namespace geode::primal
