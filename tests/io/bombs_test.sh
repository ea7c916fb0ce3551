#!/bin/bash
# Hostile inputs (tests/io/make_bombs.py) under a memory limit: each must be refused by
# `geode check` with exit 2 and one line on stderr naming the file, within 10 s, while the
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

check() {  # FILE [time|ulimit]
  local file=$dir/$1 mode=$2 start end status lines
  start=$(date +%s%N)
  if [ "$mode" = ulimit ]; then
    (ulimit -v $limit_kb; exec "$geode" check "$file") >"$dir/out" 2>"$dir/err"
    status=$?
  else
    /usr/bin/time -f %M -o "$dir/rss" "$geode" check "$file" >"$dir/out" 2>"$dir/err"
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
    [ "$rss" -lt 262144 ] || problem+=" peak resident memory $rss KiB;"
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
exit $((failures > 0))
