#include <geode/conform/buffer_layer.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

#include <geode/primal/boundary.hpp>
#include <geode/primal/disjoint_sets.hpp>
#include <geode/primal/errors.hpp>
#include <geode/primal/gradation.hpp>
#include <geode/primal/key_map.hpp>
#include <geode/primal/quality.hpp>
#include <geode/primal/topology.hpp>

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

// insert_buffer_layer's stages over one state: which part moves (BufferSide), per moved node
// (slot k of Interface::nodes) its geometry, direction and height, then the move-and-check
// loop.
class BufferBuilder {
 public:
  BufferBuilder(const Model& input, const Interface& itf, const BufferLayerOptions& opt)
      : input_(input),
        itf_(itf),
        opt_(opt),
        n_points_(input.points.size()),
        n_moved_(itf.nodes.size()),
        hex_side_(opt.side == BufferSide::kHex),
        thickness_(opt.thickness > 0.0 ? opt.thickness : default_buffer_thickness(opt.side)) {}
  BufferLayer run();

 private:
  const Point& pt(Index v) const { return input_.points[index_cast<std::size_t>(v)]; }
  std::size_t slot(Index v) const {
    return index_cast<std::size_t>(out_.top_node[index_cast<std::size_t>(v)]) - n_points_;
  }
  bool moved(Index v) const { return out_.top_node[index_cast<std::size_t>(v)] != kInvalidIndex; }
  // Whether cell c of the moving part moves at node v: carved from the tet part, a tet on the
  // hex side of the interface at v keeps v (sides()).
  bool moves(Index c, Index v) const {
    return moved(v) && (hex_side_ || !std::binary_search(kept_tets_.begin(), kept_tets_.end(),
                                                         std::pair<Index, Index>{c, v}));
  }
  void sides();
  void interface_geometry();
  template <class Cells, class Edges, class Faces>
  void moving_part(ElementKind kind, const Cells& cells, const Edges& edges, const Faces& faces,
                   const std::vector<std::pair<Index, int>>& interface_faces);
  void measure_before();
  void directions();
  void heights();
  void make_hexes();
  void place();
  std::string check(std::vector<char>& failing);
  void move_and_check();

  const Model& input_;
  const Interface& itf_;
  const BufferLayerOptions& opt_;
  const std::size_t n_points_, n_moved_;
  const bool hex_side_;  // the hex part's copies move (into the hex part), the tet part stays
  const double thickness_;
  BufferLayer out_;
  // Per moved node: unit corner normals of its interface quads pointing into the moving part,
  // the shortest interface-quad or moving-part edge at it, area-weighted outward normals of
  // the moving part's outer-boundary faces and of the faces between its blocks (from the lower
  // block) at it, its step direction and height.
  std::vector<std::vector<Point>> corner_normals_, outer_normals_;
  std::vector<double> shortest_, step_, safe_;
  std::vector<Point> direction_;
  std::vector<double>
      feature_;  // per moving node: its thickness factor (feature_thickness at edges and corners)
  GradedEdges quad_edges_;
  std::vector<Index> centre_of_;  // per input node: the quad it is the four-triangle centre of
  std::vector<Index> touched_;    // moving-part cells with a moved node (or a moved centre)
  // (tet, node) pairs of tets that keep an interface node (on its hex side), and (wedge, node)
  // pairs of wedges that take its copy (on its tet side, or loose beside a moving hex part),
  // ascending.
  std::vector<std::pair<Index, Index>> kept_tets_, copied_wedges_;
  // Per touched cell, as input: a hex's corner and centre Jacobians and its scaled Jacobian,
  // a tet's volume (in before_).
  std::vector<std::array<double, 9>> jacobians_before_;
  std::vector<double> before_;
};

// Which copy of each interface node the tets and wedges around it take (Interface::uses): the
// hex side keeps the node, the tet side takes the copy, a loose cell the copy that stays where
// the node was. The moving copy may move hexes (from the hex part) or tets (from the tet part)
// only: wedges are diced in place, and carved from the hex part the tets stay as meshed.
void BufferBuilder::sides() {
  for (const InterfaceNodeUse& u : itf_.uses) {
    const bool wedge = u.cell.kind == ElementKind::kWedge;
    const bool moves_with =
        hex_side_ ? u.side == InterfaceSide::kHex : u.side == InterfaceSide::kTet && wedge;
    if (moves_with)
      throw TopologyError("insert_buffer_layer: carved from the " +
                          std::string(buffer_side_name(opt_.side)) + " part, the moving copy of " +
                          describe_node(input_, u.node) + " would move " +
                          describe_element(input_, u.cell) + " (on the " +
                          (u.side == InterfaceSide::kHex ? "hex" : "tet") +
                          " side of the interface there), which " +
                          (wedge ? "is diced in place" : "stays as meshed from this side"));
    if (!hex_side_ && !wedge && u.side == InterfaceSide::kHex)
      kept_tets_.emplace_back(u.cell.index, u.node);
    if (hex_side_ && wedge) copied_wedges_.emplace_back(u.cell.index, u.node);
  }
  std::sort(kept_tets_.begin(), kept_tets_.end());
  std::sort(copied_wedges_.begin(), copied_wedges_.end());
}

void BufferBuilder::interface_geometry() {
  corner_normals_.assign(n_moved_, {});
  shortest_.assign(n_moved_, std::numeric_limits<double>::infinity());
  const double into = hex_side_ ? -1.0 : 1.0;  // the quads' own corner normals face the tet side
  for (const InterfaceQuad& q : itf_.quads)
    for (std::size_t i = 0; i < 4; ++i) {
      const Index v = q.corners[i];
      const Point er = pt(q.corners[(i + 1) % 4]) - pt(v);
      const Point es = pt(q.corners[(i + 3) % 4]) - pt(v);
      const Point n = er.cross(es);
      if (n.norm() <= 0.0)
        throw TopologyError("insert_buffer_layer: interface face " + std::to_string(q.face + 1) +
                            " of " + describe_element(input_, q.owner()) + " is degenerate at " +
                            describe_node(input_, v));
      corner_normals_[slot(v)].push_back(into * n.normalized());
      shortest_[slot(v)] = std::min({shortest_[slot(v)], er.norm(), es.norm()});
    }
  centre_of_.assign(n_points_, kInvalidIndex);
  for (std::size_t q = 0; q < itf_.quads.size(); ++q)
    if (itf_.quads[q].centre != kInvalidIndex)
      centre_of_[index_cast<std::size_t>(itf_.quads[q].centre)] = index_cast(q);
}

// The moving part's cells at moved nodes (with a four-triangle centre on the tet side), their
// edges at moved nodes, and the part's outer boundary (faces used once that are not interface
// faces, given as (cell, local face)) with the faces between two of its blocks, whose normals
// constrain the direction of a moved node on them.
template <class Cells, class Edges, class Faces>
void BufferBuilder::moving_part(ElementKind kind, const Cells& cells, const Edges& edges,
                                const Faces& faces,
                                const std::vector<std::pair<Index, int>>& interface_faces) {
  constexpr std::size_t kFaceSize = std::tuple_size_v<typename Faces::value_type>;
  const std::size_t nf = faces.size();
  auto face_nodes = [&](const auto& cell, const auto& fc) {
    std::array<Index, kFaceSize> f{};
    for (std::size_t i = 0; i < kFaceSize; ++i) f[i] = cell[index_cast<std::size_t>(fc[i])];
    return f;
  };
  // The cells with a moving node (or a moving centre), whose faces on the moving part's outer
  // boundary give the outward normals.
  std::vector<Index> touched;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const auto ci = index_cast(c);
    bool touches = false;
    for (Index v : cells[c])
      touches |=
          moves(ci, v) || (!hex_side_ && centre_of_[index_cast<std::size_t>(v)] != kInvalidIndex);
    if (touches) touched.push_back(ci);
  }
  // Their faces' uses over the whole part, counted in a table of those faces only (a table of
  // every face of the part, filled and searched, was most of this stage); interface faces -1;
  // with the lowest and highest block among the cells using them. Only a cell with a node of a
  // touched cell can share a face with one: the others are passed over without a look-up (on
  // the n = 36 bench, 280,000 of them on one thread).
  struct FaceUse {
    Index uses = 0;
    int low = std::numeric_limits<int>::max(), high = std::numeric_limits<int>::min();
  };
  KeyMap<4> face_of(touched.size() * nf);
  std::vector<FaceUse> face_uses;
  std::vector<char> near(n_points_, 0);
  for (Index c : touched) {
    const auto& cell = cells[index_cast<std::size_t>(c)];
    for (Index v : cell) near[index_cast<std::size_t>(v)] = 1;
    for (std::size_t f = 0; f < nf; ++f)
      if (face_of.try_emplace(face_key(face_nodes(cell, faces[f])), index_cast(face_uses.size()))
              .second)
        face_uses.emplace_back();
  }
  const auto use_of = [&](const auto& f) -> FaceUse* {
    const Index* i = face_of.find(face_key(f));
    return i ? &face_uses[index_cast<std::size_t>(*i)] : nullptr;
  };
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const auto& cell = cells[c];
    if (std::any_of(cell.begin(), cell.end(),
                    [&](Index v) { return near[index_cast<std::size_t>(v)] != 0; })) {
      const int block = block_of(input_, {kind, index_cast(c)});
      for (std::size_t f = 0; f < nf; ++f)
        if (FaceUse* u = use_of(face_nodes(cell, faces[f]))) {
          ++u->uses;
          u->low = std::min(u->low, block);
          u->high = std::max(u->high, block);
        }
    }
  }
  for (const auto& [cell, f] : interface_faces)
    if (FaceUse* u = use_of(
            face_nodes(cells[index_cast<std::size_t>(cell)], faces[index_cast<std::size_t>(f)])))
      u->uses = -1;
  outer_normals_.assign(n_moved_, {});
  for (Index ci : touched) {
    const auto& cell = cells[index_cast<std::size_t>(ci)];
    touched_.push_back(ci);
    for (const auto& e : edges) {
      const Index a = cell[index_cast<std::size_t>(e[0])], b = cell[index_cast<std::size_t>(e[1])];
      const double len = (pt(a) - pt(b)).norm();
      for (Index v : {a, b})
        if (moves(ci, v)) shortest_[slot(v)] = std::min(shortest_[slot(v)], len);
    }
    for (std::size_t k = 0; k < nf; ++k) {
      const auto f = face_nodes(cell, faces[k]);
      // The part's boundary, and the faces between two of its blocks (materials, which the
      // copy must not move across either), each of these once: from its lower block's cell.
      const FaceUse& u = *use_of(f);
      const bool between_blocks = opt_.keep_block_faces && u.uses == 2 && u.low != u.high &&
                                  block_of(input_, {kind, ci}) == u.low;
      if (u.uses != 1 && !between_blocks) continue;  // inner or interface face
      // Twice the outward area vector (triangle or quad: the cross product of the diagonals).
      const Point area = kFaceSize == 3
                             ? Point((pt(f[1]) - pt(f[0])).cross(pt(f[2]) - pt(f[0])))
                             : Point((pt(f[2]) - pt(f[0])).cross(pt(f[kFaceSize - 1]) - pt(f[1])));
      for (Index v : f)
        if (moves(ci, v)) outer_normals_[slot(v)].push_back(area);
    }
  }
}

void BufferBuilder::measure_before() {
  for (Index c : touched_) {
    if (hex_side_) {
      HexCorners corners;
      for (std::size_t i = 0; i < 8; ++i)
        corners[i] = pt(input_.hexes[index_cast<std::size_t>(c)][i]);
      jacobians_before_.push_back(hex_jacobians(corners));
      before_.push_back(hex_scaled_jacobian(corners));
    } else {
      const auto& tet = input_.tets[index_cast<std::size_t>(c)];
      before_.push_back(tet_volume(pt(tet[0]), pt(tet[1]), pt(tet[2]), pt(tet[3])));
    }
  }
}

void BufferBuilder::directions() {
  const char* part = buffer_side_name(opt_.side);
  const double feature_cos = std::cos(opt_.feature_angle * M_PI / 180.0);
  direction_.assign(n_moved_, Point::Zero());
  feature_.assign(n_moved_, 1.0);
  // Per node, the sum of (its interface quads' centres - the node): it leans into the moving
  // part where that part is convex at the node.
  std::vector<Point> lean(n_moved_, Point::Zero());
  for (const InterfaceQuad& q : itf_.quads) {
    const Point c =
        (pt(q.corners[0]) + pt(q.corners[1]) + pt(q.corners[2]) + pt(q.corners[3])) / 4.0;
    for (Index v : q.corners) lean[slot(v)] += c - pt(v);
  }
  for (std::size_t k = 0; k < n_moved_; ++k) {
    const Index v = itf_.nodes[k];
    // Cluster the outer normals into features.
    std::vector<Point> features;  // summed area vectors
    for (const Point& a : outer_normals_[k]) {
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
      throw TopologyError("insert_buffer_layer: " + describe_node(input_, v) +
                          " is a corner of the " + part +
                          " part's outer boundary or of its blocks' boundaries (" +
                          std::to_string(features.size()) + " feature faces meet there): its " +
                          part + "-side copy cannot move off the interface");
    auto project = [&](Point d) -> Point {
      if (features.size() == 1) return d - d.dot(features[0]) * features[0];
      if (features.size() == 2) {
        const Point axis = features[0].cross(features[1]).normalized();
        return d.dot(axis) * axis;
      }
      return d;
    };
    auto [d, m] = best_direction(corner_normals_[k], project);
    if (!(m >= opt_.min_visibility))
      throw TopologyError(
          "insert_buffer_layer: " + describe_node(input_, v) + ": no direction into the " + part +
          " side lies above all " + std::to_string(corner_normals_[k].size()) +
          " interface faces at it (" +
          // -inf: the part's boundary features there leave no direction to look along.
          (std::isfinite(m) ? "best min cos " + std::to_string(m)
                            : "none along its boundary's features there") +
          "), so no valid buffer layer can be placed there (the paper's Figure 9 right)");
    // The mitred offset: a step of height / (d . n) along d puts the node at distance height
    // from every interface face whose corner normal fixes the cap's rim, so at convex and
    // concave edges and corners a buffer hex's top stays parallel to its bottom instead of
    // tilting towards the edge (and folding along its diagonal where its neighbour's does not).
    direction_[k] = d / std::max(m, opt_.min_mitre_cos);
    // At a corner where the moving part is convex (interface faces in three or more directions
    // more than the feature angle apart) the buffer hexes narrow towards it in two directions by
    // their height, so a thinner layer there keeps the geode nearer a box. (Along an edge, where
    // they taper in one, and at concave corners, where they widen, the thinner geode loses more
    // than the taper costs: tried on lshape, cylinder and nugget.)
    std::vector<Point> directions_at;
    for (const Point& n : corner_normals_[k])
      if (std::none_of(directions_at.begin(), directions_at.end(), [&](const Point& f) {
            return f.normalized().dot(n.normalized()) >= feature_cos;
          }))
        directions_at.push_back(n);
    if (directions_at.size() >= 3 && d.dot(lean[k]) > 0.0) {
      feature_[k] = opt_.feature_thickness;
      ++out_.report.convex_corners;
    }
  }
}

// Height of the layer per node. thickness x the shortest edge at a node keeps its cells in
// proportion (where it does not, the checks of move_and_check halve it) but jumps where one
// short edge meets the interface: a buffer hex whose corners stand at
// unequal heights has a twisted face, folded along its diagonal, and the template's nodes
// under the fold invert. So a node is raised towards its neighbours' heights (to at least a
// neighbour's height less raise_rate x their edge, primal::grade_up), but not above thickness
// x its interface quads' mean edge (the buffer hex's own proportions); then lowered so that no
// two neighbours differ by more than smooth_rate x their edge, here and after every halving. A
// raised node whose cells or buffer hexes fail drops back to its safe height (the graded
// thickness x shortest edge) before it is ever halved.
void BufferBuilder::heights() {
  std::vector<double> mean_quad_edge(n_moved_, 0.0);
  std::vector<int> quads_at(n_moved_, 0);  // two of a quad's edges per corner
  for (const InterfaceQuad& q : itf_.quads)
    for (std::size_t i = 0; i < 4; ++i) {
      const Index a = q.corners[i], b = q.corners[(i + 1) % 4];
      const double len = (pt(a) - pt(b)).norm();
      quad_edges_.nodes.push_back({index_cast(slot(a)), index_cast(slot(b))});
      quad_edges_.length.push_back(len);
      mean_quad_edge[slot(a)] += len, mean_quad_edge[slot(b)] += len;
      ++quads_at[slot(a)];
    }
  step_.assign(n_moved_, 0.0);  // the node's height; it moves step x direction
  for (std::size_t k = 0; k < n_moved_; ++k) step_[k] = feature_[k] * thickness_ * shortest_[k];
  std::vector<double> raised = step_;
  grade_up(raised, quad_edges_, opt_.raise_rate);
  grade_down(step_, quad_edges_, opt_.smooth_rate);
  safe_ = step_;
  for (std::size_t k = 0; k < n_moved_; ++k)
    step_[k] = std::max(step_[k], std::min(raised[k], feature_[k] * thickness_ * mean_quad_edge[k] /
                                                          (2.0 * quads_at[k])));
  grade_down(step_, quad_edges_, opt_.smooth_rate);
}

void BufferBuilder::make_hexes() {
  for (const InterfaceQuad& q : itf_.quads) {
    BufferHex b;
    for (std::size_t i = 0; i < 4; ++i) {
      b.corners[i] = q.corners[i];
      b.corners[i + 4] = out_.top_node[index_cast<std::size_t>(q.corners[i])];
    }
    b.diagonal = q.diagonal == 0 ? std::array<int, 2>{4, 6} : std::array<int, 2>{5, 7};
    b.centre = q.centre;
    b.quad = index_cast(out_.hexes.size());
    out_.hexes.push_back(b);
  }
  for (std::size_t t = 0; t < out_.model.tets.size(); ++t)
    for (Index& v : out_.model.tets[t])
      if (moved(v) && !std::binary_search(kept_tets_.begin(), kept_tets_.end(),
                                          std::pair<Index, Index>{index_cast(t), v}))
        v = out_.top_node[index_cast<std::size_t>(v)];
  for (const auto& [w, v] : copied_wedges_)
    for (Index& x : out_.model.wedges[index_cast<std::size_t>(w)])
      if (x == v) x = out_.top_node[index_cast<std::size_t>(v)];
}

// Points at the current steps: the moving copy of each interface node steps along its
// direction, the other stays; a four-triangle centre (tet side) keeps its place relative to
// its quad's corners.
void BufferBuilder::place() {
  auto& pts = out_.model.points;
  pts.assign(input_.points.begin(), input_.points.end());
  for (std::size_t k = 0; k < n_moved_; ++k) {
    const std::size_t v = index_cast<std::size_t>(itf_.nodes[k]);
    const Point p = input_.points[v] + step_[k] * direction_[k];
    if (hex_side_) {
      pts.push_back(input_.points[v]);
      pts[v] = p;
    } else {
      pts.push_back(p);
    }
  }
  if (hex_side_) return;
  for (const BufferHex& b : out_.hexes) {
    if (b.centre == kInvalidIndex) continue;
    Point shift = Point::Zero();
    for (std::size_t i = 0; i < 4; ++i)
      shift += (pts[index_cast<std::size_t>(b.corners[i + 4])] - pt(b.corners[i])) / 4.0;
    pts[index_cast<std::size_t>(b.centre)] = pt(b.centre) + shift;
  }
}

// Marks the moved nodes of failing cells and buffer hexes; returns the first failure, named.
std::string BufferBuilder::check(std::vector<char>& failing) {
  const auto& pts = out_.model.points;
  // A failing centre's steps are its quad's corners'.
  auto fail_node = [&](Index v) {
    if (index_cast<std::size_t>(v) >= n_points_) {
      failing[index_cast<std::size_t>(v) - n_points_] = 1;
    } else if (hex_side_ && moved(v)) {
      failing[slot(v)] = 1;
    } else if (const Index q = centre_of_[index_cast<std::size_t>(v)];
               !hex_side_ && q != kInvalidIndex) {
      for (std::size_t i = 4; i < 8; ++i)
        failing[index_cast<std::size_t>(out_.hexes[index_cast<std::size_t>(q)].corners[i]) -
                n_points_] = 1;
    }
  };
  std::string first_failure;
  auto keeps_only = [&](ElementKind kind, Index c, double ratio, const char* what, Index v) {
    if (first_failure.empty())
      first_failure = describe_node(input_, v) + ": " + describe_element(input_, {kind, c}) +
                      " keeps only " + std::to_string(ratio) + " of its " + what;
  };
  out_.report.min_volume_ratio = 1.0;
  out_.report.min_scaled_jacobian = 1.0;
  if (hex_side_) {
    // A hex's volume near each corner is its corner Jacobian; the ratio is the least over the
    // corners and the centre.
    for (std::size_t i = 0; i < touched_.size(); ++i) {
      const Index h = touched_[i];
      const auto& hex = input_.hexes[index_cast<std::size_t>(h)];
      HexCorners after;
      for (std::size_t k = 0; k < 8; ++k) after[k] = pts[index_cast<std::size_t>(hex[k])];
      const auto& jb = jacobians_before_[i];
      const auto ja = hex_jacobians(after);
      double ratio = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < 9; ++k)
        if (jb[k] > 0.0) ratio = std::min(ratio, ja[k] / jb[k]);
      out_.report.min_volume_ratio = std::min(out_.report.min_volume_ratio, ratio);
      const double sj_ratio = before_[i] > 0.0 ? hex_scaled_jacobian(after) / before_[i] : 1.0;
      if (ratio < opt_.min_volume_ratio || sj_ratio < opt_.min_hex_quality_ratio) {
        for (Index v : hex) fail_node(v);
        const bool volume = ratio < opt_.min_volume_ratio;
        for (Index v : hex)
          if (moved(v))
            keeps_only(ElementKind::kHex, h, volume ? ratio : sj_ratio,
                       volume ? "volume" : "scaled Jacobian", v);
      }
    }
  } else {
    for (std::size_t i = 0; i < touched_.size(); ++i) {
      const Index t = touched_[i];
      const auto& tet = input_.tets[index_cast<std::size_t>(t)];
      const auto& now = out_.model.tets[index_cast<std::size_t>(t)];
      const double ratio =
          tet_volume(pts[index_cast<std::size_t>(now[0])], pts[index_cast<std::size_t>(now[1])],
                     pts[index_cast<std::size_t>(now[2])], pts[index_cast<std::size_t>(now[3])]) /
          before_[i];
      out_.report.min_volume_ratio = std::min(out_.report.min_volume_ratio, ratio);
      if (ratio < opt_.min_volume_ratio) {
        for (Index v : now) fail_node(v);
        for (Index v : tet)
          if (moves(t, v) || centre_of_[index_cast<std::size_t>(v)] != kInvalidIndex)
            keeps_only(ElementKind::kTet, t, ratio, "volume", v);
      }
    }
  }
  for (const BufferHex& b : out_.hexes) {
    HexCorners c;
    for (std::size_t i = 0; i < 8; ++i) c[i] = pts[index_cast<std::size_t>(b.corners[i])];
    double sj = hex_scaled_jacobian(c);
    if (b.centre != kInvalidIndex) {
      // A four-triangle top: each triangle must face away from the bottom face's centre,
      // measured as a scaled Jacobian (the tet's volume over its edge lengths at the centre).
      const Point& top = pts[index_cast<std::size_t>(b.centre)];
      const Point bottom = (c[0] + c[1] + c[2] + c[3]) / 4.0;
      for (std::size_t i = 0; i < 4; ++i) {
        const Point a = c[4 + i] - bottom, e = c[4 + (i + 1) % 4] - bottom, m = top - bottom;
        sj = std::min(sj, scaled_determinant(a, e, m));
      }
    }
    out_.report.min_scaled_jacobian = std::min(out_.report.min_scaled_jacobian, sj);
    if (sj < opt_.min_scaled_jacobian)
      for (std::size_t i = 4; i < 8; ++i) {
        failing[index_cast<std::size_t>(b.corners[i]) - n_points_] = 1;
        if (first_failure.empty()) {
          const InterfaceQuad& q = itf_.quads[index_cast<std::size_t>(b.quad)];
          first_failure = describe_node(input_, b.corners[i - 4]) + ": the buffer hex on face " +
                          std::to_string(q.face + 1) + " of " +
                          describe_element(input_, q.owner()) + " has scaled Jacobian " +
                          std::to_string(sj);
        }
      }
  }
  return first_failure;
}

// Move, check, halve the steps of nodes of failing elements, repeat.
void BufferBuilder::move_and_check() {
  for (int halvings = 0;;) {
    place();
    std::vector<char> failing(n_moved_, 0);
    const std::string first_failure = check(failing);
    out_.report.halvings = halvings;
    if (first_failure.empty()) break;
    if (halvings >= opt_.max_halvings)
      throw TopologyError("insert_buffer_layer: no valid buffer layer after " +
                          std::to_string(halvings) + " halvings of the step: " + first_failure);
    bool halved = false;
    for (std::size_t k = 0; k < n_moved_; ++k)
      if (failing[k]) {  // a raised node falls back to its safe height first
        if (step_[k] > safe_[k]) {
          step_[k] = safe_[k];
        } else {
          step_[k] *= 0.5, safe_[k] = step_[k];
          halved = true;
        }
      }
    halvings += halved;
    grade_down(step_, quad_edges_, opt_.smooth_rate);
  }
  out_.report.min_step = n_moved_ == 0 ? 0.0 : std::numeric_limits<double>::infinity();
  out_.report.max_step = 0.0;
  for (std::size_t k = 0; k < n_moved_; ++k) {
    const double d = step_[k] * direction_[k].norm();
    out_.report.min_step = std::min(out_.report.min_step, d);
    out_.report.max_step = std::max(out_.report.max_step, d);
  }
}

BufferLayer BufferBuilder::run() {
  out_.model = input_;
  out_.top_node.assign(n_points_, kInvalidIndex);
  for (std::size_t k = 0; k < n_moved_; ++k)
    out_.top_node[index_cast<std::size_t>(itf_.nodes[k])] = index_cast(n_points_ + k);
  sides();
  interface_geometry();
  std::vector<std::pair<Index, int>> interface_faces;  // (cell, local face) of the moving part
  for (const InterfaceQuad& q : itf_.quads) {
    if (hex_side_)
      interface_faces.emplace_back(q.hex, q.face);
    else
      for (int i = 0; i < q.triangle_count(); ++i)
        interface_faces.emplace_back(q.tets[i], q.tet_faces[i]);
  }
  if (hex_side_)
    moving_part(ElementKind::kHex, input_.hexes, topology::kHexEdgeCorners,
                topology::kHexFaceCorners, interface_faces);
  else
    moving_part(ElementKind::kTet, input_.tets, topology::kTetEdgeCorners,
                topology::kTetFaceCorners, interface_faces);
  measure_before();
  directions();
  heights();
  make_hexes();
  move_and_check();
  return std::move(out_);
}

}  // namespace

std::vector<double> buffer_height_ratios(const BufferLayer& layer) {
  const auto& p = layer.model.points;
  std::vector<double> ratio;
  ratio.reserve(layer.hexes.size());
  for (const BufferHex& b : layer.hexes) {
    double edge = 0.0, height = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < 4; ++i) {
      const auto at = [&](std::size_t k) -> const primal::Point& {
        return p[primal::index_cast<std::size_t>(b.corners[k])];
      };
      edge += (at((i + 1) % 4) - at(i)).norm() / 4.0;
      height = std::min(height, (at(i + 4) - at(i)).norm());
    }
    ratio.push_back(edge > 0.0 ? height / edge : 0.0);
  }
  return ratio;
}

std::vector<Index> interface_pieces(const BufferLayer& layer) {
  primal::DisjointSets joined(layer.top_node.size());  // over the input's nodes
  for (const BufferHex& b : layer.hexes)
    for (std::size_t i = 1; i < 4; ++i) joined.unite(b.corners[0], b.corners[i]);
  std::vector<Index> piece, number(layer.top_node.size(), kInvalidIndex);
  piece.reserve(layer.hexes.size());
  Index pieces = 0;
  for (const BufferHex& b : layer.hexes) {
    Index& n = number[index_cast<std::size_t>(joined.find(b.corners[0]))];
    if (n == kInvalidIndex) n = pieces++;
    piece.push_back(n);
  }
  return piece;
}

std::vector<Eigen::Vector3d> buffer_proportions(const BufferLayer& layer) {
  const auto& p = layer.model.points;
  std::vector<Eigen::Vector3d> sides;
  sides.reserve(layer.hexes.size());
  for (const BufferHex& b : layer.hexes) {
    const auto at = [&](std::size_t k) -> const primal::Point& {
      return p[primal::index_cast<std::size_t>(b.corners[k])];
    };
    const auto mean = [&](std::array<std::array<std::size_t, 2>, 4> edges) {
      double sum = 0.0;
      for (const auto& [i, j] : edges) sum += (at(j) - at(i)).norm();
      return sum / 4.0;
    };
    sides.emplace_back(mean({{{0, 3}, {1, 2}, {4, 7}, {5, 6}}}),
                       mean({{{0, 4}, {1, 5}, {2, 6}, {3, 7}}}),
                       mean({{{0, 1}, {3, 2}, {4, 5}, {7, 6}}}));
  }
  return sides;
}

const char* buffer_side_name(BufferSide side) { return side == BufferSide::kHex ? "hex" : "tet"; }

BufferSide parse_buffer_side(const std::string& word) {
  if (word == "hex") return BufferSide::kHex;
  if (word == "tet") return BufferSide::kTet;
  throw InvalidInput("buffer side '" + word + "': expected hex or tet");
}

BufferLayer insert_buffer_layer(const Model& input, const Interface& itf,
                                const BufferLayerOptions& opt) {
  validate(input, "insert_buffer_layer");
  if (!(opt.thickness >= 0.0 && opt.thickness <= max_buffer_thickness(opt.side)))
    throw InvalidInput("insert_buffer_layer: thickness " + std::to_string(opt.thickness) +
                       " from the " + buffer_side_name(opt.side) + " part (at most " +
                       std::to_string(max_buffer_thickness(opt.side)) + ")");
  return BufferBuilder(input, itf, opt).run();
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
