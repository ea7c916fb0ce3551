"""geode: all-hex meshing through the dual sheet arrangement (the Spatial Twist Continuum).

The library behind the `geode` command, for notebooks: templates derived from their sheet
arrangements, arrangements given as specs, the dual of any hex mesh, validity and
realizability checks, smoothing, the paper's Table 1 metrics, and whole models of hexes, tets,
pyramids and wedges conformed into one all-hex mesh. Arrays are numpy (points N x 3 float64, cells int32 in VTK
order, every id 0-based); meshes in and out of conform are meshio.Mesh objects.

    import geode
    t = geode.template("geode3d")          # 26 hexes, isomorphic to the paper's Appendix A
    t.points, t.hexes, t.sheets, t.conditions
    geode.check(t.points, t.hexes)["valid"]
    mesh, report = geode.conform(meshio.read("model.msh"))

Failures raise geode.Error subclasses with the command's message and its exit code:
InputError (2; also a ValueError), TopologyError (3), InvalidResultError (4).
Long calls release the GIL, so other Python threads run meanwhile.
"""
import html as _html
import os as _os
import warnings as _warnings

import numpy as _np

from ._geode import (  # noqa: F401  (the public C++ entry points)
    Error,
    InputError,
    InvalidResultError,
    Template,
    TopologyError,
    __version__,
    check,
    demo_model_names,
    dual,
    isomorphism,
    quality,
    smooth,
)
from . import _geode

__all__ = [
    "Error", "InputError", "TopologyError", "InvalidResultError", "GeodeWarning", "Template",
    "template", "template_names", "arrange", "dual", "check", "smooth", "quality", "isomorphism",
    "conform", "demo_model", "demo_model_names", "study_interleave",
]


class GeodeWarning(UserWarning):
    """What `geode` prints as a warning: failed interleave conditions, smoothing that could not untangle."""


def _warn(result):
    for w in result.warnings:
        _warnings.warn(w, GeodeWarning, stacklevel=3)
    return result


def template_names():
    """The built-in templates: {name: what it is}."""
    return dict(_geode._template_names())


def template(name, box=None, *, diagonal="main", higher="x", smooth=True, slide=False, fixup=True, **push):
    """Derive a built-in template from its completed, pushed-together sheet arrangement.

    name: geode3d, geode2d, geode4tri, refine3 or refine3-2d (template_names(); pyramid raises
    TopologyError with the certificate that its dual needs a self-intersecting sheet). box: the buffer
    cell (width, height, depth), tet side on top; default (24, 14, 24), (24, 14) in 2D.
    diagonal: 'main' or 'anti'; higher: 'x' or 'z' (which tunnel's roof is higher). push: the
    push parameters of `geode template` (high_roof, low_roof, dome_depth, dome_radius,
    centre_depth, centre_radius, dome_exponent, centre_exponent, dome_offset, centre_offset=(x, z);
    refine3: high_roof, low_roof, layer). smooth: place the free nodes by optimization (tet- and
    hex-side nodes fixed, or sliding with slide=True); fixup: geode4tri's obstructions pillowed
    away first. Returns a Template, as `geode template` derives it.
    """
    return _warn(_geode._template(name, box, diagonal, higher, smooth, slide, fixup, push))


def arrange(spec, smooth=False, slide=False):
    """Compute, diagnose and dualize the arrangement a spec gives (a dict, or a JSON file in the
    format of `geode arrange`); smooth=True places the nodes by optimization (box domains)."""
    if isinstance(spec, _os.PathLike):
        spec = _os.fspath(spec)
    try:
        return _warn(_geode.arrange(spec, smooth, slide))
    except TopologyError as e:
        # Input errors name the spec already (its file's name, or "spec"); topology refusals
        # from the arrangement do not: name it the same way, as `geode arrange` does.
        source = _os.path.basename(spec) if isinstance(spec, str) else "spec"
        if str(e).startswith(source + ": "):
            raise
        raise TopologyError(source + ": " + str(e)) from None


# ---- Template: meshio and the notebook viewer --------------------------------------------------

def _template_to_meshio(self):
    """The template as a meshio.Mesh (a copy), with each per-cell quality metric as cell data."""
    import meshio

    kind = "hexahedron" if self.dim == 3 else "quad"
    cell_data = {key: [_np.array(values)] for key, values in self.quality.items()}
    return meshio.Mesh(_np.array(self.points), [(kind, _np.array(self.cells))], cell_data=cell_data)


def _viewer_iframe(page, height=480):
    # The viewer is a whole page (its own scripts and styles): an iframe keeps it apart from the
    # notebook's, and srcdoc keeps it self-contained (nothing fetched).
    return ('<iframe style="width: 100%; height: {}px; border: 1px solid #ccc" srcdoc="{}"></iframe>'
            .format(int(height), _html.escape(page, quote=True)))


def _template_repr_html(self):
    return _viewer_iframe(self.html())


def _template_repr(self):
    n = len(self.cells)
    return "<geode.Template {}: {} {}, {} nodes, {} sheets>".format(
        self.name, n, "hexes" if self.dim == 3 else "quads", len(self.points), len(self.sheets))


Template.to_meshio = _template_to_meshio
Template._repr_html_ = _template_repr_html
Template.__repr__ = _template_repr


# ---- Whole models ------------------------------------------------------------------------------

# The linear volume cells geode takes, as meshio names them, and their arrays in the dicts of
# the C++ module (python/conform.cpp), in the library's kind order: meshio type, cells key,
# block key, ids key, corners. meshio's corner orders are the library's for all four (VTK's for
# hexahedron, tetra and pyramid; its linear wedge is Gmsh's prism, 0-1-2 counter-clockwise seen
# from 3-4-5, which its VTK reader and writer mirror as geode's do).
_KINDS = (("hexahedron", "hexes", "hex_block", "hex_ids", 8), ("tetra", "tets", "tet_block", "tet_ids", 4),
          ("pyramid", "pyramids", "pyramid_block", "pyramid_ids", 5),
          ("wedge", "wedges", "wedge_block", "wedge_ids", 6))
_VOLUME = {kind[0]: kind for kind in _KINDS}
# Boundary entities of a Gmsh file, not elements, by their dimension.
_SURFACE = {"vertex": 0, "line": 1, "triangle": 2, "quad": 2}


def _integers(values, what, name):
    """values (a number or an array) as integers, refused as the file readers refuse a bad tag: a
    value that is not a whole finite number was truncated (gmsh:physical 1.5 read as block 1) or
    raised Python's own ValueError."""
    try:
        a = _np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError("{}: {} holds a value that is not a number".format(name, what)) from None
    bad = ~_np.isfinite(a) | (a != _np.round(a))
    if bad.any():
        raise InputError("{}: {} holds {}, not an integer id".format(name, what, a[bad].ravel()[0]))
    return a.astype(_np.int64)


def _groups(field_data, name):
    """meshio's field_data {name: [tag, dimension]}, each checked."""
    return {k: _integers(v, "field_data '{}'".format(k), name).ravel() for k, v in (field_data or {}).items()}


def _model_arrays(mesh=None, points=None, cells=None, cell_blocks=None, name="mesh"):
    """A meshio.Mesh (or points + [(type, array)] cell blocks) as conform's arrays. Each element's
    id (messages name it) is its 1-based position among all the cells, surface cells counted:
    the element tag of a .msh file meshio or geode wrote."""
    if mesh is not None:
        points = mesh.points
        cells = [(c.type, c.data) for c in mesh.cells]
        physical = mesh.cell_data.get("gmsh:physical")
        groups = _groups(mesh.field_data, name)
        names = {int(v[0]): k for k, v in groups.items() if len(v) > 1 and int(v[1]) == 3}
        # Physical points, curves and surfaces by (dimension, tag), as Gmsh's physical names.
        set_names = {(int(v[1]), int(v[0])): k for k, v in groups.items() if len(v) > 1}
        point_sets = dict(mesh.point_sets or {})
    else:
        if points is None or cells is None:
            raise InputError("conform: give a meshio.Mesh, or points and cells")
        cells = list(cells.items()) if isinstance(cells, dict) else list(cells)
        physical, names, point_sets, set_names = None, {}, {}, {}
        if cell_blocks is not None and len(cell_blocks) != len(cells):
            raise InputError("{}: {} cell_blocks for {} cell blocks: give one block id per cell block"
                             .format(name, len(cell_blocks), len(cells)))
    points = _np.asarray(points, dtype=float)
    parts = {kind[1]: [] for kind in _KINDS}
    blocks = {kind[1]: [] for kind in _KINDS}
    ids = {kind[1]: [] for kind in _KINDS}
    volume_index = 0
    position = 0  # cells before this block
    tagged, untagged = {}, 0  # (dim, tag) -> cells and their ids; surface cells without a tag
    for i, (kind, data) in enumerate(cells):
        data = _np.asarray(data)
        first, position = position + 1, position + len(data)
        if kind in _SURFACE:
            # Gmsh's physical points, curves and surfaces (meshio gives their tags in
            # gmsh:physical): the sets `geode conform` makes of the same file.
            tags = (_integers(physical[i], "gmsh:physical of cell block {}".format(i), name)
                    if physical is not None and len(physical[i]) == len(data) else None)
            dim = _SURFACE[kind]
            for k in range(len(data)):
                tag = int(tags[k]) if tags is not None else 0
                if tag <= 0:
                    untagged += 1
                    continue
                group = tagged.setdefault((dim, tag), ([], []))
                group[0].append([int(x) for x in _np.asarray(data[k]).ravel()])
                group[1].append(first + k)
            continue
        if kind not in _VOLUME:
            raise InputError("{}: cell block {} holds '{}' cells; geode.conform takes linear hexahedron, tetra, "
                             "pyramid and wedge cells".format(name, i, kind))
        key = _VOLUME[kind][1]
        if cell_blocks is not None:
            block = _np.full(len(data), int(_integers(cell_blocks[i], "cell_blocks[{}]".format(i), name)))
        elif physical is not None and len(physical[i]) == len(data):
            block = _integers(physical[i], "gmsh:physical of cell block {}".format(i), name)
        else:
            block = _np.full(len(data), volume_index + 1)
        volume_index += 1
        parts[key].append(data)
        blocks[key].append(block)
        ids[key].append(_np.arange(first, position + 1, dtype=_np.int64))
    arrays = {}
    for _, key, block_key, ids_key, width in _KINDS:
        arrays[key] = _np.concatenate(parts[key]) if parts[key] else _np.zeros((0, width), dtype=_np.int64)
        arrays[block_key] = _np.concatenate(blocks[key]) if blocks[key] else _np.zeros(0, dtype=int)
        arrays[ids_key] = _np.concatenate(ids[key]) if ids[key] else _np.zeros(0, dtype=_np.int64)
    if untagged:
        _warnings.warn("{}: {} vertex, line, triangle or quad cells carry no gmsh:physical tag: they are not read"
                       .format(name, untagged), GeodeWarning, stacklevel=3)
    sets = [{"dim": dim, "id": tag, "name": set_names.get((dim, tag), ""), "cells": group[0], "ids": group[1]}
            for (dim, tag), group in sorted(tagged.items())]
    # Point sets numbered after the node sets of tagged cells, whose ids are their tags, and
    # after tag + 10^k, where the module moves a curve's set that has a point's tag
    # (primal::separate_node_set_ids).
    highest = max([t["id"] for t in sets if t["dim"] < 2], default=0)
    first_id = highest + 1
    if {t["id"] for t in sets if t["dim"] == 0} & {t["id"] for t in sets if t["dim"] == 1}:
        first_id += 10 ** len(str(highest))
    node_sets = [{"id": first_id + k, "name": n, "nodes": [int(x) for x in _np.asarray(v).ravel()]}
                 for k, (n, v) in enumerate(point_sets.items())]
    return points, arrays, names, node_sets, sets


def _model_to_meshio(model, cell_data_extra=None):
    """Conform's (or a demo's) arrays as a meshio.Mesh: one cell block per element block and
    cell kind (kinds in the order hexahedron, tetra, pyramid, wedge), each block a cell set named
    as the block, block ids as gmsh:physical, node sets as point sets."""
    import meshio

    cells, physical, cell_sets, field_data = [], [], {}, {}
    names = model["block_names"]
    groups = []
    for kind, key, block_key, _, _ in _KINDS:
        ids = _np.asarray(model[block_key])
        for b in sorted(set(ids.tolist())):
            groups.append((kind, b, _np.asarray(model[key])[ids == b]))
    for i, (kind, b, data) in enumerate(groups):
        cells.append((kind, data))
        physical.append(_np.full(len(data), b, dtype=int))
        set_name = names.get(b, "block {}".format(b))
        cell_sets.setdefault(set_name, [_np.zeros(0, dtype=int) for _ in groups])
        cell_sets[set_name][i] = _np.arange(len(data))
        field_data[set_name] = _np.array([b, 3])
    cell_data = {"gmsh:physical": physical, "gmsh:geometrical": [p.copy() for p in physical]}
    point_sets = {s["name"] or "node set {}".format(s["id"]): _np.asarray(s["nodes"]) for s in model["node_sets"]}
    return meshio.Mesh(model["points"], cells, cell_data=cell_data, cell_sets=cell_sets, field_data=field_data,
                       point_sets=point_sets)


def conform(mesh=None, *, points=None, cells=None, cell_blocks=None, name="mesh", smooth="local", quality="sj",
            geode_block="", buffer_side=None, buffer_thickness=0.0, smooth_target=0.0, template_box=None,
            merge_tolerance=None, relax="interface", unfold=False, allow_invalid=False):
    """Conform a model of hexes, tets, pyramids and wedges into one valid all-hex mesh, as
    `geode conform` does.

    mesh: a meshio.Mesh (hexahedron, tetra, pyramid and wedge cells in meshio's corner orders, a
    wedge's 0-1-2 counter-clockwise seen from 3-4-5 as Gmsh's prism; Gmsh's surface and point
    entities with a gmsh:physical tag become sets as `geode conform` makes them of the .msh file
    (physical points and curves node sets, surfaces side sets; untagged ones are skipped with a
    GeodeWarning); blocks from gmsh:physical, else one per cell block; block and set names from
    field_data; point sets become node sets too), or points and cells ([(type, array)] or {type: array}) with cell_blocks (one block id
    per cell block). The input gets the checks a file gets when read: a cell in another corner
    order (a wedge in VTK's mirrored order, a pyramid's base clockwise) is inverted and raises
    InputError naming it by its 1-based position among the cells (a .msh file's element tag).
    The options are those of `geode conform` (buffer_side=None: not given, hex or tet as
    `geode conform` chooses without --buffer-side; unfold=True as --unfold: tets and pyramids a
    mesher folded or wrote inverted mended, with a GeodeWarning where it changed the model, the
    report's "unfolded_cells" counting them and "unfolded_nodes" naming the nodes moved, 0-based,
    after merge_tolerance's merging if any).
    Returns (meshio.Mesh, report): the output with one cell block and one cell set per block,
    block ids as gmsh:physical, node sets as point sets; the report as `--report` writes it,
    with "side_sets" ([{id, name, sides: K x 2 (hex, local face)}]). Hexes (the sides', each
    metric's min_hex and max_hex, those an invalid result's reason names) are numbered from 0
    over the returned mesh's cells, block after block.
    A result that fails verification raises InvalidResultError, unless allow_invalid=True.
    """
    pts, arrays, names, node_sets, tagged = _model_arrays(mesh, points, cells, cell_blocks, name)
    out = _geode._conform(pts, arrays, names, node_sets, tagged, name, smooth, quality, geode_block, buffer_side or "",
                          float(buffer_thickness), float(smooth_target), template_box, merge_tolerance, relax,
                          bool(unfold))
    for w in out["read_warnings"]:  # what a file's reader says of the same cells
        _warnings.warn(w, GeodeWarning, stacklevel=2)
    if not out["valid"] and not allow_invalid:
        raise InvalidResultError(out["invalid_reason"] + " (nothing returned; allow_invalid=True returns it anyway)")
    model = out["model"]
    report = out["report"]
    # Side sets refer to hexes in conform's order; the meshio output groups them by block.
    order = _np.argsort(_np.asarray(model["hex_block"]), kind="stable")
    new_index = _np.empty_like(order)
    new_index[order] = _np.arange(len(order))
    report["side_sets"] = [{"id": s["id"], "name": s["name"],
                            "sides": _np.column_stack([new_index[s["sides"][:, 0]], s["sides"][:, 1]])
                            if len(s["sides"]) else s["sides"]} for s in model["side_sets"]]
    report["merged_nodes"] = out["merged_nodes"]
    report["unfolded_nodes"] = list(out["unfolded_nodes"])
    report["unfolded_cells"] = out["unfolded_cells"]
    if report["unfolded_cells"]:  # the model changed, as the command warns
        nodes = len(report["unfolded_nodes"])
        _warnings.warn("{}: unfold: {} cell{} a mesher folded or wrote inverted mended, {} node{} moved"
                       .format(name, report["unfolded_cells"], "" if report["unfolded_cells"] == 1 else "s",
                               nodes, "" if nodes == 1 else "s"), GeodeWarning, stacklevel=2)
    return _model_to_meshio(model), report


def demo_model(name="half", n=4):
    """A demo model meshed with the Gmsh API (demo_model_names(); `geode demo --model`), as a
    meshio.Mesh: its hexahedron, tetra, pyramid and wedge cells, one cell block per block and
    kind, as `geode demo --save-input` writes it."""
    return _model_to_meshio(_geode._demo_model(name, int(n)))


# ---- Studies -----------------------------------------------------------------------------------

def study_interleave(spec, sweep=None, *, classes=False, progress=None, as_frame=None):
    """Classify what every push of a sweep dualizes to, as `geode study interleave --spec` does.

    spec: a spec dict, a JSON file, or a built-in geode template's name (geode3d, geode4tri).
    sweep: {path: values}, each a list of numbers, {"from", "to", "count"} or "FROM:TO:COUNT"
    (e.g. {"push.high_roof": [0.75, 0.85]}); it adds to, or replaces axes of, the spec's own sweep
    block, the first axis slowest. Returns one record per push (high_roof, low_roof, dome_depth,
    dome_radius, outcome, hexes, class, conditions_ok, diagnosis, seconds, then each swept path),
    and with classes=True also one per class (the summary). Records are a pandas DataFrame when
    pandas is importable (as_frame=None) or as_frame=True, else lists of dicts.
    progress(what, done, total) is called as the sweep goes.
    """
    if isinstance(spec, _os.PathLike):
        spec = _os.fspath(spec)
    runs, summary = _geode._study_interleave(spec, sweep, progress)
    if as_frame is None:
        try:
            import pandas  # noqa: F401
            as_frame = True
        except ImportError:
            as_frame = False
    if as_frame:
        import pandas

        runs, summary = pandas.DataFrame(runs), pandas.DataFrame(summary)
    return (runs, summary) if classes else runs
