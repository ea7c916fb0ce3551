#include "conform/buffer_layer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "primal/boundary.hpp"
#include "primal/errors.hpp"
#include "primal/gradation.hpp"
#include "primal/key_map.hpp"
#include "primal/quality.hpp"
#include "primal/topology.hpp"

namespace geode::conform {

using namespace primal;

namespace {

double min_dot(const Point& d, const std::vector<Point>& normals) {
  double m = std::numeric_limits<double>::infinity();
  for (const Point& n : normals) m = std::min(m, d.dot(n));
  return m;
}

// The unit direction d maximizing min_i d . n_i over unit normals n_i, projected by `project`
// (the outer-boundary constraint). The unconstrained optimum is the centre of the smallest
// spherical cap holding the normals, fixed by at most three of them, so the candidates are the
// normals, the midpoints of pairs and the equidistant directions of triples.
template <class Project>
std::pair<Point, double> best_direction(const std::vector<Point>& n, Project project) {
  std::vector<Point> candidates;
  for (std::size_t i = 0; i < n.size(); ++i) {
    candidates.push_back(n[i]);
    for (std::size_t j = i + 1; j < n.size(); ++j) {
      candidates.push_back(n[i] + n[j]);
      for (std::size_t k = j + 1; k < n.size(); ++k) {
        const Point d = (n[i] - n[j]).cross(n[i] - n[k]);
        candidates.push_back(d);
        candidates.push_back(-d);
      }
    }
  }
  Point sum = Point::Zero();
  for (const Point& x : n) sum += x;
  candidates.push_back(sum);
  Point best = Point::Zero();
  double best_m = -std::numeric_limits<double>::infinity();
  for (Point d : candidates) {
    d = project(d);
    const double len = d.norm();
    if (len < 1e-12) continue;
    d /= len;
    const double m = min_dot(d, n);
    if (m > best_m) {
      best_m = m;
      best = d;
    }
  }
  return {best, best_m};
}

}  // namespace

BufferLayer insert_buffer_layer(const Model& input, const Interface& itf,
                                const BufferLayerOptions& opt) {
  validate(input, "insert_buffer_layer");
  const std::size_t n_points = input.points.size();
  const auto& P = input.points;
  auto pt = [&](Index v) -> const Point& { return P[static_cast<std::size_t>(v)]; };

  BufferLayer out;
  out.model = input;
  out.top_node.assign(n_points, kInvalidIndex);
  const std::vector<Index>& interface_nodes = itf.nodes;
  for (std::size_t k = 0; k < interface_nodes.size(); ++k)
    out.top_node[static_cast<std::size_t>(interface_nodes[k])] = static_cast<Index>(n_points + k);
  auto slot = [&](Index v) {
    return static_cast<std::size_t>(out.top_node[static_cast<std::size_t>(v)]) - n_points;
  };
  const std::size_t n_moved = interface_nodes.size();

  // Per moved node: unit corner normals of its interface quads, the shortest edge at it.
  std::vector<std::vector<Point>> corner_normals(n_moved);
  std::vector<double> shortest(n_moved, std::numeric_limits<double>::infinity());
  for (const InterfaceQuad& q : itf.quads)
    for (std::size_t i = 0; i < 4; ++i) {
      const Index v = q.corners[i];
      const Point er = pt(q.corners[(i + 1) % 4]) - pt(v);
      const Point es = pt(q.corners[(i + 3) % 4]) - pt(v);
      const Point n = er.cross(es);
      if (n.norm() <= 0.0)
        throw TopologyError("insert_buffer_layer: interface face " + std::to_string(q.face + 1) + " of " +
                            describe_element(input, {ElementKind::Hex, q.hex}) + " is degenerate at " +
                            describe_node(input, v));
      corner_normals[slot(v)].push_back(n.normalized());
      shortest[slot(v)] = std::min({shortest[slot(v)], er.norm(), es.norm()});
    }
  // Tets touching the interface, tet edges at moved nodes, and the tet part's outer boundary
  // (faces used once that are not interface triangles).
  // Per tet-part triangle the number of tets using it, interface triangles marked by -1.
  KeyMap<4> tet_face_uses(2 * input.tets.size());
  for (const auto& t : input.tets)
    for (const auto& fc : topology::kTetFaceCorners)
      ++*tet_face_uses
             .try_emplace(face_key(std::array<Index, 3>{t[static_cast<std::size_t>(fc[0])],
                                                       t[static_cast<std::size_t>(fc[1])],
                                                       t[static_cast<std::size_t>(fc[2])]}),
                          0)
             .first;
  std::vector<FaceKey> interface_tris;
  for (const InterfaceQuad& q : itf.quads)
    for (const auto& tri : interface_triangles(q)) interface_tris.push_back(face_key(tri));
  for (const FaceKey& key : interface_tris)
    if (Index* uses = tet_face_uses.find(key)) *uses = -1;
  std::vector<std::vector<Point>> outer_normals(n_moved);  // area-weighted
  // Per input node: the interface quad it is the four-triangle centre of, or kInvalidIndex.
  std::vector<Index> centre_of(n_points, kInvalidIndex);
  for (std::size_t q = 0; q < itf.quads.size(); ++q)
    if (itf.quads[q].centre != kInvalidIndex) centre_of[static_cast<std::size_t>(itf.quads[q].centre)] = static_cast<Index>(q);
  std::vector<Index> touched_tets;
  for (std::size_t t = 0; t < input.tets.size(); ++t) {
    const auto& tet = input.tets[t];
    bool touches = false;
    for (Index v : tet)
      touches |= out.top_node[static_cast<std::size_t>(v)] != kInvalidIndex || centre_of[static_cast<std::size_t>(v)] != kInvalidIndex;
    if (!touches) continue;
    touched_tets.push_back(static_cast<Index>(t));
    for (const auto& e : topology::kTetEdgeCorners) {
      const Index a = tet[static_cast<std::size_t>(e[0])], b = tet[static_cast<std::size_t>(e[1])];
      const double len = (pt(a) - pt(b)).norm();
      for (Index v : {a, b})
        if (out.top_node[static_cast<std::size_t>(v)] != kInvalidIndex) shortest[slot(v)] = std::min(shortest[slot(v)], len);
    }
    for (const auto& fc : topology::kTetFaceCorners) {
      const std::array<Index, 3> tri{tet[static_cast<std::size_t>(fc[0])], tet[static_cast<std::size_t>(fc[1])],
                                     tet[static_cast<std::size_t>(fc[2])]};
      const FaceKey key = face_key(tri);
      const Index* uses = tet_face_uses.find(key);
      if (!uses || *uses != 1) continue;  // inner or interface triangle
      const Point area = (pt(tri[1]) - pt(tri[0])).cross(pt(tri[2]) - pt(tri[0]));  // outward
      for (Index v : tri)
        if (out.top_node[static_cast<std::size_t>(v)] != kInvalidIndex) outer_normals[slot(v)].push_back(area);
    }
  }

  // Step direction per moved node.
  const double feature_cos = std::cos(opt.feature_angle * M_PI / 180.0);
  std::vector<Point> direction(n_moved);
  for (std::size_t k = 0; k < n_moved; ++k) {
    const Index v = interface_nodes[k];
    // Cluster the outer normals into features.
    std::vector<Point> features;  // summed area vectors
    for (const Point& a : outer_normals[k]) {
      bool merged = false;
      for (Point& f : features)
        if (f.normalized().dot(a.normalized()) >= feature_cos) {
          f += a;
          merged = true;
          break;
        }
      if (!merged) features.push_back(a);
    }
    for (Point& f : features) f.normalize();
    if (features.size() >= 3)
      throw TopologyError("insert_buffer_layer: " + describe_node(input, v) +
                          " is a corner of the tet part's outer boundary (" +
                          std::to_string(features.size()) +
                          " feature faces meet there): its tet-side copy cannot move off the interface");
    auto project = [&](Point d) -> Point {
      if (features.size() == 1) return d - d.dot(features[0]) * features[0];
      if (features.size() == 2) {
        const Point axis = features[0].cross(features[1]).normalized();
        return d.dot(axis) * axis;
      }
      return d;
    };
    auto [d, m] = best_direction(corner_normals[k], project);
    if (!(m >= opt.min_visibility))
      throw TopologyError("insert_buffer_layer: " + describe_node(input, v) +
                          ": no direction into the tet side lies above all " +
                          std::to_string(corner_normals[k].size()) +
                          " interface faces at it (best min cos " + std::to_string(m) +
                          "), so no valid buffer layer can be placed there (the paper's Figure 9 right)");
    // The mitred offset: a step of height / (d . n) along d puts the node at distance height
    // from every interface face whose corner normal fixes the cap's rim, so at convex and
    // concave edges and corners a buffer hex's top stays parallel to its bottom instead of
    // tilting towards the edge (and folding along its diagonal where its neighbour's does not).
    direction[k] = d / std::max(m, opt.min_mitre_cos);
  }

  // Height of the layer per node. thickness x the shortest edge at a node is safe for its
  // tets but jumps where one short tet edge meets the interface: a buffer hex whose corners
  // stand at unequal heights has a twisted top, folded along its diagonal, and the template's
  // nodes under the fold invert. So a node is raised towards its neighbours' heights (to at
  // least a neighbour's height less raise_rate x their edge, primal::grade_up), but not above
  // thickness x its interface quads' mean edge (the buffer hex's own proportions); then
  // lowered so that no two neighbours differ by more than smooth_rate x their edge, here and
  // after every halving. A raised node whose tets or buffer hexes fail drops back to its safe
  // height (the graded thickness x shortest edge) before it is ever halved.
  GradedEdges quad_edges;
  std::vector<double> mean_quad_edge(n_moved, 0.0);
  for (const InterfaceQuad& q : itf.quads)
    for (std::size_t i = 0; i < 4; ++i) {
      const Index a = q.corners[i], b = q.corners[(i + 1) % 4];
      const double len = (pt(a) - pt(b)).norm();
      quad_edges.nodes.push_back({static_cast<Index>(slot(a)), static_cast<Index>(slot(b))});
      quad_edges.length.push_back(len);
      mean_quad_edge[slot(a)] += len, mean_quad_edge[slot(b)] += len;
    }
  std::vector<double> step(n_moved);  // the node's height; it moves step x direction
  for (std::size_t k = 0; k < n_moved; ++k) step[k] = opt.thickness * shortest[k];
  std::vector<int> quads_at(n_moved, 0);  // two of a quad's edges per corner
  for (const InterfaceQuad& q : itf.quads)
    for (Index v : q.corners) ++quads_at[slot(v)];
  std::vector<double> raised = step;
  grade_up(raised, quad_edges, opt.raise_rate);
  grade_down(step, quad_edges, opt.smooth_rate);
  std::vector<double> safe = step;  // where a raised node falls back to
  for (std::size_t k = 0; k < n_moved; ++k)
    step[k] = std::max(step[k], std::min(raised[k], opt.thickness * mean_quad_edge[k] / (2.0 * quads_at[k])));
  grade_down(step, quad_edges, opt.smooth_rate);

  // Move, check, halve the steps of nodes of failing elements, repeat.
  auto tet_vol = [](const std::vector<Point>& pts, const std::array<Index, 4>& t) {
    return tet_volume(pts[static_cast<std::size_t>(t[0])], pts[static_cast<std::size_t>(t[1])],
                      pts[static_cast<std::size_t>(t[2])], pts[static_cast<std::size_t>(t[3])]);
  };
  for (const InterfaceQuad& q : itf.quads) {
    BufferHex b;
    for (std::size_t i = 0; i < 4; ++i) {
      b.corners[i] = q.corners[i];
      b.corners[i + 4] = out.top_node[static_cast<std::size_t>(q.corners[i])];
    }
    b.diagonal = q.diagonal == 0 ? std::array<int, 2>{4, 6} : std::array<int, 2>{5, 7};
    b.centre = q.centre;
    b.quad = static_cast<Index>(out.hexes.size());
    out.hexes.push_back(b);
  }
  for (auto& t : out.model.tets)
    for (Index& v : t)
      if (out.top_node[static_cast<std::size_t>(v)] != kInvalidIndex) v = out.top_node[static_cast<std::size_t>(v)];

  for (int halvings = 0;;) {
    out.model.points.resize(n_points);
    for (std::size_t k = 0; k < n_moved; ++k) {
      const std::size_t v = static_cast<std::size_t>(interface_nodes[k]);
      out.model.points.push_back(P[v] + step[k] * direction[k]);
    }
    // A four-triangle centre keeps its place relative to the quad's corners.
    for (const BufferHex& b : out.hexes) {
      if (b.centre == kInvalidIndex) continue;
      Point shift = Point::Zero();
      for (std::size_t i = 0; i < 4; ++i)
        shift += (out.model.points[static_cast<std::size_t>(b.corners[i + 4])] - P[static_cast<std::size_t>(b.corners[i])]) / 4.0;
      out.model.points[static_cast<std::size_t>(b.centre)] = P[static_cast<std::size_t>(b.centre)] + shift;
    }
    std::vector<char> failing(n_moved, 0);
    // A failing centre's steps are its quad's corners'.
    auto fail_node = [&](Index v) {
      if (static_cast<std::size_t>(v) >= n_points) {
        failing[static_cast<std::size_t>(v) - n_points] = 1;
      } else if (const Index q = centre_of[static_cast<std::size_t>(v)]; q != kInvalidIndex) {
        for (std::size_t i = 4; i < 8; ++i) failing[static_cast<std::size_t>(out.hexes[static_cast<std::size_t>(q)].corners[i]) - n_points] = 1;
      }
    };
    std::string first_failure;
    out.report.min_tet_volume_ratio = 1.0;
    out.report.min_scaled_jacobian = 1.0;
    for (Index t : touched_tets) {
      const double before = tet_vol(P, input.tets[static_cast<std::size_t>(t)]);
      const auto& moved = out.model.tets[static_cast<std::size_t>(t)];
      const double ratio = tet_vol(out.model.points, moved) / before;
      out.report.min_tet_volume_ratio = std::min(out.report.min_tet_volume_ratio, ratio);
      if (ratio < opt.min_volume_ratio) {
        for (Index v : moved) fail_node(v);
        for (Index v : moved) {
          if (!first_failure.empty()) break;
          const bool duplicate = static_cast<std::size_t>(v) >= n_points;
          if (duplicate || centre_of[static_cast<std::size_t>(v)] != kInvalidIndex)
            first_failure = describe_node(input, duplicate ? interface_nodes[static_cast<std::size_t>(v) - n_points] : v) +
                            ": " + describe_element(input, {ElementKind::Tet, static_cast<Index>(t)}) + " keeps only " +
                            std::to_string(ratio) + " of its volume";
        }
      }
    }
    for (const BufferHex& b : out.hexes) {
      HexCorners c;
      for (std::size_t i = 0; i < 8; ++i) c[i] = out.model.points[static_cast<std::size_t>(b.corners[i])];
      double sj = hex_scaled_jacobian(c);
      if (b.centre != kInvalidIndex) {
        // A four-triangle top: each triangle must face away from the bottom face's centre,
        // measured as a scaled Jacobian (the tet's volume over its edge lengths at the centre).
        const Point& top = out.model.points[static_cast<std::size_t>(b.centre)];
        const Point bottom = (c[0] + c[1] + c[2] + c[3]) / 4.0;
        for (std::size_t i = 0; i < 4; ++i) {
          const Point a = c[4 + i] - bottom, e = c[4 + (i + 1) % 4] - bottom, m = top - bottom;
          sj = std::min(sj, a.cross(e).dot(m) / (a.norm() * e.norm() * m.norm()));
        }
      }
      out.report.min_scaled_jacobian = std::min(out.report.min_scaled_jacobian, sj);
      if (sj < opt.min_scaled_jacobian)
        for (std::size_t i = 4; i < 8; ++i) {
          failing[static_cast<std::size_t>(b.corners[i]) - n_points] = 1;
          if (first_failure.empty())
            first_failure = "node " + std::to_string(b.corners[i - 4]) + ": the buffer hex on hex " +
                            std::to_string(itf.quads[static_cast<std::size_t>(b.quad)].hex) + " face " +
                            std::to_string(itf.quads[static_cast<std::size_t>(b.quad)].face) +
                            " has scaled Jacobian " + std::to_string(sj);
        }
    }
    out.report.halvings = halvings;
    if (first_failure.empty()) break;
    if (halvings >= opt.max_halvings)
      throw TopologyError("insert_buffer_layer: no valid buffer layer after " + std::to_string(halvings) +
                          " halvings of the step: " + first_failure);
    bool halved = false;
    for (std::size_t k = 0; k < n_moved; ++k)
      if (failing[k]) {  // a raised node falls back to its safe height first
        if (step[k] > safe[k]) {
          step[k] = safe[k];
        } else {
          step[k] *= 0.5, safe[k] = step[k];
          halved = true;
        }
      }
    halvings += halved;
    grade_down(step, quad_edges, opt.smooth_rate);
  }
  out.report.min_step = std::numeric_limits<double>::infinity();
  out.report.max_step = 0.0;
  for (std::size_t k = 0; k < n_moved; ++k) {
    const double moved = step[k] * direction[k].norm();
    out.report.min_step = std::min(out.report.min_step, moved);
    out.report.max_step = std::max(out.report.max_step, moved);
  }
  if (n_moved == 0) out.report.min_step = 0.0;
  return out;
}

HexMesh buffer_hex_mesh(const BufferLayer& layer) {
  HexMesh mesh;
  mesh.points = layer.model.points;
  for (const BufferHex& b : layer.hexes) {
    mesh.hexes.push_back(b.corners);
    mesh.block.push_back(3);
  }
  return mesh;
}

}  // namespace geode::conform
