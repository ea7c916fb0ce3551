#pragma once
// Tets a mesher turned over its neighbours, put back. Debian's Gmsh 4.8 folds hybrid meshes near
// its pyramids (docs/whole-models.md, "Hybrid meshes"): a node moved through the face of a tet,
// whose nodes the mesher then reordered so that it reads positive, lying over its neighbours.
// check_input refuses such a model (two elements on the same side of their shared face); this
// finds each tet that lies on the same side as every element it shares a face with (two
// neighbours turned together: each once the other is turned back), turns it back (now inverted,
// as the geometry has it), and moves one of its free nodes toward the point of its element star
// farthest from the planes of the star's outer faces (the star's Chebyshev centre), until every
// tet around it is positive again and well clear of flat.
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct UnfoldResult {
  std::vector<ElementRef> turned;  // tets whose node order was turned back
  std::vector<Index> moved;        // the nodes moved (at most one per turned tet)
  double farthest = 0.0;           // the longest distance a node moved
  // check_input found nothing (before, or after the mend): no need to run it again. When false
  // the model is as it was given, and require_single_covering names its first fault.
  bool covered_once = false;
  bool unfolded() const { return !moved.empty(); }
};

// Mends the folds check_input finds as above, and only where every fold it found is mended and
// check_input then finds nothing: else the model is left as it was (and the result empty), so
// that the refusal names the first fault as before. A node is moved only if its elements are
// tets of one block and it lies on no boundary face (the model's boundary and its materials do
// not move), no node set and no side set's face.
UnfoldResult unfold_tets(Model& model);

}  // namespace geode::primal
