// geode: all-hex meshing through the dual (the Spatial Twist Continuum).
#include <iostream>

#include "cli/commands.hpp"
#include "primal/errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "geode: all-hex transition templates derived from completed dual sheet arrangements, and the\n"
      "geode algorithm that conforms a diced hex mesh to a diced tet mesh with them."};
  app.require_subcommand(1);
  geode::cli::add_template_command(app);
  geode::cli::add_study_commands(app);
  geode::cli::add_conform_commands(app);
  geode::cli::add_dual_command(app);
  geode::cli::add_check_command(app);
  geode::cli::add_arrange_command(app);
  geode::cli::add_view_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const geode::InvalidInput& e) {
    std::cerr << "geode: error: " << e.what() << "\n";
    return 2;
  } catch (const geode::TopologyError& e) {
    std::cerr << "geode: topology error: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "geode: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
