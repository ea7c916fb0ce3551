// Conventions every `geode` command follows (cli/conventions.hpp): usage errors are one line
// with exit 2 and write nothing, numbers are validated, --version, the output format follows
// the extension (a contradicting --format is refused), outputs are checked before any work and
// written both or neither, a non-manifold input is refused when read (exit 3), an invalid result
// exits 4 and writes nothing unless asked.
#include <doctest/doctest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include <geode/io/exodus.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/io/vtk.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/cli_run.hpp"
#include "support/fixtures.hpp"

using namespace geode;
namespace fs = std::filesystem;

namespace {

using test::slurp;

using test::ScopedEnv;
using test::TempDir;

std::size_t lines(const std::string& s) {
  return primal::index_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

}  // namespace

TEST_CASE(
    "cli conventions: usage errors and bad numbers are one line on stderr, exit 2, nothing "
    "written") {
  TempDir dir;
  const std::string d = dir.path.string() + "/";
  const fs::path in = dir.path / "in.msh";
  io::write_gmsh(test::small_hybrid_model(), in);
  struct Case {
    std::string args;
    std::string words;  // expected in the message
  };
  const std::vector<Case> cases{
      {"", "subcommand is required"},
      {"template", "NAME is required"},
      {"template geode3d --bogus", "--bogus"},
      {"template geode5d", "geode5d"},
      {"conform", "INPUT is required"},
      {"dual", "required"},
      {"study", "subcommand"},
      {"demo -n 0", "--size: 0 is out of range [1, 64]"},
      {"demo -n 2.5", "not a whole number"},
      {"demo -n abc", "not a finite number"},
      {"demo --model sphere", "sphere"},
      {"template geode3d --box 1e400x1x1", "'1e400' is not a finite number"},
      {"template geode3d --box 1e308x14x24", "[1e-6, 1e6]"},
      {"template geode3d --box 24x14", "2 numbers for a 3D template"},
      {"template geode2d --box 24x14x24", "3 numbers for a 2D template"},
      {"template geode3d --box nanx14x24", "not a finite number"},
      {"template geode3d --box 0x14x24", "[1e-6, 1e6]"},
      {"template geode3d --box 24x0.001x24", "degenerate box"},
      {"template geode3d --box 24x14x", "not a finite number"},
      {"template geode3d --high-roof nan", "--high-roof: 'nan' is not a finite number"},
      {"template geode3d --dome-radius 1e999", "not a finite number"},
      {"study interleave --high 1e400", "not a finite number"},
      {"study interleave --low 2", "out of range [0, 1]"},
      {"study shape --heights -3", "out of range"},
      {"conform " + in.string() + " --merge-tolerance -1", "out of range"},
      {"conform " + in.string() + " --smooth fast", "fast"},
      {"conform " + in.string() + " --buffer-thickness 0.95", "out of range [0.01, 0.9]"},
      {"conform " + in.string() + " --buffer-side both", "--buffer-side"},
      {"conform " + in.string() + " --buffer-side tet --buffer-thickness 0.6", "at most 0.45"},
      {"conform " + in.string() + " --smooth-target 2", "out of range [0, 1]"},
      {"conform " + in.string() + " --template-box 24x0x24 -o " + d + "out.exo",
       "--template-box '24x0x24'"},
      // Outputs: format by extension, contradictions, unknown extensions, missing directories.
      {"template geode3d -o " + d + "t.vtu --format csv",
       "--format csv contradicts the extension '.vtu'"},
      {"template geode3d --format vtu -o " + d + "t.vtk",
       "--format vtu contradicts the extension '.vtk'"},
      {"template geode3d -o " + d + "t.xyz", "unknown output format '.xyz'"},
      {"template geode3d --format vtu", "needs -o FILE"},
      {"template geode2d -o " + d + "t.exo", "quad mesh"},
      {"template geode3d -o " + d + "missing/t.vtu", "does not exist"},
      {"conform " + in.string() + " -o " + d + "out.stl", "unknown output format '.stl'"},
      {"conform " + in.string() + " -o " + d + "out.exo --format vtu", "contradicts"},
      {"conform " + in.string() + " -o " + d + "out.exo --report " + d + "r.txt", "JSON"},
      {"conform " + in.string() + " -o " + d + "out.exo --report " + d + "missing/r.json",
       "missing"},
      {"conform " + in.string() + " -o " + d, "is a directory"},
      {"dual " + in.string() + " --rebuild " + d + "r.stl", "unknown output format '.stl'"},
      {"dual " + in.string() + " -o " + d + "r.json --format text", "contradicts"},
      {"study shape -o " + d + "h.txt", "unknown output format '.txt'"},
      // A fault hunt's: these wrote a file named "-", a mesh to a garbled temporary's name, one
      // output over the other, or took an empty value as none, all with exit 0 or after the work.
      {"template geode3d -o - --format html", "--format html is written to a file"},
      {"dual " + in.string() + " --rebuild -", "a mesh is written to a file"},
      {"demo -n 2 --save-input " + d + "h.msh -o " + d + "h.msh",
       "given to both -o and --save-input"},
      {"study interleave -o " + d + "x.csv --summary " + d + "x.csv",
       "given to both -o and --summary"},
      {"study shape -o " + d + "a.csv --distorted-csv " + d + "a.csv",
       "given to both -o and --distorted-csv"},
      {"conform " + in.string() + " -o " + d + "out.exo --report=", "--report: an empty value"},
      // Refused before parsing, named as the command's own usage errors are.
      {"conform " + in.string() + " -o ''",
       "geode conform: usage error: -o: an empty value (leave the option out instead) (see geode "
       "conform --help)"},
      {"check " + in.string() + " --planar-angle nan", "'nan' is not a finite number"},
      {"quality " + in.string(), "'quality' is not a command"},
      {"template geode3d --high-roof 2", "--low-roof / --high-roof: tunnel roofs"},
      {"template geode4tri --dome-depth 1", "--dome-depth: dome depth"},
      {"arrange " + d, "not a regular file"},
  };
  // An output link into a missing directory: refused by the check before any work (it failed
  // after the whole run, "cannot create a temporary file in ...": a fault hunt's).
  fs::create_symlink(dir.path / "missing" / "x.exo", dir.path / "dangling.exo");
  const test::CliRun dangling =
      test::geode_cli("conform " + in.string() + " -o " + d + "dangling.exo", true);
  CHECK(dangling.code == 2);
  CHECK(dangling.out.find("directory " + d + "missing does not exist") != std::string::npos);
  fs::remove(dir.path / "dangling.exo");
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const test::CliRun r = test::geode_cli(c.args, true);  // stdout is empty: all of it is stderr
    INFO(r.out);
    CHECK(r.code == 2);
    CHECK(lines(r.out) == 1);
    CHECK(r.out.size() < 300);  // no 300-digit ranges
    CHECK(r.out.find(c.words) != std::string::npos);
    CHECK(dir.entries() == 1);  // only the input
  }
}

TEST_CASE("cli conventions: --version and --help") {
  const test::CliRun v = test::geode_cli("--version");
  CHECK(v.code == 0);
  CHECK(v.out.rfind("geode ", 0) == 0);
  CHECK(lines(v.out) == 1);
  for (const char* cmd :
       {"template", "conform", "demo", "dual", "study interleave", "study shape"}) {
    CAPTURE(cmd);
    const test::CliRun h = test::geode_cli(std::string(cmd) + " --help");
    CHECK(h.code == 0);
    CHECK(h.out.find("--help") != std::string::npos);
  }
  const test::CliRun h = test::geode_cli("conform --help");
  for (const char* opt :
       {"--output", "--format", "--report", "--smooth", "--geode-block", "--merge-tolerance",
        "--write-invalid", "--quiet", "--vtk-encoding", "--msh-encoding", "--smooth-target",
        "--buffer-thickness", "--buffer-side", "--template-box"})
    CHECK(h.out.find(opt) != std::string::npos);
}

TEST_CASE("cli conventions: template -o picks the format from the extension") {
  TempDir dir;
  struct Case {
    std::string name;
    std::string starts_with;
  };
  const std::vector<Case> cases{{"t.vtu", "<?xml"},       {"t.vtk", "# vtk DataFile"},
                                {"t.msh", "$MeshFormat"}, {"t.txt", "# geode template geode3d"},
                                {"t.csv", "node,x,y,z"},  {"t.json", "{"},
                                {"t.exo", "CDF"},         {"t.e", "CDF"}};
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const fs::path out = dir.path / c.name;
    const test::CliRun r = test::geode_cli("template geode3d -o " + out.string(), true);
    INFO(r.out);
    REQUIRE(r.code == 0);
    CHECK(slurp(out).rfind(c.starts_with, 0) == 0);
  }
  // The meshes read back with 26 hexes; .vtu is binary by default (no text tables in it).
  CHECK(io::read_gmsh(dir.path / "t.msh").hexes.size() == 26);
  CHECK(io::read_exodus(dir.path / "t.exo").hexes.size() == 26);
  CHECK(io::to_hex_mesh(io::read_vtk(dir.path / "t.vtk")).hexes.size() == 26);
  CHECK(slurp(dir.path / "t.vtu").find("format=\"binary\"") != std::string::npos);
  CHECK(slurp(dir.path / "t.vtu").find("Table") == std::string::npos);
  // .msh as Gmsh 2.2 when asked.
  REQUIRE(test::geode_cli("template geode3d --format msh22 -o " + (dir.path / "t22.msh").string())
              .code == 0);
  CHECK(slurp(dir.path / "t22.msh").rfind("$MeshFormat\n2.2", 0) == 0);
  CHECK(io::read_gmsh(dir.path / "t22.msh").hexes.size() == 26);
  // Binary .msh when asked, from template and arrange alike; the same hexes as the ASCII file.
  const fs::path spec = fs::path(GEODE_SOURCE_DIR) / "notebooks-data/specs/pillow.json";
  for (const std::string& command :
       {std::string("template geode3d"), "arrange " + spec.string() + " --smooth"}) {
    CAPTURE(command);
    const fs::path text = dir.path / "text.msh", binary = dir.path / "binary.msh";
    REQUIRE(test::geode_cli(command + " -o " + text.string()).code == 0);
    REQUIRE(test::geode_cli(command + " --msh-encoding binary -o " + binary.string()).code == 0);
    CHECK(slurp(binary).rfind("$MeshFormat\n4.1 1 8\n", 0) == 0);
    const primal::Model a = io::read_gmsh(text), b = io::read_gmsh(binary);
    CHECK(!b.hexes.empty());
    CHECK(a.hexes == b.hexes);
    CHECK(a.points == b.points);
  }
}

namespace {

std::vector<std::uint8_t> base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<std::uint8_t> out;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;  // '=' padding, white space
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

// The payload of the first DataArray after `marker` in a binary .vtu, as doubles.
std::vector<double> binary_doubles(const std::string& xml, const std::string& marker) {
  const std::size_t tag = xml.find(marker);
  REQUIRE(tag != std::string::npos);
  const std::size_t start = xml.find('>', tag) + 1, end = xml.find("</DataArray>", start);
  const std::vector<std::uint8_t> bytes = base64_decode(xml.substr(start, end - start));
  REQUIRE(bytes.size() >= 8);
  std::uint64_t n = 0;
  std::memcpy(&n, bytes.data(), 8);
  REQUIRE(n + 8 == bytes.size());
  std::vector<double> v(n / 8);
  std::memcpy(v.data(), bytes.data() + 8, n);
  return v;
}

}  // namespace

TEST_CASE("cli conventions: a binary .vtu holds the same points and cell data as the ASCII one") {
  TempDir dir;
  const fs::path bin = dir.path / "b.vtu", txt = dir.path / "a.vtu";
  REQUIRE(test::geode_cli("template geode3d -o " + bin.string()).code == 0);
  REQUIRE(test::geode_cli("template geode3d --vtu-encoding ascii -o " + txt.string()).code == 0);
  const io::VtkGrid a = io::read_vtu(txt);
  REQUIRE(a.points.size() == 48);
  const std::string xml = slurp(bin);
  const std::vector<double> xyz = binary_doubles(xml, "NumberOfComponents=\"3\"");
  REQUIRE(xyz.size() == 3 * a.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      CHECK(xyz[3 * i + primal::index_cast<std::size_t>(k)] == a.points[i][k]);
  const std::vector<double> sj = binary_doubles(xml, "Name=\"scaled_jacobian\"");
  REQUIRE(a.cell_data.find_double("scaled_jacobian") != nullptr);
  CHECK(sj == *a.cell_data.find_double("scaled_jacobian"));
}

TEST_CASE(
    "cli conventions: conform checks its outputs before work and writes mesh and report both or "
    "neither") {
  TempDir dir;
  const fs::path in = dir.path / "in.msh", out = dir.path / "out.exo", report = dir.path / "r.json";
  io::write_gmsh(test::small_hybrid_model(), in);
  SUBCASE("a report in a missing directory: no mesh, exit 2, named") {
    const test::CliRun r =
        test::geode_cli("conform " + in.string() + " -o " + out.string() + " --report " +
                            (dir.path / "missing" / "r.json").string(),
                        true);
    CHECK(r.code == 2);
    CHECK(r.out.find("missing") != std::string::npos);
    CHECK(r.out.find("interface") == std::string::npos);  // refused before the first stage
    CHECK(!fs::exists(out));
  }
  SUBCASE("a directory in the report's place: refused before work, no mesh either") {
    fs::create_directory(report);
    fs::create_directory(report / "keep");  // a non-empty directory cannot be replaced
    const test::CliRun r = test::geode_cli("conform " + in.string() + " -o " + out.string() +
                                               " --report " + report.string() + " --quiet",
                                           true);
    CHECK(r.code == 2);
    CHECK(!fs::exists(out));
  }
  SUBCASE("both written") {
    const test::CliRun r = test::geode_cli("conform " + in.string() + " -o " + out.string() +
                                               " --report " + report.string() + " --quiet",
                                           true);
    INFO(r.out);
    CHECK(r.code == 0);
    CHECK(r.out.empty());
    CHECK(fs::exists(out));
    CHECK(fs::exists(report));
    CHECK(dir.entries() == 3);  // no temporaries left
  }
}

TEST_CASE(
    "cli conventions: an input whose boundary is not a manifold is refused when read, naming its "
    "nodes: exit 3") {
  // The small model plus one hex meeting the hex part along an edge only, or at one node only:
  // its diced hexes would make that edge or node non-manifold, so no output could be valid; the
  // read-time check refuses the input by the file's own node ids before any work.
  struct Row {
    const char* name;
    double z0;           // the extra hex spans z in [z0, z0 + 1] at x, y in [-1, 0]
    const char* reason;  // expected in the message
  };
  for (const Row row : {Row{"edge", 0.0, "not a manifold along the edge of nodes"},
                        Row{"node", -1.0, "not a manifold at node"}}) {
    CAPTURE(row.name);
    TempDir dir;
    primal::Model m = test::small_hybrid_model();
    auto node_at = [&](const primal::Point& p) {
      for (std::size_t i = 0; i < m.points.size(); ++i)
        if ((m.points[i] - p).norm() < 1e-12) return primal::index_cast(i);
      m.points.push_back(p);
      return primal::index_cast(m.points.size() - 1);
    };
    std::array<primal::Index, 8> h{};
    const double x[8] = {-1, 0, 0, -1, -1, 0, 0, -1}, y[8] = {-1, -1, 0, 0, -1, -1, 0, 0},
                 z[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    for (int c = 0; c < 8; ++c)
      h[primal::index_cast<std::size_t>(c)] = node_at({x[c], y[c], z[c] + row.z0});
    m.hexes.push_back(h);
    if (!m.hex_block.empty()) m.hex_block.push_back(m.hex_block.front());
    const fs::path in = dir.path / "in.exo", out = dir.path / "out.vtu";
    io::write_exodus(m, in);
    // The node ids the file gives the touching nodes (0, 0, 0) and, along an edge, (0, 0, 1).
    const primal::Model read = io::read_exodus(in);
    auto id_at = [&](const primal::Point& p) {
      for (std::size_t i = 0; i < read.points.size(); ++i)
        if ((read.points[i] - p).norm() < 1e-12)
          return std::to_string(primal::node_id(read, primal::index_cast(i)));
      return std::string("?");
    };
    const std::string nodes = row.z0 == 0.0 ? "nodes " + id_at({0, 0, 0}) + " " + id_at({0, 0, 1})
                                            : "node " + id_at({0, 0, 0});
    for (const char* verify : {"local", "full"}) {
      CAPTURE(verify);
      const test::CliRun r = test::geode_cli(
          "conform " + in.string() + " -o " + out.string() + " --verify " + verify + " --quiet",
          true);
      INFO(r.out);
      CHECK(r.code == 3);
      CHECK(lines(r.out) == 1);
      CHECK(r.out.find(in.string() + ": the boundary is " + row.reason) != std::string::npos);
      CHECK(r.out.find(nodes) != std::string::npos);
      CHECK(r.out.find("surface sheets") != std::string::npos);
      CHECK(dir.entries() == 1);
    }
  }
}

TEST_CASE(
    "cli conventions: an invalid result exits 4, says so even with --quiet, writes only with "
    "--write-invalid") {
  // A valid input whose result a faulty stage breaks: the test hook GEODE_TEST_INVERT_OUTPUT_HEX
  // (docs/cli.md) moves a corner of output hex 1 (the first diced hex) through its centre just
  // before verification, as a smoother gone wrong would; both --verify modes must catch it. (An
  // input that cannot give a valid result, such as a hex on an edge of the part, is refused when
  // read: no option of conform makes a valid input fail verification.)
  for (const char* verify : {"local", "full"}) {
    CAPTURE(verify);
    TempDir dir;
    const fs::path in = dir.path / "in.exo", out = dir.path / "out.vtu",
                   report = dir.path / "r.json";
    io::write_exodus(test::small_hybrid_model(), in);
    const std::string args = "conform " + in.string() + " -o " + out.string() + " --report " +
                             report.string() + " --verify " + verify + " --smooth none --quiet";
    const test::CliRun valid = test::geode_cli(args, true);  // without the hook: valid
    INFO(valid.out);
    REQUIRE(valid.code == 0);
    fs::remove(out);
    fs::remove(report);
    ScopedEnv hook("GEODE_TEST_INVERT_OUTPUT_HEX", "1");
    const test::CliRun r = test::geode_cli(args, true);
    INFO(r.out);
    CHECK(r.code == 4);
    CHECK(lines(r.out) == 1);
    CHECK(r.out.find("invalid result") != std::string::npos);
    CHECK(r.out.find("--write-invalid") != std::string::npos);
    CHECK(dir.entries() == 1);
    const test::CliRun w = test::geode_cli(args + " --write-invalid", true);
    CHECK(w.code == 4);
    CHECK(fs::exists(out));
    CHECK(fs::exists(report));
  }
  // With a warning of the run's own before verification (the interface's corner node on the
  // model's edge moved along it, off the interface's plane: its quad is not planar, and the
  // output's volume moves between the blocks), the one line says first what makes the result
  // invalid.
  TempDir dir;
  primal::Model m = test::small_hybrid_model();
  for (primal::Point& p : m.points)
    if (p == primal::Point(2.0, 0.0, 0.0)) p.x() += 0.1;
  const fs::path in = dir.path / "bent.exo";
  io::write_exodus(m, in);
  const std::string args = "conform " + in.string() + " -o " + (dir.path / "out.vtu").string() +
                           " --smooth none --quiet";
  const test::CliRun warned = test::geode_cli(args, true);
  INFO(warned.out);
  REQUIRE(warned.code == 0);
  REQUIRE(warned.out.find("of volume") != std::string::npos);
  ScopedEnv hook("GEODE_TEST_INVERT_OUTPUT_HEX", "1");
  const test::CliRun r = test::geode_cli(args, true);
  INFO(r.out);
  CHECK(r.code == 4);
  CHECK(lines(r.out) == 1);
  const std::size_t reason = r.out.find("invalid result: " + in.string() + ": ");
  REQUIRE(reason != std::string::npos);
  const std::string after = r.out.substr(reason + 18 + in.string().size());
  CHECK((after.starts_with("invalid mesh") || after.starts_with("1 hexes with scaled Jacobian")));
  CHECK(after.find("of volume") != std::string::npos);
  // And after a warning of conform's outer loop (Gmsh's layer-mixed: its wedges split into tets,
  // said after the run that found them), which came first.
  const fs::path mixed = dir.path / "mixed.msh";
  REQUIRE(test::geode_cli(
              "demo --model layer-mixed -n 2 --save-input " + mixed.string() + " --quiet", true)
              .code == 0);
  const test::CliRun split = test::geode_cli(
      "conform " + mixed.string() + " -o " + (dir.path / "m.vtu").string() + " --quiet", true);
  INFO(split.out);
  CHECK(split.code == 4);
  const std::size_t at = split.out.find("invalid result: " + mixed.string() + ": ");
  REQUIRE(at != std::string::npos);
  const std::string rest = split.out.substr(at + 18 + mixed.string().size());
  CHECK((rest.starts_with("invalid mesh") || rest.starts_with("1 hexes with scaled Jacobian")));
  CHECK(rest.find("wedges split") != std::string::npos);
}

TEST_CASE(
    "cli conventions: dual --rebuild writes every mesh format, by the extension, with its report "
    "as one") {
  TempDir dir;
  const fs::path in = dir.path / "grid.exo";
  io::write_exodus(primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; }), in);
  for (const char* name : {"r.msh", "r.exo", "r.e", "r.vtk", "r.vtu"}) {
    CAPTURE(name);
    const fs::path out = dir.path / name, report = dir.path / (std::string(name) + ".json");
    const test::CliRun r = test::geode_cli(
        "dual " + in.string() + " --rebuild " + out.string() + " -o " + report.string(), true);
    INFO(r.out);
    REQUIRE(r.code == 0);
    CHECK(fs::exists(report));  // the report's format from its extension: JSON
    std::ifstream is(report);
    CHECK(is.peek() == '{');
    const std::string e = out.extension().string();
    if (e == ".msh") CHECK(io::read_gmsh(out).hexes.size() == 8);
    if (e == ".exo" || e == ".e") CHECK(io::read_exodus(out).hexes.size() == 8);
    if (e == ".vtk") CHECK(io::to_hex_mesh(io::read_vtk(out)).hexes.size() == 8);
    if (e == ".vtu") {  // binary: its header and the decoded cell array
      CHECK(slurp(out).find("NumberOfCells=\"8\"") != std::string::npos);
      CHECK(binary_doubles(slurp(out), "Name=\"scaled_jacobian\"").size() == 8);
    }
  }
}

TEST_CASE("cli conventions: a file name that is not UTF-8 is written into JSON with U+FFFD") {
  // Linux file names are bytes; JSON text is UTF-8. The reports and the page name the input:
  // nlohmann::json's strict dump threw (exit 1, no output) on such a name.
  TempDir dir;
  const std::string name = "mesh-\xff\xfe";  // Latin-1 bytes, not UTF-8
  const fs::path mesh = dir.path / (name + ".exo");
  io::write_exodus(primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; }), mesh);
  const std::string quoted = "'" + mesh.string() + "'";
  const std::string replaced = "mesh-\xef\xbf\xbd\xef\xbf\xbd.exo";  // two U+FFFD
  for (const std::string& command : {"check " + quoted + " --format json --quiet",
                                     "dual " + quoted + " --format json --quiet"}) {
    CAPTURE(command);
    const auto run = test::geode_cli(command);
    REQUIRE(run.code == 0);
    const auto j = nlohmann::json::parse(run.out);  // throws on text that is not UTF-8
    CHECK(j.dump().find(replaced) != std::string::npos);
  }
  const fs::path page = dir.path / "page.html";
  REQUIRE(test::geode_cli("view " + quoted + " -o " + page.string() + " --quiet").code == 0);
  std::ifstream in(page, std::ios::binary);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(html.find(replaced) != std::string::npos);
}

namespace {

// `geode ARGS` with standard output redirected as the shell does (`>/dev/full`, `>&-`) and its
// stderr into `err`: the exit code and everything it said there.
std::pair<int, std::string> run_redirected(const std::string& args, const std::string& redirect,
                                           const fs::path& err) {
  const int status = std::system(
      (std::string(GEODE_CLI_PATH) + " " + args + " " + redirect + " 2>'" + err.string() + "'")
          .c_str());
  std::ifstream in(err);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, std::move(text)};
}

}  // namespace

TEST_CASE("cli conventions: output that cannot be written to standard output fails the run") {
  // `geode check m.exo > report.txt` on a full disk (/dev/full) or with standard output closed
  // lost the report and exited 0.
  TempDir dir;
  const fs::path mesh = dir.path / "m.exo", err = dir.path / "err.txt";
  io::write_exodus(primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; }), mesh);
  const auto run = [&](const std::string& args, const std::string& redirect) {
    return run_redirected(args, redirect, err);
  };
  for (const std::string& args :
       {std::string("template geode3d"), "check " + mesh.string() + " --quiet",
        "dual " + mesh.string() + " --quiet", std::string("formats"), std::string("--help")}) {
    CAPTURE(args);
    CHECK(run(args, ">/dev/null").first == 0);
    const auto [code, line] = run(args, ">/dev/full");
    CHECK(code == 2);
    CHECK(line.find("error: writing standard output failed") != std::string::npos);
    CHECK(run(args, ">&-").first == 2);
  }
}

TEST_CASE("cli conventions: a summary lost on standard output publishes no file") {
  // With standard output lost, conform published its mesh and report and then exited 2 (the
  // summary was printed after them): a run that fails must leave no outputs.
  TempDir dir;
  const fs::path mesh = dir.path / "m.exo", err = dir.path / "err.txt";
  io::write_exodus(primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; }), mesh);
  const fs::path out = dir.path / "out.exo", page = dir.path / "out.html",
                 report = dir.path / "out.json", runs = dir.path / "runs.csv",
                 summary = dir.path / "summary.csv";
  const auto run = [&](const std::string& args, const std::string& redirect) {
    return run_redirected(args, redirect, err);
  };
  const std::string o = " -o " + out.string();
  for (const std::string& args :
       {"demo --model nugget -n 2" + o + " --report " + report.string(),
        "demo --model nugget -n 2 --save-input " + out.string(),
        "template geode3d --format exo --quality" + o,
        "template geode3d --format html --quality -o " + page.string(),
        "dual " + mesh.string() + " --rebuild " + out.string(),
        "study interleave --high 0.8 --low 0.4 --depth 0.5 --radius 0.5 -o " + runs.string() +
            " --summary " + summary.string()}) {
    CAPTURE(args);
    // A closed descriptor fails as a full disk does (the other commands show it): the demos,
    // the slow ones under the sanitizers, once.
    const bool demo = args.starts_with("demo");
    for (const std::string redirect : {">/dev/full", ">&-"}) {
      if (demo && redirect == ">&-") continue;
      CAPTURE(redirect);
      const auto [code, text] = run(args, redirect);
      CHECK(code == 2);
      for (const auto& f : {out, page, report, runs, summary}) CHECK(!fs::exists(f));
      // One line says it, not a second one from the exit path's check.
      const auto at = text.find("writing standard output failed");
      CHECK(text.find("error: writing standard output failed") != std::string::npos);
      CHECK(text.find("writing standard output failed", at + 1) == std::string::npos);
      CHECK(text.find("(nothing written)", at) != std::string::npos);
    }
    const auto [code, text] = run(args, ">/dev/null");
    CHECK(code == 0);
    CHECK((fs::exists(out) || fs::exists(page) || fs::exists(runs)));
    for (const auto& f : {out, page, report, runs, summary}) fs::remove(f);
  }
}

TEST_CASE("cli conventions: closed standard descriptors, symlink loops, long names (a hunt's)") {
  TempDir dir;
  const fs::path mesh = dir.path / "m.exo";
  io::write_exodus(primal::grid_model({2, 2, 2}, 1.0, [](int, int, int) { return false; }), mesh);
  const auto sh = [](const std::string& line) {
    const int status = std::system((std::string(GEODE_CLI_PATH) + " " + line).c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  // Started with 0 and 1 closed, the Exodus reader's pipe got a standard descriptor, which its
  // child covered with /dev/null: the file was blamed ("a corrupt or truncated file?").
  const fs::path report = dir.path / "c.json";
  CHECK(sh("check " + mesh.string() + " -o " + report.string() + " --quiet <&- >&-") == 0);
  CHECK(fs::file_size(report) > 100);
  // A symbolic link loop as the output is refused before the work, as a missing directory is.
  fs::create_symlink("l2.json", dir.path / "l1.json");
  fs::create_symlink("l1.json", dir.path / "l2.json");
  const auto loop = test::geode_cli(
      "check " + mesh.string() + " -o " + (dir.path / "l1.json").string() + " --quiet", true);
  CHECK(loop.code == 2);
  CHECK(loop.out.find("too many levels of symbolic links") != std::string::npos);
  const auto missing =
      test::geode_cli("view " + mesh.string() + " -o /nonexistent-dir/v.html", true);
  CHECK(missing.code == 2);
  CHECK(missing.out.find("does not exist") != std::string::npos);
  CHECK(missing.out.find("read") == std::string::npos);  // no stage ran: refused first
  // A name of 244 bytes is legal (255 at most): its hidden temporary's must be too.
  const fs::path long_name = dir.path / (std::string(240, 'x') + ".vtu");
  CHECK(sh("template geode3d -o " + long_name.string()) == 0);
  CHECK(fs::exists(long_name));
  // Names longer than the system takes: said so (an input was "no such file", an output failed
  // only when its temporary was renamed, a directory "does not exist"), before any work.
  const std::string too_long = (dir.path / (std::string(300, 'y') + ".exo")).string();
  std::string deep = dir.path.string();
  while (deep.size() < 5000) deep += "/" + std::string(200, 'z');
  deep += "/m.exo";
  // A directory of 4,000 bytes (legal) with a name of 240 (legal): the temporary's path passes
  // PATH_MAX (4,096).
  std::string near = dir.path.string();
  while (near.size() < 4000)
    near += "/" + std::string(std::min<std::size_t>(200, 4000 - near.size()), 'w');
  fs::create_directories(near);
  const std::string past = near + "/" + std::string(240, 'v') + ".html";
  for (const std::string& args :
       {"check " + too_long, "check " + deep, "view " + mesh.string() + " -o " + too_long + ".html",
        "view " + mesh.string() + " -o " + deep, "view " + mesh.string() + " -o " + past,
        "arrange " + too_long + ".json"}) {
    CAPTURE(args);
    const auto run = test::geode_cli(args, true);
    CHECK(run.code == 2);
    CHECK((run.out.find("File name too long") != std::string::npos ||
           run.out.find("file name too long") != std::string::npos));
    CHECK(run.out.find(": read ") == std::string::npos);  // refused before reading
  }
}
