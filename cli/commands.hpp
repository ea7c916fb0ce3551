#pragma once
// Sub-commands of the `geode` command line; each file registers its own.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "primal/io_html.hpp"
#include "primal/model.hpp"
#include "stc/arrangement.hpp"
#include "stc/sheet.hpp"

namespace geode::cli {

void add_template_command(CLI::App& app);   // cli/template_command.cpp
void add_study_commands(CLI::App& app);     // cli/study_command.cpp
void add_conform_commands(CLI::App& app);   // cli/conform_command.cpp: conform, demo
void add_dual_command(CLI::App& app);       // cli/dual_command.cpp
void add_view_command(CLI::App& app);       // cli/view_command.cpp

// Shared by the commands (cli/files.cpp): the extension in lower case (".msh"), and a model
// read by extension (.msh, .exo, .e); InvalidInput naming the file when it is missing or of
// another format.
std::string file_extension(const std::filesystem::path& p);
primal::Model read_model(const std::filesystem::path& path);
// A mesh as read for the commands that take any all-hex mesh (dual, view): hexes from .vtu,
// .vtk, .msh, .exo, .e, or quads (a planar quad mesh in z = 0, from .vtu / .vtk only).
// InvalidInput naming the file for another format, mixed cells, tets, or a quad off z = 0.
struct InputMesh {
  int dim = 3;
  primal::HexMesh hex;
  primal::QuadMesh quad;
};
InputMesh read_hex_or_quad_mesh(const std::filesystem::path& path);

// The sheets of a computed arrangement for the HTML viewer (cli/view_command.cpp): each sheet
// contoured from its field inside the domain (stc/sheet_surfaces.hpp), its points mapped by
// `to_physical` (identity when empty), and its layer read off the dual's element_sheets.
std::vector<primal::ViewSheet> arrangement_view_sheets(const std::vector<stc::Sheet>& sheets, const stc::Domain& domain,
                                                       const std::vector<std::vector<int>>& element_sheets,
                                                       const std::function<primal::Point(const primal::Point&)>& to_physical);

// Standard output when `path` is empty or "-", else the file, written atomically.
void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace geode::cli
