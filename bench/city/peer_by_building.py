#!/usr/bin/env python3
"""hsr city against roofer building by building, and where hsr loses the distance (issue 43 item 4).

    PYTHONPATH=BUILD/python /usr/bin/python3 bench/city/peer_by_building.py HSR_OUT ROOFER_DIR [--csv FILE]
        [--plans DIR] [--only ID ...]

HSR_OUT: the prefix of a `tile_bench.py peer` run's hsr outputs (HSR_OUT.city.jsonl, .summary.csv, .work/ with
each building's points NAME.ply and footprint NAME.footprint.geojson); ROOFER_DIR: roofer's output folder of
the same run. Needs numpy and scipy (Debian's /usr/bin/python3) and the hsr module (BUILD/python).

Per building, on the building's points as hsr city cut them (the same points tile_bench.py judges both on):
every point's distance to hsr's LoD 2.2 solid and to roofer's (its BuildingParts' shells welded, as
tile_bench.py reads them), the RMS of each (m; the figures of tile_bench.py's `hsr eval`, which samples the
same point set), and the sum of squared distances split by where the point lies for hsr's model:
  outside  outside hsr's plan (its ground faces in plan): the outline against the footprint;
  wall     inside the plan, nearest a wall of hsr's model (upright face);
  roof     inside the plan, nearest a roof face;
  ground   inside the plan, nearest a ground face.
For each share, the RMS hsr would have if its points there were as close as roofer's (min of the two): which
stage loses the distance. Prints the buildings where roofer is closer, sorted by hsr's RMS, with the two medians
and how many buildings lie between them; --plans DIR draws each of those in plan (both models' faces, the
footprint, the points coloured by hsr's distance minus roofer's; matplotlib).
"""
import argparse
import csv
import json
import os
import statistics
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import tile_bench as tb  # noqa: E402

import hsr  # noqa: E402  (BUILD/python on PYTHONPATH)

SHARES = ("outside", "wall", "roof", "ground")


def closest_distances(p, a, b, c):
    """Distance of each point of p (n x 3) to the triangle a, b, c (Ericson's region test, vectorised)."""
    ab, ac = b - a, c - a
    ap, bp, cp = p - a, p - b, p - c
    d1, d2, d3, d4, d5, d6 = ap @ ab, ap @ ac, bp @ ab, bp @ ac, cp @ ab, cp @ ac
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(all="ignore"):
        denom = va + vb + vc
        q = a + np.outer(vb / denom, ab) + np.outer(vc / denom, ac)
        at_a = (d1 <= 0) & (d2 <= 0)
        at_b = (d3 >= 0) & (d4 <= d3)
        at_c = (d6 >= 0) & (d5 <= d6)
        on_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0) & ~at_a & ~at_b
        on_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0) & ~at_a & ~at_c
        on_bc = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0) & ~at_b & ~at_c
        t = d1 / (d1 - d3)
        q[on_ab] = a + np.outer(t[on_ab], ab)
        t = d2 / (d2 - d6)
        q[on_ac] = a + np.outer(t[on_ac], ac)
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        q[on_bc] = b + np.outer(t[on_bc], c - b)
        q[at_a], q[at_b], q[at_c] = a, b, c
    return np.linalg.norm(p - q, axis=1)


def newell_normal(v):
    r = np.roll(v, -1, axis=0)
    return np.array([((v[:, 1] - r[:, 1]) * (v[:, 2] + r[:, 2])).sum(), ((v[:, 2] - r[:, 2]) * (v[:, 0] + r[:, 0])).sum(),
                     ((v[:, 0] - r[:, 0]) * (v[:, 1] + r[:, 1])).sum()])


def face_kind(v):
    """wall (upright), ground (facing down) or roof, by the polygon's Newell normal."""
    n = newell_normal(v)
    nz = n[2] / (np.linalg.norm(n) or 1.0)
    return "wall" if abs(nz) < 0.2 else ("ground" if nz < -0.5 else "roof")


def point_distances(points, mesh):
    """Each point's distance to the mesh, and the kind of the face it is nearest."""
    verts = np.asarray(mesh["vertices"], float)
    faces = [np.asarray(f) for f in mesh["faces"]]
    kinds = [face_kind(verts[f]) for f in faces]
    tris = np.asarray(hsr.triangulate(verts, mesh["faces"]))
    tri_kind = np.asarray([face_kind(verts[t]) for t in tris])  # a face's triangles lie in its plane
    best = np.full(len(points), np.inf)
    arg = np.zeros(len(points), int)
    for t, tri in enumerate(tris):
        d = closest_distances(points, verts[tri[0]], verts[tri[1]], verts[tri[2]])
        better = d < best
        best[better], arg[better] = d[better], t
    return best, tri_kind[arg], verts, faces, kinds


def inside_plan(points, verts, faces, kinds):
    from matplotlib.path import Path
    inside = np.zeros(len(points), bool)
    for f, k in zip(faces, kinds):
        if k == "ground":
            inside |= Path(verts[f][:, :2]).contains_points(points[:, :2], radius=1e-6)
    return inside


def building_figures(points, hsr_mesh, roofer_mesh):
    dh, kh, verts, faces, kinds = point_distances(points, hsr_mesh)
    dr = point_distances(points, roofer_mesh)[0]
    inside = inside_plan(points, verts, faces, kinds)
    where = np.where(inside, kh, "outside")
    row = {"points": len(points), "hsr_rms_m": float(np.sqrt((dh ** 2).mean())),
           "roofer_rms_m": float(np.sqrt((dr ** 2).mean()))}
    for s in SHARES:
        m = where == s
        row[s + "_points"] = int(m.sum())
        row[s + "_hsr_sq"] = float((dh[m] ** 2).sum())
        row[s + "_roofer_sq"] = float((dr[m] ** 2).sum())
        row[s + "_as_roofer_rms_m"] = float(np.sqrt((np.where(m, np.minimum(dh, dr), dh) ** 2).mean()))
    return row, dh, dr


def draw_plan(path, bid, points, dh, dr, hsr_mesh, roofer_mesh, footprint_file):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(16, 8))
    fp = json.load(open(footprint_file)) if os.path.exists(footprint_file) else None
    for ax, tool, mesh, d in ((axs[0], "hsr", hsr_mesh, dh - dr), (axs[1], "roofer", roofer_mesh, dr - dh)):
        v = np.asarray(mesh["vertices"], float)
        for f in mesh["faces"]:
            f = list(f)
            ring = v[f + [f[0]]]
            ax.plot(ring[:, 0], ring[:, 1], "-", color="k" if face_kind(v[f]) == "wall" else "0.7", lw=0.8)
        if fp:
            for poly in fp["features"][0]["geometry"]["coordinates"]:
                for ring in poly:
                    r = np.asarray(ring)
                    ax.plot(r[:, 0], r[:, 1], "g--", lw=1.5)
        sc = ax.scatter(points[:, 0], points[:, 1], c=np.clip(d, -1, 1), cmap="coolwarm", vmin=-1, vmax=1, s=6)
        ax.set_aspect("equal")
        ax.set_title("%s %s: RMS %.3f m (red: %s farther)" % (bid, tool, np.sqrt(((d + (dr if tool == "hsr" else dh)) ** 2).mean()), tool))
    fig.colorbar(sc, ax=axs)
    fig.savefig(path, dpi=70)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("hsr_out")
    ap.add_argument("roofer_dir")
    ap.add_argument("--csv")
    ap.add_argument("--plans")
    ap.add_argument("--only", nargs="*")
    a = ap.parse_args()
    header, feats = tb.features(a.hsr_out + ".city.jsonl")
    hsr_feats = {f["id"]: f for f in feats}
    solids = {}
    for dp, _, ns in os.walk(a.roofer_dir):
        for n in ns:
            if n.endswith(".city.jsonl"):
                solids.update(tb.roofer_solids(os.path.join(dp, n)))
    tmp = a.hsr_out + ".by_building"
    os.makedirs(tmp, exist_ok=True)
    rows = []
    for s in tb.summary(a.hsr_out + ".summary.csv"):
        bid = s["building"]
        if a.only and bid not in a.only:
            continue
        if bid not in hsr_feats or bid not in solids or not solids[bid][1] or not os.path.exists(s["input"]):
            continue
        model = os.path.join(tmp, bid + ".city.jsonl")
        tb.single_feature_file(header, hsr_feats[bid], model)
        verts, faces, _ = solids[bid]
        points = np.asarray(hsr.read_points(s["input"])["points"], float)
        hm = hsr.read_mesh(model)
        rm = {"vertices": np.asarray(verts, float), "faces": [np.asarray(f) for f in faces]}
        row, dh, dr = building_figures(points, hm, rm)
        row["building"] = bid
        rows.append(row)
        if a.plans and row["hsr_rms_m"] > row["roofer_rms_m"]:
            os.makedirs(a.plans, exist_ok=True)
            draw_plan(os.path.join(a.plans, bid + ".png"), bid, points, dh, dr, hm, rm,
                      os.path.join(os.path.dirname(s["input"]), bid + ".footprint.geojson"))
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=["building"] + [k for k in rows[0] if k != "building"])
            w.writeheader()
            w.writerows(rows)
    hm_, rm_ = statistics.median(r["hsr_rms_m"] for r in rows), statistics.median(r["roofer_rms_m"] for r in rows)
    print("%d buildings both model; RMS median hsr %.4f m, roofer %.4f m; hsr closer on %d" % (
        len(rows), hm_, rm_, sum(r["hsr_rms_m"] < r["roofer_rms_m"] for r in rows)))
    print("buildings with hsr's RMS between the two medians: %d" % sum(min(hm_, rm_) < r["hsr_rms_m"] <= max(hm_, rm_) for r in rows))
    print("| building | points | hsr m | roofer m | hsr - roofer | " + " | ".join("%s: points, hsr / roofer sq, RMS as roofer's" % s for s in SHARES) + " |")
    print("|---" * (5 + len(SHARES)) + "|")
    for r in sorted(rows, key=lambda r: r["hsr_rms_m"]):
        if r["hsr_rms_m"] <= r["roofer_rms_m"]:
            continue
        cells = ["%d, %.1f / %.1f, %.3f" % (r[s + "_points"], r[s + "_hsr_sq"], r[s + "_roofer_sq"], r[s + "_as_roofer_rms_m"])
                 if r[s + "_points"] else "—" for s in SHARES]
        print("| %s | %d | %.3f | %.3f | %+.3f | %s |" % (r["building"], r["points"], r["hsr_rms_m"], r["roofer_rms_m"],
                                                    r["hsr_rms_m"] - r["roofer_rms_m"], " | ".join(cells)))
    for s in SHARES:
        print("%s: sum of squares hsr %.0f, roofer %.0f on the same points; median RMS were hsr as close there: %.4f m" % (
            s, sum(r[s + "_hsr_sq"] for r in rows), sum(r[s + "_roofer_sq"] for r in rows),
            statistics.median(r[s + "_as_roofer_rms_m"] for r in rows)))


if __name__ == "__main__":
    main()
