#pragma once
// Shared entities of a hex mesh (edges and faces identified by their sorted node numbers) and
// its boundary: the faces used by exactly one hex, as a list and as a quad surface checked by
// OpenMesh (the OpenMesh surface itself: primal/boundary_surface.hpp, the one header that
// exposes OpenMesh).
#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

// An edge or face is identified by its node numbers sorted ascending, so that every element
// using it produces the same key. A triangle's FaceKey pads slot 3 with kInvalidIndex.
using EdgeKey = std::array<Index, 2>;
using FaceKey = std::array<Index, 4>;

EdgeKey edge_key(Index a, Index b);

// 3 or 4 nodes. Inline: dicing, the interface search and the boundary scans make millions.
inline FaceKey face_key(std::span<const Index> nodes) {
  assert(nodes.size() == 3 || nodes.size() == 4);
  FaceKey k{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::copy(nodes.begin(), nodes.end(), k.begin());
  // Insertion sort: std::sort on a 3-4 element prefix trips GCC 12's -Warray-bounds.
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    for (std::size_t j = i; j > 0 && k[j - 1] > k[j]; --j) std::swap(k[j - 1], k[j]);
  }
  return k;
}

// Hash for EdgeKey / FaceKey (and any std::array<Index, N>) in unordered containers.
struct IndexArrayHash {
  template <std::size_t N>
  std::size_t operator()(const std::array<Index, N>& a) const noexcept {
    std::size_t h = 0x9e3779b97f4a7c15ull;
    for (Index i : a)
      h = (h ^ index_cast<std::size_t>(static_cast<std::uint32_t>(i))) * 0x100000001b3ull;
    return h;
  }
};

// One use of a face: hex `hex`, local face `local_face` (topology::kHexFaceCorners).
struct HexFaceUse {
  Index hex = kInvalidIndex;
  int local_face = -1;
};

// A face of the mesh with every hex using it (1 on the boundary, 2 inside, more if invalid).
struct UniqueFace {
  FaceKey key{};
  std::array<Index, 4> nodes{};  // ordered outward of uses[0]
  std::vector<HexFaceUse> uses;
};

// Every face once, in order of first appearance (hex by hex, local faces in table order).
// Throws InvalidInput if a hex references a node out of range.
std::vector<UniqueFace> unique_faces(const HexMesh& mesh);

// Every edge once, in order of first appearance (hex by hex, topology::kHexEdgeCorners order).
std::vector<EdgeKey> unique_edges(const HexMesh& mesh);

// A face used by exactly one hex; `nodes` ordered counter-clockwise seen from outside the mesh.
struct BoundaryQuad {
  Index hex = kInvalidIndex;
  int local_face = -1;
  std::array<Index, 4> nodes{};
};

std::vector<BoundaryQuad> boundary_quads(const HexMesh& mesh);

// The faces shared by two hexes of different blocks (mesh.block; none when it is empty): the
// material interfaces, once each, as a BoundaryQuad of the second hex using the face (its
// nodes ordered outward of that hex), in order of that use. Throws InvalidInput when mesh.block
// is neither empty nor one per hex.
std::vector<BoundaryQuad> block_interface_quads(const HexMesh& mesh);

// boundary_quads then block_interface_quads, each in its order, kept only where a quad has a
// node flagged in `at` (one flag per node), found by matching the faces of `hexes` (ascending)
// alone: the same quads when every hex holding a flagged node is among `hexes`, at the cost of
// those hexes instead of the mesh's (local smoothing: the nodes of a few seeds in a large mesh).
std::vector<BoundaryQuad> surface_quads_at(const HexMesh& mesh, std::span<const Index> hexes,
                                           std::span<const char> at);

// The nodes of the boundary quads, ascending.
std::vector<Index> boundary_nodes(const HexMesh& mesh);

// The boundary as a quad surface, built with OpenMesh (which refuses complex edges and
// vertices); boundary_surface.hpp returns the OpenMesh surface too.
struct BoundarySurface {
  std::vector<Index> vertex_node;      // surface vertex index -> hex mesh node
  std::vector<BoundaryQuad> faces;     // surface face index -> boundary quad
  std::vector<BoundaryQuad> rejected;  // quads OpenMesh refused (complex edge or vertex)
  bool closed = false;                 // every boundary edge is shared by two boundary quads
  bool manifold = false;               // no quad rejected and every surface vertex is manifold
  // V - E + F of the boundary quads, counted combinatorially (also when quads were rejected).
  int euler = 0;
};

BoundarySurface extract_boundary(const HexMesh& mesh);
// The same from boundary quads already found (in the order given, nodes outward), over `points`.
BoundarySurface extract_boundary(const std::vector<Point>& points, std::vector<BoundaryQuad> quads);

}  // namespace geode::primal
