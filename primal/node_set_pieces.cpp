#include <geode/primal/node_set_pieces.hpp>

#include <algorithm>
#include <unordered_map>

#include <geode/primal/boundary.hpp>

namespace geode::primal {

void infer_boundary_node_set_pieces(Model& model) {
  for (NodeSet& ns : model.node_sets) {
    if (ns.nodes.empty() ||
        std::any_of(ns.pieces.begin(), ns.pieces.end(), [](const auto& p) { return p.size() > 1; }))
      continue;
    std::vector<char> in(model.points.size(), 0);
    for (Index v : ns.nodes) in[index_cast<std::size_t>(v)] = 1;
    // The faces with a node in the set, each with its uses and its nodes (first use's order).
    struct Face {
      int uses = 0;
      std::vector<Index> nodes;
    };
    std::unordered_map<FaceKey, Face, IndexArrayHash> faces;
    for (ElementKind kind : kElementKinds) {
      const int n = cell_topology(kind).faces;
      for (std::size_t e = 0; e < element_count(model, kind); ++e)
        for (int f = 0; f < n; ++f) {
          std::vector<Index> nodes = element_face(model, {{kind, index_cast(e)}, f});
          if (std::none_of(nodes.begin(), nodes.end(),
                           [&](Index v) { return in[index_cast<std::size_t>(v)]; }))
            continue;
          Face& face = faces[face_key(nodes)];
          if (face.uses++ == 0) face.nodes = std::move(nodes);
        }
    }
    std::vector<char> on_boundary(model.points.size(), 0), covered(model.points.size(), 0);
    std::vector<std::vector<Index>> pieces;
    for (const auto& [key, face] : faces) {
      if (face.uses != 1) continue;
      for (Index v : face.nodes) on_boundary[index_cast<std::size_t>(v)] = 1;
      if (std::all_of(face.nodes.begin(), face.nodes.end(),
                      [&](Index v) { return in[index_cast<std::size_t>(v)]; })) {
        pieces.push_back(face.nodes);
        for (Index v : face.nodes) covered[index_cast<std::size_t>(v)] = 1;
      }
    }
    if (std::any_of(ns.nodes.begin(), ns.nodes.end(),
                    [&](Index v) { return !on_boundary[index_cast<std::size_t>(v)]; }))
      continue;
    // In a fixed order (the map's is not): by their sorted nodes.
    std::sort(pieces.begin(), pieces.end(),
              [](const auto& a, const auto& b) { return face_key(a) < face_key(b); });
    for (Index v : ns.nodes)
      if (!covered[index_cast<std::size_t>(v)]) pieces.push_back({v});
    ns.pieces = std::move(pieces);
  }
}

}  // namespace geode::primal
