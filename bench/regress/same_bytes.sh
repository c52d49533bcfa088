#!/usr/bin/env bash
# Same bytes before and after a restructuring (issue 39): runs one hsr binary on every shared scan, the 112
# shared buildings, their variants (bench/building/variants.py), the synth models, two halls and a synth city
# tile, and prints one line per input: NAME, exit code, md5 of the model (or of the city's CityJSONSeq).
# Compare two binaries with:  diff <(bench/regress/same_bytes.sh OLD out-old) <(bench/regress/same_bytes.sh NEW out-new)
#   bench/regress/same_bytes.sh HSR OUT [SHARED] [JOBS]
# The variants and synth inputs are made once into OUT/../regress-inputs (with the given binary) and reused.
set -uo pipefail
hsr=$(realpath "$1"); out=$2; shared=${3:-$(dirname "$0")/../../../shared}; jobs=${4:-2}
here=$(cd "$(dirname "$0")" && pwd)
inputs=$(realpath -m "$out/../regress-inputs")
mkdir -p "$out" "$inputs"
if [ ! -f "$inputs/.made" ]; then
  /usr/bin/python3 "$here/../building/variants.py" "$inputs/variants" >/dev/null
  for m in $("$hsr" synth --list | grep -v '^city$'); do
    extra=(); [ "$m" = hall ] && extra=(--planes 200)
    "$hsr" synth "$m" -o "$inputs/synth_$m" "${extra[@]}" >/dev/null 2>&1
  done
  "$hsr" synth hall --planes 500 -o "$inputs/synth_hall500" >/dev/null 2>&1
  "$hsr" synth city --buildings 20 -o "$inputs/synth_city" >/dev/null 2>&1
  touch "$inputs/.made"
fi
list=$(mktemp)
for f in "$shared"/data/* "$shared"/repro/* "$shared"/airborne/*.ply "$shared"/airborne_more/*.ply \
         "$inputs"/variants/*/*.ply "$inputs"/synth_*/points.ply; do
  case "$f" in *MANIFEST*|*_city3d.*|*.md) continue ;; esac
  [ -f "$f" ] && echo "$f"
done > "$list"
one() {  # INPUT -> "name rc md5"
  local f=$1 name
  name=$(echo "$f" | sed "s|.*/shared/||; s|.*/regress-inputs/||; s|/|__|g")
  "$hsr" -q reconstruct "$f" -o "$out/$name.obj" >"$out/$name.log" 2>&1
  local rc=$?
  local sum=-; [ -f "$out/$name.obj" ] && sum=$(md5sum < "$out/$name.obj" | cut -c1-32)
  echo "$name $rc $sum"
}
export -f one; export hsr out
xargs -P "$jobs" -I{} bash -c 'one "$@"' _ {} < "$list" | sort
rm -f "$list"
if [ -f "$inputs/synth_city/points.las" ] || ls "$inputs"/synth_city/*.la? >/dev/null 2>&1; then
  tile=$(ls "$inputs"/synth_city/*.la? | head -1)
  rm -rf "$out/city"
  "$hsr" -q city "$tile" -o "$out/city" -j "$jobs" >"$out/city.log" 2>&1
  rc=$?
  for f in $(cd "$out/city" 2>/dev/null && ls *.jsonl 2>/dev/null); do echo "city__$f $rc $(md5sum < "$out/city/$f" | cut -c1-32)"; done
fi
