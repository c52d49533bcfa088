#!/usr/bin/python3
"""Is City3D's model at the points? (issue 42: buildings where it is not are judged by p2m instead, with the reason)

For each building of airborne.py's CSV, both models (City3D's NAME_city3d.obj beside the scan, hsr's
NAME_city3d_ground.obj from airborne.py --keep, the run on City3D's ground) are rasterised in plan on a grid of
GRID_M: each cell under the model gets the model's top height there (the highest crossing of a vertical line).
Two figures per model:

- **roof over the points** (%): the share of the scan's points under the model in plan that lie more than
  ROOF_OVER_POINTS_M below the model's top there. A model whose roofs are at the points has few (points on a
  facade, under an eave); City3D's AHN3 sheds whose box was extruded from the roof up to the hand-given ground
  z = 0 (above the roof), or a Vaihingen roof that rises metres above every point, have most of them so.
- **plan off the points** (%): the share of the model's plan area farther than PLAN_OFF_M in plan from every
  point: an outline far wider than the points (or filling a box's corners where no point is).

A building is listed as "City3D off" when City3D's roof-over share exceeds hsr's by ROOF_OVER_MARGIN (its roofs
stand above the points) or its plan-off share exceeds hsr's by PLAN_OFF_MARGIN (its outline far wider than the
points): a pointer for the list of issue 42, which is decided by looking (contact_sheet.py) and by p2m. Each
threshold is a named constant below, with its unit.

    /usr/bin/python3 bench/building/city3d_off.py --csv shared.csv --models K [--dir VARIANTS/sub50] [--only A,B]
        [--above 3] [--out F.tsv]

--above N: only the buildings whose City3D → hsr on City3D's ground is above N % (or that have no model).
"""
import argparse, csv, glob, os, sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from contact_sheet import read_obj, read_ply_points  # noqa: E402

GRID_M = 0.1  # plan raster step (m): under a tenth of the sparsest scan's spacing (Vaihingen 0.5 m)
PLAN_OFF_M = 1.0  # a plan cell farther than this (m) from every point in plan is "off the points": two Vaihingen spacings
ROOF_OVER_POINTS_M = 0.2  # a point this far (m) under the model's top is not on its roof: 4 times AHN3's noise
ROOF_OVER_MARGIN = 0.25  # City3D's roof-over share this much above hsr's: its roofs are not at the points
PLAN_OFF_MARGIN = 0.25  # City3D's plan-off share this much above hsr's: its outline far wider than the points


def top_raster(v, faces, lo, shape):
    """The model's top height on a plan grid (NaN where no face is above the cell)."""
    top = np.full(shape, np.nan)
    for f in faces:
        for i in range(1, len(f) - 1):
            a, b, c = v[f[0]], v[f[i]], v[f[i + 1]]
            d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
            if abs(d) < 1e-12:
                continue  # upright in plan: no area
            i0 = max(0, int((min(a[0], b[0], c[0]) - lo[0]) / GRID_M))
            i1 = min(shape[0], int((max(a[0], b[0], c[0]) - lo[0]) / GRID_M) + 2)
            j0 = max(0, int((min(a[1], b[1], c[1]) - lo[1]) / GRID_M))
            j1 = min(shape[1], int((max(a[1], b[1], c[1]) - lo[1]) / GRID_M) + 2)
            if i1 <= i0 or j1 <= j0:
                continue
            x = lo[0] + (np.arange(i0, i1) + 0.5) * GRID_M
            y = lo[1] + (np.arange(j0, j1) + 0.5) * GRID_M
            X, Y = np.meshgrid(x, y, indexing="ij")
            l1 = ((b[0] - X) * (c[1] - Y) - (c[0] - X) * (b[1] - Y)) / d
            l2 = ((c[0] - X) * (a[1] - Y) - (a[0] - X) * (c[1] - Y)) / d
            l3 = 1 - l1 - l2
            inside = (l1 >= 0) & (l2 >= 0) & (l3 >= 0)
            z = l1 * a[2] + l2 * b[2] + l3 * c[2]
            blk = top[i0:i1, j0:j1]
            blk[inside] = np.fmax(blk[inside], z[inside])
    return top


def figures(points, model):
    """(roof over the points share, plan off the points share) of one model, or None without a model."""
    if not model or not os.path.exists(model):
        return None
    v, faces = read_obj(model)
    lo = np.minimum(points.min(0), v.min(0))[:2] - GRID_M
    hi = np.maximum(points.max(0), v.max(0))[:2] + GRID_M
    shape = tuple(np.ceil((hi - lo) / GRID_M).astype(int) + 1)
    top = top_raster(v, faces, lo, shape)
    ij = np.floor((points[:, :2] - lo) / GRID_M).astype(int)
    under = top[ij[:, 0], ij[:, 1]]
    ok = ~np.isnan(under)
    over = float((under[ok] - points[ok, 2] > ROOF_OVER_POINTS_M).sum() / max(1, ok.sum()))
    # plan cells within PLAN_OFF_M of a point: the points' cells dilated by a disc
    near = np.zeros(shape, bool)
    k = int(round(PLAN_OFF_M / GRID_M))
    di, dj = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1), indexing="ij")
    disc = (di ** 2 + dj ** 2) <= k * k
    for oi, oj in zip(di[disc], dj[disc]):
        near[np.clip(ij[:, 0] + oi, 0, shape[0] - 1), np.clip(ij[:, 1] + oj, 0, shape[1] - 1)] = True
    plan = ~np.isnan(top)
    off = float((plan & ~near).sum() / max(1, plan.sum()))
    return over, off


def verdict(c3d, hsr):
    """City3D's model not at the points (issue 42), and why; '' when it is."""
    if c3d is None:
        return ""
    # both against hsr's own figure: points on facades and the ground under an eave are under any model's top
    if c3d[0] - (hsr[0] if hsr else 0.0) > ROOF_OVER_MARGIN:
        return f"City3D's roof {100 * c3d[0]:.0f} % over the points"
    if c3d[1] - (hsr[1] if hsr else 0.0) > PLAN_OFF_MARGIN:
        return f"City3D's plan {100 * c3d[1]:.0f} % off the points"
    return ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.path.join(here, "..", "..", "..", "shared")
    ap.add_argument("--csv", required=True, help="airborne.py's CSV")
    ap.add_argument("--models", required=True, help="airborne.py --keep folder (NAME_city3d_ground.obj)")
    ap.add_argument("--dir", action="append", help="folders of the scans and City3D's models")
    ap.add_argument("--only")
    ap.add_argument("--above", type=float, help="only City3D → hsr on City3D's ground above this (%%) or no model")
    ap.add_argument("--out")
    a = ap.parse_args()
    dirs = a.dir or [os.path.join(shared, "airborne"), os.path.join(shared, "airborne_more")]
    rows = list(csv.DictReader(open(a.csv)))
    if a.only:
        keep = a.only.split(",")
        rows = [r for r in rows if r["input"] in keep]
    if a.above is not None:
        rows = [r for r in rows if not r.get("city3d_to_hsr_at_city3d_ground")
                or float(r["city3d_to_hsr_at_city3d_ground"]) > a.above]
    out = open(a.out, "w") if a.out else sys.stdout
    cols = ["input", "group", "points", "c3d_at_c3d_ground", "p2m", "city3d_p2m", "c3d_roof_over",
            "c3d_plan_off", "hsr_roof_over", "hsr_plan_off", "verdict"]
    print("\t".join(cols), file=out)
    for r in rows:
        name = r["input"]
        scan = next((os.path.join(d, name + ".ply") for d in dirs if os.path.exists(os.path.join(d, name + ".ply"))))
        pts = read_ply_points(scan, limit=10 ** 9)
        c3d = figures(pts, scan[:-4] + "_city3d.obj")
        hsr = figures(pts, os.path.join(a.models, name + "_city3d_ground.obj"))
        f = lambda x, i, s=1: "" if x is None else f"{s * x[i]:.2f}"
        num = lambda k: f"{float(r[k]):.2f}" if r.get(k) else ""
        print("\t".join([name, r["group"], r["points"], num("city3d_to_hsr_at_city3d_ground"), num("p2m"),
                         num("city3d_p2m"), f(c3d, 0, 100), f(c3d, 1, 100), f(hsr, 0, 100), f(hsr, 1, 100),
                         verdict(c3d, hsr)]), file=out)


if __name__ == "__main__":
    main()
