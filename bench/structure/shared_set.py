#!/usr/bin/python3
"""The whole shared set through `hsr reconstruct`, one CSV row per input: planes, points on no plane, cells,
faces, p2m, validity, time, peak memory; for the airborne buildings also the distances between hsr's model
and City3D's (both ways, % of the points' diagonal); for synth models the
distances to the truth. Used to measure a change of a detection or extraction rule on every input
(issue 25), then `compare.py BEFORE.csv AFTER.csv` for the distribution and the worst cases.

    flock /work/notes/heavy.lock /usr/bin/python3 bench/structure/shared_set.py --out before.csv \
        [--sets data,airborne,airborne_more,synth] [--hsr build/hsr] [-- extra reconstruct options]
"""
import argparse, csv, json, os, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "..", "shared")
SYNTH = ["box", "house", "dormer_house", "bracket", "room", "courtyard", "aerial_flat", "aerial_gable", "aerial_hip",
         "aerial_shed", "aerial_dormer", "aerial_mixed"]


def manifest(folder):
    path = os.path.join(folder, "MANIFEST.tsv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [r["file"] for r in csv.DictReader(f, delimiter="\t")]


def inputs(sets, tmp, hsr):
    out = []
    for s in sets:
        if s in ("data", "airborne", "airborne_more"):
            folder = os.path.join(SHARED, s)
            for f in manifest(folder):
                if s == "data" or f.endswith(".ply"):
                    city3d = os.path.join(folder, f[:-4] + "_city3d.obj") if s != "data" else None
                    out.append((s, f, os.path.join(folder, f), city3d if city3d and os.path.exists(city3d) else None, None))
        elif s == "synth":
            for m in SYNTH:
                d = os.path.join(tmp, "synth_" + m)
                subprocess.run([hsr, "-q", "synth", m, "-o", d], check=True)
                out.append((s, m, os.path.join(d, "points.ply"), None, os.path.join(d, "truth.obj")))
        else:
            sys.exit(f"shared_set.py: unknown set {s}")
    return out


def evaluate(hsr, points, mesh, truth):
    r = subprocess.run([hsr, "eval", points, mesh, "--json", "--truth", truth], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hsr", default=os.path.join(HERE, "..", "..", "build", "hsr"))
    ap.add_argument("--sets", default="data,airborne,airborne_more,synth")
    ap.add_argument("--out", required=True)
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="hsr-shared-set-")
    rows = []
    for s, name, points, city3d, truth in inputs(a.sets.split(","), tmp, a.hsr):
        mesh, rep = os.path.join(tmp, "mesh.obj"), os.path.join(tmp, "report.json")
        for p in (mesh, rep):
            if os.path.exists(p):
                os.remove(p)
        cmd = [a.hsr, "-q", "reconstruct", points, "-o", mesh, "--report", rep] + (["--truth", truth] if truth else []) + a.extra
        t0 = time.time()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout)
            status = "ok" if proc.returncode == 0 else "failed: " + (proc.stderr.strip().splitlines() or [""])[-1][:150]
        except subprocess.TimeoutExpired:
            status = "timeout"
        row = {"set": s, "input": name, "status": status, "wall_s": round(time.time() - t0, 2)}
        if status == "ok":
            r = json.load(open(rep))
            v = r["validity"]
            c = r["counts"]
            row.update(planes=c["planes"], on_no_plane=c.get("points_on_no_plane", ""), points=c["points"],
                       cells=c["cells"], faces=c["output_faces"], p2m_pct=100 * r["accuracy"]["p2m_mean"],
                       valid=int(all(v[k] for k in ("closed", "manifold", "oriented", "self_intersection_free", "bounds_volume"))),
                       small_faces=r["face_sizes"]["small_faces"], peak_mb=r.get("peak_memory_mb", ""),
                       extraction_s=r["seconds"].get("extraction", ""))
            if truth:
                row.update(truth_to_mesh_pct=100 * r["accuracy"].get("truth_to_mesh_mean", float("nan")),
                           mesh_to_truth_pct=100 * r["accuracy"].get("mesh_to_truth_mean", float("nan")))
            if city3d:
                ev = evaluate(a.hsr, points, mesh, city3d)
                if ev:
                    row.update(city3d_to_hsr_pct=100 * ev["accuracy"]["truth_to_mesh_mean"],
                               hsr_to_city3d_pct=100 * ev["accuracy"]["mesh_to_truth_mean"])
        rows.append(row)
        print(json.dumps(row), flush=True)
    keys = ["set", "input", "status", "planes", "on_no_plane", "points", "cells", "faces", "small_faces", "p2m_pct", "valid",
            "truth_to_mesh_pct", "mesh_to_truth_pct", "city3d_to_hsr_pct", "hsr_to_city3d_pct", "wall_s", "extraction_s", "peak_mb"]
    with open(a.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
