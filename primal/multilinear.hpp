#pragma once
// The multilinear map of the unit cube (unit square) onto a cell given by its corners in VTK
// order (primal/topology.hpp): local coordinates r in [0, 1]^dim, corner c at
// kHexCornerCoords[c] (a quad's corners are the hex's first four), and corner c's shape
// function the product over the axes of r_a (where the corner's coordinate is 1) or 1 - r_a.
// One definition for every place that maps a reference cell: templates into buffer hexes,
// arrangement domains, a mesh's cells when its sheets become fields.
#include <Eigen/Core>
#include <cstddef>

#include <geode/primal/mesh.hpp>
#include <geode/primal/topology.hpp>

namespace geode::primal {

// Shape function of corner c at r (dim 2 or 3; r's further components are ignored).
inline double multilinear_shape(int c, const Point& r, int dim) {
  double w = 1.0;
  for (int a = 0; a < dim; ++a)
    w *= topology::kHexCornerCoords[index_cast<std::size_t>(c)][index_cast<std::size_t>(a)]
             ? r[a]
             : 1.0 - r[a];
  return w;
}

// The image of r. `corners` holds at least 2^dim points (VTK order).
template <class Corners>
Point multilinear_point(const Corners& corners, const Point& r, int dim) {
  Point x = Point::Zero();
  for (int c = 0; c < (1 << dim); ++c)
    x += multilinear_shape(c, r, dim) * corners[index_cast<std::size_t>(c)];
  return x;
}

// The map's Jacobian at r: column a is the derivative along r_a (columns beyond dim are zero).
template <class Corners>
Eigen::Matrix3d multilinear_jacobian(const Corners& corners, const Point& r, int dim) {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (int c = 0; c < (1 << dim); ++c) {
    const auto& rc = topology::kHexCornerCoords[index_cast<std::size_t>(c)];
    for (int d = 0; d < dim; ++d) {
      double w = rc[index_cast<std::size_t>(d)] ? 1.0 : -1.0;
      for (int a = 0; a < dim; ++a)
        if (a != d) w *= rc[index_cast<std::size_t>(a)] ? r[a] : 1.0 - r[a];
      J.col(d) += w * corners[index_cast<std::size_t>(c)];
    }
  }
  return J;
}

}  // namespace geode::primal
