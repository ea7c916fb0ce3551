#include <geode/templates/completion.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <geode/primal/dice.hpp>
#include <geode/primal/errors.hpp>

namespace geode::templates {
namespace {

// Projection onto the interface plane (v dropped).
Point flat(const Point& p) { return Point(p[0], 0.0, p[2]); }

}  // namespace

std::vector<Tunnel> complete_tunnels(const InterfacePatch& patch,
                                     const std::function<double(const Point& along)>& height) {
  std::vector<Tunnel> out;
  if (patch.cells.size() != 1)
    throw InvalidInput("complete_tunnels: a template is built over one interface cell");
  const auto& cell = patch.cells.front();
  const auto P = [&](int i) {
    return flat(
        patch.points[primal::index_cast<std::size_t>(cell[primal::index_cast<std::size_t>(i)])]);
  };
  if (patch.dim == 2) {
    if (cell.size() != 2) throw InvalidInput("complete_tunnels: a 2D interface cell is a segment");
    // The dual of a segment is its midpoint; dicing doubles it at the quarter points.
    const Point mid = 0.5 * (P(0) + P(1));
    const double a = 0.25 * (P(1) - P(0)).norm();
    const double h = height(Point::Zero());
    Tunnel t;
    t.sheet = {"tunnel",
               [mid, a, h](const Point& x) {
                 const double d = std::abs(x[0] - mid[0]) / a, y = x[1] / h;
                 return d * d + y * y - 1.0;
               },
               "tunnel"};
    t.along = Point::Zero();
    out.push_back(t);
    return out;
  }
  if (cell.size() != 4)
    throw InvalidInput("complete_tunnels: a 3D hex-side interface cell is a quad");
  // A quad has two chords; chord i crosses edges i and i+2 (primal/topology.hpp quad edges).
  for (int i = 0; i < 2; ++i) {
    const Point m0 = 0.5 * (P(i) + P(i + 1));
    const Point m1 = 0.5 * (P((i + 2) % 4) + P((i + 3) % 4));
    const Point dir = (m1 - m0).normalized();
    const double a = 0.25 * (P(i + 1) - P(i)).norm();
    const double h = height(dir);
    Tunnel t;
    t.along = dir;
    t.sheet = {"tunnel " + std::to_string(i),
               [m0, dir, a, h](const Point& x) {
                 Point q = flat(x) - m0;
                 q -= q.dot(dir) * dir;
                 const double d = q.norm() / a, y = x[1] / h;
                 return d * d + y * y - 1.0;
               },
               "tunnel"};
    out.push_back(t);
  }
  return out;
}

DicedPatch dice_patch(const InterfacePatch& p) {
  DicedPatch d;
  if (p.dim == 2) {
    d.nodes = p.points;
    for (std::size_t i = 0; i < p.points.size(); ++i) d.owners.push_back({static_cast<int>(i)});
    for (const auto& c : p.cells) {
      if (c.size() != 2) throw InvalidInput("dice_patch: a 2D interface cell is a segment");
      d.nodes.push_back(0.5 * (p.points[primal::index_cast<std::size_t>(c[0])] +
                               p.points[primal::index_cast<std::size_t>(c[1])]));
      d.owners.push_back({c[0], c[1]});
      const int m = static_cast<int>(d.nodes.size() - 1);
      d.cells.push_back({c[0], m});
      d.cells.push_back({m, c[1]});
    }
    return d;
  }
  auto fill = [&](const auto& diced, const auto& cells) {
    d.nodes = diced.mesh.points;
    for (const auto& q : diced.mesh.quads) d.cells.push_back({q[0], q[1], q[2], q[3]});
    for (const auto& o : diced.origin) {
      std::vector<int> own;
      if (o.kind == primal::NodeOriginKind::kCell)
        for (auto v : cells[primal::index_cast<std::size_t>(o.element)]) own.push_back(v);
      else
        for (auto v : o.nodes)
          if (v != primal::kInvalidIndex) own.push_back(v);
      d.owners.push_back(own);
    }
  };
  const bool quads =
      std::all_of(p.cells.begin(), p.cells.end(), [](const auto& c) { return c.size() == 4; });
  const bool tris =
      std::all_of(p.cells.begin(), p.cells.end(), [](const auto& c) { return c.size() == 3; });
  if (quads) {
    primal::QuadMesh m{p.points, {}};
    for (const auto& c : p.cells) m.quads.push_back({c[0], c[1], c[2], c[3]});
    fill(primal::dice(m), m.quads);
  } else if (tris) {
    primal::TriMesh m{p.points, {}};
    for (const auto& c : p.cells) m.tris.push_back({c[0], c[1], c[2]});
    fill(primal::dice(m), m.tris);
  } else {
    throw InvalidInput("dice_patch: a 3D interface patch is all quads or all triangles");
  }
  return d;
}

std::vector<Dome> complete_domes(const InterfacePatch& patch, double v_top, double k,
                                 double blend) {
  return complete_domes(patch, v_top, [k, blend](int) {
    return DomeShape{k, blend, 2.0, Point::Zero()};
  });
}

std::vector<Dome> complete_domes(const InterfacePatch& patch, double v_top,
                                 const std::function<DomeShape(int vertex)>& shape) {
  const DicedPatch diced = dice_patch(patch);
  std::vector<Dome> out;
  for (int v = 0; v < primal::index_cast<int>(patch.points.size()); ++v) {
    bool used = false;
    for (const auto& c : patch.cells) used |= std::find(c.begin(), c.end(), v) != c.end();
    if (!used) continue;
    const DomeShape s = shape(v);
    const double p = s.exponent;
    if (!(p >= 1) || !std::isfinite(p))
      throw InvalidInput("complete_domes: the exponent must be >= 1 and finite");
    const bool round = p == 2.0;
    const Point V = flat(patch.points[primal::index_cast<std::size_t>(v)]) + flat(s.offset);
    // In-plane distance from the dome's centre: Euclidean for p = 2 (the spheroid's own
    // formula), else the p-norm whose unit ball is the superquadric's trace.
    const auto distance = [V, p, round](const Point& x) {
      const Point d = flat(x) - V;
      return round ? d.norm()
                   : std::pow(std::pow(std::abs(d[0]), p) + std::pow(std::abs(d[2]), p), 1.0 / p);
    };
    // The trace around v encloses the diced nodes that belong to v (v itself, the midpoints of
    // its edges, the centres of its cells) and leaves out all others.
    double inside = 0.0, outside = std::numeric_limits<double>::max();
    for (std::size_t n = 0; n < diced.nodes.size(); ++n) {
      const double d = distance(diced.nodes[n]);
      const auto& own = diced.owners[n];
      if (std::find(own.begin(), own.end(), v) != own.end())
        inside = std::max(inside, d);
      else
        outside = std::min(outside, d);
    }
    if (!(inside < outside))
      throw TopologyError("complete_domes: no " +
                          std::string(round ? "circle" : "superquadric trace") +
                          " around interface vertex " + std::to_string(v) +
                          " separates its diced nodes from the others");
    const double R = inside + s.blend * (outside - inside);
    const double depth = s.depth;
    Dome d;
    d.vertex = v;
    d.radius = R;
    if (round)
      d.sheet = {"dome " + std::to_string(v),
                 [V, R, depth, v_top](const Point& x) {
                   const double r = (flat(x) - V).norm() / R, y = (v_top - x[1]) / depth;
                   return r * r + y * y - 1.0;
                 },
                 "dome"};
    else
      d.sheet = {"dome " + std::to_string(v),
                 [V, R, depth, v_top, p](const Point& x) {
                   const Point q = flat(x) - V;
                   return std::pow(std::abs(q[0]) / R, p) + std::pow(std::abs(q[2]) / R, p) +
                          std::pow(std::abs(v_top - x[1]) / depth, p) - 1.0;
                 },
                 "dome"};
    out.push_back(d);
  }
  return out;
}

}  // namespace geode::templates
