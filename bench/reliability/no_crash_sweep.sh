#!/bin/bash
# No-crash sweep (issue 15): `hsr reconstruct` with the defaults on every scan of the shared data (mesh inputs
# also with --sample 20000), every airborne scan and every `hsr synth --list` model; one TSV row each: exit
# status, the signal if the process died of one (exit >= 128), seconds, first line of its output.
# Usage: bench/reliability/no_crash_sweep.sh [HSR_BINARY] [SCRATCH_DIR] > results.tsv   (run it under the lock)
H=${1:-build/hsr}
SCRATCH=${2:-/tmp/hsr_no_crash}
DATA=${HSR_SHARED_DATA_DIR:-../shared/data}
AIRBORNE=${HSR_SHARED_AIRBORNE_DIR:-../shared/airborne}
mkdir -p "$SCRATCH/out"
echo -e "input\textra\texit\tsignal\tseconds\tmessage"
run() {  # name file extra...
  local name=$1 file=$2; shift 2
  local t0 t1 rc sig=-
  t0=$(date +%s.%N)
  timeout -s KILL 900 nice -n 10 "$H" reconstruct -q "$file" -o "$SCRATCH/out/$name.obj" \
    --report "$SCRATCH/out/$name.json" --max-seconds 600 "$@" > "$SCRATCH/out/$name.err" 2>&1
  rc=$?
  t1=$(date +%s.%N)
  [ $rc -ge 128 ] && sig=$((rc - 128))
  echo -e "$name\t$*\t$rc\t$sig\t$(printf %.1f "$(echo "$t1 - $t0" | bc)")\t$(head -1 "$SCRATCH/out/$name.err" | head -c 200)"
}
for f in "$DATA"/*; do
  b=$(basename "$f"); [ "$b" = MANIFEST.tsv ] && continue
  run "data_$b" "$f"
  case $b in *.off|stanford_bun_zipper.ply) run "data_${b}_sample" "$f" --sample 20000;; esac
done
for f in "$AIRBORNE"/*.ply; do run "airborne_$(basename "$f")" "$f"; done
for m in $("$H" synth --list); do
  "$H" synth "$m" -q -o "$SCRATCH/synth_$m" > /dev/null 2>&1
  run "synth_$m" "$SCRATCH/synth_$m/points.ply"
done
