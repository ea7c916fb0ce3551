#pragma once
// VTK output for viewers (ParaView, VisIt) and reading it back: XML unstructured grid (.vtu,
// ASCII or base64 binary DataArrays) and legacy (.vtk, "# vtk DataFile Version 4.2": the classic
// CELLS n size layout every legacy reader since VTK 4 opens, without the 5.1 OFFSETS/CONNECTIVITY
// form). Hexes, tets and quads (quads as VTK_QUAD in 3D space), or a whole Model (hexes, tets,
// pyramids, wedges). Writes are atomic (io/atomic_file.hpp): a failure leaves no half-written file.
//
// Every written grid carries the cell arrays "scaled_jacobian" ([Verdict] hex, tet or quad
// scaled Jacobian) and "block" (mesh.block, when not empty), then the caller's arrays.
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/primal/model.hpp>

namespace geode::io {

// VTK cell type numbers (vtkCellType.h).
inline constexpr int kVtkVertex = 1;
inline constexpr int kVtkLine = 3;
inline constexpr int kVtkTriangle = 5;
inline constexpr int kVtkQuad = 9;
inline constexpr int kVtkTetra = 10;
inline constexpr int kVtkHexahedron = 12;
inline constexpr int kVtkWedge = 13;  // corners in VTK's order: primal::topology::kVtkWedgeOrder
inline constexpr int kVtkPyramid = 14;
// The VTK type per primal::ElementKind (hex, tet, pyramid, wedge).
inline constexpr std::array<int, 4> kVtkCellTypes{kVtkHexahedron, kVtkTetra, kVtkPyramid,
                                                  kVtkWedge};

// Cells below the volume: points, lines and faces that annotate a volume mesh (Gmsh's legacy
// .vtk lists its physical points, curves and surfaces so). Readers take them as sets where the
// file tags them (model_from_vtk), and leave them out of a hex mesh.
inline constexpr bool vtk_boundary_cell(int type) {
  return type == kVtkVertex || type == kVtkLine || type == kVtkTriangle || type == kVtkQuad;
}

// Named per-cell arrays, written in this order. Names: non-empty, no white space (the legacy
// format separates tokens by white space).
struct VtkCellData {
  std::vector<std::pair<std::string, std::vector<double>>> doubles;
  std::vector<std::pair<std::string, std::vector<int>>> ints;

  const std::vector<double>* find_double(const std::string& name) const;
  const std::vector<int>* find_int(const std::string& name) const;
};

// How a VTK file stores its values: ASCII text, or binary, which ParaView, VTK and meshio read:
// exact doubles without printing and parsing them as text. In .vtu, "binary" DataArrays (base64
// of a UInt64 byte count and the little-endian values; header_type="UInt64"); in legacy .vtk,
// a BINARY file (each array's big-endian values after the line announcing it, as VTK's file
// format manual lays them out).
enum class VtkEncoding { kAscii, kBinary };

// Throw geode::InvalidInput (naming the file and the array, or the node or element by its
// 1-based number) for an array of the wrong length, a bad or repeated name, a node number out of
// range, a non-finite point, or a file that cannot be written. A Model is written with its hexes,
// tets, pyramids then wedges, the cell array "block" holding each element's block (block_of);
// in .vtu its block names, node sets and side sets go into <FieldData> as Int32 arrays
// "block:NAME" (one value, the block id), "node_set:ID:NAME" (point indices) and
// "side_set:ID:NAME" (2 components: cell index, face number of primal/topology.hpp, which is
// Exodus's side order from 0), which model_from_vtk reads back.
void write_vtu(const std::filesystem::path& path, const primal::HexMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
void write_vtu(const std::filesystem::path& path, const primal::TetMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
void write_vtu(const std::filesystem::path& path, const primal::QuadMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
// `scaled_jacobians`: each element's scaled Jacobian (hexes, tets, pyramids, wedges in turn) as
// the scaled_jacobian array holds it, from a caller that has them (conform); else computed.
void write_vtu(const std::filesystem::path& path, const primal::Model& model,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii,
               std::span<const double> scaled_jacobians = {});
void write_vtk(const std::filesystem::path& path, const primal::HexMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
void write_vtk(const std::filesystem::path& path, const primal::TetMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
void write_vtk(const std::filesystem::path& path, const primal::QuadMesh& mesh,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii);
void write_vtk(const std::filesystem::path& path, const primal::Model& model,
               const VtkCellData& extra = {}, VtkEncoding encoding = VtkEncoding::kAscii,
               std::span<const double> scaled_jacobians = {});

// An unstructured grid as read: points, cells (VTK corner order) and cell arrays.
struct VtkGrid {
  std::string source;  // the file, for messages
  std::vector<primal::Point> points;
  std::vector<int> cell_types;
  std::vector<std::vector<primal::Index>> cells;
  VtkCellData cell_data;  // Float32/Float64 arrays as doubles, integer arrays as ints
  // The dataset's integer field arrays (<FieldData>): block names and sets as the writer
  // stores them (see write_vtu), and any others, which model_from_vtk ignores.
  struct FieldArray {
    std::string name;
    std::size_t components = 1;
    std::vector<long long> values;  // tuples x components
  };
  std::vector<FieldArray> field_data;
};

// Readers of ASCII files: .vtu with format="ascii" DataArrays (one Piece), legacy .vtk in
// ASCII with the classic CELLS layout or the 5.1 OFFSETS/CONNECTIVITY layout. Cells must be
// vertices, lines, triangles, quads, tets, pyramids, wedges or hexes. Point data is skipped. Throw
// geode::InvalidInput naming the file, the line (and point or cell) and the reason: truncated file,
// unknown cell type, wrong node count for a cell type, node number out of range, NaN or infinite
// coordinate, too few or too many values, unsupported encoding. The file's content is checked
// (file_format.hpp) before it is parsed.
VtkGrid read_vtu(const std::filesystem::path& path);
VtkGrid read_vtk(const std::filesystem::path& path);
// The same on a file's content; `source` names it in messages.
VtkGrid parse_vtu(std::string_view content, const std::string& source);
VtkGrid parse_vtk(std::string_view content, const std::string& source);
// By extension: .vtu or .vtk.
VtkGrid read_vtk_file(const std::filesystem::path& path);

// The grid as a typed mesh; throw geode::InvalidInput naming the file and the first cell of
// another type. An int cell array "block" becomes mesh.block.
primal::HexMesh to_hex_mesh(const VtkGrid& grid);
primal::TetMesh to_tet_mesh(const VtkGrid& grid);
primal::QuadMesh to_quad_mesh(const VtkGrid& grid);

}  // namespace geode::io
