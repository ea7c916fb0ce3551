#include "cli/commands.hpp"

namespace geode::cli {
// Whole-model commands (conform, demo) are registered here.
void add_conform_commands(CLI::App&) {}
}  // namespace geode::cli
