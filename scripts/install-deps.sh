#!/usr/bin/env bash
# Installs the Debian packages hsr needs, only those missing. Idempotent; fast when all are present.
# Runs `apt-get update` first only when something has to be installed.
#   scripts/install-deps.sh          everything: the CLI, tests, benchmarks, Python module, fuzzing, pictures
#   scripts/install-deps.sh --demo   only what building the CLI needs (`make demo`)
set -euo pipefail

# What building the CLI needs (`make demo`): compiler, CMake, the libraries it links, three.js for its pages.
DEMO_PACKAGES=(
  build-essential cmake make ccache pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libeigen3-dev libboost-dev libboost-graph-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev
  # Footprints, terrain rasters and CRS (`--ground DTM.tif`, `hsr city --footprints`): GDAL 3.6.
  libgdal-dev
  # E57 input (src/io/e57_xml.cpp reads the XML section with it): Xerces-C 3.2.
  libxerces-c-dev
  libjs-three
)

PACKAGES=(
  "${DEMO_PACKAGES[@]}"
  googletest libgtest-dev libbenchmark-dev
  libglpk-dev
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest
  # `python3 -m hsr.batch` (README "City scale"): Dask distributed, Debian's own (no pip).
  python3-distributed
  # bench/faces/plot.py: the facets-against-accuracy plot of README "Detail and face count".
  python3-matplotlib
  # `make fuzz`: clang with libFuzzer and the sanitizer runtimes (Debian 12: LLVM 14).
  clang libclang-rt-14-dev
  # Chromium renders stills headless (`hsr render`, --png) and runs the browser test; the pages' three.js
  # r111 (inlined into the HTML at build time; no npm needed) is among the demo's packages.
  chromium
)
if [ "${1:-}" = "--demo" ]; then PACKAGES=("${DEMO_PACKAGES[@]}"); fi

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
