"""Shared by the Python tests: where the sources, the build and the `geode` command are, and
a runner for the command (the round trips compare the module with it)."""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("GEODE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BUILD = pathlib.Path(os.environ.get("GEODE_BUILD_DIR", SOURCE / "build"))
CLI = os.environ.get("GEODE_CLI", str(BUILD / "geode"))
SPECS = SOURCE / "notebooks-data" / "specs"
APPENDIX = SOURCE / "notebooks-data" / "appendix-a"


def run_cli(*args, check=True, cwd=None):
    """Runs `geode ARGS` (in cwd, if given); returns the CompletedProcess (text)."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd)
    if check and r.returncode != 0:
        raise AssertionError("geode {} exited {}: {}".format(" ".join(map(str, args)), r.returncode, r.stderr))
    return r


def cli_error(result):
    """The message of a failed command, as its one stderr line prints it (after "geode: error: " etc.)."""
    line = result.stderr.strip().splitlines()[-1]
    for prefix in ("geode: error: ", "geode: topology error: ", "geode: invalid result: "):
        if line.startswith(prefix):
            return line[len(prefix):]
    raise AssertionError("not a geode error line: " + line)


def one_line(message):
    """A message with its line breaks as the command prints them (spaces)."""
    return message.replace("\n", " ").replace("\r", " ").rstrip(" ")


def cli_json(*args):
    return json.loads(run_cli(*args).stdout)


def appendix_a():
    """The paper's Appendix A (points, 0-based hexes), typed in under notebooks-data/appendix-a."""
    nodes = np.loadtxt(APPENDIX / "nodes.csv", delimiter=",", skiprows=1)
    hexes = np.loadtxt(APPENDIX / "hexes.csv", delimiter=",", skiprows=1, dtype=int)
    assert (nodes[:, 0] == np.arange(1, len(nodes) + 1)).all()
    return nodes[:, 1:], hexes[:, 1:] - 1


# The 12 edges of a hex in VTK order.
HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]


def check_mapping(a, b, mapping):
    """An isomorphism a -> b checked in Python against its definition: node and cell maps are
    bijections and every hex goes to its image hex as the same cube (its 12 edges to the image's)."""
    nodes, cells = np.asarray(mapping["node_map"]), np.asarray(mapping["cell_map"])
    assert sorted(cells.tolist()) == list(range(len(b)))
    assert len(set(nodes.tolist())) == len(nodes) == int(np.max(b)) + 1
    for h, image in enumerate(cells):
        mapped = nodes[a[h]]
        target = b[image]
        assert sorted(mapped.tolist()) == sorted(target.tolist())
        edges = {frozenset((target[i], target[j])) for i, j in HEX_EDGES}
        assert {frozenset((mapped[i], mapped[j])) for i, j in HEX_EDGES} == edges


def grid(nx, ny, nz):
    """nx x ny x nz unit cubes: node (i, j, k) = i + (nx+1) (j + (ny+1) k), hexes in VTK order."""
    pts = np.array([(i, j, k) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)], dtype=float)
    n = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)  # noqa: E731
    hexes = [[n(i, j, k), n(i + 1, j, k), n(i + 1, j + 1, k), n(i, j + 1, k),
              n(i, j, k + 1), n(i + 1, j, k + 1), n(i + 1, j + 1, k + 1), n(i, j + 1, k + 1)]
             for k in range(nz) for j in range(ny) for i in range(nx)]
    return pts, np.array(hexes)


@pytest.fixture(scope="session")
def geode3d():
    import geode
    return geode.template("geode3d")
