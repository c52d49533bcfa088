#!/usr/bin/python3
"""City-scale throughput of `hsr batch` and of the Dask driver `python3 -m hsr.batch` (README "City scale").

    PYTHONPATH=build/python /usr/bin/python3 bench/city/city_bench.py [INPUT...] [--synth N]
        [--synth-models box,house,...] [--synth-points P] [--airborne DIR] [--workers 1,2] [--work DIR]
        [--out bench/results/city.md]

Inputs: the given point files; with none, the *.ply scans of ../shared/airborne (not the *_city3d.obj models)
plus N synth buildings made by `hsr synth MODEL --seed S --points P` (models cycled, seeds 1, 2, ...), so
the lead can rerun it on other inputs (e.g. aerial synth models: --synth-models a,b or a list of files).
Runs, each into a fresh folder, timed on the wall clock with the load average before it:
  1. `hsr batch --format obj -j 2` (the reference OBJ outputs);
  2. `hsr batch --format city.json -j W` and `python3 -m hsr.batch --format city.json --workers W` per W;
  3. the in-process loop of the Python module (read_points + reconstruct, no file written, one process):
     what a child process per input costs.
Checks: every CityJSON output decodes (the module's read_mesh) to a solid that eval's check_validity
(hsr.evaluate) finds valid and that equals the OBJ output (same faces, vertices within half a grid step);
the CityJSONSeq holds every successful building with the same integers shifted; the Dask driver's files
and summary equal hsr batch's (timings aside). Writes a markdown report (--out) and prints it.
"""
import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

import hsr

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUTDOOR = ["house", "dormer_house", "courtyard", "box"]


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("inputs", nargs="*")
    p.add_argument("--synth", type=int, default=100, help="synth buildings added when no input is given")
    p.add_argument("--synth-models", default=",".join(OUTDOOR))
    p.add_argument("--synth-points", type=int, default=10000)
    p.add_argument("--airborne", default=os.path.join(ROOT, "..", "shared", "airborne"))
    p.add_argument("--workers", default="1,2", help="worker counts to time")
    p.add_argument("--work", default=os.path.join(ROOT, "build", "bench-city"))
    p.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "city.md"))
    p.add_argument("--hsr", default=hsr._hsr._cli_path())
    return p.parse_args()


def make_inputs(args):
    if args.inputs:
        return [os.path.abspath(p) for p in args.inputs]
    paths = []
    if os.path.isdir(args.airborne):
        paths += sorted(os.path.join(args.airborne, f) for f in os.listdir(args.airborne)
                        if f.endswith(".ply"))
    models = args.synth_models.split(",")
    for k in range(args.synth):
        model, seed = models[k % len(models)], k // len(models) + 1
        d = os.path.join(args.work, "synth", "%s_%03d" % (model, seed))
        if not os.path.exists(os.path.join(d, "points.ply")):
            subprocess.run([args.hsr, "synth", model, "-o", d, "--seed", str(seed),
                            "--points", str(args.synth_points), "-q"], check=True)
        paths.append(os.path.join(d, "points.ply"))
    return paths


def timed(name, cmd, out_dir):
    subprocess.run(["rm", "-rf", out_dir], check=True)
    before = load()
    cpu0 = cpu_seconds(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    cpu = cpu_seconds(resource.RUSAGE_CHILDREN) - cpu0
    if r.returncode not in (0, 1):
        sys.exit("%s failed (%d): %s" % (name, r.returncode, r.stderr[-2000:]))
    rows = read_summary(out_dir)
    ok = sum(row["status"] == "ok" for row in rows)
    return {"run": name, "wall": wall, "cpu": cpu, "inputs": len(rows), "ok": ok, "per_min": 60.0 * ok / wall,
            "load": before, "dir": out_dir}


def cpu_seconds(who):
    """User + system CPU seconds of this process (RUSAGE_SELF) or of its waited-for descendants."""
    ru = resource.getrusage(who)
    return ru.ru_utime + ru.ru_stime


def read_summary(d):
    with open(os.path.join(d, "summary.csv"), newline="") as f:
        return list(csv.DictReader(f))


def in_process(inputs):
    """Sequential reconstruct of every input in this process (the module; no output written)."""
    before = load()
    cpu0 = cpu_seconds(resource.RUSAGE_SELF)
    t0 = time.monotonic()
    ok = 0
    for p in inputs:
        scan = hsr.read_points(p)
        try:
            hsr.reconstruct(scan["points"], scan["normals"])
            ok += 1
        except hsr.Error:
            pass
    wall = time.monotonic() - t0
    return {"run": "in-process loop (Python module, 1 process, no file written)", "wall": wall,
            "cpu": cpu_seconds(resource.RUSAGE_SELF) - cpu0,
            "inputs": len(inputs), "ok": ok, "per_min": 60.0 * ok / wall, "load": before, "dir": ""}


def strip_seconds(o):
    if isinstance(o, dict):
        return {k: strip_seconds(v) for k, v in o.items() if k != "hsr_seconds"}
    if isinstance(o, list):
        return [strip_seconds(v) for v in o]
    return o


def same_files(a, b):
    """Names of the CityJSON files that differ between two runs (timings aside), and whether the summaries
    agree without their seconds column."""
    differ = []
    for name in sorted(os.listdir(a)):
        if name.endswith(".city.json") or name.endswith(".city.jsonl"):
            with open(os.path.join(a, name)) as fa, open(os.path.join(b, name)) as fb:
                if [strip_seconds(json.loads(x)) for x in fa] != [strip_seconds(json.loads(x)) for x in fb]:
                    differ.append(name)
    cut = lambda rows: [{k: v for k, v in r.items() if k != "seconds"} for r in rows]
    return differ, cut(read_summary(a)) == cut(read_summary(b))


def decoded_features(seq_path):
    """{id: (vertices as global coordinates, faces)} of a CityJSONSeq."""
    with open(seq_path) as f:
        header = json.loads(f.readline())
        scale = np.array(header["transform"]["scale"])
        translate = np.array(header["transform"]["translate"])
        out = {}
        for line in f:
            feat = json.loads(line)
            b = feat["CityObjects"][feat["id"]]
            faces = [ring[0] for ring in b["geometry"][0]["boundaries"][0]]
            out[feat["id"]] = (np.array(feat["vertices"], dtype=float) * scale + translate, faces)
    return out


def check_outputs(inputs, obj_dir, city_dir, scale=0.001):
    """Per input: CityJSON solid valid and equal to the OBJ; the sequence's copy equal to the file."""
    rows = read_summary(city_dir)
    feats = decoded_features(os.path.join(city_dir, "buildings.city.jsonl"))
    checked, problems, max_dev, merged = 0, [], 0.0, 0
    names = sorted(f[: -len(".report.json")] for f in os.listdir(city_dir) if f.endswith(".report.json"))
    by_input = {}
    for n in names:
        with open(os.path.join(city_dir, n + ".report.json")) as f:
            by_input[json.load(f)["input"]] = n
    for row in rows:
        if row["status"] != "ok":
            continue
        name = by_input[row["input"]]
        city = hsr.read_mesh(os.path.join(city_dir, name + ".city.json"))
        ref = hsr.read_mesh(os.path.join(obj_dir, name + ".obj"))
        scan = hsr.read_points(row["input"])
        valid = hsr.evaluate(scan["points"], city["vertices"], city["faces"], samples=1000)["valid"]
        city_faces = [list(f) for f in city["faces"]]
        same, dev = compare_to_obj(city, ref)
        merged += same == "merged"
        max_dev = max(max_dev, dev)
        fv, ff = feats.get(name, (None, None))
        in_seq = fv is not None and ff == city_faces and np.abs(fv - city["vertices"]).max() < 1e-6
        if not (valid and same and dev <= scale / 2 * (1 + 1e-6) and in_seq):
            problems.append("%s: valid %s, equal to the OBJ %s, max deviation %.3g, in sequence %s" % (
                name, valid, same or False, dev, in_seq))
        checked += 1
    return {"checked": checked, "problems": problems, "max_dev": max_dev, "features": len(feats), "merged": merged,
            "names": by_input, "dir": city_dir}


def compare_to_obj(city, ref):
    """("equal" | "merged" | None, max deviation): each OBJ vertex's nearest CityJSON vertex (per-axis
    distance) and the OBJ faces through that map ("merged": equal once the vertices that rounding put on
    one grid point are one, repeated ring vertices and collapsed faces dropped, as the writer does)."""
    cv, rv = city["vertices"], ref["vertices"]
    d = np.abs(rv[:, None, :] - cv[None, :, :]).max(axis=2)
    nearest, dev = d.argmin(axis=1), float(d.min(axis=1).max())
    faces = []
    for f in ref["faces"]:
        faces += [canonical(r) for r in split_ring(clean_ring([int(nearest[v]) for v in f])) if len(r) >= 3]
    if sorted(faces) != sorted(canonical(list(map(int, f))) for f in city["faces"]):
        return None, dev
    return ("equal" if len(cv) == len(rv) else "merged"), dev


def clean_ring(ring):
    ring = [v for k, v in enumerate(ring) if k == 0 or v != ring[k - 1]]
    while len(ring) > 1 and ring[-1] == ring[0]:
        ring.pop()
    return ring


def split_ring(ring):
    """A ring that visits a vertex twice, split there into rings that do not (as the writer does)."""
    for i in range(len(ring)):
        for j in range(i + 1, len(ring)):
            if ring[i] == ring[j]:
                return split_ring(clean_ring(ring[i:j])) + split_ring(clean_ring(ring[j:] + ring[:i]))
    return [ring]


def canonical(ring):
    k = ring.index(min(ring))
    return ring[k:] + ring[:k]


def startup_seconds(cli):
    times = []
    for _ in range(10):
        t0 = time.monotonic()
        subprocess.run([cli, "--version"], capture_output=True, check=True)
        times.append(time.monotonic() - t0)
    return statistics.median(times)


def points_note(args):
    """The aerial_* models' size comes from their roof density (10 points/m²), not from --points."""
    if all(m.startswith("aerial_") for m in args.synth_models.split(",")):
        return "10 points per m² of roof"
    return "%d points each" % args.synth_points


def report(args, inputs, runs, checks, agree, startup, city_rows):
    n_air = sum("airborne" in p for p in inputs)
    lines = ["# City scale: hsr batch and the Dask driver", "",
             "`%s` on %s, %d inputs (%d airborne scans, %d synth buildings: %s, %s)." % (
                 " ".join(["bench/city/city_bench.py"] + sys.argv[1:]), time.strftime("%Y-%m-%d %H:%M"),
                 len(inputs), n_air, len(inputs) - n_air, args.synth_models, points_note(args)),
             "Machine: %d cores shared with other engineers; load average (1, 5, 15 min) before each run." % os.cpu_count(),
             "CPU s: user + system time of the run's processes (less sensitive to the others' load than the wall clock).",
             "", "| run | workers | wall s | CPU s | inputs | ok | buildings / min | load before |", "|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append("| %s | %s | %.1f | %.1f | %d | %d | %.1f | %s |" % (
            r["run"], r.get("workers", "1"), r["wall"], r["cpu"], r["inputs"], r["ok"], r["per_min"], r["load"]))
    secs = [float(r["seconds"]) for r in city_rows if r["status"] == "ok"]
    lines += ["", "Mean pipeline seconds per ok input (report `seconds.total`): %.3f; `hsr --version` start-up: %.1f ms." % (
        statistics.mean(secs) if secs else 0, 1000 * startup), ""]
    lines += ["Checks on the CityJSON of `hsr batch -j %s`: %d ok buildings decoded (valid by eval's check_validity, "
              "equal to the OBJ output), %d problems; %d of them equal only once the vertices that rounding to the grid "
              "merged are one (and a ring that then touched itself is split, as the writer does); max |CityJSON - OBJ| vertex deviation %.2g (grid 0.001, so <= 0.0005 expected); the "
              "sequence holds %d features, each equal to its building's file." % (
                  args.workers.split(",")[-1], checks["checked"], len(checks["problems"]), checks["merged"],
                  checks["max_dev"], checks["features"])]
    lines += ["- " + p for p in checks["problems"]]
    finer = []
    for r in city_rows:
        name = checks["names"].get(r["input"])
        if name:
            with open(os.path.join(checks["dir"], name + ".city.json")) as f:
                scale = json.load(f)["transform"]["scale"][0]
            if scale < 0.001:
                finer.append("%s (%g)" % (name, scale))
    lines += ["", "Written on a finer grid than 1 mm because rounding to 1 mm broke the solid: %s." % (
        ", ".join(finer) if finer else "none")]
    lines += ["", "Dask driver vs hsr batch (same worker count): " + "; ".join(agree), ""]
    statuses = {}
    for r in city_rows:
        statuses.setdefault(r["status"], []).append(os.path.relpath(r["input"], ROOT + "/.."))
    lines += ["Statuses: " + "; ".join("%s %d" % (k, len(v)) for k, v in sorted(statuses.items()))]
    for k, v in sorted(statuses.items()):
        if k != "ok":
            lines += ["- %s: %s" % (k, ", ".join(v))]
    lines += ["", "Airborne rows of the summary:", "", "| input | status | seconds | facets | validity | p2m_mean |",
              "|---|---|---|---|---|---|"]
    for r in city_rows:
        if "airborne" in r["input"]:
            lines.append("| %s | %s | %s | %s | %s | %s |" % (os.path.basename(r["input"]), r["status"], r["seconds"],
                                                             r["facets"], r["validity"], r["p2m_mean"]))
    return "\n".join(lines) + "\n"


def main():
    args = parse_args()
    os.makedirs(args.work, exist_ok=True)
    inputs = make_inputs(args)
    workers = [int(w) for w in args.workers.split(",")]
    py = [sys.executable, "-m", "hsr.batch"]
    out = lambda name: os.path.join(args.work, name)
    runs = [timed("hsr batch --format obj", [args.hsr, "batch"] + inputs + ["-o", out("obj"), "-j", str(max(workers)), "-q"], out("obj"))]
    runs[0]["workers"] = str(max(workers))
    agree = []
    for w in workers:
        for name, cmd in (("hsr batch --format city.json", [args.hsr, "batch"] + inputs + ["-o", out("cli%d" % w), "-j", str(w), "-q"]),
                          ("python3 -m hsr.batch --format city.json", py + inputs + ["-o", out("dask%d" % w), "--workers", str(w), "-q"])):
            r = timed(name, cmd + ["--format", "city.json"], out(("cli%d" if "hsr batch" in name else "dask%d") % w))
            r["workers"] = str(w)
            runs.append(r)
            print("%s workers %d: %.1f s, %.1f buildings/min (load %s)" % (name, w, r["wall"], r["per_min"], r["load"]), flush=True)
        differ, summaries = same_files(out("cli%d" % w), out("dask%d" % w))
        agree.append("%d workers: %d CityJSON files differ, summaries %s" % (w, len(differ), "equal" if summaries else "DIFFER"))
    if len(workers) > 1:
        differ, summaries = same_files(out("cli%d" % workers[0]), out("cli%d" % workers[-1]))
        agree.append("hsr batch -j %d vs -j %d: %d files differ, summaries %s" % (workers[0], workers[-1], len(differ),
                                                                               "equal" if summaries else "DIFFER"))
    runs.append(in_process(inputs))
    checks = check_outputs(inputs, out("obj"), out("cli%d" % max(workers)))
    text = report(args, inputs, runs, checks, agree, startup_seconds(args.hsr), read_summary(out("cli%d" % max(workers))))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
