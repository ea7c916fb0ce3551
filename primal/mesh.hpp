#pragma once
// Compact volume and surface meshes: index arrays plus Eigen coordinates. 2D meshes (quads,
// triangles) carry 3D points so that a planar template and a face of a 3D one share a type.
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products on Point
#include <array>
#include <cassert>
#include <concepts>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace geode::primal {

// The index convention: node and element numbers are Index (32 bits, signed, so that
// kInvalidIndex can mark "none"); sizes and positions in containers are std::size_t. Between
// the two, index_cast, which checks (in builds with assertions) that the value fits: the one
// place a number crosses from one to the other, instead of a bare static_cast.
using Index = std::int32_t;  // node or element number, 0-based
using Point = Eigen::Vector3d;

inline constexpr Index kInvalidIndex = -1;

// `value` as a `To` (Index by default, std::size_t for a container position); asserts that it
// fits (std::in_range: no negative size, no number past Index's range).
// Integers only (std::integral): an enum or a real number is not an index, and a call with one
// does not compile.
template <std::integral To = Index, std::integral From>
constexpr To index_cast(From value) noexcept {
  assert(std::in_range<To>(value) && "index out of range of its type");
  return static_cast<To>(value);
}

struct HexMesh {
  std::vector<Point> points;
  std::vector<std::array<Index, 8>> hexes;  // VTK/Exodus corner order (primal/topology.hpp)
  std::vector<int>
      block;  // per hex, an origin tag (e.g. diced hex / geode / diced tet); may be empty
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
