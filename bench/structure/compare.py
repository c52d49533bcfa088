#!/usr/bin/python3
"""Compares two shared_set.py CSVs (before, after) input by input: per set and column, how many inputs
changed, the median and the range of the change, and the worst cases (largest increases of the error
columns). Failures and invalid outputs are listed.

    /usr/bin/python3 bench/structure/compare.py before.csv after.csv [--worst 5]
"""
import argparse, csv, statistics

COLUMNS = ["planes", "on_no_plane", "cells", "faces", "small_faces", "p2m_pct", "truth_to_mesh_pct", "mesh_to_truth_pct",
           "city3d_to_hsr_pct", "hsr_to_city3d_pct", "wall_s", "peak_mb"]
ERRORS = ["p2m_pct", "truth_to_mesh_pct", "mesh_to_truth_pct", "city3d_to_hsr_pct", "hsr_to_city3d_pct"]


def load(path):
    with open(path) as f:
        return {(r["set"], r["input"]): r for r in csv.DictReader(f)}


def num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--worst", type=int, default=5)
    a = ap.parse_args()
    b, c = load(a.before), load(a.after)
    keys = [k for k in b if k in c]
    for s in sorted({k[0] for k in keys}):
        ks = [k for k in keys if k[0] == s]
        print(f"## {s} ({len(ks)} inputs)")
        bad = [(k[1], b[k]["status"], c[k]["status"], b[k].get("valid"), c[k].get("valid")) for k in ks
               if b[k]["status"] != "ok" or c[k]["status"] != "ok" or b[k].get("valid") != "1" or c[k].get("valid") != "1"]
        for name, sb, sc, vb, vc in bad:
            print(f"  not ok: {name}: before {sb} valid={vb}, after {sc} valid={vc}")
        print("| column | before total / median | after total / median | changed | change median | min | max |")
        print("|---|---|---|---|---|---|---|")
        for col in COLUMNS:
            pairs = [(k, num(b[k].get(col)), num(c[k].get(col))) for k in ks]
            pairs = [(k, x, y) for k, x, y in pairs if x is not None and y is not None]
            if not pairs:
                continue
            d = [y - x for _, x, y in pairs]
            changed = sum(1 for v in d if abs(v) > 1e-9)
            bx, ax = [x for _, x, _ in pairs], [y for _, _, y in pairs]
            print(f"| {col} | {sum(bx):.4g} / {statistics.median(bx):.4g} | {sum(ax):.4g} / {statistics.median(ax):.4g} | "
                  f"{changed} | {statistics.median(d):+.4g} | {min(d):+.4g} | {max(d):+.4g} |")
        for col in ERRORS + ["faces"]:
            pairs = [(k, num(b[k].get(col)), num(c[k].get(col))) for k in ks]
            pairs = sorted(((y - x, k[1], x, y) for k, x, y in pairs if x is not None and y is not None), reverse=True)
            worst = [p for p in pairs[: a.worst] if p[0] > 1e-9]
            if worst:
                print(f"  worst {col}: " + ", ".join(f"{n} {x:.4g} -> {y:.4g}" for _, n, x, y in worst))
        print()


if __name__ == "__main__":
    main()
