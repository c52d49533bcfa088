#!/usr/bin/python3
"""Distributions of shared_set.py CSVs side by side, per set: inputs that succeed (and are valid) under each,
and over the inputs that succeed under all of them the sum, median, 90th percentile and maximum of the faces,
small faces, p2m and (airborne) City3D distances or (synth) truth distances. compare.py gives the changes
input by input and the worst cases.

    /usr/bin/python3 bench/structure/distribution.py default.csv floor.csv [...]
"""
import csv, os, statistics, sys


def load(path):
    with open(path) as f:
        return {(r["set"], r["input"]): r for r in csv.DictReader(f)}


def quantile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * (len(v) - 1) + 0.5))]


def main():
    paths = sys.argv[1:]
    if not paths:
        sys.exit(__doc__)
    names = [os.path.basename(p)[:-4] for p in paths]
    runs = [load(p) for p in paths]
    for s in ["data", "airborne", "airborne_more", "synth"]:
        keys = [k for k in runs[0] if k[0] == s and all(k in r and r[k]["status"] == "ok" for r in runs)]
        if not keys:
            continue
        ok = {n: sum(1 for k in r if k[0] == s and r[k]["status"] == "ok") for n, r in zip(names, runs)}
        invalid = {n: sum(1 for k in r if k[0] == s and r[k]["status"] == "ok" and r[k]["valid"] != "1") for n, r in zip(names, runs)}
        print(f"## {s}: {len(keys)} inputs ok under all; ok {ok}; invalid {invalid}")
        print("| column | " + " | ".join(f"{n}: sum / median / p90 / max" for n in names) + " |")
        print("|---|" + "---|" * len(names))
        cols = ["faces", "small_faces", "p2m_pct"]
        cols += ["city3d_to_hsr_pct", "hsr_to_city3d_pct"] if s.startswith("airborne") else []
        cols += ["truth_to_mesh_pct", "mesh_to_truth_pct"] if s == "synth" else []
        for col in cols:
            cells = []
            for r in runs:
                v = [float(r[k][col]) for k in keys if r[k].get(col, "") != ""]
                cells.append(f"{sum(v):.4g} / {statistics.median(v):.4g} / {quantile(v, 0.9):.4g} / {max(v):.4g}" if v else "-")
            print(f"| {col} | " + " | ".join(cells) + " |")
        print()


if __name__ == "__main__":
    main()
