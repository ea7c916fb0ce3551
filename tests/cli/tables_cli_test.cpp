// The commands read the format table (io/formats.hpp) and the template table
// (templates/template_table.hpp): their choices and help texts list every entry, and what they
// write is what the table's writer writes.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/templates/template_table.hpp>
#include "support/cli_run.hpp"

using namespace geode;
namespace fs = std::filesystem;

TEST_CASE("cli tables: geode formats prints the format table's matrix") {
  const test::CliRun r = test::geode_cli("formats");
  CHECK(r.code == 0);
  CHECK(r.out == io::format_matrix_markdown());
}

TEST_CASE("cli tables: help texts list every template and every format of the tables") {
  const test::CliRun t = test::geode_cli("template --help");
  REQUIRE(t.code == 0);
  for (const templates::TemplateEntry& e : templates::template_table()) {
    CAPTURE(e.name);
    CHECK(t.out.find(std::string(e.name) + ": " + std::string(e.summary)) != std::string::npos);
  }
  const test::CliRun s = test::geode_cli("study interleave --help");
  for (const std::string& name : templates::template_names(true))
    CHECK(s.out.find(name) != std::string::npos);
  // A fixed-up entry's note names template's --no-fixup; study has no such option.
  CHECK(t.out.find("(fixed up unless --no-fixup)") != std::string::npos);
  CHECK(s.out.find("--no-fixup") == std::string::npos);
  for (const char* cmd : {"conform --help", "arrange --help", "template --help"}) {
    CAPTURE(cmd);
    const test::CliRun h = test::geode_cli(cmd);
    for (const io::MeshFormat& f : io::mesh_formats())
      if (f.write)
        CHECK(h.out.find(std::string(f.name) + " (" + std::string(f.title)) != std::string::npos);
  }
  const test::CliRun c = test::geode_cli("conform --help");
  CHECK(c.out.find("input model (" + io::extension_list(io::FormatRole::kRead, ", ", ", ") + ")") !=
        std::string::npos);
}

TEST_CASE("cli tables: every writable format is offered by template -o and reads back") {
  test::TempDir dir;
  for (const io::MeshFormat& f : io::mesh_formats()) {
    if (!f.write) continue;
    CAPTURE(f.name);
    const fs::path out = dir.path / ("t" + std::string(f.extensions.back()));
    const test::CliRun r = test::geode_cli(
        "template geode3d --format " + std::string(f.name) + " -o " + out.string(), true);
    CHECK(r.code == 0);
    CHECK(io::read_model(out).hexes.size() == 26);
  }
  const test::CliRun bad =
      test::geode_cli("template geode3d --format stl -o " + (dir.path / "t.stl").string(), true);
  CHECK(bad.code == 2);
}
