#!/usr/bin/python3
"""Airborne buildings beside City3D (issue 13): hsr on every scan of ../shared/airborne, measured against the
scan's points and against City3D's model of the same scan, in both directions.

For each scan: hsr's validity, facets, p2m (mean distance of all input points to the model, % of the
points' bbox diagonal; ANCHORS.md's figure); City3D's own p2m on the same points; the mean distance from
City3D's model (its faces sampled, `hsr eval --truth`) to hsr's surface and back, in % of City3D's bbox
diagonal (ANCHORS.md's last column). Writes a markdown table (stdout, or --out FILE) and a CSV (--csv).

    /usr/bin/python3 bench/building/airborne.py [--hsr build/hsr] [--dir ../shared/airborne] [--out F.md]
        [--csv F.csv] [--png DIR] [-- extra reconstruct options]
"""
import argparse, csv, json, os, statistics, subprocess, sys, tempfile, time


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True)


def obj_min_z(path):
    with open(path) as f:
        return min(float(line.split()[3]) for line in f if line.startswith("v "))


def obj_bbox_diagonal(path):
    lo, hi = [float("inf")] * 3, [-float("inf")] * 3
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, v)]
                hi = [max(a, b) for a, b in zip(hi, v)]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def evaluate(hsr, points, mesh, truth=None):
    cmd = [hsr, "eval", points, mesh, "--json"] + (["--truth", truth] if truth else [])
    r = run(cmd)
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip())
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--hsr", default=os.path.join(here, "..", "..", "build", "hsr"))
    ap.add_argument("--dir", default=os.path.join(here, "..", "..", "..", "shared", "airborne"))
    ap.add_argument("--out")
    ap.add_argument("--csv")
    ap.add_argument("--png", help="folder for pictures: hsr's model over the points, City3D's model")
    ap.add_argument("extra", nargs="*", help="options passed to hsr reconstruct (after --)")
    a = ap.parse_args()
    scans = sorted(f for f in os.listdir(a.dir) if f.endswith(".ply"))
    if not scans:
        sys.exit(f"airborne.py: no scans in {a.dir}")
    rows = []
    tmp = tempfile.mkdtemp(prefix="hsr-airborne-")
    for scan in scans:
        name = scan[:-4]
        points = os.path.join(a.dir, scan)
        city3d = os.path.join(a.dir, name + "_city3d.obj")
        model = os.path.join(tmp, name + ".obj")
        report = os.path.join(tmp, name + ".json")
        t0 = time.time()
        r = run([a.hsr, "reconstruct", points, "-o", model, "--report", report, "-q"] + a.extra)
        seconds = time.time() - t0
        row = {"input": name, "seconds": round(seconds, 2)}
        if r.returncode != 0:
            row.update(valid="no output", error=r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "")
            rows.append(row)
            continue
        rep = json.load(open(report))
        ev = evaluate(a.hsr, points, model, city3d)
        c3 = evaluate(a.hsr, points, city3d)
        scale = ev["diagonal"] / obj_bbox_diagonal(city3d)  # fractions of the points' diagonal -> City3D's
        acc = ev["accuracy"]
        row.update(
            mode=rep["scene"]["mode"],
            ground=rep["scene"].get("ground_source", ""),
            valid="yes" if rep["validity"]["closed"] and rep["validity"]["manifold"] and rep["validity"]["oriented"]
            and rep["validity"]["self_intersection_free"] and rep["validity"]["bounds_volume"] else "no",
            facets=rep["counts"]["output_faces"],
            p2m=100 * acc["p2m_mean"],
            city3d_p2m=100 * c3["accuracy"]["p2m_mean"],
            city3d_to_hsr=100 * acc["truth_to_mesh_mean"] * scale,
            hsr_to_city3d=100 * acc["mesh_to_truth_mean"] * scale,
            city3d_faces=c3["faces"],
        )
        # Diagnostic: the same run standing on City3D's own ground height (its models' ground is one value per
        # data set: AHN3 0, DALES 1, Vaihingen 265), to tell a shape difference from a ground difference.
        g = obj_min_z(city3d)
        model_g = os.path.join(tmp, name + "_city3d_ground.obj")
        extra = [x for x in a.extra if x not in ("--scene", "object", "auto", "building")]
        rg = run([a.hsr, "reconstruct", points, "-o", model_g, "--ground-z", repr(g), "--scene", "building", "-q"] + extra)
        if rg.returncode == 0:
            eg = evaluate(a.hsr, points, model_g, city3d)["accuracy"]
            row.update(city3d_ground=g, city3d_to_hsr_at_city3d_ground=100 * eg["truth_to_mesh_mean"] * scale)
        rows.append(row)
        if a.png:
            os.makedirs(a.png, exist_ok=True)
            run([a.hsr, "render", model, points, "-o", os.path.join(a.png, name + "_hsr.png"), "--width", "640", "--height", "420", "-q"])
            run([a.hsr, "render", city3d, points, "-o", os.path.join(a.png, name + "_city3d.png"), "--width", "640", "--height", "420", "-q"])
    lines = ["| input | mode | ground | valid | facets | p2m % | City3D p2m % | City3D → hsr % | hsr → City3D % | s | City3D → hsr % on City3D's ground |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "p2m" not in r:
            lines.append(f"| {r['input']} | | | {r['valid']} | | | | | | {r['seconds']} |")
            continue
        cg = r.get("city3d_to_hsr_at_city3d_ground")
        at_ground = "" if cg is None else f"{cg:.2f} (z = {r['city3d_ground']:g})"
        lines.append(f"| {r['input']} | {r['mode']} | {r['ground']} | {r['valid']} | {r['facets']} | {r['p2m']:.2f} | "
                     f"{r['city3d_p2m']:.2f} | {r['city3d_to_hsr']:.2f} | {r['hsr_to_city3d']:.2f} | {r['seconds']} | "
                     f"{at_ground} |")
    ok = [r for r in rows if "p2m" in r]
    if ok:
        med = lambda k: statistics.median(r[k] for r in ok)
        at = [r["city3d_to_hsr_at_city3d_ground"] for r in ok if "city3d_ground" in r]
        med_at_ground = f"{statistics.median(at):.2f}" if at else ""
        lines.append(f"| **median** ({len(ok)} of {len(rows)} with a model, "
                     f"{sum(r['valid'] == 'yes' for r in ok)} valid) | | | | {med('facets'):.0f} | {med('p2m'):.2f} | "
                     f"{med('city3d_p2m'):.2f} | {med('city3d_to_hsr'):.2f} | {med('hsr_to_city3d'):.2f} | {med('seconds'):.2f} | "
                     f"{med_at_ground} |")
    text = "\n".join(lines) + "\n"
    if a.out:
        open(a.out, "w").write(text)
    print(text, end="")
    if a.csv:
        keys = ["input", "mode", "ground", "valid", "facets", "p2m", "city3d_p2m", "city3d_to_hsr", "hsr_to_city3d", "seconds",
                "city3d_ground", "city3d_to_hsr_at_city3d_ground"]
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
