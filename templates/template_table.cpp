// The template table (templates/template_table.hpp).
#include <geode/templates/template_table.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/templates/pyramid.hpp>

namespace geode::templates {

namespace {

// Default grids of `study interleave`: 5-6 values per parameter inside the valid ranges,
// including the paper's geode push (0.85, 0.6, 0.9, 0.6); geode4tri gets a coarser grid.
PushGrid geode3d_grid() {
  return {{0.55, 0.65, 0.75, 0.85, 0.95},
          {0.2, 0.35, 0.5, 0.6, 0.7, 0.8},
          {0.3, 0.5, 0.7, 0.9, 0.97},
          {0.2, 0.4, 0.6, 0.8}};
}
PushGrid geode4tri_grid() {
  return {{0.65, 0.85, 0.95}, {0.35, 0.6, 0.8}, {0.5, 0.7, 0.9}, {0.3, 0.6, 0.8}};
}

GeodeOptions four_triangles() {
  GeodeOptions o;
  o.split = TopSplit::kFourTriangles;
  return o;
}

// The four-triangle push conform uses: the superquadric-dome class that has no obstruction to
// untangling (docs/results.md, "4-triangle variant"), so it needs no fix-up.
PushParameters superquadric_domes() {
  PushParameters p;
  p.dome_exponent = 3.0;
  p.centre_depth = 0.45;
  p.dome_radius = 0.8;
  p.centre_radius = 0.6;
  return p;
}

primal::SmoothResult smooth_refine(Template& t, const TemplateOptions& o, bool slide) {
  return smooth_refine3(t, o.refine, !slide);
}

// The table. Fields left out keep their defaults (GCC's -Wextra would ask for every field of a
// designated initializer).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
// Schneiders' surface on the equilateral pyramid (edges 2): the derivation stops at the
// certificate, computed from the surface, until the engine represents immersed sheets.
[[noreturn]] void refuse_pyramid() {
  const double h = std::sqrt(2.0);
  const PyramidCertificate c = pyramid_certificate(
      {primal::Point(-1, 0, -1), primal::Point(-1, 0, 1), primal::Point(1, 0, 1),
       primal::Point(1, 0, -1), primal::Point(0, h, 0)});
  throw TopologyError("template pyramid: " + c.statement +
                      " (self-intersecting sheets are not represented yet; templates/pyramid.hpp)");
}

const std::vector<TemplateEntry>& table() {
  static const std::vector<TemplateEntry> entries{
      {.name = "geode3d",
       .summary = "the 26-hex geode (tet side split by a diagonal into 2 triangles)",
       .dim = 3,
       .spec = [](const TemplateOptions& o) { return geode_spec(o.geode, 3); },
       .build = [](const TemplateOptions& o) { return build_geode3d(o.geode); },
       .interleave_conditions = true,
       .study_grid = geode3d_grid,
       .conform_use = ConformUse::kTwoTriangles},
      {.name = "geode2d",
       .summary = "the 5-quad 2D geode",
       .dim = 2,
       .spec = [](const TemplateOptions& o) { return geode_spec(o.geode, 2); },
       .build = [](const TemplateOptions& o) { return build_geode2d(o.geode); }},
      {.name = "geode4tri",
       .summary = "the tet side split into 4 triangles",
       .dim = 3,
       .defaults = {four_triangles(), {}},
       .spec = [](const TemplateOptions& o) { return geode_spec(o.geode, 3); },
       .build = [](const TemplateOptions& o) { return build_geode3d(o.geode); },
       .interleave_conditions = true,
       .fix_up = true,
       .study_grid = geode4tri_grid,
       .conform_use = ConformUse::kFourTriangles,
       .conform_push = superquadric_domes()},
      {.name = "refine3",
       .summary = "one coarse quad on top over 3 x 3 fine quads below (13 hexes)",
       .dim = 3,
       .family = TemplateFamily::kRefine,
       .spec = [](const TemplateOptions& o) { return refine_spec(o.refine, 3); },
       .build = [](const TemplateOptions& o) { return build_refine3(o.refine); },
       .smooth = smooth_refine},
      {.name = "refine3-2d",
       .summary = "one coarse edge over three fine ones (4 quads)",
       .dim = 2,
       .family = TemplateFamily::kRefine,
       .spec = [](const TemplateOptions& o) { return refine_spec(o.refine, 2); },
       .build = [](const TemplateOptions& o) { return build_refine3_2d(o.refine); },
       .smooth = smooth_refine},
      {.name = "pyramid",
       .summary = "Schneiders' 16-quad pyramid (exits 3 with the certificate that its dual needs a "
                  "self-intersecting sheet, which the engine lacks)",
       .dim = 3,
       .spec = [](const TemplateOptions&) -> ArrangementSpec { refuse_pyramid(); },
       .build = [](const TemplateOptions&) -> Template { refuse_pyramid(); }},
  };
  return entries;
}
#pragma GCC diagnostic pop

}  // namespace

std::span<const TemplateEntry> template_table() { return table(); }

const TemplateEntry* find_template(std::string_view name) {
  for (const TemplateEntry& e : table())
    if (e.name == name) return &e;
  return nullptr;
}

const TemplateEntry& conform_template(ConformUse use) {
  for (const TemplateEntry& e : table())
    if (use != ConformUse::kNone && e.conform_use == use) return e;
  throw TopologyError("no template in the template table fills this interface cell");
}

std::vector<std::string> template_names(bool studied) {
  std::vector<std::string> names;
  for (const TemplateEntry& e : table())
    if (!studied || e.study_grid) names.emplace_back(e.name);
  return names;
}

std::string template_help(bool studied) {
  std::string s;
  for (const TemplateEntry& e : table())
    if (!studied || e.study_grid)
      s += (s.empty() ? "" : ";\n") + std::string(e.name) + ": " + std::string(e.summary) +
           // `template` fixes it up; `study interleave` sweeps the plain dual, with no --no-fixup.
           (e.fix_up && !studied ? " (fixed up unless --no-fixup)" : "");
  return s;
}

TemplateOptions template_options(const TemplateEntry& entry, const GeodeOptions& geode,
                                 const RefineOptions& refine) {
  TemplateOptions o = entry.defaults;
  const TopSplit split = o.geode.split;
  o.geode = geode;
  o.geode.split = split;
  o.refine = refine;
  return o;
}

std::string box_problem(std::span<const double> box) {
  for (double x : box)
    if (!(x >= 1e-6 && x <= 1e6)) return "every dimension must lie in [1e-6, 1e6]";
  const auto [lo, hi] = std::minmax_element(box.begin(), box.end());
  if (!box.empty() && *hi > 1e4 * *lo)
    return "degenerate box (the largest dimension is more than 1e4 times the smallest)";
  return {};
}

}  // namespace geode::templates
