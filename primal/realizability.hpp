#pragma once
// Combinatorial obstructions to a positive-Jacobian embedding of a hex (or quad) mesh with its
// planar boundary faces kept planar: configurations that no placement of the nodes turns into
// an embedded mesh with positive corner Jacobians, whatever the smoother does. A valid complex
// (primal/validity.hpp) can still carry them; each is reported with the hexes (quads) and
// nodes involved.
//
// Why each one blocks (corner Jacobian = det of the three edge vectors at a hex corner,
// topology::kHexCornerNeighbors; positive at every corner means every dihedral angle of a hex
// at an edge end, and every face angle at a corner, lies strictly between 0 and pi):
//  - doublet: two hexes sharing two faces, i.e. an interior edge in only two hexes. The
//    dihedral angles around an interior edge sum to a multiple of 2 pi, each less than pi, so
//    it needs at least three hexes.
//    (2D: a node inside the mesh in only two quads, which then share both its edges.)
//  - pinched corner: two distinct faces sharing both edges va, vb at a node v. Both faces are
//    tangent at v to the plane of va and vb (a two-sided polygon in the link of v), so the
//    hex corners on each side of the pair cover every direction around v a whole number of
//    times, at least once: at least twice together, and the hexes around v overlap. Corner
//    Jacobians can all be positive then (the hexes wrap twice around v), so this one blocks
//    an embedding, not positive Jacobians; when both faces are on the boundary, the boundary
//    closes on itself at v instead.
//  - two faces on one boundary face: a hex with two of its faces on the same planar boundary
//    face. Where the two faces meet (or along a face, if they are opposite) the hex's edges
//    all lie in that plane: a zero corner Jacobian.
//  - flat corner: a hex corner on a planar boundary face whose three neighbours lie on that
//    face too, so the three edge vectors are coplanar (2D: both neighbours on the straight
//    boundary side through the corner).
//  - two-quad boundary node: a node inside a planar boundary face covered by only two boundary
//    quads. Their angles at the node sum to 2 pi, so one is at least pi and its hex's corner
//    Jacobian is not positive.
// Doublets make pinched corners at both ends of their edge (the two hexes' third faces there);
// those are left out of the pinched corners, and a two-faces hex's corners on the edge the
// faces share are left out of the flat corners, so that each fact is reported once.
//
// Planar boundary faces: the boundary quads (faces used by one hex) are grouped into planar
// patches by region growing over shared boundary edges. A quad joins the patch of a seed quad
// when its normal ((p2 - p0) x (p3 - p1), the bilinear quad's mean normal) is within
// `planar_angle_degrees` of the seed's and its corners lie within `planar_distance` x (the
// bounding box diagonal) of the seed's plane; a quad whose own corners are farther from its
// plane than that is on no planar face. A node is on a planar face when it is a corner of one
// of its quads. For a template, pass `node_faces` instead: the faces of its box each node lies
// on, as bits (templates::Template::node_faces), so the answer does not depend on where the
// nodes currently are.
#include <cstddef>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

enum class ObstructionKind {
  kDoublet,
  kPinchedCorner,
  kTwoFacesOnBoundaryFace,
  kFlatCorner,
  kTwoQuadBoundaryNode
};

// "doublet", "pinched-corner", "two-faces-on-boundary-face", "flat-corner",
// "two-quad-boundary-node".
std::string_view to_string(ObstructionKind kind);

struct Obstruction {
  ObstructionKind kind;
  std::vector<Index> hexes;  // quads for a quad mesh; 0-based, ascending
  std::vector<Index>
      nodes;  // 0-based: the edge (doublet), v a b (pinched), the corner first (flat), the node
};

struct RealizabilityOptions {
  double planar_angle_degrees = 1.0;
  double planar_distance = 1e-6;  // relative to the bounding box diagonal
  // Optional planar faces per node as bits (bit f: the node lies on face f), one entry per node;
  // replaces the geometric grouping when not empty. A boundary quad lies on face f when its
  // corners all do.
  std::vector<unsigned> node_faces;
  // Called at the start and after each of the hex search's stages with (work done, all the
  // work), in units of its own, `done` equal to `total` at the last call: for a progress bar (about
  // 15 s on 5 million hexes). May be empty; quad meshes do not call it.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// The obstructions of the hexes as given, by kind (in enum order), then by first appearance.
// Hexes with a repeated node are left out (primal::check_validity reports them); throws
// InvalidInput naming the hex if a node number is out of range, or if node_faces has the
// wrong size.
std::vector<Obstruction> find_obstructions(const HexMesh& mesh,
                                           const RealizabilityOptions& options = {});

// The same for a planar quad mesh: its boundary edges grouped into straight sides (by direction
// and distance, as above; node_faces bits name the sides of a template's rectangle). Kinds
// found: doublet (two quads sharing two consecutive edges), two faces on one boundary face (a
// quad with two edges on one straight side), flat corner. The 3D pinched corner and two-quad
// node have no separate 2D form: they are the doublet and the two-edges quad.
std::vector<Obstruction> find_obstructions(const QuadMesh& mesh,
                                           const RealizabilityOptions& options = {});

// One line per obstruction, "  doublet: hexes 3 7; nodes 5 9" (quads for dim 2), numbers plus
// `base` (1 for files that number from 1), at most `limit` lines and then how many more; a
// first line counts them by kind ("no obstructions found" when there are none).
std::string format_obstructions(const std::vector<Obstruction>& obstructions, int dim,
                                Index base = 0, std::size_t limit = 50);
// [{"kind": "doublet", "hexes": [...], "nodes": [...]}, ...], numbers plus `base`.
nlohmann::json obstructions_json(const std::vector<Obstruction>& obstructions, Index base = 0);

}  // namespace geode::primal
