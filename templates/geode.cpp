#include <geode/templates/geode.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <regex>
#include <set>
#include <tuple>

#include <geode/primal/errors.hpp>
#include <geode/primal/topology.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/dualize.hpp>
#include <geode/templates/completion.hpp>
#include <geode/templates/spec.hpp>

namespace geode::templates {
namespace {

using primal::Index;

// Reference buffer cell: u, w in [-1, 1] across, v in [0, 1] from the hex side up.
stc::Domain reference_domain(int dim) {
  if (dim == 2) return {Point(-1, 0, 0), Point(1, 1, 0), 2};
  return {Point(-1, 0, -1), Point(1, 1, 1), 3};
}

// The tet side's centre vertex (the four-triangle split's), in the reference cell.
bool is_face_centre(const Point& p) { return std::abs(p.x()) < 1e-12 && std::abs(p.z()) < 1e-12; }

std::string corner_name(const Point& p) {
  return std::string("(") + (p[0] < 0 ? "-x" : "+x") + "," + (p[2] < 0 ? "-z" : "+z") + ")";
}

// Box faces a point lies on.
unsigned faces_of(const Point& r, const stc::Domain& D) {
  unsigned f = 0;
  const double eps = 1e-12 * (D.hi - D.lo).norm();
  for (int a = 0; a < D.dim; ++a) {
    if (std::abs(r[a] - D.lo[a]) < eps) f |= 1u << stc::box_face(a, false);
    if (std::abs(r[a] - D.hi[a]) < eps) f |= 1u << stc::box_face(a, true);
  }
  return f;
}

// Put the template's nodes on one interface face where dicing puts them. A dual node on that
// face matches the diced node whose neighbourhood inside the cell has the same sides of every
// sheet and which lies on the same box faces. Then every diced cell must be a boundary
// element face of the template: the boundary is the prescribed one.
void place_interface(const stc::DualMesh& D, const std::vector<stc::Sheet>& sheets,
                     const DicedPatch& diced, int face, const stc::Domain& dom,
                     std::vector<Point>& pts, const char* side_name) {
  const std::size_t nodes = D.node_faces.size();
  std::vector<int> node_of(diced.nodes.size(), -1);
  const Point centre = 0.5 * (dom.lo + dom.hi);
  for (std::size_t i = 0; i < diced.nodes.size(); ++i) {
    const Point q = diced.nodes[i];
    // Sample just inside the cell, towards its centre, to read the sides of the sheets.
    const Point s = q + 1e-7 * (centre - q);
    std::vector<int> sg;
    for (const auto& sh : sheets) sg.push_back(sh.field(s) < 0 ? -1 : 1);
    const unsigned f = faces_of(q, dom);
    for (std::size_t n = 0; n < nodes; ++n) {
      if (D.node_faces[n] != f || D.node_signs[n] != sg) continue;
      if (node_of[i] >= 0)
        throw TopologyError(std::string("geode: two template nodes match the diced ") + side_name +
                            " node " + std::to_string(i) +
                            ": the boundary is not the prescribed one");
      node_of[i] = static_cast<int>(n);
    }
    if (node_of[i] < 0)
      throw TopologyError(std::string("geode: no template node matches the diced ") + side_name +
                          " node " + std::to_string(i) +
                          ": the boundary is not the prescribed one");
  }
  // Every dual node on that face must be matched, and every diced cell must be a face of it.
  std::set<int> matched(node_of.begin(), node_of.end());
  for (std::size_t n = 0; n < nodes; ++n)
    if (((D.node_faces[n] >> face) & 1u) && !matched.count(static_cast<int>(n)))
      throw TopologyError(std::string("geode: the template has a node on the ") + side_name +
                          " face that the diced interface does not have");
  std::set<std::vector<int>> faces, on_face;  // on_face: the faces lying on the box face
  auto add_faces = [&](const auto& elements, const auto& table) {
    for (const auto& e : elements)
      for (const auto& fc : table) {
        std::vector<int> k;
        for (int c : fc) k.push_back(e[primal::index_cast<std::size_t>(c)]);
        std::sort(k.begin(), k.end());
        if (std::all_of(k.begin(), k.end(), [&](int n) {
              return (D.node_faces[primal::index_cast<std::size_t>(n)] >> face) & 1u;
            }))
          on_face.insert(k);
        faces.insert(k);
      }
  };
  if (D.dim == 3)
    add_faces(D.hex.hexes, primal::topology::kHexFaceCorners);
  else
    add_faces(D.quad.quads, primal::topology::kQuadEdgeCorners);
  std::set<std::vector<int>> given;
  for (const auto& c : diced.cells) {
    std::vector<int> k;
    for (int i : c) k.push_back(node_of[primal::index_cast<std::size_t>(i)]);
    std::sort(k.begin(), k.end());
    if (!faces.count(k))
      throw TopologyError(
          std::string("geode: a diced ") + side_name +
          " cell is not a face of the template: the boundary is not the prescribed one");
    if (!given.insert(k).second)
      throw TopologyError(std::string("geode: a ") + side_name +
                          " cell is given twice: the boundary is not the prescribed one");
  }
  // Exactly these cells: a part of them, its nodes all given, was taken (a hunt's refine3 spec
  // with 1 of its 9 bottom quads).
  if (given != on_face)
    throw TopologyError(std::string("geode: ") + side_name + ": " + std::to_string(given.size()) +
                        " cells given, the template has " + std::to_string(on_face.size()) +
                        " there: the boundary is not the prescribed one");
  for (std::size_t i = 0; i < diced.nodes.size(); ++i)
    pts[primal::index_cast<std::size_t>(node_of[i])] = diced.nodes[i];
}

InterleaveChecks check_interleave(const stc::Arrangement& A, const std::vector<SheetInfo>& info,
                                  const std::vector<stc::Sheet>& sheets) {
  InterleaveChecks c;
  std::vector<int> tunnels, domes;
  for (int s = 0; s < primal::index_cast<int>(info.size()); ++s)
    (info[primal::index_cast<std::size_t>(s)].kind == "tunnel" ? tunnels : domes).push_back(s);
  auto in_all_tunnels = [&](const Point& x) {
    for (int t : tunnels)
      if (sheets[primal::index_cast<std::size_t>(t)].field(x) >= 0) return false;
    return true;
  };
  auto in_some_tunnel = [&](const Point& x) {
    for (int t : tunnels)
      if (sheets[primal::index_cast<std::size_t>(t)].field(x) < 0) return true;
    return false;
  };
  auto is_dome = [&](int s) { return info[primal::index_cast<std::size_t>(s)].kind == "dome"; };
  c.triple_domes_in_pocket = true;
  for (const auto& v : A.vertices) {
    if (!std::all_of(v.sheets.begin(), v.sheets.end(), is_dome)) continue;
    ++c.triple_dome_points;
    if (!in_all_tunnels(v.x)) {
      c.triple_domes_in_pocket = false;
      c.failures.push_back(
          "condition 1: the point where three domes meet is not inside both tunnels");
    }
  }
  const int top = stc::box_face(1, true);
  c.dome_curves_exit_in_tunnels = true;
  for (const auto& cv : A.curves) {
    if (A.domain.dim != 3 || cv.sheets.size() != 2 || !is_dome(cv.sheets[0]) ||
        !is_dome(cv.sheets[1]))
      continue;
    ++c.dome_curves;
    if (cv.closed) {
      c.dome_curves_exit_in_tunnels = false;
      c.failures.push_back("condition 2: a dome-dome curve is closed inside the cell");
      continue;
    }
    if (cv.end_faces[0] == top && cv.end_faces[1] == top) {
      ++c.dome_curves_on_tet_face;
      continue;
    }
    for (int e = 0; e < 2; ++e) {
      const int f = cv.end_faces[primal::index_cast<std::size_t>(e)];
      if (f == top) continue;
      const Point x = e == 0 ? cv.polyline.front() : cv.polyline.back();
      if (f == stc::box_face(1, false) || !in_some_tunnel(x)) {
        c.dome_curves_exit_in_tunnels = false;
        c.failures.push_back("condition 2: the curve of " +
                             info[primal::index_cast<std::size_t>(cv.sheets[0])].name + " and " +
                             info[primal::index_cast<std::size_t>(cv.sheets[1])].name +
                             " leaves the cell outside every tunnel entrance");
      }
    }
  }
  return c;
}

// The interface cells before dicing, in reference coordinates; throws InvalidInput for a
// degenerate box or push.
std::pair<InterfacePatch, InterfacePatch> reference_patches(const GeodeOptions& o, int dim) {
  if (dim != 2 && dim != 3) throw InvalidInput("geode: dimension must be 2 or 3");
  for (int a = 0; a < dim; ++a)
    if (!(o.box[a] > 0) || !std::isfinite(o.box[a]))
      throw InvalidInput("geode: box dimensions must be positive and finite");
  if (const std::string why = push_error(o.push); !why.empty()) throw InvalidInput("geode: " + why);
  InterfacePatch bottom, top;
  bottom.dim = top.dim = dim;
  if (dim == 2) {
    bottom.points = {Point(-1, 0, 0), Point(1, 0, 0)};
    bottom.cells = {{0, 1}};
    top.points = {Point(-1, 1, 0), Point(1, 1, 0)};
    top.cells = {{0, 1}};
  } else {
    bottom.points = {Point(-1, 0, -1), Point(1, 0, -1), Point(1, 0, 1), Point(-1, 0, 1)};
    bottom.cells = {{0, 1, 2, 3}};
    // Top corners, counter-clockwise seen from above (y up): (-x,+z) (+x,+z) (+x,-z) (-x,-z).
    top.points = {Point(-1, 1, 1), Point(1, 1, 1), Point(1, 1, -1), Point(-1, 1, -1)};
    if (o.split == TopSplit::kFourTriangles) {
      top.points.push_back(Point(0, 1, 0));
      top.cells = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    } else if (o.diagonal == Diagonal::kMain) {
      top.cells = {{0, 1, 2}, {0, 2, 3}};
    } else {
      top.cells = {{0, 1, 3}, {1, 2, 3}};
    }
  }
  return {bottom, top};
}

}  // namespace

std::string push_error(const PushParameters& p, std::string* key) {
  const auto fault = [key](const char* name, const char* why) {
    if (key) *key = name;
    return std::string(why);
  };
  if (!(0 < p.low_roof && p.low_roof < p.high_roof && p.high_roof < 1))
    return fault(
        "low_roof",
        "tunnel roofs must satisfy 0 < low < high < 1 (tunnels must not reach the tet side)");
  if (!(0 < p.dome_depth && p.dome_depth < 1))
    return fault("dome_depth", "dome depth must be in (0, 1) (domes must not reach the hex side)");
  if (!(0 < p.dome_radius && p.dome_radius < 1))
    return fault("dome_radius", "dome radius blend must be in (0, 1)");
  if (!(p.centre_depth >= 0 && p.centre_depth < 1 && p.centre_radius >= 0 && p.centre_radius < 1))
    return fault(p.centre_depth >= 0 && p.centre_depth < 1 ? "centre_radius" : "centre_depth",
                 "centre dome depth and radius blend must be in [0, 1) (0: as the corner domes)");
  // Beyond 20 the superquadric is a box to the arrangement's sampling, and below 1 not convex.
  if (!(p.dome_exponent >= 1 && p.dome_exponent <= 20))
    return fault("dome_exponent", "dome exponent must be in [1, 20] (2: spheroids)");
  if (!(p.centre_exponent == 0 || (p.centre_exponent >= 1 && p.centre_exponent <= 20)))
    return fault("centre_exponent",
                 "centre dome exponent must be 0 (as the corner domes) or in [1, 20]");
  if (!(p.dome_offset >= 0 && p.dome_offset < 1))
    return fault("dome_offset",
                 "dome offset must be in [0, 1) (a fraction of the way to the tet side's centre)");
  for (int a = 0; a < 2; ++a)
    if (!(std::abs(p.centre_offset[primal::index_cast<std::size_t>(a)]) < 1))
      return fault(a == 0 ? "centre_offset[0]" : "centre_offset[1]",
                   "centre dome offsets must be in (-1, 1) (fractions of the half-width)");
  return "";
}

std::vector<stc::Sheet> complete_interface(const InterfacePatch& bottom, const InterfacePatch& top,
                                           const PushParameters& p, Higher higher, int dim) {
  const auto tunnels = complete_tunnels(bottom, [&](const Point& along) {
    if (dim == 2) return p.high_roof;
    const bool along_x = std::abs(along.x()) > std::abs(along.z());
    return along_x == (higher == Higher::kX) ? p.high_roof : p.low_roof;
  });
  const auto domes = complete_domes(top, 1.0, [&](int v) {
    const Point& x = top.points[primal::index_cast<std::size_t>(v)];
    DomeShape s{p.dome_depth, p.dome_radius, p.dome_exponent, Point::Zero()};
    if (is_face_centre(x)) {
      if (p.centre_depth > 0) s.depth = p.centre_depth;
      if (p.centre_radius > 0) s.blend = p.centre_radius;
      if (p.centre_exponent > 0) s.exponent = p.centre_exponent;
      s.offset = Point(p.centre_offset[0], 0, p.centre_offset[1]);
    } else if (p.dome_offset > 0) {
      // Toward the tet side's centre (u = w = 0 in the reference cell).
      s.offset = -p.dome_offset * Point(x[0], 0, x[2]);
    }
    return s;
  });
  std::vector<stc::Sheet> sheets;
  for (const auto& t : tunnels) {
    stc::Sheet s = t.sheet;
    if (dim == 3) s.name = std::abs(t.along.x()) > std::abs(t.along.z()) ? "tunnel x" : "tunnel z";
    sheets.push_back(s);
  }
  for (const auto& d : domes) {
    stc::Sheet s = d.sheet;
    const Point& v = top.points[primal::index_cast<std::size_t>(d.vertex)];
    s.name = dim == 2 ? std::string("dome ") + (v.x() < 0 ? "-x" : "+x")
                      : (is_face_centre(v) ? std::string("dome centre") : "dome " + corner_name(v));
    // A spec's tet side may have several vertices in one quadrant: names must stay unique.
    for (const auto& other : sheets)
      if (other.name == s.name) s.name += " " + std::to_string(d.vertex);
    sheets.push_back(s);
  }
  return sheets;
}

GeodeArrangement geode_arrangement(const GeodeOptions& o, int dim) {
  GeodeArrangement G;
  std::tie(G.hex_side, G.tet_side) = reference_patches(o, dim);
  G.domain = reference_domain(dim);
  G.sheets = complete_interface(G.hex_side, G.tet_side, o.push, o.higher, dim);
  return G;
}

ArrangementSpec geode_spec(const GeodeOptions& o, int dim) {
  auto [bottom, top] = reference_patches(o, dim);
  for (auto& q : bottom.points) q = box_point(q, o.box, dim);
  for (auto& q : top.points) q = box_point(q, o.box, dim);
  ArrangementSpec spec;
  spec.dim = dim;
  const stc::Domain ref = reference_domain(dim);
  spec.domain = stc::Domain(box_point(ref.lo, o.box, dim), box_point(ref.hi, o.box, dim), dim);
  spec.completion = CompletionSpec{bottom, top, o.higher, o.push};
  return spec;
}

namespace {

// A face whose cells the dual must have; name is for diagnoses, e.g. "hex-side".
struct PrescribedFace {
  DicedPatch cells;  // nodes and cells; owners are not read
  const char* name;
};

// The dual as a Template: nodes on the bottom (hex- or fine-side) and top faces placed at their
// prescribed cells' nodes when those are given.
Template dual_template(const stc::DualMesh& D, const std::vector<stc::Sheet>& sheets,
                       const stc::Domain& dom, const PrescribedFace* bottom,
                       const PrescribedFace* top) {
  const int dim = D.dim;
  Template T;
  T.dim = dim;
  for (const auto& s : sheets) T.sheets.push_back({s.name, s.kind});
  std::vector<Point> pts = dim == 3 ? D.hex.points : D.quad.points;
  if (bottom)
    place_interface(D, sheets, bottom->cells, stc::box_face(1, false), dom, pts, bottom->name);
  if (top) place_interface(D, sheets, top->cells, stc::box_face(1, true), dom, pts, top->name);
  if (dim == 3) {
    T.hex.hexes = D.hex.hexes;
    T.hex.points = std::move(pts);
  } else {
    T.quad.quads = D.quad.quads;
    T.quad.points = std::move(pts);
  }
  T.element_sheets = D.element_sheets;
  T.node_faces = D.node_faces;
  T.node_signs = D.node_signs;
  return T;
}

Template build_in_place(const ArrangementSpec& spec, const stc::ArrangementOptions& options) {
  const std::vector<stc::Sheet> sheets = spec_sheets(spec);
  const stc::Arrangement A = stc::compute_arrangement(sheets, spec.domain, options);
  const stc::DualMesh D = stc::dualize(A);
  Template T;
  if (spec.completion) {
    const PrescribedFace bottom{dice_patch(spec.completion->hex_side), "hex-side"};
    const PrescribedFace top{dice_patch(spec.completion->tet_side), "tet-side"};
    T = dual_template(D, sheets, spec.domain, &bottom, &top);
  } else {
    // A "faces" block's cells are taken as they are, not diced.
    const auto as_given = [](const std::optional<InterfacePatch>& p, const char* name) {
      return p ? std::optional<PrescribedFace>(
                     PrescribedFace{DicedPatch{p->points, p->cells, {}}, name})
               : std::nullopt;
    };
    const auto bottom = as_given(spec.bottom_face, "faces.bottom"),
               top = as_given(spec.top_face, "faces.top");
    T = dual_template(D, sheets, spec.domain, bottom ? &*bottom : nullptr, top ? &*top : nullptr);
  }
  T.checks = check_interleave(A, T.sheets, sheets);
  return T;
}

// The arrangement engine's and the smoother's tolerances are absolute, set for cells of the
// paper's size (24 x 14 x 24): a template is derived and smoothed in a copy of its box centred
// at the origin with its largest side kReferenceSize, and mapped back, so that it depends on
// the box's proportions alone (a box of 1e6 gives the 24 box's template scaled).
constexpr double kReferenceSize = 24.0;

struct ReferenceFrame {
  Point centre = Point::Zero();
  double scale = 1.0;  // reference = scale * (x - centre)
  bool identity() const { return scale == 1.0 && centre == Point::Zero(); }
  Point to_reference(const Point& x) const { return scale * (x - centre); }
  Point from_reference(const Point& r) const { return centre + r / scale; }
};

ReferenceFrame frame_of(const Point& lo, const Point& hi, int dim) {
  ReferenceFrame f;
  const Point size = hi - lo;
  const double largest = dim == 3 ? size.maxCoeff() : std::max(size.x(), size.y());
  if (!(largest > 0) || !std::isfinite(largest)) return f;
  f.centre = 0.5 * (lo + hi);
  if (dim == 2) f.centre.z() = 0;
  f.scale = kReferenceSize / largest;
  return f;
}

std::vector<Point>& template_points(Template& t) {
  return t.dim == 3 ? t.hex.points : t.quad.points;
}

primal::SmoothResult smooth_in_place(Template& t, bool slide_faces);

}  // namespace

Template build_template(const ArrangementSpec& spec, const stc::ArrangementOptions& options) {
  // A completion's sheets live in the box's reference frame, so only its coordinates scale.
  // Sheets given as shapes are in the spec's own units and are left as they are.
  if (!spec.completion || !spec.sheets.empty() || spec.domain.corners)
    return build_in_place(spec, options);
  const ReferenceFrame f = frame_of(spec.domain.lo, spec.domain.hi, spec.dim);
  if (f.identity()) return build_in_place(spec, options);
  ArrangementSpec s = spec;
  s.domain = stc::Domain(f.to_reference(spec.domain.lo), f.to_reference(spec.domain.hi), spec.dim);
  for (InterfacePatch* p : {&s.completion->hex_side, &s.completion->tet_side})
    for (Point& x : p->points) x = f.to_reference(x);
  Template T = build_in_place(s, options);
  for (Point& x : template_points(T)) x = f.from_reference(x);
  return T;
}

Template build_geode3d(const GeodeOptions& options) {
  return build_template(geode_spec(options, 3), options.arrangement);
}
Template build_geode2d(const GeodeOptions& options) {
  return build_template(geode_spec(options, 2), options.arrangement);
}

primal::SmoothResult smooth_template(Template& t, bool slide_faces) {
  // In the reference frame of the template's bounding box (see kReferenceSize).
  Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
  for (const auto& p : template_points(t)) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
  const ReferenceFrame f = template_points(t).empty() ? ReferenceFrame{} : frame_of(lo, up, t.dim);
  if (f.identity()) return smooth_in_place(t, slide_faces);
  for (Point& x : template_points(t)) x = f.to_reference(x);
  const primal::SmoothResult r = smooth_in_place(t, slide_faces);
  for (Point& x : template_points(t)) x = f.from_reference(x);
  return r;
}

namespace {

primal::SmoothResult smooth_in_place(Template& t, bool slide_faces) {
  if (t.dim == 3) {
    Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
    for (const auto& p : t.hex.points) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
    // Box faces in smooth.hpp order: -x, +x, -y, +y, -z, +z (as stc::box_face).
    std::array<bool, 6> fixed{};
    if (!slide_faces) fixed[2] = fixed[3] = true;
    const auto constraints = primal::box_constraints(t.hex.points, lo, up, fixed);
    return primal::smooth_hex_mesh(t.hex, constraints);
  }
  Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
  for (const auto& p : t.quad.points) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
  std::vector<primal::NodeConstraint> c;
  for (const auto& p : t.quad.points) {
    const bool on_x = std::abs(p.x() - lo.x()) < 1e-9 || std::abs(p.x() - up.x()) < 1e-9;
    const bool on_y = std::abs(p.y() - lo.y()) < 1e-9 || std::abs(p.y() - up.y()) < 1e-9;
    if ((on_x && on_y) || (on_y && !slide_faces))
      c.push_back(primal::NodeConstraint::fixed());
    else if (on_x)
      c.push_back(primal::NodeConstraint::line(p, Point::UnitY()));
    else if (on_y)
      c.push_back(primal::NodeConstraint::line(p, Point::UnitX()));
    else
      c.push_back(primal::NodeConstraint::plane(p, Point::UnitZ()));
  }
  return primal::smooth_quad_mesh(t.quad, Point::UnitZ(), c);
}

}  // namespace

std::vector<primal::Obstruction> template_obstructions(const Template& t) {
  primal::RealizabilityOptions o;
  o.node_faces = t.node_faces;
  return t.dim == 3 ? primal::find_obstructions(t.hex, o) : primal::find_obstructions(t.quad, o);
}

Point box_point(const Point& r, const Eigen::Vector3d& box, int dim) {
  return Point(0.5 * box.x() * r[0], box.y() * (r[1] - 0.5), dim == 3 ? 0.5 * box.z() * r[2] : 0.0);
}

Eigen::Vector3d parse_box(const std::string& text) {
  static const std::regex re(
      R"(^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*[xX]\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)(?:\s*[xX]\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?))?\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, re))
    throw InvalidInput("--box '" + text +
                       "': expected WIDTHxHEIGHTxDEPTH such as 24x14x24 (or 24x14 in 2D)");
  Eigen::Vector3d b(std::stod(m[1]), std::stod(m[2]), m[3].matched ? std::stod(m[3]) : 0.0);
  for (int a = 0; a < (m[3].matched ? 3 : 2); ++a)
    if (!(b[a] > 0)) throw InvalidInput("--box '" + text + "': every dimension must be positive");
  if (!m[3].matched) b.z() = b.x();
  return b;
}

}  // namespace geode::templates
