#!/usr/bin/env bash
# Builds hsr with AddressSanitizer + UndefinedBehaviorSanitizer (HSR_SANITIZE=ON, RelWithDebInfo) in its own
# folder and runs the whole CTest suite there. Any sanitizer report fails the test that triggered it
# (halt_on_error), so "all tests passed" means "no ASan/UBSan finding on the suite".
# Usage: scripts/test-asan.sh [BUILD_DIR=build-asan] [JOBS=nproc] [extra ctest args, e.g. -R pipeline]
# HSR_ASAN_TESTS="test_io test_partition_stress": build and run only these test binaries (the CI subset:
# the full sanitized build of every CGAL stage does not fit CI's time limit on 2 cores next to `make test`).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build-asan}
JOBS=${2:-$(nproc)}
shift $(( $# > 2 ? 2 : $# ))

export ASAN_OPTIONS=${ASAN_OPTIONS:-"halt_on_error=1:detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1"}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-"halt_on_error=1:print_stacktrace=1"}

start=$(date +%s)
# Always configure (cheap): new test folders must be known before their targets are named.
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHSR_SANITIZE=ON -DHSR_BUILD_BENCH=OFF >/dev/null
if [ -n "${HSR_ASAN_TESTS:-}" ]; then
  # shellcheck disable=SC2086
  cmake --build "$BUILD_DIR" -j "$JOBS" --target $HSR_ASAN_TESTS
  built=$(date +%s)
  for t in $HSR_ASAN_TESTS; do
    bin=$(find "$BUILD_DIR/tests" -type f -name "$t" -perm -u+x | head -1)
    [ -n "$bin" ] || { echo "test-asan: no test binary $t"; exit 1; }
    echo "test-asan: $t"
    "$bin" --gtest_brief=1
  done
else
  cmake --build "$BUILD_DIR" -j "$JOBS"
  built=$(date +%s)
  (cd "$BUILD_DIR" && ctest --output-on-failure -j "$JOBS" "$@")
fi
end=$(date +%s)
echo "test-asan: build $((built - start)) s, tests $((end - built)) s"
