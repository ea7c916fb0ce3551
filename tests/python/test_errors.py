"""Errors: the command's messages and exit-code kinds, as Python exceptions."""
import json
import re

import numpy as np
import pytest

import geode
from conftest import SPECS, cli_error, one_line, run_cli


def test_topology_error_matches_cli(tmp_path):
    spec = json.loads((SPECS / "pillow2d.json").read_text())
    del spec["sweep"]
    spec["sheets"][2]["circle"]["radius"] = 0.5  # the circle touches the long sides
    path = tmp_path / "tangent.json"
    path.write_text(json.dumps(spec))
    with pytest.raises(geode.TopologyError) as e:
        geode.arrange(path)
    assert e.value.exit_code == 3 and e.value.kind == "topology"
    assert str(e.value).startswith("tangent.json: ")
    cli = run_cli("arrange", path.name, check=False, cwd=tmp_path)
    assert cli.returncode == 3
    # The module names the file as given (its name); the command does the same.
    assert one_line(str(e.value)) == cli_error(cli)
    with pytest.raises(geode.TopologyError, match=r"^spec: arrangement: sheets 'a', 'c' meet"):
        geode.arrange(spec)


def test_input_errors_name_the_place(tmp_path):
    spec = json.loads((SPECS / "pillow.json").read_text())
    spec["sheets"][3]["sphere"]["radius"] = -1
    with pytest.raises(geode.InputError, match=r"spec: sheets\[3\].sphere.radius: must be > 0"):
        geode.arrange(spec)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(spec))
    cli = run_cli("arrange", path, check=False)
    with pytest.raises(geode.InputError) as e:
        geode.arrange(path)
    assert cli.returncode == e.value.exit_code == 2 and one_line(str(e.value)) == cli_error(cli)
    with pytest.raises(geode.InputError, match="unknown template 'geode5d'"):
        geode.template("geode5d")
    with pytest.raises(geode.InputError, match="unknown push parameter 'roof'"):
        geode.template("geode3d", roof=0.5)
    with pytest.raises(geode.InputError, match="0 < low < high < 1"):
        geode.template("geode3d", low_roof=0.9, smooth=False)
    with pytest.raises(geode.InputError, match="box"):
        geode.template("geode3d", box=(24, 14))
    with pytest.raises(geode.InputError, match="N x 3"):
        geode.check([[0, 0, 0, 0]], [[0] * 8])
    with pytest.raises(geode.InputError, match="integers"):
        geode.check([[0, 0, 0]], [[0.5] * 8])
    with pytest.raises(ValueError):  # InputError is a ValueError too
        geode.quality([[0, 0, 0]], [[0, 1, 2, 3, 4, 5, 6, 7]])


def test_arguments_the_command_refuses_the_module_refuses(tmp_path):
    # The module took planar_angle outside [0, 90] and boxes outside the command's range (a
    # TopologyError from the engine), and let pybind11's cast errors through for bad labels.
    t = geode.template("geode3d")
    template = tmp_path / "g.vtu"
    run_cli("template", "geode3d", "-o", template)
    for angle in (float("nan"), -1.0, 1000.0):
        with pytest.raises(geode.InputError, match=r"planar_angle must lie in \[0, 90\]"):
            geode.check(t.points, t.hexes, planar_angle=angle)
        assert run_cli("check", template, "--planar-angle", str(angle), check=False).returncode == 2
    for box, text in (((1e-7, 1, 1), "1e-7x1x1"), ((1, 1, 10001), "1x1x10001")):
        cli = run_cli("template", "geode3d", "--box", text, check=False)
        assert cli.returncode == 2
        with pytest.raises(geode.InputError) as e:
            geode.template("geode3d", box=box)
        # The same reason as the command's, after its own prefix.
        assert cli_error(cli).split("': ", 1)[1] == str(e.value).split("box: ", 1)[1]
    for labels in ((np.zeros(48), np.zeros(48)), [1, 1, 1]):
        with pytest.raises(geode.InputError, match="labels must be two sequences of integers"):
            geode.isomorphism(t.hexes, t.hexes, labels=labels)


def test_a_node_number_past_32_bits_names_the_cell_as_the_other_checks_do():
    t = geode.template("geode3d")
    tets = np.array([[0, 1, 2, 4], [0, 1, 2, 3]], dtype=np.uint64)
    tets[1, 2] = 2**63
    with pytest.raises(geode.InputError, match=r"^mesh: tet 28: corner 3 refers to node index "
                                               r"9223372036854775808, outside the 32-bit index range$"):
        geode.conform(points=t.points, cells=[("hexahedron", t.hexes.astype(np.int64)), ("tetra", tets)])


@pytest.mark.parametrize("mesh_args, said", [
    ({"cell_blocks": [float("nan")]}, "cell_blocks[0] holds nan, not an integer id"),
    ({"cell_blocks": [1.5]}, "cell_blocks[0] holds 1.5, not an integer id"),
    ({"cell_blocks": ["steel"]}, "cell_blocks[0] holds a value that is not a number"),
    ({"cell_data": {"gmsh:physical": [np.array([1.5])]}}, "gmsh:physical of cell block 0 holds 1.5"),
    ({"field_data": {"steel": "str"}}, "field_data 'steel' holds a value that is not a number"),
])
def test_block_ids_that_are_not_integers_are_input_errors(mesh_args, said):
    # A hunt's: gmsh:physical 1.5 became block 1 without a word, and a NaN block id or a text in
    # field_data raised Python's bare ValueError.
    import meshio
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    cells = [("tetra", np.array([[0, 1, 2, 3]]))]
    with pytest.raises(geode.InputError, match=r"^mesh: " + re.escape(said)):
        if "cell_blocks" in mesh_args:
            geode.conform(points=points, cells=cells, cell_blocks=mesh_args["cell_blocks"])
        else:
            geode.conform(meshio.Mesh(points, cells, **mesh_args))
