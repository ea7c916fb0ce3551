#include <geode/primal/model.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <unordered_map>

#include <Eigen/Geometry>
#include <unordered_set>

#include <geode/primal/errors.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

const topology::CellKindTopology& cell_topology(ElementKind kind) {
  return topology::kCellKinds[static_cast<std::size_t>(kind)];
}

const char* element_kind_name(ElementKind kind) { return cell_topology(kind).name; }

int default_block(ElementKind kind) { return static_cast<int>(kind) + 1; }

std::size_t element_count(const Model& model, ElementKind kind) {
  switch (kind) {
    case ElementKind::kHex:
      return model.hexes.size();
    case ElementKind::kTet:
      return model.tets.size();
    case ElementKind::kPyramid:
      return model.pyramids.size();
    case ElementKind::kWedge:
      return model.wedges.size();
  }
  return 0;
}

std::size_t element_count(const Model& model) {
  std::size_t n = 0;
  for (ElementKind k : kElementKinds) n += element_count(model, k);
  return n;
}

std::span<const Index> element_corners(const Model& model, ElementRef e) {
  if (e.index < 0 || index_cast<std::size_t>(e.index) >= element_count(model, e.kind)) return {};
  const auto i = index_cast<std::size_t>(e.index);
  switch (e.kind) {
    case ElementKind::kHex:
      return model.hexes[i];
    case ElementKind::kTet:
      return model.tets[i];
    case ElementKind::kPyramid:
      return model.pyramids[i];
    case ElementKind::kWedge:
      return model.wedges[i];
  }
  return {};
}

std::vector<int>& element_blocks(Model& model, ElementKind kind) {
  switch (kind) {
    case ElementKind::kHex:
      return model.hex_block;
    case ElementKind::kTet:
      return model.tet_block;
    case ElementKind::kPyramid:
      return model.pyramid_block;
    case ElementKind::kWedge:
      break;
  }
  return model.wedge_block;
}

const std::vector<int>& element_blocks(const Model& model, ElementKind kind) {
  return element_blocks(const_cast<Model&>(model), kind);
}

std::vector<std::int64_t>& element_ids(Model& model, ElementKind kind) {
  switch (kind) {
    case ElementKind::kHex:
      return model.hex_ids;
    case ElementKind::kTet:
      return model.tet_ids;
    case ElementKind::kPyramid:
      return model.pyramid_ids;
    case ElementKind::kWedge:
      break;
  }
  return model.wedge_ids;
}

const std::vector<std::int64_t>& element_ids(const Model& model, ElementKind kind) {
  return element_ids(const_cast<Model&>(model), kind);
}

std::vector<Index> element_face(const Model& model, const Side& side) {
  const auto corners = element_corners(model, side.element);
  const auto& topo = cell_topology(side.element.kind);
  std::vector<Index> face;
  if (corners.empty() || side.face < 0 || side.face >= topo.faces) return face;
  const auto& f = topo.face[index_cast<std::size_t>(side.face)];
  for (int k = 0; k < f.size; ++k)
    face.push_back(corners[index_cast<std::size_t>(f.corners[index_cast<std::size_t>(k)])]);
  return face;
}

std::vector<Side> tet_sides_on(const Model& model, Index first, Index count,
                               std::span<const Index> face) {
  std::vector<Side> out;
  for (Index t = first; t < first + count; ++t)
    for (int f = 0; f < 4; ++f) {
      bool on = true;
      for (int k : topology::kTetFaceCorners[index_cast<std::size_t>(f)])
        on = on && std::find(face.begin(), face.end(),
                             model.tets[index_cast<std::size_t>(t)][index_cast<std::size_t>(k)]) !=
                       face.end();
      if (on) out.push_back({{ElementKind::kTet, t}, f});
    }
  return out;
}

void rewrite_sides(Model& model, const std::function<void(const Side&, std::vector<Side>&)>& map) {
  for (SideSet& set : model.side_sets) {
    std::vector<Side> sides;
    for (const Side& s : set.sides) map(s, sides);
    std::sort(sides.begin(), sides.end());
    set.sides = std::move(sides);
  }
}

void add_element(Model& model, ElementKind kind, std::span<const Index> corners, int block,
                 std::int64_t file_id) {
  const auto n = static_cast<std::size_t>(cell_topology(kind).corners);
  auto put = [&](auto& cells) {
    auto& c = cells.emplace_back();
    for (std::size_t k = 0; k < n; ++k) c[k] = corners[k];
  };
  with_cells(model, kind, put);
  element_blocks(model, kind).push_back(block);
  element_ids(model, kind).push_back(file_id);
}

namespace {
std::array<Index, 4> sorted_key(std::span<const Index> nodes) {
  std::array<Index, 4> k{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  std::copy_n(nodes.begin(), std::min<std::size_t>(nodes.size(), 4), k.begin());
  std::sort(k.begin(),
            k.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(nodes.size(), 4)));
  return k;
}
}  // namespace

std::size_t FaceOwners::Hash::operator()(const std::array<Index, 4>& k) const {
  std::size_t h = 0;
  for (Index v : k)
    h = h * 0x9E3779B97F4A7C15ull + index_cast<std::size_t>(static_cast<std::uint32_t>(v));
  return h ^ (h >> 29);
}

FaceOwners::FaceOwners(const Model& model) {
  for (ElementKind kind : kElementKinds) {
    const auto& topo = cell_topology(kind);
    for (std::size_t e = 0; e < element_count(model, kind); ++e) {
      const ElementRef ref{kind, index_cast(e)};
      const auto corners = element_corners(model, ref);
      for (int f = 0; f < topo.faces; ++f) {
        const auto& face = topo.face[index_cast<std::size_t>(f)];
        std::array<Index, 4> nodes{};
        for (int k = 0; k < face.size; ++k)
          nodes[index_cast<std::size_t>(k)] =
              corners[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(k)])];
        owner_.emplace(
            sorted_key(std::span<const Index>(nodes.data(), index_cast<std::size_t>(face.size))),
            Side{ref, f});
      }
    }
  }
}

const Side* FaceOwners::find(std::span<const Index> nodes) const {
  const auto it = owner_.find(sorted_key(nodes));
  return it == owner_.end() ? nullptr : &it->second;
}

std::vector<MovedGroup> separate_node_set_ids(std::span<TaggedCells> groups,
                                              const std::string& source) {
  std::set<int> point_tags;
  int highest = 0;
  for (const TaggedCells& g : groups)
    if (g.dim < 2) {
      if (g.dim == 0) point_tags.insert(g.id);
      highest = std::max(highest, g.id);
    }
  int shift = 1;
  while (shift <= highest && shift <= std::numeric_limits<int>::max() / 10) shift *= 10;
  std::vector<MovedGroup> moved;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    TaggedCells& g = groups[k];
    if (g.dim != 1 || !point_tags.count(g.id)) continue;
    if (shift <= highest || g.id > std::numeric_limits<int>::max() - shift)
      throw InvalidInput(source + ": the points and lines tagged " + std::to_string(g.id) +
                         " would be two node sets of one id, and no other id is free");
    moved.push_back({k, g.id});
    g.id += shift;
  }
  return moved;
}

void add_tagged_sets(Model& model, std::span<const TaggedCells> groups, const std::string& source,
                     const std::string& cell_word) {
  FaceOwners owners;
  if (std::any_of(groups.begin(), groups.end(), [](const TaggedCells& g) { return g.dim == 2; }))
    owners = FaceOwners(model);
  for (const TaggedCells& g : groups) {
    if (g.dim == 2) {
      SideSet set{g.id, g.name, {}};
      for (std::size_t c = 0; c < g.cells.size(); ++c) {
        const Side* owner =
            g.cells[c].size() == 3 || g.cells[c].size() == 4 ? owners.find(g.cells[c]) : nullptr;
        if (!owner)
          throw InvalidInput(source + ": side set " + std::to_string(g.id) +
                             (g.name.empty() ? "" : " '" + g.name + "'") + ": " + cell_word + " " +
                             std::to_string(g.cell_ids[c]) +
                             " is not a face of any volume element");
        set.sides.push_back(*owner);
      }
      std::sort(set.sides.begin(), set.sides.end());
      set.sides.erase(std::unique(set.sides.begin(), set.sides.end()), set.sides.end());
      model.side_sets.push_back(std::move(set));
    } else {
      NodeSet set{g.id, g.name, {}, {}};
      for (const auto& cell : g.cells) {
        set.nodes.insert(set.nodes.end(), cell.begin(), cell.end());
        set.pieces.push_back(cell);
      }
      std::sort(set.nodes.begin(), set.nodes.end());
      set.nodes.erase(std::unique(set.nodes.begin(), set.nodes.end()), set.nodes.end());
      model.node_sets.push_back(std::move(set));
    }
  }
}

int block_of(const Model& model, ElementRef element) {
  const auto& blocks = element_blocks(model, element.kind);
  return blocks.empty() ? default_block(element.kind)
                        : blocks[index_cast<std::size_t>(element.index)];
}

void join_blocks(Model& model, std::span<const int> ids, std::string_view source) {
  const auto list = [&] {
    std::string text;
    for (int id : ids) text += (text.empty() ? "" : ",") + std::to_string(id);
    return text;
  };
  const auto refuse = [&](const std::string& why) {
    throw InvalidInput(std::string(source) + ": joining blocks " + list() + ": " + why);
  };
  if (ids.size() < 2) refuse("give two blocks or more");
  std::set<int> used, listed;
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(model, kind); ++e)
      used.insert(block_of(model, {kind, index_cast(e)}));
  for (int id : ids) {
    if (!listed.insert(id).second) refuse("block " + std::to_string(id) + " is listed twice");
    if (!used.count(id)) refuse("no element is in block " + std::to_string(id));
  }
  for (ElementKind kind : kElementKinds) {
    std::vector<int>& blocks = element_blocks(model, kind);
    if (blocks.empty()) blocks.assign(element_count(model, kind), default_block(kind));
    for (int& b : blocks)
      if (listed.count(b)) b = ids.front();
  }
  for (int id : ids.subspan(1)) model.block_names.erase(id);
}

// A number outside the model's (kInvalidIndex in a message) is named as its 1-based self.
std::int64_t node_id(const Model& model, Index node) {
  return node >= 0 && index_cast<std::size_t>(node) < model.node_ids.size()
             ? model.node_ids[index_cast<std::size_t>(node)]
             : std::int64_t{node} + 1;
}

std::int64_t element_id(const Model& model, ElementRef element) {
  const auto& ids = element_ids(model, element.kind);
  return element.index >= 0 && index_cast<std::size_t>(element.index) < ids.size()
             ? ids[index_cast<std::size_t>(element.index)]
             : std::int64_t{element.index} + 1;
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
  if (node >= 0 && index_cast<std::size_t>(node) < model.points.size())
    s += " " + point_text(model.points[index_cast<std::size_t>(node)]);
  return s;
}

std::string node_list(const Model& model, std::span<const Index> nodes) {
  std::string s;
  for (Index v : nodes) s += (s.empty() ? "" : " ") + std::to_string(node_id(model, v));
  return s;
}

namespace {

const char* kind_name(ElementKind kind) { return element_kind_name(kind); }

}  // namespace

std::string describe_element(const Model& model, ElementRef element) {
  std::string s =
      std::string(kind_name(element.kind)) + " " + std::to_string(element_id(model, element));
  const auto corners = element_corners(model, element);
  if (corners.empty()) return s;
  Point centre = Point::Zero();
  for (Index v : corners) {
    if (v < 0 || index_cast<std::size_t>(v) >= model.points.size()) return s;
    centre += model.points[index_cast<std::size_t>(v)];
  }
  return s + " (centre " + point_text(centre / static_cast<double>(corners.size())) + ")";
}

namespace {

// Typed per kind: element_corners' span per element was most of validating a written mesh.
template <std::size_t N>
void check_elements(const Model& model, ElementKind kind,
                    const std::vector<std::array<Index, N>>& cells, std::string_view source) {
  const auto num_points = index_cast(model.points.size());
  // A run of cells at a time, four node numbers a step (GCC/Clang vector types: SSE2, NEON),
  // without a branch per cell, so the scan runs at memory speed; a run that fails is looked at
  // cell by cell for the first offender. Every model read or written passes here (a conform run
  // of the n = 36 bench, its input and its 1.15 million output hexes: 24 -> 7 ms).
  using Lanes = std::int32_t __attribute__((vector_size(16)));
  static_assert(sizeof(Index) == 4 && sizeof(cells[0]) == N * sizeof(Index));
  constexpr std::size_t kRun = 256;
  const Lanes zero{0, 0, 0, 0};
  const Lanes last_node = zero + (num_points - 1);
  for (std::size_t first = 0; first < cells.size(); first += kRun) {
    const std::size_t last = std::min(cells.size(), first + kRun);
    const auto* at = reinterpret_cast<const unsigned char*>(cells.data() + first);
    const std::size_t bytes = (last - first) * sizeof(cells[0]);
    Lanes bad = zero;
    std::size_t k = 0;
    for (; k + sizeof(Lanes) <= bytes; k += sizeof(Lanes)) {
      Lanes n;
      std::memcpy(&n, at + k, sizeof(Lanes));
      bad |= (n < zero) | (n > last_node);
    }
    bool inside = !(bad[0] | bad[1] | bad[2] | bad[3]);
    for (; k < bytes; k += sizeof(Index)) {  // a tail of fewer than four numbers
      Index n;
      std::memcpy(&n, at + k, sizeof(Index));
      inside &= n >= 0 && n < num_points;
    }
    if (inside) continue;
    for (std::size_t e = first; e < last; ++e)
      for (std::size_t c = 0; c < N; ++c) {
        const Index n = cells[e][c];
        if (n < 0 || n >= num_points)
          throw InvalidInput(std::string(source) + ": " + kind_name(kind) + " " +
                             std::to_string(element_id(model, {kind, index_cast(e)})) +
                             ": corner " + std::to_string(c + 1) + " refers to node index " +
                             std::to_string(n) + ", out of range [0, " +
                             std::to_string(num_points) + ")");
      }
  }
}

void check_elements(const Model& model, ElementKind kind, std::string_view source) {
  with_cells(model, kind, [&](const auto& cells) { check_elements(model, kind, cells, source); });
}

void check_blocks(const Model& model, ElementKind kind, std::string_view source) {
  const std::vector<int>& blocks = element_blocks(model, kind);
  const std::size_t count = element_count(model, kind);
  if (!blocks.empty() && blocks.size() != count)
    throw InvalidInput(std::string(source) + ": " + kind_name(kind) +
                       " block ids: " + std::to_string(blocks.size()) + " ids for " +
                       std::to_string(count) + " elements");
  if (std::all_of(blocks.begin(), blocks.end(), [](int b) { return b > 0; })) return;
  for (std::size_t e = 0; e < blocks.size(); ++e)
    if (blocks[e] <= 0)
      throw InvalidInput(std::string(source) + ": " + kind_name(kind) + " " +
                         std::to_string(element_id(model, {kind, index_cast(e)})) + ": block id " +
                         std::to_string(blocks[e]) + " is not positive");
}

void check_ids(const std::vector<std::int64_t>& ids, std::size_t count, std::string_view source,
               const char* what) {
  if (!ids.empty() && ids.size() != count)
    throw InvalidInput(std::string(source) + ": " + what +
                       " file ids: " + std::to_string(ids.size()) + " ids for " +
                       std::to_string(count) + " entries");
}

}  // namespace

void validate(const Model& model, std::string_view source) {
  const auto num_points = index_cast(model.points.size());
  check_ids(model.node_ids, model.points.size(), source, "node");
  for (ElementKind kind : kElementKinds) {
    check_ids(element_ids(model, kind), element_count(model, kind), source, kind_name(kind));
    check_elements(model, kind, source);
    check_blocks(model, kind, source);
  }
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
    const std::string where =
        std::string(source) + ": node set " + std::to_string(set.id) + " '" + set.name + "'";
    if (set.id <= 0) throw InvalidInput(where + ": id is not positive");
    for (std::size_t i = 0; i < set.nodes.size(); ++i)
      if (set.nodes[i] < 0 || set.nodes[i] >= num_points)
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to node index " +
                           std::to_string(set.nodes[i]) + ", out of range");
    for (const auto& piece : set.pieces)
      for (Index v : piece)
        if (v < 0 || v >= num_points)
          throw InvalidInput(where + ": a piece refers to node index " + std::to_string(v) +
                             ", out of range");
  }
  for (const SideSet& set : model.side_sets) {
    const std::string where =
        std::string(source) + ": side set " + std::to_string(set.id) + " '" + set.name + "'";
    if (set.id <= 0) throw InvalidInput(where + ": id is not positive");
    for (std::size_t i = 0; i < set.sides.size(); ++i) {
      const Side& s = set.sides[i];
      const std::size_t count = element_count(model, s.element.kind);
      const int faces = cell_topology(s.element.kind).faces;
      if (s.element.index < 0 || index_cast<std::size_t>(s.element.index) >= count)
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + " refers to " +
                           kind_name(s.element.kind) + " index " + std::to_string(s.element.index) +
                           ", out of range");
      if (s.face < 0 || s.face >= faces)
        throw InvalidInput(where + ": entry " + std::to_string(i + 1) + ": " +
                           describe_element(model, s.element) + ": face " +
                           std::to_string(s.face + 1) + " out of range [1, " +
                           std::to_string(faces) + "]");
    }
  }
}

void check_points(const Model& model, std::string_view source) {
  for (std::size_t n = 0; n < model.points.size(); ++n)
    if (!model.points[n].allFinite()) {
      // A node no element uses is refused too (whatever reads every point, a bounding box, a
      // merge of coincident nodes, would take it in): said, so that the user looks for a stray
      // node rather than a broken element.
      bool used = false;
      for (ElementKind kind : kElementKinds)
        for (std::size_t e = 0; e < element_count(model, kind) && !used; ++e)
          for (Index v : element_corners(model, {kind, index_cast(e)})) used |= v == index_cast(n);
      throw InvalidInput(std::string(source) + ": " + describe_node(model, index_cast(n)) +
                         " has a non-finite coordinate" + (used ? "" : " (no element uses it)"));
    }
}

std::array<double, 4> pyramid_corner_volumes(const Model& model, const std::array<Index, 5>& c) {
  const auto pt = [&](Index v) -> const Point& { return model.points[index_cast<std::size_t>(v)]; };
  std::array<double, 4> v{};
  for (std::size_t k = 0; k < 4; ++k)
    v[k] =
        tet_volume(pt(c[(k + 3) % 4]), pt(c[k]), pt(c[(k + 1) % 4]), pt(c[topology::kPyramidApex]));
  return v;
}

bool splits_positive(const std::array<double, 4>& v) {
  return (v[1] > 0.0 && v[3] > 0.0) || (v[0] > 0.0 && v[2] > 0.0);
}

std::vector<std::string> geometry_findings(const Model& model, std::size_t max_findings,
                                           std::string_view inverted_hint) {
  std::vector<std::string> found;
  // Adds a finding; true once there are max_findings.
  const auto add = [&](std::string text) {
    found.push_back(std::move(text));
    return found.size() >= max_findings;
  };
  if (max_findings == 0) return found;
  // An element listing a node twice is flat or folded, but a writer's fault, not a fold: said
  // as such, without the hint (--unfold moves nodes and cannot mend it). True if it did.
  const auto repeats = [&](ElementRef ref) {
    const auto c = element_corners(model, ref);
    for (std::size_t i = 0; i < c.size(); ++i)
      if (std::find(c.begin() + static_cast<std::ptrdiff_t>(i) + 1, c.end(), c[i]) != c.end()) {
        add(describe_element(model, ref) + " lists " + describe_node(model, c[i]) +
            " twice (nodes " + node_list(model, c) + ")");
        return true;
      }
    return false;
  };
  const auto full = [&] { return found.size() >= max_findings; };
  auto pt = [&](Index v) -> const Point& { return model.points[index_cast<std::size_t>(v)]; };
  for (std::size_t t = 0; t < model.tets.size(); ++t) {
    const auto& c = model.tets[t];
    const double volume = tet_volume(pt(c[0]), pt(c[1]), pt(c[2]), pt(c[3]));
    if (!(volume > 0.0)) {
      const ElementRef e{ElementKind::kTet, index_cast(t)};
      if (repeats(e)) {
        if (full()) return found;
        continue;
      }
      if (add(describe_element(model, e) + " is " + (volume < 0.0 ? "inverted" : "flat") +
              " (signed volume " + number_text(volume) + "; nodes " + node_list(model, c) + ")" +
              std::string(inverted_hint)))
        return found;
    }
  }
  for (std::size_t h = 0; h < model.hexes.size(); ++h) {
    HexCorners corners;
    for (std::size_t c = 0; c < 8; ++c) corners[c] = pt(model.hexes[h][c]);
    const auto jacobians = hex_jacobians(corners);
    for (std::size_t c = 0; c < 8; ++c)
      if (!(jacobians[c] > 0.0)) {
        const ElementRef e{ElementKind::kHex, index_cast(h)};
        if (repeats(e)) {
          if (full()) return found;
          break;
        }
        if (add(describe_element(model, e) + " is " + (jacobians[c] < 0.0 ? "inverted" : "flat") +
                " at its corner " + describe_node(model, model.hexes[h][c]) + " (corner Jacobian " +
                number_text(jacobians[c]) + "; nodes " + node_list(model, model.hexes[h]) + ")"))
          return found;
        break;  // one finding per element
      }
  }
  // A wedge's corner Jacobian: the determinant of its three edges there (topology.hpp's
  // right-handed kWedgeCornerNeighbors), positive at all six corners.
  for (std::size_t w = 0; w < model.wedges.size(); ++w) {
    const auto& c = model.wedges[w];
    for (std::size_t k = 0; k < 6; ++k) {
      const auto& n = topology::kWedgeCornerNeighbors[k];
      const double j =
          tet_volume(pt(c[k]), pt(c[index_cast<std::size_t>(n[0])]),
                     pt(c[index_cast<std::size_t>(n[1])]), pt(c[index_cast<std::size_t>(n[2])])) *
          6.0;
      if (!(j > 0.0)) {
        const ElementRef e{ElementKind::kWedge, index_cast(w)};
        if (repeats(e)) {
          if (full()) return found;
          break;
        }
        if (add(describe_element(model, e) + " is " + (j < 0.0 ? "inverted" : "flat") +
                " at its corner " + describe_node(model, c[k]) + " (corner Jacobian " +
                number_text(j) + "; nodes " + node_list(model, c) + ")"))
          return found;
        break;  // one finding per element
      }
    }
  }
  // A pyramid must split into two positive tets along one of its base diagonals: what conform
  // makes of it.
  for (std::size_t p = 0; p < model.pyramids.size(); ++p) {
    const auto& c = model.pyramids[p];
    const std::array<double, 4> corner = pyramid_corner_volumes(model, c);
    if (!splits_positive(corner)) {
      if (repeats({ElementKind::kPyramid, index_cast(p)})) {
        if (full()) return found;
        continue;
      }
      const auto worst =
          index_cast<std::size_t>(std::min_element(corner.begin(), corner.end()) - corner.begin());
      const ElementRef e{ElementKind::kPyramid, index_cast(p)};
      if (add(describe_element(model, e) + " is " + (corner[worst] < 0.0 ? "inverted" : "flat") +
              " at its base corner " + describe_node(model, c[worst]) + " (signed volume " +
              number_text(corner[worst]) +
              " of the tet there, and neither base diagonal gives two " + "positive tets; nodes " +
              node_list(model, c) + ")" + std::string(inverted_hint)))
        return found;
    }
  }
  // A node set's node no element uses has no node in any output made from the elements: the
  // set would lose it without a word (a Gmsh file saved without the elements of a volume in no
  // physical group keeps that volume's points and curves).
  if (model.node_sets.empty()) return found;
  std::vector<char> used(model.points.size(), 0);
  for (ElementKind kind : kElementKinds)
    for (std::size_t e = 0; e < element_count(model, kind); ++e)
      for (Index v : element_corners(model, {kind, index_cast(e)}))
        used[index_cast<std::size_t>(v)] = 1;
  for (const NodeSet& set : model.node_sets)
    for (Index v : set.nodes)
      if (!used[index_cast<std::size_t>(v)])
        if (add("node set " + std::to_string(set.id) + " '" + set.name +
                "': " + describe_node(model, v) + " belongs to no element"))
          return found;
  return found;
}

void check_geometry(const Model& model, std::string_view source, std::string_view inverted_hint) {
  check_points(model, source);
  const std::vector<std::string> found = geometry_findings(model, 1, inverted_hint);
  if (!found.empty()) throw InvalidInput(std::string(source) + ": " + found.front());
}

HexMesh hex_part(const Model& model) {
  HexMesh mesh;
  mesh.points = model.points;
  mesh.hexes = model.hexes;
  mesh.block.resize(model.hexes.size());
  for (std::size_t h = 0; h < model.hexes.size(); ++h)
    mesh.block[h] = block_of(model, {ElementKind::kHex, index_cast(h)});
  return mesh;
}

TetMesh tet_part(const Model& model) {
  TetMesh mesh;
  mesh.points = model.points;
  mesh.tets = model.tets;
  mesh.block.resize(model.tets.size());
  for (std::size_t t = 0; t < model.tets.size(); ++t)
    mesh.block[t] = block_of(model, {ElementKind::kTet, index_cast(t)});
  return mesh;
}

double tet_volume(const Point& a, const Point& b, const Point& c, const Point& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

double coincident_tolerance(const Model& model) {
  if (model.points.empty()) return 0.0;
  Eigen::AlignedBox3d box;
  for (const Point& p : model.points) box.extend(p);
  return 1e-9 * box.diagonal().norm();
}

Index merge_coincident_nodes(Model& model, double tolerance) {
  const std::size_t n = model.points.size();
  if (n == 0) return 0;
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw InvalidInput("merge_coincident_nodes: tolerance " + std::to_string(tolerance) +
                       " is not a finite value >= 0");
  // Cells no smaller than 1e-12 of the largest coordinate keep every cell index below 1e12 in
  // size (the float -> integer cast must not overflow), whatever the tolerance.
  double largest = 0.0;
  for (const Point& p : model.points) largest = std::max(largest, p.cwiseAbs().maxCoeff());
  if (!std::isfinite(largest))
    throw InvalidInput("merge_coincident_nodes: a node has a non-finite coordinate");
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
      return index_cast<std::size_t>(static_cast<unsigned long long>(k.x) * 73856093ull ^
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
            if ((model.points[index_cast<std::size_t>(j)] - p).norm() <= tolerance) {
              found = j;
              break;
            }
        }
    if (found >= 0) {
      representative[i] = found;
    } else {
      representative[i] = index_cast(i);
      grid[k].push_back(index_cast(i));
    }
  }
  // Compact: new number of each kept point.
  std::vector<Index> new_index(n, kInvalidIndex);
  std::vector<Point> points;
  for (std::size_t i = 0; i < n; ++i)
    if (representative[i] == index_cast(i)) {
      new_index[i] = index_cast(points.size());
      points.push_back(model.points[i]);
    }
  auto map = [&](Index v) {
    return new_index[index_cast<std::size_t>(representative[index_cast<std::size_t>(v)])];
  };
  for (auto& h : model.hexes)
    for (Index& v : h) v = map(v);
  for (auto& t : model.tets)
    for (Index& v : t) v = map(v);
  for (auto& p : model.pyramids)
    for (Index& v : p) v = map(v);
  for (auto& w : model.wedges)
    for (Index& v : w) v = map(v);
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
      if (representative[i] == index_cast(i)) ids.push_back(model.node_ids[i]);
    model.node_ids = std::move(ids);
  }
  const auto removed = index_cast(n - points.size());
  model.points = std::move(points);
  return removed;
}

void check_merge_tolerance(const Model& model, double tolerance, const std::string& option) {
  double shortest = std::numeric_limits<double>::infinity();
  ElementRef where;
  for (ElementKind kind : kElementKinds) {
    const topology::CellKindTopology& t = cell_topology(kind);
    with_cells(model, kind, [&](const auto& cells) {
      for (std::size_t e = 0; e < cells.size(); ++e)
        for (int k = 0; k < t.edges; ++k) {
          const double l = (model.points[index_cast<std::size_t>(cells[e][t.edge[k][0]])] -
                            model.points[index_cast<std::size_t>(cells[e][t.edge[k][1]])])
                               .norm();
          if (l < shortest) shortest = l, where = {kind, index_cast(e)};
        }
    });
  }
  if (tolerance < shortest) return;
  std::ostringstream m;
  m << option << (option.ends_with('=') ? "" : " ") << tolerance
    << " is not below the shortest element edge, " << shortest << " ("
    << describe_element(model, where)
    << "): it would merge an element's own nodes; give a distance below that edge (and above the "
       "gap between duplicated interface nodes)";
  throw InvalidInput(m.str());
}

}  // namespace geode::primal
