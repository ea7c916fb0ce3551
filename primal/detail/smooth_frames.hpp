#pragma once
// Private to the smoothers (primal/smooth.cpp, primal/local_smooth.cpp): the corner frames of a
// hex they measure, the tangent plane a sliding node moves in, and the nearest point of a
// node's plane or line.
#include <array>
#include <cmath>

#include <geode/primal/mesh.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal::detail {

// Frame f of a hex (0..7 corner f, 8 the centre) as columns v_i = sum_k coef[i][k] p[corner[k]]
// (primal/quality.hpp): corner c has v_i = p[kHexCornerNeighbors[c][i]] - p[c], the centre the
// principal axes X1, X2, X3 (sums over the 8 corners), its Jacobian det / 64.
struct HexFrameShape {
  int nodes = 0;                // corner[0 .. nodes) are used
  std::array<int, 8> corner{};  // hex corners
  std::array<std::array<double, 8>, 3> coef{};
  double det_scale = 1.0;  // Jacobian = det[v0, v1, v2] * det_scale
};

inline const std::array<HexFrameShape, 9>& hex_frame_shapes() {
  static const std::array<HexFrameShape, 9> shapes = [] {
    std::array<HexFrameShape, 9> s{};
    for (int c = 0; c < 8; ++c) {
      HexFrameShape& f = s[c];
      f.nodes = 4;
      const auto& n = topology::kHexCornerNeighbors[c];
      f.corner = {n[0], n[1], n[2], c, 0, 0, 0, 0};
      for (int i = 0; i < 3; ++i) f.coef[i][i] = 1.0, f.coef[i][3] = -1.0;
    }
    HexFrameShape& centre = s[8];
    centre.nodes = 8;
    centre.det_scale = 1.0 / 64.0;
    for (int c = 0; c < 8; ++c) {
      centre.corner[c] = c;
      for (int i = 0; i < 3; ++i) centre.coef[i][c] = topology::kHexCornerCoords[c][i] ? 1.0 : -1.0;
    }
    return s;
  }();
  return shapes;
}

// Orthonormal tangent pair of a plane with unit normal n, built from the coordinate axis
// least aligned with n, so that an axis-aligned normal gives exactly axis-aligned tangents.
inline std::array<Point, 2> plane_tangents(const Point& n) {
  int k = 0;
  for (int i = 1; i < 3; ++i) {
    if (std::abs(n[i]) < std::abs(n[k])) k = i;
  }
  const Point t1 = n.cross(Point::Unit(k)).normalized();
  return {t1, n.cross(t1)};
}

// Nearest point to p of the plane through `origin` with unit normal n.
inline Point project_to_plane(const Point& p, const Point& origin, const Point& n) {
  return p - (p - origin).dot(n) * n;
}

// Nearest point to p of the line through `origin` with unit direction d.
inline Point project_to_line(const Point& p, const Point& origin, const Point& d) {
  return origin + (p - origin).dot(d) * d;
}

}  // namespace geode::primal::detail
