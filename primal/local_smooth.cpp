#include <geode/primal/local_smooth.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include <geode/primal/boundary.hpp>
#include <geode/primal/detail/smooth_frames.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/frame_derivatives.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

namespace {

namespace topo = topology;

// A patch moves the free nodes of one hex: at most 8 nodes, 24 unknowns.
constexpr int kMaxDof = 24;
using PatchVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDof, 1>;
using PatchMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDof, kMaxDof>;
using Basis = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3>;

using detail::hex_frame_shapes;
using detail::HexFrameShape;

// Closest point of triangle abc to p (C. Ericson, Real-Time Collision Detection, 5.1.5).
Point closest_on_triangle(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Point bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Point cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Nearest-triangle queries on a uniform grid of triangle bounding boxes.
class SurfaceProjector {
 public:
  explicit SurfaceProjector(const TriMesh& s) : s_(s) {
    if (s.tris.empty()) return;
    lo_ = Point::Constant(std::numeric_limits<double>::max());
    double edges = 0.0;
    for (const auto& t : s.tris) {
      for (int k = 0; k < 3; ++k) {
        lo_ = lo_.cwiseMin(s.points[t[k]]);
        edges += (s.points[t[k]] - s.points[t[(k + 1) % 3]]).norm();
      }
    }
    cell_ = std::max(2.0 * edges / (3.0 * static_cast<double>(s.tris.size())), 1e-12);
    for (std::size_t i = 0; i < s.tris.size(); ++i) {
      Point a = s.points[s.tris[i][0]], b = a;
      for (int k = 1; k < 3; ++k)
        a = a.cwiseMin(s.points[s.tris[i][k]]), b = b.cwiseMax(s.points[s.tris[i][k]]);
      const auto ca = cell_of(a), cb = cell_of(b);
      for (Index x = ca[0]; x <= cb[0]; ++x)
        for (Index y = ca[1]; y <= cb[1]; ++y)
          for (Index z = ca[2]; z <= cb[2]; ++z) grid_[{x, y, z}].push_back(index_cast(i));
    }
  }

  // Nearest point of the surface to p and the unit normal of its triangle.
  Point project(const Point& p, Point* normal) const {
    const auto c = cell_of(p);
    double best = std::numeric_limits<double>::max();
    Point out = p;
    Index best_tri = kInvalidIndex;
    for (Index r = 1; r < 1 << 20; r *= 2) {
      for (Index x = c[0] - r; x <= c[0] + r; ++x)
        for (Index y = c[1] - r; y <= c[1] + r; ++y)
          for (Index z = c[2] - r; z <= c[2] + r; ++z) {
            const auto it = grid_.find({x, y, z});
            if (it == grid_.end()) continue;
            for (Index t : it->second) {
              const auto& tri = s_.tris[t];
              const Point q =
                  closest_on_triangle(p, s_.points[tri[0]], s_.points[tri[1]], s_.points[tri[2]]);
              const double d = (q - p).squaredNorm();
              if (d < best || (d == best && t < best_tri)) best = d, out = q, best_tri = t;
            }
          }
      // Every triangle within r cells of p has been seen.
      if (best_tri != kInvalidIndex && std::sqrt(best) <= r * cell_) break;
      if (r > (1 << 16)) break;
    }
    if (normal && best_tri != kInvalidIndex) {
      const auto& tri = s_.tris[best_tri];
      *normal = (s_.points[tri[1]] - s_.points[tri[0]])
                    .cross(s_.points[tri[2]] - s_.points[tri[0]])
                    .normalized();
    }
    return out;
  }

 private:
  std::array<Index, 3> cell_of(const Point& p) const {
    std::array<Index, 3> c{};
    for (int k = 0; k < 3; ++k) c[k] = static_cast<Index>(std::floor((p[k] - lo_[k]) / cell_));
    return c;
  }

  const TriMesh& s_;
  Point lo_ = Point::Zero();
  double cell_ = 1.0;
  std::unordered_map<std::array<Index, 3>, std::vector<Index>, IndexArrayHash> grid_;
};

// Shared, read-only data of one smoothing call.
struct Context {
  HexMesh& mesh;
  std::span<const NodeConstraint> constraints;
  const SurfaceProjector* projector;
  const LocalSmoothOptions& options;
  std::vector<Index> node_start, node_hexes;  // node -> hexes (CSR)
  std::vector<double> start;       // per hex, its scaled Jacobian at the start (SmoothStart)
  std::vector<double> edge_floor;  // per hex, the shortest edge it may have
};

bool is_fixed(const Context& ctx, Index v) {
  return !ctx.constraints.empty() && ctx.constraints[v].kind == NodeConstraint::Kind::kFixed;
}

// The tangent basis a node moves in at p (3 x dof, orthonormal).
Basis motion_basis(const Context& ctx, Index v, const Point& p) {
  const NodeConstraint c = ctx.constraints.empty() ? NodeConstraint::free() : ctx.constraints[v];
  Basis b;
  auto plane = [&](const Point& n) {
    const auto t = detail::plane_tangents(n);
    b.resize(3, 2);
    b.col(0) = t[0], b.col(1) = t[1];
  };
  switch (c.kind) {
    case NodeConstraint::Kind::kFree:
      b = Eigen::Matrix3d::Identity();
      break;
    case NodeConstraint::Kind::kFixed:
      b.resize(3, 0);
      break;
    case NodeConstraint::Kind::kPlane:
      plane(c.direction.normalized());
      break;
    case NodeConstraint::Kind::kSurface: {
      Point n;
      ctx.projector->project(p, &n);
      plane(n);
      break;
    }
    case NodeConstraint::Kind::kLine:
      b.resize(3, 1);
      b.col(0) = c.direction.normalized();
      break;
  }
  return b;
}

// Where a constrained node lands: exactly on its plane, line or surface.
Point constrain(const Context& ctx, Index v, const Point& p) {
  if (ctx.constraints.empty()) return p;
  const NodeConstraint& c = ctx.constraints[v];
  switch (c.kind) {
    case NodeConstraint::Kind::kPlane:
      return detail::project_to_plane(p, c.origin, c.direction.normalized());
    case NodeConstraint::Kind::kLine:
      return detail::project_to_line(p, c.origin, c.direction.normalized());
    case NodeConstraint::Kind::kSurface:
      return ctx.projector->project(p, nullptr);
    default:
      return p;
  }
}

struct PatchOutcome {
  bool moved = false;
  int iterations = 0;
};

// One patch: the free nodes of a seed hex move; every frame with a moving node is counted.
class Patch {
 public:
  Patch(const Context& ctx, Index seed, std::span<const Index> affected,
        const std::vector<double>& sj)
      : ctx_(ctx), hex_(affected.begin(), affected.end()) {
    // Local numbers in order of first use (the seed's free nodes first), looked up in an
    // open-addressed table of twice the corners at least: a linear search of the nodes found
    // so far was a tenth of smoothing's time.
    int bits = 4;
    while ((std::size_t{1} << bits) < 16 * (hex_.size() + 1)) ++bits;
    std::vector<std::pair<Index, int>> table(std::size_t{1} << bits, {kInvalidIndex, 0});
    auto local_of = [&](Index v) {
      std::size_t i = (static_cast<std::uint64_t>(v) * 0x9E3779B97F4A7C15ull) >> (64 - bits);
      while (table[i].first != kInvalidIndex && table[i].first != v)
        i = (i + 1) & (table.size() - 1);
      if (table[i].first == kInvalidIndex) {
        table[i] = {v, index_cast<int>(node_.size())};
        node_.push_back(v);
      }
      return table[i].second;
    };
    for (Index v : ctx.mesh.hexes[seed])
      if (!is_fixed(ctx, v)) local_of(v);
    moving_ = index_cast<int>(node_.size());
    local_.resize(hex_.size());
    for (std::size_t h = 0; h < hex_.size(); ++h)
      for (int c = 0; c < 8; ++c) local_[h][c] = local_of(ctx.mesh.hexes[hex_[h]][c]);
    pos_.resize(node_.size());
    for (std::size_t i = 0; i < node_.size(); ++i) pos_[i] = ctx.mesh.points[node_[i]];
    const auto& shapes = hex_frame_shapes();
    for (std::size_t h = 0; h < hex_.size(); ++h)
      for (int f = 0; f < 9; ++f) {
        bool has = false;
        for (int k = 0; k < shapes[f].nodes; ++k)
          has = has || local_[h][shapes[f].corner[k]] < moving_;
        if (has) frames_.push_back({static_cast<int>(h), f});
      }
    // Length unit: the mean edge of the seed hex.
    double sum = 0.0;
    for (const auto& e : topo::kHexEdgeCorners)
      sum += (ctx.mesh.points[ctx.mesh.hexes[seed][e[0]]] -
              ctx.mesh.points[ctx.mesh.hexes[seed][e[1]]])
                 .norm();
    length_ = std::max(sum / 12.0, 1e-300);
    unit_ = length_ * length_ * length_;
    // Floors (see the header): the patch's worst never drops; hexes within `margin` of it keep
    // their start; better ones may lose `loss` from their start, never past worst + margin.
    double worst = std::numeric_limits<double>::max();
    for (Index h : hex_) worst = std::min(worst, sj[h]);
    tangled_ = worst <= 0.0;
    const double keep = std::max(worst, 0.0) + ctx.options.margin;
    for (Index h : hex_) {
      const double s = ctx.start[h];
      const double f = s <= 0.0   ? -std::numeric_limits<double>::infinity()
                       : s < keep ? s
                                  : std::max(keep, s - ctx.options.loss);
      floor_.push_back(sj[h] <= 0.0 ? f : std::min(sj[h], std::max(f, worst)));
    }
    // A hex already below its edge floor (shortened while untangling) just gets no shorter.
    for (std::size_t h = 0; h < hex_.size(); ++h)
      edge_floor_.push_back(std::min(ctx.edge_floor[hex_[h]], hex_shortest_edge(corners(pos_, h))));
  }

  PatchOutcome run(std::vector<double>& sj) {
    PatchOutcome out;
    if (moving_ == 0) return out;
    const LocalSmoothOptions& o = ctx_.options;
    for (int phase = 0; phase < 2; ++phase) {
      const bool untangle = phase == 0;
      // A positive scaled Jacobian means all nine frames are positive: no untangling then.
      if (untangle && (!tangled_ || min_untangle_frame() > 0.0)) continue;
      const double t = untangle ? o.untangle_sharpness : o.sharpness;
      q_at_pos_ = false;  // q_ holds the other phase's measure, if any
      for (int it = 0; it < o.max_iterations; ++it) {
        const bool ok = newton_step(untangle, t);
        ++out.iterations;
        if (!ok) break;
        out.moved = true;
        // An accepted step leaves q_ at the new positions.
        if (untangle && *std::min_element(q_.begin(), q_.end()) > 0.0) break;
        if (last_gain_ < o.min_gain) break;
      }
    }
    if (out.moved) {
      // Patches of one round write disjoint nodes and hexes (see the round selection).
      for (int i = 0; i < moving_; ++i) ctx_.mesh.points[node_[i]] = pos_[i];
      for (std::size_t h = 0; h < hex_.size(); ++h) sj[hex_[h]] = accepted_sj_[h];
    }
    return out;
  }

 private:
  struct FrameRef {
    int hex;    // index into hex_
    int frame;  // 0..8
  };

  FrameVector columns(const std::vector<Point>& p, const FrameRef& r) const {
    const HexFrameShape& s = hex_frame_shapes()[r.frame];
    FrameVector v = FrameVector::Zero();
    for (int k = 0; k < s.nodes; ++k) {
      const Point& x = p[local_[r.hex][s.corner[k]]];
      for (int i = 0; i < 3; ++i) v.segment<3>(3 * i) += s.coef[i][k] * x;
    }
    return v;
  }

  double measure(const FrameVector& v, const FrameRef& r, bool untangle, FrameVector* g,
                 FrameMatrix* h) const {
    if (!untangle) return scaled_determinant_derivatives(v, g, h);
    const double scale = hex_frame_shapes()[r.frame].det_scale / unit_;
    const double d = determinant_derivatives(v, g, h);
    if (g) *g *= scale;
    if (h) *h *= scale;
    return d * scale;
  }

  double min_untangle_frame() const {
    double m = std::numeric_limits<double>::max();
    for (const FrameRef& r : frames_)
      m = std::min(m, measure(columns(pos_, r), r, true, nullptr, nullptr));
    return m;
  }

  // Corners of affected hex h at positions p.
  HexCorners corners(const std::vector<Point>& p, std::size_t h) const {
    HexCorners c;
    for (int k = 0; k < 8; ++k) c[k] = p[local_[h][k]];
    return c;
  }

  // Soft minimum -1/t log sum exp(-t q_k) over the frames at positions p; with grad and hess,
  // the derivatives of its negative with respect to the moving nodes' xyz coordinates.
  // `q_known`: q_ already holds the frame values at p.
  double soft_min(const std::vector<Point>& p, bool untangle, double t, PatchVector* grad,
                  PatchMatrix* hess, bool q_known = false) {
    const std::size_t n = frames_.size();
    if (!q_known) {
      q_.resize(n);
      for (std::size_t k = 0; k < n; ++k)
        q_[k] = measure(columns(p, frames_[k]), frames_[k], untangle, nullptr, nullptr);
    }
    const auto [qmin, sum, value] = soft_of_q(t);
    if (!grad) return value;
    const int m3 = 3 * moving_;
    grad->setZero(m3);
    hess->setZero(m3, m3);
    const auto& shapes = hex_frame_shapes();
    for (std::size_t k = 0; k < n; ++k) {
      const double w = std::exp(-t * (q_[k] - qmin)) / sum;
      // Far above the minimum: a millionth of the gradient at most. The step is checked on the
      // exact soft minimum (Armijo), so a direction this close to the gradient's costs nothing.
      if (w < 1e-6) continue;
      // Second derivatives only where the weight is large enough to shape the step (the soft
      // minimum's curvature is dominated by its few lowest frames); elsewhere the frame adds its
      // Gauss-Newton part t w g g^T only.
      const bool second = w >= 3e-3;
      const FrameRef& r = frames_[k];
      const HexFrameShape& s = shapes[r.frame];
      FrameVector g;
      FrameMatrix h;
      measure(columns(p, r), r, untangle, &g, second ? &h : nullptr);
      int count = 0;
      std::array<int, 8> node{};
      std::array<int, 8> slot{};
      std::array<Point, 8> gn;
      for (int a = 0; a < s.nodes; ++a) {
        const int ln = local_[r.hex][s.corner[a]];
        if (ln >= moving_) continue;
        node[count] = ln, slot[count] = a;
        gn[count] = s.coef[0][a] * g.segment<3>(0) + s.coef[1][a] * g.segment<3>(3) +
                    s.coef[2][a] * g.segment<3>(6);
        grad->segment<3>(3 * ln) -= w * gn[count];
        ++count;
      }
      for (int a = 0; a < count; ++a) {
        if (!second) {
          for (int b = 0; b < count; ++b)
            hess->block<3, 3>(3 * node[a], 3 * node[b]) += t * w * gn[a] * gn[b].transpose();
          continue;
        }
        // Rows of the node-a mix of H: sum_i coef[i][a] H(3i.., :).
        Eigen::Matrix<double, 3, 9> row = Eigen::Matrix<double, 3, 9>::Zero();
        for (int i = 0; i < 3; ++i) row += s.coef[i][slot[a]] * h.block<3, 9>(3 * i, 0);
        for (int b = 0; b < count; ++b) {
          Eigen::Matrix3d blk = Eigen::Matrix3d::Zero();
          for (int j = 0; j < 3; ++j) blk += s.coef[j][slot[b]] * row.block<3, 3>(0, 3 * j);
          hess->block<3, 3>(3 * node[a], 3 * node[b]) +=
              -w * blk + t * w * gn[a] * gn[b].transpose();
        }
      }
    }
    *hess -= t * (*grad) * grad->transpose();  // the mean gradient is -grad
    return value;
  }

  // Untangling maximises Jacobians / L^3, which an edge collapse lowers: the edge floors bind
  // the shape phase only, where an untangling step may need an edge shorter for a while.
  // Most rejected trial steps break a floor, and mostly at the hex that broke one last time:
  // it is checked first, so a rejection costs about one hex.
  bool feasible(const std::vector<Point>& p, bool untangle) {
    const std::size_t n = hex_.size();
    trial_q_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t h = (i + last_broken_) % n;
      const HexCorners c = corners(p, h);
      trial_q_[h] = hex_scaled_jacobians(c);
      const double q = *std::min_element(trial_q_[h].begin(), trial_q_[h].end());
      if (q < floor_[h] || (!untangle && hex_shortest_edge(c) < edge_floor_[h])) {
        last_broken_ = h;
        return false;
      }
    }
    return true;
  }

  // The soft minimum at the positions feasible() accepted last, from the frame values it
  // measured (the shape phase's frame measure is the scaled Jacobian itself).
  double accepted_soft_min(double t) {
    for (std::size_t k = 0; k < frames_.size(); ++k)
      q_[k] = trial_q_[frames_[k].hex][frames_[k].frame];
    return soft_of_q(t).value;
  }

  // -1/t log sum exp(-t q_k) over q_, shifted by the minimum so that no exponential overflows.
  struct Soft {
    double qmin, sum, value;
  };
  Soft soft_of_q(double t) const {
    const double qmin = *std::min_element(q_.begin(), q_.end());
    double sum = 0.0;
    for (double q : q_) sum += std::exp(-t * (q - qmin));
    return {qmin, sum, qmin - std::log(sum) / t};
  }

  // One damped Newton step on -soft_min in the moving nodes' free coordinates; false when no
  // step raised the soft minimum within the floors.
  bool newton_step(bool untangle, double t) {
    PatchVector gx;
    PatchMatrix hx;
    const double f0 = -soft_min(pos_, untangle, t, &gx, &hx, q_at_pos_);
    q_at_pos_ = false;  // trial steps overwrite q_
    std::array<Basis, 8> basis;
    std::array<int, 8> offset{};
    int dof = 0;
    for (int i = 0; i < moving_; ++i) {
      basis[i] = motion_basis(ctx_, node_[i], pos_[i]);
      offset[i] = dof;
      dof += index_cast<int>(basis[i].cols());
    }
    if (dof == 0) return false;
    PatchVector g(dof);
    PatchMatrix h(dof, dof);
    for (int i = 0; i < moving_; ++i) {
      const auto di = basis[i].cols();
      g.segment(offset[i], di) = basis[i].transpose() * gx.segment<3>(3 * i);
      for (int j = 0; j < moving_; ++j)
        h.block(offset[i], offset[j], di, basis[j].cols()) =
            (basis[i].transpose() * hx.block<3, 3>(3 * i, 3 * j)).lazyProduct(basis[j]);
    }
    const double scale = std::max(h.diagonal().cwiseAbs().maxCoeff(), 1e-300);
    PatchVector d;
    for (int attempt = 0; attempt < 40; ++attempt) {
      PatchMatrix a = h;
      a.diagonal().array() += lambda_;
      Eigen::LLT<PatchMatrix> llt(a);
      if (llt.info() == Eigen::Success) {
        d = -llt.solve(g);
        if (d.allFinite() && g.dot(d) < 0.0) break;
      }
      d.resize(0);
      lambda_ = std::max(4.0 * lambda_, 1e-8 * scale);
    }
    if (d.size() == 0) return false;
    // Trust bound: no node moves more than a quarter of the seed's mean edge per step.
    double longest = 0.0;
    for (int i = 0; i < moving_; ++i)
      longest = std::max(longest, (basis[i] * d.segment(offset[i], basis[i].cols())).norm());
    if (longest > 0.25 * length_) d *= 0.25 * length_ / longest;
    const double slope = g.dot(d);
    trial_ = pos_;
    for (double step = 1.0; step > 0.01; step *= 0.5) {
      for (int i = 0; i < moving_; ++i)
        trial_[i] = constrain(ctx_, node_[i],
                              pos_[i] + step * (basis[i] * d.segment(offset[i], basis[i].cols())));
      if (!feasible(trial_, untangle)) continue;
      const double f =
          untangle ? -soft_min(trial_, untangle, t, nullptr, nullptr) : -accepted_soft_min(t);
      if (std::isfinite(f) && f <= f0 + 1e-4 * step * slope && f < f0) {
        last_gain_ = f0 - f;
        lambda_ = step == 1.0 ? lambda_ / 4.0 : std::max(4.0 * lambda_, 1e-8 * scale);
        pos_.swap(trial_);
        q_at_pos_ = true;  // measured at this trial just above
        // feasible() measured every hex at the new positions: their scaled Jacobians without
        // measuring them again, folded as hex_scaled_jacobian folds its nine frames.
        accepted_sj_.resize(trial_q_.size());
        for (std::size_t h = 0; h < trial_q_.size(); ++h) {
          double m = std::numeric_limits<double>::infinity();
          for (double q : trial_q_[h]) m = std::min(m, q);
          accepted_sj_[h] = m;
        }
        return true;
      }
    }
    return false;
  }

  const Context& ctx_;
  std::vector<Index> hex_;                 // affected hexes
  std::vector<Index> node_;                // local -> global; the first moving_ move
  std::vector<std::array<int, 8>> local_;  // per affected hex, its corners' local numbers
  std::vector<Point> pos_, trial_;
  std::vector<FrameRef> frames_;
  std::vector<double> q_, floor_, edge_floor_;
  std::size_t last_broken_ = 0;  // the hex whose floor a trial step broke last
  bool q_at_pos_ = false;  // q_ holds this phase's frame values at pos_ (after an accepted step)
  std::vector<std::array<double, 9>> trial_q_;  // per hex, its frames' scaled Jacobians
  std::vector<double> accepted_sj_;  // per hex, its scaled Jacobian at the last accepted step
  int moving_ = 0;
  bool tangled_ = false;  // some patch hex has a scaled Jacobian <= 0
  double length_ = 1.0, unit_ = 1.0, lambda_ = 0.0, last_gain_ = 0.0;
};

}  // namespace

SmoothStart smooth_start(const HexMesh& mesh) {
  return {scaled_jacobian_per_hex(mesh), shortest_edge_per_hex(mesh)};
}

LocalSmoothResult smooth_hexes_local(HexMesh& mesh, std::span<const NodeConstraint> constraints,
                                     const TriMesh* surface, std::span<const Index> seeds,
                                     const LocalSmoothOptions& options, const SmoothStart* start) {
  const auto clock_start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const std::size_t np = mesh.points.size(), nh = mesh.hexes.size();
  if (!constraints.empty() && constraints.size() != np)
    throw InvalidInput("smooth_hexes_local: " + std::to_string(constraints.size()) +
                       " constraints for " + std::to_string(np) + " nodes");
  for (std::size_t h = 0; h < nh; ++h)
    for (Index v : mesh.hexes[h])
      if (v < 0 || index_cast<std::size_t>(v) >= np)
        throw InvalidInput("smooth_hexes_local: hex " + std::to_string(h) + " names node " +
                           std::to_string(v) + ", out of range");
  for (Index s : seeds)
    if (s < 0 || index_cast<std::size_t>(s) >= nh)
      throw InvalidInput("smooth_hexes_local: seed hex " + std::to_string(s) + " out of range");
  if (start && (start->scaled_jacobian.size() != nh || start->shortest_edge.size() != nh))
    throw InvalidInput("smooth_hexes_local: the start values are not one per hex");
  if ((!options.hex_targets.empty() && options.hex_targets.size() != nh) ||
      (!options.hex_goals.empty() && options.hex_goals.size() != nh))
    throw InvalidInput("smooth_hexes_local: the per-hex targets or goals are not one per hex");
  auto target_of = [&](Index h) {
    return options.hex_targets.empty() ? options.target
                                       : options.hex_targets[index_cast<std::size_t>(h)];
  };
  const bool goals = options.goal > 0.0 || !options.hex_goals.empty();
  auto goal_of = [&](Index h) {
    return options.hex_goals.empty() ? options.goal : options.hex_goals[index_cast<std::size_t>(h)];
  };
  std::unique_ptr<SurfaceProjector> projector;
  for (std::size_t v = 0; v < constraints.size(); ++v) {
    const NodeConstraint& c = constraints[v];
    if (c.kind == NodeConstraint::Kind::kSurface && !surface)
      throw InvalidInput("smooth_hexes_local: node " + std::to_string(v) +
                         " slides on a surface but none is given");
    if ((c.kind == NodeConstraint::Kind::kPlane || c.kind == NodeConstraint::Kind::kLine) &&
        !(c.direction.norm() > 0.0 && c.direction.allFinite()))
      throw InvalidInput("smooth_hexes_local: node " + std::to_string(v) +
                         " has a zero or non-finite constraint direction");
  }
  if (surface) projector = std::make_unique<SurfaceProjector>(*surface);

  Context ctx{mesh, constraints, projector.get(), options, {}, {}, {}, {}};
  ctx.node_start.assign(np + 1, 0);
  for (const auto& h : mesh.hexes)
    for (Index v : h) ++ctx.node_start[v + 1];
  for (std::size_t v = 0; v < np; ++v) ctx.node_start[v + 1] += ctx.node_start[v];
  ctx.node_hexes.resize(ctx.node_start.back());
  {
    std::vector<Index> fill(ctx.node_start.begin(), ctx.node_start.end() - 1);
    for (std::size_t h = 0; h < nh; ++h)
      for (Index v : mesh.hexes[h]) ctx.node_hexes[fill[v]++] = index_cast(h);
  }
  // Constrained nodes start exactly on their plane, line or surface.
  for (std::size_t v = 0; v < constraints.size(); ++v)
    mesh.points[v] = constrain(ctx, index_cast(v), mesh.points[v]);

  LocalSmoothResult res;
  const SmoothStart now = start ? SmoothStart{} : smooth_start(mesh);
  const SmoothStart& from = start ? *start : now;
  std::vector<double> sj = start ? scaled_jacobian_per_hex(mesh) : now.scaled_jacobian;
  ctx.start = from.scaled_jacobian;
  ctx.edge_floor.resize(nh);
  for (std::size_t h = 0; h < nh; ++h)
    ctx.edge_floor[h] = options.min_edge_fraction * from.shortest_edge[h];
  auto summarise = [&](double& min_sj, Index& inverted) {
    min_sj = nh ? *std::min_element(sj.begin(), sj.end()) : 0.0;
    inverted =
        static_cast<Index>(std::count_if(sj.begin(), sj.end(), [](double q) { return q <= 0.0; }));
  };
  summarise(res.initial_min_scaled_jacobian, res.initial_inverted);

  std::vector<Index> pool(seeds.begin(), seeds.end());
  if (seeds.empty())
    for (std::size_t h = 0; h < nh; ++h) pool.push_back(index_cast(h));
  std::sort(pool.begin(), pool.end());
  pool.erase(std::unique(pool.begin(), pool.end()), pool.end());
  std::vector<int> visits(nh, 0);
  std::vector<char> dirty(nh, 1);
  std::vector<Index> claimed(nh, -1);
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);

  // The hexes a patch seeded by pool[i] touches (sharing a free node with it), found once.
  std::vector<std::vector<Index>> around(pool.size());
  std::vector<char> found(pool.size(), 0);
  auto find_around = [&](std::size_t i) {
    std::vector<Index>& a = around[i];
    for (Index v : mesh.hexes[pool[i]])
      if (!is_fixed(ctx, v))
        for (Index k = ctx.node_start[v]; k < ctx.node_start[v + 1]; ++k)
          a.push_back(ctx.node_hexes[k]);
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    found[i] = 1;
  };
  for (Index round = 0;; ++round) {
    std::vector<std::size_t> cand;  // positions in pool
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const Index h = pool[i];
      if (sj[h] < target_of(h) && visits[h] < options.max_visits && dirty[h]) cand.push_back(i);
    }
    if (options.progress) options.progress(pool.size() - cand.size(), pool.size());
    if (cand.empty()) break;
    // The caller's aim is met: the target above it only gave the hexes room to get there.
    if (goals &&
        std::all_of(pool.begin(), pool.end(), [&](Index h) { return sj[h] >= goal_of(h); }))
      break;
    // A strict total order (ties by hex number), so the parallel sort's order is the serial
    // one's; the sort and the neighbourhoods were a sixth of the first pass's time serially.
    std::vector<std::size_t> missing;
    for (std::size_t i : cand)
      if (!found[i]) missing.push_back(i);
    arena.execute([&] {
      tbb::parallel_sort(cand.begin(), cand.end(), [&](std::size_t i, std::size_t j) {
        const Index a = pool[i], b = pool[j];
        return sj[a] < sj[b] || (sj[a] == sj[b] && a < b);
      });
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, missing.size(), 256),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t k = r.begin(); k != r.end(); ++k)
                            find_around(missing[k]);
                        });
    });
    // Worst first, each patch sharing no hex with one kept before it in this round.
    std::vector<Index> chosen;
    std::vector<const std::vector<Index>*> affected;
    for (std::size_t i : cand) {
      const Index h = pool[i];
      const std::vector<Index>& a = around[i];
      if (a.empty()) {  // every node fixed: nothing to do, ever
        visits[h] = options.max_visits;
        continue;
      }
      if (std::any_of(a.begin(), a.end(), [&](Index x) { return claimed[x] == round; })) continue;
      for (Index x : a) claimed[x] = round;
      chosen.push_back(h);
      affected.push_back(&a);
    }
    std::vector<PatchOutcome> outcome(chosen.size());
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chosen.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                            outcome[i] = Patch(ctx, chosen[i], *affected[i], sj).run(sj);
                        });
    });
    for (std::size_t i = 0; i < chosen.size(); ++i) {
      ++visits[chosen[i]];
      dirty[chosen[i]] = 0;
      res.iterations += outcome[i].iterations;
      if (outcome[i].moved)
        for (Index a : *affected[i])
          if (a != chosen[i]) dirty[a] = 1;
    }
    res.patches += index_cast(chosen.size());
    res.rounds = round + 1;
  }
  summarise(res.final_min_scaled_jacobian, res.final_inverted);
  res.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  res.cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  return res;
}

namespace {

// boundary_slide_constraints over `surfaces` and kept.surfaces, then each kept surface's rim
// (its quads' edges used once) and kept.node_sets (KeptFeatures); nodes checked by the caller.
std::vector<NodeConstraint> slide_constraints(const HexMesh& mesh,
                                              std::vector<BoundaryQuad> surfaces,
                                              const KeptFeatures& kept) {
  for (const auto& surface : kept.surfaces)
    for (const auto& q : surface) surfaces.push_back(BoundaryQuad{kInvalidIndex, -1, q});
  std::vector<NodeConstraint> out = boundary_slide_constraints(mesh, surfaces);
  const auto& p = mesh.points;
  constexpr double kParallel = 1e-9;  // |d1 x d2| of unit directions taken as one line
  std::unordered_map<Index, std::vector<Point>> rim;  // node -> its rim edges' directions
  for (const auto& surface : kept.surfaces) {
    // Each face once: a side set may list both sides of a face inside a block.
    std::unordered_set<FaceKey, IndexArrayHash> seen;
    std::vector<std::array<Index, 4>> faces;
    for (const auto& q : surface)
      if (seen.insert(face_key(q)).second) faces.push_back(q);
    std::unordered_map<EdgeKey, int, IndexArrayHash> uses;
    for (const auto& q : faces)
      for (int k = 0; k < 4; ++k) ++uses[edge_key(q[k], q[(k + 1) % 4])];
    for (const auto& q : faces)
      for (int k = 0; k < 4; ++k) {
        const Index a = q[k], b = q[(k + 1) % 4];
        if (uses[edge_key(a, b)] != 1) continue;
        const Point d = (p[b] - p[a]).normalized();
        rim[a].push_back(d), rim[b].push_back(d);
      }
  }
  for (auto& [v, directions] : rim) {
    NodeConstraint& c = out[index_cast<std::size_t>(v)];
    const Point d = directions.front();
    const bool straight = std::all_of(directions.begin(), directions.end(), [&](const Point& e) {
      return d.cross(e).norm() <= kParallel;
    });
    if (!straight || c.kind == NodeConstraint::Kind::kFixed) {
      c = NodeConstraint::fixed();
    } else if (c.kind == NodeConstraint::Kind::kFree ||
               (c.kind == NodeConstraint::Kind::kPlane &&
                std::abs(c.direction.normalized().dot(d)) <= kParallel)) {
      c = NodeConstraint::line(p[index_cast<std::size_t>(v)], d);
    } else if (!(c.kind == NodeConstraint::Kind::kLine &&
                 c.direction.normalized().cross(d).norm() <= kParallel)) {
      c = NodeConstraint::fixed();
    }
  }
  // A node set's node slides only within its set, so that the set keeps its place: in its
  // plane where every surface quad through it there is the set's (a surface the set covers: a
  // boundary condition's face), along its line where its neighbours on the line both are (a
  // curve the set runs along); a point load, a curve's end, a surface's rim, or a node inside
  // the model stays.
  if (kept.node_sets.empty()) return out;
  using Kind = NodeConstraint::Kind;
  // Per set node on a line: its neighbours along the line, with their side (one scan of the
  // hexes for every set).
  std::vector<char> in_any(p.size(), 0);
  for (const auto& nodes : kept.node_sets)
    for (Index v : nodes) in_any[index_cast<std::size_t>(v)] = 1;
  std::unordered_map<Index, std::vector<std::pair<Index, int>>> on_line;
  for (const auto& h : mesh.hexes)
    for (const auto& e : topology::kHexEdgeCorners)
      for (const auto& [x, y] : {std::pair{h[e[0]], h[e[1]]}, std::pair{h[e[1]], h[e[0]]}}) {
        const NodeConstraint& c = out[index_cast<std::size_t>(x)];
        if (!in_any[index_cast<std::size_t>(x)] || c.kind != Kind::kLine) continue;
        const Point d = (p[y] - p[x]).normalized(), u = c.direction.normalized();
        if (d.cross(u).norm() <= kParallel) on_line[x].emplace_back(y, d.dot(u) > 0 ? 0 : 1);
      }
  std::vector<char> in_set(p.size(), 0), leaves(p.size(), 0);
  std::vector<Index> fix;  // decided against the constraints as boundary and surfaces made them
  for (const auto& nodes : kept.node_sets) {
    for (Index v : nodes) in_set[index_cast<std::size_t>(v)] = 1;
    const auto set = [&](Index v) { return in_set[index_cast<std::size_t>(v)] != 0; };
    for (const BoundaryQuad& q : surfaces) {
      if (std::none_of(q.nodes.begin(), q.nodes.end(), set) ||
          std::all_of(q.nodes.begin(), q.nodes.end(), set))
        continue;
      const Point n = (p[q.nodes[2]] - p[q.nodes[0]]).cross(p[q.nodes[3]] - p[q.nodes[1]]);
      for (Index v : q.nodes) {
        const NodeConstraint& c = out[index_cast<std::size_t>(v)];
        if (set(v) && c.kind == Kind::kPlane && n.norm() > 0.0 &&
            n.normalized().cross(c.direction.normalized()).norm() <= kParallel)
          leaves[index_cast<std::size_t>(v)] = 1;
      }
    }
    for (Index v : nodes) {
      const auto i = index_cast<std::size_t>(v);
      std::array<bool, 2> along{false, false};
      if (const auto it = on_line.find(v); it != on_line.end())
        for (const auto& [y, side] : it->second) along[index_cast<std::size_t>(side)] |= set(y);
      if (out[i].kind == Kind::kFree || (out[i].kind == Kind::kPlane && leaves[i]) ||
          (out[i].kind == Kind::kLine && !(along[0] && along[1])))
        fix.push_back(v);
    }
    for (Index v : nodes)
      in_set[index_cast<std::size_t>(v)] = leaves[index_cast<std::size_t>(v)] = 0;
  }
  for (Index v : fix) out[index_cast<std::size_t>(v)] = NodeConstraint::fixed();
  return out;
}

}  // namespace

LocalSmoothResult smooth_hexes_around(HexMesh& mesh, std::span<const Index> seeds,
                                      const LocalSmoothOptions& options, const SmoothStart* start) {
  for (Index s : seeds)
    if (s < 0 || index_cast<std::size_t>(s) >= mesh.hexes.size())
      throw InvalidInput("smooth_hexes_around: seed hex " + std::to_string(s) + " out of range");
  if (start && (start->scaled_jacobian.size() != mesh.hexes.size() ||
                start->shortest_edge.size() != mesh.hexes.size()))
    throw InvalidInput("smooth_hexes_around: the start values are not one per hex");
  if (seeds.empty()) return {};
  std::vector<Index> sorted(seeds.begin(), seeds.end());
  std::sort(sorted.begin(), sorted.end());
  const std::vector<Index> region = hexes_around(mesh, seeds);  // hexes a patch can change
  const std::vector<Index> outer =
      hexes_around(mesh, region);  // every hex sharing a face with them
  // The submesh of `outer`, nodes numbered in order of first use.
  HexMesh sub;
  std::vector<Index> local(mesh.points.size(), kInvalidIndex), global;
  sub.hexes.reserve(outer.size());
  for (Index h : outer) {
    std::array<Index, 8> c{};
    for (int k = 0; k < 8; ++k) {
      Index& l = local[mesh.hexes[h][k]];
      if (l == kInvalidIndex) l = index_cast(global.size()), global.push_back(mesh.hexes[h][k]);
      c[k] = l;
    }
    sub.hexes.push_back(c);
    if (!mesh.block.empty()) sub.block.push_back(mesh.block[index_cast<std::size_t>(h)]);
  }
  sub.points.reserve(global.size());
  for (Index g : global) sub.points.push_back(mesh.points[g]);
  // Only the seeds' nodes move; the rest of the submesh is there to be measured. Their
  // constraints come from the faces through them, whose hexes all hold a seed node, so are in
  // the region: a face of one is on the model's boundary iff it is on the submesh's, and one
  // between two blocks is one of the model's.
  std::vector<char> moves(sub.points.size(), 0);
  for (Index s : seeds)
    for (Index v : mesh.hexes[s]) moves[local[v]] = 1;
  std::vector<Index> sub_region;
  sub_region.reserve(region.size());
  {
    std::size_t r = 0;
    for (std::size_t i = 0; i < outer.size(); ++i) {
      while (r < region.size() && region[r] < outer[i]) ++r;
      if (r < region.size() && region[r] == outer[i]) sub_region.push_back(index_cast(i));
    }
  }
  // The kept features in submesh numbers: the surfaces' quads with a node that moves (every
  // node of such a quad is in the submesh, its hex being in the region), so that every quad of a
  // surface through a moving node is there and its rim through that node is told right.
  KeptFeatures kept;
  if (options.kept) {
    const auto sub_node = [&](Index v) {
      if (v < 0 || index_cast<std::size_t>(v) >= local.size())
        throw InvalidInput("smooth_hexes_around: kept node " + std::to_string(v) + " out of range");
      return local[index_cast<std::size_t>(v)];
    };
    const auto moving = [&](Index l) { return l != kInvalidIndex && moves[l]; };
    for (const auto& surface : options.kept->surfaces) {
      std::vector<std::array<Index, 4>> near;
      for (const auto& q : surface) {
        std::array<Index, 4> l{};
        for (int k = 0; k < 4; ++k) l[k] = sub_node(q[k]);
        if (std::any_of(l.begin(), l.end(), moving) &&
            std::none_of(l.begin(), l.end(), [](Index x) { return x == kInvalidIndex; }))
          near.push_back(l);
      }
      if (!near.empty()) kept.surfaces.push_back(std::move(near));
    }
    for (const auto& nodes : options.kept->node_sets) {
      std::vector<Index> near;
      for (Index v : nodes)
        if (const Index l = sub_node(v); l != kInvalidIndex) near.push_back(l);
      if (std::any_of(near.begin(), near.end(), moving)) kept.node_sets.push_back(std::move(near));
    }
  }
  auto constraints = slide_constraints(sub, surface_quads_at(sub, sub_region, moves), kept);
  std::vector<Index> local_seeds;
  local_seeds.reserve(seeds.size());
  for (std::size_t i = 0; i < outer.size(); ++i)
    if (std::binary_search(sorted.begin(), sorted.end(), outer[i]))
      local_seeds.push_back(index_cast(i));
  for (std::size_t v = 0; v < constraints.size(); ++v)
    if (!moves[v]) constraints[v] = NodeConstraint::fixed();
  SmoothStart sub_start;
  if (start)
    for (Index h : outer) {
      sub_start.scaled_jacobian.push_back(start->scaled_jacobian[index_cast<std::size_t>(h)]);
      sub_start.shortest_edge.push_back(start->shortest_edge[index_cast<std::size_t>(h)]);
    }
  LocalSmoothOptions sub_options = options;
  auto restrict_to_outer = [&](std::vector<double>& per_hex) {
    if (per_hex.empty()) return;
    if (per_hex.size() != mesh.hexes.size())
      throw InvalidInput("smooth_hexes_around: the per-hex targets or goals are not one per hex");
    std::vector<double> sub_values;
    sub_values.reserve(outer.size());
    for (Index h : outer) sub_values.push_back(per_hex[index_cast<std::size_t>(h)]);
    per_hex = std::move(sub_values);
  };
  restrict_to_outer(sub_options.hex_targets);
  restrict_to_outer(sub_options.hex_goals);
  LocalSmoothResult res = smooth_hexes_local(sub, constraints, nullptr, local_seeds, sub_options,
                                             start ? &sub_start : nullptr);
  for (std::size_t v = 0; v < global.size(); ++v)
    if (moves[v]) mesh.points[global[v]] = sub.points[v];
  res.region = region;
  return res;
}

std::vector<BoundaryQuad> material_surface_quads(const HexMesh& mesh) {
  std::vector<BoundaryQuad> out = boundary_quads(mesh);
  const std::vector<BoundaryQuad> between = block_interface_quads(mesh);
  out.insert(out.end(), between.begin(), between.end());
  return out;
}

std::vector<NodeConstraint> boundary_slide_constraints(const HexMesh& mesh) {
  return boundary_slide_constraints(mesh, material_surface_quads(mesh));
}

std::vector<NodeConstraint> boundary_slide_constraints(const HexMesh& mesh,
                                                       std::span<const BoundaryQuad> surfaces) {
  const auto& p = mesh.points;
  std::vector<NodeConstraint> out(p.size());
  // Per node, the unit normals of its surface quads; a warped quad (corners off one plane)
  // fixes its nodes: any move of a corner would change the bilinear surface it spans.
  std::vector<std::vector<Point>> normals(p.size());
  std::vector<char> fixed(p.size(), 0);
  constexpr double kFlat = 1e-9;      // corner off the quad's plane, relative to its diagonals
  constexpr double kParallel = 1e-9;  // |n1 x n2| of two normals taken as one plane
  for (const BoundaryQuad& q : surfaces) {
    const Point d0 = p[q.nodes[2]] - p[q.nodes[0]], d1 = p[q.nodes[3]] - p[q.nodes[1]];
    const Point n = d0.cross(d1);
    const double scale = std::max(d0.norm(), d1.norm());
    bool flat = n.norm() > 0.0;
    if (flat) {
      const Point u = n.normalized();
      const Point c = 0.25 * (p[q.nodes[0]] + p[q.nodes[1]] + p[q.nodes[2]] + p[q.nodes[3]]);
      for (Index v : q.nodes) flat = flat && std::abs((p[v] - c).dot(u)) <= kFlat * scale;
    }
    for (Index v : q.nodes) {
      if (!flat)
        fixed[v] = 1;
      else
        normals[v].push_back(n.normalized());
    }
  }
  for (std::size_t v = 0; v < normals.size(); ++v) {
    if (fixed[v]) {
      out[v] = NodeConstraint::fixed();
      continue;
    }
    if (normals[v].empty()) continue;
    // The distinct planes through the node (normals parallel either way: an interface quad is
    // oriented by one of its two hexes).
    std::vector<Point> planes;
    for (const Point& n : normals[v])
      if (std::none_of(planes.begin(), planes.end(),
                       [&](const Point& m) { return m.cross(n).norm() <= kParallel; }))
        planes.push_back(n);
    if (planes.size() == 1)
      out[v] = NodeConstraint::plane(p[v], planes[0]);
    else if (planes.size() == 2)
      out[v] = NodeConstraint::line(p[v], planes[0].cross(planes[1]).normalized());
    else
      out[v] = NodeConstraint::fixed();
  }
  return out;
}

std::vector<NodeConstraint> kept_slide_constraints(const HexMesh& mesh, const KeptFeatures& kept) {
  const auto check = [&](Index v) {
    if (v < 0 || index_cast<std::size_t>(v) >= mesh.points.size())
      throw InvalidInput("kept_slide_constraints: node " + std::to_string(v) + " out of range");
  };
  for (const auto& surface : kept.surfaces)
    for (const auto& q : surface)
      for (Index v : q) check(v);
  for (const auto& nodes : kept.node_sets)
    for (Index v : nodes) check(v);
  return slide_constraints(mesh, material_surface_quads(mesh), kept);
}

TriMesh boundary_triangulation(const HexMesh& mesh) {
  return boundary_triangulation(mesh.points, boundary_quads(mesh));
}

TriMesh boundary_triangulation(const std::vector<Point>& points,
                               std::span<const BoundaryQuad> boundary) {
  TriMesh t;
  t.points = points;
  for (const BoundaryQuad& q : boundary) {
    t.tris.push_back({q.nodes[0], q.nodes[1], q.nodes[2]});
    t.tris.push_back({q.nodes[0], q.nodes[2], q.nodes[3]});
  }
  return t;
}

std::vector<Index> hexes_around(const HexMesh& mesh, std::span<const Index> hexes) {
  std::vector<char> node(mesh.points.size(), 0);
  for (Index h : hexes)
    for (Index v : mesh.hexes[h]) node[v] = 1;
  std::vector<Index> out;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    if (std::any_of(mesh.hexes[h].begin(), mesh.hexes[h].end(), [&](Index v) { return node[v]; }))
      out.push_back(index_cast(h));
  return out;
}

}  // namespace geode::primal
