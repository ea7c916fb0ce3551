#pragma once
// Worst-first local smoothing of large hex meshes: the hexes below a quality target are taken
// worst first; each one's free nodes (a patch of at most 8 nodes) move together to raise the
// soft minimum of the corner measures of every frame they touch (8 corners and the centre of
// each hex around them, [Verdict] scaled Jacobian), by a damped Newton method with analytic
// gradients and Hessians (primal/frame_derivatives.hpp). A patch with a non-positive corner
// Jacobian first untangles (soft minimum of the Jacobians / L^3), then improves shape.
//
// Guarantees.
//  - Floors. Let `start` be a hex's scaled Jacobian when the call began (or the SmoothStart
//    given) and `worst` the lowest of a patch's hexes when the patch begins. No hex of a patch
//    ends below `worst`; a hex that started within `margin` of it ends no lower than its start;
//    a better one loses at most `loss` from its start and never falls below worst + margin.
//    Every trial step that would break a floor is cut back, so the patch's worst hex never
//    gets worse, hexes near the worst never lose, and good hexes pay a bounded price. An
//    inverted hex has no floor: untangling may move it through worse shapes; the soft minimum
//    of the Jacobians it maximises keeps the worst Jacobian from dropping. Improving shape, no
//    edge shrinks below min_edge_fraction of its hex's shortest edge at the start (the scaled
//    Jacobian cannot see an edge collapse); a hex untangling left shorter gets no shorter.
//  - Termination: each patch's soft minimum rises monotonically (Armijo) and stops when it rises
//    by less than `min_gain`, after max_iterations, or when no step is accepted; each hex seeds
//    at most max_visits patches, and only when a neighbouring patch moved one of its nodes since
//    its last one. Only frames with a moving node are counted, so a patch cannot stall on a
//    frame it cannot change.
//  - Determinism: patches run in rounds; a round takes the candidates worst first (ties by hex
//    number) and keeps those that share no hex with one already kept (so no two touch a common
//    frame), then runs them in parallel (TBB). The result does not depend on the thread count.
//  - Constraints (primal/smooth.hpp's NodeConstraint): plane and line nodes stay on them exactly;
//    kSurface nodes move in their tangent plane and are projected back onto the nearest triangle
//    of the given surface triangulation after every step (the bilinear faces around them then
//    change by up to their chord error, and so do the volumes they enclose: for callers that
//    accept that; boundary_slide_constraints fixes such nodes instead).
#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include <geode/primal/boundary.hpp>
#include <geode/primal/mesh.hpp>
#include <geode/primal/smooth.hpp>

namespace geode::primal {

// Boundary normals more than this many degrees apart make a feature edge or corner (the
// buffer layer's mitred offsets, conform/buffer_layer.hpp).
inline constexpr double kFeatureAngle = 30.0;

// What smoothing keeps besides the model's boundary and the faces between blocks, in the mesh's
// node numbers (conform: the output's side sets and node sets: surfaces, curves and points an
// analyst put in the model to load or read, which must stay where they are).
struct KeptFeatures {
  // Surfaces, each on its own (a side set's faces): a node on one slides in its plane, or along
  // the line where two planes meet, as on the faces between blocks; a node on its rim (an edge
  // of one of its quads only) slides along the rim where it is straight, so that the surface
  // keeps its extent; otherwise the node is fixed.
  std::vector<std::vector<std::array<Index, 4>>> surfaces;
  // Node sets, each on its own: a node slides only within every set holding it, in the plane
  // of the surfaces through it (the boundary, a face between blocks, a kept surface) where every
  // quad of theirs there is in the set, along its line where its neighbours on the line both
  // are; otherwise it is fixed (a point, a curve's end, a surface's rim, a node inside the
  // model).
  std::vector<std::vector<Index>> node_sets;
};

struct LocalSmoothOptions {
  double target = 0.35;  // hexes with a scaled Jacobian below it seed patches
  // > 0: the call ends as soon as every seed hex is at or above it, before the target is
  // reached (a caller whose aim is below the target sets the target higher only to give the
  // hexes room to rise).
  double goal = 0.0;
  double margin = 0.1;  // hexes this close to a patch's worst never lose (see Floors)
  double loss = 0.1;    // how far a better hex may fall from its start
  // Improving shape, no hex's shortest edge drops below this fraction of its shortest edge when
  // the call began (or below its current one, if untangling shortened it further): the scaled
  // Jacobian normalises edge lengths, so it would let an edge shrink to nothing.
  double min_edge_fraction = 0.5;
  int max_visits = 2;                // patches seeded by one hex
  int max_iterations = 5;            // Newton iterations per patch (per phase)
  double sharpness = 60.0;           // soft minimum of scaled Jacobians
  double untangle_sharpness = 20.0;  // soft minimum of Jacobians / L^3
  double min_gain = 1e-4;            // soft-minimum rise counted as progress
  // Per hex of the mesh (each empty, or one per hex): that hex's own target and goal instead of
  // `target` and `goal`, for callers whose aim differs from hex to hex (conform's local
  // yardstick). A goal of 0 is met by any hex.
  std::vector<double> hex_targets, hex_goals;
  int threads = 0;  // 0: TBB's default; 1: serial
  // smooth_hexes_around only (smooth_hexes_local takes its constraints from the caller:
  // kept_slide_constraints): the features kept besides the boundary and the block interfaces.
  const KeptFeatures* kept = nullptr;
  // Called before each round and at the end with (seed hexes not waiting for a patch, seeds).
  std::function<void(std::size_t settled, std::size_t seeds)> progress;
};

struct LocalSmoothResult {
  double initial_min_scaled_jacobian = 0.0;  // over the whole mesh
  double final_min_scaled_jacobian = 0.0;
  Index initial_inverted = 0, final_inverted = 0;  // hexes with scaled Jacobian <= 0
  Index patches = 0, rounds = 0;
  long iterations = 0;       // Newton iterations over all patches
  double seconds = 0.0;      // wall clock
  double cpu_seconds = 0.0;  // the process's CPU time over all threads (std::clock)
  // smooth_hexes_around: the hexes whose scaled Jacobian it can have changed (those sharing a
  // node with a seed), ascending; empty from smooth_hexes_local.
  std::vector<Index> region;
};

// What the floors are measured from, per hex of the mesh: its scaled Jacobian and its shortest
// edge. Each call measures them when it begins; a caller that smooths in several calls
// (passes) passes the values from before the first, so that the bounds (`loss`,
// `min_edge_fraction`) hold over all of them instead of compounding.
struct SmoothStart {
  std::vector<double> scaled_jacobian;
  std::vector<double> shortest_edge;
};
SmoothStart smooth_start(const HexMesh& mesh);

// Smooths `mesh` in place. `constraints`: one per node (empty: all free); `surface`: the
// triangulation kSurface nodes stay on (required when a constraint is kSurface); `seeds`: the
// hexes that may seed patches (empty: every hex; patches still move every free node of the
// seed, and their neighbours only within their floors); `start`: see SmoothStart (null: now).
// Throws InvalidInput on a size mismatch, a bad node number or a kSurface constraint without
// a surface.
LocalSmoothResult smooth_hexes_local(HexMesh& mesh, std::span<const NodeConstraint> constraints,
                                     const TriMesh* surface = nullptr,
                                     std::span<const Index> seeds = {},
                                     const LocalSmoothOptions& options = {},
                                     const SmoothStart* start = nullptr);

// smooth_hexes_local with the model's boundary, its material interfaces and options.kept kept
// (kept_slide_constraints), run on the submesh of the hexes around the seeds only: a patch
// moves the nodes of its seed hex, so every hex whose quality can change shares a node with a
// seed, and the boundary there is told from one more ring of hexes. Finding the rings still
// scans the mesh once per ring, but the costly parts (boundary faces, constraints, patches)
// follow the seeds, not the mesh (the whole-mesh boundary of a million hexes costs seconds).
// Same result as smooth_hexes_local over the whole mesh with those constraints. The result's
// minima are over the hexes around the seeds.
LocalSmoothResult smooth_hexes_around(HexMesh& mesh, std::span<const Index> seeds,
                                      const LocalSmoothOptions& options = {},
                                      const SmoothStart* start = nullptr);

// The surfaces smoothing must keep: the mesh's boundary quads, then the faces between blocks
// (block_interface_quads; none when mesh.block is empty).
std::vector<BoundaryQuad> material_surface_quads(const HexMesh& mesh);

// Constraints that keep every block's volume (materials never move): each node on one of the
// `surfaces` quads (default: material_surface_quads) moves only where the surfaces through it
// keep their shape. A node whose surface quads are all flat and lie in one plane slides in it;
// in two planes, along their intersection line (a straight feature edge, or an interface
// meeting the boundary); otherwise (corners, curved surfaces, warped quads) it is fixed.
// Sliding in a plane, the quads around a node keep covering the same planar region (the
// smoother keeps them untangled), so each block's volume, the flux of x.n / 3 through its
// faces, does not change (to rounding). Interior nodes are free.
std::vector<NodeConstraint> boundary_slide_constraints(const HexMesh& mesh);
std::vector<NodeConstraint> boundary_slide_constraints(const HexMesh& mesh,
                                                       std::span<const BoundaryQuad> surfaces);

// boundary_slide_constraints with `kept` kept too (KeptFeatures). Throws InvalidInput on a
// node out of range.
std::vector<NodeConstraint> kept_slide_constraints(const HexMesh& mesh, const KeptFeatures& kept);

// The mesh's boundary quads, each split into two triangles (along the 0-2 diagonal): the
// surface kSurface nodes slide on when no input triangulation is at hand.
TriMesh boundary_triangulation(const HexMesh& mesh);
TriMesh boundary_triangulation(const std::vector<Point>& points,
                               std::span<const BoundaryQuad> boundary);

// Every hex sharing a node with one of `hexes` (those included), ascending.
std::vector<Index> hexes_around(const HexMesh& mesh, std::span<const Index> hexes);

}  // namespace geode::primal
