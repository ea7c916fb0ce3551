#pragma once
// Tets and pyramids a mesher turned over their neighbours, put back. Debian's Gmsh 4.8 folds
// hybrid meshes near its pyramids (docs/whole-models.md, "Hybrid meshes"): a node moved through
// the face of a tet, whose nodes the mesher then reordered so that it reads positive, lying over
// its neighbours; a pyramid whose apex lies on the hex's side of its twisted base quad, positive
// along one diagonal and ordered to read so. check_input refuses such a model (two elements on
// the same side of their shared face); this finds each tet or pyramid that lies on the same side
// as every element it shares a face with (two neighbours turned together: each once the other is
// turned back), turns it back (now inverted, as the geometry has it), and moves one of its free
// nodes (a pyramid's: its apex) toward the point of its element star farthest from the planes of
// the star's outer faces (the star's Chebyshev centre), until every element around it is
// positive again and well clear of flat (a pyramid along both base diagonals). A tet or pyramid
// inverted in a model read without check_geometry (a pyramid positive along neither diagonal:
// Gmsh's apex below a twisted base) has a node moved the same way, without the turn.
#include <string>
#include <string_view>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct UnfoldResult {
  std::vector<ElementRef> turned;    // tets and pyramids whose node order was turned back
  std::vector<ElementRef> inverted;  // tets and pyramids read inverted, not turned
  std::vector<Index> moved;          // the nodes moved (at most one per turned or inverted element)
  double farthest = 0.0;             // the longest distance a node moved
  // check_input found nothing (before, or after the mend): no need to run it again. When false
  // the model is as it was given, and require_single_covering names its first fault.
  bool covered_once = false;
  // The model changed: a node moved, or only node orders turned back (a cell written in mirrored
  // order: inverted, and on the same side as every neighbour, positive once turned).
  bool unfolded() const { return !turned.empty() || !moved.empty(); }
};

// Mends the folds check_input finds and the inverted tets and pyramids as above, and only where
// every one is mended and check_input then finds nothing new: else the model is left as it was
// (and the result empty), so that the refusal names the first fault as before. Where only faults
// it does not mend are left (an element written twice), the mends stay and covered_once is
// false: the caller's check names what is left. A node is moved only
// if it lies on no boundary face (the model's boundary and its materials do not move), no node
// set and no side set's face, and its elements are tets and pyramids (whose apex it is) of one
// block. Other elements check_geometry refuses stay: the caller runs it after.
UnfoldResult unfold(Model& model);

// What a refusal offers where unfold may mend it, naming the caller's option ("--unfold",
// "unfold=True"): for a fold (InputCheckOptions::fold_hint) and for a tet or pyramid read
// inverted (ReadOptions::inverted_hint).
std::string fold_hint(std::string_view option);
std::string inverted_hint(std::string_view option);

}  // namespace geode::primal
