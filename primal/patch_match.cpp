#include <geode/primal/patch_match.hpp>

#include <unordered_set>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {
namespace {

std::size_t node_count(std::span<const std::array<int, 4>> quads) {
  std::unordered_set<int> nodes;
  for (const auto& q : quads) nodes.insert(q.begin(), q.end());
  return nodes.size();
}

}  // namespace

PatchMatch match_quad_patches(std::span<const std::array<int, 4>> qa,
                              std::span<const std::array<int, 4>> qb,
                              std::span<const std::pair<int, int>> seeds) {
  PatchMatch r;
  const std::size_t na = node_count(qa), nb = node_count(qb);
  if (na != nb || qa.size() != qb.size()) {
    r.error = "different node or quad counts (" + std::to_string(na) + " nodes, " +
              std::to_string(qa.size()) + " quads against " + std::to_string(nb) + ", " +
              std::to_string(qb.size()) + ")";
    return r;
  }
  auto& m = r.map;
  std::unordered_map<int, int> inv;
  for (const auto& [a, b] : seeds) {
    const auto ia = m.find(a);
    const auto ib = inv.find(b);
    if ((ia != m.end() && ia->second != b) || (ib != inv.end() && ib->second != a)) {
      r.error = "the given corresponding nodes contradict each other";
      return r;
    }
    m[a] = b, inv[b] = a;
  }
  std::vector<bool> done_a(qa.size(), false), done_b(qb.size(), false);
  bool progress = true;
  while (progress) {
    progress = false;
    for (std::size_t i = 0; i < qa.size(); ++i) {
      if (done_a[i]) continue;
      const auto& q = qa[i];
      int found = -1, found_dir = 0, found_s = 0, found_e = 0, candidates = 0;
      for (int e = 0; e < 4 && candidates == 0; ++e) {
        const auto x0 = m.find(q[e]), x1 = m.find(q[(e + 1) % 4]);
        if (x0 == m.end() || x1 == m.end()) continue;
        for (std::size_t j = 0; j < qb.size(); ++j) {
          if (done_b[j]) continue;
          const auto& p = qb[j];
          for (int s = 0; s < 4; ++s) {
            if (p[s] != x0->second) continue;
            for (int dir : {1, 3}) {
              if (p[(s + dir) % 4] != x1->second) continue;
              // q[e + k] -> p[s + k * dir]; every known match must agree.
              bool ok = true;
              for (int k = 0; k < 4 && ok; ++k) {
                const int a = q[(e + k) % 4], b = p[(s + k * dir) % 4];
                const auto ia = m.find(a);
                const auto ib = inv.find(b);
                if (ia != m.end() && ia->second != b) ok = false;
                if (ib != inv.end() && ib->second != a) ok = false;
              }
              if (ok) {
                ++candidates;
                found = static_cast<int>(j), found_dir = dir, found_s = s, found_e = e;
              }
            }
          }
        }
      }
      if (candidates != 1) continue;  // none yet or ambiguous: wait for more matches
      const auto& p = qb[index_cast<std::size_t>(found)];
      for (int k = 0; k < 4; ++k) {
        const int a = q[(found_e + k) % 4], b = p[(found_s + k * found_dir) % 4];
        m[a] = b, inv[b] = a;
      }
      done_a[i] = done_b[index_cast<std::size_t>(found)] = true;
      progress = true;
    }
  }
  if (m.size() != na || inv.size() != nb) r.error = "propagation left nodes unmatched";
  return r;
}

}  // namespace geode::primal
