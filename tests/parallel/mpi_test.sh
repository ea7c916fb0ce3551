#!/usr/bin/env bash
# geode_mpi on 1, 2, 3 and 4 ranks (oversubscribed) against the serial `geode conform` of the
# same demo model (made by Gmsh the way users make them): the joined output identical after the
# canonical ordering, blocks and sets included, and the same warnings; the per-rank Nemesis files
# read back by libexodusII with matching communication maps.
# On 2 and 3 ranks with --rings 1: the thinnest transition zone, grown by geode_mpi's own check
# until the smoothing and the buffer layer stop short of its cut (the check is what is tested),
# the rest diced on every rank; on 1 and 4 ranks with the default depth, as users run it (on the
# smaller models the zone is then the whole model). Each growth conforms the zone again (three
# times on the layer models), the same work on any rank count: it runs on two counts, not four,
# to keep the suite within CI's time.
# usage: mpi_test.sh GEODE GEODE_MPI PARALLEL_CHECK MPIEXEC MODEL SIZE WORKDIR
set -euo pipefail
geode=$1 geode_mpi=$2 check=$3 mpiexec=$4 model=$5 size=$6 dir=$7
flags=  # options of both the serial and the MPI runs
# OpenMPI refuses root unless told (containers and CI run tests as root).
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir"
# MODEL "sets": sets_model.py's Gmsh model with blocks, side sets and node sets, and a physical
# volume over both blocks, which the reader warns of (every rank reads the file: that warning
# was printed once per rank, and again by a rank reading it again for a grown zone); else a demo.
if [ "$model" = sets ]; then
  input=in.msh
  /usr/bin/python3 "$here/sets_model.py" "$input" "$size" aggregate
elif [ "$model" = ball ]; then  # the serial run's aims set by a tet outside the default zone
  input=in.msh
  /usr/bin/python3 "$here/../conform/ball_model.py" "$input" "$size"
elif [ "$model" = layer ]; then  # a thin hex layer with wedges through it, split into tets
  input=in.msh
  /usr/bin/python3 "$here/../conform/layer_model.py" "$input" sphere "$size"
elif [ "$model" = apart ]; then  # two bodies that share no face: each diced alone, warned
  input=in.msh
  /usr/bin/python3 "$here/../conform/apart_model.py" "$input" "$size"
elif [ "$model" = layer-quads ]; then  # a nearly thin quads-only layer: both sides tried
  input=in.msh
  /usr/bin/python3 "$here/../conform/layer_model.py" "$input" cylinder "$size" out 0.15 quads
elif [ "$model" = layer-folded ]; then  # the same at a size where Gmsh folds a pyramid: --unfold
  input=in.msh
  /usr/bin/python3 "$here/../conform/layer_model.py" "$input" cylinder "$size" out 0.15 quads
  flags=--unfold
  # Refused without it, the option named (every rank reads the file: one line).
  status=0
  timeout 300 "$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform "$input" -o refused.exo -q \
    2>refused.txt || status=$?
  [ "$status" = 2 ] && [ "$(grep -c 'lie on the same side' refused.txt)" = 1 ] &&
    grep -q -- '--unfold turns such cells back' refused.txt ||
    { echo "layer-folded: exit $status without --unfold"; cat refused.txt; exit 1; }
else
  input=in.exo
  "$geode" demo --model "$model" -n "$size" --save-input "$input"
fi
"$geode" conform "$input" -o serial.exo --quiet $flags 2>serial_warnings.txt
sed -i 's/^geode: warning: //' serial_warnings.txt
for n in 1 2 3 4; do
  rings=()
  if [ "$n" = 2 ] || [ "$n" = 3 ]; then rings=(--rings 1); fi
  timeout 300 "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform "$input" -o "out$n.exo" \
    --join "${rings[@]}" -q $flags 2>"warnings$n.txt"
  "$check" same serial.exo "out$n.exo"
  # The serial run's warnings, once, on stderr under -q (layer-mixed: its wedges split, the
  # buffer layer carved from the tets across their block's faces, so blocks do not keep their
  # volumes; the zone's conform said so on the zone rank and geode_mpi printed none of it; sets:
  # the reader's, printed by every rank), and the zone's growth, geode_mpi's own.
  if ! diff serial_warnings.txt <(sed 's/^geode_mpi: warning: //' "warnings$n.txt" |
    grep -v '^transition zone grown to [0-9]* rings$'); then
    echo "$n ranks: warnings not the serial run's"; cat "warnings$n.txt"; exit 1
  fi
  "$check" ranks "out$n.exo" "$n"
  hexes=$("$check" count "out$n.exo")
  status=0
  /usr/bin/python3 "$here/vtk_exodus_check.py" "out$n.exo" "$n" "$hexes" || status=$?
  [ "$status" = 0 ] || [ "$status" = 77 ] || exit 1
done
# The joined files of every rank count and zone depth are one file, byte for byte.
for n in 2 3 4; do cmp out1.exo "out$n.exo"; done
# The sets model's input is a .msh; its serial output, an Exodus file with blocks, node and side
# sets and number maps, is read in shares by the ranks (each its run of the nodes and elements,
# the first the sets: io/exodus.hpp read_exodus_shared) when conformed again (hex-only: diced).
if [ "$model" = sets ]; then
  "$geode" conform serial.exo -o again.exo --quiet
  for n in 2 3; do
    timeout 300 "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform serial.exo \
      -o "again$n.exo" --join -q
    "$check" same again.exo "again$n.exo"
  done
fi
echo "mpi_test $model: identical on 1 to 4 ranks"
