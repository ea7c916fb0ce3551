#include <geode/primal/split_hexes.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
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
  Model m = model;
  if (hexes.empty()) return m;
  const KeyMap<4> triangles = detail::tet_triangles(model);
  std::vector<char> split(model.hexes.size(), 0);
  for (Index h : hexes) split[index_cast<std::size_t>(h)] = 1;

  detail::tets_with_blocks_and_ids(m);
  m.hexes.clear(), m.hex_block.clear(), m.hex_ids.clear();
  std::vector<Index> first_tet(model.hexes.size(), kInvalidIndex),
      kept(model.hexes.size(), kInvalidIndex);
  // Each face of a split hex -> how many split hexes have it.
  KeyMap<4> split_faces(6 * hexes.size());
  for (Index h : hexes)
    for (const auto& fc : topology::kHexFaceCorners) {
      std::array<Index, 4> v{};
      for (std::size_t i = 0; i < 4; ++i)
        v[i] = model.hexes[index_cast<std::size_t>(h)][index_cast<std::size_t>(fc[i])];
      const auto [count, fresh] = split_faces.try_emplace(face_key(v), 1);
      if (!fresh) ++*count;
    }
  std::vector<Index> tet_count(model.hexes.size(), 0);
  // A centre node's file id: past the highest so far (found once, not per centre).
  std::int64_t last_node_id =
      m.node_ids.empty() ? 0 : *std::max_element(m.node_ids.begin(), m.node_ids.end());
  // The edges of split hexes' faces -> the third nodes of the tet triangles on them: a face
  // under four tet triangles around a node (a four-triangle interface) has that node on all
  // four of its edges, and no split of the hex follows it.
  std::map<std::pair<Index, Index>, std::vector<Index>> thirds;
  auto edge = [](Index a, Index b) { return std::pair{std::min(a, b), std::max(a, b)}; };
  for (Index h : hexes)
    for (const auto& e : topology::kHexEdgeCorners)
      thirds[edge(model.hexes[index_cast<std::size_t>(h)][index_cast<std::size_t>(e[0])],
                  model.hexes[index_cast<std::size_t>(h)][index_cast<std::size_t>(e[1])])];
  for (const auto& t : model.tets)
    for (const auto& f : topology::kTetFaceCorners)
      for (std::size_t i = 0; i < 3; ++i) {
        const auto it = thirds.find(
            edge(t[index_cast<std::size_t>(f[i])], t[index_cast<std::size_t>(f[(i + 1) % 3])]));
        if (it != thirds.end()) it->second.push_back(t[index_cast<std::size_t>(f[(i + 2) % 3])]);
      }
  for (std::size_t h = 0; h < model.hexes.size(); ++h) {
    const ElementRef ref{ElementKind::kHex, index_cast(h)};
    if (!split[h]) {
      kept[h] = index_cast(m.hexes.size());
      add_element(m, ElementKind::kHex, model.hexes[h], block_of(model, ref),
                  element_id(model, ref));
      continue;
    }
    const auto& c = model.hexes[h];
    // Each face's diagonal: the tets' on it, else through the lowest node where another split
    // hex shares the face, else (on the boundary) either.
    std::array<int, 6> want{};
    for (std::size_t f = 0; f < 6; ++f) {
      const auto& fc = topology::kHexFaceCorners[f];
      std::array<Index, 4> v{};
      for (std::size_t i = 0; i < 4; ++i) v[i] = c[index_cast<std::size_t>(fc[i])];
      want[f] = detail::tets_diagonal(triangles, v);
      if (want[f] < 0 && *split_faces.find(face_key(v)) > 1)
        want[f] = detail::lowest_node_diagonal(v);
      if (want[f] < 0) {
        // The centre: of the nodes on all four edges (the tets' apexes over the fan are too),
        // the nearest the face's middle.
        Index centre = kInvalidIndex;
        double nearest = 0.0;
        Point middle = Point::Zero();
        for (Index u : v) middle += model.points[index_cast<std::size_t>(u)] / 4.0;
        for (Index x : thirds.at(edge(v[0], v[1]))) {
          bool fan = std::find(c.begin(), c.end(), x) == c.end();
          for (std::size_t i = 1; i < 4 && fan; ++i) {
            const auto& o = thirds.at(edge(v[i], v[(i + 1) % 4]));
            fan = std::find(o.begin(), o.end(), x) != o.end();
          }
          const double d = (model.points[index_cast<std::size_t>(x)] - middle).norm();
          if (fan && (centre == kInvalidIndex || d < nearest)) centre = x, nearest = d;
        }
        if (centre != kInvalidIndex)
          throw TopologyError(describe_element(model, ref) + ": its face of nodes " +
                              node_list(model, v) + " lies under four tet triangles around " +
                              describe_node(model, centre) + ", which no split of it follows");
      }
    }
    // The triangulation with those diagonals whose tets dice best.
    std::vector<std::array<Index, 4>> best;
    double best_quality = -2.0;
    for (const Triangulation& t : cube_triangulations()) {
      bool fits = true;
      for (std::size_t f = 0; f < 6; ++f) fits &= want[f] < 0 || want[f] == t.diagonal[f];
      if (!fits) continue;
      std::vector<std::array<Index, 4>> tets;
      for (const auto& x : t.tets)
        tets.push_back({c[index_cast<std::size_t>(x[0])], c[index_cast<std::size_t>(x[1])],
                        c[index_cast<std::size_t>(x[2])], c[index_cast<std::size_t>(x[3])]});
      const double q = diced_min_scaled_jacobian(model.points, tets);
      if (best.empty() || q > best_quality) best = std::move(tets), best_quality = q;
    }
    // None fits (the 18 choices of six diagonals no triangulation has, which the tets on its
    // faces can force), or the best has a tet inverted: its centre as a node of its own, coned
    // over its faces' triangles, fits any.
    if (best.empty() || best_quality <= 0.0) {
      const Point centre = [&] {
        Point p = Point::Zero();
        for (Index v : c) p += model.points[index_cast<std::size_t>(v)] / 8.0;
        return p;
      }();
      // Measured on the hex's own 9 points (its corners, then the centre: local numbers).
      std::vector<Point> local;
      for (Index v : c) local.push_back(model.points[index_cast<std::size_t>(v)]);
      local.push_back(centre);
      std::vector<std::array<Index, 4>> tets;
      for (std::size_t f = 0; f < 6; ++f) {
        const auto& fc = topology::kHexFaceCorners[f];
        int d = want[f];
        if (d < 0) {
          std::array<Index, 4> v{};
          for (std::size_t i = 0; i < 4; ++i) v[i] = c[index_cast<std::size_t>(fc[i])];
          d = detail::lowest_node_diagonal(v);
        }
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
      throw TopologyError(describe_element(model, ref) +
                          ": the diagonals its neighbours give its faces leave no way to split "
                          "it into positive tets, on its corners or with its centre");
    tet_count[h] = index_cast(best.size());
    first_tet[h] = index_cast(m.tets.size());
    for (const auto& t : best)
      add_element(m, ElementKind::kTet, t, block_of(model, ref), element_id(model, ref));
  }
  // Sides of split hexes: the faces of its tets whose nodes all lie on the hex's face.
  rewrite_sides(m, [&](const Side& s, std::vector<Side>& sides) {
    const auto h = index_cast<std::size_t>(s.element.index);
    if (s.element.kind != ElementKind::kHex) {
      sides.push_back(s);
    } else if (!split[h]) {
      sides.push_back({{ElementKind::kHex, kept[h]}, s.face});
    } else {
      const auto on = tet_sides_on(m, first_tet[h], tet_count[h], element_face(model, s));
      sides.insert(sides.end(), on.begin(), on.end());
    }
  });
  return m;
}

}  // namespace geode::primal
