#!/usr/bin/env bash
# bench/scale/shared.sh HSR OUTDIR — runs `HSR reconstruct` (default parameters) on every scan of
# ../shared/data and ../shared/airborne, keeps each output mesh and report in OUTDIR, and writes
# OUTDIR/summary.tsv (file, planes, facets, p2m mean %, valid, seconds). Two OUTDIRs made by two builds are
# compared by bench/scale/compare_shared.py (planes, facets, p2m, identical output bytes).
# Extra arguments after OUTDIR go to every `hsr reconstruct` call.
set -u
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
HSR=${1:?usage: shared.sh HSR OUTDIR [reconstruct options]}
OUT=${2:?usage: shared.sh HSR OUTDIR [reconstruct options]}
shift 2
mkdir -p "$OUT"
printf 'file\tplanes\tfacets\tp2m_pct\tvalid\tseconds\n' > "$OUT/summary.tsv"
for dir in "$ROOT/../shared/data" "$ROOT/../shared/airborne"; do
  [ -d "$dir" ] || { echo "shared.sh: $dir absent, skipped" >&2; continue; }
  for f in "$dir"/*; do
    case "$f" in *_city3d.obj|*.tsv|*.md) continue ;; esac
    name=$(basename "$f")
    stem=${name%.*}
    if ! nice -n 10 "$HSR" reconstruct "$f" -o "$OUT/$stem.obj" --report "$OUT/$stem.json" -q "$@" \
        > "$OUT/$stem.log" 2>&1; then
      printf '%s\tfailed\t\t\t\t\n' "$name" >> "$OUT/summary.tsv"
      continue
    fi
    /usr/bin/python3 - "$OUT/$stem.json" "$name" >> "$OUT/summary.tsv" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
v = j["validity"]
valid = all(v.get(k, False) for k in ("closed", "manifold", "oriented", "self_intersection_free", "bounds_volume"))
print("\t".join([sys.argv[2], str(j["counts"]["planes"]), str(j["counts"]["output_faces"]),
                 "%.4f" % (100 * j["accuracy"]["p2m_mean"]), "yes" if valid else "no",
                 "%.2f" % j["seconds"]["total"]]))
PY
  done
done
cat "$OUT/summary.tsv"
