#pragma once
// Optimisation-based node placement for small hex meshes (templates) and planar quad meshes:
// first untangle (raise the smallest Jacobian until every corner is positive), then improve
// shape by maximising a smooth minimum of the Verdict scaled Jacobian (8 corners and the
// centre of each hex; 4 corners of each quad). Nodes move only as their constraint allows.
//
// Method. Unknowns are the free coordinates of each node in an orthonormal basis of its
// allowed motion (3 for free, 2 for a plane, 1 for a line, 0 for fixed), so constrained nodes
// stay on their plane or line by construction (exactly, for axis-aligned planes and lines).
// The objective is the log-sum-exp soft minimum  softmin_t(q) = -1/t log sum_k exp(-t q_k),
// which lies within log(K)/t below the true minimum of the K values q_k, maximised with
// a backtracking (Armijo) line search, for an increasing sequence of sharpness t
// (continuation: a blunt t spreads the improvement over many elements, a sharp one then
// pushes the worst). Untangling uses q = corner Jacobian / L^3 (L the mean edge length) and
// L-BFGS; shape improvement uses q = scaled Jacobian (plus the shape guard, SmoothOptions) and a
// damped Newton method (soft-min Hessian assembled from the analytic 9 x 9 per-corner Hessians,
// primal/frame_derivatives.hpp).
//
// Stopping rule. Untangling stops as soon as every corner and centre Jacobian is positive (or
// after max_untangle_iterations). Each shape stage stops when its soft minimum has improved by
// less than `tolerance` over `patience` consecutive iterations, when the line search finds no
// decrease, or after max_stage_iterations; all stages together stop after max_iterations. The
// returned positions are those of the iterate with the largest true minimum scaled Jacobian.
// No randomness and no threads: the same input gives bit-identical output.
#include <Eigen/Core>
#include <array>
#include <span>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

struct NodeConstraint {
  // kSurface: on a surface triangulation given to the smoother (primal/local_smooth.hpp), with
  // direction its normal at origin; smoothers without a surface keep it in that tangent plane.
  enum class Kind { kFree, kFixed, kPlane, kLine, kSurface };
  Kind kind = Kind::kFree;
  Point origin = Point::Zero();     // a point of the plane or line
  Point direction = Point::Zero();  // plane normal or line direction (any length > 0)

  static NodeConstraint free() { return {}; }
  static NodeConstraint fixed() { return {Kind::kFixed, Point::Zero(), Point::Zero()}; }
  static NodeConstraint plane(const Point& origin, const Point& normal) {
    return {Kind::kPlane, origin, normal};
  }
  static NodeConstraint line(const Point& origin, const Point& direction) {
    return {Kind::kLine, origin, direction};
  }
  static NodeConstraint surface(const Point& origin, const Point& normal) {
    return {Kind::kSurface, origin, normal};
  }
};

// Constraints for a mesh filling the axis-aligned box [lo, hi]: a node within `tol` of one box
// face slides on that face's plane, of two faces on their common edge line, of three (a box
// corner) is fixed; other nodes are free. A node on a face flagged in `fixed_faces` (order
// x-, x+, y-, y+, z-, z+) is fixed.
std::vector<NodeConstraint> box_constraints(std::span<const Point> points, const Point& lo,
                                            const Point& hi, std::array<bool, 6> fixed_faces = {},
                                            double tol = 1e-9);

// A node that moves with another (its leader): p = p0 + map (q - q0), p0 and q0 their places
// at the start, q the leader's place. Ties symmetric copies of one node, e.g. the side faces
// of a template that neighbours share in any orientation. The node's own constraint is
// ignored; the caller keeps `map` consistent with the leader's constraint (a leader mapped
// onto itself must be constrained to the map's fixed directions). A leader is not a follower.
struct NodeLink {
  Index node = 0, leader = 0;
  Eigen::Matrix3d map = Eigen::Matrix3d::Identity();
};

struct SmoothOptions {
  int max_iterations = 3000;  // L-BFGS iterations over all phases
  int max_untangle_iterations = 1000;
  int max_stage_iterations = 300;  // per sharpness value of the shape phase
  std::vector<double> sharpness = {10, 20, 40, 80, 160, 320, 640, 1280, 2560};
  double untangle_sharpness = 20;
  double tolerance = 1e-7;  // soft-minimum improvement counted as progress
  int patience = 8;
  int history = 8;  // L-BFGS memory (untangling)
  // The scaled Jacobian does not see edge lengths: a node may slide onto its neighbour with
  // every corner keeping a fine scaled Jacobian. So the shape phase maximises the soft
  // minimum over the scaled Jacobians and, per corner, Verdict's shape (3 det^(2/3) /
  // |A|_F^2; quads 2 det / (|a|^2 + |b|^2)) divided by this factor; it binds only where a
  // corner's shape falls below factor x (the scaled Jacobian being achieved). 0 turns it off.
  double shape_guard = 0.5;
  std::vector<NodeLink> links;  // hex and quad meshes alike
};

struct SmoothResult {
  bool untangled = false;  // every corner and centre Jacobian > 0 at the end
  int untangle_iterations = 0;
  int shape_iterations = 0;
  int iterations = 0;                 // sum of the two
  double initial_min_jacobian = 0.0;  // hex_jacobian / quad_jacobian minimum over the mesh
  double final_min_jacobian = 0.0;
  double initial_min_scaled_jacobian = 0.0;  // Verdict: 8 corners and centre (quads: corners)
  double final_min_scaled_jacobian = 0.0;
  double final_max_scaled_jacobian = 0.0;
  double seconds = 0.0;  // wall-clock time of the call
};

// Moves the nodes of `mesh` in place. `constraints` has one entry per node (empty: all free).
// Nodes with a plane or line constraint are first projected onto it. Throws
// geode::InvalidInput on a mesh of no hexes, a size mismatch, a zero direction, a bad node
// number or a non-finite coordinate.
SmoothResult smooth_hex_mesh(HexMesh& mesh, std::span<const NodeConstraint> constraints = {},
                             const SmoothOptions& options = {});

// The same for a quad mesh lying in a plane with normal `normal` (quads counter-clockwise seen
// from it; InvalidInput on no quads). Every node also stays in its plane: a free node moves in the
// plane, a plane constraint becomes the line where the two planes meet, a line must lie in the
// plane.
SmoothResult smooth_quad_mesh(QuadMesh& mesh, const Point& normal,
                              std::span<const NodeConstraint> constraints = {},
                              const SmoothOptions& options = {});

}  // namespace geode::primal
