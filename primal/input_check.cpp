#include <geode/primal/input_check.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <type_traits>
#include <unordered_map>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/byte_packet.hpp>
#include <geode/primal/detail/edge_thirds.hpp>
#include <geode/primal/detail/lowest_node_sort.hpp>
#include <geode/primal/detail/ordered_pieces.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/release.hpp>
#include <geode/primal/submodel.hpp>

namespace geode::primal {

namespace {

constexpr double kPi = std::numbers::pi;

// Signed solid angle of the triangle a, b, c seen from the origin (Van Oosterom and Strackee,
// IEEE Trans. Biomed. Eng. BME-30(2), 1983), as in validity.cpp: in (0, 2 pi) when det > 0.
double solid_angle(const Point& a, const Point& b, const Point& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2.0 * std::atan2(a.dot(b.cross(c)), den);
}

double orient(const Point& a, const Point& b, const Point& c, const Point& d) {
  return (b - a).cross(c - a).dot(d - a);
}

// One use of a face: its sorted key, the element and local face.
struct FaceUse {
  FaceKey key;
  ElementRef element;
  int face;
  bool operator<(const FaceUse& o) const {
    return std::tie(key, element, face) < std::tie(o.key, o.element, o.face);
  }
};

// A boundary face: nodes in outward order (3 or 4), its element.
struct BoundaryFace {
  std::array<Index, 4> nodes;
  int size;
  ElementRef element;
};

// A boundary face seen from one of its corners v along one of its edges there (v, end): the
// face's other edge at v and its outward normal at v; the two faces on each boundary edge at v
// give the interior dihedral angle there.
struct HalfEdge {
  Index v, end, other;
  Point normal;
  Index face;
  // The face last: one order whatever the sort (the sums over a node's edges, the findings).
  bool operator<(const HalfEdge& o) const {
    return std::tie(v, end, face) < std::tie(o.v, o.end, o.face);
  }
};

struct Triangle {
  std::array<Index, 3> v;
  Index face;  // into the boundary faces
};

// The interior dihedral angle at the boundary edge along `axis` from the face through `a` to the
// face through `b`, turning through the side `inward` points to, in (0, 2 pi].
double dihedral(const Point& axis, const Point& a, const Point& inward, const Point& b) {
  const Point u = axis.normalized();
  const Point pa = a - a.dot(u) * u;
  auto turn = [&](const Point& x) { return std::atan2(u.dot(pa.cross(x)), pa.dot(x)); };
  double t = turn(b);
  if (turn(inward) < 0.0) t = -t;
  return t > 0.0 ? t : t + 2.0 * kPi;
}

// The stages of check_input over one model, each adding findings.
class InputChecker {
  using ElementPair = std::array<Index, 2>;

 public:
  InputChecker(const Model& model, const InputCheckOptions& options)
      : model_(model), options_(options), offsets_(element_offsets(model)) {}

  InputCheckResult run() {
    node_runs();
    pair_faces();
    if (!full()) boundary_links();
    if (!full()) covering_at_nodes();
    if (!full() && options_.contacts) boundary_contacts();
    if (!full()) degree_of_components();
    return std::move(result_);
  }

 private:
  const Point& pt(Index v) const { return model_.points[index_cast<std::size_t>(v)]; }
  bool full() const { return result_.findings.size() >= options_.max_findings; }
  void add(InputFinding f) {
    if (!full()) result_.findings.push_back(std::move(f));
  }
  std::span<const Index> corners(ElementRef e) const { return element_corners(model_, e); }
  Point centre(ElementRef e) const {
    Point c = Point::Zero();
    const auto cs = corners(e);
    for (Index v : cs) c += pt(v);
    return c / static_cast<double>(cs.size());
  }
  // The nodes of a local face in outward order.
  std::array<Index, 4> face_nodes(ElementRef e, int face, int* size = nullptr) const {
    const auto& f = cell_topology(e.kind).face[index_cast<std::size_t>(face)];
    const auto cs = corners(e);
    std::array<Index, 4> n{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
    for (int i = 0; i < f.size; ++i)
      n[index_cast<std::size_t>(i)] = cs[index_cast<std::size_t>(f.corners[i])];
    if (size) *size = f.size;
    return n;
  }

  // visit(use) for each face of e.
  template <class Visit>
  void face_uses(ElementRef e, Visit&& visit) const {
    for (int f = 0; f < cell_topology(e.kind).faces; ++f) {
      int size = 0;
      const auto n = face_nodes(e, f, &size);
      visit(
          FaceUse{face_key(std::span<const Index>(n.data(), index_cast<std::size_t>(size))), e, f});
    }
  }

  // Every face use, in FaceUse's order, sorted by lowest node first (detail/lowest_node_sort.hpp:
  // `geode check` of 2.2 million tets and hexes 2.7 s -> 1.9 s against one sort of them all).
  std::vector<FaceUse> sorted_face_uses() const {
    const Index first = first_, last = last_;
    const bool all_nodes = options_.shares <= 1;
    // visit(use) for every face of every element with its lowest node in the run, the elements
    // split among threads; an element with no node in the run or past it has none.
    auto each_use = [&](auto&& visit) {
      for (ElementKind kind : kElementKinds) {
        const tbb::blocked_range<std::size_t> all(0, element_count(model_, kind), 4096);
        tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const ElementRef e{kind, index_cast(i)};
            if (all_nodes) {
              face_uses(e, visit);
              continue;
            }
            const auto [lo, hi] = std::ranges::minmax(corners(e));
            if (lo >= last || hi < first) continue;
            face_uses(e, [&](const FaceUse& u) {
              if (u.key[0] >= first && u.key[0] < last) visit(u);
            });
          }
        });
      }
    };
    // The counting pass: each face's lowest node only, from the cell tables (no key sorted, no
    // use made).
    auto each_lowest = [&](auto&& visit) {
      for (ElementKind kind : kElementKinds) {
        const auto& topo = cell_topology(kind);
        const tbb::blocked_range<std::size_t> all(0, element_count(model_, kind), 4096);
        tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto cs = corners({kind, index_cast(i)});
            for (int f = 0; f < topo.faces; ++f) {
              const auto& face = topo.face[index_cast<std::size_t>(f)];
              Index low = cs[index_cast<std::size_t>(face.corners[0])];
              for (int q = 1; q < face.size; ++q)
                low = std::min(low, cs[index_cast<std::size_t>(face.corners[q])]);
              if (all_nodes || (low >= first && low < last)) visit(low);
            }
          }
        });
      }
    };
    std::vector<std::size_t> start;
    return detail::sort_by_lowest_node<FaceUse>(
        model_.points.size(), each_lowest, each_use, [](const FaceUse& u) { return u.key[0]; },
        start);
  }

  // This share's run of the nodes [first_, last_): each share about as many corners (weighed by
  // their element's faces per corner, a proxy for the faces whose lowest node they are), so that
  // the shares pair about as many faces (the hex part's nodes often come first, a tet's node
  // has more faces around it).
  void node_runs() {
    const std::size_t nv = model_.points.size();
    first_ = 0, last_ = index_cast(nv);
    if (options_.shares <= 1) return;
    std::vector<double> weight(nv + 1, 0.0);
    for (ElementKind kind : kElementKinds) {
      const auto& t = cell_topology(kind);
      const double w = static_cast<double>(t.faces) / t.corners;
      for (std::size_t i = 0; i < element_count(model_, kind); ++i)
        for (Index v : corners({kind, index_cast(i)})) weight[index_cast<std::size_t>(v) + 1] += w;
    }
    for (std::size_t v = 0; v < nv; ++v) weight[v + 1] += weight[v];
    const auto cut = [&](int share) {
      if (share >= options_.shares) return index_cast(nv);
      const double aim = weight.back() * share / options_.shares;
      return index_cast(std::lower_bound(weight.begin(), weight.end(), aim) - weight.begin());
    };
    first_ = options_.share == 0 ? 0 : cut(options_.share);
    last_ = cut(options_.share + 1);
  }
  bool mine(Index v) const { return v >= first_ && v < last_; }

  // With options_.exchange: the findings from `from` on of every share, in share order (each
  // found them in its run of the nodes, in node order), in place of this share's.
  void share_findings(std::size_t from) {
    detail::BytePacket out;
    put_findings(out, from);
    detail::BytePacket all(options_.exchange(out.bytes()));
    result_.findings.resize(from);
    for (int s = 0; s < options_.shares; ++s) get_findings(all);
  }
  void put_findings(detail::BytePacket& out, std::size_t from) const {
    out.put(result_.findings.size() - from);
    for (std::size_t k = from; k < result_.findings.size(); ++k) {
      const InputFinding& f = result_.findings[k];
      out.put(f.fault), out.put(f.node), out.put(f.measure), out.put(f.edge_end);
      for (int c = 0; c < 3; ++c) out.put(f.place[c]);
      out.put(f.elements.size());
      for (const ElementRef& e : f.elements) out.put(e);
    }
  }
  void get_findings(detail::BytePacket& in) {
    for (auto n = in.get<std::size_t>(); n > 0; --n) {
      InputFinding f;
      in.get(f.fault), in.get(f.node), in.get(f.measure), in.get(f.edge_end);
      for (int c = 0; c < 3; ++c) in.get(f.place[c]);
      f.elements.resize(in.get<std::size_t>());
      for (ElementRef& e : f.elements) in.get(e);
      add(std::move(f));
    }
  }

  // With options_.exchange: the findings so far and the faces used once, of every share in
  // share order (their order in one process's pairing, whose uses are by lowest node).
  void share_pairing(std::vector<FaceUse>& single) {
    detail::BytePacket out;
    put_findings(out, 0);
    out.put(single.size());
    for (const FaceUse& u : single) out.put(u);
    detail::BytePacket all(options_.exchange(out.bytes()));
    result_.findings.clear();
    single.clear();
    for (int s = 0; s < options_.shares; ++s) {
      get_findings(all);
      for (auto n = all.get<std::size_t>(); n > 0; --n) single.push_back(all.get<FaceUse>());
    }
  }

  // Faces by their node sets: pairs must be seen in opposite orders; a quad one side meets as
  // two or four triangles of the other is an interface, not boundary.
  void pair_faces() {
    std::vector<FaceUse> single;  // faces used once
    {
      const std::vector<FaceUse> uses = sorted_face_uses();
      pair_uses(uses, single);
    }
    if (options_.exchange) share_pairing(single);
    match_interfaces(single);
  }

  // f(piece, findings, begin, end) on [0, n) cut into kPieces pieces of whole runs (items i
  // with same(i - 1, i) in one), pieces in parallel, each keeping its findings (keep()); then
  // the pieces' findings added in piece order: what one pass in order finds, for any thread
  // count.
  static constexpr std::size_t kPieces = 64;
  template <class Same, class F>
  void in_pieces(std::size_t n, Same&& same, F&& f) {
    std::array<std::size_t, kPieces + 1> cut{};
    for (std::size_t p = 0; p <= kPieces; ++p) {
      std::size_t at = n * p / kPieces;
      while (at > 0 && at < n && same(at - 1, at)) ++at;  // a run's start
      cut[p] = at;
    }
    room_ = options_.max_findings - std::min(options_.max_findings, result_.findings.size());
    auto found = detail::in_ordered_pieces<std::vector<InputFinding>>(
        std::span<const std::size_t>(cut),
        [&](std::size_t p, std::size_t from, std::size_t to, std::vector<InputFinding>& out) {
          f(p, out, from, to);
        });
    for (std::vector<InputFinding>& piece : found)
      for (InputFinding& x : piece) add(std::move(x));
  }
  // Whether a piece may keep more findings: fewer than add() has room for when it starts.
  bool more(const std::vector<InputFinding>& out) const { return out.size() < room_; }
  void keep(std::vector<InputFinding>& out, InputFinding f) const {
    if (more(out)) out.push_back(std::move(f));
  }
  // Faces used more than once: pairs must be seen in opposite orders; the rest into `single`.
  void pair_uses(const std::vector<FaceUse>& uses, std::vector<FaceUse>& single) {
    std::vector<std::vector<FaceUse>> singles(kPieces);
    std::vector<std::vector<ElementPair>> pairs(options_.element_pairs ? kPieces : 0);
    in_pieces(
        uses.size(), [&](std::size_t a, std::size_t b) { return uses[a].key == uses[b].key; },
        [&](std::size_t p, std::vector<InputFinding>& out, std::size_t from, std::size_t to) {
          pair_piece(uses, from, to, out, singles[p], pairs.empty() ? nullptr : &pairs[p]);
        });
    for (const std::vector<FaceUse>& piece : singles)
      single.insert(single.end(), piece.begin(), piece.end());
    if (options_.element_pairs) {
      std::size_t n = 0;
      for (const auto& piece : pairs) n += piece.size();
      options_.element_pairs->clear();
      options_.element_pairs->reserve(n);
      for (auto& piece : pairs) {
        options_.element_pairs->insert(options_.element_pairs->end(), piece.begin(), piece.end());
        release(piece);
      }
    }
  }
  // An element's flat number (element_offsets).
  Index flat(ElementRef e) const {
    return index_cast(offsets_[static_cast<std::size_t>(e.kind)]) + e.index;
  }

  // pair_uses on the runs of uses [from, to): findings into `out`, faces used once into
  // `single`.
  void pair_piece(const std::vector<FaceUse>& uses, std::size_t from, std::size_t to,
                  std::vector<InputFinding>& out, std::vector<FaceUse>& single,
                  std::vector<ElementPair>* pairs) const {
    for (std::size_t i = from; i < to;) {
      std::size_t j = i + 1;
      while (j < to && uses[j].key == uses[i].key) ++j;
      // The common case first: a face two elements see in opposite orders. Those are not one
      // element twice: positive elements on the same nodes lie on the same side of each face.
      if (j - i == 2 && opposite(uses[i], uses[i + 1])) {
        if (pairs) pairs->push_back({flat(uses[i].element), flat(uses[i + 1].element)});
        i = j;
        continue;
      }
      std::size_t twin = j;  // a use whose element repeats another's nodes
      for (std::size_t a = i; a < j && twin == j; ++a)
        for (std::size_t b = a + 1; b < j && twin == j; ++b)
          if (same_nodes(uses[a].element, uses[b].element)) twin = a;
      if (j - i == 1) {
        single.push_back(uses[i]);
      } else if (twin != j) {
        // An element twice is seen on every face the two share (a face of two such pairs holds
        // both): each pair said once, at the face 0 of its first element.
        for (std::size_t a = i; a < j; ++a) {
          if (uses[a].face != 0) continue;
          for (std::size_t b = i; b < j; ++b)
            if (b != a && same_nodes(uses[a].element, uses[b].element)) {
              if (uses[a].element < uses[b].element)
                keep(out, {InputFault::kDuplicateElement,
                           {uses[a].element, uses[b].element},
                           kInvalidIndex,
                           centre(uses[a].element),
                           0.0});
              break;
            }
        }
      } else if (j - i > 2) {
        InputFinding f{InputFault::kOversharedFace, {}, kInvalidIndex, face_centre(uses[i]), 0.0};
        for (std::size_t k = i; k < j && k < i + 3; ++k) f.elements.push_back(uses[k].element);
        keep(out, std::move(f));
      } else if (!opposite(uses[i], uses[i + 1])) {
        keep(out, {InputFault::kSameSideFace,
                   {uses[i].element, uses[i + 1].element},
                   kInvalidIndex,
                   face_centre(uses[i]),
                   0.0});
      }
      i = j;
    }
  }

  // The quad-triangle interface: an unpaired quad whose nodes two unpaired triangles (a
  // diagonal) or four around one more node cover. The faces left are the boundary.
  // Sorted lists rather than hash maps (the third nodes' held a vector per edge: 11 ms of the
  // n = 36 bench's check); a key's entries keep their order (stable sorts).
  void match_interfaces(const std::vector<FaceUse>& uses) {  // the faces used once
    struct Triangle {
      FaceKey key;
      std::size_t use;
    };
    std::vector<Triangle> triangle;  // by key: its first use
    detail::EdgeThirds third;        // by edge: the third nodes of its triangles
    for (std::size_t s = 0; s < uses.size(); ++s) {
      const FaceKey& k = uses[s].key;
      if (k[3] != kInvalidIndex) continue;
      triangle.push_back({k, s});
      third.add(k[0], k[1], k[2]);
    }
    auto by_key = [](const Triangle& a, const Triangle& b) { return a.key < b.key; };
    std::stable_sort(triangle.begin(), triangle.end(), by_key);
    third.sort();
    std::vector<bool> paired(uses.size(), false);
    // Each quad covered adds two or four pairs, of the triangles used once.
    if (options_.element_pairs && options_.share == 0)
      options_.element_pairs->reserve(options_.element_pairs->size() + triangle.size());
    // A triangle of the quad's own element never covers it: a lone pyramid's four sides meet
    // at its apex around its base as four triangles of a neighbour would.
    ElementRef quad_element{};
    auto tri = [&](Index a, Index b, Index c) -> const std::size_t* {
      const Index n[3] = {a, b, c};
      const Triangle probe{face_key(n), 0};
      const auto it = std::lower_bound(triangle.begin(), triangle.end(), probe, by_key);
      return it == triangle.end() || it->key != probe.key || paired[it->use] ||
                     uses[it->use].element == quad_element
                 ? nullptr
                 : &it->use;
    };
    for (std::size_t s = 0; s < uses.size(); ++s) {
      if (uses[s].key[3] == kInvalidIndex) continue;
      quad_element = uses[s].element;
      const auto q = face_nodes(uses[s].element, uses[s].face);
      std::vector<std::size_t> cover;
      for (int d = 0; d < 2 && cover.empty(); ++d) {  // diagonal q[d] - q[d + 2]
        const auto* t1 = tri(q[d], q[d + 1], q[d + 2]);
        const auto* t2 = tri(q[d + 2], q[(d + 3) % 4], q[d]);
        if (t1 && t2) cover = {*t1, *t2};
      }
      if (cover.empty()) {
        for (const auto& [edge, x] : third.on(q[0], q[1])) {
          const auto *t1 = tri(q[0], q[1], x), *t2 = tri(q[1], q[2], x), *t3 = tri(q[2], q[3], x),
                     *t4 = tri(q[3], q[0], x);
          if (t1 && t2 && t3 && t4) {
            cover = {*t1, *t2, *t3, *t4};
            break;
          }
        }
      }
      if (cover.empty()) continue;
      // The triangles' element must lie across the quad: their outward normals against its own.
      const Point nq = (pt(q[2]) - pt(q[0])).cross(pt(q[3]) - pt(q[1]));
      for (std::size_t t : cover) {
        const auto n = face_nodes(uses[t].element, uses[t].face);
        if ((pt(n[1]) - pt(n[0])).cross(pt(n[2]) - pt(n[0])).dot(nq) > 0.0) {
          add({InputFault::kSameSideFace,
               {uses[s].element, uses[t].element},
               kInvalidIndex,
               face_centre(uses[s]),
               0.0});
          break;
        }
      }
      paired[s] = true;
      for (std::size_t t : cover) paired[t] = true;
      if (options_.element_pairs && options_.share == 0)
        for (std::size_t t : cover)
          options_.element_pairs->push_back({flat(uses[s].element), flat(uses[t].element)});
      // A four-triangle centre lies on the quad, inside its element's face: that element covers
      // the half space beyond it there (the quad's tangent plane).
      if (cover.size() == 4) centre_on_quad_.push_back(third_node(uses[cover[0]].key, q));
      ++result_.interface_quads;
    }
    for (std::size_t s = 0; s < uses.size(); ++s) {
      if (paired[s]) continue;
      BoundaryFace b{};
      b.nodes = face_nodes(uses[s].element, uses[s].face, &b.size);
      b.element = uses[s].element;
      boundary_.push_back(b);
    }
    result_.boundary_faces = boundary_.size();
  }

  bool same_nodes(ElementRef a, ElementRef b) const {
    if (a.kind != b.kind) return false;
    const auto x = corners(a), y = corners(b);
    // Neighbours share a face but never all their nodes: their sums differ almost always.
    std::int64_t sx = 0, sy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) sx += x[i], sy += y[i];
    return sx == sy && std::is_permutation(x.begin(), x.end(), y.begin(), y.end());
  }

  // The node of triangle key k that is not a corner of quad q.
  static Index third_node(const FaceKey& k, const std::array<Index, 4>& q) {
    for (int i = 0; i < 3; ++i)
      if (std::find(q.begin(), q.end(), k[index_cast<std::size_t>(i)]) == q.end())
        return k[index_cast<std::size_t>(i)];
    return kInvalidIndex;
  }

  bool opposite(const FaceUse& a, const FaceUse& b) const {
    int n = 0;
    const auto x = face_nodes(a.element, a.face, &n);
    const auto y = face_nodes(b.element, b.face);
    const int j = static_cast<int>(std::find(y.begin(), y.begin() + n, x[0]) - y.begin());
    if (j == n) return false;
    for (int i = 0; i < n; ++i)
      if (y[index_cast<std::size_t>((j - i + n) % n)] != x[index_cast<std::size_t>(i)])
        return false;
    return true;
  }

  Point face_centre(const FaceUse& u) const {
    int n = 0;
    const auto f = face_nodes(u.element, u.face, &n);
    Point c = Point::Zero();
    for (int i = 0; i < n; ++i) c += pt(f[index_cast<std::size_t>(i)]);
    return c / n;
  }

  // The boundary as a surface, from its faces seen at each of their corners along both edges
  // there (sorted by corner and edge): every boundary edge on exactly two boundary faces, and the
  // faces around every boundary node one cycle (a disk); anything else is refused. Where it is a
  // disk, the solid angle inside the spherical polygon of the faces' sectors, 2 pi - sum(pi -
  // interior dihedral angle) over the boundary edges there, is what covering_at_nodes expects
  // (4 pi off the boundary); elsewhere a node is not judged by it.
  void boundary_links() {
    const std::size_t nv = model_.points.size();
    expected_.assign(nv, 4.0 * kPi);
    judged_.assign(nv, 1);
    std::vector<HalfEdge> half;
    half.reserve(8 * boundary_.size());
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const auto& b = boundary_[f];
      for (int i = 0; i < b.size; ++i) {
        const Index v = b.nodes[index_cast<std::size_t>(i)];
        const Index next = b.nodes[index_cast<std::size_t>((i + 1) % b.size)];
        const Index prev = b.nodes[index_cast<std::size_t>((i + b.size - 1) % b.size)];
        const Point n = (pt(next) - pt(v)).cross(pt(prev) - pt(v));
        half.push_back({v, next, prev, n, index_cast(f)});
        half.push_back({v, prev, next, n, index_cast(f)});
      }
    }
    tbb::parallel_sort(half.begin(), half.end());
    // Nodes in pieces in parallel (in_pieces): each writes its own expected_ and judged_.
    in_pieces(
        half.size(), [&](std::size_t a, std::size_t b) { return half[a].v == half[b].v; },
        [&](std::size_t, std::vector<InputFinding>& out, std::size_t from, std::size_t to) {
          link_nodes(half, from, to, out);
        });
  }

  // boundary_links at the nodes of half[from, to) (whole runs of one node each).
  void link_nodes(const std::vector<HalfEdge>& half, std::size_t from, std::size_t to,
                  std::vector<InputFinding>& out) {
    DisjointSets faces_at;
    std::vector<Index> local;  // the faces at v, numbered by order of appearance
    for (std::size_t i = from; i < to;) {
      const Index v = half[i].v;
      std::size_t j = i;
      while (j < to && half[j].v == v) ++j;
      local.clear();
      for (std::size_t k = i; k < j; ++k)
        if (std::find(local.begin(), local.end(), half[k].face) == local.end())
          local.push_back(half[k].face);
      faces_at.reset(local.size());
      auto slot = [&](Index f) {
        return index_cast(std::find(local.begin(), local.end(), f) - local.begin());
      };
      double exterior = 0.0;
      bool manifold = true;
      for (std::size_t k = i; k < j;) {
        std::size_t m = k + 1;  // [k, m): the faces on the edge v - end
        while (m < j && half[m].end == half[k].end) ++m;
        if (m - k != 2) {
          manifold = false;
          if (v < half[k].end)  // each edge once, from its lower end
            keep(out, edge_finding(half, k, m));
        } else {
          const Point& o = pt(v);
          exterior += kPi - dihedral(pt(half[k].end) - o, pt(half[k].other) - o, -half[k].normal,
                                     pt(half[k + 1].other) - o);
          faces_at.unite(slot(half[k].face), slot(half[k + 1].face));
        }
        k = m;
      }
      const std::size_t cycles = manifold ? faces_at.count() : 0;
      if (cycles > 1) {
        // One element of each of the first two cycles (their smallest local face: the root).
        InputFinding f{InputFault::kNonManifoldNode, {}, v, pt(v), static_cast<double>(cycles)};
        for (std::size_t r = 0; r < local.size() && f.elements.size() < 2; ++r)
          if (faces_at.find(index_cast(r)) == index_cast(r))
            f.elements.push_back(boundary_[index_cast<std::size_t>(local[r])].element);
        keep(out, std::move(f));
      }
      if (cycles == 1)
        expected_[index_cast<std::size_t>(v)] = 2.0 * kPi - exterior;
      else
        judged_[index_cast<std::size_t>(v)] = 0;
      i = j;
    }
  }

  // A boundary edge on m - k boundary faces (half[k, m)), not two: the lowest and highest of
  // their elements.
  InputFinding edge_finding(const std::vector<HalfEdge>& half, std::size_t k, std::size_t m) const {
    ElementRef lo = boundary_[index_cast<std::size_t>(half[k].face)].element, hi = lo;
    for (std::size_t x = k + 1; x < m; ++x) {
      const ElementRef e = boundary_[index_cast<std::size_t>(half[x].face)].element;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    InputFinding f{InputFault::kNonManifoldEdge,
                   {lo},
                   half[k].v,
                   0.5 * (pt(half[k].v) + pt(half[k].end)),
                   static_cast<double>(m - k)};
    if (hi != lo) f.elements.push_back(hi);
    f.edge_end = half[k].end;
    return f;
  }

  // The corners' solid angles at every node against 4 pi inside and the boundary's enclosed
  // solid angle on it. A pyramid counts as the two positive tets check_geometry found in it
  // (their cones tile its corners'), every other corner as the cone of its three edges.
  // Every corner cone of element i of `kind` (a pyramid as its two positive tets along a base
  // diagonal): visit(k, v, a, b, c) for its k-th cone, at v spanned by a, b, c.
  template <class Visit>
  void element_cones(ElementKind kind, std::size_t i, Visit&& visit) const {
    auto at = [&](const auto& cell, const auto& neighbors, int first) {
      static_assert(std::tuple_size_v<std::decay_t<decltype(cell)>> ==
                    std::tuple_size_v<std::decay_t<decltype(neighbors)>>);
      for (std::size_t c = 0; c < cell.size(); ++c) {
        const auto& n = neighbors[c];
        visit(first + static_cast<int>(c), cell[c], cell[index_cast<std::size_t>(n[0])],
              cell[index_cast<std::size_t>(n[1])], cell[index_cast<std::size_t>(n[2])]);
      }
    };
    switch (kind) {
      case ElementKind::kHex:
        return at(model_.hexes[i], topology::kHexCornerNeighbors, 0);
      case ElementKind::kWedge:
        return at(model_.wedges[i], topology::kWedgeCornerNeighbors, 0);
      case ElementKind::kTet:
        return at(model_.tets[i], topology::kTetCornerNeighbors, 0);
      case ElementKind::kPyramid: {
        const auto& p = model_.pyramids[i];
        const bool d02 = tet_volume(pt(p[0]), pt(p[1]), pt(p[2]), pt(p[4])) > 0.0 &&
                         tet_volume(pt(p[0]), pt(p[2]), pt(p[3]), pt(p[4])) > 0.0;
        const std::array<std::array<Index, 4>, 2> tets =
            d02 ? std::array<std::array<Index, 4>, 2>{{{p[0], p[1], p[2], p[4]},
                                                       {p[0], p[2], p[3], p[4]}}}
                : std::array<std::array<Index, 4>, 2>{
                      {{p[0], p[1], p[3], p[4]}, {p[1], p[2], p[3], p[4]}}};
        at(tets[0], topology::kTetCornerNeighbors, 0);
        return at(tets[1], topology::kTetCornerNeighbors, 4);
      }
    }
  }

  // The corner cones' solid angles (atan2, most of this pass) in parallel, one slot per cone;
  // their sums per node then in one order (hexes, wedges, tets, the centres of quads met by
  // four triangles, pyramids), so that the sums do not depend on the threads. Shared, each
  // share judges its run of the nodes, with the same sums.
  void covering_at_nodes() {
    const std::size_t nv = model_.points.size();
    constexpr std::array<std::pair<ElementKind, std::size_t>, 4> kOrder{
        {{ElementKind::kHex, 8},
         {ElementKind::kWedge, 6},
         {ElementKind::kTet, 4},
         {ElementKind::kPyramid, 8}}};
    std::array<std::size_t, 5> base{};
    for (std::size_t k = 0; k < kOrder.size(); ++k)
      base[k + 1] = base[k] + kOrder[k].second * element_count(model_, kOrder[k].first);
    std::vector<double> cone(base.back());
    for (std::size_t k = 0; k < kOrder.size(); ++k) {
      const ElementKind kind = kOrder[k].first;
      const std::size_t per = kOrder[k].second;
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, element_count(model_, kind), 2048),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                            element_cones(kind, i, [&](int j, Index v, Index a, Index b, Index c) {
                              if (!mine(v)) return;  // another share's node
                              const Point& o = pt(v);
                              cone[base[k] + per * i + index_cast<std::size_t>(j)] =
                                  solid_angle(pt(a) - o, pt(b) - o, pt(c) - o);
                            });
                        });
    }
    std::vector<double> angle(nv, 0.0);
    std::vector<ElementRef> at(nv, ElementRef{ElementKind::kHex, kInvalidIndex});
    for (std::size_t k = 0; k < kOrder.size(); ++k) {
      const ElementKind kind = kOrder[k].first;
      const std::size_t per = kOrder[k].second;
      if (kind == ElementKind::kPyramid)
        for (Index x : centre_on_quad_) angle[index_cast<std::size_t>(x)] += 2.0 * kPi;
      for (std::size_t i = 0; i < element_count(model_, kind); ++i)
        element_cones(kind, i, [&](int j, Index v, Index, Index, Index) {
          if (!mine(v)) return;
          const auto u = index_cast<std::size_t>(v);
          angle[u] += cone[base[k] + per * i + index_cast<std::size_t>(j)];
          if (at[u].index == kInvalidIndex) at[u] = {kind, index_cast(i)};
        });
    }
    release(cone);
    const std::size_t before = result_.findings.size();
    for (auto v = index_cast<std::size_t>(first_); v < index_cast<std::size_t>(last_) && !full();
         ++v) {
      if (at[v].index == kInvalidIndex || !judged_[v]) continue;
      if (!(std::abs(angle[v] - expected_[v]) > kPi)) continue;  // NaN: not judged
      add({InputFault::kFoldedNode,
           {at[v]},
           index_cast(v),
           pt(index_cast(v)),
           angle[v] / expected_[v]});
    }
    if (options_.exchange) share_findings(before);
  }

  // Boundary faces without a common node that cross, or that face each other across a gap
  // thinner than gap_fraction x their longest edge: pairs found through a uniform grid.
  void boundary_contacts() {
    for (std::size_t f = 0; f < boundary_.size(); ++f) {
      const auto& b = boundary_[f];
      triangles_.push_back({{b.nodes[0], b.nodes[1], b.nodes[2]}, index_cast(f)});
      if (b.size == 4) triangles_.push_back({{b.nodes[0], b.nodes[2], b.nodes[3]}, index_cast(f)});
    }
    const std::size_t nt = triangles_.size();
    if (nt < 2) return;
    std::vector<double> longest(nt);
    std::vector<Point> lo(nt), hi(nt);
    double mean = 0.0, most = 0.0;
    Point all_lo = pt(triangles_[0].v[0]), all_hi = all_lo;
    for (std::size_t t = 0; t < nt; ++t) {
      const auto& v = triangles_[t].v;
      double l = 0.0;
      for (int k = 0; k < 3; ++k) l = std::max(l, (pt(v[k]) - pt(v[(k + 1) % 3])).norm());
      longest[t] = l;
      mean += l;
      most = std::max(most, l);
      const double pad = options_.gap_fraction * l;
      lo[t] = pt(v[0]).cwiseMin(pt(v[1])).cwiseMin(pt(v[2])).array() - pad;
      hi[t] = pt(v[0]).cwiseMax(pt(v[1])).cwiseMax(pt(v[2])).array() + pad;
      all_lo = all_lo.cwiseMin(lo[t]);
      all_hi = all_hi.cwiseMax(hi[t]);
    }
    mean /= static_cast<double>(nt);
    if (!all_lo.allFinite() || !all_hi.allFinite() || !std::isfinite(mean)) return;
    // Cells about the mean edge, but never so small that the longest triangle spans more than
    // about 8 cells along an axis, nor more than 2^20 along the model; doubled until the
    // triangles' boxes take at most 8 cells each on average (graded meshes).
    double h = std::max({mean, most / 8.0, (all_hi - all_lo).maxCoeff() / double(1 << 20)});
    for (;;) {
      double cells = 0.0;
      for (std::size_t t = 0; t < nt; ++t) {
        const Eigen::Array3d a = ((lo[t] - all_lo) / h).array().floor();
        const Eigen::Array3d b = ((hi[t] - all_lo) / h).array().floor();
        cells += (b - a + 1.0).prod();
      }
      if (cells <= 8.0 * static_cast<double>(nt)) break;
      h *= 2.0;
    }
    auto cell = [&](const Point& p) {
      const Eigen::Array3d c = ((p - all_lo) / h).array().floor();
      return std::array<std::int64_t, 3>{static_cast<std::int64_t>(c[0]),
                                         static_cast<std::int64_t>(c[1]),
                                         static_cast<std::int64_t>(c[2])};
    };
    auto code = [](const std::array<std::int64_t, 3>& c) {
      return static_cast<std::uint64_t>(c[0]) << 42 | static_cast<std::uint64_t>(c[1]) << 21 |
             static_cast<std::uint64_t>(c[2]);
    };
    std::vector<std::pair<std::uint64_t, Index>> binned;
    binned.reserve(4 * nt);
    for (std::size_t t = 0; t < nt; ++t) {
      const auto a = cell(lo[t]), b = cell(hi[t]);
      for (auto x = a[0]; x <= b[0]; ++x)
        for (auto y = a[1]; y <= b[1]; ++y)
          for (auto z = a[2]; z <= b[2]; ++z) binned.emplace_back(code({x, y, z}), Index(t));
    }
    tbb::parallel_sort(binned.begin(), binned.end());
    // Cells in pieces in parallel (in_pieces), a piece stopping once it holds as many findings
    // as the check has room for.
    in_pieces(
        binned.size(),
        [&](std::size_t a, std::size_t b) { return binned[a].first == binned[b].first; },
        [&](std::size_t, std::vector<InputFinding>& out, std::size_t from, std::size_t to) {
          for (std::size_t i = from; i < to && more(out);) {
            std::size_t j = i + 1;
            while (j < to && binned[j].first == binned[i].first) ++j;
            for (std::size_t a = i; a < j && more(out); ++a)
              for (std::size_t b = a + 1; b < j && more(out); ++b) {
                const auto s = index_cast<std::size_t>(binned[a].second);
                const auto t = index_cast<std::size_t>(binned[b].second);
                if (((hi[s].array() < lo[t].array()) || (hi[t].array() < lo[s].array())).any())
                  continue;
                // Each pair once: in the cell holding the lower corner of the boxes' overlap.
                if (code(cell(lo[s].cwiseMax(lo[t]))) != binned[i].first) continue;
                if (auto f = contact(s, t, std::max(longest[s], longest[t])))
                  keep(out, std::move(*f));
              }
            i = j;
          }
        });
  }

  // Boundary triangles s and t crossing, or facing across a thin gap: the finding.
  std::optional<InputFinding> contact(std::size_t s, std::size_t t, double length) const {
    const auto& a = triangles_[s].v;
    const auto& b = triangles_[t].v;
    for (Index x : a)
      if (std::find(b.begin(), b.end(), x) != b.end()) return std::nullopt;
    const ElementRef ea = boundary_[index_cast<std::size_t>(triangles_[s].face)].element;
    const ElementRef eb = boundary_[index_cast<std::size_t>(triangles_[t].face)].element;
    if (const auto x = crossing(s, t, length); x)
      return InputFinding{InputFault::kCrossingFaces, {ea, eb}, kInvalidIndex, *x, 0.0};
    if (const auto x = crossing(t, s, length); x)
      return InputFinding{InputFault::kCrossingFaces, {ea, eb}, kInvalidIndex, *x, 0.0};
    const Point na = (pt(a[1]) - pt(a[0])).cross(pt(a[2]) - pt(a[0])).normalized();
    const Point nb = (pt(b[1]) - pt(b[0])).cross(pt(b[2]) - pt(b[0])).normalized();
    // In one plane and facing the same way, their elements lie on the same side of it: where
    // the triangles overlap, so do the elements (no edge crosses the other's interior there).
    if (na.dot(nb) > 0.9 &&
        std::abs(((pt(a[0]) + pt(a[1]) + pt(a[2])) / 3.0 - pt(b[0])).dot(nb)) <= 1e-9 * length)
      if (const auto x = coplanar_overlap(a, b, nb, length); x)
        return InputFinding{InputFault::kCrossingFaces, {ea, eb}, kInvalidIndex, *x, 0.0};
    if (!(na.dot(nb) < -0.9)) return std::nullopt;
    if (const auto g = facing(a, b, nb, length); g)
      return InputFinding{InputFault::kGap, {ea, eb}, kInvalidIndex, g->first, g->second};
    if (const auto h = facing(b, a, na, length); h)
      return InputFinding{InputFault::kGap, {eb, ea}, kInvalidIndex, h->first, h->second};
    return std::nullopt;
  }

  // a's centre in front of b (in the void b's outward normal nb points to), closer than the
  // gap fraction, over b: the point on b and the distance.
  std::optional<std::pair<Point, double>> facing(const std::array<Index, 3>& a,
                                                 const std::array<Index, 3>& b, const Point& nb,
                                                 double length) const {
    const Point g = (pt(a[0]) + pt(a[1]) + pt(a[2])) / 3.0;
    const double d = (g - pt(b[0])).dot(nb);
    if (d < -1e-9 * length || d > options_.gap_fraction * length) return std::nullopt;
    const Point y = g - d * nb;
    if (!inside(b, y, -1e-9)) return std::nullopt;
    return std::pair<Point, double>{y, d > 1e-9 * length ? d : 0.0};  // 0: coincident
  }

  // Whether point y (in the triangle's plane) lies inside it, barycentric margin `margin`.
  bool inside(const std::array<Index, 3>& t, const Point& y, double margin) const {
    const Point n = (pt(t[1]) - pt(t[0])).cross(pt(t[2]) - pt(t[0]));
    const double n2 = n.squaredNorm();
    for (int k = 0; k < 3; ++k) {
      const Point& p = pt(t[k]);
      const Point& q = pt(t[(k + 1) % 3]);
      if ((q - p).cross(y - p).dot(n) < margin * n2) return false;
    }
    return true;
  }

  // Whether x, in the plane of boundary triangle t, lies inside its face: strictly inside the
  // triangle, or, for a quad's triangle, on the quad's diagonal (the edge it shares with the
  // quad's other triangle) strictly between the quad's outer edges: an edge through a quad's
  // centre is strictly in neither triangle (two hexes overlapping by exactly half a cell were
  // found valid so). Only on the diagonal itself: elsewhere a warped quad's surface is the other
  // triangle, not this one's plane.
  bool inside_face(std::size_t t, const Point& x) const {
    const auto& v = triangles_[t].v;
    if (inside(v, x, 1e-9)) return true;
    const BoundaryFace& f = boundary_[index_cast<std::size_t>(triangles_[t].face)];
    if (f.size != 4) return false;
    const Point n = (pt(v[1]) - pt(v[0])).cross(pt(v[2]) - pt(v[0]));
    const double n2 = n.squaredNorm();
    for (std::size_t k = 0; k < 3; ++k) {
      const Index p = v[k], q = v[(k + 1) % 3];
      const double side = (pt(q) - pt(p)).cross(x - pt(p)).dot(n) / n2;
      const bool diagonal =
          (p == f.nodes[0] && q == f.nodes[2]) || (p == f.nodes[2] && q == f.nodes[0]);
      if (diagonal ? std::abs(side) > 1e-9 : side < 1e-9) return false;
    }
    return true;
  }

  // Coplanar triangles a and b (unit normal n) overlapping: an edge of one properly crossing an
  // edge of the other, or the centroid of one strictly inside the other. Where, if so.
  std::optional<Point> coplanar_overlap(const std::array<Index, 3>& a,
                                        const std::array<Index, 3>& b, const Point& n,
                                        double length) const {
    const double eps = 1e-9 * length * length;  // twice a signed area
    const auto side = [&](const Point& p, const Point& q, const Point& x) {
      return (q - p).cross(x - p).dot(n);
    };
    const auto apart = [eps](double x, double y) {
      return (x > eps && y < -eps) || (x < -eps && y > eps);
    };
    for (std::size_t i = 0; i < 3; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const Point& p = pt(a[i]);
        const Point& q = pt(a[(i + 1) % 3]);
        const Point& r = pt(b[j]);
        const Point& u = pt(b[(j + 1) % 3]);
        const double d3 = side(r, u, p), d4 = side(r, u, q);
        if (apart(side(p, q, r), side(p, q, u)) && apart(d3, d4))
          return Point(p + (d3 / (d3 - d4)) * (q - p));
      }
    const Point ga = (pt(a[0]) + pt(a[1]) + pt(a[2])) / 3.0;
    const Point gb = (pt(b[0]) + pt(b[1]) + pt(b[2])) / 3.0;
    if (inside(b, ga, 1e-9)) return ga;
    if (inside(a, gb, 1e-9)) return gb;
    return std::nullopt;
  }

  // Where an edge of boundary triangle s passes through the face of boundary triangle t, if
  // one does.
  std::optional<Point> crossing(std::size_t s, std::size_t t, double length) const {
    const auto& a = triangles_[s].v;
    const auto& b = triangles_[t].v;
    const double eps = 1e-9 * length * length * length;
    for (int k = 0; k < 3; ++k) {
      const Point& u = pt(a[k]);
      const Point& w = pt(a[(k + 1) % 3]);
      const double su = orient(pt(b[0]), pt(b[1]), pt(b[2]), u);
      const double sw = orient(pt(b[0]), pt(b[1]), pt(b[2]), w);
      if (!((su > eps && sw < -eps) || (su < -eps && sw > eps))) continue;
      const Point x = u + (su / (su - sw)) * (w - u);
      if (inside_face(t, x)) return x;
    }
    return std::nullopt;
  }

  // The winding number of the boundary (its faces as triangles) at the centre of one element of
  // each boundary component must be 1.
  void degree_of_components() {
    if (boundary_.empty()) return;
    if (triangles_.empty())
      for (std::size_t f = 0; f < boundary_.size(); ++f) {
        const auto& b = boundary_[f];
        triangles_.push_back({{b.nodes[0], b.nodes[1], b.nodes[2]}, index_cast(f)});
        if (b.size == 4)
          triangles_.push_back({{b.nodes[0], b.nodes[2], b.nodes[3]}, index_cast(f)});
      }
    DisjointSets components(boundary_.size());
    std::unordered_map<Index, Index> first_face;
    for (std::size_t f = 0; f < boundary_.size(); ++f)
      for (int i = 0; i < boundary_[f].size; ++i) {
        const auto [it, fresh] =
            first_face.emplace(boundary_[f].nodes[index_cast<std::size_t>(i)], index_cast(f));
        if (!fresh) components.unite(it->second, index_cast(f));
      }
    std::vector<Index> representative;
    for (std::size_t f = 0; f < boundary_.size(); ++f)
      if (components.find(index_cast(f)) == index_cast(f)) representative.push_back(index_cast(f));
    result_.boundary_components = representative.size();
    if (representative.size() < 2) return;  // one closed surface: its winding number is 1 inside
    for (std::size_t r = 0; r < representative.size() && r < options_.max_components && !full();
         ++r) {
      const ElementRef e = boundary_[index_cast<std::size_t>(representative[r])].element;
      const Point x = centre(e);
      double omega = 0.0;
      for (const Triangle& t : triangles_)
        omega += solid_angle(pt(t.v[0]) - x, pt(t.v[1]) - x, pt(t.v[2]) - x);
      const double winding = omega / (4.0 * kPi);
      if (std::abs(winding - 1.0) > 0.5)
        add({InputFault::kCoveredTwice, {e}, kInvalidIndex, x, winding});
    }
  }

  const Model& model_;
  const InputCheckOptions& options_;
  const std::array<std::size_t, 5> offsets_;  // element_offsets
  Index first_ = 0, last_ = 0;                // this share's run of the nodes (node_runs)
  InputCheckResult result_;
  std::vector<BoundaryFace> boundary_;
  std::vector<Index> centre_on_quad_;  // four-triangle centres, one per such interface quad
  // Per node, from boundary_links: the solid angle its elements must cover, and whether the
  // boundary is a disk there (0: not judged by covering_at_nodes).
  std::size_t room_ = 0;  // in_pieces: the findings add() still keeps
  std::vector<double> expected_;
  std::vector<char> judged_;
  std::vector<Triangle> triangles_;
};

std::string number(double x) {
  std::ostringstream os;
  os.precision(3);
  os << x;
  return os.str();
}

// "two" for 2, up to twelve, then digits.
std::string count_text(long n) {
  static const char* const words[] = {"no",    "one",   "two",  "three", "four",   "five",  "six",
                                      "seven", "eight", "nine", "ten",   "eleven", "twelve"};
  return n >= 0 && n <= 12 ? words[n] : std::to_string(n);
}

// Where one of `elements`' corners lies at the same place as another node (coincident_tolerance,
// as conform's hint and --merge-tolerance's scale): "; hint: ..." naming both,
// else nothing. Elements that meet the rest of the model only along an edge or at a node are
// most often a part whose interface nodes were duplicated (meshed separately, or a node
// copied): the manifold refusal alone does not say so. A scan of the nodes per corner: this
// runs once, on a refusal.
std::string twin_node_hint(const Model& model, std::span<const ElementRef> elements) {
  const double tolerance = coincident_tolerance(model);
  for (const ElementRef& e : elements)
    for (Index v : element_corners(model, e)) {
      const Point& p = model.points[index_cast<std::size_t>(v)];
      for (std::size_t w = 0; w < model.points.size(); ++w)
        if (index_cast(w) != v && (model.points[w] - p).norm() <= tolerance)
          return "; hint: " + describe_node(model, v) + " lies at the same place as node " +
                 std::to_string(node_id(model, index_cast(w))) +
                 " (duplicated nodes: parts meshed separately?), which --merge-tolerance merges";
    }
  return {};
}

// Where two of the elements at a non-manifold edge or node have faces through it (`at`: the
// edge's two nodes, or the node) lying against each other with other nodes (planes within a tenth
// of the faces' size, outward normals opposed, one's centre inside the other): "; hint: ..."
// saying the interface between them does not conform, else nothing. Parts meshed separately and
// then merged (--merge-tolerance) share their boundary nodes but not their faces: the tets'
// triangles do not split the hexes' quads, and the check can only call that a non-manifold
// boundary.
std::string nonconforming_hint(const Model& model, std::span<const ElementRef> elements,
                               std::span<const Index> at) {
  if (elements.size() < 2) return {};
  struct Face {
    std::vector<Index> nodes;
    Point normal, centre;
    double size = 0.0;
  };
  const auto faces_through = [&](ElementRef e) {
    std::vector<Face> out;
    const auto& topo = cell_topology(e.kind);
    const auto cs = element_corners(model, e);
    for (int f = 0; f < topo.faces; ++f) {
      const auto& cf = topo.face[index_cast<std::size_t>(f)];
      Face face;
      for (int i = 0; i < cf.size; ++i)
        face.nodes.push_back(cs[index_cast<std::size_t>(cf.corners[index_cast<std::size_t>(i)])]);
      if (!std::all_of(at.begin(), at.end(), [&](Index v) {
            return std::find(face.nodes.begin(), face.nodes.end(), v) != face.nodes.end();
          }))
        continue;
      // Newell's normal (outward: the faces' corners run outward), the centre, the size.
      face.normal = Point::Zero();
      face.centre = Point::Zero();
      for (std::size_t i = 0; i < face.nodes.size(); ++i) {
        const Point& p = model.points[index_cast<std::size_t>(face.nodes[i])];
        const Point& q =
            model.points[index_cast<std::size_t>(face.nodes[(i + 1) % face.nodes.size()])];
        face.normal += p.cross(q);
        face.centre += p;
        face.size = std::max(face.size, (q - p).norm());
      }
      face.centre /= static_cast<double>(face.nodes.size());
      if (!(face.normal.norm() > 0.0)) continue;
      face.normal.normalize();
      out.push_back(std::move(face));
    }
    return out;
  };
  // Whether x, in the face's plane, lies inside it (its corners run counter-clockwise about
  // Newell's normal; the faces are convex enough for this).
  const auto inside = [&](const Face& f, const Point& x) {
    for (std::size_t i = 0; i < f.nodes.size(); ++i) {
      const Point& p = model.points[index_cast<std::size_t>(f.nodes[i])];
      const Point& q = model.points[index_cast<std::size_t>(f.nodes[(i + 1) % f.nodes.size()])];
      if ((q - p).cross(x - p).dot(f.normal) < 0.0) return false;
    }
    return true;
  };
  for (std::size_t i = 0; i < elements.size(); ++i)
    for (std::size_t j = i + 1; j < elements.size(); ++j)
      for (const Face& a : faces_through(elements[i]))
        for (const Face& b : faces_through(elements[j])) {
          auto sa = a.nodes, sb = b.nodes;
          std::sort(sa.begin(), sa.end());
          std::sort(sb.begin(), sb.end());
          const double reach = 0.1 * std::min(a.size, b.size);
          if (sa == sb || a.normal.dot(b.normal) > -0.95 ||
              std::abs(a.normal.dot(b.centre - a.centre)) > reach ||
              std::abs(b.normal.dot(a.centre - b.centre)) > reach)
            continue;
          // Faces on either side of an edge or node where the parts only touch (fragmented in
          // one plane) do not overlap: no hint.
          if (!inside(a, b.centre) && !inside(b, a.centre)) continue;
          const auto named = [&](ElementRef e, const Face& f) {
            return std::string(cell_topology(e.kind).name) + " " +
                   std::to_string(element_id(model, e)) + "'s " +
                   (f.nodes.size() == 4 ? "quad" : "triangle");
          };
          return "; hint: " + named(elements[i], a) + " and " + named(elements[j], b) +
                 " lie against each other here on other nodes: the interface does not conform, "
                 "as when parts are meshed separately (in Gmsh, fragment the volumes before "
                 "meshing, gmsh.model.occ.fragment, so that they share the interface's mesh; "
                 "in TetGen, -Y keeps the given boundary's faces as they are)";
        }
  return {};
}

}  // namespace

std::string InputFinding::text(const Model& model) const {
  auto named = [&](std::size_t i) {
    return i < elements.size() ? describe_element(model, elements[i]) : std::string("?");
  };
  switch (fault) {
    case InputFault::kOversharedFace: {
      std::string s = "the face at " + point_text(place) + " is shared by " +
                      std::to_string(elements.size()) + " elements (";
      for (std::size_t i = 0; i < elements.size(); ++i)
        s += (i ? ", " : "") + describe_element(model, elements[i]);
      return s + "): the parts overlap there";
    }
    case InputFault::kDuplicateElement:
      return named(0) + " and " + named(1) + " are one element twice (the same nodes " +
             node_list(model, element_corners(model, elements[0])) + ")";
    case InputFault::kSameSideFace:
      return named(0) + " and " + named(1) + " lie on the same side of their shared face at " +
             point_text(place) + ": the mesh folds over itself there";
    case InputFault::kNonManifoldEdge: {
      const auto faces = static_cast<long>(measure);
      const std::string edge = "the edge of nodes " +
                               node_list(model, std::array<Index, 2>{node, edge_end}) + " at " +
                               point_text(place);
      std::string through = named(0) + (elements.size() > 1 ? " and " + named(1) : "");
      if (faces % 2 == 1)
        return "the boundary is not closed along " + edge + ": it lies on " + count_text(faces) +
               " boundary face" + (faces == 1 ? "" : "s") + " (of " + through +
               "), not two: faces there are not matched node for node";
      return "the boundary is not a manifold along " + edge + ": " + count_text(faces) +
             " boundary faces meet there, " + count_text(faces / 2) + " surface sheets (through " +
             through +
             "; the model touches itself there: elements meeting the rest of it only "
             "along this edge, or faces not matched node for node)" +
             [&] {
               std::string hint = twin_node_hint(model, elements);
               return hint.empty() ? nonconforming_hint(model, elements,
                                                        std::array<Index, 2>{node, edge_end})
                                   : hint;
             }();
    }
    case InputFault::kNonManifoldNode:
      return "the boundary is not a manifold at " + describe_node(model, node) + ": " +
             count_text(static_cast<long>(measure)) + " surface sheets meet there (through " +
             named(0) + " and " + named(1) +
             "; the model touches itself there: elements meeting the rest of it only at this "
             "node, or faces not matched node for node)" +
             [&] {
               std::string hint = twin_node_hint(model, elements);
               return hint.empty() ? nonconforming_hint(model, elements, std::array<Index, 1>{node})
                                   : hint;
             }();
    case InputFault::kFoldedNode:
      return "the elements around " + describe_node(model, node) + " (" + named(0) +
             " among them) cover its neighbourhood " + number(measure) +
             " times, not once (corner solid angles): the mesh folds over itself there";
    case InputFault::kCrossingFaces:
      return "the boundary of " + named(0) + " crosses the boundary of " + named(1) + " at " +
             point_text(place) + ": two parts overlap";
    case InputFault::kGap:
      if (measure == 0.0)
        return named(0) + " and " + named(1) + " lie against each other at " + point_text(place) +
               " without sharing nodes: their nodes lie at the same place as others' (duplicated "
               "interface nodes, which --merge-tolerance merges)";
      return named(0) + " and " + named(1) + " face each other across a gap of " + number(measure) +
             " at " + point_text(place) +
             " without sharing nodes: an interface with a gap (or duplicated interface nodes, "
             "which --merge-tolerance merges)";
    case InputFault::kCoveredTwice:
      return named(0) + " lies inside other elements (the boundary winds " + number(measure) +
             " times around its centre, not once): two parts overlap";
  }
  return "covering check";
}

InputCheckResult check_input(const Model& model, const InputCheckOptions& options) {
  if (options.shares < 1 || options.share < 0 || options.share >= options.shares ||
      (options.shares > 1 && !options.exchange))
    throw std::invalid_argument("check_input: share " + std::to_string(options.share) + " of " +
                                std::to_string(options.shares) +
                                (options.exchange ? "" : " without an exchange"));
  return InputChecker(model, options).run();
}

void require_single_covering(const Model& model, std::string_view source,
                             const InputCheckOptions& options) {
  InputCheckOptions one = options;
  one.max_findings = 1;
  const InputCheckResult r = check_input(model, one);
  if (r.ok()) return;
  // The hint where a tet or pyramid folds (what unfold mends), not a hex or wedge alone.
  const InputFinding& f = r.findings[0];
  const bool mendable_fold =
      (f.fault == InputFault::kSameSideFace || f.fault == InputFault::kFoldedNode) &&
      std::any_of(f.elements.begin(), f.elements.end(), [](const ElementRef& e) {
        return e.kind == ElementKind::kTet || e.kind == ElementKind::kPyramid;
      });
  const std::string what =
      std::string(source) + ": " + f.text(model) + (mendable_fold ? options.fold_hint : "");
  if (r.findings[0].topological()) throw TopologyError(what);
  throw InvalidInput(what);
}

}  // namespace geode::primal
