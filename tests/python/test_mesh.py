"""geode.check, quality, dual, smooth and isomorphism on arrays, against the CLI on files."""
import numpy as np
import pytest

import geode
from conftest import check_mapping, cli_json, grid


@pytest.fixture(scope="module")
def plain4tri(tmp_path_factory):
    """The four-triangle dual before fix-up and smoothing, and the same mesh as a .vtu file."""
    t = geode.template("geode4tri", fixup=False, smooth=False)
    path = tmp_path_factory.mktemp("mesh") / "plain.vtu"
    from conftest import run_cli
    # Its pinched corners cannot be untangled: the command refuses to write it (exit 4) unless
    # told to, and then still exits 4.
    assert not geode.check(t.points, t.hexes)["valid"]
    assert run_cli("template", "geode4tri", "--no-fixup", "--no-smooth", "-o", path, check=False).returncode == 4
    assert not path.exists()
    r = run_cli("template", "geode4tri", "--no-fixup", "--no-smooth", "--write-invalid", "-o", path, check=False)
    assert r.returncode == 4 and "invalid result" in r.stderr and path.exists()
    return t, path


def test_check_matches_cli(plain4tri):
    t, path = plain4tri
    mine = geode.check(t.points, t.hexes)
    cli = cli_json("check", path, "--format", "json")
    assert cli["index_base"] == 0
    assert mine["valid"] == cli["valid"] and mine["validity"] == cli["validity"]
    assert mine["obstructions"] == cli["obstructions"]
    assert [o["kind"] for o in mine["obstructions"]].count("pinched-corner") == 2
    assert mine["quality"]["metrics"] == pytest.approx(cli["quality"]["metrics"])


def test_check_finds_an_inverted_hex():
    pts, hexes = grid(2, 1, 1)
    assert geode.check(pts, hexes)["valid"]
    hexes[1] = hexes[1][[4, 5, 6, 7, 0, 1, 2, 3]]  # upside down
    r = geode.check(pts, hexes)
    assert not r["valid"] and r["report"]["inverted_hexes"] == [1]
    bad = hexes.copy()
    bad[0, 0] = 99
    r = geode.check(pts, bad)
    assert not r["valid"] and r["report"]["out_of_range_hexes"] == [0] and r["obstructions"] is None


def test_check_quads():
    t = geode.template("geode2d")
    r = geode.check(t.points, t.quads)
    assert r["dimension"] == 2 and r["valid"] and r["quality"]["scaled_jacobian"]["min"] > 0


def test_quality_per_hex(geode3d):
    q = geode.quality(geode3d.points, geode3d.hexes, per_hex=True)
    assert q["num_hexes"] == 26
    for m in q["metrics"]:
        values = q["per_hex"][m["key"]]
        assert values.min() == pytest.approx(m["min"]) and values.max() == pytest.approx(m["max"])
        assert values[m["min_hex"]] == pytest.approx(m["min"])
    assert "Scaled Jacobian" in q["table"]


def test_dual_matches_cli(plain4tri):
    t, path = plain4tri
    mine = geode.dual(t.points, t.hexes)
    cli = cli_json("dual", path, "--format", "json")
    assert mine["nodes"] == cli["nodes"] and mine["cells"] == cli["cells"]
    assert [{k: s[k] for k in cli["sheets"][0]} for s in mine["sheets"]] == cli["sheets"]
    assert mine["intersections"] == cli["intersections"]
    assert mine["cell_sheets"].shape == (len(t.hexes), 3)
    assert (mine["edge_sheet"][:] < len(mine["sheets"])).all()


def test_dual_rebuild_gives_the_mesh_back():
    pts, hexes = grid(3, 2, 2)
    inner = (pts[:, 0] == 1) & (pts[:, 1] == 1)
    pts[inner, 0] += 0.2 * (pts[inner, 2] - 1)  # moved interior nodes: kinked sheets, the box still filled
    d = geode.dual(pts, hexes, rebuild=True)
    assert len(d["sheets"]) == 3 + 2 + 2
    for s, sheet in enumerate(d["sheets"]):  # each a disk across the box: one closed trace loop of its own edges
        assert len(sheet["trace"]) == 1 and sheet["trace"][0]["closed"]
        assert all(d["edge_sheet"][e] == s for e in sheet["trace"][0]["edges"])
    loops = sorted(len(sheet["trace"][0]["edges"]) for sheet in d["sheets"])
    assert loops == [8, 8, 8, 10, 10, 10, 10]  # around 2 x 2 (x sheets), 3 x 2 (y and z sheets) cells
    r = d["rebuild"]
    m = geode.isomorphism(r["cells"], hexes)
    assert m is not None
    check_mapping(r["cells"], hexes, m)
    q = geode.dual(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [2, 0], [2, 1]], float), [[0, 1, 2, 3], [1, 4, 5, 2]], rebuild=True)
    assert q["dimension"] == 2 and len(q["sheets"]) == 3 and len(q["rebuild"]["cells"]) == 2


def test_smooth_keeps_the_boundary_and_untangles():
    pts, hexes = grid(2, 2, 2)
    centre = 13
    pts[centre] = [1.8, 1.7, 1.9]  # far off: some hexes inverted
    assert not geode.check(pts, hexes)["valid"]
    r = geode.smooth(pts, hexes)
    assert r["untangled"] and r["final_min_scaled_jacobian"] > 0.99
    moved = np.linalg.norm(r["points"] - pts, axis=1) > 0
    assert moved.tolist() == [i == centre for i in range(len(pts))]
    assert geode.check(r["points"], hexes)["valid"]
    pts2 = pts.copy()
    pts2[4] += [0, 0, 0.3]  # a node inside the bottom face, off its plane: "box" projects it back and slides it
    b = geode.smooth(pts2, hexes, boundary="box")
    assert b["points"][4][2] == pytest.approx(0) and b["final_min_scaled_jacobian"] > 0.99
    f = geode.smooth(pts, hexes, boundary="free", fixed=list(range(27)))
    assert np.array_equal(f["points"], pts)


def test_smooth_refuses_no_cells():
    pts, _ = grid(1, 1, 1)
    for points in (np.zeros((0, 3)), pts):
        for boundary in ("fixed", "free", "box"):
            with pytest.raises(geode.InputError, match="no hexes"):
                geode.smooth(points, np.zeros((0, 8), dtype=np.int32), boundary=boundary)
    with pytest.raises(geode.InputError, match="no quads"):
        geode.smooth(np.zeros((0, 2)), np.zeros((0, 4), dtype=np.int32))


def test_points_not_finite_are_refused_by_number():
    pts, hexes = grid(1, 1, 1)
    pts[5] = [np.nan, 0, 0]
    for f in (geode.quality, geode.check, geode.smooth):
        with pytest.raises(geode.InputError, match="point 5 .* is not finite"):
            f(pts, hexes)


def test_isomorphism_of_renumbered_grid():
    _, hexes = grid(2, 2, 1)
    rng = np.random.default_rng(1)
    perm = rng.permutation(hexes.max() + 1)
    renumbered = perm[hexes][rng.permutation(len(hexes))]
    m = geode.isomorphism(hexes, renumbered)
    check_mapping(hexes, renumbered, m)
    assert geode.isomorphism(hexes, grid(4, 1, 1)[1]) is None
