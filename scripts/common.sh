# Shared by scripts/run and scripts/test: install what is missing, configure and build.
# Sourced, not executed.
set -euo pipefail
GEODE_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GEODE_PACKAGES=(cmake g++ make libopenmesh-dev libeigen3-dev doctest-dev libcli11-dev
  nlohmann-json3-dev libexodusii-dev libgmsh-dev gmsh python3-vtk9 python3-matplotlib
  libtbb-dev)
JOBS=${JOBS:-$(nproc)}

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

# geode_build DIR [cmake args...]
geode_build() {
  local dir=$1; shift
  cmake -S "$GEODE_ROOT" -B "$GEODE_ROOT/$dir" "$@" >/dev/null
  cmake --build "$GEODE_ROOT/$dir" -j "$JOBS"
}
