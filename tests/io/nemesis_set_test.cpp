// Nemesis input sets (io/nemesis_set.hpp) without MPI, so that the reader runs under the
// sanitizers too: a conform output cut in two pieces by position, each written as Exodus with
// its global node and element maps and Nemesis I counts, read back as the one model; then
// pieces made inconsistent, refused naming the piece.
#include <doctest/doctest.h>
#include <exodusII.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <geode/io/exodus.hpp>
#include <geode/io/formats.hpp>
#include <geode/io/nemesis_set.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/submodel.hpp>
#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

struct PieceOptions {
  bool nemesis = true;     // write the Nemesis I counts
  int processors = 2;      // the set's size as the piece states it
  std::int64_t extra = 0;  // added to the global node count
};

// Piece r of 2: the hexes whose first corner lies left (r = 0) or right of x = cut, written
// as BASE.2.r with global ids (model numbers + 1) in its maps.
void write_piece(const Model& model, double cut, int r, const fs::path& base,
                 const PieceOptions& o = {}) {
  std::vector<char> keep(model.hexes.size());
  for (std::size_t h = 0; h < model.hexes.size(); ++h)
    keep[h] = (model.points[index_cast<std::size_t>(model.hexes[h][0])].x() < cut) == (r == 0);
  const Submodel piece = extract_submodel(model, keep);
  const fs::path path = base.string() + ".2." + std::to_string(r);
  write_exodus(piece.model, path);
  int cpu = 8, io_size = 8;
  float version = 0;
  const int exo = ex_open(path.string().c_str(), EX_WRITE, &cpu, &io_size, &version);
  REQUIRE(exo >= 0);
  std::vector<int> nodes, hexes;
  for (Index v : piece.node) nodes.push_back(v + 1);
  for (Index h : piece.element[0]) hexes.push_back(h + 1);
  REQUIRE(ex_put_id_map(exo, EX_NODE_MAP, nodes.data()) >= 0);
  REQUIRE(ex_put_id_map(exo, EX_ELEM_MAP, hexes.data()) >= 0);
  if (o.nemesis) {
    char type[] = "p";
    REQUIRE(ex_put_init_info(exo, o.processors, 1, type) >= 0);
    REQUIRE(ex_put_init_global(exo, index_cast<int64_t>(model.points.size()) + o.extra,
                               index_cast<int64_t>(model.hexes.size()),
                               index_cast<int64_t>(model.block_names.size()),
                               index_cast<int64_t>(model.node_sets.size()),
                               index_cast<int64_t>(model.side_sets.size())) >= 0);
  }
  REQUIRE(ex_close(exo) >= 0);
}

}  // namespace

TEST_CASE("a Nemesis set of a conform output reads as the whole model, refused when inconsistent") {
  const test::TempDir dir;
  // The half demo (hex part + tet part), conformed: an all-hex model with two blocks.
  const fs::path whole_file = dir.path / "whole.exo";
  const auto run =
      test::geode_cli("demo --model half -n 2 --quiet -o " + whole_file.string(), true);
  INFO(run.out);
  REQUIRE(run.code == 0);
  const Model whole = read_model(whole_file);
  REQUIRE(whole.block_names.size() == 2);
  double lo = whole.points[0].x(), hi = lo;
  for (const Point& p : whole.points) lo = std::min(lo, p.x()), hi = std::max(hi, p.x());
  const double cut = (lo + hi) / 2;

  const fs::path base = dir.path / "set.exo";
  write_piece(whole, cut, 0, base);
  write_piece(whole, cut, 1, base);
  const auto set = find_nemesis_set(base);
  REQUIRE(set);
  CHECK(set->files.size() == 2);
  CHECK(set->name() == base.string() + ".2.*");
  FilePartition partition;
  const Model joined = read_nemesis_set(*set, {}, &partition);
  CHECK(joined.points == whole.points);
  CHECK(joined.hexes == whole.hexes);
  CHECK(joined.hex_block == whole.hex_block);
  CHECK(joined.block_names == whole.block_names);
  REQUIRE(partition.parts == 2);
  REQUIRE(partition.part.size() == whole.hexes.size());
  for (std::size_t h = 0; h < whole.hexes.size(); ++h)
    CHECK(partition.part[h] ==
          (whole.points[index_cast<std::size_t>(whole.hexes[h][0])].x() < cut ? 0 : 1));
  // read_model finds the set from its base name (no such file) and from a piece.
  CHECK(read_model(base).hexes == whole.hexes);
  CHECK(read_model(base.string() + ".2.1").hexes == whole.hexes);
  // So does the hex-mesh read of check, dual and view, which refused both names ("no such file",
  // "unknown input format '.1'"), as an Exodus file.
  for (const fs::path& name : {base, fs::path(base.string() + ".2.1")}) {
    CAPTURE(name);
    const MeshFormat* format = nullptr;
    const PlainMesh plain = read_plain_mesh(name, &format);
    CHECK(plain.hex.hexes == whole.hexes);
    REQUIRE(format);
    CHECK(format->index_base == 1);
  }

  const std::string piece1 = base.string() + ".2.1";
  const auto refused = [&](const PieceOptions& o, const std::string& message) {
    write_piece(whole, cut, 1, base, o);
    CHECK_THROWS_WITH_AS(read_nemesis_set(*set), doctest::Contains(message.c_str()), InvalidInput);
  };
  refused({.nemesis = false}, piece1 + ": no Nemesis I counts");
  refused({.processors = 3}, piece1 + ": a piece of 3 processors in a set of 2 files");
  refused({.extra = 1}, piece1 + ": global counts");
  // Both pieces claim one node more than they hold between them: that node is in none.
  write_piece(whole, cut, 0, base, {.extra = 1});
  refused({.extra = 1}, set->name() + ": global node " + std::to_string(whole.points.size() + 1) +
                            " is in no piece of 2");
  // A missing piece.
  fs::remove(piece1);
  CHECK_THROWS_WITH_AS(read_model(base), doctest::Contains((piece1 + ": missing").c_str()),
                       InvalidInput);
}
