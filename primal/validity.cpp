#include "primal/validity.hpp"

#include "primal/disjoint_sets.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "primal/quality.hpp"
#include "primal/topology.hpp"

namespace geode::primal {

namespace topo = topology;

namespace {

// ---- Derived hex tables (computed from topology.hpp, not typed) ---------------------------

struct HexIncidence {
  std::array<std::array<int, 2>, 12> edge_faces{};   // the two local faces containing edge e
  std::array<std::array<int, 3>, 8> corner_faces{};  // the three local faces at corner c
  std::array<std::array<int, 3>, 8> corner_edges{};  // the three local edges at corner c
};

bool face_has_edge(int f, int a, int b) {
  const auto& q = topo::kHexFaceCorners[f];
  for (int i = 0; i < 4; ++i) {
    const int u = q[i], v = q[(i + 1) % 4];
    if ((u == a && v == b) || (u == b && v == a)) return true;
  }
  return false;
}

const HexIncidence& hex_incidence() {
  static const HexIncidence inc = [] {
    HexIncidence t;
    for (int e = 0; e < topo::kHexEdges; ++e) {
      int n = 0;
      for (int f = 0; f < topo::kHexFaces; ++f) {
        if (face_has_edge(f, topo::kHexEdgeCorners[e][0], topo::kHexEdgeCorners[e][1])) {
          t.edge_faces[e][n++] = f;
        }
      }
      assert(n == 2);
    }
    for (int c = 0; c < topo::kHexCorners; ++c) {
      int nf = 0, ne = 0;
      for (int f = 0; f < topo::kHexFaces; ++f) {
        const auto& q = topo::kHexFaceCorners[f];
        if (std::find(q.begin(), q.end(), c) != q.end()) t.corner_faces[c][nf++] = f;
      }
      for (int e = 0; e < topo::kHexEdges; ++e) {
        if (topo::kHexEdgeCorners[e][0] == c || topo::kHexEdgeCorners[e][1] == c) {
          t.corner_edges[c][ne++] = e;
        }
      }
      assert(nf == 3 && ne == 3);
    }
    return t;
  }();
  return inc;
}

// Union-find over a small set of element uses.

template <std::size_t N>
bool has_repeated(const std::array<Index, N>& a) {
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = i + 1; j < N; ++j) {
      if (a[i] == a[j]) return true;
    }
  }
  return false;
}

template <std::size_t N>
bool in_range(const std::array<Index, N>& a, std::size_t n) {
  return std::all_of(a.begin(), a.end(),
                     [n](Index v) { return v >= 0 && static_cast<std::size_t>(v) < n; });
}

// Two uses of a face (or edge) agree when one is the reverse cyclic order of the other.
template <std::size_t N>
bool opposite_cycles(const std::array<Index, N>& a, const std::array<Index, N>& b) {
  const auto j = static_cast<int>(std::find(b.begin(), b.end(), a[0]) - b.begin());
  if (j == static_cast<int>(N)) return false;
  for (int i = 0; i < static_cast<int>(N); ++i) {
    if (b[(j - i + static_cast<int>(N)) % static_cast<int>(N)] != a[i]) return false;
  }
  return true;
}

std::vector<Index> non_finite(const std::vector<Point>& points) {
  std::vector<Index> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) out.push_back(static_cast<Index>(i));
  }
  return out;
}

// "name: N (a, b, c, ...)" listing at most a few offenders.
template <typename T, typename F>
void list(std::ostringstream& os, const char* what, const std::vector<T>& items, F&& show) {
  if (items.empty()) return;
  os << "  " << what << ": " << items.size() << " (";
  const std::size_t shown = std::min<std::size_t>(items.size(), 8);
  for (std::size_t i = 0; i < shown; ++i) os << (i ? ", " : "") << show(items[i]);
  if (shown < items.size()) os << ", ...";
  os << ")\n";
}

std::string show_index(Index i) { return std::to_string(i); }
template <std::size_t N>
std::string show_key(const std::array<Index, N>& k) {
  std::string s = "{";
  for (std::size_t i = 0; i < N; ++i) {
    if (k[i] == kInvalidIndex) break;
    s += (i ? " " : "") + std::to_string(k[i]);
  }
  return s + "}";
}

}  // namespace

// ---- Hex meshes ----------------------------------------------------------------------------

bool HexValidityReport::ok() const {
  return out_of_range_hexes.empty() && non_finite_nodes.empty() && repeated_node_hexes.empty() &&
         overshared_faces.empty() && misoriented_faces.empty() && nonmanifold_edges.empty() &&
         nonmanifold_vertices.empty() && inverted_hexes.empty() && boundary.closed &&
         boundary.manifold;
}

std::string HexValidityReport::summary() const {
  std::ostringstream os;
  os << "hex mesh: " << num_hexes << " hexes, " << num_nodes
     << " nodes: " << (ok() ? "valid" : "INVALID") << "\n";
  os << "  complex: V - E + F - C = " << num_vertices << " - " << num_edges << " + " << num_faces
     << " - " << num_cells << " = " << euler << "\n";
  os << "  boundary: " << (boundary.faces.size() + boundary.rejected.size()) << " quads, "
     << (boundary.closed ? "closed" : "NOT closed") << ", "
     << (boundary.manifold ? "manifold" : "NOT manifold") << ", V - E + F = " << boundary.euler
     << "\n";
  if (unused_nodes > 0) os << "  unused nodes: " << unused_nodes << "\n";
  list(os, "hexes with out-of-range nodes", out_of_range_hexes, show_index);
  list(os, "nodes with non-finite coordinates", non_finite_nodes, show_index);
  list(os, "hexes with a repeated node", repeated_node_hexes, show_index);
  list(os, "faces shared by more than two hexes", overshared_faces, show_key<4>);
  list(os, "faces seen in the same order by both hexes", misoriented_faces, show_key<4>);
  list(os, "non-manifold edges", nonmanifold_edges, show_key<2>);
  list(os, "non-manifold vertices", nonmanifold_vertices, show_index);
  list(os, "boundary quads OpenMesh rejected (hex)", boundary.rejected,
       [](const BoundaryQuad& q) { return std::to_string(q.hex); });
  list(os, "hexes with a non-positive corner Jacobian", inverted_hexes, show_index);
  return os.str();
}

HexValidityReport check_validity(const HexMesh& mesh) {
  HexValidityReport r;
  r.num_nodes = static_cast<Index>(mesh.points.size());
  r.num_hexes = static_cast<Index>(mesh.hexes.size());
  r.non_finite_nodes = non_finite(mesh.points);

  // The proper hexes, on which the topology is analysed.
  HexMesh proper;
  proper.points = mesh.points;
  std::vector<Index> original;  // proper hex -> input hex
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const auto& hex = mesh.hexes[h];
    if (!in_range(hex, mesh.points.size())) {
      r.out_of_range_hexes.push_back(static_cast<Index>(h));
    } else if (has_repeated(hex)) {
      r.repeated_node_hexes.push_back(static_cast<Index>(h));
    } else {
      proper.hexes.push_back(hex);
      original.push_back(static_cast<Index>(h));
    }
  }

  // Orientation (on in-range hexes with finite corners; a repeated node gives a zero Jacobian).
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    if (!in_range(mesh.hexes[h], mesh.points.size())) continue;
    const auto j = hex_jacobians(hex_corners(mesh, static_cast<Index>(h)));
    // Corners 0..7 only: the centre value (index 8) is not a corner Jacobian.
    if (!std::all_of(j.begin(), j.begin() + 8, [](double d) { return d > 0.0; })) {
      r.inverted_hexes.push_back(static_cast<Index>(h));
    }
  }

  const auto& inc = hex_incidence();
  const std::size_t nh = proper.hexes.size();

  // Global face and edge numbers per hex.
  const auto faces = unique_faces(proper);
  std::vector<std::array<Index, 6>> hex_faces(nh);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (const auto& u : faces[f].uses) hex_faces[u.hex][u.local_face] = static_cast<Index>(f);
    if (faces[f].uses.size() > 2) r.overshared_faces.push_back(faces[f].key);
    if (faces[f].uses.size() == 2) {
      const auto& u1 = faces[f].uses[1];
      std::array<Index, 4> other{};
      for (int i = 0; i < 4; ++i) {
        other[i] = proper.hexes[u1.hex][topo::kHexFaceCorners[u1.local_face][i]];
      }
      if (!opposite_cycles(faces[f].nodes, other)) {
        r.misoriented_faces.push_back(faces[f].key);
      }
    }
  }
  std::unordered_map<EdgeKey, Index, IndexArrayHash> edge_id;
  std::vector<EdgeKey> edges;
  std::vector<std::array<Index, 12>> hex_edges(nh);
  for (std::size_t h = 0; h < nh; ++h) {
    for (int e = 0; e < topo::kHexEdges; ++e) {
      const auto& c = topo::kHexEdgeCorners[e];
      const EdgeKey k = edge_key(proper.hexes[h][c[0]], proper.hexes[h][c[1]]);
      auto [it, inserted] = edge_id.try_emplace(k, static_cast<Index>(edges.size()));
      if (inserted) edges.push_back(k);
      hex_edges[h][e] = it->second;
    }
  }

  // Edges: the hexes around an edge must form one chain or ring through shared faces.
  {
    std::vector<std::vector<std::pair<Index, int>>> edge_uses(edges.size());  // (hex, local edge)
    for (std::size_t h = 0; h < nh; ++h) {
      for (int e = 0; e < topo::kHexEdges; ++e)
        edge_uses[hex_edges[h][e]].emplace_back(static_cast<Index>(h), e);
    }
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const auto& uses = edge_uses[e];
      DisjointSets sets(uses.size());
      std::unordered_map<Index, int> first_use_of_face;
      bool overshared = false;
      for (std::size_t i = 0; i < uses.size(); ++i) {
        for (int lf : inc.edge_faces[uses[i].second]) {
          const Index f = hex_faces[uses[i].first][lf];
          overshared |= faces[f].uses.size() > 2;
          auto [it, inserted] = first_use_of_face.try_emplace(f, static_cast<int>(i));
          if (!inserted) sets.unite(it->second, static_cast<int>(i));
        }
      }
      if (overshared || sets.count() != 1) r.nonmanifold_edges.push_back(edges[e]);
    }
  }

  // Vertices: the link (triangles = hexes, edges = faces, vertices = edges at the vertex) must
  // be connected with Euler characteristic 2 (sphere, interior) or 1 (disk, boundary).
  std::vector<std::vector<std::pair<Index, int>>> vertex_uses(mesh.points.size());  // (hex, corner)
  for (std::size_t h = 0; h < nh; ++h) {
    for (int c = 0; c < topo::kHexCorners; ++c)
      vertex_uses[proper.hexes[h][c]].emplace_back(static_cast<Index>(h), c);
  }
  for (std::size_t v = 0; v < vertex_uses.size(); ++v) {
    const auto& uses = vertex_uses[v];
    if (uses.empty()) {
      ++r.unused_nodes;
      continue;
    }
    ++r.num_vertices;
    DisjointSets sets(uses.size());
    std::unordered_map<Index, int> first_use_of_face;
    std::unordered_set<Index> link_vertices;
    bool boundary = false, overshared = false;
    for (std::size_t i = 0; i < uses.size(); ++i) {
      const auto [h, c] = uses[i];
      for (int lf : inc.corner_faces[c]) {
        const Index f = hex_faces[h][lf];
        boundary |= faces[f].uses.size() == 1;
        overshared |= faces[f].uses.size() > 2;
        auto [it, inserted] = first_use_of_face.try_emplace(f, static_cast<int>(i));
        if (!inserted) sets.unite(it->second, static_cast<int>(i));
      }
      for (int le : inc.corner_edges[c]) link_vertices.insert(hex_edges[h][le]);
    }
    const auto link_euler = static_cast<long>(link_vertices.size()) -
                            static_cast<long>(first_use_of_face.size()) +
                            static_cast<long>(uses.size());
    if (overshared || sets.count() != 1 || link_euler != (boundary ? 1 : 2)) {
      r.nonmanifold_vertices.push_back(static_cast<Index>(v));
    }
  }

  r.num_edges = static_cast<Index>(edges.size());
  r.num_faces = static_cast<Index>(faces.size());
  r.num_cells = static_cast<Index>(nh);
  r.euler = r.num_vertices - r.num_edges + r.num_faces - r.num_cells;

  r.boundary = extract_boundary(proper);
  // Report boundary quads against the input hex numbers.
  for (auto* list : {&r.boundary.faces, &r.boundary.rejected}) {
    for (auto& q : *list) q.hex = original[q.hex];
  }
  return r;
}

// ---- Planar quad meshes --------------------------------------------------------------------

bool QuadValidityReport::ok() const {
  return out_of_range_quads.empty() && non_finite_nodes.empty() && repeated_node_quads.empty() &&
         planar && overshared_edges.empty() && misoriented_edges.empty() &&
         nonmanifold_vertices.empty() && inverted_quads.empty();
}

std::string QuadValidityReport::summary() const {
  std::ostringstream os;
  os << "quad mesh: " << num_quads << " quads, " << num_nodes
     << " nodes: " << (ok() ? "valid" : "INVALID") << "\n";
  os << "  complex: V - E + F = " << num_vertices << " - " << num_edges << " + " << num_faces
     << " = " << euler << "\n";
  os << "  boundary: " << boundary_loops.size() << " loop(s) of";
  for (const auto& l : boundary_loops) os << " " << l.size();
  os << " edges\n";
  if (!planar) os << "  not planar\n";
  if (unused_nodes > 0) os << "  unused nodes: " << unused_nodes << "\n";
  list(os, "quads with out-of-range nodes", out_of_range_quads, show_index);
  list(os, "nodes with non-finite coordinates", non_finite_nodes, show_index);
  list(os, "quads with a repeated node", repeated_node_quads, show_index);
  list(os, "edges shared by more than two quads", overshared_edges, show_key<2>);
  list(os, "edges run in the same direction by both quads", misoriented_edges, show_key<2>);
  list(os, "non-manifold vertices", nonmanifold_vertices, show_index);
  list(os, "quads with a non-positive corner", inverted_quads, show_index);
  return os.str();
}

QuadValidityReport check_validity(const QuadMesh& mesh, const Point& normal_in) {
  QuadValidityReport r;
  r.num_nodes = static_cast<Index>(mesh.points.size());
  r.num_quads = static_cast<Index>(mesh.quads.size());
  r.non_finite_nodes = non_finite(mesh.points);
  const Point normal = normal_in.normalized();

  if (!mesh.points.empty() && r.non_finite_nodes.empty()) {
    Point lo = mesh.points[0], hi = mesh.points[0];
    for (const auto& p : mesh.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double tol = 1e-9 * std::max((hi - lo).norm(), 1e-300);
    for (const auto& p : mesh.points) r.planar &= std::abs((p - mesh.points[0]).dot(normal)) <= tol;
  }

  std::vector<std::array<Index, 4>> proper;
  for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
    const auto& quad = mesh.quads[q];
    if (!in_range(quad, mesh.points.size())) {
      r.out_of_range_quads.push_back(static_cast<Index>(q));
      continue;
    }
    if (quad_jacobian(quad_corners(mesh, static_cast<Index>(q)), normal) <= 0.0) {
      r.inverted_quads.push_back(static_cast<Index>(q));
    }
    if (has_repeated(quad)) {
      r.repeated_node_quads.push_back(static_cast<Index>(q));
    } else {
      proper.push_back(quad);
    }
  }

  // Edges with their uses (quad, local edge); the direction of a use is quad order.
  std::unordered_map<EdgeKey, Index, IndexArrayHash> edge_id;
  std::vector<EdgeKey> edges;
  std::vector<std::vector<std::pair<Index, int>>> edge_uses;
  for (std::size_t q = 0; q < proper.size(); ++q) {
    for (int e = 0; e < 4; ++e) {
      const auto& c = topo::kQuadEdgeCorners[e];
      const EdgeKey k = edge_key(proper[q][c[0]], proper[q][c[1]]);
      auto [it, inserted] = edge_id.try_emplace(k, static_cast<Index>(edges.size()));
      if (inserted) {
        edges.push_back(k);
        edge_uses.emplace_back();
      }
      edge_uses[it->second].emplace_back(static_cast<Index>(q), e);
    }
  }
  auto tail = [&](const std::pair<Index, int>& u) {
    return proper[u.first][topo::kQuadEdgeCorners[u.second][0]];
  };
  auto head = [&](const std::pair<Index, int>& u) {
    return proper[u.first][topo::kQuadEdgeCorners[u.second][1]];
  };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto& uses = edge_uses[e];
    if (uses.size() > 2) r.overshared_edges.push_back(edges[e]);
    if (uses.size() == 2 && tail(uses[0]) == tail(uses[1])) r.misoriented_edges.push_back(edges[e]);
  }

  // Vertices: the quads around a vertex must be connected through the edges at it.
  std::vector<std::vector<std::pair<Index, int>>> vertex_uses(mesh.points.size());
  for (std::size_t q = 0; q < proper.size(); ++q) {
    for (int c = 0; c < 4; ++c) vertex_uses[proper[q][c]].emplace_back(static_cast<Index>(q), c);
  }
  for (std::size_t v = 0; v < vertex_uses.size(); ++v) {
    const auto& uses = vertex_uses[v];
    if (uses.empty()) {
      ++r.unused_nodes;
      continue;
    }
    ++r.num_vertices;
    DisjointSets sets(uses.size());
    std::unordered_map<Index, int> first_use_of_edge;
    bool overshared = false;
    for (std::size_t i = 0; i < uses.size(); ++i) {
      const auto [q, c] = uses[i];
      // The two edges at corner c: edge c (leaving it) and edge c-1 (arriving).
      for (int le : {c, (c + 3) % 4}) {
        const auto& lc = topo::kQuadEdgeCorners[le];
        const Index e = edge_id.at(edge_key(proper[q][lc[0]], proper[q][lc[1]]));
        overshared |= edge_uses[e].size() > 2;
        auto [it, inserted] = first_use_of_edge.try_emplace(e, static_cast<int>(i));
        if (!inserted) sets.unite(it->second, static_cast<int>(i));
      }
    }
    if (overshared || sets.count() != 1) r.nonmanifold_vertices.push_back(static_cast<Index>(v));
  }

  r.num_edges = static_cast<Index>(edges.size());
  r.num_faces = static_cast<Index>(proper.size());
  r.euler = r.num_vertices - r.num_edges + r.num_faces;

  // Boundary loops: chain the boundary edges (used once) tail to head, in quad direction so
  // that the mesh is on the left.
  std::vector<std::pair<Index, Index>> bedges;  // (tail, head)
  std::unordered_map<Index, std::vector<std::size_t>> leaving;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edge_uses[e].size() != 1) continue;
    leaving[tail(edge_uses[e][0])].push_back(bedges.size());
    bedges.emplace_back(tail(edge_uses[e][0]), head(edge_uses[e][0]));
  }
  std::vector<bool> used(bedges.size(), false);
  for (std::size_t start = 0; start < bedges.size(); ++start) {
    if (used[start]) continue;
    std::vector<Index> loop;
    std::size_t e = start;
    while (true) {
      used[e] = true;
      loop.push_back(bedges[e].first);
      const Index next_node = bedges[e].second;
      if (next_node == bedges[start].first) break;
      const auto it = leaving.find(next_node);
      std::size_t next = bedges.size();
      if (it != leaving.end()) {
        for (std::size_t cand : it->second) {
          if (!used[cand]) {
            next = cand;
            break;
          }
        }
      }
      if (next == bedges.size()) break;  // open chain: only in an invalid mesh
      e = next;
    }
    r.boundary_loops.push_back(std::move(loop));
  }
  return r;
}

}  // namespace geode::primal
