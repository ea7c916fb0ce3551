#pragma once
// The sheets of an existing mesh realized as fields, so that the arrangement engine can take a
// mesh apart and put it back together: mesh -> mesh_dual -> sheet_fields -> compute_arrangement
// -> dualize gives a mesh isomorphic to the input (tests/stc/round_trip_test.cpp). This is the
// STC seen both ways on one mesh: the sheets are the mesh's own dual surfaces.
//
// Construction (the same in 2D and 3D). A sheet S is a class of parallel edges; removing its
// edges splits the nodes into exactly two sides when S neither crosses itself nor fails to
// separate the domain. Every node gets the value  side * layer,  where side is -1 / +1 and
// layer is the number of edges (not in S) from the node to the nearest end of an S edge, plus
// one. The field is the multilinear interpolation of these values in the cell holding the
// point. In a cell that S crosses, its 2^(d-1) corners on one side all end an S edge (value
// -1) and the opposite ones too (+1), so the field is exactly the cell's local coordinate
// across S, rescaled to [-1, 1]: its zero set is the cell's mid-surface (mid-line) and three
// sheets meet at the cell's centre. In every other cell all corners have one sign: no zero.
// The field is continuous but only piecewise smooth (its gradient jumps across cell faces),
// and grows away from the sheet like a layer count, so Newton's method finds the sheet from
// anywhere near it.
//
// The cell holding a point is found by a bucket grid and Newton's method on the inverse
// multilinear map; a point outside every cell (a finite-difference probe just off the
// boundary) uses the nearest cell's map extended. Evaluating a field is not thread-safe (the
// fields of one mesh share a cache of located points); the arrangement engine is
// single-threaded.
#include <vector>

#include <geode/primal/mesh.hpp>
#include <geode/stc/arrangement.hpp>
#include <geode/stc/mesh_dual.hpp>
#include <geode/stc/sheet.hpp>

namespace geode::stc {

// What compute_arrangement needs to rebuild a mesh: its bounding box and one sheet per
// sheet (chord) of its dual, in mesh_dual's order, named "sheet <k>" and of kind "mesh".
struct MeshArrangementInput {
  Domain domain;
  std::vector<Sheet> sheets;
};

// Throws InvalidInput when the mesh does not fill its bounding box (a boundary face off every
// box face, named by cell and face) or has a cell whose multilinear map is inverted at a corner;
// TopologyError when a sheet crosses itself or does not split the nodes into two sides (naming
// the sheet and a cell or edge where it happens).
MeshArrangementInput sheet_fields(const primal::HexMesh& mesh);
// The quad mesh lies in the plane z = 0 (x and y are used).
MeshArrangementInput sheet_fields(const primal::QuadMesh& mesh);

}  // namespace geode::stc
