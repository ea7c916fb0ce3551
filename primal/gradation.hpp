#pragma once
// Limiting how fast a field may change along the edges of a graph, the mesh-size gradation of
// Borouchaki, Hecht and Frey ("Mesh gradation control", IJNME 1998), in its additive form.
#include <utility>
#include <vector>

#include <geode/primal/mesh.hpp>

namespace geode::primal {

struct GradedEdges {
  std::vector<std::pair<Index, Index>> nodes;  // node pairs, nodes 0..n-1 of the field
  std::vector<double> length;                  // per edge, >= 0
};

// The largest field h' <= h with h'(a) <= h'(b) + rate * |ab| on every edge (values only
// decrease). Dijkstra from every node at once: O(E log V).
void grade_down(std::vector<double>& value, const GradedEdges& edges, double rate);

// The smallest field h' >= h with h'(a) >= h'(b) - rate * |ab| on every edge (values only
// increase).
void grade_up(std::vector<double>& value, const GradedEdges& edges, double rate);

}  // namespace geode::primal
