#pragma once
// A demo model as a user's run reads it: built by the command in a process of its own
// (`geode demo --save-input`), written to a file and read back. libgmsh 4.8's pyramid relocation
// trips an Eigen assertion on a second hybrid generate(3) in one process, so a test never builds
// several demo models in its own.
#include <doctest/doctest.h>

#include <string>

#include <geode/io/read_model.hpp>
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace geode::test {

// Saved as dir/NAME.EXT; n <= 0 keeps the model's default size. check_covering as
// io::read_model's (false: read a model meant to be judged by the test itself).
inline primal::Model demo_input(const std::string& name, int n, const TempDir& dir,
                                const std::string& ext = ".vtu", bool check_covering = true) {
  const auto path = dir.path / (name + ext);
  const auto run =
      geode_cli("demo --model " + name + (n > 0 ? " -n " + std::to_string(n) : std::string()) +
                    " --quiet --save-input " + path.string(),
                true);
  INFO(run.out);
  REQUIRE(run.code == 0);
  return io::read_model(path, {}, check_covering);
}

}  // namespace geode::test
