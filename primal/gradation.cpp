#include <geode/primal/gradation.hpp>

#include <functional>
#include <queue>

namespace geode::primal {

void grade_down(std::vector<double>& value, const GradedEdges& edges, double rate) {
  const std::size_t n = value.size();
  std::vector<std::vector<std::pair<std::size_t, double>>> adjacent(n);
  for (std::size_t e = 0; e < edges.nodes.size(); ++e) {
    const auto a = index_cast<std::size_t>(edges.nodes[e].first),
               b = index_cast<std::size_t>(edges.nodes[e].second);
    adjacent[a].push_back({b, rate * edges.length[e]});
    adjacent[b].push_back({a, rate * edges.length[e]});
  }
  // Smallest values first: a value popped is final, as in Dijkstra's shortest paths with every
  // node a source at its own value.
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (std::size_t v = 0; v < n; ++v) queue.push({value[v], v});
  std::vector<char> settled(n, 0);
  while (!queue.empty()) {
    const auto [h, v] = queue.top();
    queue.pop();
    if (settled[v] || h > value[v]) continue;
    settled[v] = 1;
    for (const auto& [u, step] : adjacent[v])
      if (h + step < value[u]) {
        value[u] = h + step;
        queue.push({value[u], u});
      }
  }
}

void grade_up(std::vector<double>& value, const GradedEdges& edges, double rate) {
  for (double& v : value) v = -v;
  grade_down(value, edges, rate);
  for (double& v : value) v = -v;
}

}  // namespace geode::primal
