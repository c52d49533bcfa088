#!/usr/bin/env bash
# bench/scale/run.sh [POINTS...] — hsr at scale (issue 16): wall time, CPU time and peak memory, whole run
# and per stage, on two scenes at several sizes; writes bench/results/scale.md (and scale.csv).
#
# Scenes (simulated scans with their true model, so accuracy is measured against the truth as well):
#   courtyard  `hsr synth courtyard --points N`: two buildings around a courtyard, 16 planes, binary PLY
#              with normals (the issue's 3 M-point case)
#   dense      a raw scan as real scanners give it: `hsr synth dormer_house --points N --noise 0.0002`
#              (a smaller house with dormer and chimney, so denser for the same N; noise about 3 mm, fixed
#              while the density grows), normals removed (bench/scale/strip_normals.py): the normals are
#              estimated and oriented (MST) by hsr
# Default sizes: 300000 1000000 3000000, plus 10000000 when SCALE_10M=1 (needs several GB and minutes).
#
# Environment (optional):
#   BUILD_DIR  build folder with hsr (default <repo>/build)     HSR       the binary (default $BUILD_DIR/hsr)
#   SCENES     "courtyard dense"                                 OUT       results folder (default bench/results)
#   WORK       scratch folder (default $BUILD_DIR/bench-scale)   NICE      nice level of the runs (default 0)
#   HSR_THREADS is passed through (the runs' thread count; default all cores)
# Machines shared with other work make wall times noisy: the load average (uptime) is recorded with each
# run; CPU seconds and peak memory are what to compare between runs on a busy machine.
set -u
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD_DIR=${BUILD_DIR:-$ROOT/build}
HSR=${HSR:-$BUILD_DIR/hsr}
OUT=${OUT:-$ROOT/bench/results}
WORK=${WORK:-$BUILD_DIR/bench-scale}
SCENES=${SCENES:-courtyard dense}
NICE=${NICE:-0}
PY=/usr/bin/python3
SIZES=("$@")
if [ ${#SIZES[@]} -eq 0 ]; then
  SIZES=(300000 1000000 3000000)
  [ "${SCALE_10M:-0}" = 1 ] && SIZES+=(10000000)
fi
[ -x "$HSR" ] || { echo "scale: $HSR not found (make build first)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "scale: /usr/bin/time (GNU time) is needed" >&2; exit 2; }
mkdir -p "$OUT" "$WORK"

make_input() {  # make_input SCENE N -> prints the point file (made once, kept in $WORK)
  local scene=$1 n=$2 dir="$WORK/$1_$2"
  if [ ! -f "$dir/input.ply" ]; then
    case "$scene" in
      courtyard) "$HSR" synth courtyard --points "$n" -o "$dir" -q && mv "$dir/points.ply" "$dir/input.ply" ;;
      dense) "$HSR" synth dormer_house --points "$n" --noise 0.0002 -o "$dir" -q &&
               $PY "$ROOT/bench/scale/strip_normals.py" "$dir/points.ply" "$dir/input.ply" && rm "$dir/points.ply" ;;
      *) echo "scale: unknown scene $scene" >&2; return 1 ;;
    esac
  fi
  echo "$dir/input.ply"
}

ROWS="$WORK/rows.jsonl"
: > "$ROWS"
for scene in $SCENES; do
  for n in "${SIZES[@]}"; do
    input=$(make_input "$scene" "$n") || continue
    dir=$(dirname "$input")
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    echo "scale: $scene $n points (load $load)" >&2
    nice -n "$NICE" /usr/bin/time -v -o "$dir/time.txt" "$HSR" reconstruct "$input" -o "$dir/out.obj" \
      --truth "$dir/truth.obj" --report "$dir/report.json" -q > "$dir/log.txt" 2>&1
    status=$?
    $PY - "$scene" "$n" "$dir" "$status" "$load" "$(date '+%Y-%m-%d %H:%M')" >> "$ROWS" <<'PY'
import json, os, re, sys
scene, n, d, status, load, when = sys.argv[1:]
row = {"scene": scene, "target": int(n), "status": int(status), "load": load, "date": when}
t = open(os.path.join(d, "time.txt")).read()
def grab(pattern, conv=float):
    m = re.search(pattern, t)
    return conv(m.group(1)) if m else None
wall = grab(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", str)
if wall:
    parts = [float(x) for x in wall.split(":")]
    row["wall"] = parts[-1] + 60 * parts[-2] + (3600 * parts[-3] if len(parts) > 2 else 0)
row["cpu"] = (grab(r"User time \(seconds\): (\S+)") or 0) + (grab(r"System time \(seconds\): (\S+)") or 0)
row["peak_mb"] = (grab(r"Maximum resident set size \(kbytes\): (\d+)", int) or 0) / 1024
try:
    r = json.load(open(os.path.join(d, "report.json")))
    row["points"] = r["counts"]["points"]
    row["planes"] = r["counts"]["planes"]
    row["facets"] = r["counts"]["output_faces"]
    row["valid"] = r["validity"]["valid"]
    row["p2m"] = 100 * r["accuracy"]["p2m_mean"]
    row["chamfer"] = 100 * r["accuracy"].get("chamfer", float("nan"))
    row["threads"] = r.get("threads", 0)
    row["stages"] = {s: [r["seconds"][s], r.get("cpu_seconds", {}).get(s, float("nan")),
                         r.get("peak_memory_mb_after", {}).get(s, float("nan"))]
                     for s in ["structure", "visibility", "recovery", "hulls", "partition", "extraction", "eval"]
                     if s in r["seconds"]}
    row["pipeline_wall"] = r["seconds"]["total"]
    row["pipeline_cpu"] = r.get("cpu_seconds", {}).get("total", float("nan"))
except (OSError, KeyError, ValueError):
    pass
print(json.dumps(row))
PY
  done
done

MACHINE="$(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores, $(free -g | awk '/^Mem:/ {print $2}') GiB, $(uname -sr)"
$PY - "$ROWS" "$OUT/scale.md" "$OUT/scale.csv" "$HSR" "bash bench/scale/run.sh${*:+ $*}" "$MACHINE" <<'PY'
import json, math, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
md, csvp, hsr, cmd, machine = sys.argv[2:]
stages = ["structure", "visibility", "recovery", "hulls", "partition", "extraction", "eval"]
f = lambda x, p=2: "" if x is None or (isinstance(x, float) and math.isnan(x)) else ("%.*f" % (p, x))
out = ["# hsr at scale", "",
       "`%s` (binary `%s`). Whole process: wall and CPU seconds (user + system, all threads) and peak resident "
       "memory from GNU time; per stage: wall / CPU seconds and the process's peak memory when the stage ended "
       "(the run report). `other` = reading the input, writing the output and what lies between the stages. "
       "p2m: mean distance from the input points to the output, Chamfer: symmetric distance to the true model, "
       "both in %% of the bbox diagonal. Load: the load average (1, 5, 15 min) when the run started." % (cmd, hsr), "",
       "| scene | points | planes | facets | valid | p2m % | Chamfer % | wall s | CPU s | peak MB | threads | load | date |",
       "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for r in rows:
    out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
        r["scene"], "{:,}".format(r.get("points", r["target"])), r.get("planes", ""), r.get("facets", ""),
        {True: "yes", False: "no"}.get(r.get("valid"), "failed (exit %d)" % r["status"]), f(r.get("p2m"), 3),
        f(r.get("chamfer"), 3), f(r.get("wall")), f(r.get("cpu")), f(r.get("peak_mb"), 0),
        r.get("threads", "") or "all", r["load"], r["date"]))
out += ["", "Per stage, wall s / CPU s / peak MB at its end:", "",
        "| scene | points | " + " | ".join(stages) + " | other |", "|---|---|" + "---|" * (len(stages) + 1)]
for r in rows:
    st = r.get("stages", {})
    cells = ["%s / %s / %s" % (f(st[s][0]), f(st[s][1]), f(st[s][2], 0)) if s in st else "" for s in stages]
    other = ""
    if "wall" in r and "pipeline_wall" in r:
        other = "%s / %s" % (f(r["wall"] - r["pipeline_wall"]), f(r["cpu"] - r.get("pipeline_cpu", float("nan"))))
    out.append("| %s | %s | %s | %s |" % (r["scene"], "{:,}".format(r.get("points", r["target"])), " | ".join(cells), other))
# Growth: the exponent of CPU time (and peak memory) in the point count between consecutive sizes.
out += ["", "Growth between consecutive sizes: exponent e in cost ~ points^e (1 = linear):", ""]
for scene in dict.fromkeys(r["scene"] for r in rows):
    rs = sorted([r for r in rows if r["scene"] == scene and r.get("points") and r.get("cpu")], key=lambda r: r["points"])
    parts = []
    for a, b in zip(rs, rs[1:]):
        k = math.log(b["points"] / a["points"])
        parts.append("%s -> %s: CPU %.2f, wall %.2f, memory %.2f" % ("{:,}".format(a["points"]), "{:,}".format(b["points"]),
                     math.log(b["cpu"] / a["cpu"]) / k, math.log(b["wall"] / a["wall"]) / k,
                     math.log(b["peak_mb"] / a["peak_mb"]) / k))
    if parts:
        out.append("- %s: %s" % (scene, "; ".join(parts)))
# Least-squares slope of log cost against log points over all sizes of a scene.
def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
out += ["", "Cost exponent fitted over all sizes (least-squares slope of log cost on log points):", ""]
for scene in dict.fromkeys(r["scene"] for r in rows):
    rs = [r for r in rows if r["scene"] == scene and r.get("points") and r.get("cpu") and r.get("wall")]
    if len(rs) >= 2:
        xs = [r["points"] for r in rs]
        out.append("- %s: CPU %.2f, wall %.2f, peak memory %.2f" % (scene, slope(xs, [r["cpu"] for r in rs]),
                   slope(xs, [r["wall"] for r in rs]), slope(xs, [r["peak_mb"] for r in rs])))
# The issue's targets and the peers' figures for the 3 M-point courtyard (ANCHORS.md, same machine type).
out += ["", "Targets (issue 16) and the 3 M-point courtyard against ANCHORS.md (KSR 20.7 s, 750 MB; hsr before "
        "this work 50.5 s, 1.42 GB):", ""]
for r in rows:
    if r["scene"] != "courtyard" or "wall" not in r:
        continue
    if r["target"] == 3000000:
        out.append("- courtyard 3 M: %.2f s wall (target 10: %s), %.0f MB peak (target 750: %s); %.2fx KSR's wall time, "
                   "%.2fx its memory; %.2fx the old hsr's time, %.2fx its memory" % (
                       r["wall"], "met" if r["wall"] <= 10 else "not met", r["peak_mb"],
                       "met" if r["peak_mb"] <= 750 else "not met", r["wall"] / 20.7, r["peak_mb"] / 750,
                       r["wall"] / 50.5, r["peak_mb"] / 1420))
    if r["target"] == 10000000:
        out.append("- courtyard 10 M: %.2f s wall (target 40: %s), %.0f MB peak (target 3000: %s)" % (
            r["wall"], "met" if r["wall"] <= 40 else "not met", r["peak_mb"], "met" if r["peak_mb"] <= 3000 else "not met"))
out += ["", "Machine: " + machine]
open(md, "w").write("\n".join(out) + "\n")
with open(csvp, "w") as c:
    c.write("scene,points,planes,facets,valid,p2m_pct,chamfer_pct,wall_s,cpu_s,peak_mb,threads,load,date\n")
    for r in rows:
        c.write(",".join(str(x) for x in [r["scene"], r.get("points", r["target"]), r.get("planes", ""), r.get("facets", ""),
                 r.get("valid", ""), f(r.get("p2m"), 4), f(r.get("chamfer"), 4), f(r.get("wall")), f(r.get("cpu")),
                 f(r.get("peak_mb"), 0), r.get("threads", ""), r["load"].replace(" ", "/"), r["date"]]) + "\n")
print("\n".join(out))
PY
