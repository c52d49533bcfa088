#!/usr/bin/env python3
"""`hsr city` on whole tiles (issue 27; README "City scale"; results in bench/results/city_tiles.md).

    /usr/bin/python3 bench/city/tile_bench.py synth [--buildings 50] [--seeds 1 2] [--jobs 2] [--out DIR]
    /usr/bin/python3 bench/city/tile_bench.py terraced [--buildings 50] [--terraced 10] [--seeds 1]
    /usr/bin/python3 bench/city/tile_bench.py real [--out DIR]             # ../shared/data, ../shared/laz tiles
    /usr/bin/python3 bench/city/tile_bench.py throughput [--buildings 50] [--seed 1] [--out DIR]
    /usr/bin/python3 bench/city/tile_bench.py peer --roofer PATH [--buildings-list 50 1000] [--jobs-list 1 2]
                                              [--eval-every K] [--real] [--out DIR]

synth: for each seed, `hsr synth city --buildings N --seed S` (sloping ground, trees, buildings of the six
aerial families, their truth), then `hsr city` four ways: with and without the file's classification
(tile.las / tile_unclassified.las) x with and without the footprints. Per way: buildings found (a truth is
found when a model's centre lies in its footprint; with footprints the ids say it), the symmetric Chamfer
distance of each model to its truth (`hsr eval POINTS MODEL --truth TRUTH`: fraction of the building's
points' bbox diagonal), the largest distance of a ground face's vertex from the true ground (m), and every
feature decoded and checked by `hsr eval` (check_validity, the project's exact check).
terraced: the same on a tile where `--terraced` of the buildings share a wall with a neighbour, with
footprints and classes: also the deepest vertex of one solid inside its neighbour's footprint (m).
real: `hsr city` on the real tiles at hand, a model per building, and a picture of each tile (`hsr render` of
the sequence over the tile's points) in DIR/NAME.png.
peer: hsr city and roofer (3DBAG/roofer, the 3DBAG's engine, built outside the tree by
../shared/peers/build_roofer.sh; --roofer PATH) side by side in one run, with 1 and 2 jobs, on synthetic tiles
of --buildings-list sizes (classes + footprints, both tools given the same tile and footprints), with
--real, on the real tiles at hand where roofer can run (a projected CRS in metres or feet, footprints), and
with --ahn3 on a tile of the 56 shared real AHN3 buildings laid out by real_buildings_tile.py. Per
run: wall time (clock inside the heavy lock), peak memory (the largest single process, /usr/bin/time -v; and
the process tree's summed proportional set size, sampled every 50 ms: hsr city's buildings run in processes
time -v does not see), models written; per model, on the building's points as hsr city cut them (NAME.ply
of its work folder, the same points for both): validity by the project's exact check (`hsr eval`;
roofer's LoD 2.2 solid of all its BuildingParts, its repeated vertices welded), the RMS of the points to
the solid (m), and with a truth the symmetric Chamfer distance to it (% of the points' bbox diagonal).
throughput: buildings per minute of `hsr city` with 1 and 2 jobs and of `python3 -m hsr.city` with 1 and 2
workers on one synthetic tile (reading and planning it included), each try under flock /work/notes/heavy.lock
when it exists (its clock inside the lock), --repeat tries each, the best kept; the sequences of every run
compared byte for byte.
Prints markdown tables; --json FILE keeps the raw figures.
"""
import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HSR = os.environ.get("HSR_CLI", os.path.join(ROOT, "build", "hsr"))
LOCK = "/work/notes/heavy.lock"


def sh(args, **kw):
    r = subprocess.run(args, capture_output=True, text=True, **kw)
    if r.returncode not in (0, 1):
        raise SystemExit("failed (%d): %s\n%s" % (r.returncode, " ".join(args), r.stderr[-3000:]))
    return r


INNER_CLOCK = ("import os, subprocess, sys, time\n"
               "load = os.getloadavg()[0]; t = time.monotonic(); r = subprocess.run(sys.argv[1:])\n"
               "print('TIMED %.6f %.2f' % (time.monotonic() - t, load), file=sys.stderr); sys.exit(r.returncode)")


def timed(args, lock=False, env=None):
    """(seconds of wall time, result, load when it started) of a command; under the heavy lock when asked and
    present, the clock inside the lock (waiting for it is not counted)."""
    if lock and os.path.exists(LOCK):
        r = sh(["flock", LOCK, "/usr/bin/python3", "-c", INNER_CLOCK] + args, env=env)
        line = [l for l in r.stderr.splitlines() if l.startswith("TIMED ")][-1].split()
        return float(line[1]), r, float(line[2])
    load = os.getloadavg()[0]
    t0 = time.monotonic()
    r = sh(args, env=env)
    return time.monotonic() - t0, r, load


def load(path):
    with open(path) as f:
        return json.load(f)


def features(sequence):
    """(header, [feature dicts]) of a CityJSONSeq."""
    with open(sequence) as f:
        lines = [json.loads(line) for line in f if line.strip()]
    return lines[0], lines[1:]


def summary(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def decoded_vertices(header, feature):
    s, t = header["transform"]["scale"], header["transform"]["translate"]
    return [[v[k] * s[k] + t[k] for k in range(3)] for v in feature["vertices"]]


def ground_face_error(header, feature, true_ground):
    """Largest |z - true ground| over the vertices of the feature's GroundSurface faces (m)."""
    vs = decoded_vertices(header, feature)
    worst = 0.0
    for obj in feature["CityObjects"].values():
        for g in obj["geometry"]:
            types = [s["type"] for s in g["semantics"]["surfaces"]]
            for face, value in zip(g["boundaries"][0], g["semantics"]["values"][0]):
                if value is not None and types[value] == "GroundSurface":
                    for i in face[0]:
                        worst = max(worst, abs(vs[i][2] - true_ground))
    return worst


def inside(x, y, rings):
    """Even-odd over the GeoJSON polygon rings (the first repeated at the end)."""
    c = False
    for ring in rings:
        for (x1, y1), (x2, y2) in zip(ring, ring[1:]):
            if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
                c = not c
    return c


def in_footprint(x, y, geometry):
    return any(inside(x, y, poly) for poly in geometry["coordinates"])


def single_feature_file(header, feature, path):
    with open(path, "w") as f:
        f.write(json.dumps(header) + "\n" + json.dumps(feature) + "\n")


def evaluate_run(tile_dir, out, label):
    """Found / Chamfer / ground / validity of one `hsr city` run against the tile's truth."""
    truth = load(os.path.join(tile_dir, "truth.json"))
    seq = out + ".city.jsonl"
    header, feats = features(seq)
    rows = {r["building"]: r for r in summary(out + ".summary.csv")}
    by_id = {b["id"]: b for b in truth["building"]}
    matched = {}  # truth id -> feature
    extra = 0
    for f in feats:
        fid = f["id"]
        if fid in by_id:
            matched.setdefault(fid, []).append(f)
            continue
        vs = decoded_vertices(header, f)
        cx = (min(v[0] for v in vs) + max(v[0] for v in vs)) / 2
        cy = (min(v[1] for v in vs) + max(v[1] for v in vs)) / 2
        hit = [b["id"] for b in truth["building"] if in_footprint(cx, cy, b["footprint"])]
        if hit:
            matched.setdefault(hit[0], []).append(f)
        else:
            extra += 1
    chamfers, grounds, invalid, detail = [], [], 0, []
    tmp = tempfile.mkdtemp(prefix="tile_bench_")
    for tid, fs in sorted(matched.items()):
        f = fs[0]
        model = os.path.join(tmp, f["id"] + ".city.jsonl")
        single_feature_file(header, f, model)
        points = rows[f["id"]]["input"]
        r = sh([HSR, "eval", points, model, "--truth", os.path.join(tile_dir, "truth", tid + ".obj"), "--json"])
        ev = json.loads(r.stdout)
        valid = ev["validity"]["valid"]
        invalid += not valid
        chamfers.append(100 * ev["accuracy"]["chamfer"])
        grounds.append(ground_face_error(header, f, by_id[tid]["ground_z"]))
        detail.append({"truth": tid, "model": f["id"], "family": by_id[tid]["family"], "chamfer_pct": chamfers[-1],
                       "ground_err_m": grounds[-1], "valid": valid, "parts": len(fs)})
    failed = [r for r in rows.values() if r["status"] != "ok"]
    return {"run": label, "truths": len(truth["building"]), "found": len(matched), "features": len(feats),
            "extra": extra, "split": sum(len(v) > 1 for v in matched.values()), "failed": len(failed),
            "chamfer_median_pct": statistics.median(chamfers) if chamfers else None,
            "chamfer_max_pct": max(chamfers) if chamfers else None,
            "within_1pct": sum(c <= 1.0 for c in chamfers),
            "ground_max_m": max(grounds) if grounds else None, "invalid": invalid, "detail": detail}


def cmd_synth(args):
    results = []
    for seed in args.seeds:
        tile = os.path.join(args.out, "seed%d" % seed)
        if not os.path.exists(os.path.join(tile, "truth.json")):
            sh([HSR, "synth", "city", "--buildings", str(args.buildings), "--seed", str(seed), "-o", tile, "-q"])
        for classes in (True, False):
            for footprints in (True, False):
                label = "%s, %s" % ("classes" if classes else "no classes", "footprints" if footprints else "no footprints")
                out = os.path.join(tile, "run_%s_%s" % ("c" if classes else "u", "f" if footprints else "g"))
                cmd = [HSR, "city", os.path.join(tile, "tile.las" if classes else "tile_unclassified.las"),
                       "-o", out + ".city.jsonl", "-j", str(args.jobs), "-q"]
                if footprints:
                    cmd += ["--footprints", os.path.join(tile, "footprints.geojson"), "--id-field", "id"]
                seconds, _, _ = timed(cmd)
                res = evaluate_run(tile, out, label)
                res.update({"seed": seed, "seconds": seconds})
                results.append(res)
                print("seed %d, %s: %d/%d found, median Chamfer %.3f %%, ground max %.3f m, invalid %d, %.0f s" % (
                    seed, label, res["found"], res["truths"], res["chamfer_median_pct"] or -1, res["ground_max_m"] or -1,
                    res["invalid"], seconds), file=sys.stderr)
    print("| seed | run | found | features | failed | median Chamfer % | max Chamfer % | within 1 % | ground face max error m | invalid | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in results:
        print("| %d | %s | %d / %d | %d | %d | %.3f | %.3f | %d | %.3f | %d | %.0f |" % (
            r["seed"], r["run"], r["found"], r["truths"], r["features"], r["failed"], r["chamfer_median_pct"],
            r["chamfer_max_pct"], r["within_1pct"], r["ground_max_m"], r["invalid"], r["seconds"]))
    return results


def depth_inside(x, y, geometry):
    """Distance of (x, y) to the footprint's boundary when inside it, else 0."""
    if not in_footprint(x, y, geometry):
        return 0.0
    best = float("inf")
    for poly in geometry["coordinates"]:
        for ring in poly:
            for (x1, y1), (x2, y2) in zip(ring, ring[1:]):
                dx, dy = x2 - x1, y2 - y1
                t = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / (dx * dx + dy * dy)))
                best = min(best, ((x - x1 - t * dx) ** 2 + (y - y1 - t * dy) ** 2) ** 0.5)
    return best


def cmd_terraced(args):
    """A tile where `terraced` of the buildings share a wall with a neighbour: with footprints, each solid
    stays out of its neighbour's footprint (the deepest vertex of one inside the other's, m)."""
    results = []
    for seed in args.seeds:
        tile = os.path.join(args.out, "terraced%d" % seed)
        if not os.path.exists(os.path.join(tile, "truth.json")):
            sh([HSR, "synth", "city", "--buildings", str(args.buildings), "--terraced", str(args.terraced), "--seed",
                str(seed), "-o", tile, "-q"])
        out = os.path.join(tile, "run_c_f")
        seconds, _, _ = timed([HSR, "city", os.path.join(tile, "tile.las"), "-o", out + ".city.jsonl", "-j", str(args.jobs), "-q",
                            "--footprints", os.path.join(tile, "footprints.geojson"), "--id-field", "id"])
        res = evaluate_run(tile, out, "classes, footprints, %d terraced" % args.terraced)
        truth = {b["id"]: b for b in load(os.path.join(tile, "truth.json"))["building"]}
        header, feats = features(out + ".city.jsonl")
        verts = {f["id"]: decoded_vertices(header, f) for f in feats}
        worst, pairs = 0.0, 0
        for b in truth.values():
            host = b["attached_to"]
            if not host or b["id"] not in verts or host not in verts:
                continue
            pairs += 1
            for mine, other in ((b["id"], host), (host, b["id"])):
                for v in verts[mine]:
                    worst = max(worst, depth_inside(v[0], v[1], truth[other]["footprint"]))
        res.update({"seed": seed, "seconds": seconds, "pairs": pairs, "overlap_max_m": worst})
        results.append(res)
        print("terraced seed %d: %d/%d found, median Chamfer %.3f %%, %d pairs, deepest vertex in the neighbour's "
              "footprint %.4f m" % (seed, res["found"], res["truths"], res["chamfer_median_pct"], pairs, worst), file=sys.stderr)
    print("| seed | run | found | median Chamfer % | max Chamfer % | ground face max error m | invalid | pairs sharing a wall | deepest vertex inside the neighbour's footprint m |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        print("| %d | %s | %d / %d | %.3f | %.3f | %.3f | %d | %d | %.4f |" % (
            r["seed"], r["run"], r["found"], r["truths"], r["chamfer_median_pct"], r["chamfer_max_pct"], r["ground_max_m"],
            r["invalid"], r["pairs"], r["overlap_max_m"]))
    return results


REAL = [("cgal_urban", "../shared/data/cgal_urban.las"), ("cgal_b9", "../shared/data/cgal_b9.ply"),
        ("autzen_trim", "../shared/laz/autzen_trim.las"), ("autzen_trim_laz", "../shared/laz/autzen_trim.laz")]


def cmd_real(args):
    results = []
    for name, rel in REAL:
        path = os.path.join(ROOT, rel)
        if not os.path.exists(path):
            print("%s: %s absent, skipped" % (name, rel), file=sys.stderr)
            continue
        out = os.path.join(args.out, name)
        t0 = time.monotonic()
        r = subprocess.run([HSR, "city", path, "-o", out + ".city.jsonl", "-j", str(args.jobs)], capture_output=True, text=True)
        seconds = time.monotonic() - t0
        if r.returncode not in (0, 1) or not os.path.exists(out + ".city.jsonl"):
            print("%s: hsr city failed: %s" % (name, r.stderr.strip().splitlines()[-1:]), file=sys.stderr)
            results.append({"tile": name, "error": r.stderr.strip().splitlines()[-1:]})
            continue
        header, feats = features(out + ".city.jsonl")
        rows = summary(out + ".summary.csv")
        tmp = tempfile.mkdtemp(prefix="tile_bench_real_")
        invalid = 0
        for f in feats:
            model = os.path.join(tmp, f["id"] + ".city.jsonl")
            single_feature_file(header, f, model)
            pts = next(row["input"] for row in rows if row["building"] == f["id"])
            ev = json.loads(sh([HSR, "eval", pts, model, "--json"]).stdout)
            invalid += not ev["validity"]["valid"]
        png = os.path.join(args.out, name + ".png")
        if feats:
            sh([HSR, "render", out + ".city.jsonl", path, "-o", png, "-q"])
        classes = [line for line in r.stderr.splitlines() if "ground" in line and "building" in line]
        results.append({"tile": name, "buildings": len(rows), "ok": sum(row["status"] == "ok" for row in rows),
                        "features": len(feats), "invalid": invalid, "seconds": seconds, "png": png,
                        "classes": classes[0] if classes else "",
                        "failed": [(row["building"], row["message"]) for row in rows if row["status"] != "ok"]})
        print("%s: %d buildings, %d ok, %d invalid, %.0f s" % (name, len(rows), results[-1]["ok"], invalid, seconds),
              file=sys.stderr)
    print("| tile | buildings | models | invalid | wall s | how the points were split |")
    print("|---|---|---|---|---|---|")
    for r in results:
        if "error" in r:
            print("| %s | — | — | — | — | %s |" % (r["tile"], r["error"]))
        else:
            print("| %s | %d | %d | %d | %.0f | %s |" % (r["tile"], r["buildings"], r["features"], r["invalid"], r["seconds"],
                                                       r["classes"].split(": ", 2)[-1]))
    return results


def cmd_throughput(args):
    tile = os.path.join(args.out, "seed%d" % args.seed)
    if not os.path.exists(os.path.join(tile, "truth.json")):
        sh([HSR, "synth", "city", "--buildings", str(args.buildings), "--seed", str(args.seed), "-o", tile, "-q"])
    base = [os.path.join(tile, "tile.las"), "--footprints", os.path.join(tile, "footprints.geojson"), "--id-field", "id", "-q"]
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "build", "python"))
    runs = []
    for label, program, parallel in (("hsr city -j 1", [HSR, "city"], ["-j", "1"]),
                                     ("hsr city -j 2", [HSR, "city"], ["-j", "2"]),
                                     ("python3 -m hsr.city --workers 1", ["/usr/bin/python3", "-m", "hsr.city"], ["--workers", "1"]),
                                     ("python3 -m hsr.city --workers 2", ["/usr/bin/python3", "-m", "hsr.city"], ["--workers", "2"])):
        out = os.path.join(args.out, "tp_" + label.replace(" ", "_").replace("-", ""))
        full = program + base + parallel + ["-o", out + ".city.jsonl"]
        tries = []
        for _ in range(args.repeat):
            shutil.rmtree(out + ".work", ignore_errors=True)
            tries.append(timed(full, lock=True, env=env))
        seconds, _, load_before = min(tries, key=lambda t: t[0])
        rows = summary(out + ".summary.csv")
        runs.append({"run": label, "buildings": len(rows), "ok": sum(r["status"] == "ok" for r in rows), "seconds": seconds,
                     "all_seconds": [t[0] for t in tries], "loads": [t[2] for t in tries],
                     "per_minute": 60 * len(rows) / seconds, "load": load_before,
                     "sequence": open(out + ".city.jsonl", "rb").read()})
        print("%s: %s s (loads %s), best %.1f buildings/min" % (label, [round(t[0], 1) for t in tries],
                                                               [t[2] for t in tries], runs[-1]["per_minute"]), file=sys.stderr)
    same = all(r["sequence"] == runs[0]["sequence"] for r in runs)
    print("| run | buildings | ok | wall s (each try) | buildings / min (best) | load at the best's start |")
    print("|---|---|---|---|---|---|")
    for r in runs:
        print("| `%s` | %d | %d | %s | %.1f | %.1f |" % (r["run"], r["buildings"], r["ok"],
                                                     " / ".join("%.1f" % t for t in r["all_seconds"]), r["per_minute"], r["load"]))
    print("\nsequences byte-identical across the four runs: %s" % same)
    for r in runs:
        del r["sequence"]
    return {"runs": runs, "identical": same}


# ------------------------------------------------------------------------------------------ peer: roofer

HEAVY_LOCK = os.environ.get("HSR_BENCH_LOCK", "/tmp/heavy.lock")


def tree_memory(root):
    """(summed proportional set size of `root` and every descendant, largest resident set of one), bytes."""
    children = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open("/proc/%s/stat" % d) as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(d))
            except (OSError, IndexError, ValueError):
                pass
    total, largest, todo = 0, 0, [root]
    while todo:
        pid = todo.pop()
        todo += children.get(pid, [])
        try:
            with open("/proc/%d/smaps_rollup" % pid) as f:
                for line in f:
                    if line.startswith("Rss:"):
                        largest = max(largest, 1024 * int(line.split()[1]))
                    elif line.startswith("Pss:"):
                        total += 1024 * int(line.split()[1])
        except OSError:
            pass
    return total, largest


def measured(args):
    """A command run under the heavy lock (when it exists; the clock inside it): (wall s, exit code, peak RSS
    of the largest process by /usr/bin/time -v, peak summed PSS of the process tree sampled every 50 ms,
    stderr)."""
    import fcntl
    import threading
    lock = open(HEAVY_LOCK) if os.path.exists(HEAVY_LOCK) else None
    if lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
    try:
        t0 = time.monotonic()
        p = subprocess.Popen(["/usr/bin/time", "-v"] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        peak = [0]
        done = threading.Event()

        def sample():
            while not done.wait(0.05):
                peak[0] = max(peak[0], tree_memory(p.pid)[0])
        t = threading.Thread(target=sample)
        t.start()
        err = p.communicate()[1]
        seconds = time.monotonic() - t0
        done.set()
        t.join()
    finally:
        if lock:
            fcntl.flock(lock, fcntl.LOCK_UN)
            lock.close()
    rss = [int(l.split()[-1]) * 1024 for l in err.splitlines() if "Maximum resident set size" in l]
    return seconds, p.returncode, rss[-1] if rss else 0, peak[0], err


def roofer_solids(sequence):
    """{building id: (vertices, faces, inner rings dropped)} of a roofer CityJSONSeq (no faces: the feature has no
    LoD 2.2 solid, e.g. roofer's LoD 0 outline of a building without usable points): the LoD 2.2 Solids of each
    Building's parts as one polygon mesh, vertices decoded, the repeated ones welded (equal integers: one
    vertex; a ring's repeated neighbours: one corner)."""
    out = {}
    with open(sequence) as f:
        lines = [json.loads(line) for line in f if line.strip()]
    header = lines[0]
    s, t = header["transform"]["scale"], header["transform"]["translate"]
    for feat in lines[1:]:
        ints = feat["vertices"]
        for oid, obj in feat["CityObjects"].items():
            if obj["type"] != "Building":
                continue
            weld, verts, faces, holes = {}, [], [], 0
            for part in obj.get("children", []):
                for g in feat["CityObjects"][part].get("geometry", []):
                    if g["type"] != "Solid" or g["lod"] != "2.2":
                        continue
                    for shell in g["boundaries"]:
                        for surface in shell:
                            holes += len(surface) - 1
                            ring = []
                            for i in surface[0]:
                                key = tuple(ints[i])
                                if key not in weld:
                                    weld[key] = len(verts)
                                    verts.append([key[k] * s[k] + t[k] for k in range(3)])
                                if not ring or ring[-1] != weld[key]:
                                    ring.append(weld[key])
                            while len(ring) > 1 and ring[0] == ring[-1]:
                                ring.pop()
                            faces.append(ring)
            out[feat.get("id", oid)] = (verts, faces, holes)
    return out


def write_obj(path, verts, faces):
    with open(path, "w") as f:
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % tuple(v))
        for face in faces:
            f.write("f %s\n" % " ".join(str(i + 1) for i in face))


def model_figures(points, model, truth, samples):
    """Validity (the project's exact check), RMS of the points to the model (m), Chamfer to the truth (% of the
    points' bbox diagonal, None without a truth), by `hsr eval`."""
    cmd = [HSR, "eval", points, model, "--json", "--samples", str(samples)]
    if truth:
        cmd += ["--truth", truth]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        return {"valid": False, "rms_m": None, "chamfer_pct": None, "error": (r.stderr.strip().splitlines() or [""])[-1]}
    ev = json.loads(r.stdout)
    acc = ev["accuracy"]
    return {"valid": ev["validity"]["valid"], "rms_m": acc["p2m_rms"] * ev["diagonal"],
            "chamfer_pct": 100 * acc["chamfer"] if truth else None}


def evaluate_pair(hsr_out, roofer_dir, truth_dir, every, samples):
    """Per building (every `every`-th of hsr's summary, in order): both tools' figures on hsr's points."""
    header, feats = features(hsr_out + ".city.jsonl")
    hsr_feats = {f["id"]: f for f in feats}
    rows = summary(hsr_out + ".summary.csv")
    seqs = [os.path.join(dp, n) for dp, _, ns in os.walk(roofer_dir) for n in ns if n.endswith(".city.jsonl")]
    solids = {}
    for seq in seqs:
        solids.update(roofer_solids(seq))
    tmp = tempfile.mkdtemp(prefix="tile_bench_peer_")
    per = []
    for row in rows[::every]:
        bid, points = row["building"], row["input"]
        if not os.path.exists(points):
            continue
        truth = os.path.join(truth_dir, bid + ".obj") if truth_dir else None
        if truth and not os.path.exists(truth):
            truth = None
        item = {"building": bid}
        if bid in hsr_feats:
            model = os.path.join(tmp, bid + ".city.jsonl")
            single_feature_file(header, hsr_feats[bid], model)
            item["hsr"] = model_figures(points, model, truth, samples)
        if bid in solids and solids[bid][1]:
            verts, faces, holes = solids[bid]
            model = os.path.join(tmp, bid + ".obj")
            write_obj(model, verts, faces)
            item["roofer"] = model_figures(points, model, truth, samples)
            item["roofer"]["inner_rings_dropped"] = holes
        per.append(item)
    return per, len(feats), sum(1 for v in solids.values() if v[1])


def peer_summary(per, tool):
    got = [p[tool] for p in per if tool in p]
    rms = [g["rms_m"] for g in got if g["rms_m"] is not None]
    ch = [g["chamfer_pct"] for g in got if g["chamfer_pct"] is not None]
    return {"evaluated": len(per), "models": len(got), "valid": sum(g["valid"] for g in got),
            "rms_median_m": statistics.median(rms) if rms else None,
            "chamfer_median_pct": statistics.median(ch) if ch else None}


def peer_runs(args, name, tile, footprints, id_field, srs, truth_dir, extra_roofer=()):
    """Both tools on one tile with each job count; the figures of each run and of its models."""
    results = []
    for jobs in args.jobs_list:
        hsr_out = os.path.join(args.out, "%s_hsr_j%d" % (name, jobs))
        shutil.rmtree(hsr_out + ".work", ignore_errors=True)
        hcmd = [HSR, "city", tile, "-o", hsr_out + ".city.jsonl", "-j", str(jobs), "-q"]
        if footprints:
            hcmd += ["--footprints", footprints] + (["--id-field", id_field] if id_field else [])
        rdir = os.path.join(args.out, "%s_roofer_j%d" % (name, jobs))
        shutil.rmtree(rdir, ignore_errors=True)
        rcmd = [args.roofer] + (["--srs", srs] if srs else []) + ["--lod12", "--lod13", "--lod22", "-j", str(jobs)]
        rcmd += list(extra_roofer)
        rcmd += (["--id-attribute", id_field] if id_field else []) + [tile, footprints, rdir]
        for label, cmd in (("hsr city", hcmd), ("roofer", rcmd)):
            seconds, code, rss, pss, err = measured(cmd)
            results.append({"tile": name, "tool": label, "jobs": jobs, "seconds": seconds, "exit": code,
                            "max_rss_mb": rss / 1e6, "tree_pss_mb": pss / 1e6,
                            "error": "" if code in (0, 1) else (err.strip().splitlines() or [""])[-1]})
            print("%s, %s -j %d: %.2f s, exit %d, largest process %.0f MB, all processes %.0f MB" % (
                name, label, jobs, seconds, code, rss / 1e6, pss / 1e6), file=sys.stderr)
        per, hsr_models, roofer_models = evaluate_pair(hsr_out, rdir, truth_dir, args.eval_every, args.samples)
        for r in results[-2:]:
            tool = "hsr" if r["tool"] == "hsr city" else "roofer"
            r.update(peer_summary(per, tool))
            r["models_written"] = hsr_models if tool == "hsr" else roofer_models
        results[-1]["per_building"] = per
    return results


def tile_classes(path):
    """{class: points} of a LAS/LAZ tile, from `hsr info` (empty when the file has no classes)."""
    out = sh([HSR, "info", path]).stdout
    line = next((l for l in out.splitlines() if l.startswith("classes")), "")
    return {int(k): int(v) for k, v in (c.split(":") for c in line[len("classes"):].split(",") if ":" in c)}


def derived_footprints(args, name, path):
    """A footprint file for a real tile that has none: the plan (the LoD 2.2 GroundSurface's outer ring) of each
    building `hsr city` finds in the tile WITHOUT footprints (its connected groups), written as CSV (WKT) with the
    group's id in `id`. Both tools are then given these footprints, so they model the same buildings; the plans
    are hsr's, which may favour hsr where roofer would have drawn another outline (said in the results)."""
    plan = os.path.join(args.out, name + "_plan")
    shutil.rmtree(plan + ".work", ignore_errors=True)
    sh([HSR, "city", path, "-o", plan + ".city.jsonl", "-q"])
    header, feats = features(plan + ".city.jsonl")
    s, t = header["transform"]["scale"], header["transform"]["translate"]
    rows = []
    for f in feats:
        geom = next(g for g in f["CityObjects"][f["id"]]["geometry"] if g["lod"] == "2.2")
        types = [x["type"] for x in geom["semantics"]["surfaces"]]
        for surface, v in zip(geom["boundaries"][0], geom["semantics"]["values"][0]):
            if v is None or types[v] != "GroundSurface":
                continue
            ring = [(f["vertices"][k][0] * s[0] + t[0], f["vertices"][k][1] * s[1] + t[1]) for k in surface[0]]
            ring = ring[::-1] + ring[-1:]  # the ground face looks down: reversed, counter-clockwise from above
            rows.append('%s,"POLYGON ((%s))"' % (f["id"], ", ".join("%.3f %.3f" % p for p in ring)))
    # CSV with a WKT column: GDAL (hsr's and roofer's reader) gives it no CRS, as the tiles' plans have none of
    # their own (GeoJSON would be taken as WGS 84).
    fp = os.path.join(args.out, name + ".footprints.csv")
    with open(fp, "w") as f:
        f.write("id,WKT\n" + "".join(r + "\n" for r in rows))
    return fp, len(rows)


def real_peer_tiles(args):
    """(name, tile, footprints, id field, srs, extra roofer options) of the real LAS/LAZ tiles: their footprint
    file beside the tile (NAME.footprints.geojson) or, without one, the plans of hsr city's groups
    (derived_footprints). roofer's building class: 6 when the tile has it, else the most common class other than
    ground (2), since the shared tiles' buildings are not class 6 (cgal_urban: 4, autzen_trim: 1)."""
    tiles = []
    for name, rel in REAL:
        path = os.path.join(ROOT, rel)
        if not os.path.exists(path) or not path.endswith((".las", ".laz")):
            continue
        classes = tile_classes(path)
        if 2 not in classes:
            print("%s: no ground class (2): roofer cannot run, skipped" % name, file=sys.stderr)
            continue
        fp = os.path.splitext(path)[0] + ".footprints.geojson"
        if not os.path.exists(fp):
            fp, n = derived_footprints(args, name, path)
            print("%s: no footprints beside it: the plans of hsr city's %d groups given to both" % (name, n),
                  file=sys.stderr)
        others = {c: n for c, n in classes.items() if c != 2}
        building = 6 if 6 in classes else max(others, key=lambda c: (others[c], -c))
        tiles.append((name, path, fp, "id", "", ("--bld-class", str(building))))
    return tiles


def cmd_peer(args):
    if not args.roofer or not os.access(args.roofer, os.X_OK):
        raise SystemExit("peer: give --roofer PATH (build it with ../shared/peers/build_roofer.sh)")
    results = []
    for n in args.buildings_list:
        tile = os.path.join(args.out, "synth%d_seed%d" % (n, args.seed))
        if not os.path.exists(os.path.join(tile, "truth.json")):
            sh([HSR, "synth", "city", "--buildings", str(n), "--seed", str(args.seed), "-o", tile, "-q"])
        srs = load(os.path.join(tile, "truth.json"))["crs"]
        results += peer_runs(args, "synth%d" % n, os.path.join(tile, "tile.las"), os.path.join(tile, "footprints.geojson"),
                             "id", srs, os.path.join(tile, "truth"))
    if args.real:
        for name, path, fp, idf, srs, extra in real_peer_tiles(args):
            results += peer_runs(args, name, path, fp, idf, srs, None, extra)
    if args.ahn3:
        tile = os.path.join(args.out, "ahn3_buildings")
        if not os.path.exists(os.path.join(tile, "footprints.csv")):
            sh([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "real_buildings_tile.py"), tile])
        results += peer_runs(args, "ahn3_buildings", os.path.join(tile, "tile.las"), os.path.join(tile, "footprints.csv"),
                             "id", "", None, ("--bld-class", "6"))
    print("| tile | tool | jobs | wall s | largest process MB | all processes MB | models | valid (of evaluated) | "
          "RMS points → LoD 2.2 median m | Chamfer to truth median % |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    fmt = lambda v, f: "—" if v is None else f % v
    for r in results:
        print("| %s | %s | %d | %.2f | %.0f | %.0f | %s | %s / %s | %s | %s |" % (
            r["tile"], r["tool"], r["jobs"], r["seconds"], r["max_rss_mb"], r["tree_pss_mb"], r.get("models_written", "—"),
            r.get("valid", "—"), r.get("models", "—"), fmt(r.get("rms_median_m"), "%.3f"), fmt(r.get("chamfer_median_pct"), "%.3f")))
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=["synth", "terraced", "real", "throughput", "peer"])
    p.add_argument("--roofer", help="peer: the roofer binary")
    p.add_argument("--buildings-list", type=int, nargs="*", default=[50, 1000], help="peer: synthetic tile sizes (none: only --real)")
    p.add_argument("--jobs-list", type=int, nargs="+", default=[1, 2], help="peer: job counts")
    p.add_argument("--eval-every", type=int, default=1, help="peer: evaluate every K-th building")
    p.add_argument("--samples", type=int, default=200000, help="peer: samples per mesh of hsr eval")
    p.add_argument("--real", action="store_true", help="peer: also the real tiles where roofer can run")
    p.add_argument("--ahn3", action="store_true",
                   help="peer: also a tile of the shared real AHN3 buildings with City3D's ground faces as footprints "
                        "(real_buildings_tile.py)")
    p.add_argument("--terraced", type=int, default=10, help="terraced: buildings attached to a neighbour")
    p.add_argument("--buildings", type=int, default=50)
    p.add_argument("--seeds", type=int, nargs="+", default=[1])
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--repeat", type=int, default=2, help="throughput: tries per run (the best is kept)")
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "hsr_tile_bench"))
    p.add_argument("--json", help="write the raw figures here")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    result = {"synth": cmd_synth, "terraced": cmd_terraced, "real": cmd_real, "throughput": cmd_throughput,
              "peer": cmd_peer}[args.what](args)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
