#include <geode/stc/arrangement.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/topology.hpp>

namespace geode::stc {

std::string format_point(const Point& x, int dim) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << x[0] << ", " << x[1];
  if (dim == 3) s << ", " << x[2];
  s << ")";
  return s.str();
}

namespace {

// Length of the first dim components (no dynamic-size head(): GCC 12 misreads it as out of
// bounds under -Warray-bounds).
double norm_d(const Point& v, int dim) { return dim == 3 ? v.norm() : std::hypot(v[0], v[1]); }

// Trilinear (bilinear for dim 2) map of the unit cube onto the hexahedron (quadrilateral)
// with VTK corners P (primal/multilinear.hpp), kept in the plane z = 0 in 2D.
Point multilinear(const std::array<Point, 8>& P, const Point& r, int dim) {
  Point x = primal::multilinear_point(P, r, dim);
  if (dim == 2) x[2] = 0.0;
  return x;
}

// Determinant of the map's Jacobian at local coordinates r.
double multilinear_jacobian(const std::array<Point, 8>& P, const Point& r, int dim) {
  const Eigen::Matrix3d J = primal::multilinear_jacobian(P, r, dim);
  return dim == 3 ? J.determinant() : J(0, 0) * J(1, 1) - J(0, 1) * J(1, 0);
}

Domain make_cell_domain(const std::array<Point, 8>& P, int dim, bool pyramid = false) {
  const char* what = pyramid ? "pyramid" : dim == 3 ? "hexahedron" : "quadrilateral";
  const int n = 1 << dim;
  Point lo = Point::Constant(1e300), hi = Point::Constant(-1e300);
  for (int c = 0; c < n; ++c) {
    if (!P[primal::index_cast<std::size_t>(c)].allFinite())
      throw InvalidInput(std::string("domain: ") + what + " corner " + std::to_string(c) +
                         " is not finite");
    lo = lo.cwiseMin(P[primal::index_cast<std::size_t>(c)]);
    hi = hi.cwiseMax(P[primal::index_cast<std::size_t>(c)]);
  }
  const double size = norm_d(hi - lo, dim);
  if (!(size > 0))
    throw InvalidInput(std::string("domain: degenerate ") + what + " (all corners coincide)");
  // Positive at every corner and at the centre: the test the mesh-quality literature uses
  // for a valid trilinear element (Knupp's corner Jacobians plus the centre). Relative to the
  // cell's size so that a flattened cell is refused too.
  const double floor = 1e-12 * std::pow(size, dim);
  for (int c = 0; c <= n; ++c) {
    if (pyramid && c >= 4 && c < n) continue;  // the apex: the map's Jacobian vanishes there
    Point r = Point::Constant(0.5);
    if (c < n)
      for (int a = 0; a < 3; ++a)
        r[a] = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(c)]
                                                 [primal::index_cast<std::size_t>(a)];
    const double j = multilinear_jacobian(P, r, dim);
    if (!(j > floor))
      throw InvalidInput(
          std::string("domain: the ") + what + "'s Jacobian is not positive at " +
          (c < n ? "corner " + std::to_string(c) + " " +
                       format_point(P[primal::index_cast<std::size_t>(c)], dim)
                 : std::string("its centre")) +
          " (det " + std::to_string(j) + "): corners must be in VTK order" +
          (pyramid    ? " (base 0-1-2-3 counter-clockwise seen from the apex 4)"
           : dim == 3 ? " (bottom 0-1-2-3 counter-clockwise seen from above, 4-7 above them)"
                      : " (counter-clockwise)") +
          " and the cell not inverted or flat");
  }
  Domain d(lo, hi, dim);
  if (dim == 2) d.lo[2] = d.hi[2] = 0.0;
  d.corners = P;
  d.is_pyramid = pyramid;
  return d;
}

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
    h_ = options_.step * diag_;
    grad_h_ = 1e-6 * diag_;
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
  const int corners = dim_ == 3 ? 8 : 4;
  for (int k = 0; k < kcells; ++k)
    for (int j = 0; j < n_[1]; ++j)
      for (int i = 0; i < n_[0]; ++i) {
        bool all = true;
        for (std::size_t s = 0; s < S.size() && all; ++s) {
          const auto& val = grid_[primal::index_cast<std::size_t>(S[s])];
          double lo = 1e300, hi = -1e300;
          for (int c = 0; c < corners; ++c) {
            const double v =
                val[grid_id(i + (c & 1), j + ((c >> 1) & 1), dim_ == 3 ? k + ((c >> 2) & 1) : 0)];
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
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
              ": a piece smaller than the seeding grid was missed (raise the seed resolution)");
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

int Engine::register_vertex(std::vector<int> S, const Point& x) {
  std::sort(S.begin(), S.end());
  long long key = 0;
  for (int s : S) key = key * static_cast<long long>(sheets_.size()) + s;
  std::vector<int>& same = vertices_by_sheets_[key];
  // The first match in registration order, as a scan over all vertices would find.
  for (int i : same) {
    Vertex& v = vertices_[primal::index_cast<std::size_t>(i)];
    if ((v.x - x).norm() < 1e-7 * diag_) {
      ++v.found;
      return i;
    }
  }
  Vertex v;
  v.sheets = S;
  v.x = x;
  v.found = 1;
  Eigen::MatrixXd J(dim_, dim_);
  for (int r = 0; r < dim_; ++r)
    J.row(r) = grad(S[primal::index_cast<std::size_t>(r)], x).head(dim_).transpose();
  v.orientation = J.determinant() > 0 ? 1 : -1;
  check_vertex(v, J);
  vertices_.push_back(v);
  jacobians_.push_back(std::move(J));
  same.push_back(static_cast<int>(vertices_.size() - 1));
  return static_cast<int>(vertices_.size() - 1);
}

void Engine::check_vertex(const Vertex& v, const Eigen::MatrixXd& J) const {
  double prod = 1.0;
  for (int r = 0; r < dim_; ++r) prod *= J.row(r).norm();
  if (std::abs(J.determinant()) < 1e-6 * prod)
    throw TopologyError("arrangement: sheets " + names(v.sheets) + " meet tangentially at " +
                        fmt_point(v.x, dim_) + " (not in general position)");
  for (int e = 0; e < primal::index_cast<int>(sheets_.size()); ++e) {
    if (std::find(v.sheets.begin(), v.sheets.end(), e) != v.sheets.end()) continue;
    const double g = grad(e, v.x).norm();
    if (std::abs(value(e, v.x)) < 1e-7 * diag_ * std::max(g, 1e-300))
      throw TopologyError("arrangement: " + std::to_string(dim_ + 1) + " sheets " +
                          names(v.sheets) + " and " + name(e) + " pass through one point " +
                          fmt_point(v.x, dim_) + " (not in general position)");
  }
  for (int a = 0; a < dim_; ++a)
    if (std::min(std::abs(v.x[a] - domain_.lo[a]), std::abs(v.x[a] - domain_.hi[a])) < 1e-6 * diag_)
      throw TopologyError("arrangement: sheets " + names(v.sheets) +
                          " meet on the domain boundary at " + fmt_point(v.x, dim_) +
                          " (not in general position)");
}

Arrangement Engine::run() {
  Arrangement A;
  A.domain = user_;
  A.sheet_count = primal::index_cast<int>(sheets_.size());
  for (const auto& s : sheets_) A.sheet_names.push_back(s.name);

  check_apex();
  sample_grid();
  // 1. Curves: every (d-1)-subset of sheets, every component.
  std::vector<std::vector<int>> subsets;
  const int m = A.sheet_count;
  if (dim_ == 2)
    for (int a = 0; a < m; ++a) subsets.push_back({a});
  else
    for (int a = 0; a < m; ++a)
      for (int b = a + 1; b < m; ++b) subsets.push_back({a, b});
  for (std::size_t k = 0; k < subsets.size(); ++k) {
    if (options_.progress) options_.progress(k, subsets.size());
    const auto& S = subsets[k];
    std::vector<Curve> found;
    for (const Point& s : seeds(S)) {
      bool covered = false;
      for (const Curve& c : found) {
        for (const Point& p : c.polyline)
          if ((p - s).norm() < 2.0 * h_) {
            covered = true;
            break;
          }
        if (covered) break;
      }
      if (!covered) found.push_back(trace(S, s));
    }
    for (auto& c : found) A.curves.push_back(std::move(c));
  }
  if (options_.progress) options_.progress(subsets.size(), subsets.size());

  // 2. Events along each curve, vertices, and 1-cells.
  struct RawEdge {
    std::vector<int> sheets;
    int va, vb;  // vertex or -1
    int sa, sb;  // the vertex's extra sheet (toward the edge)
    int fa, fb;  // face when no vertex
    Point xa, xb;
    std::vector<int> side;
  };
  std::vector<RawEdge> raw;
  for (const Curve& c : A.curves) {
    std::vector<Event> ev = events(c);
    if (ev.empty()) {
      std::string where = c.closed
                              ? "a closed loop"
                              : "a curve from boundary face " + std::to_string(c.end_faces[0]) +
                                    " to face " + std::to_string(c.end_faces[1]);
      throw TopologyError(
          "arrangement: sheets " + names(c.sheets) + " meet in " + where + " through " +
          fmt_point(c.polyline.front(), dim_) +
          " that no other sheet crosses: a 1-cell with no vertex has no dual element");
    }
    for (Event& e : ev) {
      std::vector<int> T = c.sheets;
      T.push_back(e.sheet);
      e.vertex = register_vertex(T, e.x);
    }
    const auto& P = c.polyline;
    const double n = static_cast<double>(P.size());
    auto point_at = [&](double param) {
      double p = c.closed ? std::fmod(param, n) : param;
      const auto i = static_cast<std::size_t>(std::clamp(std::floor(p), 0.0, n - 1));
      const std::size_t j = c.closed ? (i + 1) % P.size() : std::min(i + 1, P.size() - 1);
      Point y = P[i] + (p - static_cast<double>(i)) * (P[j] - P[i]);
      project(c.sheets, y);
      return y;
    };
    auto make = [&](int va, int sa, int fa, const Point& xa, double pa, int vb, int sb, int fb,
                    const Point& xb, double pb) {
      RawEdge r{c.sheets, va, vb, sa, sb, fa, fb, xa, xb, {}};
      const Point mid = point_at(0.5 * (pa + pb));
      for (int s = 0; s < m; ++s) r.side.push_back(value(s, mid) < 0 ? -1 : 1);
      raw.push_back(std::move(r));
    };
    if (c.closed) {
      for (std::size_t i = 0; i < ev.size(); ++i) {
        const Event& a = ev[i];
        const Event& b = ev[(i + 1) % ev.size()];
        const double pb = i + 1 < ev.size() ? b.param : b.param + n;
        make(a.vertex, a.sheet, -1, a.x, a.param, b.vertex, b.sheet, -1, b.x, pb);
      }
    } else {
      make(-1, -1, c.end_faces[0], P.front(), 0.0, ev.front().vertex, ev.front().sheet, -1,
           ev.front().x, ev.front().param);
      for (std::size_t i = 0; i + 1 < ev.size(); ++i)
        make(ev[i].vertex, ev[i].sheet, -1, ev[i].x, ev[i].param, ev[i + 1].vertex, ev[i + 1].sheet,
             -1, ev[i + 1].x, ev[i + 1].param);
      make(ev.back().vertex, ev.back().sheet, -1, ev.back().x, ev.back().param, -1, -1,
           c.end_faces[1], P.back(), n - 1.0);
    }
  }
  check_touching(A.curves);
  for (const Vertex& v : vertices_)
    if (v.found != dim_)
      throw TopologyError(
          "arrangement: the vertex of sheets " + names(v.sheets) + " at " + fmt_point(v.x, dim_) +
          " was found on " + std::to_string(v.found) + " of its " + std::to_string(dim_) +
          " curves: part of a curve was missed (raise the seed resolution) or the sheets are not "
          "in general position");

  // 3. Deterministic vertex order: by sheets, then by position.
  std::vector<int> order(vertices_.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](const Vertex& v) {
    std::vector<long long> k(v.sheets.begin(), v.sheets.end());
    for (int a = 0; a < dim_; ++a) k.push_back(std::llround(v.x[a] / diag_ * 1e6));
    return k;
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return key(vertices_[primal::index_cast<std::size_t>(a)]) <
           key(vertices_[primal::index_cast<std::size_t>(b)]);
  });
  std::vector<int> rank(vertices_.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    rank[primal::index_cast<std::size_t>(order[i])] = static_cast<int>(i);
    A.vertices.push_back(vertices_[primal::index_cast<std::size_t>(order[i])]);
  }

  // 4. Regions: union the octants around each 1-cell at its two ends.
  const int octants = 1 << dim_;
  const int nv = primal::index_cast<int>(A.vertices.size());
  primal::DisjointSets uf(primal::index_cast<std::size_t>(nv * octants));
  std::vector<unsigned> faces(primal::index_cast<std::size_t>(nv * octants), 0u);
  auto octant_bits = [&](int v, const std::vector<int>& S, int sigma, int extra,
                         const std::vector<int>& side) {
    const Vertex& V = A.vertices[primal::index_cast<std::size_t>(v)];
    int bits = 0;
    for (int i = 0; i < dim_; ++i) {
      const int s = V.sheets[primal::index_cast<std::size_t>(i)];
      bool pos;
      if (s == extra)
        pos = side[primal::index_cast<std::size_t>(s)] > 0;
      else {
        const auto it = std::find(S.begin(), S.end(), s);
        assert(it != S.end());
        pos = (sigma >> (it - S.begin())) & 1;
      }
      if (pos) bits |= 1 << i;
    }
    return v * octants + bits;
  };
  for (RawEdge& r : raw) {
    Edge1 e;
    e.sheets = r.sheets;
    e.side = r.side;
    if (r.va >= 0) r.va = rank[primal::index_cast<std::size_t>(r.va)];
    if (r.vb >= 0) r.vb = rank[primal::index_cast<std::size_t>(r.vb)];
    e.a = {r.va, r.fa, r.xa};
    e.b = {r.vb, r.fb, r.xb};
    for (int sigma = 0; sigma < (1 << (dim_ - 1)); ++sigma) {
      const int ka = r.va >= 0 ? octant_bits(r.va, r.sheets, sigma, r.sa, r.side) : -1;
      const int kb = r.vb >= 0 ? octant_bits(r.vb, r.sheets, sigma, r.sb, r.side) : -1;
      if (ka >= 0 && kb >= 0) uf.unite(ka, kb);
      if (ka >= 0 && kb < 0) faces[primal::index_cast<std::size_t>(ka)] |= 1u << r.fb;
      if (kb >= 0 && ka < 0) faces[primal::index_cast<std::size_t>(kb)] |= 1u << r.fa;
    }
    A.edges.push_back(std::move(e));
  }
  std::vector<int> label(primal::index_cast<std::size_t>(nv * octants), -1);
  A.region.assign(primal::index_cast<std::size_t>(nv), {-1, -1, -1, -1, -1, -1, -1, -1});
  for (int v = 0; v < nv; ++v) {
    const Vertex& V = A.vertices[primal::index_cast<std::size_t>(v)];
    const Eigen::MatrixXd Jinv =
        jacobians_[primal::index_cast<std::size_t>(order[primal::index_cast<std::size_t>(v)])]
            .inverse();
    for (int b = 0; b < octants; ++b) {
      const int root = uf.find(v * octants + b);
      int& l = label[primal::index_cast<std::size_t>(root)];
      const bool fresh = l < 0;
      if (fresh) {
        l = A.region_count++;
        A.region_faces.push_back(0u);
        A.region_signs.emplace_back();
      }
      A.region[primal::index_cast<std::size_t>(v)][primal::index_cast<std::size_t>(b)] = l;
      A.region_faces[primal::index_cast<std::size_t>(l)] |=
          faces[primal::index_cast<std::size_t>(v * octants + b)];
      // Sign vector of the region, sampled just inside this octant.
      Eigen::VectorXd sigma(dim_);
      for (int i = 0; i < dim_; ++i) sigma[i] = (b >> i) & 1 ? 1.0 : -1.0;
      Eigen::VectorXd d = Jinv * sigma;
      Point x = V.x;
      for (int i = 0; i < dim_; ++i) x[i] += 1e-5 * diag_ * d[i] / d.norm();
      std::vector<int> sg;
      for (int s = 0; s < m; ++s) sg.push_back(value(s, x) < 0 ? -1 : 1);
      auto& rs = A.region_signs[primal::index_cast<std::size_t>(l)];
      if (fresh)
        rs = sg;
      else if (rs != sg)
        throw TopologyError(
            "arrangement: one region joins octants of different sign vectors (near " +
            fmt_point(V.x, dim_) + " where sheets " + names(V.sheets) +
            " meet): the curves were traced inconsistently");
    }
  }
  // A pyramid's apex touches the domain only at face 5, where no curve ends: its region is
  // the one with the apex's sign vector, which must be unique to be told apart (among those
  // that touch all four triangles, where several have it).
  if (user_.is_pyramid) {
    const Point apex = (*user_.corners)[4];
    std::vector<int> sg;
    for (const Sheet& s : given_) sg.push_back(s.field(apex) < 0 ? -1 : 1);
    std::vector<int> hits;
    for (int r = 0; r < A.region_count; ++r)
      if (A.region_signs[primal::index_cast<std::size_t>(r)] == sg) hits.push_back(r);
    // Two regions may share a sign vector; the apex's touches all four triangles near it, a
    // region far below rarely does.
    if (hits.size() > 1) {
      std::vector<int> around;
      for (int r : hits)
        if ((A.region_faces[primal::index_cast<std::size_t>(r)] & 0xFu) == 0xFu)
          around.push_back(r);
      if (around.size() == 1) hits = around;
    }
    if (hits.size() != 1) {
      std::string masks;
      for (int r : hits)
        masks += (masks.empty() ? "" : ", ") +
                 std::to_string(A.region_faces[primal::index_cast<std::size_t>(r)]);
      throw TopologyError(
          "arrangement: " + std::to_string(hits.size()) +
          " regions have the sign vector of the pyramid's apex " + format_point(apex, dim_) +
          (hits.empty()
               ? ": its region has no vertex around it"
               : ": the apex's region is split where no 1-cell joins its vertices (its hexes "
                 "would not meet face to face around its node), or another region has its "
                 "sides (boundary faces touched, as masks: " +
                     masks + ")"));
    }
    A.region_faces[primal::index_cast<std::size_t>(hits[0])] |= 1u << box_face(2, true);
  }
  // Report physical positions (the identity for a box). A vertex's orientation was taken
  // from the composed fields' gradients: it is the physical one where the map's Jacobian is
  // positive, which the corner and centre test does not promise everywhere.
  for (Vertex& v : A.vertices) {
    v.local = local(v.x);
    if (user_.corners && !(multilinear_jacobian(*user_.corners, v.local, dim_) > 0))
      throw InvalidInput(
          "arrangement: the domain cell folds over (Jacobian not positive) where sheets " +
          names(v.sheets) + " meet at " + fmt_point(v.x, dim_));
    v.x = physical(v.x);
  }
  if (user_.corners) {
    for (Edge1& e : A.edges) e.a.x = physical(e.a.x), e.b.x = physical(e.b.x);
    for (Curve& c : A.curves)
      for (Point& p : c.polyline) p = physical(p);
  }
  return A;
}

}  // namespace

Domain Domain::hexahedron(const std::array<Point, 8>& corners) {
  return make_cell_domain(corners, 3);
}

Domain Domain::pyramid(const std::array<Point, 5>& corners) {
  std::array<Point, 8> P;
  for (std::size_t c = 0; c < 8; ++c) P[c] = corners[std::min<std::size_t>(c, 4)];
  return make_cell_domain(P, 3, true);
}

Domain Domain::quadrilateral(const std::array<Point, 4>& corners) {
  std::array<Point, 8> P;
  for (std::size_t c = 0; c < 8; ++c) P[c] = corners[c % 4];  // 4-7 unused in 2D
  return make_cell_domain(P, 2);
}

Point domain_point(const Domain& domain, const Point& r) {
  if (domain.corners) return multilinear(*domain.corners, r, domain.dim);
  Point x = Point::Zero();
  for (int a = 0; a < domain.dim; ++a) x[a] = domain.lo[a] + (domain.hi[a] - domain.lo[a]) * r[a];
  return x;
}

Arrangement compute_arrangement(const std::vector<Sheet>& sheets, const Domain& domain,
                                const ArrangementOptions& options) {
  return Engine(sheets, domain, options).run();
}

}  // namespace geode::stc
