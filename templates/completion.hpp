#pragma once
// Completion builders (the paper's Section 2): the dual curves of a diced interface cell are
// completed into sheets that close inside the buffer cell.
//
// The buffer cell is worked in reference coordinates: u = x across, v = y up from the hex
// side (v = 0) to the tet side (v = 1), w = z across (u, w in [-1, 1]). 2D uses u and v only.
// The arrangement's topology does not change under the affine map to the real box, so the
// template is derived once per choice and then mapped.
#include <functional>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/sheet.hpp>

namespace geode::templates {

using primal::Point;

// One interface cell before dicing, in the plane v = const: a quad (hex side) or a set of
// triangles (tet side) in 3D, a segment in 2D. Points are reference coordinates.
struct InterfacePatch {
  int dim = 3;
  std::vector<Point> points;
  std::vector<std::vector<int>> cells;  // quads or triangles (3D); segments (2D)
};

// The patch after dicing (primal/dice.hpp in 3D; a segment splits at its midpoint in 2D):
// the diced nodes, the diced cells (quads; segments in 2D), and for every diced node the
// patch vertices it belongs to (itself, the two ends of its edge, or the corners of its cell).
struct DicedPatch {
  std::vector<Point> nodes;
  std::vector<std::vector<int>> cells;
  std::vector<std::vector<int>> owners;
};
DicedPatch dice_patch(const InterfacePatch& patch);

// Hex side: each dual chord of the pre-diced quad (2D: the dual point of the segment) is
// doubled by dicing into two parallel copies; complete each pair into a tunnel over them:
// f = (d / a)^2 + (v / height)^2 - 1, with d the distance from the pre-diced chord within the
// interface plane and a the distance from it to the diced copies (a quarter of the edge it
// crosses). Negative inside the tunnel. height(along) gives the roof of the tunnel whose
// chord runs in direction `along` (2D: along is zero).
struct Tunnel {
  stc::Sheet sheet;
  Point along;  // direction of the chord (3D); zero in 2D
};
std::vector<Tunnel> complete_tunnels(const InterfacePatch& quads,
                                     const std::function<double(const Point& along)>& height);

// Tet side: the dual of the diced triangles is a circle around every original vertex,
// crossing the halves of its edges away from it. Complete each circle into a dome over the
// vertex: f = (r / R)^2 + ((v_top - v) / depth)^2 - 1, r the distance from the vertex in the
// interface plane, R between the farthest diced node the circle encloses (the vertex, the
// midpoints of its edges, the centroids of its triangles: blend 0) and the nearest one it
// leaves out (blend 1);
// depth (a fraction of the cell height) says how far below the tet side the dome reaches.
// Negative inside.
struct Dome {
  stc::Sheet sheet;
  int vertex;     // interface vertex it goes around
  double radius;  // R
};
std::vector<Dome> complete_domes(const InterfacePatch& triangles, double v_top, double depth,
                                 double blend = 0.5);

// A wider dome family: each vertex's dome gets its own depth and blend, a superquadric shape
// f = |dx / R|^p + |dz / R|^p + |(v_top - v) / depth|^p - 1 (p = 2 is the spheroid above,
// computed by the same formula bit for bit), and a centre moved off the vertex within the
// interface plane by `offset`. R and the blend are then measured in the same p-norm from that
// centre, so the dome's trace on the interface still separates the vertex's diced nodes from
// the others (TopologyError when no such trace exists).
struct DomeShape {
  double depth = 0.9;
  double blend = 0.5;
  double exponent = 2.0;
  Point offset = Point::Zero();  // in the interface plane (its v component is ignored)
};
std::vector<Dome> complete_domes(const InterfacePatch& triangles, double v_top,
                                 const std::function<DomeShape(int vertex)>& shape);

}  // namespace geode::templates
