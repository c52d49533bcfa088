#!/usr/bin/env python3
"""A classified tile of real buildings for hsr city and roofer side by side (issue 43).

    /usr/bin/python3 bench/city/real_buildings_tile.py OUT_DIR [--prefix AHN3_] [--spacing 0.5] [--seed 1]

Why: the issue's real AHN3 tile pair with its cadastre is kept apart from us, and none of the shared real tiles
has footprints. The 66 shared AHN3 buildings (../shared/airborne, ../shared/airborne_more: real AHN3 points of one
building each, City3D's model of each beside it) are real roofs and walls; this lays them out on a grid as one
tile so both tools model the same real points the way they would model a city.

What it writes:
  OUT_DIR/tile.las             LAS 1.2, point format 0, 1 mm steps: each building's points (class 6), moved
                               on a grid; a flat ground of class-2 points on a --spacing grid (2 cm noise, --seed)
                               at the building's ground height (the lowest vertex of City3D's model, the ground
                               City3D was given), --ground-margin around each building, none inside a footprint
  OUT_DIR/footprints.csv       id, WKT (no CRS, as the tile has none): each building's footprint, the plan of the
                               lowest faces of City3D's model (its ground face), moved like its points
  OUT_DIR/MANIFEST.tsv         id, source file, points, footprint area (m²); the buildings left out and why (a
                               City3D model whose ground face holds under --min-held of the points: tiny objects
                               at ground level, a ground face in slivers)
The footprints are City3D's outlines, not a cadastre: where City3D's model is off its points (listed in
bench/results/building_112_issue42.md), both tools get the same off footprint.
"""
import argparse
import math
import os
import struct
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
FOLDERS = ("airborne", "airborne_more")

sys.path.insert(0, os.path.join(ROOT, "bench", "building"))
from variants import read_ply  # noqa: E402  (the shared buildings' PLY reader: points and normals)


def read_ply_xyz(path):
    """The x y z of a shared building's PLY."""
    return read_ply(path)[0]


def read_obj(path):
    vs, fs = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if p and p[0] == "v":
                vs.append([float(x) for x in p[1:4]])
            elif p and p[0] == "f":
                fs.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    return np.array(vs), fs


def ring_area(ring):
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def ground_faces(vs, fs, tol=0.01):
    """The model's faces whose vertices all lie within `tol` of its lowest z, as counter-clockwise plan rings,
    and that z."""
    z0 = float(vs[:, 2].min())
    rings = []
    for f in fs:
        if len(f) >= 3 and all(vs[k, 2] - z0 <= tol for k in f):
            ring = vs[f, :2]
            a = ring_area(ring)
            if abs(a) > 1e-6:
                rings.append(ring if a > 0 else ring[::-1])
    return rings, z0


def inside_any(x, y, rings):
    """A boolean array: (x[i], y[i]) inside one of the rings (even-odd per ring)."""
    out = np.zeros(len(x), bool)
    for ring in rings:
        c = np.zeros(len(x), bool)
        n = len(ring)
        for i in range(n):
            ax, ay = ring[i - 1]
            bx, by = ring[i]
            cross = ((ay > y) != (by > y)) & (x < (bx - ax) * (y - ay) / np.where(by == ay, 1e-300, by - ay) + ax)
            c ^= cross
        out |= c
    return out


def write_las(path, xyz, classes):
    """LAS 1.2, point format 0, scale 0.001, single returns."""
    scale = 0.001
    lo, hi = xyz.min(0), xyz.max(0)
    offset = np.floor(lo)
    ints = np.round((xyz - offset) / scale).astype("<i4")
    rec = np.zeros(len(xyz), np.dtype([("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("intensity", "<u2"),
                                       ("bits", "u1"), ("cls", "u1"), ("angle", "i1"), ("user", "u1"),
                                       ("source", "<u2")]))
    rec["x"], rec["y"], rec["z"] = ints.T
    rec["bits"] = 0b00001001  # return 1 of 1
    rec["cls"] = classes
    header = b"LASF" + struct.pack("<HH", 0, 0) + b"\0" * 16 + struct.pack("<BB", 1, 2)
    header += b"hsr bench".ljust(32, b"\0") + b"real_buildings_tile.py".ljust(32, b"\0")
    header += struct.pack("<HHHIIBHI", 1, 2026, 227, 227, 0, 0, 20, len(xyz))
    header += struct.pack("<5I", len(xyz), 0, 0, 0, 0)
    header += struct.pack("<3d", scale, scale, scale) + struct.pack("<3d", *offset)
    header += struct.pack("<6d", hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    assert len(header) == 227
    with open(path, "wb") as f:
        f.write(header)
        f.write(rec.tobytes())


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("--prefix", default="AHN3_", help="buildings whose file names start so")
    p.add_argument("--spacing", type=float, default=0.5, help="ground grid spacing, m")
    p.add_argument("--gap", type=float, default=12.0, help="free ground between neighbouring buildings' boxes, m")
    p.add_argument("--ground-margin", type=float, default=6.0, help="ground this far around each building's box, m")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--min-held", type=float, default=0.5,
                   help="a building is left out when its footprint (City3D's ground face) holds less of its points")
    args = p.parse_args()
    names = sorted({(folder, f[:-4]) for folder in FOLDERS if os.path.isdir(os.path.join(SHARED, folder))
                    for f in os.listdir(os.path.join(SHARED, folder))
                    if f.startswith(args.prefix) and f.endswith(".ply")})
    if not names:
        sys.exit("real_buildings_tile.py: no %s*.ply in %s/{%s}" % (args.prefix, SHARED, ",".join(FOLDERS)))
    blds, skipped = [], []
    for folder, stem in names:
        pts = read_ply_xyz(os.path.join(SHARED, folder, stem + ".ply"))
        obj = os.path.join(SHARED, folder, stem + "_city3d.obj")
        if not os.path.exists(obj):
            continue
        vs, fs = read_obj(obj)
        rings, z0 = ground_faces(vs, fs)
        held = inside_any(pts[:, 0], pts[:, 1], rings).mean() if rings else 0.0
        if held < args.min_held:
            skipped.append("%s\t%s/%s.ply\t%d\tskipped: City3D's ground face holds %.0f %% of the points" % (
                stem, folder, stem, len(pts), 100 * held))
            continue
        lo = np.minimum(pts[:, :2].min(0), vs[:, :2].min(0))
        hi = np.maximum(pts[:, :2].max(0), vs[:, :2].max(0))
        blds.append((stem, folder, pts, rings, z0, lo, hi))
    cols = int(math.ceil(math.sqrt(len(blds))))
    cell = max(float((b[6] - b[5]).max()) for b in blds) + args.gap
    origin = np.array([100000.0, 400000.0])  # metres, an arbitrary projected-looking place
    rng = np.random.default_rng(args.seed)
    xyz, cls, wkt, manifest, all_rings = [], [], [], [], []
    ground_z, boxes = [], []
    for i, (stem, folder, pts, rings, z0, lo, hi) in enumerate(blds):
        r, c = divmod(i, cols)
        shift = origin + np.array([c, r]) * cell + (cell - (hi - lo)) / 2 - lo
        moved = pts.copy()
        moved[:, :2] += shift
        xyz.append(moved)
        cls.append(np.full(len(moved), 6, np.uint8))
        moved_rings = [ring + shift for ring in rings]
        boxes.append((lo + shift - args.ground_margin, hi + shift + args.ground_margin))
        all_rings.append(moved_rings)
        ground_z.append(z0)
        polys = ["((%s))" % ", ".join("%.3f %.3f" % tuple(q) for q in np.vstack([ring, ring[:1]]))
                 for ring in moved_rings]
        geom = "POLYGON " + polys[0] if len(polys) == 1 else "MULTIPOLYGON (%s)" % ", ".join(polys)
        wkt.append('%s,"%s"' % (stem, geom))
        manifest.append("%s\t%s/%s.ply\t%d\t%.1f" % (stem, folder, stem, len(pts), sum(ring_area(q) for q in rings)))
    # The ground: around each building at its height, nothing inside a footprint.
    for i in range(len(blds)):
        (x0, y0), (x1, y1) = boxes[i]
        gx, gy = np.meshgrid(np.arange(x0, x1, args.spacing), np.arange(y0, y1, args.spacing))
        gx, gy = gx.ravel(), gy.ravel()
        keep = ~inside_any(gx, gy, all_rings[i])
        n = int(keep.sum())
        gz = ground_z[i] + rng.normal(0, 0.02, n)
        xyz.append(np.stack([gx[keep], gy[keep], gz], 1))
        cls.append(np.full(n, 2, np.uint8))
    os.makedirs(args.out, exist_ok=True)
    xyz = np.vstack(xyz)
    write_las(os.path.join(args.out, "tile.las"), xyz, np.concatenate(cls))
    with open(os.path.join(args.out, "footprints.csv"), "w") as f:
        f.write("id,WKT\n" + "".join(w + "\n" for w in wkt))
    with open(os.path.join(args.out, "MANIFEST.tsv"), "w") as f:
        f.write("id\tsource\tpoints\tfootprint_m2\n" + "".join(m + "\n" for m in manifest + skipped))
    print("real_buildings_tile.py: %d buildings, %d points (%d on buildings) in %s; %d left out (MANIFEST.tsv)" % (
        len(blds), len(xyz), sum(len(b[2]) for b in blds), args.out, len(skipped)), file=sys.stderr)


if __name__ == "__main__":
    main()
