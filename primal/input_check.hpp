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
// - the boundary a 2-manifold: every boundary edge on exactly two boundary faces (four or more:
//   parts touching along the edge only; one or three: faces not matched node for node), and at
//   every boundary node the boundary faces around it one cycle (one disk; two or more: parts
//   touching at that node only, or a finer part beside a coarser one sharing only corners, whose
//   middle nodes hang). These are topology refusals (TopologyError). A node whose element star
//   falls apart needs no test of its own: a component of the star with no boundary face at the
//   node has a closed link of positive triangles, so it covers the node's neighbourhood once
//   more, and the covering below counts 2 or more there.
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
#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <geode/primal/model.hpp>
#include <geode/primal/shares.hpp>

namespace geode::primal {

// Shares (shares.hpp): the check shared among `shares` processes, this one being `share`: each
// pairs the faces whose lowest node is in its run of the nodes, then `exchange` gives each the
// whole pairing, and every process goes on from the same data to the same findings. More than
// one share without an exchange is refused (std::invalid_argument).
struct InputCheckOptions : Shares {
  bool contacts = true;             // boundary faces crossing or facing across a thin gap
  double gap_fraction = 0.05;       // a gap thinner than this x the faces' longest edge is refused
  std::size_t max_components = 32;  // boundary components whose degree is checked
  std::size_t max_findings = 8;     // the check stops after this many
  // When set, filled with the pairs of elements sharing a face, by flat number (submodel.hpp's
  // element_offsets), in the order the check pairs them: the faces this share pairs (every face
  // with one share), then each interface quad with the triangles covering it (share 0 only: every
  // share matches the same interface). What geode_mpi's partition graph is made of, so that the
  // faces are paired once (parallel/partition.hpp). Complete only when the check finds nothing.
  std::vector<std::array<Index, 2>>* element_pairs = nullptr;
  // require_single_covering: appended to the message of a fold with a tet or pyramid in it
  // (kSameSideFace, kFoldedNode), e.g. what the command offers for one.
  std::string fold_hint;
};

enum class InputFault {
  kOversharedFace,    // a face used by three or more elements
  kDuplicateElement,  // two elements of one kind on the same nodes
  kSameSideFace,      // two elements on the same side of their shared face
  kNonManifoldEdge,   // a boundary edge on other than two boundary faces
  kNonManifoldNode,   // the boundary faces around a node form two or more cycles (disks)
  kFoldedNode,        // the corners around a node cover it more (or less) than once
  kCrossingFaces,     // two boundary faces cross
  kGap,               // two boundary faces face each other across a gap without sharing nodes
  kCoveredTwice,      // an element inside another part (winding number of the boundary != 1)
};

struct InputFinding {
  InputFault fault = InputFault::kFoldedNode;
  std::vector<ElementRef> elements;  // the elements at fault (1 to 3)
  Index node = kInvalidIndex;        // kFoldedNode, kNonManifoldNode: the node; kNonManifoldEdge:
                                     // the edge's first node
  Point place = Point::Zero();       // where
  // kFoldedNode: covering count (angle sum / expected); kGap: the gap width (0: the faces
  // coincide, duplicated nodes); kCoveredTwice: the winding number; kNonManifoldEdge: the
  // boundary faces on the edge; kNonManifoldNode: the cycles of boundary faces around the node.
  double measure = 0.0;
  Index edge_end = kInvalidIndex;  // kNonManifoldEdge: the edge's other node
  // Whether the finding is a topology refusal (the non-manifold ones) rather than bad input.
  bool topological() const {
    return fault == InputFault::kNonManifoldEdge || fault == InputFault::kNonManifoldNode;
  }
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

// Throws "source: <the first finding's text>" when check_input finds anything: TopologyError
// (exit 3) for a non-manifold boundary, which is well-formed but no sheet arrangement can be the
// dual of, InvalidInput (exit 2) for the rest, which is not a mesh of one domain at all.
void require_single_covering(const Model& model, std::string_view source,
                             const InputCheckOptions& options = {});

}  // namespace geode::primal
