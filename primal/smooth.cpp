#include <geode/primal/smooth.hpp>

#include <tbb/task_group.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <string>

#include <geode/primal/detail/smooth_frames.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/frame_derivatives.hpp>
#include <geode/primal/quality.hpp>

namespace geode::primal {

namespace {

using Vec = Eigen::VectorXd;

// One column of a corner matrix: a linear combination of node positions plus a constant
// (quads use the fixed unit normal as third column, so that (a x b) . n = det[a, b, n]).
struct Column {
  int terms = 0;
  std::array<Index, 8> node{};
  std::array<double, 8> coef{};
  Point constant = Point::Zero();
};

struct Frame {
  std::array<Column, 3> col;
  double det_scale = 1.0;  // Jacobian = det * det_scale (1/64 at a hex centre)
  // 0: a scaled-Jacobian frame. 3 or 2: a guard frame, see SmoothOptions::shape_guard: in the
  // shape phase its value is the Verdict corner shape (3D: 3 det^(2/3) / |A|_F^2; 2D:
  // 2 det / (|a|^2 + |b|^2)) divided by the guard factor.
  int guard = 0;
};

Column difference(Index to, Index from) {
  Column c;
  c.terms = 2;
  c.node[0] = to, c.coef[0] = 1.0;
  c.node[1] = from, c.coef[1] = -1.0;
  return c;
}

std::vector<Frame> hex_frames(const HexMesh& mesh) {
  const auto& shapes = detail::hex_frame_shapes();
  std::vector<Frame> frames;
  frames.reserve(mesh.hexes.size() * 17);
  for (const auto& h : mesh.hexes) {
    for (const detail::HexFrameShape& shape : shapes) {
      Frame f;
      f.det_scale = shape.det_scale;
      for (int i = 0; i < 3; ++i) {
        Column& c = f.col[i];
        for (int k = 0; k < shape.nodes; ++k) {
          if (shape.coef[i][k] == 0.0) continue;
          c.node[c.terms] = h[shape.corner[k]], c.coef[c.terms] = shape.coef[i][k];
          ++c.terms;
        }
      }
      frames.push_back(f);
    }
    for (int c = 0; c < 8; ++c) {
      Frame g = frames[frames.size() - 9 + c];
      g.guard = 3;
      frames.push_back(g);
    }
  }
  return frames;
}

std::vector<Frame> quad_frames(const QuadMesh& mesh, const Point& unit_normal) {
  std::vector<Frame> frames;
  frames.reserve(mesh.quads.size() * 4);
  for (const auto& q : mesh.quads) {
    for (int c = 0; c < 4; ++c) {
      Frame f;
      f.col[0] = difference(q[(c + 1) % 4], q[c]);
      f.col[1] = difference(q[(c + 3) % 4], q[c]);
      f.col[2].constant = unit_normal;
      frames.push_back(f);
      f.guard = 2;
      frames.push_back(f);
    }
  }
  return frames;
}

// Each node moves as p = base + B u with B a 3 x dof orthonormal basis.
struct NodeSpace {
  Point base;
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3> basis;
  int offset = 0;
};

std::string node_name(std::size_t i) { return "node " + std::to_string(i); }

std::vector<NodeSpace> node_spaces(const std::vector<Point>& points,
                                   std::span<const NodeConstraint> constraints,
                                   const Point* plane_normal, std::span<const NodeLink> links) {
  if (!constraints.empty() && constraints.size() != points.size()) {
    throw InvalidInput("smooth: " + std::to_string(constraints.size()) + " constraints for " +
                       std::to_string(points.size()) + " nodes");
  }
  std::vector<NodeSpace> spaces(points.size());
  int offset = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) throw InvalidInput("smooth: " + node_name(i) + " is not finite");
    const NodeConstraint c = constraints.empty() ? NodeConstraint::free() : constraints[i];
    if (c.kind != NodeConstraint::Kind::kFree && c.kind != NodeConstraint::Kind::kFixed &&
        !(c.direction.norm() > 0.0 && c.direction.allFinite() && c.origin.allFinite())) {
      throw InvalidInput("smooth: " + node_name(i) + " has a plane or line constraint with a " +
                         "zero or non-finite direction");
    }
    NodeSpace& s = spaces[i];
    s.base = points[i];
    std::vector<Point> dirs;
    switch (c.kind) {
      case NodeConstraint::Kind::kFixed:
        break;
      case NodeConstraint::Kind::kFree:
        if (plane_normal) {
          const auto t = detail::plane_tangents(*plane_normal);
          dirs = {t[0], t[1]};
        } else {
          dirs = {Point::UnitX(), Point::UnitY(), Point::UnitZ()};
        }
        break;
      case NodeConstraint::Kind::kPlane:
      case NodeConstraint::Kind::kSurface: {
        const Point n = c.direction.normalized();
        s.base = detail::project_to_plane(s.base, c.origin, n);
        if (plane_normal && n.cross(*plane_normal).norm() > 1e-12) {
          dirs = {n.cross(*plane_normal).normalized()};  // the line where the planes meet
        } else {
          // The mesh plane itself (same normal) or, for a hex mesh, the plane.
          const auto t = detail::plane_tangents(plane_normal ? *plane_normal : n);
          dirs = {t[0], t[1]};
        }
        break;
      }
      case NodeConstraint::Kind::kLine: {
        const Point d = c.direction.normalized();
        s.base = detail::project_to_line(s.base, c.origin, d);
        if (!plane_normal || std::abs(d.dot(*plane_normal)) < 1e-12) dirs = {d};
        break;
      }
    }
    s.basis.resize(3, static_cast<Eigen::Index>(dirs.size()));
    for (std::size_t k = 0; k < dirs.size(); ++k)
      s.basis.col(static_cast<Eigen::Index>(k)) = dirs[k];
  }
  // Followers take their leader's coordinates through the link's map; the others get their own.
  std::vector<char> follows(points.size(), 0);
  for (const NodeLink& l : links) {
    // The signs first: index_cast asserts that what it converts fits.
    if (l.node < 0 || l.leader < 0 || index_cast<std::size_t>(l.node) >= points.size() ||
        index_cast<std::size_t>(l.leader) >= points.size() || l.node == l.leader ||
        !l.map.allFinite())
      throw InvalidInput("smooth: a node link names node " + std::to_string(l.node) +
                         " and leader " + std::to_string(l.leader) + " (" +
                         std::to_string(points.size()) + " nodes)");
    follows[index_cast<std::size_t>(l.node)] = 1;
  }
  for (const NodeLink& l : links)
    if (follows[index_cast<std::size_t>(l.leader)])
      throw InvalidInput("smooth: " + node_name(index_cast<std::size_t>(l.leader)) +
                         " leads a link but follows another");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (follows[i]) continue;
    spaces[i].offset = offset;
    offset += index_cast<int>(spaces[i].basis.cols());
  }
  for (const NodeLink& l : links) {
    NodeSpace& s = spaces[index_cast<std::size_t>(l.node)];
    const NodeSpace& lead = spaces[index_cast<std::size_t>(l.leader)];
    s.base = points[index_cast<std::size_t>(l.node)];
    s.basis = l.map * lead.basis;
    s.offset = lead.offset;
  }
  return spaces;
}

// What a frame measures: its Jacobian det * scale (untangling) or, in the shape phase, its
// scaled Jacobian (or, for a guard frame, its corner shape / guard factor).
enum class Measure { kJacobian, kShape };

// Value of a corner matrix [v0, v1, v2]; with grad (hess), also its first (second) derivatives
// with respect to the 9 column entries (primal/frame_derivatives.hpp). `scale` multiplies a
// Jacobian and divides a guard frame's shape.
double column_value(const FrameVector& v, Measure measure, int guard, double scale,
                    FrameVector* grad, FrameMatrix* hess = nullptr) {
  if (measure == Measure::kShape && guard == 0)
    return scaled_determinant_derivatives(v, grad, hess);
  const double factor = measure == Measure::kJacobian ? scale : 1.0 / scale;
  const double q = measure == Measure::kJacobian ? determinant_derivatives(v, grad, hess)
                                                 : corner_shape_derivatives(v, guard, grad, hess);
  if (grad) *grad *= factor;
  if (hess) *hess *= factor;
  return q * factor;
}

// The problem in reduced coordinates u (the free coordinates of every node, NodeSpace). Each
// frame's columns are an affine function of the few u it touches: v = v0 + M u_local.
class Problem {
 public:
  // unit: Jacobians are divided by it; guard: the guard factor (guard frames are left out
  // when it is 0).
  Problem(const std::vector<Frame>& frames, std::vector<NodeSpace> spaces, double unit,
          double guard)
      : spaces_(std::move(spaces)), unit_(unit), guard_(guard) {
    for (const auto& s : spaces_) dof_ = std::max(dof_, s.offset + index_cast<int>(s.basis.cols()));
    for (const Frame& f : frames) {
      if (f.guard != 0 && !(guard > 0.0)) continue;
      Local l;
      l.det_scale = f.det_scale;
      l.guard = f.guard;
      l.v0.setZero();
      std::vector<FrameVector> cols;
      for (int j = 0; j < 3; ++j) {
        const Column& c = f.col[j];
        l.v0.segment<3>(3 * j) += c.constant;
        for (int t = 0; t < c.terms; ++t) {
          const NodeSpace& s = spaces_[c.node[t]];
          l.v0.segment<3>(3 * j) += c.coef[t] * s.base;
          for (int k = 0; k < s.basis.cols(); ++k) {
            const int dof = s.offset + k;
            auto it = std::find(l.idx.begin(), l.idx.end(), dof);
            const auto col = index_cast<std::size_t>(it - l.idx.begin());
            if (it == l.idx.end()) {
              l.idx.push_back(dof);
              cols.push_back(FrameVector::Zero());
            }
            cols[col].segment<3>(3 * j) += c.coef[t] * s.basis.col(k);
          }
        }
      }
      l.map.resize(9, static_cast<Eigen::Index>(cols.size()));
      for (std::size_t k = 0; k < cols.size(); ++k)
        l.map.col(static_cast<Eigen::Index>(k)) = cols[k];
      locals_.push_back(std::move(l));
    }
  }

  int dof() const { return dof_; }

  void positions(const Vec& x, std::vector<Point>& out) const {
    out.resize(spaces_.size());
    for (std::size_t i = 0; i < spaces_.size(); ++i) {
      const auto& s = spaces_[i];
      out[i] = s.base;
      if (s.basis.cols() > 0) out[i] += s.basis * x.segment(s.offset, s.basis.cols());
    }
  }

  // Values of every non-guard frame: scaled Jacobian (kShape) or Jacobian / unit.
  void values(const Vec& x, Measure m, std::vector<double>& q) const {
    q.clear();
    for (std::size_t k = 0; k < locals_.size(); ++k) {
      if (locals_[k].guard != 0) continue;
      q.push_back(column_value(columns(k, x), m, 0, scale_of(locals_[k], m), nullptr));
    }
  }

  // Soft minimum of the frame values. With grad (and hess), the gradient (and Hessian) of its
  // negative, the function we minimise:
  //   grad f = -sum w_k g_k,  hess f = -sum w_k H_k + t (sum w_k g_k g_k^T - gbar gbar^T)
  // with w the softmax weights, g_k, H_k the derivatives of q_k, gbar = sum w_k g_k (H_k the
  // analytic 9 x 9 Hessian of the frame's columns, then mapped by M).
  double soft_min(const Vec& x, Measure m, double t, Vec* grad, Eigen::MatrixXd* hess = nullptr) {
    const std::size_t n = locals_.size();
    q_.resize(n);
    if (grad) dq_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const Local& l = locals_[k];
      // Untangling looks at Jacobians only: a guard frame repeats its corner there. Line-search
      // evaluations (no grad) need the values only.
      q_[k] = column_value(columns(k, x), m, m == Measure::kJacobian ? 0 : l.guard, scale_of(l, m),
                           grad ? &dq_[k] : nullptr);
    }
    const double qmin = *std::min_element(q_.begin(), q_.end());
    double sum = 0.0;
    w_.resize(n);
    for (std::size_t k = 0; k < n; ++k) sum += (w_[k] = std::exp(-t * (q_[k] - qmin)));
    const double value = qmin - std::log(sum) / t;
    if (!grad) return value;
    grad->setZero(dof_);
    if (hess) hess->setZero(dof_, dof_);
    for (std::size_t k = 0; k < n; ++k) {
      const double w = w_[k] / sum;
      if (w < 1e-14) continue;  // far above the minimum: contributes nothing measurable
      const Local& l = locals_[k];
      // A frame of fixed nodes only (the outer ring of a local patch) has no derivatives; its
      // value counted in the soft minimum above.
      if (l.idx.empty()) continue;
      const Vec gk = l.map.transpose() * dq_[k];
      for (std::size_t i = 0; i < l.idx.size(); ++i) (*grad)[l.idx[i]] -= w * gk[i];
      if (!hess) continue;
      FrameMatrix hv;
      column_value(columns(k, x), m, m == Measure::kJacobian ? 0 : l.guard, scale_of(l, m), nullptr,
                   &hv);
      const Eigen::MatrixXd hk = l.map.transpose() * hv * l.map;
      for (std::size_t i = 0; i < l.idx.size(); ++i) {
        for (std::size_t j = 0; j < l.idx.size(); ++j) {
          (*hess)(l.idx[i], l.idx[j]) += -w * hk(i, j) + t * w * gk[i] * gk[j];
        }
      }
    }
    if (hess) *hess -= t * (*grad) * grad->transpose();  // gbar = -grad
    return value;
  }

 private:
  struct Local {
    FrameVector v0;
    Eigen::Matrix<double, 9, Eigen::Dynamic> map;
    std::vector<int> idx;  // the reduced coordinates this frame depends on
    double det_scale = 1.0;
    int guard = 0;
  };

  // The scale argument of column_value for frame l.
  double scale_of(const Local& l, Measure m) const {
    return m == Measure::kJacobian ? l.det_scale / unit_ : guard_;
  }

  FrameVector columns(std::size_t k, const Vec& x) const {
    const Local& l = locals_[k];
    FrameVector v = l.v0;
    for (std::size_t i = 0; i < l.idx.size(); ++i) {
      v += l.map.col(static_cast<Eigen::Index>(i)) * x[l.idx[i]];
    }
    return v;
  }

  std::vector<NodeSpace> spaces_;
  double unit_ = 1.0, guard_ = 0.0;
  std::vector<Local> locals_;
  int dof_ = 0;
  std::vector<double> q_, w_;
  std::vector<FrameVector> dq_;
};

// An unfinished smoothing must not look finished: in a cancelled task group it throws.
void stop_if_cancelled() {
  if (tbb::is_current_task_group_canceling()) throw Cancelled("smoothing cancelled");
}

// Minimises f with a damped Newton method: solve (H + lambda I) d = -g by Cholesky, raising
// lambda until H + lambda I is positive definite and lowering it after each success, then a
// backtracking (Armijo) line search. `done(x, f)` is asked after every accepted step and stops
// the run when it returns true. Returns the iterations taken.
template <class F, class Done>
int newton(Vec& x, F&& f, Done&& done, int max_iterations, double max_step) {
  const auto n = x.size();
  if (n == 0) return 0;
  Vec g(n), x_new(n);
  Eigen::MatrixXd h(n, n);
  double fx = f(x, &g, &h);
  double lambda = 0.0;
  int it = 0;
  for (; it < max_iterations; ++it) {
    stop_if_cancelled();
    const double scale = std::max(h.diagonal().cwiseAbs().maxCoeff(), 1e-300);
    Vec d;
    for (int attempt = 0; attempt < 60; ++attempt) {
      Eigen::MatrixXd a = h;
      a.diagonal().array() += lambda;
      Eigen::LLT<Eigen::MatrixXd> llt(a);
      if (llt.info() == Eigen::Success) {
        d = -llt.solve(g);
        if (d.allFinite() && g.dot(d) < 0.0) break;
      }
      d.resize(0);
      lambda = std::max(4.0 * lambda, 1e-10 * scale);
    }
    if (d.size() == 0) break;
    const double longest = d.cwiseAbs().maxCoeff();
    if (longest > max_step) d *= max_step / longest;  // a trust bound on node displacement
    const double slope = g.dot(d);
    double step = 1.0;
    bool accepted = false;
    double f_new = 0.0;
    for (int ls = 0; ls < 30; ++ls) {
      x_new = x + step * d;
      f_new = f(x_new, nullptr, nullptr);
      if (std::isfinite(f_new) && f_new <= fx + 1e-4 * step * slope) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    lambda = step == 1.0 ? lambda / 4.0 : std::max(4.0 * lambda, 1e-10 * scale);
    x = x_new;
    fx = f(x, &g, &h);
    if (done(x, fx)) {
      ++it;
      break;
    }
  }
  return it;
}

// Minimises f with L-BFGS; `done(x, f)` is asked after every accepted step and stops the run
// when it returns true. Returns the iterations taken.
template <class F, class Done>
int lbfgs(Vec& x, F&& f, Done&& done, int max_iterations, int history, double initial_step) {
  const int n = index_cast<int>(x.size());
  if (n == 0) return 0;
  std::deque<Vec> s_hist, y_hist;
  std::deque<double> rho_hist;
  Vec g(n), g_new(n), d(n), x_new(n);
  double fx = f(x, &g);
  int it = 0;
  for (; it < max_iterations; ++it) {
    stop_if_cancelled();
    // Two-loop recursion for d = -H g.
    d = -g;
    std::vector<double> alpha(s_hist.size());
    for (int i = index_cast<int>(s_hist.size()) - 1; i >= 0; --i) {
      alpha[i] = rho_hist[i] * s_hist[i].dot(d);
      d -= alpha[i] * y_hist[i];
    }
    if (!s_hist.empty()) d *= s_hist.back().dot(y_hist.back()) / y_hist.back().squaredNorm();
    for (std::size_t i = 0; i < s_hist.size(); ++i) {
      const double beta = rho_hist[i] * y_hist[i].dot(d);
      d += (alpha[i] - beta) * s_hist[i];
    }
    double slope = g.dot(d);
    if (!(slope < 0.0)) {  // not a descent direction: restart from steepest descent
      s_hist.clear(), y_hist.clear(), rho_hist.clear();
      d = -g;
      slope = -g.squaredNorm();
      if (!(slope < 0.0)) break;  // stationary
    }
    // First step (or after a restart): limit the largest displacement to initial_step.
    double step = 1.0;
    if (s_hist.empty()) step = std::min(1.0, initial_step / d.cwiseAbs().maxCoeff());
    bool accepted = false;
    double f_new = 0.0;
    for (int ls = 0; ls < 40; ++ls) {
      x_new = x + step * d;
      f_new = f(x_new, &g_new);
      if (std::isfinite(f_new) && f_new <= fx + 1e-4 * step * slope) {
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    const Vec s = x_new - x;
    const Vec y = g_new - g;
    const double sy = s.dot(y);
    if (sy > 1e-16 * s.norm() * y.norm()) {
      s_hist.push_back(s), y_hist.push_back(y), rho_hist.push_back(1.0 / sy);
      if (index_cast<int>(s_hist.size()) > history) {
        s_hist.pop_front(), y_hist.pop_front(), rho_hist.pop_front();
      }
    }
    x = x_new, g = g_new, fx = f_new;
    if (done(x, fx)) {
      ++it;
      break;
    }
  }
  return it;
}

double mean_edge_length(const std::vector<Frame>& frames, const std::vector<Point>& p) {
  double sum = 0.0;
  int count = 0;
  for (const auto& f : frames) {
    for (const auto& c : f.col) {
      if (c.terms != 2) continue;
      sum += (p[c.node[0]] - p[c.node[1]]).norm();
      ++count;
    }
  }
  return count > 0 && sum > 0.0 ? sum / count : 1.0;
}

// dim 3: Jacobians are volumes, scaled by L^3; dim 2: areas, by L^2 (L the mean edge length),
// so that the untangling sharpness means the same for any mesh size.
SmoothResult run(std::vector<Point>& points, std::vector<Frame> frames,
                 std::vector<NodeSpace> spaces, int dim, const SmoothOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const double length = mean_edge_length(frames, points);
  const double unit = std::pow(length, dim);
  Problem problem(frames, std::move(spaces), unit, options.shape_guard);
  Vec x = Vec::Zero(problem.dof());

  SmoothResult result;
  std::vector<double> q;
  auto min_of = [&](const Vec& at, bool scaled) {
    problem.values(at, scaled ? Measure::kShape : Measure::kJacobian, q);
    return *std::min_element(q.begin(), q.end());
  };
  // Jacobians in the units of quality.hpp: values are det * det_scale / unit.
  result.initial_min_jacobian = min_of(x, false) * unit;
  result.initial_min_scaled_jacobian = min_of(x, true);

  int budget = options.max_iterations;
  // Phase 1: untangle.
  if (min_of(x, false) <= 0.0) {
    auto f = [&](const Vec& at, Vec* g) {
      return -problem.soft_min(at, Measure::kJacobian, options.untangle_sharpness, g);
    };
    auto untangled = [&](const Vec& at, double) { return min_of(at, false) > 0.0; };
    result.untangle_iterations =
        lbfgs(x, f, untangled, std::min(budget, options.max_untangle_iterations), options.history,
              0.05 * length);
    budget -= result.untangle_iterations;
  }

  // Phase 2: shape, keeping the iterate with the best true minimum scaled Jacobian.
  Vec best = x;
  double best_min = min_of(x, true);
  for (double t : options.sharpness) {
    if (budget <= 0) break;
    double last = -std::numeric_limits<double>::infinity();
    int stalled = 0;
    auto f = [&](const Vec& at, Vec* g, Eigen::MatrixXd* h) {
      return -problem.soft_min(at, Measure::kShape, t, g, h);
    };
    auto done = [&](const Vec& at, double fx) {
      const double m = min_of(at, true);
      if (m > best_min) best_min = m, best = at;
      const double soft = -fx;
      stalled = soft - last < options.tolerance ? stalled + 1 : 0;
      last = soft;
      return stalled >= options.patience;
    };
    const int used =
        newton(x, f, done, std::min(budget, options.max_stage_iterations), 0.1 * length);
    result.shape_iterations += used;
    budget -= used;
    x = best;  // continue the next stage from the best point so far
  }
  x = best;

  problem.positions(x, points);
  result.iterations = result.untangle_iterations + result.shape_iterations;
  result.final_min_jacobian = min_of(x, false) * unit;
  result.untangled = result.final_min_jacobian > 0.0;
  result.final_min_scaled_jacobian = min_of(x, true);
  result.final_max_scaled_jacobian = *std::max_element(q.begin(), q.end());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

void check_nodes(std::size_t num_points, Index node, const std::string& element) {
  if (node < 0 || index_cast<std::size_t>(node) >= num_points) {
    throw InvalidInput("smooth: " + element + " names node " + std::to_string(node) +
                       ", out of range (mesh has " + std::to_string(num_points) + " nodes)");
  }
}

}  // namespace

std::vector<NodeConstraint> box_constraints(std::span<const Point> points, const Point& lo,
                                            const Point& hi, std::array<bool, 6> fixed_faces,
                                            double tol) {
  std::vector<NodeConstraint> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    std::vector<int> axes;  // box faces the node lies on, at most one per axis
    bool fixed = false;
    for (int a = 0; a < 3; ++a) {
      for (int side = 0; side < 2; ++side) {
        const double plane = side == 0 ? lo[a] : hi[a];
        if (std::abs(p[a] - plane) <= tol) {
          axes.push_back(a);
          if (fixed_faces[2 * a + side]) fixed = true;
          break;
        }
      }
    }
    Point snapped = p;  // exactly on the faces, so that sliding keeps the box coordinate
    for (int a : axes) snapped[a] = std::abs(p[a] - lo[a]) <= tol ? lo[a] : hi[a];
    if (fixed || axes.size() == 3) {
      out[i] = NodeConstraint::fixed();
    } else if (axes.size() == 2) {
      out[i] = NodeConstraint::line(snapped, Point::Unit(3 - axes[0] - axes[1]));
    } else if (axes.size() == 1) {
      out[i] = NodeConstraint::plane(snapped, Point::Unit(axes[0]));
    }
  }
  return out;
}

SmoothResult smooth_hex_mesh(HexMesh& mesh, std::span<const NodeConstraint> constraints,
                             const SmoothOptions& options) {
  // Its minimum, and so what the smoother maximises, is not defined on no hexes.
  if (mesh.hexes.empty()) throw InvalidInput("smooth: the mesh has no hexes");
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    for (Index n : mesh.hexes[h]) check_nodes(mesh.points.size(), n, "hex " + std::to_string(h));
  }
  auto spaces = node_spaces(mesh.points, constraints, nullptr, options.links);
  return run(mesh.points, hex_frames(mesh), std::move(spaces), 3, options);
}

SmoothResult smooth_quad_mesh(QuadMesh& mesh, const Point& normal,
                              std::span<const NodeConstraint> constraints,
                              const SmoothOptions& options) {
  if (!(normal.norm() > 0.0) || !normal.allFinite()) {
    throw InvalidInput("smooth_quad_mesh: the plane normal is zero or not finite");
  }
  if (mesh.quads.empty()) throw InvalidInput("smooth_quad_mesh: the mesh has no quads");
  for (std::size_t q = 0; q < mesh.quads.size(); ++q) {
    for (Index n : mesh.quads[q]) check_nodes(mesh.points.size(), n, "quad " + std::to_string(q));
  }
  const Point n = normal.normalized();
  auto spaces = node_spaces(mesh.points, constraints, &n, options.links);
  return run(mesh.points, quad_frames(mesh, n), std::move(spaces), 2, options);
}

}  // namespace geode::primal
