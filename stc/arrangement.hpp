#pragma once
// The arrangement of sheets inside a box or hexahedron (3D), rectangle or quadrilateral (2D),
// computed to the precision of Newton's method on the sheets' fields.
//
// Route: for every set of d-1 sheets (pairs in 3D, single curves in 2D) the engine traces
// the curve where they meet (predictor-corrector, seeded from a coarse sampling grid and
// from nowhere else), finds on it, in order, the vertices where one more sheet crosses
// (Newton on the d x d system), and where it leaves the domain. Consecutive events along a
// curve bound a 1-cell; the 2^(d-1) regions around a 1-cell are the same at both of its
// ends. Joining those region labels across all 1-cells gives the d-cells (a union-find over
// the octants of the vertices): in a hex mesh every node is a corner of some hex and the
// hexes around a node are face-connected, so face adjacency alone identifies every cell.
//
// General position is checked, not assumed: four sheets through one point, a tangency, a
// vertex on the domain boundary, a curve leaving through a box edge, a curve with no vertex,
// a vertex missed by one of its curves are thrown as TopologyError naming the sheets and
// the point. Cells that are not balls are caught when dualizing (stc/dualize.hpp).
//
// Tangencies away from vertices leave nothing behind to trace, so they are searched for:
//  - two sheets that touch (3D: surfaces meeting at an isolated point; 2D: curves touching):
//    from every seeding-grid cell where both zero sets come within about a cell and their
//    gradients, estimated from the grid, are within 45 degrees of parallel, and which is more
//    than two cells from the curves traced for that pair (2D: from its vertices),
//    Levenberg-Marquardt looks for a common zero; one with gradients parallel to within
//    sin 1e-3 is a touching, one with crossing gradients must lie on a traced curve (be a
//    vertex), else a piece of the arrangement smaller than the grid was missed;
//  - a curve that touches a third sheet (2D: a curve touching another): along the traced
//    curve, where that sheet's field comes close without changing sign;
//  - a sheet that touches a domain face: from grid nodes on the face where the field is a
//    discrete extremum of one sign within a grid step of zero.
// Resolution limits, honestly: a common zero counts as one when both fields are below 1e-9
// of the domain diagonal times their gradients, so sheets closer than about 2e-9 diagonals
// are reported as touching; sheets crossing at an angle below about 0.06 degrees are
// reported as tangent. A touching is found only if the grid sees both zero sets near it:
// features much smaller than a seeding cell (a sphere of radius below a cell touching a
// plane) can pass unseen, as can a touching within two cells of a traced curve of the same
// two sheets. Raising seed_resolution tightens all of these.
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/sheet.hpp>

namespace geode::stc {

// The domain: an axis-aligned box (dim 2 uses x and y only, z of lo and hi ignored), or a
// hexahedron given by its 8 corners in VTK order (primal/topology.hpp), or a pyramid given by
// its 5 (VTK order: base 0-1-2-3 counter-clockwise seen from the apex 4), or in 2D a
// quadrilateral given by 4 corners counter-clockwise.
//
// A hexahedron is the trilinear (a quadrilateral the bilinear) image of the unit cube: local
// coordinates (r, s, t) in [0, 1]^d, corner c at kHexCornerCoords[c]. The engine computes in
// a box of the same proportions, on every sheet's field composed with that map, so planar
// box faces and straight box edges are exactly the hexahedron's (possibly curved) faces and
// edges; every position it reports is mapped back to physical space.
//
// A pyramid is the hexahedron whose top corners 4-7 are all the apex: the map
// (1 - t) B(r, s) + t apex, B the bilinear base. Its face t = 1 is the apex alone, so a sheet
// through the apex (every curve there ending in one point) is refused; otherwise the apex lies
// inside one region, the only one that touches face 5. The map's Jacobian vanishes only there.
struct Domain {
  Point lo = Point::Zero();  // the box; for a hexahedron, its bounding box (informative)
  Point hi = Point::Ones();
  int dim = 3;
  std::optional<std::array<Point, 8>> corners;  // set for a hexahedron / quadrilateral / pyramid
  bool is_pyramid = false;                      // corners 4-7 are one apex

  Domain() = default;
  Domain(const Point& box_lo, const Point& box_hi, int d = 3) : lo(box_lo), hi(box_hi), dim(d) {}
  // Throw InvalidInput naming the corner when the map's Jacobian is not positive at a corner
  // or at the centre (corners out of VTK order, or an inverted / degenerate hexahedron).
  static Domain hexahedron(const std::array<Point, 8>& corners);
  static Domain quadrilateral(const std::array<Point, 4>& corners);
  // Throws InvalidInput when the Jacobian is not positive at a base corner or at the centre
  // (base not counter-clockwise seen from the apex, or the apex in the base's plane).
  static Domain pyramid(const std::array<Point, 5>& corners);
};

// Physical position of the local coordinates (r, s, t) in [0, 1]^d of the domain (for a box,
// lo + (hi - lo) * r componentwise).
Point domain_point(const Domain& domain, const Point& local);

// Domain boundary pieces: face 2*axis + (0 for the low side, 1 for the high side), axis in
// local coordinates. For a hexahedron, with VTK corners (primal/topology.hpp):
//   face 0: r = 0, corners 0 3 7 4   face 1: r = 1, corners 1 2 6 5
//   face 2: s = 0, corners 0 1 5 4   face 3: s = 1, corners 3 2 6 7
//   face 4: t = 0, corners 0 1 2 3   face 5: t = 1, corners 4 5 6 7
// (a pyramid: faces 0-3 its triangles, 4 its base, 5 the apex)
// and for a quadrilateral: face 0 = edge 3-0, 1 = edge 1-2, 2 = edge 0-1, 3 = edge 2-3.
inline int box_face(int axis, bool high) { return 2 * axis + (high ? 1 : 0); }

struct ArrangementOptions {
  // Seeding grid: cells along the longest domain axis. Results are identical for every value
  // in the supported range (see tests/stc/arrangement_test.cpp).
  int seed_resolution = 24;
  // Tracing step as a fraction of the domain diagonal.
  double step = 0.004;
  // Newton tolerance on field values, relative to the field gradient (a length).
  double tolerance = 1e-11;
  // Told how many of the sheet pairs (2D: sheets) have been traced, for a progress display;
  // empty: silent. Does not change the result.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// A 0-cell: d sheets meet transversally at x.
struct Vertex {
  std::vector<int> sheets;  // sorted ascending, d entries
  Point x;
  Point local;          // x in the domain's local coordinates (domain_point(domain, local) == x)
  int orientation = 1;  // sign of det of the sheets' gradients, in sheet order
  int found = 0;        // how many of its d curves reported it (must be d)
};

// Where a 1-cell ends: at a vertex, or on the domain boundary (a face).
struct CurveEnd {
  int vertex = -1;  // vertex index or -1
  int face = -1;    // box face when vertex < 0
  Point x;
};

// A 1-cell: piece of the curve where d-1 sheets meet, between two consecutive events.
struct Edge1 {
  std::vector<int> sheets;  // d-1 sheets, sorted
  CurveEnd a, b;
  std::vector<int> side;  // sign (+1/-1) of every sheet at the 1-cell's midpoint
};

// One traced component of the meeting curve of d-1 sheets.
struct Curve {
  std::vector<int> sheets;
  std::vector<Point> polyline;
  bool closed = false;
  std::array<int, 2> end_faces{-1, -1};  // box faces at the two ends when open
};

struct Arrangement {
  Domain domain;
  int sheet_count = 0;
  std::vector<std::string> sheet_names;
  std::vector<Vertex> vertices;  // in a deterministic order (sheets, then position)
  std::vector<Edge1> edges;
  std::vector<Curve> curves;
  // Region (d-cell) of each vertex octant: region[v][bits], bit i set when the i-th sheet
  // of the vertex is positive there. Regions are numbered 0..region_count-1.
  std::vector<std::array<int, 8>> region;
  int region_count = 0;
  // Per region: the box faces it touches (bit mask), a sign vector over all sheets.
  std::vector<unsigned> region_faces;
  std::vector<std::vector<int>> region_signs;
};

// "(x, y, z)" ("(x, y)" in 2D) to 6 significant digits, for diagnoses.
std::string format_point(const Point& x, int dim);

Arrangement compute_arrangement(const std::vector<Sheet>& sheets, const Domain& domain,
                                const ArrangementOptions& options = {});

}  // namespace geode::stc
