#!/usr/bin/env python3
"""`hsr city` with its tile streamed (issue 40 item 2, issue 43's memory target; DECISIONS #96): the same bytes
as a binary that holds the whole tile, and the memory and time of both, paired in one run.

    /usr/bin/python3 bench/city/stream_bench.py same --old OLD_HSR [--new HSR] [--seeds 1 2 3] [--out DIR]
    /usr/bin/python3 bench/city/stream_bench.py memory --old OLD_HSR [--new HSR] --tiles DIR [DIR ...]
                                                [--jobs 1 2] [--no-footprints] [--out DIR]
    /usr/bin/python3 bench/city/stream_bench.py survey [--old OLD_HSR] [--new HSR] --sizes 1 2 4 [--density 20] [--jobs 1 2]
                                                [--dask 2] [--data DIR] [--out DIR] [--generate-only] [--delete]

same: `hsr synth city --buildings 50 --seed S --tiles 3` per seed, then `hsr city` with both binaries on the
classified and the unclassified tile, with and without the footprints, and on the 3 x 3 tiles of each (one
survey, with and without footprints); and on the shared real tiles (../shared/data/cgal_urban.las,
../shared/laz/autzen_trim.laz, and each cut in four through its plan centre, bench/city/split_tiles.py). Every
sequence and summary (without its times) compared byte for byte.
memory: per DIR (a `hsr synth city` folder: tile.las, footprints.geojson), `hsr city DIR/tile.las --footprints
DIR/footprints.geojson -j J` with both binaries, old then new, per J: wall time (clock inside the heavy lock),
peak memory of the largest process (/usr/bin/time -v: the driver) and of the whole process tree (summed PSS,
sampled every 50 ms; tile_bench.py measured), bytes of the largest process per point of the tile, the points
the new binary kept (its log), buildings written and buildings per minute; the two sequences compared.
survey (issue 40 item 2's Must show): per SIZE (km a side), `hsr synth city --size SIZE --density D --seed 1 -o
DATA/sizeSIZE` (measured: the generator's wall and peak memory; skipped when the folder holds a truth.json), then
`hsr city DATA/sizeSIZE/tiles/*.las --footprints DATA/sizeSIZE/footprints.geojson -o OUT -j J` per J and, with
--dask W, `python3 -m hsr.city` (LocalCluster of W workers) on the same: wall, peak memory of the largest process
and of the process tree, bytes per point of the largest tile and of the whole survey (largest process), points kept (the driver's log), buildings
written and per minute; every run's sequences compared with the first's. The largest process is /usr/bin/time's
figure: the driver or one building's `hsr reconstruct` child, whichever is larger; the planning process is the
driver alone (its VmHWM, sampled). --old OLD_HSR: each `hsr city` run with OLD_HSR first, then the new one. Each command is one job under the heavy
lock (tile_bench.measured takes it: do not wrap this script in flock unless HSR_BENCH_LOCK=/nonexistent);
--delete: a size's folder is deleted after its runs (the 16 km² survey is about 9 GB). --one-tile: each size is
ONE tile (`hsr synth city --tile-size SIZE*1000`; a large file planned block by block, DECISIONS #124); use its
own --data folder.
Prints markdown tables; --json FILE keeps the raw figures.
"""
import argparse
import glob
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tile_bench import measured  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
SPLIT = os.path.join(ROOT, "bench", "city", "split_tiles.py")
LOCK = os.environ.get("HSR_BENCH_LOCK", "/tmp/heavy.lock")


def sh(args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode not in (0, 1):
        raise SystemExit("failed (%d): %s\n%s" % (r.returncode, " ".join(args), r.stderr[-3000:]))
    return r


def locked(args):
    return sh(["flock", LOCK] + args) if os.path.exists(LOCK) else sh(args)


def las_header(path):
    """(point count, min x, min y, max x, max y) of a LAS file's header."""
    with open(path, "rb") as f:
        h = f.read(375)
    count = struct.unpack_from("<I", h, 107)[0]
    if h[25] >= 4 and len(h) >= 255:
        count = struct.unpack_from("<Q", h, 247)[0] or count
    maxx, minx, maxy, miny = struct.unpack_from("<4d", h, 179)
    return count, minx, miny, maxx, maxy


def without_seconds(summary):
    """A summary CSV's bytes without its `seconds` column (each run's time)."""
    lines = summary.decode().splitlines()
    if not lines or "seconds" not in lines[0].split(","):
        return summary
    k = lines[0].split(",").index("seconds")
    out = []
    for line in lines:  # the columns before `seconds` (input, status) hold no comma
        cells = line.split(",", k + 1)
        out.append(",".join(cells[:k] + cells[k + 1:]))
    return "\n".join(out).encode()


def outputs(out):
    """{file name: bytes} of the sequences and summaries (without their times) under `out` (a stem or a folder)."""
    files = glob.glob(out + ".city.jsonl") + glob.glob(out + ".summary.csv") + glob.glob(os.path.join(out, "*.city.jsonl")) + \
        glob.glob(os.path.join(out, "*.summary.csv"))
    return {os.path.basename(p): without_seconds(open(p, "rb").read()) if p.endswith(".csv") else open(p, "rb").read() for p in files}


def city(hsr, tiles, footprints, out, jobs=2):
    args = [hsr, "-q", "city"] + tiles + ["-o", out + (".city.jsonl" if len(tiles) == 1 else ""), "-j", str(jobs)]
    if footprints:
        args += ["--footprints", footprints]
    return locked(args).returncode


def cmd_same(a):
    cases = []
    for seed in a.seeds:
        d = os.path.join(a.out, "seed%d" % seed)
        if not os.path.exists(os.path.join(d, "tile.las")):
            locked([a.new, "synth", "city", "--buildings", "50", "--seed", str(seed), "--tiles", "3", "-o", d])
        fp = os.path.join(d, "footprints.geojson")
        for name in ("tile", "tile_unclassified"):
            cases.append(("seed %d %s" % (seed, name), [os.path.join(d, name + ".las")], fp))
            cases.append(("seed %d %s, groups" % (seed, name), [os.path.join(d, name + ".las")], None))
        for name in ("tiles", "tiles_unclassified"):
            tiles = sorted(glob.glob(os.path.join(d, name, "*.las")))
            cases.append(("seed %d %s (3 x 3)" % (seed, name), tiles, fp))
            cases.append(("seed %d %s (3 x 3), groups" % (seed, name), tiles, None))
    for rel, twin in (("data/cgal_urban.las", "data/cgal_urban.las"), ("laz/autzen_trim.laz", "laz/autzen_trim.las")):
        path = os.path.join(SHARED, rel)
        if not os.path.exists(path):
            print("%s absent, skipped" % path, file=sys.stderr)
            continue
        name = os.path.splitext(os.path.basename(rel))[0]
        cases.append((rel, [path], None))
        _, x0, y0, x1, y1 = las_header(os.path.join(SHARED, twin))
        cut = os.path.join(a.out, name + "_cut")
        if not glob.glob(os.path.join(cut, "*.las")):
            sh(["/usr/bin/python3", SPLIT, os.path.join(SHARED, twin), cut, "--x", "%.3f" % ((x0 + x1) / 2), "--y", "%.3f" % ((y0 + y1) / 2)])
        cases.append((rel + " cut in four", sorted(glob.glob(os.path.join(cut, "*.las"))), None))
    rows = []
    for n, (label, tiles, fp) in enumerate(cases):
        got = {}
        for which, hsr in (("old", a.old), ("new", a.new)):
            out = os.path.join(a.out, "case%d" % n)  # the same paths for both: the summaries name the work files
            shutil.rmtree(out, ignore_errors=True)
            os.makedirs(out)
            stem = os.path.join(out, "run")
            code = city(hsr, tiles, fp, stem)
            got[which] = (code, outputs(stem))
        same = got["old"] == got["new"]
        features = sum(v.count(b"\n") - 1 for k, v in got["new"][1].items() if k.endswith(".city.jsonl"))
        rows.append({"case": label, "tiles": len(tiles), "footprints": bool(fp), "exit": got["new"][0], "features": features,
                     "files": len(got["new"][1]), "identical": same})
        print("%s: %s (%d features, exit %d)" % (label, "identical" if same else "DIFFERENT", features, got["new"][0]), file=sys.stderr)
    print("| case | tiles | footprints | features | exit | sequences and summaries identical |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %d | %s | %d | %d | %s |" % (r["case"], r["tiles"], "yes" if r["footprints"] else "no", r["features"], r["exit"],
                                                 "yes" if r["identical"] else "**no**"))
    return rows


def cmd_memory(a):
    rows = []
    for d in a.tiles:
        tile = os.path.join(d, "tile.las")
        fp = None if a.no_footprints else os.path.join(d, "footprints.geojson")
        count, x0, y0, x1, y1 = las_header(tile)
        km2 = (x1 - x0) * (y1 - y0) / 1e6
        for jobs in a.jobs:
            seqs = {}
            for which, hsr in (("old", a.old), ("new", a.new)):
                out = os.path.join(a.out, "%s_j%d" % (os.path.basename(d.rstrip("/")), jobs))
                shutil.rmtree(out + ".work", ignore_errors=True)
                args = [hsr, "city", tile, "-o", out + ".city.jsonl", "-j", str(jobs)]
                if fp:
                    args += ["--footprints", fp]
                seconds, code, rss, pss, err = measured(args)
                kept = re.findall(r"(\d+) of (\d+) points kept", err)
                seqs[which] = open(out + ".city.jsonl", "rb").read()
                written = seqs[which].count(b"\n") - 1
                rows.append({"tile": os.path.basename(d.rstrip("/")), "km2": km2, "points": count, "binary": which, "jobs": jobs,
                             "seconds": seconds, "exit": code, "max_rss_mb": rss / 1e6, "tree_pss_mb": pss / 1e6,
                             "bytes_per_point": rss / count, "kept": int(kept[-1][0]) if kept else count,
                             "buildings": written, "per_minute": 60 * written / seconds})
                print("%s %s -j %d: %.1f s, largest %.0f MB, tree %.0f MB, exit %d" % (d, which, jobs, seconds, rss / 1e6, pss / 1e6, code),
                      file=sys.stderr)
            rows[-1]["identical"] = rows[-2]["identical"] = seqs["old"] == seqs["new"]
    print("| tile | km² | points | binary | jobs | wall s | largest process MB | all processes MB | bytes per tile point (largest) "
          "| points kept | buildings | per minute | sequence identical |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %.2f | %.1f M | %s | %d | %.1f | %.0f | %.0f | %.1f | %.1f M (%.0f %%) | %d | %.0f | %s |" % (
            r["tile"], r["km2"], r["points"] / 1e6, r["binary"], r["jobs"], r["seconds"], r["max_rss_mb"], r["tree_pss_mb"],
            r["bytes_per_point"], r["kept"] / 1e6, 100.0 * r["kept"] / r["points"], r["buildings"], r["per_minute"],
            "yes" if r["identical"] else "**no**"))
    return rows


def driver_hwm(pid):
    """VmHWM (peak resident set) of process `pid` alone, bytes; 0 when it is gone."""
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return 1024 * int(line.split()[1])
    except OSError:
        pass
    return 0


def measured_driver(args):
    """tile_bench.measured, and the peak resident set of the planning process itself (the command's own
    process, /usr/bin/time's child: its VmHWM sampled every 50 ms until it exits): (wall s, exit code, largest
    process (/usr/bin/time -v: the driver or one building's run), tree PSS, planning process, stderr)."""
    import fcntl
    import threading
    import time
    from tile_bench import HEAVY_LOCK, tree_memory
    lock = open(HEAVY_LOCK) if os.path.exists(HEAVY_LOCK) else None
    if lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
    try:
        t0 = time.monotonic()
        p = subprocess.Popen(["/usr/bin/time", "-v"] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        peak, hwm = [0], [0]
        done = threading.Event()

        def sample():
            child = None
            while not done.wait(0.05):
                peak[0] = max(peak[0], tree_memory(p.pid)[0])
                if child is None:
                    try:
                        child = int(open("/proc/%d/task/%d/children" % (p.pid, p.pid)).read().split()[0])
                    except (OSError, IndexError, ValueError):
                        continue
                hwm[0] = max(hwm[0], driver_hwm(child))
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
    return seconds, p.returncode, rss[-1] if rss else 0, peak[0], hwm[0], err


def sequences(out):
    """{file name: bytes} of the CityJSONSeqs in folder `out`."""
    return {os.path.basename(p): open(p, "rb").read() for p in glob.glob(os.path.join(out, "*.city.jsonl"))}


def cmd_survey(a):
    rows = []
    for size in a.sizes:
        d = os.path.join(a.data, "size%g" % size)
        if not os.path.exists(os.path.join(d, "truth.json")):
            shutil.rmtree(d, ignore_errors=True)
            args = [a.new, "synth", "city", "--size", "%g" % size, "--density", "%g" % a.density, "--seed", "1", "-o", d]
            if a.one_tile:
                args += ["--tile-size", "%g" % (1000 * size)]
            seconds, code, rss, pss, err = measured(args)
            if code != 0:
                raise SystemExit("failed (%d): %s\n%s" % (code, " ".join(args), err[-3000:]))
            truth = json.load(open(os.path.join(d, "truth.json")))
            rows.append({"run": "synth city", "km2": size * size, "size_km": size, "points": truth["points"], "jobs": 0,
                         "seconds": seconds, "exit": code, "max_rss_mb": rss / 1e6, "tree_pss_mb": pss / 1e6,
                         "bytes_per_point": rss / truth["points"], "buildings": truth["buildings"],
                         "tiles": len(truth["survey"]["tiles"]), "kept": 0, "per_minute": 0, "identical": True})
            print("synth %g km: %.1f s, %.0f MB, %d points" % (size, seconds, rss / 1e6, truth["points"]), file=sys.stderr)
        if a.generate_only:
            continue
        truth = json.load(open(os.path.join(d, "truth.json")))
        tiles = sorted(glob.glob(os.path.join(d, "tiles", "*.las")))
        fp = os.path.join(d, "footprints.geojson")
        points = sum(las_header(t)[0] for t in tiles)
        tile_points = max(las_header(t)[0] for t in tiles)  # the largest tile: what one plan reads at most
        binaries = [("old", a.old), ("new", a.new)] if a.old else [("", a.new)]
        runs = [("hsr city", j, b) for j in a.jobs for b in binaries] + [("Dask", w, ("", a.new)) for w in a.dask]
        first = None
        for what, jobs, (which, hsr) in runs:
            out = os.path.join(a.out, "size%g_%s%d%s" % (size, "dask" if what == "Dask" else "j", jobs, which))
            shutil.rmtree(out, ignore_errors=True)
            if what == "Dask":
                os.environ["PYTHONPATH"] = os.path.join(os.path.dirname(a.new), "python")
                args = ["/usr/bin/python3", "-m", "hsr.city"] + tiles + ["-o", out, "--footprints", fp, "--workers", str(jobs),
                                                                         "--hsr", a.new]
            else:
                args = [hsr, "city"] + tiles + ["-o", out, "--footprints", fp, "-j", str(jobs)]
            seconds, code, rss, pss, planner, err = measured_driver(args)
            with open(out + ".log", "w") as f:  # the run's log beside its folder
                f.write(err)
            kept = sum(int(k) for k, _ in re.findall(r"(\d+) of (\d+) points kept", err))
            census = re.findall(r"its census decoded (\d+) of (\d+) parts of the region's files, (\d+) points", err)
            seqs = sequences(out)
            written = sum(v.count(b"\n") - 1 for v in seqs.values())
            if first is None:
                first = seqs
            rows.append({"run": what + (" (%s)" % which if which else ""), "km2": size * size, "size_km": size, "points": points,
                         "jobs": jobs, "seconds": seconds, "planner_mb": planner / 1e6,
                         "exit": code, "max_rss_mb": rss / 1e6, "tree_pss_mb": pss / 1e6, "bytes_per_point": rss / tile_points,
                         "bytes_per_survey_point": rss / points, "tile_points": tile_points, "buildings": written, "tiles": len(tiles), "kept": kept, "per_minute": 60 * written / seconds,
                         "identical": seqs == first, "footprints": truth["buildings"],
                         "census_parts": [sum(int(c[0]) for c in census), sum(int(c[1]) for c in census)],
                         "census_points": sum(int(c[2]) for c in census)})
            print("%s %s %g km -j %d: %.1f s, largest %.0f MB, planning process %.0f MB, tree %.0f MB, %d of %d buildings, exit %d" % (
                what, which, size, jobs, seconds, rss / 1e6, planner / 1e6, pss / 1e6, written, truth["buildings"], code), file=sys.stderr)
            if a.json:
                with open(a.json, "w") as f:
                    json.dump(rows, f, indent=1)
        if a.delete:
            shutil.rmtree(d, ignore_errors=True)
    print("| run | km² | tiles | points | jobs / workers | wall s | largest process MB | planning process MB | all processes MB "
          "| bytes per point of the largest tile / of the survey (largest process) | points kept | buildings | per minute | sequences identical |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %g | %d | %.1f M | %s | %.1f | %.0f | %s | %.0f | %s | %s | %d | %s | %s |" % (
            r["run"], r["km2"], r["tiles"], r["points"] / 1e6, r["jobs"] or "", r["seconds"], r["max_rss_mb"],
            "%.0f" % r["planner_mb"] if r.get("planner_mb") else "", r["tree_pss_mb"],
            "%.1f / %.2f" % (r["bytes_per_point"], r.get("bytes_per_survey_point", r["bytes_per_point"])), "%.1f M (%.0f %%)" % (r["kept"] / 1e6, 100.0 * r["kept"] / r["points"]) if r["kept"] else "",
            r["buildings"], "%.0f" % r["per_minute"] if r["per_minute"] else "", "yes" if r["identical"] else "**no**"))
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("what", choices=["same", "memory", "survey"])
    p.add_argument("--old", help="the binary before (a copy; same and memory; survey: run before the new one)")
    p.add_argument("--new", default=os.path.join(ROOT, "build", "hsr"))
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--tiles", nargs="+", default=[])
    p.add_argument("--jobs", type=int, nargs="*", default=[2], help="hsr city -j per run (survey: none with --jobs alone, to run only --dask)")
    p.add_argument("--no-footprints", action="store_true")
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "hsr_stream_bench"))
    p.add_argument("--json", help="write the raw figures here")
    p.add_argument("--sizes", type=float, nargs="+", default=[1, 2, 4], help="survey: km a side")
    p.add_argument("--density", type=float, default=20.0, help="survey: points per m²")
    p.add_argument("--dask", type=int, nargs="*", default=[], help="survey: Dask LocalCluster workers per run")
    p.add_argument("--data", default=os.path.join(tempfile.gettempdir(), "survey"), help="survey: the generated surveys")
    p.add_argument("--generate-only", action="store_true", help="survey: only generate (and measure) the surveys")
    p.add_argument("--delete", action="store_true", help="survey: delete each survey's files after its runs")
    p.add_argument("--one-tile", action="store_true",
                   help="survey: each size written as ONE tile of SIZE km a side (--tile-size), planned block by block")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.what != "survey" and not a.old:
        p.error("--old is needed for same and memory")
    rows = cmd_same(a) if a.what == "same" else cmd_memory(a) if a.what == "memory" else cmd_survey(a)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
