#pragma once
// Pillowing (Mitchell and Tautges, "Pillowing doublets: refining a mesh to ensure that faces
// share at most one edge", 4th International Meshing Roundtable, 1995): a new sheet is inserted
// around a shrink set of hexes. Every node of the set's boundary surface is copied, the set's
// hexes move onto the copies (the set shrinks inward), and every boundary face of the set
// becomes a new hex between the face and its copy. Faces of the set on the mesh boundary get
// their hex too, so the mesh boundary keeps its quads and nodes: the new sheet closes inside
// the mesh and every new node is interior.
//
// In the dual, the new sheet is a sphere around the set's dual vertices; each edge of the set's
// boundary gains a hex, which is what removes a doublet (an interior edge in only two hexes)
// when one of its two hexes is the shrink set.
#include <span>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

struct PillowOptions {
  // Each copy starts at its node moved this fraction of the way to the mean centroid of the
  // set's hexes around it (a first guess; smoothing places it).
  double shrink = 0.3;
};

struct PillowResult {
  HexMesh mesh;                // the old hexes first (same numbers), then the new layer
  std::vector<Index> layer;    // the new hexes
  std::vector<Index> copy_of;  // per new node (numbered from the old node count): its node
};

// The shrink set's boundary surface must be a manifold (every node's set hexes connected
// through faces of the set), since a node is copied once. InvalidInput for an empty set, a hex
// number out of range or repeated, or a shrink fraction outside (0, 1).
PillowResult pillow(const HexMesh& mesh, std::span<const Index> shrink_set,
                    const PillowOptions& options = {});

}  // namespace geode::primal
