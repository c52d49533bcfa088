#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, coverage) in BUILD_DIR, writes the seed corpus with the
# project's own writers and synth, and runs each target for FUZZ_SECONDS (default 60), one after the other.
# The growing corpus is kept in BUILD_DIR/fuzz/corpus/<target> (so later runs continue where earlier ones
# stopped); crashes land in BUILD_DIR/fuzz/artifacts/<target>/ and make this script exit non-zero.
# Env: FUZZ_SECONDS, FUZZ_TARGETS (default "ply xyz off las laz e57 pipeline extraction"), BUILD_DIR (default
# build-fuzz), JOBS. fuzz_laz's seeds are the small LAZ/COPC files of ../shared/laz (copied into the build
# folder at run time, never into the project): pointwise v1 and v2 items, layered v3 items.
# Reproduce a finding: BUILD_DIR/fuzz/fuzz_<target> <artifact file>.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
FUZZ_TARGETS=${FUZZ_TARGETS:-"ply xyz off las laz e57 pipeline extraction"}
JOBS=${JOBS:-$(nproc)}

CC=clang CXX=clang++ cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHSR_BUILD_FUZZ=ON \
  -DHSR_SANITIZE=ON -DHSR_BUILD_TESTS=OFF -DHSR_BUILD_BENCH=OFF >/dev/null
targets=(hsr_fuzz_seeds)
for t in $FUZZ_TARGETS; do targets+=("fuzz_$t"); done
cmake --build "$BUILD_DIR" -j "$JOBS" --target "${targets[@]}"

FUZZ_DIR="$BUILD_DIR/fuzz"
"$FUZZ_DIR/hsr_fuzz_seeds" "$FUZZ_DIR/seeds"
mkdir -p "$FUZZ_DIR/seeds/laz"
for f in simple.laz simple-laszip-compressor-version-1.2r0.laz 1.2-with-color.copc.laz; do
  if [ -f "../shared/laz/$f" ]; then cp "../shared/laz/$f" "$FUZZ_DIR/seeds/laz/"; fi
done
export ASAN_OPTIONS=${ASAN_OPTIONS:-"detect_leaks=1"}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-"halt_on_error=1:print_stacktrace=1"}
status=0
for t in $FUZZ_TARGETS; do
  mkdir -p "$FUZZ_DIR/corpus/$t" "$FUZZ_DIR/artifacts/$t"
  log="$FUZZ_DIR/fuzz_$t.log"
  echo "fuzz: $t for ${FUZZ_SECONDS} s (log $log)"
  if ! "$FUZZ_DIR/fuzz_$t" "$FUZZ_DIR/corpus/$t" "$FUZZ_DIR/seeds/$t" -max_total_time="$FUZZ_SECONDS" \
      -timeout=30 -rss_limit_mb=2560 -malloc_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$FUZZ_DIR/artifacts/$t/" >"$log" 2>&1; then
    echo "fuzz: $t FOUND A PROBLEM:"; grep -E "ERROR|violated|SUMMARY|Test unit written" "$log" | head -20
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" | sed "s/^/fuzz: $t /" || true
  grep -E "^#[0-9]+.*(DONE|cov:)" "$log" | tail -1 | sed "s/^/fuzz: $t /" || true
done
exit $status
