// Our .msh writer (io/gmsh_write.cpp) against libgmsh's on the same large model: wall time
// and peak memory of each, every version and encoding, each in a child process (fork) so that
// peak RSS is the writer's own. libgmsh's run builds its model through the API (discrete
// entities, nodes, elements, physical groups: what the old writer did) and calls gmsh::write;
// both times include building what is written. File sizes and a read-back of every file by our
// reader (element and node counts) are printed, so a writer that did nothing cannot look fast.
//
// Usage: bench_msh_writer [n] [repeats]   (n^3 hexes beside n^3 * 6 / 2 tets; default 60)
#include <gmsh.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "child_run.hpp"

#include <geode/demo/gmsh_session.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;

namespace {

void gmsh_write(const Model& model, const fs::path& file, bool binary, bool v22) {
  demo::GmshSession session;
  gmsh::model::add("bench");
  std::vector<std::size_t> tags(model.points.size());
  std::vector<double> xyz;
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    tags[i] = i + 1;
    xyz.insert(xyz.end(), {model.points[i].x(), model.points[i].y(), model.points[i].z()});
  }
  gmsh::model::addDiscreteEntity(3, 1);
  gmsh::model::addDiscreteEntity(3, 2);
  gmsh::model::mesh::addNodes(3, 1, tags, xyz);
  std::size_t next = 1;
  for (int b : {1, 2}) {
    std::vector<std::size_t> et, en;
    for (std::size_t h = 0; h < model.hexes.size(); ++h)
      if (block_of(model, {ElementKind::kHex, index_cast(h)}) == b) {
        et.push_back(next++);
        for (Index v : model.hexes[h]) en.push_back(index_cast<std::size_t>(v) + 1);
      }
    std::vector<std::size_t> tt, tn;
    for (std::size_t t = 0; t < model.tets.size(); ++t)
      if (block_of(model, {ElementKind::kTet, index_cast(t)}) == b) {
        tt.push_back(next++);
        for (Index v : model.tets[t]) tn.push_back(index_cast<std::size_t>(v) + 1);
      }
    if (!et.empty()) gmsh::model::mesh::addElementsByType(b, 5, et, en);
    if (!tt.empty()) gmsh::model::mesh::addElementsByType(b, 4, tt, tn);
    gmsh::model::addPhysicalGroup(3, {b}, b);
  }
  gmsh::option::setNumber("Mesh.MshFileVersion", v22 ? 2.2 : 4.1);
  gmsh::option::setNumber("Mesh.Binary", binary ? 1 : 0);
  gmsh::option::setNumber("Mesh.SaveAll", 1);
  gmsh::write(file.string());
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 60;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 1;
  const Model model = grid_model({2 * n, n, n}, 1.0 / n, [n](int i, int, int) { return i >= n; });
  const fs::path dir =
      fs::temp_directory_path() / ("geode-bench-msh-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::printf("model: %zu nodes, %zu hexes, %zu tets; the parent holds it (peak RSS includes it)\n",
              model.points.size(), model.hexes.size(), model.tets.size());
  {
    const bench::ChildRun r = bench::run_in_child([] {});
    std::printf("%-28s %8.3f s %8.1f MiB\n", "(nothing: the baseline)", r.seconds, r.peak_mib);
  }
  struct Case {
    const char* name;
    bool binary, v22;
  };
  for (const Case& c : {Case{"4.1 ASCII", false, false}, Case{"4.1 binary", true, false},
                        Case{"2.2 ASCII", false, true}, Case{"2.2 binary", true, true}}) {
    for (int who = 0; who < 2; ++who) {
      const fs::path file = dir / (std::string(who ? "gmsh-" : "geode-") + (c.binary ? "b" : "a") +
                                   (c.v22 ? "22" : "41") + ".msh");
      double best = 1e30, mem = 0;
      for (int i = 0; i < repeats; ++i) {
        const bench::ChildRun r = bench::run_in_child([&] {
          if (who == 0)
            io::write_gmsh(model, file, c.binary ? io::GmshFormat::kBinary : io::GmshFormat::kAscii,
                           c.v22 ? io::GmshVersion::k22 : io::GmshVersion::k41);
          else
            gmsh_write(model, file, c.binary, c.v22);
        });
        if (r.seconds < best) best = r.seconds, mem = r.peak_mib;
      }
      const Model back = io::read_gmsh(file, {false, {}});
      std::printf(
          "%-10s %-7s %8.3f s %8.1f MiB peak %8.1f MiB file, read back %zu hexes %zu tets\n",
          c.name, who ? "libgmsh" : "geode", best, mem,
          static_cast<double>(fs::file_size(file)) / (1 << 20), back.hexes.size(),
          back.tets.size());
    }
  }
  fs::remove_all(dir);
  return 0;
}
