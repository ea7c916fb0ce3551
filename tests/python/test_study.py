"""geode.study_interleave against `geode study interleave --spec`."""
import csv
import io
import sys
import types

import pytest

import geode
from conftest import SPECS, run_cli


def cli_rows(*args):
    return list(csv.DictReader(io.StringIO(run_cli("study", "interleave", "--quiet", *args).stdout)))


def test_spec_sweep_block_matches_cli():
    runs, classes = geode.study_interleave(SPECS / "pillow2d.json", classes=True, as_frame=False)
    cli = cli_rows("--spec", SPECS / "pillow2d.json")
    assert len(runs) == len(cli) == 6
    for mine, theirs in zip(runs, cli):
        assert mine["outcome"] == theirs["outcome"] and str(mine["hexes"]) == theirs["hexes"]
        assert mine["class"] == theirs["class"]
        assert mine["sheets[2].circle.radius"] == pytest.approx(float(theirs["sheets[2].circle.radius"]))
    # README: 5 quads up to radius 0.4, not in general position at 0.5 (the circle touches the
    # long sides), 3 quads at 0.6.
    assert [r["hexes"] for r in runs] == [5, 5, 5, 5, 0, 3]
    assert "'c' meet on the domain boundary" in runs[4]["diagnosis"] and runs[4]["outcome"] == "error"
    assert sum(c["count"] for c in classes) == 6


def test_sweep_argument_replaces_and_adds_axes():
    seen = []
    runs = geode.study_interleave("geode3d", {"push.high_roof": [0.75, 0.85], "push.dome_radius": "0.6:0.6:1"},
                                  as_frame=False, progress=lambda what, done, total: seen.append((what, done, total)))
    cli = cli_rows("--spec", SPECS / "geode3d.json", "--sweep", "push.high_roof=0.75,0.85", "--sweep", "push.dome_radius=0.6:0.6:1")
    assert [(r["class"], r["hexes"]) for r in runs] == [(c["class"], int(c["hexes"])) for c in cli]
    assert runs[-1]["high_roof"] == 0.85 and runs[-1]["hexes"] == 26
    assert seen and seen[-1][1] == seen[-1][2]


def test_records_become_a_dataframe_when_pandas_is_there(monkeypatch):
    made = []
    fake = types.ModuleType("pandas")
    fake.DataFrame = lambda records: made.append(records) or ("frame", len(records))
    monkeypatch.setitem(sys.modules, "pandas", fake)
    assert geode.study_interleave(SPECS / "pillow2d.json") == ("frame", 6)
    assert made and made[0][0]["outcome"] == "valid"


def test_study_errors():
    with pytest.raises(geode.InputError, match="nothing to sweep"):
        geode.study_interleave(SPECS / "pillow.json")
    with pytest.raises(geode.InputError, match="push.nope"):
        geode.study_interleave("geode3d", {"push.nope": [1]})
    with pytest.raises(geode.InputError, match="no push to sweep"):
        geode.study_interleave("refine3", {"push.high_roof": [0.5]})
    # The command's bound on the sweep's size holds here too (a hunt's 200 x 200 sweep ran on,
    # past Ctrl-C, with the GIL released).
    with pytest.raises(geode.InputError, match=r"200 x 200 = 40000 sweep points; at most 20000"):
        geode.study_interleave("geode3d", {"push.high_roof": [0.61 + 0.0019 * k for k in range(200)],
                                           "push.dome_radius": [0.1 + 0.004 * k for k in range(200)]})
