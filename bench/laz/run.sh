#!/usr/bin/env bash
# LAZ decode speed: hsr's decoder (laz_decode_bench) against npm's laz-perf (its WASM build under node),
# on ../shared/laz/autzen_trim.laz and lone-star.laz. laz-perf is installed by npm into
# BUILD_DIR/bench-laz-npm (never by the build). One core: both pinned to CPU 0 (taskset), HSR_THREADS=1;
# two cores: HSR_THREADS=2, unpinned. Best of REPEATS runs each. Both print an FNV-1a hash of all decoded
# records: equal hashes say both decoded the same bytes.
# Env: BUILD_DIR (default build), REPEATS (default 5), LOCK (a file to flock while measuring, optional).
# Results: bench/results/laz.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD_DIR=${BUILD_DIR:-build}
REPEATS=${REPEATS:-5}
NPM_DIR="$BUILD_DIR/bench-laz-npm"
FILES=(../shared/laz/autzen_trim.laz ../shared/laz/lone-star.laz)
for f in "${FILES[@]}"; do [ -f "$f" ] || { echo "bench/laz: $f not found"; exit 1; }; done
if [ ! -f "$NPM_DIR/node_modules/laz-perf/package.json" ]; then
  npm install --no-audit --no-fund --prefix "$NPM_DIR" laz-perf@0.0.7 >/dev/null
fi
cmake --build "$BUILD_DIR" --target laz_decode_bench >/dev/null
measure() {
  if [ -n "${LOCK:-}" ]; then flock "$LOCK" "$@"; else "$@"; fi
}
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores," \
  "laz-perf $(node -p "require('./$NPM_DIR/node_modules/laz-perf/package.json').version"), node $(node --version)"
echo "# load before: $(uptime | sed 's/.*load average: //')"
measure taskset -c 0 node bench/laz/lazperf_decode.cjs "$PWD/$NPM_DIR/node_modules" "$REPEATS" "${FILES[@]}"
HSR_THREADS=1 measure taskset -c 0 "$BUILD_DIR/bench/laz/laz_decode_bench" "$REPEATS" "${FILES[@]}"
HSR_THREADS=2 measure "$BUILD_DIR/bench/laz/laz_decode_bench" "$REPEATS" "${FILES[@]}"
echo "# load after: $(uptime | sed 's/.*load average: //')"
