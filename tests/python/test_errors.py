"""Errors: the command's messages and exit-code kinds, as Python exceptions."""
import json

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
