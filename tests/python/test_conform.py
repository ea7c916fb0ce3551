"""geode.conform on meshio meshes and arrays, against `geode demo` / `geode conform`."""
import json
import pathlib
import subprocess
import sys

import meshio
import numpy as np
import pytest

import geode
from conftest import SOURCE, cli_error, one_line, run_cli


@pytest.fixture(scope="module")
def half():
    return geode.demo_model("half", 2)


def hexes_of(mesh):
    return np.concatenate([c.data for c in mesh.cells if c.type == "hexahedron"])


def test_demo_model(half):
    kinds = {c.type for c in half.cells}
    assert kinds == {"hexahedron", "tetra"}
    assert set(half.cell_sets) == {"hex", "tet"}
    assert "half" in geode.demo_model_names()


def test_conform_matches_cli(half, tmp_path):
    out, report = geode.conform(half)
    run_cli("demo", "--model", "half", "-n", "2", "--report", tmp_path / "r.json", "--quiet")
    cli = json.loads((tmp_path / "r.json").read_text())
    assert report["valid"] and cli["valid"]
    assert report["output"] == cli["output"] and report["input"] == cli["input"]
    assert [b["name"] for b in report["blocks"]] == [b["name"] for b in cli["blocks"]]
    for mine, theirs in zip(report["blocks"], cli["blocks"]):
        assert mine["quality"]["metrics"][0]["min"] == pytest.approx(theirs["quality"]["metrics"][0]["min"], abs=1e-9)
    hexes = hexes_of(out)
    assert len(hexes) == report["output"]["hexes"] and {c.type for c in out.cells} == {"hexahedron"}
    assert geode.check(out.points, hexes)["valid"]
    # Blocks are cell sets, named as the input's, and gmsh:physical ids.
    assert set(out.cell_sets) == {"hex", "tet"}
    sizes = {name: sum(len(a) for a in arrays) for name, arrays in out.cell_sets.items()}
    assert sizes == {b["name"]: b["quality"]["num_hexes"] for b in report["blocks"]}
    assert [int(p[0]) for p in out.cell_data["gmsh:physical"]] == [b["id"] for b in report["blocks"]]


def test_conform_a_file_meshio_read(tmp_path):
    path = tmp_path / "in.msh"
    run_cli("demo", "--model", "delaunay", "-n", "2", "--save-input", path, "--quiet")
    run_cli("conform", path, "--report", tmp_path / "r.json", "--quiet", "--geode-block", "geode")
    cli = json.loads((tmp_path / "r.json").read_text())
    out, report = geode.conform(meshio.read(path), geode_block="geode")
    assert report["output"] == cli["output"]
    assert [b["name"] for b in report["blocks"]] == [b["name"] for b in cli["blocks"]]
    assert "geode" in out.cell_sets


def test_conform_arrays_and_sets(half):
    hexes = np.concatenate([c.data for c in half.cells if c.type == "hexahedron"])
    tets = np.concatenate([c.data for c in half.cells if c.type == "tetra"])
    ends = np.flatnonzero(np.isclose(half.points[:, 0], 0))
    out, report = geode.conform(points=half.points, cells=[("hexahedron", hexes), ("tetra", tets)], cell_blocks=[5, 7],
                                quality="full")
    assert [b["id"] for b in report["blocks"]] == [5, 7]
    assert len(report["blocks"][0]["quality"]["metrics"]) == 12
    # A node set on the face x = 0: the output's set is every output node there (the diced edge
    # and face nodes of the face included; the output numbers nodes its own way).
    with_set = meshio.Mesh(half.points, half.cells, cell_data=half.cell_data, field_data=half.field_data,
                           point_sets={"x0": ends})
    out, report = geode.conform(with_set)
    assert set(out.point_sets) == {"x0"}
    assert sorted(out.point_sets["x0"]) == np.flatnonzero(np.isclose(out.points[:, 0], 0)).tolist()
    assert len(out.point_sets["x0"]) > len(ends)


def test_conform_report_names_hexes_in_the_returned_mesh(half):
    # The hex part in block 9, the tets in 7: conform's own order has the hex part's hexes first,
    # the returned mesh block 7's; min_hex and max_hex index the latter.
    hexes = np.concatenate([c.data for c in half.cells if c.type == "hexahedron"])
    tets = np.concatenate([c.data for c in half.cells if c.type == "tetra"])
    out, report = geode.conform(points=half.points, cells=[("hexahedron", hexes), ("tetra", tets)],
                                cell_blocks=[9, 7])
    all_hexes = hexes_of(out)
    sj = geode.quality(out.points, all_hexes, per_hex=True)["per_hex"]["scaled_jacobian"]
    physical = np.concatenate(out.cell_data["gmsh:physical"])
    assert [b["id"] for b in report["blocks"]] == [7, 9]
    assert report["numbering"] == {"index_base": 0, "element_order": "by block"}
    for b in report["blocks"]:
        m = b["quality"]["metrics"][0]
        for at, key in (("min_hex", "min"), ("max_hex", "max")):
            assert physical[m[at]] == b["id"]
            assert sj[m[at]] == pytest.approx(m[key], abs=1e-12)


def test_block_ids_beyond_32_bits_are_refused_by_element(half):
    # The files hold 32-bit block ids: a larger one is an input error naming the first element
    # of the block (its 1-based position), not a failed conversion; so is a block name's id.
    hexes = np.concatenate([c.data for c in half.cells if c.type == "hexahedron"])
    tets = np.concatenate([c.data for c in half.cells if c.type == "tetra"])
    cells = [("hexahedron", hexes), ("tetra", tets)]
    with pytest.raises(geode.InputError, match=r"^mesh: tet {}: block id 2147483648 is out of range"
                       .format(len(hexes) + 1)):
        geode.conform(points=half.points, cells=cells, cell_blocks=[5, 2**31])
    with pytest.raises(geode.InputError, match=r"^mesh: hex 1: block id -2147483649 is out of range"):
        geode.conform(points=half.points, cells=cells, cell_blocks=[-2**31 - 1, 7])
    with pytest.raises(geode.InputError, match=r"^mesh: hex 1: block id 0 is not positive"):
        geode.conform(points=half.points, cells=cells, cell_blocks=[0, 7])
    named = meshio.Mesh(half.points, half.cells, cell_data=half.cell_data,
                        field_data={"big": np.array([2**32, 3])})
    with pytest.raises(geode.InputError, match=r"^mesh: block name 'big': block id 4294967296 is out of range"):
        geode.conform(named)


def test_conform_errors_match_cli(half, tmp_path):
    # A tet-only model (conform takes it) with its first tet inverted, in a Gmsh file: element and
    # node ids are then the module's 1-based numbers, and the two messages must be the same line.
    tets = np.concatenate([c.data for c in half.cells if c.type == "tetra"]).copy()
    tets[0] = tets[0][[1, 0, 2, 3]]
    path = tmp_path / "tets.msh"
    meshio.write(path, meshio.Mesh(half.points, [("tetra", tets)]), file_format="gmsh", binary=False)
    with pytest.raises(geode.InputError) as e:
        geode.conform(meshio.read(path), name=path.name)
    assert e.value.exit_code == 2 and e.value.kind == "input" and isinstance(e.value, ValueError)
    assert "tet 1 " in str(e.value) and "inverted" in str(e.value)
    cli = run_cli("conform", path.name, "-o", "out.vtu", check=False, cwd=tmp_path)
    assert cli.returncode == 2 and not (tmp_path / "out.vtu").exists()
    # (The hint names the module's option where the command names its own.)
    assert "unfold=True mends such cells" in str(e.value)
    assert one_line(str(e.value)).replace("unfold=True", "--unfold") == cli_error(cli)
    # That tet lies on the same side as each of its neighbours: unfold turns it back, no node moved.
    with pytest.warns(geode.GeodeWarning, match="1 cell a mesher folded or wrote inverted mended, 0 nodes"):
        out, report = geode.conform(meshio.read(path), name=path.name, unfold=True)
    assert report["valid"] and report["unfolded_cells"] == 1 and report["unfolded_nodes"] == []
    cli = run_cli("conform", path.name, "-o", "out.vtu", "--unfold", check=False, cwd=tmp_path)
    assert cli.returncode == 0 and "--unfold: 1 tet folded over its neighbours turned back\n" in cli.stderr


def test_conform_buffer_side(half):
    # Not given: as `geode conform` without --buffer-side (the hex part here); given: as asked.
    _, report = geode.conform(half, smooth="none")
    assert report["buffer_side"] == "hex"
    _, report = geode.conform(half, smooth="none", buffer_side="tet")
    assert report["buffer_side"] == "tet"
    with pytest.raises(geode.InputError) as e:
        geode.conform(half, buffer_side="both")
    assert "buffer side 'both'" in str(e.value)


def test_conform_refuses_bad_cells(half):
    quadratic = meshio.Mesh(half.points, [("tetra10", np.array([list(range(10))]))])
    with pytest.raises(geode.InputError, match="cell block 0 holds 'tetra10' cells"):
        geode.conform(quadratic)
    tets = np.concatenate([c.data for c in half.cells if c.type == "tetra"]).copy()
    tets[0] = tets[0][[1, 0, 2, 3]]  # inverted
    hexes = hexes_of(half)
    # Elements are named by their 1-based position among all the cells given: the first tet
    # comes after the hexes.
    with pytest.raises(geode.InputError, match="tet {} .*volume".format(len(hexes) + 1)):
        geode.conform(points=half.points, cells=[("hexahedron", hexes), ("tetra", tets)])
    with pytest.raises(geode.InputError, match="smooth"):
        geode.conform(half, smooth="everywhere")


def test_conform_refuses_a_cell_blocks_list_of_another_length(half):
    cells = [(c.type, c.data) for c in half.cells]
    with pytest.raises(geode.InputError, match="1 cell_blocks for {} cell blocks".format(len(cells))):
        geode.conform(points=half.points, cells=cells, cell_blocks=[1])


def test_merge_tolerance_as_long_as_an_edge_is_refused_as_the_command_does(half, tmp_path):
    path = tmp_path / "half.msh"
    meshio.write(path, half, file_format="gmsh22", binary=False)
    with pytest.raises(geode.InputError) as e:
        geode.conform(meshio.read(path), name=path.name, merge_tolerance=10.0)
    assert "merge_tolerance=10 is not below the shortest element edge" in str(e.value)
    cli = run_cli("conform", path.name, "-o", "out.exo", "--merge-tolerance", "10", check=False, cwd=tmp_path)
    assert cli.returncode == 2 and not (tmp_path / "out.exo").exists()
    assert cli_error(cli) == one_line(str(e.value)).replace("merge_tolerance=", "--merge-tolerance ")


def test_invalid_result_error_kind():
    assert geode.InvalidResultError.exit_code == 4 and issubclass(geode.InvalidResultError, geode.Error)
    assert geode.TopologyError.exit_code == 3 and geode.TopologyError.kind == "topology"


def test_conform_refuses_a_non_manifold_model():
    # Two hexes meeting along an edge only: the read-time check a file gets (local verification,
    # the default, takes it as given) refuses the arrays too, naming the edge's nodes (1-based).
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    points = np.concatenate([cube, cube - [1, 1, 0]])
    hexes = np.array([list(range(8)), list(range(8, 16))])
    points = np.concatenate([points[:8], points[[8, 9, 11, 12, 13, 15]]])
    hexes[1] = [8, 9, 0, 10, 11, 12, 4, 13]  # its corners (0, 0, 0) and (0, 0, 1) are the cube's
    with pytest.raises(geode.TopologyError, match="not a manifold along the edge of nodes 1 5"):
        geode.conform(points=points, cells=[("hexahedron", hexes)])


def test_conform_relax_option_matches_cli(tmp_path):
    # relax= as --relax: the default moves the Delaunay tets beside the hex part, "none" keeps
    # every node; the yardstick (the input's own cells) is the same either way.
    mesh = geode.demo_model("delaunay", 4)
    _, relaxed = geode.conform(mesh)
    _, kept = geode.conform(mesh, relax="none")
    assert relaxed["tet_relaxation"]["nodes_moved"] > 0
    assert kept["tet_relaxation"]["nodes_moved"] == 0
    assert relaxed["input_diced_alone_min_scaled_jacobian"] == kept["input_diced_alone_min_scaled_jacobian"]
    run_cli("demo", "--model", "delaunay", "-n", "4", "--relax", "none", "--report", tmp_path / "r.json",
            "--quiet")
    cli = json.loads((tmp_path / "r.json").read_text())
    assert kept["output_min_scaled_jacobian"] == pytest.approx(cli["output_min_scaled_jacobian"], abs=1e-9)
    with pytest.raises(geode.InputError, match="tet relaxation"):
        geode.conform(mesh, relax="all")


def test_gmsh_physical_points_curves_and_surfaces_are_the_commands_sets(tmp_path):
    # meshio gives a Gmsh file's physical points, curves and surfaces as vertex, line, triangle
    # and quad cells tagged in gmsh:physical; the module dropped them without a word, where
    # `geode conform` of the same file keeps them as node and side sets.
    path = tmp_path / "sets.msh"
    subprocess.run([sys.executable, str(SOURCE / "tests" / "conform" / "sets_models.py"), "embedded", str(path)],
                   check=True)
    run_cli("conform", path, "-o", tmp_path / "cli.vtu", "--quiet")
    cli = meshio.read(tmp_path / "cli.vtu")
    cli_nodes = {k.split(":", 2)[2]: len(v) for k, v in cli.field_data.items() if k.startswith("node_set:")}
    cli_sides = {k.split(":", 2)[2]: len(np.asarray(v).reshape(-1, 2)) for k, v in cli.field_data.items()
                 if k.startswith("side_set:")}
    assert set(cli_nodes) == {"load_point", "probe_line"} and set(cli_sides) == {"sheet", "patch"}
    out, report = geode.conform(meshio.read(path))
    assert {name: len(nodes) for name, nodes in out.point_sets.items()} == cli_nodes
    assert {s["name"]: len(s["sides"]) for s in report["side_sets"]} == cli_sides


def test_a_physical_curve_with_a_physical_points_tag_is_a_node_set_of_its_own(tmp_path):
    # Gmsh's tags are per dimension: both groups were node set 5 and the mesh was refused ("node
    # set id 5 is used twice"), as the command refused the file.
    path = tmp_path / "sets.msh"
    subprocess.run([sys.executable, str(SOURCE / "tests" / "conform" / "sets_models.py"), "embedded", str(path)],
                   check=True)
    mesh = meshio.read(path)
    for block, tags in zip(mesh.cells, mesh.cell_data["gmsh:physical"]):
        if block.type == "line":
            tags[:] = 5  # the curve "probe_line" (6) given the tag of the point "load_point" (5)
    mesh.field_data["probe_line"][0] = 5
    # Point sets are numbered after the node sets: past the curve's moved id too.
    mesh.point_sets = {"p{}".format(k): np.array([k]) for k in range(12)}
    with pytest.warns(geode.GeodeWarning, match="line cells tagged 5 'probe_line' and vertex cells tagged 5 "
                                                "'load_point' would both be node set 5: the lines are node set 15"):
        out, report = geode.conform(mesh)
    assert report["valid"]
    assert set(out.point_sets) == {"load_point", "probe_line"} | set(mesh.point_sets)
    assert len(out.point_sets["load_point"]) == 1 and len(out.point_sets["probe_line"]) > 2


def test_unfold_turns_back_the_tets_gmsh_folds_as_the_command_does(tmp_path):
    # Made by the script a user would run, in a process of its own (libgmsh is not finalized in
    # this one: the demo models use it).
    path = tmp_path / "ring.msh"
    script = pathlib.Path(__file__).resolve().parent.parent / "conform" / "ring_model.py"
    subprocess.run([sys.executable, str(script), str(path), "3"], check=True)
    mesh = meshio.read(path)
    with pytest.raises(geode.InputError) as e:
        geode.conform(mesh, name=path.name)
    assert "the mesh folds over itself there" in str(e.value) and "unfold=True" in str(e.value)
    with pytest.warns(geode.GeodeWarning, match="unfold: "):
        out, report = geode.conform(mesh, name=path.name, unfold=True)
    assert report["valid"] and report["unfolded_nodes"]
    assert geode.check(out.points, hexes_of(out))["valid"]
    cli = run_cli("conform", path.name, "-o", "out.exo", "--unfold", "--report", "r.json", cwd=tmp_path)
    assert "--unfold: " in cli.stderr
    assert json.loads((tmp_path / "r.json").read_text())["output"] == report["output"]
