#!/usr/bin/python3
"""Faces bench report (issue 14): bench/results/faces.csv (bench/faces/run.py) beside KSR's per-file figures
(../shared/ANCHORS.md) and PolyFit / Poisson+QEM (bench/results/results.csv) -> bench/results/faces.md.

    /usr/bin/python3 bench/faces/report.py [--csv bench/results/faces.csv] [--anchors /work/shared/ANCHORS.md]
"""
import argparse, csv, os, statistics, subprocess, sys, time

SMALL = "faces under 0.1 % of the area"


def read_anchors(path):
    """KSR per file from the shared-scan and airborne tables of ANCHORS.md: {input file: (valid, facets, p2m %)}
    (the airborne table names its inputs without the .ply)."""
    out = {}
    if not os.path.exists(path):
        return out
    table = None
    for line in open(path):
        if line.startswith("## "):
            table = "data" if "shared scans" in line else "airborne" if "Airborne" in line else None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if table is None or len(cells) < 4 or cells[0] in ("input",) or cells[0].startswith("---"):
            continue
        name = cells[0] if table == "data" else cells[0] + ".ply"
        try:
            out[name] = (cells[1] == "yes", int(cells[2]), float(cells[3].rstrip("%")))
        except ValueError:
            out[name] = (False, None, None)
    return out


def read_peers(path):
    out = {}
    if not os.path.exists(path):
        return out
    for r in csv.DictReader(open(path)):
        if r["method"] in ("polyfit", "poisson_qem") and r["status"] == "ok":
            out[(r["input"], r["method"])] = (r["valid"] == "True", int(r["facets"]), float(r["p2m_mean_pct"]))
    return out


def med(xs):
    return statistics.median(xs) if xs else float("nan")


BOX_P2M = 10.0  # a KSR output this far from the points (% of the diagonal) is its bounding box


def read_ksr_lambdas(path):
    """bench/faces/ksr.py's rows: {(input, λ): (valid, facets, p2m %, box)} for the runs with an output."""
    out = {}
    if not path or not os.path.exists(path):
        return out
    for r in csv.DictReader(open(path)):
        if r["status"] == "ok":
            out[(r["input"], float(r["lambda"]))] = (r["valid"] == "True", int(r["facets"]), float(r["p2m_pct"]),
                                                     r["box"] == "True")
    return out


def ksr_usable(ksr_l, inputs, lam):
    """The inputs whose KSR output at λ is usable: there is one, and it is not KSR's bounding box."""
    return [i for i in inputs if (i, lam) in ksr_l and not ksr_l[(i, lam)][3]]


def ksr_lambda_section(ok, ksr_l, settings, in_group):
    """Issue 25: KSR at several λ (bench/faces/ksr.py, run beside hsr) against hsr's --detail levels, per group
    and λ, on the inputs where KSR's output at that λ is usable (an output that is not its bounding box)."""
    lams = sorted({k[1] for k in ksr_l})
    L = ["## KSR at several λ (bench/faces/ksr.py, this machine)", "",
         "KSR (CGAL 6.1.1, its default detection, k = 1, all box sides outside) once per input, reconstructed at "
         "λ = " + ", ".join(f"{x:g}" for x in lams) + "; facets, validity and p2m by `hsr eval`. A KSR output "
         f"with p2m over {BOX_P2M:g} % is its bounding box, not a valid output for the comparison (issue 25): each "
         "row is over the inputs whose KSR output at that λ is usable, and hsr's medians are over the same inputs.", "",
         "| group | λ | usable / all | KSR valid | KSR facets / p2m % | " +
         " | ".join(f"hsr {s} facets / p2m %" for s in settings) + " |",
         "|---|---|---|---|---|" + "---|" * len(settings)]
    by = {(r["input"], r["setting"]): r for r in ok}
    for g in ["building", "cad", "indoor", "freeform", "data/ (all)", "airborne", "all"]:
        inputs = sorted({r["input"] for r in ok if in_group(r, g)})
        if not inputs:
            continue
        for x in lams:
            keep = ksr_usable(ksr_l, inputs, x)
            vs = [ksr_l[(i, x)] for i in keep]
            cells = [f"{med([v[1] for v in vs]):g} / {med([v[2] for v in vs]):.3f}" if vs else "-"]
            for s in settings:
                rs = [by[(i, s)] for i in keep if (i, s) in by]
                cells.append(f"{med([r['facets'] for r in rs]):g} / {med([r['p2m_pct'] for r in rs]):.3f}" if rs else "-")
            L.append(f"| {g} | {x:g} | {len(keep)} / {len(inputs)} | {sum(v[0] for v in vs)} | " + " | ".join(cells) + " |")
    per = [f"{i} at λ {x:g} ({v[2]:.1f} %)" for (i, x), v in sorted(ksr_l.items()) if v[3]]
    L += ["", "Box outputs left out: " + (", ".join(per) if per else "none") + ".", ""]
    return L


def ksr_rows(L, keys, ksr, by, settings, label, medians_only=False):
    """Per-input rows (unless medians_only) and the median row of hsr against KSR over `keys`."""
    if not medians_only:
        for k in keys:
            cells = [f"{by[(k, s)]['facets']} / {by[(k, s)]['p2m_pct']:.3f}" if (k, s) in by else "-" for s in settings]
            L.append(f"| {k} | {ksr[k][1]} | {ksr[k][2]:.2f} | " + " | ".join(cells) + " |")
    kf, kp = med([ksr[k][1] for k in keys]), med([ksr[k][2] for k in keys])
    cells = []
    for s in settings:
        hs = [by[(k, s)] for k in keys if (k, s) in by]
        f, p = med([h["facets"] for h in hs]), med([h["p2m_pct"] for h in hs])
        ratio = med([by[(k, s)]["p2m_pct"] / ksr[k][2] for k in keys if (k, s) in by])
        cells.append(f"**{f:g} / {p:.3f}** (facets {'<=' if f <= kf else '>'} KSR: {'met' if f <= kf else 'not met'}; "
                     f"p2m {p / kp:.2f}x KSR's median, per-file ratio median {ratio:.2f}: "
                     f"{'met' if p <= 0.5 * kp else 'not met'})")
    L.append(f"| {label}, {len(keys)} inputs | {kf:g} | {kp:.3f} | " + " | ".join(cells) + " |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--csv", default="bench/results/faces.csv")
    ap.add_argument("--anchors", default="/work/shared/ANCHORS.md")
    ap.add_argument("--peers", default="bench/results/results.csv")
    ap.add_argument("--out", default="bench/results/faces.md")
    ap.add_argument("--command", default="")
    ap.add_argument("--ksr-csv", default="bench/results/faces_ksr.csv", help="bench/faces/ksr.py's output (if any)")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    ksr_l = read_ksr_lambdas(a.ksr_csv)
    ksr = read_anchors(a.anchors)
    peers = read_peers(a.peers)
    settings = list(dict.fromkeys(r["setting"] for r in rows))
    ok = [r for r in rows if r["status"] == "ok"]
    for r in ok:
        r["facets"], r["small_faces"] = int(r["facets"]), int(r["small_faces"])
        r["p2m_pct"] = float(r["p2m_pct"])
    L = []
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    L += ["# Faces: as few as the shape needs (issue 14)", "",
          f"- Date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; machine: 2 cores, shared; load average "
          f"when written: {' / '.join(f'{x:.2f}' for x in os.getloadavg())}",
          f"- hsr commit {commit} (plus the working tree when run); command: `{a.command or 'see bench/faces/README'}`",
          "- p2m = mean distance from the input points to the mesh, % of the bbox diagonal; small = " + SMALL +
          " (report `face_sizes.small_faces`); KSR figures from ANCHORS.md (CGAL 6.1.1, same files)" +
          ("; KSR at several λ run here by bench/faces/ksr.py (" + a.ksr_csv + ")." if ksr_l else "."), ""]
    # Per setting and group.
    L += ["## Per input group and detail level", "",
          "| detail | group | inputs | valid | median facets | median p2m % | small faces / all faces |",
          "|---|---|---|---|---|---|---|"]
    def in_group(r, g):
        return (g == "all" or r["kind"] == g or (g == "data/ (all)" and r["kind"] != "airborne"))

    for s in settings:
        for g in ["building", "cad", "indoor", "freeform", "data/ (all)", "airborne", "all"]:
            rs = [r for r in ok if r["setting"] == s and in_group(r, g)]
            if not rs:
                continue
            valid = sum(r["valid"] == "True" for r in rs)
            nf, ns = sum(r["facets"] for r in rs), sum(r["small_faces"] for r in rs)
            L.append(f"| {s} | {g} | {len(rs)} | {valid} | {med([r['facets'] for r in rs]):g} | "
                     f"{med([r['p2m_pct'] for r in rs]):.3f} | {ns} / {nf} = {100 * ns / max(nf, 1):.1f} % |")
    L.append("")
    # Against KSR where KSR is valid.
    by = {(r["input"], r["setting"]): r for r in ok}
    ran = {r["input"] for r in rows}
    airborne = {r["input"] for r in rows if r["kind"] == "airborne"}
    kv = sorted(k for k, v in ksr.items() if v[0] and k in ran and k not in airborne)
    L += ["## Where KSR gives a valid mesh", "",
          "Target: median facets <= KSR's and median p2m <= 0.5 x KSR's.", "",
          "| input | KSR facets | KSR p2m % | " + " | ".join(f"{s} facets / p2m %" for s in settings) + " |",
          "|---|---|---|" + "---|" * len(settings)]
    ksr_rows(L, kv, ksr, by, settings, "median (data/)")
    ka = sorted(k for k, v in ksr.items() if v[0] and k in airborne)
    if ka:
        ksr_rows(L, ka, ksr, by, settings, "median (airborne)", medians_only=False)
        ksr_rows(L, kv + ka, ksr, by, settings, "median (both)", medians_only=True)
        kt = [k for k in kv + ka if ksr[k][2] <= BOX_P2M]
        ksr_rows(L, kt, ksr, by, settings, f"median (both, KSR p2m <= {BOX_P2M:g} %)", medians_only=True)
        L += ["", f"KSR's outputs over {BOX_P2M:g} % p2m are its bounding box (officeCorner 21.6 %, AHN3_11969 "
              "27.8 % in ANCHORS.md): valid meshes, but not of the shape; the last row leaves them out."]
    L.append("")
    if ksr_l:
        L += ksr_lambda_section(ok, ksr_l, settings, in_group)
    # Small faces on all inputs.
    L += ["## Small faces on every input", "", "Target: " + SMALL + " <= 2 % of all faces.", "",
          "| input | group | " + " | ".join(f"{s}: facets, small, p2m %, valid" for s in settings) +
          " | PolyFit facets / p2m % | Poisson+QEM facets / p2m % |",
          "|---|---|" + "---|" * len(settings) + "---|---|"]
    for k in dict.fromkeys(r["input"] for r in rows):
        kind = next(r["kind"] for r in rows if r["input"] == k)
        cells = []
        for s in settings:
            r = by.get((k, s))
            cells.append(f"{r['facets']}, {r['small_faces']}, {r['p2m_pct']:.3f}, {'yes' if r['valid'] == 'True' else 'NO'}"
                         if r else "failed")
        pe = []
        for m in ("polyfit", "poisson_qem"):
            v = peers.get((k, m))
            pe.append(f"{v[1]} / {v[2]:.2f}{'' if v[0] else ' (invalid)'}" if v else "no mesh")
        L.append(f"| {k} | {kind} | " + " | ".join(cells) + " | " + " | ".join(pe) + " |")
    for label, g in (("the shared scans (data/)", "data/ (all)"), ("the airborne buildings", "airborne"),
                     ("all inputs", "all")):
        tot = []
        for s in settings:
            rs = [r for r in ok if r["setting"] == s and in_group(r, g)]
            if not rs:
                continue
            nf, ns = sum(r["facets"] for r in rs), sum(r["small_faces"] for r in rs)
            tot.append(f"{s}: {ns} / {nf} = {100 * ns / max(nf, 1):.1f} % ({'met' if ns <= 0.02 * nf else 'not met'})")
        if tot:
            L += ["", f"Small faces over {label}: " + "; ".join(tot) + "."]
    L.append("")
    tmp = a.out + ".tmp"
    open(tmp, "w").write("\n".join(L) + "\n")
    os.replace(tmp, a.out)
    print("\n".join(L))
    return 0


if __name__ == "__main__":
    sys.exit(main())
