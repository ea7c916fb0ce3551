// Mesh-size gradation: the result meets the rate on every edge, moves values only one way, and
// is the extreme such field (the fixed point of relaxing every edge, found here by brute force).
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include <geode/primal/gradation.hpp>

using namespace geode::primal;

TEST_CASE("grade_down / grade_up on a path, by hand") {
  const GradedEdges path{{{0, 1}, {1, 2}, {2, 3}}, {1.0, 1.0, 1.0}};
  std::vector<double> down{1.0, 5.0, 5.0, 0.2};
  grade_down(down, path, 0.5);
  CHECK(down == std::vector<double>{1.0, 1.2, 0.7, 0.2});
  std::vector<double> up{1.0, 0.0, 0.0, 3.0};
  grade_up(up, path, 0.5);
  CHECK(up == std::vector<double>{1.5, 2.0, 2.5, 3.0});
}

TEST_CASE("grade_down: the largest field below the input meeting the rate, on a random graph") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 60;
  GradedEdges g;
  for (int e = 0; e < 150; ++e) {
    const Index a = index_cast(rng() % n), b = index_cast(rng() % n);
    g.nodes.push_back({a, b});
    g.length.push_back(u(rng));
  }
  std::vector<double> value(n);
  for (double& v : value) v = u(rng);
  const double rate = 0.3;
  std::vector<double> fast = value;
  grade_down(fast, g, rate);
  // Brute force: relax every edge until nothing changes.
  std::vector<double> slow = value;
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t e = 0; e < g.nodes.size(); ++e) {
      const auto [a, b] = g.nodes[e];
      for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}})
        if (slow[y] + rate * g.length[e] < slow[x])
          slow[x] = slow[y] + rate * g.length[e], changed = true;
    }
  }
  for (int v = 0; v < n; ++v) {
    CHECK(fast[v] == doctest::Approx(slow[v]).epsilon(1e-12));
    CHECK(fast[v] <= value[v]);
  }
  for (std::size_t e = 0; e < g.nodes.size(); ++e) {
    const auto [a, b] = g.nodes[e];
    CHECK(std::abs(fast[a] - fast[b]) <= rate * g.length[e] + 1e-12);
  }
}
