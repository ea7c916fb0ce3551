#!/usr/bin/python3
"""A hex ring in tet potting, as a user scripts it with Gmsh's built-in kernel (tests/python).

usage: ring_model.py OUT.msh [n] [size factor]

An annulus of radii 0.5 and 1 at z = -0.25, recombined (2n + 1 nodes per quarter circle) and
swept 0.5 up in n layers (physical volume 1), inside the box [-2, 2]^2 x [-1, 1] whose tets
(physical volume 2, size 1.5 / n) have the ring's faces as a hole, meshed in one generate(3):
Gmsh puts pyramids on the ring's quads, and Debian's Gmsh 4.8 folds tets next to them (at n = 3
one tet; 17 of 20 meshes at n = 3 to 6 and size factors 0.98 to 1.02).
tests/demo/input_check_test.cpp builds the same through the C++ API.
"""
import math
import sys

import gmsh

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 3
factor = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
gmsh.initialize(["-nt", "1"])
gmsh.option.setNumber("General.Terminal", 0)
geo = gmsh.model.geo
ring_size, box_size = 1.0 / n, 1.5 / n


def circle(r):
    c = geo.addPoint(0, 0, -0.25, ring_size)
    p = [geo.addPoint(r * math.cos(i * math.pi / 2), r * math.sin(i * math.pi / 2), -0.25, ring_size)
         for i in range(4)]
    arcs = [geo.addCircleArc(p[i], c, p[(i + 1) % 4]) for i in range(4)]
    for a in arcs:
        geo.mesh.setTransfiniteCurve(a, 2 * n + 1)
    return geo.addCurveLoop(arcs)


annulus = geo.addPlaneSurface([circle(1.0), circle(0.5)])
geo.mesh.setRecombine(2, annulus)
swept = geo.extrude([(2, annulus)], 0, 0, 0.5, numElements=[n], recombine=True)
ring = [t for d, t in swept if d == 3][0]
ring_faces = [annulus] + [t for d, t in swept if d == 2]
corner = [geo.addPoint(2 if c & 1 else -2, 2 if c & 2 else -2, 1 if c & 4 else -1, box_size)
          for c in range(8)]
lines = {}


def line(a, b):
    if (b, a) in lines:
        return -lines[(b, a)]
    if (a, b) not in lines:
        lines[(a, b)] = geo.addLine(corner[a], corner[b])
    return lines[(a, b)]


faces = [geo.addPlaneSurface([geo.addCurveLoop([line(f[i], f[(i + 1) % 4]) for i in range(4)])])
         for f in ([0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [1, 3, 7, 5], [3, 2, 6, 7], [2, 0, 4, 6])]
potting = geo.addVolume([geo.addSurfaceLoop(faces), geo.addSurfaceLoop(ring_faces)])
geo.synchronize()
gmsh.model.addPhysicalGroup(3, [ring], 1)
gmsh.model.setPhysicalName(3, 1, "ring")
gmsh.model.addPhysicalGroup(3, [potting], 2)
gmsh.model.setPhysicalName(3, 2, "potting")
gmsh.option.setNumber("Mesh.MeshSizeFactor", factor)
gmsh.model.mesh.generate(3)
gmsh.write(out)
gmsh.finalize()
