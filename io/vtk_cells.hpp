#pragma once
// VTK cell types as the .vtu / .vtk writers and readers (vtk.cpp, vtu_read.cpp, vtk_read.cpp) name
// and size them. Internal to io's VTK I/O.
#include <geode/io/vtk.hpp>

namespace geode::io::vtk_cells {

inline const char* cell_type_name(int type) {
  switch (type) {
    case kVtkTriangle:
      return "triangle";
    case kVtkQuad:
      return "quad";
    case kVtkTetra:
      return "tetra";
    case kVtkHexahedron:
      return "hexahedron";
    case kVtkWedge:
      return "wedge";
    case kVtkPyramid:
      return "pyramid";
    default:
      return nullptr;
  }
}

inline int cell_type_size(int type) {
  switch (type) {
    case kVtkTriangle:
      return 3;
    case kVtkQuad:
      return 4;
    case kVtkTetra:
      return 4;
    case kVtkHexahedron:
      return 8;
    case kVtkWedge:
      return 6;
    case kVtkPyramid:
      return 5;
    default:
      return 0;
  }
}

}  // namespace geode::io::vtk_cells
