#!/usr/bin/env bash
# bench/partition/compare_partition.sh — the partition of an earlier commit against this tree's, in one run.
#
# usage: bench/partition/compare_partition.sh BASE_COMMIT [BUILD_DIR=build] -- BENCH_PARTITION_ARGS...
# Builds bench_partition from BASE_COMMIT's src/core and src/partition, with this tree's bench_partition.cpp and
# PartitionInput JSON reader (the partition's public API is the same), with g++ and the project's Release flags
# (no cmake; kept as BUILD_DIR/bench/partition/bench_partition_base_<commit> for the next run); then runs the
# base and the current bench_partition (BUILD_DIR's) one after the other on the same arguments, each under
# flock /work/notes/heavy.lock when that file exists, and prints both outputs with the load average before each.
# Example (issue 25): bench/partition/compare_partition.sh 55846fa -- --sizes 1000 --methods hierarchical
set -eu
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BASE=$1; shift
BUILD_DIR=$ROOT/build
if [ $# -gt 0 ] && [ "$1" != "--" ]; then BUILD_DIR=$1; shift; fi
[ $# -gt 0 ] && [ "$1" = "--" ] && shift
CURRENT=$BUILD_DIR/bench/partition/bench_partition
[ -x "$CURRENT" ] || { echo "compare_partition: $CURRENT not found (build bench_partition first)" >&2; exit 2; }
BASE_BIN=$BUILD_DIR/bench/partition/bench_partition_base_$(git -C "$ROOT" rev-parse --short "$BASE")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
if [ ! -x "$BASE_BIN" ]; then
git -C "$ROOT" archive "$BASE" src/core src/partition | tar -x -C "$WORK"
cp "$ROOT/src/partition/partition_input_json.cpp" "$WORK/src/partition/"
grep -q "const PartitionInput& in)" "$WORK/src/partition/partition.h" ||
  sed -i 's|^CellComplex run_partition(|void to_json(nlohmann::json\& j, const PartitionInput\& in);\nvoid from_json(const nlohmann::json\& j, PartitionInput\& in);\nCellComplex run_partition(|' \
    "$WORK/src/partition/partition.h"
mkdir -p "$WORK/bench"
cp "$ROOT/bench/partition/bench_partition.cpp" "$ROOT/bench/partition/partition_options.h" "$WORK/bench/"
echo "compare_partition: building the partition of $BASE ..." >&2
g++ -O3 -DNDEBUG -std=c++20 -frounding-math -w -I "$WORK/src" -I /usr/include/eigen3 -DHSR_VERSION='"base"' \
  "$WORK"/src/core/*.cpp "$WORK"/src/partition/*.cpp "$WORK/bench/bench_partition.cpp" \
  -o "$BASE_BIN" -lgmpxx -lgmp -ltbb -lpthread
fi
run() {
  echo "# $1: load average $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
  shift
  if [ -e /work/notes/heavy.lock ]; then flock /work/notes/heavy.lock "$@"; else "$@"; fi
}
run "base $BASE" "$BASE_BIN" "$@"
run "current $(git -C "$ROOT" rev-parse --short HEAD)" "$CURRENT" "$@"
