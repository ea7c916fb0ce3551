#pragma once
// Dualize a sheet arrangement into a mesh: every region (d-cell) becomes a node, every
// vertex where d sheets meet becomes an element (a hex in 3D, a quad in 2D) whose corners
// are the 2^d regions around it, ordered by the sheets' sides and oriented by the sign of
// the sheets' gradient determinant so that every element is positively oriented
// (primal/topology.hpp numbering).
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/arrangement.hpp>

namespace geode::stc {

struct DualMesh {
  int dim = 3;
  primal::HexMesh hex;    // dim 3
  primal::QuadMesh quad;  // dim 2
  // Per node: the domain faces its region touches (bit stc::box_face(axis, high), axis in
  // the domain's local coordinates); 0 for interior nodes.
  std::vector<unsigned> node_faces;
  // Per node: the region's sign over every sheet (+1/-1).
  std::vector<std::vector<int>> node_signs;
  // Per element: the sheets meeting at its vertex (sorted), and the vertex position.
  std::vector<std::vector<int>> element_sheets;
  std::vector<primal::Point> element_centres;
};

// Throws TopologyError when an element would repeat a node (a sheet folds back on itself
// around a vertex) or a region is not a ball (a node's link is not a sphere, or a disk on
// the boundary), naming the sheets and where.
DualMesh dualize(const Arrangement& arrangement);

}  // namespace geode::stc
