#pragma once
// Dicing: split every element at its edge midpoints, face centres and centre. Quads -> 4
// quads, triangles -> 3 quads, hexes -> 8 hexes, tets -> 4 hexes. Each edge and each face gets
// one new node shared by all elements around it, so a conforming mesh dices into a conforming
// mesh. Children keep the corner order of primal/topology.hpp and the orientation of their
// parent: a positively oriented (VTK order) input gives positively oriented output.
//
// Node numbering of the result: the input points keep their numbers 0..V-1 (even unused
// ones), then one node per edge, per face (3D only), per element, each group in order of first
// appearance, so V' = V + E + F + C (hexes, tets) or V + E + F (quads, triangles).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/mesh.hpp>

namespace geode::primal {

enum class NodeOriginKind : std::uint8_t { kNode, kEdge, kFace, kCell };

// What a node of a diced mesh came from.
struct NodeOrigin {
  NodeOriginKind kind = NodeOriginKind::kNode;
  // kNode: {node}; kEdge: its 2 nodes; kFace: its 3 or 4 nodes; sorted ascending and padded
  // with kInvalidIndex (a FaceKey). kCell: all kInvalidIndex.
  FaceKey nodes{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  Index element = kInvalidIndex;  // kCell: the input element it is the centre of
};

struct DicedHexMesh {
  HexMesh mesh;                    // block copied from the parent element when given
  std::vector<NodeOrigin> origin;  // per node of mesh
  std::vector<Index> parent;       // per hex of mesh: the input element
};

struct DicedQuadMesh {
  QuadMesh mesh;
  std::vector<NodeOrigin> origin;
  std::vector<Index> parent;
};

// dice()'s children without its points and origins, for callers that number and place the
// diced nodes themselves (dice_model): children in dice()'s node numbers (above), V being the
// `nodes` passed. `room`: capacity in `children` for that many more, which the caller adds
// without a copy of the children.
template <std::size_t NC>
struct DicedCellsOf {
  std::vector<FaceKey> edges;  // per edge node (V, V + 1, ...): its 2 nodes, ascending, padded
  std::vector<FaceKey> faces;  // per face node (after the edges): its 3 or 4 nodes, ascending
  std::vector<std::array<Index, NC>> children;
  std::vector<Index> parent;  // per child: the input element
};
using DicedCells = DicedCellsOf<8>;
DicedCells dice_cells(Index nodes, const std::vector<std::array<Index, 8>>& hexes,
                      std::size_t room = 0);
DicedCells dice_cells(Index nodes, const std::vector<std::array<Index, 4>>& tets,
                      std::size_t room = 0);

// Where dice() places a node: the centroid of the corners (in their order: an element's
// centre), or of an edge or face node's origin nodes (a padded FaceKey).
Point corner_centroid(std::span<const Point> points, std::span<const Index> corners);
Point origin_centroid(std::span<const Point> points, const FaceKey& key);

// Throw geode::InvalidInput naming the element if a node number is out of range.
DicedHexMesh dice(const HexMesh& mesh);    // 8 per hex; child c has parent corner c as corner c
DicedHexMesh dice(const TetMesh& mesh);    // 4 per tet; child c has parent corner c as corner 0
DicedQuadMesh dice(const QuadMesh& mesh);  // 4 per quad; like hexes
DicedQuadMesh dice(const TriMesh& mesh);   // 3 per triangle; like tets

// The dicing tables dice() works from: table[child][k] is the bit mask of the parent's local
// corners whose centroid child corner k is (one bit: the corner itself; all bits: the cell
// centre). check_dicing (dice_model.hpp) reads a diced model against them.
using DicingTable8 = std::array<std::array<unsigned, 8>, 8>;
using DicingTable4 = std::array<std::array<unsigned, 8>, 4>;
const DicingTable8& hex_dicing_table();
const DicingTable4& tet_dicing_table();

// The lowest scaled Jacobian (primal/quality.hpp) of the hexes `dice` would make of these
// elements, computed element by element without building the diced mesh: what an element
// part gives when diced alone, the yardstick for a transition placed beside it. 1 when empty.
double diced_min_scaled_jacobian(std::span<const Point> points,
                                 std::span<const std::array<Index, 4>> tets);
double diced_min_scaled_jacobian(std::span<const Point> points,
                                 std::span<const std::array<Index, 8>> hexes);

// One tet's lowest diced scaled Jacobian, from its four corners (for callers that move nodes).
double diced_tet_min_scaled_jacobian(const std::array<Point, 4>& corners);
// The same, except that once a child hex is at or below `bound` the rest are not measured: the
// value is exact when above `bound`, and some value at or below it otherwise. The children are
// taken from child *first (0 to 3) on, which is left at the child found at or below `bound`: a
// caller trying one node at many places meets the same child failing.
double diced_tet_min_scaled_jacobian(const std::array<Point, 4>& corners, double bound, int* first);

// The same per element: each one's lowest diced scaled Jacobian, in element order (the local
// yardstick of a transition next to it).
std::vector<double> diced_scaled_jacobian_per_cell(std::span<const Point> points,
                                                   std::span<const std::array<Index, 4>> tets);
std::vector<double> diced_scaled_jacobian_per_cell(std::span<const Point> points,
                                                   std::span<const std::array<Index, 8>> hexes);

}  // namespace geode::primal
