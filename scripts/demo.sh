#!/usr/bin/env bash
# make demo: synthesise the default model, reconstruct it, and evaluate the result against the truth.
# Usage: scripts/demo.sh BUILD_DIR MODEL OUT_DIR
set -euo pipefail
build=${1:-build}
model=${2:-house}
out=${3:-$build/demo}
hsr="$build/hsr"
mkdir -p "$out"
echo "== hsr synth $model -o $out"
"$hsr" synth "$model" -o "$out"
echo "== hsr reconstruct $out/points.ply -o $out/model.obj --truth $out/truth.obj"
# reconstruct checks and evaluates its output before writing it, and prints the evaluation (the same
# numbers as `hsr eval $out/points.ply $out/model.obj --truth $out/truth.obj`).
"$hsr" reconstruct "$out/points.ply" -o "$out/model.obj" --report "$out/report.json" --truth "$out/truth.obj"
echo "demo: outputs in $out (model.obj, report.json; open model.obj in any mesh viewer)"
