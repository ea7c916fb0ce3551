#!/usr/bin/python3
"""Write the Gmsh models of tests/conform/conform_sets_test.cpp, as a user makes them with Gmsh.

usage: sets_models.py embedded|points OUT.msh

embedded: a transfinite hex box [0,1]^3 beside a tet box [1,2] x [0,1]^2 (the interface x = 1,
  fragmented so that the two share it), with physical groups on entities embedded in the tet box
  near the interface (a rectangle at z = 0.5, x in [1.04, 1.64], y in [0.15, 0.75]; a point
  (1.7, 0.8, 0.3); a segment x = 1.2, y = 0.9, z in [0.1, 0.9]) and on a patch of the tet box's
  top face z = 1 (x in [1.1, 1.6], y in [0.2, 0.7]), as .msh 4.1. Physical groups: volumes 1
  "steel" (hexes), 2 "rubber" (tets); surfaces 3 "sheet" (embedded), 4 "patch" (top face);
  points 5 "load_point"; curves 6 "probe_line".
points: eight transfinite hex boxes filling [0,2]^3 (one physical volume) beside a tet box
  [2,3] x [0,2]^2, with physical groups on the hex boxes' inner faces and on the interface x = 2,
  physical points at the centre (1, 1, 1) and on the interface at (2, 1, 1), and physical curves
  through them, as binary .msh 4.1 (the encoding in which global smoothing moved the point on
  the interface). Physical groups: volumes 1 "steel", 2 "rubber"; surfaces 3 "mid_z1" (z = 1
  inside the hexes), 4 "x1_quarter" (x = 1, y and z in [0, 1]), 5 "interface"; points 6
  "centre", 8 "interface_mid"; curves 7 "centre_line" (x = y = 1), 9 "interface_line" (x = 2,
  z = 1), 10 "x_line" (y = z = 1).
"""
import sys

import gmsh


def group(dim, tags, tag, name):
    gmsh.model.addPhysicalGroup(dim, tags, tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def within(dim, lo, hi):
    """The entities of dimension dim inside the box [lo, hi]."""
    found = []
    for _, t in gmsh.model.getEntities(dim):
        b = gmsh.model.getBoundingBox(dim, t)
        if all(lo[k] - 1e-6 <= b[k] and b[k + 3] <= hi[k] + 1e-6 for k in range(3)):
            found.append(t)
    return found


def transfinite_hexes(volume, nodes):
    """A structured hex mesh of the volume, `nodes` nodes along each of its curves."""
    gmsh.model.mesh.setTransfiniteVolume(volume)
    gmsh.model.mesh.setRecombine(3, volume)
    for _, s in gmsh.model.getBoundary([(3, volume)], oriented=False):
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
        for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
            gmsh.model.mesh.setTransfiniteCurve(c, nodes)


def embedded():
    occ = gmsh.model.occ
    hexes = occ.addBox(0, 0, 0, 1, 1, 1)
    tets = occ.addBox(1, 0, 0, 1, 1, 1)
    patch = occ.addRectangle(1.1, 0.2, 1.0, 0.5, 0.5)
    occ.fragment([(3, hexes), (3, tets)], [(2, patch)])
    sheet = occ.addRectangle(1.04, 0.15, 0.5, 0.6, 0.6)
    point = occ.addPoint(1.7, 0.8, 0.3)
    line = occ.addLine(occ.addPoint(1.2, 0.9, 0.1), occ.addPoint(1.2, 0.9, 0.9))
    occ.synchronize()

    hex_volume = within(3, (0, 0, 0), (1, 1, 1))[0]
    tet_volume = within(3, (1, 0, 0), (2, 1, 1))[0]
    top = within(2, (1.1, 0.2, 1), (1.6, 0.7, 1))
    gmsh.model.mesh.embed(2, [sheet], 3, tet_volume)
    gmsh.model.mesh.embed(0, [point], 3, tet_volume)
    gmsh.model.mesh.embed(1, [line], 3, tet_volume)
    transfinite_hexes(hex_volume, 5)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
    group(3, [hex_volume], 1, "steel")
    group(3, [tet_volume], 2, "rubber")
    group(2, [sheet], 3, "sheet")
    group(2, top, 4, "patch")
    group(0, [point], 5, "load_point")
    group(1, [line], 6, "probe_line")


def points():
    occ = gmsh.model.occ
    boxes = [occ.addBox(i, j, k, 1, 1, 1) for i in range(2) for j in range(2) for k in range(2)]
    tets = occ.addBox(2, 0, 0, 1, 2, 2)
    occ.fragment([(3, b) for b in boxes + [tets]], [])
    occ.synchronize()

    hex_volumes = within(3, (0, 0, 0), (2, 2, 2))
    tet_volumes = within(3, (2, 0, 0), (3, 2, 2))
    for v in hex_volumes:
        transfinite_hexes(v, 3)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
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


def main(model, out):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    {"embedded": embedded, "points": points}[model]()
    gmsh.model.mesh.generate(3)
    if model == "points":
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.write(out)
    gmsh.finalize()


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("embedded", "points"):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
