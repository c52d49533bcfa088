#!/usr/bin/env bash
# The functions a usual run of the CLI executes, as the section names the link of build/hsr lays side by side
# (apps/hsr/hot_text.txt, read by gold's --section-ordering-file; DECISIONS #243). Why: a run maps the program's
# code 64 KiB at a time around each page it touches (the kernel's fault-around), and the 1.6 MB of functions a
# room's reconstruction runs were spread over 5.2 MB of code among the synth, city and tiles code: 3.8 MB of it
# resident. Side by side they take about what they are.
# The runs: `hsr reconstruct` on a one-room office, the synth house and the mixed aerial building (a room's, a
# building's and an airborne scan's paths), under valgrind's callgrind (one thread), then natively under perf where
# it is installed. The list only orders code: a stale list costs memory, never a different result. Rerun it on a
# build of the program (its objects name the sections) after large changes; tests/cli checks the list still
# names most of the program's functions.
#   scripts/hot_text.sh [HSR] [OUT]      (defaults: build/hsr, apps/hsr/hot_text.txt; HSR in its build folder)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
hsr=$(realpath "${1:-$here/build/hsr}")
out=${2:-$here/apps/hsr/hot_text.txt}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$hsr" -q synth office --rooms 1 --seed 1 -o "$work/office" >/dev/null
"$hsr" -q synth house -o "$work/house" >/dev/null
"$hsr" -q synth aerial_mixed -o "$work/aerial" >/dev/null
# --force: valgrind keeps SSE in round-to-nearest where CGAL's interval filters ask for rounding up, so a model may
# come out other than natively (and be refused as invalid); the functions run are the same but for a few.
for scene in office house aerial; do
  HSR_THREADS=1 valgrind --tool=callgrind --demangle=no --dump-instr=no --callgrind-out-file="$work/$scene.cg" \
    "$hsr" -q reconstruct "$work/$scene/points.ply" -o "$work/$scene/model.obj" --force >/dev/null 2>&1 || true
done
# Natively, where perf is at hand: the functions whose code a run faulted in (the first fetch in each 64 KiB), which
# callgrind does not see run: CGAL's exact fallbacks where an interval filter fails natively, TBB's task stealing.
# Run on a program already laid out by a list, they are the ones that list misses.
: > "$work/faults.txt"
if command -v perf >/dev/null; then
  for scene in office house aerial; do
    perf record -q -e page-faults -c 1 -d -o "$work/$scene.perf" \
      "$hsr" -q reconstruct "$work/$scene/points.ply" -o "$work/$scene/model.obj" >/dev/null 2>&1 || true
    perf script -i "$work/$scene.perf" -F addr,ip,sym,dso --no-demangle 2>/dev/null >> "$work/faults.txt" || true
  done
fi
# Each function of the program that ran, in the order callgrind first lists it (roughly the order of its first
# call), then those only the native runs faulted in, once, as the name of the section that holds it in the build's objects (read with readelf: a constructor's
# C1 symbol lives in its C2 section, a function GCC deems cold in .text.unlikely.NAME, main in .text.startup.main).
objects=$(find "$(dirname "$hsr")/src" "$(dirname "$hsr")/apps/hsr" -name '*.o')
HOT_TEXT_OBJECTS="$objects" HOT_TEXT_FAULTS="$work/faults.txt" /usr/bin/python3 - "$hsr" "$work"/office.cg "$work"/house.cg "$work"/aerial.cg > "$out" <<'EOF2'
import os, re, subprocess, sys
program, seen, names = sys.argv[1], set(), []
for path in sys.argv[2:]:
    objects, functions, current = {}, {}, None
    for line in open(path):
        m = re.match(r"^(c?ob)=\((\d+)\)(?: (.*))?", line)
        if m:
            if m.group(3):
                objects[m.group(2)] = m.group(3).strip()
            if m.group(1) == "ob":
                current = objects[m.group(2)]
            continue
        m = re.match(r"^(c?fn)=\((\d+)\)(?: (.*))?", line)
        if m:
            if m.group(3):
                functions[m.group(2)] = re.sub(r"'\d+$", "", m.group(3).strip())
            name = functions[m.group(2)]
            if m.group(1) == "fn" and current == program and name not in seen and not name.startswith("0x"):
                seen.add(name)
                names.append(name)
sections_of = {}  # function symbol -> the names of the sections that hold it, over the build's objects (a file's
for obj in os.environ["HOT_TEXT_OBJECTS"].split():  # own symbols, its static initialiser among them, recur in others)
    text = subprocess.run(["readelf", "-SW", "-sW", obj], capture_output=True, text=True).stdout
    sections = dict(re.findall(r"^\s*\[\s*(\d+)\]\s+(\.text\S*)", text, re.M))
    for index, symbol in re.findall(r"^\s*\d+:\s+\S+\s+\d+\s+FUNC\s+\S+\s+\S+\s+(\d+)\s+(\S+)$", text, re.M):
        if index in sections:
            sections_of.setdefault(symbol, []).append(sections[index])
for line in open(os.environ["HOT_TEXT_FAULTS"]):  # "ADDR SYM (DSO) IP SYM (DSO)": a fetch where ADDR's page is IP's
    m = re.match(r"\s*([0-9a-f]+)\s+\S+\s+\((\S+)\)\s+([0-9a-f]+)\s+(\S+)\s+\((\S+)\)", line)
    if m and os.path.realpath(m.group(5)) == program and int(m.group(1), 16) >> 12 == int(m.group(3), 16) >> 12:
        if m.group(4) not in seen:
            seen.add(m.group(4))
            names.append(m.group(4))
printed = set()
for name in names:
    for section in sections_of.get(name, []):
        if section != ".text" and section not in printed:
            printed.add(section)
            print(section)
EOF2
echo "hot_text: $(wc -l < "$out") functions in $out"
