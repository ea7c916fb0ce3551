// geode view MESH -o FILE.html: any hex (or planar quad) mesh as a self-contained HTML viewer
// (viewer/html.hpp) with its sheets: each sheet of the mesh's dual (stc/mesh_dual.hpp) shown
// as the dual surface through its layer of hexes (stc/sheet_surfaces.hpp). Also the helper the
// template (and arrangement) commands use for sheets given as fields.
#include <filesystem>
#include <iostream>
#include <memory>
#include <type_traits>

#include <geode/primal/errors.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/sheet_surfaces.hpp>
#include "cli/commands.hpp"
#include "cli/conventions.hpp"
#include "cli/progress.hpp"

namespace geode::cli {

std::vector<viewer::ViewSheet> arrangement_view_sheets(
    const std::vector<stc::Sheet>& sheets, const stc::Domain& domain,
    const std::vector<std::vector<int>>& element_sheets,
    const std::function<primal::Point(const primal::Point&)>& to_physical) {
  std::vector<viewer::ViewSheet> out(sheets.size());
  for (std::size_t s = 0; s < sheets.size(); ++s)
    out[s].name = sheets[s].name, out[s].kind = sheets[s].kind;
  if (domain.dim == 3) {
    auto surfaces = stc::contour_sheets(sheets, domain);
    for (std::size_t s = 0; s < sheets.size(); ++s) {
      out[s].surface = std::move(surfaces[s]);
      out[s].smooth = true;
      if (to_physical)
        for (auto& p : out[s].surface.points) p = to_physical(p);
    }
  } else {
    auto curves = stc::contour_curves(sheets, domain);
    for (std::size_t s = 0; s < sheets.size(); ++s) {
      out[s].curve = std::move(curves[s]);
      if (to_physical)
        for (auto& p : out[s].curve.points) p = to_physical(p);
    }
  }
  for (std::size_t e = 0; e < element_sheets.size(); ++e)
    for (int s : element_sheets[e])
      if (s >= 0 && primal::index_cast<std::size_t>(s) < out.size())
        out[primal::index_cast<std::size_t>(s)].layer.push_back(primal::index_cast(e));
  return out;
}

namespace {

struct ViewArgs {
  std::string input;
  std::string output;
  std::string title;
  bool quiet = false;
};

// Sheets named as `geode dual` numbers them (0-based, first appearance), so the two agree.
template <class Mesh, class Surfaces>
std::vector<viewer::ViewSheet> mesh_view_sheets(const Mesh& mesh, const Surfaces& make_surfaces,
                                                Progress& progress) {
  const bool hexes = std::is_same_v<Mesh, primal::HexMesh>;
  stc::MeshDualOptions dual_options;
  dual_options.progress = [&progress, what = dual_step(hexes ? 3 : 2)](std::size_t done,
                                                                       std::size_t total) {
    progress.step(what, done, total);
  };
  const auto dual = stc::mesh_dual(mesh, dual_options);
  progress.stage_done("dual: " + std::to_string(dual.sheets.size()) +
                      (hexes ? " sheets" : " chords"));
  stc::DualSurfaceOptions surface_options;
  surface_options.progress =
      [&progress, what = std::string(hexes ? "hexes' sheet quads" : "quads' chord segments")](
          std::size_t done, std::size_t total) { progress.step(what, done, total); };
  auto shapes = make_surfaces(mesh, dual, surface_options);
  const auto layers = stc::sheet_layers(dual);
  progress.stage_done(hexes ? "sheet surfaces" : "chord curves");
  std::vector<viewer::ViewSheet> out(dual.sheets.size());
  for (std::size_t s = 0; s < out.size(); ++s) {
    out[s].name = "sheet " + std::to_string(s);
    out[s].kind = "mesh";
    if constexpr (std::is_same_v<Mesh, primal::HexMesh>)
      out[s].surface = std::move(shapes[s]);
    else
      out[s].curve = std::move(shapes[s]);
    out[s].layer = layers[s];
  }
  return out;
}

void run_view(const ViewArgs& a) {
  check_output_path(a.output);         // before the work, as every command does
  check_not_input(a.output, a.input);  // the page never replaces the mesh it shows
  const std::filesystem::path out(a.output);
  if (file_extension(out) != ".html")
    throw InvalidInput(a.output + ": unknown output format '" + file_extension(out) +
                       "' (expected .html)");
  Progress progress = Progress::for_stderr(a.quiet);
  const MeshFile m = read_mesh_file(a.input);
  progress.stage_done(read_line(a.input, m));
  viewer::ViewScene scene;
  scene.title = a.title.empty() ? std::filesystem::path(a.input).filename().string() : a.title;
  const char* cells = m.dim == 3 ? "hexes" : "quads";
  const std::size_t n = m.dim == 3 ? m.hex.hexes.size() : m.quad.quads.size();
  scene.caption =
      "geode view " + a.input + ": " + std::to_string(n) + " " + cells + "; " +
      (m.dim == 3
           ? "each sheet of the mesh's dual drawn as the quads through the mid-edge points of its "
             "layer"
           : "each chord of the mesh's dual drawn through the mid-edge points of its layer") +
      " (stc::mesh_dual, sheet numbers as in `geode dual`).";
  // A mesh whose dual cannot be read (a face on three hexes, ...) is still worth looking at.
  try {
    const auto surfaces = [](const auto& mesh, const auto& d, const auto& o) {
      return stc::dual_surfaces(mesh, d, o);
    };
    const auto curves = [](const auto& mesh, const auto& d, const auto& o) {
      return stc::dual_curves(mesh, d, o);
    };
    scene.sheets = m.dim == 3 ? mesh_view_sheets(m.hex, surfaces, progress)
                              : mesh_view_sheets(m.quad, curves, progress);
  } catch (const TopologyError& e) {
    std::cerr << "geode: warning: " << a.input << ": no sheets shown: " << e.what() << "\n";
  }
  if (m.dim == 3)
    viewer::write_html(out, m.hex, scene);
  else
    viewer::write_html(out, m.quad, scene);
  progress.stage_done("wrote " + a.output);
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* v = app.add_subcommand(
      "view",
      "Write a hex (or planar quad) mesh as one self-contained HTML file (three.js inlined, "
      "nothing fetched\n"
      "when opened): the hexes with shrink, explode and peeling; every sheet of the mesh's dual as "
      "the\n"
      "surface through its layer of hexes, each with a toggle; each sheet's layer alone or "
      "highlighted;\n"
      "colour by scaled Jacobian; node and hex ids on hover (1-based, as the CSV and appendix "
      "outputs).\n"
      "URL hash parameters (FILE.html#layer=sheet-0&peel=1) select a view; see viewer/viewer.js.");
  v->add_option("mesh", a->input, hex_or_quad_input_help())->required();
  v->add_option("-o,--output", a->output, "The HTML file to write (atomically)")->required();
  v->add_option("--title", a->title, "Title shown in the page (default: the input's file name)");
  add_quiet_flag(v, a->quiet);
  v->callback([a] { run_view(*a); });
}

}  // namespace geode::cli
