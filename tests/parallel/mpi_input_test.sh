#!/usr/bin/env bash
# geode_mpi's partitioned inputs (issue 26), on 1, 2, 3 and 4 ranks (oversubscribed), against
# the serial `geode conform` of the same input:
# - a Gmsh-partitioned .msh 4.1 (MODEL: a demo model saved by `geode demo --save-input`, or
#   "sets", tests/parallel/sets_model.py's blocks, side and node sets), partitioned into 3 by
#   Gmsh at test time: `geode conform` reads it as the unpartitioned file (the same output), and
#   geode_mpi uses its 3 parts (3 ranks), joins them (1, 2: fewer ranks than parts) or runs
#   METIS (4 ranks: more), the output identical every time;
# - geode_mpi's own per-rank output read back as a Nemesis input set (a hex-only model, which
#   conform dices) by `geode conform` and by geode_mpi: the same as the joined file conformed;
# - the refusals: a piece missing, pieces of two sets mixed (global counts differ), a shared
#   node moved in one piece, an element given in two pieces (tests/parallel/corrupt_piece.py),
#   two sets beside a missing base name, one file of Gmsh's Mesh.PartitionSplitMeshFiles=1 set;
# - --join-blocks on 2 ranks as in the serial run, and a block it names missing refused.
# usage: mpi_input_test.sh GEODE GEODE_MPI PARALLEL_CHECK MPIEXEC MODEL SIZE WORKDIR
set -euo pipefail
geode=$1 geode_mpi=$2 check=$3 mpiexec=$4 model=$5 size=$6 dir=$7
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir"
if [ "$model" = sets ]; then
  /usr/bin/python3 "$here/sets_model.py" in.msh "$size"
else
  "$geode" demo --model "$model" -n "$size" --save-input in.msh >/dev/null
fi
/usr/bin/python3 "$here/partition_model.py" in.msh parts.msh 3 --whole whole.msh
grep -q '^\$PartitionedEntities' parts.msh
# Refused by name: expect CODE WORDS... -- COMMAND...
refused() {
  local code=$1 words=$2
  shift 3
  local status=0
  "$@" >out.txt 2>err.txt || status=$?
  if [ "$status" != "$code" ] || ! grep -qF -- "$words" err.txt; then
    echo "expected exit $code and '$words' from: $*"; cat err.txt; exit 1
  fi
}

# on_1_to_4_ranks INPUT PREFIX REFERENCE: geode_mpi on 1 to 4 ranks (the input's 3 parts as they
# are, joined on fewer ranks, METIS on more), each joined output REFERENCE after canonical
# ordering, and the joined files of every rank count the same bytes.
on_1_to_4_ranks() {
  local input=$1 prefix=$2 reference=$3 n
  for n in 1 2 3 4; do
    "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform "$input" -o "$prefix$n.exo" --join \
      --rings 1 >"$prefix$n.txt"
    case $n in
      4) grep -q "partition: METIS (the input's 3 parts are fewer than the ranks)" "$prefix$n.txt" ;;
      3) grep -q "partition: the input's 3 parts, " "$prefix$n.txt" ;;
      *) grep -q "partition: the input's 3 parts joined on $n rank" "$prefix$n.txt" ;;
    esac
    "$check" same "$reference" "$prefix$n.exo"
    "$check" ranks "$prefix$n.exo" "$n"
  done
  for n in 2 3 4; do cmp "${prefix}1.exo" "$prefix$n.exo"; done
}

# The partitioned file is the unpartitioned model (as Gmsh writes both): the same serial output.
"$geode" conform whole.msh -o serial.exo --quiet
"$geode" conform parts.msh -o serial-parts.exo --quiet
"$check" same serial.exo serial-parts.exo
on_1_to_4_ranks parts.msh out serial.exo

# geode_mpi's own output as a Nemesis input set: 3 pieces, named by one piece, and by the base
# name when no joined file has that name. The set's model is the joined file's in another node
# order (global ids, not coordinates), which dicing's bits follow: the same counts, and each
# rank count the serial run of the set itself, bit for bit.
"$check" same out3.exo out3.exo.3.2
"$geode" conform out3.exo -o diced-joined.exo --quiet
"$geode" conform out3.exo.3.1 -o diced.exo --quiet
[ "$("$check" count diced.exo)" = "$("$check" count diced-joined.exo)" ]
[ "$("$check" count diced.exo)" = $((8 * $("$check" count out3.exo))) ]
mkdir -p set && cp out3.exo.3.* set/
"$geode" conform set/out3.exo -o diced-base.exo --quiet
"$check" same diced.exo diced-base.exo
on_1_to_4_ranks set/out3.exo nem diced.exo

# Inconsistent sets, refused naming the file.
mkdir -p missing && cp out3.exo.3.0 out3.exo.3.2 missing/
refused 2 "missing/out3.exo.3.1: missing (piece 1 of the Nemesis set" -- \
  "$geode" conform missing/out3.exo -o x.exo
mkdir -p mixed && cp out3.exo.3.0 out3.exo.3.1 mixed/ && cp nem3.exo.3.2 mixed/out3.exo.3.2
refused 2 "mixed/out3.exo.3.2: global counts" -- "$geode" conform mixed/out3.exo.3.0 -o x.exo
refused 2 "mixed/out3.exo.3.2: global counts" -- \
  "$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform mixed/out3.exo.3.0 -o x.exo
mkdir -p moved && cp out3.exo.3.* moved/
g=$(/usr/bin/python3 "$here/corrupt_piece.py" moved/out3.exo.3.1 moved/out3.exo.3.0 moved)
refused 2 "moved/out3.exo.3.1: global node $g is at" -- "$geode" conform moved/out3.exo.3.0 -o x.exo
mkdir -p twice && cp out3.exo.3.* twice/
g=$(/usr/bin/python3 "$here/corrupt_piece.py" twice/out3.exo.3.2 twice/out3.exo.3.0 element)
refused 2 "twice/out3.exo.3.2: element $g is also in twice/out3.exo.3.0" -- \
  "$geode" conform twice/out3.exo.3.0 -o x.exo
mkdir -p two && cp out3.exo.3.* two/ && cp out2.exo.2.* two/ && for f in two/out2.exo.2.*; do
  mv "$f" "two/out3.exo.2.${f##*.}"; done
refused 2 "two/out3.exo: missing, and pieces of 2 Nemesis sets" -- \
  "$geode" conform two/out3.exo -o x.exo
/usr/bin/python3 "$here/partition_model.py" in.msh split.msh 3 --split
refused 2 "split_1.msh: holds partition 1 of 3 only" -- "$geode" conform split_1.msh -o x.exo
# --join-blocks as the serial run takes it (both models' blocks 1 and 2 made one material).
"$geode" conform whole.msh --join-blocks 2,1 -o serial-join.exo --quiet
"$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform whole.msh --join-blocks 2,1 -o join2.exo \
  --join -q
"$check" same serial-join.exo join2.exo
refused 2 "whole.msh: joining blocks 2,9: no element is in block 9" -- \
  "$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform whole.msh --join-blocks 2,9 -o x.exo
# Nothing written by any refused run: neither the serial file nor a rank's piece.
[ ! -e x.exo ]
if compgen -G "x.exo.*" >/dev/null; then echo "a refused run wrote $(compgen -G "x.exo.*")" >&2; exit 1; fi
echo "mpi_input_test $model: partitioned .msh and Nemesis set identical on 1 to 4 ranks"
