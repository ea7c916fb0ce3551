// One output whatever the thread count, and whatever the verification: `geode demo` on models as
// Gmsh makes them (six hex parts in a tet potting; hexes, tets, pyramids and wedges side by side)
// writes the same bytes with --threads 1 and --threads 2, with --verify full and --verify local,
// and `geode --version` starts without the demo models' libgmsh.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_run.hpp"
#include "support/sanitized.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
namespace fs = std::filesystem;

namespace {

using geode::test::slurp;

}  // namespace

// Skipped in the sanitized build (54 s there for the hex-dominant model alone): what it proves,
// one output for any thread count, is not the sanitizers' to check, and the conform suite runs
// the same conform and verification under them.
TEST_CASE("geode demo: the same bytes on one thread and two, verified whole or locally" *
          doctest::skip(test::kSanitized)) {
  const test::TempDir dir;
  for (const char* model : {"potting", "hexdominant"}) {
    CAPTURE(model);
    std::string reference;
    for (const char* extra :
         {"--threads 1 --verify full", "--threads 2 --verify full", "--threads 2"}) {
      CAPTURE(extra);
      const fs::path out = dir.path / "out.exo", report = dir.path / "r.json";
      const auto run =
          test::geode_cli(std::string("demo --model ") + model + " -n 2 --quiet -o " +
                              out.string() + " --report " + report.string() + " " + extra,
                          true);
      INFO(run.out);
      REQUIRE(run.code == 0);
      const auto j = nlohmann::json::parse(slurp(report));
      CHECK(j["valid"] == true);
      CHECK(j["verification"]["scope"] ==
            (std::string(extra).find("full") != std::string::npos ? "full" : "local"));
      const std::string written = slurp(out);
      CHECK(!written.empty());
      if (reference.empty())
        reference = written;
      else
        CHECK(written == reference);
      fs::remove(out), fs::remove(report);
    }
  }
}

TEST_CASE("geode --version does not load libgmsh") {
  const auto run = test::geode_cli("--version", true);
  CHECK(run.code == 0);
  CHECK(run.out.find("geode") != std::string::npos);
  // The libraries the dynamic loader maps for the command: libgmsh is not among them.
  const int found =
      std::system(("ldd " + std::string(GEODE_CLI_PATH) + " | grep -q libgmsh").c_str());
  CHECK(found != 0);
}
