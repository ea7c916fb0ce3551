#include "primal/model.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "primal/errors.hpp"
#include "primal/topology.hpp"

namespace geode::primal {

int block_of(const Model& model, ElementRef element) {
  if (element.kind == ElementKind::Hex)
    return model.hex_block.empty() ? 1 : model.hex_block[static_cast<std::size_t>(element.index)];
  return model.tet_block.empty() ? 2 : model.tet_block[static_cast<std::size_t>(element.index)];
}

namespace {

template <std::size_t N>
void check_elements(const std::vector<std::array<Index, N>>& elements, Index num_points,
                    std::string_view source, const char* what) {
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::size_t c = 0; c < N; ++c) {
      const Index n = elements[e][c];
      if (n < 0 || n >= num_points)
        throw InvalidInput(std::string(source) + ": " + what + " " + std::to_string(e) +
                           ": corner " + std::to_string(c) + " refers to node " +
                           std::to_string(n) + ", out of range [0, " +
                           std::to_string(num_points) + ")");
    }
}

void check_blocks(const std::vector<int>& blocks, std::size_t count, std::string_view source,
                  const char* what) {
  if (!blocks.empty() && blocks.size() != count)
    throw InvalidInput(std::string(source) + ": " + what + " block ids: " +
                       std::to_string(blocks.size()) + " ids for " + std::to_string(count) +
                       " elements");
  for (std::size_t e = 0; e < blocks.size(); ++e)
    if (blocks[e] <= 0)
      throw InvalidInput(std::string(source) + ": " + what + " " + std::to_string(e) +
                         ": block id " + std::to_string(blocks[e]) + " is not positive");
}

}  // namespace

void validate(const Model& model, std::string_view source) {
  const auto num_points = static_cast<Index>(model.points.size());
  check_elements(model.hexes, num_points, source, "hex");
  check_elements(model.tets, num_points, source, "tet");
  check_blocks(model.hex_block, model.hexes.size(), source, "hex");
  check_blocks(model.tet_block, model.tets.size(), source, "tet");
  std::unordered_set<int> node_set_ids, side_set_ids;
  for (const NodeSet& set : model.node_sets)
    if (!node_set_ids.insert(set.id).second)
      throw InvalidInput(std::string(source) + ": node set id " + std::to_string(set.id) +
                         " is used twice");
  for (const SideSet& set : model.side_sets)
    if (!side_set_ids.insert(set.id).second)
      throw InvalidInput(std::string(source) + ": side set id " + std::to_string(set.id) +
                         " is used twice");
  for (const NodeSet& set : model.node_sets) {
    const std::string where = std::string(source) + ": node set " + std::to_string(set.id) +
                              " '" + set.name + "'";
    if (set.id <= 0) throw InvalidInput(where + ": id is not positive");
    for (std::size_t i = 0; i < set.nodes.size(); ++i)
      if (set.nodes[i] < 0 || set.nodes[i] >= num_points)
        throw InvalidInput(where + ": entry " + std::to_string(i) + " refers to node " +
                           std::to_string(set.nodes[i]) + ", out of range");
  }
  for (const SideSet& set : model.side_sets) {
    const std::string where = std::string(source) + ": side set " + std::to_string(set.id) +
                              " '" + set.name + "'";
    if (set.id <= 0) throw InvalidInput(where + ": id is not positive");
    for (std::size_t i = 0; i < set.sides.size(); ++i) {
      const Side& s = set.sides[i];
      const bool hex = s.element.kind == ElementKind::Hex;
      const std::size_t count = hex ? model.hexes.size() : model.tets.size();
      const int faces = hex ? topology::kHexFaces : 4;
      if (s.element.index < 0 || static_cast<std::size_t>(s.element.index) >= count)
        throw InvalidInput(where + ": entry " + std::to_string(i) + " refers to " +
                           (hex ? "hex " : "tet ") + std::to_string(s.element.index) +
                           ", out of range");
      if (s.face < 0 || s.face >= faces)
        throw InvalidInput(where + ": entry " + std::to_string(i) + ": face " +
                           std::to_string(s.face) + " out of range");
    }
  }
}

HexMesh hex_part(const Model& model) {
  HexMesh mesh;
  mesh.points = model.points;
  mesh.hexes = model.hexes;
  mesh.block.resize(model.hexes.size());
  for (std::size_t h = 0; h < model.hexes.size(); ++h)
    mesh.block[h] = block_of(model, {ElementKind::Hex, static_cast<Index>(h)});
  return mesh;
}

TetMesh tet_part(const Model& model) {
  TetMesh mesh;
  mesh.points = model.points;
  mesh.tets = model.tets;
  mesh.block.resize(model.tets.size());
  for (std::size_t t = 0; t < model.tets.size(); ++t)
    mesh.block[t] = block_of(model, {ElementKind::Tet, static_cast<Index>(t)});
  return mesh;
}

double tet_volume(const Point& a, const Point& b, const Point& c, const Point& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

Index merge_coincident_nodes(Model& model, double tolerance) {
  const std::size_t n = model.points.size();
  if (n == 0) return 0;
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw InvalidInput("merge_coincident_nodes: tolerance " + std::to_string(tolerance) + " is not a finite value >= 0");
  // Cells no smaller than 1e-12 of the largest coordinate keep every cell index below 1e12 in
  // size (the float -> integer cast must not overflow), whatever the tolerance.
  double largest = 0.0;
  for (const Point& p : model.points) largest = std::max(largest, p.cwiseAbs().maxCoeff());
  if (!std::isfinite(largest)) throw InvalidInput("merge_coincident_nodes: a node has a non-finite coordinate");
  const double cell = std::max({2.0 * tolerance, 1e-12 * largest, 1e-300});
  // Hash each point into a grid of cells of size 2*tol; a partner lies in one of the 27
  // neighbouring cells.
  struct Key {
    long long x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      // Unsigned arithmetic: wraps instead of overflowing.
      return static_cast<std::size_t>(static_cast<unsigned long long>(k.x) * 73856093ull ^
                                      static_cast<unsigned long long>(k.y) * 19349663ull ^
                                      static_cast<unsigned long long>(k.z) * 83492791ull);
    }
  };
  auto key_of = [&](const Point& p) {
    return Key{static_cast<long long>(std::floor(p.x() / cell)),
               static_cast<long long>(std::floor(p.y() / cell)),
               static_cast<long long>(std::floor(p.z() / cell))};
  };
  std::unordered_map<Key, std::vector<Index>, KeyHash> grid;
  std::vector<Index> representative(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = model.points[i];
    const Key k = key_of(p);
    Index found = kInvalidIndex;
    for (long long dx = -1; dx <= 1 && found < 0; ++dx)
      for (long long dy = -1; dy <= 1 && found < 0; ++dy)
        for (long long dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = grid.find(Key{k.x + dx, k.y + dy, k.z + dz});
          if (it == grid.end()) continue;
          for (Index j : it->second)
            if ((model.points[static_cast<std::size_t>(j)] - p).norm() <= tolerance) {
              found = j;
              break;
            }
        }
    if (found >= 0) {
      representative[i] = found;
    } else {
      representative[i] = static_cast<Index>(i);
      grid[k].push_back(static_cast<Index>(i));
    }
  }
  // Compact: new number of each kept point.
  std::vector<Index> new_index(n, kInvalidIndex);
  std::vector<Point> points;
  for (std::size_t i = 0; i < n; ++i)
    if (representative[i] == static_cast<Index>(i)) {
      new_index[i] = static_cast<Index>(points.size());
      points.push_back(model.points[i]);
    }
  auto map = [&](Index v) {
    return new_index[static_cast<std::size_t>(representative[static_cast<std::size_t>(v)])];
  };
  for (auto& h : model.hexes)
    for (Index& v : h) v = map(v);
  for (auto& t : model.tets)
    for (Index& v : t) v = map(v);
  for (NodeSet& set : model.node_sets) {
    for (Index& v : set.nodes) v = map(v);
    std::unordered_set<Index> seen;
    std::vector<Index> unique;
    for (Index v : set.nodes)
      if (seen.insert(v).second) unique.push_back(v);
    set.nodes = std::move(unique);
  }
  const auto removed = static_cast<Index>(n - points.size());
  model.points = std::move(points);
  return removed;
}

}  // namespace geode::primal
