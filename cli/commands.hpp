#pragma once
// Sub-commands of the `geode` command line; each file registers its own. A new command follows
// cli/conventions.hpp (exit codes, number_check / parse_box for numbers, output_format +
// check_output_path before any work, OutputFiles for outputs written as one, write_mesh for
// every mesh format) and reports long work through cli/progress.hpp.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

#include "primal/model.hpp"

namespace geode::cli {

void add_template_command(CLI::App& app);   // cli/template_command.cpp
void add_study_commands(CLI::App& app);     // cli/study_command.cpp
void add_conform_commands(CLI::App& app);   // cli/conform_command.cpp: conform, demo
void add_dual_command(CLI::App& app);       // cli/dual_command.cpp

// Shared by the commands (cli/files.cpp): the extension in lower case (".msh"), and a model
// read by extension (.msh, .exo, .e); InvalidInput naming the file when it is missing or of
// another format.
std::string file_extension(const std::filesystem::path& p);
primal::Model read_model(const std::filesystem::path& path);
// Standard output when `path` is empty or "-", else the file, written atomically.
void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace geode::cli
