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
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerCoords{
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

// Faces with outward normals (corners counter-clockwise seen from outside), in the VTK/Exodus
// side order: 0 = s-min (front), 1 = r-max (right), 2 = s-max (back), 3 = r-min (left),
// 4 = t-min (bottom), 5 = t-max (top).
inline constexpr std::array<std::array<int, 4>, 6> kHexFaceCorners{
    {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

// Opposite face of each face.
inline constexpr std::array<int, 6> kHexOppositeFace{2, 3, 0, 1, 5, 4};

// Edges; edge e belongs to parallel class e / 4 (0: along r, 1: along s, 2: along t).
inline constexpr std::array<std::array<int, 2>, 12> kHexEdgeCorners{{{0, 1},
                                                                     {3, 2},
                                                                     {4, 5},
                                                                     {7, 6},  // along r
                                                                     {0, 3},
                                                                     {1, 2},
                                                                     {4, 7},
                                                                     {5, 6},  // along s
                                                                     {0, 4},
                                                                     {1, 5},
                                                                     {2, 6},
                                                                     {3, 7}}};  // along t

// The three edges at each corner, pointing away from it, ordered (r, s, t) so that their
// directions form a right-handed frame: the corner Jacobian is det(e_r, e_s, e_t).
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerNeighbors{
    {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}}};

// Quad: corners counter-clockwise; edge i joins corner i and i+1. Opposite edges: i, i+2.
inline constexpr std::array<std::array<int, 2>, 4> kQuadEdgeCorners{
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}}};

// Tetrahedron (VTK_TETRA / Exodus TET4): 0-1-2 counter-clockwise seen from corner 3.
inline constexpr std::array<std::array<int, 3>, 4> kTetFaceCorners{
    {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}}};
inline constexpr std::array<std::array<int, 2>, 6> kTetEdgeCorners{
    {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}};

// Triangle: corners counter-clockwise.
inline constexpr std::array<std::array<int, 2>, 3> kTriEdgeCorners{{{0, 1}, {1, 2}, {2, 0}}};

// Pyramid (VTK_PYRAMID / Exodus PYRAMID5 / Gmsh 5-node pyramid, one order in all three): base
// 0-1-2-3 counter-clockwise seen from the apex 4. Faces outward in the Exodus side order (the
// four triangles, then the base).
inline constexpr int kPyramidApex = 4;

// Wedge (Exodus WEDGE6 / Gmsh 6-node prism order): triangle 0-1-2 counter-clockwise seen from
// the other triangle 3-4-5, corner 3 + i above corner i. VTK_WEDGE lists the triangles the
// other way round (its 0-1-2 is clockwise seen from 3-4-5): the VTK readers and writers swap
// corners 1 <-> 2 and 4 <-> 5 (kVtkWedgeOrder). Faces outward in the Exodus side order: the
// three quads (0-1 side, 1-2 side, 2-0 side), then the triangles 0-2-1 and 3-4-5.
inline constexpr std::array<int, 6> kVtkWedgeOrder{0, 2, 1, 3, 5, 4};  // an involution

// The three edges at each corner of a wedge, pointing away from it, in the order making them a
// right-handed frame (as kHexCornerNeighbors): a wedge's corner Jacobians, and the axes of the
// hex its dicing puts at that corner.
inline constexpr std::array<std::array<int, 3>, 6> kWedgeCornerNeighbors{
    {{1, 2, 3}, {2, 0, 4}, {0, 1, 5}, {5, 4, 0}, {3, 5, 1}, {4, 3, 2}}};
// The same for a tetrahedron: (1, 2, 3) at 0 is right-handed for a positive tet, and every
// even permutation keeps it.
inline constexpr std::array<std::array<int, 3>, 4> kTetCornerNeighbors{
    {{1, 2, 3}, {0, 3, 2}, {3, 0, 1}, {2, 1, 0}}};

// The linear cell kinds of a model as one table, indexed by primal::ElementKind (hex, tet,
// pyramid, wedge): corner count, faces (outward, counter-clockwise seen from outside, in the
// Exodus side order, so local face f is Exodus side f + 1) and edges. Generic code (model
// checks, face maps of readers, side sets, dicing) reads these instead of spelling kinds out.
struct CellFace {
  int size = 0;                  // 3 or 4
  std::array<int, 4> corners{};  // the first `size` are used
};

struct CellKindTopology {
  const char* name;  // as messages name the cell: "hex", "tet", "pyramid", "wedge"
  int corners;
  int faces;
  std::array<CellFace, 6> face;
  int edges;
  std::array<std::array<int, 2>, 12> edge;
};

inline constexpr std::array<CellKindTopology, 4> kCellKinds{{
    {"hex",
     8,
     6,
     {{{4, {0, 1, 5, 4}},
       {4, {1, 2, 6, 5}},
       {4, {2, 3, 7, 6}},
       {4, {3, 0, 4, 7}},
       {4, {0, 3, 2, 1}},
       {4, {4, 5, 6, 7}}}},
     12,
     {{{0, 1},
       {3, 2},
       {4, 5},
       {7, 6},
       {0, 3},
       {1, 2},
       {4, 7},
       {5, 6},
       {0, 4},
       {1, 5},
       {2, 6},
       {3, 7}}}},
    {"tet",
     4,
     4,
     {{{3, {0, 1, 3}}, {3, {1, 2, 3}}, {3, {2, 0, 3}}, {3, {0, 2, 1}}}},
     6,
     {{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}}},
    {"pyramid",
     5,
     5,
     {{{3, {0, 1, 4}}, {3, {1, 2, 4}}, {3, {2, 3, 4}}, {3, {3, 0, 4}}, {4, {0, 3, 2, 1}}}},
     8,
     {{{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}}},
    {"wedge",
     6,
     5,
     {{{4, {0, 1, 4, 3}}, {4, {1, 2, 5, 4}}, {4, {2, 0, 3, 5}}, {3, {0, 2, 1}}, {3, {3, 4, 5}}}},
     9,
     {{{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}}},
}};

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
  static constexpr const auto& kEdgeTable = kHexEdgeCorners;
  static constexpr const auto& kFacetTable = kHexFaceCorners;
  static constexpr int edge_class(int e) { return e / 4; }
};

template <>
struct CellTopology<2> {
  static constexpr int kCorners = 4;
  static constexpr int kFacets = 4;
  static constexpr int kFacetSize = 2;
  static constexpr const char* kCellName = "quad";
  static constexpr const auto& kEdgeTable = kQuadEdgeCorners;
  static constexpr const auto& kFacetTable = kQuadEdgeCorners;
  static constexpr int edge_class(int e) { return e % 2; }  // opposite edges i, i + 2
};

}  // namespace geode::primal::topology
