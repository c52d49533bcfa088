#!/usr/bin/python3
"""Faces bench (issue 14): hsr at each --detail setting on the shared scans (data/) and the airborne buildings
(airborne/, kind "airborne"), one run per (input, setting).

Writes one CSV row per run: facets, mean p2m, faces under 0.1 % of the area, validity, seconds (from the
reconstruct report). Usage (from the repository root, after `make build`; through the shared lock):
    flock /work/notes/heavy.lock /usr/bin/python3 bench/faces/run.py --out bench/results/faces.csv
"""
import argparse, csv, json, os, subprocess, sys, tempfile, time

DEFAULT_SETTINGS = ["full", "high", "medium", "low"]


def manifest(data_dir, kind=None):
    """(path, file name, kind) of the inputs listed in data_dir/MANIFEST.tsv; `kind` overrides the listed one."""
    rows = []
    path = os.path.join(data_dir, "MANIFEST.tsv")
    if not data_dir or not os.path.exists(path):
        return rows
    with open(path) as f:
        for r in csv.DictReader(f, delimiter="\t"):
            rows.append((os.path.join(data_dir, r["file"]), r["file"], kind or r["kind"]))
    return rows


def run_one(hsr, path, setting, extra, workdir, timeout):
    out = os.path.join(workdir, "mesh.obj")
    rep = os.path.join(workdir, "report.json")
    for p in (out, rep):
        if os.path.exists(p):
            os.remove(p)
    cmd = [hsr, "-q", "reconstruct", path, "-o", out, "--report", rep, "--detail", setting] + extra
    t0 = time.time()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        status = "ok" if proc.returncode == 0 else "failed: " + proc.stderr.strip().splitlines()[-1][:120]
    except subprocess.TimeoutExpired:
        status = "timeout"
    wall = time.time() - t0
    row = {"status": status, "wall_s": round(wall, 3)}
    if status == "ok":
        r = json.load(open(rep))
        row.update(valid=r["validity"]["valid"], facets=r["counts"]["output_faces"],
                   p2m_pct=100 * r["accuracy"]["p2m_mean"], small_faces=r["face_sizes"]["small_faces"],
                   smallest_share_pct=100 * r["face_sizes"]["smallest_share"],
                   cleanup_cells=r["counts"].get("cleanup_cells", 0), scene=r.get("scene", {}).get("mode", ""))
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hsr", default="build/hsr")
    ap.add_argument("--data", default="/work/shared/data")
    ap.add_argument("--airborne", default="/work/shared/airborne", help="airborne buildings ('' to skip)")
    ap.add_argument("--settings", nargs="*", default=DEFAULT_SETTINGS)
    ap.add_argument("--extra", default="", help="more reconstruct options, one string")
    ap.add_argument("--only", nargs="*", default=None, help="input file names to run (default: all)")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("--out", default="bench/results/faces.csv")
    a = ap.parse_args()
    if not os.path.exists(os.path.join(a.data, "MANIFEST.tsv")):
        print(f"faces bench: {a.data}/MANIFEST.tsv not found; nothing to run", file=sys.stderr)
        return 0
    fields = ["input", "kind", "setting", "status", "valid", "facets", "p2m_pct", "small_faces",
              "smallest_share_pct", "cleanup_cells", "scene", "wall_s"]
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for path, name, kind in manifest(a.data) + manifest(a.airborne, "airborne"):
            if a.only and name not in a.only:
                continue
            for s in a.settings:
                row = {"input": name, "kind": kind, "setting": s}
                row.update(run_one(a.hsr, path, s, a.extra.split(), work, a.timeout))
                rows.append(row)
                print(",".join(str(row.get(k, "")) for k in fields), flush=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
