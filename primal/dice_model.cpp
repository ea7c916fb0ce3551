#include "primal/dice_model.hpp"

#include <algorithm>
#include <set>

#include "primal/dice.hpp"
#include "primal/topology.hpp"

namespace geode::primal {

namespace topo = topology;

FaceKey normalized_origin(FaceKey k) {
  std::sort(k.begin(), k.end(), [](Index a, Index b) {
    if (a == kInvalidIndex || b == kInvalidIndex) return b == kInvalidIndex && a != kInvalidIndex;
    return a < b;
  });
  return k;
}

Index DicedModel::add_node(const Point& p, const FaceKey& origin_key) {
  points.push_back(p);
  origin.push_back(origin_key);
  return static_cast<Index>(points.size() - 1);
}

Index DicedModel::find(const FaceKey& key) const {
  const FaceKey k = normalized_origin(key);
  if (k[0] == kInvalidIndex) return kInvalidIndex;
  if (k[1] == kInvalidIndex) return k[0];
  const Index* id = shared.find(k);
  return id ? *id : kInvalidIndex;
}

DicedModel dice_model(const Model& model, std::span<const char> shareable) {
  const Index V = static_cast<Index>(model.points.size());
  DicedModel out;
  out.points = model.points;
  out.origin.resize(V);
  for (Index v = 0; v < V; ++v) out.origin[v] = {v, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::vector<char> share(static_cast<std::size_t>(V), 0);
  {
    std::vector<char> in_hex(static_cast<std::size_t>(V), 0);
    for (const auto& h : model.hexes)
      for (Index v : h) in_hex[v] = 1;
    std::size_t interface_nodes = 0;
    for (const auto& t : model.tets)
      for (Index v : t) share[v] |= in_hex[v];
    for (std::size_t v = 0; v < share.size(); ++v) {
      if (v < shareable.size()) share[v] |= shareable[v];
      interface_nodes += share[v];
    }
    out.shared = KeyMap<4>(8 * interface_nodes);
  }
  auto may_meet = [&](const FaceKey& key) {
    for (Index v : key)
      if (v != kInvalidIndex && !share[v]) return false;
    return true;
  };
  // Diced node -> global node, merging by origin where both parts (or the caller) may meet it.
  auto global_of = [&](const DicedHexMesh& d) {
    std::vector<Index> g(d.mesh.points.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
      if (static_cast<Index>(i) < V) {
        g[i] = static_cast<Index>(i);
        continue;
      }
      const NodeOrigin& o = d.origin[i];
      if (o.kind == NodeOriginKind::kCell) {
        g[i] = out.add_node(d.mesh.points[i]);
        continue;
      }
      const FaceKey key = normalized_origin(o.nodes);
      if (!may_meet(key)) {
        g[i] = out.add_node(d.mesh.points[i], key);
        continue;
      }
      auto [id, inserted] = out.shared.try_emplace(key, kInvalidIndex);
      if (inserted) *id = out.add_node(d.mesh.points[i], key);
      g[i] = *id;
    }
    return g;
  };
  auto take = [&](DicedHexMesh d, std::vector<std::array<Index, 8>>& children,
                  std::vector<Index>& parent) {
    const std::vector<Index> g = global_of(d);
    d.mesh.points = {}, d.origin = {};
    children.resize(d.mesh.hexes.size());
    for (std::size_t c = 0; c < children.size(); ++c)
      for (int k = 0; k < 8; ++k) children[c][k] = g[d.mesh.hexes[c][k]];
    parent = std::move(d.parent);
  };
  take(dice(hex_part(model)), out.hex_children, out.hex_parent);
  take(dice(tet_part(model)), out.tet_children, out.tet_parent);
  return out;
}

std::vector<NodeSet> diced_node_sets(const Model& model, const DicedModel& diced,
                                     std::span<const Index> renumber) {
  std::vector<NodeSet> sets;
  for (const NodeSet& ns : model.node_sets) {
    std::vector<char> in(model.points.size(), 0);
    for (Index v : ns.nodes) in[v] = 1;
    NodeSet o{ns.id, ns.name, {}};
    // With pieces (model.hpp), a node made from nodes of one piece: its key's nodes, sorted.
    std::set<FaceKey> within;
    for (const auto& piece : ns.pieces) {
      const std::size_t n = std::min<std::size_t>(piece.size(), 4);
      for (std::size_t mask = 1; mask < (std::size_t{1} << n); ++mask) {
        FaceKey sub{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
        std::size_t used = 0;
        for (std::size_t k = 0; k < n; ++k)
          if (mask >> k & 1) sub[used++] = piece[k];
        within.insert(normalized_origin(sub));
      }
    }
    for (std::size_t g = 0; g < diced.origin.size() && g < renumber.size(); ++g) {
      if (renumber[g] == kInvalidIndex || diced.origin[g][0] == kInvalidIndex) continue;
      bool all = true;
      for (Index v : diced.origin[g])
        if (v != kInvalidIndex) all = all && in[v];
      if (all && !ns.pieces.empty()) all = within.count(normalized_origin(diced.origin[g])) > 0;
      if (all) o.nodes.push_back(renumber[g]);
    }
    std::sort(o.nodes.begin(), o.nodes.end());
    sets.push_back(std::move(o));
  }
  return sets;
}

std::vector<SideSet> diced_side_sets(const Model& model, const DicedModel& diced,
                                     Index hex_offset, Index tet_offset) {
  std::vector<SideSet> sets;
  if (model.side_sets.empty()) return sets;
  std::vector<std::vector<Index>> hex_children(model.hexes.size()), tet_children(model.tets.size());
  for (std::size_t c = 0; c < diced.hex_parent.size(); ++c)
    hex_children[diced.hex_parent[c]].push_back(static_cast<Index>(c));
  for (std::size_t c = 0; c < diced.tet_parent.size(); ++c)
    tet_children[diced.tet_parent[c]].push_back(static_cast<Index>(c));
  for (const SideSet& ss : model.side_sets) {
    SideSet o{ss.id, ss.name, {}};
    for (const Side& side : ss.sides) {
      const bool is_hex = side.element.kind == ElementKind::Hex;
      std::vector<Index> face;
      if (is_hex) {
        for (int c : topo::kHexFaceCorners[side.face]) face.push_back(model.hexes[side.element.index][c]);
      } else {
        for (int c : topo::kTetFaceCorners[side.face]) face.push_back(model.tets[side.element.index][c]);
      }
      // A diced node lies on the face when every node it was made from does.
      auto on_face = [&](Index node) {
        const FaceKey& og = diced.origin[node];
        if (og[0] == kInvalidIndex) return false;
        for (Index v : og)
          if (v != kInvalidIndex && std::find(face.begin(), face.end(), v) == face.end()) return false;
        return true;
      };
      const auto& children = is_hex ? hex_children[side.element.index] : tet_children[side.element.index];
      const auto& hexes = is_hex ? diced.hex_children : diced.tet_children;
      for (Index c : children)
        for (int f = 0; f < 6; ++f) {
          bool all = true;
          for (int k : topo::kHexFaceCorners[f]) all = all && on_face(hexes[c][k]);
          if (all) o.sides.push_back({{ElementKind::Hex, (is_hex ? hex_offset : tet_offset) + c}, f});
        }
    }
    sets.push_back(std::move(o));
  }
  return sets;
}

}  // namespace geode::primal
