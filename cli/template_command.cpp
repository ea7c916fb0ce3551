// geode template NAME: derive a transition template from its sheet arrangement and print or
// write it.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include <geode/io/formats.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/templates/fixup.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/pyramid.hpp>
#include <geode/templates/refine.hpp>
#include <geode/templates/spec.hpp>
#include <geode/templates/template_table.hpp>
#include <geode/viewer/html.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"

namespace geode::cli {
namespace {

struct TemplateArgs {
  std::string name;
  std::string box;  // empty: 24x14x24 (24x14 in 2D)
  std::string diagonal = "main";
  std::string higher = "x";
  std::string format;     // empty: by the extension of -o, else appendix
  EncodingArgs encoding;  // --vtk-encoding, --msh-encoding
  std::string output;
  bool slide = false;
  bool no_smooth = false;
  bool no_fixup = false;
  bool quality = false;
  bool write_invalid = false;
  templates::PushParameters push;
  templates::RefineOptions refine;
  bool refine_roofs = false;  // --high-roof / --low-roof given: they apply to refine3 too
};

// The paper's Table 2 layout: three column groups of "Node x y z", 1-based.
std::string appendix_nodes(const std::vector<primal::Point>& pts, int dim) {
  std::ostringstream s;
  const std::size_t n = pts.size(), rows = (n + 2) / 3;
  s << "Table 2: Node positions (" << n << " nodes)\n";
  for (int g = 0; g < 3; ++g) s << (g ? "\t" : "") << (dim == 3 ? "Node\tx\ty\tz" : "Node\tx\ty");
  s << "\n" << std::fixed << std::setprecision(1);
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t g = 0; g < 3; ++g) {
      const std::size_t i = g * rows + r;
      if (i >= n) break;
      s << (g ? "\t" : "") << i + 1 << "\t" << pts[i].x() << "\t" << pts[i].y();
      if (dim == 3) s << "\t" << pts[i].z();
    }
    s << "\n";
  }
  return s.str();
}

// The paper's Table 3 layout: two column groups of "Hex n1 .. n8", 1-based.
template <class Cells>
std::string appendix_cells(const Cells& cells, const char* what) {
  std::ostringstream s;
  const std::size_t n = cells.size(), rows = (n + 1) / 2, k = cells.empty() ? 0 : cells[0].size();
  s << "Table 3: Connectivity (" << n << " " << what << ")\n";
  for (int g = 0; g < 2; ++g) {
    s << (g ? "\t" : "") << (k == 8 ? "Hex" : "Quad");
    for (std::size_t c = 0; c < k; ++c) s << "\tn" << c + 1;
  }
  s << "\n";
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t g = 0; g < 2; ++g) {
      const std::size_t i = g * rows + r;
      if (i >= n) break;
      s << (g ? "\t" : "") << i + 1;
      for (auto v : cells[i]) s << "\t" << v + 1;
    }
    s << "\n";
  }
  return s.str();
}

template <class Cells>
std::string csv_tables(const std::vector<primal::Point>& pts, const Cells& cells, int dim) {
  std::ostringstream s;
  s << std::setprecision(17) << (dim == 3 ? "node,x,y,z\n" : "node,x,y\n");
  for (std::size_t i = 0; i < pts.size(); ++i) {
    s << i + 1 << "," << pts[i].x() << "," << pts[i].y();
    if (dim == 3) s << "," << pts[i].z();
    s << "\n";
  }
  s << "\n" << (dim == 3 ? "hex" : "quad");
  for (std::size_t c = 0; c < (dim == 3 ? 8u : 4u); ++c) s << ",n" << c + 1;
  s << "\n";
  for (std::size_t i = 0; i < cells.size(); ++i) {
    s << i + 1;
    for (auto v : cells[i]) s << "," << v + 1;
    s << "\n";
  }
  return s.str();
}

nlohmann::json to_json(const templates::Template& T, const std::string& name) {
  nlohmann::json j;
  j["template"] = name;
  j["index_base"] = 1;
  const auto& pts = T.dim == 3 ? T.hex.points : T.quad.points;
  for (const auto& p : pts)
    j["nodes"].push_back(T.dim == 3 ? nlohmann::json{p.x(), p.y(), p.z()}
                                    : nlohmann::json{p.x(), p.y()});
  auto cells = nlohmann::json::array();
  if (T.dim == 3)
    for (const auto& h : T.hex.hexes) {
      nlohmann::json c;
      for (auto v : h) c.push_back(v + 1);
      cells.push_back(c);
    }
  else
    for (const auto& q : T.quad.quads) {
      nlohmann::json c;
      for (auto v : q) c.push_back(v + 1);
      cells.push_back(c);
    }
  j[T.dim == 3 ? "hexes" : "quads"] = cells;
  for (const auto& s : T.sheets) j["sheets"].push_back({{"name", s.name}, {"kind", s.kind}});
  std::map<std::vector<int>, int> table;
  for (std::size_t e = 0; e < T.element_sheets.size(); ++e) {
    j["element_sheets"].push_back(T.element_sheets[e]);
    ++table[T.element_sheets[e]];
  }
  for (const auto& [sheets, count] : table) {
    nlohmann::json names;
    for (int s : sheets) names.push_back(T.sheets[primal::index_cast<std::size_t>(s)].name);
    j["intersections"].push_back({{"sheets", names}, {"elements", count}});
  }
  j["obstructions"] = primal::obstructions_json(templates::template_obstructions(T), 1);
  if (name.rfind("refine", 0) == 0) return j;  // the paper's conditions are about domes
  j["checks"] = {{"triple_domes_in_pocket", T.checks.triple_domes_in_pocket},
                 {"dome_curves_exit_in_tunnels", T.checks.dome_curves_exit_in_tunnels},
                 {"failures", T.checks.failures}};
  return j;
}

// The template with its arrangement's sheets contoured from their fields in the domain and
// mapped as the nodes are (Figure 7 of the paper), each sheet's layer of hexes, and the tet and
// hex sides as face groups (Figure 1, left).
void write_template_html(const TemplateOutput& a, const templates::Template& T,
                         const std::string& smooth_note) {
  viewer::ViewScene scene;
  scene.title = "geode template " + a.name;
  scene.caption =
      (a.caption.empty() ? a.name + ", " + a.title : a.caption) + ": " +
      std::to_string(T.dim == 3 ? T.hex.hexes.size() : T.quad.quads.size()) +
      (T.dim == 3 ? " hexes" : " quads") +
      (smooth_note.empty() ? ", not smoothed" : ", " + smooth_note) +
      ". Sheets: the arrangement's fields contoured in the cell (marching tetrahedra), mapped "
      "like the nodes; the smoothed hexes need not follow them. Layers: the hexes dual to each "
      "sheet.";
  scene.sheets = arrangement_view_sheets(a.sheets, a.domain, T.element_sheets, a.to_physical);
  if (T.dim == 2) {
    viewer::write_html(a.output, T.quad, scene);
    return;
  }
  scene.groups = {
      viewer::boundary_face_group("tet side", T.hex, T.node_faces, stc::box_face(1, true)),
      viewer::boundary_face_group("hex side", T.hex, T.node_faces, stc::box_face(1, false))};
  viewer::write_html(a.output, T.hex, scene);
}

const std::vector<std::string> kTemplateFormats =
    with_mesh_formats({"appendix", "csv", "json"}, {"spec", "html"});

void run_template(const TemplateArgs& a) {
  // Refuse a bad output before the derivation, not after it.
  check_output_path(a.output);
  const std::string format = output_format(a.output, a.format, kTemplateFormats, "appendix");
  const templates::TemplateEntry* entry = templates::find_template(a.name);
  if (!entry) throw InvalidInput("template: unknown template '" + a.name + "'");
  const int dim = entry->dim;
  if (dim == 2 && is_mesh_format(format) && !io::find_mesh_format(format)->write_quads)
    throw InvalidInput(a.output + ": " + a.name + " is a quad mesh; write it as " +
                       quad_output_extensions());
  const std::string box_text = a.box.empty() ? (dim == 3 ? "24x14x24" : "24x14") : a.box;
  const auto box = parse_box("--box", box_text, dim);
  templates::GeodeOptions o;
  o.box = Eigen::Vector3d(box[0], box[1], box[2]);
  o.diagonal = a.diagonal == "anti" ? templates::Diagonal::kAnti : templates::Diagonal::kMain;
  o.higher = a.higher == "z" ? templates::Higher::kZ : templates::Higher::kX;
  o.push = a.push;
  // Named by the option that sets it (the library names its field: "geode: tunnel roofs ...").
  if (std::string key; !templates::push_error(a.push, &key).empty()) {
    std::string option = "--" + key.substr(0, key.find('['));
    std::replace(option.begin(), option.end(), '_', '-');
    if (key == "low_roof") option = "--low-roof / --high-roof";
    throw InvalidInput(option + ": " + templates::push_error(a.push));
  }
  const bool refine = entry->family == templates::TemplateFamily::kRefine;
  templates::RefineOptions ro = a.refine;
  ro.box = o.box;
  if (a.refine_roofs) ro.high_roof = a.push.high_roof, ro.low_roof = a.push.low_roof;
  const templates::TemplateOptions options = templates::template_options(*entry, o, ro);
  o = options.geode;  // with the entry's split
  if (format == "spec") {
    const auto spec = entry->spec(options);
    const std::string text = templates::format_spec(templates::spec_json(spec));
    write_or_print(a.output, [&](std::ostream& os) { os << text; });
    return;
  }
  TemplateOutput out;
  out.name = a.name, out.title = "box " + box_text, out.format = format, out.output = a.output;
  out.encoding = a.encoding;
  out.smooth = !a.no_smooth, out.slide = a.slide, out.quality = a.quality;
  out.write_invalid = a.write_invalid;
  templates::Template T = entry->build(options);
  out.check_conditions = entry->interleave_conditions;
  if (entry->smooth)
    out.smoother = [entry, options, slide = a.slide](templates::Template& t) {
      return entry->smooth(t, options, slide);
    };
  if (refine) {
    if (format == "html") {
      // The refinement's spec is in the box already.
      const templates::ArrangementSpec spec = entry->spec(options);
      out.sheets = templates::spec_sheets(spec), out.domain = spec.domain;
    }
  } else {
    if (format == "html") {
      const templates::GeodeArrangement G = templates::geode_arrangement(o, dim);
      out.sheets = G.sheets, out.domain = G.domain;
    }
    // The geode's arrangement is built in the reference cell; the nodes are mapped to the box.
    out.to_physical = [box = o.box, dim](const primal::Point& r) {
      return templates::box_point(r, box, dim);
    };
  }
  std::ostringstream cmd;
  cmd << "geode template " << a.name << " --box " << box_text;
  if (!refine)
    cmd << " --diagonal " << a.diagonal << " --higher " << a.higher << " --high-roof "
        << o.push.high_roof << " --low-roof " << o.push.low_roof << " --dome-depth "
        << o.push.dome_depth << " --dome-radius " << o.push.dome_radius;
  // The wider dome family, where it differs from the defaults.
  const templates::PushParameters plain;
  if (!refine) {
    if (o.push.centre_depth != plain.centre_depth) cmd << " --centre-depth " << o.push.centre_depth;
    if (o.push.centre_radius != plain.centre_radius)
      cmd << " --centre-radius " << o.push.centre_radius;
    if (o.push.dome_exponent != plain.dome_exponent)
      cmd << " --dome-exponent " << o.push.dome_exponent;
    if (o.push.centre_exponent != plain.centre_exponent)
      cmd << " --centre-exponent " << o.push.centre_exponent;
    if (o.push.dome_offset != plain.dome_offset) cmd << " --dome-offset " << o.push.dome_offset;
    if (o.push.centre_offset != plain.centre_offset)
      cmd << " --centre-offset " << o.push.centre_offset[0] << " " << o.push.centre_offset[1];
  }
  if (a.slide) cmd << " --slide";
  out.caption = cmd.str();
  if (entry->fix_up && !a.no_fixup) {
    const auto f = templates::fix_up(T);
    std::ostringstream s;
    s << "fix-up: " << f.obstructions_before << " -> " << f.obstructions_after << " obstructions, "
      << T.hex.hexes.size() << " hexes";
    for (const auto& step : f.steps) s << "; " << step;
    out.note = s.str();
    if (f.obstructions_after > 0)
      std::cerr << "geode: warning: fix-up left " << f.obstructions_after << " obstructions\n";
  }
  write_template(T, out);
}

}  // namespace

void write_template(templates::Template& T, const TemplateOutput& a) {
  if (a.check_conditions && !T.checks.ok()) {
    std::string why;
    for (const auto& f : T.checks.failures) why += (why.empty() ? "" : "; ") + f;
    std::cerr << "geode: warning: the interleave fails the paper's conditions: " << why << "\n";
  }
  std::string smooth_note = a.note;
  if (a.smooth) {
    const auto r = a.smoother ? a.smoother(T) : templates::smooth_template(T, a.slide);
    std::ostringstream s;
    s << "smoothing ("
      << (a.smoother ? (a.slide ? "side nodes slide" : "side faces fixed at the 2D template")
                     : (a.slide ? "tet/hex-side nodes slide" : "tet/hex-side nodes fixed"))
      << "): min scaled Jacobian " << r.initial_min_scaled_jacobian << " -> "
      << r.final_min_scaled_jacobian << " in " << r.iterations << " iterations, " << r.seconds
      << " s";
    smooth_note += (smooth_note.empty() ? "" : "; ") + s.str();
    // Say whether the mesh itself forbids an untangled embedding, rather than blame the smoother
    // (or trust positive Jacobians around a pinched corner, where the cells overlap).
    const auto obstructions = templates::template_obstructions(T);
    if (!r.untangled)
      std::cerr << "geode: warning: smoothing could not untangle every element; "
                << (obstructions.empty()
                        ? "no combinatorial obstruction found (primal/realizability.hpp)\n"
                        : "no placement can: " +
                              primal::format_obstructions(obstructions, T.dim, 1));
    if (!r.untangled && !obstructions.empty() && !a.obstruction_hint.empty())
      std::cerr << "geode: " << a.obstruction_hint << "\n";
    else if (!obstructions.empty())
      // The smoother's corners may all be positive while the cells overlap (a pinched corner),
      // or the validity check below may still find a corner at or below 0: the obstruction
      // is what holds either way.
      std::cerr << "geode: warning: the connectivity admits no valid placement (the cells "
                   "overlap or fold somewhere): "
                << primal::format_obstructions(obstructions, T.dim, 1);
  }
  const int dim = T.dim;
  // The one validity check before anything holding the mesh is written: tables, JSON, the
  // viewer and the mesh formats alike (the quality tables alone describe it, they are not it).
  const std::string what =
      a.name + " (" + a.title + "): the " + (dim == 3 ? "hex" : "quad") + " mesh";
  const primal::Index base = output_index_base(a.format);
  const std::string invalid =
      dim == 3 ? invalid_mesh_reason(T.hex, base) : invalid_mesh_reason(T.quad, base);
  refuse_invalid(what, invalid, a.write_invalid);
  const auto& pts = dim == 3 ? T.hex.points : T.quad.points;
  std::string text;
  if (a.format == "appendix") {
    text = "# geode template " + a.name + ", " + a.title +
           (smooth_note.empty() ? "" : "; " + smooth_note) + "\n";
    text += appendix_nodes(pts, dim) + "\n";
    text += dim == 3 ? appendix_cells(T.hex.hexes, "hexes") : appendix_cells(T.quad.quads, "quads");
  } else if (a.format == "csv") {
    text = dim == 3 ? csv_tables(pts, T.hex.hexes, 3) : csv_tables(pts, T.quad.quads, 2);
  } else if (a.format == "json") {
    text = json_text(to_json(T, a.name), 1);
  }
  if (a.quality && dim == 3)
    text +=
        "\nQuality report (Verdict definitions, but Element Volume is the exact trilinear "
        "volume)\n" +
        primal::format_quality_table(primal::hex_quality_report(T.hex));
  if (a.quality && dim == 2) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t q = 0; q < T.quad.quads.size(); ++q) {
      const double v = primal::quad_scaled_jacobian(
          primal::quad_corners(T.quad, primal::index_cast(q)), primal::Point::UnitZ());
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    std::ostringstream s;
    s << "\nQuad scaled Jacobian: min " << lo << ", max " << hi << "\n";
    text += s.str();
  }
  if (a.format == "html") {
    if (a.output.empty()) throw InvalidInput("--format html needs -o FILE.html");
    if (!text.empty()) std::cout << text;  // first: nothing is written if it was lost
    require_standard_output();
    write_template_html(a, T, smooth_note);
    invalid_written(what, invalid);
    return;
  }
  if (is_mesh_format(a.format)) {
    // The mesh goes to the file (the writers add the scaled Jacobian cell array); the quality
    // tables, if asked for, to standard output.
    if (a.output.empty()) throw InvalidInput("--format " + a.format + " needs -o FILE");
    const io::WriteOptions options = write_options(a.encoding);
    if (!text.empty()) std::cout << text;  // first: nothing is written if it was lost
    require_standard_output();
    if (dim == 2) {
      io::write_quad_mesh(T.quad, a.output, a.format, options);  // refuses formats without quads
    } else {
      primal::Model m;
      m.points = T.hex.points;
      m.hexes = T.hex.hexes;
      io::write_model(m, a.output, a.format, options);
    }
    invalid_written(what, invalid);
    return;
  }
  write_or_print(a.output, [&](std::ostream& os) { os << text; });
  invalid_written(what, invalid);
}

void add_template_command(CLI::App& app) {
  auto args = std::make_shared<TemplateArgs>();
  CLI::App* t = app.add_subcommand(
      "template",
      "Derive a transition template from its completed, pushed-together sheet arrangement (no\n"
      "connectivity is typed in) and print or write it. Tet- and hex-side nodes sit where dicing\n"
      "puts them; the rest are placed by optimization unless --no-smooth. A mesh that fails the "
      "validity\n"
      "check (inverted or overlapping cells) exits 4 and nothing is written (see "
      "--write-invalid).");
  t->add_option("NAME", args->name,
                templates::template_help() + " (the template table, templates/template_table.hpp)")
      ->required()
      ->check(CLI::IsMember(templates::template_names()));
  t->add_option(
      "--box", args->box,
      "buffer cell WIDTHxHEIGHTxDEPTH (x, y up, z; WIDTHxHEIGHT for the 2D templates), centred at\n"
      "the origin, tet side on top; each in [1e-6, 1e6], at most 1e4 between largest and smallest\n"
      "(default 24x14x24)");
  t->add_option("--diagonal", args->diagonal,
                "main: the top diagonal joins (-x,+z) and (+x,-z) as in the paper's Appendix A; "
                "anti: the other one")
      ->check(CLI::IsMember({"main", "anti"}))
      ->capture_default_str();
  t->add_option("--higher", args->higher,
                "which tunnel's roof is higher where they cross: the one along x or along z")
      ->check(CLI::IsMember({"x", "z"}))
      ->capture_default_str();
  t->add_option(
       "--format", args->format,
       "appendix (default): the paper's Tables 2 and 3 (1-based); csv: node and element tables;\n"
       "json: with sheets, their intersections and the interleave checks; " +
           mesh_formats_help() + ":\nthe mesh (needs -o; 2D templates: " + mesh_formats_help(true) +
           "); spec: the template as an\narrangement spec for `geode arrange` (nothing is "
           "derived); html: a "
           "self-contained viewer of\nthe hexes, the arrangement's sheets and their layers (needs "
           "-o). "
           "Without it, the extension\nof -o decides (.txt .csv .json " +
           io::extension_list(io::FormatRole::kWrite, " ", " ") +
           " .html); one that contradicts the extension is refused")
      ->check(CLI::IsMember(kTemplateFormats));
  add_encoding_options(t, args->encoding);
  t->add_option(
      "-o,--output", args->output,
      "write to FILE (atomically) instead of standard output; its extension picks the format");
  t->add_flag("--slide", args->slide,
              "let tet- and hex-side nodes slide within their faces while smoothing; refine3: let "
              "the side\n"
              "faces' nodes slide instead of fixing them at the smoothed 2D template (neighbours "
              "then need\n"
              "not match)");
  t->add_flag("--no-smooth", args->no_smooth, "keep the dual's first-guess positions");
  t->add_flag(
      "--no-fixup", args->no_fixup,
      "geode4tri: the plain dual of the arrangement, without pillowing away the obstructions to a\n"
      "positive-Jacobian placement (its pinched corners cannot be untangled)");
  t->add_flag("--quality", args->quality,
              "append the quality report (the paper's Table 1 metrics)");
  add_write_invalid_flag(t, args->write_invalid);
  // Every push parameter (and refine3's layer): a number with its default shown.
  auto number_option = [t](const std::string& name, double& value, const std::string& help) {
    t->add_option(name, value, help)->check(number_check())->capture_default_str();
  };
  number_option("--high-roof", args->push.high_roof,
                "push: higher tunnel roof, fraction of the height (refine3: the tunnel along x; "
                "default 0.75 there)");
  number_option("--low-roof", args->push.low_roof,
                "push: lower tunnel roof, fraction of the height (refine3: the tunnel along z; "
                "default 0.6 there)");
  number_option("--centre-depth", args->push.centre_depth,
                "push, geode4tri: depth of the centre vertex's dome (0: --dome-depth)");
  number_option("--centre-radius", args->push.centre_radius,
                "push, geode4tri: radius blend of the centre vertex's dome (0: --dome-radius)");
  number_option("--dome-exponent", args->push.dome_exponent,
                "push: superquadric exponent p of the domes (|x|^p + |y|^p + |z|^p level sets; 2: "
                "spheroids)");
  number_option("--centre-exponent", args->push.centre_exponent,
                "push, geode4tri: exponent of the centre vertex's dome (0: --dome-exponent)");
  number_option("--dome-offset", args->push.dome_offset,
                "push: move each corner dome's centre along the tet side toward its centre, "
                "fraction of the way");
  t->add_option(
       "--centre-offset", args->push.centre_offset,
       "push, geode4tri: move the centre vertex's dome by X Z, fractions of the half-width")
      ->check(number_check());
  number_option("--layer", args->refine.layer,
                "refine3: height of the horizontal layer sheet, below both roofs");
  number_option("--dome-depth", args->push.dome_depth,
                "push: how far below the tet side the domes reach, fraction of the height");
  number_option(
      "--dome-radius", args->push.dome_radius,
      "push: where each dome's circle crosses the diced tet side, 0..1 between the nodes it\n"
      "must enclose and the nearest it must leave out");
  t->callback([args, t] {
    args->refine_roofs = t->count("--high-roof") + t->count("--low-roof") > 0;
    run_template(*args);
  });
}

}  // namespace geode::cli
