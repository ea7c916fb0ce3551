#include "templates/completion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "primal/errors.hpp"

namespace geode::templates {
namespace {

// Projection onto the interface plane (v dropped).
Point flat(const Point& p) { return Point(p[0], 0.0, p[2]); }

}  // namespace

std::vector<Tunnel> complete_tunnels(const InterfacePatch& patch,
                                     const std::function<double(const Point& along)>& height) {
  std::vector<Tunnel> out;
  if (patch.cells.size() != 1) throw InvalidInput("complete_tunnels: a template is built over one interface cell");
  const auto& cell = patch.cells.front();
  const auto P = [&](int i) { return flat(patch.points[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)])]); };
  if (patch.dim == 2) {
    if (cell.size() != 2) throw InvalidInput("complete_tunnels: a 2D interface cell is a segment");
    // The dual of a segment is its midpoint; dicing doubles it at the quarter points.
    const Point mid = 0.5 * (P(0) + P(1));
    const double a = 0.25 * (P(1) - P(0)).norm();
    const double h = height(Point::Zero());
    Tunnel t;
    t.sheet = {"tunnel", [mid, a, h](const Point& x) {
                 const double d = std::abs(x[0] - mid[0]) / a, y = x[1] / h;
                 return d * d + y * y - 1.0;
               }, "tunnel"};
    t.along = Point::Zero();
    out.push_back(t);
    return out;
  }
  if (cell.size() != 4) throw InvalidInput("complete_tunnels: a 3D hex-side interface cell is a quad");
  // A quad has two chords; chord i crosses edges i and i+2 (primal/topology.hpp quad edges).
  for (int i = 0; i < 2; ++i) {
    const Point m0 = 0.5 * (P(i) + P(i + 1));
    const Point m1 = 0.5 * (P((i + 2) % 4) + P((i + 3) % 4));
    const Point dir = (m1 - m0).normalized();
    const double a = 0.25 * (P(i + 1) - P(i)).norm();
    const double h = height(dir);
    Tunnel t;
    t.along = dir;
    t.sheet = {"tunnel " + std::to_string(i), [m0, dir, a, h](const Point& x) {
                 Point q = flat(x) - m0;
                 q -= q.dot(dir) * dir;
                 const double d = q.norm() / a, y = x[1] / h;
                 return d * d + y * y - 1.0;
               }, "tunnel"};
    out.push_back(t);
  }
  return out;
}

std::vector<Dome> complete_domes(const InterfacePatch& patch, double v_top, double k, double blend) {
  // Diced nodes: the vertices, the edge midpoints, the cell centroids.
  std::set<std::pair<int, int>> edges;
  for (const auto& c : patch.cells)
    for (std::size_t i = 0; i < c.size(); ++i) {
      const int a = c[i], b = c[(i + 1) % c.size()];
      if (patch.dim == 2 && i == 1) break;  // a segment has one edge
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  std::vector<Dome> out;
  for (int v = 0; v < static_cast<int>(patch.points.size()); ++v) {
    bool used = false;
    for (const auto& c : patch.cells) used |= std::find(c.begin(), c.end(), v) != c.end();
    if (!used) continue;
    const Point V = flat(patch.points[static_cast<std::size_t>(v)]);
    double inside = 0.0, outside = std::numeric_limits<double>::max();
    auto classify = [&](const Point& p, bool in) {
      const double d = (flat(p) - V).norm();
      if (in) inside = std::max(inside, d); else outside = std::min(outside, d);
    };
    for (int u = 0; u < static_cast<int>(patch.points.size()); ++u)
      if (u != v) classify(patch.points[static_cast<std::size_t>(u)], false);
    for (const auto& e : edges)
      classify(0.5 * (patch.points[static_cast<std::size_t>(e.first)] + patch.points[static_cast<std::size_t>(e.second)]),
               e.first == v || e.second == v);
    if (patch.dim == 3)
      for (const auto& c : patch.cells) {
        Point g = Point::Zero();
        for (int i : c) g += patch.points[static_cast<std::size_t>(i)];
        classify(g / static_cast<double>(c.size()), std::find(c.begin(), c.end(), v) != c.end());
      }
    if (!(inside < outside))
      throw TopologyError("complete_domes: no circle around interface vertex " + std::to_string(v) +
                          " separates its diced nodes from the others");
    const double R = inside + blend * (outside - inside);
    const double depth = k;
    Dome d;
    d.vertex = v;
    d.radius = R;
    d.sheet = {"dome " + std::to_string(v), [V, R, depth, v_top](const Point& x) {
                 const double r = (flat(x) - V).norm() / R, y = (v_top - x[1]) / depth;
                 return r * r + y * y - 1.0;
               }, "dome"};
    out.push_back(d);
  }
  return out;
}

}  // namespace geode::templates
