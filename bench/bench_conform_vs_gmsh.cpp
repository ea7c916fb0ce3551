// Whole-process time and peak memory of `geode conform` with its default options next to
// gmsh's all-hex subdivision of the same tet part (the Speed and memory case).
//
// The model is demo::demo_delaunay_block(n): structured hexes [0,1]^3 (n^3) beside a Gmsh
// Delaunay tet box [1,2] x [0,1]^2 with alternating interface diagonals (n = 26: about 200k
// tets). It is written to a temporary directory twice, as
// binary .msh v4.1: the whole model (geode's input) and its tet part alone, compacted (gmsh's
// input). Then, each as a child process timed from fork to wait4 (wall time; peak RSS from the
// child's rusage):
//   gmsh subdivide        gmsh -nt 1 sub.geo -   with  Merge; Mesh.SubdivisionAlgorithm = 2;
//                         RefineMesh;   (read + subdivide, nothing written)
//   gmsh subdivide+save   the same, then Mesh.Binary = 1; Save "gmsh.msh";
//   geode conform         geode conform model.msh -o geode.exo --report r.json --quiet
//                         (defaults: read, interface, buffer layer, dice, templates, local
//                         smoothing, local verification, scaled Jacobian per block, write
//                         Exodus)
//   geode --smooth none   the same without smoothing
//   floor                 bench_floor model.msh floor.exo: read, dice (hexes 8, tets 4, nodes
//                         shared through per-node tables), write Exodus; one thread, nothing else
//   geode --threads 1     the defaults on one thread (the 2-core speed-up)
//   geode --verify full   the defaults with the whole output verified (conform.hpp's
//                         ConformVerify; the default is local)
//   geode -o .msh/.vtu/.vtk  the defaults writing every other output format (against .exo);
//                         .msh also with --msh-encoding binary
// Each row prints wall and CPU seconds (user + system, from rusage: on a shared machine the CPU
// ratio is the steadier one) and the ratios to gmsh subdivide and to the floor.
// The local smoothing's CPU milliseconds per buffer hex come from geode's report (its
// smoothing stage alone); the wall-time difference of the two runs is printed beside it.
// Every child runs `repeats` times; the fastest run is shown (the machine is shared). Output hex
// counts are read back (gmsh's file through read_gmsh, geode's from its report), so a child that
// did nothing cannot look fast.
//
// Hybrid mode (bench_conform_vs_gmsh hybrid [n] [repeats] [geode]): the model is
// demo::demo_hexdominant(n), all four cell kinds side by side (two transfinite hex boxes, a
// Delaunay tet box with Gmsh's pyramids on the quads it meets, wedge layers extruded off it; n
// default 32: 189k tets, the hybrid-mesh issue's ~200k, which conforms once the default tet
// relaxation has moved a sliver by the hex box's edge (with --relax none no buffer layer fits
// there, exit 3); 28 has 126k tets; at 30 Gmsh's mesh holds a tet twice and at 34 a tet folds
// over its neighbour, which the read-time check refuses),
// written as binary .msh 4.1. Gmsh's side runs through the libgmsh API in
// a fresh process (this program re-executed: gmsh::open, Mesh.SubdivisionAlgorithm = 2,
// gmsh::model::mesh::refine, gmsh::write binary .msh); geode's is `geode conform model.msh -o
// geode.msh --quiet`. Both outputs are read back and judged alike (check_validity, the minimum
// scaled Jacobian, the hex count); wall time and peak RSS per child.
//
// Usage: bench_conform_vs_gmsh [n] [repeats] [geode-executable]
//   n default 26, repeats default 1, geode default: `geode` next to this program; gmsh is
//   /usr/bin/gmsh unless GMSH is set in the environment; GEODE_BENCH_KEEP set keeps the
//   temporary directory (inputs, outputs, logs). Exit 0 when every child succeeded.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <gmsh.h>

#include "child_run.hpp"

#include <geode/demo/demo_models.hpp>
#include <geode/io/exodus.hpp>
#include <geode/io/gmsh.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/validity.hpp>

namespace fs = std::filesystem;
namespace gp = geode::primal;

namespace {

using Run = geode::bench::ChildRun;

// fork + execv `argv`, stdout and stderr to `log`; wall time from fork to wait4.
Run run_child(const std::vector<std::string>& argv, const fs::path& log) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::fflush(nullptr);
  // Every run starts with no write pending: the files an earlier run left unsynced (gmsh and
  // the floor do not sync theirs) would otherwise be written back during this one, and in the
  // sync of geode's output (ext4 commits them together), by up to 0.2 s on this machine.
  ::sync();
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    std::perror("bench_conform_vs_gmsh: fork");
    std::exit(2);
  }
  if (pid == 0) {
    if (!std::freopen(log.c_str(), "w", stdout) || !std::freopen(log.c_str(), "a", stderr))
      _exit(126);
    execv(args[0], args.data());
    std::perror("execv");
    _exit(127);
  }
  return geode::bench::wait_child(pid, t0);
}

Run best_of(int repeats, const std::vector<std::string>& argv, const fs::path& log,
            const char* what) {
  Run best;
  for (int i = 0; i < repeats; ++i) {
    const Run r = run_child(argv, log);
    if (r.status != 0) {
      std::fprintf(stderr, "bench_conform_vs_gmsh: %s failed (wait status %d), see %s\n", what,
                   r.status, log.c_str());
      std::exit(1);
    }
    if (i == 0 || r.seconds < best.seconds) best = r;
  }
  return best;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream os(path);
  os << text;
  if (!os) {
    std::fprintf(stderr, "bench_conform_vs_gmsh: cannot write %s\n", path.c_str());
    std::exit(2);
  }
}

// The tet part alone with only the nodes it uses, in one block.
gp::Model tet_model(const gp::Model& m) {
  gp::Model t;
  std::vector<gp::Index> renum(m.points.size(), gp::kInvalidIndex);
  for (const auto& tet : m.tets) {
    std::array<gp::Index, 4> o{};
    for (int c = 0; c < 4; ++c) {
      gp::Index& r = renum[geode::primal::index_cast<std::size_t>(
          tet[geode::primal::index_cast<std::size_t>(c)])];
      if (r == gp::kInvalidIndex) {
        r = static_cast<gp::Index>(t.points.size());
        t.points.push_back(m.points[geode::primal::index_cast<std::size_t>(
            tet[geode::primal::index_cast<std::size_t>(c)])]);
      }
      o[geode::primal::index_cast<std::size_t>(c)] = r;
    }
    t.tets.push_back(o);
  }
  t.tet_block.assign(t.tets.size(), 1);
  return t;
}

void print_row(const char* what, const Run& r, std::size_t hexes, const Run& reference,
               const Run& floor) {
  std::printf(
      "%-22s %7.2f s %7.2f s CPU %8.1f MiB %9zu hexes %5.0f B/hex   x gmsh %.2f  x floor %.2f (CPU "
      "%.2f)\n",
      what, r.seconds, r.cpu_seconds, r.peak_mib, hexes, r.peak_mib * 1048576.0 / hexes,
      r.seconds / reference.seconds, r.seconds / floor.seconds, r.cpu_seconds / floor.cpu_seconds);
}

// The Gmsh side of the hybrid mode, in this process (re-executed as a child): libgmsh reads
// `in`, subdivides every element into hexes (Mesh.SubdivisionAlgorithm = 2, RefineMesh) and
// writes `out` as binary .msh.
int gmsh_refine(const char* in, const char* out) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.NumThreads", 1);
  gmsh::open(in);
  gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 2);
  gmsh::model::mesh::refine();
  gmsh::option::setNumber("Mesh.Binary", 1);
  gmsh::write(out);
  gmsh::finalize();
  return 0;
}

// An output read back without the reader's geometry checks (Gmsh's may hold inverted hexes)
// and judged as every geode output is.
struct Judged {
  std::size_t hexes = 0, other_cells = 0, inverted = 0;
  bool valid = false;
  double min_sj = 0.0;
};

Judged judge(const fs::path& path) {
  gp::ReadOptions o;
  o.check_geometry = false;
  const gp::Model m = geode::io::read_gmsh(path, o);
  Judged j;
  j.hexes = m.hexes.size();
  j.other_cells = m.tets.size() + m.pyramids.size() + m.wedges.size();
  const gp::HexMesh mesh = gp::hex_part(m);
  const gp::HexValidityReport v = gp::check_validity(mesh);
  j.valid = v.ok() && j.other_cells == 0;
  j.inverted = v.inverted_hexes.size();
  j.min_sj = gp::min_scaled_jacobian(mesh);
  return j;
}

int hybrid_bench(int n, int repeats, const std::string& geode, const fs::path& dir) {
  const auto t0 = std::chrono::steady_clock::now();
  const gp::Model model = geode::demo::demo_hexdominant(n);
  const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  geode::io::write_gmsh(model, dir / "model.msh", geode::io::GmshFormat::kBinary);
  std::printf(
      "hybrid n %d: %zu hexes, %zu tets, %zu pyramids, %zu wedges (%zu nodes; built in %.1f s); "
      "input in %s\n",
      n, model.hexes.size(), model.tets.size(), model.pyramids.size(), model.wedges.size(),
      model.points.size(), build, dir.c_str());
  const std::string self = fs::canonical("/proc/self/exe").string();
  const Run gmsh = best_of(
      repeats, {self, "--gmsh-refine", (dir / "model.msh").string(), (dir / "gmsh.msh").string()},
      dir / "gmsh.log", "libgmsh read + RefineMesh + save");
  const Run conform = best_of(repeats,
                              {geode, "conform", (dir / "model.msh").string(), "-o",
                               (dir / "geode.msh").string(), "--quiet"},
                              dir / "geode.log", "geode conform");
  const Run none = best_of(repeats,
                           {geode, "conform", (dir / "model.msh").string(), "-o",
                            (dir / "geode_none.msh").string(), "--smooth", "none", "--quiet"},
                           dir / "geode_none.log", "geode conform --smooth none");
  Judged jg, jc, jn;
  try {
    jg = judge(dir / "gmsh.msh");
    jc = judge(dir / "geode.msh");
    jn = judge(dir / "geode_none.msh");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_conform_vs_gmsh: reading the outputs back: %s\n", e.what());
    return 1;
  }
  std::printf("best of %d\n", repeats);
  auto row = [](const char* what, const Run& r, const Judged& j) {
    std::printf(
        "%-30s %7.2f s %7.2f s CPU %8.1f MiB %9zu hexes %5.0f B/hex  %s (%zu inverted, %zu other "
        "cells)  min scaled Jacobian %.4f\n",
        what, r.seconds, r.cpu_seconds, r.peak_mib, j.hexes,
        j.hexes ? r.peak_mib * 1048576.0 / static_cast<double>(j.hexes) : 0.0,
        j.valid ? "valid" : "INVALID", j.inverted, j.other_cells, j.min_sj);
  };
  row("gmsh read+RefineMesh+save", gmsh, jg);
  row("geode conform", conform, jc);
  row("geode conform --smooth none", none, jn);
  std::printf(
      "geode / gmsh: time %.2fx (target <= 0.5), memory %.0f B per output hex (target <= 300), "
      "hexes %.2fx\n",
      conform.seconds / gmsh.seconds,
      conform.peak_mib * 1048576.0 / static_cast<double>(std::max<std::size_t>(jc.hexes, 1)),
      static_cast<double>(jc.hexes) / static_cast<double>(std::max<std::size_t>(jg.hexes, 1)));
  return jc.valid && jn.valid ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--gmsh-refine") return gmsh_refine(argv[2], argv[3]);
  const bool hybrid = argc > 1 && std::string(argv[1]) == "hybrid";
  if (hybrid) ++argv, --argc;
  const int n = argc > 1 ? std::atoi(argv[1]) : hybrid ? 32 : 26;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 1;
  const fs::path self = fs::canonical("/proc/self/exe");
  const std::string geode = argc > 3 ? argv[3] : (self.parent_path() / "geode").string();
  const std::string floor_exe = (self.parent_path() / "bench_floor").string();
  const char* gmsh_env = std::getenv("GMSH");
  const std::string gmsh = gmsh_env ? gmsh_env : "/usr/bin/gmsh";
  if (n < 2 || repeats < 1) {
    std::fprintf(stderr, "usage: bench_conform_vs_gmsh [hybrid] [n >= 2] [repeats >= 1] [geode]\n");
    return 2;
  }
  // The hybrid mode runs Gmsh through libgmsh and has no floor row.
  for (const auto& exe :
       hybrid ? std::vector<std::string>{geode} : std::vector<std::string>{geode, gmsh, floor_exe})
    if (access(exe.c_str(), X_OK) != 0) {
      std::fprintf(stderr, "bench_conform_vs_gmsh: %s is not an executable\n", exe.c_str());
      return 2;
    }

  std::string dir_template = (fs::temp_directory_path() / "geode-bench-XXXXXX").string();
  if (!mkdtemp(dir_template.data())) {
    std::perror("bench_conform_vs_gmsh: mkdtemp");
    return 2;
  }
  const fs::path dir = dir_template;
  if (hybrid) {
    const int status = hybrid_bench(n, repeats, geode, dir);
    if (std::getenv("GEODE_BENCH_KEEP")) {
      std::printf("kept %s\n", dir.c_str());
    } else {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
    return status;
  }

  const gp::Model model = geode::demo::demo_delaunay_block(n);
  geode::io::write_gmsh(model, dir / "model.msh", geode::io::GmshFormat::kBinary);
  geode::io::write_gmsh(tet_model(model), dir / "tets.msh", geode::io::GmshFormat::kBinary);
  std::printf("n %d: %zu hexes + %zu tets (%zu nodes); inputs in %s\n", n, model.hexes.size(),
              model.tets.size(), model.points.size(), dir.c_str());

  const std::string refine = "Merge \"" + (dir / "tets.msh").string() +
                             "\";\nMesh.SubdivisionAlgorithm = 2;\nRefineMesh;\n";
  write_text(dir / "sub.geo", refine);
  write_text(dir / "sub_save.geo",
             refine + "Mesh.Binary = 1;\nSave \"" + (dir / "gmsh.msh").string() + "\";\n");

  const Run sub = best_of(repeats, {gmsh, "-nt", "1", (dir / "sub.geo").string(), "-"},
                          dir / "gmsh.log", "gmsh subdivide");
  const Run sub_save = best_of(repeats, {gmsh, "-nt", "1", (dir / "sub_save.geo").string(), "-"},
                               dir / "gmsh_save.log", "gmsh subdivide+save");
  const Run conform =
      best_of(repeats,
              {geode, "conform", (dir / "model.msh").string(), "-o", (dir / "geode.exo").string(),
               "--report", (dir / "report.json").string(), "--quiet"},
              dir / "geode.log", "geode conform");
  const Run conform_none = best_of(
      repeats,
      {geode, "conform", (dir / "model.msh").string(), "-o", (dir / "geode_none.exo").string(),
       "--report", (dir / "report_none.json").string(), "--smooth", "none", "--quiet"},
      dir / "geode_none.log", "geode conform --smooth none");

  const Run floor =
      best_of(repeats, {floor_exe, (dir / "model.msh").string(), (dir / "floor.exo").string()},
              dir / "floor.log", "floor");
  // The same defaults on one thread (--threads 1): the 2-core speed-up, wall and CPU.
  const Run conform_one = best_of(
      repeats,
      {geode, "conform", (dir / "model.msh").string(), "-o", (dir / "geode_one.exo").string(),
       "--report", (dir / "report_one.json").string(), "--threads", "1", "--quiet"},
      dir / "geode_one.log", "geode conform --threads 1");
  // The whole output verified against the default's local verification (the transition and its
  // rings checked whole, the diced parts through the dicing tables).
  const Run conform_full = best_of(
      repeats,
      {geode, "conform", (dir / "model.msh").string(), "-o", (dir / "geode_full.exo").string(),
       "--report", (dir / "report_full.json").string(), "--verify", "full", "--quiet"},
      dir / "geode_full.log", "geode conform --verify full");
  // Every other output format against .exo (the same defaults), .msh in both encodings.
  struct Variant {
    const char* label;  // after "-o ."
    const char* ext;
    std::vector<std::string> options;
  };
  const Variant variants[] = {{"msh", "msh", {}},
                              {"msh (binary)", "msh", {"--msh-encoding", "binary"}},
                              {"vtu", "vtu", {}},
                              {"vtk", "vtk", {}}};
  std::vector<std::pair<std::string, Run>> formats;
  for (std::size_t k = 0; k < std::size(variants); ++k) {
    const Variant& v = variants[k];
    const std::string name = "geode" + std::to_string(k);
    const std::string out = (dir / (name + "." + v.ext)).string();
    std::vector<std::string> command{geode,
                                     "conform",
                                     (dir / "model.msh").string(),
                                     "-o",
                                     out,
                                     "--report",
                                     (dir / ("report_" + name + ".json")).string(),
                                     "--quiet"};
    command.insert(command.end(), v.options.begin(), v.options.end());
    formats.emplace_back(v.label,
                         best_of(repeats, command, dir / ("geode_" + name + ".log"), v.label));
    std::error_code ec;
    fs::remove(out, ec);
  }

  std::size_t gmsh_hexes = 0, geode_hexes = 0, floor_hexes = 0;
  bool geode_valid = false;
  std::size_t buffer_hexes = 0;
  double smoothing_cpu = 0.0;
  std::vector<std::string> block_min;
  try {
    floor_hexes = geode::io::read_exodus(dir / "floor.exo").hexes.size();
    const gp::Model g = geode::io::read_gmsh(dir / "gmsh.msh");
    gmsh_hexes = g.hexes.size();
    if (!g.tets.empty()) std::printf("warning: gmsh's output still has %zu tets\n", g.tets.size());
    std::ifstream is(dir / "report.json");
    const nlohmann::json j = nlohmann::json::parse(is);
    geode_hexes = j.at("output").at("hexes").get<std::size_t>();
    geode_valid = j.at("valid").get<bool>();
    buffer_hexes = j.at("input").at("interface_quads").get<std::size_t>();
    smoothing_cpu = j.at("smoothing").at("cpu_seconds").get<double>();
    for (const auto& b : j.at("blocks"))
      for (const auto& m : b.at("quality").at("metrics"))
        if (m.at("key") == "scaled_jacobian")
          block_min.push_back(b.at("name").get<std::string>() + " " +
                              std::to_string(m.at("min").get<double>()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_conform_vs_gmsh: reading the outputs back: %s\n", e.what());
    return 1;
  }
  if (gmsh_hexes == 0 || geode_hexes == 0 || floor_hexes == 0) {
    std::fprintf(stderr, "bench_conform_vs_gmsh: an output has no hexes\n");
    return 1;
  }

  std::printf(
      "best of %d; ratios against gmsh subdivide (read + RefineMesh, no output) and the floor\n",
      repeats);
  print_row("floor (read+dice+exo)", floor, floor_hexes, sub, floor);
  print_row("gmsh subdivide", sub, gmsh_hexes, sub, floor);
  print_row("gmsh subdivide+save", sub_save, gmsh_hexes, sub, floor);
  print_row("geode conform", conform, geode_hexes, sub, floor);
  print_row("geode --threads 1", conform_one, geode_hexes, sub, floor);
  print_row("geode --smooth none", conform_none, geode_hexes, sub, floor);
  print_row("geode --verify full", conform_full, geode_hexes, sub, floor);
  for (const auto& [ext, r] : formats)
    print_row(("geode -o ." + ext).c_str(), r, geode_hexes, sub, floor);
  std::printf("geode conform / floor: time %.2fx, CPU %.2fx; --threads 1 / 2: wall %.2fx\n",
              conform.seconds / floor.seconds, conform.cpu_seconds / floor.cpu_seconds,
              conform_one.seconds / conform.seconds);
  std::printf(
      "geode conform / gmsh subdivide+save: time %.2fx; --verify full / floor: time %.2fx, CPU "
      "%.2fx\n",
      conform.seconds / sub_save.seconds, conform_full.seconds / floor.seconds,
      conform_full.cpu_seconds / floor.cpu_seconds);
  for (const auto& [ext, r] : formats)
    std::printf("-o .%s / -o .exo: time %.2fx, CPU %.2fx\n", ext.c_str(),
                r.seconds / conform.seconds, r.cpu_seconds / conform.cpu_seconds);
  std::printf(
      "local smoothing: %.2f ms CPU per buffer hex (%zu buffer hexes); the two runs differ by %.2f "
      "s wall\n",
      1e3 * smoothing_cpu / static_cast<double>(buffer_hexes), buffer_hexes,
      conform.seconds - conform_none.seconds);
  std::printf("min scaled Jacobian per block:");
  for (const auto& b : block_min) std::printf("  %s", b.c_str());
  std::printf("\n");
  std::printf("geode conform / gmsh subdivide+save: time %.2fx, memory %.2fx; output %s\n",
              conform.seconds / sub_save.seconds, conform.peak_mib / sub_save.peak_mib,
              geode_valid ? "valid" : "INVALID");
  if (std::getenv("GEODE_BENCH_KEEP")) {
    std::printf("kept %s\n", dir.c_str());
  } else {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  return geode_valid ? 0 : 1;
}
