#!/usr/bin/python3
"""Partition a mesh with Gmsh (gmsh.model.mesh.partition, METIS inside Gmsh) the way users do
before a parallel run, and write it as .msh 4.1: one file with $PartitionedEntities, or with
--split one file per partition (Mesh.PartitionSplitMeshFiles=1: OUT_1.msh, ...). With
--whole W.msh, the mesh as Gmsh writes it unpartitioned first (Gmsh prints 16 digits, so its
coordinates are the partitioned file's, not always IN's).
usage: partition_model.py IN.msh OUT.msh PARTS [--split] [--whole W.msh]"""
import sys

import gmsh

src, out, parts = sys.argv[1], sys.argv[2], int(sys.argv[3])
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(src)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
if "--whole" in sys.argv:
    gmsh.write(sys.argv[sys.argv.index("--whole") + 1])
# Gmsh 4.8's partitioner fails ("No mesh elements were found") on volumes without surface
# entities, as geode's writer saves a model without side sets: their topology made first.
if not gmsh.model.getEntities(2):
    gmsh.model.mesh.createTopology()
gmsh.model.mesh.partition(parts)
gmsh.option.setNumber("Mesh.PartitionSplitMeshFiles", 1 if "--split" in sys.argv[4:] else 0)
gmsh.write(out)
gmsh.finalize()
