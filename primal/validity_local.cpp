#include <geode/primal/validity_local.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/cell_nodes.hpp>
#include <geode/primal/detail/ordered_pieces.hpp>
#include <geode/primal/detail/validity_focus.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/release.hpp>

namespace geode::primal {

namespace {

using Hexes = std::span<const std::array<Index, 8>>;

using detail::has_repeated;
using detail::in_range;

// Every corner Jacobian above 0 (hex_jacobians' corners, the same values; not its centre, as
// check_validity), the first that is not ending the search.
bool corners_positive(const HexCorners& p) {
  for (int c = 0; c < 8; ++c)
    if (!(hex_corner_jacobian(p, c) > 0.0)) return false;
  return true;
}

// The region grown a ring at a time: the nodes of the hexes in it marked, then the hexes with
// a marked node added. Finding those is a pass over the hex array (no incidence built), hexes
// in parallel, in fixed chunks whose finds are joined in order; the rest follows the region's
// own list. `proper` (per hex, bit 0): the hexes the region may take.
class Region {
 public:
  static constexpr std::size_t kChunk = 8192;

  Region(Hexes hexes, std::size_t nodes, const std::vector<char>& proper)
      : hexes_(hexes), proper_(proper), hex_in_(hexes.size(), 0), node_in_(nodes, 0) {}

  // A seed: in range, in the mesh's range and with no node twice (a proper hex, told before the
  // per-hex pass has run).
  void add_seed(Index h) {
    if (h < 0 || index_cast<std::size_t>(h) >= hexes_.size()) return;
    const auto i = index_cast<std::size_t>(h);
    if (hex_in_[i] || !in_range(hexes_[i], node_in_.size()) || has_repeated(hexes_[i])) return;
    hex_in_[i] = 1;
    list_.push_back(h);
  }

  // The nodes of the hexes added since the last call.
  void mark_nodes() {
    for (; marked_ < list_.size(); ++marked_)
      for (Index v : hexes_[index_cast<std::size_t>(list_[marked_])])
        node_in_[index_cast<std::size_t>(v)] = 1;
  }

  // Hex h, proper, taken (into its chunk's `found`) when it is not in yet and has a marked node.
  void take_if_near(std::vector<Index>& found, std::size_t h, bool proper) {
    if (hex_in_[h] || !proper) return;
    for (Index v : hexes_[h])
      if (node_in_[index_cast<std::size_t>(v)]) {
        hex_in_[h] = 1;
        found.push_back(index_cast(h));
        return;
      }
  }

  // f(found, h) for every hex, chunk by chunk in parallel; then what take_if_near took, in
  // order.
  template <class F>
  void pass(F&& f) {
    const auto found = detail::in_ordered_chunks<std::vector<Index>>(
        hexes_.size(), kChunk,
        [&](std::size_t, std::size_t begin, std::size_t end, std::vector<Index>& out) {
          for (std::size_t h = begin; h < end; ++h) f(out, h);
        });
    for (const auto& taken : found) list_.insert(list_.end(), taken.begin(), taken.end());
  }

  // Every proper hex with a marked node.
  void add_hexes_at_nodes() {
    pass([&](std::vector<Index>& found, std::size_t h) {
      take_if_near(found, h, (proper_[h] & 1) != 0);
    });
  }

  // The hexes in the region, ascending (its list is consumed).
  std::vector<Index> take_hexes() {
    std::sort(list_.begin(), list_.end());
    release(hex_in_);
    return std::move(list_);
  }
  const std::vector<char>& marked_nodes() const { return node_in_; }

 private:
  Hexes hexes_;
  const std::vector<char>& proper_;
  std::vector<char> hex_in_, node_in_;
  std::vector<Index> list_;
  std::size_t marked_ = 0;  // list_[0, marked_) have their nodes marked
};

}  // namespace

HexValidityReport check_validity_around(const HexMesh& mesh, std::span<const Index> seeds,
                                        const RegionValidityOptions& options) {
  return check_validity_around(mesh.points, mesh.hexes, seeds, options);
}

HexValidityReport check_validity_around(std::span<const Point> points, Hexes hexes,
                                        std::span<const Index> seeds,
                                        const RegionValidityOptions& options) {
  const std::size_t nv = points.size(), nh = hexes.size();
  HexValidityReport r;
  r.num_nodes = index_cast(nv);
  r.num_hexes = index_cast(nh);

  // Per hex and per node over the whole mesh, as check_validity finds them, in one parallel
  // pass each (one slot per hex or node); the lists are gathered in order (the same for any
  // thread count) only when something was found. The hex pass also takes the region's first
  // ring (the hexes at the seeds' nodes), which saves a pass over the hexes.
  enum : char { kProper = 1, kOutOfRange = 2, kRepeated = 4, kInverted = 8 };
  std::vector<char> proper_hex(nh, 0), used(nv, 0);
  Region region(hexes, nv, proper_hex);  // reads bit 0, kProper
  for (Index h : seeds) region.add_seed(h);
  region.mark_nodes();
  std::atomic<bool> faulty = false;
  const bool known = options.positive.size() == nh;
  region.pass([&](std::vector<Index>& found, std::size_t h) {
    const auto& hex = hexes[h];
    if (!in_range(hex, nv)) {
      proper_hex[h] = kOutOfRange;
      faulty.store(true, std::memory_order_relaxed);
      return;
    }
    char code = kProper;
    if (has_repeated(hex)) {
      code = kRepeated;
    } else {
      for (Index v : hex)
        std::atomic_ref<char>(used[index_cast<std::size_t>(v)]).store(1, std::memory_order_relaxed);
    }
    if (!(known && options.positive[h])) {  // else all 9 dets > 0
      HexCorners p;
      for (std::size_t c = 0; c < 8; ++c) p[c] = points[index_cast<std::size_t>(hex[c])];
      if (!corners_positive(p)) code |= kInverted;
    }
    proper_hex[h] = code;
    if (code != kProper) faulty.store(true, std::memory_order_relaxed);
    region.take_if_near(found, h, (code & kProper) != 0);
  });
  if (faulty) {
    for (std::size_t h = 0; h < nh; ++h) {
      if (proper_hex[h] & kOutOfRange) r.out_of_range_hexes.push_back(index_cast(h));
      if (proper_hex[h] & kRepeated) r.repeated_node_hexes.push_back(index_cast(h));
      if (proper_hex[h] & kInverted) r.inverted_hexes.push_back(index_cast(h));
    }
  }
  // Unused nodes counted, non-finite ones flagged (in `used`), in one pass.
  constexpr char kNonFinite = 2;
  r.unused_nodes = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nv, 8192), Index{0},
      [&](const tbb::blocked_range<std::size_t>& range, Index unused) {
        for (std::size_t v = range.begin(); v != range.end(); ++v) {
          unused += used[v] ? 0 : 1;
          if (!points[v].allFinite()) used[v] = kNonFinite, faulty = true;
        }
        return unused;
      },
      [](Index a, Index b) { return a + b; });
  if (faulty)
    for (std::size_t v = 0; v < nv; ++v)
      if (used[v] == kNonFinite) r.non_finite_nodes.push_back(index_cast(v));
  release(used);

  // The region: the checked nodes (those of the hexes within `rings` of the seeds) and every
  // hex around them; the first ring was taken above.
  for (int ring = 0; ring < options.rings; ++ring) {
    region.mark_nodes();
    region.add_hexes_at_nodes();
  }
  const std::vector<char>& checked = region.marked_nodes();

  // The region as a mesh of its own, checked at its checked nodes (detail::check_validity's
  // focus): they have all their hexes in it, so its findings there hold for the whole mesh;
  // at the others it would find the region's cut.
  HexMesh sub;
  const std::vector<Index> sub_hex = region.take_hexes();
  std::vector<Index> sub_node, local(nv, kInvalidIndex);
  sub.hexes.reserve(sub_hex.size());
  for (Index hi : sub_hex) {
    const auto h = index_cast<std::size_t>(hi);
    std::array<Index, 8> q{};
    for (int c = 0; c < 8; ++c) {
      const auto v = index_cast<std::size_t>(hexes[h][c]);
      if (local[v] == kInvalidIndex) {
        local[v] = index_cast(sub_node.size());
        sub_node.push_back(index_cast(v));
        sub.points.push_back(points[v]);
      }
      q[c] = local[v];
    }
    sub.hexes.push_back(q);
  }
  release(local);
  std::vector<char> focus(sub_node.size());
  for (std::size_t i = 0; i < sub_node.size(); ++i)
    focus[i] = checked[index_cast<std::size_t>(sub_node[i])];
  const HexValidityReport s = detail::check_validity(sub, focus);
  auto node = [&](Index v) { return sub_node[index_cast<std::size_t>(v)]; };
  auto is_checked = [&](Index v) { return checked[index_cast<std::size_t>(node(v))] != 0; };
  auto global_key = [&](const FaceKey& k) {
    std::array<Index, 4> q{};
    std::size_t n = 0;
    for (Index v : k)
      if (v != kInvalidIndex) q[n++] = node(v);
    return face_key(std::span<const Index>(q.data(), n));
  };
  auto touches = [&](const auto& key) {
    return std::any_of(key.begin(), key.end(),
                       [&](Index v) { return v != kInvalidIndex && is_checked(v); });
  };
  for (const FaceKey& k : s.overshared_faces)
    if (touches(k)) r.overshared_faces.push_back(global_key(k));
  for (const FaceKey& k : s.misoriented_faces)
    if (touches(k)) r.misoriented_faces.push_back(global_key(k));
  // The focus check reports vertices, coverings and edges at checked nodes only, and boundary
  // quads with a checked node: theirs, in the mesh's numbers. Faces it reports everywhere.
  for (const EdgeKey& e : s.nonmanifold_edges) {
    const Index a = node(e[0]), b = node(e[1]);
    r.nonmanifold_edges.push_back({std::min(a, b), std::max(a, b)});
  }
  for (Index v : s.nonmanifold_vertices) r.nonmanifold_vertices.push_back(node(v));
  for (NodeCoverage c : s.overlapping_nodes)
    c.node = node(c.node), r.overlapping_nodes.push_back(c);
  std::sort(r.nonmanifold_vertices.begin(), r.nonmanifold_vertices.end());
  std::sort(r.overlapping_nodes.begin(), r.overlapping_nodes.end(),
            [](const NodeCoverage& a, const NodeCoverage& b) { return a.node < b.node; });

  r.num_vertices = s.num_vertices, r.num_edges = s.num_edges, r.num_faces = s.num_faces;
  r.num_cells = s.num_cells, r.euler = s.euler;
  auto global_quad = [&](BoundaryQuad q) {
    for (Index& v : q.nodes) v = node(v);
    q.hex = sub_hex[index_cast<std::size_t>(q.hex)];
    return q;
  };
  for (const BoundaryQuad& q : s.boundary.faces) r.boundary.faces.push_back(global_quad(q));
  for (const BoundaryQuad& q : s.boundary.rejected) r.boundary.rejected.push_back(global_quad(q));
  r.boundary.euler = s.boundary.euler;
  const bool manifold = r.nonmanifold_vertices.empty() && r.nonmanifold_edges.empty() &&
                        r.overshared_faces.empty() && r.boundary.rejected.empty();
  r.boundary.closed = r.boundary.manifold = manifold;
  return r;
}

std::vector<char> corner_jacobians_positive(std::span<const Point> points, Hexes hexes) {
  std::vector<char> positive(hexes.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, hexes.size(), 8192),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t h = r.begin(); h != r.end(); ++h) {
                        if (!in_range(hexes[h], points.size())) continue;
                        HexCorners p;
                        for (std::size_t c = 0; c < 8; ++c)
                          p[c] = points[index_cast<std::size_t>(hexes[h][c])];
                        positive[h] = corners_positive(p) ? 1 : 0;
                      }
                    });
  return positive;
}

}  // namespace geode::primal
