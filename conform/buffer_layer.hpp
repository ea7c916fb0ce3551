#pragma once
// The buffer layer of the geode algorithm (the paper's Section 1): one layer of hexes between
// the hex part and the tet part. Each interface node is duplicated; one copy belongs to the hex
// part, the other (the duplicate) to the tet part, and the copies of one side (BufferSide) move
// into their part, so each interface quad becomes a buffer hex whose bottom face is the hex
// part's quad and whose top face is the tet part's two (or four) triangles.
//
// Buffer hex corner convention (VTK/Exodus order, primal/topology.hpp):
//   corners 0-3: the interface quad (InterfaceQuad::corners), the hex-part side, counter-
//                clockwise seen from the tet side, so the buffer hex is positively oriented;
//   corners 4-7: their tet-side duplicates, corner 4+i above corner i;
//   the top face (local face 5, t = 1) is on the tet side, split into two triangles along
//   `diagonal` = {4, 6} or {5, 7} (the corners the split joins), or into four triangles
//   around `centre` (a tet-part node used by no hex, so it is not duplicated: carved from the
//   tet side, it moves by the mean step of the quad's corners); the bottom face (local face 4,
//   t = 0) is on the hex side. For the geode template of templates/geode.hpp (y up, top at
//   y = +h/2) one right-handed map is r = z, s = x, t = y, under which Diagonal::kMain (which
//   joins (-x,+z) and (+x,-z)) is {5, 7} and Diagonal::kAnti is {4, 6}.
#include <array>
#include <string>
#include <vector>

#include <geode/primal/interface.hpp>
#include <geode/primal/local_smooth.hpp>
#include <geode/primal/model.hpp>

namespace geode::conform {

using primal::HexMesh;
using primal::Index;
using primal::Interface;
using primal::kInvalidIndex;
using primal::Model;

// Which part the buffer layer is carved from: the copies of the interface nodes on that side
// move into it, the other part keeps its elements exactly as they are. From the hex part
// (default) the tets stay as meshed, so the diced tets are exactly the input's own, and the
// buffer can be near the template's best proportions: a box squashed along its edge is still a
// box, while a tet loses height (and quality) as fast as the layer gains it. The tet side suits
// hex parts that must not move.
enum class BufferSide { kHex, kTet };

// The default thickness per side: half the shortest edge from the hex part; 0.3 from the tet
// part, whose first tets lose that fraction of their height.
constexpr double default_buffer_thickness(BufferSide side) {
  return side == BufferSide::kHex ? 0.5 : 0.3;
}
// The largest thickness per side: a hex squashed by more than 0.9 of its edge is nearly flat;
// tets beside the interface would lose more than 0.45 of their height.
constexpr double max_buffer_thickness(BufferSide side) {
  return side == BufferSide::kHex ? 0.9 : 0.45;
}

// "hex" or "tet"; parse_buffer_side throws InvalidInput naming any other word.
const char* buffer_side_name(BufferSide side);
BufferSide parse_buffer_side(const std::string& word);

struct BufferLayerOptions {
  BufferSide side = BufferSide::kHex;
  // Height of the buffer layer at each interface node (its distance from the interface faces
  // there) before grading, as a fraction of the shortest edge of the moving part's elements or
  // interface quads at the node; grading (below) may raise it up to this fraction of the
  // node's mean quad edge. 0: default_buffer_thickness(side); at most max_buffer_thickness(side).
  double thickness = 0.0;
  // Heights vary smoothly along the interface (buffer_layer.cpp, heights()): a node is raised to
  // within raise_rate x edge length of its neighbours' heights (not above thickness x its
  // interface quads' mean edge), and neighbours differ by at most smooth_rate x their edge.
  double raise_rate = 0.03;
  double smooth_rate = 0.1;
  // At a node where interface faces meet at a corner (in three or more directions, each
  // feature_angle apart) at which the moving part is convex, the height is this fraction of
  // thickness: a buffer hex there narrows towards the corner in two directions by its height,
  // and a thinner layer keeps the geode nearer a box. Measured on the potting demo (n = 3,
  // --smooth none): geode hexes at convex box corners 0.063 with 1 (off), 0.12 with 0.5.
  double feature_thickness = 0.5;
  // A node whose faces meet at an edge or corner moves height / cos along the direction d
  // (cos = min over its corner normals n of d . n, the mitred offset), cos at least this.
  double min_mitre_cos = 0.5;
  // Every moved element keeps at least this fraction of its volume (a hex: at every corner and
  // at its centre, its Jacobian's fraction there).
  double min_volume_ratio = 0.05;
  // Every moved hex keeps at least this fraction of its scaled Jacobian (one that was not
  // positive is not held to it). A cube touching the interface at one concave corner only, that
  // corner pushed a quarter edge along each axis, keeps 0.44; squashed hexes of unstructured
  // parts lose more unless held back here.
  double min_hex_quality_ratio = 0.4;
  // Every buffer hex has a Verdict scaled Jacobian (min over 8 corners and centre) above this.
  double min_scaled_jacobian = 1e-3;
  // The step direction d at a node must satisfy d . n >= min_visibility for the unit corner
  // normal n of every interface quad at the node; otherwise no valid buffer hex fits there.
  double min_visibility = 0.05;
  // Nodes of failing elements have their step halved at most this often.
  int max_halvings = 8;
  // Angle (degrees) above which two outer-boundary faces of the moving part at a node form a
  // feature: a moved node slides in the boundary's tangent plane, along a feature edge, or
  // (at a feature corner) cannot move.
  double feature_angle = primal::kFeatureAngle;
  // The faces between two blocks of the moving part count as its boundary: a moved copy slides
  // in them, so every block keeps its volume (materials never move). Off, a copy may move
  // across them (conform's last resort, with a warning, where no layer keeps them).
  bool keep_block_faces = true;
};

struct BufferHex {
  std::array<Index, 8> corners{};  // see the convention above
  std::array<int, 2> diagonal{};   // {4, 6} or {5, 7}; not used with a centre
  Index centre = kInvalidIndex;    // four-triangle top: its centre node (model.points[centre])
  Index quad = kInvalidIndex;      // index into Interface::quads
};

struct BufferLayerReport {
  double min_volume_ratio = 1.0;          // over the elements that moved
  double min_scaled_jacobian = 1.0;       // over the buffer hexes
  double min_step = 0.0, max_step = 0.0;  // distances the moving copies moved
  int halvings = 0;                       // rounds of step halving needed
  // Interface nodes at a corner where the moving part is convex (feature_thickness applies):
  // its buffer hexes taper there.
  Index convex_corners = 0;
};

struct BufferLayer {
  // The input model with one part shrunk: one duplicate per interface node appended to the
  // points (model.points[top_node[v]]), the cells on the tet side of the interface at a node
  // (primal::InterfaceSide: the tets, and wedges beside them) renumbered to its duplicate. Carved
  // from the hex part, the hex-side nodes (the input's ids) have moved and the duplicates stand
  // where the interface was; from the tet part, the duplicates and the centre nodes of
  // four-triangle quads have moved. Hexes, blocks, node sets (which keep the hex-side nodes) and
  // side sets are unchanged; the buffer hexes are not in it.
  Model model;
  std::vector<Index> top_node;   // per input node: its tet-side duplicate or kInvalidIndex
  std::vector<BufferHex> hexes;  // one per interface quad, in Interface::quads order
  BufferLayerReport report;
};

// Per buffer hex, its height (the shortest of its four edges from the interface quad to the
// top) over its interface quad's mean edge: how flat its geode template will be squashed (the
// reference box is half as high as wide).
std::vector<double> buffer_height_ratios(const BufferLayer& layer);

// Per buffer hex, the piece of the interface it is on: buffer hexes sharing an interface node
// are on one piece (a hex layer between tets has two, one on each side), numbered from 0 in the
// order of their first buffer hex. The same for any layer of one interface (its hexes are in
// Interface::quads order, on the same interface nodes).
std::vector<Index> interface_pieces(const BufferLayer& layer);

// Per buffer hex: its mean edge lengths along its three directions, in the template box's axes
// (conform/reference_template.hpp): x along corners 0-3 (and 1-2, 4-7, 5-6), y its height (the
// four edges from the interface quad to the top), z along 0-1 (and 3-2, 4-5, 7-6); the sides of
// an undistorted cell of its proportions (conform::template_ceiling).
std::vector<Eigen::Vector3d> buffer_proportions(const BufferLayer& layer);

// Wedges are diced in place and never moved: an interface quad of a wedge, or a tet on the hex
// side of a node (Interface::uses), needs the layer carved from the tet part; a wedge on the
// tet side of a node needs it carved from the hex part.
// Throws TopologyError naming the node (and the element) where no valid layer can be placed
// (a wedge the moving copy would move, named with the node);
// no direction sees all interface faces at a node (the paper's Figure 9 right), a node at a
// corner of the moving part's outer boundary, or an element still inverted / collapsed after
// max_halvings halvings; InvalidInput for a thickness below 0 or above max_buffer_thickness.
BufferLayer insert_buffer_layer(const Model& model, const Interface& interface,
                                const BufferLayerOptions& options = {});

// The buffer hexes as a hex mesh over layer.model.points (block = 3).
HexMesh buffer_hex_mesh(const BufferLayer& layer);

}  // namespace geode::conform
