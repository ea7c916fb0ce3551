#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/stc/detail/arrangement_engine.hpp>

namespace geode::stc::detail {

bool Engine::common_zero(const Equation& a, const Equation& b, Point& x) const {
  const double zero = 1e-9 * diag_;
  double mu = 1e-3;
  for (int it = 0; it < 60; ++it) {
    const Point ga = eval_grad(a, x), gb = eval_grad(b, x);
    const double na = ga.norm(), nb = gb.norm();
    if (!(na > 1e-300 && nb > 1e-300)) return false;
    const Eigen::Vector2d r(eval(a, x) / na, eval(b, x) / nb);
    if (r.cwiseAbs().maxCoeff() < zero) return true;
    Eigen::Matrix<double, 2, 3> J;
    J.row(0) = (ga / na).transpose();
    J.row(1) = (gb / nb).transpose();
    if (dim_ == 2) J.col(2).setZero();
    const Eigen::Matrix2d JJt = J * J.transpose();
    bool accepted = false;
    while (!accepted && mu < 1e8) {
      const Eigen::Vector2d w = (JJt + mu * Eigen::Matrix2d::Identity()).ldlt().solve(r);
      const Point y = x - J.transpose() * w;
      const Eigen::Vector2d ry(eval(a, y) / na, eval(b, y) / nb);
      if (ry.allFinite() && ry.squaredNorm() < r.squaredNorm()) {
        x = y;
        mu = std::max(mu / 3.0, 1e-12);
        accepted = true;
      } else {
        mu *= 4.0;
      }
    }
    if (!accepted || !inside(x, 0.1 * diag_)) return false;
  }
  return false;
}

// A piece of a sheet on which no curve was traced (3D) meets no other sheet: it holds no vertex,
// so no dual element, and the dual would silently lack it (a whole sheet, or a second piece of
// one whose first piece crosses the others). The pieces are the sheet's cells of the seeding
// grid (its field changing sign over the cell's corners) joined through faces, edges and
// corners; a piece is met when a curve of the sheet passes within one cell of it. Like the
// seeds, this takes the grid to resolve the sheet: a fold thinner than a cell could cut a piece
// in two there (see the resolution limits in arrangement.hpp). (In 2D the curve is the sheet
// itself, refused later when no other sheet crosses it.)
void Engine::check_lone_pieces(const std::vector<Curve>& curves) const {
  if (dim_ != 3) return;
  const int ncell = cell_count();
  const int m = primal::index_cast<int>(sheets_.size());
  std::vector<int> piece(primal::index_cast<std::size_t>(ncell));
  std::vector<char> met;
  std::vector<int> stack;
  for (int s = 0; s < m; ++s) {
    // -1: the sheet does not cross the cell; -2: it does, the piece not known yet; else its
    // piece.
    for (int k = 0; k < n_[2]; ++k)
      for (int j = 0; j < n_[1]; ++j)
        for (int i = 0; i < n_[0]; ++i) {
          const auto [lo, hi] = cell_span(s, i, j, k);
          piece[primal::index_cast<std::size_t>(cell_id(i, j, k))] =
              lo <= 0.0 && hi >= 0.0 ? -2 : -1;
        }
    int pieces = 0;
    for (int start = 0; start < ncell; ++start) {
      if (piece[primal::index_cast<std::size_t>(start)] != -2) continue;
      piece[primal::index_cast<std::size_t>(start)] = pieces;
      stack.assign(1, start);
      while (!stack.empty()) {
        const int id = stack.back();
        stack.pop_back();
        const int i = id % n_[0], j = (id / n_[0]) % n_[1], k = id / (n_[0] * n_[1]);
        for (int c = std::max(0, k - 1); c <= std::min(n_[2] - 1, k + 1); ++c)
          for (int b = std::max(0, j - 1); b <= std::min(n_[1] - 1, j + 1); ++b)
            for (int a = std::max(0, i - 1); a <= std::min(n_[0] - 1, i + 1); ++a) {
              int& p = piece[primal::index_cast<std::size_t>(cell_id(a, b, c))];
              if (p != -2) continue;
              p = pieces;
              stack.push_back(cell_id(a, b, c));
            }
      }
      ++pieces;
    }
    // The pieces a curve of the sheet passes within one cell of.
    met.assign(primal::index_cast<std::size_t>(pieces), 0);
    for (const Curve& curve : curves) {
      if (std::find(curve.sheets.begin(), curve.sheets.end(), s) == curve.sheets.end()) continue;
      for (const Point& x : curve.polyline) {
        const auto cell = cell_of(x);
        for (int c = std::max(0, cell[2] - 1); c <= std::min(n_[2] - 1, cell[2] + 1); ++c)
          for (int b = std::max(0, cell[1] - 1); b <= std::min(n_[1] - 1, cell[1] + 1); ++b)
            for (int a = std::max(0, cell[0] - 1); a <= std::min(n_[0] - 1, cell[0] + 1); ++a)
              if (const int p = piece[primal::index_cast<std::size_t>(cell_id(a, b, c))]; p >= 0)
                met[primal::index_cast<std::size_t>(p)] = 1;
      }
    }
    // An unmet piece inside the domain: a point of it, as seeds() finds one (a cell's centre
    // projected onto the sheet).
    for (int id = 0; id < ncell; ++id) {
      const int p = piece[primal::index_cast<std::size_t>(id)];
      if (p < 0 || met[primal::index_cast<std::size_t>(p)]) continue;
      const int i = id % n_[0], j = (id / n_[0]) % n_[1], k = id / (n_[0] * n_[1]);
      Point x = 0.5 * (grid_node(i, j, k) + grid_node(i + 1, j + 1, k + 1));
      if (!project({s}, x) || !inside(x)) continue;
      const bool any = std::any_of(curves.begin(), curves.end(), [s](const Curve& c) {
        return std::find(c.sheets.begin(), c.sheets.end(), s) != c.sheets.end();
      });
      throw TopologyError("arrangement: sheet " + name(s) + " passes through " +
                          fmt_point(x, dim_) + " but " +
                          (any ? "that piece of it meets" : "meets") +
                          " no other sheet inside the domain: a sheet piece with no vertex has "
                          "no dual element");
    }
  }
}

// Sheets that touch without crossing leave no curve (3D) or no vertex (2D) behind, and a sheet
// that touches the domain boundary no trace on it: nothing else notices them. Look where the
// seeding grid says two zero sets come within about a cell of each other with nearly parallel
// gradients, away from the curves already traced for that pair (vertices in 2D), and solve
// for a common zero there. See the resolution limits in arrangement.hpp.
void Engine::check_touching(const std::vector<Curve>& curves) const {
  const int kcells = dim_ == 3 ? n_[2] : 1;
  const int corners = dim_ == 3 ? 8 : 4;
  const int ncell = cell_count();
  const int m = primal::index_cast<int>(sheets_.size());
  std::array<double, 3> step{};
  for (int a = 0; a < dim_; ++a)
    step[primal::index_cast<std::size_t>(a)] =
        (domain_.hi[a] - domain_.lo[a]) / n_[primal::index_cast<std::size_t>(a)];
  auto corner_id = [&](int i, int j, int k, int c) {
    return grid_id(i + (c & 1), j + ((c >> 1) & 1), dim_ == 3 ? k + ((c >> 2) & 1) : 0);
  };
  // Per sheet and cell: is the zero set within about one cell (the smallest corner value no
  // larger than the spread over the corners, which for a linear field is the gradient times
  // the cell's extent along it).
  std::vector<std::vector<char>> near(primal::index_cast<std::size_t>(m),
                                      std::vector<char>(primal::index_cast<std::size_t>(ncell), 0));
  for (int s = 0; s < m; ++s) {
    const auto& val = grid_[primal::index_cast<std::size_t>(s)];
    for (int k = 0; k < kcells; ++k)
      for (int j = 0; j < n_[1]; ++j)
        for (int i = 0; i < n_[0]; ++i) {
          double lo = 1e300, hi = -1e300, least = 1e300;
          for (int c = 0; c < corners; ++c) {
            const double v = val[corner_id(i, j, k, c)];
            lo = std::min(lo, v), hi = std::max(hi, v), least = std::min(least, std::abs(v));
          }
          near[primal::index_cast<std::size_t>(s)]
              [primal::index_cast<std::size_t>(cell_id(i, j, k))] = least <= hi - lo;
        }
  }
  // The field's gradient in a cell, estimated from its corners.
  auto slope = [&](int s, int id) {
    const int i = id % n_[0], j = (id / n_[0]) % n_[1], k = id / (n_[0] * n_[1]);
    const auto& val = grid_[primal::index_cast<std::size_t>(s)];
    Point g = Point::Zero();
    for (int c = 0; c < corners; ++c) {
      const double v = val[corner_id(i, j, k, c)];
      for (int a = 0; a < dim_; ++a)
        g[a] +=
            ((c >> a) & 1 ? v : -v) / (step[primal::index_cast<std::size_t>(a)] * (corners / 2));
    }
    return g;
  };
  auto centre = [&](int id) {
    const int i = id % n_[0], j = (id / n_[0]) % n_[1], k = id / (n_[0] * n_[1]);
    return Point(0.5 * (grid_node(i, j, k) + grid_node(i + 1, j + 1, dim_ == 3 ? k + 1 : 0)));
  };
  // Cells within `r` cells of x; consecutive calls from the same cell are skipped (a polyline
  // has many points per cell).
  std::array<int, 3> last{-1, -1, -1};
  auto mark = [&](std::vector<char>& covered, const Point& x, int r) {
    const auto c = cell_of(x);
    if (c == last) return;
    last = c;
    for (int k = std::max(0, c[2] - r); k <= std::min(kcells - 1, c[2] + r); ++k)
      for (int j = std::max(0, c[1] - r); j <= std::min(n_[1] - 1, c[1] + r); ++j)
        for (int i = std::max(0, c[0] - r); i <= std::min(n_[0] - 1, c[0] + r); ++i)
          covered[primal::index_cast<std::size_t>(cell_id(i, j, k))] = 1;
  };

  // Pairs of sheets. A common zero with parallel gradients is a touching point; one with
  // crossing gradients must lie on a traced curve (3D) or be a vertex (2D), else a piece of
  // the arrangement smaller than the seeding grid was missed.
  std::vector<char> covered(primal::index_cast<std::size_t>(ncell));
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b) {
      const std::vector<int> S{a, b};
      std::fill(covered.begin(), covered.end(), 0);
      last = {-1, -1, -1};
      std::vector<const Curve*> mine;
      std::vector<Point> crossings;
      if (dim_ == 3) {
        for (const Curve& c : curves)
          if (c.sheets == S) {
            mine.push_back(&c);
            for (const Point& p : c.polyline) mark(covered, p, 2);
          }
      } else {
        for (const Vertex& v : vertices_)
          if (v.sheets == S) {
            crossings.push_back(v.x);
            mark(covered, v.x, 2);
          }
      }
      for (int id = 0; id < ncell; ++id) {
        const auto I = primal::index_cast<std::size_t>(id);
        if (covered[I] || !near[primal::index_cast<std::size_t>(a)][I] ||
            !near[primal::index_cast<std::size_t>(b)][I])
          continue;
        // Zero sets crossing at more than 45 degrees here: a crossing, not a touching.
        const Point ga = slope(a, id), gb = slope(b, id);
        if (ga.norm() > 0 && gb.norm() > 0 && sine(ga, gb) > 0.7) continue;
        covered[I] = 1;
        Point x = centre(id);
        const bool zero = common_zero({a}, {b}, x);
        last = {-1, -1, -1};
        if (inside(x)) mark(covered, x, 1);  // later starts nearby would end there too
        if (!zero || !inside(x)) continue;
        if (sine(grad(a, x), grad(b, x)) < kParallel)
          throw TopologyError("arrangement: sheets " + names(S) + " touch at " +
                              fmt_point(x, dim_) +
                              " without crossing (tangent there; not in general position)");
        double best = 1e300;
        for (const Curve* c : mine)
          for (const Point& p : c->polyline) best = std::min(best, (p - x).norm());
        for (const Point& p : crossings) best = std::min(best, (p - x).norm());
        if (best > (dim_ == 3 ? 2.0 * h_ : 1e-6 * diag_))
          throw TopologyError(
              "arrangement: sheets " + names(S) + " meet at " + fmt_point(x, dim_) + " but no " +
              (dim_ == 3 ? "curve traced for them passes there" : "vertex was found there") +
              ": a piece smaller than the seeding grid was missed (raise the seed resolution: "
              "geode arrange --seed-resolution)");
      }
    }

  // A sheet and a domain face: a common zero where the sheet's gradient is normal to the face
  // is a touching point. There the field restricted to the face has an extremum near zero:
  // start from every face node of the grid whose value is the smallest in size among its
  // neighbours on the face, all of the same sign, and within a grid step of zero by their
  // differences. A trace crossing the face has a sign change next to it and starts nothing.
  for (int axis = 0; axis < dim_; ++axis)
    for (int high = 0; high < 2; ++high) {
      const Equation face{-1, axis, high ? domain_.hi[axis] : domain_.lo[axis]};
      std::array<int, 3> top{n_[0], n_[1], dim_ == 3 ? n_[2] : 0};
      const auto A = primal::index_cast<std::size_t>(axis);
      for (int s = 0; s < m; ++s) {
        const auto& val = grid_[primal::index_cast<std::size_t>(s)];
        std::array<int, 3> p{0, 0, 0}, from{0, 0, 0}, to = top;
        from[A] = to[A] = high ? top[A] : 0;
        for (p[2] = from[2]; p[2] <= to[2]; ++p[2])
          for (p[1] = from[1]; p[1] <= to[1]; ++p[1])
            for (p[0] = from[0]; p[0] <= to[0]; ++p[0]) {
              const double v = val[grid_id(p[0], p[1], p[2])];
              bool extremum = true;
              double spread = 0.0;
              int sign = v < 0   ? -1
                         : v > 0 ? 1
                                 : 0;  // of the node, or of its first nonzero neighbour
              for (int d = 0; d < 27 && extremum; ++d) {
                std::array<int, 3> q{p[0] + d % 3 - 1, p[1] + (d / 3) % 3 - 1, p[2] + d / 9 - 1};
                if (q[A] != p[A] || q == p) continue;
                bool in = true;
                for (std::size_t a = 0; a < 3; ++a) in = in && q[a] >= 0 && q[a] <= top[a];
                if (!in) continue;
                const double w = val[grid_id(q[0], q[1], q[2])];
                const int sw = w < 0 ? -1 : w > 0 ? 1 : 0;
                if (sign == 0) sign = sw;
                extremum = (sw == 0 || sw == sign) && std::abs(v) <= std::abs(w);
                spread = std::max(spread, std::abs(w - v));
              }
              if (!extremum || std::abs(v) > spread) continue;
              Point x = grid_node(p[0], p[1], p[2]);
              // On the face only to the solver's tolerance: allow for that, not more.
              if (!common_zero({s}, face, x) || !inside(x, 1e-6 * diag_)) continue;
              if (sine(grad(s, x), Point::Unit(axis)) < kParallel)
                throw TopologyError(
                    "arrangement: sheet " + name(s) + " touches the domain boundary (face " +
                    std::to_string(box_face(axis, high == 1)) + ") at " + fmt_point(x, dim_) +
                    " without crossing it (tangent to it; not in general position)");
            }
      }
    }
}

void Engine::check_apex() const {
  if (!user_.is_pyramid) return;
  const Point apex = (*user_.corners)[4];
  for (int s = 0; s < primal::index_cast<int>(sheets_.size()); ++s) {
    // In physical space (the composed field's gradient vanishes at the apex).
    const Field& f = given_[primal::index_cast<std::size_t>(s)].field;
    const double g = gradient(f, apex, grad_h_, dim_).norm();
    if (std::abs(f(apex)) < 1e-6 * diag_ * std::max(g, 1e-300))
      throw TopologyError("arrangement: sheet " + name(s) + " passes through the pyramid's apex " +
                          format_point(apex, dim_) +
                          " (its curves would end in one point; not in general position)");
  }
}

}  // namespace geode::stc::detail
