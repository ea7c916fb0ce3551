#pragma once
// Sheets as surfaces to look at (curves in 2D), from either side of the STC:
//  - from an arrangement's fields: the zero set of each sheet inside the domain, by marching
//    tetrahedra (marching triangles in 2D) over a grid in the domain's local coordinates;
//  - from a mesh (stc/mesh_dual.hpp): the sheet's dual surface through its layer of cells;
//    every cell the sheet crosses contributes the quad through the midpoints of its 4 edges of
//    that parallel class (in 2D the segment through the midpoints of the 2 opposite edges).
// Both are for display; neither feeds back into the arrangement engine.
#include <cstddef>
#include <functional>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/sheet.hpp>

namespace geode::stc {

struct ContourOptions {
  // Grid cells along the longest axis of the domain (at least 2 along every axis).
  int resolution = 40;
  // Bracketed secant steps that move each vertex from the linear estimate onto the field's zero.
  int refine_steps = 10;
};

// One triangulated surface per sheet (3D domains), in physical coordinates. Vertices are shared
// between neighbouring triangles (one per crossed grid edge) and triangles are oriented with
// their normal towards the sheet's positive side. A sheet that does not enter the domain gives
// an empty mesh.
std::vector<primal::TriMesh> contour_sheets(const std::vector<Sheet>& sheets, const Domain& domain,
                                            const ContourOptions& options = {});
// One polyline per sheet (2D domains, z = 0).
std::vector<primal::SegmentMesh> contour_curves(const std::vector<Sheet>& sheets,
                                                const Domain& domain,
                                                const ContourOptions& options = {});

struct DualSurfaceOptions {
  // Told how many of the cells are done, every few thousand cells and once at the end, for a
  // progress display; empty: silent. Called from the calling thread. Does not change the result.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// The dual surface of every sheet of `dual` (computed from `mesh`), in dual's sheet order, as
// triangles (each quad split in two); midpoints are shared between the cells of a sheet.
std::vector<primal::TriMesh> dual_surfaces(const primal::HexMesh& mesh, const HexDual& dual,
                                           const DualSurfaceOptions& options = {});
// The dual curve of every chord of a quad mesh.
std::vector<primal::SegmentMesh> dual_curves(const primal::QuadMesh& mesh, const QuadDual& dual,
                                             const DualSurfaceOptions& options = {});

// The layer of each sheet: the cells it crosses, ascending, each once (a sheet that crosses
// itself lists the cell once).
template <int Dim>
std::vector<std::vector<primal::Index>> sheet_layers(const MeshDual<Dim>& dual);

}  // namespace geode::stc
