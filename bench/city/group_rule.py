#!/usr/bin/env python3
"""The tree rule of `hsr city`'s groups (src/city/city.h step 5, CityParams::max_group_variation; issue 40 item 5).

    /usr/bin/python3 bench/city/group_rule.py [--seeds 1 2 3 4] [--buildings 50] [--trees -1] [--out DIR]
                                              [--real TILE ...] [--jobs 2]

Without classes and without footprints, `hsr city` finds buildings as groups of the points its building rule
lets through; a group whose points' median surface variation is above --max-group-variation is vegetation,
listed as `not-a-building` and not modelled. Per tile, two runs: the rule on (the default) and off
(--max-group-variation 1e9, the behaviour before the rule). Per run: exit code, groups, features written,
groups listed as not-a-building, failed buildings, and on the synthetic tiles (`hsr synth city`, the
unclassified copy, trees beside the buildings) the true buildings found (a feature's plan centre in a true
footprint) and the false buildings (a feature in none). With --show-variation each group's median (from the
not-a-building message of a run at --max-group-variation 0).
Prints a markdown table.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HSR = os.environ.get("HSR_CLI", os.path.join(ROOT, "build", "hsr"))
SHARED = os.environ.get("HSR_SHARED", os.path.join(os.path.dirname(ROOT), "shared"))
REAL = [os.path.join(SHARED, "laz", "autzen_trim.laz"), os.path.join(SHARED, "data", "cgal_urban.las")]

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tile_bench import inside  # noqa: E402  (even-odd point in the footprint rings)


def feature_centres(sequence):
    with open(sequence) as f:
        lines = [json.loads(line) for line in f if line.strip()]
    if not lines:
        return []
    s, t = lines[0]["transform"]["scale"], lines[0]["transform"]["translate"]
    out = []
    for feat in lines[1:]:
        xs = [v[0] * s[0] + t[0] for v in feat["vertices"]]
        ys = [v[1] * s[1] + t[1] for v in feat["vertices"]]
        out.append(((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2))
    return out


def run(tile, out, extra, jobs):
    r = subprocess.run([HSR, "city", tile, "-o", out + ".city.jsonl", "-j", str(jobs), "-q"] + extra,
                       capture_output=True, text=True)
    if r.returncode not in (0, 1):
        raise SystemExit("hsr city failed (%d): %s" % (r.returncode, r.stderr[-2000:]))
    with open(out + ".summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return r.returncode, rows, feature_centres(out + ".city.jsonl")


def medians(tile, out, jobs):
    """Each group's median surface variation (id -> value), from a run that calls every group vegetation."""
    _, rows, _ = run(tile, out, ["--max-group-variation", "0"], jobs)
    return {r["building"]: float(r["message"].split(" is ")[1].split()[0]) for r in rows if r["status"] == "not-a-building"}


def measure(tile, out, truth, jobs, label):
    results = []
    for rule, extra in (("on", []), ("off", ["--max-group-variation", "1e9"])):
        code, rows, centres = run(tile, out + "_" + rule, extra, jobs)
        res = {"tile": label, "rule": rule, "exit": code, "groups": len(rows), "features": len(centres),
               "not_a_building": sum(r["status"] == "not-a-building" for r in rows),
               "failed": sum(r["status"] not in ("ok", "not-a-building") for r in rows)}
        if truth is not None:
            hit = set()
            false = 0
            for x, y in centres:
                ids = [b["id"] for b in truth if any(inside(x, y, poly) for poly in b["footprint"]["coordinates"])]
                if ids:
                    hit.add(ids[0])
                else:
                    false += 1
            res.update({"found": len(hit), "truths": len(truth), "false": false})
        results.append(res)
        print(res, file=sys.stderr)
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", type=int, nargs="*", default=[1, 2, 3, 4])
    p.add_argument("--buildings", type=int, default=50)
    p.add_argument("--trees", type=int, default=-1)
    p.add_argument("--real", nargs="*", default=[t for t in REAL if os.path.exists(t)])
    p.add_argument("--out", default="/tmp/group_rule")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--show-variation", action="store_true")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = []
    for seed in a.seeds:
        tile = os.path.join(a.out, "seed%d" % seed)
        if not os.path.exists(os.path.join(tile, "truth.json")):
            subprocess.run([HSR, "synth", "city", "--buildings", str(a.buildings), "--seed", str(seed), "--trees",
                            str(a.trees), "-o", tile, "-q"], check=True)
        with open(os.path.join(tile, "truth.json")) as f:
            truth = json.load(f)["building"]
        las = os.path.join(tile, "tile_unclassified.las")
        results += measure(las, os.path.join(tile, "run"), truth, a.jobs, "synth seed %d" % seed)
        if a.show_variation:
            print("seed %d medians:" % seed, sorted(medians(las, os.path.join(tile, "var"), a.jobs).values()), file=sys.stderr)
    for t in a.real:
        name = os.path.basename(t).split(".")[0]
        results += measure(t, os.path.join(a.out, name), None, a.jobs, name)
        if a.show_variation:
            print(name, "medians:", medians(t, os.path.join(a.out, name + "_var"), a.jobs), file=sys.stderr)
    print("| tile | rule | exit | groups | features | not-a-building | failed | found | false buildings |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        found = "%d / %d" % (r["found"], r["truths"]) if "found" in r else "—"
        print("| %s | %s | %d | %d | %d | %d | %d | %s | %s |" % (r["tile"], r["rule"], r["exit"], r["groups"], r["features"],
                                                            r["not_a_building"], r["failed"], found, r.get("false", "—")))


if __name__ == "__main__":
    main()
