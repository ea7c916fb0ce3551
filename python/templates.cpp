// geode.template, geode.arrange and geode.study_interleave: templates derived from their sheet
// arrangements, as `geode template`, `geode arrange` and `geode study interleave` derive them
// (cli/template_command.cpp, cli/arrange_command.cpp, cli/study_command.cpp), returned as objects
// with numpy arrays instead of written as files.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/stc/sheet_surfaces.hpp>
#include <geode/templates/fixup.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/refine.hpp>
#include <geode/templates/spec.hpp>
#include <geode/templates/study.hpp>
#include <geode/templates/template_table.hpp>
#include <geode/viewer/html.hpp>
#include "python/arrays.hpp"

namespace geode::python {
namespace {

namespace fs = std::filesystem;

// ---- The built-in templates: the library's table (templates/template_table.hpp) ------------

const templates::TemplateEntry& find_entry(const std::string& name) {
  if (const templates::TemplateEntry* e = templates::find_template(name)) return *e;
  std::string names;
  for (const auto& n : templates::template_names()) names += (names.empty() ? "" : ", ") + n;
  throw InvalidInput("template: unknown template '" + name + "' (expected " + names + ")");
}

// ---- The result ---------------------------------------------------------------------------------

struct TemplateResult {
  std::string name;
  templates::Template t;
  bool check_conditions = false;
  // For the viewer and spec(): the arrangement's sheets and domain, the map from the domain to the
  // template's coordinates (identity when empty), and how it was made.
  std::vector<stc::Sheet> sheets;
  stc::Domain domain;
  std::function<Point(const Point&)> to_physical;
  std::string caption;
  nlohmann::json spec;  // null when unknown
  // How the template may be smoothed again (refine3's own smoother, else smooth_template).
  std::function<primal::SmoothResult(templates::Template&, bool slide)> smoother;
  std::optional<primal::SmoothResult> smoothing;
  std::optional<templates::FixupResult> fixup;
  std::vector<std::string> warnings;
};

py::dict smooth_dict(const primal::SmoothResult& r) {
  py::dict d;
  d["untangled"] = r.untangled;
  d["iterations"] = r.iterations;
  d["untangle_iterations"] = r.untangle_iterations;
  d["shape_iterations"] = r.shape_iterations;
  d["initial_min_jacobian"] = r.initial_min_jacobian;
  d["final_min_jacobian"] = r.final_min_jacobian;
  d["initial_min_scaled_jacobian"] = r.initial_min_scaled_jacobian;
  d["final_min_scaled_jacobian"] = r.final_min_scaled_jacobian;
  d["final_max_scaled_jacobian"] = r.final_max_scaled_jacobian;
  d["seconds"] = r.seconds;
  return d;
}

py::list obstructions_list(const std::vector<primal::Obstruction>& obstructions) {
  return to_python(primal::obstructions_json(obstructions, 0));
}

// Smooths (GIL released) and notes what the smoother could not do, as `geode template` warns.
void smooth(TemplateResult& r, bool slide) {
  {
    py::gil_scoped_release free;
    r.smoothing = r.smoother ? r.smoother(r.t, slide) : templates::smooth_template(r.t, slide);
  }
  const auto obstructions = templates::template_obstructions(r.t);
  if (!r.smoothing->untangled)
    r.warnings.push_back(
        "smoothing could not untangle every element; " +
        (obstructions.empty()
             ? std::string("no combinatorial obstruction found")
             : "no placement can: " + primal::format_obstructions(obstructions, r.t.dim, 0)));
  else if (!obstructions.empty())
    r.warnings.push_back(
        "the connectivity admits no valid placement (the cells overlap or fold somewhere): " +
        primal::format_obstructions(obstructions, r.t.dim, 0));
}

void note_conditions(TemplateResult& r) {
  if (!r.check_conditions || r.t.checks.ok()) return;
  std::string why;
  for (const auto& f : r.t.checks.failures) why += (why.empty() ? "" : "; ") + f;
  r.warnings.push_back("the interleave fails the paper's conditions: " + why);
}

// The arrangement's sheets contoured in the domain for the viewer, mapped like the nodes, each
// with its layer of cells (as `geode template --format html` draws them).
std::vector<viewer::ViewSheet> view_sheets(const TemplateResult& r) {
  std::vector<viewer::ViewSheet> out(r.sheets.size());
  for (std::size_t s = 0; s < r.sheets.size(); ++s)
    out[s].name = r.sheets[s].name, out[s].kind = r.sheets[s].kind;
  if (r.domain.dim == 3) {
    auto surfaces = stc::contour_sheets(r.sheets, r.domain);
    for (std::size_t s = 0; s < out.size(); ++s) {
      out[s].surface = std::move(surfaces[s]);
      out[s].smooth = true;
      if (r.to_physical)
        for (auto& p : out[s].surface.points) p = r.to_physical(p);
    }
  } else {
    auto curves = stc::contour_curves(r.sheets, r.domain);
    for (std::size_t s = 0; s < out.size(); ++s) {
      out[s].curve = std::move(curves[s]);
      if (r.to_physical)
        for (auto& p : out[s].curve.points) p = r.to_physical(p);
    }
  }
  for (std::size_t e = 0; e < r.t.element_sheets.size(); ++e)
    for (int s : r.t.element_sheets[e])
      if (s >= 0 && primal::index_cast<std::size_t>(s) < out.size())
        out[primal::index_cast<std::size_t>(s)].layer.push_back(primal::index_cast(e));
  return out;
}

std::string template_html(const TemplateResult& r) {
  const auto& T = r.t;
  viewer::ViewScene scene;
  scene.title = "geode template " + r.name;
  std::ostringstream caption;
  caption << r.caption << ": " << (T.dim == 3 ? T.hex.hexes.size() : T.quad.quads.size())
          << (T.dim == 3 ? " hexes" : " quads");
  if (r.smoothing)
    caption << ", smoothed: min scaled Jacobian " << r.smoothing->initial_min_scaled_jacobian
            << " -> " << r.smoothing->final_min_scaled_jacobian;
  else
    caption << ", not smoothed";
  caption << ". Sheets: the arrangement's fields contoured in the cell (marching tetrahedra), "
             "mapped like the nodes; "
             "the smoothed cells need not follow them. Layers: the cells dual to each sheet.";
  scene.caption = caption.str();
  scene.sheets = view_sheets(r);
  if (T.dim == 2) return viewer::html_view(T.quad, scene);
  // The tet and hex sides as face groups (the paper's Figure 1), when the template knows its box
  // faces.
  if (T.node_faces.size() == T.hex.points.size()) {
    scene.groups = {
        viewer::boundary_face_group("tet side", T.hex, T.node_faces, stc::box_face(1, true)),
        viewer::boundary_face_group("hex side", T.hex, T.node_faces, stc::box_face(1, false))};
  }
  return viewer::html_view(T.hex, scene);
}

// ---- template() ---------------------------------------------------------------------------------

Eigen::Vector3d parse_box(const py::handle& box, int dim) {
  std::vector<double> b;
  try {
    b = box.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw InvalidInput("template: box must be a sequence of numbers");
  }
  if (b.size() != primal::index_cast<std::size_t>(dim))
    throw InvalidInput("template: box has " + std::to_string(b.size()) + " numbers for a " +
                       std::to_string(dim) + "D template");
  if (const std::string why = templates::box_problem(b); !why.empty())
    throw InvalidInput("template: box: " + why);  // as `geode template --box` refuses it
  return {b[0], b[1], dim == 3 ? b[2] : b[0]};
}

// The push keywords (PushParameters' fields, and refine3's layer); the keyword named when unknown.
struct PushArgs {
  templates::PushParameters push;
  std::optional<double> high_roof, low_roof, layer;
};

PushArgs parse_push(const py::dict& kwargs, bool refine) {
  PushArgs a;
  auto& p = a.push;
  const std::map<std::string, double*> numbers{
      {"high_roof", &p.high_roof},         {"low_roof", &p.low_roof},
      {"dome_depth", &p.dome_depth},       {"dome_radius", &p.dome_radius},
      {"centre_depth", &p.centre_depth},   {"centre_radius", &p.centre_radius},
      {"dome_exponent", &p.dome_exponent}, {"centre_exponent", &p.centre_exponent},
      {"dome_offset", &p.dome_offset}};
  for (const auto& [k, v] : kwargs) {
    const std::string key = k.cast<std::string>();
    try {
      if (key == "centre_offset") {
        const auto xz = v.cast<std::vector<double>>();
        if (xz.size() != 2)
          throw InvalidInput("template: centre_offset must be two numbers (x, z)");
        p.centre_offset = {xz[0], xz[1]};
      } else if (key == "layer") {
        if (!refine) throw InvalidInput("template: layer is refine3's parameter");
        a.layer = v.cast<double>();
      } else if (auto it = numbers.find(key); it != numbers.end()) {
        *it->second = v.cast<double>();
        if (key == "high_roof") a.high_roof = *it->second;
        if (key == "low_roof") a.low_roof = *it->second;
      } else {
        std::string names = "centre_offset, layer";
        for (const auto& [n, _] : numbers) names += ", " + n;
        throw InvalidInput("template: unknown push parameter '" + key + "' (expected " + names +
                           ")");
      }
    } catch (const py::cast_error&) {
      throw InvalidInput("template: " + key + " must be a number");
    }
  }
  for (const auto& [key, value] : numbers)
    if (!std::isfinite(*value)) throw InvalidInput("template: " + key + " must be finite");
  return a;
}

std::unique_ptr<TemplateResult> make_template(const std::string& name, const py::handle& box_arg,
                                              const std::string& diagonal,
                                              const std::string& higher, bool smooth_it, bool slide,
                                              bool fixup, const py::dict& kwargs) {
  const templates::TemplateEntry& entry = find_entry(name);
  if (diagonal != "main" && diagonal != "anti")
    throw InvalidInput("template: diagonal must be 'main' or 'anti'");
  if (higher != "x" && higher != "z") throw InvalidInput("template: higher must be 'x' or 'z'");
  const int dim = entry.dim;
  const Eigen::Vector3d box =
      box_arg.is_none() ? Eigen::Vector3d(24, 14, 24) : parse_box(box_arg, dim);
  const bool refine = entry.family == templates::TemplateFamily::kRefine;
  const PushArgs push = parse_push(kwargs, refine);
  auto r = std::make_unique<TemplateResult>();
  r->name = name;
  std::ostringstream caption;
  caption << "geode.template(\"" << name << "\", box=(" << box.x() << ", " << box.y();
  if (dim == 3) caption << ", " << box.z();
  caption << "))";
  r->caption = caption.str();
  {
    py::gil_scoped_release free;
    templates::GeodeOptions o;
    o.box = box;
    o.diagonal = diagonal == "anti" ? templates::Diagonal::kAnti : templates::Diagonal::kMain;
    o.higher = higher == "z" ? templates::Higher::kZ : templates::Higher::kX;
    o.push = push.push;
    templates::RefineOptions ro;
    ro.box = box;
    if (push.high_roof) ro.high_roof = *push.high_roof;
    if (push.low_roof) ro.low_roof = *push.low_roof;
    if (push.layer) ro.layer = *push.layer;
    // As `geode template` builds it: the entry's own split, spec, build, smoothing, fix-up (and
    // its refusal: Schneiders' pyramid raises TopologyError with its certificate).
    const templates::TemplateOptions options = templates::template_options(entry, o, ro);
    r->t = entry.build(options);
    const templates::ArrangementSpec spec = entry.spec(options);
    r->spec = templates::spec_json(spec);
    if (refine) {  // its spec is in the box already
      r->sheets = templates::spec_sheets(spec), r->domain = spec.domain;
    } else {  // the geode's arrangement is built in the reference cell, mapped to the box
      const templates::GeodeArrangement G = templates::geode_arrangement(options.geode, dim);
      r->sheets = G.sheets, r->domain = G.domain;
      r->to_physical = [box, dim](const Point& p) { return templates::box_point(p, box, dim); };
    }
    if (entry.smooth)
      r->smoother = [&entry, options](templates::Template& t, bool s) {
        return entry.smooth(t, options, s);
      };
    r->check_conditions = entry.interleave_conditions;
    if (entry.fix_up && fixup) r->fixup = templates::fix_up(r->t);
  }
  note_conditions(*r);
  if (r->fixup && r->fixup->obstructions_after > 0)
    r->warnings.push_back("fix-up left " + std::to_string(r->fixup->obstructions_after) +
                          " obstructions");
  if (smooth_it) smooth(*r, slide);
  return r;
}

// ---- arrange() ----------------------------------------------------------------------------------

// A spec argument: a dict, or a path to a JSON file; `source` names it in messages.
nlohmann::json spec_argument(const py::handle& spec, std::string& source, std::string& stem) {
  if (py::isinstance<py::dict>(spec)) {
    source = "spec", stem = "spec";
    return to_json(spec, "spec");
  }
  if (py::isinstance<py::str>(spec) || py::hasattr(spec, "__fspath__")) {
    const fs::path path(
        py::str(py::module_::import("os").attr("fspath")(spec)).cast<std::string>());
    source = path.filename().string(), stem = path.stem().string();
    return templates::read_spec_json(path);
  }
  throw InvalidInput("spec: expected a dict or a path to a JSON spec");
}

std::unique_ptr<TemplateResult> arrange(const py::handle& spec_arg, bool smooth_it, bool slide) {
  std::string source, stem;
  const nlohmann::json j = spec_argument(spec_arg, source, stem);
  const templates::ArrangementSpec spec = templates::parse_spec(j, source);
  if (smooth_it && spec.domain.corners)
    throw InvalidInput(source + ": smoothing needs a box domain (this spec's domain is a " +
                       (spec.dim == 3 ? "hexahedron)" : "quadrilateral)"));
  auto r = std::make_unique<TemplateResult>();
  r->name = stem;
  r->caption = "geode.arrange(" + source + ")";
  r->spec = templates::spec_json(spec);
  r->sheets = templates::spec_sheets(spec), r->domain = spec.domain;
  r->check_conditions = spec.completion.has_value() && spec.dim == 3;
  {
    py::gil_scoped_release free;
    r->t = templates::build_template(spec);
  }
  note_conditions(*r);
  if (smooth_it) smooth(*r, slide);
  return r;
}

// ---- study_interleave() -------------------------------------------------------------------------

py::dict push_dict(const templates::PushParameters& p) {
  py::dict d;
  d["high_roof"] = p.high_roof, d["low_roof"] = p.low_roof, d["dome_depth"] = p.dome_depth,
  d["dome_radius"] = p.dome_radius;
  return d;
}

py::tuple study_interleave(const py::handle& spec_arg, const py::object& sweep,
                           const py::object& progress) {
  std::string source, stem;
  nlohmann::json spec;
  if (py::isinstance<py::str>(spec_arg) && !fs::exists(spec_arg.cast<std::string>())) {
    // A built-in geode template by name: its spec, swept the same way.
    const templates::TemplateEntry& e = find_entry(spec_arg.cast<std::string>());
    if (e.family != templates::TemplateFamily::kGeode)
      throw InvalidInput("study_interleave: " + std::string(e.name) + " has no push to sweep");
    spec = templates::spec_json(e.spec(templates::template_options(e, {}, {})));
    source = stem = e.name;
  } else {
    spec = spec_argument(spec_arg, source, stem);
  }
  templates::parse_spec(spec, source);  // the unswept spec must be valid too
  std::vector<templates::SweepAxis> axes = templates::spec_sweep(spec, source);
  if (!sweep.is_none()) {
    if (!py::isinstance<py::dict>(sweep))
      throw InvalidInput("study_interleave: sweep must be a dict {path: values}");
    for (const auto& [k, v] : sweep.cast<py::dict>()) {
      const std::string path = k.cast<std::string>();
      templates::SweepAxis axis;
      if (py::isinstance<py::str>(v)) {
        axis = templates::parse_sweep_option(path + "=" + v.cast<std::string>());
      } else {
        // Read as the spec's own sweep block would be (checked against the spec).
        nlohmann::json with = spec;
        with["sweep"] = nlohmann::json::object();
        with["sweep"][path] = to_json(v, "sweep." + path);
        axis = templates::spec_sweep(with, source).front();
      }
      nlohmann::json probe = spec;
      templates::set_spec_number(probe, axis.path, axis.values.front(), source);
      auto same = std::find_if(axes.begin(), axes.end(),
                               [&](const auto& x) { return x.path == axis.path; });
      if (same != axes.end())
        *same = axis;
      else
        axes.push_back(axis);
    }
  }
  if (axes.empty())
    throw InvalidInput(source + ": nothing to sweep (give sweep={path: values} or a sweep block)");
  templates::StudyProgress report;
  if (!progress.is_none())
    report = [&progress](const std::string& what, std::size_t done, std::size_t total) {
      py::gil_scoped_acquire held;
      progress(what, done, total);
    };
  templates::InterleaveStudy study;
  {
    py::gil_scoped_release free;
    study = templates::interleave_study(spec, source, axes, stem, report);
  }
  if (study.runs.empty())
    throw InvalidInput(source + ": every sweep point is invalid input (e.g. low roof above high)");
  py::list runs, classes;
  for (const auto& r : study.runs) {
    py::dict d = push_dict(r.push);
    d["outcome"] = r.valid ? "valid" : "error";
    d["hexes"] = r.hexes;
    d["class"] = r.class_label;
    d["conditions_ok"] = r.valid ? py::object(py::bool_(r.conditions_ok)) : py::object(py::none());
    d["diagnosis"] = r.valid ? r.conditions : r.diagnosis;
    d["seconds"] = r.seconds;
    for (std::size_t i = 0; i < r.parameters.size(); ++i)
      d[py::str(study.parameter_names[i])] = r.parameters[i];
    runs.append(d);
  }
  for (const auto& c : study.classes) {
    py::dict d;
    d["class"] = c.label;
    d["outcome"] = c.valid ? "valid" : "error";
    d["count"] = c.count;
    d["hexes"] = c.hexes;
    d["conditions_ok"] = c.conditions_ok;
    for (const auto& [k, v] : push_dict(c.example))
      d[py::str("example_" + k.cast<std::string>())] = v;
    d["key"] = c.key;
    d["obstructions"] =
        c.valid ? py::object(obstructions_list(c.obstructions)) : py::object(py::none());
    d["min_sj_fixed"] = c.valid ? py::object(py::float_(c.min_sj_fixed)) : py::object(py::none());
    d["min_sj_slide"] = c.valid ? py::object(py::float_(c.min_sj_slide)) : py::object(py::none());
    d["usable"] = c.valid ? py::object(py::bool_(c.usable)) : py::object(py::none());
    for (std::size_t i = 0; i < c.example_parameters.size(); ++i)
      d[py::str("example_" + study.parameter_names[i])] = c.example_parameters[i];
    classes.append(d);
  }
  return py::make_tuple(runs, classes);
}

}  // namespace

void bind_templates(py::module_& m) {
  py::class_<TemplateResult>(
      m, "Template",
      "A template derived from its sheet arrangement: the mesh (points, cells), its sheets and "
      "their triples, the paper's conditions, quality; every id 0-based.")
      .def_readonly("name", &TemplateResult::name)
      .def_property_readonly("dim", [](const TemplateResult& r) { return r.t.dim; })
      // Copies (templates are small): fix_up() changes the mesh, which would leave a view dangling.
      .def_property_readonly(
          "points",
          [](const TemplateResult& r) {
            return points_array(
                std::vector<Point>(r.t.dim == 3 ? r.t.hex.points : r.t.quad.points));
          },
          "N x 3 float64 node positions (z = 0 in 2D)")
      .def_property_readonly(
          "cells",
          [](const TemplateResult& r) {
            return r.t.dim == 3 ? cells_array<8>(std::vector(r.t.hex.hexes))
                                : cells_array<4>(std::vector(r.t.quad.quads));
          },
          "M x 8 hexes (VTK order) in 3D, M x 4 quads (counter-clockwise) in 2D, int32, 0-based")
      .def_property_readonly(
          "hexes",
          [](const TemplateResult& r) -> py::object {
            if (r.t.dim != 3) return py::none();
            return cells_array<8>(std::vector(r.t.hex.hexes));
          },
          "M x 8 int32 hexes in VTK order (None for a 2D template)")
      .def_property_readonly("quads",
                             [](const TemplateResult& r) -> py::object {
                               if (r.t.dim != 2) return py::none();
                               return cells_array<4>(std::vector(r.t.quad.quads));
                             })
      .def_property_readonly(
          "sheets",
          [](const TemplateResult& r) {
            py::list l;
            for (const auto& s : r.t.sheets)
              l.append(py::dict(py::arg("name") = s.name, py::arg("kind") = s.kind));
            return l;
          },
          "the arrangement's sheets: [{'name', 'kind'}] (tunnels, then domes)")
      .def_property_readonly(
          "element_sheets", [](const TemplateResult& r) { return r.t.element_sheets; },
          "per cell, the sheets (indices into sheets) meeting at its vertex")
      .def_property_readonly(
          "triples",
          [](const TemplateResult& r) {
            std::map<std::vector<int>, int> table;
            for (const auto& e : r.t.element_sheets) ++table[e];
            py::list l;
            for (const auto& [sheets, count] : table) {
              py::list names;
              for (int s : sheets)
                names.append(r.t.sheets[primal::index_cast<std::size_t>(s)].name);
              l.append(py::dict(py::arg("sheets") = py::tuple(names), py::arg("cells") = count));
            }
            return l;
          },
          "the sheet triples (pairs in 2D) of the arrangement, each with the number of cells where "
          "they meet")
      .def_property_readonly(
          "conditions",
          [](const TemplateResult& r) -> py::object {
            if (!r.check_conditions) return py::none();
            const auto& c = r.t.checks;
            py::dict d;
            d["ok"] = c.ok();
            d["triple_domes_in_pocket"] = c.triple_domes_in_pocket;
            d["triple_dome_points"] = c.triple_dome_points;
            d["dome_curves_exit_in_tunnels"] = c.dome_curves_exit_in_tunnels;
            d["dome_curves"] = c.dome_curves;
            d["dome_curves_on_tet_face"] = c.dome_curves_on_tet_face;
            d["failures"] = c.failures;
            return d;
          },
          "the paper's two interleave conditions (Section 2.2); None where they do not apply")
      .def_property_readonly(
          "node_faces", [](const TemplateResult& r) { return py::array(py::cast(r.t.node_faces)); },
          "per node, the box faces it lies on as bits (bit 2 * axis + high side; y is up)")
      .def_property_readonly(
          "quality",
          [](const TemplateResult& r) {
            py::dict d;
            if (r.t.dim == 2) {
              std::vector<double> sj;
              for (std::size_t q = 0; q < r.t.quad.quads.size(); ++q)
                sj.push_back(primal::quad_scaled_jacobian(
                    primal::quad_corners(r.t.quad, primal::index_cast(q)), Point::UnitZ()));
              d["scaled_jacobian"] = double_array(std::move(sj));
              return d;
            }
            for (const auto& info : primal::hex_metrics()) {
              std::vector<double> v;
              for (std::size_t h = 0; h < r.t.hex.hexes.size(); ++h)
                v.push_back(info.evaluate(primal::hex_corners(r.t.hex, primal::index_cast(h))));
              d[py::str(std::string(info.key))] = double_array(std::move(v));
            }
            return d;
          },
          "per cell quality: {metric key: array} (Verdict definitions, the paper's Table 1 "
          "metrics; 2D: the scaled Jacobian)")
      .def_property_readonly(
          "smoothing",
          [](const TemplateResult& r) -> py::object {
            if (!r.smoothing) return py::none();
            return smooth_dict(*r.smoothing);
          },
          "what the last smoothing did (None when not smoothed)")
      .def_property_readonly(
          "fixup",
          [](const TemplateResult& r) -> py::object {
            if (!r.fixup) return py::none();
            py::dict d;
            d["obstructions_before"] = r.fixup->obstructions_before;
            d["obstructions_after"] = r.fixup->obstructions_after;
            d["steps"] = r.fixup->steps;
            return d;
          },
          "what the fix-up did (geode4tri; None when not fixed up)")
      .def_readonly("warnings", &TemplateResult::warnings)
      .def_property_readonly(
          "spec", [](const TemplateResult& r) { return to_python(r.spec); },
          "the arrangement as a spec dict (geode.arrange's input), or None")
      .def(
          "obstructions",
          [](const TemplateResult& r) {
            return obstructions_list(templates::template_obstructions(r.t));
          },
          "the combinatorial obstructions to untangling it (planar faces: its box faces), 0-based")
      .def(
          "fix_up",
          [](TemplateResult& r) {
            templates::FixupResult f;
            {
              py::gil_scoped_release free;
              f = templates::fix_up(r.t);
            }
            r.fixup = f;
            r.smoothing.reset();
            py::dict d;
            d["obstructions_before"] = f.obstructions_before;
            d["obstructions_after"] = f.obstructions_after;
            d["steps"] = f.steps;
            return d;
          },
          "pillow small shrink sets of the obstructions away (templates/fixup.hpp); the boundary "
          "is kept")
      .def(
          "smooth",
          [](TemplateResult& r, bool slide) {
            smooth(r, slide);
            return smooth_dict(*r.smoothing);
          },
          py::arg("slide") = false,
          "place the free nodes by optimization (tet- and hex-side nodes fixed, or sliding in "
          "their faces)")
      .def(
          "quality_report",
          [](const TemplateResult& r) -> py::object {
            if (r.t.dim != 3) throw InvalidInput(r.name + ": the quality report is for hexes");
            const auto q = primal::hex_quality_report(r.t.hex);
            py::dict d = to_python(primal::quality_report_json(q));
            d["table"] = primal::format_quality_table(q);
            return d;
          },
          "the paper's Table 1 over the hexes: {'metrics': [...], 'table': text}")
      .def("html", &template_html,
           "the self-contained viewer page (three.js inlined): cells, sheets, layers, quality");

  m.def("_template", &make_template, py::arg("name"), py::arg("box"), py::arg("diagonal"),
        py::arg("higher"), py::arg("smooth"), py::arg("slide"), py::arg("fixup"), py::arg("push"));
  m.def("_template_names", [] {
    py::dict d;
    for (const auto& e : templates::template_table()) d[py::str(e.name)] = py::str(e.summary);
    return d;
  });
  m.def(
      "arrange", &arrange, py::arg("spec"), py::arg("smooth") = false, py::arg("slide") = false,
      "Compute the arrangement of a spec's sheets (a dict or a JSON file, the format of `geode "
      "arrange`), "
      "dualize it and return the Template; smooth places the nodes by optimization (box domains).");
  m.def("_study_interleave", &study_interleave, py::arg("spec"), py::arg("sweep"),
        py::arg("progress"));
}

}  // namespace geode::python
