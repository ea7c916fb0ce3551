#!/usr/bin/python3
"""Write the hostile input files of tests/io/bombs_test.sh into OUTDIR.

usage: make_bombs.py OUTDIR

- nested.vtu: 30,000 nested tags (200 KB), which once overflowed the XML parser's stack;
- zlib.vtu: 1.2 MB of zlib blocks that inflate to 1.2 GB of points, every array pointing at
  the same appended bytes (2.5 GB and more inflated in all);
- nodes.exo: a 19 KB netCDF-4 Exodus file whose header claims 2e9 nodes (never written: HDF5
  stores nothing for them), made from a meshio-written hex;
- big.msh: a 6 GiB sparse .msh (no disk space used) with a bad token after its nodes, which a
  reader that copies whole files into memory loads at once before finding it;
- small.msh: a valid unit hex (the memory a run needs to read a file at all);
- nodes.msh: a valid 69 MB .msh of 2.5 million nodes and one hex: its model needs a few hundred
  MB, honestly (read when the process may have enough);
- grid.msh: a valid 20^3 hex grid (8,000 hexes, 470 KB), read in a few MB, whose conform run
  (diced, smoothed) needs tens of MB more;
- sheets.json: an arrangement spec of 200,000 planes (13 MB), which once took 9.5 s and 243 MB
  to be refused after parsing (at most 256 sheets).
Exit status 77 when a Python module is missing.
"""
import os
import struct
import sys
import zlib


def nested(outdir):
    with open(os.path.join(outdir, "nested.vtu"), "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0">\n')
        f.write("<a>" * 30000)
        f.write("</a>" * 30000)
        f.write("\n</VTKFile>\n")


def zlib_bomb(outdir):
    block = 1 << 20
    compressed = zlib.compress(bytes(block), 9)
    blocks = 1200 * 1024 // len(compressed)  # about 1.2 MB of compressed data
    points = blocks * block // 24
    last = points * 24 - (blocks - 1) * block  # the blocks add up to the points array exactly
    tail = zlib.compress(bytes(last), 9)
    header = struct.pack("<" + "Q" * (3 + blocks), blocks, block, last, *([len(compressed)] * (blocks - 1)), len(tail))
    data = header + compressed * (blocks - 1) + tail
    arrays = ""
    for name, kind, comps in (("Points", "Float64", 3),):
        arrays += f'<Points><DataArray type="{kind}" NumberOfComponents="{comps}" format="appended" offset="0"/></Points>\n'
    cells = "".join(
        f'<DataArray type="{t}" Name="{n}" format="appended" offset="0"/>\n'
        for n, t in (("connectivity", "Int64"), ("offsets", "Int64"), ("types", "UInt8")))
    with open(os.path.join(outdir, "zlib.vtu"), "wb") as f:
        f.write(('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
                 'header_type="UInt64" compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n'
                 f'<Piece NumberOfPoints="{points}" NumberOfCells="{points // 8}">\n'
                 + arrays + "<Cells>\n" + cells + "</Cells>\n</Piece>\n</UnstructuredGrid>\n"
                 '<AppendedData encoding="raw">\n_').encode())
        f.write(data)
        f.write(b"\n</AppendedData>\n</VTKFile>\n")


def exodus_nodes(outdir):
    try:
        import meshio
        import netCDF4
        import numpy as np
    except ImportError:
        sys.exit(77)
    small = os.path.join(outdir, "small.exo")
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    meshio.Mesh(points, [("hexahedron", np.arange(8).reshape(1, 8))]).write(small)
    with netCDF4.Dataset(small) as src, netCDF4.Dataset(os.path.join(outdir, "nodes.exo"), "w", format="NETCDF4") as dst:
        dst.setncatts({k: src.getncattr(k) for k in src.ncattrs()})
        for name, dim in src.dimensions.items():
            size = 2000000000 if name == "num_nodes" else (None if dim.isunlimited() else len(dim))
            dst.createDimension(name, size)
        for name, var in src.variables.items():
            big = "num_nodes" in var.dimensions
            out = dst.createVariable(name, var.datatype, var.dimensions,
                                     chunksizes=[1024 if d == "num_nodes" else len(src.dimensions[d]) for d in var.dimensions] if big else None)
            out.setncatts({k: var.getncattr(k) for k in var.ncattrs()})
            if not big and var.size > 0:
                out[:] = var[:]
    os.remove(small)


def big_msh(outdir):
    # A valid start, then a bad token and 6 GiB of holes: a reader that maps the file touches
    # one page; one that copies it first holds 6 GiB.
    path = os.path.join(outdir, "big.msh")
    with open(path, "wb") as f:
        f.write(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n3 1 0 2\n1\n2\n0 0 0\n1 0 0\n"
                b"$EndNodes\n$Elements\nX\n")
        f.truncate(6 << 30)


UNIT = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def msh(path, points, hexes):
    n = len(points)
    with open(path, "w") as f:
        f.write(f"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 {n} 1 {n}\n3 1 0 {n}\n")
        f.write("".join(f"{i}\n" for i in range(1, n + 1)))
        f.write("".join(f"{x} {y} {z}\n" for x, y, z in points))
        f.write(f"$EndNodes\n$Elements\n1 {len(hexes)} 1 {len(hexes)}\n3 1 5 {len(hexes)}\n")
        f.write("".join(f"{e + 1} " + " ".join(str(v + 1) for v in h) + "\n" for e, h in enumerate(hexes)))
        f.write("$EndElements\n")


def small_and_nodes(outdir):
    msh(os.path.join(outdir, "small.msh"), UNIT, [list(range(8))])
    extra = [(2 + (i % 1000) * 1e-3, (i // 1000 % 1000) * 1e-3, (i // 1000000) * 1e-3) for i in range(2500000 - 8)]
    msh(os.path.join(outdir, "nodes.msh"), UNIT + extra, [list(range(8))])


def grid(outdir, n=20):
    index = lambda i, j, k: (k * (n + 1) + j) * (n + 1) + i
    points = [(i, j, k) for k in range(n + 1) for j in range(n + 1) for i in range(n + 1)]
    hexes = [[index(i + di, j + dj, k + dk) for di, dj, dk in
              ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1))]
             for k in range(n) for j in range(n) for i in range(n)]
    msh(os.path.join(outdir, "grid.msh"), points, hexes)


def many_sheets(outdir, n=200000):
    with open(os.path.join(outdir, "sheets.json"), "w") as f:
        f.write('{"dim": 3, "domain": {"box": [[0, 0, 0], [1, 1, 1]]}, "sheets": [\n')
        f.write(",\n".join(f'{{"name": "p{i}", "plane": {{"point": [{(i + 1) / (n + 1):.7f}, 0, 0], '
                            f'"normal": [1, 0, 0]}}}}' for i in range(n)))
        f.write("\n]}\n")


if __name__ == "__main__":
    outdir = sys.argv[1]
    nested(outdir)
    zlib_bomb(outdir)
    exodus_nodes(outdir)
    big_msh(outdir)
    small_and_nodes(outdir)
    grid(outdir)
    many_sheets(outdir)
