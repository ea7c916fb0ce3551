#!/usr/bin/python3
"""Write the model of tests/conform/conform_sets_test.cpp's "a point among curves" case, as a
user makes it with Gmsh: eight transfinite hex boxes filling [0,2]^3 (one physical volume) beside
a tet box [2,3] x [0,2]^2, with physical groups on the hex boxes' inner faces and on the
interface x = 2, physical points at the centre (1, 1, 1) and on the interface at (2, 1, 1), and
physical curves through them, as binary .msh 4.1 (the encoding in which global smoothing moved
the point on the interface).

usage: point_sets_model.py OUT.msh
Physical groups: volumes 1 "steel", 2 "rubber"; surfaces 3 "mid_z1" (z = 1 inside the hexes),
4 "x1_quarter" (x = 1, y and z in [0, 1]), 5 "interface"; points 6 "centre", 8 "interface_mid";
curves 7 "centre_line" (x = y = 1), 9 "interface_line" (x = 2, z = 1), 10 "x_line" (y = z = 1).
"""
import sys

import gmsh


def main(out):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    boxes = [occ.addBox(i, j, k, 1, 1, 1) for i in range(2) for j in range(2) for k in range(2)]
    tets = occ.addBox(2, 0, 0, 1, 2, 2)
    occ.fragment([(3, b) for b in boxes + [tets]], [])
    occ.synchronize()

    def within(dim, lo, hi):
        found = []
        for _, t in gmsh.model.getEntities(dim):
            b = gmsh.model.getBoundingBox(dim, t)
            if all(lo[k] - 1e-6 <= b[k] and b[k + 3] <= hi[k] + 1e-6 for k in range(3)):
                found.append(t)
        return found

    hex_volumes = within(3, (0, 0, 0), (2, 2, 2))
    tet_volumes = within(3, (2, 0, 0), (3, 2, 2))
    for v in hex_volumes:
        gmsh.model.mesh.setTransfiniteVolume(v)
        gmsh.model.mesh.setRecombine(3, v)
        for _, s in gmsh.model.getBoundary([(3, v)], oriented=False):
            gmsh.model.mesh.setTransfiniteSurface(s)
            gmsh.model.mesh.setRecombine(2, s)
            for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
                gmsh.model.mesh.setTransfiniteCurve(c, 3)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)

    def group(dim, tags, tag, name):
        gmsh.model.addPhysicalGroup(dim, tags, tag)
        gmsh.model.setPhysicalName(dim, tag, name)

    group(3, hex_volumes, 1, "steel")
    group(3, tet_volumes, 2, "rubber")
    group(2, within(2, (0, 0, 1), (2, 2, 1)), 3, "mid_z1")
    group(2, within(2, (1, 0, 0), (1, 1, 1)), 4, "x1_quarter")
    group(2, within(2, (2, 0, 0), (2, 2, 2)), 5, "interface")
    group(0, within(0, (1, 1, 1), (1, 1, 1)), 6, "centre")
    group(1, within(1, (1, 1, 0), (1, 1, 2)), 7, "centre_line")
    group(0, within(0, (2, 1, 1), (2, 1, 1)), 8, "interface_mid")
    group(1, within(1, (2, 0, 1), (2, 2, 1)), 9, "interface_line")
    group(1, within(1, (0, 1, 1), (2, 1, 1)), 10, "x_line")
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(out)
    gmsh.finalize()


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
