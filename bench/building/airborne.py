#!/usr/bin/python3
"""Real airborne buildings beside City3D (issues 13, 24): hsr on every scan of ../shared/airborne and
../shared/airborne_more (112 buildings: AHN3, DALES, Vaihingen), measured against the scan's points and
against City3D's model of the same scan, in both directions.

For each scan: the mode `auto` chose, validity, facets, p2m (mean distance of all input points to the model,
% of the points' bbox diagonal; ANCHORS.md's figure); City3D's own p2m on the same points; the mean distance
from City3D's model (its faces sampled, `hsr eval --truth`) to hsr's surface and back, in % of City3D's bbox
diagonal (ANCHORS.md's last column); the model's thickness (smallest side of its oriented box in plan over
the points' one: a slab is far below 1). Then the same run standing on City3D's own ground height
(`--ground-z` = its model's lowest vertex), to tell a shape difference from a ground difference (DALES scans
hold no ground; City3D's models stand metres lower).

Writes a markdown report (stdout, or --out FILE): per-group summary (valid, auto = building, hsr's and City3D's
p2m medians over the same buildings, City3D → hsr medians on both grounds and the counts above 3 %, the
unexplained share of #83 and the count above its 5 % warning), then one row per building (with its unexplained
share and the own frame's turn, #94), and the worst ten by City3D → hsr on each ground, by unexplained share and
by p2m over City3D's; --csv writes the rows, --png DIR pictures. bench/building/distributions.py gives the
quartiles of several runs' CSVs.

    /usr/bin/python3 bench/building/airborne.py [--hsr build/hsr] [--dir D ...] [--only NAME,...] [--out F.md]
        [--csv F.csv] [--png DIR] [--jobs N] [--keep DIR] [-- extra reconstruct options]
"""
import argparse, concurrent.futures, csv, json, math, os, statistics, subprocess, sys, tempfile, time

GROUPS = ["AHN3", "Dales3d", "Vaihingen"]


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True)


def obj_vertices(path):
    with open(path) as f:
        return [[float(x) for x in line.split()[1:4]] for line in f if line.startswith("v ")]


def bbox_diagonal(v):
    lo = [min(p[k] for p in v) for k in range(3)]
    hi = [max(p[k] for p in v) for k in range(3)]
    return math.dist(lo, hi)


def plan_width(xy):
    """Smallest width of a point set in plan over 180 directions (1 degree): a slab's is small."""
    best = float("inf")
    for a in range(180):
        c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
        t = [c * x + s * y for x, y in xy]
        best = min(best, max(t) - min(t))
    return best


def read_ply_xy(path):
    """xy of the points of a PLY scan (ascii or binary little endian, float or double x y)."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii", "replace").strip()
            header.append(line)
            if line == "end_header":
                break
        body = f.read()
    fmt = next(l.split()[1] for l in header if l.startswith("format"))
    count, props, in_vertex = 0, [], False
    for l in header:
        t = l.split()
        if t[:2] == ["element", "vertex"]:
            count, in_vertex = int(t[2]), True
        elif t and t[0] == "element":
            in_vertex = False
        elif in_vertex and t and t[0] == "property":
            props.append((t[1], t[2]))
    if fmt == "ascii":
        rows = body.decode().split("\n")
        xi, yi = [n for _, n in props].index("x"), [n for _, n in props].index("y")
        return [(float(r.split()[xi]), float(r.split()[yi])) for r in rows[:count] if r.strip()]
    import struct
    sizes = {"float": "f", "float32": "f", "double": "d", "float64": "d", "uchar": "B", "uint8": "B", "char": "b",
             "int8": "b", "short": "h", "int16": "h", "ushort": "H", "uint16": "H", "int": "i", "int32": "i",
             "uint": "I", "uint32": "I"}
    rec = "<" + "".join(sizes[t] for t, _ in props)
    n = struct.calcsize(rec)
    names = [p for _, p in props]
    xi, yi = names.index("x"), names.index("y")
    return [(r[xi], r[yi]) for r in struct.iter_unpack(rec, body[:n * count])]


def evaluate(hsr, points, mesh, truth=None):
    cmd = [hsr, "eval", points, mesh, "--json"] + (["--truth", truth] if truth else [])
    r = run(cmd)
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip())
    return json.loads(r.stdout)


def is_valid(validity):
    return all(validity[k] for k in ("closed", "manifold", "oriented", "self_intersection_free", "bounds_volume"))


def measure(hsr, folder, scan, tmp, extra, png):
    name = scan[:-4]
    points = os.path.join(folder, scan)
    city3d = os.path.join(folder, name + "_city3d.obj")
    model = os.path.join(tmp, name + ".obj")
    report = os.path.join(tmp, name + ".json")
    group = next((g for g in GROUPS if name.startswith(g)), "other")
    t0 = time.time()
    r = run([hsr, "reconstruct", points, "-o", model, "--report", report, "-q"] + extra)
    row = {"input": name, "group": group, "seconds": round(time.time() - t0, 2)}
    xy = read_ply_xy(points)
    row["points"] = len(xy)
    c3v = obj_vertices(city3d)
    c3_diag = bbox_diagonal(c3v)
    c3 = evaluate(hsr, points, city3d)
    row["city3d_p2m"] = 100 * c3["accuracy"]["p2m_mean"]
    row["city3d_faces"] = c3["faces"]
    if r.returncode != 0:
        lines = r.stderr.strip().splitlines()
        row.update(valid="no output", error=lines[-1] if lines else f"exit {r.returncode}")
        if os.path.exists(report):
            rep = json.load(open(report))
            row["mode"] = rep.get("scene", {}).get("mode", "")
        return row
    rep = json.load(open(report))
    ev = evaluate(hsr, points, model, city3d)
    scale = ev["diagonal"] / c3_diag  # fractions of the points' diagonal -> City3D's
    acc = ev["accuracy"]
    mv = obj_vertices(model)
    row.update(
        mode=rep["scene"]["mode"],
        ground=rep["scene"].get("ground_source", ""),
        valid="yes" if is_valid(rep["validity"]) else "no",
        facets=rep["counts"]["output_faces"],
        p2m=100 * acc["p2m_mean"],
        city3d_to_hsr=100 * acc["truth_to_mesh_mean"] * scale,
        hsr_to_city3d=100 * acc["mesh_to_truth_mean"] * scale,
        thickness=plan_width([(p[0], p[1]) for p in mv]) / max(plan_width(xy), 1e-9),
        unexplained=100 * rep.get("quality", {}).get("points_unexplained_share", 0.0),
        turn=rep["scene"].get("own_frame_turn_deg", 0.0),
    )
    g = min(p[2] for p in c3v)
    model_g = os.path.join(tmp, name + "_city3d_ground.obj")
    extra_g = [x for x in extra if x not in ("--scene", "object", "auto", "building")]
    report_g = os.path.join(tmp, name + "_city3d_ground.json")  # kept with --keep (which steps kept their run)
    rg = run([hsr, "reconstruct", points, "-o", model_g, "--ground-z", repr(g), "--scene", "building", "--report",
              report_g, "-q"] + extra_g)
    if rg.returncode == 0:
        eg = evaluate(hsr, points, model_g, city3d)["accuracy"]
        row.update(city3d_ground=g, city3d_to_hsr_at_city3d_ground=100 * eg["truth_to_mesh_mean"] * scale)
    if png:
        os.makedirs(png, exist_ok=True)
        cj = os.path.join(tmp, name + ".city.json")
        run([hsr, "reconstruct", points, "-o", cj, "-q"] + extra)
        src = cj if os.path.exists(cj) else model
        run([hsr, "render", src, points, "-o", os.path.join(png, name + "_hsr.png"), "--width", "480", "--height", "340", "-q"])
        run([hsr, "render", city3d, points, "-o", os.path.join(png, name + "_city3d.png"), "--width", "480", "--height", "340", "-q"])
    return row


def fmt(x, d=2):
    return "" if x is None else f"{x:.{d}f}"


def summary(rows, label):
    ok = [r for r in rows if "p2m" in r]
    n = len(rows)
    valid = sum(r.get("valid") == "yes" for r in rows)
    building = sum(r.get("mode") == "building" for r in rows)
    med = lambda k, rs=ok: statistics.median(r[k] for r in rs) if rs else None
    above = sum(r["city3d_to_hsr"] > 3 for r in ok) + (n - len(ok))
    at = [r["city3d_to_hsr_at_city3d_ground"] for r in ok if "city3d_to_hsr_at_city3d_ground" in r]
    thin = sum(r["thickness"] < 0.5 for r in ok)
    above_at = sum(x > 3 for x in at)
    unexpl = [r["unexplained"] for r in ok]
    warned = sum(x > 5 for x in unexpl)
    # City3D's p2m over the same buildings as hsr's (those with a model), so that the two medians are paired
    p2m_h, p2m_c = med("p2m"), med("city3d_p2m")
    worse = "" if p2m_h is None or p2m_h <= p2m_c else " (worse)"
    return (f"| {label} | {n} | {valid} | {building} | {fmt(p2m_h)} / {fmt(p2m_c)}{worse} | "
            f"{fmt(med('city3d_to_hsr'))} | {fmt(med('hsr_to_city3d'))} | {above} | "
            f"{fmt(statistics.median(at)) if at else ''} | {above_at} | {fmt(statistics.median(unexpl)) if unexpl else ''} | "
            f"{warned} | {thin} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.path.join(here, "..", "..", "..", "shared")
    ap.add_argument("--hsr", default=os.path.join(here, "..", "..", "build", "hsr"))
    ap.add_argument("--dir", action="append", help="folder of NAME.ply + NAME_city3d.obj (repeatable; default "
                    "../shared/airborne and ../shared/airborne_more)")
    ap.add_argument("--only", help="comma-separated names (without .ply)")
    ap.add_argument("--out")
    ap.add_argument("--csv")
    ap.add_argument("--png", help="folder for pictures: hsr's model over the points, City3D's model")
    ap.add_argument("--jobs", type=int, default=1, help="buildings measured at once (default 1)")
    ap.add_argument("--keep", help="keep hsr's models (NAME.obj, NAME.json) in this folder (contact_sheet.py reads them)")
    ap.add_argument("extra", nargs="*", help="options passed to hsr reconstruct (after --)")
    a = ap.parse_args()
    dirs = a.dir or [os.path.join(shared, "airborne"), os.path.join(shared, "airborne_more")]
    only = set(a.only.split(",")) if a.only else None
    work = [(d, f) for d in dirs if os.path.isdir(d) for f in sorted(os.listdir(d))
            if f.endswith(".ply") and (only is None or f[:-4] in only)]
    if not work:
        sys.exit(f"airborne.py: no scans in {dirs}")
    tmp = a.keep or tempfile.mkdtemp(prefix="hsr-airborne-")
    os.makedirs(tmp, exist_ok=True)
    t0 = time.time()
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        rows = list(pool.map(lambda w: measure(a.hsr, w[0], w[1], tmp, a.extra, a.png), work))
    wall = time.time() - t0
    out = [f"{len(rows)} buildings, `hsr reconstruct NAME.ply -o m.obj {' '.join(a.extra)}`, {wall:.0f} s wall "
           f"({a.jobs} at once). Distances in % of the diagonal (p2m: the points'; City3D's: its model's). "
           "Thin: the model's smallest width in plan under half the points'.", "",
           "| group | n | valid | auto = building | p2m median hsr / City3D (same buildings) | City3D → hsr median | hsr → City3D median | "
           "City3D → hsr above 3 % (or no model) | on City3D's ground, median | above 3 % there | unexplained % median | "
           "unexplained above 5 % | thin |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for g in GROUPS:
        rs = [r for r in rows if r["group"] == g]
        if rs:
            out.append(summary(rs, g))
    out.append(summary([r for r in rows if r["group"] in ("AHN3", "Vaihingen")], "AHN3 + Vaihingen"))
    out.append(summary(rows, "all"))
    out += ["", "| input | points | mode | ground | valid | facets | p2m % | City3D p2m % | City3D → hsr % | hsr → City3D % | "
            "thickness | s | City3D → hsr % on City3D's ground | unexplained % | own frame turn ° |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "p2m" not in r:
            out.append(f"| {r['input']} | {r['points']} | {r.get('mode', '')} | | {r['valid']}: {r.get('error', '')} | | | "
                       f"{fmt(r['city3d_p2m'])} | | | | {r['seconds']} | | | |")
            continue
        cg = r.get("city3d_to_hsr_at_city3d_ground")
        out.append(f"| {r['input']} | {r['points']} | {r['mode']} | {r['ground']} | {r['valid']} | {r['facets']} | "
                   f"{fmt(r['p2m'])} | {fmt(r['city3d_p2m'])} | {fmt(r['city3d_to_hsr'])} | {fmt(r['hsr_to_city3d'])} | "
                   f"{fmt(r['thickness'])} | {r['seconds']} | {'' if cg is None else '%.2f (z = %.2f)' % (cg, r['city3d_ground'])} | "
                   f"{fmt(r['unexplained'])} | {fmt(r['turn'], 1)} |")
    worst = sorted((r for r in rows if "p2m" in r), key=lambda r: -r["city3d_to_hsr"])[:10]
    out += ["", "Worst ten, City3D → hsr: " + ", ".join(f"{r['input']} {r['city3d_to_hsr']:.2f} %" for r in worst)]
    worst_at = sorted((r for r in rows if "city3d_to_hsr_at_city3d_ground" in r), key=lambda r: -r["city3d_to_hsr_at_city3d_ground"])[:10]
    out += ["", "Worst ten on City3D's ground: " + ", ".join(f"{r['input']} {r['city3d_to_hsr_at_city3d_ground']:.2f} %" for r in worst_at)]
    worst_u = sorted((r for r in rows if "p2m" in r), key=lambda r: -r["unexplained"])[:10]
    out += ["", "Worst ten, unexplained share: " + ", ".join(f"{r['input']} {r['unexplained']:.1f} %" for r in worst_u)]
    worst_p = sorted((r for r in rows if "p2m" in r), key=lambda r: -(r["p2m"] - r["city3d_p2m"]))[:10]
    out += ["", "Worst ten, p2m above City3D's: " + ", ".join(f"{r['input']} {r['p2m']:.2f} / {r['city3d_p2m']:.2f} %" for r in worst_p)]
    text = "\n".join(out) + "\n"
    if a.out:
        open(a.out, "w").write(text)
    print(text, end="")
    if a.csv:
        keys = ["input", "group", "points", "mode", "ground", "valid", "error", "facets", "p2m", "city3d_p2m", "city3d_to_hsr",
                "hsr_to_city3d", "thickness", "seconds", "city3d_ground", "city3d_to_hsr_at_city3d_ground", "unexplained", "turn"]
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
