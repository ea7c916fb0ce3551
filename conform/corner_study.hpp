#pragma once
// The transition at hex-part edges and corners (issue 22): per dihedral angle and corner kind,
// the lowest scaled Jacobian of the geode hexes before smoothing (--smooth none) and after it
// (the defaults, and --smooth global), their lowest ratio to the local yardstick
// (ConformResult::local_yardstick) and the lowest local yardstick there. `geode study corners` and
// bench_transition_study print it; notebooks-data/plot.py draws its CSV.
//
// Classes. Every interface edge shared by two interface quads has a dihedral angle measured
// inside the hex part (180: flat; below: convex; above: concave). A node where three or more
// edges at least kCornerFeatureAngle from flat meet is a corner: convex if all are convex,
// concave if all are concave, a saddle otherwise. An interface quad is classed by its corners
// (saddle, then convex, then concave corner) or else by its sharpest edge (convex or concave
// edge, or flat), at the angle of its sharpest edge rounded to 5 degrees.
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <geode/conform/conform.hpp>
#include <geode/primal/interface.hpp>
#include <geode/primal/model.hpp>

namespace geode::conform {

inline constexpr double kCornerFeatureAngle = 20.0;  // degrees from flat that make an edge count

struct QuadClass {
  std::string kind;  // "flat", "convex edge", "concave edge", "convex/concave/saddle corner"
  double angle = 180.0;
};

// Per interface quad (Interface::quads order): its class.
std::vector<QuadClass> classify_interface_quads(const primal::Model& model,
                                                const primal::Interface& itf);

// Per buffer hex of a conform result: the lowest scaled Jacobian of its geode hexes (each
// buffer hex's template hexes follow the diced hexes, in buffer-hex order).
std::vector<double> geode_minima(const ConformResult& result);

// A model's name and how to build it (demo::corner_study_models gives the demo set).
using CornerStudyModel = std::pair<std::string, std::function<primal::Model()>>;

struct CornerStudyRow {
  std::string model, kind;
  double angle = 180.0;
  int buffer_hexes = 0;
  double min_none = 1.0, min_default = 1.0;  // geode hexes' minimum, --smooth none / defaults
  double min_global = 1.0;                   // the same with --smooth global
  double min_local_ratio = 1e9;              // defaults: min of geode minimum / local yardstick
  double min_local_yardstick = 1.0;
  // Defaults: min of geode minimum / min(local yardstick, ConformResult::template_ceiling): at
  // or above 0.9 where min_local_ratio is not, the template's ceiling stops it, not placement.
  double min_capped_ratio = 1e9;
};

struct CornerStudyModelSummary {
  std::string name;
  std::string failure;                        // not built or refused: why (no rows then)
  BufferSide buffer_side = BufferSide::kHex;  // the defaults' (the run without smoothing: the same)
  bool valid_none = false, valid_default = false, valid_global = false;
  double seconds_none = 0.0, seconds_default = 0.0, seconds_global = 0.0;
  int patches = 0;  // smoothing patches with the defaults
};

struct CornerStudy {
  int n = 0;
  std::vector<CornerStudyRow> rows;  // per model, by kind and angle
  std::vector<CornerStudyModelSummary> models;
};

// Conforms each model three times (the defaults, --smooth none and --smooth global) and classes
// its buffer hexes. `n` is only recorded (the models are built at their own size). `done` is
// called after each model. `side`: the buffer side the defaults' run takes (chosen, as
// --buffer-side is; "": automatic); the other two runs are given the side that one took.
CornerStudy corner_study(const std::vector<CornerStudyModel>& models, int n,
                         const std::function<void(const CornerStudyModelSummary&)>& done = {},
                         const std::string& side = "");

// model,n,kind,angle,buffer_hexes,min_sj_none,min_sj_default,min_local_ratio_default,
// min_local_yardstick,min_capped_ratio_default,min_sj_global
void write_corner_csv(std::ostream& out, const CornerStudy& study);
// The same as a table, with one summary line per model.
void write_corner_table(std::ostream& out, const CornerStudy& study);

}  // namespace geode::conform
