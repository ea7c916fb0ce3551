#pragma once
// The dual of an existing mesh, read off its connectivity: the sheets of a hex mesh and the
// chords of a quad mesh (the Spatial Twist Continuum seen from the primal side).
//
// A sheet (chord) is an equivalence class of edges: inside every cell, the edges of one
// parallel class of primal/topology.hpp are equivalent (4 per class in a hex, 2 in a quad), and
// the classes are joined across cells through shared edges (union-find). Each cell is crossed by
// Dim sheets, one per parallel class; a sheet self-intersects where it crosses one cell twice.
// On the boundary a sheet leaves a trace: in 3D the dual curves of the boundary quad mesh that
// cross the sheet's boundary edges (closed loops on a closed boundary), in 2D the chord's ends.
//
// The same template serves both dimensions: MeshDual<3> from a HexMesh, MeshDual<2> from a
// QuadMesh. Nothing here knows about geodes; naming sheets is left to callers through
// trace_by_region (e.g. per box face).
#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::stc {

// A facet of a cell: a face of a hex (index into kHexFaceCorners) in 3D, an edge of a quad
// (index into kQuadEdgeCorners) in 2D.
struct CellFacet {
  primal::Index cell = primal::kInvalidIndex;
  int local = -1;
  friend bool operator==(const CellFacet&, const CellFacet&) = default;
};

// One connected piece of a sheet's boundary trace.
// 3D: a dual curve of the boundary quad mesh. `edges` are the boundary edges of the sheet it
//     crosses, in order; facets[i] is the boundary quad between edges[i] and edges[i+1]
//     (edges[0] when closed and i is last): closed curves have as many facets as edges, open
//     ones one fewer.
// 2D: one end of a chord: `edges` is the boundary edge it leaves through and `facets` that same
//     edge as a facet of its quad; never closed.
struct TraceCurve {
  std::vector<primal::Index> edges;  // ids into MeshDual::edges
  std::vector<CellFacet> facets;
  bool closed = false;
};

// A sheet (3D) or chord (2D).
struct MeshSheet {
  std::vector<primal::Index> edges;  // the mesh edges of the class, ascending
  std::vector<primal::Index> cells;  // cells crossed, ascending; twice (thrice) where it
                                     // crosses itself, so cells.size() counts crossings
  std::vector<TraceCurve> trace;     // boundary trace, see TraceCurve
  bool self_intersecting = false;    // some cell has two of its classes in this sheet
};

template <int Dim>
struct MeshDual {
  static_assert(Dim == 2 || Dim == 3, "hex (3) or quad (2) meshes");
  static constexpr int kCellEdges = Dim == 3 ? 12 : 4;

  std::vector<std::array<primal::Index, 2>> edges;  // distinct mesh edges, smaller node first
  std::vector<primal::Index> edge_sheet;            // sheet of each edge
  // Per cell: its edges (local edge order of primal/topology.hpp) and the sheet of each
  // parallel class (class k = hex edges 4k..4k+3, quad edges k and k+2).
  std::vector<std::array<primal::Index, kCellEdges>> cell_edges;
  std::vector<std::array<primal::Index, Dim>> cell_sheets;
  std::vector<CellFacet> boundary;  // facets used by one cell only, in (cell, local) order
  // Sheets numbered by first appearance in (cell, class) order.
  std::vector<MeshSheet> sheets;
  // For each ascending tuple of Dim sheet ids (repeated ids where a sheet self-intersects):
  // the number of cells where exactly those sheets meet. 3D: triple intersections; 2D:
  // chord crossings. Tuples that meet nowhere are absent.
  std::map<std::array<primal::Index, Dim>, primal::Index> intersections;
};

using HexDual = MeshDual<3>;
using QuadDual = MeshDual<2>;

struct MeshDualOptions {
  // Told how many of the cell visits are done (the dual reads every cell kMeshDualPasses
  // times: done of cells x kMeshDualPasses), every few thousand cells and once at the end, for a
  // progress display (a mesh of millions of hexes takes tens of seconds); empty: silent. Called
  // from the calling thread. Does not change the result.
  std::function<void(std::size_t done, std::size_t total)> progress;
};
inline constexpr std::size_t kMeshDualPasses = 6;

// Throws geode::InvalidInput for a corner out of range or repeated within a cell, and
// geode::TopologyError for a facet shared by more than two cells or (3D) a boundary edge not
// on exactly two boundary quads; messages name the cell (edge) and the reason.
HexDual mesh_dual(const primal::HexMesh& mesh, const MeshDualOptions& options = {});
QuadDual mesh_dual(const primal::QuadMesh& mesh, const MeshDualOptions& options = {});

// Region of a boundary facet, e.g. which box face it lies on; a region in [0, regions), or
// -1 for "none".
using FacetClassifier = std::function<int(const CellFacet&)>;

// The trace of `sheet` cut into maximal runs by region: result[r] holds the pieces lying on
// region r, as TraceCurves of their own (a piece is closed only if its whole curve lies in r).
// Throws geode::InvalidInput when the classifier returns a region outside [0, regions) for a
// facet of the trace.
std::vector<std::vector<TraceCurve>> trace_by_region(const HexDual& dual, primal::Index sheet,
                                                     const FacetClassifier& classify, int regions);
std::vector<std::vector<TraceCurve>> trace_by_region(const QuadDual& dual, primal::Index sheet,
                                                     const FacetClassifier& classify, int regions);

// Classifies a boundary facet by the axis-aligned box face [lo, hi] whose plane holds all its
// corners within `tol`: face 2 * axis + (0 low, 1 high), as stc::box_face numbers them; -1 when
// none. The quad version uses x and y only (the box sides are lines). The classifier keeps a
// reference to `mesh`.
FacetClassifier box_face_classifier(const primal::HexMesh& mesh, const primal::Point& lo,
                                    const primal::Point& hi, double tol);
FacetClassifier box_face_classifier(const primal::QuadMesh& mesh, const primal::Point& lo,
                                    const primal::Point& hi, double tol);

}  // namespace geode::stc
