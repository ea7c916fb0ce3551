// Bad input files through the `geode` command, one table row each: the command, the file's
// name and content, the exit code, the words the one-line message must hold; no output file
// may be left, and nothing in a file may run (a Gmsh script in a .msh must not touch its
// marker file).
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "support/cli_run.hpp"

namespace fs = std::filesystem;
using geode::test::geode_cli;
using geode::test::TempDir;

namespace {

using geode::test::slurp;

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
  for (const auto& [key, path] : {std::pair<std::string, fs::path>{"{in}", in},
                                  {"{out}", dir / "out"},
                                  {"{marker}", dir / "marker"}})
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key))
      s.replace(at, key.size(), path.string());
  return s;
}

}  // namespace

TEST_CASE(
    "bad input: refused with one line naming the file and the node or element, nothing written") {
  const std::string script = "SystemCall \"touch {marker}\";\n";
  const std::vector<BadInput> table = {
      {"a Gmsh script in a .msh (conform)",
       "conform {in} -o {out}.exo",
       "script.msh",
       script,
       2,
       {"script.msh", "not in Gmsh .msh format", "scripts are not read"}},
      {"a Gmsh script in a .msh (dual)",
       "dual {in} -o {out}.txt",
       "script.msh",
       script,
       2,
       {"script.msh", "not in Gmsh .msh format"}},
      {"a script after a valid header line",
       "conform {in} -o {out}.exo",
       "header.msh",
       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n" + script,
       2,
       {"header.msh", "line 4", "expected a section"}},
      {"text in a .vtu (dual)",
       "dual {in}",
       "text.vtu",
       "hello\n",
       2,
       {"text.vtu", "not in VTK XML .vtu format"}},
      {"text in a .exo",
       "conform {in} -o {out}.exo",
       "text.exo",
       "hello\n",
       2,
       {"text.exo", "not in Exodus II format", "no netCDF or HDF5 signature"}},
      {"an empty .vtk", "dual {in}", "empty.vtk", "", 2, {"empty.vtk", "the file is empty"}},
      {"surfaces only (a 2D Gmsh mesh) given to check",
       "check {in}",
       "surface.msh",
       "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
       "$EndNodes\n$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n",
       2,
       {"surface.msh", "holds no hexes (no volume element at all)"}},
      {"VTK content named .msh",
       "conform {in} -o {out}.exo",
       "vtk.msh",
       "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n",
       2,
       {"vtk.msh", "its content is VTK XML"}},
      {"an unknown extension",
       "conform {in} -o {out}.exo",
       "mesh.obj",
       "v 0 0 0\n",
       2,
       {"mesh.obj", "unknown input format"}},
      {"a NaN coordinate",
       "conform {in} -o {out}.exo",
       "nan.msh",
       msh41(replaced(kNodes, "1 1 0\n", "1 nan 0\n")),
       2,
       {"nan.msh", "node 3 (1, nan, 0)", "non-finite"}},
      {"an infinite coordinate (dual)",
       "dual {in}",
       "inf.msh",
       msh41(replaced(kNodes, "0 1 1\n", "0 1 1e999\n")),
       2,
       {"inf.msh", "node 8 (0, 1, inf)", "non-finite"}},
      {"an element referring to a missing node",
       "conform {in} -o {out}.exo",
       "missing.msh",
       msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 99 3 6")),
       2,
       {"missing.msh", "element 2", "node 99", "not in $Nodes"}},
      {"no $EndElements",
       "conform {in} -o {out}.exo",
       "truncated.msh",
       msh41(kNodes, kElements, ""),
       2,
       {"truncated.msh", "$Elements has no $EndElements"}},
      {"a section cut short",
       "dual {in}",
       "short.msh",
       msh41(kNodes, replaced(kElements, "2 2 9 3 6\n", "2 2 9\n")),
       2,
       {"short.msh", "line 32", "expected an element's node tag, found $EndElements"}},
      {"two positive tets folded back into the hex they meet (read-time covering check)",
       "conform {in} -o {out}.exo",
       "folded.msh",
       replaced(msh41(replaced(kNodes, "2 0 0\n", "0.5 0.5 0.5\n"),
                      "3 1 5 1\n1 1 2 3 4 5 6 7 8\n3 1 4 2\n2 3 2 7 9\n3 7 2 6 9\n"),
                "2 2 1 2\n", "2 3 1 3\n"),
       2,
       {"folded.msh", "hex 1", "tet 2", "same side", "folds"}},
      {"an inverted hex (top and bottom swapped)",
       "conform {in} -o {out}.exo",
       "inverted.msh",
       msh41(kNodes, replaced(kElements, "1 1 2 3 4 5 6 7 8", "1 5 6 7 8 1 2 3 4")),
       2,
       {"inverted.msh",
        "hex 1 (centre (0.5, 0.5, 0.5)) is inverted at its corner node 5 (0, 0, 1)"}},
      {"an inverted tet",
       "conform {in} -o {out}.exo",
       "tet.msh",
       msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 3 9 6")),
       2,
       {"tet.msh", "tet 2 (centre (1.25, 0.25, 0.25)) is inverted", "nodes 2 3 9 6"}},
      {"a flat tet",
       "conform {in} -o {out}.exo",
       "flat.msh",
       msh41(kNodes, replaced(kElements, "2 2 9 3 6", "2 2 9 3 1")),
       2,
       {"flat.msh", "tet 2", "is flat"}},
      {"a quadratic tet",
       "conform {in} -o {out}.exo",
       "tet10.msh",
       msh41(kNodes, replaced(kElements, "3 1 4 1\n2 2 9 3 6", "3 1 11 1\n2 2 9 3 6 1 4 5 7 8 2")),
       2,
       {"tet10.msh", "element 2", "10-node tetrahedron", "not supported"}},
      {"MSH version 3",
       "conform {in} -o {out}.exo",
       "v3.msh",
       replaced(msh41(), "4.1 0 8", "3.0 0 8"),
       2,
       {"v3.msh", "line 2", "MSH version 3.0 is not read"}},
      {"a node count larger than the file",
       "conform {in} -o {out}.exo",
       "count.msh",
       replaced(msh41(), "1 9 1 9\n", "1 999999999 1 9\n"),
       2,
       {"count.msh", "more than the rest of the file can hold"}},
      {"a corrupt netCDF-4 .exo on which libhdf5 crashes (read in a child process)",
       "conform {in} -o {out}.exo",
       "segv.exo",
       slurp(fs::path(GEODE_SOURCE_DIR) / "tests/fuzz/regressions/exo-netcdf4-hdf5-segv.exo"),
       2,
       {"segv.exo", "reading the netCDF-4 (HDF5) file failed"}},
      {"a truncated netCDF-4 .exo",
       "conform {in} -o {out}.exo",
       "short.exo",
       slurp(fs::path(GEODE_SOURCE_DIR) / "tests/fuzz/corpus/exo/meshio-netcdf4.exo")
           .substr(0, 9000),
       2,
       {"short.exo", "not a consistent netCDF-4 (HDF5) file", "the file is truncated"}},
      {"a classic .exo whose data goes past its end",
       "conform {in} -o {out}.exo",
       "cut.exo",
       slurp(fs::path(GEODE_SOURCE_DIR) / "tests/fuzz/corpus/exo/classic.exo").substr(0, 1300),
       2,
       {"cut.exo", "not a consistent netCDF classic file", "past the end"}},
      {"a legacy .vtk with a NaN point",
       "dual {in}",
       "nan.vtk",
       "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 double\n0 nan "
       "0\n",
       2,
       {"nan.vtk", "point 0", "non-finite"}},
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
    for (const std::string& word : row.words)
      CHECK_MESSAGE(run.out.find(word) != std::string::npos, word);
    CHECK_MESSAGE(dir.entries() == 1, "an output or marker file was left");  // the input alone
    CHECK_FALSE(fs::exists(dir.path / "marker"));
  }
}
