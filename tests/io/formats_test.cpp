// The format table (io/formats.hpp): every entry's writer and reader round-trip a model with
// what the entry says it carries, and drop what it says it drops; signatures tell the formats
// apart; dispatch by extension and by name; the docs' matrix is the table's.
#include <doctest/doctest.h>
#include <pthread.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <string>

#include <geode/io/file_format.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/element_numbers.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

using geode::test::slurp;

// Hexes (block 1 "steel") beside Kuhn tets (block 2), a node set and a side set with names.
Model formats_model() {
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.block_names[1] = "steel";
  m.node_sets.push_back({11, "bottom", {0, 2, 4, 8}});
  SideSet outside{21, "outside", {}};
  outside.sides.push_back({{ElementKind::kHex, 0}, 0});
  m.side_sets.push_back(outside);
  return m;
}

}  // namespace

TEST_CASE("format table: names unique, extensions lower case, every entry reads or writes") {
  std::set<std::string_view> names;
  for (const MeshFormat& f : mesh_formats()) {
    CAPTURE(f.name);
    CHECK(names.insert(f.name).second);
    CHECK(!f.extensions.empty());
    for (std::string_view e : f.extensions) {
      CHECK(e.size() >= 2);
      CHECK(e.front() == '.');
      for (char c : e) CHECK(!(c >= 'A' && c <= 'Z'));
    }
    CHECK((f.signature != nullptr));
    CHECK((f.read != nullptr || f.write != nullptr));
    CHECK(find_mesh_format(f.name) == &f);
    // Every extension is read by some entry: a file we write can be read back.
    for (std::string_view e : f.extensions)
      CHECK(reader_for(fs::path("x") += std::string(e)) != nullptr);
  }
  CHECK(find_mesh_format("stl") == nullptr);
  CHECK(reader_for("mesh.obj") == nullptr);
  CHECK(reader_for("MESH.EXO")->name == "exo");  // any case
  CHECK(writer_for("out.msh")->name == "msh");   // 4.1 before 2.2
  CHECK(extension_list(FormatRole::kWriteQuads) == ".vtu or .vtk");
}

TEST_CASE(
    "format table: each writer's output has its signature and no other's, and reads back with what "
    "it carries") {
  const geode::test::TempDir dir;
  const Model m = formats_model();
  for (const MeshFormat& f : mesh_formats()) {
    if (!f.write) continue;
    CAPTURE(f.name);
    const fs::path path = dir.path / ("model" + std::string(f.extensions.front()));
    write_model(m, path, f.name);
    const std::string head = read_file_head(path);
    CHECK(f.signature(head));
    for (const MeshFormat& g : mesh_formats())
      if (g.signature != f.signature) CHECK_FALSE(g.signature(head));
    const Model r = read_model(path);
    CHECK(r.hexes.size() == m.hexes.size());
    CHECK(r.tets.size() == m.tets.size());
    const FormatCarries& c = f.carries;
    if (c.blocks == Carried::kYes) {
      CHECK(r.hex_block == std::vector<int>(m.hexes.size(), 1));
      CHECK(r.tet_block == std::vector<int>(m.tets.size(), 2));
    }
    CHECK((r.block_names.count(1) && r.block_names.at(1) == "steel") ==
          (c.block_names == Carried::kYes));
    if (c.block_names == Carried::kWritten) CHECK(slurp(path).find("steel") != std::string::npos);
    if (c.block_names == Carried::kNo) CHECK(slurp(path).find("steel") == std::string::npos);
    CHECK((r.node_sets.size() == 1) == (c.node_sets == Carried::kYes));
    CHECK((r.side_sets.size() == 1) == (c.side_sets == Carried::kYes));
    if (c.set_names == Carried::kYes) {
      REQUIRE(r.node_sets.size() == 1);
      CHECK(r.node_sets[0].name == "bottom");
      CHECK(r.side_sets[0].name == "outside");
    }
    if (f.write_quads) {
      QuadMesh q;
      q.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
      q.quads = {{0, 1, 2, 3}};
      const fs::path qp = dir.path / ("quad" + std::string(f.extensions.front()));
      write_quad_mesh(q, qp, f.name);
      const PlainMesh p = read_plain_mesh(qp);
      CHECK(p.dim == 2);
      CHECK(p.quad.quads.size() == 1);
    }
  }
}

TEST_CASE(
    "format table: dispatch refuses unknown formats and content of another format, naming the "
    "file") {
  const geode::test::TempDir dir;
  const Model m = formats_model();
  CHECK_THROWS_WITH_AS(write_model(m, dir.path / "out.stl"),
                       doctest::Contains("unknown output format '.stl'"), InvalidInput);
  CHECK_THROWS_WITH_AS(write_model(m, dir.path / "out.vtu", "obj"),
                       doctest::Contains("'obj' is not a mesh format"), InvalidInput);
  QuadMesh q;
  CHECK_THROWS_WITH_AS(write_quad_mesh(q, dir.path / "q.exo"), doctest::Contains("for quad meshes"),
                       InvalidInput);
  const fs::path fake = dir.path / "fake.exo";
  write_model(m, dir.path / "real.vtu");
  fs::copy_file(dir.path / "real.vtu", fake);
  CHECK_THROWS_WITH_AS(
      read_model(fake),
      doctest::Contains("fake.exo: not in Exodus II format (its content is VTK XML"), InvalidInput);
  CHECK_THROWS_WITH_AS(read_model(dir.path / "mesh.obj"), doctest::Contains("no such file"),
                       InvalidInput);
  std::ofstream(dir.path / "mesh.obj") << "v 0 0 0\n";
  CHECK_THROWS_WITH_AS(
      read_model(dir.path / "mesh.obj"),
      doctest::Contains("unknown input format '.obj' (expected .exo, .e, .msh, .vtu or .vtk)"),
      InvalidInput);
}

namespace {
std::atomic<int> forks{0};  // counted by a pthread_atfork handler in the parent
}  // namespace

TEST_CASE("read_forks says which reads fork a child (a caller's threads must rest then)") {
  static const int registered = ::pthread_atfork(
      nullptr, [] { ++forks; }, nullptr);
  REQUIRE(registered == 0);
  const test::TempDir dir;
  for (const MeshFormat& f : mesh_formats()) {
    if (!f.read || !f.write) continue;
    CAPTURE(f.name);
    const fs::path file = dir.path / ("model" + std::string(f.extensions.front()));
    write_model(formats_model(), file, f.name);
    const int before = forks;
    (void)read_model(file);
    CHECK((forks > before) == read_forks(file));
    CHECK(read_forks(file) == f.reads_in_child);
  }
  CHECK(read_forks("missing.exo"));  // by the extension, as read_model chooses its reader
  CHECK(!read_forks("missing.vtu"));
}

TEST_CASE("format table: docs/formats.md holds the table's matrix (geode formats prints it)") {
  const std::string doc = slurp(fs::path(GEODE_SOURCE_DIR) / "docs" / "formats.md");
  CHECK(doc.find(format_matrix_markdown()) != std::string::npos);
}

TEST_CASE("format table: element_numbering names each hex as the written file numbers it") {
  // An all-hex model whose blocks are not in ascending runs, as a conform output's are not.
  Model m = grid_model({4, 2, 1}, 0.5, [](int, int, int) { return false; });
  m.hex_block = {3, 1, 2, 1, 3, 3, 2, 1};
  std::vector<Index> all(m.hexes.size());
  std::iota(all.begin(), all.end(), Index{0});
  test::TempDir dir;
  int formats = 0;
  for (const MeshFormat& f : mesh_formats()) {
    if (!f.write) continue;
    INFO(f.name);
    const fs::path file = dir.path / ("numbered" + std::string(f.extensions.front()));
    write_model(m, file, f.name);
    const Model back = read_model(file);
    REQUIRE(back.hexes.size() == m.hexes.size());
    std::map<std::int64_t, std::array<Index, 8>> by_id;  // the file's id -> its corners
    for (std::size_t k = 0; k < back.hexes.size(); ++k)
      by_id[element_id(back, {ElementKind::kHex, index_cast(k)})] = back.hexes[k];
    const std::vector<std::int64_t> numbers = hex_numbers(m.hex_block, all, element_numbering(f));
    for (std::size_t h = 0; h < m.hexes.size(); ++h) {
      INFO("hex " << h << " numbered " << numbers[h]);
      REQUIRE(by_id.contains(numbers[h]));
      CHECK(by_id[numbers[h]] == m.hexes[h]);  // nodes keep their order in every format
    }
    ++formats;
  }
  CHECK(formats >= 4);
}
