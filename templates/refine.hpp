#pragma once
// Refinement transition templates from the same engine as the geode (the paper's Section 5,
// fourth variation, in its simplest form): a cell with one coarse quad on top and its 3 x 3
// refinement below (2D: one coarse edge over three fine ones), derived as the dual of a
// completed sheet arrangement. Nothing is typed in.
//
// Completion, in the box (fine side at the bottom): every dual chord of the fine side is
// completed into a sheet. In each direction the fine side has three parallel chords; the
// middle one is the coarse side's chord too and goes straight up as a plane; the outer two are
// paired into a tunnel (an elliptic arch over both). The side faces' chord (crossing the
// cell's vertical edges) is a horizontal layer below both roofs. 3D: two tunnels, two middle
// planes, one layer; 2D: one of each.
#include <Eigen/Core>

#include <geode/stc/arrangement.hpp>
#include <geode/templates/geode.hpp>

namespace geode::templates {

// Heights in reference units (cell height 1). The layer must lie below both roofs: above a
// roof, the tunnel's top hex would have three faces on the fine side.
struct RefineOptions {
  Eigen::Vector3d box{24.0, 14.0, 24.0};  // fine side at the bottom (y = -box.y/2), coarse on top
  double high_roof = 0.75;                // roof of the tunnel along x (3D; the 2D tunnel's roof)
  double low_roof = 0.6;                  // roof of the tunnel along z (3D)
  double layer = 0.35;                    // the horizontal sheet through the side faces
  stc::ArrangementOptions arrangement;
};

// The template as an arrangement spec (templates/spec.hpp) in the box, centred at the origin:
// the fine face (3 x 3 quads; 2D: 3 segments) prescribed on the bottom, the coarse one on top
// (a "faces" block), and the sheets as shapes: tunnels ("tunnel x", "tunnel z"; 2D "tunnel"),
// middle planes ("middle x", "middle z"; 2D "middle"), then "layer". InvalidInput for heights
// out of order or a degenerate box.
struct ArrangementSpec;
ArrangementSpec refine_spec(const RefineOptions& options, int dim);

// build_template(refine_spec(options, 3 or 2)): the fine and coarse faces' nodes are placed
// where the refinement puts them (TopologyError if the dual's boundary differs), the rest at
// the dual's first guess.
Template build_refine3(const RefineOptions& options);
Template build_refine3_2d(const RefineOptions& options);

// Smooth a refinement template (primal/smooth.hpp) with its fine and coarse faces fixed. In 3D
// with match_sides, every side-face node is first fixed where the smoothed 2D template of that
// face's width puts it, so all four side faces are the same 2D mesh and neighbouring cells
// (translated or rotated copies) match node for node; otherwise side nodes slide in their face.
primal::SmoothResult smooth_refine3(Template& t, const RefineOptions& options,
                                    bool match_sides = true);

}  // namespace geode::templates
