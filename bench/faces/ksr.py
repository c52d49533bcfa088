#!/usr/bin/python3
"""KSR at several λ on the faces bench's inputs (issue 25): facets against p2m beside hsr's --detail curve.

CGAL's Kinetic Surface Reconstruction (KSR) is run by a driver program built OUTSIDE this repository from a
fetched CGAL 6.1.1 (no fetched code, binary built from it or recipe to build it is committed here; README
"Indoor scenes" says how it was configured). Give its path with --ksr or $HSR_KSR; without it this script
says so and exits 0. The driver's interface: `DRIVER INPUT OUT_PREFIX [--min-region N] [--lambda L1,L2,..]`
detects planes (KSR's region growing, its defaults unless --min-region), partitions once (k = 1), then
reconstructs once per λ with all six bounding-box sides forced outside, writes OUT_PREFIX_<λ>.off per λ
and prints one JSON line (planes, seconds per step, peak memory, one entry per λ).

Per (input, λ) one CSV row: KSR's facets, validity and p2m as `hsr eval` measures them (the same referee
as hsr's rows in faces.csv), and `box`: p2m over 10 % of the diagonal, KSR's bounding box rather than the
shape (issue 25's decision: not a valid output for the comparison). LAS inputs are written to a PLY first
(local coordinates: the driver reads no LAS) and evaluated against that PLY.

    flock /work/notes/heavy.lock /usr/bin/python3 bench/faces/ksr.py --ksr /path/to/ksr_driver \\
        [--lambdas 0.3,0.5,0.7,0.9] [--out bench/results/faces_ksr.csv]
"""
import argparse, csv, json, os, subprocess, sys, tempfile, time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run import manifest  # noqa: E402  (the same inputs as the faces bench)

BOX_P2M = 10.0  # % of the diagonal: a KSR output this far from the points is its bounding box
FIELDS = ["input", "kind", "lambda", "status", "valid", "facets", "p2m_pct", "box", "planes", "volumes",
          "detect_partition_s", "reconstruct_s", "peak_mb"]


def las_to_ply(build, las, ply):
    """The LAS file's points as an ASCII PLY in local coordinates (the driver reads no LAS)."""
    sys.path.insert(0, os.path.join(build, "python"))
    import hsr  # noqa: E402  (this build's module)
    pts = hsr.read_points(las)["points"]
    origin = pts.min(axis=0)
    with open(ply, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\nproperty double x\nproperty double y\n"
                "property double z\nend_header\n")
        for p in pts - origin:
            f.write(f"{p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n")


def evaluate(hsr_cli, points, mesh):
    r = subprocess.run([hsr_cli, "eval", points, mesh, "--json"], capture_output=True, text=True)
    if r.returncode != 0:
        return {"status": "eval failed: " + (r.stderr.strip().splitlines() or [""])[-1][:100]}
    e = json.loads(r.stdout)
    p2m = 100 * e["accuracy"]["p2m_mean"]
    return {"status": "ok", "valid": e["validity"]["valid"], "facets": e["faces"], "p2m_pct": p2m, "box": p2m > BOX_P2M}


def run_ksr(driver, points, prefix, lambdas, min_region, timeout):
    cmd = [driver, points, prefix, "--lambda", ",".join(f"{x:g}" for x in lambdas)]
    if min_region:
        cmd += ["--min-region", str(min_region)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, "timeout"
    if p.returncode != 0:
        return None, f"failed ({'signal ' + str(-p.returncode) if p.returncode < 0 else 'exit ' + str(p.returncode)})"
    lines = [x for x in p.stdout.splitlines() if x.startswith("{")]
    return (json.loads(lines[-1]), "ok") if lines else (None, "no output")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ksr", default=os.environ.get("HSR_KSR", ""), help="the KSR driver (default $HSR_KSR)")
    ap.add_argument("--hsr", default=os.path.join(here, "..", "..", "build", "hsr"), help="hsr, for eval")
    ap.add_argument("--data", default="/work/shared/data")
    ap.add_argument("--airborne", default="/work/shared/airborne", help="airborne buildings ('' to skip)")
    ap.add_argument("--lambdas", default="0.3,0.5,0.7,0.9")
    ap.add_argument("--min-region", type=int, default=0, help="KSR's minimum region in points (0: its default)")
    ap.add_argument("--only", nargs="*", default=None, help="input file names to run (default: all)")
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--out", default="bench/results/faces_ksr.csv")
    a = ap.parse_args()
    if not a.ksr or not os.access(a.ksr, os.X_OK):
        print(f"faces/ksr: no KSR driver ({a.ksr or 'give --ksr PATH or set HSR_KSR'}): KSR not run", file=sys.stderr)
        return 0
    lambdas = [float(x) for x in a.lambdas.split(",")]
    build = os.path.dirname(os.path.abspath(a.hsr))
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for path, name, kind in manifest(a.data) + manifest(a.airborne, "airborne"):
            if a.only and name not in a.only:
                continue
            points = path
            if name.lower().endswith(".las"):
                points = os.path.join(work, name + ".ply")
                las_to_ply(build, path, points)
            prefix = os.path.join(work, "ksr")
            t0 = time.time()
            info, status = run_ksr(a.ksr, points, prefix, lambdas, a.min_region, a.timeout)
            for lam in lambdas:
                row = {"input": name, "kind": kind, "lambda": lam, "status": status}
                if info:
                    rec = next((x for x in info["reconstructions"] if abs(x["lambda"] - lam) < 1e-9), None)
                    row.update(planes=info["planes"], volumes=info["volumes"], peak_mb=round(info["peak_kb"] / 1024, 1),
                               detect_partition_s=round(info["seconds"]["read_normals"] + info["seconds"]["detection"] +
                                                        info["seconds"]["partition"], 3))
                    if rec and rec["file"]:
                        row["reconstruct_s"] = round(rec["seconds"], 3)
                        row.update(evaluate(a.hsr, points, rec["file"]))
                        os.remove(rec["file"])
                    else:
                        row["status"] = "empty output"
                rows.append(row)
                print(",".join(str(row.get(k, "")) for k in FIELDS), flush=True)
            print(f"  {name}: {time.time() - t0:.1f} s", file=sys.stderr, flush=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
