#!/usr/bin/python3
"""A hex ball in tet potting, as a user makes one with Gmsh (tests/conform/conform_test.cpp).

usage: ball_model.py OUT.msh [n]

A transfinite 7-block ball of radius 0.5 (an inner cube of half-side 0.2 and six cushions out to
the sphere, n cells along each sphere arc, n / 2 across a cushion; physical volume 1 "ball") in a
Delaunay tet box [-1, 1]^3 (physical volume 2 "potting"), meshed in one generate(3): Gmsh puts a
pyramid on each of the ball's curved quads, whose corners are not in one plane.
"""
import itertools
import math
import sys

import gmsh

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 4
gmsh.initialize(["-nt", "1"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("ball")
geo = gmsh.model.geo
radius, half = 0.5, 0.2
centre = geo.addPoint(0, 0, 0)
corners = list(itertools.product((-1, 1), repeat=3))
inner = {k: geo.addPoint(*(half * x for x in k)) for k in corners}
outer = {k: geo.addPoint(*(radius / math.sqrt(3) * x for x in k)) for k in corners}
edges = [(u, v) for u in corners for v in corners
         if u < v and sum(x != y for x, y in zip(u, v)) == 1]
lines = {e: geo.addLine(inner[e[0]], inner[e[1]]) for e in edges}
arcs = {e: geo.addCircleArc(outer[e[0]], centre, outer[e[1]]) for e in edges}
rays = {k: geo.addLine(inner[k], outer[k]) for k in corners}


def curve(table, u, v):
    return table[u, v] if (u, v) in table else -table[v, u]


# Each face of the cube: its four corners in a cycle.
cycles = []
for d in range(3):
    for side in (-1, 1):
        other = [q for q in range(3) if q != d]
        face = [k for k in corners if k[d] == side]
        cycles.append(sorted(face, key=lambda k: math.atan2(k[other[1]], k[other[0]])))


def loop(table, cycle):
    return geo.addCurveLoop([curve(table, cycle[i], cycle[(i + 1) % 4]) for i in range(4)])


cube_faces = [geo.addPlaneSurface([loop(lines, c)]) for c in cycles]
sphere_faces = [geo.addSurfaceFilling([loop(arcs, c)], sphereCenterTag=centre) for c in cycles]
ray_faces = {e: geo.addPlaneSurface([geo.addCurveLoop([lines[e], rays[e[1]], -arcs[e], -rays[e[0]]])])
             for e in edges}
cube = geo.addVolume([geo.addSurfaceLoop(cube_faces)])
cushions = []
for i, c in enumerate(cycles):
    sides = [ray_faces[tuple(sorted((c[j], c[(j + 1) % 4])))] for j in range(4)]
    cushions.append(geo.addVolume([geo.addSurfaceLoop([cube_faces[i], sphere_faces[i]] + sides)]))
box = {k: geo.addPoint(*k, 0.15) for k in corners}
box_lines = {e: geo.addLine(box[e[0]], box[e[1]]) for e in edges}
box_faces = [geo.addPlaneSurface([loop(box_lines, c)]) for c in cycles]
potting = geo.addVolume([geo.addSurfaceLoop(box_faces), geo.addSurfaceLoop(sphere_faces)])
geo.synchronize()
for e in edges:
    gmsh.model.mesh.setTransfiniteCurve(lines[e], n + 1)
    gmsh.model.mesh.setTransfiniteCurve(arcs[e], n + 1)
for k in corners:
    gmsh.model.mesh.setTransfiniteCurve(rays[k], max(1, n // 2) + 1)
for s in cube_faces + sphere_faces + list(ray_faces.values()):
    gmsh.model.mesh.setTransfiniteSurface(s)
    gmsh.model.mesh.setRecombine(2, s)
for v in [cube] + cushions:
    gmsh.model.mesh.setTransfiniteVolume(v)
    gmsh.model.mesh.setRecombine(3, v)
gmsh.model.addPhysicalGroup(3, [cube] + cushions, 1)
gmsh.model.setPhysicalName(3, 1, "ball")
gmsh.model.addPhysicalGroup(3, [potting], 2)
gmsh.model.setPhysicalName(3, 2, "potting")
gmsh.model.mesh.generate(3)
gmsh.write(out)
gmsh.finalize()
