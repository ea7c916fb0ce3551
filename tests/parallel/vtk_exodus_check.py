#!/usr/bin/python3
"""Open every per-rank file of a geode_mpi run with VTK's Exodus reader (what ParaView uses).

usage: vtk_exodus_check.py OUT.exo N TOTAL_HEXES

Each OUT.exo.N.r must read as hexahedra only, and the ranks' cells must add up to TOTAL_HEXES.
Exit status: 0 ok, 1 check failed, 77 vtk cannot be imported (the caller skips).
"""
import sys

try:
    from vtkmodules.vtkIOExodus import vtkExodusIIReader
    from vtkmodules.vtkCommonDataModel import VTK_HEXAHEDRON
except ImportError as e:
    print(f"vtk not importable: {e}")
    sys.exit(77)


def main():
    out, n, total = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    width = len(str(n))
    cells = 0
    for r in range(n):
        path = f"{out}.{n}.{r:0{width}d}"
        reader = vtkExodusIIReader()
        if not reader.CanReadFile(path):
            print(f"{path}: VTK cannot read it")
            return 1
        reader.SetFileName(path)
        reader.UpdateInformation()
        for b in range(reader.GetNumberOfObjects(vtkExodusIIReader.ELEM_BLOCK)):
            reader.SetObjectStatus(vtkExodusIIReader.ELEM_BLOCK, b, 1)
        reader.Update()
        mb = reader.GetOutput()
        it = mb.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            grid = it.GetCurrentDataObject()
            for c in range(grid.GetNumberOfCells()):
                if grid.GetCellType(c) != VTK_HEXAHEDRON:
                    print(f"{path}: cell {c} is not a hexahedron")
                    return 1
            cells += grid.GetNumberOfCells()
            it.GoToNextItem()
    if cells != total:
        print(f"VTK read {cells} hexes over {n} files, expected {total}")
        return 1
    print(f"vtk: {n} files, {cells} hexes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
