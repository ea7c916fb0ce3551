#pragma once
// Does an input model cover its domain once? The read-time counterpart of check_validity (which
// judges hex outputs): a model whose elements are each positive can still fold over itself (an
// element written positively over its neighbours), hold two parts that overlap, or leave a gap
// along an interface meant to be shared. check_input finds these on any mix of hexes, tets,
// pyramids and wedges, naming input elements and a place, fast enough to run on every read.
//
// What is checked (each finding names the elements by ElementRef and a point):
// - face pairing: a face used by more than two elements, or by two that see it in the same cyclic
//   order (both on one side: a fold), or one element twice. A quad one side meets as two or four
//   triangles of the other (the quad-triangle interface conform makes conforming) counts as paired.
// - local covering at every node: the solid angles of the corners around it (the cones of their
//   edges, as check_validity's local covering) add up to 4 pi inside and, on the boundary, to the
//   solid angle the boundary faces there enclose (Gauss-Bonnet); more means the elements wrap
//   around the node more than once.
// - boundary contacts (Options::contacts): two boundary faces without a common node that cross
//   (two parts overlap), or that face each other closer than gap_fraction x their longest edge
//   (an interface with a gap, or duplicated interface nodes not merged).
// - degree: an element of each boundary component (up to max_components) must be covered once by
//   the winding number of the whole boundary (a part lying inside another one).
// Elements are assumed to have passed check_geometry (positive corners).
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <geode/primal/model.hpp>

namespace geode::primal {

struct InputCheckOptions {
  bool contacts = true;             // boundary faces crossing or facing across a thin gap
  double gap_fraction = 0.05;       // a gap thinner than this x the faces' longest edge is refused
  std::size_t max_components = 32;  // boundary components whose degree is checked
  std::size_t max_findings = 8;     // the check stops after this many
};

enum class InputFault {
  kOversharedFace,    // a face used by three or more elements
  kDuplicateElement,  // two elements of one kind on the same nodes
  kSameSideFace,      // two elements on the same side of their shared face
  kFoldedNode,        // the corners around a node cover it more (or less) than once
  kCrossingFaces,     // two boundary faces cross
  kGap,               // two boundary faces face each other across a gap without sharing nodes
  kCoveredTwice,      // an element inside another part (winding number of the boundary != 1)
};

struct InputFinding {
  InputFault fault = InputFault::kFoldedNode;
  std::vector<ElementRef> elements;  // the elements at fault (1 to 3)
  Index node = kInvalidIndex;        // kFoldedNode: the node
  Point place = Point::Zero();       // where
  // kFoldedNode: covering count (angle sum / expected); kGap: the gap width (0: the faces
  // coincide, duplicated nodes); kCoveredTwice: the winding number.
  double measure = 0.0;
  // One line: the reason, the elements and node by the model's file ids, the place.
  std::string text(const Model& model) const;
};

struct InputCheckResult {
  std::vector<InputFinding> findings;
  std::size_t boundary_faces = 0;
  std::size_t interface_quads = 0;  // quads met by two or four triangles
  std::size_t boundary_components = 0;
  bool ok() const { return findings.empty(); }
};

InputCheckResult check_input(const Model& model, const InputCheckOptions& options = {});

// Throws InvalidInput "source: <the first finding's text>" when check_input finds anything.
void require_single_covering(const Model& model, std::string_view source,
                             const InputCheckOptions& options = {});

}  // namespace geode::primal
