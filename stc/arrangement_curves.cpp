#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/stc/detail/arrangement_engine.hpp>

namespace geode::stc::detail {

Point Engine::grid_node(int i, int j, int k) const {
  Point p = domain_.lo;
  const std::array<int, 3> ijk{i, j, k};
  for (int a = 0; a < dim_; ++a)
    p[a] = domain_.lo[a] + (domain_.hi[a] - domain_.lo[a]) *
                               ijk[primal::index_cast<std::size_t>(a)] /
                               n_[primal::index_cast<std::size_t>(a)];
  if (dim_ == 2) p[2] = 0.0;
  return p;
}

void Engine::sample_grid() {
  double longest = 0.0;
  for (int i = 0; i < dim_; ++i) longest = std::max(longest, domain_.hi[i] - domain_.lo[i]);
  n_ = {1, 1, 0};
  for (int i = 0; i < dim_; ++i)
    n_[primal::index_cast<std::size_t>(i)] =
        std::max(2, static_cast<int>(std::lround(options_.seed_resolution *
                                                 (domain_.hi[i] - domain_.lo[i]) / longest)));
  const std::size_t nn = primal::index_cast<std::size_t>((n_[0] + 1) * (n_[1] + 1) * (n_[2] + 1));
  grid_.assign(sheets_.size(), std::vector<double>(nn));
  for (int k = 0; k <= n_[2]; ++k)
    for (int j = 0; j <= n_[1]; ++j)
      for (int i = 0; i <= n_[0]; ++i) {
        const Point p = grid_node(i, j, k);
        for (std::size_t s = 0; s < sheets_.size(); ++s)
          grid_[s][grid_id(i, j, k)] = value(static_cast<int>(s), p);
      }
}

std::vector<Point> Engine::seeds(const std::vector<int>& S) const {
  // A grid cell where every field of S changes sign holds a piece of their meeting curve (or
  // comes close to one): project its centre onto the curve.
  std::vector<Point> out;
  const int kcells = dim_ == 3 ? n_[2] : 1;
  for (int k = 0; k < kcells; ++k)
    for (int j = 0; j < n_[1]; ++j)
      for (int i = 0; i < n_[0]; ++i) {
        bool all = true;
        for (std::size_t s = 0; s < S.size() && all; ++s) {
          const auto [lo, hi] = cell_span(S[s], i, j, k);
          all = lo <= 0.0 && hi >= 0.0;
        }
        if (!all) continue;
        Point c = 0.5 * (grid_node(i, j, dim_ == 3 ? k : 0) +
                         grid_node(i + 1, j + 1, dim_ == 3 ? k + 1 : 0));
        if (project(S, c) && inside(c)) out.push_back(c);
      }
  return out;
}

std::vector<Point> Engine::walk(const std::vector<int>& S, const Point& x0, Point t, bool& closed,
                                int& end_face) const {
  std::vector<Point> pts;
  Point x = x0;
  t.normalize();
  // The curve's tangent (gradient cross product, or the rotated gradient in 2D) keeps its
  // orientation along the curve between tangencies: walk with it, not by comparing with the
  // last step, so that a kink of more than 90 degrees (piecewise-smooth fields) is followed.
  const double sigma = tangent(S, x0).dot(t) < 0 ? -1.0 : 1.0;
  double travelled = 0.0;
  long steps = 0;
  closed = false;
  end_face = -1;
  while (true) {
    double hh = h_;
    Point xp;
    Point tn;
    while (true) {
      // A step: predict along t (or, at a kink, along the curve's direction just beyond x),
      // correct onto the curve, and accept when it moved forward by about the step length and
      // the new tangent agrees with the direction taken.
      auto attempt = [&](const Point& dir, bool at_kink) {
        xp = x + hh * dir;
        std::array<Point, 3> g;
        if (!project(S, xp, 0, &g) || (xp - x).norm() >= 2.0 * hh || (xp - x).dot(dir) < 0.25 * hh)
          return false;
        tn = sigma * tangent_of(g);
        if (tn.norm() < 1e-12) return false;
        const double transversal =
            !at_kink || dim_ == 2 ? 1.0 : tn.norm() / (g[0].norm() * g[1].norm());
        tn.normalize();
        return tn.dot(dir) > 0.9 && transversal > 0.05;
      };
      bool ok = attempt(t, false);
      // A smooth curve turns little over a step. One that still cannot be followed over a tiny
      // step, while its sheets stay transversal, has a kink (piecewise-smooth fields such as
      // stc/mesh_fields.hpp's, whose gradients jump across cell faces): continue along the
      // tangent found just past x. Tangent sheets (parallel gradients) still stall below.
      if (!ok && hh < 1e-3 * h_) {
        Point beyond = sigma * tangent(S, x + hh * t);
        if (beyond.norm() > 1e-12) ok = attempt(beyond.normalized(), true);
      }
      if (ok) break;
      hh *= 0.5;
      if (hh < 1e-5 * h_)
        throw TopologyError("arrangement: tracing the curve where sheets " + names(S) +
                            " meet stalls near " + fmt_point(x, dim_) +
                            ": the sheets are tangent there (not in general position)");
    }
    if (!inside(xp)) {
      // Leave through the face crossed first; solve the curve and that face exactly.
      int axis = -1;
      bool high = false;
      double best = 2.0;
      for (int a = 0; a < dim_; ++a) {
        for (int side = 0; side < 2; ++side) {
          const double b = side ? domain_.hi[a] : domain_.lo[a];
          const bool out = side ? xp[a] > b : xp[a] < b;
          if (!out) continue;
          const double f = (b - x[a]) / (xp[a] - x[a]);
          if (f < best) best = f, axis = a, high = side == 1;
        }
      }
      assert(axis >= 0);
      Point y = x + best * (xp - x);
      y[axis] = high ? domain_.hi[axis] : domain_.lo[axis];
      if (!project(S, y, 1u << axis) || !inside(y, 1e-9 * diag_))
        throw TopologyError("arrangement: the curve where sheets " + names(S) +
                            " meet leaves the domain near " + fmt_point(xp, dim_) +
                            " where it cannot be followed (it grazes the boundary)");
      for (int a = 0; a < dim_; ++a) {
        if (a == axis) continue;
        if (std::min(std::abs(y[a] - domain_.lo[a]), std::abs(y[a] - domain_.hi[a])) < 1e-6 * diag_)
          throw TopologyError("arrangement: the curve where sheets " + names(S) +
                              " meet leaves the domain through " +
                              std::string(dim_ == 3 ? "an edge" : "a corner") + " of the box at " +
                              fmt_point(y, dim_) + " (not in general position)");
      }
      end_face = box_face(axis, high);
      pts.push_back(y);
      return pts;
    }
    // Closing a loop: the step passes next to the start.
    if (travelled > 4.0 * h_) {
      const Point d = xp - x;
      const double s = std::clamp((x0 - x).dot(d) / d.squaredNorm(), 0.0, 1.0);
      if ((x + s * d - x0).norm() < 0.5 * h_) {
        closed = true;
        return pts;
      }
    }
    travelled += (xp - x).norm();
    // A curve longer than many domain diagonals, or one that needs far more steps than its
    // length asks for, is hopping between branches near a tangency: report, do not spin.
    if (travelled > 20.0 * diag_ || ++steps > 40 * static_cast<long>(20.0 * diag_ / h_))
      throw TopologyError("arrangement: the curve where sheets " + names(S) +
                          " meet does not close or end (near " + fmt_point(xp, dim_) + ")");
    pts.push_back(xp);
    x = xp;
    t = tn;
  }
}

Curve Engine::trace(const std::vector<int>& S, const Point& x0) const {
  Curve c;
  c.sheets = S;
  // Two surfaces that only touch have an isolated common point where the projection of a
  // seed may land: no curve to trace, and their gradients are parallel there.
  std::array<Point, 3> g;
  for (std::size_t r = 0; r < S.size(); ++r) g[r] = grad(S[r], x0);
  if (dim_ == 3 && sine(g[0], g[1]) < kParallel)
    throw TopologyError("arrangement: sheets " + names(S) + " touch at " + fmt_point(x0, dim_) +
                        " without crossing (tangent there; not in general position)");
  const Point t0 = tangent_of(g).normalized();
  bool closed = false;
  int face_f = -1, face_b = -1;
  std::vector<Point> fwd = walk(S, x0, t0, closed, face_f);
  if (closed) {
    c.closed = true;
    c.polyline.push_back(x0);
    c.polyline.insert(c.polyline.end(), fwd.begin(), fwd.end());
    return c;
  }
  std::vector<Point> bwd = walk(S, x0, -t0, closed, face_b);
  c.polyline.assign(bwd.rbegin(), bwd.rend());
  c.polyline.push_back(x0);
  c.polyline.insert(c.polyline.end(), fwd.begin(), fwd.end());
  c.end_faces = {face_b, face_f};
  return c;
}

std::vector<Event> Engine::events(const Curve& c) const {
  std::vector<Event> out;
  const auto& P = c.polyline;
  const std::size_t n = P.size();
  const std::size_t segs = c.closed ? n : n - 1;
  for (int s = 0; s < primal::index_cast<int>(sheets_.size()); ++s) {
    if (std::find(c.sheets.begin(), c.sheets.end(), s) != c.sheets.end()) continue;
    std::vector<int> T = c.sheets;
    T.push_back(s);
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = value(s, P[i]);
    // Where the sheet comes close without a sign change, the point of the curve nearest to
    // it: if the d sheets have a common point there that is not a crossing found below, the
    // curve touches the sheet (a tangency away from any vertex of theirs).
    std::vector<Point> touch;
    for (std::size_t i = 0; i < segs; ++i) {
      const std::size_t j = (i + 1) % n;
      // Sub-sample a segment where the sheet comes close without a sign change: it may cross
      // twice within one step.
      std::vector<std::pair<double, Point>> sub{{0.0, P[i]}, {1.0, P[j]}};
      if ((v[i] < 0) == (v[j] < 0) && std::min(std::abs(v[i]), std::abs(v[j])) <
                                          2.0 * grad(s, P[i]).norm() * (P[j] - P[i]).norm()) {
        sub.clear();
        for (int q = 0; q <= 16; ++q) {
          Point y = P[i] + (q / 16.0) * (P[j] - P[i]);
          if (q != 0 && q != 16) project(c.sheets, y);
          sub.emplace_back(q / 16.0, y);
        }
      }
      std::vector<double> sv(sub.size());
      for (std::size_t q = 0; q < sub.size(); ++q) sv[q] = value(s, sub[q].second);
      if (sub.size() > 2) {
        // A touching point lies within half a sub-step of a sub-sample, where the field is
        // then far below its gradient times a sub-step; a near miss farther away is not tried.
        std::size_t best = 0;
        bool change = false;
        for (std::size_t q = 0; q < sub.size(); ++q) {
          if (std::abs(sv[q]) < std::abs(sv[best])) best = q;
          change = change || (sv[q] < 0) != (sv[0] < 0);
        }
        Point y = sub[best].second;
        const double substep = (P[j] - P[i]).norm() / 16.0;
        if (!change && std::abs(sv[best]) < grad(s, y).norm() * substep && project(T, y) &&
            (y - sub[best].second).norm() < 16.0 * substep)
          touch.push_back(y);
      }
      for (std::size_t q = 0; q + 1 < sub.size(); ++q) {
        const double a = sv[q], b = sv[q + 1];
        if ((a < 0) == (b < 0)) continue;
        const double f = a / (a - b);
        Point x = sub[q].second + f * (sub[q + 1].second - sub[q].second);
        if (!project(T, x))
          throw TopologyError("arrangement: sheets " + names(T) + " cross near " +
                              fmt_point(x, dim_) +
                              " but their meeting point cannot be solved (tangency?)");
        out.push_back(
            {static_cast<double>(i) + sub[q].first + f * (sub[q + 1].first - sub[q].first), s, x});
      }
    }
    for (const Point& y : touch) {
      bool crossing = false;
      for (const Event& e : out)
        crossing = crossing || (e.sheet == s && (e.x - y).norm() < 1e-6 * diag_);
      if (!crossing)
        throw TopologyError("arrangement: the curve where sheets " + names(c.sheets) +
                            " meet touches sheet " + name(s) + " at " + fmt_point(y, dim_) +
                            " without crossing it (tangent there; not in general position)");
    }
  }
  std::sort(out.begin(), out.end(),
            [](const Event& a, const Event& b) { return a.param < b.param; });
  return out;
}

// Levenberg-Marquardt on the two equations, each scaled by its gradient so that residuals are
// distances: from x, look for a point where both vanish. Returns true with x there, false at
// a local minimum of the residual that is not a common zero (a near miss) or when the search
// leaves the domain. Near a touching point the system is singular and convergence only
// linear, but the residual falls as the square of the distance: a few dozen steps suffice.

}  // namespace geode::stc::detail
