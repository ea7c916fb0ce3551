#include <geode/stc/sheet_surfaces.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>

namespace geode::stc {
namespace {

using primal::Index;

// Marching simplices over a regular grid on [0, 1]^dim (the domain's local coordinates).
// Cubes are split into the 6 Kuhn tetrahedra along their main diagonal (squares into 2
// triangles), which match across shared faces, so the zero set comes out without cracks.
class GridContour {
 public:
  GridContour(const Domain& domain, const ContourOptions& options)
      : domain_(domain), options_(options) {
    if (options.resolution < 2) throw InvalidInput("contour: resolution must be at least 2");
    const int dim = domain.dim;
    const Point extent = domain.hi - domain.lo;
    double longest = 0;
    for (int a = 0; a < dim; ++a) longest = std::max(longest, extent[a]);
    if (!(longest > 0)) throw InvalidInput("contour: the domain is empty");
    for (int a = 0; a < 3; ++a)
      n_[a] =
          a < dim
              ? std::max(2, static_cast<int>(std::lround(options.resolution * extent[a] / longest)))
              : 0;
    // Kuhn simplices: a path from corner 0 to the opposite corner, one axis at a time.
    std::array<int, 3> axes{0, 1, 2};
    do {
      std::array<int, 4> s{0, 0, 0, 0};
      for (int k = 0; k < dim; ++k)
        s[primal::index_cast<std::size_t>(k + 1)] =
            s[primal::index_cast<std::size_t>(k)] | (1 << axes[primal::index_cast<std::size_t>(k)]);
      simplices_.push_back(s);
    } while (std::next_permutation(axes.begin(), axes.begin() + dim));
  }

  // Zero set of one field: triangles (dim 3) or segments (dim 2) into points / cells.
  void run(const Field& f, std::vector<Point>& points, std::vector<std::array<Index, 3>>* tris,
           std::vector<std::array<Index, 2>>* segs) {
    const int dim = domain_.dim;
    const std::size_t nodes =
        primal::index_cast<std::size_t>(n_[0] + 1) * (n_[1] + 1) * (dim == 3 ? n_[2] + 1 : 1);
    values_.assign(nodes, 0.0);
    for (std::size_t i = 0; i < nodes; ++i) values_[i] = f(domain_point(domain_, local(i)));
    edge_vertex_.clear();
    const int nz = dim == 3 ? n_[2] : 1;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < n_[1]; ++j)
        for (int i = 0; i < n_[0]; ++i)
          for (const auto& s : simplices_) {
            std::array<std::size_t, 4> g{};
            for (int c = 0; c <= dim; ++c) {
              const int b = s[primal::index_cast<std::size_t>(c)];
              g[primal::index_cast<std::size_t>(c)] =
                  node(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
            }
            simplex(f, g, points, tris, segs);
          }
  }

 private:
  std::size_t node(int i, int j, int k) const {
    return (primal::index_cast<std::size_t>(k) * (n_[1] + 1) + primal::index_cast<std::size_t>(j)) *
               (n_[0] + 1) +
           primal::index_cast<std::size_t>(i);
  }
  Point local(std::size_t id) const {
    const std::size_t nx = primal::index_cast<std::size_t>(n_[0] + 1),
                      ny = primal::index_cast<std::size_t>(n_[1] + 1);
    Point r = Point::Zero();
    r[0] = static_cast<double>(id % nx) / n_[0];
    r[1] = static_cast<double>((id / nx) % ny) / n_[1];
    if (domain_.dim == 3) r[2] = static_cast<double>(id / (nx * ny)) / n_[2];
    return r;
  }

  // The vertex where the zero set crosses grid edge (a, b), shared by every simplex on it:
  // linear estimate, then the Illinois variant of regula falsi on the field along the edge
  // (the bracket is kept, and an end that stays put has its value halved so that it converges).
  Index edge_vertex(const Field& f, std::size_t a, std::size_t b, std::vector<Point>& points) {
    if (a > b) std::swap(a, b);
    const std::uint64_t key = static_cast<std::uint64_t>(a) * values_.size() + b;
    const auto it = edge_vertex_.find(key);
    if (it != edge_vertex_.end()) return it->second;
    const Point ra = local(a), rb = local(b);
    double t0 = 0, t1 = 1, f0 = values_[a], f1 = values_[b];
    double t = f0 / (f0 - f1);
    int kept = 0;  // which end stayed last time: -1 t0, +1 t1
    for (int s = 0; s < options_.refine_steps && f0 != f1; ++s) {
      t = t0 + (t1 - t0) * f0 / (f0 - f1);
      const double ft = f(domain_point(domain_, ra + t * (rb - ra)));
      if (ft == 0) break;
      if ((ft < 0) == (f0 < 0)) {
        t0 = t, f0 = ft;
        if (kept == 1) f1 *= 0.5;
        kept = 1;
      } else {
        t1 = t, f1 = ft;
        if (kept == -1) f0 *= 0.5;
        kept = -1;
      }
    }
    const Index v = primal::index_cast(points.size());
    points.push_back(domain_point(domain_, ra + t * (rb - ra)));
    edge_vertex_.emplace(key, v);
    return v;
  }

  void simplex(const Field& f, const std::array<std::size_t, 4>& g, std::vector<Point>& points,
               std::vector<std::array<Index, 3>>* tris, std::vector<std::array<Index, 2>>* segs) {
    const int dim = domain_.dim;
    std::array<std::size_t, 4> neg{}, pos{};
    int nn = 0, np = 0;
    for (int c = 0; c <= dim; ++c) {
      const std::size_t v = g[primal::index_cast<std::size_t>(c)];
      if (values_[v] < 0)
        neg[primal::index_cast<std::size_t>(nn++)] = v;
      else
        pos[primal::index_cast<std::size_t>(np++)] = v;
    }
    if (nn == 0 || np == 0) return;
    if (dim == 2) {
      const std::size_t lone = nn == 1 ? neg[0] : pos[0];
      const auto& others = nn == 1 ? pos : neg;
      segs->push_back(
          {edge_vertex(f, lone, others[0], points), edge_vertex(f, lone, others[1], points)});
      return;
    }
    // Normal towards the positive side: from the negative corners' centroid to the positive.
    Point towards = Point::Zero();
    for (int c = 0; c < np; ++c)
      towards += domain_point(domain_, local(pos[primal::index_cast<std::size_t>(c)])) / np;
    for (int c = 0; c < nn; ++c)
      towards -= domain_point(domain_, local(neg[primal::index_cast<std::size_t>(c)])) / nn;
    auto add = [&](Index a, Index b, Index c) {
      const Point n =
          (points[primal::index_cast<std::size_t>(b)] - points[primal::index_cast<std::size_t>(a)])
              .cross(points[primal::index_cast<std::size_t>(c)] -
                     points[primal::index_cast<std::size_t>(a)]);
      if (n.dot(towards) < 0) std::swap(b, c);
      tris->push_back({a, b, c});
    };
    if (nn == 1 || np == 1) {
      const std::size_t lone = nn == 1 ? neg[0] : pos[0];
      const auto& others = nn == 1 ? pos : neg;
      add(edge_vertex(f, lone, others[0], points), edge_vertex(f, lone, others[1], points),
          edge_vertex(f, lone, others[2], points));
      return;
    }
    // Two and two: the crossed edges form a quad n0p0, n0p1, n1p1, n1p0.
    const Index q0 = edge_vertex(f, neg[0], pos[0], points),
                q1 = edge_vertex(f, neg[0], pos[1], points);
    const Index q2 = edge_vertex(f, neg[1], pos[1], points),
                q3 = edge_vertex(f, neg[1], pos[0], points);
    add(q0, q1, q2);
    add(q0, q2, q3);
  }

  const Domain& domain_;
  ContourOptions options_;
  std::array<int, 3> n_{};
  std::vector<std::array<int, 4>> simplices_;
  std::vector<double> values_;
  std::unordered_map<std::uint64_t, Index> edge_vertex_;
};

// Position of each of a class's 4 hex edges around the sheet's quad: the edge's two
// coordinates off its axis, (0,0) (1,0) (1,1) (0,1), read from the corner table.
std::array<std::array<int, 4>, 3> quad_order() {
  std::array<std::array<int, 4>, 3> order{};
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 4; ++i) {
      const auto& c = primal::topology::kHexCornerCoords[primal::index_cast<std::size_t>(
          primal::topology::kHexEdgeCorners[primal::index_cast<std::size_t>(4 * k + i)][0])];
      const int u = c[primal::index_cast<std::size_t>((k + 1) % 3)],
                v = c[primal::index_cast<std::size_t>((k + 2) % 3)];
      const int slot = v == 0 ? u : 3 - u;  // (0,0) 0, (1,0) 1, (1,1) 2, (0,1) 3
      order[primal::index_cast<std::size_t>(k)][primal::index_cast<std::size_t>(slot)] = 4 * k + i;
    }
  return order;
}

// The midpoint of global edge e as a vertex of its sheet's mesh `out`, shared between cells.
// An edge lies in one sheet only, so one id per edge (`ids`, -1 until made) serves every sheet:
// a hash map per sheet took most of a million-hex mesh's surfaces.
template <class Out>
Index midpoint_vertex(const std::vector<Point>& nodes, const std::array<Index, 2>& edge, Index e,
                      std::vector<Index>& ids, Out& out) {
  Index& id = ids[primal::index_cast<std::size_t>(e)];
  if (id < 0) {
    id = primal::index_cast(out.points.size());
    out.points.push_back(0.5 * (nodes[primal::index_cast<std::size_t>(edge[0])] +
                                nodes[primal::index_cast<std::size_t>(edge[1])]));
  }
  return id;
}

}  // namespace

std::vector<primal::TriMesh> contour_sheets(const std::vector<Sheet>& sheets, const Domain& domain,
                                            const ContourOptions& options) {
  if (domain.dim != 3)
    throw InvalidInput("contour_sheets: a 3D domain is needed (contour_curves for 2D)");
  GridContour grid(domain, options);
  std::vector<primal::TriMesh> out(sheets.size());
  for (std::size_t s = 0; s < sheets.size(); ++s)
    grid.run(sheets[s].field, out[s].points, &out[s].tris, nullptr);
  return out;
}

std::vector<primal::SegmentMesh> contour_curves(const std::vector<Sheet>& sheets,
                                                const Domain& domain,
                                                const ContourOptions& options) {
  if (domain.dim != 2)
    throw InvalidInput("contour_curves: a 2D domain is needed (contour_sheets for 3D)");
  GridContour grid(domain, options);
  std::vector<primal::SegmentMesh> out(sheets.size());
  for (std::size_t s = 0; s < sheets.size(); ++s)
    grid.run(sheets[s].field, out[s].points, nullptr, &out[s].segments);
  return out;
}

namespace {

// DualSurfaceOptions::progress, every kEvery cells of `cells` and at the end.
void tell(const DualSurfaceOptions& options, std::size_t done, std::size_t cells) {
  constexpr std::size_t kEvery = 1 << 14;
  if (options.progress && (done % kEvery == 0 || done == cells)) options.progress(done, cells);
}

}  // namespace

std::vector<primal::TriMesh> dual_surfaces(const primal::HexMesh& mesh, const HexDual& dual,
                                           const DualSurfaceOptions& options) {
  static const auto order = quad_order();
  std::vector<primal::TriMesh> out(dual.sheets.size());
  std::vector<Index> ids(dual.edges.size(), -1);
  const std::size_t cells = dual.cell_sheets.size();
  for (std::size_t c = 0; c < cells; ++c) {
    tell(options, c, cells);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto s = primal::index_cast<std::size_t>(dual.cell_sheets[c][k]);
      std::array<Index, 4> q{};
      for (std::size_t i = 0; i < 4; ++i) {
        const Index e = dual.cell_edges[c][primal::index_cast<std::size_t>(order[k][i])];
        q[i] = midpoint_vertex(mesh.points, dual.edges[primal::index_cast<std::size_t>(e)], e, ids,
                               out[s]);
      }
      out[s].tris.push_back({q[0], q[1], q[2]});
      out[s].tris.push_back({q[0], q[2], q[3]});
    }
  }
  tell(options, cells, cells);
  return out;
}

std::vector<primal::SegmentMesh> dual_curves(const primal::QuadMesh& mesh, const QuadDual& dual,
                                             const DualSurfaceOptions& options) {
  std::vector<primal::SegmentMesh> out(dual.sheets.size());
  std::vector<Index> ids(dual.edges.size(), -1);
  const std::size_t cells = dual.cell_sheets.size();
  for (std::size_t c = 0; c < cells; ++c) {
    tell(options, c, cells);
    for (std::size_t k = 0; k < 2; ++k) {
      const auto s = primal::index_cast<std::size_t>(dual.cell_sheets[c][k]);
      const Index a = dual.cell_edges[c][k], b = dual.cell_edges[c][k + 2];  // opposite edges
      out[s].segments.push_back(
          {midpoint_vertex(mesh.points, dual.edges[primal::index_cast<std::size_t>(a)], a, ids,
                           out[s]),
           midpoint_vertex(mesh.points, dual.edges[primal::index_cast<std::size_t>(b)], b, ids,
                           out[s])});
    }
  }
  tell(options, cells, cells);
  return out;
}

template <int Dim>
std::vector<std::vector<Index>> sheet_layers(const MeshDual<Dim>& dual) {
  std::vector<std::vector<Index>> layers;
  layers.reserve(dual.sheets.size());
  for (const auto& s : dual.sheets) {
    std::vector<Index> cells = s.cells;  // ascending already; a self-crossing repeats a cell
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    layers.push_back(std::move(cells));
  }
  return layers;
}

template std::vector<std::vector<Index>> sheet_layers(const MeshDual<2>&);
template std::vector<std::vector<Index>> sheet_layers(const MeshDual<3>&);

}  // namespace geode::stc
