#pragma once
// Compact volume and surface meshes: index arrays plus Eigen coordinates. 2D meshes (quads,
// triangles) carry 3D points so that a planar template and a face of a 3D one share a type.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products on Point
#include <array>
#include <cstdint>
#include <vector>

namespace geode::primal {

using Index = std::int32_t;  // node or element number, 0-based
using Point = Eigen::Vector3d;

inline constexpr Index kInvalidIndex = -1;

struct HexMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 8>> hexes;  // VTK/Exodus corner order (primal/topology.hpp)
  std::vector<int> block;  // per hex, an origin tag (e.g. diced hex / geode / diced tet); may be empty
};

struct TetMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 4>> tets;
  std::vector<int> block;
};

struct QuadMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 4>> quads;  // counter-clockwise seen from the outside / +z
};

struct TriMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 3>> tris;
};

// Line segments in space, e.g. a chord of a quad mesh drawn as a curve.
struct SegmentMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 2>> segments;
};

}  // namespace geode::primal
