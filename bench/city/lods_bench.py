#!/usr/bin/python3
"""The LoDs and attributes of `hsr city` features (issue 40 item 3; docs/guide/batch-and-city.md "LoDs and
attributes of a feature"; DECISIONS "Each feature carries LoD 1.2, 1.3 and 2.2").

    PYTHONPATH=build/python /usr/bin/python3 bench/city/lods_bench.py [--seeds 1,2,3] [--buildings 30]
        [--hsr build/hsr] [--base OTHER_HSR] [--work /tmp/lods_bench] [--reuse]

Per tile (`hsr synth city --seed S --buildings N` with its footprints, and the shared real tiles cgal_urban and
autzen_trim, groups without footprints): `hsr city -j 2`; every Solid of every feature decoded from the sequence
and checked by eval's check_validity (hsr.evaluate, independent of the writer's own check); LoD 1.3's levels;
for the synthetic tiles each LoD 2.2 roof surface of 10 m² or more against the generator's truth (the truth's
topmost roof face over a plan point inside the surface): slope and azimuth errors. With --base, the same tile run by
another hsr (e.g. main's, without the LoDs): its LoD 2.2 must be the same (boundaries, vertices, surface types).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

import hsr

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.environ.get("HSR_SHARED", os.path.join(os.path.dirname(ROOT), "shared"))
REAL = [("cgal_urban", os.path.join(SHARED, "data", "cgal_urban.las")),
        ("autzen_trim", os.path.join(SHARED, "laz", "autzen_trim.las"))]


def run(args):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode not in (0, 1):
        sys.exit("failed: %s\n%s" % (" ".join(args), r.stderr))
    return r


def features(path):
    with open(path) as f:
        lines = f.read().splitlines()
    header = json.loads(lines[0])
    return header, [json.loads(line) for line in lines[1:]]


def solids(feature, header):
    """(id, attributes, [(lod, vertices (global), faces, surfaces (semantic object per face))])."""
    (bid, b), = feature["CityObjects"].items()
    scale, translate = header["transform"]["scale"], header["transform"]["translate"]
    verts = [[q[k] * scale[k] + translate[k] for k in range(3)] for q in feature["vertices"]]
    out = []
    for g in b["geometry"]:
        faces = [s[0] for s in g["boundaries"][0]]
        used = sorted({i for f in faces for i in f})
        local = {v: k for k, v in enumerate(used)}
        sem = g.get("semantics", {})
        surfaces = [sem["surfaces"][v] if v is not None else {} for v in sem.get("values", [[None] * len(faces)])[0]]
        out.append((g["lod"], [verts[v] for v in used], [[local[i] for i in f] for f in faces], surfaces))
    return bid, b.get("attributes", {}), out


def valid(vertices, faces):
    r = hsr.evaluate(vertices, vertices, faces, samples=1000)
    return r["valid"]


def newell(vs, f):
    n = [0.0, 0.0, 0.0]
    for i in range(len(f)):
        a, b = vs[f[i]], vs[f[(i + 1) % len(f)]]
        n[0] += (a[1] - b[1]) * (a[2] + b[2])
        n[1] += (a[2] - b[2]) * (a[0] + b[0])
        n[2] += (a[0] - b[0]) * (a[1] + b[1])
    return n


def inside(vs, f, x, y):
    c = False
    j = len(f) - 1
    for i in range(len(f)):
        a, b = vs[f[i]], vs[f[j]]
        if (a[1] > y) != (b[1] > y) and x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]:
            c = not c
        j = i
    return c


def read_obj(path):
    vs, fs = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if p and p[0] == "v":
                vs.append([float(x) for x in p[1:4]])
            elif p and p[0] == "f":
                fs.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    return vs, fs


def point_in_face(vs, face):
    """A plan point well inside the face: of its vertex average and its fan triangles' centres, the one inside
    it farthest from its edges (an L-shaped face's vertex average can lie outside it, over another roof; a
    point near an edge can lie over the truth's neighbouring face where the model's edge is off the truth's)."""
    cands = [(sum(vs[i][0] for i in face) / len(face), sum(vs[i][1] for i in face) / len(face))]
    for i in range(1, len(face) - 1):
        cands.append(((vs[face[0]][0] + vs[face[i]][0] + vs[face[i + 1]][0]) / 3,
                      (vs[face[0]][1] + vs[face[i]][1] + vs[face[i + 1]][1]) / 3))

    def depth(x, y):
        d = math.inf
        for i in range(len(face)):
            a, b = vs[face[i]], vs[face[(i + 1) % len(face)]]
            dx, dy = b[0] - a[0], b[1] - a[1]
            L = dx * dx + dy * dy
            t = 0 if L == 0 else max(0.0, min(1.0, ((x - a[0]) * dx + (y - a[1]) * dy) / L))
            d = min(d, math.hypot(x - a[0] - t * dx, y - a[1] - t * dy))
        return d

    inside_ones = [c for c in cands if inside(vs, face, *c)]
    return max(inside_ones, key=lambda c: depth(*c)) if inside_ones else cands[0]


def truth_normal(tv, tf, x, y):
    """The unit normal of the truth's topmost upward face over (x, y), or None."""
    best, normal = -math.inf, None
    for f in tf:
        n = newell(tv, f)
        if n[2] <= 0 or not inside(tv, f, x, y):
            continue
        p = tv[f[0]]
        z = p[2] - (n[0] * (x - p[0]) + n[1] * (y - p[1])) / n[2]
        if z > best:
            norm = math.sqrt(sum(c * c for c in n))
            best, normal = z, [c / norm for c in n]
    return normal


def lod22_key(feature):
    (bid, b), = feature["CityObjects"].items()
    g = b["geometry"][0]
    n = 1 + max(i for s in g["boundaries"][0] for r in s for i in r)
    types = [g["semantics"]["surfaces"][v]["type"] for v in g["semantics"]["values"][0]]
    return g["lod"], g["boundaries"], feature["vertices"][:n], types


def tile(name, las, args, footprints=None, truth_dir=None):
    out = os.path.join(args.work, name)
    cmd = [args.hsr, "city", las, "-o", out + ".city.jsonl", "-j", "2", "-q"]
    if footprints:
        cmd += ["--footprints", footprints, "--id-field", "id"]
    if not (args.reuse and os.path.exists(out + ".city.jsonl")):
        run(cmd)
    header, feats = features(out + ".city.jsonl")
    row = {"tile": name, "features": len(feats), "invalid": {"1.2": 0, "1.3": 0, "2.2": 0}, "missing": 0,
           "levels": {}, "fallback": 0, "slope_err": [], "azimuth_err": []}
    for f in feats:
        bid, attrs, ss = solids(f, header)
        lods = [s[0] for s in ss]
        row["missing"] += lods != ["2.2", "1.2", "1.3"]
        for lod, vs, fs, _ in ss:
            row["invalid"][lod] += not valid(vs, fs)
        row["levels"][attrs.get("hsr_lod13_parts")] = row["levels"].get(attrs.get("hsr_lod13_parts"), 0) + 1
        row["fallback"] += "hsr_lod13_note" in attrs
        if truth_dir:
            tv, tf = read_obj(os.path.join(truth_dir, bid + ".obj"))
            _, vs, fs, surfaces = ss[0]
            for face, s in zip(fs, surfaces):
                if s.get("type") != "RoofSurface" or s.get("b3_opp", 0) < 10:
                    continue
                cx, cy = point_in_face(vs, face)
                n = truth_normal(tv, tf, cx, cy)
                if n is None:
                    continue
                slope = math.degrees(math.acos(max(-1.0, min(1.0, n[2]))))
                row["slope_err"].append((abs(s["b3_hellingshoek"] - slope), name + " " + bid, slope))
                if slope > 5:
                    az = math.degrees(math.atan2(n[0], n[1])) % 360
                    d = abs((s["b3_azimut"] - az + 180) % 360 - 180)
                    row["azimuth_err"].append((d, name + " " + bid, slope))
    if args.base and not (args.reuse and os.path.exists(out + ".base.city.jsonl")):
        run([args.base, "city"] + cmd[2:3] + ["-o", out + ".base.city.jsonl"] + cmd[5:])
    if args.base:
        _, base = features(out + ".base.city.jsonl")
        row["lod22_same"] = sum(lod22_key(a) == lod22_key(b) for a, b in zip(base, feats)) if len(base) == len(feats) else -1
    return row


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", default="1,2,3")
    p.add_argument("--buildings", type=int, default=30)
    p.add_argument("--hsr", default=os.path.join(ROOT, "build", "hsr"))
    p.add_argument("--base", default="")
    p.add_argument("--work", default="/tmp/lods_bench")
    p.add_argument("--reuse", action="store_true", help="check the sequences already in --work (no hsr city run)")
    args = p.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rows = []
    for seed in [int(s) for s in args.seeds.split(",")]:
        d = os.path.join(args.work, "synth%d" % seed)
        if not os.path.exists(os.path.join(d, "truth.json")):
            run([args.hsr, "synth", "city", "--buildings", str(args.buildings), "--seed", str(seed), "-o", d, "-q"])
        rows.append(tile("synth%d" % seed, os.path.join(d, "tile.las"), args, os.path.join(d, "footprints.geojson"),
                         os.path.join(d, "truth")))
        print(rows[-1]["tile"], "done", file=sys.stderr)
    for name, las in REAL:
        if os.path.exists(las):
            rows.append(tile(name, las, args))
            print(name, "done", file=sys.stderr)
    print("| tile | features | all three LoDs | invalid LoD 1.2 / 1.3 / 2.2 | LoD 1.3 levels (count) | LoD 1.3 = block "
          "(note) | LoD 2.2 as --base |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        levels = ", ".join("%s: %d" % (k, v) for k, v in sorted(r["levels"].items(), key=lambda kv: str(kv[0])))
        print("| %s | %d | %d | %d / %d / %d | %s | %d | %s |" % (
            r["tile"], r["features"], r["features"] - r["missing"], r["invalid"]["1.2"], r["invalid"]["1.3"],
            r["invalid"]["2.2"], levels, r["fallback"], r.get("lod22_same", "—")))
    slope = sorted(e for r in rows for e in r["slope_err"])
    az = sorted(e for r in rows for e in r["azimuth_err"])
    if slope:
        q = lambda v, f: v[min(len(v) - 1, int(f * len(v)))][0]
        print()
        print("Roof surfaces of 10 m² or more against the truth (synthetic tiles): %d slopes, error median %.2f°, "
              "95th percentile %.2f°, worst %.2f° (%s, truth %.1f°); %d azimuths (slopes over 5°), error median %.2f°, "
              "95th percentile %.2f°, worst %.2f° (%s, truth slope %.1f°)" % (
                  len(slope), statistics.median(e[0] for e in slope), q(slope, 0.95), slope[-1][0], slope[-1][1],
                  slope[-1][2], len(az), statistics.median(e[0] for e in az), q(az, 0.95), az[-1][0], az[-1][1], az[-1][2]))
        print("Slope errors over 5°: %d of %d; azimuth errors over 5°: %d of %d" % (
            sum(e[0] > 5 for e in slope), len(slope), sum(e[0] > 5 for e in az), len(az)))


if __name__ == "__main__":
    main()
