#include <geode/primal/split_wedges.hpp>

#include <algorithm>
#include <optional>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/split_cells.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/key_map.hpp>

namespace geode::primal {

namespace {

using Tets = std::array<std::array<int, 4>, 3>;  // in local corners

// Per choice of the three quad diagonals (bit q: face q's), the three tets that have them, or
// none (the two choices going round the wedge). Made from one decomposition by the wedge's
// twelve symmetries (the triangle's six, with and without swapping the triangles), each tet
// oriented positively in the reference wedge.
const std::array<std::optional<Tets>, 8>& decompositions() {
  static const auto table = [] {
    constexpr std::array<std::array<double, 3>, 6> kRef{
        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}}};
    const auto& faces = cell_topology(ElementKind::kWedge).face;
    constexpr Tets kChain{{{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}}};
    std::array<std::optional<Tets>, 8> out;
    std::array<int, 3> sigma{0, 1, 2};
    do {
      for (int flip = 0; flip < 2; ++flip) {
        auto map = [&](int c) {
          const int m =
              c < 3 ? sigma[index_cast<std::size_t>(c)] : sigma[index_cast<std::size_t>(c - 3)] + 3;
          return flip ? (m + 3) % 6 : m;
        };
        Tets tets{};
        for (std::size_t t = 0; t < 3; ++t) {
          for (std::size_t k = 0; k < 4; ++k) tets[t][k] = map(kChain[t][k]);
          auto at = [&](std::size_t k) { return kRef[index_cast<std::size_t>(tets[t][k])]; };
          const auto sub = [&](std::size_t a) {
            return std::array<double, 3>{at(a)[0] - at(0)[0], at(a)[1] - at(0)[1],
                                         at(a)[2] - at(0)[2]};
          };
          const auto a = sub(1), b = sub(2), c = sub(3);
          const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) -
                             a[1] * (b[0] * c[2] - b[2] * c[0]) +
                             a[2] * (b[0] * c[1] - b[1] * c[0]);
          if (det < 0) std::swap(tets[t][2], tets[t][3]);
        }
        unsigned bits = 0;
        for (std::size_t q = 0; q < 3; ++q) {
          const auto& f = faces[q].corners;
          const bool first = std::any_of(tets.begin(), tets.end(), [&](const auto& t) {
            return std::count(t.begin(), t.end(), f[0]) && std::count(t.begin(), t.end(), f[2]);
          });
          bits |= (first ? 0u : 1u) << q;
        }
        out[bits] = tets;
      }
    } while (std::next_permutation(sigma.begin(), sigma.end()));
    return out;
  }();
  return table;
}

}  // namespace

std::array<std::array<Index, 4>, 3> wedge_tets(const Model& model, Index wedge,
                                               const std::array<int, 3>& diagonal) {
  unsigned bits = 0;
  for (std::size_t q = 0; q < 3; ++q) bits |= (diagonal[q] ? 1u : 0u) << q;
  const auto& tets = decompositions()[bits];
  if (!tets)
    throw TopologyError(describe_element(model, {ElementKind::kWedge, wedge}) +
                        ": the diagonals the tets on its quad faces give it go round it, so no "
                        "three tets split it");
  const auto& c = model.wedges[index_cast<std::size_t>(wedge)];
  std::array<std::array<Index, 4>, 3> out{};
  for (std::size_t t = 0; t < 3; ++t)
    for (std::size_t k = 0; k < 4; ++k) out[t][k] = c[index_cast<std::size_t>((*tets)[t][k])];
  return out;
}

std::vector<Index> wedge_pieces(const Model& model, std::span<const Index> seeds) {
  const std::size_t n = model.wedges.size();
  DisjointSets sets(n);
  KeyMap<4> first(5 * n);  // a wedge face -> the first wedge on it
  const auto& topo = cell_topology(ElementKind::kWedge);
  for (std::size_t w = 0; w < n; ++w)
    for (int face = 0; face < topo.faces; ++face) {  // the table holds a sixth, empty face
      const auto& f = topo.face[index_cast<std::size_t>(face)];
      std::array<Index, 4> nodes{};
      for (int i = 0; i < f.size; ++i)
        nodes[index_cast<std::size_t>(i)] =
            model.wedges[w][index_cast<std::size_t>(f.corners[index_cast<std::size_t>(i)])];
      const auto [id, fresh] = first.try_emplace(
          face_key(std::span<const Index>(nodes.data(), index_cast<std::size_t>(f.size))),
          index_cast(w));
      if (!fresh) sets.unite(*id, index_cast(w));
    }
  std::vector<char> chosen(n, 0);
  for (Index s : seeds) chosen[index_cast<std::size_t>(sets.find(s))] = 1;
  std::vector<Index> out;
  for (std::size_t w = 0; w < n; ++w)
    if (chosen[index_cast<std::size_t>(sets.find(index_cast(w)))]) out.push_back(index_cast(w));
  return out;
}

Model split_wedges(const Model& model, std::span<const Index> wedges) {
  Model m = model;
  if (wedges.empty()) return m;
  const auto& faces = cell_topology(ElementKind::kWedge).face;
  // The triangles of the tets already there: a quad face with two of them has their diagonal.
  const KeyMap<4> triangles = detail::tet_triangles(model);
  std::vector<char> split(model.wedges.size(), 0);
  for (Index w : wedges) split[index_cast<std::size_t>(w)] = 1;

  detail::tets_with_blocks_and_ids(m);
  m.wedges.clear(), m.wedge_block.clear(), m.wedge_ids.clear();
  std::vector<Index> first_tet(model.wedges.size(), kInvalidIndex),
      kept(model.wedges.size(), kInvalidIndex);
  for (std::size_t w = 0; w < model.wedges.size(); ++w) {
    const ElementRef ref{ElementKind::kWedge, index_cast(w)};
    if (!split[w]) {
      kept[w] = index_cast(m.wedges.size());
      add_element(m, ElementKind::kWedge, model.wedges[w], block_of(model, ref),
                  element_id(model, ref));
      continue;
    }
    const auto& c = model.wedges[w];
    std::array<int, 3> diagonal{};
    for (std::size_t q = 0; q < 3; ++q) {
      std::array<Index, 4> v{};
      for (std::size_t i = 0; i < 4; ++i) v[i] = c[index_cast<std::size_t>(faces[q].corners[i])];
      diagonal[q] = detail::tets_diagonal(triangles, v);
      if (diagonal[q] < 0) diagonal[q] = detail::lowest_node_diagonal(v);
    }
    first_tet[w] = index_cast(m.tets.size());
    for (const auto& t : wedge_tets(model, index_cast(w), diagonal))
      add_element(m, ElementKind::kTet, t, block_of(model, ref), element_id(model, ref));
  }
  // Sides of split wedges: the faces of its three tets whose nodes all lie on the wedge's face.
  rewrite_sides(m, [&](const Side& s, std::vector<Side>& sides) {
    const auto w = index_cast<std::size_t>(s.element.index);
    if (s.element.kind != ElementKind::kWedge) {
      sides.push_back(s);
    } else if (!split[w]) {
      sides.push_back({{ElementKind::kWedge, kept[w]}, s.face});
    } else {
      const auto on = tet_sides_on(m, first_tet[w], 3, element_face(model, s));
      sides.insert(sides.end(), on.begin(), on.end());
    }
  });
  return m;
}

}  // namespace geode::primal
