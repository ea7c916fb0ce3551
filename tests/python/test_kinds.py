"""All four linear cell kinds (hexahedron, tetra, pyramid, wedge) through the module: the
Gmsh-built hybrid demo models as `geode demo --save-input` writes them, read with meshio and
conformed by geode.conform, against `geode conform` on the same file."""
import json
import re

import meshio
import numpy as np
import pytest

import geode
from conftest import cli_error, one_line, run_cli

# hexdominant holds all four kinds side by side; hybrid Gmsh's pyramids on a hex box's face;
# boundary-layer wedge layers on tets, no quad meeting a triangle; layer-side wedge quads that
# meet tets through Gmsh's pyramids.
MODELS = [("hexdominant", 4), ("hybrid", 4), ("boundary-layer", 4), ("layer-side", 4)]
VOLUME = ("hexahedron", "tetra", "pyramid", "wedge")


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """Each model saved by the command, in a process of its own (libgmsh 4.8 trips an Eigen
    assertion on a second hybrid generate(3) in one process), with the counts it printed."""
    folder = tmp_path_factory.mktemp("kinds")
    files = {}
    for name, n in MODELS:
        path = folder / (name + ".msh")
        out = run_cli("demo", "--model", name, "-n", n, "--save-input", path).stdout
        m = re.search(r"\((\d+) hexes, (\d+) tets, (\d+) pyramids, (\d+) wedges\)", out)
        files[name] = path, dict(zip(VOLUME, map(int, m.groups())))
    return files


def volume_counts(mesh):
    counts = dict.fromkeys(VOLUME, 0)
    for c in mesh.cells:
        if c.type in counts:
            counts[c.type] += len(c.data)
    return counts


def output_hexes(mesh):
    assert {c.type for c in mesh.cells} == {"hexahedron"}
    return np.concatenate([c.data for c in mesh.cells])


@pytest.mark.parametrize("name", [m for m, _ in MODELS])
def test_conform_matches_cli(saved, name, tmp_path):
    path, printed = saved[name]
    mesh = meshio.read(path)
    counts = volume_counts(mesh)
    assert counts == printed  # meshio reads every kind the command wrote
    assert counts["pyramid"] + counts["wedge"] > 0
    run_cli("conform", path, "-o", tmp_path / "out.vtu", "--report", tmp_path / "r.json", "--quiet")
    cli = json.loads((tmp_path / "r.json").read_text())
    out, report = geode.conform(mesh, name=path.name)
    assert report["valid"] and cli["valid"]
    assert report["input"] == cli["input"]
    assert report["input"]["pyramids"] == counts["pyramid"] and report["input"]["wedges"] == counts["wedge"]
    assert report["output"] == cli["output"]
    assert report["output_min_scaled_jacobian"] == cli["output_min_scaled_jacobian"] > 0
    # The output itself: valid, its least scaled Jacobian the report's, the command's hexes.
    hexes = output_hexes(out)
    assert len(hexes) == report["output"]["hexes"] == len(output_hexes(meshio.read(tmp_path / "out.vtu")))
    assert geode.check(out.points, hexes)["valid"]
    sj = geode.quality(out.points, hexes, per_hex=True)["per_hex"]["scaled_jacobian"]
    assert sj.min() == pytest.approx(report["output_min_scaled_jacobian"], abs=1e-12)
    # Blocks kept: every input block (its id and name) is an output block, with the command's
    # hexes in it, a cell set of that many hexes and its id as gmsh:physical.
    physical = mesh.cell_data["gmsh:physical"]
    ids = {int(b) for c, p in zip(mesh.cells, physical) if c.type in VOLUME for b in np.unique(p)}
    names = {int(v[0]): k for k, v in mesh.field_data.items() if int(v[1]) == 3}
    blocks = [(b["id"], b["name"], b["quality"]["num_hexes"]) for b in report["blocks"]]
    assert blocks == [(b["id"], b["name"], b["quality"]["num_hexes"]) for b in cli["blocks"]]
    assert {b[0] for b in blocks} == ids and {b[0]: b[1] for b in blocks} == names
    sizes = {k: sum(len(a) for a in arrays) for k, arrays in out.cell_sets.items()}
    assert sizes == {b[1]: b[2] for b in blocks}
    assert sorted({int(p[0]) for p in out.cell_data["gmsh:physical"]}) == sorted(ids)
    for c, p in zip(out.cells, out.cell_data["gmsh:physical"]):
        assert len(set(p.tolist())) == 1


def test_vtk_files_keep_the_wedges(saved, tmp_path):
    # meshio writes a wedge to VTK in VTK's mirrored order and geode's VTK reader mirrors it
    # back: the command on meshio's .vtu conforms what geode.conform does on the mesh.
    path, _ = saved["hexdominant"]
    mesh = meshio.read(path)
    vtu = tmp_path / "hexdominant.vtu"
    meshio.write(vtu, meshio.Mesh(mesh.points, [(c.type, c.data) for c in mesh.cells if c.type in VOLUME],
                                  cell_data={"gmsh:physical": [p for c, p in zip(mesh.cells, mesh.cell_data[
                                      "gmsh:physical"]) if c.type in VOLUME]}))
    run_cli("conform", vtu, "--report", tmp_path / "r.json", "--quiet")
    cli = json.loads((tmp_path / "r.json").read_text())
    _, report = geode.conform(mesh)
    assert cli["input"] == report["input"] and cli["input"]["wedges"] > 0
    assert cli["output"]["hexes"] == report["output"]["hexes"]
    assert cli["output_min_scaled_jacobian"] == report["output_min_scaled_jacobian"]
    assert [b["id"] for b in cli["blocks"]] == [b["id"] for b in report["blocks"]]


def with_cell(mesh, kind, order):
    """The mesh (its Gmsh entities too) with the middle cell of its first `kind` block given in
    `order`, and that cell's element tag as meshio writes it (its 1-based position)."""
    cells, before = [], 0
    tag = None
    for c in mesh.cells:
        data = c.data.copy()
        if c.type == kind and tag is None:
            k = len(data) // 2
            data[k] = data[k][order]
            tag = before + k + 1
        before += len(data)
        cells.append((c.type, data))
    cell_data = {key: mesh.cell_data[key] for key in ("gmsh:physical", "gmsh:geometrical")}
    return meshio.Mesh(mesh.points, cells, cell_data=cell_data, field_data=mesh.field_data), tag


@pytest.mark.parametrize("name, kind, order", [
    ("boundary-layer", "wedge", [0, 2, 1, 3, 5, 4]),  # VTK's wedge order
    ("boundary-layer", "wedge", [3, 4, 5, 0, 1, 2]),  # its triangles swapped
    ("hybrid", "pyramid", [0, 3, 2, 1, 4]),  # the base clockwise seen from the apex
])
def test_a_cell_in_a_mirrored_order_is_refused_as_the_command_refuses_it(saved, name, kind, order, tmp_path):
    # The readers refuse it (a mirrored cell is inverted): the module names the same element
    # with the same line, and the command writes nothing.
    mesh, tag = with_cell(meshio.read(saved[name][0]), kind, order)
    path = tmp_path / "mirrored.msh"
    meshio.write(path, mesh, file_format="gmsh22", binary=False)  # meshio's 4.1 wants one entity
    with pytest.raises(geode.InputError) as e:
        geode.conform(meshio.read(path), name=path.name)
    assert "{} {} ".format(kind, tag) in str(e.value) and "inverted" in str(e.value)
    cli = run_cli("conform", path.name, "-o", "out.vtu", check=False, cwd=tmp_path)
    assert cli.returncode == 2 and not (tmp_path / "out.vtu").exists()
    # (A tet's or pyramid's hint names the module's option where the command names its own.)
    assert ("unfold=True mends such cells" in str(e.value)) == (kind in ("tet", "pyramid"))
    assert one_line(str(e.value)).replace("unfold=True", "--unfold") == cli_error(cli)
    # The same element given as arrays is refused by the same id.
    with pytest.raises(geode.InputError, match="{} {} ".format(kind, tag)):
        geode.conform(points=mesh.points, cells=[(c.type, c.data) for c in mesh.cells])
    # A pyramid so written lies on the same side as each of its neighbours: unfold turns it back.
    if kind == "pyramid":
        with pytest.warns(geode.GeodeWarning, match="1 cell a mesher folded or wrote inverted mended"):
            _, report = geode.conform(meshio.read(path), name=path.name, unfold=True)
        assert report["valid"] and report["unfolded_cells"] == 1 and report["unfolded_nodes"] == []


def test_a_rotated_wedge_is_the_same_wedge(saved):
    # Another corner taken first (0-1-2 turned, 3-4-5 with it) names the same wedge: it conforms,
    # to as many hexes.
    mesh = meshio.read(saved["boundary-layer"][0])
    rotated, _ = with_cell(mesh, "wedge", [1, 2, 0, 4, 5, 3])
    _, report = geode.conform(mesh)
    _, turned = geode.conform(rotated)
    assert turned["valid"] and turned["output"]["hexes"] == report["output"]["hexes"]


def test_demo_model_hands_out_every_kind(saved):
    # The only hybrid model this process builds with Gmsh (see saved): the command's file, cell
    # for cell, block for block, and conformed the same.
    mesh = geode.demo_model("hexdominant", 4)
    path, printed = saved["hexdominant"]
    assert volume_counts(mesh) == printed and all(printed.values())
    read = meshio.read(path)
    assert np.array_equal(mesh.points, read.points)

    def by_block(m):
        groups = {}
        for c, p in zip(m.cells, m.cell_data["gmsh:physical"]):
            if c.type in VOLUME:
                for b in np.unique(p):
                    groups.setdefault((c.type, int(b)), []).append(c.data[p == b])
        return {k: np.concatenate(v) for k, v in groups.items()}

    mine, theirs = by_block(mesh), by_block(read)
    assert mine.keys() == theirs.keys()
    assert all(np.array_equal(mine[k], theirs[k]) for k in mine)
    names = {int(v[0]): k for k, v in read.field_data.items() if int(v[1]) == 3}
    assert {k: int(v[0]) for k, v in mesh.field_data.items()} == {v: k for k, v in names.items()}
    _, report = geode.conform(mesh)
    _, from_file = geode.conform(read)
    assert report["valid"] and report["output"] == from_file["output"]
