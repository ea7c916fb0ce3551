#!/usr/bin/python3
"""A hex box beside a tet box, meshed together by Gmsh (pyramids on the shared quads), with the
physical groups users give: two volumes (blocks), surfaces (side sets), a curve and a point
(node sets). usage: sets_model.py OUT.msh [n] [aggregate]
aggregate: also a physical volume "all" over both volumes (a group over materials, as users add
one), which the reader names in a warning (each element goes to its most specific group)."""
import sys

import gmsh

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 8
aggregate = len(sys.argv) > 3 and sys.argv[3] == "aggregate"
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("sets")
occ = gmsh.model.occ
a = occ.addBox(0, 0, 0, 1, 1, 1)
b = occ.addBox(1, 0, 0, 1, 1, 1)
occ.fragment([(3, a)], [(3, b)])
occ.synchronize()
h = 1.0 / n
gmsh.model.mesh.setSize(gmsh.model.getEntities(0), h)
for dim, tag in gmsh.model.getEntities(1):
    lo = gmsh.model.getBoundingBox(dim, tag)
    if lo[3] <= 1.0 + 1e-5:  # curves of the hex box
        gmsh.model.mesh.setTransfiniteCurve(tag, n + 1)
for dim, tag in gmsh.model.getEntities(2):
    x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, tag)
    if x1 <= 1.0 + 1e-5:
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(dim, tag)
gmsh.model.mesh.setTransfiniteVolume(a)
gmsh.model.mesh.setRecombine(3, a)


def group(dim, tags, tag, name):
    gmsh.model.addPhysicalGroup(dim, tags, tag)
    gmsh.model.setPhysicalName(dim, tag, name)


def surfaces(test):
    return [t for d, t in gmsh.model.getEntities(2) if test(*gmsh.model.getBoundingBox(d, t))]


def curves(test):
    return [t for d, t in gmsh.model.getEntities(1) if test(*gmsh.model.getBoundingBox(d, t))]


group(3, [a], 1, "steel")
group(3, [b], 2, "potting")
if aggregate:
    group(3, [a, b], 3, "all")
group(2, surfaces(lambda x0, y0, z0, x1, y1, z1: x1 < 1e-5), 10, "fixed")
group(2, surfaces(lambda x0, y0, z0, x1, y1, z1: x0 > 2 - 1e-5), 11, "load")
group(2, surfaces(lambda x0, y0, z0, x1, y1, z1: z1 < 1e-5), 12, "floor")
group(
    1, curves(lambda x0, y0, z0, x1, y1, z1: z0 > 1 - 1e-5 and y0 > 1 - 1e-5), 20, "top edge")
pts = [t for d, t in gmsh.model.getEntities(0) if gmsh.model.getValue(0, t, [])[0] > 2 - 1e-5]
group(0, pts[:1], 21, "corner")
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write(out)
gmsh.finalize()
