// File-name helpers shared by the commands (cli/commands.hpp).
#include <algorithm>
#include <cctype>
#include <iostream>

#include "cli/commands.hpp"
#include "primal/atomic_file.hpp"
#include "primal/errors.hpp"
#include "primal/read_model.hpp"

namespace geode::cli {

namespace fs = std::filesystem;

std::string file_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

primal::Model read_model(const fs::path& path) { return primal::read_model(path); }

void write_or_print(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty() || path == "-") {
    write(std::cout);
    return;
  }
  primal::write_file_atomically(path, write);
}

}  // namespace geode::cli
