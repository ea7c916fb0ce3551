// parallel::partition_elements with its options, on demo models as users make them (the half
// model: a hex box beside a tet box meshed together by Gmsh; hexdominant: all four kinds): each
// part gets its share of the weight within METIS's balance bound, the weights are the caller's
// when given, the result is the same twice, and options of the wrong size are refused; the graph
// geode_mpi gives it (the read-time check's face pairs, graph_of_pairs) partitions as well.
#include <doctest/doctest.h>

#include <array>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <geode/parallel/partition.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/submodel.hpp>
#include "support/demo_input.hpp"

namespace gp = geode::primal;
using geode::parallel::partition_elements;
using geode::parallel::PartitionOptions;

namespace {

// Per part: the summed weight of its elements.
std::vector<std::int64_t> loads(const std::vector<int>& part, const std::vector<gp::Index>& weight,
                                int parts) {
  std::vector<std::int64_t> load(static_cast<std::size_t>(parts), 0);
  std::size_t outside = 0;
  for (std::size_t e = 0; e < part.size(); ++e) {
    if (part[e] < 0 || part[e] >= parts)
      ++outside;
    else
      load[static_cast<std::size_t>(part[e])] += weight[e];
  }
  REQUIRE(outside == 0);
  return load;
}

// The hexes each element dices into: the default weights.
std::vector<gp::Index> dicing_weights(const gp::Model& m) {
  std::vector<gp::Index> w;
  for (gp::ElementKind kind : gp::kElementKinds)
    w.insert(w.end(), gp::element_count(m, kind),
             kind == gp::ElementKind::kPyramid ? 8 : gp::cell_topology(kind).corners);
  return w;
}

// Every part within 5 % of its share: METIS's bound is 3 % over (parts 2.6 % and 3.0 % over
// are seen here), and the others are then under by as much.
void require_shares(const std::vector<int>& part, const std::vector<gp::Index>& weight,
                    const std::vector<double>& share) {
  const auto load = loads(part, weight, static_cast<int>(share.size()));
  const double total = static_cast<double>(std::accumulate(load.begin(), load.end(), 0L));
  for (std::size_t p = 0; p < share.size(); ++p) {
    INFO("part " << p << ": " << load[p] << " of " << total << ", share " << share[p]);
    CHECK(static_cast<double>(load[p]) <= 1.05 * share[p] * total);
    CHECK(static_cast<double>(load[p]) >= 0.95 * share[p] * total);
  }
}

}  // namespace

TEST_CASE("partition_elements: parts get their shares, of the dicing weights or the caller's") {
  const geode::test::TempDir dir;
  for (const auto& [name_, n] : {std::pair{"half", 24}, std::pair{"hexdominant", 8}}) {
    // Named again: clang 14 cannot capture a structured binding (CAPTURE's lambda).
    const auto& name = name_;
    CAPTURE(name);
    const gp::Model m = geode::test::demo_input(name, n, dir, ".exo");
    const std::size_t cells = gp::element_offsets(m).back();
    const auto dicing = dicing_weights(m);
    require_shares(partition_elements(m, 2), dicing, {0.5, 0.5});
    for (const std::vector<double>& share :
         {std::vector<double>{0.3, 0.7}, std::vector<double>{0.5, 0.35, 0.15}}) {
      PartitionOptions o;
      o.share = share;
      const auto part = partition_elements(m, static_cast<int>(share.size()), o);
      require_shares(part, dicing, share);
      CHECK(part == partition_elements(m, static_cast<int>(share.size()), o));
    }
    // The caller's weights: the first half of the elements weigh 1, the rest 9.
    PartitionOptions o;
    o.weight.assign(cells, 9);
    std::fill(o.weight.begin(), o.weight.begin() + static_cast<std::ptrdiff_t>(cells / 2), 1);
    o.share = {0.4, 0.6};
    require_shares(partition_elements(m, 2, o), o.weight, o.share);
    // The graph of the check's face pairs, as geode_mpi's rank 0 has it: balanced as well, and
    // a different graph (no quad-triangle joins where pairs cover a quad): its own partition.
    std::vector<std::array<gp::Index, 2>> pairs;
    gp::InputCheckOptions check;
    check.element_pairs = &pairs;
    REQUIRE(gp::check_input(m, check).ok());
    PartitionOptions given;
    given.graph = geode::parallel::graph_of_pairs(cells, pairs);
    CHECK(given.graph.neighbour.size() == 2 * pairs.size());
    require_shares(partition_elements(m, 2, given), dicing, {0.5, 0.5});
    given.graph = geode::parallel::graph_of_pairs(cells - 1, {});
    CHECK_THROWS_AS(partition_elements(m, 2, given), std::invalid_argument);
    pairs.push_back({0, static_cast<gp::Index>(cells)});
    CHECK_THROWS_AS(geode::parallel::graph_of_pairs(cells, pairs), std::invalid_argument);
    // Options of the wrong size.
    PartitionOptions bad;
    bad.weight.assign(cells - 1, 1);
    CHECK_THROWS_AS(partition_elements(m, 2, bad), std::invalid_argument);
    bad = {};
    bad.share = {1.0};
    CHECK_THROWS_AS(partition_elements(m, 2, bad), std::invalid_argument);
  }
}
