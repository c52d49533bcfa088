#!/usr/bin/env python3
"""A survey's buildings at its tiles' edges against the same tile whole: doubled, cut, or as whole (issue 40 item 1).

    /usr/bin/python3 bench/city/edges_check.py WHOLE.summary.csv TILES_DIR [--log TILES.log]

WHOLE.summary.csv: `hsr city tile.las -o WHOLE.city.jsonl` (one tile); TILES_DIR: `hsr city tiles/*.las -o TILES_DIR`
(the same points cut into tiles, e.g. `hsr synth city --tiles 3`), both with or both without --footprints. Each
building is its points file (NAME.ply of the work folder, the summary's `input`): matched to the whole run's
building with the nearest plan centre (within --match m). Prints: buildings in each, matched, doubled (two
tile buildings on one whole one), missing; per matched building the points in the tiles run against the whole
run's (a building cut at an edge has fewer); with --log (the tiles run's stderr) the points each tile kept and
read from its neighbours' margins.
"""
import argparse
import csv
import glob
import os
import re
import sys

import numpy as np


def ply_xyz(path):
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.readline()
        n = int(re.search(rb"element vertex (\d+)", header).group(1))
        return np.frombuffer(f.read(24 * n), "<f8").reshape(n, 3)


def buildings(summaries):
    out = []
    for s in summaries:
        with open(s, newline="") as f:
            for row in csv.DictReader(f):
                if row.get("status") != "ok" or not os.path.exists(row["input"]):
                    continue
                p = ply_xyz(row["input"])
                out.append({"id": row["building"], "tile": os.path.basename(s).split(".")[0], "points": len(p),
                            "centre": p[:, :2].mean(0)})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("whole")
    ap.add_argument("tiles")
    ap.add_argument("--log")
    ap.add_argument("--match", type=float, default=2.0, help="plan centres this close are one building, m")
    a = ap.parse_args()
    whole = buildings([a.whole])
    tiles = buildings(sorted(glob.glob(os.path.join(a.tiles, "*.summary.csv"))))
    used = {}
    for t in tiles:
        d = [np.linalg.norm(w["centre"] - t["centre"]) for w in whole]
        k = int(np.argmin(d)) if d else -1
        if k >= 0 and d[k] <= a.match:
            used.setdefault(k, []).append(t)
    doubled = sum(len(v) - 1 for v in used.values() if len(v) > 1)
    missing = [whole[k]["id"] for k in range(len(whole)) if k not in used]
    ratio = [(v[0]["points"] / whole[k]["points"], whole[k]["id"], v[0]["tile"]) for k, v in used.items()]
    fewer = [r for r in ratio if r[0] < 0.999]
    print("whole: %d buildings; tiles: %d buildings; matched %d; doubled %d; missing %d %s; unmatched tile buildings %d"
          % (len(whole), len(tiles), len(used), doubled, len(missing), missing[:5],
             len(tiles) - sum(len(v) for v in used.values())))
    if ratio:
        r = sorted(x[0] for x in ratio)
        print("points in the tiles run / in the whole run: min %.4f (%s), median %.4f, max %.4f; %d buildings with fewer"
              % (r[0], min(ratio)[1], float(np.median(r)), r[-1], len(fewer)))
    if a.log:
        text = open(a.log).read()
        kept = [(int(k), int(n)) for k, n in re.findall(r"(\d+) of (\d+) points kept", text)]
        margin = [int(m) for m in re.findall(r"(\d+) ground and building points of its neighbour", text)]
        if kept:
            print("points kept by the %d tile plans: %d of %d read (%.1f %%); from neighbours' margins: %d points read"
                  % (len(kept), sum(k for k, _ in kept), sum(n for _, n in kept), 100.0 * sum(k for k, _ in kept) / max(1, sum(n for _, n in kept)),
                     sum(margin)))
        m = re.findall(r"(\d+) groups across its edges are planned by a neighbour", text)
        if m:
            print("groups across an edge planned by a neighbour (left by the tile that read them): %d" % sum(int(x) for x in m))
    return 0


if __name__ == "__main__":
    sys.exit(main())
