#pragma once
// compute_arrangement's private engine, not part of the API: the Engine class, its geometry
// helpers and the curve events. Its methods are defined by topic in arrangement.cpp (run(): the
// curves, vertices and cells found and checked; a vertex registered and its sheets' crossing
// checked), arrangement_curves.cpp (the sampling grid, seeds, curve walking and tracing,
// events along a curve) and arrangement_checks.cpp (sheets touching, the pyramid's apex).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <geode/primal/errors.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/topology.hpp>
#include <geode/stc/arrangement.hpp>

namespace geode::stc::detail {

// Length of the first dim components (no dynamic-size head(): GCC 12 misreads it as out of
// bounds under -Warray-bounds).
inline double norm_d(const Point& v, int dim) {
  return dim == 3 ? v.norm() : std::hypot(v[0], v[1]);
}

// Trilinear (bilinear for dim 2) map of the unit cube onto the hexahedron (quadrilateral)
// with VTK corners P (primal/multilinear.hpp), kept in the plane z = 0 in 2D.
inline Point multilinear(const std::array<Point, 8>& P, const Point& r, int dim) {
  Point x = primal::multilinear_point(P, r, dim);
  if (dim == 2) x[2] = 0.0;
  return x;
}

// Determinant of the map's Jacobian at local coordinates r.
inline double multilinear_jacobian(const std::array<Point, 8>& P, const Point& r, int dim) {
  const Eigen::Matrix3d J = primal::multilinear_jacobian(P, r, dim);
  return dim == 3 ? J.determinant() : J(0, 0) * J(1, 1) - J(0, 1) * J(1, 0);
}

// A hexahedron (quadrilateral, pyramid) domain from its corners, refused (InvalidInput) when a
// corner is not finite or the map's Jacobian is not positive at a corner or the centre.
Domain make_cell_domain(const std::array<Point, 8>& P, int dim, bool pyramid = false);

// An event on a traced curve: the curve crosses sheet `sheet` at vertex position x, between
// polyline points i and i+1 at fraction t.
struct Event {
  double param;  // i + t
  int sheet;
  Point x;
  int vertex = -1;
};

// Gradients whose angle has a sine below this are parallel: the sheets are tangent (about
// 0.06 degrees; a touching point found to the engine's tolerance is far below it).
constexpr double kParallel = 1e-3;

class Engine {
 public:
  Engine(const std::vector<Sheet>& sheets, const Domain& domain, const ArrangementOptions& opt)
      : user_(domain),
        domain_(reference_box(domain)),
        mapped_(compose(sheets)),
        sheets_(domain.corners ? mapped_ : sheets),
        given_(sheets),
        options_(opt),
        dim_(domain.dim) {
    if (primal::index_cast<int>(sheets.size()) < dim_)
      throw InvalidInput("arrangement: needs at least as many sheets as dimensions");
    diag_ = (domain_.hi - domain_.lo).head(dim_).norm();
    // The tracing step and the gradient's difference step follow the diagonal, but at most
    // 32 times the shortest side: in a slab or a needle (refine3 in a --box of aspect 80 and
    // more) a step of the diagonal's 0.004 was a third of the short side, and curves there
    // were missed. Boxes of aspect up to about 23 (all of conform's) are traced as before.
    double shortest = diag_;
    for (int a = 0; a < dim_; ++a) shortest = std::min(shortest, domain_.hi[a] - domain_.lo[a]);
    const double scale = std::min(diag_, 32.0 * shortest);
    h_ = options_.step * scale;
    grad_h_ = 1e-6 * scale;
    tol_ = options_.tolerance * diag_;
  }

  Arrangement run();

 private:
  // A sheet through a pyramid's apex would end every curve of it in that one point (face 5
  // of the reference box): refused, as a vertex on the boundary is.
  void check_apex() const;

  // The box the engine computes in. For a hexahedron: corner 0's position, and per axis the
  // mean length of the cell's edges along it, so that the seeding grid, the step and the
  // tolerances (all relative to this box) keep their meaning; for a hexahedron equal to a
  // box it is that box.
  static Domain reference_box(const Domain& d) {
    if (d.dim != 2 && d.dim != 3) throw InvalidInput("arrangement: dimension must be 2 or 3");
    if (!d.corners) {
      for (int i = 0; i < d.dim; ++i)
        if (!(d.hi[i] > d.lo[i])) throw InvalidInput("arrangement: empty domain");
      return Domain(d.lo, d.hi, d.dim);
    }
    make_cell_domain(*d.corners, d.dim,
                     d.is_pyramid);  // throws on bad corners (they may be filled in by hand)
    const auto& P = *d.corners;
    Point len = Point::Zero();
    for (const auto& e : primal::topology::kHexEdgeCorners) {
      const Point v =
          P[primal::index_cast<std::size_t>(e[1])] - P[primal::index_cast<std::size_t>(e[0])];
      const auto& a = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(e[0])];
      const auto& b = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(e[1])];
      int axis = 0;
      while (a[primal::index_cast<std::size_t>(axis)] == b[primal::index_cast<std::size_t>(axis)])
        ++axis;
      if (d.dim == 2 && (axis == 2 || a[2] || b[2])) continue;  // the quad's 4 edges only
      len[axis] += norm_d(v, d.dim) / (d.dim == 3 ? 4.0 : 2.0);
    }
    Point lo = P[0];
    if (d.dim == 2) lo[2] = 0.0, len[2] = 0.0;
    return Domain(lo, lo + len, d.dim);
  }
  // Every field composed with the map from the reference box to the hexahedron.
  std::vector<Sheet> compose(const std::vector<Sheet>& sheets) const {
    if (!user_.corners) return {};
    std::vector<Sheet> out;
    for (const Sheet& s : sheets) {
      Sheet m{s.name, {}, s.kind};
      m.field = [f = &s.field, P = *user_.corners, lo = domain_.lo, hi = domain_.hi,
                 dim = user_.dim](const Point& u) {
        Point r = Point::Zero();
        for (int a = 0; a < dim; ++a) r[a] = (u[a] - lo[a]) / (hi[a] - lo[a]);
        return (*f)(multilinear(P, r, dim));
      };
      out.push_back(std::move(m));
    }
    return out;
  }
  // Reference-box position -> local coordinates in [0, 1]^d -> physical position.
  Point local(const Point& u) const {
    Point r = Point::Zero();
    for (int a = 0; a < dim_; ++a) r[a] = (u[a] - domain_.lo[a]) / (domain_.hi[a] - domain_.lo[a]);
    return r;
  }
  Point physical(const Point& u) const { return user_.corners ? domain_point(user_, local(u)) : u; }
  // Positions in messages are physical.
  std::string fmt_point(const Point& u, int dim) const { return format_point(physical(u), dim); }

  double value(int s, const Point& x) const {
    return sheets_[primal::index_cast<std::size_t>(s)].field(x);
  }
  Point grad(int s, const Point& x) const {
    return gradient(sheets_[primal::index_cast<std::size_t>(s)].field, x, grad_h_, dim_);
  }
  std::string name(int s) const {
    return "'" + sheets_[primal::index_cast<std::size_t>(s)].name + "'";
  }
  std::string names(const std::vector<int>& S) const {
    std::string r;
    for (std::size_t i = 0; i < S.size(); ++i) r += (i ? ", " : "") + name(S[i]);
    return r;
  }

  bool inside(const Point& x, double eps = 0.0) const {
    for (int i = 0; i < dim_; ++i)
      if (x[i] < domain_.lo[i] - eps || x[i] > domain_.hi[i] + eps) return false;
    return true;
  }

  // Newton projection onto {f_s = 0, s in S}, with the coordinates in `fixed` (bit mask of
  // axes) held. Returns false when it does not converge. A step that does not reduce the
  // residual is halved (up to 12 times): on smooth fields near their zero set the full step
  // always does, so this only acts where fields are piecewise smooth (stc/mesh_fields.hpp),
  // where plain Newton can cycle between the pieces of a kinked sheet.
  // On success `grads` (when given) receives the sheets' gradients at the returned x, which
  // the convergence test has just computed: callers need them for the curve's tangent.
  bool project(const std::vector<int>& S, Point& x, unsigned fixed = 0,
               std::array<Point, 3>* grads = nullptr) const {
    const int k = primal::index_cast<int>(S.size());
    // At most 3 x 3: fixed capacity keeps the hot path off the heap.
    using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
    using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
    Mat J(k, dim_);
    Vec F(k), gnorm(k);
    for (int r = 0; r < k; ++r) F[r] = value(S[primal::index_cast<std::size_t>(r)], x);
    for (int it = 0; it < 40; ++it) {
      double err = 0.0;
      for (int r = 0; r < k; ++r) {
        const Point g = grad(S[primal::index_cast<std::size_t>(r)], x);
        if (grads) (*grads)[primal::index_cast<std::size_t>(r)] = g;
        for (int c = 0; c < dim_; ++c) J(r, c) = (fixed >> c) & 1u ? 0.0 : g[c];
        gnorm[r] = J.row(r).norm();
        if (gnorm[r] < 1e-14) return false;
        err = std::max(err, std::abs(F[r]) / gnorm[r]);
      }
      if (err < tol_) return true;
      const Mat JJt = J * J.transpose();
      const double det = JJt.determinant();
      if (!(std::abs(det) > 1e-30)) return false;
      const Vec dx = J.transpose() * JJt.inverse() * F;
      if (!dx.allFinite() || dx.norm() > 0.25 * diag_) return false;
      double step = 1.0;
      for (int halving = 0;; ++halving) {
        Point y = x;
        for (int c = 0; c < dim_; ++c) y[c] -= step * dx[c];
        double trial = 0.0;
        for (int r = 0; r < k; ++r) {
          F[r] = value(S[primal::index_cast<std::size_t>(r)], y);
          trial = std::max(trial, std::abs(F[r]) / gnorm[r]);
        }
        if (trial < err || trial < tol_) {
          x = y;
          break;
        }
        if (halving == 12) return false;
        step *= 0.5;
      }
    }
    return false;
  }

  // The curve's tangent from the gradients of its d-1 sheets: the rotated gradient in 2D,
  // their cross product in 3D.
  Point tangent_of(const std::array<Point, 3>& g) const {
    return dim_ == 2 ? Point(-g[0][1], g[0][0], 0.0) : g[0].cross(g[1]);
  }
  Point tangent(const std::vector<int>& S, const Point& x) const {
    std::array<Point, 3> g;
    for (std::size_t r = 0; r < S.size(); ++r) g[r] = grad(S[r], x);
    return tangent_of(g);
  }

  std::vector<Point> seeds(const std::vector<int>& S) const;
  std::vector<Point> walk(const std::vector<int>& S, const Point& x0, Point t, bool& closed,
                          int& end_face) const;
  Curve trace(const std::vector<int>& S, const Point& x0) const;
  std::vector<Event> events(const Curve& c) const;
  void check_touching(const std::vector<Curve>& curves) const;
  void check_lone_pieces(const std::vector<Curve>& curves) const;
  int register_vertex(std::vector<int> sheets, const Point& x);
  void check_vertex(const Vertex& v, const Eigen::MatrixXd& J) const;

  // An equation for the touching search: sheet `sheet`'s field, or (sheet < 0) the domain
  // face x[axis] = at.
  struct Equation {
    int sheet = -1;
    int axis = 0;
    double at = 0.0;
  };
  double eval(const Equation& e, const Point& x) const {
    return e.sheet >= 0 ? value(e.sheet, x) : x[e.axis] - e.at;
  }
  Point eval_grad(const Equation& e, const Point& x) const {
    return e.sheet >= 0 ? grad(e.sheet, x) : Point::Unit(e.axis);
  }
  bool common_zero(const Equation& a, const Equation& b, Point& x) const;
  // Sine of the angle between two gradients (0: parallel or antiparallel).
  double sine(const Point& a, const Point& b) const {
    const double s = dim_ == 3 ? a.cross(b).norm() : std::abs(a[0] * b[1] - a[1] * b[0]);
    return s / (a.norm() * b.norm());
  }

  // Sampling grid for seeds, evaluated once for every sheet.
  void sample_grid();
  int cell_count() const { return n_[0] * n_[1] * (dim_ == 3 ? n_[2] : 1); }
  std::array<int, 3> cell_of(const Point& x) const {
    std::array<int, 3> c{0, 0, 0};
    for (int a = 0; a < dim_; ++a) {
      const auto A = primal::index_cast<std::size_t>(a);
      const double t = (x[a] - domain_.lo[a]) / (domain_.hi[a] - domain_.lo[a]) * n_[A];
      c[A] = std::clamp(static_cast<int>(std::floor(t)), 0, n_[A] - 1);
    }
    return c;
  }
  int cell_id(int i, int j, int k) const { return (k * n_[1] + j) * n_[0] + i; }
  // The least and greatest of sheet s's field over the corners of cell (i, j, k) (k = 0 in 2D):
  // the sheet may cross the cell when the first is <= 0 <= the second.
  std::pair<double, double> cell_span(int s, int i, int j, int k) const {
    const auto& val = grid_[primal::index_cast<std::size_t>(s)];
    double lo = 1e300, hi = -1e300;
    for (int c = 0; c < (dim_ == 3 ? 8 : 4); ++c) {
      const double v =
          val[grid_id(i + (c & 1), j + ((c >> 1) & 1), dim_ == 3 ? k + ((c >> 2) & 1) : 0)];
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    return {lo, hi};
  }
  Point grid_node(int i, int j, int k) const;
  std::size_t grid_id(int i, int j, int k) const {
    return primal::index_cast<std::size_t>((k * (n_[1] + 1) + j) * (n_[0] + 1) + i);
  }
  std::array<int, 3> n_{1, 1, 1};
  std::vector<std::vector<double>> grid_;

  Domain user_;                // as given
  Domain domain_;              // the reference box (user_ itself for a box)
  std::vector<Sheet> mapped_;  // the fields composed with the map, for a hexahedron
  const std::vector<Sheet>& sheets_;
  const std::vector<Sheet>& given_;  // the fields in physical space
  ArrangementOptions options_;
  int dim_;
  double diag_, h_, grad_h_, tol_;
  std::vector<Vertex> vertices_;
  std::vector<Eigen::MatrixXd> jacobians_;  // per vertex: its sheets' gradients as rows
  // Vertices by their sheets (key: the sorted sheet indices in base sheet_count), for
  // register_vertex's search; each list in registration order.
  std::unordered_map<long long, std::vector<int>> vertices_by_sheets_;
};

}  // namespace geode::stc::detail
