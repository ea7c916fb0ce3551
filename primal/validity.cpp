#include <geode/primal/validity.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <geode/primal/detail/cell_nodes.hpp>
#include <geode/primal/detail/ordered_pieces.hpp>
#include <geode/primal/detail/validity_focus.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace topo = topology;

namespace {

// ---- Derived hex tables (computed from topology.hpp, not typed) ---------------------------

struct HexIncidence {
  std::array<std::array<int, 2>, 12> edge_faces{};   // the two local faces containing edge e
  std::array<std::array<int, 3>, 8> corner_faces{};  // the three local faces at corner c
  std::array<std::array<int, 3>, 8> corner_edges{};  // the three local edges at corner c
  // The local face at corner c spanned by the two edges other than edge k of
  // kHexCornerNeighbors[c], i.e. the corner's face without neighbour k.
  std::array<std::array<int, 3>, 8> corner_face_without{};
};

bool face_has_edge(int f, int a, int b) {
  const auto& q = topo::kHexFaceCorners[f];
  for (int i = 0; i < 4; ++i) {
    const int u = q[i], v = q[(i + 1) % 4];
    if ((u == a && v == b) || (u == b && v == a)) return true;
  }
  return false;
}

const HexIncidence& hex_incidence() {
  static const HexIncidence inc = [] {
    HexIncidence t;
    for (int e = 0; e < topo::kHexEdges; ++e) {
      int n = 0;
      for (int f = 0; f < topo::kHexFaces; ++f) {
        if (face_has_edge(f, topo::kHexEdgeCorners[e][0], topo::kHexEdgeCorners[e][1])) {
          t.edge_faces[e][n++] = f;
        }
      }
      assert(n == 2);
    }
    for (int c = 0; c < topo::kHexCorners; ++c) {
      int nf = 0, ne = 0;
      for (int f = 0; f < topo::kHexFaces; ++f) {
        const auto& q = topo::kHexFaceCorners[f];
        if (std::find(q.begin(), q.end(), c) != q.end()) t.corner_faces[c][nf++] = f;
      }
      for (int e = 0; e < topo::kHexEdges; ++e) {
        if (topo::kHexEdgeCorners[e][0] == c || topo::kHexEdgeCorners[e][1] == c) {
          t.corner_edges[c][ne++] = e;
        }
      }
      assert(nf == 3 && ne == 3);
      for (int k = 0; k < 3; ++k) {
        for (int f : t.corner_faces[c]) {
          const auto& q = topo::kHexFaceCorners[f];
          if (std::find(q.begin(), q.end(), topo::kHexCornerNeighbors[c][k]) == q.end())
            t.corner_face_without[c][k] = f;
        }
      }
    }
    return t;
  }();
  return inc;
}

using detail::has_repeated;
using detail::in_range;

// Two uses of a face (or edge) agree when one is the reverse cyclic order of the other.
template <std::size_t N>
bool opposite_cycles(const std::array<Index, N>& a, const std::array<Index, N>& b) {
  const auto j = static_cast<int>(std::find(b.begin(), b.end(), a[0]) - b.begin());
  if (j == static_cast<int>(N)) return false;
  for (int i = 0; i < static_cast<int>(N); ++i) {
    if (b[(j - i + static_cast<int>(N)) % static_cast<int>(N)] != a[i]) return false;
  }
  return true;
}

std::vector<Index> non_finite(const std::vector<Point>& points) {
  std::vector<Index> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) out.push_back(index_cast(i));
  }
  return out;
}

// "name: N (a, b, c, ...)" listing at most a few offenders.
template <typename T, typename F>
void list(std::ostringstream& os, const char* what, const std::vector<T>& items, F&& show) {
  if (items.empty()) return;
  os << "  " << what << ": " << items.size() << " (";
  const std::size_t shown = std::min<std::size_t>(items.size(), 8);
  for (std::size_t i = 0; i < shown; ++i) os << (i ? ", " : "") << show(items[i]);
  if (shown < items.size()) os << ", ...";
  os << ")\n";
}

// Each shows numbers from `base` (0, or 1 as a file numbers them).
auto show_index(Index base) {
  return [base](Index i) { return std::to_string(i + base); };
}
template <std::size_t N>
auto show_key(Index base) {
  return [base](const std::array<Index, N>& k) {
    std::string s = "{";
    for (std::size_t i = 0; i < N; ++i) {
      if (k[i] == kInvalidIndex) break;
      s += (i ? " " : "") + std::to_string(k[i] + base);
    }
    return s + "}";
  };
}
auto show_coverage(Index base) {
  return [base](const NodeCoverage& c) {
    std::ostringstream os;
    os.precision(3);
    os << c.node + base << ": " << c.angle / std::numbers::pi << " pi, not "
       << c.expected / std::numbers::pi << " pi";
    return os.str();
  };
}

// Work done on any thread, handed to a ValidityProgress one call at a time: a thread that finds
// a call under way goes on with its work instead of waiting. Each call reads the count after the
// previous one did, so what it is told never decreases.
class ProgressTicker {
 public:
  ProgressTicker(const ValidityProgress& report, std::size_t total)
      : report_(report), total_(total) {
    if (report_) report_(0, total_);  // the start, from which a bar counts
  }
  void add(std::size_t work) {
    if (!report_) return;
    done_.fetch_add(work, std::memory_order_relaxed);
    std::unique_lock lock(calling_, std::try_to_lock);
    if (lock.owns_lock()) report_(std::min(done_.load(std::memory_order_relaxed), total_), total_);
  }
  void finish() {
    if (!report_) return;
    std::lock_guard lock(calling_);
    report_(total_, total_);
  }

 private:
  const ValidityProgress& report_;
  const std::size_t total_;
  std::atomic<std::size_t> done_{0};
  std::mutex calling_;
};

// ---- Local covering ------------------------------------------------------------------------
// The corners around a node tile its neighbourhood once when the mesh is embedded there. The
// corner's tangent cone is what the element covers next to the node (a multilinear element's
// derivative at a corner maps the unit cube's corner onto the cone of its edges), and
// neighbouring cones share their face sectors, so the cones' angles add up to the space
// around the node times the number of times they wrap around it. That number is an integer,
// so the sum differs from the expected value by a multiple of 2 pi (4 pi at interior 3D
// nodes): half of that is the tolerance, far beyond rounding.

constexpr double kPi = std::numbers::pi;

bool overlaps(const NodeCoverage& c) { return std::abs(c.angle - c.expected) > kPi; }

// Signed solid angle of the triangle a, b, c seen from the origin: A. Van Oosterom and
// J. Strackee, "The Solid Angle of a Plane Triangle", IEEE Trans. Biomed. Eng. BME-30(2),
// 125-126 (1983): tan(omega / 2) = det[a b c] / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|),
// the quadrant taken from atan2, so omega is in (0, 2 pi) when det > 0.
double solid_angle(const Point& a, const Point& b, const Point& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2.0 * std::atan2(a.dot(b.cross(c)), den);
}

// The dihedral angle around `axis` from the half-plane through `from`, turning to the side of
// `toward`, to the half-plane through `to`, in (0, 2 pi].
double wedge_angle(const Point& axis, const Point& from, const Point& toward, const Point& to) {
  const Point u = axis.normalized();
  const Point a = from - from.dot(u) * u;
  auto turn = [&](const Point& x) { return std::atan2(u.dot(a.cross(x)), a.dot(x)); };
  double t = turn(to);
  if (turn(toward) < 0.0) t = -t;
  return t > 0.0 ? t : t + 2.0 * kPi;
}

// A hex corner at a node: the far ends of its edges (kHexCornerNeighbors order) and, for each
// k, whether the corner's face without edge k is a boundary face.
struct CornerStar {
  std::array<Index, 3> ends{};
  std::array<bool, 3> boundary_without{};
};

// A boundary face seen from one of its two edges at the node: the edge's far end, the face's
// other edge there, and the third edge of the hex corner (pointing inside).
struct BoundaryWedge {
  Index end;
  Point other, inward;
};

// The covering degree at an interior node is also the number of corner cones containing a
// direction d that lies on none of their faces (d is in the cone of e_0, e_1, e_2 when
// det(d, e_j, e_k) > 0 for its three faces, given det(e_0, e_1, e_2) > 0), which costs no
// square root or arctangent. A sign is trusted only when |det(d, e_j, e_k)| exceeds its rounding
// error (a few ulps of |e_j| |e_k|) by far, so each count is exact; d nearly on a face or along
// an edge leaves the node to the solid angles.
constexpr double kProbeMargin = 1e-24;  // squared sine of the angle to a face counted as "on" it

class ProbeCount {
 public:
  enum : std::uint8_t { kNotPositive = 1, kNearFace = 2 };

  explicit ProbeCount(std::size_t nodes) : containing_(nodes, 0), flags_(nodes, 0) {}

  // What the probe finds at each corner of a proper hex, 2 bits per corner (kOut, kInside,
  // kNear, kNotPositiveCorner), from its corner positions and Jacobians (hex_jacobians). Pure,
  // so hexes can be classified in parallel and added in order.
  enum : std::uint8_t { kOut = 0, kInside = 1, kNear = 2, kNotPositiveCorner = 3 };
  // Corners outside `corners` (a bit mask) are left kOut, which add() ignores.
  static std::uint16_t classify(const HexCorners& p, const std::array<double, 9>& jacobians,
                                unsigned corners = 0xffu) {
    const Point& d = coverage_probe();
    std::uint16_t code = 0;
    for (int c = 0; c < 8; ++c) {
      if (!(corners & (1u << c))) continue;
      std::uint16_t k_code = kNotPositiveCorner;
      if (jacobians[c] > 0.0) {
        std::array<Point, 3> e;
        std::array<double, 3> length2;
        for (int k = 0; k < 3; ++k) {
          e[k] = p[topo::kHexCornerNeighbors[c][k]] - p[c];
          length2[k] = e[k].squaredNorm();
        }
        // Inside when on the inner side of all three faces; certainly outside once clearly
        // outside one of them, whatever the others say.
        bool out = false, near = false;
        for (int k = 0; k < 3 && !out; ++k) {
          const int i = (k + 1) % 3, j = (k + 2) % 3;
          const double t = d.dot(e[i].cross(e[j]));
          if (t * t <= kProbeMargin * length2[i] * length2[j])
            near = true;
          else
            out = t < 0.0;
        }
        k_code = out ? kOut : near ? kNear : kInside;
      }
      code = static_cast<std::uint16_t>(code | (k_code << (2 * c)));
    }
    return code;
  }

  void add(const std::array<Index, 8>& hex, std::uint16_t code) {
    for (int c = 0; c < 8; ++c) {
      const auto v = index_cast<std::size_t>(hex[c]);
      switch ((code >> (2 * c)) & 3) {
        case kNotPositiveCorner:
          flags_[v] |= kNotPositive;
          break;
        case kNear:
          flags_[v] |= kNearFace;
          break;
        case kInside:
          ++containing_[v];
          break;
        default:
          break;
      }
    }
  }

  std::uint8_t flags(std::size_t v) const { return flags_[v]; }
  int containing(std::size_t v) const { return containing_[v]; }

 private:
  std::vector<int> containing_;
  std::vector<std::uint8_t> flags_;
};

// The covering at node v of a manifold hex mesh: the corners' solid angles against 4 pi inside
// and, on the boundary, against the solid angle inside the spherical polygon of the boundary
// faces' sectors, 2 pi - sum(pi - interior angle), the interior angle at a boundary edge being
// the dihedral angle between its two boundary faces measured through the inside. Nothing when
// a corner is not positive (the cones are not oriented) or the boundary does not pair up.
std::optional<NodeCoverage> hex_coverage(const std::vector<Point>& points, Index v,
                                         const std::vector<CornerStar>& corners,
                                         std::vector<BoundaryWedge>& wedges) {
  const Point& o = points[index_cast<std::size_t>(v)];
  NodeCoverage c{v, 0.0, 4.0 * kPi};
  wedges.clear();
  for (const CornerStar& s : corners) {
    std::array<Point, 3> e;
    for (int k = 0; k < 3; ++k) e[k] = points[index_cast<std::size_t>(s.ends[k])] - o;
    if (!(e[0].dot(e[1].cross(e[2])) > 0.0)) return std::nullopt;
    c.angle += solid_angle(e[0], e[1], e[2]);
    for (int k = 0; k < 3; ++k) {
      if (!s.boundary_without[k]) continue;
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      wedges.push_back({s.ends[i], e[j], e[k]});
      wedges.push_back({s.ends[j], e[i], e[k]});
    }
  }
  if (wedges.empty()) return c;
  std::sort(wedges.begin(), wedges.end(),
            [](const BoundaryWedge& a, const BoundaryWedge& b) { return a.end < b.end; });
  double exterior = 0.0;
  for (std::size_t i = 0; i < wedges.size(); i += 2) {
    if (i + 1 == wedges.size() || wedges[i + 1].end != wedges[i].end ||
        (i + 2 < wedges.size() && wedges[i + 2].end == wedges[i].end))
      return std::nullopt;
    const Point axis = points[index_cast<std::size_t>(wedges[i].end)] - o;
    exterior += kPi - wedge_angle(axis, wedges[i].other, wedges[i].inward, wedges[i + 1].other);
  }
  c.expected = 2.0 * kPi - exterior;
  return c;
}

// The 2D covering at node v (QuadValidityReport::overlapping_nodes): the corners' angles against
// 2 pi inside and against the angle from the leaving to the arriving boundary edge on the
// boundary. `corners` holds (edge to the next corner, edge to the previous one, leaving edge on
// the boundary, arriving edge on the boundary). Nothing when a corner is not positive or the
// node does not have one boundary edge each way.
struct QuadCornerAt {
  Point next, prev;
  bool leaving_boundary, arriving_boundary;
};

std::optional<NodeCoverage> quad_coverage(Index v, const std::vector<QuadCornerAt>& corners,
                                          const Point& normal) {
  NodeCoverage c{v, 0.0, 2.0 * kPi};
  const Point *out = nullptr, *in = nullptr;
  int leaving = 0, arriving = 0;
  for (const QuadCornerAt& q : corners) {
    const double area = normal.dot(q.next.cross(q.prev));
    if (!(area > 0.0)) return std::nullopt;
    c.angle += std::atan2(area, q.next.dot(q.prev));
    if (q.leaving_boundary) out = &q.next, ++leaving;
    if (q.arriving_boundary) in = &q.prev, ++arriving;
  }
  if (leaving != arriving || leaving > 1) return std::nullopt;
  if (out) {
    const double t = std::atan2(normal.dot(out->cross(*in)), out->dot(*in));
    c.expected = t > 0.0 ? t : t + 2.0 * kPi;
  }
  return c;
}

}  // namespace

// Arbitrary decimals, chosen to avoid grid axes and diagonals.
const Point& coverage_probe() {
  static const Point d = Point(0.3164, 0.5871, 0.7451).normalized();
  return d;
}

// ---- Hex meshes ----------------------------------------------------------------------------

bool HexValidityReport::ok() const {
  return out_of_range_hexes.empty() && non_finite_nodes.empty() && repeated_node_hexes.empty() &&
         overshared_faces.empty() && misoriented_faces.empty() && nonmanifold_edges.empty() &&
         nonmanifold_vertices.empty() && inverted_hexes.empty() && overlapping_nodes.empty() &&
         boundary.closed && boundary.manifold;
}

std::string HexValidityReport::summary(Index base) const {
  std::ostringstream os;
  os << "hex mesh: " << num_hexes << " hexes, " << num_nodes
     << " nodes: " << (ok() ? "valid" : "INVALID") << "\n";
  os << "  complex: V - E + F - C = " << num_vertices << " - " << num_edges << " + " << num_faces
     << " - " << num_cells << " = " << euler << "\n";
  os << "  boundary: " << (boundary.faces.size() + boundary.rejected.size()) << " quads, "
     << (boundary.closed ? "closed" : "NOT closed") << ", "
     << (boundary.manifold ? "manifold" : "NOT manifold") << ", V - E + F = " << boundary.euler
     << "\n";
  if (unused_nodes > 0) os << "  unused nodes: " << unused_nodes << "\n";
  list(os, "hexes with out-of-range nodes", out_of_range_hexes, show_index(base));
  list(os, "nodes with non-finite coordinates", non_finite_nodes, show_index(base));
  list(os, "hexes with a repeated node", repeated_node_hexes, show_index(base));
  list(os, "faces shared by more than two hexes", overshared_faces, show_key<4>(base));
  list(os, "faces seen in the same order by both hexes", misoriented_faces, show_key<4>(base));
  list(os, "non-manifold edges", nonmanifold_edges, show_key<2>(base));
  list(os, "non-manifold vertices", nonmanifold_vertices, show_index(base));
  list(os, "boundary quads OpenMesh rejected (hex)", boundary.rejected,
       [base](const BoundaryQuad& q) { return std::to_string(q.hex + base); });
  list(os, "hexes with a non-positive corner Jacobian", inverted_hexes, show_index(base));
  list(os, "nodes the hexes cover more than once (corner solid angles)", overlapping_nodes,
       show_coverage(base));
  return os.str();
}

HexValidityReport check_validity(const HexMesh& mesh, const ValidityProgress& progress) {
  return detail::check_validity(mesh, {}, progress);
}

namespace detail {

HexValidityReport check_validity(const HexMesh& mesh, std::span<const char> focus,
                                 const ValidityProgress& progress) {
  // Everything is read off the node -> hex incidence (CSR) instead of hashing every face and
  // edge of the mesh: all hexes using a face (an edge) contain its smallest node, so the uses of
  // a face or edge are found among the few hexes around one node. A face or edge is numbered by
  // its first use (hex, local face / edge), which is the order of first appearance.
  HexValidityReport r;
  r.num_nodes = index_cast(mesh.points.size());
  r.num_hexes = index_cast(mesh.hexes.size());
  r.non_finite_nodes = non_finite(mesh.points);
  // The work in units of about equal cost (measured on a million hexes): a hex's geometry, its
  // place in the incidence, and per node twice that for its faces and four times for its link;
  // one more for the boundary surface, so that only the end says all is done.
  const std::size_t nh_all = mesh.hexes.size(), nv_all = mesh.points.size();
  ProgressTicker ticker(progress, 2 * nh_all + 6 * nv_all + 1);

  // The proper hexes, on which the topology is analysed; use p refers to mesh.hexes[original[p]].
  std::vector<Index> original;  // proper hex -> input hex
  original.reserve(mesh.hexes.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const auto& hex = mesh.hexes[h];
    if (!in_range(hex, mesh.points.size())) {
      r.out_of_range_hexes.push_back(index_cast(h));
    } else if (has_repeated(hex)) {
      r.repeated_node_hexes.push_back(index_cast(h));
    } else {
      original.push_back(index_cast(h));
    }
  }

  // Orientation (on in-range hexes with finite corners; a repeated node gives a zero Jacobian),
  // and the interior covering counted along the probe on proper hexes.
  // The geometry per hex in parallel (TBB), one slot each: the probe's corner codes in bits
  // 0-15, bit 16 when a corner Jacobian is not positive, bit 17 when the hex was measured;
  // then gathered in hex order, so nothing depends on the thread count.
  ProbeCount probe(mesh.points.size());
  {
    constexpr std::uint32_t kInverted = 1u << 16, kMeasured = 1u << 17;
    std::vector<std::uint32_t> found(mesh.hexes.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t h = range.begin(); h != range.end(); ++h) {
                          const auto& hex = mesh.hexes[h];
                          if (!in_range(hex, mesh.points.size())) continue;
                          unsigned corners = 0xffu;  // the corners at focus nodes
                          if (!focus.empty()) {
                            corners = 0;
                            for (int c = 0; c < 8; ++c)
                              if (focus[index_cast<std::size_t>(hex[c])]) corners |= 1u << c;
                          }
                          const HexCorners p = hex_corners(mesh, index_cast(h));
                          // The corner Jacobians (hex_jacobians' first eight), the centre's is no
                          // corner's.
                          std::array<double, 9> j{};
                          bool positive = true;
                          for (int c = 0; c < 8; ++c)
                            if (corners & (1u << c)) {
                              j[c] = hex_corner_jacobian(p, c);
                              positive &= j[c] > 0.0;
                            }
                          found[h] = kMeasured | (positive ? 0u : kInverted) |
                                     ProbeCount::classify(p, j, corners);
                        }
                        ticker.add(range.size());
                      });
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
      if (!(found[h] & kMeasured)) continue;
      if (found[h] & kInverted) r.inverted_hexes.push_back(index_cast(h));
      if (!has_repeated(mesh.hexes[h]))
        probe.add(mesh.hexes[h], static_cast<std::uint16_t>(found[h] & 0xffffu));
    }
  }

  const auto& inc = hex_incidence();
  const std::size_t nh = original.size();
  const std::size_t nv = mesh.points.size();
  auto hex = [&](Index p) -> const std::array<Index, 8>& {
    return mesh.hexes[index_cast<std::size_t>(original[index_cast<std::size_t>(p)])];
  };
  // Local edge joining two corners (-1 if they are not joined by an edge).
  static const auto edge_of = [] {
    std::array<std::array<int, 8>, 8> t{};
    for (auto& row : t) row.fill(-1);
    for (int e = 0; e < topo::kHexEdges; ++e) {
      t[topo::kHexEdgeCorners[e][0]][topo::kHexEdgeCorners[e][1]] = e;
      t[topo::kHexEdgeCorners[e][1]][topo::kHexEdgeCorners[e][0]] = e;
    }
    return t;
  }();

  // Node -> proper hexes, ascending, each with the node's corner in it: 8 p + corner (no search
  // for the corner where a node's hexes are visited).
  if (nh >= (std::size_t{1} << 28))
    throw InvalidInput("check_validity: " + std::to_string(nh) + " hexes, 2^28 or more");
  std::vector<Index> start(nv + 1, 0), around;
  for (std::size_t p = 0; p < nh; ++p)
    for (Index v : hex(index_cast(p))) ++start[index_cast<std::size_t>(v) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  around.resize(index_cast<std::size_t>(start.back()));
  {
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (std::size_t p = 0; p < nh; ++p) {
      const auto& h = hex(index_cast(p));
      for (int c = 0; c < 8; ++c)
        around[index_cast<std::size_t>(fill[index_cast<std::size_t>(h[c])]++)] =
            index_cast(8 * p + index_cast<std::size_t>(c));
    }
  }
  ticker.add(nh_all);
  // An incidence entry: the hex and the node's corner in it.
  auto use_at = [&](Index k) {
    const Index a = around[index_cast<std::size_t>(k)];
    return std::pair<Index, int>{a >> 3, a & 7};
  };
  auto face_nodes = [&](Index p, int lf) {
    std::array<Index, 4> q{};
    for (int i = 0; i < 4; ++i) q[i] = hex(p)[topo::kHexFaceCorners[lf][i]];
    return q;
  };

  // Faces. face_lead[6 p + f]: the first use of that face; face_info[6 p + f]: the number of
  // uses (1, 2, 3 = more) in bits 0-1, bit 2 set when two uses see it in the same cyclic order,
  // the same at every use: the node pass below reads it next to face_lead, at the hex in hand,
  // instead of at the face's first use (a random read per face and node).
  std::vector<Index> face_lead(6 * nh, kInvalidIndex);
  std::vector<std::uint8_t> face_info(6 * nh, 0);
  // Each face is handled at its smallest node only, so nodes write disjoint slots and run in
  // parallel (TBB) with the same result for any thread count.
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, nv, 4096),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<std::pair<FaceKey, Index>> local;  // faces whose smallest node is v, with use
        for (std::size_t v = range.begin(); v != range.end(); ++v) {
          local.clear();
          for (Index k = start[v]; k < start[v + 1]; ++k) {
            const auto [p, c] = use_at(k);
            for (int lf : inc.corner_faces[c]) {
              const auto q = face_nodes(p, lf);
              if (*std::min_element(q.begin(), q.end()) != index_cast(v)) continue;
              local.emplace_back(face_key(q), 6 * p + lf);
            }
          }
          std::sort(local.begin(), local.end());
          for (std::size_t i = 0; i < local.size();) {
            std::size_t j = i + 1;
            while (j < local.size() && local[j].first == local[i].first) ++j;
            const Index lead = local[i].second;
            for (std::size_t k = i; k < j; ++k)
              face_lead[index_cast<std::size_t>(local[k].second)] = lead;
            std::uint8_t info = static_cast<std::uint8_t>(std::min<std::size_t>(j - i, 3));
            if (j - i == 2) {
              const Index u1 = local[i + 1].second;
              if (!opposite_cycles(face_nodes(lead / 6, lead % 6), face_nodes(u1 / 6, u1 % 6)))
                info |= 4;
            }
            for (std::size_t k = i; k < j; ++k)
              face_info[index_cast<std::size_t>(local[k].second)] = info;
            i = j;
          }
        }
        ticker.add(2 * range.size());
      });
  std::vector<BoundaryQuad> boundary;
  for (std::size_t u = 0; u < 6 * nh; ++u) {
    if (face_lead[u] != index_cast(u)) continue;
    ++r.num_faces;
    const Index p = index_cast(u / 6);
    const int lf = static_cast<int>(u % 6);
    const auto uses = face_info[u] & 3;
    if (uses == 3) r.overshared_faces.push_back(face_key(face_nodes(p, lf)));
    if (face_info[u] & 4) r.misoriented_faces.push_back(face_key(face_nodes(p, lf)));
    if (uses == 1) {
      const auto q = face_nodes(p, lf);
      if (focus.empty() || std::any_of(q.begin(), q.end(), [&](Index v) {
            return focus[index_cast<std::size_t>(v)] != 0;
          }))
        boundary.push_back(BoundaryQuad{original[index_cast<std::size_t>(p)], lf, q});
    }
  }
  auto face_uses = [&](Index p, int lf) {
    return face_info[index_cast<std::size_t>(6 * p + lf)] & 3;
  };

  // Vertices and the edges starting at them (other end larger). An edge's hexes must form one
  // chain or ring through shared faces. A vertex's link (triangles = hexes, edges = faces,
  // vertices = edges at the vertex) must be connected with Euler characteristic 2 (sphere,
  // interior) or 1 (disk, boundary).
  // Per node, independently: chunks of nodes run in parallel (detail/ordered_pieces.hpp), each
  // with its own scratch and findings, which are then joined in node order.
  struct EdgeUse {
    Index other;  // the edge's other end
    Index use;    // 12 p + local edge
  };
  struct Scratch {
    DisjointSets uses_joined;  // over the local uses
    std::vector<EdgeUse> edge_uses;
    std::vector<std::pair<Index, int>> first_use_of_face;  // (face lead, local use)
    std::vector<Index> others;
    std::vector<CornerStar> stars;
    std::vector<BoundaryWedge> wedges;
  };
  struct Found {
    Index unused_nodes = 0, num_vertices = 0, num_edges = 0;
    std::vector<Index> nonmanifold_vertices;
    std::vector<NodeCoverage> overlapping_nodes;
    std::vector<std::pair<Index, EdgeKey>> bad_edges;  // (first use 12 p + e, edge)
  };
  // The covering at a manifold node: counted along the probe inside, else from solid angles;
  // nothing where a corner is not positive (its hexes are listed as inverted).
  auto covering = [&](Index v, bool on_boundary, Scratch& s) -> std::optional<NodeCoverage> {
    const auto flags = probe.flags(index_cast<std::size_t>(v));
    if (flags & ProbeCount::kNotPositive) return std::nullopt;
    if (!on_boundary && !(flags & ProbeCount::kNearFace)) {
      const int k = probe.containing(index_cast<std::size_t>(v));
      return NodeCoverage{v, 4.0 * kPi * k, 4.0 * kPi};
    }
    s.stars.clear();
    for (Index i = start[index_cast<std::size_t>(v)]; i < start[index_cast<std::size_t>(v) + 1];
         ++i) {
      const auto [p, c] = use_at(i);
      CornerStar& star = s.stars.emplace_back();
      for (int k = 0; k < 3; ++k) {
        star.ends[k] = hex(p)[topo::kHexCornerNeighbors[c][k]];
        star.boundary_without[k] = face_uses(p, inc.corner_face_without[c][k]) == 1;
      }
    }
    return hex_coverage(mesh.points, v, s.stars, s.wedges);
  };
  auto visit = [&](std::size_t v, Scratch& s, Found& r) {
    auto& uses_joined = s.uses_joined;
    auto& edge_uses = s.edge_uses;
    auto& first_use_of_face = s.first_use_of_face;
    auto& others = s.others;
    auto& bad_edges = r.bad_edges;
    const Index n = start[v + 1] - start[v];
    if (n == 0) {
      ++r.unused_nodes;
      return;
    }
    ++r.num_vertices;
    const bool whole = focus.empty() || focus[v];  // else its edges to focus nodes only
    uses_joined.reset(index_cast<std::size_t>(n));
    first_use_of_face.clear();
    others.clear();
    edge_uses.clear();
    bool on_boundary = false, overshared = false;
    for (Index i = 0; i < n; ++i) {
      const auto [p, c] = use_at(start[v] + i);
      if (whole)
        for (int lf : inc.corner_faces[c]) {
          const auto uses = face_uses(p, lf);
          on_boundary |= uses == 1;
          overshared |= uses == 3;
          const Index f = face_lead[index_cast<std::size_t>(6 * p + lf)];
          auto it = std::find_if(first_use_of_face.begin(), first_use_of_face.end(),
                                 [f](const auto& x) { return x.first == f; });
          if (it == first_use_of_face.end())
            first_use_of_face.emplace_back(f, i);
          else
            uses_joined.unite(it->second, i);
        }
      for (int nc : topo::kHexCornerNeighbors[c]) {
        const Index b = hex(p)[nc];
        if (whole) others.push_back(b);
        if (b > index_cast(v)) edge_uses.push_back({b, 12 * p + edge_of[c][nc]});
      }
    }
    if (whole) {
      std::sort(others.begin(), others.end());
      const auto link_vertices = std::unique(others.begin(), others.end()) - others.begin();
      const auto link_euler = static_cast<long>(link_vertices) -
                              static_cast<long>(first_use_of_face.size()) + static_cast<long>(n);
      if (overshared || uses_joined.count() != 1 || link_euler != (on_boundary ? 1 : 2)) {
        r.nonmanifold_vertices.push_back(index_cast(v));
      } else if (const auto cover = covering(index_cast(v), on_boundary, s);
                 cover && overlaps(*cover)) {
        r.overlapping_nodes.push_back(*cover);
      }
    }

    std::sort(edge_uses.begin(), edge_uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
      return std::tie(a.other, a.use) < std::tie(b.other, b.use);
    });
    for (std::size_t i = 0; i < edge_uses.size();) {
      std::size_t j = i + 1;
      while (j < edge_uses.size() && edge_uses[j].other == edge_uses[i].other) ++j;
      ++r.num_edges;
      if (!whole && !focus[index_cast<std::size_t>(edge_uses[i].other)]) {
        i = j;
        continue;
      }
      const std::size_t m = j - i;
      uses_joined.reset(m);
      first_use_of_face.clear();
      bool edge_overshared = false;
      for (std::size_t k = 0; k < m; ++k) {
        const Index p = edge_uses[i + k].use / 12;
        const int le = edge_uses[i + k].use % 12;
        for (int lf : inc.edge_faces[le]) {
          edge_overshared |= face_uses(p, lf) == 3;
          const Index f = face_lead[index_cast<std::size_t>(6 * p + lf)];
          auto it = std::find_if(first_use_of_face.begin(), first_use_of_face.end(),
                                 [f](const auto& x) { return x.first == f; });
          if (it == first_use_of_face.end())
            first_use_of_face.emplace_back(f, static_cast<int>(k));
          else
            uses_joined.unite(it->second, index_cast(k));
        }
      }
      if (edge_overshared || uses_joined.count() != 1)
        bad_edges.emplace_back(edge_uses[i].use, edge_key(index_cast(v), edge_uses[i].other));
      i = j;
    }
  };
  std::vector<Found> found = in_ordered_chunks<Found>(
      nv, 4096, [&](std::size_t, std::size_t begin, std::size_t end, Found& out) {
        Scratch scratch;
        for (std::size_t v = begin; v < end; ++v) visit(v, scratch, out);
        ticker.add(4 * (end - begin));
      });
  std::vector<std::pair<Index, EdgeKey>> bad_edges;
  for (Found& f : found) {
    r.unused_nodes += f.unused_nodes;
    r.num_vertices += f.num_vertices;
    r.num_edges += f.num_edges;
    r.nonmanifold_vertices.insert(r.nonmanifold_vertices.end(), f.nonmanifold_vertices.begin(),
                                  f.nonmanifold_vertices.end());
    r.overlapping_nodes.insert(r.overlapping_nodes.end(), f.overlapping_nodes.begin(),
                               f.overlapping_nodes.end());
    bad_edges.insert(bad_edges.end(), f.bad_edges.begin(), f.bad_edges.end());
  }
  std::sort(bad_edges.begin(), bad_edges.end());
  for (const auto& [use, e] : bad_edges) r.nonmanifold_edges.push_back(e);

  r.num_cells = index_cast(nh);
  r.euler = r.num_vertices - r.num_edges + r.num_faces - r.num_cells;

  r.boundary = extract_boundary(mesh.points, std::move(boundary));
  ticker.finish();
  return r;
}

}  // namespace detail

// ---- Planar quad meshes --------------------------------------------------------------------

bool QuadValidityReport::ok() const {
  return out_of_range_quads.empty() && non_finite_nodes.empty() && repeated_node_quads.empty() &&
         planar && overshared_edges.empty() && misoriented_edges.empty() &&
         nonmanifold_vertices.empty() && inverted_quads.empty() && overlapping_nodes.empty();
}

std::string QuadValidityReport::summary(Index base) const {
  std::ostringstream os;
  os << "quad mesh: " << num_quads << " quads, " << num_nodes
     << " nodes: " << (ok() ? "valid" : "INVALID") << "\n";
  os << "  complex: V - E + F = " << num_vertices << " - " << num_edges << " + " << num_faces
     << " = " << euler << "\n";
  os << "  boundary: " << boundary_loops.size() << " loop(s) of";
  for (const auto& l : boundary_loops) os << " " << l.size();
  os << " edges\n";
  if (!planar) os << "  not planar\n";
  if (unused_nodes > 0) os << "  unused nodes: " << unused_nodes << "\n";
  list(os, "quads with out-of-range nodes", out_of_range_quads, show_index(base));
  list(os, "nodes with non-finite coordinates", non_finite_nodes, show_index(base));
  list(os, "quads with a repeated node", repeated_node_quads, show_index(base));
  list(os, "edges shared by more than two quads", overshared_edges, show_key<2>(base));
  list(os, "edges run in the same direction by both quads", misoriented_edges, show_key<2>(base));
  list(os, "non-manifold vertices", nonmanifold_vertices, show_index(base));
  list(os, "quads with a non-positive corner", inverted_quads, show_index(base));
  list(os, "nodes the quads cover more than once (corner angles)", overlapping_nodes,
       show_coverage(base));
  return os.str();
}

QuadValidityReport check_validity(const QuadMesh& mesh, const Point& normal_in) {
  QuadValidityReport r;
  r.num_nodes = index_cast(mesh.points.size());
  r.num_quads = index_cast(mesh.quads.size());
  r.non_finite_nodes = non_finite(mesh.points);
  const Point normal = normal_in.normalized();

  if (!mesh.points.empty() && r.non_finite_nodes.empty()) {
    Point lo = mesh.points[0], hi = mesh.points[0];
    for (const auto& p : mesh.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double tol = 1e-9 * std::max((hi - lo).norm(), 1e-300);
    for (const auto& p : mesh.points) r.planar &= std::abs((p - mesh.points[0]).dot(normal)) <= tol;
  }

  std::vector<std::array<Index, 4>> proper;
  for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
    const auto& quad = mesh.quads[q];
    if (!in_range(quad, mesh.points.size())) {
      r.out_of_range_quads.push_back(index_cast(q));
      continue;
    }
    if (quad_jacobian(quad_corners(mesh, index_cast(q)), normal) <= 0.0) {
      r.inverted_quads.push_back(index_cast(q));
    }
    if (has_repeated(quad)) {
      r.repeated_node_quads.push_back(index_cast(q));
    } else {
      proper.push_back(quad);
    }
  }

  // Edges with their uses (quad, local edge); the direction of a use is quad order.
  std::unordered_map<EdgeKey, Index, IndexArrayHash> edge_id;
  std::vector<EdgeKey> edges;
  std::vector<std::vector<std::pair<Index, int>>> edge_uses;
  for (std::size_t q = 0; q < proper.size(); ++q) {
    for (int e = 0; e < 4; ++e) {
      const auto& c = topo::kQuadEdgeCorners[e];
      const EdgeKey k = edge_key(proper[q][c[0]], proper[q][c[1]]);
      auto [it, inserted] = edge_id.try_emplace(k, index_cast(edges.size()));
      if (inserted) {
        edges.push_back(k);
        edge_uses.emplace_back();
      }
      edge_uses[it->second].emplace_back(index_cast(q), e);
    }
  }
  auto tail = [&](const std::pair<Index, int>& u) {
    return proper[u.first][topo::kQuadEdgeCorners[u.second][0]];
  };
  auto head = [&](const std::pair<Index, int>& u) {
    return proper[u.first][topo::kQuadEdgeCorners[u.second][1]];
  };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto& uses = edge_uses[e];
    if (uses.size() > 2) r.overshared_edges.push_back(edges[e]);
    if (uses.size() == 2 && tail(uses[0]) == tail(uses[1])) r.misoriented_edges.push_back(edges[e]);
  }

  // Vertices: the quads around a vertex must be connected through the edges at it; a manifold
  // one must be covered once.
  std::vector<std::vector<std::pair<Index, int>>> vertex_uses(mesh.points.size());
  std::vector<QuadCornerAt> corners;
  for (std::size_t q = 0; q < proper.size(); ++q) {
    for (int c = 0; c < 4; ++c) vertex_uses[proper[q][c]].emplace_back(index_cast(q), c);
  }
  for (std::size_t v = 0; v < vertex_uses.size(); ++v) {
    const auto& uses = vertex_uses[v];
    if (uses.empty()) {
      ++r.unused_nodes;
      continue;
    }
    ++r.num_vertices;
    DisjointSets sets(uses.size());
    std::unordered_map<Index, int> first_use_of_edge;
    bool overshared = false;
    corners.clear();
    const Point& o = mesh.points[v];
    for (std::size_t i = 0; i < uses.size(); ++i) {
      const auto [q, c] = uses[i];
      corners.push_back({mesh.points[proper[q][(c + 1) % 4]] - o,
                         mesh.points[proper[q][(c + 3) % 4]] - o, false, false});
      // The two edges at corner c: edge c (leaving it) and edge c-1 (arriving).
      for (int le : {c, (c + 3) % 4}) {
        const auto& lc = topo::kQuadEdgeCorners[le];
        const Index e = edge_id.at(edge_key(proper[q][lc[0]], proper[q][lc[1]]));
        overshared |= edge_uses[e].size() > 2;
        (le == c ? corners.back().leaving_boundary : corners.back().arriving_boundary) =
            edge_uses[e].size() == 1;
        auto [it, inserted] = first_use_of_edge.try_emplace(e, static_cast<int>(i));
        if (!inserted) sets.unite(it->second, static_cast<int>(i));
      }
    }
    if (overshared || sets.count() != 1) {
      r.nonmanifold_vertices.push_back(index_cast(v));
    } else if (r.planar) {
      const auto cover = quad_coverage(index_cast(v), corners, normal);
      if (cover && overlaps(*cover)) r.overlapping_nodes.push_back(*cover);
    }
  }

  r.num_edges = index_cast(edges.size());
  r.num_faces = index_cast(proper.size());
  r.euler = r.num_vertices - r.num_edges + r.num_faces;

  // Boundary loops: chain the boundary edges (used once) tail to head, in quad direction so
  // that the mesh is on the left.
  std::vector<std::pair<Index, Index>> bedges;  // (tail, head)
  std::unordered_map<Index, std::vector<std::size_t>> leaving;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edge_uses[e].size() != 1) continue;
    leaving[tail(edge_uses[e][0])].push_back(bedges.size());
    bedges.emplace_back(tail(edge_uses[e][0]), head(edge_uses[e][0]));
  }
  std::vector<bool> used(bedges.size(), false);
  for (std::size_t start = 0; start < bedges.size(); ++start) {
    if (used[start]) continue;
    std::vector<Index> loop;
    std::size_t e = start;
    while (true) {
      used[e] = true;
      loop.push_back(bedges[e].first);
      const Index next_node = bedges[e].second;
      if (next_node == bedges[start].first) break;
      const auto it = leaving.find(next_node);
      std::size_t next = bedges.size();
      if (it != leaving.end()) {
        for (std::size_t cand : it->second) {
          if (!used[cand]) {
            next = cand;
            break;
          }
        }
      }
      if (next == bedges.size()) break;  // open chain: only in an invalid mesh
      e = next;
    }
    r.boundary_loops.push_back(std::move(loop));
  }
  return r;
}

namespace {

// "3 hexes with a repeated node: 2 5 9": a count, what they are, and the first few.
template <class T, class Show>
void finding(std::vector<std::string>& out, const std::vector<T>& items, const std::string& what,
             Show&& show) {
  if (items.empty()) return;
  std::string s = std::to_string(items.size()) + " " + what + ":";
  for (std::size_t i = 0; i < items.size() && i < 5; ++i) s += " " + show(items[i]);
  out.push_back(s + (items.size() > 5 ? " ..." : ""));
}

template <std::size_t N>
std::string show_nodes(const std::array<Index, N>& k, const Numbering& node) {
  std::string s;
  for (auto n : k)
    if (n != kInvalidIndex) s += (s.empty() ? "" : "-") + std::to_string(node(n));
  return s;
}

std::string joined(const std::vector<std::string>& parts) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : "; ") + p;
  return s;
}

}  // namespace

std::string findings(const HexValidityReport& r, const Numbering& cell_number,
                     const Numbering& node_number) {
  if (r.ok()) return {};
  const auto cell = [&cell_number](Index i) { return std::to_string(cell_number(i)); };
  const auto node = [&node_number](Index i) { return std::to_string(node_number(i)); };
  const auto face = [&node_number](const FaceKey& k) { return show_nodes(k, node_number); };
  const auto edge = [&node_number](const EdgeKey& k) { return show_nodes(k, node_number); };
  std::vector<std::string> f;
  finding(f, r.out_of_range_hexes, "hexes with a node out of range", cell);
  finding(f, r.non_finite_nodes, "nodes with a non-finite coordinate", node);
  finding(f, r.repeated_node_hexes, "hexes with a repeated node", cell);
  finding(f, r.inverted_hexes,
          "of " + std::to_string(r.num_hexes) + " hexes inverted (a corner Jacobian <= 0), hexes",
          cell);
  finding(f, r.overlapping_nodes, "nodes covered more than once (overlapping hexes), nodes",
          [&node](const NodeCoverage& c) { return node(c.node); });
  finding(f, r.overshared_faces, "faces in more than two hexes, by their nodes", face);
  finding(f, r.misoriented_faces, "faces seen in the same order by both hexes, by their nodes",
          face);
  finding(f, r.nonmanifold_edges, "non-manifold edges, by their nodes", edge);
  finding(f, r.nonmanifold_vertices, "non-manifold nodes", node);
  if (!r.boundary.closed) f.push_back("the boundary is not closed");
  if (!r.boundary.manifold) f.push_back("the boundary is not manifold");
  return joined(f);
}

std::string findings(const QuadValidityReport& r, const Numbering& cell_number,
                     const Numbering& node_number) {
  if (r.ok()) return {};
  const auto cell = [&cell_number](Index i) { return std::to_string(cell_number(i)); };
  const auto node = [&node_number](Index i) { return std::to_string(node_number(i)); };
  const auto edge = [&node_number](const EdgeKey& k) { return show_nodes(k, node_number); };
  std::vector<std::string> f;
  finding(f, r.out_of_range_quads, "quads with a node out of range", cell);
  finding(f, r.non_finite_nodes, "nodes with a non-finite coordinate", node);
  finding(f, r.repeated_node_quads, "quads with a repeated node", cell);
  finding(f, r.inverted_quads,
          "of " + std::to_string(r.num_quads) + " quads inverted (a corner <= 0), quads", cell);
  finding(f, r.overlapping_nodes, "nodes covered more than once (overlapping quads), nodes",
          [&node](const NodeCoverage& c) { return node(c.node); });
  finding(f, r.overshared_edges, "edges in more than two quads, by their nodes", edge);
  finding(f, r.misoriented_edges, "edges run the same way by both quads, by their nodes", edge);
  finding(f, r.nonmanifold_vertices, "non-manifold nodes", node);
  if (!r.planar) f.push_back("not planar");
  if (f.empty()) f.push_back("not a valid quad mesh");
  return joined(f);
}

}  // namespace geode::primal
