# Shared by scripts/run and scripts/test: install what is missing, configure and build.
# Sourced, not executed.
set -euo pipefail
GEODE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GEODE_PACKAGES=(cmake g++ make libopenmesh-dev libeigen3-dev doctest-dev libcli11-dev
  nlohmann-json3-dev libexodusii-dev libgmsh-dev gmsh python3-vtk9 python3-matplotlib
  zlib1g-dev python3-meshio python3-netcdf4 clang libclang-rt-14-dev libjs-three chromium
  libtbb-dev libfmt-dev ccache python3-getfem pybind11-dev python3-numpy python3-pytest python3-nbclient python3-nbformat
  python3-ipykernel python3-gmsh clang-format clang-tidy tetgen libopenmpi-dev openmpi-bin libmetis-dev)
JOBS=${JOBS:-$(nproc)}
# ccache keeps compiled objects between runs (and between clones: paths below the root are
# hashed relative to it, the build directory not at all), so a second build costs little.
export CCACHE_BASEDIR="$GEODE_ROOT" CCACHE_NOHASHDIR=1
# Set again after geode_install: on a fresh machine ccache is one of the packages it installs.
geode_launcher() {
  GEODE_LAUNCHER=()
  if command -v ccache >/dev/null 2>&1; then GEODE_LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
}
geode_launcher

geode_install() {
  local missing=()
  for p in "${GEODE_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing: ${missing[*]}"
    if [ "$(id -u)" -ne 0 ]; then
      echo "error: packages missing (${missing[*]}) and not running as root" >&2
      exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
  geode_launcher
}

# geode_fuzz: the libFuzzer targets of the file readers and the JSON spec reader (tests/fuzz), built with clang in
# build-fuzz, each run for GEODE_FUZZ_RUNS inputs (300,000) or GEODE_FUZZ_SECONDS (60 s),
# whichever ends first, from its seed corpus with a fixed seed, so a run is repeatable for a
# given build: a regression check that keeps scripts/test within CI's 30 minutes (the five took
# 7 min at 1,000,000 inputs each); a longer search: GEODE_FUZZ_RUNS=-1 GEODE_FUZZ_SECONDS=600.
# fuzz_exo runs GEODE_FUZZ_EXO_RUNS inputs (30,000): each netCDF-4 input is read in a child
# process (io/isolated.hpp), a fork per input, 35 to 900 inputs a second here, so the time
# limit may stop it first. With two cores or more they run in two lanes side by side (exo, the
# one the time limit stops, then vtk; spec, vtu, msh: about 80 s each here instead of 165 s
# in one).
# A crash fails, its input kept as build-fuzz/crash-<reader>-*: fix it and add it to
# tests/fuzz/regressions.
geode_fuzz_reader() {
  local reader=$1 dir="$GEODE_ROOT/build-fuzz" work n=${GEODE_FUZZ_RUNS:-300000}
  [ "$reader" = exo ] && n=${GEODE_FUZZ_EXO_RUNS:-30000}
  work=$(mktemp -d)
  echo "== fuzz $reader ($n inputs, at most ${GEODE_FUZZ_SECONDS:-60} s)"
  if ! "$dir/fuzz_$reader" -seed=1 -runs="$n" -max_total_time="${GEODE_FUZZ_SECONDS:-60}" -rss_limit_mb=2048 \
      -timeout=10 -artifact_prefix="$dir/crash-$reader-" "$work" "$GEODE_ROOT/tests/fuzz/corpus/$reader" \
      >"$dir/fuzz_$reader.log" 2>&1; then
    echo "== fuzz $reader failed:" >&2
    tail -40 "$dir/fuzz_$reader.log" >&2
    rm -rf "$work"
    return 1
  fi
  rm -rf "$work"
}
geode_fuzz_lane() {
  local reader
  for reader in "$@"; do geode_fuzz_reader "$reader" || return 1; done
}
geode_fuzz() {
  local dir="$GEODE_ROOT/build-fuzz" status=0
  # The two lanes; one after the other on one core.
  local lane1=(exo vtk) lane2=(spec vtu msh)
  CC=clang CXX=clang++ cmake -S "$GEODE_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEODE_FUZZ=ON \
    -DGEODE_BENCH=OFF "${GEODE_LAUNCHER[@]}" >/dev/null
  cmake --build "$dir" -j "$JOBS" --target $(printf 'fuzz_%s ' "${lane1[@]}" "${lane2[@]}")
  if [ "$JOBS" -lt 2 ]; then
    geode_fuzz_lane "${lane1[@]}" "${lane2[@]}" || exit 1
    return
  fi
  local first second
  geode_fuzz_lane "${lane1[@]}" &
  first=$!
  geode_fuzz_lane "${lane2[@]}" &
  second=$!
  wait "$first" || status=1
  wait "$second" || status=1
  [ $status -eq 0 ] || exit 1
}

# geode_build DIR [cmake args...]
geode_build() {
  local dir=$1; shift
  cmake -S "$GEODE_ROOT" -B "$GEODE_ROOT/$dir" "${GEODE_LAUNCHER[@]}" "$@" >/dev/null
  cmake --build "$GEODE_ROOT/$dir" -j "$JOBS"
}
