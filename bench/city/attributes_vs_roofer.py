#!/usr/bin/env python3
"""hsr city's attributes on the shared AHN3 buildings against roofer's and against the points (issue 40).

    /usr/bin/python3 bench/city/attributes_vs_roofer.py --roofer PATH [--out DIR] [--jobs 2] [--reuse] [--json FILE]

Why: issue 40's Must show "the attributes on the shared airborne buildings checked against independent figures".
roofer (3DBAG/roofer, the engine of the 3DBAG, whose names hsr's attributes take) is run on the same tile and
footprints (the 56 shared AHN3 buildings laid out by real_buildings_tile.py, --bld-class 6), and so is `hsr city`;
the figures of both are compared building by building, and both against figures this script computes itself
with numpy from the tile's points and from each tool's written solids (numpy only, no hsr code):
  - points: the class-6 points of the tile inside the footprint (the WKT of footprints.csv), even-odd rule;
    their density (per m² of the footprint), their heights' percentiles (roofer's own definition of
    h_roof_*: 2nd, 50th, 70th, 99th percentile of its roof points);
  - solids: volume (divergence theorem over the faces), each roof surface's slope, azimuth and area (Newell
    normal), the heights of the LoD 2.2 roof over the footprint on a 0.25 m grid (hsr's definition of
    b3_h_dak_*), the RMS distance of the footprint's points to each solid (exact point-to-polygon distance).
Each command (hsr city, roofer) runs under flock /tmp/heavy.lock (HSR_BENCH_LOCK; a missing file: no lock).
--reuse: keep DIR's outputs from an earlier run (only the comparison again).

Names: hsr writes 3DBAG's (b3_h_maaiveld, b3_h_dak_min/50p/70p/max, b3_dak_type, b3_volume_lod12/13/22,
b3_rmse_lod12/13/22, b3_puntdichtheid, b3_nodata_fractie; per roof surface b3_hellingshoek, b3_azimut, b3_opp),
roofer its rf_ ones (rf_h_ground, rf_h_roof_min/50p/70p/max, rf_roof_type, rf_volume_*, rf_rmse_*, rf_pt_density,
rf_nodata_frac; per roof surface rf_slope, rf_azimuth; no area: computed from its polygon).
Roof surfaces are matched by plan position: each hsr roof surface of at least --min-area m² to the roofer roof
surface of the same building under its plan centroid (the highest there, as seen from above).
Prints markdown tables (per attribute: buildings, median and 90th percentile of the difference, the worst with
its building); --json keeps every figure per building.
"""
import argparse
import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HSR = os.environ.get("HSR_CLI", os.path.join(ROOT, "build", "hsr"))
LOCK = os.environ.get("HSR_BENCH_LOCK", "/tmp/heavy.lock")
HERE = os.path.dirname(os.path.abspath(__file__))


# ------------------------------------------------------------------------------------------ reading
def read_las(path):
    """x, y, z, classification of a LAS 1.x file (any point format: the first 20 bytes are format 0's)."""
    with open(path, "rb") as f:
        data = f.read()
    offset = int.from_bytes(data[96:100], "little")
    fmt, length = data[104], int.from_bytes(data[105:107], "little")
    n = int.from_bytes(data[107:111], "little")
    scale = np.frombuffer(data, "<f8", 3, 131)
    shift = np.frombuffer(data, "<f8", 3, 155)
    rec = np.frombuffer(data, np.dtype({"names": ["x", "y", "z", "c"], "formats": ["<i4", "<i4", "<i4", "u1"],
                                        "offsets": [0, 4, 8, 15], "itemsize": length}), n, offset)
    cls = rec["c"] & 31 if fmt < 6 else np.frombuffer(data, np.dtype({"names": ["c"], "formats": ["u1"],
                                                                      "offsets": [16], "itemsize": length}), n, offset)["c"]
    xyz = np.stack([rec["x"] * scale[0] + shift[0], rec["y"] * scale[1] + shift[1], rec["z"] * scale[2] + shift[2]], 1)
    return xyz, np.asarray(cls)


def parse_wkt_polygon(wkt):
    """Rings [(n, 2) arrays] of a WKT POLYGON (outer first)."""
    rings = re.findall(r"\(([^()]+)\)", wkt)
    return [np.array([[float(v) for v in p.split()[:2]] for p in r.split(",")]) for r in rings]


def inside_rings(xy, rings):
    """Even-odd rule: points of xy (n, 2) inside the rings (holes are rings too)."""
    inside = np.zeros(len(xy), bool)
    x, y = xy[:, 0], xy[:, 1]
    for r in rings:
        a, b = r, np.roll(r, -1, 0)
        for (x1, y1), (x2, y2) in zip(a, b):
            if y1 == y2:
                continue
            cross = ((y1 > y) != (y2 > y)) & (x < x1 + (y - y1) * (x2 - x1) / (y2 - y1))
            inside ^= cross
    return inside


def shoelace(ring):
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def features(path):
    """[(header, feature)] of a CityJSONSeq file."""
    with open(path) as f:
        lines = [json.loads(line) for line in f if line.strip()]
    return lines[0], lines[1:]


def solids_of(header, feat, obj_ids):
    """{lod: [(polygon rings as (k, 3) arrays, semantic surface dict)]} of the Solids of the given CityObjects."""
    s, t = header["transform"]["scale"], header["transform"]["translate"]
    verts = np.array(feat["vertices"], float) * np.array(s) + np.array(t)
    out = {}
    for oid in obj_ids:
        for g in feat["CityObjects"][oid].get("geometry", []):
            if g["type"] != "Solid":
                continue
            sem = g.get("semantics", {"surfaces": [], "values": []})
            for si, shell in enumerate(g["boundaries"]):
                for fi, face in enumerate(shell):
                    v = sem["values"][si][fi] if sem.get("values") else None
                    surface = sem["surfaces"][v] if v is not None else {}
                    out.setdefault(g["lod"], []).append(([verts[r] for r in face], surface))
    return out


# ------------------------------------------------------------------------------------------ numpy figures
def newell(ring):
    """Newell vector of a ring (its normal times twice its area)."""
    a, b = ring, np.roll(ring, -1, 0)
    return np.array([np.sum((a[:, 1] - b[:, 1]) * (a[:, 2] + b[:, 2])),
                     np.sum((a[:, 2] - b[:, 2]) * (a[:, 0] + b[:, 0])),
                     np.sum((a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1]))])


def face_normal_area(rings):
    """Unit normal and area of a polygon with holes (outer ring counter-clockwise from outside, holes opposite)."""
    n = sum((newell(r) for r in rings), np.zeros(3))  # a hole, turning the other way, takes its area off
    area = np.linalg.norm(n) / 2
    return n / (np.linalg.norm(n) or 1), area


def slope_azimuth(normal):
    """Slope from horizontal (degrees) and azimuth of the plan direction of the normal (degrees clockwise from
    north = +y; None when horizontal), as 3DBAG defines b3_hellingshoek and b3_azimut."""
    slope = math.degrees(math.acos(max(-1.0, min(1.0, abs(normal[2])))))
    if normal[0] == 0 and normal[1] == 0:
        return slope, None
    return slope, math.degrees(math.atan2(normal[0], normal[1])) % 360


def volume(faces):
    """Volume enclosed by the faces (divergence theorem: sum of centroid . Newell / 6 over fan triangles)."""
    v = 0.0
    for rings, _ in faces:
        for k, r in enumerate(rings):
            o = r[0]
            for i in range(1, len(r) - 1):
                v += np.dot(o, np.cross(r[i], r[i + 1])) / 6.0  # a hole turns the other way
    return abs(v)


def roof_grid_heights(faces, fp_rings, cell=0.25):
    """Heights of the topmost roof face over each cell centre of a `cell` grid inside the footprint (hsr's
    definition of b3_h_dak_*: the LoD 2.2 model's roof over its plan)."""
    lo, hi = np.min(np.vstack(fp_rings), 0), np.max(np.vstack(fp_rings), 0)
    nx, ny = max(1, math.ceil((hi[0] - lo[0]) / cell)), max(1, math.ceil((hi[1] - lo[1]) / cell))
    gx, gy = np.meshgrid(lo[0] + (np.arange(nx) + 0.5) * cell, lo[1] + (np.arange(ny) + 0.5) * cell)
    xy = np.stack([gx.ravel(), gy.ravel()], 1)
    xy = xy[inside_rings(xy, fp_rings)]
    best = np.full(len(xy), -np.inf)
    for rings, surface in faces:
        if surface.get("type") != "RoofSurface":
            continue
        n, _ = face_normal_area(rings)
        if abs(n[2]) < 1e-9:
            continue
        ins = inside_rings(xy, [r[:, :2] for r in rings])
        p = rings[0][0]
        z = p[2] - (n[0] * (xy[ins, 0] - p[0]) + n[1] * (xy[ins, 1] - p[1])) / n[2]
        best[ins] = np.maximum(best[ins], z)
    return best[np.isfinite(best)]


def nearest_rank(values, p):
    """The p-th percentile by nearest rank: the sorted values' element p/100 (n - 1), rounded half up (hsr's)."""
    v = np.sort(values)
    return float(v[int(math.floor(p / 100 * (len(v) - 1) + 0.5))])


def point_polygon_distance(pts, rings):
    """Exact distance of each point to a planar polygon with holes."""
    n, _ = face_normal_area(rings)
    o = rings[0][0]
    u = rings[0][1] - o
    u = u - np.dot(u, n) * n
    u /= np.linalg.norm(u) or 1
    w = np.cross(n, u)
    d = pts - o
    h = d @ n
    uv = np.stack([d @ u, d @ w], 1)
    rings2 = [np.stack([(r - o) @ u, (r - o) @ w], 1) for r in rings]
    ins = inside_rings(uv, rings2)
    edge = np.full(len(pts), np.inf)
    for r in rings:
        a, b = r, np.roll(r, -1, 0)
        ab = b - a
        for k in range(len(r)):
            L = np.dot(ab[k], ab[k])
            t = np.clip(((pts - a[k]) @ ab[k]) / L, 0, 1) if L > 0 else np.zeros(len(pts))
            edge = np.minimum(edge, np.linalg.norm(pts - (a[k] + t[:, None] * ab[k]), axis=1))
    return np.where(ins, np.abs(h), edge)


def rms_to_solid(pts, faces):
    if not len(pts) or not faces:
        return None
    best = np.full(len(pts), np.inf)
    for rings, _ in faces:
        best = np.minimum(best, point_polygon_distance(pts, rings))
    return float(np.sqrt(np.mean(best ** 2)))


def roof_surfaces(faces, min_area):
    """[(plan centroid, slope, azimuth, area, written attributes)] of the roof faces of at least min_area."""
    out = []
    for rings, surface in faces:
        if surface.get("type") != "RoofSurface":
            continue
        n, area = face_normal_area(rings)
        if area < min_area or n[2] <= 0:
            continue
        plan = rings[0][:, :2]
        a = shoelace(plan)
        c = plan.mean(0) if abs(a) < 1e-9 else np.array([
            np.sum((plan[:, 0] + np.roll(plan[:, 0], -1)) * (plan[:, 0] * np.roll(plan[:, 1], -1) - np.roll(plan[:, 0], -1) * plan[:, 1])),
            np.sum((plan[:, 1] + np.roll(plan[:, 1], -1)) * (plan[:, 0] * np.roll(plan[:, 1], -1) - np.roll(plan[:, 0], -1) * plan[:, 1]))]) / (6 * a)
        slope, az = slope_azimuth(n)
        out.append({"centroid": c, "slope": slope, "azimuth": az, "area": area, "rings": rings, "normal": n,
                    "written": surface})
    return out


def angle_diff(a, b):
    d = abs(a - b) % 360
    return min(d, 360 - d)


# ------------------------------------------------------------------------------------------ running
def locked(cmd):
    if os.path.exists(LOCK):
        cmd = ["flock", LOCK] + cmd
    t = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 1):
        raise SystemExit("failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr[-3000:]))
    return time.time() - t


def run_tools(args, tile_dir):
    tile, fp = os.path.join(tile_dir, "tile.las"), os.path.join(tile_dir, "footprints.csv")
    hsr_out = os.path.join(args.out, "hsr.city.jsonl")
    rdir = os.path.join(args.out, "roofer")
    if args.reuse and os.path.exists(hsr_out) and os.path.isdir(rdir):
        return hsr_out, rdir
    shutil.rmtree(os.path.join(args.out, "hsr.work"), ignore_errors=True)
    shutil.rmtree(rdir, ignore_errors=True)
    cmd = [HSR, "city", tile, "-o", hsr_out, "-j", str(args.jobs), "-q", "--footprints", fp, "--id-field", "id"]
    print("%s: %.1f s" % (" ".join(cmd), locked(cmd)), file=sys.stderr)
    cmd = [args.roofer, "--lod12", "--lod13", "--lod22", "-j", str(args.jobs), "--bld-class", "6", "--id-attribute", "id",
           tile, fp, rdir]
    print("%s: %.1f s" % (" ".join(cmd), locked(cmd)), file=sys.stderr)
    return hsr_out, rdir


# ------------------------------------------------------------------------------------------ comparing
def per_building(args, tile_dir, hsr_out, rdir):
    xyz, cls = read_las(os.path.join(tile_dir, "tile.las"))
    bxyz = xyz[cls == 6]
    gxyz = xyz[cls == 2]
    fps = {}
    with open(os.path.join(tile_dir, "footprints.csv"), newline="") as f:
        for row in csv.DictReader(f):
            fps[row["id"]] = parse_wkt_polygon(row["WKT"])
    hh, hf = features(hsr_out)
    hsr = {}
    for feat in hf:
        (oid,) = [k for k, o in feat["CityObjects"].items() if o["type"] == "Building"]
        hsr[oid] = (feat["CityObjects"][oid].get("attributes", {}), solids_of(hh, feat, [oid]))
    rof = {}
    for dp, _, names in os.walk(rdir):
        for name in names:
            if not name.endswith(".city.jsonl"):
                continue
            rh, rf = features(os.path.join(dp, name))
            for feat in rf:
                for oid, o in feat["CityObjects"].items():
                    if o["type"] == "Building":
                        rof[o.get("attributes", {}).get("id", oid)] = (o.get("attributes", {}),
                                                                       solids_of(rh, feat, o.get("children", [])))
    rows = []
    for bid in sorted(fps):
        rings = fps[bid]
        sel = inside_rings(bxyz[:, :2], rings)
        pts = bxyz[sel]
        area = abs(shoelace(rings[0])) - sum(abs(shoelace(r)) for r in rings[1:])
        row = {"building": bid, "points": int(len(pts)), "footprint_m2": area}
        if len(pts):
            z = pts[:, 2]
            row["pts"] = {"density": len(pts) / area, "h_p02": float(np.percentile(z, 2)), "h_p50": float(np.percentile(z, 50)),
                          "h_p70": float(np.percentile(z, 70)), "h_p99": float(np.percentile(z, 99))}
        ring = ground_ring(gxyz, rings, 0.5, 3.0)
        if len(ring):
            row.setdefault("pts", {}).update({"ground_p50": float(np.median(ring[:, 2])),
                                              "ground_p05": float(np.percentile(ring[:, 2], 5)), "ground_points": int(len(ring))})
        for tool, data in (("hsr", hsr), ("roofer", rof)):
            if bid not in data:
                continue
            attrs, solids = data[bid]
            key = (lambda k: {"ground": "b3_h_maaiveld", "min": "b3_h_dak_min", "p50": "b3_h_dak_50p", "p70": "b3_h_dak_70p",
                              "max": "b3_h_dak_max", "type": "b3_dak_type", "density": "b3_puntdichtheid",
                              "nodata": "b3_nodata_fractie"}.get(k, "b3_" + k)) if tool == "hsr" else \
                  (lambda k: {"ground": "rf_h_ground", "min": "rf_h_roof_min", "p50": "rf_h_roof_50p", "p70": "rf_h_roof_70p",
                              "max": "rf_h_roof_max", "type": "rf_roof_type", "density": "rf_pt_density",
                              "nodata": "rf_nodata_frac"}.get(k, "rf_" + k))
            t = {"ground_z": attrs.get("hsr_ground_z")} if tool == "hsr" else {}
            t.update({k: attrs.get(key(k)) for k in ("ground", "min", "p50", "p70", "max", "type", "density", "nodata",
                                                 "volume_lod12", "volume_lod13", "volume_lod22", "rmse_lod12", "rmse_lod13",
                                                 "rmse_lod22")})
            if tool == "roofer" and all(t[k] == 0 for k in ("min", "p50", "p70", "max")):
                t["heights_zero"] = True  # roofer wrote 0.0 for all four: no figure (its default), left out
                for k in ("min", "p50", "p70", "max"):
                    t[k] = None
            for lod, faces in solids.items():
                tag = lod.replace(".", "")
                t["np_volume_lod" + tag] = volume(faces)
                if not args.no_rms:
                    t["np_rmse_lod" + tag] = rms_to_solid(pts, faces)
            if "2.2" in solids:
                grid = roof_grid_heights(solids["2.2"], rings)
                if len(grid):
                    t.update({"np_grid_min": nearest_rank(grid, 2), "np_grid_p50": nearest_rank(grid, 50),
                              "np_grid_p70": nearest_rank(grid, 70), "np_grid_max": nearest_rank(grid, 99)})
                surf = roof_surfaces(solids["2.2"], args.min_area)
                t["roof_area"] = sum(s["area"] for s in roof_surfaces(solids["2.2"], 0))
                t["surfaces"] = surf
            row[tool] = t
        rows.append(row)
    return rows


def ground_ring(ground, rings, inner, outer):
    """The ground points between inner and outer (m) outside the footprint in plan (hsr's ring, hsr_ground_source)."""
    allv = np.vstack(rings)
    lo, hi = allv.min(0) - outer, allv.max(0) + outer
    near = ground[np.all((ground[:, :2] >= lo) & (ground[:, :2] <= hi), 1)]
    dist = np.full(len(near), np.inf)
    for r in rings:
        for p, q in zip(r, np.roll(r, -1, 0)):
            t = np.clip(((near[:, :2] - p) @ (q - p)) / max(float(np.dot(q - p, q - p)), 1e-12), 0, 1)
            dist = np.minimum(dist, np.linalg.norm(near[:, :2] - (p + t[:, None] * (q - p)), axis=1))
    return near[(dist >= inner) & (dist <= outer) & ~inside_rings(near[:, :2], rings)]


def match_surfaces(h, r):
    """Pairs (hsr surface, roofer surface): the roofer roof surface whose plan holds hsr's centroid (the highest
    there), else none."""
    pairs = []
    for s in h:
        c = s["centroid"][None, :]
        best, bz = None, -np.inf
        for q in r:
            if inside_rings(c, [ring[:, :2] for ring in q["rings"]])[0]:
                n, p = q["normal"], q["rings"][0][0]
                z = p[2] - (n[0] * (c[0, 0] - p[0]) + n[1] * (c[0, 1] - p[1])) / n[2]
                if z > bz:
                    best, bz = q, z
        pairs.append((s, best))
    return pairs


def stats(diffs):
    """Median and 90th percentile of |difference|, the worst (building, difference), of [(building, diff)]."""
    d = [(b, v) for b, v in diffs if v is not None and math.isfinite(v)]
    if not d:
        return None
    a = np.abs([v for _, v in d])
    w = max(d, key=lambda bv: abs(bv[1]))
    return {"n": len(d), "median_abs": float(np.median(a)), "p90_abs": float(np.percentile(a, 90)),
            "median_signed": float(np.median([v for _, v in d])), "worst": w}


def compare(rows, min_area):
    tables = []

    def diff(name, unit, f, rel=False):
        out = []
        for row in rows:
            try:
                v = f(row)
            except (KeyError, TypeError):
                v = None
            if v is not None:
                out.append((row["building"], v))
        tables.append((name, unit, stats(out)))

    g = lambda row, tool, k: row[tool][k]
    # the written attributes, hsr against roofer
    for k, name in (("ground", "ground height (b3_h_maaiveld − rf_h_ground)"), ("min", "roof min (b3_h_dak_min − rf_h_roof_min)"),
                    ("p50", "roof 50p"), ("p70", "roof 70p"), ("max", "roof max")):
        diff("hsr − roofer: " + name, "m", lambda row, k=k: g(row, "hsr", k) - g(row, "roofer", k))
    for lod in ("12", "13", "22"):
        diff("hsr − roofer: volume LoD %s.%s, relative" % (lod[0], lod[1]), "%",
             lambda row, lod=lod: 100 * (g(row, "hsr", "volume_lod" + lod) / g(row, "roofer", "volume_lod" + lod) - 1))
    for lod in ("12", "13", "22"):
        diff("hsr − roofer: written RMSE LoD %s.%s" % (lod[0], lod[1]), "m",
             lambda row, lod=lod: g(row, "hsr", "rmse_lod" + lod) - g(row, "roofer", "rmse_lod" + lod))
    diff("hsr − roofer: point density, relative", "%", lambda row: 100 * (g(row, "hsr", "density") / g(row, "roofer", "density") - 1))
    diff("hsr − roofer: share without points", "share", lambda row: g(row, "hsr", "nodata") - g(row, "roofer", "nodata"))
    diff("hsr − roofer: LoD 2.2 roof area, relative", "%", lambda row: 100 * (g(row, "hsr", "roof_area") / g(row, "roofer", "roof_area") - 1))
    # against the points (numpy)
    diff("hsr − points: hsr_ground_z against the ground points' median 0.5-3 m around", "m", lambda row: g(row, "hsr", "ground_z") - row["pts"]["ground_p50"])
    diff("hsr − points: b3_h_maaiveld (the LoD 2.2 bottom) against the same median", "m", lambda row: g(row, "hsr", "ground") - row["pts"]["ground_p50"])
    diff("roofer − points: rf_h_ground against the same points' 5th percentile", "m", lambda row: g(row, "roofer", "ground") - row["pts"]["ground_p05"])
    for k, p in (("p50", "h_p50"), ("p70", "h_p70")):  # all the footprint's points (walls too): not roofer's roof points
        diff("hsr − points: roof %s against the points' %s" % (k, p), "m", lambda row, k=k, p=p: g(row, "hsr", k) - row["pts"][p])
        diff("roofer − points: roof %s against the points' %s" % (k, p), "m", lambda row, k=k, p=p: g(row, "roofer", k) - row["pts"][p])
    diff("hsr − points: point density, relative", "%", lambda row: 100 * (g(row, "hsr", "density") / row["pts"]["density"] - 1))
    diff("roofer − points: point density, relative", "%", lambda row: 100 * (g(row, "roofer", "density") / row["pts"]["density"] - 1))
    # each tool's written figures against its own solids (numpy)
    for tool in ("hsr", "roofer"):
        for k in ("min", "p50", "p70", "max"):
            diff("%s − its LoD 2.2 roof's 2/50/70/99th percentile on a 0.25 m grid over the footprint: roof %s" % (tool, k), "m", lambda row, k=k, tool=tool: g(row, tool, k) - g(row, tool, "np_grid_" + k))
        for lod in ("12", "13", "22"):
            diff("%s − its solid: volume LoD %s.%s, relative" % (tool, lod[0], lod[1]), "%",
                 lambda row, lod=lod, tool=tool: 100 * (g(row, tool, "volume_lod" + lod) / g(row, tool, "np_volume_lod" + lod) - 1))
            diff("%s − numpy: RMSE LoD %s.%s (footprint's points to its solid)" % (tool, lod[0], lod[1]), "m",
                 lambda row, lod=lod, tool=tool: g(row, tool, "rmse_lod" + lod) - g(row, tool, "np_rmse_lod" + lod))
    for lod in ("12", "13", "22"):
        diff("hsr − roofer: RMSE LoD %s.%s, both by numpy (footprint's points)" % (lod[0], lod[1]), "m",
             lambda row, lod=lod: g(row, "hsr", "np_rmse_lod" + lod) - g(row, "roofer", "np_rmse_lod" + lod))
    # roof surfaces
    own = {"hsr": ("b3_hellingshoek", "b3_azimut", "b3_opp"), "roofer": ("rf_slope", "rf_azimuth", None)}
    for tool, (ks, ka, kar) in own.items():
        sl, az, ar = [], [], []
        for row in rows:
            for s in row.get(tool, {}).get("surfaces", []):
                w = s["written"]
                if ks in w:
                    sl.append((row["building"], w[ks] - s["slope"]))
                if w.get(ka) is not None and s["azimuth"] is not None and s["slope"] >= 4:
                    az.append((row["building"], angle_diff(w[ka], s["azimuth"])))
                if kar and kar in w:
                    ar.append((row["building"], 100 * (w[kar] / s["area"] - 1)))
        tables.append(("%s − its polygon: roof surface slope" % tool, "°", stats(sl)))
        tables.append(("%s − its polygon: roof surface azimuth (slope ≥ 4°)" % tool, "°", stats(az)))
        if kar:
            tables.append(("%s − its polygon: roof surface area, relative" % tool, "%", stats(ar)))
    sl, az, ar, unmatched, total = [], [], [], 0, 0
    for row in rows:
        if "hsr" not in row or "roofer" not in row:
            continue
        for s, q in match_surfaces(row["hsr"].get("surfaces", []), row["roofer"].get("surfaces", [])):
            total += 1
            if q is None:
                unmatched += 1
                continue
            sl.append((row["building"], s["written"].get("b3_hellingshoek", s["slope"]) - q["written"].get("rf_slope", q["slope"])))
            if s["slope"] >= 4 and q["slope"] >= 4:
                az.append((row["building"], angle_diff(s["written"].get("b3_azimut") or s["azimuth"], q["written"].get("rf_azimuth", q["azimuth"]))))
            ar.append((row["building"], 100 * (s["area"] / q["area"] - 1)))
    tables.append(("hsr − roofer: roof surface slope (%d of %d hsr surfaces ≥ %g m² matched)" % (total - unmatched, total, min_area), "°", stats(sl)))
    tables.append(("hsr − roofer: roof surface azimuth (both ≥ 4°)", "°", stats(az)))
    tables.append(("hsr − roofer: matched roof surface area, relative", "%", stats(ar)))
    types = {}
    for row in rows:
        if "hsr" in row and "roofer" in row:
            k = (row["hsr"]["type"], row["roofer"]["type"])
            types.setdefault(k, []).append(row["building"])
    return tables, types


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--roofer", default="/work/peers/roofer/build/apps/roofer-app/roofer")
    p.add_argument("--out", default="/tmp/hsr_attributes_vs_roofer")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--reuse", action="store_true", help="compare DIR's outputs of an earlier run again")
    p.add_argument("--min-area", type=float, default=5.0, help="roof surfaces compared: at least this area, m²")
    p.add_argument("--no-rms", action="store_true", help="skip the numpy RMS distances (the slow part)")
    p.add_argument("--json", help="write every figure per building here")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    tile_dir = os.path.join(args.out, "ahn3_buildings")
    if not os.path.exists(os.path.join(tile_dir, "footprints.csv")):
        subprocess.run([sys.executable, os.path.join(HERE, "real_buildings_tile.py"), tile_dir], check=True)
    hsr_out, rdir = run_tools(args, tile_dir)
    rows = per_building(args, tile_dir, hsr_out, rdir)
    tables, types = compare(rows, args.min_area)
    print("%d footprints; hsr features %d, roofer features %d" % (len(rows), sum("hsr" in r for r in rows),
                                                                   sum("roofer" in r for r in rows)))
    print()
    print("| figure | unit | buildings / surfaces | median of the difference (signed) | median abs | p90 abs | worst (building) |")
    print("|---|---|---|---|---|---|---|")
    for name, unit, s in tables:
        if s is None:
            print("| %s | %s | 0 | — | — | — | — |" % (name, unit))
            continue
        print("| %s | %s | %d | %+.3f | %.3f | %.3f | %+.3f (%s) |" % (name, unit, s["n"], s["median_signed"], s["median_abs"],
                                                                   s["p90_abs"], s["worst"][1], s["worst"][0]))
    print()
    print("| hsr b3_dak_type | roofer rf_roof_type | buildings |")
    print("|---|---|---|")
    for (a, b), ids in sorted(types.items(), key=lambda kv: -len(kv[1])):
        print("| %s | %s | %d%s |" % (a, b, len(ids), "" if a == b else " (" + ", ".join(ids[:6]) + ")"))
    if args.json:
        def clean(o):
            if isinstance(o, dict):
                return {k: clean(v) for k, v in o.items() if k not in ("rings", "normal")}
            if isinstance(o, (list, tuple)):
                return [clean(v) for v in o]
            if isinstance(o, np.ndarray):
                return o.tolist()
            if isinstance(o, np.generic):
                return o.item()
            return o
        with open(args.json, "w") as f:
            json.dump(clean(rows), f, indent=1)


if __name__ == "__main__":
    main()
