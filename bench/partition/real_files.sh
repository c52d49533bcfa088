#!/usr/bin/env bash
# bench/partition/real_files.sh — the four partitions on every real scan in ../shared/data (issue 6).
#
# For each file and partition, runs the whole default pipeline (`hsr reconstruct --partition P`) and prints
# the partition stage's seconds, the process's peak memory, the partition's cells and facets, and the
# extracted mesh's facets, validity and mean point-to-mesh distance (% of the bbox diagonal), then the means
# over the files and whether the paper's Figure 12/15 claims hold here (hierarchical: fewer cells than
# kinetic and bsp on average, with equal or better accuracy).
# Peak memory is the whole process's (every stage), not the partition's alone.
#
# usage: bench/partition/real_files.sh [BUILD_DIR=build] [DATA_DIR=../shared/data]
# Environment: PARTITIONS (default "exhaustive bsp kinetic hierarchical"), TIME_LIMIT per run (default 300 s).
set -u
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD_DIR=${1:-$ROOT/build}
DATA=${2:-$ROOT/../shared/data}
PARTITIONS=${PARTITIONS:-"exhaustive bsp kinetic hierarchical"}
LIMIT=${TIME_LIMIT:-300}
HSR=$BUILD_DIR/hsr
[ -x "$HSR" ] || { echo "real_files: $HSR not found (run 'make build' first)" >&2; exit 2; }
[ -d "$DATA" ] || { echo "real_files: no data folder $DATA: skipped" >&2; exit 0; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

rows=$WORK/rows.tsv
: > "$rows"
for f in "$DATA"/*; do
  name=$(basename "$f")
  case "$name" in *.ply|*.xyz|*.las|*.off) ;; *) continue ;; esac
  extra=()
  case "$name" in *.off) extra=(--sample 50000) ;; esac  # meshes: sample points with face normals
  for p in $PARTITIONS; do
    report=$WORK/$name.$p.json
    timeout -k 10 "$LIMIT" "$HSR" -q reconstruct "$f" -o "$WORK/out.obj" --partition "$p" --report "$report" \
      "${extra[@]}" > /dev/null 2> "$WORK/err.txt"
    /usr/bin/python3 - "$name" "$p" "$report" "$WORK/err.txt" >> "$rows" <<'PY'
import json, sys
name, method, report, err = sys.argv[1:]
try:
    d = json.load(open(report))
    c, a = d["counts"], d["accuracy"]
    print("\t".join(map(str, [name, method, "%.3f" % d["seconds"]["partition"], "%.0f" % d["peak_memory_mb"],
                              c["cells"], c["partition_facets"], c["output_faces"],
                              "yes" if d["validity"]["valid"] else "NO", "%.3f" % (100 * a["p2m_mean"])])))
except Exception:
    msg = open(err).read().strip().splitlines()
    print("\t".join([name, method, "-", "-", "-", "-", "-", "FAILED", (msg[-1] if msg else "no report")[:60]]))
PY
  done
done

/usr/bin/python3 - "$rows" "$PARTITIONS" <<'PY'
import sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])]
methods = sys.argv[2].split()
print("| file | partition | partition s | peak MB | cells | partition facets | mesh facets | valid | p2m % |")
print("|---|---|---|---|---|---|---|---|---|")
for r in rows:
    print("| " + " | ".join(r) + " |")
files = sorted({r[0] for r in rows})
ok = [f for f in files if all(any(r[0] == f and r[1] == m and r[7] == "yes" for r in rows) for m in methods)]
print(f"\nMeans over the {len(ok)} files where every partition gave a valid mesh:\n")
print("| partition | partition s | cells | mesh facets | p2m % |")
print("|---|---|---|---|---|")
mean = {}
for m in methods:
    sel = [r for r in rows if r[1] == m and r[0] in ok]
    if not sel:
        continue
    mean[m] = [sum(float(r[i]) for r in sel) / len(sel) for i in (2, 4, 6, 8)]
    print(f"| {m} | {mean[m][0]:.3f} | {mean[m][1]:.0f} | {mean[m][2]:.1f} | {mean[m][3]:.3f} |")
if "hierarchical" in mean:
    h = mean["hierarchical"]
    for other in ("kinetic", "bsp"):
        if other in mean:
            o = mean[other]
            print(f"\nhierarchical vs {other}: fewer cells on average: {'yes' if h[1] < o[1] else 'no'} "
                  f"({h[1]:.0f} vs {o[1]:.0f}); equal or better p2m: {'yes' if h[3] <= o[3] else 'no'} "
                  f"({h[3]:.3f}% vs {o[3]:.3f}%)")
PY
