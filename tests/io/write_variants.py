#!/usr/bin/python3
"""Write one mesh file in the encodings other programs use, for the reader round-trip tests.

usage: write_variants.py vtk SOURCE.vtu OUTDIR    VTK's own writer: .vtu ascii, binary (base64),
                                                   binary + zlib, appended raw, appended base64,
                                                   appended raw + zlib, UInt64 headers; legacy
                                                   .vtk ascii and binary
       write_variants.py meshio SOURCE.vtu OUTDIR  meshio: .exo (also with node sets), .msh 2.2
                                                   ascii and binary, .vtu (its default: binary +
                                                   zlib), .vtk, .vtu and .vtk with the blocks as a
                                                   mat_id cell array

SOURCE is an ASCII .vtu geode wrote; each output is named after its variant. Exit status 77 when
the Python module is missing (the caller fails: the packages are required).
"""
import os
import sys


def vtk_variants(source, outdir):
    try:
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter
        from vtkmodules.vtkIOLegacy import vtkUnstructuredGridWriter
    except ImportError:
        sys.exit(77)
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(source)
    reader.Update()
    grid = reader.GetOutput()
    variants = {
        "ascii": dict(mode="ascii"),
        "binary": dict(mode="binary"),
        "binary-zlib": dict(mode="binary", zlib=True),
        "appended-raw": dict(mode="appended"),
        "appended-base64": dict(mode="appended", base64=True),
        "appended-raw-zlib": dict(mode="appended", zlib=True),
        "binary-zlib-uint64": dict(mode="binary", zlib=True, uint64=True),
        "appended-base64-zlib-uint64": dict(mode="appended", base64=True, zlib=True, uint64=True),
    }
    for name, v in variants.items():
        w = vtkXMLUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(os.path.join(outdir, name + ".vtu"))
        {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary,
         "appended": w.SetDataModeToAppended}[v["mode"]]()
        w.SetEncodeAppendedData(1 if v.get("base64") else 0)
        if v.get("zlib"):
            w.SetCompressorTypeToZLib()
            w.SetBlockSize(64)  # several blocks even for a small mesh
        else:
            w.SetCompressorTypeToNone()
        if v.get("uint64"):
            w.SetHeaderTypeToUInt64()
        else:
            w.SetHeaderTypeToUInt32()
        assert w.Write() == 1, name
    for name, binary in (("legacy-ascii", False), ("legacy-binary", True)):
        w = vtkUnstructuredGridWriter()
        w.SetInputData(grid)
        w.SetFileName(os.path.join(outdir, name + ".vtk"))
        w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
        assert w.Write() == 1, name


def meshio_variants(source, outdir):
    try:
        import meshio
    except ImportError:
        sys.exit(77)
    mesh = meshio.read(source)
    mesh = meshio.Mesh(mesh.points, [(c.type, c.data) for c in mesh.cells])
    mesh.write(os.path.join(outdir, "meshio.exo"))
    mesh.write(os.path.join(outdir, "meshio-22-ascii.msh"), file_format="gmsh22", binary=False)
    mesh.write(os.path.join(outdir, "meshio-22-binary.msh"), file_format="gmsh22", binary=True)
    mesh.write(os.path.join(outdir, "meshio.vtu"))
    mesh.write(os.path.join(outdir, "meshio-ascii.vtu"), binary=False)
    mesh.write(os.path.join(outdir, "meshio.vtk"), binary=False)
    # Node sets, which meshio numbers from 0 (ns_prop1 = 0, 1, ...).
    import numpy as np
    bottom = np.nonzero(mesh.points[:, 2] < mesh.points[:, 2].min() + 1e-9)[0]
    top = np.nonzero(mesh.points[:, 2] > mesh.points[:, 2].max() - 1e-9)[0]
    meshio.Mesh(mesh.points, mesh.cells, point_sets={"ns_bottom": bottom, "ns_top": top}).write(
        os.path.join(outdir, "meshio-sets.exo"))
    # As meshio writes a Gmsh mesh read with meshio.read: its physical points and surfaces as
    # blocks of vertices and quads (here the bottom's quads and one node) before the volume's.
    quads = [h[:4] for h in mesh.cells[0].data if all(mesh.points[h[:4], 2] < mesh.points[:, 2].min() + 1e-9)]
    meshio.Mesh(mesh.points, [("vertex", np.array([[bottom[0]]])), ("quad", np.array(quads))] +
                [(c.type, c.data) for c in mesh.cells]).write(
        os.path.join(outdir, "meshio-surfaces.exo"))
    # Materials as SfePy and meshio users give them: the source's blocks as the cell array mat_id.
    blocks = meshio.read(source).cell_data["block"]
    for name in ("meshio-matid.vtu", "meshio-matid.vtk"):
        meshio.Mesh(mesh.points, mesh.cells, cell_data={"mat_id": blocks}).write(
            os.path.join(outdir, name), binary=False)
    # Under a name the readers do not know: warned about, not read.
    meshio.Mesh(mesh.points, mesh.cells, cell_data={"material": blocks}).write(
        os.path.join(outdir, "meshio-material.vtu"), binary=False)


if __name__ == "__main__":
    kind, source, outdir = sys.argv[1:4]
    (vtk_variants if kind == "vtk" else meshio_variants)(source, outdir)
