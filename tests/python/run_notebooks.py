#!/usr/bin/python3
"""Runs every notebook in a folder top to bottom (nbclient, a python3 kernel) and fails on the
first cell that raises. The notebooks are not rewritten: their outputs stay out of git.

Run: run_notebooks.py notebooks-data [NAME.ipynb ...]   (PYTHONPATH must reach the geode module;
GEODE_NOTEBOOK_OUTPUT=DIR writes the executed notebooks, outputs included, to DIR)
"""
import os
import pathlib
import sys
import time

import nbclient
import nbformat


def main(argv):
    os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # ipykernel's debugger notes on stderr
    keep = os.environ.get("GEODE_NOTEBOOK_OUTPUT")  # a folder: write the executed notebooks there
    folder = pathlib.Path(argv[1])
    names = argv[2:]
    notebooks = [folder / n for n in names] if names else sorted(folder.glob("*.ipynb"))
    if not notebooks:
        print("no notebooks in {}".format(folder), file=sys.stderr)
        return 1
    for path in notebooks:
        start = time.perf_counter()
        nb = nbformat.read(path, as_version=4)
        client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                         resources={"metadata": {"path": str(folder)}})
        try:
            client.execute()
        except nbclient.exceptions.CellExecutionError as e:
            print("{}: {}".format(path.name, e), file=sys.stderr)
            return 1
        if keep:
            nbformat.write(nb, pathlib.Path(keep) / path.name)
        print("{}: {} cells, {:.1f} s".format(path.name, len(nb.cells), time.perf_counter() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
