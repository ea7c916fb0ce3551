#pragma once
// Parameter studies of the geode templates (the paper's Sections 2.2 and 3.2):
//  - interleave study: sweep how far the two completed arrangements are pushed together and
//    classify what each push dualizes to (a template class, or the reason it does not);
//  - shape study: the smoothed template's minimum scaled Jacobian against the buffer cell's
//    height, and in sheared and tapered buffer cells.
// Results are computed, never typed in; the only paper numbers here are Table 1's, printed
// next to ours for comparison (paper_table1()).
#include <array>
#include <functional>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include <geode/primal/quality_report.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/spec.hpp>

namespace geode::templates {

// ---- Interleave study ----------------------------------------------------------------------

// A canonical invariant of a template (equal for isomorphic templates; different values prove
// the templates differ): "<hexes>h|<kind triples>|<hash>", where kind triples is the sorted
// multiset of per-element sheet-kind triples (e.g. "dome+dome+tunnel:8") and hash is a
// 64-bit colour-refinement (1-dimensional Weisfeiler-Leman) hash of the node-hex incidence
// graph, hexes initially coloured by their kind triple and nodes by which box faces (tet
// side, hex side, sides) they lie on.
std::string template_class_key(const Template& t);

// An error message with its numbers (coordinates, node numbers) replaced by '#', so that runs
// failing for the same reason share one diagnosis; sheet names are kept.
std::string strip_numbers(const std::string& message);

struct PushGrid {
  std::vector<double> high_roof, low_roof, dome_depth, dome_radius;
};

struct InterleaveRun {
  PushParameters push;
  std::vector<double> parameters;  // the swept values, one per InterleaveStudy::parameter_names
  bool valid = false;              // the arrangement dualized to a template
  int hexes = 0;
  std::string class_label;     // "V1", "V2", ... for template classes, "E1", ... for diagnoses
  bool conditions_ok = false;  // the paper's two interleave conditions (valid runs only)
  std::string conditions;      // the failed conditions, stripped of numbers (valid runs)
  std::string diagnosis;       // the TopologyError, stripped (error runs)
  double seconds = 0.0;
};

struct InterleaveClass {
  std::string label;
  bool valid = false;
  std::string key;  // template_class_key, or the stripped diagnosis
  int hexes = 0;
  int count = 0;
  int conditions_ok = 0;                   // runs of the class meeting the paper's conditions
  PushParameters example;                  // the first run of the class in sweep order
  std::vector<double> example_parameters;  // its swept values (spec studies)
  // Valid classes, measured on the example's template: the obstructions to untangling it
  // (template_obstructions), and its smoothed minimum scaled Jacobian with tet- and hex-side
  // nodes fixed at the diced positions and sliding in their faces (smooth_template). A class is
  // usable as a template when it has no obstruction and the fixed-side minimum is positive.
  std::vector<primal::Obstruction> obstructions;
  double min_sj_fixed = 0.0, min_sj_slide = 0.0;
  bool usable = false;
};

struct InterleaveStudy {
  std::string template_name;
  std::vector<std::string> parameter_names;  // swept spec paths (spec studies; else empty)
  int skipped = 0;                           // sweep points whose spec is invalid input
  std::vector<InterleaveRun> runs;           // sweep order: high, low, depth, radius
  std::vector<InterleaveClass> classes;      // valid classes, then errors; each by count, then key
};

// Called with (what, done, total) as a sweep goes: "pushes" built, then "classes" measured.
using StudyProgress =
    std::function<void(const std::string& what, std::size_t done, std::size_t total)>;

// Builds the template for every grid point with 0 < low < high < 1 (others are skipped:
// build_geode3d rejects them as invalid input), then measures each valid class. split picks geode3d
// or geode4tri; the rest of `base` (box, diagonal, higher) is kept.
InterleaveStudy interleave_study(const GeodeOptions& base, const PushGrid& grid,
                                 const std::string& template_name,
                                 const StudyProgress& progress = {});

// One point of a sweep: the push and swept values the CSV records, and how to build it.
struct InterleaveCase {
  PushParameters push;
  std::vector<double> parameters;
  std::function<Template()> build;
};
InterleaveStudy interleave_study(const std::vector<InterleaveCase>& cases,
                                 const std::string& template_name,
                                 const std::vector<std::string>& parameter_names = {},
                                 const StudyProgress& progress = {});

// At most this many sweep points (the product of the axes' counts): 20,000 runs of the geode
// take hours on two cores, and every run is kept in memory for the summary.
inline constexpr double kMaxSweepPoints = 20000;
// InvalidInput naming `where` when the product of `counts` is above kMaxSweepPoints.
void check_sweep_size(const std::vector<std::size_t>& counts, const std::string& where);

// A spec (templates/spec.hpp) swept over every combination of the axes' values (the first
// axis slowest); points whose spec is invalid input (e.g. low roof above high) are skipped
// and counted. `source` names the spec in messages. InvalidInput past kMaxSweepPoints
// points, before any run.
InterleaveStudy interleave_study(const nlohmann::json& spec, const std::string& source,
                                 const std::vector<SweepAxis>& axes,
                                 const std::string& template_name,
                                 const StudyProgress& progress = {});

// CSV: high_roof,low_roof,dome_depth,dome_radius,outcome,hexes,class,conditions_ok,diagnosis,
// then one column per swept spec path (spec studies)
void write_interleave_csv(std::ostream& out, const InterleaveStudy& study);
// CSV: class,outcome,count,hexes,conditions_ok,example high/low/depth/radius,key,obstructions
// (count per kind, "doublet:10;pinched-corner:1"),min_sj_fixed,min_sj_slide,usable, then the
// example's value of each swept spec path ("example_" + path; spec studies)
void write_interleave_summary(std::ostream& out, const InterleaveStudy& study);

// ---- Shape study ---------------------------------------------------------------------------

// A buffer cell given by its 8 corners, corner[bx + 2 by + 4 bz] with bx, by, bz in {0, 1}
// (by = 1 is the tet side). Each face must be planar (shears and tapers are).
using CellCorners = std::array<primal::Point, 8>;
CellCorners box_cell(const Eigen::Vector3d& box);
// Top face shifted by height * tan(angle) along +x (a parallelepiped).
CellCorners sheared_cell(const Eigen::Vector3d& box, double angle_degrees);
// Top face scaled about the axis by `ratio` in x and z (a frustum; ratio 1 is the box).
CellCorners tapered_cell(const Eigen::Vector3d& box, double ratio);

// Maps the template's positions (built in the box of `box_of_t`, centred) trilinearly into
// the cell, then smooths: tet- and hex-side nodes fixed (slide = false) or sliding in their
// planes (slide = true); side-face nodes slide in their face planes, nodes on two faces along
// the common edge, cell corners fixed.
primal::SmoothResult smooth_in_cell(Template& t, const Eigen::Vector3d& box_of_t,
                                    const CellCorners& cell, bool slide);

struct ShapeRow {
  std::string cell;        // "box", "shear", "taper"
  double parameter = 0.0;  // height, shear angle (degrees) or taper ratio
  std::string mode;        // "fixed" or "slide"
  double initial_min_sj = 0.0, final_min_sj = 0.0, final_max_sj = 0.0;
  bool untangled = false;
  int iterations = 0;
  double seconds = 0.0;
};

// Geode in a 24 x h x 24 box for each height, both modes.
std::vector<ShapeRow> height_study(const std::vector<double>& heights, double base = 24.0);
// Geode in sheared (angles, degrees) and tapered (top/bottom ratios) 24 x 14 x 24 cells.
std::vector<ShapeRow> distorted_study(const std::vector<double>& shear_degrees,
                                      const std::vector<double>& taper_ratios);
// CSV: cell,parameter,mode,initial_min_sj,final_min_sj,final_max_sj,untangled,iterations,seconds
void write_shape_csv(std::ostream& out, const std::vector<ShapeRow>& rows);

// The paper's Table 1 (CUBIT report, 24 x 14 x 24 geode), for comparison only.
struct PaperRow {
  primal::HexMetric metric;
  double average, std_dev, minimum, maximum;
};
const std::vector<PaperRow>& paper_table1();

// Smoothed 24 x 14 x 24 geode in both modes: the Table 1 report next to the paper's values
// (CSV: metric,key,mode,average,std_dev,min,max,paper_average,paper_std_dev,paper_min,paper_max)
// and per-hex scaled Jacobians (CSV: mode,hex,scaled_jacobian).
void write_geode_quality(std::ostream& report_csv, std::ostream* per_hex_csv);

}  // namespace geode::templates
