#!/usr/bin/python3
"""A solver takes it: GetFEM (Debian's python3-getfem) on geode conform outputs.

usage: getfem_patch_test.py GEODE WORKDIR

For three demo models (geode demo --model NAME: a swept cylinder in a Delaunay tet box, a hex
block in the notch of an L-shaped tet part, a tet cube in 26 structured blocks), the conformed
all-hex mesh is written as .msh 4.1, .msh 2.2 and .vtu, and each file, read as written, must
1. carry its element blocks as the solver's regions: GetFEM's Gmsh import gives one region per
   physical volume (meshio reads the same from the .msh files), the .vtu (read with meshio)
   gives the cell array mat_id; the region ids are
   the blocks of geode's report, with the same element counts in all three files, and every
   hex in exactly one region;
2. pass the linear patch test: Laplace's equation with u = a + bx + cy + dz imposed on the
   boundary, trilinear elements (FEM_QK(3,1)), is solved by that u to 1e-10 at every node.
A control must fail: the same mesh cut along its block interface (the interface nodes
duplicated for one block, shifted by 1e-9 so that GetFEM does not merge them back) leaves the
cut free, so the solution is no longer linear: the test must see an error above 1e-4.
Exit 0 when all hold; prints one line per check.
"""
import json
import os
import subprocess
import sys

import getfem as gf
import meshio
import numpy as np

DEMOS = [("cylinder", 2), ("lshape", 2), ("nugget", 2)]
COEF = np.array([0.3, 1.7, -0.6, 2.2])  # u = a + b x + c y + d z
VTK_TO_GETFEM_HEX = [0, 1, 3, 2, 4, 5, 7, 6]  # GT_QK(3,1) numbers corners lexicographically

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def exact(points):
    return COEF[0] + COEF[1:] @ points


def patch_error(m, dirichlet_faces=None):
    """Largest |u_h - u| over the nodes; Dirichlet on dirichlet_faces (default: every outer face)."""
    mf = gf.MeshFem(m, 1)
    mf.set_classical_fem(1)
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(3,5)"))
    faces = m.outer_faces() if dirichlet_faces is None else dirichlet_faces
    region = 900001
    m.set_region(region, faces)
    md = gf.Model("real")
    md.add_fem_variable("u", mf)
    md.add_Laplacian_brick(mim, "u")
    dofs = mf.basic_dof_nodes()
    md.add_initialized_fem_data("g", mf, exact(dofs))
    md.add_Dirichlet_condition_with_simplification("u", region, "g")
    md.solve()
    u = md.variable("u")
    m.delete_region(region)
    return float(np.max(np.abs(u - exact(dofs)))) / float(np.max(np.abs(exact(dofs))))


def mesh_from_arrays(points, hexes, regions):
    m = gf.Mesh("empty", 3)
    gt = gf.GeoTrans("GT_QK(3,1)")
    pts = points[hexes[:, VTK_TO_GETFEM_HEX]]  # (cells, 8, 3)
    cvs = m.add_convex(gt, np.transpose(pts, (2, 1, 0)))
    for rid in np.unique(regions):
        m.set_region(int(rid), np.array([cvs[regions == rid]]))
    return m


def region_counts(m, ids):
    return {int(r): m.region(int(r)).shape[1] for r in ids}


def cut_along_interface(points, hexes, blocks):
    """Duplicates the nodes shared by the first block and the others for the other blocks."""
    first = blocks == blocks.min()
    shared = np.intersect1d(np.unique(hexes[first]), np.unique(hexes[~first]))
    new = dict((int(v), len(points) + k) for k, v in enumerate(shared))
    extra = points[shared] + 1e-9 * np.array([1.0, 0.7, 0.3])
    cut = hexes.copy()
    for h in np.nonzero(~first)[0]:
        cut[h] = [new.get(int(v), v) for v in hexes[h]]
    return np.vstack([points, extra]), cut, len(shared)


def run(geode, workdir, name, n):
    report = os.path.join(workdir, name + ".json")
    files = {"msh41": name + ".msh", "msh22": name + "-22.msh", "vtu": name + ".vtu",
             "msh41-binary": name + "-binary.msh", "msh22-binary": name + "-22-binary.msh"}
    for fmt, f in files.items():
        cmd = [geode, "demo", "--model", name, "-n", str(n), "--quiet", "-o", os.path.join(workdir, f)]
        if fmt.startswith("msh22"):
            cmd += ["--format", "msh22"]
        if fmt.endswith("binary"):
            cmd += ["--msh-encoding", "binary"]
        if fmt == "vtu":
            cmd += ["--report", report]
        subprocess.run(cmd, check=True)
    blocks = sorted(b["id"] for b in json.load(open(report))["blocks"])
    counts = {}
    for fmt in ("msh41", "msh22"):
        path = os.path.join(workdir, files[fmt])
        m = gf.Mesh("import", "gmsh", path)
        # Every physical volume and surface of the file is a region of that number (GetFEM
        # renumbers a tag used twice, with a warning).
        text = open(path, "rb").read()
        names = text[text.index(b"$PhysicalNames"):text.index(b"$EndPhysicalNames")].decode().splitlines()[2:]
        tags = sorted(int(line.split()[1]) for line in names if line.split()[0] in ("2", "3"))
        check(sorted(int(r) for r in m.regions()) == tags, f"{name} {fmt}: GetFEM regions {sorted(int(r) for r in m.regions())} are the file's physical volumes and surfaces {tags}")
        c = region_counts(m, blocks)
        check(sorted(c) == blocks and all(v > 0 for v in c.values()), f"{name} {fmt}: GetFEM regions {sorted(c)} are the blocks {blocks}")
        check(sum(c.values()) == m.nbcvs(), f"{name} {fmt}: every hex of {m.nbcvs()} in one region ({c})")
        counts[fmt] = c
        # meshio reads the same file to the same blocks and names.
        mm = meshio.read(path)
        physical = np.concatenate([d for cb, d in zip(mm.cells, mm.cell_data["gmsh:physical"]) if cb.type == "hexahedron"])
        mc = {int(b): int(np.sum(physical == b)) for b in np.unique(physical)}
        check(mc == c and all(v[1] == 3 for k, v in mm.field_data.items() if int(v[0]) in blocks),
              f"{name} {fmt}: meshio reads the same blocks ({mc}) and their names ({sorted(mm.field_data)})")
        err = patch_error(m)
        check(err < 1e-10, f"{name} {fmt}: patch test, max relative error {err:.2e} over {m.nbpts()} nodes")
    # GetFEM reads ASCII .msh only; meshio reads the binary files to the same mesh and blocks.
    for fmt in ("msh41", "msh22"):
        text, binary = (meshio.read(os.path.join(workdir, files[f])) for f in (fmt, fmt + "-binary"))
        check(np.array_equal(text.points, binary.points)
              and all(a.type == b.type and np.array_equal(a.data, b.data) for a, b in zip(text.cells, binary.cells))
              and len(text.cells) == len(binary.cells)
              and all(np.array_equal(a, b) for a, b in zip(text.cell_data["gmsh:physical"], binary.cell_data["gmsh:physical"])),
              f"{name} {fmt}: the binary file (--msh-encoding binary) holds what the ASCII one does")
    mesh = meshio.read(os.path.join(workdir, files["vtu"]))
    hexes = np.vstack([c.data for c in mesh.cells if c.type == "hexahedron"])
    mat = np.concatenate([d for c, d in zip(mesh.cells, mesh.cell_data["mat_id"]) if c.type == "hexahedron"])
    block = np.concatenate([d for c, d in zip(mesh.cells, mesh.cell_data["block"]) if c.type == "hexahedron"])
    check(np.array_equal(mat, block), f"{name} vtu: mat_id equals block")
    m = mesh_from_arrays(mesh.points, hexes, mat)
    c = region_counts(m, blocks)
    counts["vtu"] = c
    check(counts["msh41"] == counts["msh22"] == c, f"{name}: the same block counts in .msh 4.1, 2.2 and .vtu ({c})")
    err = patch_error(m)
    check(err < 1e-10, f"{name} vtu: patch test, max relative error {err:.2e} over {m.nbpts()} nodes")

    # The control: cut along the block interface, Dirichlet on the original boundary only.
    boundary_nodes = m.pid_in_faces(m.outer_faces())
    points, cut, duplicated = cut_along_interface(mesh.points, hexes, mat)
    mc = mesh_from_arrays(points, cut, mat)
    check(mc.nbpts() == m.nbpts() + duplicated and duplicated > 0,
          f"{name} control: {duplicated} interface nodes duplicated ({mc.nbpts()} points)")
    # Original boundary nodes and their duplicates; faces of the cut mesh's boundary made of
    # them only (the cut faces have interior nodes).
    # GetFEM numbers points in order of first use: match them by coordinates (duplicates
    # moved back by their shift).
    shift = 1e-9 * np.array([1.0, 0.7, 0.3])
    coords = {tuple(np.round(m.pts()[:, v], 7)) for v in boundary_nodes}
    pc = mc.pts()
    pids = [p for p in range(mc.nbpts()) if tuple(np.round(pc[:, p], 7)) in coords or tuple(np.round(pc[:, p] - shift, 7)) in coords]
    outer = mc.outer_faces()
    on_boundary = {tuple(f) for f in mc.faces_from_pid(np.array(pids)).T}
    keep = np.array([f for f in outer.T if tuple(f) in on_boundary]).T
    err = patch_error(mc, keep)
    check(err > 1e-4, f"{name} control (cut along the block interface): patch test fails, error {err:.2e}")


def main():
    geode, workdir = sys.argv[1], sys.argv[2]
    os.makedirs(workdir, exist_ok=True)
    for name, n in DEMOS:
        run(geode, workdir, name, n)
    if failures:
        print(f"{len(failures)} checks failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
