#!/usr/bin/env bash
# make demo: synthesise the default model, reconstruct it, evaluate the result against the truth, and write a
# page that shows the model over its points.
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
"$hsr" reconstruct "$out/points.ply" -o "$out/model.obj" --report "$out/report.json" --truth "$out/truth.obj" \
  --html "$out/model.html"
echo "demo: outputs in $out: model.html (the model over its points: open it in a browser), model.obj (any mesh"
echo "      viewer), report.json; with Chromium installed, 'hsr render $out/model.obj $out/points.ply -o x.png'"
