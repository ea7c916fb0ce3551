#include <geode/primal/submodel.hpp>

#include <algorithm>
#include <functional>

namespace geode::primal {

std::array<std::size_t, 5> element_offsets(const Model& model) {
  std::array<std::size_t, 5> o{};
  for (std::size_t k = 0; k < kElementKinds.size(); ++k)
    o[k + 1] = o[k] + element_count(model, kElementKinds[k]);
  return o;
}

namespace {

template <std::size_t N>
void take(const std::vector<std::array<Index, N>>& from, const std::vector<int>& block,
          const std::vector<std::int64_t>& ids, std::span<const Index> elements,
          std::span<const Index> renumber, std::vector<std::array<Index, N>>& to,
          std::vector<int>& to_block, std::vector<std::int64_t>& to_ids,
          const std::function<std::int64_t(Index)>& file_id) {
  to.reserve(elements.size());
  for (Index e : elements) {
    std::array<Index, N> c = from[index_cast<std::size_t>(e)];
    for (Index& v : c) v = renumber[index_cast<std::size_t>(v)];
    to.push_back(c);
    if (!block.empty()) to_block.push_back(block[index_cast<std::size_t>(e)]);
    to_ids.push_back(ids.empty() ? file_id(e) : ids[index_cast<std::size_t>(e)]);
  }
}

}  // namespace

Submodel extract_submodel(const Model& model, std::span<const char> keep) {
  Submodel s;
  const auto offsets = element_offsets(model);
  std::vector<Index> renumber(model.points.size(), kInvalidIndex);
  for (std::size_t k = 0; k < kElementKinds.size(); ++k) {
    const ElementKind kind = kElementKinds[k];
    for (std::size_t e = 0; e < element_count(model, kind); ++e) {
      if (!keep[offsets[k] + e]) continue;
      s.element[k].push_back(index_cast(e));
      for (Index v : element_corners(model, {kind, index_cast(e)}))
        renumber[index_cast<std::size_t>(v)] = 0;
    }
  }
  for (std::size_t v = 0; v < renumber.size(); ++v)
    if (renumber[v] == 0) {
      renumber[v] = index_cast(s.node.size());
      s.node.push_back(index_cast(v));
    }
  Model& m = s.model;
  m.points.reserve(s.node.size());
  for (Index v : s.node) {
    m.points.push_back(model.points[index_cast<std::size_t>(v)]);
    // The file's ids, so that messages name the model's nodes, not the submodel's.
    m.node_ids.push_back(model.node_ids.empty() ? v + 1
                                                : model.node_ids[index_cast<std::size_t>(v)]);
  }
  take(model.hexes, model.hex_block, model.hex_ids, s.element[0], renumber, m.hexes, m.hex_block,
       m.hex_ids, [&](Index e) {
         return element_id(model, {ElementKind::kHex, e});
       });
  take(model.tets, model.tet_block, model.tet_ids, s.element[1], renumber, m.tets, m.tet_block,
       m.tet_ids, [&](Index e) {
         return element_id(model, {ElementKind::kTet, e});
       });
  take(model.pyramids, model.pyramid_block, model.pyramid_ids, s.element[2], renumber, m.pyramids,
       m.pyramid_block, m.pyramid_ids, [&](Index e) {
         return element_id(model, {ElementKind::kPyramid, e});
       });
  take(model.wedges, model.wedge_block, model.wedge_ids, s.element[3], renumber, m.wedges,
       m.wedge_block, m.wedge_ids, [&](Index e) {
         return element_id(model, {ElementKind::kWedge, e});
       });
  m.block_names = model.block_names;
  for (const NodeSet& ns : model.node_sets) {
    NodeSet o{ns.id, ns.name, {}};
    for (Index v : ns.nodes)
      if (renumber[index_cast<std::size_t>(v)] != kInvalidIndex)
        o.nodes.push_back(renumber[index_cast<std::size_t>(v)]);
    // A piece keeps the nodes of its first four (those dicing reads) that are here.
    for (const auto& piece : ns.pieces) {
      std::vector<Index> p;
      for (std::size_t k = 0; k < std::min<std::size_t>(piece.size(), 4); ++k)
        if (renumber[index_cast<std::size_t>(piece[k])] != kInvalidIndex)
          p.push_back(renumber[index_cast<std::size_t>(piece[k])]);
      if (!p.empty()) o.pieces.push_back(std::move(p));
    }
    m.node_sets.push_back(std::move(o));
  }
  // Per kind: model element -> submodel element, for the side sets.
  std::array<std::vector<Index>, 4> local;
  for (std::size_t k = 0; k < kElementKinds.size(); ++k) {
    local[k].assign(element_count(model, kElementKinds[k]), kInvalidIndex);
    for (std::size_t i = 0; i < s.element[k].size(); ++i)
      local[k][index_cast<std::size_t>(s.element[k][i])] = index_cast(i);
  }
  for (const SideSet& ss : model.side_sets) {
    SideSet o{ss.id, ss.name, {}};
    for (const Side& side : ss.sides) {
      const auto k = static_cast<std::size_t>(side.element.kind);
      const Index e = local[k][index_cast<std::size_t>(side.element.index)];
      if (e != kInvalidIndex) o.sides.push_back({{side.element.kind, e}, side.face});
    }
    m.side_sets.push_back(std::move(o));
  }
  return s;
}

}  // namespace geode::primal
