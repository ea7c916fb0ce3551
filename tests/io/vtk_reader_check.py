#!/usr/bin/python3
"""Open a file geode wrote with VTK's own readers (what ParaView uses) and check it.

usage: vtk_reader_check.py FILE EXPECTED_CELLS [--compare-scaled-jacobian]

FILE is .vtu (vtkXMLUnstructuredGridReader) or .vtk (vtkUnstructuredGridReader). Checks the
cell count, that every cell is a triangle/quad/tetra/hexahedron, that the "scaled_jacobian"
cell array is there with one value per cell and, with --compare-scaled-jacobian, that it agrees
with vtkMeshQuality's Verdict scaled Jacobian (an independent implementation).
Exit status: 0 ok, 1 check failed, 77 vtk cannot be imported (the caller skips).
"""
import sys

try:
    import vtk  # noqa: F401
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
    from vtkmodules.vtkFiltersVerdict import vtkMeshQuality
except ImportError as e:
    print(f"vtk not importable: {e}")
    sys.exit(77)


def main():
    path, expected = sys.argv[1], int(sys.argv[2])
    compare = "--compare-scaled-jacobian" in sys.argv[3:]
    reader = vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtkUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    if grid is None or grid.GetNumberOfCells() != expected:
        n = None if grid is None else grid.GetNumberOfCells()
        print(f"{path}: VTK read {n} cells, expected {expected}")
        return 1
    types = {grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}
    if not types <= {5, 9, 10, 12}:
        print(f"{path}: unexpected cell types {sorted(types)}")
        return 1
    sj = grid.GetCellData().GetArray("scaled_jacobian")
    if sj is None or sj.GetNumberOfTuples() != expected:
        print(f"{path}: no scaled_jacobian cell array with {expected} values")
        return 1
    if compare:
        q = vtkMeshQuality()
        q.SetInputData(grid)
        q.SetHexQualityMeasureToScaledJacobian()
        q.SetTetQualityMeasureToScaledJacobian()
        q.SetQuadQualityMeasureToScaledJacobian()
        q.Update()
        ref = q.GetOutput().GetCellData().GetArray("Quality")
        for i in range(expected):
            a, b = sj.GetValue(i), ref.GetValue(i)
            if abs(a - b) > 1e-9 * max(1.0, abs(b)):
                print(f"{path}: cell {i}: scaled_jacobian {a} but vtkMeshQuality says {b}")
                return 1
    print(f"{path}: {expected} cells, types {sorted(types)}: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
