#include "primal/model.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "primal/errors.hpp"
#include "primal/quality.hpp"
#include "primal/topology.hpp"

namespace geode::primal {

int block_of(const Model& model, ElementRef element) {
  if (element.kind == ElementKind::Hex)
    return model.hex_block.empty() ? 1 : model.hex_block[static_cast<std::size_t>(element.index)];
  return model.tet_block.empty() ? 2 : model.tet_block[static_cast<std::size_t>(element.index)];
}

std::int64_t node_id(const Model& model, Index node) {
  const auto n = static_cast<std::size_t>(node);
  return n < model.node_ids.size() ? model.node_ids[n] : std::int64_t{node} + 1;
}

std::int64_t element_id(const Model& model, ElementRef element) {
  const auto& ids = element.kind == ElementKind::Hex ? model.hex_ids : model.tet_ids;
  const auto e = static_cast<std::size_t>(element.index);
  return e < ids.size() ? ids[e] : std::int64_t{element.index} + 1;
}

std::string number_text(double x) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::string point_text(const Point& p) {
  return "(" + number_text(p.x()) + ", " + number_text(p.y()) + ", " + number_text(p.z()) + ")";
}

std::string describe_node(const Model& model, Index node) {
  std::string s = "node " + std::to_string(node_id(model, node));
  if (node >= 0 && static_cast<std::size_t>(node) < model.points.size())
    s += " " + point_text(model.points[static_cast<std::size_t>(node)]);
  return s;
}

std::string node_list(const Model& model, std::span<const Index> nodes) {
  std::string s;
  for (Index v : nodes) s += (s.empty() ? "" : " ") + std::to_string(node_id(model, v));
  return s;
}

namespace {

const char* kind_name(ElementKind kind) { return kind == ElementKind::Hex ? "hex" : "tet"; }

// The element's corners, or an empty span when it does not exist.
std::span<const Index> corners_of(const Model& model, ElementRef e) {
  const auto i = static_cast<std::size_t>(e.index);
  if (e.kind == ElementKind::Hex)
    return e.index >= 0 && i < model.hexes.size() ? std::span<const Index>(model.hexes[i]) : std::span<const Index>();
  return e.index >= 0 && i < model.tets.size() ? std::span<const Index>(model.tets[i]) : std::span<const Index>();
}

}  // namespace

std::string describe_element(const Model& model, ElementRef element) {
  std::string s = std::string(kind_name(element.kind)) + " " + std::to_string(element_id(model, element));
  const auto corners = corners_of(model, element);
  if (corners.empty()) return s;
  Point centre = Point::Zero();
  for (Index v : corners) {
    if (v < 0 || static_cast<std::size_t>(v) >= model.points.size()) return s;
    centre += model.points[static_cast<std::size_t>(v)];
  }
  return s + " (centre " + point_text(centre / static_cast<double>(corners.size())) + ")";
}

namespace {

template <std::size_t N>
void check_elements(const Model& model, const std::vector<std::array<Index, N>>& elements,
                    ElementKind kind, std::string_view source) {
  const auto num_points = static_cast<Index>(model.points.size());
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::size_t c = 0; c < N; ++c) {
      const Index n = elements[e][c];
      if (n < 0 || n >= num_points)
        throw InvalidInput(std::string(source) + ": " + kind_name(kind) + " " +
                           std::to_string(element_id(model, {kind, static_cast<Index>(e)})) +
                           ": corner " + std::to_string(c + 1) + " refers to node index " +
                           std::to_string(n) + ", out of range [0, " + std::to_string(num_points) + ")");
    }
}

void check_blocks(const Model& model, const std::vector<int>& blocks, ElementKind kind,
                  std::string_view source) {
  const std::size_t count = kind == ElementKind::Hex ? model.hexes.size() : model.tets.size();
  if (!blocks.empty() && blocks.size() != count)
    throw InvalidInput(std::string(source) + ": " + kind_name(kind) + " block ids: " +
                       std::to_string(blocks.size()) + " ids for " + std::to_string(count) +
                       " elements");
  for (std::size_t e = 0; e < blocks.size(); ++e)
    if (blocks[e] <= 0)
      throw InvalidInput(std::string(source) + ": " + kind_name(kind) + " " +
                         std::to_string(element_id(model, {kind, static_cast<Index>(e)})) +
                         ": block id " + std::to_string(blocks[e]) + " is not positive");
}

void check_ids(const std::vector<std::int64_t>& ids, std::size_t count, std::string_view source,
               const char* what) {
  if (!ids.empty() && ids.size() != count)
    throw InvalidInput(std::string(source) + ": " + what + " file ids: " + std::to_string(ids.size()) +
                       " ids for " + std::to_string(count) + " entries");
}

}  // namespace

void validate(const Model& model, std::string_view source) {
  const auto num_points = static_cast<Index>(model.points.size());
  check_ids(model.node_ids, model.points.size(), source, "node");
  check_ids(model.hex_ids, model.hexes.size(), source, "hex");
  check_ids(model.tet_ids, model.tets.size(), source, "tet");
  check_elements(model, model.hexes, ElementKind::Hex, source);
  check_elements(model, model.tets, ElementKind::Tet, source);
  check_blocks(model, model.hex_block, ElementKind::Hex, source);
  check_blocks(model, model.tet_block, ElementKind::Tet, source);
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
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to node index " +
                           std::to_string(set.nodes[i]) + ", out of range");
    for (const auto& piece : set.pieces)
      for (Index v : piece)
        if (v < 0 || v >= num_points)
          throw InvalidInput(where + ": a piece refers to node index " + std::to_string(v) + ", out of range");
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
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to " +
                           (hex ? "hex index " : "tet index ") + std::to_string(s.element.index) +
                           ", out of range");
      if (s.face < 0 || s.face >= faces)
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + ": " +
                           describe_element(model, s.element) + ": face " +
                           std::to_string(s.face + 1) + " out of range [1, " + std::to_string(faces) + "]");
    }
  }
}

void check_points(const Model& model, std::string_view source) {
  for (std::size_t n = 0; n < model.points.size(); ++n)
    if (!model.points[n].allFinite())
      throw InvalidInput(std::string(source) + ": " + describe_node(model, static_cast<Index>(n)) +
                         " has a non-finite coordinate");
}

void check_geometry(const Model& model, std::string_view source) {
  const std::string where(source);
  check_points(model, source);
  auto pt = [&](Index v) -> const Point& { return model.points[static_cast<std::size_t>(v)]; };
  for (std::size_t t = 0; t < model.tets.size(); ++t) {
    const auto& c = model.tets[t];
    const double volume = tet_volume(pt(c[0]), pt(c[1]), pt(c[2]), pt(c[3]));
    if (!(volume > 0.0)) {
      const ElementRef e{ElementKind::Tet, static_cast<Index>(t)};
      throw InvalidInput(where + ": " + describe_element(model, e) + " is " +
                         (volume < 0.0 ? "inverted" : "flat") + " (signed volume " +
                         number_text(volume) + "; nodes " + node_list(model, c) + ")");
    }
  }
  for (std::size_t h = 0; h < model.hexes.size(); ++h) {
    HexCorners corners;
    for (std::size_t c = 0; c < 8; ++c) corners[c] = pt(model.hexes[h][c]);
    const auto jacobians = hex_jacobians(corners);
    for (std::size_t c = 0; c < 8; ++c)
      if (!(jacobians[c] > 0.0)) {
        const ElementRef e{ElementKind::Hex, static_cast<Index>(h)};
        throw InvalidInput(where + ": " + describe_element(model, e) + " is " +
                           (jacobians[c] < 0.0 ? "inverted" : "flat") + " at its corner " +
                           describe_node(model, model.hexes[h][c]) + " (corner Jacobian " +
                           number_text(jacobians[c]) + "; nodes " + node_list(model, model.hexes[h]) + ")");
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
    for (auto& piece : set.pieces)
      for (Index& v : piece) v = map(v);
    std::unordered_set<Index> seen;
    std::vector<Index> unique;
    for (Index v : set.nodes)
      if (seen.insert(v).second) unique.push_back(v);
    set.nodes = std::move(unique);
  }
  if (!model.node_ids.empty()) {
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < n; ++i)
      if (representative[i] == static_cast<Index>(i)) ids.push_back(model.node_ids[i]);
    model.node_ids = std::move(ids);
  }
  const auto removed = static_cast<Index>(n - points.size());
  model.points = std::move(points);
  return removed;
}

}  // namespace geode::primal
