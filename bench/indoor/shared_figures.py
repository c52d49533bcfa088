#!/usr/bin/python3
"""The shared scans' and the airborne buildings' figures, for a before/after comparison of a rule change
(issue 25: visibility indoors must leave them unchanged or better).

`run`: hsr reconstruct with default options (plus --extra) on every input listed in the MANIFEST.tsv of each
folder given (default ../shared/data, ../shared/airborne, ../shared/airborne_more); one CSV row per input:
status, validity, output faces, p2m (% of the points' bbox diagonal), highly visible planes, partition
cells, the output mesh's SHA-1 (equal hashes: byte-identical outputs) and, where a `NAME_city3d.obj` lies
beside the scan, the mean distance from City3D's model to hsr's and back (% of City3D's bbox diagonal, as
bench/building/airborne.py and ANCHORS.md).
`compare BEFORE.csv AFTER.csv`: how many outputs are byte-identical, and for the others the change of each
figure, as a distribution (median, quartiles) with the worst cases.

    /usr/bin/python3 bench/indoor/shared_figures.py run --out /tmp/before.csv [--hsr build/hsr] [--extra '...']
    /usr/bin/python3 bench/indoor/shared_figures.py compare /tmp/before.csv /tmp/after.csv
"""
import argparse, csv, hashlib, json, os, statistics, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared"))
FIELDS = ["input", "folder", "status", "valid", "faces", "p2m_pct", "highly_visible", "planes", "cells", "mode",
          "city3d_to_hsr_pct", "hsr_to_city3d_pct", "sha1"]


def manifest(folder):
    path = os.path.join(folder, "MANIFEST.tsv")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [r["file"] for r in csv.DictReader(f, delimiter="\t")]


def bbox_diagonal_obj(path):
    lo, hi = [float("inf")] * 3, [-float("inf")] * 3
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, v)]
                hi = [max(a, b) for a, b in zip(hi, v)]
    return sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5


def run_one(hsr, folder, name, extra, work):
    points = os.path.join(folder, name)
    mesh, rep = os.path.join(work, "m.obj"), os.path.join(work, "r.json")
    for p in (mesh, rep):
        if os.path.exists(p):
            os.remove(p)
    row = {"input": name, "folder": os.path.basename(folder.rstrip("/"))}
    r = subprocess.run([hsr, "-q", "reconstruct", points, "-o", mesh, "--report", rep] + extra,
                       capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(mesh):
        row["status"] = "failed: " + (r.stderr.strip().splitlines() or [""])[-1][:100]
        return row
    j = json.load(open(rep))
    c = j["counts"]
    row.update(status="ok", valid=j["validity"]["valid"], faces=c["output_faces"],
               p2m_pct=100 * j["accuracy"]["p2m_mean"], highly_visible=c.get("highly_visible_planes", ""),
               planes=c.get("planes", ""), cells=c.get("cells", ""), mode=j.get("scene", {}).get("mode", ""),
               sha1=hashlib.sha1(open(mesh, "rb").read()).hexdigest())
    city3d = os.path.join(folder, os.path.splitext(name)[0] + "_city3d.obj")
    if os.path.exists(city3d):
        e = subprocess.run([hsr, "eval", points, mesh, "--truth", city3d, "--json"], capture_output=True, text=True)
        if e.returncode == 0:
            ev = json.loads(e.stdout)
            scale = ev["diagonal"] / bbox_diagonal_obj(city3d)  # fractions of the points' diagonal -> City3D's
            row.update(city3d_to_hsr_pct=100 * ev["accuracy"]["truth_to_mesh_mean"] * scale,
                       hsr_to_city3d_pct=100 * ev["accuracy"]["mesh_to_truth_mean"] * scale)
    return row


def cmd_run(a):
    folders = a.folders or [os.path.join(SHARED, d) for d in ("data", "airborne", "airborne_more")]
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for folder in folders:
            names = manifest(folder)
            if not names:
                print(f"shared_figures: {folder}/MANIFEST.tsv not found, skipped", file=sys.stderr)
            for name in names:
                row = run_one(a.hsr, folder, name, a.extra.split(), work)
                rows.append(row)
                print(",".join(str(row.get(k, "")) for k in FIELDS), flush=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, a.out)
    return 0


def num(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def cmd_compare(a):
    before = {(r["folder"], r["input"]): r for r in csv.DictReader(open(a.before))}
    after = {(r["folder"], r["input"]): r for r in csv.DictReader(open(a.after))}
    keys = sorted(set(before) & set(after))
    same = [k for k in keys if before[k]["sha1"] == after[k]["sha1"] and before[k]["status"] == after[k]["status"]]
    changed = [k for k in keys if k not in same]
    failed = [k for k in same if before[k]["status"] != "ok"]
    print(f"{len(keys)} inputs in both; {len(same)} unchanged ({len(same) - len(failed)} byte-identical outputs, "
          f"{len(failed)} failing the same way), {len(changed)} changed")
    for folder in sorted({k[0] for k in keys}):
        ks = [k for k in keys if k[0] == folder]
        print(f"  {folder}: {len(ks)} inputs, {sum(k in same for k in ks)} identical; valid before "
              f"{sum(before[k]['valid'] == 'True' for k in ks)}, after {sum(after[k]['valid'] == 'True' for k in ks)}")
    for field, better in (("faces", "lower"), ("p2m_pct", "lower"), ("city3d_to_hsr_pct", "lower"),
                          ("hsr_to_city3d_pct", "lower"), ("highly_visible", "")):
        d = []
        for k in changed:
            b, x = num(before[k].get(field)), num(after[k].get(field))
            if b is not None and x is not None:
                d.append((x - b, k, b, x))
        if not d:
            continue
        ds = sorted(v[0] for v in d)
        q = statistics.quantiles(ds, n=4) if len(ds) >= 2 else [ds[0]] * 3
        print(f"{field} (after - before, {better or 'for information'}; {len(d)} changed inputs): median {q[1]:+.4g}, "
              f"quartiles {q[0]:+.4g} / {q[2]:+.4g}, min {ds[0]:+.4g}, max {ds[-1]:+.4g}; "
              f"worse {sum(v[0] > 0 for v in d) if better else '-'}, better {sum(v[0] < 0 for v in d) if better else '-'}")
        worst = sorted(d, key=lambda v: -v[0])[: a.worst]
        for delta, k, b, x in worst:
            print(f"    {k[0]}/{k[1]}: {b:.4g} -> {x:.4g} ({delta:+.4g})")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--hsr", default=os.path.join(HERE, "..", "..", "build", "hsr"))
    r.add_argument("--extra", default="", help="more reconstruct options, one string")
    r.add_argument("--out", required=True)
    r.add_argument("folders", nargs="*", help="folders with a MANIFEST.tsv (default: the three shared ones)")
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--worst", type=int, default=5, help="worst cases listed per figure")
    a = ap.parse_args()
    return cmd_run(a) if a.cmd == "run" else cmd_compare(a)


if __name__ == "__main__":
    sys.exit(main())
