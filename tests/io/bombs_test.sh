#!/bin/bash
# Hostile inputs (tests/io/make_bombs.py) under a memory limit: each must be refused by
# `geode check` (a spec by `geode arrange`) with exit 2 and one line on stderr naming the file, within 10 s, while the
# process's address space is capped by `ulimit -v` (the zlib .vtu once inflated 2.5 GB, the
# Exodus file asked for 48 GB, the nested tags overflowed the stack). The 6 GiB .msh is mapped,
# not copied, so it is run without the cap (a mapping counts as address space) and its peak
# resident memory is measured instead.
# usage: bombs_test.sh GEODE SOURCE_DIR
set -u
geode=$1
src=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
/usr/bin/python3 "$src/tests/io/make_bombs.py" "$dir" || { echo "make_bombs.py failed"; exit 1; }
limit_kb=$((1536 * 1024))  # 1.5 GiB of address space; geode itself starts in about 0.5
failures=0

check() {  # FILE time|ulimit [COMMAND (default check) [PEAK_KIB (time: default 256 MiB)]]
  local file=$dir/$1 mode=$2 command=${3:-check} peak=${4:-262144} start end status lines
  start=$(date +%s%N)
  if [ "$mode" = ulimit ]; then
    (ulimit -v $limit_kb; exec "$geode" $command "$file") >"$dir/out" 2>"$dir/err"
    status=$?
  else
    /usr/bin/time -f %M -o "$dir/rss" "$geode" $command "$file" >"$dir/out" 2>"$dir/err"
    status=$?
  fi
  end=$(date +%s%N)
  lines=$(wc -l <"$dir/err")
  local ms=$(((end - start) / 1000000)) problem=""
  [ "$status" -eq 2 ] || problem+=" exit $status, expected 2;"
  [ "$lines" -eq 1 ] || problem+=" $lines lines on stderr, expected 1;"
  grep -qF "$file" "$dir/err" || problem+=" the message does not name the file;"
  [ "$ms" -lt 10000 ] || problem+=" took $ms ms;"
  if [ "$mode" = time ]; then
    local rss
    rss=$(tail -1 "$dir/rss")
    [ "$rss" -lt "$peak" ] || problem+=" peak resident memory $rss KiB;"
    ms="$ms ms, peak $rss KiB"
  else
    ms="$ms ms"
  fi
  if [ -n "$problem" ]; then
    echo "FAIL $1:$problem"
    sed 's/^/  stderr: /' "$dir/err" | head -5
    failures=$((failures + 1))
  else
    echo "ok   $1 ($ms): $(cat "$dir/err")"
  fi
}

check nested.vtu ulimit
check zlib.vtu ulimit
check nodes.exo ulimit
check big.msh time
# 200,000 sheets, refused while parsing: the 16 MB text and the start (about 50 MiB), not the
# 200 MB and more its JSON tree took before it was counted.
check sheets.json time arrange 98304

# std::bad_alloc anywhere is one line and exit 2, nothing written. The base: the smallest
# address space in which geode reads a unit hex (found to 32 MiB). nodes.msh (valid, read without
# a cap as a control) needs more than the base + 96 MiB to be read: the reader's message names
# it. grid.msh is read within a few MiB more than the base, its conform run needs more: under
# caps from the base up in 8 MiB steps each run either finishes or fails in one line, exit 2,
# nothing written, and some fail after reading ("geode conform: error: out of memory"). One
# thread (--threads 1): a worker thread that cannot be created is another error than memory.
runs() {  # LIMIT_KIB ARGS...: geode under the cap, output in $dir/out, status returned
  local limit=$1
  shift
  (ulimit -v "$limit"; exec "$geode" "$@") >"$dir/out" 2>&1
}
lo=0
hi=$((8192 * 1024))
runs $hi check "$dir/small.msh" || { echo "FAIL: geode check small.msh fails with 8 GiB"; exit 1; }
while [ $((hi - lo)) -gt 32768 ]; do
  mid=$(((lo + hi) / 2))
  if runs $mid check "$dir/small.msh"; then hi=$mid; else lo=$mid; fi
done
echo "     (geode reads a unit hex in $((hi / 1024)) MiB of address space)"

refused_in_one_line() {  # WORDS: the last run exited 2 with one line holding WORDS, no output
  local problem=""
  [ "$status" -eq 2 ] || problem+=" exit $status, expected 2;"
  [ "$(wc -l <"$dir/out")" -eq 1 ] || problem+=" $(wc -l <"$dir/out") lines of output, expected 1;"
  grep -qF -- "$1" "$dir/out" || problem+=" no '$1' in the message;"
  [ ! -e "$dir/o.exo" ] || problem+=" an output was written;"
  echo "$problem"
}

"$geode" check "$dir/nodes.msh" >/dev/null 2>&1
control=$?
runs $((hi + 98304)) check "$dir/nodes.msh"
status=$?
problem=$(refused_in_one_line "$dir/nodes.msh: out of memory reading it")
[ "$control" -eq 0 ] || problem+=" without a cap: exit $control, expected 0;"
if [ -n "$problem" ]; then
  echo "FAIL nodes.msh (reading under $(((hi + 98304) / 1024)) MiB):$problem"
  sed 's/^/  output: /' "$dir/out" | head -5
  failures=$((failures + 1))
else
  echo "ok   nodes.msh (reading under $(((hi + 98304) / 1024)) MiB): $(cat "$dir/out")"
fi

"$geode" conform "$dir/grid.msh" -o "$dir/o.exo" --quiet --threads 1 >/dev/null 2>&1
control=$?
rm -f "$dir/o.exo"
later=0
problem=""
[ "$control" -eq 0 ] || problem+=" without a cap: exit $control, expected 0;"
for add in 0 8 16 24 32 40 48 56 64; do
  runs $((hi + add * 1024)) conform "$dir/grid.msh" -o "$dir/o.exo" --quiet --threads 1
  status=$?
  if [ "$status" -eq 0 ]; then
    rm -f "$dir/o.exo"
    continue
  fi
  p=$(refused_in_one_line "out of memory")
  [ -z "$p" ] || problem+=" at +$add MiB:$p $(head -c 200 "$dir/out");"
  grep -qF "geode conform: error: out of memory" "$dir/out" && later=$((later + 1))
  rm -f "$dir/o.exo"
done
[ "$later" -gt 0 ] || problem+=" no run failed after reading the model;"
if [ -n "$problem" ]; then
  echo "FAIL grid.msh (conform):$problem"
  failures=$((failures + 1))
else
  echo "ok   grid.msh (conform): $later runs out of memory after reading, in one line, exit 2"
fi
# Every core (no --threads), on a Delaunay hybrid (geode demo): under caps about the base, a
# worker thread whose stack does not fit cannot be started (TBB: "pthread_create has failed").
# Each run finishes or fails in one line, exit 2, nothing written (the base was found to 32
# MiB, so the caps start 32 MiB below it: some runs cannot read the file, or even start). Once
# an exception unwinding for want of memory aborted in glibc, which had to load libgcc_s first;
# one thrown while the commands were built ended in std::terminate. On one core TBB starts no
# worker, so the thread failures are counted, not required.
"$geode" demo --model delaunay -n 6 --save-input "$dir/hybrid.msh" --quiet || {
  echo "FAIL: geode demo --save-input"
  exit 1
}
threads=0
library=0
problem=""
for add in $(seq -32 2 4); do
  runs $((hi + add * 1024)) conform "$dir/hybrid.msh" -o "$dir/o.exo" --quiet
  status=$?
  if [ "$status" -eq 0 ]; then
    rm -f "$dir/o.exo"
    continue
  fi
  # Below what the dynamic loader needs to map the libraries, geode never starts.
  [ "$status" -eq 127 ] && grep -qF "error while loading shared libraries" "$dir/out" && continue
  # Just above it the libraries' own constructors run out, before main: libgnutls prints its
  # line, then OpenMesh's reader registry cannot allocate in its constructor and the C++ runtime
  # aborts ("terminate called", from __cxa_allocate_exception; seen in gdb). geode never started
  # either: no line of geode's own.
  if [ "$status" -eq 134 ] && grep -qF "Error in GnuTLS initialization" "$dir/out" &&
    grep -qF "terminate called" "$dir/out" && ! grep -q "^geode" "$dir/out"; then
    library=$((library + 1))
    continue
  fi
  # A little above it, libgnutls (linked through libnetcdf and libcurl) may fail in its own
  # constructor, before main, and print a line of its own: counted, and geode's line judged.
  if grep -qF "Error in GnuTLS initialization" "$dir/out"; then
    library=$((library + 1))
    grep -vF "Error in GnuTLS initialization" "$dir/out" >"$dir/out.geode"
    mv "$dir/out.geode" "$dir/out"
  fi
  p=$(refused_in_one_line "error")
  [ -z "$p" ] || problem+=" at $add MiB:$p $(head -c 200 "$dir/out");"
  grep -qF "cannot start a worker thread" "$dir/out" && threads=$((threads + 1))
  rm -f "$dir/o.exo"
done
if [ -n "$problem" ]; then
  echo "FAIL hybrid.msh (conform, every core):$problem"
  failures=$((failures + 1))
else
  echo "ok   hybrid.msh (conform, every core): $threads runs could not start a thread, in one line, exit 2 ($library with libgnutls's own constructor line before it)"
fi
exit $((failures > 0))
