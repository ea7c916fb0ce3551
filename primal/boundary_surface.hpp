#pragma once
// The boundary of a hex mesh as an OpenMesh surface, for code that works on it with OpenMesh.
// The only primal header that includes OpenMesh: geode_primal links OpenMesh privately, so a
// target that includes this header links OpenMeshCore itself.
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <vector>

#include <geode/primal/boundary.hpp>

namespace geode::primal {

// Float points, the library's default traits; exact coordinates are points[vertex_node[v]].
using SurfaceMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

// extract_boundary (boundary.hpp) that also hands over the surface it built: its vertex v is
// node b.vertex_node[v], its face f the boundary quad b.faces[f].
BoundarySurface extract_boundary(const std::vector<Point>& points, std::vector<BoundaryQuad> quads,
                                 SurfaceMesh& surface);

}  // namespace geode::primal
