#include <geode/primal/boundary.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include <algorithm>
#include <cassert>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include <geode/primal/boundary_surface.hpp>
#include <geode/primal/detail/lowest_node_sort.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/key_map.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace topo = topology;

EdgeKey edge_key(Index a, Index b) { return a < b ? EdgeKey{a, b} : EdgeKey{b, a}; }

namespace {

// OpenMesh reports refused faces on its process-wide error stream; extract_boundary reports them
// in `rejected` instead. Boundaries are extracted from several threads at once (templates are
// built in parallel), and OpenMesh's omerr() connects std::cerr on its first call without a lock,
// so the first call and every enable/disable go through one mutex (what OpenMesh then writes
// to the disabled stream is buffered under OpenMesh's own lock); the stream is disabled while
// any extraction is adding faces and restored to its previous state when the last one ends.
class OpenMeshErrorsSilenced {
 public:
  OpenMeshErrorsSilenced() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (active_++ == 0) {
      was_enabled_ = omerr().is_enabled();
      omerr().disable();
    }
  }
  ~OpenMeshErrorsSilenced() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (--active_ == 0 && was_enabled_) omerr().enable();
  }
  OpenMeshErrorsSilenced(const OpenMeshErrorsSilenced&) = delete;
  OpenMeshErrorsSilenced& operator=(const OpenMeshErrorsSilenced&) = delete;

 private:
  static inline std::mutex mutex_;
  static inline int active_ = 0;
  static inline bool was_enabled_ = true;
};

void check_indices(const HexMesh& mesh) {
  const auto n = index_cast(mesh.points.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    for (Index v : mesh.hexes[h]) {
      if (v < 0 || v >= n) {
        throw InvalidInput("hex " + std::to_string(h) + ": node " + std::to_string(v) +
                           " out of range [0, " + std::to_string(n) + ")");
      }
    }
  }
}

std::array<Index, 4> hex_face_nodes(const std::array<Index, 8>& hex, int f) {
  std::array<Index, 4> q{};
  for (int i = 0; i < 4; ++i) q[i] = hex[topo::kHexFaceCorners[f][i]];
  return q;
}

}  // namespace

std::vector<UniqueFace> unique_faces(const HexMesh& mesh) {
  check_indices(mesh);
  std::vector<UniqueFace> faces;
  std::unordered_map<FaceKey, std::size_t, IndexArrayHash> index;
  index.reserve(mesh.hexes.size() * 4);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    for (int f = 0; f < topo::kHexFaces; ++f) {
      const auto nodes = hex_face_nodes(mesh.hexes[h], f);
      const FaceKey key = face_key(nodes);
      auto [it, inserted] = index.try_emplace(key, faces.size());
      if (inserted) faces.push_back(UniqueFace{key, nodes, {}});
      faces[it->second].uses.push_back(HexFaceUse{index_cast(h), f});
    }
  }
  return faces;
}

std::vector<EdgeKey> unique_edges(const HexMesh& mesh) {
  check_indices(mesh);
  std::vector<EdgeKey> edges;
  std::unordered_set<EdgeKey, IndexArrayHash> seen;
  seen.reserve(mesh.hexes.size() * 4);
  for (const auto& hex : mesh.hexes) {
    for (const auto& e : topo::kHexEdgeCorners) {
      const EdgeKey key = edge_key(hex[e[0]], hex[e[1]]);
      if (seen.insert(key).second) edges.push_back(key);
    }
  }
  return edges;
}

std::vector<Index> boundary_nodes(const HexMesh& mesh) {
  std::vector<char> on(mesh.points.size(), 0);
  for (const auto& q : boundary_quads(mesh))
    for (Index v : q.nodes) on[index_cast<std::size_t>(v)] = 1;
  std::vector<Index> out;
  for (std::size_t i = 0; i < on.size(); ++i)
    if (on[i]) out.push_back(index_cast(i));
  return out;
}

std::vector<BoundaryQuad> boundary_quads(const HexMesh& mesh) {
  check_indices(mesh);
  // Every face use (6 hex + local face) sorted by its key's smallest node, so that a face's
  // uses sit together (detail::sort_by_lowest_node, in parallel: a hash map of first uses was
  // one thread's random accesses, 0.04 s on the n = 36 bench's hex part); a face used once is
  // on the boundary. Boundary faces in order of their use: the order of first appearance.
  using Use = detail::KeyedUse<4>;
  const std::size_t nh = mesh.hexes.size();
  std::vector<std::size_t> start;
  const std::vector<Use> uses = detail::sort_by_lowest_node<Use>(
      mesh.points.size(),
      [&](auto&& visit) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nh, 4096),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                            for (std::size_t h = r.begin(); h != r.end(); ++h)
                              for (int f = 0; f < topo::kHexFaces; ++f)
                                visit(Use{face_key(hex_face_nodes(mesh.hexes[h], f)),
                                          6 * h + index_cast<std::size_t>(f)});
                          });
      },
      [](const Use& u) { return u.key[0]; }, start);
  std::vector<char> once(6 * nh, 0);
  detail::for_each_run(
      start, [&](std::size_t i, std::size_t j) { return uses[i].key == uses[j].key; },
      [&](std::size_t b, std::size_t e) {
        if (e == b + 1) once[uses[b].at] = 1;
      });
  std::vector<BoundaryQuad> out;
  for (std::size_t pos = 0; pos < once.size(); ++pos)
    if (once[pos]) {
      const auto h = index_cast(pos / 6);
      const int f = static_cast<int>(pos % 6);
      out.push_back(BoundaryQuad{h, f, hex_face_nodes(mesh.hexes[index_cast<std::size_t>(h)], f)});
    }
  return out;
}

std::vector<BoundaryQuad> block_interface_quads(const HexMesh& mesh) {
  check_indices(mesh);
  std::vector<BoundaryQuad> out;
  if (mesh.block.empty()) return out;
  if (mesh.block.size() != mesh.hexes.size())
    throw InvalidInput("block_interface_quads: " + std::to_string(mesh.block.size()) +
                       " block ids for " + std::to_string(mesh.hexes.size()) + " hexes");
  KeyMap<4> first_use(mesh.hexes.size() * 3);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int f = 0; f < topo::kHexFaces; ++f) {
      const auto nodes = hex_face_nodes(mesh.hexes[h], f);
      const auto [slot, inserted] = first_use.try_emplace(face_key(nodes), index_cast(6 * h + f));
      if (!inserted && mesh.block[index_cast<std::size_t>(*slot / 6)] != mesh.block[h])
        out.push_back(BoundaryQuad{index_cast(h), f, nodes});
    }
  return out;
}

std::vector<BoundaryQuad> surface_quads_at(const HexMesh& mesh, std::span<const Index> hexes,
                                           std::span<const char> at) {
  check_indices(mesh);
  if (at.size() != mesh.points.size())
    throw InvalidInput("surface_quads_at: " + std::to_string(at.size()) + " node flags for " +
                       std::to_string(mesh.points.size()) + " nodes");
  const bool blocks = !mesh.block.empty();
  if (blocks && mesh.block.size() != mesh.hexes.size())
    throw InvalidInput("surface_quads_at: " + std::to_string(mesh.block.size()) +
                       " block ids for " + std::to_string(mesh.hexes.size()) + " hexes");
  auto flagged = [&](const std::array<Index, 4>& q) {
    return std::any_of(q.begin(), q.end(), [&](Index v) { return at[index_cast<std::size_t>(v)]; });
  };
  // Face key -> its first use (6 hex + local face), negated (-2 - use) once a second hex uses
  // it; the interface quads are found at their later uses, as block_interface_quads does.
  auto first_of = [](Index value) { return value >= 0 ? value : -2 - value; };
  KeyMap<4> first_use(hexes.size() * 3);
  std::vector<BoundaryQuad> between;
  for (Index h : hexes) {
    if (h < 0 || index_cast<std::size_t>(h) >= mesh.hexes.size())
      throw InvalidInput("surface_quads_at: hex " + std::to_string(h) + " out of range");
    for (int f = 0; f < topo::kHexFaces; ++f) {
      const auto nodes = hex_face_nodes(mesh.hexes[index_cast<std::size_t>(h)], f);
      if (!flagged(nodes)) continue;
      const auto [slot, inserted] = first_use.try_emplace(face_key(nodes), 6 * h + f);
      if (inserted) continue;
      const Index first = first_of(*slot);
      *slot = -2 - first;
      if (blocks &&
          mesh.block[index_cast<std::size_t>(first / 6)] != mesh.block[index_cast<std::size_t>(h)])
        between.push_back(BoundaryQuad{h, f, nodes});
    }
  }
  std::vector<BoundaryQuad> out;
  for (Index h : hexes)
    for (int f = 0; f < topo::kHexFaces; ++f) {
      const auto nodes = hex_face_nodes(mesh.hexes[index_cast<std::size_t>(h)], f);
      if (flagged(nodes) && *first_use.find(face_key(nodes)) == 6 * h + f)
        out.push_back(BoundaryQuad{h, f, nodes});
    }
  out.insert(out.end(), between.begin(), between.end());
  return out;
}

BoundarySurface extract_boundary(const HexMesh& mesh) {
  return extract_boundary(mesh.points, boundary_quads(mesh));
}

BoundarySurface extract_boundary(const std::vector<Point>& points,
                                 std::vector<BoundaryQuad> quads) {
  SurfaceMesh surface;
  return extract_boundary(points, std::move(quads), surface);
}

BoundarySurface extract_boundary(const std::vector<Point>& points, std::vector<BoundaryQuad> quads,
                                 SurfaceMesh& surface) {
  BoundarySurface b;
  surface.clear();

  // Combinatorial Euler characteristic, independent of what OpenMesh accepts.
  std::unordered_map<Index, SurfaceMesh::VertexHandle> vertex_of;
  std::unordered_map<EdgeKey, int, IndexArrayHash> edge_uses;
  for (const auto& q : quads) {
    for (int i = 0; i < 4; ++i) {
      vertex_of.try_emplace(q.nodes[i]);
      ++edge_uses[edge_key(q.nodes[i], q.nodes[(i + 1) % 4])];
    }
  }
  b.euler = index_cast<int>(vertex_of.size()) - index_cast<int>(edge_uses.size()) +
            index_cast<int>(quads.size());

  // Vertices in order of first appearance so that the surface is deterministic.
  for (const auto& q : quads) {
    for (Index v : q.nodes) {
      auto& vh = vertex_of[v];
      if (!vh.is_valid()) {
        const Point& p = points[index_cast<std::size_t>(v)];
        vh = surface.add_vertex(SurfaceMesh::Point(
            static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())));
        b.vertex_node.push_back(v);
      }
    }
  }
  const OpenMeshErrorsSilenced silenced;
  for (const auto& q : quads) {
    std::vector<SurfaceMesh::VertexHandle> vhs;
    for (Index v : q.nodes) vhs.push_back(vertex_of[v]);
    const auto fh = surface.add_face(vhs);
    if (fh.is_valid()) {
      assert(index_cast<std::size_t>(fh.idx()) == b.faces.size());
      b.faces.push_back(q);
    } else {
      b.rejected.push_back(q);
    }
  }

  b.closed = std::all_of(edge_uses.begin(), edge_uses.end(),
                         [](const auto& kv) { return kv.second == 2; });
  b.manifold = b.rejected.empty();
  for (auto vh : surface.vertices()) {
    if (!surface.is_manifold(vh)) b.manifold = false;
  }
  return b;
}

}  // namespace geode::primal
