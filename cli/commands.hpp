#pragma once
// Sub-commands of the `geode` command line; each file registers its own.
#include <CLI/CLI.hpp>

namespace geode::cli {

void add_template_command(CLI::App& app);   // cli/template_command.cpp
void add_study_commands(CLI::App& app);     // cli/study_command.cpp
void add_conform_commands(CLI::App& app);   // cli/conform_command.cpp: conform, demo
void add_dual_command(CLI::App& app);       // cli/dual_command.cpp

}  // namespace geode::cli
