// Exodus II input/output: round trip, the file's own corner convention read back raw, and bad
// input rejected with messages naming the file, the block or element, and the reason.
#include <doctest/doctest.h>
#include <exodusII.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <geode/io/exodus.hpp>
#include <geode/io/read_warnings.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/grid_model.hpp>
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

// One directory for the whole test program, removed at exit.
const fs::path& scratch_dir() {
  static const geode::test::TempDir dir;
  return dir.path;
}

// 2 x 2 x 1 cells of size 0.5: x < 0.5 hexes (block 1 "steel"), x >= 0.5 Kuhn tets (block 2),
// a node set and a side set listed out of order (Exodus keeps the order).
Model exodus_model() {
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.points[4] += Point(0.01, -0.02, 0.03);
  m.block_names[1] = "steel";
  m.node_sets.push_back({11, "bottom", {8, 0, 4, 2}});
  m.node_sets.push_back({12, "", {17}});
  SideSet outside{21, "outside", {}};
  outside.sides.push_back({{ElementKind::kTet, 5}, 3});
  outside.sides.push_back({{ElementKind::kHex, 1}, 5});
  outside.sides.push_back({{ElementKind::kHex, 0}, 0});
  m.side_sets.push_back(outside);
  return m;
}

// A raw Exodus file written with the C API: `type` block of one element with `conn`.
void write_raw(const fs::path& file, const char* type, const std::vector<int>& conn,
               int num_nodes) {
  int cpu = 8, io = 8;
  const int exo = ex_create(file.string().c_str(), EX_CLOBBER, &cpu, &io);
  REQUIRE(exo >= 0);
  REQUIRE(ex_put_init(exo, "raw", 3, num_nodes, 1, 1, 0, 0) >= 0);
  std::vector<double> x(index_cast<std::size_t>(num_nodes)), y(x.size()), z(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i);
  REQUIRE(ex_put_coord(exo, x.data(), y.data(), z.data()) >= 0);
  REQUIRE(ex_put_block(exo, EX_ELEM_BLOCK, 3, type, 1, index_cast<int64_t>(conn.size()), 0, 0, 0) >=
          0);
  REQUIRE(ex_put_conn(exo, EX_ELEM_BLOCK, 3, conn.data(), nullptr, nullptr) >= 0);
  REQUIRE(ex_close(exo) >= 0);
}

// A written file opened with the raw C API, to read it as the library lays it out.
int open_raw(const fs::path& file) {
  int cpu = 8, io = 0;
  float version = 0;
  const int exo = ex_open(file.string().c_str(), EX_READ, &cpu, &io, &version);
  REQUIRE(exo >= 0);
  return exo;
}

std::string message_of(const fs::path& file) {
  try {
    (void)read_exodus(file);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "no exception";
}

// The sample model written as a 64-bit file (netCDF-4, every integer 64 bits) with number maps
// from `first_node` and `first_element` on, an empty NULL block (as libexodus writes a block
// of no elements) after the others, and side set 7: `more` writes it, else it is empty.
fs::path write_int64(const std::string& name, std::int64_t first_node, std::int64_t first_element,
                     const std::function<void(int exo)>& more = {}) {
  const Model m = exodus_model();
  const fs::path file = scratch_dir() / name;
  write_exodus(m, file);
  // Read back raw, written again through the 64-bit API.
  const int in = open_raw(file);
  ex_init_params p{};
  REQUIRE(ex_get_init_ext(in, &p) >= 0);
  std::vector<double> x(static_cast<std::size_t>(p.num_nodes)), y(x.size()), z(x.size());
  REQUIRE(ex_get_coord(in, x.data(), y.data(), z.data()) >= 0);
  std::vector<int> ids(static_cast<std::size_t>(p.num_elem_blk));
  REQUIRE(ex_get_ids(in, EX_ELEM_BLOCK, ids.data()) >= 0);
  int cpu = 8, io = 8;
  const fs::path out = scratch_dir() / ("64-" + name);
  const int exo =
      ex_create(out.string().c_str(), EX_CLOBBER | EX_NETCDF4 | EX_ALL_INT64_DB, &cpu, &io);
  REQUIRE(exo >= 0);
  ex_set_int64_status(exo, EX_ALL_INT64_API);
  REQUIRE(ex_put_init(exo, "int64", 3, p.num_nodes, p.num_elem, p.num_elem_blk + 1, 0, 1) >= 0);
  REQUIRE(ex_put_coord(exo, x.data(), y.data(), z.data()) >= 0);
  for (int id : ids) {
    char type[MAX_STR_LENGTH + 1] = {};
    int count = 0, per = 0, edges = 0, faces = 0, attributes = 0;
    REQUIRE(ex_get_block(in, EX_ELEM_BLOCK, id, type, &count, &per, &edges, &faces, &attributes) >=
            0);
    std::vector<int> conn(static_cast<std::size_t>(count * per));
    REQUIRE(ex_get_conn(in, EX_ELEM_BLOCK, id, conn.data(), nullptr, nullptr) >= 0);
    REQUIRE(ex_put_block(exo, EX_ELEM_BLOCK, id, type, count, per, 0, 0, 0) >= 0);
    const std::vector<std::int64_t> wide(conn.begin(), conn.end());
    REQUIRE(ex_put_conn(exo, EX_ELEM_BLOCK, id, wide.data(), nullptr, nullptr) >= 0);
  }
  REQUIRE(ex_put_block(exo, EX_ELEM_BLOCK, 42, "NULL", 0, 0, 0, 0, 0) >= 0);
  std::vector<std::int64_t> node_map(x.size()), element_map(static_cast<std::size_t>(p.num_elem));
  for (std::size_t i = 0; i < node_map.size(); ++i)
    node_map[i] = first_node + static_cast<std::int64_t>(i);
  for (std::size_t i = 0; i < element_map.size(); ++i)
    element_map[i] = first_element + static_cast<std::int64_t>(i);
  REQUIRE(ex_put_id_map(exo, EX_NODE_MAP, node_map.data()) >= 0);
  REQUIRE(ex_put_id_map(exo, EX_ELEM_MAP, element_map.data()) >= 0);
  if (more)
    more(exo);
  else
    REQUIRE(ex_put_set_param(exo, EX_SIDE_SET, 7, 0, 0) >= 0);  // empty
  REQUIRE(ex_close(exo) >= 0);
  REQUIRE(ex_close(in) >= 0);
  return out;
}

}  // namespace

TEST_CASE("write_exodus then read_exodus gives the same model") {
  const Model m = exodus_model();
  const fs::path file = scratch_dir() / "rt.exo";
  write_exodus(m, file);
  const Model r = read_exodus(file);
  REQUIRE(r.points.size() == m.points.size());
  for (std::size_t i = 0; i < m.points.size(); ++i) CHECK(r.points[i] == m.points[i]);
  CHECK(r.hexes == m.hexes);
  CHECK(r.tets == m.tets);
  CHECK(r.hex_block == m.hex_block);
  CHECK(r.tet_block == m.tet_block);
  CHECK(r.block_names == m.block_names);
  REQUIRE(r.node_sets.size() == 2);
  for (std::size_t s = 0; s < 2; ++s) {
    CHECK(r.node_sets[s].id == m.node_sets[s].id);
    CHECK(r.node_sets[s].name == m.node_sets[s].name);
    CHECK(r.node_sets[s].nodes == m.node_sets[s].nodes);
  }
  REQUIRE(r.side_sets.size() == 1);
  CHECK(r.side_sets[0].id == 21);
  CHECK(r.side_sets[0].name == "outside");
  CHECK(r.side_sets[0].sides == m.side_sets[0].sides);
}

TEST_CASE("the written file follows Exodus's own HEX8 / TETRA4 / side conventions") {
  // Read back with the raw C API, not with read_exodus: Exodus II manual, HEX8 nodes 1-4 are
  // one face counter-clockwise seen from nodes 5-8 (node 5 above node 1); TETRA4 nodes 1-2-3
  // counter-clockwise seen from node 4; hex side 5 is the face 1-4-3-2.
  const Model m = exodus_model();
  const fs::path file = scratch_dir() / "raw.exo";
  write_exodus(m, file);
  const int exo = open_raw(file);
  std::vector<double> x(m.points.size()), y(x.size()), z(x.size());
  REQUIRE(ex_get_coord(exo, x.data(), y.data(), z.data()) >= 0);
  auto p = [&](int n) {
    return Point(x[index_cast<std::size_t>(n - 1)], y[index_cast<std::size_t>(n - 1)],
                 z[index_cast<std::size_t>(n - 1)]);
  };
  std::vector<int> hex(2 * 8), tet(12 * 4);
  REQUIRE(ex_get_conn(exo, EX_ELEM_BLOCK, 1, hex.data(), nullptr, nullptr) >= 0);
  REQUIRE(ex_get_conn(exo, EX_ELEM_BLOCK, 2, tet.data(), nullptr, nullptr) >= 0);
  for (int h = 0; h < 2; ++h) {
    const int* c = &hex[index_cast<std::size_t>(8 * h)];
    const Point up = (p(c[1]) - p(c[0])).cross(p(c[3]) - p(c[0]));
    CHECK(up.dot(p(c[4]) - p(c[0])) > 0);  // nodes 5-8 on the side the 1-2-3-4 normal points to
    for (int i = 0; i < 4; ++i)
      CHECK((p(c[i + 4]) - p(c[i])).normalized().z() > 0.99);  // node i+5 above node i+1
  }
  for (int t = 0; t < 12; ++t) {
    const int* c = &tet[index_cast<std::size_t>(4 * t)];
    CHECK(tet_volume(p(c[0]), p(c[1]), p(c[2]), p(c[3])) > 0);
  }
  std::vector<int> elems(3), sides(3);
  REQUIRE(ex_get_set(exo, EX_SIDE_SET, 21, elems.data(), sides.data()) >= 0);
  // Global numbering: block 1 (hexes 1, 2) then block 2 (tets 3..14); tet 5 is element 8.
  CHECK(elems == std::vector<int>{8, 2, 1});
  CHECK(sides == std::vector<int>{4, 6, 1});
  ex_close(exo);
}

TEST_CASE("read_exodus rejects bad input naming the file, element and reason") {
  const fs::path dir = scratch_dir();
  SUBCASE("missing file") {
    const fs::path file = dir / "nope.exo";
    const std::string what = message_of(file);
    CHECK(what.find(file.string()) != std::string::npos);
    CHECK(what.find("no such file") != std::string::npos);
  }
  SUBCASE("truncated file") {
    const fs::path whole = dir / "whole.exo", cut = dir / "cut.exo";
    write_exodus(exodus_model(), whole);
    std::ifstream in(whole, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    const std::string all = bytes.str();
    std::ofstream(cut, std::ios::binary) << all.substr(0, all.size() / 3);
    const std::string what = message_of(cut);
    CHECK(what.find(cut.string()) != std::string::npos);
  }
  SUBCASE("unknown element type") {
    const fs::path file = dir / "tet10.exo";
    write_raw(file, "TETRA10", {1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 10);
    const std::string what = message_of(file);
    CHECK(what.find(file.string()) != std::string::npos);
    CHECK(what.find("element block 3: element 1") != std::string::npos);
    CHECK(what.find("'TETRA10' with 10 nodes is not supported") != std::string::npos);
  }
  SUBCASE("a block of faces is left out, warned") {
    const fs::path file = dir / "shell.exo";
    write_raw(file, "SHELL4", {1, 2, 3, 4}, 4);
    ReadWarnings warnings;
    const Model m = read_exodus(file);
    CHECK(element_count(m) == 0);
    REQUIRE(warnings.messages().size() == 1);
    CHECK(warnings.messages()[0].find("not read (block id, type, elements): 3 (SHELL4, 1)") !=
          std::string::npos);
  }
  SUBCASE("a wedge with the wrong node count") {
    const fs::path file = dir / "wedge5.exo";
    write_raw(file, "WEDGE", {1, 2, 3, 4, 5}, 5);
    CHECK(message_of(file).find("'WEDGE' with 5 nodes is not supported") != std::string::npos);
  }
  SUBCASE("node index out of range") {
    const fs::path file = dir / "range.exo";
    write_raw(file, "TETRA4", {1, 2, 99, 4}, 4);
    const std::string what = message_of(file);
    CHECK(what.find(file.string()) != std::string::npos);
    CHECK(what.find("element 1: corner 3 refers to node number 99") != std::string::npos);
  }
}

TEST_CASE("write_exodus numbers a block's elements in runs: sides name the file's numbers") {
  // Tets two by two between blocks 2 and 3: each block is three runs of two tets. The file
  // numbers its elements block by block (ascending id), each block in model order: hexes 1-2
  // (block 1), tets 0, 1, 4, 5, 8, 9 as 3-8 (block 2), tets 2, 3, 6, 7, 10, 11 as 9-14 (block 3).
  Model m = exodus_model();
  for (std::size_t t = 0; t < m.tets.size(); ++t) m.tet_block[t] = t / 2 % 2 ? 3 : 2;
  m.side_sets[0].sides = {{{ElementKind::kTet, 5}, 3},
                          {{ElementKind::kTet, 4}, 0},
                          {{ElementKind::kHex, 1}, 5},
                          {{ElementKind::kTet, 11}, 1},
                          {{ElementKind::kTet, 3}, 2}};
  const fs::path file = scratch_dir() / "runs.exo";
  write_exodus(m, file);
  const int exo = open_raw(file);
  std::vector<int> elems(5), sides(5);
  REQUIRE(ex_get_set(exo, EX_SIDE_SET, 21, elems.data(), sides.data()) >= 0);
  CHECK(elems == std::vector<int>{6, 5, 2, 14, 10});
  // Block 3's connectivity: tets 2, 3, 6, 7, 10, 11 in order (the same corners, as the file
  // orders them: compared as sets).
  std::vector<int> conn(6 * 4);
  REQUIRE(ex_get_conn(exo, EX_ELEM_BLOCK, 3, conn.data(), nullptr, nullptr) >= 0);
  for (std::size_t k = 0; k < 6; ++k) {
    std::multiset<int> file_corners(conn.begin() + static_cast<std::ptrdiff_t>(4 * k),
                                    conn.begin() + static_cast<std::ptrdiff_t>(4 * k + 4));
    std::multiset<int> model_corners;
    for (Index v : m.tets[k / 2 * 4 + 2 + k % 2]) model_corners.insert(v + 1);
    CHECK(file_corners == model_corners);
  }
  ex_close(exo);
  const Model back = read_exodus(file);
  CHECK(back.tet_block == std::vector<int>{2, 2, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3});
}

TEST_CASE("a block of two kinds: one Exodus block per kind, joined again on reading") {
  const fs::path file = scratch_dir() / "mixed.exo";
  Model mixed = exodus_model();
  mixed.tet_block.assign(mixed.tets.size(), 1);  // block 1 now holds both
  mixed.block_names[1] = "steel";
  write_exodus(mixed, file);
  {  // as the file holds it: hexes keep the id, the tets get the next one and say whose they are
    const int exo = open_raw(file);
    std::vector<int> ids(2);
    REQUIRE(ex_inquire_int(exo, EX_INQ_ELEM_BLK) == 2);
    REQUIRE(ex_get_ids(exo, EX_ELEM_BLOCK, ids.data()) >= 0);
    CHECK(ids == std::vector<int>{1, 2});
    char name[MAX_STR_LENGTH + 1] = {};
    REQUIRE(ex_get_name(exo, EX_ELEM_BLOCK, 2, name) >= 0);
    CHECK(std::string(name) == "steel tets");
    for (int id : ids) {
      int whose = 0;
      REQUIRE(ex_get_prop(exo, EX_ELEM_BLOCK, id, "GEODE_BLOCK", &whose) >= 0);
      CHECK(whose == 1);
    }
    ex_close(exo);
  }
  const Model back = read_exodus(file);
  CHECK(back.hexes == mixed.hexes);
  CHECK(back.tets == mixed.tets);
  CHECK(back.hex_block == mixed.hex_block);
  CHECK(back.tet_block == mixed.tet_block);
  CHECK(back.block_names == mixed.block_names);
}

TEST_CASE("read_exodus joins only blocks whose GEODE_BLOCK names a block that names itself") {
  // Four one-tet blocks: 3 names 4 (which names itself: joined), 5 names 9 (absent) and 6
  // names 3 (a part itself): kept as the file has them, names and all.
  const fs::path file = scratch_dir() / "parts.exo";
  int cpu = 8, io = 8;
  const int exo = ex_create(file.string().c_str(), EX_CLOBBER, &cpu, &io);
  REQUIRE(exo >= 0);
  const std::vector<int> ids{3, 4, 5, 6}, whose{4, 4, 9, 3};
  REQUIRE(ex_put_init(exo, "parts", 3, 4, 4, 4, 0, 0) >= 0);
  const std::vector<double> x{0, 1, 0, 0}, y{0, 0, 1, 0}, z{0, 0, 0, 1};
  REQUIRE(ex_put_coord(exo, x.data(), y.data(), z.data()) >= 0);
  char property[] = "GEODE_BLOCK";
  char* properties[] = {property};
  REQUIRE(ex_put_prop_names(exo, EX_ELEM_BLOCK, 1, properties) >= 0);
  const std::vector<int> conn{1, 2, 3, 4};
  std::vector<std::string> names{"a", "b", "c", "d"};
  for (std::size_t b = 0; b < ids.size(); ++b) {
    REQUIRE(ex_put_block(exo, EX_ELEM_BLOCK, ids[b], "TETRA4", 1, 4, 0, 0, 0) >= 0);
    REQUIRE(ex_put_conn(exo, EX_ELEM_BLOCK, ids[b], conn.data(), nullptr, nullptr) >= 0);
    REQUIRE(ex_put_prop(exo, EX_ELEM_BLOCK, ids[b], "GEODE_BLOCK", whose[b]) >= 0);
    REQUIRE(ex_put_name(exo, EX_ELEM_BLOCK, ids[b], names[b].data()) >= 0);
  }
  REQUIRE(ex_close(exo) >= 0);
  const Model back = read_exodus(file);
  CHECK(back.tet_block == std::vector<int>{4, 4, 5, 6});
  CHECK(back.block_names == std::map<int, std::string>{{4, "b"}, {5, "c"}, {6, "d"}});
}

TEST_CASE("write_exodus is atomic") {
  const fs::path file = scratch_dir() / "atomic.exo";
  std::ofstream(file) << "previous content";
  Model bad = exodus_model();
  bad.side_sets[0].sides[0].face = 4;  // tets have faces 0..3
  CHECK_THROWS_WITH_AS(write_exodus(bad, file), doctest::Contains("face 5 out of range"),
                       InvalidInput);
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  CHECK(text.str() == "previous content");
}

TEST_CASE(
    "64-bit files: ids of 2^31 and more, an empty NULL block, sides named by the file's ids") {
  // A Cubit / SEACAS file with 64-bit integers and ids past 2^31 (refused before: the 32-bit
  // API cannot hold them) and the NULL block libexodus writes for a block of no elements
  // (refused before as an element of type 'NULL').
  const std::int64_t first_node = std::int64_t{5} << 30, first_element = std::int64_t{9} << 31;
  const Model read = read_exodus(write_int64("big.exo", first_node, first_element));
  const Model m = exodus_model();
  CHECK(read.points.size() == m.points.size());
  CHECK(read.hexes.size() == m.hexes.size());
  CHECK(read.tets.size() == m.tets.size());
  REQUIRE(!read.node_ids.empty());
  CHECK(read.node_ids.front() == first_node);
  CHECK(read.node_ids.back() == first_node + static_cast<std::int64_t>(m.points.size()) - 1);
  REQUIRE(!read.hex_ids.empty());
  CHECK(read.hex_ids.front() == first_element);  // block 1's hexes are written first
  CHECK(read.block_names.count(42) == 0);
  // A side set entry whose side is out of range is named by the element's id, not its place.
  const fs::path bad = write_int64("bad-side.exo", 1000, 5000, [](int exo) {
    REQUIRE(ex_put_set_param(exo, EX_SIDE_SET, 7, 1, 0) >= 0);
    const std::int64_t element = 2, side = 9;
    REQUIRE(ex_put_set(exo, EX_SIDE_SET, 7, &element, &side) >= 0);
  });
  const std::string what = message_of(bad);
  CHECK(what.find("side set 7: entry 1: element 5001: side 9 out of range") != std::string::npos);
}
