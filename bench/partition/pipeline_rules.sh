#!/usr/bin/env bash
# bench/partition/pipeline_rules.sh KEY=VALUE... — the whole pipeline (`hsr reconstruct`, every stage with its
# defaults, building mode where the scene says so) on the 10 shared scans and the 6 synth models, once with the
# default partition parameters and once with PartitionParams fields overridden (JSON names, e.g.
# wait_at_bounds=false trim=false), through `--config`. Prints per input and in total: cells, output faces,
# faces under 0.1 % of the area, validity, p2m mean (% of the bbox diagonal); then the totals and the mean p2m.
# (bench_partition_scans runs the stages by hand without the scene stage: its building inputs differ.)
# Environment: BUILD_DIR (default <repo>/build), DATA (default /work/shared/data), WORK (default a temp dir).
set -eu
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
HSR=${BUILD_DIR:-$ROOT/build}/hsr
DATA=${DATA:-/work/shared/data}
WORK=${WORK:-$(mktemp -d)}
PY=/usr/bin/python3
[ -x "$HSR" ] || { echo "pipeline_rules: $HSR not found" >&2; exit 2; }
[ $# -ge 1 ] || { echo "usage: pipeline_rules.sh KEY=VALUE..." >&2; exit 2; }
mkdir -p "$WORK"
for m in box house dormer_house bracket room courtyard; do
  [ -f "$WORK/synth_$m/points.ply" ] || "$HSR" synth "$m" -o "$WORK/synth_$m" > /dev/null
done
inputs=()
for f in "$DATA"/*.ply "$DATA"/*.xyz "$DATA"/*.las "$DATA"/*.off "$WORK"/synth_*/points.ply; do
  [ -f "$f" ] && inputs+=("$f")
done
run() {  # run NAME FILE CONFIG_ARGS...
  local name=$1 f=$2; shift 2
  local truth=()
  [ -f "$(dirname "$f")/truth.obj" ] && truth=(--truth "$(dirname "$f")/truth.obj")
  local base
  base=$(echo "$f" | sed "s|$DATA/||; s|$WORK/||; s|/points.ply||")
  "$HSR" reconstruct "$f" -o "$WORK/$base.$name.obj" --report "$WORK/$base.$name.json" "${truth[@]}" "$@" \
    > "$WORK/$base.$name.log" 2>&1 || echo "pipeline_rules: $base ($name) failed, see $WORK/$base.$name.log" >&2
}
for f in "${inputs[@]}"; do run default "$f"; done
# The override config: the parameters of a default run's report with the fields replaced.
first=$(ls "$WORK"/*.default.json | head -1)
$PY - "$first" "$WORK/override.json" "$@" << 'EOF'
import json, sys
r = json.load(open(sys.argv[1]))
for kv in sys.argv[3:]:
    k, v = kv.split("=", 1)
    if k not in r["parameters"]["partition"]: sys.exit("pipeline_rules: unknown partition field " + k)
    r["parameters"]["partition"][k] = json.loads(v)
json.dump(r, open(sys.argv[2], "w"))
EOF
for f in "${inputs[@]}"; do run override "$f" --config "$WORK/override.json"; done
$PY - "$WORK" << 'EOF'
import glob, json, os, sys
w = sys.argv[1]
names = sorted(os.path.basename(f)[:-len(".default.json")] for f in glob.glob(w + "/*.default.json"))
total = {}
print("%-30s %-9s %6s %6s %6s %6s %8s" % ("input", "run", "cells", "faces", "small", "valid", "p2m%"))
for n in names:
    for run in ("default", "override"):
        r = json.load(open("%s/%s.%s.json" % (w, n, run)))
        row = (r["counts"]["cells"], r["counts"]["output_faces"], r["face_sizes"]["small_faces"],
               r["validity"]["valid"], 100 * r["accuracy"]["p2m_mean"])
        t = total.setdefault(run, [0, 0, 0, 0, 0.0, 0])
        for i in range(4): t[i] += int(row[i])
        t[4] += row[4]; t[5] += 1
        print("%-30s %-9s %6d %6d %6d %6s %8.3f" % ((n, run) + row))
for run, t in total.items():
    print("%s: %d inputs, %d valid, cells %d, faces %d, small faces %d, mean p2m %.4f %%" %
          (run, t[5], t[3], t[0], t[1], t[2], t[4] / t[5]))
EOF
