// Folded tets put back (primal/unfold.hpp).
#include <geode/primal/unfold.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <map>
#include <span>

#include <geode/primal/boundary.hpp>
#include <geode/primal/input_check.hpp>

namespace geode::primal {

namespace {

using Triangle = std::array<Index, 3>;

// The signed volume of tet t (tet_volume) with node `at` (one of its corners) placed at x.
double volume_with(const Model& m, const std::array<Index, 4>& t, Index at, const Point& x) {
  const auto p = [&](std::size_t i) -> const Point& {
    return t[i] == at ? x : m.points[index_cast<std::size_t>(t[i])];
  };
  return tet_volume(p(0), p(1), p(2), p(3));
}

// Where node v goes: the star of v (its tets, oriented) has a point farthest inside the planes
// of their faces opposite v, max t such that the distance from x to each of those planes, on the
// tet's side, is at least t (the Chebyshev centre; each such distance is linear in x, so the
// optimum is where four of them are equal: the LP's vertices, enumerated, a star having a few
// dozen tets). v moves from where the mesher put it toward that centre only until every distance
// is half that depth: its tets positive and well clear of flat, the mesh changed no more than
// that needs. False when no point leaves every tet positive.
bool unfolded_position(const Model& m, Index v, const std::vector<Index>& star, Point& best) {
  struct Plane {
    Point n;  // unit, into the tet
    double d;
  };
  std::vector<Plane> planes;
  const Point here = m.points[index_cast<std::size_t>(v)];
  for (Index t : star) {
    const auto& tet = m.tets[index_cast<std::size_t>(t)];
    // The volume is linear in x: its gradient from three unit steps (exact up to rounding).
    const double at0 = volume_with(m, tet, v, here);
    Point g;
    for (int a = 0; a < 3; ++a) g[a] = volume_with(m, tet, v, here + Point::Unit(a)) - at0;
    const double norm = g.norm();
    if (!(norm > 0.0)) return false;
    planes.push_back({g / norm, (g.dot(here) - at0) / norm});  // n.x - d = distance
  }
  double top = 0.0;
  bool found = false;
  const std::size_t n = planes.size();
  Eigen::Matrix4d A;
  Eigen::Vector4d b;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      for (std::size_t k = j + 1; k < n; ++k)
        for (std::size_t l = k + 1; l < n; ++l) {
          const std::size_t rows[4] = {i, j, k, l};
          for (int r = 0; r < 4; ++r) {
            const Plane& p = planes[rows[r]];
            A.row(r) << p.n.x(), p.n.y(), p.n.z(), -1.0;
            b[r] = p.d;
          }
          const Eigen::FullPivLU<Eigen::Matrix4d> lu(A);
          if (!lu.isInvertible()) continue;
          const Eigen::Vector4d s = lu.solve(b);
          const double t = s[3];
          if (!(t > top)) continue;
          const Point x = s.head<3>();
          if (std::all_of(planes.begin(), planes.end(),
                          [&](const Plane& p) { return p.n.dot(x) - p.d >= t * (1 - 1e-9); }))
            top = t, best = x, found = true;
        }
  if (!found) return false;
  // Along the segment each distance is linear: the least step that puts every one at top / 2.
  double step = 0.0;
  for (const Plane& p : planes) {
    const double from = p.n.dot(here) - p.d, to = p.n.dot(best) - p.d;  // to >= top
    if (from < 0.5 * top) step = std::max(step, (0.5 * top - from) / (to - from));
  }
  best = here + std::min(step, 1.0) * (best - here);
  return true;
}

}  // namespace

UnfoldResult unfold_tets(Model& model) {
  InputCheckOptions o;
  o.max_findings = 1000;
  const InputCheckResult check = check_input(model, o);
  UnfoldResult none;
  if (check.ok()) {
    none.covered_once = true;
    return none;
  }
  // The tets check_input found on the same side of a shared face as another element.
  std::vector<Index> work;
  for (const InputFinding& f : check.findings)
    if (f.fault == InputFault::kSameSideFace)
      for (const ElementRef& e : f.elements)
        if (e.kind == ElementKind::kTet) work.push_back(e.index);
  if (work.empty()) return none;

  // Near the folds (their tets' nodes and three rings of elements around them, so that each
  // node moved has its whole star and each tet turned its neighbours'): every element's
  // triangles (a quad face is no tet's) with the elements using them, each in the cyclic order
  // that element gives it; per node: on a boundary face, elements other than tets, blocks.
  const std::size_t nv = model.points.size();
  std::vector<char> near(nv, 0);
  for (Index t : work)
    for (Index v : model.tets[index_cast<std::size_t>(t)]) near[index_cast<std::size_t>(v)] = 1;
  const auto touches = [&](std::span<const Index> cs) {
    return std::any_of(cs.begin(), cs.end(),
                       [&](Index v) { return near[index_cast<std::size_t>(v)] == 1; });
  };
  for (int ring = 0; ring < 3; ++ring) {
    for (ElementKind kind : kElementKinds)
      for (std::size_t i = 0; i < element_count(model, kind); ++i) {
        const auto cs = element_corners(model, {kind, index_cast(i)});
        if (touches(cs))
          for (Index v : cs)
            if (!near[index_cast<std::size_t>(v)]) near[index_cast<std::size_t>(v)] = 2;
      }
    for (char& c : near) c = c ? 1 : 0;
  }
  struct Use {
    ElementRef element;
    Triangle cycle;  // as the element orders it (outward)
  };
  std::map<FaceKey, std::vector<Use>> uses;
  std::vector<char> fixed(nv, 0);
  std::vector<int> block(nv, 0);  // the one block of the node's tets, -1 when more than one
  std::vector<std::vector<Index>> tets_at(nv);
  const auto triangle = [&](std::span<const Index> cs, const topology::CellFace& cf) {
    return Triangle{cs[static_cast<std::size_t>(cf.corners[0])],
                    cs[static_cast<std::size_t>(cf.corners[1])],
                    cs[static_cast<std::size_t>(cf.corners[2])]};
  };
  for (ElementKind kind : kElementKinds)
    for (std::size_t i = 0; i < element_count(model, kind); ++i) {
      const ElementRef e{kind, index_cast(i)};
      const auto cs = element_corners(model, e);
      if (!touches(cs)) continue;
      const auto& topo = cell_topology(kind);
      for (int f = 0; f < topo.faces; ++f) {
        const auto& cf = topo.face[static_cast<std::size_t>(f)];
        if (cf.size != 3) continue;
        const Triangle t = triangle(cs, cf);
        uses[face_key(t)].push_back({e, t});
      }
      for (Index v : cs) {
        const auto u = index_cast<std::size_t>(v);
        if (kind != ElementKind::kTet) {
          fixed[u] = 1;
          continue;
        }
        tets_at[u].push_back(e.index);
        const int b = block_of(model, e);
        block[u] = block[u] == 0 || block[u] == b ? b : -1;
      }
    }
  // Nodes on a face used once (the boundary; quads are not counted, so a tet corner on a quad
  // interface counts as boundary too, and stays), in a node set, or between blocks stay.
  for (const auto& [t, list] : uses)
    if (list.size() == 1)
      for (Index v : t)
        if (v != kInvalidIndex) fixed[index_cast<std::size_t>(v)] = 1;  // a triangle's pad
  for (const NodeSet& s : model.node_sets)
    for (Index v : s.nodes) fixed[index_cast<std::size_t>(v)] = 1;
  for (const SideSet& s : model.side_sets)  // a surface embedded in the tets stays too
    for (const Side& side : s.sides) {
      const auto cs = element_corners(model, side.element);
      const auto& cf = cell_topology(side.element.kind).face[static_cast<std::size_t>(side.face)];
      for (int i = 0; i < cf.size; ++i)
        fixed[index_cast<std::size_t>(cs[static_cast<std::size_t>(cf.corners[i])])] = 1;
    }
  for (std::size_t v = 0; v < nv; ++v)
    if (block[v] < 0) fixed[v] = 1;

  // Tets turned over: each on the same side as every element it shares a face with, counting
  // the tets turned so far as turned (two neighbours turned together agree on their face until
  // one of them is turned back). Turned until none is left.
  std::vector<char> turned(model.tets.size(), 0);
  const auto same_cycle = [](const Triangle& a, const Triangle& b) {
    return a == b || a == Triangle{b[1], b[2], b[0]} || a == Triangle{b[2], b[0], b[1]};
  };
  const auto flipped = [&](const Use& u) {
    return u.element.kind == ElementKind::kTet && turned[index_cast<std::size_t>(u.element.index)];
  };
  // (faces t shares with another element, of them those on one side) as the tets stand now.
  const auto sides = [&](Index t) {
    const auto cs = element_corners(model, {ElementKind::kTet, t});
    std::pair<int, int> n{0, 0};
    for (int f = 0; f < 4; ++f) {
      const Triangle mine =
          triangle(cs, cell_topology(ElementKind::kTet).face[static_cast<std::size_t>(f)]);
      const auto found = uses.find(face_key(mine));
      if (found == uses.end() || found->second.size() != 2) continue;
      const auto& list = found->second;
      ++n.first;
      const Use& other = list[0].element == ElementRef{ElementKind::kTet, t} ? list[1] : list[0];
      // Each side's cycle as it is now (a turned tet's reversed), the same: one side.
      n.second +=
          same_cycle(mine, other.cycle) != (flipped(other) != turned[index_cast<std::size_t>(t)]);
    }
    return n;
  };
  std::map<Index, int> folds;  // the tets found, with their faces on one side
  for (Index t : work) folds[t] = sides(t).second;
  // The tets on one side of the most faces first: a neighbour of a fold, on one side of its one
  // face with the fold, is not turned in its place (its nodes fixed, the whole mend given up).
  std::sort(work.begin(), work.end());
  work.erase(std::unique(work.begin(), work.end()), work.end());
  std::stable_sort(work.begin(), work.end(), [&](Index a, Index b) { return folds[a] > folds[b]; });
  for (std::size_t round = 0; !work.empty() && round < 100; ++round) {
    std::vector<Index> next;
    for (Index t : work) {
      if (turned[index_cast<std::size_t>(t)]) continue;
      const auto [shared, same] = sides(t);
      if (shared == 0 || same < shared) continue;
      turned[index_cast<std::size_t>(t)] = 1;
      // Its neighbours may now be on its same side: looked at again.
      for (Index v : model.tets[index_cast<std::size_t>(t)])
        for (Index s : tets_at[index_cast<std::size_t>(v)]) next.push_back(s);
    }
    std::sort(next.begin(), next.end());
    next.erase(std::unique(next.begin(), next.end()), next.end());
    work = std::move(next);
  }
  // Neighbours turned together (each on one side with all its faces but theirs): the tets left
  // with two or more such faces, joined through shared faces, turned as one where that leaves
  // none of them on one side of any face.
  std::vector<Index> left;
  for (const auto& [t, same] : folds)
    if (same >= 2 && !turned[index_cast<std::size_t>(t)] && sides(t).second >= 2) left.push_back(t);
  std::vector<char> seen(model.tets.size(), 0);
  for (Index start : left) {
    if (seen[index_cast<std::size_t>(start)]) continue;
    std::vector<Index> group{start};
    seen[index_cast<std::size_t>(start)] = 1;
    for (std::size_t i = 0; i < group.size(); ++i)
      for (Index t : left)
        if (!seen[index_cast<std::size_t>(t)]) {
          int common = 0;
          for (Index v : model.tets[index_cast<std::size_t>(t)])
            common += std::count(model.tets[index_cast<std::size_t>(group[i])].begin(),
                                 model.tets[index_cast<std::size_t>(group[i])].end(), v) > 0;
          if (common == 3) group.push_back(t), seen[index_cast<std::size_t>(t)] = 1;
        }
    for (Index t : group) turned[index_cast<std::size_t>(t)] = 1;
    if (!std::all_of(group.begin(), group.end(), [&](Index t) { return sides(t).second == 0; }))
      for (Index t : group) turned[index_cast<std::size_t>(t)] = 0;
  }

  UnfoldResult result;
  std::vector<Point> from;  // where the moved nodes were
  // Unless every fold is mended, the model goes back as it was.
  const auto undo = [&] {
    for (const ElementRef& e : result.turned) {
      auto& tet = model.tets[index_cast<std::size_t>(e.index)];
      std::swap(tet[0], tet[1]);
    }
    for (std::size_t i = result.moved.size(); i-- > 0;)  // the first place last
      model.points[index_cast<std::size_t>(result.moved[i])] = from[i];
    return none;
  };
  for (std::size_t t = 0; t < model.tets.size(); ++t)
    if (turned[t]) {
      std::swap(model.tets[t][0], model.tets[t][1]);  // as the geometry has it: inverted
      result.turned.push_back({ElementKind::kTet, index_cast(t)});
    }
  for (const ElementRef& e : result.turned) {
    const auto& tet = model.tets[index_cast<std::size_t>(e.index)];
    if (volume_with(model, tet, tet[0], model.points[index_cast<std::size_t>(tet[0])]) > 0.0)
      continue;  // put right by a node moved for a neighbour
    // Of its free nodes, the one whose tets come out the largest at its new place moves.
    Index node = kInvalidIndex;
    Point to = Point::Zero();
    double depth = 0.0;
    for (Index v : tet) {
      if (fixed[index_cast<std::size_t>(v)]) continue;
      Point x;
      if (!unfolded_position(model, v, tets_at[index_cast<std::size_t>(v)], x)) continue;
      double d = 1e300;
      for (Index s : tets_at[index_cast<std::size_t>(v)])
        d = std::min(d, volume_with(model, model.tets[index_cast<std::size_t>(s)], v, x));
      if (d > depth) depth = d, node = v, to = x;
    }
    if (node == kInvalidIndex) return undo();
    Point& at = model.points[index_cast<std::size_t>(node)];
    result.farthest = std::max(result.farthest, (to - at).norm());
    from.push_back(at);
    result.moved.push_back(node);
    at = to;
  }
  if (result.moved.empty() || !check_input(model).ok()) return undo();
  result.covered_once = true;
  return result;
}

}  // namespace geode::primal
