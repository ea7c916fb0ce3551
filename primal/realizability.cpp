#include <geode/primal/realizability.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/cell_nodes.hpp>
#include <geode/primal/detail/lowest_node_sort.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace topo = topology;

std::string_view to_string(ObstructionKind kind) {
  switch (kind) {
    case ObstructionKind::kDoublet:
      return "doublet";
    case ObstructionKind::kPinchedCorner:
      return "pinched-corner";
    case ObstructionKind::kTwoFacesOnBoundaryFace:
      return "two-faces-on-boundary-face";
    case ObstructionKind::kFlatCorner:
      return "flat-corner";
    case ObstructionKind::kTwoQuadBoundaryNode:
      return "two-quad-boundary-node";
  }
  return "unknown";
}

namespace {

constexpr Index kNoPatch = -1;

using detail::has_repeated;

template <std::size_t N>
void check_range(const std::array<Index, N>& cell, std::size_t nodes, const char* what,
                 std::size_t id) {
  for (Index v : cell)
    if (v < 0 || index_cast<std::size_t>(v) >= nodes)
      throw InvalidInput(std::string(what) + " " + std::to_string(id) + ": node " +
                         std::to_string(v) + " out of range [0, " + std::to_string(nodes) + ")");
}

void sort_unique(std::vector<Index>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

double bbox_diagonal(const std::vector<Point>& points) {
  if (points.empty()) return 0.0;
  Point lo = points.front(), hi = points.front();
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return (hi - lo).norm();
}

// Region growing: element i joins the patch of seed s (reached through `neighbours`) when
// fits(s, i); elements that cannot seed (flat(i) false) stay on no patch. Patches are numbered
// by their seed's order, so the result does not depend on hashing.
std::vector<Index> grow_patches(std::size_t n,
                                const std::function<std::vector<Index>(Index)>& neighbours,
                                const std::function<bool(Index)>& flat,
                                const std::function<bool(Index, Index)>& fits) {
  std::vector<Index> patch(n, kNoPatch);
  Index next = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const auto seed = index_cast(s);
    if (patch[s] != kNoPatch || !flat(seed)) continue;
    patch[s] = next;
    std::deque<Index> queue{seed};
    while (!queue.empty()) {
      const Index e = queue.front();
      queue.pop_front();
      for (Index o : neighbours(e)) {
        auto& p = patch[index_cast<std::size_t>(o)];
        if (p != kNoPatch || !flat(o) || !fits(seed, o)) continue;
        p = next;
        queue.push_back(o);
      }
    }
    ++next;
  }
  return patch;
}

bool contains(const std::vector<Index>& sorted, Index x) {
  return std::binary_search(sorted.begin(), sorted.end(), x);
}

void check_node_faces(const RealizabilityOptions& options, std::size_t nodes) {
  if (!options.node_faces.empty() && options.node_faces.size() != nodes)
    throw InvalidInput("realizability: node_faces has " +
                       std::to_string(options.node_faces.size()) + " entries for " +
                       std::to_string(nodes) + " nodes");
}

// Nodes' planar faces from the template's bits: face f for bit f.
std::vector<std::vector<Index>> node_patches_from_bits(const std::vector<unsigned>& bits) {
  std::vector<std::vector<Index>> out(bits.size());
  for (std::size_t v = 0; v < bits.size(); ++v)
    for (unsigned f = 0; f < 32; ++f)
      if ((bits[v] >> f) & 1u) out[v].push_back(index_cast(f));
  return out;
}

// The planar face all of `nodes` lie on by their bits (the lowest if several), or kNoPatch.
template <std::size_t N>
Index patch_from_bits(const std::vector<unsigned>& bits, const std::array<Index, N>& nodes) {
  unsigned common = ~0u;
  for (Index v : nodes) common &= bits[index_cast<std::size_t>(v)];
  for (unsigned f = 0; f < 32; ++f)
    if ((common >> f) & 1u) return index_cast(f);
  return kNoPatch;
}

// Quads (hex faces, or a quad mesh's quads) sharing a corner: the same node v with the same two
// neighbours a, b in the quad. One group per such (v, min(a, b), max(a, b)) used by two or more
// quads, in order of first appearance, quads ascending. quad(i) is null for quads to skip.
struct SharedCorner {
  std::array<Index, 3> corner;
  std::vector<Index> quads;
};

// Keyed uses grouped by key: group(key, first, last) for each key, its uses in `at` order (so
// `first->at` is its first use). The uses are bucketed by key[0] and each bucket sorted
// (detail/lowest_node_sort.hpp, in parallel); `each(visit)` visits every use, from any thread.
// Groups come by key; a caller wanting them in order of first use sorts what it keeps by
// `first->at` (most keep a few). Hash maps of vectors over every face, edge or corner made
// `geode check` of a million hexes take 36 s and 1 GB; with this, 8 s.

using detail::KeyedUse;

template <std::size_t N, class Each, class Group>
void group_by_key(std::size_t nodes, Each&& each, Group&& group) {
  std::vector<std::size_t> start;
  const std::vector<KeyedUse<N>> uses = detail::sort_by_lowest_node<KeyedUse<N>>(
      nodes, each, [](const KeyedUse<N>& u) { return u.key[0]; }, start);
  for (std::size_t g = 0; g < uses.size();) {
    std::size_t e = g + 1;
    while (e < uses.size() && uses[e].key == uses[g].key) ++e;
    group(uses[g].key, uses.data() + g, uses.data() + e);
    g = e;
  }
}

// Items kept with the place of their first use, put in that order.
template <class T>
std::vector<T> in_first_use_order(std::vector<std::pair<std::size_t, T>> kept) {
  std::sort(kept.begin(), kept.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<T> out;
  out.reserve(kept.size());
  for (auto& [at, item] : kept) out.push_back(std::move(item));
  return out;
}

std::vector<SharedCorner> shared_corners(
    std::size_t n, const std::function<const std::array<Index, 4>*(std::size_t)>& quad) {
  Index nodes = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (const auto* q = quad(i))
      for (Index v : *q) nodes = std::max(nodes, v + 1);
  std::vector<std::pair<std::size_t, SharedCorner>> kept;
  group_by_key<3>(
      index_cast<std::size_t>(nodes),
      [&](auto&& visit) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              const auto* q = quad(i);
                              if (!q) continue;
                              for (std::size_t c = 0; c < 4; ++c) {
                                const Index v = (*q)[c], a = (*q)[(c + 3) % 4],
                                            b = (*q)[(c + 1) % 4];
                                visit(KeyedUse<3>{{v, std::min(a, b), std::max(a, b)}, 4 * i + c});
                              }
                            }
                          });
      },
      [&](const std::array<Index, 3>& key, const KeyedUse<3>* first, const KeyedUse<3>* last) {
        if (last - first < 2) return;
        SharedCorner sc{key, {}};
        for (const auto* u = first; u != last; ++u) sc.quads.push_back(index_cast(u->at / 4));
        sort_unique(sc.quads);
        if (sc.quads.size() >= 2) kept.emplace_back(first->at, std::move(sc));
      });
  return in_first_use_order(std::move(kept));
}

// ---- Hex meshes ----------------------------------------------------------------------------

class HexFinder {
 public:
  HexFinder(const HexMesh& mesh, const RealizabilityOptions& options)
      : mesh_(mesh), options_(options) {}

  std::vector<Obstruction> run() {
    // Each stage's share of the work, in percent as measured on 5.2 million hexes.
    const auto stage = [this](auto&& search, std::size_t share) {
      search();
      done_ += share;
      if (options_.progress) options_.progress(done_, 100);
    };
    if (options_.progress) options_.progress(0, 100);  // the start, from which a bar counts
    stage([this] { collect_faces(); }, 37);
    stage([this] { find_patches(); }, 6);
    stage([this] { find_doublets(); }, 26);
    stage([this] { find_pinched_corners(); }, 25);
    stage([this] { find_two_faces(); }, 0);
    stage([this] { find_flat_corners(); }, 6);
    stage([this] { find_two_quad_nodes(); }, 0);
    std::vector<Obstruction> out;
    for (auto* list : {&doublets_, &pinched_, &two_faces_, &flat_, &two_quad_})
      out.insert(out.end(), list->begin(), list->end());
    return out;
  }

 private:
  std::size_t done_ = 0;                  // the stages' shares reported
  using FaceUse = std::pair<Index, int>;  // (hex, local face)
  struct Face {
    std::array<Index, 4> nodes{};  // as the first hex using it sees it
    std::size_t first_use = 0;     // its uses: face_uses_[first_use, first_use + uses)
    std::size_t uses = 0;
  };
  std::span<const FaceUse> uses(const Face& f) const {
    return {face_uses_.data() + f.first_use, f.uses};
  }

  void collect_faces() {
    const std::size_t nv = mesh_.points.size();
    check_node_faces(options_, nv);
    for (std::size_t h = 0; h < mesh_.hexes.size(); ++h) check_range(mesh_.hexes[h], nv, "hex", h);
    auto face_of = [&](std::size_t h, int f) {
      std::array<Index, 4> q{};
      for (int i = 0; i < 4; ++i)
        q[index_cast<std::size_t>(i)] = mesh_.hexes[h][index_cast<std::size_t>(
            topo::kHexFaceCorners[index_cast<std::size_t>(f)][index_cast<std::size_t>(i)])];
      return q;
    };
    // Faces numbered in order of first use, each as its first hex sees it.
    const std::size_t per = index_cast<std::size_t>(topo::kHexFaces);
    std::vector<std::pair<std::size_t, Face>> order;
    face_uses_.reserve(per * mesh_.hexes.size());
    group_by_key<4>(
        nv,
        [&](auto&& visit) {
          tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh_.hexes.size(), 4096),
                            [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t h = r.begin(); h != r.end(); ++h) {
                                if (has_repeated(mesh_.hexes[h])) continue;
                                for (int f = 0; f < topo::kHexFaces; ++f)
                                  visit(KeyedUse<4>{face_key(face_of(h, f)),
                                                    per * h + index_cast<std::size_t>(f)});
                              }
                            });
        },
        [&](const FaceKey&, const KeyedUse<4>* first, const KeyedUse<4>* last) {
          Face face{{}, face_uses_.size(), index_cast<std::size_t>(last - first)};
          for (const auto* u = first; u != last; ++u)
            face_uses_.emplace_back(index_cast(u->at / per), index_cast<int>(u->at % per));
          order.emplace_back(first->at, face);
        });
    faces_ = in_first_use_order(std::move(order));
    for (Face& f : faces_) {
      const FaceUse& u = face_uses_[f.first_use];
      f.nodes = face_of(index_cast<std::size_t>(u.first), u.second);
    }
    for (std::size_t f = 0; f < faces_.size(); ++f)
      if (faces_[f].uses == 1) boundary_.push_back(index_cast(f));
  }

  // Patch of each boundary quad (index into boundary_) and the patches at each node.
  void find_patches() {
    const std::size_t nb = boundary_.size();
    node_patches_.assign(mesh_.points.size(), {});
    boundary_quads_at_.assign(mesh_.points.size(), {});
    for (std::size_t b = 0; b < nb; ++b)
      for (Index v : face(b).nodes)
        boundary_quads_at_[index_cast<std::size_t>(v)].push_back(index_cast(b));
    if (!options_.node_faces.empty()) {
      quad_patch_.resize(nb);
      for (std::size_t b = 0; b < nb; ++b)
        quad_patch_[b] = patch_from_bits(options_.node_faces, face(b).nodes);
      node_patches_ = node_patches_from_bits(options_.node_faces);
      return;
    }
    const double tol = options_.planar_distance * bbox_diagonal(mesh_.points);
    const double cos_tol = std::cos(options_.planar_angle_degrees * M_PI / 180.0);
    std::vector<Point> normal(nb), centre(nb);
    std::vector<char> flat(nb, 0);
    auto pt = [&](Index v) -> const Point& { return mesh_.points[index_cast<std::size_t>(v)]; };
    auto off_plane = [&](std::size_t plane, std::size_t quad) {
      double d = 0.0;
      for (Index v : face(quad).nodes)
        d = std::max(d, std::abs(normal[plane].dot(pt(v) - centre[plane])));
      return d;
    };
    for (std::size_t b = 0; b < nb; ++b) {
      const auto& q = face(b).nodes;
      const Point n = (pt(q[2]) - pt(q[0])).cross(pt(q[3]) - pt(q[1]));
      centre[b] = 0.25 * (pt(q[0]) + pt(q[1]) + pt(q[2]) + pt(q[3]));
      if (!(n.norm() > 0.0)) continue;
      normal[b] = n.normalized();
      flat[b] = off_plane(b, b) <= tol;
    }
    // Boundary quads sharing an edge.
    std::unordered_map<EdgeKey, std::vector<Index>, IndexArrayHash> by_edge;
    for (std::size_t b = 0; b < nb; ++b) {
      const auto& q = face(b).nodes;
      for (int i = 0; i < 4; ++i)
        by_edge[edge_key(q[index_cast<std::size_t>(i)], q[index_cast<std::size_t>((i + 1) % 4)])]
            .push_back(index_cast(b));
    }
    quad_patch_ = grow_patches(
        nb,
        [&](Index b) {
          std::vector<Index> out;
          const auto& q = face(index_cast<std::size_t>(b)).nodes;
          for (int i = 0; i < 4; ++i)
            for (Index o : by_edge.at(edge_key(q[index_cast<std::size_t>(i)],
                                               q[index_cast<std::size_t>((i + 1) % 4)])))
              if (o != b) out.push_back(o);
          return out;
        },
        [&](Index b) { return flat[index_cast<std::size_t>(b)] != 0; },
        [&](Index s, Index b) {
          const auto su = index_cast<std::size_t>(s), bu = index_cast<std::size_t>(b);
          return normal[su].dot(normal[bu]) >= cos_tol && off_plane(su, bu) <= tol;
        });
    for (std::size_t b = 0; b < nb; ++b)
      if (quad_patch_[b] != kNoPatch)
        for (Index v : face(b).nodes)
          node_patches_[index_cast<std::size_t>(v)].push_back(quad_patch_[b]);
    for (auto& p : node_patches_) sort_unique(p);
  }

  // Interior edges in fewer than three hexes, merged by their pair of hexes.
  void find_doublets() {
    std::unordered_map<EdgeKey, bool, IndexArrayHash> on_boundary;
    for (Index f : boundary_) {
      const auto& q = faces_[index_cast<std::size_t>(f)].nodes;
      for (int i = 0; i < 4; ++i)
        on_boundary[edge_key(q[index_cast<std::size_t>(i)],
                             q[index_cast<std::size_t>((i + 1) % 4)])] = true;
    }
    std::map<std::vector<Index>, std::size_t> by_hexes;
    const std::size_t per = topo::kHexEdgeCorners.size();
    std::vector<std::pair<std::size_t, std::pair<EdgeKey, std::vector<Index>>>> thin;
    group_by_key<2>(
        mesh_.points.size(),
        [&](auto&& visit) {
          tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh_.hexes.size(), 4096),
                            [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t h = r.begin(); h != r.end(); ++h) {
                                const auto& hex = mesh_.hexes[h];
                                if (has_repeated(hex)) continue;
                                for (std::size_t e = 0; e < per; ++e) {
                                  const auto& ends = topo::kHexEdgeCorners[e];
                                  visit(KeyedUse<2>{edge_key(hex[index_cast<std::size_t>(ends[0])],
                                                             hex[index_cast<std::size_t>(ends[1])]),
                                                    per * h + e});
                                }
                              }
                            });
        },
        [&](const EdgeKey& k, const KeyedUse<2>* first, const KeyedUse<2>* last) {
          if (last - first >= 3) return;  // in three hexes or more (or on the boundary below)
          std::vector<Index> hexes;
          for (const auto* u = first; u != last; ++u) hexes.push_back(index_cast(u->at / per));
          sort_unique(hexes);
          if (hexes.size() < 3 && !on_boundary.count(k))
            thin.emplace_back(first->at, std::make_pair(k, std::move(hexes)));
        });
    // Merged by their pair of hexes in order of first use.
    for (auto& [k, hexes] : in_first_use_order(std::move(thin))) {
      auto [it, inserted] = by_hexes.try_emplace(hexes, doublets_.size());
      if (inserted) doublets_.push_back(Obstruction{ObstructionKind::kDoublet, hexes, {}});
      auto& nodes = doublets_[it->second].nodes;
      nodes.insert(nodes.end(), k.begin(), k.end());
      sort_unique(nodes);
      for (Index v : k) doublet_ends_.emplace(v, it->second);
    }
  }

  // Distinct faces sharing both edges va, vb at a node v.
  void find_pinched_corners() {
    for (const auto& [corner, faces] :
         shared_corners(faces_.size(), [&](std::size_t f) { return &faces_[f].nodes; })) {
      std::vector<Index> hexes;
      for (Index f : faces)
        for (const auto& [h, lf] : uses(faces_[index_cast<std::size_t>(f)])) hexes.push_back(h);
      sort_unique(hexes);
      if (explained_by_doublet(corner[0], hexes)) continue;
      pinched_.push_back(
          Obstruction{ObstructionKind::kPinchedCorner, hexes, {corner[0], corner[1], corner[2]}});
    }
  }

  // A doublet's two hexes, at an end of its edge, have their third faces there pinched.
  bool explained_by_doublet(Index v, const std::vector<Index>& hexes) const {
    const auto [lo, hi] = doublet_ends_.equal_range(v);
    for (auto it = lo; it != hi; ++it) {
      const auto& pair = doublets_[it->second].hexes;
      if (std::all_of(pair.begin(), pair.end(), [&](Index h) { return contains(hexes, h); }))
        return true;
    }
    return false;
  }

  // Hexes with two boundary faces on one planar face.
  void find_two_faces() {
    std::map<Index, std::vector<std::pair<int, Index>>> per_hex;  // hex -> (local face, patch)
    for (std::size_t b = 0; b < boundary_.size(); ++b) {
      if (quad_patch_[b] == kNoPatch) continue;
      const FaceUse& use = uses(face(b)).front();
      per_hex[use.first].emplace_back(use.second, quad_patch_[b]);
    }
    for (const auto& [h, list] : per_hex) {
      std::map<Index, std::vector<int>> by_patch;
      for (const auto& [lf, p] : list) by_patch[p].push_back(lf);
      for (const auto& [p, local] : by_patch) {
        if (local.size() < 2) continue;
        Obstruction o{ObstructionKind::kTwoFacesOnBoundaryFace, {h}, {}};
        for (int lf : local)
          for (int c : topo::kHexFaceCorners[index_cast<std::size_t>(lf)])
            o.nodes.push_back(hex(h)[index_cast<std::size_t>(c)]);
        sort_unique(o.nodes);
        two_faces_.push_back(o);
        // Corners on two of these faces: already explained, not repeated as flat corners.
        for (int c = 0; c < topo::kHexCorners; ++c) {
          int on = 0;
          for (int lf : local) {
            const auto& fc = topo::kHexFaceCorners[index_cast<std::size_t>(lf)];
            on += std::find(fc.begin(), fc.end(), c) != fc.end();
          }
          if (on >= 2) explained_corners_.insert({h, c});
        }
      }
    }
  }

  // Hex corners whose node and three neighbours share a planar face.
  void find_flat_corners() {
    for (std::size_t h = 0; h < mesh_.hexes.size(); ++h) {
      const auto& hx = mesh_.hexes[h];
      if (has_repeated(hx)) continue;
      for (int c = 0; c < topo::kHexCorners; ++c) {
        if (explained_corners_.count({index_cast(h), c})) continue;
        const Index v = hx[index_cast<std::size_t>(c)];
        const auto& nb = topo::kHexCornerNeighbors[index_cast<std::size_t>(c)];
        const bool flat = std::any_of(patches(v).begin(), patches(v).end(), [&](Index p) {
          return std::all_of(nb.begin(), nb.end(), [&](int n) {
            return contains(patches(hx[index_cast<std::size_t>(n)]), p);
          });
        });
        if (!flat) continue;
        flat_.push_back(
            Obstruction{ObstructionKind::kFlatCorner,
                        {index_cast(h)},
                        {v, hx[index_cast<std::size_t>(nb[0])], hx[index_cast<std::size_t>(nb[1])],
                         hx[index_cast<std::size_t>(nb[2])]}});
      }
    }
  }

  // Nodes inside one planar face (every boundary quad at them on it) with fewer than three.
  void find_two_quad_nodes() {
    for (std::size_t v = 0; v < mesh_.points.size(); ++v) {
      const auto& quads = boundary_quads_at_[v];
      if (quads.empty() || node_patches_[v].size() != 1) continue;
      const Index p = node_patches_[v].front();
      if (!std::all_of(quads.begin(), quads.end(),
                       [&](Index b) { return quad_patch_[index_cast<std::size_t>(b)] == p; }))
        continue;
      if (quads.size() >= 3) continue;
      Obstruction o{ObstructionKind::kTwoQuadBoundaryNode, {}, {index_cast(v)}};
      for (Index b : quads) o.hexes.push_back(uses(face(index_cast<std::size_t>(b))).front().first);
      sort_unique(o.hexes);
      two_quad_.push_back(o);
    }
  }

  const Face& face(std::size_t boundary_index) const {
    return faces_[index_cast<std::size_t>(boundary_[boundary_index])];
  }
  const std::array<Index, 8>& hex(Index h) const { return mesh_.hexes[index_cast<std::size_t>(h)]; }
  const std::vector<Index>& patches(Index v) const {
    return node_patches_[index_cast<std::size_t>(v)];
  }

  const HexMesh& mesh_;
  const RealizabilityOptions& options_;
  std::vector<Face> faces_;
  std::vector<FaceUse> face_uses_;                     // every face's uses, face by face
  std::vector<Index> boundary_;                        // faces used by one hex
  std::vector<Index> quad_patch_;                      // per boundary_ entry
  std::vector<std::vector<Index>> node_patches_;       // sorted
  std::vector<std::vector<Index>> boundary_quads_at_;  // per node, boundary_ entries
  std::multimap<Index, std::size_t> doublet_ends_;     // node -> doublet
  std::set<std::pair<Index, int>> explained_corners_;  // (hex, corner) in a two-faces finding
  std::vector<Obstruction> doublets_, pinched_, two_faces_, flat_, two_quad_;
};

// ---- Quad meshes ---------------------------------------------------------------------------

class QuadFinder {
 public:
  QuadFinder(const QuadMesh& mesh, const RealizabilityOptions& options)
      : mesh_(mesh), options_(options) {}

  std::vector<Obstruction> run() {
    collect_edges();
    find_sides();
    find_doublets();
    find_two_edges_and_flat_corners();
    std::vector<Obstruction> out = doublets_;
    out.insert(out.end(), two_edges_.begin(), two_edges_.end());
    out.insert(out.end(), flat_.begin(), flat_.end());
    return out;
  }

 private:
  void collect_edges() {
    const std::size_t nv = mesh_.points.size();
    check_node_faces(options_, nv);
    std::unordered_map<EdgeKey, std::vector<std::pair<Index, int>>, IndexArrayHash> uses;
    std::vector<EdgeKey> order;
    for (std::size_t q = 0; q < mesh_.quads.size(); ++q) {
      check_range(mesh_.quads[q], nv, "quad", q);
      if (has_repeated(mesh_.quads[q])) continue;
      for (int e = 0; e < 4; ++e) {
        const auto k = key(index_cast(q), e);
        auto [it, inserted] = uses.try_emplace(k);
        if (inserted) order.push_back(k);
        it->second.emplace_back(index_cast(q), e);
      }
    }
    for (const auto& k : order)
      if (uses.at(k).size() == 1) boundary_.push_back(uses.at(k).front());
  }

  EdgeKey key(Index q, int e) const {
    const auto& quad = mesh_.quads[index_cast<std::size_t>(q)];
    return edge_key(quad[index_cast<std::size_t>(e)], quad[index_cast<std::size_t>((e + 1) % 4)]);
  }

  void find_sides() {
    const std::size_t nb = boundary_.size();
    node_sides_.assign(mesh_.points.size(), {});
    if (!options_.node_faces.empty()) {
      side_.resize(nb);
      for (std::size_t b = 0; b < nb; ++b) {
        const auto [q, e] = boundary_[b];
        side_[b] = patch_from_bits(options_.node_faces, key(q, e));
      }
      node_sides_ = node_patches_from_bits(options_.node_faces);
      return;
    }
    const double tol = options_.planar_distance * bbox_diagonal(mesh_.points);
    const double cos_tol = std::cos(options_.planar_angle_degrees * M_PI / 180.0);
    auto ends = [&](std::size_t b) { return key(boundary_[b].first, boundary_[b].second); };
    auto pt = [&](Index v) -> const Point& { return mesh_.points[index_cast<std::size_t>(v)]; };
    std::vector<Point> dir(nb);
    std::vector<char> flat(nb, 0);
    for (std::size_t b = 0; b < nb; ++b) {
      const auto k = ends(b);
      const Point d = pt(k[1]) - pt(k[0]);
      if (!(d.norm() > 0.0)) continue;
      dir[b] = d.normalized();
      flat[b] = 1;
    }
    auto off_line = [&](std::size_t line, std::size_t edge) {
      const Point& o = pt(ends(line)[0]);
      double d = 0.0;
      for (Index v : ends(edge)) {
        const Point r = pt(v) - o;
        d = std::max(d, (r - r.dot(dir[line]) * dir[line]).norm());
      }
      return d;
    };
    std::unordered_map<Index, std::vector<Index>> at_node;
    for (std::size_t b = 0; b < nb; ++b)
      for (Index v : ends(b)) at_node[v].push_back(index_cast(b));
    side_ = grow_patches(
        nb,
        [&](Index b) {
          std::vector<Index> out;
          for (Index v : ends(index_cast<std::size_t>(b)))
            for (Index o : at_node.at(v))
              if (o != b) out.push_back(o);
          return out;
        },
        [&](Index b) { return flat[index_cast<std::size_t>(b)] != 0; },
        [&](Index s, Index b) {
          const auto su = index_cast<std::size_t>(s), bu = index_cast<std::size_t>(b);
          return std::abs(dir[su].dot(dir[bu])) >= cos_tol && off_line(su, bu) <= tol;
        });
    for (std::size_t b = 0; b < nb; ++b)
      if (side_[b] != kNoPatch)
        for (Index v : ends(b)) node_sides_[index_cast<std::size_t>(v)].push_back(side_[b]);
    for (auto& s : node_sides_) sort_unique(s);
  }

  // Quads sharing both edges va, vb at a node v.
  void find_doublets() {
    const auto groups = shared_corners(mesh_.quads.size(), [&](std::size_t q) {
      return has_repeated(mesh_.quads[q]) ? nullptr : &mesh_.quads[q];
    });
    for (const auto& [corner, quads] : groups)
      doublets_.push_back(
          Obstruction{ObstructionKind::kDoublet, quads, {corner[0], corner[1], corner[2]}});
  }

  void find_two_edges_and_flat_corners() {
    std::map<Index, std::vector<std::pair<int, Index>>> per_quad;  // quad -> (local edge, side)
    for (std::size_t b = 0; b < boundary_.size(); ++b)
      if (side_[b] != kNoPatch)
        per_quad[boundary_[b].first].emplace_back(boundary_[b].second, side_[b]);
    std::set<std::pair<Index, int>> explained;  // (quad, corner) between two edges on one side
    for (const auto& [q, list] : per_quad) {
      std::map<Index, std::vector<int>> by_side;
      for (const auto& [e, s] : list) by_side[s].push_back(e);
      for (const auto& [s, local] : by_side) {
        if (local.size() < 2) continue;
        Obstruction o{ObstructionKind::kTwoFacesOnBoundaryFace, {q}, {}};
        std::map<int, int> corner_uses;
        for (int e : local)
          for (int c : {e, (e + 1) % 4}) {
            o.nodes.push_back(mesh_.quads[index_cast<std::size_t>(q)][index_cast<std::size_t>(c)]);
            ++corner_uses[c];
          }
        sort_unique(o.nodes);
        two_edges_.push_back(o);
        for (const auto& [c, n] : corner_uses)
          if (n >= 2) explained.insert({q, c});
      }
    }
    for (std::size_t q = 0; q < mesh_.quads.size(); ++q) {
      const auto& quad = mesh_.quads[q];
      if (has_repeated(quad)) continue;
      for (int c = 0; c < 4; ++c) {
        if (explained.count({index_cast(q), c})) continue;
        const Index v = quad[index_cast<std::size_t>(c)],
                    a = quad[index_cast<std::size_t>((c + 1) % 4)],
                    b = quad[index_cast<std::size_t>((c + 3) % 4)];
        const auto& sv = node_sides_[index_cast<std::size_t>(v)];
        const bool flat = std::any_of(sv.begin(), sv.end(), [&](Index s) {
          return contains(node_sides_[index_cast<std::size_t>(a)], s) &&
                 contains(node_sides_[index_cast<std::size_t>(b)], s);
        });
        if (flat)
          flat_.push_back(Obstruction{ObstructionKind::kFlatCorner, {index_cast(q)}, {v, a, b}});
      }
    }
  }

  const QuadMesh& mesh_;
  const RealizabilityOptions& options_;
  std::vector<std::pair<Index, int>> boundary_;  // boundary edges as (quad, local edge)
  std::vector<Index> side_;                      // per boundary edge
  std::vector<std::vector<Index>> node_sides_;   // sorted
  std::vector<Obstruction> doublets_, two_edges_, flat_;
};

}  // namespace

std::vector<Obstruction> find_obstructions(const HexMesh& mesh,
                                           const RealizabilityOptions& options) {
  return HexFinder(mesh, options).run();
}

std::vector<Obstruction> find_obstructions(const QuadMesh& mesh,
                                           const RealizabilityOptions& options) {
  return QuadFinder(mesh, options).run();
}

std::string format_obstructions(const std::vector<Obstruction>& obstructions, int dim, Index base,
                                std::size_t limit) {
  std::ostringstream os;
  if (obstructions.empty()) return "no obstructions found\n";
  std::map<ObstructionKind, int> count;
  for (const auto& o : obstructions) ++count[o.kind];
  os << obstructions.size() << (obstructions.size() == 1 ? " obstruction" : " obstructions")
     << " (";
  bool first = true;
  for (const auto& [kind, n] : count)
    os << (first ? "" : ", ") << n << " " << to_string(kind), first = false;
  os << ")\n";
  auto list = [&](const std::vector<Index>& ids) {
    for (std::size_t i = 0; i < ids.size(); ++i) os << (i ? " " : "") << ids[i] + base;
  };
  for (std::size_t i = 0; i < std::min(limit, obstructions.size()); ++i) {
    const auto& o = obstructions[i];
    os << "  " << to_string(o.kind) << ": " << (dim == 2 ? "quads " : "hexes ");
    list(o.hexes);
    os << "; nodes ";
    list(o.nodes);
    os << "\n";
  }
  if (obstructions.size() > limit) os << "  ... and " << obstructions.size() - limit << " more\n";
  return os.str();
}

nlohmann::json obstructions_json(const std::vector<Obstruction>& obstructions, Index base) {
  auto j = nlohmann::json::array();
  auto shifted = [base](const std::vector<Index>& ids) {
    std::vector<Index> out;
    for (Index i : ids) out.push_back(i + base);
    return out;
  };
  for (const auto& o : obstructions)
    j.push_back({{"kind", std::string(to_string(o.kind))},
                 {"hexes", shifted(o.hexes)},
                 {"nodes", shifted(o.nodes)}});
  return j;
}

}  // namespace geode::primal
