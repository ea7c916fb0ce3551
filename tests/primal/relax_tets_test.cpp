// Tet relaxation (primal/relax_tets.hpp) on Gmsh's hybrid meshes as a user's run reads them:
// only the nodes tet_nodes_to_relax allows move (none on the boundary, between blocks, on the
// hex part or in a node set), no tet's diced minimum falls below where its neighbourhood's
// lowest started, the tet part's volume stays, and the result does not depend on the threads.
#include <doctest/doctest.h>

#include <algorithm>
#include <set>

#include <tbb/global_control.h>

#include <geode/primal/dice.hpp>
#include <geode/primal/relax_tets.hpp>
#include <geode/primal/split_pyramids.hpp>
#include "support/demo_input.hpp"
#include "support/temp_dir.hpp"

using namespace geode;
using primal::Index;

namespace {

double tet_volume(const primal::Model& m) {
  double v = 0.0;
  for (const auto& t : m.tets)
    v += primal::tet_volume(m.points[primal::index_cast<std::size_t>(t[0])],
                            m.points[primal::index_cast<std::size_t>(t[1])],
                            m.points[primal::index_cast<std::size_t>(t[2])],
                            m.points[primal::index_cast<std::size_t>(t[3])]);
  return v;
}

}  // namespace

TEST_CASE("tet relaxation: Gmsh's flat pyramids beside a hex part rise, nothing else moves") {
  test::TempDir dir;
  for (const std::string name : {"hexdominant", "hybrid-cylinder"}) {
    CAPTURE(name);
    const primal::Model m = primal::split_pyramids(test::demo_input(name, 6, dir)).model;
    const std::vector<Index> nodes = primal::tet_nodes_to_relax(m, 2);
    REQUIRE(!nodes.empty());
    CHECK(std::is_sorted(nodes.begin(), nodes.end()));
    // None of them on another kind of cell or on a face of one element.
    std::set<Index> other;
    for (const auto& h : m.hexes) other.insert(h.begin(), h.end());
    for (const auto& w : m.wedges) other.insert(w.begin(), w.end());
    for (Index v : nodes) CHECK(other.count(v) == 0);

    primal::Model a = m;
    const primal::RelaxTetsResult r = primal::relax_tet_nodes(a.points, a.tets, nodes);
    CHECK(r.nodes_moved > 0);
    CHECK(r.min_after > r.min_before);
    // Gmsh puts a pyramid with a low apex on the quads: its two tets limit the part diced.
    const double before = primal::diced_min_scaled_jacobian(m.points, m.tets);
    const double after = primal::diced_min_scaled_jacobian(a.points, a.tets);
    CHECK(after >= before);
    MESSAGE(name << ": " << r.nodes_moved << " of " << nodes.size() << " nodes moved, diced min "
                 << before << " -> " << after);
    // Only the listed nodes moved.
    std::vector<char> listed(m.points.size(), 0);
    for (Index v : nodes) listed[primal::index_cast<std::size_t>(v)] = 1;
    for (std::size_t v = 0; v < m.points.size(); ++v)
      if (!listed[v]) CHECK(a.points[v] == m.points[v]);
    // Every tet still positive; the tet part's volume (its boundary fixed) unchanged.
    const auto each = primal::diced_scaled_jacobian_per_cell(a.points, a.tets);
    CHECK(*std::min_element(each.begin(), each.end()) > 0.0);
    CHECK(tet_volume(a) == doctest::Approx(tet_volume(m)).epsilon(1e-12));

    // One thread gives the same points.
    primal::Model b = m;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      primal::relax_tet_nodes(b.points, b.tets, nodes);
    }
    CHECK(b.points == a.points);
  }
}

TEST_CASE("tet relaxation: node sets, block interfaces and the boundary stay") {
  test::TempDir dir;
  primal::Model m = primal::split_pyramids(test::demo_input("hexdominant", 4, dir)).model;
  const std::vector<Index> all = primal::tet_nodes_to_relax(m, 2);
  REQUIRE(all.size() >= 2);
  // A node set naming one free node keeps it.
  m.node_sets.push_back({7, "probe", {all.front()}});
  std::vector<Index> with_set = primal::tet_nodes_to_relax(m, 2);
  CHECK(std::find(with_set.begin(), with_set.end(), all.front()) == with_set.end());
  CHECK(with_set.size() + 1 == all.size());
  m.node_sets.clear();
  // A side set on a face inside the tets (an embedded surface) keeps the face's nodes.
  {
    std::size_t t = 0;
    while (std::find(m.tets[t].begin(), m.tets[t].end(), all.front()) == m.tets[t].end()) ++t;
    m.side_sets.push_back(
        {8, "embedded", {{{primal::ElementKind::kTet, primal::index_cast(t)}, 0}}});
    const std::vector<Index> face = primal::element_face(m, m.side_sets.back().sides.front());
    const std::vector<Index> with_sides = primal::tet_nodes_to_relax(m, 2);
    for (Index v : face)
      CHECK(std::find(with_sides.begin(), with_sides.end(), v) == with_sides.end());
    std::size_t free_on_face = 0;
    for (Index v : face) free_on_face += std::binary_search(all.begin(), all.end(), v);
    CHECK(free_on_face > 0);
    CHECK(with_sides.size() + free_on_face == all.size());
    m.side_sets.clear();
  }
  // A tet of another block at a free node makes that node an interface between materials.
  std::size_t t = 0;
  while (std::find(m.tets[t].begin(), m.tets[t].end(), all.back()) == m.tets[t].end()) ++t;
  if (m.tet_block.empty()) m.tet_block.assign(m.tets.size(), 2);
  m.tet_block[t] = 9;
  const std::vector<Index> blocks = primal::tet_nodes_to_relax(m, 2);
  for (Index v : m.tets[t]) CHECK(std::find(blocks.begin(), blocks.end(), v) == blocks.end());
  // Rings: more rings reach more nodes, none fewer.
  const std::vector<Index> one = primal::tet_nodes_to_relax(m, 1);
  CHECK(one.size() < blocks.size());
  for (Index v : one) CHECK(std::binary_search(blocks.begin(), blocks.end(), v));
}
