#include <geode/templates/side_faces.hpp>

#include <cmath>
#include <map>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/primal/patch_match.hpp>
#include <geode/primal/topology.hpp>
#include <geode/stc/arrangement.hpp>

namespace geode::templates {
namespace {

namespace topo = primal::topology;
using primal::Point;

struct Box {
  Point centre, half;
};

Box bounding_box(const Template& t) {
  Point lo = Point::Constant(1e300), up = Point::Constant(-1e300);
  for (const auto& p : t.hex.points) lo = lo.cwiseMin(p), up = up.cwiseMax(p);
  return {(lo + up) / 2, (up - lo) / 2};
}

// Face coordinates: u along the face (the direction y x normal, so that a rotation of the box
// about y carries one face's u onto another's), scaled to [-1, 1]; v the height.
struct FaceFrame {
  int along;    // the box axis u runs along
  double sign;  // u = sign * (p[along] - centre) / half
};

FaceFrame frame(const SideFace& f) {
  // y x (+x) = -z, y x (-x) = +z, y x (+z) = +x, y x (-z) = -x.
  if (f.axis == 0) return {2, f.high ? -1.0 : 1.0};
  return {0, f.high ? 1.0 : -1.0};
}

double face_u(const Point& p, const SideFace& f, const Box& b) {
  const FaceFrame fr = frame(f);
  return fr.sign * (p[fr.along] - b.centre[fr.along]) / b.half[fr.along];
}

// Top (1) / bottom (0) nodes of a face keyed by (top, u in {-1, 0, 1}).
std::map<std::pair<int, int>, int> edge_nodes(const Template& t, const SideFace& f, const Box& b) {
  std::map<std::pair<int, int>, int> keyed;
  const unsigned bottom = 1u << stc::box_face(1, false), top = 1u << stc::box_face(1, true);
  for (int n : f.nodes) {
    const unsigned nf = t.node_faces[n];
    if (!(nf & (bottom | top))) continue;
    const double u = face_u(t.hex.points[n], f, b);
    const double k = std::round(u);
    if (std::abs(u - k) > 1e-6)
      throw TopologyError(
          "side faces: a top or bottom node of a side face lies between its corners and midpoint");
    keyed[{(nf & top) ? 1 : 0, static_cast<int>(k)}] = n;
  }
  return keyed;
}

// The images of face 0's nodes on every face, mirrored or not (the symmetries of the box's
// sides about y), matched topologically from the faces' top and bottom nodes.
struct Image {
  int face;
  bool mirror;
  std::unordered_map<int, int> map;  // face 0 node -> its image
};

std::vector<Image> face_images(const Template& t, const std::array<SideFace, 4>& faces,
                               const Box& box) {
  std::array<std::map<std::pair<int, int>, int>, 4> keyed;
  for (int k = 0; k < 4; ++k) keyed[k] = edge_nodes(t, faces[k], box);
  std::vector<Image> images;
  for (int k = 0; k < 4; ++k)
    for (bool mirror : {false, true}) {
      std::vector<std::pair<int, int>> seeds;
      for (const auto& [key, n] : keyed[0]) {
        const auto it = keyed[k].find({key.first, mirror ? -key.second : key.second});
        if (it != keyed[k].end()) seeds.emplace_back(n, it->second);
      }
      primal::PatchMatch m = primal::match_quad_patches(faces[0].quads, faces[k].quads, seeds);
      if (!m.ok())
        throw TopologyError("side faces: face " + std::to_string(k) + (mirror ? " mirrored" : "") +
                            " is not the mesh of face 0: " + m.error);
      images.push_back({k, mirror, std::move(m.map)});
    }
  return images;
}

// The linear map carrying a displacement on face 0 to the image's displacement on its face.
Eigen::Matrix3d image_map(const std::array<SideFace, 4>& faces, const Image& im, const Box& box) {
  const FaceFrame f0 = frame(faces[0]), fk = frame(faces[im.face]);
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(1, 1) = 1.0;
  m(fk.along, f0.along) =
      fk.sign * (im.mirror ? -1.0 : 1.0) * f0.sign * box.half[fk.along] / box.half[f0.along];
  m(faces[im.face].axis, faces[0].axis) = 1.0;
  return m;
}

}  // namespace

std::array<SideFace, 4> side_faces(const Template& t) {
  std::array<SideFace, 4> faces;
  const std::array<std::pair<int, bool>, 4> which{{{0, false}, {0, true}, {2, false}, {2, true}}};
  for (int k = 0; k < 4; ++k) {
    SideFace& f = faces[k];
    f.axis = which[k].first;
    f.high = which[k].second;
    const unsigned bit = 1u << stc::box_face(f.axis, f.high);
    for (std::size_t n = 0; n < t.hex.points.size(); ++n)
      if (t.node_faces[n] & bit) f.nodes.push_back(static_cast<int>(n));
    for (const auto& h : t.hex.hexes)
      for (const auto& fc : topo::kHexFaceCorners) {
        std::array<int, 4> q{};
        bool on = true;
        for (int j = 0; j < 4; ++j) {
          q[j] = static_cast<int>(h[fc[j]]);
          on = on && (t.node_faces[q[j]] & bit);
        }
        if (on) f.quads.push_back(q);
      }
  }
  return faces;
}

void unify_side_faces(Template& t) {
  if (t.dim != 3) throw InvalidInput("unify_side_faces: a 3D template is needed");
  const Box box = bounding_box(t);
  const auto faces = side_faces(t);
  const std::vector<Image> images = face_images(t, faces, box);
  // Mean (u, v) per node of face 0 over its eight images; then every image takes it.
  std::map<int, std::pair<double, double>> mean;
  for (int n : faces[0].nodes) {
    double u = 0, v = 0;
    for (const Image& im : images) {
      const Point& p = t.hex.points[im.map.at(n)];
      const double ui = face_u(p, faces[im.face], box);
      u += im.mirror ? -ui : ui, v += p.y();
    }
    mean[n] = {u / static_cast<double>(images.size()), v / static_cast<double>(images.size())};
  }
  std::vector<char> placed(t.hex.points.size(), 0);
  const double tol = 1e-9 * box.half.norm();
  for (const Image& im : images) {
    const SideFace& f = faces[im.face];
    const FaceFrame fr = frame(f);
    for (const auto& [n, uv] : mean) {
      const int m = im.map.at(n);
      Point p = t.hex.points[m];
      const double u = im.mirror ? -uv.first : uv.first;
      p[fr.along] = box.centre[fr.along] + fr.sign * u * box.half[fr.along];
      p.y() = uv.second;
      auto& q = t.hex.points[m];
      if (placed[m] && (p - q).norm() > tol)
        throw TopologyError("side faces: two faces place a node on their common edge differently");
      q = p;
      placed[m] = 1;
    }
  }
}

primal::SmoothResult smooth_template_shared_sides(Template& t) {
  smooth_template(t, false);
  unify_side_faces(t);
  const Box b = bounding_box(t);
  const auto faces = side_faces(t);
  const std::vector<Image> images = face_images(t, faces, b);
  // Top and bottom fixed, side nodes sliding; every side node follows the face 0 node it is
  // an image of, so the faces stay one mesh while the template is smoothed. A leader that is
  // its own mirror image (on the face's centre line) may only move up and down.
  auto constraints = primal::box_constraints(t.hex.points, b.centre - b.half, b.centre + b.half,
                                             {false, false, true, true, false, false});
  primal::SmoothOptions o;
  std::vector<char> assigned(t.hex.points.size(), 0);
  for (int leader : faces[0].nodes) {
    if (assigned[leader]) continue;
    assigned[leader] = 1;
    for (const Image& im : images) {
      const int n = im.map.at(leader);
      if (n == leader) {
        if (im.mirror && constraints[n].kind == primal::NodeConstraint::Kind::kPlane)
          constraints[n] = primal::NodeConstraint::line(t.hex.points[n], Point::UnitY());
        continue;
      }
      if (assigned[n]) continue;
      assigned[n] = 1;
      o.links.push_back({n, leader, image_map(faces, im, b)});
    }
  }
  return primal::smooth_hex_mesh(t.hex, constraints, o);
}

}  // namespace geode::templates
