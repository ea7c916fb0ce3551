#include <geode/stc/mesh_fields.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <limits>
#include <memory>
#include <string>

#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/multilinear.hpp>
#include <geode/primal/topology.hpp>

namespace geode::stc {
namespace {

namespace topo = primal::topology;
using primal::Index;

template <int Dim>
using CellArray = std::array<Index, std::size_t{1} << Dim>;

// The cell holding a point, and its local coordinates under the cell's multilinear map.
template <int Dim>
class CellLocator {
 public:
  static constexpr int kCorners = 1 << Dim;
  using Vec = Eigen::Matrix<double, Dim, 1>;
  using Mat = Eigen::Matrix<double, Dim, Dim>;

  struct Hit {
    Index cell = primal::kInvalidIndex;
    Vec u = Vec::Zero();
  };

  CellLocator(const std::vector<Point>& points, const std::vector<CellArray<Dim>>& cells)
      : points_(points), cells_(cells) {
    // NaN never compares equal: an empty cache slot matches no point.
    for (auto& entry : cache_)
      entry.first = Vec::Constant(std::numeric_limits<double>::quiet_NaN());
    lo_ = Vec::Constant(1e300);
    hi_ = Vec::Constant(-1e300);
    for (const auto& c : cells_)
      for (Index n : c) {
        lo_ = lo_.cwiseMin(points_[primal::index_cast<std::size_t>(n)].template head<Dim>());
        hi_ = hi_.cwiseMax(points_[primal::index_cast<std::size_t>(n)].template head<Dim>());
      }
    scale_ = std::max((hi_ - lo_).norm(), 1e-300);
    // About one or two cells per bucket along each axis.
    const double per_axis = std::pow(static_cast<double>(cells_.size()), 1.0 / Dim);
    for (int a = 0; a < Dim; ++a)
      n_[a] = std::clamp(static_cast<int>(std::lround(1.5 * per_axis)), 1, 64);
    std::size_t buckets = 1;
    for (int a = 0; a < Dim; ++a) buckets *= primal::index_cast<std::size_t>(n_[a]);
    buckets_.resize(buckets);
    const double pad = 1e-9 * scale_;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      Vec blo = Vec::Constant(1e300), bhi = Vec::Constant(-1e300);
      for (Index n : cells_[c]) {
        blo = blo.cwiseMin(points_[primal::index_cast<std::size_t>(n)].template head<Dim>());
        bhi = bhi.cwiseMax(points_[primal::index_cast<std::size_t>(n)].template head<Dim>());
      }
      box_lo_.push_back(blo - Vec::Constant(pad));
      box_hi_.push_back(bhi + Vec::Constant(pad));
      const auto a = bucket_coords(box_lo_.back()), b = bucket_coords(box_hi_.back());
      for_each_bucket(a, b, [&](std::size_t id) { buckets_[id].push_back(primal::index_cast(c)); });
    }
  }

  static Point local(const Vec& u) {
    Point r = Point::Zero();
    r.template head<Dim>() = u;
    return r;
  }
  static double shape(int c, const Vec& u) { return primal::multilinear_shape(c, local(u), Dim); }

  // The cell's map (primal/multilinear.hpp) at u, and its Jacobian.
  Vec map(Index cell, const Vec& u, Mat* jacobian = nullptr) const {
    std::array<Point, kCorners> P;
    for (int c = 0; c < kCorners; ++c)
      P[primal::index_cast<std::size_t>(c)] = points_[primal::index_cast<std::size_t>(
          cells_[primal::index_cast<std::size_t>(cell)][primal::index_cast<std::size_t>(c)])];
    if (jacobian)
      *jacobian = primal::multilinear_jacobian(P, local(u), Dim).template topLeftCorner<Dim, Dim>();
    return primal::multilinear_point(P, local(u), Dim).template head<Dim>();
  }

  // Local coordinates of x in `cell` by Newton's method, kept within a margin of the cell so
  // that a point far outside a distorted cell cannot send the iteration astray.
  // With `probe`, gives up early once x is clearly outside (the caller only asks "is x here?").
  Vec invert(Index cell, const Vec& x, bool probe) const {
    Vec u = Vec::Constant(0.5);
    for (int it = 0; it < 30; ++it) {
      Mat J;
      const Vec r = map(cell, u, &J) - x;
      const Vec du = J.inverse() * r;  // closed form for 2 x 2 and 3 x 3
      if (!du.allFinite()) break;
      u = (u - du).cwiseMax(-1.0).cwiseMin(2.0);
      if (du.norm() < 1e-13) break;
      if (probe && it >= 2 && outside(u) > 0.25) break;
    }
    return u;
  }

  static double outside(const Vec& u) {
    return std::max(0.0, std::max((-u).maxCoeff(), (u - Vec::Ones()).maxCoeff()));
  }

  Hit locate(const Point& p) const {
    const Vec x = p.template head<Dim>();
    // A diverged iterate: no cell, and the field's value is NaN (the engine rejects it).
    if (!x.allFinite()) return {0, Vec::Constant(std::numeric_limits<double>::quiet_NaN())};
    // Every sheet is evaluated at the same points (values, finite-difference probes, every
    // point of a traced curve once per other sheet): a direct-mapped cache keyed by the exact
    // coordinates.
    std::size_t key = 0;
    for (int a = 0; a < Dim; ++a) {
      std::uint64_t bits;
      std::memcpy(&bits, &x[a], sizeof bits);
      key = (key ^ static_cast<std::size_t>(bits)) * 0x9E3779B97F4A7C15ull;
    }
    auto& slot = cache_[(key >> 40) % cache_.size()];
    if (slot.first == x) return slot.second;
    Hit best;
    double best_out = 1e300;
    auto consider = [&](Index c, bool probe) {
      const Vec u = invert(c, x, probe);
      // Newton may stall (clamped) at a wrong u inside the cell: a cell counts only where its
      // map reaches x.
      const double miss = (map(c, u) - x).norm() / scale_;
      const double o = miss > 1e-10 ? 1.0 + miss : outside(u);
      if (o < best_out) best_out = o, best = {c, u};
      return best_out <= 1e-12;
    };
    auto in_box = [&](Index c) {
      const auto i = primal::index_cast<std::size_t>(c);
      return (x.array() >= box_lo_[i].array()).all() && (x.array() <= box_hi_[i].array()).all();
    };
    // Points come in runs along a curve: the last cell first, then the bucket's cells.
    bool found = last_ != primal::kInvalidIndex && in_box(last_) && consider(last_, true);
    for (Index c : buckets_[bucket_id(bucket_coords(x))]) {
      if (found) break;
      if (in_box(c)) found = consider(c, true);
    }
    if (!found) {
      // Off the mesh (a probe or a Newton iterate outside the box): the nearest cells' maps,
      // extended; the one that needs the least extension wins.
      std::vector<double> gap(cells_.size());
      double nearest = 1e300;
      for (std::size_t c = 0; c < cells_.size(); ++c) {
        gap[c] = ((box_lo_[c] - x).cwiseMax(x - box_hi_[c])).cwiseMax(0.0).norm();
        nearest = std::min(nearest, gap[c]);
      }
      for (std::size_t c = 0; c < cells_.size(); ++c)
        if (gap[c] <= nearest + 1e-6 * scale_) consider(primal::index_cast(c), false);
    }
    last_ = best.cell;
    slot = {x, best};
    return best;
  }

 private:
  std::array<int, Dim> bucket_coords(const Vec& x) const {
    std::array<int, Dim> b{};
    for (int a = 0; a < Dim; ++a) {
      const double t = (x[a] - lo_[a]) / std::max(hi_[a] - lo_[a], 1e-300);
      // Clamped as a double: a point far off the mesh must not overflow the int cast.
      b[a] = static_cast<int>(std::clamp(std::floor(t * n_[a]), 0.0, n_[a] - 1.0));
    }
    return b;
  }
  std::size_t bucket_id(const std::array<int, Dim>& b) const {
    std::size_t id = 0;
    for (int a = Dim - 1; a >= 0; --a)
      id = id * primal::index_cast<std::size_t>(n_[a]) + primal::index_cast<std::size_t>(b[a]);
    return id;
  }
  template <class F>
  void for_each_bucket(const std::array<int, Dim>& a, const std::array<int, Dim>& b, F f) const {
    std::array<int, Dim> i = a;
    while (true) {
      f(bucket_id(i));
      int k = 0;
      while (k < Dim && ++i[k] > b[k]) i[k] = a[k], ++k;
      if (k == Dim) return;
    }
  }

  const std::vector<Point>& points_;
  const std::vector<CellArray<Dim>>& cells_;
  Vec lo_, hi_;
  double scale_ = 1.0;
  std::array<int, Dim> n_{};
  std::vector<std::vector<Index>> buckets_;
  std::vector<Vec> box_lo_, box_hi_;  // per cell, padded
  mutable Index last_ = primal::kInvalidIndex;
  mutable std::vector<std::pair<Vec, Hit>> cache_ = std::vector<std::pair<Vec, Hit>>(4096);
};

// What the fields of one mesh share: a copy of the mesh, its locator and the nodal values.
template <int Dim>
struct MeshFieldData {
  std::vector<Point> points;
  std::vector<CellArray<Dim>> cells;
  std::unique_ptr<CellLocator<Dim>> locator;
  std::vector<std::vector<double>> values;  // per sheet, per node
};

const char* cell_word(int dim) { return dim == 3 ? "hex" : "quad"; }

// make_classifier(lo, hi, tol): stc::box_face_classifier for the mesh at hand.
template <int Dim, class Dual, class MakeClassifier>
MeshArrangementInput build(const std::vector<Point>& points,
                           const std::vector<CellArray<Dim>>& cells, const Dual& dual,
                           MakeClassifier make_classifier) {
  constexpr int kCorners = 1 << Dim;
  if (cells.empty())
    throw InvalidInput(std::string("sheet_fields: the mesh has no ") + cell_word(Dim) + "es");
  auto data = std::make_shared<MeshFieldData<Dim>>();
  data->points = points;
  data->cells = cells;
  data->locator = std::make_unique<CellLocator<Dim>>(data->points, data->cells);
  const CellLocator<Dim>& loc = *data->locator;

  const std::size_t nn = points.size();
  // Node adjacency with each edge's sheet, built once: per sheet, the walks skip its own edges.
  std::vector<std::vector<std::pair<Index, Index>>> adjacent(nn);
  for (std::size_t e = 0; e < dual.edges.size(); ++e) {
    const auto& E = dual.edges[e];
    adjacent[primal::index_cast<std::size_t>(E[0])].emplace_back(E[1], dual.edge_sheet[e]);
    adjacent[primal::index_cast<std::size_t>(E[1])].emplace_back(E[0], dual.edge_sheet[e]);
  }
  MeshArrangementInput out;
  for (std::size_t s = 0; s < dual.sheets.size(); ++s) {
    const MeshSheet& sheet = dual.sheets[s];
    const std::string who = "sheet_fields: sheet " + std::to_string(s);
    if (sheet.self_intersecting) {
      // A cell it crosses itself in is listed twice (cells ascend); the first cell it crosses
      // was named, which need not be one (a hunt's: quad 0 for a crossing in quad 184).
      const auto twice = std::adjacent_find(sheet.cells.begin(), sheet.cells.end());
      throw TopologyError(who + " crosses itself (in " + cell_word(Dim) + " " +
                          std::to_string(twice == sheet.cells.end() ? -1 : *twice) +
                          " and maybe others): it has no two sides to give a field");
    }
    // Sides: the nodes joined by edges of other sheets.
    primal::DisjointSets sides(nn);
    for (std::size_t e = 0; e < dual.edges.size(); ++e)
      if (dual.edge_sheet[e] != primal::index_cast(s))
        sides.unite(dual.edges[e][0], dual.edges[e][1]);
    for (Index e : sheet.edges) {
      const auto& E = dual.edges[primal::index_cast<std::size_t>(e)];
      if (sides.find(E[0]) == sides.find(E[1]))
        throw TopologyError(who + " does not separate the mesh: the ends of its edge " +
                            std::to_string(E[0]) + "-" + std::to_string(E[1]) +
                            " are joined by edges of other sheets");
    }
    const Index first =
        sides.find(dual.edges[primal::index_cast<std::size_t>(sheet.edges.front())][0]);
    const Index second =
        sides.find(dual.edges[primal::index_cast<std::size_t>(sheet.edges.front())][1]);
    // Layers: breadth-first over edges of other sheets from the nodes ending an S edge.
    std::vector<int> layer(nn, -1);
    std::deque<Index> queue;
    for (Index e : sheet.edges)
      for (Index n : dual.edges[primal::index_cast<std::size_t>(e)])
        if (layer[primal::index_cast<std::size_t>(n)] < 0)
          layer[primal::index_cast<std::size_t>(n)] = 1, queue.push_back(n);
    while (!queue.empty()) {
      const Index n = queue.front();
      queue.pop_front();
      for (const auto& [m, sheet_of_edge] : adjacent[primal::index_cast<std::size_t>(n)])
        if (sheet_of_edge != primal::index_cast(s) &&
            layer[primal::index_cast<std::size_t>(m)] < 0) {
          layer[primal::index_cast<std::size_t>(m)] = layer[primal::index_cast<std::size_t>(n)] + 1;
          queue.push_back(m);
        }
    }
    std::vector<double> value(nn, 0.0);
    for (std::size_t n = 0; n < nn; ++n) {
      if (layer[n] < 0) continue;  // a node of no cell
      const Index root = sides.find(primal::index_cast(n));
      if (root != first && root != second)
        throw TopologyError(who + " leaves node " + std::to_string(n) +
                            " on neither of its two sides (the mesh is not connected)");
      value[n] = (root == first ? -1.0 : 1.0) * layer[n];
    }
    data->values.push_back(std::move(value));
    const std::size_t id = data->values.size() - 1;
    Field f = [data, id](const Point& x) {
      const auto hit = data->locator->locate(x);
      const auto& cell = data->cells[primal::index_cast<std::size_t>(hit.cell)];
      const auto& v = data->values[id];
      double r = 0.0;
      for (int c = 0; c < kCorners; ++c)
        r += CellLocator<Dim>::shape(c, hit.u) *
             v[primal::index_cast<std::size_t>(cell[primal::index_cast<std::size_t>(c)])];
      return r;
    };
    out.sheets.push_back({"sheet " + std::to_string(s), std::move(f), "mesh"});
  }
  // Cells must be positively oriented at every corner: the inverse map and the sides of a
  // sheet inside a cell rely on it.
  for (std::size_t c = 0; c < cells.size(); ++c)
    for (int k = 0; k < kCorners; ++k) {
      typename CellLocator<Dim>::Vec u;
      for (int a = 0; a < Dim; ++a)
        u[a] = topo::kHexCornerCoords[primal::index_cast<std::size_t>(k)]
                                     [primal::index_cast<std::size_t>(a)];
      typename CellLocator<Dim>::Mat J;
      loc.map(primal::index_cast(c), u, &J);
      if (!(J.determinant() > 0.0))
        throw InvalidInput(std::string("sheet_fields: ") + cell_word(Dim) + " " +
                           std::to_string(c) + " is inverted or flat at its corner " +
                           std::to_string(k) + " (Jacobian " + std::to_string(J.determinant()) +
                           "); place the nodes first");
    }

  // The mesh must fill its bounding box: every boundary facet on a box face.
  Point lo = Point::Constant(1e300), hi = Point::Constant(-1e300);
  for (const auto& cell : cells)
    for (Index n : cell) {
      lo = lo.cwiseMin(points[primal::index_cast<std::size_t>(n)]);
      hi = hi.cwiseMax(points[primal::index_cast<std::size_t>(n)]);
    }
  if (Dim == 2) lo[2] = hi[2] = 0.0;
  const FacetClassifier classify = make_classifier(lo, hi, 1e-9 * (hi - lo).norm());
  for (const CellFacet& f : dual.boundary) {
    const bool on = classify(f) >= 0;
    if (!on)
      throw InvalidInput(
          std::string("sheet_fields: boundary ") + (Dim == 3 ? "face " : "edge ") +
          std::to_string(f.local) + " of " + cell_word(Dim) + " " + std::to_string(f.cell) +
          " lies on no face of the bounding box: the arrangement domain is a box, so the "
          "mesh must fill one");
  }

  out.domain = Domain{lo, hi, Dim};
  return out;
}

}  // namespace

MeshArrangementInput sheet_fields(const primal::HexMesh& mesh) {
  return build<3>(mesh.points, mesh.hexes, mesh_dual(mesh),
                  [&](const Point& lo, const Point& hi, double tol) {
                    return box_face_classifier(mesh, lo, hi, tol);
                  });
}

MeshArrangementInput sheet_fields(const primal::QuadMesh& mesh) {
  return build<2>(mesh.points, mesh.quads, mesh_dual(mesh),
                  [&](const Point& lo, const Point& hi, double tol) {
                    return box_face_classifier(mesh, lo, hi, tol);
                  });
}

}  // namespace geode::stc
