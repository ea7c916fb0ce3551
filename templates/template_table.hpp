#pragma once
// The template table: every built-in template, one entry each (name, the options it reads, its
// arrangement as a spec, its builder and smoother, what studies and conform may use it for).
// `geode template`, `geode study interleave`, conform's reference templates and the commands'
// help texts are read off it, so a new template is its builder in a file of its own plus one
// entry in template_table.cpp (docs/developer-guide.md, "A template").
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <geode/primal/smooth.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/refine.hpp>
#include <geode/templates/spec.hpp>
#include <geode/templates/study.hpp>

namespace geode::templates {

// The boxes a template may be built in (`geode template --box`, the module's box=): each
// dimension in [1e-6, 1e6], the largest at most 1e4 times the smallest. Empty when `box` is one,
// else why not.
std::string box_problem(std::span<const double> box);

// Which options a template reads: the geode family's (GeodeOptions: box, diagonal, higher, push)
// or the refinement family's (RefineOptions: box, roofs, layer).
enum class TemplateFamily { kGeode, kRefine };

// What conform may fill with a template: nothing, a buffer hex whose tet side is two triangles
// (one template per diagonal), or one whose tet side is four triangles around a centre node.
enum class ConformUse { kNone, kTwoTriangles, kFourTriangles };

// Everything a built-in template can be given; each entry reads its family's part.
struct TemplateOptions {
  GeodeOptions geode;
  RefineOptions refine;
};

struct TemplateEntry {
  std::string_view name;     // `geode template NAME`
  std::string_view summary;  // one line for --help
  int dim = 3;
  TemplateFamily family = TemplateFamily::kGeode;
  TemplateOptions defaults;  // what the name stands for beyond the command's options (the split)
  ArrangementSpec (*spec)(const TemplateOptions& options) = nullptr;
  Template (*build)(const TemplateOptions& options) = nullptr;
  // Its own smoothing (slide: side nodes free in their faces); nullptr: smooth_template.
  primal::SmoothResult (*smooth)(Template& t, const TemplateOptions& options, bool slide) = nullptr;
  bool interleave_conditions = false;  // the paper's two conditions apply (geode family, 3D)
  bool fix_up = false;                 // obstructions pillowed away by default (--no-fixup)
  PushGrid (*study_grid)() =
      nullptr;  // `study interleave --template NAME`'s grid; nullptr: not studied
  ConformUse conform_use = ConformUse::kNone;
  PushParameters conform_push;  // the push conform builds it with (conform_use != kNone)
};

// Every entry, in the order --help lists them.
std::span<const TemplateEntry> template_table();

// The entry named `name`, or nullptr.
const TemplateEntry* find_template(std::string_view name);

// The entry conform uses for `use` (not kNone); TopologyError when the table has none.
const TemplateEntry& conform_template(ConformUse use);

// Names of every entry (studied: those with a study grid), in table order.
std::vector<std::string> template_names(bool studied = false);

// "geode3d: ...;\ngeode2d: ..." for --help (studied: those with a study grid, for `study
// interleave`, which does not fix them up: without the --no-fixup note of a fix_up entry).
std::string template_help(bool studied = false);

// The options for `entry`: its defaults with the family's part replaced by what the caller
// gives (the command's box, diagonal, push, ...), the split kept from the entry.
TemplateOptions template_options(const TemplateEntry& entry, const GeodeOptions& geode,
                                 const RefineOptions& refine);

}  // namespace geode::templates
