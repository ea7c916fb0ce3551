#pragma once
// Reference-element topology as data. Generic code reads these tables instead of spelling
// cases out. Numbering follows VTK_HEXAHEDRON / Exodus HEX8: bottom face 0-1-2-3
// counter-clockwise seen from above, top face 4-7 with corner 4 above corner 0, so that
// (p1-p0, p3-p0, p4-p0) is a right-handed frame for a positively oriented hex.
//
//            7-----------6
//           /|          /|          t (local z)
//          / |         / |          |
//         4-----------5  |          |   s (local y)
//         |  |        |  |          |  /
//         |  3--------|--2          | /
//         | /         | /           +------ r (local x)
//         |/          |/
//         0-----------1
//
// Local coordinates of corner c: r = bit0 of (c ^ (c >> 1)), s = bit1 of c, t = bit2 of c,
// i.e. corners 0..7 at (0,0,0) (1,0,0) (1,1,0) (0,1,0) (0,0,1) (1,0,1) (1,1,1) (0,1,1).
#include <array>

namespace geode::primal::topology {

inline constexpr int kHexCorners = 8;
inline constexpr int kHexFaces = 6;
inline constexpr int kHexEdges = 12;

// Unit-cube coordinates of the corners (r, s, t).
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerCoords{{
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

// Faces with outward normals (corners counter-clockwise seen from outside), in the VTK/Exodus
// side order: 0 = s-min (front), 1 = r-max (right), 2 = s-max (back), 3 = r-min (left),
// 4 = t-min (bottom), 5 = t-max (top).
inline constexpr std::array<std::array<int, 4>, 6> kHexFaceCorners{{
    {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

// Opposite face of each face.
inline constexpr std::array<int, 6> kHexOppositeFace{2, 3, 0, 1, 5, 4};

// Edges; edge e belongs to parallel class e / 4 (0: along r, 1: along s, 2: along t).
inline constexpr std::array<std::array<int, 2>, 12> kHexEdgeCorners{{
    {0, 1}, {3, 2}, {4, 5}, {7, 6},   // along r
    {0, 3}, {1, 2}, {4, 7}, {5, 6},   // along s
    {0, 4}, {1, 5}, {2, 6}, {3, 7}}};  // along t

// The three edges at each corner, pointing away from it, ordered (r, s, t) so that their
// directions form a right-handed frame: the corner Jacobian is det(e_r, e_s, e_t).
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerNeighbors{{
    {1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7},
    {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}}};

// Quad: corners counter-clockwise; edge i joins corner i and i+1. Opposite edges: i, i+2.
inline constexpr std::array<std::array<int, 2>, 4> kQuadEdgeCorners{{{0, 1}, {1, 2}, {2, 3}, {3, 0}}};

// Tetrahedron (VTK_TETRA / Exodus TET4): 0-1-2 counter-clockwise seen from corner 3.
inline constexpr std::array<std::array<int, 3>, 4> kTetFaceCorners{{
    {0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}}};
inline constexpr std::array<std::array<int, 2>, 6> kTetEdgeCorners{{
    {0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};

// Triangle: corners counter-clockwise.
inline constexpr std::array<std::array<int, 2>, 3> kTriEdgeCorners{{{0, 1}, {1, 2}, {2, 0}}};

// The cells of a d-dimensional mesh as one trait, for code written once for hex (3) and quad
// (2) meshes: corners, facets (what two neighbouring cells share: hex faces, quad edges),
// edges and their parallel class.
template <int Dim>
struct CellTopology;

template <>
struct CellTopology<3> {
  static constexpr int kCorners = kHexCorners;
  static constexpr int kFacets = kHexFaces;
  static constexpr int kFacetSize = 4;
  static constexpr const char* kCellName = "hex";
  static constexpr const auto& edges = kHexEdgeCorners;
  static constexpr const auto& facets = kHexFaceCorners;
  static constexpr int edge_class(int e) { return e / 4; }
};

template <>
struct CellTopology<2> {
  static constexpr int kCorners = 4;
  static constexpr int kFacets = 4;
  static constexpr int kFacetSize = 2;
  static constexpr const char* kCellName = "quad";
  static constexpr const auto& edges = kQuadEdgeCorners;
  static constexpr const auto& facets = kQuadEdgeCorners;
  static constexpr int edge_class(int e) { return e % 2; }  // opposite edges i, i + 2
};

}  // namespace geode::primal::topology
