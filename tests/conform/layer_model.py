#!/usr/bin/python3
"""A hex layer with a few wedges in it between tets on both sides, as a user makes one with Gmsh.

usage: layer_model.py OUT.msh cylinder|sphere [n] [out|in] [thickness] [quads] [cells=N]
       [ratio=R]

A curved surface recombined by Gmsh's default recombination (Blossom), which leaves a few
triangles among the quads, extruded along its normals in 2 cells (`Extrude {Surface{...};
Layers{2}; Recombine;}`, the geo kernel's extrudeBoundaryLayer): a layer of hexes with a few
wedges in it (physical volume 2 "layer") between Delaunay tets on both sides, the core
(physical volume 1 "core") and a box of potting (physical volume 3 "potting"), all meshed in one
generate(3), so Gmsh puts a pyramid on every layer quad a tet volume meets.

cylinder: the side of a cylinder of radius 0.4 along z through the box [-1, 1]^2 x [0, 1], its
ends on the box's bottom and top (the side meshed by Gmsh's 2D Delaunay algorithm before it is
recombined). sphere: a sphere of
radius 0.5 in the box [-1, 1]^3. The layer is `thickness` thick (0.1), extruded out of the surface
into the potting (out, the default) or into the core (in); n cells per unit length (6). quads: the
surface recombined into quads only, so the layer has no wedges (the cylinder's side meshed by
Gmsh's default frontal algorithm, which Blossom recombines fully there; the sphere by Blossom
full-quad, Mesh.RecombinationAlgorithm 3).
cells=N: the layer in N cells (2); ratio=R: their heights growing by R from the surface
(1: equal).
Physical surface 1 "skin": the model's boundary; physical surface 2 "surface": the surface the
layer was extruded from.
"""
import sys

import gmsh

out = sys.argv[1]
shape = sys.argv[2]
n = int(sys.argv[3]) if len(sys.argv) > 3 else 6
inward = len(sys.argv) > 4 and sys.argv[4] == "in"
thickness = float(sys.argv[5]) if len(sys.argv) > 5 else 0.1
options = sys.argv[6:]
quads = "quads" in options
cells = next((int(o[6:]) for o in options if o.startswith("cells=")), 2)
ratio = next((float(o[6:]) for o in options if o.startswith("ratio=")), 1.0)
assert shape in ("cylinder", "sphere")
gmsh.initialize(["-nt", "1"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add(shape + "-layer")
geo = gmsh.model.geo
lc = 1.0 / n
radius = 0.4 if shape == "cylinder" else 0.5


def point(x, y, z):
    return geo.addPoint(x, y, z, lc)


def loop(curves):
    return geo.addCurveLoop(curves)


def box(z0, z1):
    """The sides of [-1, 1]^2 x [z0, z1] and its bottom and top edge rings."""
    c = [[point(x, y, z) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))] for z in (z0, z1)]
    rings = [[geo.addLine(r[i], r[(i + 1) % 4]) for i in range(4)] for r in c]
    up = [geo.addLine(c[0][i], c[1][i]) for i in range(4)]
    sides = [geo.addPlaneSurface([loop([rings[0][i], up[(i + 1) % 4], -rings[1][i], -up[i]])]) for i in range(4)]
    return sides, rings


if shape == "cylinder":
    centres = [point(0, 0, z) for z in (0, 1)]
    rim = [[point(radius * x, radius * y, z) for x, y in ((1, 0), (0, 1), (-1, 0), (0, -1))] for z in (0, 1)]
    arcs = [[geo.addCircleArc(r[i], c, r[(i + 1) % 4]) for i in range(4)] for r, c in zip(rim, centres)]
    up = [geo.addLine(rim[0][i], rim[1][i]) for i in range(4)]
    surface = [geo.addSurfaceFilling([loop([arcs[0][i], up[(i + 1) % 4], -arcs[1][i], -up[i]])]) for i in range(4)]
else:
    centre = point(0, 0, 0)
    axis = {(d, s): point(*(s * radius if k == d else 0 for k in range(3))) for d in range(3) for s in (-1, 1)}
    arc = {}

    def curve(a, b):
        if (a, b) not in arc:
            arc[a, b] = geo.addCircleArc(axis[a], centre, axis[b])
            arc[b, a] = -arc[a, b]
        return arc[a, b]

    surface = []  # the eight octants, normals outward
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                cycle = [(0, sx), (1, sy), (2, sz)] if sx * sy * sz > 0 else [(0, sx), (2, sz), (1, sy)]
                surface.append(geo.addSurfaceFilling([loop([curve(cycle[i], cycle[(i + 1) % 3]) for i in range(3)])],
                                                     sphereCenterTag=centre))
for s in surface:
    # The geo kernel's own settings: a later synchronize would undo gmsh.model.mesh's.
    geo.mesh.setRecombine(2, s)
    if shape == "cylinder" and not quads:
        geo.mesh.setAlgorithm(2, s, 5)
if shape == "sphere" and quads:
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 3)  # Blossom full-quad
# The layer: 2 cells along the surface's normals (the surface given negatively: the other way).
sign = -1 if inward else 1
# Equal cells: one layer of `cells` elements; graded: one element per height, the heights
# cumulative (extrudeBoundaryLayer's numElements and heights).
if ratio == 1.0:
    elements, heights = [cells], [thickness]
else:
    grow = [ratio**i for i in range(cells)]
    elements = [1] * cells
    heights = [thickness * sum(grow[:i + 1]) / sum(grow) for i in range(cells)]
extruded = geo.extrudeBoundaryLayer([(2, sign * s) for s in surface], elements, heights, True)
geo.synchronize()
# Per surface: its top, its volume, then the sides (the extrusions of its curves; Gmsh 4.8
# lists the surface itself first when it is given negatively).
layer = [t for d, t in extruded if d == 3]
tops = [extruded[i - 1][1] for i, (d, _) in enumerate(extruded) if d == 3]
inner, outer = (tops, surface) if inward else (surface, tops)
if shape == "cylinder":
    # The layer's end faces (the extrusions of the surface's arcs) lie in z = 0 and z = 1; each
    # one's far arc is also on its patch's top.
    near = [[abs(a) for a in ring] for ring in arcs]
    ends, far = [[], []], [[], []]
    for i, (d, t) in enumerate(extruded):
        if d != 3:
            continue
        top = {abs(c) for _, c in gmsh.model.getBoundary([(2, extruded[i - 1][1])], oriented=False)}
        for _, s in extruded[i + 1:i + 6]:
            curves = {abs(c) for _, c in gmsh.model.getBoundary([(2, s)], oriented=False)}
            for z in (0, 1):
                if curves & set(near[z]) and s not in surface and s not in ends[z]:
                    ends[z].append(s)
                    far[z].append(next(iter(curves & top)))
    box_sides, rings = box(0, 1)
    discs, holes = (far, near) if inward else (near, far)
    core_ends = [geo.addPlaneSurface([loop(d)]) for d in discs]
    potting_ends = [geo.addPlaneSurface([loop(rings[z]), loop(holes[z])]) for z in (0, 1)]
    core = geo.addVolume([geo.addSurfaceLoop(core_ends + inner)])
    potting = geo.addVolume([geo.addSurfaceLoop(box_sides + potting_ends + outer)])
    skin = box_sides + potting_ends + core_ends + ends[0] + ends[1]
else:
    box_sides, rings = box(-1, 1)
    skin = box_sides + [geo.addPlaneSurface([loop(r)]) for r in rings]
    core = geo.addVolume([geo.addSurfaceLoop(inner)])
    potting = geo.addVolume([geo.addSurfaceLoop(skin), geo.addSurfaceLoop(outer)])
geo.synchronize()
for tag, (name, volumes) in enumerate((("core", [core]), ("layer", layer), ("potting", [potting])), 1):
    gmsh.model.addPhysicalGroup(3, volumes, tag)
    gmsh.model.setPhysicalName(3, tag, name)
gmsh.model.addPhysicalGroup(2, skin, 1)
gmsh.model.setPhysicalName(2, 1, "skin")
gmsh.model.addPhysicalGroup(2, surface, 2)
gmsh.model.setPhysicalName(2, 2, "surface")
gmsh.model.mesh.generate(3)
gmsh.write(out)
gmsh.finalize()
