#pragma once
// Validity of a hex mesh (and of a planar quad mesh): is it a conforming, manifold,
// positively oriented complex? The checks return a report instead of throwing so that a
// researcher can see everything that is wrong at once; report.ok() is the yes/no answer.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/mesh.hpp>

namespace geode::primal {

// A node where the elements around it overlap: the solid angles (angles in 2D) of their corners
// add up to more than the space there, i.e. the elements cover the node's neighbourhood more
// than once although every corner is positive.
struct NodeCoverage {
  Index node = kInvalidIndex;
  double angle = 0.0;  // sum of the incident corners' solid angles (angles in 2D)
  double expected =
      0.0;  // 4 pi (2 pi in 2D) inside; on the boundary what the boundary leaves inside
};

// The direction along which check_validity counts the corner cones at an interior hex node (the
// covering degree, without trigonometry); a node where it lies on a cone's face gets the sum of
// solid angles instead. Public so that tests can put it on a face.
const Point& coverage_probe();

// Elements with an out-of-range node or a repeated node are listed and left out of the
// topological checks (Euler characteristic, faces, edges, vertices, boundary), which run on
// the remaining "proper" elements.
struct HexValidityReport {
  Index num_nodes = 0;
  Index num_hexes = 0;
  std::vector<Index> out_of_range_hexes;   // a node number outside [0, num_nodes)
  std::vector<Index> non_finite_nodes;     // NaN or infinite coordinate
  std::vector<Index> repeated_node_hexes;  // a node appearing twice in one hex
  Index unused_nodes = 0;                  // nodes used by no proper hex

  std::vector<FaceKey> overshared_faces;   // used by more than two hexes
  std::vector<FaceKey> misoriented_faces;  // two hexes see it in the same cyclic order
  // An edge whose hexes are not connected through faces around it (or that has a face used
  // by more than two hexes); a vertex whose link is not a sphere (interior) or a disk
  // (boundary), i.e. not face-connected or of the wrong Euler characteristic.
  std::vector<EdgeKey> nonmanifold_edges;
  std::vector<Index> nonmanifold_vertices;

  // The complex of proper hexes: V - E + F - C (1 for a ball, 0 for a solid torus).
  Index num_vertices = 0, num_edges = 0, num_faces = 0, num_cells = 0;
  int euler = 0;

  BoundarySurface boundary;  // closed, manifold, euler (2 for a sphere) inside

  // Hexes with a corner Jacobian det(e_r, e_s, e_t) <= 0 (topology::kHexCornerNeighbors).
  std::vector<Index> inverted_hexes;

  // Local covering: at a manifold node whose incident corners are all positive, the tangent cones
  // of the corners (spanned by each corner's three edges) must tile the space around it once.
  // Their solid angles sum to 4 pi k at an interior node whose hexes wrap k times around it; at
  // a boundary node the sum must be the solid angle the boundary quads enclose on the inside
  // (2 pi - the sum of the exterior angles of the boundary's spherical polygon around the node,
  // Gauss-Bonnet). Positive Jacobians alone allow k = 2. Nodes with a non-positive corner are
  // not judged here (their hexes are listed as inverted).
  std::vector<NodeCoverage> overlapping_nodes;

  bool ok() const;
  // One line per finding, listing the first few offenders, numbered from `base` (0, or 1 as a
  // file numbers its elements and nodes).
  std::string summary(Index base = 0) const;
};

// Called now and then while check_validity runs with (work done, all the work), in the check's
// own units, one call at a time (from whichever thread did the work), `done` never decreasing
// and equal to `total` at the last call: for a progress bar, the check taking seconds on
// millions of hexes.
using ValidityProgress = std::function<void(std::size_t done, std::size_t total)>;

// Throws InvalidInput for a mesh of 2^28 hexes or more (the incidence is kept in 32 bits).
HexValidityReport check_validity(const HexMesh& mesh, const ValidityProgress& progress = {});

// A quad mesh lying in the plane through its first node with normal `normal`.
struct QuadValidityReport {
  Index num_nodes = 0;
  Index num_quads = 0;
  std::vector<Index> out_of_range_quads;
  std::vector<Index> non_finite_nodes;
  std::vector<Index> repeated_node_quads;
  Index unused_nodes = 0;
  bool planar = true;  // every node within 1e-9 x (bounding box diagonal) of the plane

  std::vector<EdgeKey> overshared_edges;    // used by more than two quads
  std::vector<EdgeKey> misoriented_edges;   // two quads run along it in the same direction
  std::vector<Index> nonmanifold_vertices;  // quads around it not connected through edges

  Index num_vertices = 0, num_edges = 0, num_faces = 0;
  int euler = 0;  // V - E + F: 1 for a disk, 0 for an annulus

  // Boundary edges chained into closed loops, each a node cycle with the mesh on its left
  // (seen from `normal`): the outer loop runs counter-clockwise, holes clockwise.
  std::vector<std::vector<Index>> boundary_loops;

  // Quads with a corner whose signed area (a x b) . normal is <= 0.
  std::vector<Index> inverted_quads;

  // The 2D local covering: at a manifold node whose incident corners are all positive, their
  // angles sum to 2 pi inside and to the boundary's interior angle on the boundary; 4 pi etc.
  // where the quads wrap around the node more than once.
  std::vector<NodeCoverage> overlapping_nodes;

  bool ok() const;
  std::string summary(Index base = 0) const;  // as HexValidityReport's
};

QuadValidityReport check_validity(const QuadMesh& mesh, const Point& normal = Point::UnitZ());

// What makes a report not ok(), in one line for a message ("2 of 26 hexes inverted (a corner
// Jacobian <= 0), hexes: 2 7; ..."; "" when ok()): a count and the first five of each finding,
// cells and nodes named by `cell_number` and `node_number` (index -> the number the output file
// gives it).
using Numbering = std::function<std::int64_t(Index)>;
std::string findings(const HexValidityReport& report, const Numbering& cell_number,
                     const Numbering& node_number);
std::string findings(const QuadValidityReport& report, const Numbering& cell_number,
                     const Numbering& node_number);

}  // namespace geode::primal
