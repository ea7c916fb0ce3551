// geode check MESH: is a hex (or planar quad) mesh a valid complex, how good are its elements,
// and which combinatorial obstructions keep any placement of its nodes from positive
// Jacobians (primal/validity.hpp, primal/quality_report.hpp, primal/realizability.hpp); for a
// hybrid mesh, conform's input checks (primal/input_check.hpp).
#include <algorithm>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include <geode/primal/errors.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/model.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/quality_report.hpp>
#include <geode/primal/realizability.hpp>
#include <geode/primal/validity.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/progress.hpp"

namespace geode::cli {
namespace {

using primal::Index;

struct CheckArgs {
  std::string input;
  std::string format;  // empty: by the extension of -o, else text
  std::string output;
  double planar_angle = primal::RealizabilityOptions{}.planar_angle_degrees;
  bool quiet = false;
};

struct Checked {
  bool valid = false;
  std::string validity;  // the report's summary
  bool analysable =
      false;  // every element's nodes in range and distinct: quality and obstructions computed
  nlohmann::json quality;
  std::string quality_text;
  std::vector<primal::Obstruction> obstructions;
  // A hybrid mesh: each finding of conform's input checks (the first kFindingsListed), as the
  // text lists it, and how many there were.
  std::vector<std::string> findings;
  std::size_t finding_count = 0;
};

// "valid" or "invalid" (the report says what fails).
std::string validity_line(bool valid) {
  return std::string("validity: ") + (valid ? "valid" : "invalid");
}

std::string obstructions_line(const std::vector<primal::Obstruction>& o) {
  return "realizability: " + std::to_string(o.size()) + " obstructions";
}

Checked check_hexes(const primal::HexMesh& mesh, const primal::RealizabilityOptions& options,
                    Index base, Progress& progress) {
  Checked c;
  const auto v = primal::check_validity(mesh, [&progress](std::size_t done, std::size_t total) {
    progress.share("of the mesh checked", done, total);
  });
  c.valid = v.ok();
  c.validity = v.summary(base);
  if (c.valid && !mesh.hexes.empty()) {
    // A valid complex of positive hexes may still overlap itself: parts that interpenetrate
    // share no face. The covering check conform makes of its input finds them (a hunt's two
    // interpenetrating hexes were "valid").
    primal::Model model;
    model.points = mesh.points;
    model.hexes = mesh.hexes;
    for (std::size_t n = 0; n < mesh.points.size(); ++n) model.node_ids.push_back(base + Index(n));
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) model.hex_ids.push_back(base + Index(h));
    const primal::InputCheckResult r = primal::check_input(model);
    if (!r.ok()) {
      c.valid = false;
      // The summary's first line said "valid" of the complex.
      if (const auto at = c.validity.find(": valid\n"); at != std::string::npos)
        c.validity.replace(at, 8, ": invalid (it overlaps itself)\n");
      c.validity +=
          "covering: " + std::to_string(r.findings.size()) +
          (r.findings.size() == primal::InputCheckOptions{}.max_findings ? " or more" : "") +
          " findings, the mesh overlaps itself or folds\n";
      for (const primal::InputFinding& f : r.findings) c.validity += "  " + f.text(model) + "\n";
    }
  }
  progress.stage_done(validity_line(c.valid));
  c.analysable =
      v.out_of_range_hexes.empty() && v.repeated_node_hexes.empty() && !mesh.hexes.empty();
  if (!c.analysable) return c;
  auto q = primal::hex_quality_report(mesh, {}, {}, primal::StdDevKind::kSample,
                                      [&progress](std::size_t done, std::size_t total) {
                                        progress.step("quality metrics", done, total);
                                      });
  for (auto& metric : q.metrics) metric.min_hex += base, metric.max_hex += base;
  c.quality = primal::quality_report_json(q);
  c.quality_text = primal::format_quality_table(q);
  progress.stage_done("quality: " + std::to_string(q.metrics.size()) + " metrics");
  primal::RealizabilityOptions shown = options;
  shown.progress = [&progress](std::size_t done, std::size_t total) {
    progress.share("of the realizability search done", done, total);
  };
  c.obstructions = primal::find_obstructions(mesh, shown);
  progress.stage_done(obstructions_line(c.obstructions));
  return c;
}

Checked check_quads(const primal::QuadMesh& mesh, const primal::RealizabilityOptions& options,
                    Index base, Progress& progress) {
  Checked c;
  const auto v = primal::check_validity(mesh);
  c.valid = v.ok();
  c.validity = v.summary(base);
  progress.stage_done(validity_line(c.valid));
  c.analysable =
      v.out_of_range_quads.empty() && v.repeated_node_quads.empty() && !mesh.quads.empty();
  if (!c.analysable) return c;
  double lo = 1e300, hi = -1e300;
  Index at = 0;
  for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
    const double s = primal::quad_scaled_jacobian(primal::quad_corners(mesh, primal::index_cast(q)),
                                                  primal::Point::UnitZ());
    if (s < lo) lo = s, at = primal::index_cast(q);
    hi = std::max(hi, s);
  }
  c.quality = {{"num_quads", mesh.quads.size()},
               {"scaled_jacobian", {{"min", lo}, {"max", hi}, {"min_quad", at + base}}}};
  std::ostringstream s;
  s << "Quad scaled Jacobian: min " << lo << " (quad " << at + base << "), max " << hi << "\n";
  c.quality_text = s.str();
  progress.stage_done("quality: scaled Jacobian");
  c.obstructions = primal::find_obstructions(mesh, options);
  progress.stage_done(obstructions_line(c.obstructions));
  return c;
}

// "hexes", "tets", "pyramids", "wedges".
std::string kind_plural(primal::ElementKind kind) {
  return kind == primal::ElementKind::kHex ? "hexes"
                                           : std::string(primal::element_kind_name(kind)) + "s";
}

constexpr std::size_t kFindingsListed = 1000;  // a mesh broken everywhere: a readable report

// A hybrid mesh (tets, pyramids or wedges, with hexes or not): the checks conform makes when it
// reads one (primal::check_geometry, then the covering check of primal/input_check.hpp), with
// every covering finding listed where conform refuses at the first. Quality and realizability
// are an all-hex mesh's: conform's output.
Checked check_model(const primal::Model& model, const std::string& source, Progress& progress) {
  Checked c;
  std::ostringstream s;
  s << "hybrid mesh: ";
  for (primal::ElementKind kind : primal::kElementKinds)
    s << primal::element_count(model, kind) << " " << kind_plural(kind) << ", ";
  s << model.points.size() << " nodes\n";
  const auto list = [&](const std::vector<std::string>& findings) {
    for (std::size_t i = 0; i < std::min(findings.size(), kFindingsListed); ++i) {
      s << "  " << findings[i] << "\n";
      c.findings.push_back(findings[i]);
    }
    if (findings.size() > kFindingsListed)
      s << "  ... and " << findings.size() - kFindingsListed << " more\n";
  };
  try {
    primal::check_points(model, source);
  } catch (const InvalidInput& e) {  // a non-finite coordinate: nothing else can be measured
    s << "conform's input checks: " << e.what() << "\n";
    c.findings.push_back(e.what());
    c.finding_count = 1;
    c.validity = s.str();
    progress.stage_done(validity_line(c.valid));
    return c;
  }
  // Every element conform's read would refuse (it stops at the first), then the covering
  // check, which measures the elements' corners and so needs them all positive.
  const std::vector<std::string> geometry =
      primal::geometry_findings(model, std::numeric_limits<std::size_t>::max());
  if (!geometry.empty()) {
    s << "conform's input checks: " << geometry.size()
      << " elements or nodes refused (the covering check needs every element positive: not "
         "run)\n";
    list(geometry);
    c.finding_count = geometry.size();
  } else {
    primal::InputCheckOptions every;  // conform's read stops at its first few
    every.max_findings = std::numeric_limits<std::size_t>::max();
    const primal::InputCheckResult r = primal::check_input(model, every);
    c.valid = r.ok();
    s << "conform's input checks: "
      << (r.ok() ? "passed" : std::to_string(r.findings.size()) + " findings") << " ("
      << r.boundary_faces << " boundary faces)\n";
    std::vector<std::string> texts;
    for (std::size_t i = 0; i < std::min(r.findings.size(), kFindingsListed); ++i)
      texts.push_back(r.findings[i].text(model));
    list(texts);
    c.finding_count = r.findings.size();
    if (r.findings.size() > kFindingsListed)
      s << "  ... and " << r.findings.size() - kFindingsListed << " more\n";
  }
  c.validity = s.str();
  progress.stage_done(validity_line(c.valid));
  return c;
}

void run_check(const CheckArgs& a) {
  check_output_path(a.output);
  const std::string format = output_format(a.output, a.format, {"text", "json"}, "text");
  check_not_input(a.output, a.input);  // a report never replaces the mesh it is about
  Progress progress = Progress::for_stderr(a.quiet);
  const MeshFile m = read_mesh_file(a.input, /*other_cells=*/true);
  progress.stage_done(m.model ? "read " + a.input + ": " +
                                    std::to_string(primal::element_count(*m.model)) + " elements"
                              : read_line(a.input, m));
  primal::RealizabilityOptions options;
  options.planar_angle_degrees = a.planar_angle;
  const Index base = m.index_base;
  Checked c = m.model      ? check_model(*m.model, a.input, progress)
              : m.dim == 3 ? check_hexes(m.hex, options, base, progress)
                           : check_quads(m.quad, options, base, progress);
  std::string text;
  if (format == "json") {
    nlohmann::json j;
    j["file"] = a.input;
    j["dimension"] = m.dim;
    j["index_base"] = base;
    if (m.model)
      for (primal::ElementKind kind : primal::kElementKinds)
        j["elements"][kind_plural(kind)] = primal::element_count(*m.model, kind);
    j["valid"] = c.valid;
    j["validity"] = c.validity;
    if (m.model) {  // conform's input checks: the findings listed, and how many there were
      j["findings"] = c.findings;
      j["finding_count"] = c.finding_count;
    }
    j["quality"] = c.analysable ? c.quality : nlohmann::json();
    j["obstructions"] =
        c.analysable ? primal::obstructions_json(c.obstructions, base) : nlohmann::json();
    text = json_text(j, 1);
  } else {
    std::ostringstream s;
    s << a.input << " (" << (m.dim == 3 ? "elements" : "quads") << " and nodes numbered from "
      << base << ")\n"
      << c.validity;
    if (m.model) {
      s << "quality and realizability not checked: they are an all-hex mesh's (geode conform "
           "makes one)\n";
    } else if (c.analysable) {
      s << "\n"
        << c.quality_text << "\nrealizability: "
        << primal::format_obstructions(c.obstructions, m.dim, base, static_cast<std::size_t>(-1));
    } else {
      s << "\nquality and realizability not checked: some elements have out-of-range or repeated "
           "nodes\n";
    }
    text = s.str();
  }
  write_or_print(a.output, [&](std::ostream& os) { os << text; });
}

}  // namespace

void add_check_command(CLI::App& app) {
  auto a = std::make_shared<CheckArgs>();
  CLI::App* c = app.add_subcommand(
      "check",
      "Check a hex (or planar quad) mesh: its validity as a complex (faces shared by two hexes, "
      "manifold\n"
      "edges and vertices, closed boundary, Euler characteristic, positive corner Jacobians), its "
      "quality\n"
      "(the paper's Table 1 metrics), and the combinatorial obstructions to any positive-Jacobian\n"
      "embedding with its planar boundary faces kept planar: doublets, pinched corners, a hex with "
      "two\n"
      "faces on one planar boundary face, flat corners, two-quad boundary nodes "
      "(primal/realizability.hpp\n"
      "says why each blocks). A hybrid mesh (tets, pyramids, wedges) gets the checks conform makes "
      "when\n"
      "it reads one (positive elements, one covering of one domain: folds, overlaps, gaps), every "
      "finding\n"
      "listed. Exit 0 whenever the file could be checked.");
  c->add_option("mesh", a->input,
                hex_or_quad_input_help() + ", or a hybrid mesh (tets, pyramids, wedges, hexes)")
      ->required();
  c->add_option("--format", a->format,
                "text (default), or json: {\"valid\", \"validity\", \"quality\", "
                "\"obstructions\": [{\"kind\", \"hexes\", \"nodes\"}]}\n"
                "with ids as the file numbers them (\"index_base\"); a hybrid mesh: \"elements\" "
                "per kind,\nquality and obstructions null. Without it the extension of -o decides "
                "(.txt, .json);\none that contradicts the extension is refused")
      ->check(CLI::IsMember({"text", "json"}));
  c->add_option("-o,--output", a->output, "Write the report here instead of standard output");
  c->add_option("--planar-angle", a->planar_angle,
                "boundary quads whose normals differ by less than this many degrees (and that lie "
                "in one plane)\n"
                "form one planar boundary face")
      ->check(number_check(0.0, 90.0))
      ->capture_default_str();
  add_quiet_flag(c, a->quiet);
  c->callback([a] { run_check(*a); });
}

}  // namespace geode::cli
