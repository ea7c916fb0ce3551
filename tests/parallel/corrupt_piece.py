#!/usr/bin/python3
"""Makes a Nemesis piece inconsistent with the others, in place (python3-netcdf4), for the
refusals of mpi_input_test.sh. usage: corrupt_piece.py PIECE OTHER_PIECE moved|element
moved: a node also in OTHER_PIECE (a border node) moved by 0.5 in x;
element: the piece's first element given OTHER_PIECE's first element's global id.
Prints the global id it changed."""
import sys

import netCDF4

piece, other, what = sys.argv[1], sys.argv[2], sys.argv[3]
o = netCDF4.Dataset(other)
with netCDF4.Dataset(piece, "r+") as d:
    if what == "moved":
        mine = list(d.variables["node_num_map"][:])
        theirs = set(int(g) for g in o.variables["node_num_map"][:])
        i = next(k for k, g in enumerate(mine) if int(g) in theirs)
        d.variables["coordx"][i] += 0.5
        print(int(mine[i]))
    else:
        g = int(o.variables["elem_num_map"][0])
        d.variables["elem_num_map"][0] = g
        print(g)
