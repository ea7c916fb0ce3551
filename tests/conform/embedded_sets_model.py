#!/usr/bin/python3
"""Write the model of tests/conform/conform_sets_test.cpp's "sets inside a block" case, as a
user makes it with Gmsh: a transfinite hex box [0,1]^3 beside a tet box [1,2] x [0,1]^2 (the
interface x = 1, fragmented so that the two share it), with physical groups on entities embedded
in the tet box near the interface (a rectangle at z = 0.5, x in [1.04, 1.64], y in [0.15, 0.75];
a point (1.7, 0.8, 0.3); a segment x = 1.2, y = 0.9, z in [0.1, 0.9]) and on a patch of the tet
box's top face z = 1 (x in [1.1, 1.6], y in [0.2, 0.7]), as .msh 4.1.

usage: embedded_sets_model.py OUT.msh
Physical groups: volumes 1 "steel" (hexes), 2 "rubber" (tets); surfaces 3 "sheet" (embedded),
4 "patch" (top face); points 5 "load_point"; curves 6 "probe_line".
"""
import sys

import gmsh


def group(dim, tags, tag, name):
    gmsh.model.addPhysicalGroup(dim, tags, tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def main(out):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    occ = gmsh.model.occ
    hexes = occ.addBox(0, 0, 0, 1, 1, 1)
    tets = occ.addBox(1, 0, 0, 1, 1, 1)
    patch = occ.addRectangle(1.1, 0.2, 1.0, 0.5, 0.5)
    occ.fragment([(3, hexes), (3, tets)], [(2, patch)])
    sheet = occ.addRectangle(1.04, 0.15, 0.5, 0.6, 0.6)
    point = occ.addPoint(1.7, 0.8, 0.3)
    line = occ.addLine(occ.addPoint(1.2, 0.9, 0.1), occ.addPoint(1.2, 0.9, 0.9))
    occ.synchronize()

    def in_box(dim, tag, lo, hi):
        b = gmsh.model.getBoundingBox(dim, tag)
        return all(lo[k] - 1e-6 <= b[k] and b[k + 3] <= hi[k] + 1e-6 for k in range(3))

    volumes = [t for _, t in gmsh.model.getEntities(3)]
    hex_volume = [v for v in volumes if in_box(3, v, (0, 0, 0), (1, 1, 1))][0]
    tet_volume = [v for v in volumes if v != hex_volume][0]
    top = [t for _, t in gmsh.model.getEntities(2) if in_box(2, t, (1.1, 0.2, 1), (1.6, 0.7, 1))]
    gmsh.model.mesh.embed(2, [sheet], 3, tet_volume)
    gmsh.model.mesh.embed(0, [point], 3, tet_volume)
    gmsh.model.mesh.embed(1, [line], 3, tet_volume)
    gmsh.model.mesh.setTransfiniteVolume(hex_volume)
    for _, s in gmsh.model.getBoundary([(3, hex_volume)], oriented=False):
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
        for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
            gmsh.model.mesh.setTransfiniteCurve(c, 5)
    gmsh.model.mesh.setRecombine(3, hex_volume)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
    group(3, [hex_volume], 1, "steel")
    group(3, [tet_volume], 2, "rubber")
    group(2, [sheet], 3, "sheet")
    group(2, top, 4, "patch")
    group(0, [point], 5, "load_point")
    group(1, [line], 6, "probe_line")
    gmsh.model.mesh.generate(3)
    gmsh.write(out)
    gmsh.finalize()


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
