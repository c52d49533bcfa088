#!/usr/bin/env bash
# Installs the Debian packages hsr needs, only those missing. Idempotent; fast when all are present.
# Runs `apt-get update` first only when something has to be installed.
set -euo pipefail

PACKAGES=(
  build-essential cmake make ccache pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libeigen3-dev libboost-dev libboost-graph-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev
  googletest libgtest-dev libbenchmark-dev
  libglpk-dev
  # Footprints, terrain rasters and CRS (`--ground DTM.tif`, `hsr city --footprints`): GDAL 3.6.
  libgdal-dev
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  # `python3 -m hsr.batch` (README "City scale"): Dask distributed, Debian's own (no pip).
  python3-distributed
  # bench/faces/plot.py: the facets-against-accuracy plot of README "Detail and face count".
  python3-matplotlib
  # `make fuzz`: clang with libFuzzer and the sanitizer runtimes (Debian 12: LLVM 14).
  clang libclang-rt-14-dev
  # Visual reports: three.js r111 from Debian (inlined into the HTML at build time; no npm needed) and
  # Chromium to render stills headless (`hsr render`, --png) and for the browser test.
  libjs-three chromium
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
