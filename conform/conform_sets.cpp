// conform()'s node and side sets (detail/conformer.hpp): where the buffer layer moved one copy of
// each interface node into its part, a set keeps the places it named. A set on the interface stays
// on it (the copy that stayed, the geode hexes' faces there), and a set on a surface crossing the
// interface (a boundary face of both parts) takes the buffer layer's strip of it too (the moved
// copies, the template nodes and faces on the buffer hexes' side faces).
#include <geode/conform/detail/conformer.hpp>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include <geode/primal/boundary.hpp>

namespace geode::conform::detail {

namespace {

namespace topo = primal::topology;
using primal::FaceKey;

Point face_normal(const std::vector<Point>& p, std::span<const Index> f) {
  const auto at = [&](std::size_t i) { return p[primal::index_cast<std::size_t>(f[i])]; };
  return f.size() == 4 ? Point((at(2) - at(0)).cross(at(3) - at(1)))
                       : Point((at(1) - at(0)).cross(at(2) - at(0)));
}

}  // namespace

// The moving copy of an interface node is in a node set when the set goes on into the moving
// part there: a node of the set beside it, across an edge of a moving-part element, that is not
// on the interface (a boundary face or curve running across the interface, along which the copy
// slid). Otherwise the set lies on the interface there, and only the copy that stayed keeps its
// place. Pieces (model.hpp) are given for both copies, and for the buffer hex edge or side face
// between them, so that the template nodes made there (side_origin_) follow the same rule.
primal::Model Conformer::node_set_model() const {
  const primal::Model& lm = layer_.model;
  const std::vector<Index>& top = layer_.top_node;
  primal::Model sets;
  sets.points.resize(lm.points.size());
  sets.node_sets = lm.node_sets;
  if (sets.node_sets.empty()) return sets;
  const bool hex_moves = res_.buffer_side == BufferSide::kHex;
  const auto dup = [&](Index v) {
    const auto i = primal::index_cast<std::size_t>(v);
    return i < top.size() ? top[i] : kInvalidIndex;
  };
  std::vector<Index> moving_copy_of(lm.points.size(), kInvalidIndex);
  std::vector<char> on_interface(lm.points.size(), 0);
  for (std::size_t v = 0; v < top.size(); ++v)
    if (top[v] != kInvalidIndex) {
      const Index iv = primal::index_cast(v);
      moving_copy_of[primal::index_cast<std::size_t>(hex_moves ? iv : top[v])] = iv;
      on_interface[v] = on_interface[primal::index_cast<std::size_t>(top[v])] = 1;
    }
  // (interface node, a neighbour off the interface across an edge of a moving-part element)
  std::vector<std::pair<Index, Index>> beside;
  for (primal::ElementKind kind : primal::kElementKinds) {
    const auto& t = primal::cell_topology(kind);
    for (std::size_t e = 0; e < primal::element_count(lm, kind); ++e) {
      const auto c = primal::element_corners(lm, {kind, primal::index_cast(e)});
      for (int k = 0; k < t.edges; ++k) {
        const Index a = c[primal::index_cast<std::size_t>(t.edge[k][0])],
                    b = c[primal::index_cast<std::size_t>(t.edge[k][1])];
        for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
          const Index v = moving_copy_of[primal::index_cast<std::size_t>(x)];
          if (v != kInvalidIndex && !on_interface[primal::index_cast<std::size_t>(y)])
            beside.push_back({v, y});
        }
      }
    }
  }
  std::sort(beside.begin(), beside.end());
  beside.erase(std::unique(beside.begin(), beside.end()), beside.end());
  for (primal::NodeSet& ns : sets.node_sets) {
    std::vector<char> in(lm.points.size(), 0);
    for (Index v : ns.nodes) in[primal::index_cast<std::size_t>(v)] = 1;
    std::vector<Index> nodes;
    for (Index v : ns.nodes) {
      const Index d = dup(v);
      if (d == kInvalidIndex) {
        nodes.push_back(v);
        continue;
      }
      auto it = std::lower_bound(beside.begin(), beside.end(), std::pair{v, Index{0}});
      bool goes_on = false;
      for (; it != beside.end() && it->first == v && !goes_on; ++it)
        goes_on = in[primal::index_cast<std::size_t>(it->second)];
      nodes.push_back(hex_moves ? d : v);  // the copy that stayed
      if (goes_on) nodes.push_back(hex_moves ? v : d);
    }
    ns.nodes = std::move(nodes);
    const std::size_t given = ns.pieces.size();
    for (std::size_t p = 0; p < given; ++p) {
      std::vector<Index> tet_side = ns.pieces[p], between;
      for (Index& v : tet_side)
        if (const Index d = dup(v); d != kInvalidIndex) {
          between.push_back(v), between.push_back(d);
          v = d;
        }
      if (between.empty()) continue;
      ns.pieces.push_back(std::move(tet_side));
      if (between.size() <= 4) ns.pieces.push_back(std::move(between));
    }
  }
  return sets;
}

// The output's side sets: each input side's diced children (primal::diced_side_sets), and where
// the buffer layer changed the surface:
// - a buffer hex whose moving-side faces (the hex part's quad, or the tet part's triangles,
//   before they moved) are all in a set, with its geode hexes in the block of the element they
//   were carved from (no --geode-block): the block's face is now the geode hexes' faces on the
//   side that stayed, which replace those sides;
// - a buffer hex side face whose edge on the moving side is shared with a face of a set lying
//   on the same surface (a boundary or block face running across the interface): its geode
//   hexes' faces there join the set; where two buffer hexes share the side face, those of the
//   one carved from the set face's block if the two were carved from two blocks, else of the
//   one carved from the set face's own element.
void Conformer::carry_side_sets() {
  primal::Model& lm = layer_.model;
  side_sets_.clear();
  if (lm.side_sets.empty()) return;
  const std::size_t nb = layer_.hexes.size();
  const bool hex_moves = res_.buffer_side == BufferSide::kHex;
  std::vector<Index> first(nb + 1, primal::index_cast(diced_.hex_children.size()));
  for (std::size_t b = 0; b < nb; ++b)
    first[b + 1] = first[b] + primal::index_cast(ref(b).tpl.hex.hexes.size());
  const auto geode_faces = [&](std::size_t b, int face, std::vector<primal::Side>& out) {
    for (const auto& [h, f] : ref(b).faces_on[primal::index_cast<std::size_t>(face)])
      out.push_back({{primal::ElementKind::kHex, first[b] + h}, f});
  };
  const auto corners = [&](std::size_t b, std::initializer_list<int> which) {
    std::vector<Index> v;
    for (int c : which) v.push_back(layer_.hexes[b].corners[primal::index_cast<std::size_t>(c)]);
    return v;
  };
  // Each buffer hex's faces on the moving side, and the side faces two buffer hexes share.
  std::unordered_map<FaceKey, std::size_t, primal::IndexArrayHash> moving_face;
  std::vector<std::size_t> moving_faces(nb, 0);
  std::unordered_map<FaceKey, std::vector<std::size_t>, primal::IndexArrayHash> side_owners;
  for (std::size_t b = 0; b < nb; ++b) {
    const BufferHex& bh = layer_.hexes[b];
    std::vector<std::vector<Index>> faces;
    if (hex_moves) {
      faces.push_back(corners(b, {0, 1, 2, 3}));
    } else if (bh.centre != kInvalidIndex) {
      for (int i = 0; i < 4; ++i) {
        std::vector<Index> f = corners(b, {4 + i, 4 + (i + 1) % 4});
        f.push_back(bh.centre);
        faces.push_back(f);
      }
    } else {
      std::vector<int> others;
      for (int c = 4; c < 8; ++c)
        if (c != bh.diagonal[0] && c != bh.diagonal[1]) others.push_back(c);
      for (int o : others) faces.push_back(corners(b, {bh.diagonal[0], bh.diagonal[1], o}));
    }
    moving_faces[b] = faces.size();
    for (const auto& f : faces) moving_face[primal::face_key(f)] = b;
    for (int k = 0; k < 4; ++k) {
      std::vector<Index> f;
      for (int c : topo::kHexFaceCorners[k])
        f.push_back(bh.corners[primal::index_cast<std::size_t>(c)]);
      side_owners[primal::face_key(f)].push_back(b);
    }
  }
  std::vector<std::vector<primal::Side>> added(lm.side_sets.size());
  for (std::size_t s = 0; s < lm.side_sets.size(); ++s) {
    std::vector<primal::Side>& sides = lm.side_sets[s].sides;
    std::vector<std::vector<Index>> face(sides.size());
    std::map<std::size_t, std::vector<std::size_t>> on_buffer;  // buffer hex -> its sides here
    std::unordered_map<primal::EdgeKey, std::vector<std::size_t>, primal::IndexArrayHash> by_edge;
    for (std::size_t i = 0; i < sides.size(); ++i) {
      face[i] = primal::element_face(lm, sides[i]);
      if (auto it = moving_face.find(primal::face_key(face[i])); it != moving_face.end()) {
        on_buffer[it->second].push_back(i);
        continue;
      }
      for (std::size_t k = 0; k < face[i].size(); ++k)
        by_edge[primal::edge_key(face[i][k], face[i][(k + 1) % face[i].size()])].push_back(i);
    }
    std::vector<char> drop(sides.size(), 0);
    if (blocks_.geode_id == 0)
      for (const auto& [b, list] : on_buffer)
        if (list.size() == moving_faces[b]) {
          for (std::size_t i : list) drop[i] = 1;
          geode_faces(b, hex_moves ? 5 : 4, added[s]);
        }
    for (std::size_t b = 0; b < nb; ++b)
      for (int k = 0; k < 4; ++k) {
        std::vector<Index> edge, f;
        for (int c : topo::kHexFaceCorners[k]) {
          f.push_back(layer_.hexes[b].corners[primal::index_cast<std::size_t>(c)]);
          if ((c < 4) == hex_moves) edge.push_back(f.back());
        }
        const auto it = by_edge.find(primal::edge_key(edge[0], edge[1]));
        if (it == by_edge.end()) continue;
        // A side face two buffer hexes share is taken from one of them: the one carved from
        // the set face's block where the two were carved from two blocks (a surface between
        // blocks crossing the layer), else the one carved from the set face's own element.
        const std::vector<std::size_t>& owners = side_owners[primal::face_key(f)];
        const std::size_t other = owners.size() > 1 ? owners[owners[0] == b ? 1 : 0] : b;
        const int mine = primal::block_of(lm, carved_from_[b]),
                  theirs = primal::block_of(lm, carved_from_[other]);
        const Point n = face_normal(lm.points, f);
        for (std::size_t i : it->second) {
          const Point m = face_normal(lm.points, face[i]);
          if (other != b && (mine != theirs ? primal::block_of(lm, sides[i].element) != mine
                                            : !(sides[i].element == carved_from_[b])))
            continue;
          if (std::abs(n.dot(m)) < 0.5 * n.norm() * m.norm()) continue;  // not the same surface
          geode_faces(b, k, added[s]);
          break;
        }
      }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < sides.size(); ++i)
      if (!drop[i]) sides[kept++] = sides[i];
    sides.resize(kept);
  }
  side_sets_ = primal::diced_side_sets(lm, diced_, 0, res_.diced_hexes + res_.geode_hexes);
  // The geode hexes' faces are none of the children's: appended, each once.
  for (std::size_t s = 0; s < side_sets_.size(); ++s)
    side_sets_[s].sides.insert(side_sets_[s].sides.end(), added[s].begin(), added[s].end());
}

// The sets smoothing keeps (primal::KeptFeatures), in the output's numbers: the side sets'
// faces, wherever they are (one embedded in a block, a surface the analyst loads or reads, moved
// with the hexes around it under global smoothing: z 0.487-0.506 instead of 0.5 on a Gmsh
// model's physical surface inside the tets), and the node sets' nodes (a load point, a curve).
// The tet relaxation keeps them too (primal::tet_nodes_to_relax).
void Conformer::keep_sets() {
  kept_ = {};
  const auto& hex = primal::cell_topology(primal::ElementKind::kHex);
  for (const primal::SideSet& s : side_sets_) {
    std::vector<std::array<Index, 4>> quads;
    for (const primal::Side& side : s.sides) {
      const auto& h = mesh_.hexes[primal::index_cast<std::size_t>(side.element.index)];
      const auto& f = hex.face[primal::index_cast<std::size_t>(side.face)];
      quads.push_back({h[primal::index_cast<std::size_t>(f.corners[0])],
                       h[primal::index_cast<std::size_t>(f.corners[1])],
                       h[primal::index_cast<std::size_t>(f.corners[2])],
                       h[primal::index_cast<std::size_t>(f.corners[3])]});
    }
    kept_.surfaces.push_back(std::move(quads));
  }
  for (const primal::NodeSet& s : node_sets_) kept_.node_sets.push_back(s.nodes);
}

}  // namespace geode::conform::detail
