#include <geode/stc/arrangement.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <sstream>

#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include <geode/stc/detail/arrangement_engine.hpp>

namespace geode::stc {

std::string format_point(const Point& x, int dim) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << x[0] << ", " << x[1];
  if (dim == 3) s << ", " << x[2];
  s << ")";
  return s.str();
}

namespace detail {

Domain make_cell_domain(const std::array<Point, 8>& P, int dim, bool pyramid) {
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
  check_lone_pieces(A.curves);

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
          " was found " + std::to_string(v.found) + " times on its " + std::to_string(dim_) +
          " curves (once on each): part of a curve was missed or traced twice (raise the seed "
          "resolution: geode arrange --seed-resolution) or the sheets are not in general "
          "position");

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
    // Step into each octant along the direction that moves every sheet of the vertex by the
    // same distance: the gradients normalized first, since fields are scaled arbitrarily (a
    // plane's gradient is 1, a tunnel's 1 / its size). Unnormalized, the step runs nearly along
    // the sheet with the steeper field, whose curvature can then put the sample on its other
    // side (on boxes a few 1e-4 across: refine3).
    Eigen::MatrixXd J =
        jacobians_[primal::index_cast<std::size_t>(order[primal::index_cast<std::size_t>(v)])];
    for (int i = 0; i < dim_; ++i) J.row(i).normalize();
    const Eigen::MatrixXd Jinv = J.inverse();
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

}  // namespace detail

using detail::make_cell_domain;
using detail::multilinear;

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
  return detail::Engine(sheets, domain, options).run();
}

}  // namespace geode::stc
