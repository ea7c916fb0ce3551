#pragma once
// VTK cell types as the .vtu / .vtk writers and readers (vtk.cpp, vtu_read.cpp, vtk_read.cpp) name
// and size them: one table, read by the lookups and by the readers' message naming what they take.
// Internal to io's VTK I/O.
#include <array>
#include <string>

#include <geode/io/vtk.hpp>

namespace geode::io::vtk_cells {

struct CellType {
  int type;
  const char* name;
  int size;  // nodes
};

inline constexpr std::array<CellType, 8> kCellTypes{{{kVtkVertex, "vertex", 1},
                                                     {kVtkLine, "line", 2},
                                                     {kVtkTriangle, "triangle", 3},
                                                     {kVtkQuad, "quad", 4},
                                                     {kVtkTetra, "tetra", 4},
                                                     {kVtkHexahedron, "hexahedron", 8},
                                                     {kVtkWedge, "wedge", 6},
                                                     {kVtkPyramid, "pyramid", 5}}};

inline const CellType* find_cell_type(int type) {
  for (const CellType& t : kCellTypes)
    if (t.type == type) return &t;
  return nullptr;
}

inline const char* cell_type_name(int type) {
  const CellType* t = find_cell_type(type);
  return t ? t->name : nullptr;
}

inline int cell_type_size(int type) {
  const CellType* t = find_cell_type(type);
  return t ? t->size : 0;
}

// VTK's higher-order cells (vtkCellType.h: 21 VTK_QUADRATIC_EDGE to 37
// VTK_TRIQUADRATIC_PYRAMID, 68 VTK_LAGRANGE_CURVE to 80 VTK_BEZIER_PYRAMID): named as such when
// refused, since a mesher's second-order output is the usual reason for one.
inline bool higher_order(int type) {
  return (type >= 21 && type <= 37) || (type >= 68 && type <= 80);
}

// "5 triangle, 9 quad, ...": the types the readers take.
inline std::string supported_cell_types() {
  std::string s;
  for (const CellType& t : kCellTypes)
    s += (s.empty() ? "" : ", ") + std::to_string(t.type) + " " + t.name;
  return s;
}

}  // namespace geode::io::vtk_cells
