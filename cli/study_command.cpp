#include "cli/commands.hpp"

namespace geode::cli {
// Studies (interleave sweep, shape study) are registered here.
void add_study_commands(CLI::App&) {}
}  // namespace geode::cli
