#pragma once
// Sub-commands of the `geode` command line; each file registers its own. A new command follows
// cli/conventions.hpp (exit codes, number_check / parse_box for numbers, output_format +
// check_output_path before any work, OutputFiles for outputs written as one, io::write_model
// for every mesh format) and reports long work through cli/progress.hpp.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <geode/primal/model.hpp>
#include <geode/primal/smooth.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/sheet.hpp>
#include <geode/viewer/html.hpp>

#include "cli/conventions.hpp"

namespace geode::templates {
struct Template;
}

namespace geode::cli {

void add_template_command(CLI::App& app);  // cli/template_command.cpp
void add_study_commands(CLI::App& app);    // cli/study_command.cpp
void add_conform_commands(CLI::App& app);  // cli/conform_command.cpp: conform, demo
void add_dual_command(CLI::App& app);      // cli/dual_command.cpp
void add_check_command(CLI::App& app);     // cli/check_command.cpp
void add_arrange_command(CLI::App& app);   // cli/arrange_command.cpp
void add_view_command(CLI::App& app);      // cli/view_command.cpp
void add_formats_command(CLI::App& app);   // cli/formats_command.cpp

// Shared by the commands (cli/files.cpp): the extension in lower case (".msh"), and a model
// read by extension and checked content (io/read_model.hpp, any format of io/formats.hpp);
// InvalidInput naming the file when it is missing or of another format.
std::string file_extension(const std::filesystem::path& p);
primal::Model read_model(const std::filesystem::path& path);
// An all-hex mesh, or a planar quad mesh in z = 0 (formats with PlainReader only), read by
// extension (io::read_plain_mesh); InvalidInput naming the file otherwise (tets included).
// index_base is how the file numbers its nodes and elements (io::MeshFormat::index_base: 0 for
// VTK, 1 for Gmsh and Exodus).
struct MeshFile {
  int dim = 3;
  primal::HexMesh hex;
  primal::QuadMesh quad;
  primal::Index index_base = 0;
  std::optional<primal::Model> model;  // with other_cells: a hybrid mesh (io::PlainMesh::model)
};
MeshFile read_mesh_file(const std::filesystem::path& path, bool other_cells = false);
// The progress line of a mesh read: "read PATH: N hexes, M nodes" (quads in 2D).
std::string read_line(const std::string& path, const MeshFile& m);
// What the progress of stc::mesh_dual counts (MeshDualOptions::progress): "hex visits of the
// dual" (quad in 2D), each cell visited stc::kMeshDualPasses times.
std::string dual_step(int dim);

// The sheets of a computed arrangement for the HTML viewer (cli/view_command.cpp): each sheet
// contoured from its field inside the domain (stc/sheet_surfaces.hpp), its points mapped by
// `to_physical` (identity when empty), and its layer read off the dual's element_sheets.
std::vector<viewer::ViewSheet> arrangement_view_sheets(
    const std::vector<stc::Sheet>& sheets, const stc::Domain& domain,
    const std::vector<std::vector<int>>& element_sheets,
    const std::function<primal::Point(const primal::Point&)>& to_physical);

// Standard output when `path` is empty or "-", else the file, written atomically.
void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write);

// A derived template's output, shared by `template` and `arrange` (cli/template_command.cpp):
// warns when the paper's interleave conditions fail, smooths, then writes `format`
// (appendix, csv, json, vtu) to `output` or standard output.
struct TemplateOutput {
  std::string name;   // the template's name in the JSON ("template") and the appendix title
  std::string title;  // what follows the name in the appendix title, e.g. "box 24x14x24"
  std::string format = "appendix";  // resolved (cli/conventions.hpp: output_format)
  std::string output;
  EncodingArgs encoding;
  bool smooth = true;
  bool slide = false;
  bool quality = false;
  bool check_conditions = true;  // the paper's interleave conditions (geode templates only)
  // An invalid mesh (cli/conventions.hpp invalid_mesh_reason) is refused (exit 4, nothing
  // written) unless this is set; it is then written and the exit code is still 4.
  bool write_invalid = false;
  std::string note;  // e.g. what a fix-up did; printed with the smoothing note
  // Said after obstructions that no placement can untangle (arrange: its --fixup).
  std::string obstruction_hint;
  // Replaces templates::smooth_template (e.g. the refinement template's own smoothing).
  std::function<primal::SmoothResult(templates::Template&)> smoother;
  // --format html: the arrangement's sheets and domain (contoured for the viewer), the map from
  // the domain to the template's coordinates (identity when empty), and the command that made it.
  std::vector<stc::Sheet> sheets;
  stc::Domain domain;
  std::function<primal::Point(const primal::Point&)> to_physical;
  std::string caption;
};
void write_template(templates::Template& t, const TemplateOutput& out);

}  // namespace geode::cli
