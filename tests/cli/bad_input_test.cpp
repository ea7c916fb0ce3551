// Bad input files through the `geode` command, one table row each: the command, the file's
// name and content, the exit code, the words the one-line message must hold; no output file
// may be left, and nothing in a file may run (a Gmsh script in a .msh must not touch its
// marker file). A second table does the same for bad commands (issue 21: invalid results,
// outputs over inputs, links, full devices, misleading diagnoses, the spec reader's bounds),
// also checking that an existing output's bytes are unchanged.
#include <doctest/doctest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "primal/mesh.hpp"
#include "support/cli_run.hpp"

namespace fs = std::filesystem;
using geode::test::geode_cli;
using geode::test::TempDir;

namespace {

// A .msh 4.1 file: the unit hex on tags 1..8 (Gmsh corner order, the same as VTK's) and one tet
// on its x = 1 face with tag 9 at (2, 0, 0); `nodes` and `elements` replace the defaults.
const std::string kNodes = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n2 0 0\n";
const std::string kElements = "3 1 5 1\n1 1 2 3 4 5 6 7 8\n3 1 4 1\n2 2 9 3 6\n";
std::string msh41(const std::string& coordinates = kNodes, const std::string& elements = kElements,
                  const std::string& end = "$EndElements\n") {
  return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
         "$Nodes\n1 9 1 9\n3 1 0 9\n1\n2\n3\n4\n5\n6\n7\n8\n9\n" +
         coordinates + "$EndNodes\n$Elements\n2 2 1 2\n" + elements + end;
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

std::string repeated(const std::string& s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

struct BadInput {
  const char* what;
  std::string command;  // {in}, {out}, {marker}: see substituted
  std::string file;     // the input's name
  std::string content;
  int exit_code;
  std::vector<std::string> words;
};

// {in}, {out} and {marker} replaced by paths in `dir`.
std::string substituted(std::string s, const fs::path& dir, const fs::path& in) {
  for (const auto& [key, path] : {std::pair<std::string, fs::path>{"{in}", in}, {"{out}", dir / "out"}, {"{marker}", dir / "marker"}})
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key)) s.replace(at, key.size(), path.string());
  return s;
}

}  // namespace

TEST_CASE("bad input: refused with one line naming the file and the node or element, nothing written") {
  const std::string script = "SystemCall \"touch {marker}\";\n";
  const std::vector<BadInput> table = {
      {"a Gmsh script in a .msh (conform)", "conform {in} -o {out}.exo", "script.msh", script, 2,
       {"script.msh", "not in Gmsh .msh format", "scripts are not read"}},
      {"a Gmsh script in a .msh (dual)", "dual {in} -o {out}.txt", "script.msh", script, 2,
       {"script.msh", "not in Gmsh .msh format"}},
      {"a script after a valid header line", "conform {in} -o {out}.exo", "header.msh",
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n" + script, 2, {"header.msh", "line 4", "expected a section"}},
      {"text in a .vtu (dual)", "dual {in}", "text.vtu", "hello\n", 2, {"text.vtu", "not in VTK XML .vtu format"}},
      {"text in a .exo", "conform {in} -o {out}.exo", "text.exo", "hello\n", 2,
       {"text.exo", "not in Exodus II format", "no netCDF or HDF5 signature"}},
      {"an empty .vtk", "dual {in}", "empty.vtk", "", 2, {"empty.vtk", "the file is empty"}},
      {"VTK content named .msh", "conform {in} -o {out}.exo", "vtk.msh",
       "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n", 2, {"vtk.msh", "its content is VTK XML"}},
      {"an unknown extension", "conform {in} -o {out}.exo", "mesh.obj", "v 0 0 0\n", 2, {"mesh.obj", "unknown input format"}},
      {"a NaN coordinate", "conform {in} -o {out}.exo", "nan.msh", msh41(replaced(kNodes, "1 1 0\n", "1 nan 0\n")), 2,
       {"nan.msh", "node 3 (1, nan, 0)", "non-finite"}},
      {"an infinite coordinate (dual)", "dual {in}", "inf.msh", msh41(replaced(kNodes, "0 1 1\n", "0 1 1e999\n")), 2,
       {"inf.msh", "node 8 (0, 1, inf)", "non-finite"}},
      {"an element referring to a missing node", "conform {in} -o {out}.exo", "missing.msh",
       msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 99 3 6")), 2,
       {"missing.msh", "element 2", "node 99", "not in $Nodes"}},
      {"no $EndElements", "conform {in} -o {out}.exo", "truncated.msh", msh41(kNodes, kElements, ""), 2,
       {"truncated.msh", "$Elements has no $EndElements"}},
      {"a section cut short", "dual {in}", "short.msh", msh41(kNodes, replaced(kElements, "2 2 9 3 6\n", "2 2 9\n")), 2,
       {"short.msh", "line 32", "expected an element's node tag, found $EndElements"}},
      {"an inverted hex (top and bottom swapped)", "conform {in} -o {out}.exo", "inverted.msh",
       msh41(kNodes, replaced(kElements, "1 1 2 3 4 5 6 7 8", "1 5 6 7 8 1 2 3 4")), 2,
       {"inverted.msh", "hex 1 (centre (0.5, 0.5, 0.5)) is inverted at its corner node 5 (0, 0, 1)"}},
      {"an inverted tet", "conform {in} -o {out}.exo", "tet.msh", msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 3 9 6")),
       2, {"tet.msh", "tet 2 (centre (1.25, 0.25, 0.25)) is inverted", "nodes 2 3 9 6"}},
      {"a flat tet", "conform {in} -o {out}.exo", "flat.msh", msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 9 3 1")),
       2, {"flat.msh", "tet 2", "is flat"}},
      {"a quadratic tet", "conform {in} -o {out}.exo", "tet10.msh", msh41(kNodes, replaced(kElements, "3 1 4 1\n2 2 9 3 6", "3 1 11 1\n2 2 9 3 6 7 8 1 4 5 1")),
       2, {"tet10.msh", "element 2", "10-node", "not supported"}},
      {"MSH version 3", "conform {in} -o {out}.exo", "v3.msh", replaced(msh41(), "4.1 0 8", "3.0 0 8"), 2,
       {"v3.msh", "line 2", "MSH version 3.0 is not read"}},
      {"a node count larger than the file", "conform {in} -o {out}.exo", "count.msh", replaced(msh41(), "1 9 1 9\n", "1 999999999 1 9\n"), 2,
       {"count.msh", "more than the rest of the file can hold"}},
      {"a legacy .vtk with a NaN point", "dual {in}", "nan.vtk",
       "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 nan 0\n", 2,
       {"nan.vtk", "point 0", "non-finite"}},
      // File formats (branch ioreliab, issue 21): hostile structure refused before it costs.
      {"a .vtu of 30,000 nested tags (once a stack overflow)", "check {in}", "nested.vtu",
       "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n" + repeated("<a>", 30000) + repeated("</a>", 30000) +
           "</VTKFile>\n",
       2, {"nested.vtu", "nested.vtu:3:", "nested more than 64 deep"}},
      {"$PartitionedEntities in a .msh 2.2", "conform {in} -o {out}.exo", "part22.msh",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PartitionedEntities\n1\n0\n0 0 0 0\n$EndPartitionedEntities\n", 2,
       {"part22.msh", "line 4", "$PartitionedEntities in a version 2 file"}},
      {"a partitioned entity count larger than the file", "conform {in} -o {out}.exo", "partcount.msh",
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PartitionedEntities\n2\n0\n0 0 0 99999999\n$EndPartitionedEntities\n", 2,
       {"partcount.msh", "a partitioned entity count 99999999 is more than the rest of the file can hold"}},
  };
  for (const BadInput& row : table) {
    CAPTURE(row.what);
    TempDir dir;
    const fs::path in = dir.path / row.file;
    {
      std::ofstream f(in, std::ios::binary);
      f << substituted(row.content, dir.path, in);
    }
    const std::string cmd = substituted(row.command, dir.path, in);
    const auto run = geode_cli(cmd, true);
    CAPTURE(cmd);
    CAPTURE(run.out);
    CHECK(run.code == row.exit_code);
    CHECK(std::count(run.out.begin(), run.out.end(), '\n') == 1);
    for (const std::string& word : row.words) CHECK_MESSAGE(run.out.find(word) != std::string::npos, word);
    CHECK_MESSAGE(dir.entries() == 1, "an output or marker file was left");  // the input alone
    CHECK_FALSE(fs::exists(dir.path / "marker"));
  }
}

namespace {

// ---- Command-level cases (issue 21): each run in a fresh directory holding `files`; after it,
// the exit code and the words of the message, no file but those (and `outputs` when it
// succeeds), and every file's bytes as they were (an existing output is never touched by a
// failed run).

struct CommandCase {
  std::string what;
  std::string command;  // {dir} is the run's directory, {specs} notebooks-data/specs
  std::vector<std::pair<std::string, std::string>> files;  // name, content
  int exit_code;
  std::vector<std::string> words;
  std::vector<std::pair<std::string, std::string>> links = {};  // name, target ({dir} substituted)
};

std::string with_dirs(std::string s, const fs::path& dir) {
  const std::string specs = std::string(GEODE_SOURCE_DIR) + "/notebooks-data/specs";
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"{dir}", dir.string()}, {"{specs}", specs}})
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key)) s.replace(at, key.size(), value);
  return s;
}

std::string file_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// A .msh 4.1 file of the unit hex (tags 1..8) with four tets fanning over its x = 1 face
// (nodes 2 3 7 6) around a centre node 9 at x = 1 + offset, to an apex 10 at (2, 0.5, 0.5);
// each tet oriented positively.
std::string fan_msh(double offset) {
  const std::vector<geode::primal::Point> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1},
                                               {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {1 + offset, 0.5, 0.5},
                                               {2, 0.5, 0.5}};
  std::ostringstream s;
  s << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 10 1 10\n3 1 0 10\n";
  for (int i = 1; i <= 10; ++i) s << i << "\n";
  for (const auto& q : p) s << q.x() << " " << q.y() << " " << q.z() << "\n";
  s << "$EndNodes\n$Elements\n2 5 1 5\n3 1 5 1\n1 1 2 3 4 5 6 7 8\n3 1 4 4\n";
  const int quad[4] = {2, 3, 7, 6};
  for (int i = 0; i < 4; ++i) {
    std::array<int, 4> t{quad[i], quad[(i + 1) % 4], 9, 10};
    const auto at = [&](int k) { return p[static_cast<std::size_t>(t[static_cast<std::size_t>(k)] - 1)]; };
    if ((at(1) - at(0)).cross(at(2) - at(0)).dot(at(3) - at(0)) < 0) std::swap(t[0], t[1]);
    s << 2 + i << " " << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
  }
  s << "$EndElements\n";
  return s.str();
}

// A spec of `n` sheets, or one sheet of `depth` nested offsets.
std::string planes_spec(int n, bool same) {
  std::string s = "{\"dim\": 3, \"domain\": {\"box\": [[0, 0, 0], [1, 1, 1]]}, \"sheets\": [";
  for (int i = 0; i < n; ++i) {
    const double x = same ? 0.5 : (i + 0.5) / n;
    s += std::string(i ? ", " : "") + "{\"name\": \"p" + std::to_string(i) + "\", \"plane\": {\"point\": [" +
         std::to_string(x) + ", 0.5, 0.5], \"normal\": [1, 0, 0]}}";
  }
  return s + "]}";
}
std::string nested_spec(int depth) {
  std::string shape = "{\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.3}}";
  std::string open, close;
  for (int i = 0; i < depth; ++i) open += "{\"offset\": {\"by\": 0, \"of\": ", close += "}}";
  return "{\"dim\": 3, \"domain\": {\"box\": [[0, 0, 0], [1, 1, 1]]}, \"sheets\": [{\"name\": \"s\", " +
         open.substr(1) + shape + close + "]}";
}

}  // namespace

TEST_CASE("bad commands: exit code, one message saying what is wrong, nothing left behind, outputs untouched") {
  const std::string old = "an existing output\n";
  const std::string hex_and_tet = msh41();
  const std::vector<CommandCase> table = {
      // Invalid results are refused, not written (exit 4), on every command that writes a mesh.
      {"template --no-smooth: the dual's first guess", "template geode3d --no-smooth -o {dir}/out.vtu",
       {{"out.vtu", old}}, 4, {"geode3d", "hexes inverted", "nothing written", "--write-invalid"}},
      {"template --no-smooth to standard output", "template geode3d --no-smooth", {}, 4,
       {"hexes inverted", "nothing written"}},
      {"template geode4tri --no-fixup: pinched corners", "template geode4tri --no-fixup --format json -o {dir}/out.json",
       {{"out.json", old}}, 4, {"geode4tri", "is invalid", "nothing written"}},
      {"template --slide: positive corners, overlapping cells (the V1 class)",
       "template geode3d --slide --high-roof 0.55 --low-roof 0.5 --dome-depth 0.97 --dome-radius 0.8 -o {dir}/out.vtu",
       {{"out.vtu", old}}, 4, {"is invalid", "nodes covered more than once (overlapping hexes)", "nothing written"}},
      {"dual --rebuild of the four-triangle template: the rebuilt first guess is inverted",
       "dual {dir}/geode4tri.vtu --rebuild {dir}/out.vtu", {{"out.vtu", old}}, 4,
       {"geode4tri.vtu: the rebuilt mesh", "of 56 hexes inverted", "nothing written"}},
      {"arrange without smoothing: the first guess is inverted", "arrange {specs}/geode3d.json -o {dir}/out.vtu",
       {{"out.vtu", old}}, 4, {"geode3d", "inverted", "nothing written"}},
      // Four-triangle interfaces are checked geometrically, naming the file's node ids.
      {"a fan centre 0.2 off the hex face (a gap)", "conform {dir}/gap.msh -o {dir}/out.exo", {{"gap.msh", fan_msh(0.2)}},
       3, {"gap.msh", "four triangles around node 9", "outside the hex face (a gap between the parts)"}},
      {"a fan centre 0.2 inside the hex (an overlap)", "conform {dir}/overlap.msh -o {dir}/out.exo",
       {{"overlap.msh", fan_msh(-0.2)}}, 3, {"overlap.msh", "node 9", "inside the hex (the parts overlap)"}},
      // Process hygiene: outputs never replace inputs; links are written through; a full device is an error.
      {"conform writing over its input", "conform {dir}/same.msh -o {dir}/same.msh", {{"same.msh", hex_and_tet}}, 2,
       {"same.msh", "is the input file", "--force"}},
      {"dual rebuilding over its input", "dual {dir}/in.msh --rebuild {dir}/in.msh", {{"in.msh", hex_and_tet}}, 2,
       {"in.msh", "is the input file"}},
      {"-o a link to /dev/full", "template geode3d -o {dir}/full.vtu", {}, 2,
       {"full.vtu", "No space left on device"}, {{"full.vtu", "/dev/full"}}},
      // Misleading diagnoses: say what is wrong.
      {"a duplicated hex", "conform {dir}/dup.msh -o {dir}/out.exo",
       {{"dup.msh", replaced(replaced(msh41(), "2 2 1 2\n", "2 3 1 3\n"), "3 1 5 1\n1 1 2 3 4 5 6 7 8\n",
                             "3 1 5 2\n1 1 2 3 4 5 6 7 8\n3 1 2 3 4 5 6 7 8\n")}},
       3, {"dup.msh", "hex 3", "same nodes as hex 1", "duplicated element"}},
      {"--merge-tolerance longer than the elements", "conform {dir}/in.msh -o {dir}/out.exo --merge-tolerance 10",
       {{"in.msh", hex_and_tet}}, 2, {"in.msh", "--merge-tolerance 10", "shortest element edge"}},
      // Bounds of the spec reader and the study.
      {"20,000 nested offsets", "arrange {dir}/deep.json", {{"deep.json", nested_spec(20000)}}, 2,
       {"deep.json", "nested deeper than 64 levels"}},
      {"shapes nested 20 deep", "arrange {dir}/nested.json", {{"nested.json", nested_spec(20)}}, 2,
       {"nested.json", "nested deeper than 16 levels"}},
      {"300 sheets", "arrange {dir}/many.json", {{"many.json", planes_spec(300, false)}}, 2,
       {"many.json", "300 sheets; at most 256"}},
      {"identical planes", "arrange {dir}/same.json", {{"same.json", planes_spec(3, true)}}, 2,
       {"same.json", "sheets[1] (p1)", "the same surface as sheets[0] (p0)", "coincident"}},
      {"a sweep of 10,000 x 10,000 points",
       "study interleave --spec {specs}/geode3d.json --sweep push.high_roof=0.7:0.9:10000 "
       "--sweep push.dome_radius=0.3:0.7:10000 -o {dir}/out.csv",
       {}, 2, {"geode3d.json", "10000 x 10000", "at most 20000"}},
  };
  for (const CommandCase& row : table) {
    CAPTURE(row.what);
    TempDir dir;
    for (const auto& [name, content] : row.files) {
      std::ofstream f(dir.path / name, std::ios::binary);
      f << content;
    }
    for (const auto& [name, target] : row.links) fs::create_symlink(with_dirs(target, dir.path), dir.path / name);
    if (row.command.find("{dir}/geode4tri.vtu") != std::string::npos)
      REQUIRE(geode_cli("template geode4tri -o " + (dir.path / "geode4tri.vtu").string()).code == 0);
    const std::size_t before = dir.entries();
    const std::string cmd = with_dirs(row.command, dir.path);
    CAPTURE(cmd);
    const auto run = geode_cli(cmd, true);
    CAPTURE(run.out);
    CHECK(run.code == row.exit_code);
    for (const std::string& word : row.words) CHECK_MESSAGE(run.out.find(word) != std::string::npos, word);
    CHECK_MESSAGE(dir.entries() == before, "a file (a temporary?) was left behind");
    for (const auto& [name, content] : row.files) CHECK_MESSAGE(file_bytes(dir.path / name) == content, name);
    for (const auto& [name, target] : row.links) CHECK(fs::is_symlink(dir.path / name));
  }
}

TEST_CASE("outputs: a symbolic link is written through, and stays a link") {
  TempDir dir;
  const fs::path target = dir.path / "target.csv", link = dir.path / "link.csv";
  {
    std::ofstream f(target);
    f << "old\n";
  }
  fs::create_symlink(target, link);
  const auto r = geode_cli("template geode2d -o " + link.string(), true);
  CAPTURE(r.out);
  REQUIRE(r.code == 0);
  CHECK(fs::is_symlink(link));
  CHECK(file_bytes(target).rfind("node,x,y\n", 0) == 0);  // the template's node table
  CHECK(dir.entries() == 2);
}

TEST_CASE("outputs: a signal removes the hidden temporaries, then ends the process by that signal") {
  // The mechanism every writer goes through (io/atomic_file.hpp), in a child process: a
  // temporary registered and half written when SIGTERM (then SIGINT) arrives.
  for (const int sig : {SIGTERM, SIGINT}) {
    CAPTURE(sig);
    TempDir dir;
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      geode::io::install_signal_cleanup();
      const fs::path temp = geode::io::create_temporary(geode::io::resolve_output(dir.path / "out.exo"), ".exo");
      std::ofstream(temp) << "half a mesh";
      ::raise(sig);
      ::_exit(0);  // not reached
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == sig);
    CHECK(dir.entries() == 0);
  }
}
