// Blocks, their names, node sets and side sets through every pair of formats: a model written as
// A, read, written as B and read again keeps what both A and B carry (the format table's
// kYes), compared by geometry (element centroids, node positions, face centroids), since a
// format may order elements its own way.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include <geode/io/formats.hpp>
#include <geode/io/read_model.hpp>
#include <geode/primal/grid_model.hpp>
#include <geode/primal/topology.hpp>
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace geode;
using namespace geode::primal;
using namespace geode::io;

namespace {

using Key = std::array<long long, 3>;  // a position in 1/1000ths

Key key_of(const Point& p) {
  return {std::llround(p.x() * 1000), std::llround(p.y() * 1000), std::llround(p.z() * 1000)};
}

Point centroid(const Model& m, std::span<const Index> corners) {
  Point c(0, 0, 0);
  for (Index v : corners) c += m.points[index_cast<std::size_t>(v)];
  return c / static_cast<double>(corners.size());
}

// Hexes (block 1 "steel") beside Kuhn tets (block 2 "rubber"), one of which is steel too (a
// block of two kinds, which Exodus writes as two blocks); a node set, a side set on a hex and
// one on a tet, each named.
Model round_trip_model() {
  Model m = grid_model({2, 2, 1}, 0.5, [](int i, int, int) { return i >= 1; });
  m.tet_block[0] = 1;
  m.block_names[1] = "steel";
  m.block_names[2] = "rubber: soft";
  m.node_sets.push_back({11, "bottom", {0, 2, 4, 8}});
  SideSet outside{21, "outside", {}};
  outside.sides.push_back({{ElementKind::kHex, 0}, 0});
  outside.sides.push_back({{ElementKind::kHex, 1}, 0});
  m.side_sets.push_back(outside);
  SideSet tet_side{22, "tet side", {}};
  tet_side.sides.push_back({{ElementKind::kTet, 3}, 2});
  m.side_sets.push_back(tet_side);
  return m;
}

struct Summary {
  std::multiset<std::pair<Key, int>> blocks;  // element centroid, block
  std::map<int, std::string> block_names;
  std::set<std::tuple<int, std::string, std::set<Key>>> node_sets;
  std::set<std::tuple<int, std::string, std::multiset<Key>>> side_sets;  // face centroids
};

Summary summary(const Model& m, const FormatCarries& c) {
  Summary s;
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(m, kind); ++e) {
      const ElementRef ref{kind, index_cast(e)};
      s.blocks.insert({key_of(centroid(m, element_corners(m, ref))),
                       c.blocks == Carried::kYes ? block_of(m, ref) : 0});
    }
  if (c.block_names == Carried::kYes) s.block_names = m.block_names;
  if (c.node_sets == Carried::kYes)
    for (const NodeSet& set : m.node_sets) {
      std::set<Key> nodes;
      for (Index v : set.nodes) nodes.insert(key_of(m.points[index_cast<std::size_t>(v)]));
      s.node_sets.insert({set.id, c.set_names == Carried::kYes ? set.name : "", nodes});
    }
  if (c.side_sets == Carried::kYes)
    for (const SideSet& set : m.side_sets) {
      std::multiset<Key> faces;
      for (const Side& side : set.sides) {
        const auto corners = element_corners(m, side.element);
        const topology::CellFace& f =
            cell_topology(side.element.kind).face[index_cast<std::size_t>(side.face)];
        std::vector<Index> face;
        for (int k = 0; k < f.size; ++k)
          face.push_back(corners[index_cast<std::size_t>(f.corners[index_cast<std::size_t>(k)])]);
        faces.insert(key_of(centroid(m, face)));
      }
      s.side_sets.insert({set.id, c.set_names == Carried::kYes ? set.name : "", faces});
    }
  return s;
}

Carried both(Carried a, Carried b) {
  return a == Carried::kYes && b == Carried::kYes ? a : Carried::kNo;
}

}  // namespace

TEST_CASE("round trips: blocks, block names, node sets and side sets through every format pair") {
  const geode::test::TempDir dir;
  const Model original = round_trip_model();
  int pairs = 0;
  for (const MeshFormat& a : mesh_formats()) {
    if (!a.write) continue;
    for (const MeshFormat& b : mesh_formats()) {
      if (!b.write) continue;
      CAPTURE(a.name);
      CAPTURE(b.name);
      const fs::path pa = dir.path / ("a-" + std::string(a.name) + "-" + std::string(b.name) +
                                      std::string(a.extensions.front()));
      const fs::path pb = dir.path / ("b-" + std::string(a.name) + "-" + std::string(b.name) +
                                      std::string(b.extensions.front()));
      // The first with the defaults (binary VTK data), the second as text: both carry it all.
      write_model(original, pa, a.name);
      const Model via_a = read_model(pa);
      WriteOptions text;
      text.vtk_encoding = VtkEncoding::kAscii;
      write_model(via_a, pb, b.name, text);
      const Model via_b = read_model(pb);
      // The reader of a format written only (msh22) is the entry with its extension.
      const FormatCarries& ca = a.carries;
      const FormatCarries& cb = b.carries;
      const FormatCarries c{both(ca.blocks, cb.blocks),       both(ca.block_names, cb.block_names),
                            both(ca.node_sets, cb.node_sets), both(ca.side_sets, cb.side_sets),
                            both(ca.set_names, cb.set_names), {}};
      const Summary want = summary(original, c), got = summary(via_b, c);
      CHECK(got.blocks == want.blocks);
      CHECK(got.block_names == want.block_names);
      CHECK(got.node_sets == want.node_sets);
      CHECK(got.side_sets == want.side_sets);
      ++pairs;
    }
  }
  CHECK(pairs == 25);
}

TEST_CASE("round trips: every format carries blocks, names and sets") {
  // The promise of the README ("nothing lost"), held against the table the test above reads.
  for (const MeshFormat& f : mesh_formats()) {
    CAPTURE(f.name);
    CHECK(f.carries.blocks == Carried::kYes);
    CHECK(f.carries.block_names == Carried::kYes);
    CHECK(f.carries.node_sets == Carried::kYes);
    CHECK(f.carries.side_sets == Carried::kYes);
    CHECK(f.carries.set_names == Carried::kYes);
  }
}
