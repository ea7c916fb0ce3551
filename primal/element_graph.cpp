#include <geode/primal/element_graph.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <geode/primal/boundary.hpp>
#include <geode/primal/submodel.hpp>

namespace geode::primal {

namespace {

// Face slots: element e's local face k is slot e * kSlots + k (a division by a constant away
// from its element; a hex has the most faces).
constexpr std::size_t kSlots = 6;

// One use of a face, filed under its lowest node: its other nodes ascending (a triangle's third
// kInvalidIndex) and its slot.
struct FaceUse {
  std::array<Index, 3> rest;
  std::uint32_t slot;
  Index element() const { return index_cast(slot / kSlots); }
  bool operator<(const FaceUse& o) const { return std::tie(rest, slot) < std::tie(o.rest, o.slot); }
};

// Calls f(its nodes, their count, its slot) for every local face of every element, elements in
// flat order (element_offsets).
template <typename F>
void for_each_face(const Model& model, F&& f) {
  std::uint32_t first = 0;  // slot of the element's face 0
  auto kind_faces = [&](const auto& elements, ElementKind kind) {
    const auto& topo = cell_topology(kind);
    for (const auto& corners : elements) {
      for (int k = 0; k < topo.faces; ++k) {
        const topology::CellFace& face = topo.face[index_cast<std::size_t>(k)];
        std::array<Index, 4> nodes{};
        for (int i = 0; i < face.size; ++i)
          nodes[index_cast<std::size_t>(i)] =
              corners[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(i)])];
        f(nodes, index_cast<std::size_t>(face.size), first + index_cast<std::uint32_t>(k));
      }
      first += kSlots;
    }
  };
  static_assert(kElementKinds[0] == ElementKind::kHex && kElementKinds[1] == ElementKind::kTet &&
                kElementKinds[2] == ElementKind::kPyramid &&
                kElementKinds[3] == ElementKind::kWedge);
  kind_faces(model.hexes, ElementKind::kHex);
  kind_faces(model.tets, ElementKind::kTet);
  kind_faces(model.pyramids, ElementKind::kPyramid);
  kind_faces(model.wedges, ElementKind::kWedge);
}

}  // namespace

ElementGraph element_graph(const Model& model) {
  const std::size_t n = element_count(model);
  if (n > std::numeric_limits<std::uint32_t>::max() / kSlots)
    throw std::length_error("element_graph: more than 715 million elements");
  const std::size_t slots = n * kSlots;

  // The face uses bucketed by lowest node (a counting sort), each bucket a few dozen uses paired
  // by sorting it: a hash of every face (primal/key_map.hpp, its table far larger than the
  // caches) took four times as long on 1.8 million elements.
  std::vector<std::size_t> start(model.points.size() + 1, 0);
  for_each_face(model, [&](const std::array<Index, 4>& nodes, std::size_t size, std::uint32_t) {
    const Index low =
        std::min(std::min(nodes[0], nodes[1]), size == 4 ? std::min(nodes[2], nodes[3]) : nodes[2]);
    ++start[index_cast<std::size_t>(low) + 1];
  });
  for (std::size_t v = 0; v < model.points.size(); ++v) start[v + 1] += start[v];
  // Every entry is written below: no zeroing of the largest array.
  const auto uses = std::make_unique_for_overwrite<FaceUse[]>(start.back());
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for_each_face(
        model, [&](const std::array<Index, 4>& nodes, std::size_t size, std::uint32_t slot) {
          const FaceKey key = face_key(std::span<const Index>(nodes.data(), size));
          uses[fill[index_cast<std::size_t>(key[0])]++] = {{key[1], key[2], key[3]}, slot};
        });
  }
  auto bucket = [&](std::size_t v) {
    return std::span<FaceUse>(uses.get() + start[v], start[v + 1] - start[v]);
  };
  // Per slot the element across that face, kInvalidIndex if none (yet).
  std::vector<Index> across(slots, kInvalidIndex);
  std::vector<std::pair<Index, FaceUse>> lonely_quads;  // unpaired: (lowest node, use)
  for (std::size_t v = 0; v < model.points.size(); ++v) {
    auto b = bucket(v);
    std::sort(b.begin(), b.end());
    // A face used more than twice (an invalid model) joins its uses two by two.
    for (std::size_t i = 0; i < b.size(); ++i)
      if (i + 1 < b.size() && b[i].rest == b[i + 1].rest) {
        across[b[i].slot] = b[i + 1].element();
        across[b[i + 1].slot] = b[i].element();
        ++i;
      } else if (b[i].rest[2] != kInvalidIndex) {
        lonely_quads.push_back({index_cast(v), b[i]});
      }
  }
  // An unpaired triangle on 3 nodes of an unpaired quad (filed under the triangle's lowest
  // node): METIS's ncommon = 3 joins them too. A quad may meet two such triangles, so these
  // joins are kept apart from `across`.
  std::vector<std::array<Index, 2>> extra;
  auto find_triangle = [&](Index a, Index b, Index c) -> const FaceUse* {
    const auto s = bucket(index_cast<std::size_t>(a));
    const FaceUse probe{{b, c, kInvalidIndex}, 0};
    for (auto it = std::lower_bound(s.begin(), s.end(), probe);
         it != s.end() && it->rest == probe.rest; ++it)
      if (across[it->slot] == kInvalidIndex) return &*it;
    return nullptr;
  };
  for (const auto& [a, q] : lonely_quads) {
    const Index b = q.rest[0], c = q.rest[1], d = q.rest[2];
    for (const auto& [x, y, z] :
         {std::array{a, b, c}, std::array{a, b, d}, std::array{a, c, d}, std::array{b, c, d}}) {
      const FaceUse* t = find_triangle(x, y, z);
      if (t == nullptr || t->element() == q.element()) continue;
      across[t->slot] = q.element();  // the triangle is taken; the quad may take another
      extra.push_back({q.element(), t->element()});
    }
  }
  // The quad-triangle joins were set on the triangle's slot only: listed from the quad's side.
  std::vector<std::size_t> extra_count(n, 0);
  for (const auto& [quad, tri] : extra) ++extra_count[index_cast<std::size_t>(quad)];
  ElementGraph g;
  g.offset.assign(n + 1, 0);
  for (std::size_t e = 0; e < n; ++e) {
    std::size_t degree = extra_count[e];
    for (std::size_t s = e * kSlots; s < (e + 1) * kSlots; ++s)
      degree += across[s] != kInvalidIndex;
    g.offset[e + 1] = g.offset[e] + degree;
  }
  g.neighbour.resize(g.offset[n]);
  std::vector<std::size_t> fill(n);
  for (std::size_t e = 0; e < n; ++e) {
    std::size_t k = g.offset[e];
    for (std::size_t s = e * kSlots; s < (e + 1) * kSlots; ++s)
      if (across[s] != kInvalidIndex) g.neighbour[k++] = across[s];
    fill[e] = k;
  }
  for (const auto& [quad, tri] : extra) g.neighbour[fill[index_cast<std::size_t>(quad)]++] = tri;
  return g;
}

}  // namespace geode::primal
