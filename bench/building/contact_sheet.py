#!/usr/bin/python3
"""Contact sheet of real buildings (issue 24): hsr's model beside City3D's model of the same scan, each pair
drawn from the same camera over the same box (matplotlib's mplot3d, Debian's python3-matplotlib; no browser).

Faces are coloured by what they are, from their normal (as src/core/face_class.h does for files without
classes): roofs terracotta (facing up), walls grey (vertical within |n_z| < 0.2), ground dark (facing down).
The scan's points are drawn over both, small and black. Each cell is titled with the building's name and its
figures from airborne.py's CSV when given (City3D → hsr and back, % of City3D's diagonal; on City3D's ground).

    /usr/bin/python3 bench/building/contact_sheet.py --models DIR [--csv airborne.csv] [--only A,B,...]
        [--dir ../shared/airborne_more ...] [--columns 4] -o sheet.png

DIR holds NAME.obj (hsr's models, e.g. airborne.py --keep DIR).
"""
import argparse, csv, math, os, sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
import numpy as np


def read_obj(path):
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                v.append([float(x) for x in t[1:4]])
            elif t[0] == "f":
                f.append([int(x.split("/")[0]) - 1 for x in t[1:]])
    return np.array(v), f


def read_ply_points(path, limit=4000):
    with open(path, "rb") as fh:
        header = []
        while True:
            line = fh.readline().decode("ascii", "replace").strip()
            header.append(line)
            if line == "end_header":
                break
        body = fh.read()
    count = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
    props = [l.split()[1] for l in header if l.startswith("property")]
    types = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8", "uchar": "u1", "uint8": "u1"}
    if "ascii" in next(l for l in header if l.startswith("format")):
        pts = np.array([[float(x) for x in r.split()[:3]] for r in body.decode().split("\n")[:count] if r.strip()])
    else:
        dt = np.dtype([(f"p{i}", types[t]) for i, t in enumerate(props)])
        rec = np.frombuffer(body[:dt.itemsize * count], dtype=dt)
        pts = np.stack([rec["p0"].astype(float), rec["p1"].astype(float), rec["p2"].astype(float)], axis=1)
    step = max(1, len(pts) // limit)
    return pts[::step]


COLOURS = {"roof": (0.80, 0.42, 0.30), "wall": (0.78, 0.78, 0.80), "ground": (0.30, 0.30, 0.33)}


def face_colour(poly):
    n = np.zeros(3)
    for i in range(len(poly)):  # Newell's normal
        a, b = poly[i], poly[(i + 1) % len(poly)]
        n += np.array([(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])])
    norm = np.linalg.norm(n)
    if norm == 0:
        return COLOURS["wall"], n
    n /= norm
    kind = "wall" if abs(n[2]) < 0.2 else ("roof" if n[2] > 0 else "ground")
    base = np.array(COLOURS[kind])
    light = 0.55 + 0.45 * max(0.0, float(n @ np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])))
    return tuple(np.clip(base * light, 0, 1)), n


def draw(ax, verts, faces, points, centre, radius, title):
    polys, colours = [], []
    for f in faces:
        p = verts[f] - centre
        c, _ = face_colour(p)
        polys.append(p)
        colours.append(c)
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors=(0.15, 0.15, 0.15, 0.6), linewidths=0.3))
    if points is not None and len(points):
        q = points - centre
        ax.scatter(q[:, 0], q[:, 1], q[:, 2], s=0.3, c="k", alpha=0.5, depthshade=False)
    for set_lim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        set_lim(-radius, radius)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=28, azim=-55)
    ax.set_axis_off()
    ax.set_title(title, fontsize=6)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.path.join(here, "..", "..", "..", "shared")
    ap.add_argument("--models", required=True, help="folder of hsr's NAME.obj")
    ap.add_argument("--dir", action="append", help="folders of the scans and City3D's models (default: airborne, airborne_more)")
    ap.add_argument("--csv", help="airborne.py's CSV, for the figures in the titles")
    ap.add_argument("--only", help="comma-separated names, in this order")
    ap.add_argument("--columns", type=int, default=4, help="building pairs per row")
    ap.add_argument("-o", "--output", required=True)
    a = ap.parse_args()
    dirs = a.dir or [os.path.join(shared, "airborne"), os.path.join(shared, "airborne_more")]
    figures = {r["input"]: r for r in csv.DictReader(open(a.csv))} if a.csv else {}
    names = a.only.split(",") if a.only else sorted(n[:-4] for n in os.listdir(a.models) if n.endswith(".obj"))
    cells = []
    for name in names:
        scan = next((os.path.join(d, name + ".ply") for d in dirs if os.path.exists(os.path.join(d, name + ".ply"))), None)
        model = os.path.join(a.models, name + ".obj")
        if scan is None:
            sys.exit(f"contact_sheet.py: no scan {name}.ply in {dirs}")
        cells.append((name, scan, model if os.path.exists(model) else None, scan[:-4] + "_city3d.obj"))
    cols = max(1, a.columns)
    rows = math.ceil(len(cells) / cols)
    fig = plt.figure(figsize=(2 * 2.2 * cols, 2.3 * rows), dpi=110)
    for i, (name, scan, model, city3d) in enumerate(cells):
        pts = read_ply_points(scan)
        cv, cf = read_obj(city3d)
        hv, hf = read_obj(model) if model else (np.zeros((0, 3)), [])
        allv = np.vstack([pts, cv] + ([hv] if len(hv) else []))
        lo, hi = allv.min(0), allv.max(0)
        centre, radius = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo)) * 1.02
        r = figures.get(name, {})
        fmt = lambda k: f"{float(r[k]):.1f}" if r.get(k) not in (None, "") else "–"
        status = "" if model else " (no model)"
        ax = fig.add_subplot(rows, 2 * cols, 2 * i + 1, projection="3d")
        draw(ax, hv, hf, pts, centre, radius, f"{name} hsr{status}\nC3D→hsr {fmt('city3d_to_hsr')} / back "
             f"{fmt('hsr_to_city3d')} / on C3D ground {fmt('city3d_to_hsr_at_city3d_ground')} %")
        ax = fig.add_subplot(rows, 2 * cols, 2 * i + 2, projection="3d")
        draw(ax, cv, cf, pts, centre, radius, f"{name} City3D\np2m hsr {fmt('p2m')} / City3D {fmt('city3d_p2m')} %")
    fig.subplots_adjust(left=0, right=1, bottom=0, top=0.97, wspace=0, hspace=0.12)
    fig.savefig(a.output)
    print(f"contact_sheet.py: wrote {a.output} ({len(cells)} buildings)")


if __name__ == "__main__":
    main()
