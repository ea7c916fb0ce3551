#include <geode/primal/split_hexes.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <utility>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/split_cells.hpp>
#include <geode/primal/dice.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/key_map.hpp>

namespace geode::primal {

namespace {

// The nodes of local face `face` of a cell.
template <std::size_t N>
std::vector<Index> face_nodes(const std::array<Index, N>& cell, const topology::CellFace& face) {
  std::vector<Index> out;
  for (int i = 0; i < face.size; ++i)
    out.push_back(cell[index_cast<std::size_t>(face.corners[index_cast<std::size_t>(i)])]);
  return out;
}

// A triangulation of the cube by its corners: its tets (local corners, positively oriented) and
// per face the diagonal its tets have there (0: the face's corners 0-2, 1: 1-3).
struct Triangulation {
  std::vector<std::array<int, 4>> tets;
  std::array<int, 6> diagonal{};
};

using Vec = std::array<int, 3>;
Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
int dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec corner(int c) { return topology::kHexCornerCoords[index_cast<std::size_t>(c)]; }
int det(const std::array<int, 4>& t) {
  return dot(sub(corner(t[1]), corner(t[0])),
             cross(sub(corner(t[2]), corner(t[0])), sub(corner(t[3]), corner(t[0]))));
}

// Whether two tets of cube corners overlap (share interior points): no face normal of either,
// nor the cross product of an edge of each, separates them (exact, on integers).
bool overlap(const std::array<int, 4>& a, const std::array<int, 4>& b) {
  std::vector<Vec> normals;
  for (const auto* t : {&a, &b})
    for (const auto& f : topology::kTetFaceCorners)
      normals.push_back(cross(sub(corner((*t)[index_cast<std::size_t>(f[1])]),
                                  corner((*t)[index_cast<std::size_t>(f[0])])),
                              sub(corner((*t)[index_cast<std::size_t>(f[2])]),
                                  corner((*t)[index_cast<std::size_t>(f[0])]))));
  for (const auto& e : topology::kTetEdgeCorners)
    for (const auto& g : topology::kTetEdgeCorners)
      normals.push_back(cross(
          sub(corner(a[index_cast<std::size_t>(e[1])]), corner(a[index_cast<std::size_t>(e[0])])),
          sub(corner(b[index_cast<std::size_t>(g[1])]), corner(b[index_cast<std::size_t>(g[0])]))));
  for (const Vec& n : normals) {
    if (n == Vec{0, 0, 0}) continue;
    int lo_a = 1 << 20, hi_a = -(1 << 20), lo_b = 1 << 20, hi_b = -(1 << 20);
    for (int c : a)
      lo_a = std::min(lo_a, dot(n, corner(c))), hi_a = std::max(hi_a, dot(n, corner(c)));
    for (int c : b)
      lo_b = std::min(lo_b, dot(n, corner(c))), hi_b = std::max(hi_b, dot(n, corner(c)));
    if (hi_a <= lo_b || hi_b <= lo_a) return false;
  }
  return true;
}

// Every triangulation of the cube by its corners (74: two of 5 tets, the rest of 6), found once
// by a search over the corner tets: sets of tets that pairwise do not overlap, fill the cube's
// volume (6 in units of a corner tet's determinant) and meet face to face.
const std::vector<Triangulation>& cube_triangulations() {
  static const auto table = [] {
    std::vector<std::array<int, 4>> tets;
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b)
        for (int c = b + 1; c < 8; ++c)
          for (int d = c + 1; d < 8; ++d) {
            std::array<int, 4> t{a, b, c, d};
            const int v = det(t);
            if (v == 0) continue;
            if (v < 0) std::swap(t[2], t[3]);
            tets.push_back(t);
          }
    std::vector<Triangulation> out;
    std::vector<std::size_t> chosen;
    auto search = [&](auto&& self, std::size_t from, int volume) -> void {
      if (volume == 6) {
        Triangulation t;
        for (std::size_t i : chosen) t.tets.push_back(tets[i]);
        // Face to face: every tet face inside the cube is another's too (else two prisms
        // split their shared rectangle along different diagonals: a dissection, not a mesh).
        std::vector<std::array<int, 3>> inner;
        for (const auto& x : t.tets)
          for (const auto& f : topology::kTetFaceCorners) {
            std::array<int, 3> tri{x[index_cast<std::size_t>(f[0])],
                                   x[index_cast<std::size_t>(f[1])],
                                   x[index_cast<std::size_t>(f[2])]};
            bool boundary = false;
            for (std::size_t k = 0; k < 3; ++k)
              boundary |=
                  corner(tri[0])[k] == corner(tri[1])[k] && corner(tri[1])[k] == corner(tri[2])[k];
            std::sort(tri.begin(), tri.end());
            if (!boundary) inner.push_back(tri);
          }
        std::sort(inner.begin(), inner.end());
        for (std::size_t i = 0; i < inner.size(); ++i)
          if ((i == 0 || inner[i - 1] != inner[i]) &&
              (i + 1 == inner.size() || inner[i + 1] != inner[i]))
            return;
        for (std::size_t f = 0; f < 6; ++f) {
          const auto& fc = topology::kHexFaceCorners[f];
          t.diagonal[f] = std::any_of(t.tets.begin(), t.tets.end(),
                                      [&](const auto& x) {
                                        return std::count(x.begin(), x.end(), fc[0]) &&
                                               std::count(x.begin(), x.end(), fc[2]);
                                      })
                              ? 0
                              : 1;
        }
        out.push_back(std::move(t));
        return;
      }
      for (std::size_t i = from; i < tets.size(); ++i) {
        const int v = det(tets[i]);
        if (volume + v > 6) continue;
        if (std::any_of(chosen.begin(), chosen.end(),
                        [&](std::size_t j) { return overlap(tets[i], tets[j]); }))
          continue;
        chosen.push_back(i);
        self(self, i + 1, volume + v);
        chosen.pop_back();
      }
    };
    search(search, 0, 0);
    return out;
  }();
  return table;
}

// A hex's quality under a choice of its six diagonals, for comparing choices: 1 + the diced
// minimum of its best split on its corners when that is positive (a split on corners adds no
// node, so any beats a centre), else the better of that and its centre's split (at most 1).
double split_value(double corners, double centre) {
  return corners > 0.0 ? 1.0 + corners : std::max(corners, centre);
}

// The stages of split_hexes. A face's diagonal is kept as a choice between the one through its
// lowest node (0) and the other (1), so that the split hexes sharing it read it alike.
class HexSplitter {
 public:
  HexSplitter(const Model& model, std::span<const Index> hexes)
      : model_(model), hexes_(hexes.begin(), hexes.end()) {}

  Model run() {
    number_faces();
    refuse_fans();
    find_pyramids();
    measure();
    choose_along_chains();
    return build();
  }

 private:
  // A run of split hexes through opposite faces: hex i enters by local face in[i] and leaves by
  // out[i]; faces[i] and faces[i + 1] are those; on a cycle the last face is the first.
  struct Chain {
    std::vector<std::size_t> hexes;
    std::vector<int> in, out;
    std::vector<Index> faces;
  };

  // A pyramid on a forced face (find_pyramids): its two tets, the face's nodes as its split hex
  // has them and its apex; per choice of the face (as choice_), its tets' split_value.
  struct Pyramid {
    std::size_t face;
    std::array<Index, 2> tets;
    std::array<Index, 4> quad;
    Index apex;
    bool reversed;  // its tets are (quad's cyclic order, apex) mirrored
    std::array<double, 2> value;
    int low;    // the quad's lowest-node diagonal
    int given;  // the choice its tets have
  };

  // The node of tet t not on quad q, or none if it has two.
  Index fourth(Index t, const std::array<Index, 4>& q) const {
    Index out = kInvalidIndex;
    for (Index v : model_.tets[index_cast<std::size_t>(t)])
      if (std::find(q.begin(), q.end(), v) == q.end()) {
        if (out != kInvalidIndex) return kInvalidIndex;
        out = v;
      }
    return out;
  }
  // Pyramid p's two tets along diagonal d of its quad (0: q[0]-q[2], 1: q[1]-q[3]).
  std::array<std::array<Index, 4>, 2> tets_of(const Pyramid& p, int d) const {
    const auto& q = p.quad;
    const auto at = [&](int i) { return q[index_cast<std::size_t>((d + i) % 4)]; };
    std::array<std::array<Index, 4>, 2> t{
        {{at(0), at(1), at(2), p.apex}, {at(0), at(2), at(3), p.apex}}};
    if (p.reversed)
      for (auto& x : t) std::swap(x[0], x[1]);
    return t;
  }
  // Face `face`'s pyramid's value under choice x, or none (2: above every value) where it has no
  // pyramid.
  double pyramid_value(Index face, int x) const {
    const int p = pyramid_[index_cast<std::size_t>(face)];
    return p < 0 ? 2.0 : pyramids_[index_cast<std::size_t>(p)].value[index_cast<std::size_t>(x)];
  }

  std::array<Index, 4> face_of(std::size_t k, std::size_t f) const {
    std::array<Index, 4> v{};
    for (std::size_t i = 0; i < 4; ++i)
      v[i] = hex(k)[index_cast<std::size_t>(topology::kHexFaceCorners[f][i])];
    return v;
  }
  const std::array<Index, 8>& hex(std::size_t k) const {
    return model_.hexes[index_cast<std::size_t>(hexes_[k])];
  }
  // Hex k's local diagonals (bit f: face f's, 0 through its corners 0-2, 1 through 1-3) under
  // the current choice.
  int diagonals(std::size_t k) const {
    int bits = 0;
    for (std::size_t f = 0; f < 6; ++f)
      bits |= (low_[k][f] ^ choice_[index_cast<std::size_t>(face_[k][f])]) << f;
    return bits;
  }

  // Every face of the split hexes, the split hexes on it, and the diagonal the tets on it have
  // (forced; only the tet part's side can hold tets, so a forced face has one split hex).
  void number_faces() {
    triangles_ = detail::tet_triangles(model_);
    KeyMap<4> ids(6 * hexes_.size());
    face_.resize(hexes_.size()), low_.resize(hexes_.size());
    for (std::size_t k = 0; k < hexes_.size(); ++k)
      for (std::size_t f = 0; f < 6; ++f) {
        const auto v = face_of(k, f);
        const auto [id, fresh] = ids.try_emplace(face_key(v), index_cast(on_.size()));
        if (fresh) {
          on_.push_back({index_cast(k), kInvalidIndex});
          const int d = detail::tets_diagonal(triangles_, v);
          forced_.push_back(d >= 0);
          choice_.push_back(d >= 0 ? static_cast<char>(d ^ detail::lowest_node_diagonal(v)) : 0);
        } else {
          on_[index_cast<std::size_t>(*id)][1] = index_cast(k);
        }
        face_[k][f] = *id;
        low_[k][f] = detail::lowest_node_diagonal(v);
      }
  }

  // A face no tets force and no other split hex shares, under four tet triangles around a node
  // (a four-triangle interface): that node lies on all four of its edges, and no split of the
  // hex follows it.
  void refuse_fans() const {
    auto edge = [](Index a, Index b) { return std::pair{std::min(a, b), std::max(a, b)}; };
    // The edges of split hexes' faces -> the third nodes of the tet triangles on them.
    std::map<std::pair<Index, Index>, std::vector<Index>> thirds;
    for (std::size_t k = 0; k < hexes_.size(); ++k)
      for (const auto& e : topology::kHexEdgeCorners)
        thirds[edge(hex(k)[index_cast<std::size_t>(e[0])], hex(k)[index_cast<std::size_t>(e[1])])];
    for (const auto& t : model_.tets)
      for (const auto& f : topology::kTetFaceCorners)
        for (std::size_t i = 0; i < 3; ++i) {
          const auto it = thirds.find(
              edge(t[index_cast<std::size_t>(f[i])], t[index_cast<std::size_t>(f[(i + 1) % 3])]));
          if (it != thirds.end()) it->second.push_back(t[index_cast<std::size_t>(f[(i + 2) % 3])]);
        }
    for (std::size_t k = 0; k < hexes_.size(); ++k)
      for (std::size_t f = 0; f < 6; ++f) {
        const auto face = index_cast<std::size_t>(face_[k][f]);
        if (forced_[face] || on_[face][1] != kInvalidIndex) continue;
        const auto v = face_of(k, f);
        // The centre: of the nodes on all four edges (the tets' apexes over the fan are too),
        // the nearest the face's middle.
        Index centre = kInvalidIndex;
        double nearest = 0.0;
        Point middle = Point::Zero();
        for (Index u : v) middle += model_.points[index_cast<std::size_t>(u)] / 4.0;
        for (Index x : thirds.at(edge(v[0], v[1]))) {
          bool fan = std::find(hex(k).begin(), hex(k).end(), x) == hex(k).end();
          for (std::size_t i = 1; i < 4 && fan; ++i) {
            const auto& o = thirds.at(edge(v[i], v[(i + 1) % 4]));
            fan = std::find(o.begin(), o.end(), x) != o.end();
          }
          const double d = (model_.points[index_cast<std::size_t>(x)] - middle).norm();
          if (fan && (centre == kInvalidIndex || d < nearest)) centre = x, nearest = d;
        }
        if (centre != kInvalidIndex)
          throw TopologyError(describe_element(model_, {ElementKind::kHex, hexes_[k]}) +
                              ": its face of nodes " + node_list(model_, v) +
                              " lies under four tet triangles around " +
                              describe_node(model_, centre) + ", which no split of it follows");
      }
  }

  // The forced faces whose two tets share their fourth node: a pyramid split along the face's
  // diagonal (Gmsh's, on the tet side of a layer; or two of a split wedge's three tets), which
  // can as well be split along the other one, its four side triangles kept. Such a face's
  // diagonal is chosen with the hexes' (a column's end need not cross its cells' faces the wrong
  // way), each choice valued by its two tets as a hex by its split (split_value). Left forced:
  // a pyramid inverted along the other diagonal, one with a side on its base, and both where a
  // tet is on two such faces.
  void find_pyramids() {
    pyramid_.assign(on_.size(), -1);
    std::vector<int> uses(model_.tets.size(), 0);
    // Triangles a side set names on a tet: a pyramid with a side on its base keeps its split
    // (half the quad has no counterpart along the other diagonal).
    std::set<std::array<Index, 3>> sided;
    for (const SideSet& set : model_.side_sets)
      for (const Side& side : set.sides)
        if (side.element.kind == ElementKind::kTet) {
          const auto f = element_face(model_, side);
          std::array<Index, 3> t{f[0], f[1], f[2]};
          std::sort(t.begin(), t.end());
          sided.insert(t);
        }
    const auto has_side = [&](std::array<Index, 3> t) {
      std::sort(t.begin(), t.end());
      return sided.contains(t);
    };
    for (std::size_t k = 0; k < hexes_.size(); ++k)
      for (std::size_t f = 0; f < 6; ++f) {
        const auto face = index_cast<std::size_t>(face_[k][f]);
        if (!forced_[face]) continue;
        const auto q = face_of(k, f);
        const int given = low_[k][f] ^ choice_[face];  // 0: q[0]-q[2], 1: q[1]-q[3]
        const auto g = index_cast<std::size_t>(given);
        const std::array<Index, 3> base_a{q[g], q[g + 1], q[g + 2]},
            base_b{q[g], q[g + 2], q[(g + 3) % 4]};
        const Index* a = triangles_.find(face_key(base_a));
        const Index* b = triangles_.find(face_key(base_b));
        if (a == nullptr || b == nullptr || *a == *b || has_side(base_a) || has_side(base_b))
          continue;
        const Index apex = fourth(*a, q), other = fourth(*b, q);
        if (apex == kInvalidIndex || apex != other) continue;
        Pyramid p{face, {*a, *b}, q, apex, false, {}, low_[k][f], choice_[face]};
        // Its tets as the model has them are positive: the quad's cyclic order then the apex is
        // their orientation, or its mirror.
        const auto t = tets_of(p, given)[0];
        const auto at = [&](std::size_t i) { return model_.points[index_cast<std::size_t>(t[i])]; };
        p.reversed = tet_volume(at(0), at(1), at(2), at(3)) < 0.0;
        for (int x = 0; x < 2; ++x) {
          double lowest = 1.0;
          for (const auto& t : tets_of(p, low_[k][f] ^ x)) {
            std::array<Point, 4> c;
            for (std::size_t i = 0; i < 4; ++i) c[i] = model_.points[index_cast<std::size_t>(t[i])];
            lowest = std::min(lowest, diced_tet_min_scaled_jacobian(c));
          }
          p.value[index_cast<std::size_t>(x)] = split_value(lowest, lowest);
        }
        // Along the other diagonal a tet would be inverted (a non-convex pyramid): not a choice.
        if (p.value[index_cast<std::size_t>(1 - p.given)] <= 0.0) continue;
        ++uses[index_cast<std::size_t>(*a)], ++uses[index_cast<std::size_t>(*b)];
        pyramid_[face] = index_cast<int>(pyramids_.size());
        pyramids_.push_back(p);
      }
    for (std::size_t i = 0; i < pyramids_.size(); ++i)
      for (Index t : pyramids_[i].tets)
        if (uses[index_cast<std::size_t>(t)] > 1) pyramid_[pyramids_[i].face] = -1;
  }

  // Each hex's split_value under each of the 64 choices of its diagonals, from the diced
  // minimum of each tet it could have (on its corners, or its centre coned over a face's
  // triangle), each measured once.
  void measure() {
    value_.resize(hexes_.size());
    for (std::size_t k = 0; k < hexes_.size(); ++k) {
      std::array<Point, 9> p;  // its corners, then its centre
      p[8] = Point::Zero();
      for (std::size_t i = 0; i < 8; ++i) {
        p[i] = model_.points[index_cast<std::size_t>(hex(k)[i])];
        p[8] += p[i] / 8.0;
      }
      auto tet = [&](int a, int b, int c, int d) {
        return diced_tet_min_scaled_jacobian(
            {p[index_cast<std::size_t>(a)], p[index_cast<std::size_t>(b)],
             p[index_cast<std::size_t>(c)], p[index_cast<std::size_t>(d)]});
      };
      // Per corner tet (by its corners' bits): its diced minimum, measured when first needed.
      std::array<double, 256> corner_tet;
      corner_tet.fill(2.0);
      std::array<double, 64> corners;
      corners.fill(-2.0);  // none
      for (const Triangulation& t : cube_triangulations()) {
        double q = 1.0;
        for (const auto& x : t.tets) {
          double& m = corner_tet[index_cast<std::size_t>((1 << x[0]) | (1 << x[1]) | (1 << x[2]) |
                                                         (1 << x[3]))];
          if (m > 1.0) m = tet(x[0], x[1], x[2], x[3]);
          q = std::min(q, m);
        }
        int bits = 0;
        for (std::size_t f = 0; f < 6; ++f) bits |= t.diagonal[f] << f;
        corners[index_cast<std::size_t>(bits)] =
            std::max(corners[index_cast<std::size_t>(bits)], q);
      }
      // Per face and diagonal: its two triangles coned to the centre, as build() makes them.
      std::array<std::array<double, 2>, 6> cone{};
      for (std::size_t f = 0; f < 6; ++f)
        for (int d = 0; d < 2; ++d) {
          const auto at = [&](int i) {
            return topology::kHexFaceCorners[f][index_cast<std::size_t>((d + i) % 4)];
          };
          cone[f][index_cast<std::size_t>(d)] =
              std::min(tet(at(0), at(2), at(1), 8), tet(at(0), at(3), at(2), 8));
        }
      for (std::size_t bits = 0; bits < 64; ++bits) {
        double centre = 1.0;
        for (std::size_t f = 0; f < 6; ++f) centre = std::min(centre, cone[f][(bits >> f) & 1]);
        value_[k][bits] = split_value(corners[bits], centre);
      }
    }
  }

  // The runs of split hexes through opposite faces: a thin layer's columns, where the diagonals
  // of the faces between its cells must agree with those the tets force at its two ends (a
  // face's warp can be as high as the cell, so a cell whose top and bottom diagonals cross the
  // wrong way has a flat or inverted tet), and the layer's rows along it.
  std::vector<Chain> chains() const {
    // Across hex k's local face f: the other split hex there and its local face, if any.
    auto across = [&](std::size_t k, int f) -> std::pair<std::size_t, int> {
      const auto face = index_cast<std::size_t>(face_[k][index_cast<std::size_t>(f)]);
      const Index o = on_[face][0] == index_cast(k) ? on_[face][1] : on_[face][0];
      if (o == kInvalidIndex) return {hexes_.size(), -1};
      const auto ko = index_cast<std::size_t>(o);
      for (int g = 0; g < 6; ++g)
        if (face_[ko][index_cast<std::size_t>(g)] == index_cast(face)) return {ko, g};
      return {hexes_.size(), -1};
    };
    auto opposite = [](int f) { return topology::kHexOppositeFace[index_cast<std::size_t>(f)]; };
    auto axis = [](int f) { return f < 4 ? f % 2 : 2; };
    std::vector<std::array<char, 3>> seen(hexes_.size(), {0, 0, 0});
    std::vector<Chain> out;
    for (std::size_t k0 = 0; k0 < hexes_.size(); ++k0)
      for (int e0 : {0, 1, 4}) {
        if (seen[k0][index_cast<std::size_t>(axis(e0))]) continue;
        // Back to its first hex (or round a cycle to this one), then forward through it.
        std::size_t k = k0;
        int e = e0;
        for (std::size_t step = 0; step <= 3 * hexes_.size(); ++step) {
          const auto [kb, fb] = across(k, e);
          if (fb < 0 || (kb == k0 && opposite(fb) == e0)) break;
          k = kb, e = opposite(fb);
        }
        Chain c;
        const std::size_t ks = k;
        const int es = e;
        c.faces.push_back(face_[k][index_cast<std::size_t>(e)]);
        for (std::size_t step = 0; step <= 3 * hexes_.size(); ++step) {
          seen[k][index_cast<std::size_t>(axis(e))] = 1;
          c.hexes.push_back(k), c.in.push_back(e), c.out.push_back(opposite(e));
          c.faces.push_back(face_[k][index_cast<std::size_t>(opposite(e))]);
          const auto [kn, fn] = across(k, opposite(e));
          if (fn < 0 || (kn == ks && fn == es)) break;
          k = kn, e = fn;
        }
        out.push_back(std::move(c));
      }
    return out;
  }

  // The free faces' diagonals: from the lowest-node rule's (which splits every hex where no tets
  // force any), each chain in turn takes the diagonals of its free faces that give its hexes the
  // highest lowest split_value, then the highest sum (exactly, by dynamic programming along it,
  // the hexes' other faces as they are), until no chain gains; a hex met twice in a chain is
  // measured as it is after the change, which is kept only where it gains.
  void choose_along_chains() {
    const std::vector<Chain> all = chains();
    constexpr int kSweeps = 8;  // in practice two or three
    for (int sweep = 0; sweep < kSweeps; ++sweep) {
      bool gained = false;
      for (const Chain& c : all) gained |= improve(c);
      if (!gained) break;
    }
  }

  // The lowest and the sum of the split_values of the (distinct) hexes of chain c.
  std::pair<double, double> score(const Chain& c) const {
    std::vector<std::size_t> ks = c.hexes;
    std::sort(ks.begin(), ks.end());
    ks.erase(std::unique(ks.begin(), ks.end()), ks.end());
    double lowest = 2.0, sum = 0.0;
    for (std::size_t k : ks) {
      const double v = value_[k][index_cast<std::size_t>(diagonals(k))];
      lowest = std::min(lowest, v), sum += v;
    }
    // Its ends' pyramids (a face with one: only at an end, the tets on its other side).
    for (Index f : {c.faces.front(), c.faces.back()})
      if (pyramid_[index_cast<std::size_t>(f)] >= 0) {
        const double v = pyramid_value(f, choice_[index_cast<std::size_t>(f)]);
        lowest = std::min(lowest, v), sum += v;
      }
    return {lowest, sum};
  }

  bool improve(const Chain& c) {
    const std::size_t n = c.hexes.size();
    const bool cycle = c.faces.front() == c.faces.back() && n > 1;
    auto free_face = [&](std::size_t j) { return !forced_[index_cast<std::size_t>(c.faces[j])]; };
    // Hex i's split_value with its entering face's choice u and its leaving face's v.
    auto value = [&](std::size_t i, int u, int v) {
      const std::size_t k = c.hexes[i];
      int bits = diagonals(k);
      for (const auto& [f, x] : {std::pair{c.in[i], u}, std::pair{c.out[i], v}}) {
        const auto fi = index_cast<std::size_t>(f);
        bits = (bits & ~(1 << f)) | ((low_[k][fi] ^ x) << f);
      }
      return value_[k][index_cast<std::size_t>(bits)];
    };
    auto has_pyramid = [&](std::size_t j) {
      return pyramid_[index_cast<std::size_t>(c.faces[j])] >= 0;
    };
    auto allowed = [&](std::size_t j, int x) {
      return free_face(j) || has_pyramid(j) || choice_[index_cast<std::size_t>(c.faces[j])] == x;
    };
    // Face j's own value under choice x (its pyramid's), and its part of the sum.
    auto face_value = [&](std::size_t j, int x) { return pyramid_value(c.faces[j], x); };
    auto face_sum = [&](std::size_t j, int x) { return has_pyramid(j) ? face_value(j, x) : 0.0; };
    constexpr double kUnreached = -1e300;
    // Along the chain from face 0 fixed at `first` (-1: either): per face j and choice, the best
    // lowest value (no floor), or the best sum with every value at least `*floor`; `from` the
    // choice of the face before. Returns the best at the last face (fixed at `first` on a cycle)
    // and fills `pick`.
    std::vector<std::array<int, 2>> from(n + 1);
    auto solve = [&](int first, const double* floor, std::vector<char>& pick) {
      const bool lowest = floor == nullptr;
      std::array<double, 2> best{kUnreached, kUnreached};
      for (int x = 0; x < 2; ++x)
        if (allowed(0, x) && (first < 0 || x == first) && (lowest || face_value(0, x) >= *floor))
          best[index_cast<std::size_t>(x)] = lowest ? face_value(0, x) : face_sum(0, x);
      for (std::size_t i = 0; i < n; ++i) {
        std::array<double, 2> next{kUnreached, kUnreached};
        for (int v = 0; v < 2; ++v) {
          if (!allowed(i + 1, v) || (cycle && i + 1 == n && first >= 0 && v != first)) continue;
          for (int u = 0; u < 2; ++u) {
            if (best[index_cast<std::size_t>(u)] <= kUnreached) continue;
            // The hex, and the face it leaves by unless that is face 0 again (a cycle).
            const bool again = cycle && i + 1 == n;
            const double q = value(i, u, v), w = again ? 2.0 : face_value(i + 1, v);
            if (!lowest && (q < *floor || w < *floor)) continue;
            const double s =
                lowest ? std::min({best[index_cast<std::size_t>(u)], q, w})
                       : best[index_cast<std::size_t>(u)] + q + (again ? 0.0 : face_sum(i + 1, v));
            if (s > next[index_cast<std::size_t>(v)])
              next[index_cast<std::size_t>(v)] = s, from[i + 1][index_cast<std::size_t>(v)] = u;
          }
        }
        best = next;
      }
      const int last = best[1] > best[0] ? 1 : 0;
      if (best[index_cast<std::size_t>(last)] <= kUnreached) return kUnreached;
      pick.assign(n + 1, 0);
      pick[n] = static_cast<char>(last);
      for (std::size_t j = n; j > 0; --j)
        pick[j - 1] = static_cast<char>(from[j][static_cast<std::size_t>(pick[j])]);
      return best[index_cast<std::size_t>(last)];
    };
    // On a cycle face 0 is its last face too: each choice of it in turn.
    const std::vector<int> firsts = cycle ? std::vector<int>{0, 1} : std::vector<int>{-1};
    double floor = kUnreached;
    std::vector<char> pick, chosen;
    for (int first : firsts) floor = std::max(floor, solve(first, nullptr, pick));
    if (floor <= kUnreached) return false;
    double sum = kUnreached;
    for (int first : firsts) {
      const double s = solve(first, &floor, pick);
      if (s > sum) sum = s, chosen = pick;
    }
    if (chosen.empty()) return false;
    // Kept where the chain gains: a higher lowest value, or as high and a higher sum.
    const auto before = score(c);
    std::vector<char> old;
    for (Index f : c.faces) old.push_back(choice_[index_cast<std::size_t>(f)]);
    for (std::size_t j = 0; j <= n; ++j) choice_[index_cast<std::size_t>(c.faces[j])] = chosen[j];
    const auto after = score(c);
    constexpr double kGain = 1e-9;
    if (after.first > before.first + kGain ||
        (after.first >= before.first - kGain && after.second > before.second + kGain))
      return true;
    for (std::size_t j = 0; j <= n; ++j) choice_[index_cast<std::size_t>(c.faces[j])] = old[j];
    return false;
  }

  Model build() const;

  const Model& model_;
  std::vector<Index> hexes_;  // the split hexes, ascending (k: a position in it)
  KeyMap<4> triangles_;
  std::vector<std::array<Index, 6>> face_;     // per split hex, its faces' numbers
  std::vector<std::array<int, 6>> low_;        // per split hex, its faces' lowest-node diagonals
  std::vector<std::array<Index, 2>> on_;       // per face, the split hexes on it
  std::vector<char> forced_, choice_;          // per face: tets on it; 1: not the lowest-node one
  std::vector<std::array<double, 64>> value_;  // per split hex, per choice of its diagonals
  std::vector<Pyramid> pyramids_;
  std::vector<int> pyramid_;  // per face: its pyramid in pyramids_, or -1
};

// `model` with the split hexes as tets on the chosen diagonals: each the triangulation of the
// cube with them whose tets dice best, or, none fitting or the best with a tet inverted, its
// centre coned over its faces' triangles.
Model HexSplitter::build() const {
  Model m = model_;
  std::vector<char> split(model_.hexes.size(), 0);
  std::vector<std::size_t> position(model_.hexes.size(), 0);
  for (std::size_t k = 0; k < hexes_.size(); ++k) {
    split[index_cast<std::size_t>(hexes_[k])] = 1;
    position[index_cast<std::size_t>(hexes_[k])] = k;
  }
  detail::tets_with_blocks_and_ids(m);
  m.hexes.clear(), m.hex_block.clear(), m.hex_ids.clear();
  std::vector<Index> first_tet(model_.hexes.size(), kInvalidIndex),
      kept(model_.hexes.size(), kInvalidIndex), tet_count(model_.hexes.size(), 0);
  // A centre node's file id: past the highest so far (found once, not per centre).
  std::int64_t last_node_id =
      m.node_ids.empty() ? 0 : *std::max_element(m.node_ids.begin(), m.node_ids.end());
  for (std::size_t h = 0; h < model_.hexes.size(); ++h) {
    const ElementRef ref{ElementKind::kHex, index_cast(h)};
    if (!split[h]) {
      kept[h] = index_cast(m.hexes.size());
      add_element(m, ElementKind::kHex, model_.hexes[h], block_of(model_, ref),
                  element_id(model_, ref));
      continue;
    }
    const auto& c = model_.hexes[h];
    const int want = diagonals(position[h]);
    auto diagonal = [&](std::size_t f) { return (want >> f) & 1; };
    // The triangulation with those diagonals whose tets dice best.
    std::vector<std::array<Index, 4>> best;
    double best_quality = -2.0;
    for (const Triangulation& t : cube_triangulations()) {
      bool fits = true;
      for (std::size_t f = 0; f < 6; ++f) fits &= diagonal(f) == t.diagonal[f];
      if (!fits) continue;
      std::vector<std::array<Index, 4>> tets;
      for (const auto& x : t.tets)
        tets.push_back({c[index_cast<std::size_t>(x[0])], c[index_cast<std::size_t>(x[1])],
                        c[index_cast<std::size_t>(x[2])], c[index_cast<std::size_t>(x[3])]});
      const double q = diced_min_scaled_jacobian(model_.points, tets);
      if (best.empty() || q > best_quality) best = std::move(tets), best_quality = q;
    }
    // None fits (the 18 choices of six diagonals no triangulation has, which the tets on its
    // faces can force), or the best has a tet inverted: its centre as a node of its own, coned
    // over its faces' triangles, fits any.
    if (best.empty() || best_quality <= 0.0) {
      const Point centre = [&] {
        Point p = Point::Zero();
        for (Index v : c) p += model_.points[index_cast<std::size_t>(v)] / 8.0;
        return p;
      }();
      // Measured on the hex's own 9 points (its corners, then the centre: local numbers).
      std::vector<Point> local;
      for (Index v : c) local.push_back(model_.points[index_cast<std::size_t>(v)]);
      local.push_back(centre);
      std::vector<std::array<Index, 4>> tets;
      for (std::size_t f = 0; f < 6; ++f) {
        const auto& fc = topology::kHexFaceCorners[f];
        const int d = diagonal(f);
        // Its two triangles, outward, coned to the centre inside: (a, c, b, centre).
        for (int k : {1, 2}) {
          const auto at = [&](int i) {
            return index_cast(fc[index_cast<std::size_t>((d + i) % 4)]);
          };
          tets.push_back(k == 1 ? std::array<Index, 4>{at(0), at(2), at(1), 8}
                                : std::array<Index, 4>{at(0), at(3), at(2), 8});
        }
      }
      const double q = diced_min_scaled_jacobian(local, tets);
      if (best.empty() || q > best_quality) {
        const Index node = index_cast(m.points.size());
        for (auto& t : tets)
          for (Index& v : t) v = v == 8 ? node : c[index_cast<std::size_t>(v)];
        best = std::move(tets), best_quality = q;
        m.points.push_back(centre);
        if (!m.node_ids.empty()) m.node_ids.push_back(++last_node_id);
      }
    }
    if (best_quality <= 0.0)
      throw TopologyError(describe_element(model_, ref) +
                          ": the diagonals its neighbours give its faces leave no way to split "
                          "it into positive tets, on its corners or with its centre");
    tet_count[h] = index_cast(best.size());
    first_tet[h] = index_cast(m.tets.size());
    for (const auto& t : best)
      add_element(m, ElementKind::kTet, t, block_of(model_, ref), element_id(model_, ref));
  }
  // The pyramids whose face took the other diagonal: their two tets along it, in their places.
  std::vector<int> flipped(model_.tets.size(), -1);  // per tet: its re-split pyramid
  for (std::size_t i = 0; i < pyramids_.size(); ++i) {
    const Pyramid& p = pyramids_[i];
    if (pyramid_[p.face] < 0 || choice_[p.face] == p.given) continue;
    const auto tets = tets_of(p, p.low ^ choice_[p.face]);
    for (std::size_t j = 0; j < 2; ++j) {
      m.tets[index_cast<std::size_t>(p.tets[j])] = tets[j];
      flipped[index_cast<std::size_t>(p.tets[j])] = index_cast<int>(i);
    }
  }
  // Sides of split hexes: the faces of its tets whose nodes all lie on the hex's face; of a
  // flipped pyramid's tets: the new one's on the same side triangle.
  rewrite_sides(m, [&](const Side& s, std::vector<Side>& sides) {
    const auto h = index_cast<std::size_t>(s.element.index);
    if (s.element.kind == ElementKind::kTet && flipped[h] >= 0) {
      // On a side triangle (none is on the base: find_pyramids).
      for (Index t : pyramids_[index_cast<std::size_t>(flipped[h])].tets) {
        const auto on = tet_sides_on(m, t, 1, element_face(model_, s));
        sides.insert(sides.end(), on.begin(), on.end());
      }
    } else if (s.element.kind != ElementKind::kHex) {
      sides.push_back(s);
    } else if (!split[h]) {
      sides.push_back({{ElementKind::kHex, kept[h]}, s.face});
    } else {
      const auto on = tet_sides_on(m, first_tet[h], tet_count[h], element_face(model_, s));
      sides.insert(sides.end(), on.begin(), on.end());
    }
  });
  return m;
}

}  // namespace

CellPieces cell_pieces(const Model& model, std::span<const Index> wedges) {
  const std::size_t nh = model.hexes.size(), nw = model.wedges.size();
  DisjointSets sets(nh + nw);  // hexes first, then wedges
  KeyMap<4> first(6 * nh + 5 * nw);
  auto join = [&](std::span<const Index> nodes, std::size_t cell) {
    const auto [id, fresh] = first.try_emplace(face_key(nodes), index_cast(cell));
    if (!fresh) sets.unite(*id, index_cast(cell));
  };
  for (std::size_t h = 0; h < nh; ++h)
    for (const auto& f : topology::kHexFaceCorners) {
      std::array<Index, 4> nodes{};
      for (std::size_t i = 0; i < 4; ++i) nodes[i] = model.hexes[h][index_cast<std::size_t>(f[i])];
      join(nodes, h);
    }
  const auto& topo = cell_topology(ElementKind::kWedge);
  for (std::size_t w = 0; w < nw; ++w)
    for (int face = 0; face < topo.faces; ++face)
      join(face_nodes(model.wedges[w], topo.face[index_cast<std::size_t>(face)]), nh + w);
  std::vector<char> chosen(nh + nw, 0);
  for (Index w : wedges) chosen[index_cast<std::size_t>(sets.find(index_cast(nh) + w))] = 1;
  CellPieces out;
  for (std::size_t c = 0; c < nh + nw; ++c)
    if (chosen[index_cast<std::size_t>(sets.find(index_cast(c)))])
      (c < nh ? out.hexes : out.wedges).push_back(index_cast(c < nh ? c : c - nh));
  return out;
}

WedgeColumns wedge_columns(const Model& model, std::span<const Index> wedges) {
  const auto& topo = cell_topology(ElementKind::kWedge);
  // A wedge triangle -> the wedges on it (two where a column goes on through it).
  KeyMap<4> first(2 * model.wedges.size());
  std::vector<std::array<Index, 2>> next(model.wedges.size(), {kInvalidIndex, kInvalidIndex});
  for (std::size_t w = 0; w < model.wedges.size(); ++w)
    for (std::size_t t = 0; t < 2; ++t) {
      const auto nodes = face_nodes(model.wedges[w], topo.face[3 + t]);
      const auto [id, fresh] = first.try_emplace(face_key(nodes), index_cast(w));
      if (fresh) continue;
      const auto o = index_cast<std::size_t>(*id);
      next[w][t] = *id;
      for (std::size_t u = 0; u < 2; ++u)  // the other wedge's face on it
        if (face_key(face_nodes(model.wedges[o], topo.face[3 + u])) == face_key(nodes))
          next[o][u] = index_cast(w);
    }
  const KeyMap<4> triangles = detail::tet_triangles(model);
  const auto at = [&](Index n) { return model.points[index_cast<std::size_t>(n)]; };
  WedgeColumns out;
  std::vector<char> seen(model.wedges.size(), 0);
  double sum = 0.0;
  int columns = 0;
  for (Index start : wedges) {
    if (seen[index_cast<std::size_t>(start)]) continue;
    // Walk the column both ways to its two end triangles.
    std::array<std::vector<Index>, 2> end{};  // per direction: its end triangle's nodes
    int cells = 1;
    seen[index_cast<std::size_t>(start)] = 1;
    for (std::size_t dir = 0; dir < 2; ++dir) {
      Index w = start;
      std::size_t face = dir;
      for (;;) {
        const Index n = next[index_cast<std::size_t>(w)][face];
        if (n == kInvalidIndex || seen[index_cast<std::size_t>(n)]) break;
        const auto nodes =
            face_nodes(model.wedges[index_cast<std::size_t>(w)], topo.face[3 + face]);
        const auto& o = model.wedges[index_cast<std::size_t>(n)];
        face = face_key(face_nodes(o, topo.face[3])) == face_key(nodes) ? 1 : 0;  // its far one
        w = n;
        seen[index_cast<std::size_t>(w)] = 1;
        ++cells;
      }
      end[dir] = face_nodes(model.wedges[index_cast<std::size_t>(w)], topo.face[3 + face]);
    }
    if (triangles.find(face_key(end[0])) == nullptr || triangles.find(face_key(end[1])) == nullptr)
      continue;
    Point centre[2];
    double edge = 0.0;
    for (std::size_t d = 0; d < 2; ++d) {
      centre[d] = (at(end[d][0]) + at(end[d][1]) + at(end[d][2])) / 3.0;
      for (std::size_t i = 0; i < 3; ++i) edge += (at(end[d][i]) - at(end[d][(i + 1) % 3])).norm();
    }
    sum += (centre[1] - centre[0]).norm() / cells / (edge / 6.0);
    ++columns;
  }
  out.through = columns > 0;
  out.height_ratio = columns ? sum / columns : 0.0;
  return out;
}

Model split_hexes(const Model& model, std::span<const Index> hexes) {
  if (hexes.empty()) return model;
  return HexSplitter(model, hexes).run();
}

}  // namespace geode::primal
