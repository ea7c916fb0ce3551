#include <geode/templates/refine.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/templates/spec.hpp>

namespace geode::templates {
namespace {

using nlohmann::json;

constexpr int kRefinement = 3;

// The refined (or coarse) face of the box: a k x k grid of quads (k segments in 2D) at height
// y, nodes in lexicographic order.
InterfacePatch grid_face(int k, double y, const Eigen::Vector3d& box, int dim) {
  InterfacePatch d;
  d.dim = dim;
  const auto at = [k](int i, double width) { return width * (2.0 * i - k) / (2.0 * k); };
  if (dim == 2) {
    for (int i = 0; i <= k; ++i) d.points.push_back(Point(at(i, box.x()), y, 0));
    for (int i = 0; i < k; ++i) d.cells.push_back({i, i + 1});
    return d;
  }
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) d.points.push_back(Point(at(i, box.x()), y, at(j, box.z())));
  const auto n = [k](int i, int j) { return i + (k + 1) * j; };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i)
      d.cells.push_back({n(i, j), n(i + 1, j), n(i + 1, j + 1), n(i, j + 1)});
  return d;
}

// Where the dual chords of a face cross the axis `axis`: the midpoints between consecutive
// node coordinates on that axis.
std::vector<double> chord_offsets(const InterfacePatch& face, int axis) {
  std::set<double> c;
  for (const auto& p : face.points) c.insert(p[axis]);
  const std::vector<double> x(c.begin(), c.end());
  std::vector<double> mid;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) mid.push_back(0.5 * (x[i] + x[i + 1]));
  return mid;
}

json vec(const Point& p, int dim) {
  return dim == 3 ? json{p.x(), p.y(), p.z()} : json{p.x(), p.y()};
}

SheetSpec sheet(const std::string& name, const std::string& kind, json shape) {
  return {name, kind, json{{kind, std::move(shape)}}};
}

// The sheets completing the fine side's chords that cross axis `axis` (x = 0, z = 2): the
// chord the coarse side shares becomes a plane; the two outer ones pair into a tunnel of roof
// height `roof` over them (the spec's tunnel shape, footed on the fine face at y = foot).
void complete_chords(const InterfacePatch& fine, const InterfacePatch& coarse, int axis,
                     double roof, double foot, const std::string& suffix, int dim,
                     std::vector<SheetSpec>& tunnels, std::vector<SheetSpec>& planes) {
  const std::vector<double> f = chord_offsets(fine, axis), c = chord_offsets(coarse, axis);
  const double width = f.empty() ? 0.0 : f.back() - f.front();
  if (f.size() != primal::index_cast<std::size_t>(kRefinement) || c.size() != 1 ||
      std::abs(f[1] - c[0]) > 1e-12 * width)
    throw InvalidInput("refine3: the fine side must be the 3-refinement of the coarse side");
  Point centre = Point::Zero(), normal = Point::Zero();
  centre[axis] = 0.5 * (f.front() + f.back());
  centre.y() = foot;
  normal[axis] = 1.0;
  json tunnel = {{"point", vec(centre, dim)}, {"half_width", 0.5 * width}, {"height", roof}};
  // A tunnel runs across the axis its chords cross: along z over x, along x over z.
  if (dim == 3) tunnel["along"] = axis == 0 ? json{0.0, 0.0, 1.0} : json{1.0, 0.0, 0.0};
  tunnels.push_back(sheet("tunnel" + suffix, "tunnel", tunnel));
  Point mid = Point::Zero();
  mid[axis] = c[0];
  planes.push_back(
      sheet("middle" + suffix, "plane", {{"point", vec(mid, dim)}, {"normal", vec(normal, dim)}}));
}

Template build(const RefineOptions& o, int dim) {
  return build_template(refine_spec(o, dim), o.arrangement);
}

int sheet_index(const Template& t, const std::string& name) {
  for (std::size_t s = 0; s < t.sheets.size(); ++s)
    if (t.sheets[s].name == name) return static_cast<int>(s);
  throw InvalidInput("refine3: the template has no sheet '" + name + "'");
}

}  // namespace

ArrangementSpec refine_spec(const RefineOptions& o, int dim) {
  if (dim != 2 && dim != 3) throw InvalidInput("refine3: dimension must be 2 or 3");
  for (int a = 0; a < dim; ++a)
    if (!(o.box[a] > 0) || !std::isfinite(o.box[a]))
      throw InvalidInput("refine3: box dimensions must be positive and finite");
  const bool order =
      dim == 2 ? 0 < o.layer && o.layer < o.high_roof && o.high_roof < 1
               : 0 < o.layer && o.layer < o.low_roof && o.low_roof < o.high_roof && o.high_roof < 1;
  if (!order)
    throw InvalidInput(dim == 2
                           ? "refine3: heights must satisfy 0 < layer < roof < 1"
                           : "refine3: heights must satisfy 0 < layer < low roof < high roof < 1");
  ArrangementSpec spec;
  spec.dim = dim;
  const Point half(0.5 * o.box.x(), 0.5 * o.box.y(), dim == 3 ? 0.5 * o.box.z() : 0.0);
  spec.domain = stc::Domain(-half, half, dim);
  const double bottom = -half.y(), height = o.box.y();
  spec.bottom_face = grid_face(kRefinement, bottom, o.box, dim);
  spec.top_face = grid_face(1, half.y(), o.box, dim);
  std::vector<SheetSpec> tunnels, planes;
  if (dim == 2) {
    complete_chords(*spec.bottom_face, *spec.top_face, 0, o.high_roof * height, bottom, "", dim,
                    tunnels, planes);
  } else {
    // Chords running along x cross the z axis (2), those along z the x axis (0).
    complete_chords(*spec.bottom_face, *spec.top_face, 2, o.high_roof * height, bottom, " x", dim,
                    tunnels, planes);
    complete_chords(*spec.bottom_face, *spec.top_face, 0, o.low_roof * height, bottom, " z", dim,
                    tunnels, planes);
  }
  spec.sheets = tunnels;
  spec.sheets.insert(spec.sheets.end(), planes.begin(), planes.end());
  spec.sheets.push_back(sheet("layer", "plane",
                              {{"point", vec(Point(0, bottom + o.layer * height, 0), dim)},
                               {"normal", vec(Point::UnitY(), dim)}}));
  return spec;
}

Template build_refine3(const RefineOptions& options) { return build(options, 3); }
Template build_refine3_2d(const RefineOptions& options) { return build(options, 2); }

primal::SmoothResult smooth_refine3(Template& t, const RefineOptions& o, bool match_sides) {
  if (t.dim == 2 || !match_sides) return smooth_template(t, false);
  // Side faces: axis 0 (x = +-box.x/2, showing the tunnel along x over w) and axis 2 (z,
  // showing the tunnel along z over u). A side node is the 2D node on the same sides of the
  // face's tunnel, middle plane and layer, and on the same edges of the face.
  struct Side {
    int axis, across;  // face normal axis; the 3D axis the 2D template's u runs along
    const char* suffix;
    double width;
  };
  const Side sides[] = {{0, 2, " x", o.box.z()}, {2, 0, " z", o.box.x()}};
  const int layer = sheet_index(t, "layer");
  std::vector<char> placed(t.hex.points.size(), 0);
  for (const Side& s : sides) {
    RefineOptions o2 = o;
    o2.box = Eigen::Vector3d(s.width, o.box.y(), s.width);
    Template t2 = build_refine3_2d(o2);
    smooth_template(t2, false);
    using Key = std::pair<std::vector<int>, unsigned>;
    std::map<Key, Point> where;
    for (std::size_t n = 0; n < t2.quad.points.size(); ++n)
      where[{t2.node_signs[n], t2.node_faces[n]}] = t2.quad.points[n];
    const int tunnel = sheet_index(t, "tunnel" + std::string(s.suffix));
    const int middle = sheet_index(t, "middle" + std::string(s.suffix));
    for (std::size_t n = 0; n < t.hex.points.size(); ++n) {
      const unsigned f = t.node_faces[n];
      for (bool high : {false, true}) {
        if (!((f >> stc::box_face(s.axis, high)) & 1u)) continue;
        const auto& sg = t.node_signs[n];
        const std::vector<int> signs{sg[primal::index_cast<std::size_t>(tunnel)],
                                     sg[primal::index_cast<std::size_t>(middle)],
                                     sg[primal::index_cast<std::size_t>(layer)]};
        const unsigned faces = ((f >> (2 * s.across)) & 3u) | (((f >> 2) & 3u) << 2);
        const auto it = where.find({signs, faces});
        if (it == where.end())
          throw TopologyError(
              "refine3: a side-face node has no counterpart in the 2D refinement template");
        Point p = t.hex.points[n];
        p[s.across] = it->second.x();
        p[1] = it->second.y();
        if (placed[n] && (p - t.hex.points[n]).norm() > 1e-9 * o.box.norm())
          throw TopologyError(
              "refine3: two side faces place a node on their common edge differently");
        t.hex.points[n] = p;
        placed[n] = 1;
      }
    }
  }
  Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
  for (const auto& p : t.hex.points) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
  auto constraints =
      primal::box_constraints(t.hex.points, lo, up, {true, true, true, true, true, true});
  return primal::smooth_hex_mesh(t.hex, constraints);
}

}  // namespace geode::templates
