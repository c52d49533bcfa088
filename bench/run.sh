#!/usr/bin/env bash
# bench/run.sh [DIR_OR_FILE...] — hsr against its peers, in one run, with one table (issue 7).
#
# Inputs: every point file (.ply .xyz .xyzn .pwn .off .las .txt .pts) in the given folders / the given files;
# default: ../shared/data (next to the repository) plus the synthetic models of `hsr synth --list`,
# generated with their ground truth into the scratch folder.
# Methods per input: hsr with each partition (exhaustive, bsp, kinetic, hierarchical), with recovery and,
# when `hsr reconstruct --help` offers --no-recovery, without; polyfit_baseline; poisson_qem_baseline with
# the facet budget of hsr's default run (hierarchical) on the same input, and again with 500 faces (the budget of the
# peers' figures in ../shared/ANCHORS.md). Every output is evaluated by
# `hsr eval --json` (with --truth for synthetic inputs).
# Writes bench/results/results.csv and bench/results/results.md (bench/report.py).
#
# Environment (all optional):
#   BUILD_DIR            build folder holding hsr and bench/baselines            (default: <repo>/build)
#   BENCH_TIME_LIMIT     wall-clock limit of one run, seconds                     (default: 120)
#   BENCH_POLYFIT_LIMIT  PolyFit's own limit (reported as "timed out"), seconds   (default: 30)
#   BENCH_BUDGET         total seconds; runs after it are recorded as skipped     (default: 1500 = 25 min)
#   BENCH_SYNTH          1: add the synthetic models to the default inputs         (default: 1)
#   BENCH_OUT            results folder                                           (default: <repo>/bench/results)
#   BENCH_WORK           scratch folder (meshes, logs)                            (default: $BUILD_DIR/bench-work)
set -u

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build}
case "$BUILD_DIR" in /*) ;; *) BUILD_DIR=$ROOT/$BUILD_DIR ;; esac
HSR=$BUILD_DIR/hsr
BASELINES=$BUILD_DIR/bench/baselines
TIME_LIMIT=${BENCH_TIME_LIMIT:-120}
POLYFIT_LIMIT=${BENCH_POLYFIT_LIMIT:-30}
BUDGET=${BENCH_BUDGET:-1500}
SYNTH=${BENCH_SYNTH:-1}
OUT=${BENCH_OUT:-$ROOT/bench/results}
WORK=${BENCH_WORK:-$BUILD_DIR/bench-work}
PYTHON=/usr/bin/python3
COMMAND="bash bench/run.sh${*:+ $*}"

[ -x "$HSR" ] || { echo "bench: $HSR not found (run 'make build' first)" >&2; exit 2; }
if [ ! -x "$BASELINES/polyfit_baseline" ] || [ ! -x "$BASELINES/poisson_qem_baseline" ]; then
  # A build folder configured before bench/baselines existed does not know the targets yet: reconfigure.
  echo "bench: building the baselines in $BUILD_DIR" >&2
  cmake -S "$ROOT" -B "$BUILD_DIR" -DHSR_BUILD_BENCH=ON > /dev/null &&
    cmake --build "$BUILD_DIR" --target polyfit_baseline poisson_qem_baseline -j "$(nproc)" > /dev/null
  for b in polyfit_baseline poisson_qem_baseline; do
    [ -x "$BASELINES/$b" ] || echo "bench: warning: $BASELINES/$b not built; its rows will say so" >&2
  done
fi
timed() {  # timed LIMIT TIMEFILE CMD...: runs CMD under a wall-clock limit, GNU time's report in TIMEFILE
  local limit=$1 tf=$2; shift 2
  if [ -x /usr/bin/time ]; then timeout -k 10 "$limit" /usr/bin/time -v -o "$tf" "$@"
  else timeout -k 10 "$limit" "$@"; fi
}

rm -rf "$WORK"
mkdir -p "$WORK/runs" "$OUT"
MANIFEST=$WORK/manifest.tsv
printf 'input\tinput_path\ttruth\tmethod\tstatus\tmesh\treport\ttime\teval\tnote\n' > "$MANIFEST"

# ---- inputs: "name<TAB>path<TAB>truth"
INPUTS=$WORK/inputs.tsv
: > "$INPUTS"
add_path() {
  local p=$1 f
  if [ -d "$p" ]; then
    for f in "$p"/*; do
      case "${f,,}" in *.ply|*.xyz|*.xyzn|*.pwn|*.off|*.las|*.txt|*.pts) printf '%s\t%s\t\n' "$(basename "$f")" "$f" >> "$INPUTS" ;; esac
    done
  elif [ -f "$p" ]; then
    printf '%s\t%s\t\n' "$(basename "$p")" "$p" >> "$INPUTS"
  else
    echo "bench: warning: $p not found, skipped" >&2
  fi
}
if [ $# -gt 0 ]; then
  for p in "$@"; do add_path "$p"; done
else
  DATA=$(cd "$ROOT/.." && pwd)/shared/data
  if [ -d "$DATA" ]; then add_path "$DATA"; else echo "bench: warning: $DATA absent, real scans skipped" >&2; fi
  if [ "$SYNTH" = 1 ]; then
    for m in $("$HSR" synth --list); do
      d=$WORK/synth/$m
      if "$HSR" synth "$m" -o "$d" > "$WORK/synth_$m.log" 2>&1; then
        printf 'synth_%s\t%s\t%s\n' "$m" "$d/points.ply" "$d/truth.obj" >> "$INPUTS"
      else
        echo "bench: warning: hsr synth $m failed (see $WORK/synth_$m.log)" >&2
      fi
    done
  fi
fi
[ -s "$INPUTS" ] || { echo "bench: no inputs" >&2; exit 2; }

# ---- what this hsr supports
HELP=$("$HSR" reconstruct --help 2>&1)
RECOVERY_MODES=("rec")
if grep -q -- '--no-recovery' <<< "$HELP"; then RECOVERY_MODES=("rec" "norec"); fi
PARTITIONS=(exhaustive bsp kinetic hierarchical)

# ---- helpers
record() {  # input path truth method status mesh report time eval note
  local IFS=$'\t'
  printf '%s\n' "$*" >> "$MANIFEST"
}
over_budget() { [ "$SECONDS" -ge "$BUDGET" ]; }
last_error() {  # one line: the last line of a log that looks like an error, tabs removed
  { grep -E -i 'error|not ?implemented|hsr: |what\(\)|abort|failed' "$1" || tail -n 1 "$1"; } 2>/dev/null \
    | tail -n 1 | tr '\t' ' ' | cut -c1-160
}
evaluate() {  # input_path truth mesh out.json
  local args=("$1" "$3" --json)
  [ -n "$2" ] && args+=(--truth "$2")
  timeout "$TIME_LIMIT" "$HSR" eval "${args[@]}" > "$4" 2> "$4.log" || { rm -f "$4"; return 1; }
}

echo "bench: $(wc -l < "$INPUTS") inputs, partitions ${PARTITIONS[*]}, recovery modes ${RECOVERY_MODES[*]}, limit ${TIME_LIMIT}s per run"
while IFS=$'\t' read -r name path truth; do
  base=$WORK/runs/$name
  default_faces=""
  for part in "${PARTITIONS[@]}"; do
    for rec in "${RECOVERY_MODES[@]}"; do
      method="hsr-$part"; [ "$rec" = norec ] && method="$method-norec"
      run=$base.$method
      if over_budget; then record "$name" "$path" "$truth" "$method" skipped "" "" "" "" "bench time budget spent"; continue; fi
      args=(reconstruct "$path" -o "$run.obj" --partition "$part" --report "$run.report.json" --force)
      [ "$rec" = norec ] && args+=(--no-recovery)
      timed "$TIME_LIMIT" "$run.time" "$HSR" "${args[@]}" > "$run.log" 2>&1
      rc=$?
      if [ $rc -eq 0 ] && [ -s "$run.obj" ]; then
        if evaluate "$path" "$truth" "$run.obj" "$run.eval.json"; then
          record "$name" "$path" "$truth" "$method" ok "$run.obj" "$run.report.json" "$run.time" "$run.eval.json" ""
          if [ "$method" = hsr-hierarchical ]; then
            default_faces=$($PYTHON -c 'import json,sys; print(json.load(open(sys.argv[1]))["faces"])' "$run.eval.json" 2>/dev/null)
          fi
        else
          record "$name" "$path" "$truth" "$method" "eval failed" "$run.obj" "$run.report.json" "$run.time" "" "$(last_error "$run.eval.json.log")"
        fi
      elif [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
        record "$name" "$path" "$truth" "$method" "timed out" "" "" "" "" "limit ${TIME_LIMIT}s"
      elif grep -q -i 'NotImplemented\|not implemented\|unknown partitioner' "$run.log"; then
        record "$name" "$path" "$truth" "$method" "not implemented" "" "" "" "" "$(last_error "$run.log")"
      else
        record "$name" "$path" "$truth" "$method" failed "" "" "$run.time" "" "exit $rc: $(last_error "$run.log")"
      fi
      echo "  $name $method: $(tail -n 1 "$MANIFEST" | cut -f5)"
    done
  done

  # baselines: fixed method names, one run each
  for method in polyfit poisson_qem poisson_qem_500; do
    run=$base.$method
    if over_budget; then record "$name" "$path" "$truth" "$method" skipped "" "" "" "" "bench time budget spent"; continue; fi
    note=""
    if [ "$method" = polyfit ]; then
      exe=$BASELINES/polyfit_baseline
      args=("$path" "$run.obj" --time-limit "$POLYFIT_LIMIT" --report "$run.report.json")
    elif [ "$method" = poisson_qem_500 ]; then  # the peers' budget of ../shared/ANCHORS.md
      exe=$BASELINES/poisson_qem_baseline
      note="target 500 faces"
      args=("$path" "$run.obj" --faces 500 --time-limit "$TIME_LIMIT" --report "$run.report.json")
    else
      exe=$BASELINES/poisson_qem_baseline
      faces=${default_faces:-500}
      [ -n "$default_faces" ] && note="target $faces faces (hsr-hierarchical)" || note="target 500 faces (no hsr-hierarchical mesh)"
      args=("$path" "$run.obj" --faces "$faces" --time-limit "$TIME_LIMIT" --report "$run.report.json")
    fi
    if [ ! -x "$exe" ]; then record "$name" "$path" "$truth" "$method" "not built" "" "" "" "" "$exe missing"; continue; fi
    timed $((TIME_LIMIT + 30)) "$run.time" "$exe" "${args[@]}" > "$run.log" 2>&1
    rc=$?
    if [ $rc -eq 0 ] && [ -s "$run.obj" ]; then
      if evaluate "$path" "$truth" "$run.obj" "$run.eval.json"; then
        record "$name" "$path" "$truth" "$method" ok "$run.obj" "$run.report.json" "$run.time" "$run.eval.json" "$note"
      else
        record "$name" "$path" "$truth" "$method" "eval failed" "$run.obj" "$run.report.json" "$run.time" "" "$(last_error "$run.eval.json.log")"
      fi
    elif [ $rc -eq 3 ] || [ $rc -eq 124 ] || [ $rc -eq 137 ]; then
      lim=$TIME_LIMIT; [ "$method" = polyfit ] && lim=$POLYFIT_LIMIT
      record "$name" "$path" "$truth" "$method" "timed out" "" "$run.report.json" "$run.time" "" "limit ${lim}s"
    elif [ $rc -eq 4 ]; then
      record "$name" "$path" "$truth" "$method" crashed "" "$run.report.json" "$run.time" "" "$(last_error "$run.log")"
    else
      record "$name" "$path" "$truth" "$method" failed "" "$run.report.json" "$run.time" "" "exit $rc: $(last_error "$run.log")"
    fi
    echo "  $name $method: $(tail -n 1 "$MANIFEST" | cut -f5)"
  done
done < "$INPUTS"

MEM_KB=$(awk '/MemTotal/ {print $2}' /proc/meminfo)
"$PYTHON" "$ROOT/bench/report.py" --manifest "$MANIFEST" --out "$OUT" \
  --command "$COMMAND" --machine "$(nproc) cores, $((MEM_KB / 1024 / 1024)) GB RAM, $(uname -sr)" \
  --hsr "$("$HSR" --version 2>/dev/null | head -n 1), commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null)$(git -C "$ROOT" diff --quiet HEAD 2>/dev/null || echo ' + uncommitted changes')" \
  --limits "per run ${TIME_LIMIT}s, PolyFit ${POLYFIT_LIMIT}s" --elapsed "$SECONDS"
echo "bench: done in ${SECONDS}s: $OUT/results.md, $OUT/results.csv"
