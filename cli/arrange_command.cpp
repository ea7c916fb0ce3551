// geode arrange SPEC.json: an arrangement given as a file (templates/spec.hpp) -> arrangement
// -> diagnoses -> dual mesh -> optional smoothing -> the template command's outputs.
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include <geode/primal/errors.hpp>
#include <geode/templates/fixup.hpp>
#include <geode/templates/geode.hpp>
#include <geode/templates/spec.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/progress.hpp"

namespace geode::cli {
namespace {

struct ArrangeArgs {
  std::string spec;
  std::string output;
  std::string format;     // empty: by the extension of -o, else appendix
  EncodingArgs encoding;  // --vtk-encoding, --msh-encoding
  bool smooth = false;
  bool fixup = false;
  int seed_resolution = stc::ArrangementOptions{}.seed_resolution;
  bool slide = false;
  bool quality = false;
  bool write_invalid = false;
  bool force = false;
};

void run_arrange(const ArrangeArgs& a) {
  check_output_path(a.output);
  const std::string format = output_format(
      a.output, a.format, with_mesh_formats({"appendix", "csv", "json"}, {"html"}), "appendix");
  check_not_input(a.output, a.spec, a.force);
  const templates::ArrangementSpec spec = templates::read_spec(a.spec);
  if (a.fixup && spec.dim != 3)
    throw InvalidInput(a.spec + ": --fixup: only 3D templates are fixed up (this spec is 2D)");
  // The smoother's constraints keep nodes on axis-aligned box faces.
  if (a.smooth && spec.domain.corners)
    throw InvalidInput(a.spec + ": --smooth needs a box domain (this spec's domain is a " +
                       (spec.domain.is_pyramid ? "pyramid)"
                        : spec.dim == 3        ? "hexahedron)"
                                               : "quadrilateral)"));
  // Many sheets take the engine a while (it meets every pair): progress after 2 s. Its
  // diagnoses name sheets and places; the file is named here.
  Progress progress = Progress::for_stderr(false);
  stc::ArrangementOptions options;
  options.seed_resolution = a.seed_resolution;
  options.progress = [&progress,
                      what = std::string(spec.dim == 3 ? "sheet pairs traced" : "sheets traced")](
                         std::size_t done, std::size_t total) { progress.step(what, done, total); };
  templates::Template t;
  try {
    t = templates::build_template(spec, options);
  } catch (const TopologyError& e) {
    throw TopologyError(a.spec + ": " + e.what());
  } catch (const InvalidInput& e) {
    throw InvalidInput(a.spec + ": " + e.what());
  }
  const std::string name = std::filesystem::path(a.spec).stem().string();
  TemplateOutput out;
  if (a.fixup) {  // as `geode template geode4tri` does (templates/fixup.hpp)
    const auto f = templates::fix_up(t);
    std::ostringstream note;
    note << "fix-up: " << f.obstructions_before << " -> " << f.obstructions_after
         << " obstructions, " << t.hex.hexes.size() << " hexes";
    for (const auto& step : f.steps) note << "; " << step;
    out.note = note.str();
    if (f.obstructions_after > 0)
      std::cerr << "geode: warning: fix-up left " << f.obstructions_after << " obstructions\n";
  }
  out.name = name, out.title = "spec " + std::filesystem::path(a.spec).filename().string();
  out.format = format, out.output = a.output, out.smooth = a.smooth, out.slide = a.slide,
  out.quality = a.quality;
  out.write_invalid = a.write_invalid;
  if (!a.fixup)
    out.obstruction_hint = "--fixup pillows the obstructions away (templates/fixup.hpp)";
  out.encoding = a.encoding;
  if (format == "html") out.sheets = templates::spec_sheets(spec), out.domain = spec.domain;
  out.caption = "geode arrange " + a.spec + (a.fixup ? " --fixup" : "") +
                (a.smooth ? " --smooth" : "") + (a.slide ? " --slide" : "");
  write_template(t, out);
}

}  // namespace

void add_arrange_command(CLI::App& app) {
  auto args = std::make_shared<ArrangeArgs>();
  CLI::App* c = app.add_subcommand(
      "arrange",
      "Compute the arrangement of the sheets a JSON spec gives (domain, sheets, optional "
      "completion\n"
      "block and push; format in docs/specs.md), diagnose it, dualize it and\n"
      "print or write the mesh. Exit 2 for a bad spec (naming the JSON path), 3 when the\n"
      "arrangement does not dualize (naming the sheets and the place), 4 when the mesh is invalid\n"
      "(inverted or overlapping cells: nothing written unless --write-invalid).");
  c->add_option("SPEC", args->spec, "the spec, a JSON file")->required();
  c->add_option("--format", args->format,
                "appendix: node and element tables (1-based); csv; json: with sheets, their\n"
                "intersections and the interleave checks; " +
                    mesh_formats_help() +
                    ":\nthe mesh (needs -o); html: a self-contained viewer of the mesh, the sheets "
                    "and their\n"
                    "layers (needs -o)")
      ->check(CLI::IsMember(with_mesh_formats({"appendix", "csv", "json"}, {"html"})));
  c->add_option("-o,--output", args->output,
                "write to FILE (atomically) instead of standard output");
  c->add_flag(
      "--smooth", args->smooth,
      "place the nodes by optimization (untangle, then maximise the minimum scaled Jacobian);\n"
      "without it, nodes sit at the dual's first guess (diced positions on a completion's faces)");
  auto* smooth_flag = c->get_option("--smooth");
  c->add_flag("--slide", args->slide,
              "with --smooth: tet- and hex-side nodes slide within their faces")
      ->needs(smooth_flag);
  c->add_flag(
      "--fixup", args->fixup,
      "3D specs: pillow away the obstructions to a positive-Jacobian placement (pinched\n"
      "corners, as `geode template geode4tri` does; docs/results.md) before placing the\n"
      "nodes: the boundary's quads are kept, the dual is no longer the arrangement's alone");
  c->add_option(
       "--seed-resolution", args->seed_resolution,
       "cells of the grid that seeds the tracing of the sheets' intersections, along the\n"
       "domain's longest axis: raise it where a diagnosis says a piece smaller than the\n"
       "grid was missed (every value that finds every piece gives the same mesh, its node\n"
       "positions to rounding)")
      ->check(CLI::Range(4, 400))
      ->capture_default_str();
  c->add_flag("--quality", args->quality,
              "append the quality report (the paper's Table 1 metrics)");
  add_encoding_options(c, args->encoding);
  add_write_invalid_flag(c, args->write_invalid);
  add_force_flag(c, args->force);
  c->callback([args] { run_arrange(*args); });
}

}  // namespace geode::cli
