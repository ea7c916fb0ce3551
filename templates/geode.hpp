#pragma once
// Geode transition templates derived from completed dual sheet arrangements (the paper's
// Section 2). Nothing here is typed in: each template is the dual of its arrangement.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/templates/completion.hpp>

namespace geode::templates {

// Which diagonal splits the tet-side (top) quad into two triangles. Box corners are named in
// (x, z) at the top face y = +h/2: Main joins (-x, +z) to (+x, -z) (as in the paper's
// Appendix A, nodes 1 and 2); Anti joins (+x, +z) to (-x, -z).
enum class Diagonal { kMain, kAnti };

// Which tunnel's roof is higher where the two tunnels cross: the tunnel running along x (its
// feet are the two dual chords of the diced bottom quad parallel to x) or along z.
enum class Higher { kX, kZ };

// How the tet-side quad is split: two triangles by a diagonal (the geode), or four around a
// centre vertex (the paper's Section 5 variant).
enum class TopSplit { kTwoTriangles, kFourTriangles };

// How the two completed arrangements are pushed together, in reference units of the buffer
// cell (height 1, half-width 1): the tunnels' roof heights, how deep the domes reach below
// the tet side, and where each dome's circle crosses the diced tet interface (0: just
// outside the diced nodes it must enclose, 1: just inside the nearest it must leave out).
struct PushParameters {
  double high_roof = 0.85;
  double low_roof = 0.6;
  double dome_depth = 0.9;
  double dome_radius = 0.6;
  // Four-triangle split only: the centre vertex's dome gets its own depth and radius blend
  // (0: the same as the corner domes'), a wider family than one depth for all.
  double centre_depth = 0.0;
  double centre_radius = 0.0;
  // Superquadric domes (templates/completion.hpp DomeShape): the exponent p of the corner
  // domes' |x|^p + |y|^p + |z|^p level sets (2: spheroids) and of the centre dome's (0: as the
  // corners'). The centre dome is the one over a vertex at the tet side's centre.
  double dome_exponent = 2.0;
  double centre_exponent = 0.0;
  // Domes off their vertices: every other dome's centre moves along the tet side toward the
  // side's centre by this fraction of the way; the centre dome's by (x, z), fractions of the
  // half-width.
  double dome_offset = 0.0;
  std::array<double, 2> centre_offset{0.0, 0.0};
};

// The buffer cell: an axis-aligned box centred at the origin, y up; the tet side (diced
// triangles) on top (y = +box.y/2), the hex side (diced quad) at the bottom. 2D templates use
// box.x and box.y.
struct GeodeOptions {
  Eigen::Vector3d box{24.0, 14.0, 24.0};
  Diagonal diagonal = Diagonal::kMain;
  Higher higher = Higher::kX;
  TopSplit split = TopSplit::kTwoTriangles;
  PushParameters push;
  stc::ArrangementOptions arrangement;  // sampling and tracing; the result does not depend on it
};

// The paper's two conditions on the pushed-together arrangement (Section 2.2), evaluated on
// the computed arrangement.
struct InterleaveChecks {
  // (1) every point where three dome sheets meet lies inside both tunnels.
  bool triple_domes_in_pocket = false;
  int triple_dome_points = 0;
  // (2) every dome-dome curve but the one(s) starting and ending on the tet face leaves the
  // cell through a side inside a tunnel entrance.
  bool dome_curves_exit_in_tunnels = false;
  int dome_curves = 0;
  int dome_curves_on_tet_face = 0;
  std::vector<std::string> failures;
  bool ok() const { return triple_domes_in_pocket && dome_curves_exit_in_tunnels; }
};

struct SheetInfo {
  std::string name;
  std::string kind;  // "tunnel" or "dome"
};

struct Template {
  int dim = 3;
  primal::HexMesh hex;    // dim 3: corner order as primal/topology.hpp, nodes in the box
  primal::QuadMesh quad;  // dim 2: in the (x, y) plane
  std::vector<SheetInfo> sheets;
  std::vector<std::vector<int>> element_sheets;  // sheets meeting in each element
  std::vector<unsigned> node_faces;  // box faces under each node: bit 2*axis + (high side)
  // Per node: the side (+1/-1) of every sheet its region lies on. With node_faces this names a
  // node independently of numbering, e.g. to identify side-face nodes of neighbouring templates.
  std::vector<std::vector<int>> node_signs;
  InterleaveChecks checks;
};

// The completed, pushed-together arrangement before it is computed: the sheets (tunnels
// first, then domes) in the reference cell (u, w in [-1, 1], v in [0, 1] up), and the two
// interface patches they were completed from. dim is 2 or 3.
struct GeodeArrangement {
  std::vector<stc::Sheet> sheets;
  stc::Domain domain;
  InterfacePatch hex_side, tet_side;
};
GeodeArrangement geode_arrangement(const GeodeOptions& options, int dim);

// Where a reference point (u, v, w) of the buffer cell lies in the box centred at the origin
// (the map that places a derived template's nodes).
Point box_point(const Point& reference, const Eigen::Vector3d& box, int dim);

// Why a push cannot be used ("" when it can): roofs 0 < low < high < 1, depth and radius
// blend in (0, 1), exponents in [1, 20] (the centre's may be 0), dome offset in [0, 1), centre
// offsets in (-1, 1). `key` (when given) receives the offending field's name, e.g.
// "dome_exponent" or "centre_offset[1]" ("low_roof" for the roofs' order).
std::string push_error(const PushParameters& push, std::string* key = nullptr);

// Complete the hex side's chords into tunnels and the tet side's vertices into domes and push
// them together, in the reference cell: the tunnels first ("tunnel x", "tunnel z"; 2D
// "tunnel"), then the domes ("dome (-x,+z)", "dome centre"; 2D "dome -x"). The tunnel whose
// chord runs along `higher` gets the high roof.
std::vector<stc::Sheet> complete_interface(const InterfacePatch& hex_side,
                                           const InterfacePatch& tet_side,
                                           const PushParameters& push, Higher higher, int dim);

// The template as an arrangement spec (templates/spec.hpp): the buffer cell's box, its two
// interface patches before dicing, the push. build_geode3d and build_geode2d derive from it.
struct ArrangementSpec;
ArrangementSpec geode_spec(const GeodeOptions& options, int dim);

// Derive a template from a spec: compute the arrangement of its sheets and dualize it. With a
// completion block, tet- and hex-side nodes are placed exactly where dicing puts them; a node
// is matched to its diced position by the sides of every sheet it lies on, so a boundary that
// differs from the prescribed diced interface is an error, not a silent mismatch. Other nodes
// get the dual's first guess (see smoothing). A "faces" block's cells are matched the same way
// and their nodes placed at the given points. Throws TopologyError with the diagnosis when the
// arrangement does not dualize to a valid mesh or to the prescribed faces.
Template build_template(const ArrangementSpec& spec, const stc::ArrangementOptions& options = {});

// build_template(geode_spec(options, 3 or 2)); InvalidInput for a degenerate box or push.
Template build_geode3d(const GeodeOptions& options);

Template build_geode2d(const GeodeOptions& options);

// Place the template's free nodes by optimization (primal/smooth.hpp): untangle, then maximise
// the minimum scaled Jacobian. Tet- and hex-side nodes stay at their diced positions unless
// slide_faces, in which case they slide within their face (box edges along the edge, corners
// fixed); side-face nodes always slide within their face.
primal::SmoothResult smooth_template(Template& t, bool slide_faces);

// The combinatorial obstructions to untangling the template (primal/realizability.hpp), its
// planar faces being the faces of its box (node_faces), wherever its nodes currently are.
std::vector<primal::Obstruction> template_obstructions(const Template& t);

// Parse "24x14x24" (or "24x14" for 2D); InvalidInput naming the text otherwise.
Eigen::Vector3d parse_box(const std::string& text);

}  // namespace geode::templates
