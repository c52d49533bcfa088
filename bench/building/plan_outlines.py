#!/usr/bin/python3
"""Outlines in plan, before and after (DECISIONS #219): for each scan, its points, City3D's model and hsr's model
reconstructed twice (on City3D's ground, `--scene building`, with two --config files), each model drawn as the
convex hull of its vertices in plan (the outline prisms and boxes this is for are convex). One panel per scan.

    /usr/bin/python3 bench/building/plan_outlines.py OUT.png --before B.json --after A.json [--hsr build/hsr]
        NAME=DIR/SCAN [...]      (DIR/SCAN.ply and DIR/SCAN_city3d.obj)
"""
import argparse, os, subprocess, sys, tempfile

from PIL import Image, ImageDraw

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from airborne import obj_vertices, read_ply_xy  # noqa: E402

PANEL_PX = 420  # a panel's side, pixels
MARGIN_M = 0.5  # around everything drawn, metres


def hull(xy):
    """Convex hull (Andrew's monotone chain), counter-clockwise."""
    p = sorted(set(map(tuple, xy)))
    if len(p) < 3:
        return p
    cross = lambda o, a, b: (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lo, hi = [], []
    for q in p:
        while len(lo) >= 2 and cross(lo[-2], lo[-1], q) <= 0:
            lo.pop()
        lo.append(q)
    for q in reversed(p):
        while len(hi) >= 2 and cross(hi[-2], hi[-1], q) <= 0:
            hi.pop()
        hi.append(q)
    return lo[:-1] + hi[:-1]


def panel(name, scan, hsr, configs, tmp):
    points = read_ply_xy(scan + ".ply")
    city3d = [v for v in obj_vertices(scan + "_city3d.obj")]
    ground = min(v[2] for v in city3d)
    outlines = [hull([(v[0], v[1]) for v in city3d])]
    for k, c in enumerate(configs):
        m = os.path.join(tmp, f"{name}_{k}.obj")
        subprocess.run([hsr, "-q", "reconstruct", scan + ".ply", "-o", m, "--ground-z", repr(ground), "--scene",
                        "building", "--config", c], check=True, capture_output=True)
        outlines.append(hull([(v[0], v[1]) for v in obj_vertices(m)]))
    every = [q for o in outlines for q in o] + [tuple(p) for p in points]
    lo = [min(q[i] for q in every) - MARGIN_M for i in (0, 1)]
    hi = [max(q[i] for q in every) + MARGIN_M for i in (0, 1)]
    s = PANEL_PX / max(hi[0] - lo[0], hi[1] - lo[1])
    im = Image.new("RGB", (PANEL_PX, PANEL_PX + 28), "white")
    d = ImageDraw.Draw(im)
    at = lambda q: ((q[0] - lo[0]) * s, PANEL_PX + 28 - (q[1] - lo[1]) * s)
    for o, colour, width in zip(outlines, [(200, 0, 0), (120, 120, 120), (0, 90, 220)], [3, 2, 2]):
        xy = [at(q) for q in o]
        d.line(xy + xy[:1], fill=colour, width=width)
    for p in points:
        x, y = at(p)
        d.ellipse([x - 3, y - 3, x + 3, y + 3], fill="black")
    d.text((6, 2), name, fill="black")
    d.text((6, 12), "points, City3D (red), hsr before (grey), after (blue)", fill="black")
    return im


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("scans", nargs="+", help="NAME=DIR/SCAN (without .ply)")
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--hsr", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "build", "hsr"))
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        panels = [panel(*s.split("=", 1), a.hsr, [a.before, a.after], tmp) for s in a.scans]
    out = Image.new("RGB", (sum(p.width + 10 for p in panels), panels[0].height), "white")
    x = 0
    for p in panels:
        out.paste(p, (x, 0))
        x += p.width + 10
    out.save(a.out)


if __name__ == "__main__":
    main()
