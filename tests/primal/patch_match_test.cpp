// Matching two quad patches topologically (primal/patch_match.hpp): the same mesh renumbered,
// rotated and mirrored is recovered from two seeds; different meshes, contradicting seeds and
// too few seeds are errors, not wrong answers.
#include <doctest/doctest.h>

#include <array>
#include <utility>
#include <vector>

#include <geode/primal/patch_match.hpp>

namespace {

using geode::primal::match_quad_patches;
using Quads = std::vector<std::array<int, 4>>;

// An nx x ny grid of quads, node (i, j) numbered i + (nx + 1) j.
Quads grid(int nx, int ny) {
  Quads q;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = i + (nx + 1) * j;
      q.push_back({a, a + 1, a + nx + 2, a + nx + 1});
    }
  return q;
}

// The patch renumbered by `perm`, each quad starting at another corner, half of them reversed.
Quads renumbered(const Quads& q, const std::vector<int>& perm) {
  Quads out;
  int k = 0;
  for (auto it = q.rbegin(); it != q.rend(); ++it, ++k) {
    std::array<int, 4> r{};
    for (int c = 0; c < 4; ++c) r[c] = perm[(*it)[(c + k) % 4]];
    if (k % 2) std::swap(r[1], r[3]);
    out.push_back(r);
  }
  return out;
}

}  // namespace

TEST_CASE("match_quad_patches recovers a renumbering and a mirror image from two seeds") {
  const Quads a = grid(3, 2);  // 12 nodes
  std::vector<int> perm(12);
  for (int n = 0; n < 12; ++n) perm[n] = (5 * n + 7) % 12;  // a permutation (gcd(5, 12) = 1)
  const Quads b = renumbered(a, perm);
  const std::vector<std::pair<int, int>> seeds{{0, perm[0]}, {1, perm[1]}};
  const auto m = match_quad_patches(a, b, seeds);
  REQUIRE(m.ok());
  REQUIRE(m.map.size() == 12);
  for (int n = 0; n < 12; ++n) CHECK(m.map.at(n) == perm[n]);

  // Mirror: node (i, j) -> (3 - i, j); seeded on the bottom row it is found, not the identity.
  const std::vector<std::pair<int, int>> mirror_seeds{{0, 3}, {1, 2}};
  const auto mm = match_quad_patches(a, a, mirror_seeds);
  REQUIRE(mm.ok());
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 3; ++i) CHECK(mm.map.at(i + 4 * j) == (3 - i) + 4 * j);
}

TEST_CASE("match_quad_patches: meshes that differ, contradicting or too few seeds are errors") {
  const Quads a = grid(2, 2);
  struct Row {
    const char* name;
    Quads b;
    std::vector<std::pair<int, int>> seeds;
  };
  const Row rows[] = {
      {"another mesh (a 4 x 1 strip)", grid(4, 1), {{0, 0}, {1, 1}}},
      {"a seed contradicting another", grid(2, 2), {{0, 0}, {1, 1}, {0, 2}}},
      {"one seed: nothing to propagate from", grid(2, 2), {{0, 0}}},
      {"seeds across a diagonal do not form an edge of B", grid(2, 2), {{0, 0}, {1, 4}}},
  };
  for (const Row& r : rows) {
    CAPTURE(r.name);
    const auto m = match_quad_patches(a, r.b, r.seeds);
    CHECK_FALSE(m.ok());
  }
}
