#pragma once
// The side faces of a 3D template: the four box faces x = +-, z = +- that a buffer hex shares
// with its neighbours in a model (the top and bottom are the diced tet and hex sides). Two
// neighbouring templates meet on a side face in any of its orientations (a template's x-face
// against the other's z-face, mirrored), so a template whose four side faces carry one mirror-
// symmetric mesh needs no reconciling of positions there.
#include <array>
#include <vector>

#include <geode/primal/smooth.hpp>
#include <geode/templates/geode.hpp>

namespace geode::templates {

struct SideFace {
  int axis = 0;       // 0 (x) or 2 (z): the face's normal
  bool high = false;  // the + face
  std::vector<int> nodes;
  std::vector<std::array<int, 4>> quads;
};

// In the order x-, x+, z-, z+.
std::array<SideFace, 4> side_faces(const Template& t);

// Gives the four side faces one mesh, symmetric about the face's vertical centre line: each
// node's place in face coordinates (along the face, seen from outside, and height) becomes the
// mean over its images on the four faces and their mirror images. The faces' meshes are
// matched topologically from their top and bottom nodes (at the corners and edge midpoints);
// TopologyError when they are not one mesh up to rotation and mirroring. Top and bottom nodes
// must sit at their diced places (they are not moved).
void unify_side_faces(Template& t);

// smooth_template (top and bottom fixed, side nodes sliding), unify_side_faces, then smoothing
// again with every box face fixed: the template for cells of a model, whose neighbours then
// share its side-face nodes exactly.
primal::SmoothResult smooth_template_shared_sides(Template& t);

}  // namespace geode::templates
