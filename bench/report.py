#!/usr/bin/python3
"""Turns the run manifest of bench/run.sh into bench/results/results.csv and results.md.

Standard library only. One row per (input, method); a run that failed, timed out, was not implemented or
was skipped keeps its row with that status and no metrics. Distances are in % of the input points' bbox
diagonal (as `hsr eval` reports them, times 100).
"""
import argparse
import csv
import datetime
import json
import math
import os
import statistics

METHOD_ORDER = ["hsr-exhaustive", "hsr-exhaustive-norec", "hsr-bsp", "hsr-bsp-norec", "hsr-kinetic",
                "hsr-kinetic-norec", "hsr-hierarchical", "hsr-hierarchical-norec", "polyfit", "poisson_qem",
                "poisson_qem_500"]
REFERENCE = "hsr-hierarchical"  # hsr's default run, compared head to head with every other method

CSV_FIELDS = ["input", "method", "status", "valid", "closed", "manifold", "oriented", "self_intersection_free",
              "vertices", "facets", "points", "p2m_mean_pct", "p2m_rms_pct", "p2m_max_pct", "m2p_mean_pct",
              "m2p_max_pct", "hausdorff_pct", "truth_chamfer_pct", "truth_hausdorff_pct", "rh", "seconds",
              "peak_mb", "cells", "planes", "note"]


def load_json(path):
    if not path or not os.path.exists(path):
        return None
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def parse_time_file(path):
    """Peak RSS (MB) and wall seconds from GNU time -v output, or (None, None)."""
    peak = wall = None
    if not path or not os.path.exists(path):
        return peak, wall
    with open(path, errors="replace") as f:
        for line in f:
            line = line.strip()
            if line.startswith("Maximum resident set size (kbytes):"):
                peak = int(line.rsplit(":", 1)[1]) / 1024.0
            elif line.startswith("Elapsed (wall clock) time"):
                t = line.rsplit(": ", 1)[1].split(":")
                wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(t)))
    return peak, wall


def method_rank(m):
    return (METHOD_ORDER.index(m) if m in METHOD_ORDER else len(METHOD_ORDER), m)


def build_rows(manifest):
    rows = []
    with open(manifest, newline="") as f:
        for rec in csv.DictReader(f, delimiter="\t"):
            row = {k: "" for k in CSV_FIELDS}
            row.update(input=rec["input"], method=rec["method"], status=rec["status"], note=rec["note"])
            ev = load_json(rec["eval"])
            rep = load_json(rec["report"])
            peak_time, wall = parse_time_file(rec["time"])
            if rep:
                counts = rep.get("counts", {})
                row["cells"] = counts.get("cells", "")
                row["planes"] = counts.get("planes", rep.get("planes", ""))
                secs = rep.get("seconds")
                if isinstance(secs, dict):  # hsr: reconstruction time, without the report's own evaluation
                    row["seconds"] = secs.get("total", 0.0) - secs.get("eval", 0.0)
                elif isinstance(secs, (int, float)):
                    row["seconds"] = secs
            if row["seconds"] == "" and wall is not None:
                row["seconds"] = wall
            peaks = [p for p in (peak_time, rep.get("peak_memory_mb") if rep else None) if p is not None]
            if peaks:
                row["peak_mb"] = max(peaks)
            if rec["status"] == "ok" and ev:
                v = ev["validity"]
                a = ev["accuracy"]
                row.update(valid=v.get("valid"), closed=v.get("closed"), manifold=v.get("manifold"),
                           oriented=v.get("oriented"), self_intersection_free=v.get("self_intersection_free"),
                           vertices=ev["vertices"], facets=ev["faces"], points=ev["points"],
                           p2m_mean_pct=100 * a["p2m_mean"], p2m_rms_pct=100 * a["p2m_rms"],
                           p2m_max_pct=100 * a["p2m_max"], m2p_mean_pct=100 * a["m2p_mean"],
                           m2p_max_pct=100 * a["m2p_max"])
                hausdorff = max(a["p2m_max"], a["m2p_max"])
                row["hausdorff_pct"] = 100 * hausdorff
                row["rh"] = hausdorff * ev["vertices"] / ev["points"] if ev["points"] else ""
                if a.get("has_truth"):
                    row["truth_chamfer_pct"] = 100 * a["chamfer"]
                    row["truth_hausdorff_pct"] = 100 * a["hausdorff"]
            rows.append(row)
    inputs = []
    for r in rows:
        if r["input"] not in inputs:
            inputs.append(r["input"])
    rows.sort(key=lambda r: (inputs.index(r["input"]), method_rank(r["method"])))
    return rows, inputs


def fmt(x, digits=3):
    if x == "" or x is None:
        return ""
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return "%.0f" % x
    return "%.*g" % (digits, x)


def fmt_rh(x):
    return "" if x == "" else "%.2e" % x


def validity_text(r):
    if r["status"] != "ok":
        return r["status"].upper()
    if r["valid"] is True:
        return "yes"
    why = [name for key, name in (("closed", "open"), ("manifold", "non-manifold"),
                                  ("self_intersection_free", "self-intersecting"), ("oriented", "not oriented"))
           if r[key] is False]
    return "no (" + ", ".join(why) + ")" if why else "no"


def has_mesh(r):
    return r["status"] == "ok" and r["facets"] != ""


def mean(values):
    values = [v for v in values if v != "" and v is not None]
    return statistics.fmean(values) if values else ""


def write_csv(rows, path):
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r[k] is None else r[k]) for k in CSV_FIELDS})
    os.replace(path + ".tmp", path)


def summary_rows(rows, inputs):
    methods = sorted({r["method"] for r in rows}, key=method_rank)
    out = []
    for m in methods:
        mine = [r for r in rows if r["method"] == m]
        meshes = [r for r in mine if has_mesh(r)]
        statuses = {}
        for r in mine:
            if not has_mesh(r):
                statuses[r["status"]] = statuses.get(r["status"], 0) + 1
        out.append(dict(
            method=m, runs=len(mine), meshes=len(meshes), valid=sum(1 for r in meshes if r["valid"] is True),
            other=", ".join("%d %s" % (n, s) for s, n in sorted(statuses.items())),
            vertices=mean([r["vertices"] for r in meshes]), facets=mean([r["facets"] for r in meshes]),
            p2m_mean=mean([r["p2m_mean_pct"] for r in meshes]), p2m_rms=mean([r["p2m_rms_pct"] for r in meshes]),
            p2m_max=mean([r["p2m_max_pct"] for r in meshes]), m2p_mean=mean([r["m2p_mean_pct"] for r in meshes]),
            chamfer=mean([r["truth_chamfer_pct"] for r in meshes]), rh=mean([r["rh"] for r in meshes]),
            seconds=mean([r["seconds"] for r in mine if r["status"] in ("ok", "timed out")]),
            peak=mean([r["peak_mb"] for r in meshes])))
    return out


def head_to_head(rows, inputs):
    """Per other method: on inputs where both it and REFERENCE produced a mesh, median ratios."""
    by = {(r["input"], r["method"]): r for r in rows}
    methods = sorted({r["method"] for r in rows if r["method"] != REFERENCE}, key=method_rank)
    out = []
    for m in methods:
        pairs = [(by.get((i, REFERENCE)), by.get((i, m))) for i in inputs]
        pairs = [(a, b) for a, b in pairs if a and b and has_mesh(a) and has_mesh(b)]
        ran = [i for i in inputs if by.get((i, m))]
        only_ref_valid = sum(1 for i in ran if by.get((i, REFERENCE)) and has_mesh(by[(i, REFERENCE)])
                             and by[(i, REFERENCE)]["valid"] is True
                             and not (has_mesh(by[(i, m)]) and by[(i, m)]["valid"] is True))
        only_m_valid = sum(1 for i in ran if has_mesh(by[(i, m)]) and by[(i, m)]["valid"] is True
                           and not (by.get((i, REFERENCE)) and has_mesh(by[(i, REFERENCE)])
                                    and by[(i, REFERENCE)]["valid"] is True))

        def ratio(key):
            vals = [a[key] / b[key] for a, b in pairs if a[key] not in ("", None) and b[key] not in ("", None)
                    and b[key] > 0]
            return statistics.median(vals) if vals else ""

        wins = sum(1 for a, b in pairs if a["p2m_mean_pct"] < b["p2m_mean_pct"])
        out.append(dict(method=m, both=len(pairs), wins=wins, p2m=ratio("p2m_mean_pct"), rms=ratio("p2m_rms_pct"),
                        m2p=ratio("m2p_mean_pct"), facets=ratio("facets"), vertices=ratio("vertices"),
                        seconds=ratio("seconds"), only_ref_valid=only_ref_valid, only_m_valid=only_m_valid))
    return out


AERIAL_PREFIX = "synth_aerial_"


def summary_table(L, rows, inputs):
    L.append("| method | runs | meshes | valid | no mesh | vertices | facets | p2m mean | p2m RMS | p2m max | "
             "m2p mean | truth Chamfer | RH | seconds | peak MB |")
    L.append("|" + "---|" * 15)
    for s in summary_rows(rows, inputs):
        L.append("| %s | %d | %d | %d | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            s["method"], s["runs"], s["meshes"], s["valid"], s["other"] or "0", fmt(s["vertices"]),
            fmt(s["facets"]), fmt(s["p2m_mean"]), fmt(s["p2m_rms"]), fmt(s["p2m_max"]), fmt(s["m2p_mean"]),
            fmt(s["chamfer"]) or "n/a", fmt_rh(s["rh"]) or "n/a", fmt(s["seconds"]), fmt(s["peak"])))


def write_md(rows, inputs, args, path):
    L = []
    L.append("# hsr against its peers")
    L.append("")
    L.append("- Date: %s" % datetime.datetime.now().strftime("%Y-%m-%d %H:%M"))
    try:
        with open("/proc/loadavg") as f:
            load = " / ".join(f.read().split()[:3])
    except OSError:
        load = "unknown"
    L.append("- Machine: %s; load average (1 / 5 / 15 min) when the table was written: %s "
             "(times are wall-clock, so a busy machine inflates them for every method alike)" % (args.machine, load))
    L.append("- Command: `%s` (from the repository root; `make bench` runs it after building)" % args.command)
    L.append("- hsr: %s" % args.hsr)
    L.append("- Limits: %s; whole run took %s s" % (args.limits, args.elapsed))
    L.append("- Inputs: %d (%s)" % (len(inputs), ", ".join(inputs)))
    L.append("")
    L.append("Methods: `hsr-<partition>` is `hsr reconstruct --partition <partition>` (default pipeline, with "
             "missing-plane recovery); `-norec` adds `--no-recovery` (only when the CLI offers it). `polyfit` is "
             "CGAL 5.5 Polygonal_surface_reconstruction on hsr's detected planes, GLPK, default weights. "
             "`poisson_qem` is CGAL 5.5 Poisson reconstruction then Garland-Heckbert edge collapse down to the "
             "facet count of `hsr-hierarchical` on the same input (500 when it produced nothing); `poisson_qem_500` "
             "stops at 500 faces, the budget of the peers' figures in ANCHORS.md. Every mesh is "
             "evaluated by `hsr eval` against the input points.")
    L.append("")
    L.append("## Summary per method")
    L.append("")
    summary_table(L, rows, inputs)
    L.append("")
    L.append("Means are over the inputs where the method produced a mesh (column *meshes*; valid or not), so "
             "rows with different mesh counts average different inputs — see the head-to-head table for paired "
             "comparisons. *seconds* averages runs that produced a mesh, failed, or timed out (counted at the "
             "limit); *no mesh* counts the other outcomes.")
    L.append("")
    ground = [i for i in inputs if not i.startswith(AERIAL_PREFIX)]
    if len(ground) < len(inputs):
        L.append("## Summary without the aerial synth buildings")
        L.append("")
        L.append("The %d inputs not named %s* (the shared scans and the terrestrial synth models): the aerial "
                 "synth scans' p2m counts their ground and tree points, which building mode leaves out of the "
                 "model (bench/building/ measures them against their truth)." % (len(ground), AERIAL_PREFIX))
        L.append("")
        summary_table(L, [r for r in rows if r["input"] in ground], ground)
        L.append("")
    L.append("## Head to head: %s against each other method" % REFERENCE)
    L.append("")
    L.append("Paired over the inputs where both produced a mesh. Ratios are medians of "
             "%s / other (below 1: %s is smaller, i.e. better for distances, facets and time)." %
             (REFERENCE, REFERENCE))
    L.append("")
    L.append("| other method | paired inputs | %s lower p2m | p2m mean ratio | p2m RMS ratio | m2p mean ratio | "
             "facets ratio | vertices ratio | time ratio | only %s valid | only other valid |" %
             (REFERENCE, REFERENCE))
    L.append("|" + "---|" * 11)
    for h in head_to_head(rows, inputs):
        L.append("| %s | %d | %d | %s | %s | %s | %s | %s | %s | %d | %d |" % (
            h["method"], h["both"], h["wins"], fmt(h["p2m"]) or "n/a", fmt(h["rms"]) or "n/a",
            fmt(h["m2p"]) or "n/a", fmt(h["facets"]) or "n/a", fmt(h["vertices"]) or "n/a",
            fmt(h["seconds"]) or "n/a", h["only_ref_valid"], h["only_m_valid"]))
    L.append("")
    L.append("## Per input")
    L.append("")
    L.append("| input | method | valid | vertices | facets | p2m mean | p2m RMS | p2m max | m2p mean | "
             "truth Chamfer | RH | seconds | peak MB | cells | note |")
    L.append("|" + "---|" * 15)
    for r in rows:
        mesh = has_mesh(r)
        dash = "—"
        truth = fmt(r["truth_chamfer_pct"]) if r["truth_chamfer_pct"] != "" else ("n/a" if mesh else dash)
        cells = fmt(r["cells"]) if r["cells"] != "" else ("n/a" if not r["method"].startswith("hsr") else dash)
        L.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["input"], r["method"], validity_text(r),
            fmt(r["vertices"]) if mesh else dash, fmt(r["facets"]) if mesh else dash,
            fmt(r["p2m_mean_pct"]) if mesh else dash, fmt(r["p2m_rms_pct"]) if mesh else dash,
            fmt(r["p2m_max_pct"]) if mesh else dash, fmt(r["m2p_mean_pct"]) if mesh else dash,
            truth, fmt_rh(r["rh"]) if mesh else dash, fmt(r["seconds"]) or dash,
            fmt(r["peak_mb"]) or dash, cells, r["note"].replace("|", "/")))
    L.append("")
    L.append("Columns. *valid*: closed, manifold, consistently oriented and free of self-intersections (`hsr eval`); "
             "otherwise `no (...)` lists what failed; capitals mark runs without a mesh (FAILED, TIMED OUT, "
             "NOT IMPLEMENTED, SKIPPED, NOT BUILT). *vertices*, *facets*: of the output polygon mesh (Poisson+QEM "
             "facets are triangles). *p2m*: distance from each input point to the mesh, mean / root mean square / "
             "max; *m2p mean*: mean distance from %s uniform samples on the mesh to the nearest input point; all in "
             "%% of the input points' bounding-box diagonal. *truth Chamfer*: symmetric mean distance between the "
             "mesh and the true surface, %% of the diagonal (synthetic inputs only; n/a elsewhere). *RH*: the "
             "paper's composite conciseness figure, H x V / N, where H = max(p2m max, m2p max) is the symmetric "
             "Hausdorff distance between the input points and the mesh as a fraction of the diagonal, V the "
             "output vertex count and N the input point count (lower is better). *seconds*: wall time of the "
             "reconstruction (hsr: its report's total minus its own evaluation; baselines: reading, plane "
             "detection / normals and solving, in the worker process); for timeouts, the time until killed. "
             "*peak MB*: maximum resident set size (GNU time, which includes a baseline's forked worker, or "
             "the program's own report, whichever is larger). *cells*: cells of hsr's space partition (n/a for "
             "the baselines: PolyFit's candidate faces are not exposed by CGAL)." % "200000")
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(L) + "\n")
    os.replace(path + ".tmp", path)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--command", default="bash bench/run.sh")
    ap.add_argument("--machine", default="")
    ap.add_argument("--limits", default="")
    ap.add_argument("--hsr", default="")
    ap.add_argument("--elapsed", default="")
    args = ap.parse_args()
    rows, inputs = build_rows(args.manifest)
    os.makedirs(args.out, exist_ok=True)
    write_csv(rows, os.path.join(args.out, "results.csv"))
    write_md(rows, inputs, args, os.path.join(args.out, "results.md"))


if __name__ == "__main__":
    main()
