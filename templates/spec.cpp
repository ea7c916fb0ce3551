#include <geode/templates/spec.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <geode/primal/errors.hpp>

namespace geode::templates {
namespace {

using nlohmann::json;

// Shapes by name: the dimension they live in (0: both) and their fields' definitions.
const std::map<std::string, int>& shape_dims() {
  static const std::map<std::string, int> d = {
      {"plane", 0},   {"line", 2},         {"sphere", 3},   {"circle", 2}, {"ellipsoid", 3},
      {"ellipse", 2}, {"superquadric", 0}, {"cylinder", 3}, {"tunnel", 0}, {"dome", 3},
      {"union", 0},   {"intersection", 0}, {"offset", 0},   {"scaled", 0}};
  return d;
}

// Bounds: a spec is a handful of sheets, each a shape of a few nested parts. Deeper nesting
// (20,000 nested offsets) would recurse the reader off the stack, and thousands of sheets would
// take the arrangement hours (it meets every triple of sheets) before it could say anything.
constexpr int kMaxJsonDepth = 64;            // nesting of objects and arrays in the file
constexpr int kMaxShapeDepth = 16;           // shapes inside union / intersection / offset / scaled
constexpr std::size_t kMaxShapeParts = 256;  // shapes in one sheet, all levels
constexpr std::size_t kMaxSheets = 256;

// Validates spec JSON against the format, naming the spec and the JSON path of every fault.
class Reader {
 public:
  Reader(std::string source, int dim) : source_(std::move(source)), dim_(dim) {}

  [[noreturn]] void fail(const std::string& path, const std::string& why) const {
    throw InvalidInput(source_ + ": " + (path.empty() ? "" : path + ": ") + why);
  }

  void object(const json& j, const std::string& path, const std::set<std::string>& allowed) const {
    if (!j.is_object()) fail(path, "must be an object");
    for (const auto& [key, value] : j.items())
      if (!allowed.count(key)) fail(join(path, key), "unknown key");
  }
  const json& member(const json& j, const std::string& path, const std::string& key) const {
    if (!j.contains(key)) fail(join(path, key), "missing");
    return j.at(key);
  }
  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number");
    const double x = j.get<double>();
    if (!std::isfinite(x)) fail(path, "must be finite");
    return x;
  }
  double positive(const json& j, const std::string& path) const {
    const double x = number(j, path);
    if (!(x > 0)) fail(path, "must be > 0");
    return x;
  }
  Point point(const json& j, const std::string& path) const {
    if (!j.is_array() || primal::index_cast<int>(j.size()) != dim_)
      fail(path, "must be " + std::to_string(dim_) + " numbers (the spec's dim)");
    Point p = Point::Zero();
    for (int a = 0; a < dim_; ++a)
      p[a] = number(j[primal::index_cast<std::size_t>(a)], index(path, a));
    return p;
  }
  Point direction(const json& j, const std::string& path) const {
    const Point p = point(j, path);
    if (!(p.norm() > 0)) fail(path, "must not be zero");
    return p.normalized();
  }
  template <class F>
  void each(const json& j, const std::string& path, std::size_t min_count, const F& f) const {
    if (!j.is_array() || j.size() < min_count)
      fail(path, "must be an array of at least " + std::to_string(min_count));
    for (std::size_t i = 0; i < j.size(); ++i) f(j[i], index(path, static_cast<int>(i)));
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, int i) {
    return path + "[" + std::to_string(i) + "]";
  }

  stc::Domain domain(const json& j) const;
  // prescribed: a "faces" block's face (quads or segments, any number), else a completion's
  // side (the hex side one quad, the tet side triangles).
  InterfacePatch patch(const json& j, const std::string& path, const stc::Domain& box, bool top,
                       bool prescribed = false) const;
  PushParameters push(const json& j) const;
  stc::Field shape(const json& j, const std::string& path) const {
    std::size_t parts = 0;
    return shape(j, path, 0, parts);
  }

 private:
  stc::Field shape(const json& j, const std::string& path, int level, std::size_t& parts) const;
  // An orthonormal frame from optional "axes" (3D: the first two, 2D: the first), else x, y, z.
  std::array<Point, 3> frame(const json& j, const std::string& path) const;
  std::string source_;
  int dim_;
};

stc::Domain Reader::domain(const json& j) const {
  object(j, "domain", {"box", "hexahedron", "pyramid", "quadrilateral"});
  if (j.size() != 1)
    fail("domain", "give exactly one of box, hexahedron, pyramid (3D), quadrilateral (2D)");
  if (j.contains("box")) {
    const json& b = j["box"];
    if (!b.is_array() || b.size() != 2) fail("domain.box", "must be [low corner, high corner]");
    const Point lo = point(b[0], "domain.box[0]"), hi = point(b[1], "domain.box[1]");
    for (int a = 0; a < dim_; ++a)
      if (!(lo[a] < hi[a]))
        fail("domain.box", "the low corner must be below the high corner on every axis");
    return stc::Domain(lo, hi, dim_);
  }
  const bool pyramid = j.contains("pyramid");
  const bool hex = j.contains("hexahedron") || pyramid;
  const std::string key = pyramid ? "pyramid" : hex ? "hexahedron" : "quadrilateral";
  if (hex != (dim_ == 3))
    fail("domain." + key, "is a " + std::string(hex ? "3D" : "2D") + " domain");
  const json& c = j[key];
  const std::size_t n = pyramid ? 5 : hex ? 8 : 4;
  if (!c.is_array() || c.size() != n)
    fail("domain." + key, "must be " + std::to_string(n) + " corners");
  std::array<Point, 8> corners;
  for (std::size_t i = 0; i < n; ++i)
    corners[i] = point(c[i], index("domain." + key, static_cast<int>(i)));
  try {
    if (pyramid)
      return stc::Domain::pyramid({corners[0], corners[1], corners[2], corners[3], corners[4]});
    return hex ? stc::Domain::hexahedron(corners)
               : stc::Domain::quadrilateral({corners[0], corners[1], corners[2], corners[3]});
  } catch (const InvalidInput& e) {
    fail("domain." + key, e.what());
  }
}

InterfacePatch Reader::patch(const json& j, const std::string& path, const stc::Domain& box,
                             bool top, bool prescribed) const {
  object(j, path, {"points", "cells"});
  InterfacePatch p;
  p.dim = dim_;
  const double y = top ? box.hi.y() : box.lo.y();
  const double eps = 1e-9 * (box.hi - box.lo).norm();
  each(member(j, path, "points"), join(path, "points"), 2,
       [&](const json& q, const std::string& at) {
         const Point x = point(q, at);
         if (std::abs(x.y() - y) > eps)
           fail(at, std::string("must lie on the domain's ") + (top ? "high" : "low") +
                        "-y face (y = " + std::to_string(y) + ")");
         for (int a = 0; a < dim_; ++a)
           if (x[a] < box.lo[a] - eps || x[a] > box.hi[a] + eps) fail(at, "must lie in the domain");
         p.points.push_back(x);
       });
  const bool triangles = top && !prescribed;
  const std::size_t k = dim_ == 2 ? 2 : (triangles ? 3 : 4);
  each(member(j, path, "cells"), join(path, "cells"), 1, [&](const json& c, const std::string& at) {
    if (!c.is_array() || c.size() != k)
      fail(at, "must be " + std::to_string(k) + " point indices (" +
                   (dim_ == 2   ? "a segment"
                    : triangles ? "a triangle"
                                : "a quad") +
                   ")");
    std::vector<int> cell;
    for (std::size_t i = 0; i < k; ++i) {
      if (!c[i].is_number_integer() || c[i].get<long long>() < 0 ||
          c[i].get<long long>() >= static_cast<long long>(p.points.size()))
        fail(index(at, static_cast<int>(i)), "must be an index into points (0-based)");
      cell.push_back(c[i].get<int>());
    }
    p.cells.push_back(cell);
  });
  if (!top && !prescribed && p.cells.size() != 1)
    fail(join(path, "cells"), "the hex side is one cell (its tunnels are its chords)");
  return p;
}

PushParameters Reader::push(const json& j) const {
  object(j, "push",
         {"high_roof", "low_roof", "dome_depth", "dome_radius", "centre_depth", "centre_radius",
          "dome_exponent", "centre_exponent", "dome_offset", "centre_offset"});
  PushParameters p;
  const auto get = [&](const char* key, double& x) {
    if (j.contains(key)) x = number(j[key], join("push", key));
  };
  get("high_roof", p.high_roof);
  get("low_roof", p.low_roof);
  get("dome_depth", p.dome_depth);
  get("dome_radius", p.dome_radius);
  get("centre_depth", p.centre_depth);
  get("centre_radius", p.centre_radius);
  get("dome_exponent", p.dome_exponent);
  get("centre_exponent", p.centre_exponent);
  get("dome_offset", p.dome_offset);
  if (j.contains("centre_offset")) {
    const json& c = j["centre_offset"];
    if (!c.is_array() || c.size() != 2)
      fail("push.centre_offset", "must be [x, z] (fractions of the half-width)");
    for (std::size_t a = 0; a < 2; ++a)
      p.centre_offset[a] = number(c[a], index("push.centre_offset", static_cast<int>(a)));
  }
  std::string key;
  if (const std::string why = push_error(p, &key); !why.empty()) {
    // The roofs' order is a fault of the pair, so it names the push object; others their key.
    fail(key == "low_roof" ? "push" : join("push", key), why);
  }
  return p;
}

std::array<Point, 3> Reader::frame(const json& j, const std::string& path) const {
  std::array<Point, 3> e{Point::UnitX(), Point::UnitY(), Point::UnitZ()};
  if (!j.contains("axes")) return e;
  const std::string at = join(path, "axes");
  const json& a = j["axes"];
  const std::size_t n = dim_ == 3 ? 2 : 1;
  if (!a.is_array() || a.size() != n)
    fail(at, dim_ == 3 ? "must be the first two axes" : "must be the first axis");
  e[0] = direction(a[0], index(at, 0));
  if (dim_ == 2) {
    e[1] = Point(-e[0].y(), e[0].x(), 0);
    return e;
  }
  const Point second = direction(a[1], index(at, 1));
  e[1] = second - second.dot(e[0]) * e[0];
  if (!(e[1].norm() > 1e-9)) fail(index(at, 1), "must not be parallel to the first axis");
  e[1].normalize();
  e[2] = e[0].cross(e[1]);
  return e;
}

stc::Field Reader::shape(const json& j, const std::string& path, int level,
                         std::size_t& parts) const {
  if (level > kMaxShapeDepth)
    fail(path, "shapes nested deeper than " + std::to_string(kMaxShapeDepth) + " levels");
  if (++parts > kMaxShapeParts)
    fail(path, "more than " + std::to_string(kMaxShapeParts) + " shapes in one sheet");
  if (!j.is_object()) fail(path, "must be an object holding one shape");
  std::string kind;
  for (const auto& [key, value] : j.items())
    if (shape_dims().count(key)) {
      if (!kind.empty()) fail(path, "has two shapes, '" + kind + "' and '" + key + "'");
      kind = key;
    } else if (key != "name" && key != "kind") {  // a sheet's own keys; parse_spec checks those
      fail(join(path, key), "unknown key");
    }
  if (kind.empty()) {
    std::string known;
    for (const auto& [k, d] : shape_dims()) known += (known.empty() ? "" : ", ") + k;
    fail(path, "no shape (one of " + known + ")");
  }
  const int d = shape_dims().at(kind);
  const std::string at = join(path, kind);
  if (d != 0 && d != dim_)
    fail(at, "is a " + std::to_string(d) + "D shape; the spec's dim is " + std::to_string(dim_));
  const json& s = j[kind];

  if (kind == "union" || kind == "intersection") {
    if (s.is_array() && s.size() > kMaxShapeParts)
      fail(at, "more than " + std::to_string(kMaxShapeParts) + " shapes in one sheet");
    std::vector<stc::Field> fields;
    each(s, at, 2, [&](const json& q, const std::string& p) {
      fields.push_back(shape(q, p, level + 1, parts));
    });
    stc::Field f = fields[0];
    for (std::size_t i = 1; i < fields.size(); ++i)
      f = kind == "union" ? stc::field_union(f, fields[i]) : stc::field_intersection(f, fields[i]);
    return f;
  }
  if (kind == "offset" || kind == "scaled") {
    object(s, at, {"of", "by"});
    const stc::Field of = shape(member(s, at, "of"), join(at, "of"), level + 1, parts);
    const double by = number(member(s, at, "by"), join(at, "by"));
    if (kind == "offset") return stc::field_offset(of, by);
    if (by == 0) fail(join(at, "by"), "must not be zero");
    return stc::field_scaled(of, by);
  }
  if (kind == "plane" || kind == "line") {
    object(s, at, {"point", "normal"});
    const Point p = point(member(s, at, "point"), join(at, "point"));
    const Point n = direction(member(s, at, "normal"), join(at, "normal"));
    return [p, n](const Point& x) { return n.dot(x - p); };
  }
  if (kind == "sphere" || kind == "circle") {
    object(s, at, {"center", "radius"});
    const Point c = point(member(s, at, "center"), join(at, "center"));
    const double r = positive(member(s, at, "radius"), join(at, "radius"));
    return [c, r](const Point& x) { return (x - c).squaredNorm() / (r * r) - 1.0; };
  }
  if (kind == "ellipsoid" || kind == "ellipse" || kind == "superquadric") {
    const bool super = kind == "superquadric";
    if (super)
      object(s, at, {"center", "radii", "axes", "exponent"});
    else
      object(s, at, {"center", "radii", "axes"});
    const Point c = point(member(s, at, "center"), join(at, "center"));
    const Point r = point(member(s, at, "radii"), join(at, "radii"));
    for (int a = 0; a < dim_; ++a)
      if (!(r[a] > 0)) fail(index(join(at, "radii"), a), "must be > 0");
    const auto e = frame(s, at);
    double p = 2.0;
    if (super) {
      p = number(member(s, at, "exponent"), join(at, "exponent"));
      // Below 2 the field's gradient is not continuous where a coordinate crosses zero.
      if (!(p >= 2)) fail(join(at, "exponent"), "must be >= 2 (the field must be smooth)");
    }
    const int dim = dim_;
    return [c, r, e, p, dim](const Point& x) {
      double f = -1.0;
      for (int a = 0; a < dim; ++a)
        f += std::pow(std::abs(e[primal::index_cast<std::size_t>(a)].dot(x - c) / r[a]), p);
      return f;
    };
  }
  if (kind == "cylinder") {
    object(s, at, {"point", "axis", "radius", "radii", "up"});
    const Point p = point(member(s, at, "point"), join(at, "point"));
    const Point axis = direction(member(s, at, "axis"), join(at, "axis"));
    double a = 0, b = 0;
    Point up;
    if (s.contains("radius") == s.contains("radii"))
      fail(at, "give radius (circular) or radii with up (elliptic)");
    if (s.contains("radius")) {
      a = b = positive(s["radius"], join(at, "radius"));
      up = axis.unitOrthogonal();
    } else {
      const json& rr = s["radii"];
      if (!rr.is_array() || rr.size() != 2) fail(join(at, "radii"), "must be [across, up]");
      a = positive(rr[0], index(join(at, "radii"), 0));
      b = positive(rr[1], index(join(at, "radii"), 1));
      up = direction(member(s, at, "up"), join(at, "up"));
      up -= up.dot(axis) * axis;
      if (!(up.norm() > 1e-9)) fail(join(at, "up"), "must not be parallel to the axis");
      up.normalize();
    }
    const Point across = axis.cross(up);
    return [p, across, up, a, b](const Point& x) {
      const double u = across.dot(x - p) / a, v = up.dot(x - p) / b;
      return u * u + v * v - 1.0;
    };
  }
  if (kind == "tunnel") {
    // As complete_tunnels makes it: an elliptic arch of half-width a and height h over its
    // foot line (3D: through point along `along`; 2D: the point) in the interface plane.
    if (dim_ == 3)
      object(s, at, {"point", "along", "half_width", "height", "up"});
    else
      object(s, at, {"point", "half_width", "height", "up"});
    const Point p = point(member(s, at, "point"), join(at, "point"));
    const double a = positive(member(s, at, "half_width"), join(at, "half_width"));
    const double h = positive(member(s, at, "height"), join(at, "height"));
    const Point up = s.contains("up") ? direction(s["up"], join(at, "up")) : Point::UnitY();
    Point across(up.y(), -up.x(), 0);
    if (dim_ == 3) {
      Point along = direction(member(s, at, "along"), join(at, "along"));
      along -= along.dot(up) * up;
      if (!(along.norm() > 1e-9)) fail(join(at, "along"), "must not be parallel to up");
      across = along.normalized().cross(up);
    }
    return [p, across, up, a, h](const Point& x) {
      const double d = across.dot(x - p) / a, v = up.dot(x - p) / h;
      return d * d + v * v - 1.0;
    };
  }
  // dome, as complete_domes makes it: a half-spheroid of radius R reaching depth below its
  // vertex on the interface plane (up points out of the cell).
  object(s, at, {"vertex", "radius", "depth", "up"});
  const Point v = point(member(s, at, "vertex"), join(at, "vertex"));
  const double R = positive(member(s, at, "radius"), join(at, "radius"));
  const double depth = positive(member(s, at, "depth"), join(at, "depth"));
  const Point up = s.contains("up") ? direction(s["up"], join(at, "up")) : Point::UnitY();
  return [v, up, R, depth](const Point& x) {
    const Point q = x - v;
    const double h = up.dot(q);
    return (q - h * up).squaredNorm() / (R * R) + (h / depth) * (h / depth) - 1.0;
  };
}

// The box's reference frame of the completion builders (templates/completion.hpp): u, w in
// [-1, 1] across, v in [0, 1] from the low-y face up.
Point to_reference(const stc::Domain& box, const Point& x) {
  const Point c = 0.5 * (box.lo + box.hi), w = box.hi - box.lo;
  return Point(2 * (x.x() - c.x()) / w.x(), (x.y() - box.lo.y()) / w.y(),
               box.dim == 3 ? 2 * (x.z() - c.z()) / w.z() : 0.0);
}

json vector_json(const Point& p, int dim) {
  json v = json::array();
  for (int a = 0; a < dim; ++a) v.push_back(p[a]);
  return v;
}

json patch_json(const InterfacePatch& p) {
  json j;
  j["points"] = json::array();
  for (const auto& x : p.points) j["points"].push_back(vector_json(x, p.dim));
  j["cells"] = p.cells;
  return j;
}

// Keys in the order a reader expects them (the rest after, alphabetically).
int key_rank(const std::string& key) {
  static const std::vector<std::string> order = {
      "dim",           "domain",        "completion",
      "hex_side",      "tet_side",      "higher",
      "faces",         "bottom",        "top",
      "push",          "high_roof",     "low_roof",
      "dome_depth",    "dome_radius",   "centre_depth",
      "centre_radius", "dome_exponent", "centre_exponent",
      "dome_offset",   "centre_offset", "sheets",
      "name",          "kind",          "sweep"};
  const auto it = std::find(order.begin(), order.end(), key);
  return it == order.end() ? primal::index_cast<int>(order.size())
                           : static_cast<int>(it - order.begin());
}

// Arrays of numbers, and arrays of those, on one line; everything else one entry a line.
bool one_line(const json& j) {
  if (!j.is_array()) return j.is_primitive();
  return std::all_of(j.begin(), j.end(), [](const json& x) {
    return x.is_primitive() || (x.is_array() && std::all_of(x.begin(), x.end(), [](const json& y) {
                                  return y.is_primitive();
                                }));
  });
}

void format(const json& j, int indent, std::ostream& out) {
  const std::string pad(primal::index_cast<std::size_t>(indent + 2), ' '),
      end(primal::index_cast<std::size_t>(indent), ' ');
  if (one_line(j) || j.empty()) {
    if (!j.is_array()) {
      out << j.dump();
      return;
    }
    out << "[";
    for (std::size_t i = 0; i < j.size(); ++i) {
      out << (i ? ", " : "");
      format(j[i], indent, out);
    }
    out << "]";
  } else if (j.is_object()) {
    std::vector<std::string> keys;
    for (const auto& [key, value] : j.items()) keys.push_back(key);
    std::stable_sort(keys.begin(), keys.end(),
                     [](const auto& a, const auto& b) { return key_rank(a) < key_rank(b); });
    out << "{\n";
    for (std::size_t i = 0; i < keys.size(); ++i) {
      out << pad << json(keys[i]).dump() << ": ";
      format(j[keys[i]], indent + 2, out);
      out << (i + 1 < keys.size() ? ",\n" : "\n");
    }
    out << end << "}";
  } else {
    out << "[\n";
    for (std::size_t i = 0; i < j.size(); ++i) {
      out << pad;
      format(j[i], indent + 2, out);
      out << (i + 1 < j.size() ? ",\n" : "\n");
    }
    out << end << "]";
  }
}

// "a.b[2].c" -> JSON pointer "/a/b/2/c".
json::json_pointer pointer(const std::string& path, const std::string& source) {
  std::string p;
  std::string token;
  const auto flush = [&] {
    if (!token.empty()) p += "/" + token;
    token.clear();
  };
  for (char ch : path) {
    if (ch == '.' || ch == '[' || ch == ']')
      flush();
    else
      token += ch;
  }
  flush();
  if (p.empty()) throw InvalidInput(source + ": sweep: empty path");
  return json::json_pointer(p);
}

// Whether two validated sheet shapes are one surface: the same JSON, or two planes (lines) with
// parallel normals through one another's point (a plane's field is its signed distance, so the
// sign of the normal does not change the surface).
bool coincident(const json& a, const json& b, int dim) {
  if (a == b) return true;
  const auto plane = [dim](const json& s, Point& p, Point& n) {
    const char* key = s.contains("plane") ? "plane" : s.contains("line") ? "line" : nullptr;
    if (!key) return false;
    p = n = Point::Zero();
    for (int i = 0; i < dim; ++i) {
      p[i] = s[key]["point"][primal::index_cast<std::size_t>(i)].get<double>();
      n[i] = s[key]["normal"][primal::index_cast<std::size_t>(i)].get<double>();
    }
    n.normalize();
    return true;
  };
  Point pa, na, pb, nb;
  if (!plane(a, pa, na) || !plane(b, pb, nb)) return false;
  const double scale = std::max({1.0, pa.norm(), pb.norm()});
  return na.cross(nb).norm() < 1e-12 && std::abs(na.dot(pb - pa)) < 1e-12 * scale;
}

}  // namespace

ArrangementSpec parse_spec(const json& j, const std::string& source) {
  Reader top(source, 3);
  top.object(j, "", {"dim", "domain", "completion", "faces", "push", "sheets", "sweep", "comment"});
  ArrangementSpec spec;
  const json& d = top.member(j, "", "dim");
  if (!d.is_number_integer() || (d.get<long long>() != 2 && d.get<long long>() != 3))
    top.fail("dim", "must be 2 or 3");
  spec.dim = d.get<int>();
  const Reader r(source, spec.dim);
  spec.domain = r.domain(r.member(j, "", "domain"));

  if (j.contains("completion")) {
    const json& c = j["completion"];
    r.object(c, "completion", {"hex_side", "tet_side", "higher"});
    if (spec.domain.corners)
      r.fail("completion", "needs a box domain (the builders work in its reference frame)");
    CompletionSpec cs;
    cs.hex_side =
        r.patch(r.member(c, "completion", "hex_side"), "completion.hex_side", spec.domain, false);
    cs.tet_side =
        r.patch(r.member(c, "completion", "tet_side"), "completion.tet_side", spec.domain, true);
    if (c.contains("higher")) {
      if (c["higher"] != "x" && c["higher"] != "z")
        r.fail("completion.higher", "must be \"x\" or \"z\"");
      cs.higher = c["higher"] == "z" ? Higher::kZ : Higher::kX;
    }
    if (j.contains("push")) cs.push = r.push(j["push"]);
    spec.completion = cs;
  } else if (j.contains("push")) {
    r.fail("push", "is read by a completion block, and there is none");
  }
  if (j.contains("faces")) {
    const json& f = j["faces"];
    r.object(f, "faces", {"bottom", "top"});
    if (spec.completion) r.fail("faces", "a completion block prescribes both faces already");
    if (spec.domain.corners)
      r.fail("faces", "needs a box domain (the faces are its low-y and high-y faces)");
    if (f.empty()) r.fail("faces", "give bottom, top or both");
    if (f.contains("bottom"))
      spec.bottom_face = r.patch(f["bottom"], "faces.bottom", spec.domain, false, true);
    if (f.contains("top")) spec.top_face = r.patch(f["top"], "faces.top", spec.domain, true, true);
  }

  std::set<std::string> names;
  if (j.contains("sheets") && j["sheets"].is_array() && j["sheets"].size() > kMaxSheets)
    r.fail("sheets", std::to_string(j["sheets"].size()) + " sheets; at most " +
                         std::to_string(kMaxSheets) +
                         " (the arrangement meets every triple of sheets)");
  if (j.contains("sheets"))
    r.each(j["sheets"], "sheets", 0, [&](const json& s, const std::string& at) {
      if (!s.is_object()) r.fail(at, "must be an object");
      const json& name = r.member(s, at, "name");
      if (!name.is_string() || name.get<std::string>().empty())
        r.fail(Reader::join(at, "name"), "must be a non-empty string");
      SheetSpec sh;
      sh.name = name.get<std::string>();
      const std::string where = at + " (" + sh.name + ")";
      if (!names.insert(sh.name).second) r.fail(where, "a second sheet of this name");
      for (const auto& [key, value] : s.items())
        if (key != "name" && key != "kind" && !shape_dims().count(key))
          r.fail(Reader::join(at, key), "unknown key (sheet '" + sh.name + "')");
      if (s.contains("kind") && !s["kind"].is_string())
        r.fail(Reader::join(at, "kind"), "must be a string");
      r.shape(s, at);  // validates
      for (const auto& [key, value] : s.items())
        if (shape_dims().count(key)) sh.shape = json{{key, value}}, sh.kind = key;
      if (s.contains("kind")) sh.kind = s["kind"].get<std::string>();
      // Two sheets that are one surface are never in general position; say so now, not after
      // tracing every curve between them.
      for (std::size_t o = 0; o < spec.sheets.size(); ++o)
        if (coincident(spec.sheets[o].shape, sh.shape, spec.dim))
          r.fail(where, "the same surface as sheets[" + std::to_string(o) + "] (" +
                            spec.sheets[o].name + "): coincident sheets cannot be arranged");
      spec.sheets.push_back(sh);
    });
  else if (!spec.completion)
    r.fail("sheets", "missing (or give a completion block)");
  if (spec.sheets.empty() && !spec.completion) r.fail("sheets", "no sheets");
  if (j.contains("sweep")) {
    spec.sweep = j["sweep"];
    spec_sweep(j, source);  // validates
  }
  return spec;
}

json read_spec_json(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    const bool exists = fs::exists(path, ec);  // ec: why not, when not simply missing
    throw InvalidInput(name + (exists ? ": not a regular file"
                                      : ": " + (ec ? ec.message() : std::string("no such file"))));
  }
  // A spec is a few kilobytes; anything much larger is not one.
  if (fs::file_size(path, ec) > (16u << 20))
    throw InvalidInput(name + ": larger than 16 MiB, not a spec");
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw InvalidInput(name + ": cannot be read");
  return parse_spec_text(text.str(), name);
}

json parse_spec_text(std::string_view text, const std::string& name) {
  try {
    // Nesting and the sheet count are bounded while parsing, before a deep or long tree is built
    // (and torn down): 200,000 sheets once took 9.5 s and 243 MB to be refused afterwards.
    // Depths as the parser gives them: 1 for the top object's keys and arrays, 2 for the
    // elements of the top-level "sheets" array.
    bool sheets_key = false, in_sheets = false;
    std::size_t sheets = 0;
    const json::parser_callback_t depth_check = [&](int depth, json::parse_event_t event,
                                                    json& parsed) {
      using Event = json::parse_event_t;
      if ((event == Event::object_start || event == Event::array_start) && depth >= kMaxJsonDepth)
        throw InvalidInput(name + ": nested deeper than " + std::to_string(kMaxJsonDepth) +
                           " levels, not a spec");
      if (depth == 1) {
        if (event == Event::key) sheets_key = parsed == "sheets";
        if (event == Event::array_start) in_sheets = sheets_key;
        if (event == Event::array_end) in_sheets = false;
      } else if (depth == 2 && in_sheets &&
                 (event == Event::object_start || event == Event::array_start ||
                  event == Event::value) &&
                 ++sheets > kMaxSheets) {
        throw InvalidInput(name + ": sheets: more than " + std::to_string(kMaxSheets) +
                           " sheets (the arrangement meets every triple of sheets)");
      }
      return true;
    };
    json j = json::parse(text, depth_check, true, /*ignore_comments=*/true);
    if (!j.is_object()) throw InvalidInput(name + ": must be a JSON object");
    return j;
  } catch (const json::parse_error& e) {
    throw InvalidInput(name + ": not valid JSON: " + e.what());
  } catch (const json::out_of_range& e) {  // a number too large for a double
    throw InvalidInput(name + ": not valid JSON: " + e.what());
  }
}

ArrangementSpec read_spec(const std::filesystem::path& path) {
  return parse_spec(read_spec_json(path), path.filename().string());
}

json spec_json(const ArrangementSpec& s) {
  json j;
  j["dim"] = s.dim;
  if (s.domain.corners) {
    json c = json::array();
    for (int i = 0; i < (s.domain.is_pyramid ? 5 : s.dim == 3 ? 8 : 4); ++i)
      c.push_back(vector_json((*s.domain.corners)[primal::index_cast<std::size_t>(i)], s.dim));
    j["domain"][s.domain.is_pyramid ? "pyramid" : s.dim == 3 ? "hexahedron" : "quadrilateral"] = c;
  } else {
    j["domain"]["box"] = {vector_json(s.domain.lo, s.dim), vector_json(s.domain.hi, s.dim)};
  }
  if (s.completion) {
    const CompletionSpec& c = *s.completion;
    j["completion"] = {{"hex_side", patch_json(c.hex_side)}, {"tet_side", patch_json(c.tet_side)}};
    if (s.dim == 3) j["completion"]["higher"] = c.higher == Higher::kZ ? "z" : "x";
    j["push"] = {{"high_roof", c.push.high_roof},
                 {"low_roof", c.push.low_roof},
                 {"dome_depth", c.push.dome_depth},
                 {"dome_radius", c.push.dome_radius}};
    // The centre dome's own depth and radius: written only when set (0 means as the corners').
    if (c.push.centre_depth > 0) j["push"]["centre_depth"] = c.push.centre_depth;
    if (c.push.centre_radius > 0) j["push"]["centre_radius"] = c.push.centre_radius;
    // The wider dome family likewise, only off its defaults (spheroids on their vertices).
    if (c.push.dome_exponent != 2.0) j["push"]["dome_exponent"] = c.push.dome_exponent;
    if (c.push.centre_exponent > 0) j["push"]["centre_exponent"] = c.push.centre_exponent;
    if (c.push.dome_offset > 0) j["push"]["dome_offset"] = c.push.dome_offset;
    if (c.push.centre_offset[0] != 0 || c.push.centre_offset[1] != 0)
      j["push"]["centre_offset"] = c.push.centre_offset;
  }
  if (s.bottom_face) j["faces"]["bottom"] = patch_json(*s.bottom_face);
  if (s.top_face) j["faces"]["top"] = patch_json(*s.top_face);
  if (!s.sheets.empty()) {
    j["sheets"] = json::array();
    for (const auto& sh : s.sheets) {
      json e = sh.shape;
      e["name"] = sh.name;
      if (sh.kind != sh.shape.begin().key()) e["kind"] = sh.kind;
      j["sheets"].push_back(e);
    }
  }
  if (!s.sweep.is_null()) j["sweep"] = s.sweep;
  return j;
}

std::string format_spec(const json& spec) {
  std::ostringstream out;
  format(spec, 0, out);
  out << "\n";
  return out.str();
}

std::vector<stc::Sheet> spec_sheets(const ArrangementSpec& spec) {
  std::vector<stc::Sheet> sheets;
  if (spec.completion) {
    // The builders work in the box's reference frame; the fields are composed with it.
    const CompletionSpec& c = *spec.completion;
    const stc::Domain box = spec.domain;
    InterfacePatch hex = c.hex_side, tet = c.tet_side;
    for (auto& p : hex.points) p = to_reference(box, p);
    for (auto& p : tet.points) p = to_reference(box, p);
    for (stc::Sheet s : complete_interface(hex, tet, c.push, c.higher, spec.dim)) {
      s.field = [f = std::move(s.field), box](const Point& x) { return f(to_reference(box, x)); };
      sheets.push_back(std::move(s));
    }
  }
  const Reader r("spec", spec.dim);
  for (const auto& sh : spec.sheets)
    sheets.push_back({sh.name, r.shape(sh.shape, sh.name), sh.kind});
  return sheets;
}

SweepAxis parse_sweep_option(const std::string& text) {
  const auto eq = text.find('=');
  const std::string where = "--sweep '" + text + "'";
  if (eq == std::string::npos || eq == 0)
    throw InvalidInput(where + ": expected PATH=FROM:TO:COUNT or PATH=V1,V2,...");
  SweepAxis axis{text.substr(0, eq), {}};
  const std::string values = text.substr(eq + 1);
  const auto number = [&](const std::string& s) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(x))
      throw InvalidInput(where + ": '" + s + "' is not a number");
    return x;
  };
  std::vector<std::string> parts;
  const char sep = values.find(':') != std::string::npos ? ':' : ',';
  std::stringstream in(values);
  for (std::string p; std::getline(in, p, sep);) parts.push_back(p);
  if (sep == ':') {
    if (parts.size() != 3) throw InvalidInput(where + ": expected FROM:TO:COUNT");
    const double from = number(parts[0]), to = number(parts[1]);
    const double count = number(parts[2]);
    if (!(count >= 1) || count != std::floor(count) || count > 10000)
      throw InvalidInput(where + ": COUNT must be a whole number from 1 to 10000");
    const int n = static_cast<int>(count);
    for (int i = 0; i < n; ++i)
      axis.values.push_back(n == 1 ? from : from + (to - from) * i / (n - 1));
  } else {
    for (const auto& p : parts) axis.values.push_back(number(p));
  }
  if (axis.values.empty()) throw InvalidInput(where + ": no values");
  return axis;
}

std::vector<SweepAxis> spec_sweep(const json& spec, const std::string& source) {
  std::vector<SweepAxis> axes;
  if (!spec.contains("sweep")) return axes;
  const Reader r(source, 3);
  const json& s = spec["sweep"];
  if (!s.is_object())
    r.fail("sweep", "must be an object {\"path\": [values] or {\"from\", \"to\", \"count\"}}");
  for (const auto& [path, v] : s.items()) {
    const std::string at = "sweep." + path;
    SweepAxis axis{path, {}};
    if (v.is_array()) {
      r.each(v, at, 1,
             [&](const json& x, const std::string& p) { axis.values.push_back(r.number(x, p)); });
    } else {
      r.object(v, at, {"from", "to", "count"});
      const double from = r.number(r.member(v, at, "from"), at + ".from");
      const double to = r.number(r.member(v, at, "to"), at + ".to");
      const json& c = r.member(v, at, "count");
      if (!c.is_number_integer() || c.get<long long>() < 1 || c.get<long long>() > 10000)
        r.fail(at + ".count", "must be a whole number from 1 to 10000");
      const int n = c.get<int>();
      for (int i = 0; i < n; ++i)
        axis.values.push_back(n == 1 ? from : from + (to - from) * i / (n - 1));
    }
    json probe = spec;
    set_spec_number(probe, path, axis.values.front(), source);
    axes.push_back(axis);
  }
  return axes;
}

void set_spec_number(json& spec, const std::string& path, double value, const std::string& source) {
  json::json_pointer p;
  try {
    p = pointer(path, source);
  } catch (const json::exception&) {
    throw InvalidInput(source + ": sweep: '" + path +
                       "' is not a path such as push.high_roof or sheets[1].sphere.radius");
  }
  bool found = false;
  try {
    found = spec.contains(p) && spec.at(p).is_number();
  } catch (const json::exception&) {
    found = false;
  }
  if (!found) throw InvalidInput(source + ": sweep: '" + path + "' is not a number in the spec");
  spec.at(p) = value;
}

}  // namespace geode::templates
