// `geode formats`: the format table (io/formats.hpp) as the Markdown matrix of docs/formats.md.
#include <iostream>

#include <geode/io/formats.hpp>
#include "cli/commands.hpp"

namespace geode::cli {

void add_formats_command(CLI::App& app) {
  CLI::App* c = app.add_subcommand("formats",
                                   "Print the mesh formats geode reads and writes (the format "
                                   "table, io/formats.hpp) as a Markdown\n"
                                   "table: extensions, versions read and written, cell kinds, and "
                                   "whether blocks, block names, node\n"
                                   "sets, side sets and set names are carried (yes: written and "
                                   "read back; written: not read back).");
  c->callback([] { std::cout << io::format_matrix_markdown(); });
}

}  // namespace geode::cli
