#!/usr/bin/env bash
# geode_mpi's verification (issue 26): --verify local (the default: the diced hexes against the
# dicing tables, the whole check around the transition zone, every corner Jacobian) and --verify
# full pass the same valid result; a dicing broken on purpose (the test hook
# GEODE_TEST_BREAK_DICED_HEX, docs/cli.md) is found by both on 1 and 2 ranks: exit 4, the
# failing check named, nothing written. A transition zone made invalid on the zone rank (the last;
# GEODE_TEST_INVERT_OUTPUT_HEX in its conform) fails every rank count alike; so does a partition
# failing on rank 0 (GEODE_TEST_FAIL_PARTITION), and one rank's share of the read refused
# (GEODE_TEST_FAIL_READ_SHARE), without a rank left waiting; so does one rank failing alone
# (GEODE_TEST_FAIL_RANK). Options out of range exit 2; a summary rank 0 cannot print publishes
# nothing. Rank 0 alone prints progress, -q none.
# usage: mpi_verify_test.sh GEODE GEODE_MPI MPIEXEC WORKDIR
set -euo pipefail
geode=$1 geode_mpi=$2 mpiexec=$3 dir=$4
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir"
"$geode" demo --model half -n 8 --save-input in.exo >/dev/null
for n in 1 2; do
  for mode in local full; do
    "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform in.exo -o "ok_${mode}$n.exo" \
      --verify "$mode" --join -q
    status=0
    GEODE_TEST_BREAK_DICED_HEX=1 "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform in.exo \
      -o "broken_${mode}$n.exo" --verify "$mode" -q 2>err.txt >/dev/null || status=$?
    if [ "$status" != 4 ]; then
      echo "verify $mode, $n ranks: a broken dicing exited $status, not 4"; cat err.txt; exit 1
    fi
    grep -q "invalid result, nothing written" err.txt
    grep -q "hexes inverted (a corner Jacobian <= 0), hexes: " err.txt
    if [ "$mode" = local ]; then grep -q "dicing: NOT as its tables make it" err.txt; fi
    if ls broken_* >/dev/null 2>&1; then echo "verify $mode, $n ranks: wrote a file"; exit 1; fi
  done
  cmp "ok_local$n.exo" "ok_full$n.exo"
done
for n in 1 2 3; do
  status=0
  GEODE_TEST_INVERT_OUTPUT_HEX=1 "$mpiexec" --oversubscribe -np "$n" "$geode_mpi" conform in.exo \
    -o "zone$n.exo" -q 2>err.txt >/dev/null || status=$?
  if [ "$status" != 4 ]; then
    echo "an invalid zone, $n ranks: exited $status, not 4"; cat err.txt; exit 1
  fi
  grep -q "the transition zone (numbered in its own output): [0-9]* of [0-9]* hexes inverted" err.txt
  grep -q "invalid result, nothing written" err.txt
  if ls zone"$n".exo* >/dev/null 2>&1; then echo "an invalid zone, $n ranks: wrote a file"; exit 1; fi
done
# METIS failing on rank 0 (GEODE_TEST_FAIL_PARTITION) while the zone rank waits for its partition:
# every rank stops with the reason, none waits (timeout: a wait would hang the suite).
for n in 2 3; do
  status=0
  GEODE_TEST_FAIL_PARTITION=1 timeout 120 "$mpiexec" --oversubscribe -x GEODE_TEST_FAIL_PARTITION \
    -np "$n" "$geode_mpi" conform in.exo -o "fail$n.exo" -q 2>err.txt >/dev/null || status=$?
  if [ "$status" = 0 ] || [ "$status" = 124 ]; then
    echo "a failed partition, $n ranks: exited $status"; cat err.txt; exit 1
  fi
  grep -q "the partition failed: GEODE_TEST_FAIL_PARTITION is set" err.txt
  if ls fail"$n".exo* >/dev/null 2>&1; then echo "a failed partition, $n ranks: wrote a file"; exit 1; fi
done
# One rank's share of the shared Exodus read refused (GEODE_TEST_FAIL_READ_SHARE, as a corrupt
# run of the file would be) while the others read theirs: every rank stops with that reason,
# exit 2, none waits at the exchange; and a truncated file is refused on every rank alike.
for n in 2 3; do
  for fail in 0 $((n - 1)); do
    status=0
    GEODE_TEST_FAIL_READ_SHARE=$fail timeout 120 "$mpiexec" --oversubscribe \
      -x GEODE_TEST_FAIL_READ_SHARE -np "$n" "$geode_mpi" conform in.exo -o "read$n.exo" -q \
      2>err.txt >/dev/null || status=$?
    if [ "$status" != 2 ]; then
      echo "share $fail of $n refused: exited $status, not 2"; cat err.txt; exit 1
    fi
    grep -q "in.exo: GEODE_TEST_FAIL_READ_SHARE is set" err.txt
    if ls read"$n".exo* >/dev/null 2>&1; then echo "a refused share, $n ranks: wrote a file"; exit 1; fi
  done
done
# One rank failing alone (GEODE_TEST_FAIL_RANK=R:STAGE): after reading, while the others go on
# into the conform's collectives, it aborts the run after its wait for them (exit 2 with the
# reason, no rank left waiting); before writing its piece, after the others wrote theirs, every
# rank agrees on the failure: exit 2, the reason from that rank, no piece of the set written.
for n in 2 3; do
  for stage in read write; do
    status=0
    GEODE_TEST_FAIL_RANK=$((n - 1)):$stage timeout 120 "$mpiexec" --oversubscribe \
      -x GEODE_TEST_FAIL_RANK -np "$n" "$geode_mpi" conform in.exo -o "alone$n.exo" --join -q \
      2>err.txt >/dev/null || status=$?
    if [ "$status" != 2 ]; then
      echo "rank $((n - 1)) failing alone at $stage of $n: exited $status, not 2"; cat err.txt; exit 1
    fi
    grep -q "rank $((n - 1)): GEODE_TEST_FAIL_RANK is set ($stage)" err.txt
    if ls alone"$n".exo* .alone* >/dev/null 2>&1; then
      echo "rank $((n - 1)) failing alone at $stage: a file is left"; ls -a; exit 1
    fi
  done
done
head -c $(($(stat -c %s in.exo) * 3 / 4)) in.exo >cut.exo
status=0
timeout 120 "$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform cut.exo -o cut-out.exo -q \
  2>err.txt >/dev/null || status=$?
[ "$status" = 2 ] || { echo "a truncated file on 2 ranks: exited $status, not 2"; cat err.txt; exit 1; }
grep -q "cut.exo: .*truncated" err.txt
if ls cut-out.exo* >/dev/null 2>&1; then echo "a truncated file: wrote a file"; exit 1; fi
# Options out of their range are usage errors (exit 2) before any work, as in geode conform:
# --smooth global, an unknown side, --rings past 1..64, a thickness past its side's maximum.
# Started alone (MPI's singleton, one rank): mpirun adds 2 s to every run that exits non-zero.
for args in "--smooth global" "--buffer-side wedge" "--rings 0" "--rings 65" \
    "--buffer-thickness 0" "--buffer-thickness nan" "--buffer-side tet --buffer-thickness 0.5"; do
  status=0
  # shellcheck disable=SC2086
  timeout 120 "$geode_mpi" conform in.exo -o refused.exo $args -q 2>err.txt >/dev/null || status=$?
  [ "$status" = 2 ] || { echo "conform $args: exited $status, not 2"; cat err.txt; exit 1; }
  if ls refused.exo* >/dev/null 2>&1; then echo "conform $args: wrote a file"; exit 1; fi
done
grep -q "with --buffer-side tet: at most 0.45" err.txt
for threads in 0 4097; do  # a usage error on one line (CLI11's two, unprefixed, before)
  status=0
  timeout 120 "$geode_mpi" conform in.exo -o refused.exo --threads "$threads" 2>err.txt >/dev/null ||
    status=$?
  [ "$status" = 2 ] || { echo "--threads $threads: exited $status, not 2"; cat err.txt; exit 1; }
  [ "$(wc -l <err.txt)" = 1 ] && grep -q "^geode_mpi conform: usage error: --threads" err.txt
done
# Progress: rank 0 alone says each stage as it ends, with its seconds (every rank reads, dices
# and verifies: a stage said twice was said by two ranks); -q says nothing.
"$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform in.exo -o said.exo 2>said.txt >/dev/null
# The two steps of the zone selection and of the partition each under a name of its own.
for stage in "read in.exo: " "zone selection: rings (" "yardstick (" "zone selection: closed (" \
  "partition: face pairs gathered (" "partition (" "dicing (" "zone shared (" "verification (" \
  "wrote rank 0's piece ("; do
  [ "$(grep -c "^geode_mpi: $stage" said.txt)" = 1 ] || {
    echo "progress: '$stage' not said once"; cat said.txt; exit 1
  }
done
# The zone's conform says its stages on the rank that runs it, marked so.
grep -q '^geode_mpi: zone: interface: ' said.txt || { echo "progress: the zone's stages not said"; cat said.txt; exit 1; }
if grep -v '^geode_mpi: zone: ' said.txt | grep -v '^geode_mpi: .* ([0-9]*\.[0-9] s)$'; then
  echo "progress: not a stage's line"; exit 1
fi
"$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform in.exo -o quiet.exo -q 2>quiet.txt >/dev/null
[ ! -s quiet.txt ] || { echo "progress: -q printed"; cat quiet.txt; exit 1; }
# Outputs checked before any work (a fault hunt's: -o IN --join overwrote the input, exit 0; -o
# m.msh, -o - and -o '' wrote Exodus pieces named m.msh.2.0, -.2.0, .2.0): refused, the input
# untouched, nothing written; so is an output whose pieces are the input set's.
cp in.exo keep.exo
"$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform in.exo -o set.exo -q
for args in "-o in.exo --join" "-o m.msh" "-o -" "-o ''" "-o ." "-o set.exo"; do
  status=0
  input=in.exo
  [ "$args" = "-o set.exo" ] && input=set.exo.2.0
  # shellcheck disable=SC2086
  eval timeout 120 "$mpiexec" --oversubscribe -np 2 "$geode_mpi" conform "$input" $args -q \
    2>err.txt >/dev/null || status=$?
  [ "$status" = 2 ] || { echo "conform $args: exited $status, not 2"; cat err.txt; exit 1; }
  if ls m.msh* ./-* .2.* >/dev/null 2>&1; then echo "conform $args: wrote a file"; exit 1; fi
done
cmp in.exo keep.exo
# Rank 0's summary lost (started alone, its standard output its own; under mpirun the launcher
# holds it): the run fails, no piece published.
status=0
"$geode_mpi" conform in.exo -o lost.exo >/dev/full 2>err.txt || status=$?
[ "$status" = 2 ] || { echo "summary to /dev/full: exited $status, not 2"; cat err.txt; exit 1; }
grep -q "writing standard output failed: .* (nothing written)" err.txt
if ls lost.exo* >/dev/null 2>&1; then echo "summary to /dev/full: wrote a file"; exit 1; fi
# Two ranks, rank 0's standard output a full disk of its own: neither publishes its piece.
status=0
# shellcheck disable=SC2016
"$mpiexec" --oversubscribe -np 2 sh -c 'if [ "$OMPI_COMM_WORLD_RANK" = 0 ]; then exec "$0" "$@" >/dev/full; else exec "$0" "$@"; fi' \
  "$geode_mpi" conform in.exo -o lost2.exo 2>err.txt || status=$?
[ "$status" = 2 ] || { echo "2 ranks, rank 0's summary to /dev/full: exited $status, not 2"; cat err.txt; exit 1; }
grep -q "writing standard output failed: .* (nothing written)" err.txt
if ls lost2.exo* >/dev/null 2>&1; then echo "2 ranks, rank 0's summary lost: wrote a piece"; exit 1; fi
# Interrupted (Ctrl-C, a scheduler's SIGTERM) once the pieces are written: mpirun tells the ranks
# by SIGCONT at once and SIGTERM a second later, so a rank that waited for SIGTERM published its
# pieces in between (found by a fault hunt). Every rank waits 0.6 s with its pieces written
# (GEODE_TEST_PAUSE_BEFORE_COMMIT); mpiexec is interrupted as soon as one appears: nothing is
# published, no temporary stays.
for sig in INT TERM; do
  rm -rf sig && mkdir sig
  GEODE_TEST_PAUSE_BEFORE_COMMIT=0.6 "$mpiexec" --oversubscribe -x GEODE_TEST_PAUSE_BEFORE_COMMIT \
    -np 2 "$geode_mpi" conform in.exo -o sig/out.exo --join -q </dev/null 2>/dev/null >/dev/null &
  launcher=$!
  for _ in $(seq 600); do  # the rank's hidden temporary of its piece: .out.exo.2.0.tmp-...
    if compgen -G 'sig/.out.exo.2.0*' >/dev/null; then break; fi
    sleep 0.01
  done
  kill -s "$sig" "$launcher"
  status=0
  wait "$launcher" || status=$?
  sleep 1.5  # mpirun's SIGKILL of what is left
  [ "$status" != 0 ] || { echo "SIG$sig before publishing: exited 0"; exit 1; }
  if [ -n "$(ls -A sig)" ]; then echo "SIG$sig before publishing: left $(ls -A sig)"; exit 1; fi
done
echo "mpi_verify_test: both modes pass the result and find the broken dicing on 1 and 2 ranks, an invalid zone on 1 to 3, a refused share of the read on 2 and 3, a rank failing alone on 2 and 3, options out of range and outputs that are not Exodus files or are the input refused, a lost summary publishing nothing, an interrupted run publishing nothing, progress from rank 0 alone"
