#include "templates/refine.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "primal/errors.hpp"
#include "stc/dualize.hpp"

namespace geode::templates {
namespace {

constexpr int kRefinement = 3;

// The refined (or coarse) face of the reference cell: a k x k grid of quads (k x 1 segments
// in 2D) at height v.
DicedPatch grid_face(int k, double v, int dim) {
  DicedPatch d;
  const auto at = [k](int i) { return -1.0 + 2.0 * i / k; };
  if (dim == 2) {
    for (int i = 0; i <= k; ++i) d.nodes.push_back(Point(at(i), v, 0));
    for (int i = 0; i < k; ++i) d.cells.push_back({i, i + 1});
    return d;
  }
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) d.nodes.push_back(Point(at(i), v, at(j)));
  const auto n = [k](int i, int j) { return i + (k + 1) * j; };
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) d.cells.push_back({n(i, j), n(i + 1, j), n(i + 1, j + 1), n(i, j + 1)});
  return d;
}

// Where the dual chords of a face cross the axis `axis`: the midpoints between consecutive
// node coordinates on that axis.
std::vector<double> chord_offsets(const DicedPatch& face, int axis) {
  std::set<double> c;
  for (const auto& p : face.nodes) c.insert(p[axis]);
  const std::vector<double> x(c.begin(), c.end());
  std::vector<double> mid;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) mid.push_back(0.5 * (x[i] + x[i + 1]));
  return mid;
}

// The sheets completing the fine side's chords that cross axis `axis` (u = 0, w = 2): the
// chord the coarse side shares becomes a plane; the two outer ones pair into a tunnel of
// roof `roof` over them.
void complete_chords(const DicedPatch& fine, const DicedPatch& coarse, int axis, double roof, const std::string& suffix,
                     std::vector<stc::Sheet>& tunnels, std::vector<stc::Sheet>& planes) {
  const std::vector<double> f = chord_offsets(fine, axis), c = chord_offsets(coarse, axis);
  if (f.size() != static_cast<std::size_t>(kRefinement) || c.size() != 1 || std::abs(f[1] - c[0]) > 1e-12)
    throw InvalidInput("refine3: the fine side must be the 3-refinement of the coarse side");
  const double mid = c[0], centre = 0.5 * (f.front() + f.back()), a = 0.5 * (f.back() - f.front());
  tunnels.push_back({"tunnel" + suffix, [axis, centre, a, roof](const Point& x) {
                       const double d = (x[axis] - centre) / a, y = x[1] / roof;
                       return d * d + y * y - 1.0;
                     }, "tunnel"});
  planes.push_back({"middle" + suffix, [axis, mid](const Point& x) { return x[axis] - mid; }, "plane"});
}

Template build(const RefineOptions& o, int dim) {
  const RefineArrangement R = refine3_arrangement(o, dim);
  const stc::Arrangement A = stc::compute_arrangement(R.sheets, R.domain, o.arrangement);
  const stc::DualMesh D = stc::dualize(A);
  return template_from_dual(D, R.sheets, R.domain, {R.fine, "fine-side"}, {R.coarse, "coarse-side"}, o.box);
}

int sheet_index(const Template& t, const std::string& name) {
  for (std::size_t s = 0; s < t.sheets.size(); ++s)
    if (t.sheets[s].name == name) return static_cast<int>(s);
  throw InvalidInput("refine3: the template has no sheet '" + name + "'");
}

}  // namespace

RefineArrangement refine3_arrangement(const RefineOptions& o, int dim) {
  if (dim != 2 && dim != 3) throw InvalidInput("refine3: dimension must be 2 or 3");
  for (int a = 0; a < dim; ++a)
    if (!(o.box[a] > 0) || !std::isfinite(o.box[a])) throw InvalidInput("refine3: box dimensions must be positive and finite");
  const bool order = dim == 2 ? 0 < o.layer && o.layer < o.high_roof && o.high_roof < 1
                              : 0 < o.layer && o.layer < o.low_roof && o.low_roof < o.high_roof && o.high_roof < 1;
  if (!order)
    throw InvalidInput(dim == 2 ? "refine3: heights must satisfy 0 < layer < roof < 1"
                                : "refine3: heights must satisfy 0 < layer < low roof < high roof < 1");
  RefineArrangement R;
  R.domain = dim == 2 ? stc::Domain(Point(-1, 0, 0), Point(1, 1, 0), 2) : stc::Domain(Point(-1, 0, -1), Point(1, 1, 1), 3);
  R.fine = grid_face(kRefinement, 0.0, dim);
  R.coarse = grid_face(1, 1.0, dim);
  std::vector<stc::Sheet> tunnels, planes;
  if (dim == 2) {
    complete_chords(R.fine, R.coarse, 0, o.high_roof, "", tunnels, planes);
  } else {
    // Chords running along x cross the w axis (2), those along z the u axis (0).
    complete_chords(R.fine, R.coarse, 2, o.high_roof, " x", tunnels, planes);
    complete_chords(R.fine, R.coarse, 0, o.low_roof, " z", tunnels, planes);
  }
  R.sheets = tunnels;
  R.sheets.insert(R.sheets.end(), planes.begin(), planes.end());
  const double layer = o.layer;
  R.sheets.push_back({"layer", [layer](const Point& x) { return x[1] - layer; }, "plane"});
  return R;
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
        const std::vector<int> signs{sg[static_cast<std::size_t>(tunnel)], sg[static_cast<std::size_t>(middle)],
                                     sg[static_cast<std::size_t>(layer)]};
        const unsigned faces = ((f >> (2 * s.across)) & 3u) | (((f >> 2) & 3u) << 2);
        const auto it = where.find({signs, faces});
        if (it == where.end())
          throw TopologyError("refine3: a side-face node has no counterpart in the 2D refinement template");
        Point p = t.hex.points[n];
        p[s.across] = it->second.x();
        p[1] = it->second.y();
        if (placed[n] && (p - t.hex.points[n]).norm() > 1e-9 * o.box.norm())
          throw TopologyError("refine3: two side faces place a node on their common edge differently");
        t.hex.points[n] = p;
        placed[n] = 1;
      }
    }
  }
  Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
  for (const auto& p : t.hex.points) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
  auto constraints = primal::box_constraints(t.hex.points, lo, up, {true, true, true, true, true, true});
  return primal::smooth_hex_mesh(t.hex, constraints);
}

}  // namespace geode::templates
