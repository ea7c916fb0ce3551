#pragma once
// The geode template prepared for the buffer hexes of conform(): built from the dual sheet
// arrangement (templates/geode.hpp) and smoothed once per process and diagonal, with every
// node's reference coordinates (r, s, t) in the buffer hex and, for tet- and hex-side nodes,
// the buffer hex corners whose diced node it is (corner, edge midpoint, face centre,
// triangle centroid).
#include <Eigen/Core>
#include <array>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/templates/geode.hpp>

namespace geode::conform {

// A key_corners entry naming the centre node of a four-triangle top (not a buffer hex corner).
inline constexpr int kCentreCorner = 8;

struct RefTemplate {
  templates::Template tpl;
  double min_scaled_jacobian = 0.0;
  std::vector<primal::Point> rst;  // reference coordinates in [0, 1]^3
  std::vector<std::vector<int>>
      key_corners;  // empty: not a tet/hex-side node; else corners 0..7 or kCentreCorner
  // Node i is used by this template alone: not a tet/hex-side node, not on a side face.
  bool interior(std::size_t i) const { return key_corners[i].empty() && tpl.node_faces[i] == 0; }
  // Per buffer hex side face 0..3 (topology order): its template nodes and quads.
  std::array<std::vector<int>, 4> side_nodes;
  std::array<std::vector<std::array<int, 4>>, 4> side_quads;
  // Per node on the side faces only (empty for the others): the buffer hex corners of the
  // smallest face or edge holding it (a side face's 4, or a vertical edge's 2), which is what it
  // is made from, as a diced node's origin says (primal/dice_model.hpp): node sets read it.
  std::vector<std::vector<int>> side_corners;
  // Per buffer hex face (0..3 its sides, 4 its bottom, 5 its top: topology order): the template
  // hexes' faces lying on it, as (hex, local face).
  std::array<std::vector<std::array<int, 2>>, 6> faces_on;
};

// The template for a buffer hex whose top is split along `diagonal` ({4, 6} or {5, 7},
// conform/buffer_layer.hpp), built and smoothed in a box of proportions `box` on the first
// call and kept for the process (thread-safe). Throws TopologyError when the smoothed template
// has two nodes at one place or a tet/hex-side node at no diced position.
const RefTemplate& reference_template(const Eigen::Vector3d& box, std::array<int, 2> diagonal);

// The same for a buffer hex whose top is split into four triangles around a centre node: the
// four-triangle variant's arrangement (templates/geode.hpp, TopSplit::kFourTriangles) with
// superquadric domes, a push class with no obstruction to untangling (checked: TopologyError
// otherwise), smoothed. Its tet-side nodes are the corners, edge midpoints, the centre, the
// midpoints of centre-corner edges and the four triangle centroids; its side faces have the
// ordinary geode's quad mesh (match_side pairs them) and are given the {4, 6} geode's
// reference positions, the rest smoothed with them fixed in a box of 0.7 box.y (the buffer
// hexes are flat; see the .cpp).
const RefTemplate& reference_template_four_triangles(const Eigen::Vector3d& box);

// What the template reaches in an undistorted cell of a buffer hex's proportions: the
// smoothed template's own minimum (its min_scaled_jacobian) in the box whose sides are `cell`,
// the buffer hex's mean edge lengths in the template box's axes (x: along its corners 0-3, y:
// its height, z: along 0-1; buffer_proportions), each rounded up to a whole 24th of the
// longest and not below 3 of them (a thinner side is given 3/24, which gives a higher figure:
// measured 24x12x24 0.330, 24x8x24 0.248, 24x5x24 0.165, 24x3x24 0.102, 24x5x8 0.114). Where
// the cell is not thinner than `box` (--template-box) in any direction, the box's own. Built and
// kept as reference_template() keeps them; throws as it does.
double template_ceiling(const Eigen::Vector3d& box, std::array<int, 2> diagonal,
                        const Eigen::Vector3d& cell);

// Starts building both diagonals' templates for `box` (what conform() asks for first) on a thread
// of its own, so that a caller can overlap them with reading its input: conform() then finds
// them built, or waits for the build under way (the cache above). A failed build is left to
// conform(), which builds again and reports it. Destroying the handle stops a build still
// under way (the caller's input was refused: it need not wait for templates it will not use)
// and joins the thread.
std::jthread build_reference_templates_ahead(const Eigen::Vector3d& box);

// Matches the nodes of side face ka of template A with those of side face kb of template B
// (the same face of the model), starting from the nodes both share on the tet and hex sides
// (global ids ga / gb >= 0) and propagating across the quads of the face: a quad of A with an
// edge whose two ends are matched corresponds to the one unmatched quad of B having the
// images as an edge and agreeing with every match made so far. Returns A node -> B node;
// throws TopologyError naming `where` when the face meshes do not correspond.
std::unordered_map<int, int> match_side(const RefTemplate& A, int ka,
                                        const std::vector<primal::Index>& ga, const RefTemplate& B,
                                        int kb, const std::vector<primal::Index>& gb,
                                        const std::string& where);

}  // namespace geode::conform
