#pragma once
// Exact combinatorial isomorphism of hex meshes (and of quad meshes): compares a built template
// against a reference such as the paper's Appendix A (the tests; the Python module's
// geode.isomorphism).
//
// Two meshes are isomorphic when a node bijection m and a cell bijection exist such that each
// cell a of the first maps to a cell b of the second *as the same cube* (square): there is a
// symmetry s of the reference cell with m(a[c]) == b[s[c]] for every corner c. The symmetries
// are the 48 (8) corner permutations that preserve the edges of primal/topology.hpp; they
// include reflections, so a mesh and its mirror image are isomorphic. Boundary nodes map to
// boundary nodes automatically (a boundary face is a face of one cell only).
//
// Search: joint colour refinement of the nodes (number of cells, boundary flag, edge degree,
// optional user label, then the multiset of neighbour colours, repeated until stable), then
// backtracking over the cells in breadth-first order through shared faces. Once a seed cell is
// placed, every face neighbour has at most one candidate cell and one symmetry, so the search
// only branches at the seed of each face-connected component: about (seed candidates x
// symmetries x cells) work, milliseconds for a thousand hexes.
#include <array>
#include <optional>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

// Corner permutations of the cube (the square) preserving its edges, derived from the edge
// tables of primal/topology.hpp; the identity comes first.
const std::vector<std::array<int, 8>>& hex_symmetries();   // 48
const std::vector<std::array<int, 4>>& quad_symmetries();  // 8

// True when the cube symmetry is a rotation (keeps the right-handed corner frames of
// kHexCornerNeighbors right-handed): 24 of the 48.
bool is_rotation(const std::array<int, 8>& symmetry);

struct MeshMapping {
  std::vector<Index> node_map;  // node of the first mesh -> node of the second
  std::vector<Index> cell_map;  // hex (quad) of the first -> hex (quad) of the second
};

// Optional node labels, one per node of each mesh (or both empty): the mapping must send each
// node to a node with the same label, e.g. "on the top face of the box" = 1.
struct NodeLabels {
  std::vector<int> first;
  std::vector<int> second;
};

// An isomorphism from `a` to `b`, or nothing when none exists. Throws geode::InvalidInput
// for a corner out of range or repeated in a cell, geode::TopologyError for a face shared by
// more than two cells, both naming the mesh ("first"/"second") and the cell.
std::optional<MeshMapping> find_isomorphism(const HexMesh& a, const HexMesh& b,
                                            const NodeLabels& labels = {});
std::optional<MeshMapping> find_isomorphism(const QuadMesh& a, const QuadMesh& b,
                                            const NodeLabels& labels = {});

// Independent check of a mapping against the definition above (bijections, every cell sent to
// its image cell by a symmetry, labels kept). Used by tests to validate what the search returns.
bool is_isomorphism(const HexMesh& a, const HexMesh& b, const MeshMapping& m,
                    const NodeLabels& labels = {});
bool is_isomorphism(const QuadMesh& a, const QuadMesh& b, const MeshMapping& m,
                    const NodeLabels& labels = {});

}  // namespace geode::primal
