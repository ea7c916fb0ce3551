// A mesh and its report are both written or neither (io::publish_together), also when a signal
// arrives between the two renames and when the second output fails after the first was renamed:
// the outputs' former bytes come back, no hidden temporary or backup file is left.
#include <doctest/doctest.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <geode/io/gmsh.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/cli_run.hpp"

namespace fs = std::filesystem;
using geode::test::geode_cli;
using geode::test::ScopedEnv;
using geode::test::TempDir;

namespace {

using geode::test::slurp;

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// dir/hexes.msh: an n^3 grid of unit hexes, conform's input here; returns its path.
fs::path hex_grid_msh(const TempDir& dir, int n) {
  const fs::path path = dir.path / "hexes.msh";
  geode::io::write_gmsh(
      geode::primal::grid_model({n, n, n}, 1.0, [](int, int, int) { return false; }), path);
  return path;
}

}  // namespace

TEST_CASE("conform -o and --report: a signal between the two renames leaves both or neither") {
  struct Row {
    int signal;
    bool former_outputs;  // out.exo and r.json exist before the run
  };
  // Beside the interrupts, what else ends a process: a CPU limit (ulimit -t: SIGXCPU), a timer,
  // a script's SIGUSR1; these left the temporaries behind before they were handled.
  for (const Row row :
       {Row{SIGINT, false}, Row{SIGTERM, false}, Row{SIGINT, true}, Row{SIGTERM, true},
        Row{SIGHUP, true}, Row{SIGXCPU, true}, Row{SIGALRM, true}, Row{SIGUSR1, true}}) {
    CAPTURE(row.signal);
    CAPTURE(row.former_outputs);
    TempDir dir;
    const fs::path input = hex_grid_msh(dir, 2);
    const fs::path out = dir.path / "out.exo", report = dir.path / "r.json";
    if (row.former_outputs) {
      std::ofstream(out) << "former mesh\n";
      std::ofstream(report) << "former report\n";
    }
    const std::vector<std::string> before = names_in(dir.path);
    const std::string command = "conform " + input.string() + " -o " + out.string() + " --report " +
                                report.string() + " --quiet";
    {
      ScopedEnv hook("GEODE_TEST_SIGNAL_BETWEEN_RENAMES", std::to_string(row.signal));
      const auto run = geode_cli(command, true);
      INFO(run.out);
      // Killed by the signal: the shell reports 128 + N, or the status is not an exit at all.
      CHECK((run.code == -1 || run.code == 128 + row.signal));
    }
    CHECK(names_in(dir.path) == before);  // no temporary, no backup, no lone output
    if (row.former_outputs) {
      CHECK(slurp(out) == "former mesh\n");
      CHECK(slurp(report) == "former report\n");
    }
    // The control: without the signal the same run writes both.
    const auto run = geode_cli(command, true);
    INFO(run.out);
    CHECK(run.code == 0);
    CHECK(fs::file_size(out) > 1000);
    CHECK(slurp(report).find("\"valid\"") != std::string::npos);
    CHECK(names_in(dir.path).size() == 3);
  }
}

TEST_CASE("conform -o and --report: a report that cannot be written puts the former mesh back") {
  TempDir dir;
  const fs::path input = hex_grid_msh(dir, 2);
  const fs::path out = dir.path / "out.exo", report = dir.path / "r.json";
  std::ofstream(out) << "former mesh\n";
  // The report goes to a full device (copied into last, after the mesh's rename).
  fs::create_symlink("/dev/full", report);
  const auto run = geode_cli("conform " + input.string() + " -o " + out.string() + " --report " +
                                 report.string() + " --quiet",
                             true);
  INFO(run.out);
  CHECK(run.code == 2);
  CHECK(run.out.find("nothing written") != std::string::npos);
  CHECK(slurp(out) == "former mesh\n");
  CHECK(names_in(dir.path) == std::vector<std::string>{"hexes.msh", "out.exo", "r.json"});
}

TEST_CASE("demo --save-input is published with -o: a mesh that cannot be written leaves neither") {
  // A fault hunt's: the demo model was saved before the run, which then failed ("nothing
  // written") with the input file left behind.
  TempDir dir;
  const fs::path saved = dir.path / "in.msh", out = dir.path / "out.exo";
  fs::create_symlink("/dev/full", out);
  const auto run = geode_cli(
      "demo --model half -n 2 --save-input " + saved.string() + " -o " + out.string() + " --quiet",
      true);
  INFO(run.out);
  CHECK(run.code == 2);
  CHECK(run.out.find("nothing written") != std::string::npos);
  CHECK(names_in(dir.path) == std::vector<std::string>{"out.exo"});
  fs::remove(out);
  const auto ok = geode_cli("demo --model half -n 2 --save-input " + saved.string() + " -o " +
                            out.string() + " --quiet");
  CHECK(ok.code == 0);
  CHECK(names_in(dir.path) == std::vector<std::string>{"in.msh", "out.exo"});
}

TEST_CASE("demo without outputs conforms and prints its report; --save-input alone saves") {
  // A hunt's: docs/whole-models.md's `geode demo --model delaunay -n 4 --smooth none` printed
  // nothing and exited 0, the conform skipped as if --save-input had been given.
  TempDir dir;
  const auto printed = geode_cli("demo --model half -n 2 --smooth none");
  CHECK(printed.code == 0);
  CHECK(printed.out.find("block 1 ") != std::string::npos);
  CHECK(printed.out.find("input diced alone: min scaled Jacobian") != std::string::npos);
  const fs::path saved = dir.path / "in.msh";
  const auto save = geode_cli("demo --model half -n 2 --save-input " + saved.string());
  CHECK(save.code == 0);
  CHECK(save.out.find("wrote " + saved.string()) != std::string::npos);
  CHECK(save.out.find("block 1 ") == std::string::npos);
  CHECK(names_in(dir.path) == std::vector<std::string>{"in.msh"});
}

TEST_CASE("an output FIFO whose reader leaves: exit 2 in one line, the report not replaced") {
  // A hunt's: the write into the FIFO raised SIGPIPE, which ended the run with the new report
  // published and the mesh lost. geode ignores SIGPIPE: the write fails as an error instead.
  TempDir dir;
  const fs::path input = hex_grid_msh(dir, 12);
  const fs::path fifo = dir.path / "f.msh", report = dir.path / "r.json";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  std::ofstream(report) << "former report\n";
  // The reader takes one byte and leaves: the mesh (about 1 MB) does not fit the pipe.
  REQUIRE(std::system(("(head -c 1 '" + fifo.string() + "' >/dev/null &)").c_str()) == 0);
  const auto run = geode_cli("conform " + input.string() + " -o " + fifo.string() + " --report " +
                                 report.string() + " --quiet",
                             true);
  INFO(run.out);
  CHECK(run.code == 2);
  CHECK(run.out.find("f.msh: write failed: Broken pipe") != std::string::npos);
  CHECK(slurp(report) == "former report\n");
  CHECK(names_in(dir.path) == std::vector<std::string>{"f.msh", "hexes.msh", "r.json"});
}

TEST_CASE(
    "study shape's CSVs are written as one: a fourth that fails leaves the three as they were") {
  TempDir dir;
  for (const char* name : {"sh.csv", "sd.csv", "sq.csv"}) std::ofstream(dir.path / name) << "OLD\n";
  fs::create_symlink("/dev/full", dir.path / "sj.csv");
  const auto at = [&](const char* name) { return (dir.path / name).string(); };
  const std::string command = "study shape --heights 10 --shears 0 --tapers 1 -o " + at("sh.csv") +
                              " --distorted-csv " + at("sd.csv") + " --quality-csv " +
                              at("sq.csv") + " --sj-csv " + at("sj.csv");
  const auto run = geode_cli(command, true);
  INFO(run.out);
  CHECK(run.code == 2);
  CHECK(run.out.find("nothing written") != std::string::npos);
  for (const char* name : {"sh.csv", "sd.csv", "sq.csv"}) CHECK(slurp(dir.path / name) == "OLD\n");
  CHECK(names_in(dir.path) == std::vector<std::string>{"sd.csv", "sh.csv", "sj.csv", "sq.csv"});
  fs::remove(dir.path / "sj.csv");
  CHECK(geode_cli(command).code == 0);
  for (const char* name : {"sh.csv", "sd.csv", "sq.csv", "sj.csv"})
    CHECK(slurp(dir.path / name).rfind("OLD", 0) != 0);
}

TEST_CASE("conform --report -: the JSON alone on standard output, after the mesh is written") {
  TempDir dir;
  const fs::path input = dir.path / "m.msh", mesh = dir.path / "out.vtk";
  geode::io::write_gmsh(
      geode::primal::grid_model({2, 2, 2}, 1.0, [](int i, int, int) { return i == 1; }), input);
  const auto run = geode_cli("conform " + input.string() + " -o " + mesh.string() + " --report -");
  CHECK(run.code == 0);
  const auto j = nlohmann::json::parse(run.out);  // nothing but the report: the summary on stderr
  CHECK(j.at("valid") == true);
  CHECK(j.at("blocks").size() == 2);
  CHECK(fs::file_size(mesh) > 0);
  const auto both = geode_cli("conform " + input.string() + " --report - --quiet", true);
  CHECK(both.code == 0);
  CHECK(both.out.rfind("{", 0) == 0);  // --quiet, stderr kept: no summary, the report printed
}

TEST_CASE("an output linked to /dev/stdout, stdout a pipe: the mesh comes through the pipe") {
  // A hunt's: the link's target, "pipe:[N]", was taken for a path (/proc/self/fd/pipe:[N]), and
  // the run refused naming it. The pipe is a FIFO: the finished file is copied into it.
  TempDir dir;
  const fs::path input = dir.path / "m.msh", link = dir.path / "out.vtk";
  geode::io::write_gmsh(
      geode::primal::grid_model({2, 2, 2}, 1.0, [](int i, int, int) { return i == 1; }), input);
  fs::create_symlink("/dev/stdout", link);
  const auto run = geode_cli("conform " + input.string() + " -o " + link.string() + " --quiet");
  CHECK(run.code == 0);
  CHECK(run.out.rfind("# vtk DataFile Version", 0) == 0);
  CHECK(fs::is_symlink(link));  // still the link
  // With --report - the report would go there too: refused before the work.
  const auto both =
      geode_cli("conform " + input.string() + " -o " + link.string() + " --report - --quiet", true);
  CHECK(both.code == 2);
  CHECK(both.out.find("is standard output, where --report - prints the report") !=
        std::string::npos);
  // Beside a report (or as the report), the link was resolved to compare the two paths and
  // the run ended with exit 1 and libstdc++'s "cannot make canonical path" (a hunt's).
  const fs::path report_link = dir.path / "out.json";
  fs::create_symlink("/dev/stdout", report_link);
  const auto mesh_there = geode_cli("conform " + input.string() + " -o " + link.string() +
                                    " --report " + (dir.path / "r.json").string() + " --quiet");
  CHECK(mesh_there.code == 0);
  CHECK(mesh_there.out.rfind("# vtk DataFile Version", 0) == 0);
  CHECK(fs::exists(dir.path / "r.json"));
  const auto report_there =
      geode_cli("conform " + input.string() + " -o " + (dir.path / "m.exo").string() +
                " --report " + report_link.string() + " --quiet");
  CHECK(report_there.code == 0);
  CHECK(report_there.out.rfind("{", 0) == 0);
  CHECK(fs::exists(dir.path / "m.exo"));
  // /dev/stdout itself has no extension to tell the format by: the refusal says how to get
  // there (it said "unknown output format ''").
  const auto bare = geode_cli("conform " + input.string() + " -o /dev/stdout --quiet", true);
  CHECK(bare.code == 2);
  CHECK(bare.out.find("/dev/stdout: no extension, which tells the output format") !=
        std::string::npos);
}
