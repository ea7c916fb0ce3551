// Folded tets and pyramids put back (primal/unfold.hpp).
#include <geode/primal/unfold.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <span>

#include <geode/primal/boundary.hpp>
#include <geode/primal/input_check.hpp>
#include <geode/primal/split_pyramids.hpp>

namespace geode::primal {

namespace {

using Tet = std::array<Index, 4>;
using Cycle = std::array<Index, 4>;  // a face's corners as an element orders it; a triangle's
                                     // fourth kInvalidIndex

// The tets whose signed volumes say that an element is positive: a tet itself; a pyramid's two
// tets along each base diagonal (pyramid_tets; all four positive: positive along both
// diagonals, which check_geometry's one and conform's choice of either follow from, and linear
// in the apex).
std::vector<Tet> pieces(const Model& m, ElementRef e) {
  if (e.kind == ElementKind::kTet) return {m.tets[index_cast<std::size_t>(e.index)]};
  const auto& p = m.pyramids[index_cast<std::size_t>(e.index)];
  const auto d02 = pyramid_tets(p, 0), d13 = pyramid_tets(p, 1);
  return {d02[0], d02[1], d13[0], d13[1]};
}

// The least signed volume of the tets.
double min_volume(const Model& m, const std::vector<Tet>& tets) {
  double least = 1e300;
  for (const Tet& t : tets)
    least = std::min(least, tet_volume(m.points[index_cast<std::size_t>(t[0])],
                                       m.points[index_cast<std::size_t>(t[1])],
                                       m.points[index_cast<std::size_t>(t[2])],
                                       m.points[index_cast<std::size_t>(t[3])]));
  return least;
}

// Turns an element's node order (its faces' cycles reversed): a tet's first two corners, a
// pyramid's base corners 1 and 3. Its own inverse.
void turn(Model& m, ElementRef e) {
  const auto i = index_cast<std::size_t>(e.index);
  if (e.kind == ElementKind::kTet)
    std::swap(m.tets[i][0], m.tets[i][1]);
  else
    std::swap(m.pyramids[i][1], m.pyramids[i][3]);
}

// The signed volume of tet t (tet_volume) with node `at` (one of its corners) placed at x.
double volume_with(const Model& m, const Tet& t, Index at, const Point& x) {
  const auto p = [&](std::size_t i) -> const Point& {
    return t[i] == at ? x : m.points[index_cast<std::size_t>(t[i])];
  };
  return tet_volume(p(0), p(1), p(2), p(3));
}

// Where node v goes: the star of v (its elements' pieces, oriented) has a point farthest inside
// the planes of their faces opposite v, max t such that the distance from x to each of those
// planes, on the tet's side, is at least t (the Chebyshev centre; each such distance is linear in
// x, so the optimum is where four of them are equal: the LP's vertices, enumerated, a star having a
// few dozen tets). v moves from where the mesher put it toward that centre only until every
// distance is half that depth: its tets positive and well clear of flat, the mesh changed no more
// than that needs. False when no point leaves every tet positive.
bool unfolded_position(const Model& m, Index v, const std::vector<Tet>& star, Point& best) {
  struct Plane {
    Point n;  // unit, into the tet
    double d;
  };
  std::vector<Plane> planes;
  const Point here = m.points[index_cast<std::size_t>(v)];
  for (const Tet& tet : star) {
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

UnfoldResult unfold(Model& model) {
  InputCheckOptions o;
  o.max_findings = 1000;
  const InputCheckResult check = check_input(model, o);
  UnfoldResult none;
  // Tets and pyramids the readers refuse as inverted (check_geometry), read without that check:
  // a node pushed through a face and left there, the node orders agreeing with the neighbours'.
  std::vector<ElementRef> inverted;
  const auto pt = [&](Index v) -> const Point& { return model.points[index_cast<std::size_t>(v)]; };
  for (std::size_t t = 0; t < model.tets.size(); ++t) {
    const auto& c = model.tets[t];
    if (!(tet_volume(pt(c[0]), pt(c[1]), pt(c[2]), pt(c[3])) > 0.0))
      inverted.push_back({ElementKind::kTet, index_cast(t)});
  }
  for (std::size_t p = 0; p < model.pyramids.size(); ++p)
    if (!splits_positive(pyramid_corner_volumes(model, model.pyramids[p])))
      inverted.push_back({ElementKind::kPyramid, index_cast(p)});
  if (check.ok() && inverted.empty()) {
    none.covered_once = true;
    return none;
  }
  // The tets and pyramids check_input found on the same side of a shared face as another element.
  const auto mendable = [](ElementKind k) {
    return k == ElementKind::kTet || k == ElementKind::kPyramid;
  };
  std::vector<ElementRef> work;
  for (const InputFinding& f : check.findings)
    if (f.fault == InputFault::kSameSideFace)
      for (const ElementRef& e : f.elements)
        if (mendable(e.kind)) work.push_back(e);
  if (work.empty() && inverted.empty()) return none;

  // Near the folds (their elements' nodes and three rings of elements around them, so that each
  // node moved has its whole star and each element turned its neighbours', unless the turning
  // below spreads further: the checks at the end stand behind it): every element's
  // faces with the elements using them, each in the cyclic order that element gives it; per
  // node: on a boundary face, elements it cannot move in, blocks.
  const std::size_t nv = model.points.size();
  std::vector<char> near(nv, 0);
  for (const auto* list : {&work, &inverted})
    for (const ElementRef& e : *list)
      for (Index v : element_corners(model, e)) near[index_cast<std::size_t>(v)] = 1;
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
    Cycle cycle;  // as the element orders it (outward)
  };
  std::map<FaceKey, std::vector<Use>> uses;
  std::vector<char> fixed(nv, 0);
  std::vector<int> block(nv, 0);  // the one block of the node's elements, -1 when more than one
  std::vector<std::vector<ElementRef>> star(nv);  // the elements the node may move in
  const auto cycle = [](std::span<const Index> cs, const topology::CellFace& cf) {
    Cycle c{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
    for (int i = 0; i < cf.size; ++i)
      c[static_cast<std::size_t>(i)] = cs[static_cast<std::size_t>(cf.corners[i])];
    return c;
  };
  const auto key = [](const Cycle& c) {
    return face_key(std::span<const Index>(c.data(), c[3] == kInvalidIndex ? 3 : 4));
  };
  for (ElementKind kind : kElementKinds)
    for (std::size_t i = 0; i < element_count(model, kind); ++i) {
      const ElementRef e{kind, index_cast(i)};
      const auto cs = element_corners(model, e);
      if (!touches(cs)) continue;
      const auto& topo = cell_topology(kind);
      for (int f = 0; f < topo.faces; ++f) {
        const Cycle c = cycle(cs, topo.face[static_cast<std::size_t>(f)]);
        uses[key(c)].push_back({e, c});
      }
      for (std::size_t k = 0; k < cs.size(); ++k) {
        const auto u = index_cast<std::size_t>(cs[k]);
        // A tet's corners and a pyramid's apex may move; a pyramid's base (on a quad of a hex
        // or wedge, or of another pyramid), hexes and wedges stay.
        if (!(kind == ElementKind::kTet ||
              (kind == ElementKind::kPyramid && k == topology::kPyramidApex))) {
          fixed[u] = 1;
          continue;
        }
        star[u].push_back(e);
        const int b = block_of(model, e);
        block[u] = block[u] == 0 || block[u] == b ? b : -1;
      }
    }
  // Nodes on a face used once (the boundary; a quad covered by two triangles, as at a hex part's
  // interface with tets, is used once as well: its nodes stay), in a node set, or between blocks
  // stay.
  for (const auto& [k, list] : uses)
    if (list.size() == 1)
      for (Index v : k)
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

  // Elements turned over: each on the same side as every element it shares a face with,
  // counting the elements turned so far as turned (two neighbours turned together agree on their
  // face until one of them is turned back). Turned until none is left.
  std::array<std::vector<char>, kElementKinds.size()> turned_by_kind;
  for (ElementKind kind : kElementKinds)
    turned_by_kind[static_cast<std::size_t>(kind)].assign(element_count(model, kind), 0);
  const auto turned = [&](const ElementRef& e) -> char& {
    return turned_by_kind[static_cast<std::size_t>(e.kind)][index_cast<std::size_t>(e.index)];
  };
  const auto same_cycle = [](const Cycle& a, const Cycle& b) {
    const std::size_t n = a[3] == kInvalidIndex ? 3 : 4;
    for (std::size_t r = 0; r < n; ++r) {
      bool same = true;
      for (std::size_t i = 0; i < n && same; ++i) same = a[i] == b[(i + r) % n];
      if (same) return true;
    }
    return false;
  };
  // (faces e shares with another element, of them those on one side) as the elements stand now;
  // the elements on one side with e added to `with` if given.
  const auto sides = [&](const ElementRef& e, std::vector<ElementRef>* with = nullptr) {
    const auto cs = element_corners(model, e);
    const auto& topo = cell_topology(e.kind);
    std::pair<int, int> n{0, 0};
    for (int f = 0; f < topo.faces; ++f) {
      const Cycle mine = cycle(cs, topo.face[static_cast<std::size_t>(f)]);
      const auto found = uses.find(key(mine));
      if (found == uses.end() || found->second.size() != 2) continue;
      const auto& list = found->second;
      ++n.first;
      const Use& other = list[0].element == e ? list[1] : list[0];
      // Each side's cycle as it is now (a turned element's reversed), the same: one side.
      const bool other_turned = turned(other.element);
      const bool one_side = same_cycle(mine, other.cycle) != (other_turned != (turned(e) != 0));
      n.second += one_side;
      if (one_side && with) with->push_back(other.element);
    }
    return n;
  };
  // An element written twice (check_input found it on the same nodes as another) is no fold:
  // never turned (its faces with its twin alone looked like one).
  std::set<ElementRef> twice;
  for (const InputFinding& f : check.findings)
    if (f.fault == InputFault::kDuplicateElement)
      twice.insert(f.elements.begin(), f.elements.end());
  const auto written_twice = [&](const ElementRef& e) { return twice.count(e) > 0; };
  std::erase_if(work, written_twice);
  std::map<ElementRef, int> folds;  // the elements found, with their faces on one side
  for (const ElementRef& e : work) folds[e] = sides(e).second;
  // The elements on one side of the most faces first: a neighbour of a fold, on one side of its
  // one face with the fold, is not turned in its place (its nodes fixed, the whole mend given up).
  std::sort(work.begin(), work.end());
  work.erase(std::unique(work.begin(), work.end()), work.end());
  std::stable_sort(work.begin(), work.end(),
                   [&](const ElementRef& a, const ElementRef& b) { return folds[a] > folds[b]; });
  for (std::size_t round = 0; !work.empty() && round < 100; ++round) {
    std::vector<ElementRef> next;
    for (const ElementRef& e : work) {
      if (turned(e) || written_twice(e)) continue;
      const auto [shared, same] = sides(e);
      if (shared == 0 || same < shared) continue;
      turned(e) = 1;
      // Its neighbours may now be on its same side: looked at again.
      for (Index v : element_corners(model, e))
        for (const ElementRef& s : star[index_cast<std::size_t>(v)]) next.push_back(s);
    }
    std::sort(next.begin(), next.end());
    next.erase(std::unique(next.begin(), next.end()), next.end());
    work = std::move(next);
  }
  // Neighbours turned together (each on one side with all its faces but theirs): the elements
  // left with two or more such faces, joined through shared faces (three common corners), turned
  // as one where that leaves none of them on one side of any face.
  std::vector<ElementRef> left;
  for (const auto& [e, same] : folds)
    if (same >= 2 && !turned(e) && sides(e).second >= 2) left.push_back(e);
  std::set<ElementRef> seen;
  const auto common = [&](const ElementRef& a, const ElementRef& b) {
    const auto ca = element_corners(model, a), cb = element_corners(model, b);
    return std::count_if(ca.begin(), ca.end(),
                         [&](Index v) { return std::find(cb.begin(), cb.end(), v) != cb.end(); });
  };
  for (const ElementRef& start : left) {
    if (!seen.insert(start).second) continue;
    std::vector<ElementRef> group{start};
    for (std::size_t i = 0; i < group.size(); ++i)
      for (const ElementRef& e : left)
        if (!seen.count(e) && common(e, group[i]) >= 3) group.push_back(e), seen.insert(e);
    // Members on one side of a face with an element outside the turned group once it is turned
    // (a pyramid whose base, on a hex, turned with it) are turned back, all such at once, until
    // none is left; the group is kept where that leaves none of its members on one side.
    for (const ElementRef& e : group) turned(e) = 1;
    const auto in_group = [&](const ElementRef& o) {
      return turned(o) && std::find(group.begin(), group.end(), o) != group.end();
    };
    for (;;) {
      std::vector<ElementRef> back;
      for (const ElementRef& e : group) {
        std::vector<ElementRef> with;
        if (turned(e) && sides(e, &with).second != 0 &&
            !std::all_of(with.begin(), with.end(), in_group))
          back.push_back(e);
      }
      if (back.empty()) break;
      for (const ElementRef& e : back) turned(e) = 0;
    }
    if (!std::all_of(group.begin(), group.end(),
                     [&](const ElementRef& e) { return !turned(e) || sides(e).second == 0; }))
      for (const ElementRef& e : group) turned(e) = 0;
  }

  UnfoldResult result;
  std::vector<Point> from;  // where the moved nodes were
  // Unless every fold is mended, the model goes back as it was.
  const auto undo = [&] {
    for (const ElementRef& e : result.turned) turn(model, e);
    for (std::size_t i = result.moved.size(); i-- > 0;)  // the first place last
      model.points[index_cast<std::size_t>(result.moved[i])] = from[i];
    return none;
  };
  for (ElementKind kind : {ElementKind::kTet, ElementKind::kPyramid})
    for (std::size_t i = 0; i < element_count(model, kind); ++i) {
      const ElementRef e{kind, index_cast(i)};
      if (!turned(e)) continue;
      turn(model, e);  // as the geometry has it: inverted
      result.turned.push_back(e);
    }
  for (const ElementRef& e : inverted)
    if (!turned(e)) result.inverted.push_back(e);
  // The pieces of v's elements, each with v a corner (so volume_with can move it).
  const auto pieces_at = [&](Index v) {
    std::vector<Tet> all;
    for (const ElementRef& e : star[index_cast<std::size_t>(v)])
      for (const Tet& t : pieces(model, e)) all.push_back(t);
    return all;
  };
  const auto least = [&](const std::vector<Tet>& ts, Index v, const Point& x) {
    double d = 1e300;
    for (const Tet& t : ts) d = std::min(d, volume_with(model, t, v, x));
    return d;
  };
  std::vector<ElementRef> mend = result.turned;
  mend.insert(mend.end(), result.inverted.begin(), result.inverted.end());
  for (const ElementRef& e : mend) {
    const auto cs = element_corners(model, e);
    if (min_volume(model, pieces(model, e)) > 0.0) continue;  // put right by a turn or a move
    // Of its free nodes, the one whose elements come out the largest at its new place moves.
    Index node = kInvalidIndex;
    Point to = Point::Zero();
    double depth = 0.0;
    for (Index v : cs) {
      if (fixed[index_cast<std::size_t>(v)]) continue;
      const std::vector<Tet> around = pieces_at(v);
      Point x;
      if (!unfolded_position(model, v, around, x)) continue;
      const double d = least(around, v, x);
      if (d > depth) depth = d, node = v, to = x;
    }
    if (node == kInvalidIndex) return undo();
    Point& at = model.points[index_cast<std::size_t>(node)];
    result.farthest = std::max(result.farthest, (to - at).norm());
    from.push_back(at);
    result.moved.push_back(node);
    at = to;
  }
  if (!result.unfolded()) return undo();
  const InputCheckResult after = check_input(model, o);
  if (after.ok()) {
    result.covered_once = true;
    return result;
  }
  // Only faults unfold does not mend left, each found before it (an element written twice):
  // the mends stay, so that the caller's check names what is left rather than a fold mended.
  const auto found_before = [&](const InputFinding& f) {
    return f.fault != InputFault::kSameSideFace &&
           std::any_of(check.findings.begin(), check.findings.end(), [&](const InputFinding& g) {
             // A node's finding by its node (the element named among those around it may
             // change), the others by their elements.
             return g.fault == f.fault &&
                    (f.node != kInvalidIndex ? g.node == f.node : g.elements == f.elements);
           });
  };
  if (!std::all_of(after.findings.begin(), after.findings.end(), found_before)) return undo();
  return result;
}

std::string fold_hint(std::string_view option) {
  return " (a mesher's fold: " + std::string(option) +
         " turns such cells back, or mesh again at another size)";
}

std::string inverted_hint(std::string_view option) {
  return " (a mesher's fault: " + std::string(option) +
         " mends such cells where it can, or mesh again at another size)";
}

}  // namespace geode::primal
