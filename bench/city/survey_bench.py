#!/usr/bin/python3
"""Tiles cut through buildings are one survey (issue 40 item 1; docs/results/city.md "Tiles of a survey").

    /usr/bin/python3 bench/city/survey_bench.py synth [--buildings 50] [--seeds 1 2 3] [--tiles 3] [--out DIR]
    /usr/bin/python3 bench/city/survey_bench.py real [--out DIR]      # cgal_urban.las, autzen_trim.las

synth: `hsr synth city --tiles T` writes the survey whole (tile.las) and cut into T x T tiles along equal lines
through whatever buildings they cross (tiles/). `hsr city` on the whole tile and on the tiles (classes and
footprints; then classes without footprints): buildings found, planned twice (must be 0), and for the buildings
a cut line crosses (their truth footprint in two tiles) the symmetric Chamfer distance to the truth
(tile_bench.evaluate_run: `hsr eval --truth`, % of the points' bbox diagonal), tiled against whole.
real: each real tile run whole (groups, its classes), then cut by bench/city/split_tiles.py along x and y
through the centre of its largest model; the tiles run as one survey: models, and each whole model's nearest
tiled model compared to it (`hsr eval POINTS TILED --truth WHOLE`: Chamfer, % of the diagonal).
"""
import argparse
import glob
import json
import os
import statistics
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tile_bench import HSR, ROOT, decoded_vertices, evaluate_run, features, sh, single_feature_file, summary  # noqa: E402

SPLIT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "split_tiles.py")


def las_extent(path):
    """(min x, min y, max x, max y) of a LAS header."""
    with open(path, "rb") as f:
        h = f.read(227)
    max_x, min_x, max_y, min_y = struct.unpack_from("<4d", h, 179)
    return min_x, min_y, max_x, max_y


def tile_of(x, y, extents):
    for i, (a, b, c, d) in enumerate(extents):
        if a <= x <= c and b <= y <= d:
            return i
    return -1


def crossed(building, extents):
    """True when the truth footprint's vertices lie in more than one tile (a cut line crosses it)."""
    ring = building["footprint"]["coordinates"][0][0]
    return len({tile_of(x, y, extents) for x, y in ring}) > 1


def run_survey(tile_dir, tiles, footprints, out):
    cmd = [HSR, "city"] + tiles + ["-o", out, "-j", "2", "-q"]
    if footprints:
        cmd += ["--footprints", os.path.join(tile_dir, "footprints.geojson"), "--id-field", "id"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 1):
        raise SystemExit("hsr city failed: %s" % r.stderr[-2000:])


def cmd_synth(args):
    rows = []
    for seed in args.seeds:
        d = os.path.join(args.out, "seed%d" % seed)
        if not os.path.exists(os.path.join(d, "truth.json")):
            sh([HSR, "synth", "city", "--buildings", str(args.buildings), "--seed", str(seed), "--tiles", str(args.tiles),
                "-o", d, "-q"])
        tiles = sorted(glob.glob(os.path.join(d, "tiles", "*.las")))
        extents = [las_extent(t) for t in tiles]
        truth = json.load(open(os.path.join(d, "truth.json")))
        cut = {b["id"] for b in truth["building"] if crossed(b, extents)}
        for footprints in (True, False):
            label = "footprints" if footprints else "groups"
            whole = os.path.join(d, "whole_" + label)
            run_survey(d, [os.path.join(d, "tile.las")], footprints, whole + ".city.jsonl")
            w = evaluate_run(d, whole, "whole")
            tiled_dir = os.path.join(d, "tiled_" + label)
            run_survey(d, tiles, footprints, tiled_dir)
            details, failed, feats = [], 0, 0
            for t in tiles:
                prefix = os.path.join(tiled_dir, os.path.splitext(os.path.basename(t))[0])
                if not os.path.exists(prefix + ".city.jsonl"):
                    continue
                e = evaluate_run(d, prefix, "tile")
                details += e["detail"]
                failed += e["failed"]
                feats += e["features"]
            seen = {}
            for x in details:
                seen.setdefault(x["truth"], []).append(x)
            wd = {x["truth"]: x for x in w["detail"]}
            pairs = [(wd[t]["chamfer_pct"], seen[t][0]["chamfer_pct"]) for t in cut if t in wd and t in seen]
            rows.append({"seed": seed, "run": label, "truths": len(truth["building"]), "cut": len(cut),
                         "found_whole": w["found"], "found_tiled": len(seen), "twice": sum(len(v) > 1 for v in seen.values()),
                         "features_whole": w["features"], "features_tiled": feats, "failed_tiled": failed,
                         "cut_found": len(pairs),
                         "cut_chamfer_whole": statistics.median([p[0] for p in pairs]) if pairs else None,
                         "cut_chamfer_tiled": statistics.median([p[1] for p in pairs]) if pairs else None,
                         "cut_worst_ratio": max((p[1] / p[0] for p in pairs if p[0] > 0), default=None),
                         "cut_within_10pct": sum(p[1] <= 1.1 * p[0] for p in pairs),
                         "invalid_tiled": sum(not x["valid"] for x in details)})
            r = rows[-1]
            print("seed %d %s: found %d / %d, tiled %d (twice %d), cut %d: median Chamfer %s -> %s, within 10 %% %d" % (
                seed, label, r["found_whole"], r["truths"], r["found_tiled"], r["twice"], r["cut"], r["cut_chamfer_whole"],
                r["cut_chamfer_tiled"], r["cut_within_10pct"]), file=sys.stderr)
    print("| seed | buildings from | truths | found whole / tiled | planned twice | features whole / tiled | cut by a line (found) "
          "| their median Chamfer % whole → tiled | worst tiled / whole | within 10 % | invalid |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    f = lambda v: "—" if v is None else "%.3f" % v
    for r in rows:
        print("| %d | %s | %d | %d / %d | %d | %d / %d | %d (%d) | %s → %s | %s | %d of %d | %d |" % (
            r["seed"], r["run"], r["truths"], r["found_whole"], r["found_tiled"], r["twice"], r["features_whole"],
            r["features_tiled"], r["cut"], r["cut_found"], f(r["cut_chamfer_whole"]), f(r["cut_chamfer_tiled"]),
            f(r["cut_worst_ratio"]), r["cut_within_10pct"], r["cut_found"], r["invalid_tiled"]))
    return rows


REAL = [("cgal_urban", "../shared/data/cgal_urban.las"), ("autzen_trim", "../shared/laz/autzen_trim.las")]


def centre(header, feat):
    vs = decoded_vertices(header, feat)
    return [(min(v[k] for v in vs) + max(v[k] for v in vs)) / 2 for k in range(2)], len(vs)


def cmd_real(args):
    rows = []
    for name, rel in REAL:
        path = os.path.join(ROOT, rel)
        if not os.path.exists(path):
            print("%s absent, skipped" % path, file=sys.stderr)
            continue
        d = os.path.join(args.out, name)
        os.makedirs(d, exist_ok=True)
        run_survey(d, [path], False, os.path.join(d, "whole.city.jsonl"))
        header, whole = features(os.path.join(d, "whole.city.jsonl"))
        if not whole:
            continue
        (cx, cy), _ = centre(header, max(whole, key=lambda f: centre(header, f)[1]))
        sh(["/usr/bin/python3", SPLIT, path, os.path.join(d, "tiles"), "--x", "%.3f" % cx, "--y", "%.3f" % cy])
        tiles = sorted(glob.glob(os.path.join(d, "tiles", "*.las")))
        run_survey(d, tiles, False, os.path.join(d, "tiled"))
        tiled = []
        for t in tiles:
            seq = os.path.join(d, "tiled", os.path.splitext(os.path.basename(t))[0] + ".city.jsonl")
            if os.path.exists(seq):
                h, fs = features(seq)
                rws = {r["building"]: r for r in summary(seq[:-len(".city.jsonl")] + ".summary.csv")}
                tiled += [(h, f, rws[f["id"]]["input"]) for f in fs]
        wrows = {r["building"]: r for r in summary(os.path.join(d, "whole.summary.csv"))}
        tmp = tempfile.mkdtemp(prefix="survey_bench_")
        chamfers = []
        for f in whole:
            (x, y), _ = centre(header, f)
            best = min(tiled, key=lambda t: (centre(t[0], t[1])[0][0] - x) ** 2 + (centre(t[0], t[1])[0][1] - y) ** 2, default=None)
            if best is None:
                continue
            a, b = os.path.join(tmp, "w_" + f["id"] + ".city.jsonl"), os.path.join(tmp, "t_" + best[1]["id"] + ".city.jsonl")
            single_feature_file(header, f, a)
            single_feature_file(best[0], best[1], b)
            ev = json.loads(sh([HSR, "eval", wrows[f["id"]]["input"], b, "--truth", a, "--json"]).stdout)
            chamfers.append(100 * ev["accuracy"]["chamfer"])
        rows.append({"tile": name, "cut_at": [cx, cy], "tiles": len(tiles), "models_whole": len(whole), "models_tiled": len(tiled),
                     "chamfer_median": statistics.median(chamfers) if chamfers else None,
                     "chamfer_max": max(chamfers) if chamfers else None})
        print("%s: %d models whole, %d tiled; Chamfer tiled vs whole median %s max %s" % (
            name, len(whole), len(tiled), rows[-1]["chamfer_median"], rows[-1]["chamfer_max"]), file=sys.stderr)
    print("| tile | cut (x, y) through its largest model | tiles | models whole / tiled | Chamfer tiled vs whole model, median / max % |")
    print("|---|---|---|---|---|")
    for r in rows:
        print("| %s | %.1f, %.1f | %d | %d / %d | %.3f / %.3f |" % (r["tile"], r["cut_at"][0], r["cut_at"][1], r["tiles"],
                                                                 r["models_whole"], r["models_tiled"], r["chamfer_median"] or 0,
                                                                 r["chamfer_max"] or 0))
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("what", choices=["synth", "real"])
    p.add_argument("--buildings", type=int, default=50)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--tiles", type=int, default=3)
    p.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "hsr_survey_bench"))
    p.add_argument("--json", help="write the raw figures here")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    res = {"synth": cmd_synth, "real": cmd_real}[a.what](a)
    if a.json:
        json.dump(res, open(a.json, "w"), indent=1)


if __name__ == "__main__":
    main()
