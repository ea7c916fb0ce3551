#!/usr/bin/python3
"""Two bodies apart in one file, as a user meshes an assembly with Gmsh (tests/parallel).

usage: apart_model.py OUT.msh [n]

A transfinite hex box [0, 1]^3 with n cells along each edge (physical volume 1 "bolt") and a
Delaunay tet box [1.5, 2.5] x [0, 1]^2 of size 1 / n (physical volume 2 "bracket"), a gap of 0.5
between them, meshed in one generate(3): no face is shared, so there is no transition to make and
each body is diced alone.
"""
import sys

import gmsh

out = sys.argv[1]
n = int(sys.argv[2]) if len(sys.argv) > 2 else 4
gmsh.initialize(["-nt", "1"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("apart")
occ = gmsh.model.occ
bolt = occ.addBox(0, 0, 0, 1, 1, 1)
bracket = occ.addBox(1.5, 0, 0, 1, 1, 1)
occ.synchronize()
mesh = gmsh.model.mesh
_, surfaces = gmsh.model.getAdjacencies(3, bolt)
for s in surfaces:
    for c in gmsh.model.getAdjacencies(2, s)[1]:
        mesh.setTransfiniteCurve(abs(c), n + 1)
    mesh.setTransfiniteSurface(s)
    mesh.setRecombine(2, s)
mesh.setTransfiniteVolume(bolt)
mesh.setRecombine(3, bolt)
gmsh.model.addPhysicalGroup(3, [bolt], 1)
gmsh.model.setPhysicalName(3, 1, "bolt")
gmsh.model.addPhysicalGroup(3, [bracket], 2)
gmsh.model.setPhysicalName(3, 2, "bracket")
gmsh.option.setNumber("Mesh.MeshSizeMax", 1.0 / n)
mesh.generate(3)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write(out)
gmsh.finalize()
