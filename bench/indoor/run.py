#!/usr/bin/python3
"""Indoor bench (issue 25): the synth hall (`hsr synth hall --planes N`) reconstructed by hsr with DEFAULT
options beside CGAL 6.1.1's Kinetic Surface Reconstruction (KSR, minimum region 40 points), in the same run.

For each plane count N: hsr's validity, output faces, and their regions against the truth's (every block present:
within 5 %; a region is a connected set of coplanar faces counted 1 + its holes, the truth's `polygon_faces`),
truth -> mesh and mesh -> truth (mean, % of the diagonal, `hsr eval --truth`), wall time, peak memory and
per-stage seconds; the same for KSR (its detection, partition and reconstruction seconds). The main cases
(--planes, default 500 and 1000) are checked against the issue's targets (valid, faces within 5 %, truth ->
mesh <= 0.03 %, wall <= 0.5 x KSR's, peak memory <= KSR's); the sweep (--sweep, default 100 ... 2000) gives
time and memory against the plane count and the fitted exponent (least squares on the logs; goal < 1.5).

KSR is run by a driver program built OUTSIDE this repository from a fetched CGAL 6.1.1 (nothing fetched,
built from it, or a recipe to build it is committed; README "Indoor scenes" says how it is configured). Give
its path with --ksr or $HSR_KSR; without it the KSR columns say "not run". Its interface: `DRIVER INPUT
OUT_PREFIX --min-region N --lambda 0.5` writes OUT_PREFIX_0.5.off and prints one JSON line (planes,
seconds per step, peak memory). Every timed run holds --lock (default $HSR_HEAVY_LOCK, e.g.
/work/notes/heavy.lock) while it runs, so one measurement at a time runs on a shared machine.

    /usr/bin/python3 bench/indoor/run.py --ksr /path/to/ksr_driver --lock /work/notes/heavy.lock \\
        [--planes 500 1000] [--sweep 100 250 500 1000 2000] [--out bench/results/indoor.md] [--png docs/images]
"""
import argparse, contextlib, csv, fcntl, json, math, os, platform, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
TARGET = {"faces_within": 0.05, "truth_to_mesh_pct": 0.03, "wall_ratio": 0.5, "memory_ratio": 1.0, "exponent": 1.5}


@contextlib.contextmanager
def held(lock):
    """The shared measurement lock, held while one timed run runs (no lock: nothing)."""
    if not lock:
        yield
        return
    with open(lock, "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def run_measured(cmd, lock, timeout, log):
    """Runs cmd under the lock (stdout to LOG.out, stderr to LOG); returns (exit code or None on timeout,
    stdout, wall s, peak RSS MB of this child alone (os.wait4), load average when it started)."""
    with held(lock):
        load = os.getloadavg()[0]
        t0 = time.time()
        with open(log, "w") as err, open(log + ".out", "w") as out:
            p = subprocess.Popen(cmd, stdout=out, stderr=err)
            deadline = t0 + timeout
            while True:
                pid, status, usage = os.wait4(p.pid, os.WNOHANG)
                if pid:
                    break
                if time.time() > deadline:
                    p.kill()
                    pid, status, usage = os.wait4(p.pid, 0)
                    return None, "", time.time() - t0, None, load
                time.sleep(0.02)
        wall = time.time() - t0
    code = os.waitstatus_to_exitcode(status)
    return code, open(log + ".out").read(), wall, usage.ru_maxrss / 1024, load


def evaluate(hsr, points, mesh, truth):
    r = subprocess.run([hsr, "eval", points, mesh, "--truth", truth, "--json"], capture_output=True, text=True)
    if r.returncode != 0:
        return {"eval_error": (r.stderr.strip().splitlines() or [""])[-1][:120]}
    e = json.loads(r.stdout)
    a = e["accuracy"]
    return {"valid": e["validity"]["valid"], "faces": e["faces"], "regions": e.get("regions"),
            "truth_to_mesh_pct": 100 * a["truth_to_mesh_mean"],
            "mesh_to_truth_pct": 100 * a["mesh_to_truth_mean"], "p2m_pct": 100 * a["p2m_mean"],
            "validity": e["validity"]}


def make_hall(hsr, n, seed, work):
    d = os.path.join(work, f"hall_{n}_s{seed}")
    if not os.path.exists(os.path.join(d, "planes.json")):
        subprocess.run([hsr, "-q", "synth", "hall", "--planes", str(n), "--seed", str(seed), "-o", d], check=True)
    truth = json.load(open(os.path.join(d, "planes.json")))
    return d, truth


def run_hsr(a, d, lock):
    mesh, rep = os.path.join(d, "hsr.obj"), os.path.join(d, "hsr_report.json")
    for f in (mesh, rep):
        if os.path.exists(f):
            os.remove(f)
    cmd = [a.hsr, "reconstruct", os.path.join(d, "points.ply"), "-o", mesh, "--report", rep] + a.hsr_extra.split()
    code, _, wall, peak, load = run_measured(cmd, lock, a.timeout, os.path.join(d, "hsr.log"))
    row = {"wall_s": wall, "peak_mb": peak, "load": load, "exit": code}
    if code != 0 or not os.path.exists(mesh):
        tail = open(os.path.join(d, "hsr.log")).read().strip().splitlines()
        row["status"] = "timeout" if code is None else "failed: " + (tail[-1][:140] if tail else f"exit {code}")
        return row
    r = json.load(open(rep))
    row.update(status="ok", stages={k: v for k, v in r["seconds"].items()}, planes=r["counts"].get("planes"),
               cells=r["counts"].get("cells"), highly=r["counts"].get("highly_visible_planes"),
               report_peak_mb=r.get("peak_memory_mb"))
    row.update(evaluate(a.hsr, os.path.join(d, "points.ply"), mesh, os.path.join(d, "truth.obj")))
    return row


def run_ksr_once(a, d, lock, flip):
    prefix = os.path.join(d, "ksr_flipped" if flip else "ksr")
    off = prefix + "_0.5.off"
    if os.path.exists(off):
        os.remove(off)
    cmd = [a.ksr, os.path.join(d, "points.ply"), prefix, "--min-region", str(a.ksr_min_region), "--lambda", "0.5"]
    if flip:
        cmd.append("--flip-normals")
    code, out, wall, peak, load = run_measured(cmd, lock, a.timeout, prefix + ".log")
    row = {"wall_s": wall, "peak_mb": peak, "load": load, "exit": code, "normals": "reversed" if flip else "as given",
           "mesh": off}
    lines = [x for x in out.splitlines() if x.startswith("{")]
    if code != 0 or not lines or not os.path.exists(off):
        row["status"] = "timeout" if code is None else f"failed (exit {code})"
        return row
    info = json.loads(lines[-1])
    rec = info["reconstructions"][0]
    row.update(status="ok", planes=info["planes"], cells=info["volumes"],
               stages={"detection": info["seconds"]["read_normals"] + info["seconds"]["detection"],
                       "partition": info["seconds"]["partition"], "reconstruction": rec["seconds"]})
    row.update(evaluate(a.hsr, os.path.join(d, "points.ply"), off, os.path.join(d, "truth.obj")))
    return row


def run_ksr(a, d, lock):
    """KSR twice: the scan's normals as given (pointing at the scanners: KSR then builds the furniture as the
    solid) and reversed (KSR builds the room's air, the truth's solid); the one closer to the truth counts."""
    if not a.ksr or not os.access(a.ksr, os.X_OK):
        return {"status": "not run (no KSR driver: --ksr PATH or $HSR_KSR)"}
    runs = [run_ksr_once(a, d, lock, flip) for flip in (False, True)]
    ok = [r for r in runs if r.get("status") == "ok" and "truth_to_mesh_pct" in r]
    best = dict(min(ok, key=lambda r: r["truth_to_mesh_pct"]) if ok else runs[0])
    best["other"] = {k: v for k, v in (runs[1] if best["normals"] == "as given" else runs[0]).items()
                     if k in ("normals", "status", "valid", "faces", "regions", "truth_to_mesh_pct", "wall_s", "peak_mb")}
    return best


def fit_exponent(xs, ys):
    """Least-squares slope of log y against log x (None with fewer than 2 usable points)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x and y and x > 0 and y > 0]
    if len(pts) < 2:
        return None
    mx, my = sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


def f(x, fmt="%.3g"):
    return "" if x is None else (fmt % x)


def yes(ok):
    return "**met**" if ok else "**not met**"


def report(a, rows, sweep_rows, commit):
    L = ["# Indoor scenes: the synth hall beside KSR (issue 25)", "",
         f"- Date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; machine: {platform.machine()}, "
         f"{os.cpu_count()} cores, {os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES') / 2**30:.0f} GiB, shared "
         f"(load average at each timed run in the tables); hsr commit {commit}",
         f"- Command: `{a.command}`",
         "- hsr: `hsr reconstruct points.ply -o hsr.obj` with default options" +
         (f" plus `{a.hsr_extra}`" if a.hsr_extra else "") + "; KSR: CGAL 6.1.1 Kinetic_surface_reconstruction_3 "
         f"through a driver built outside this repository: its default region growing with minimum region "
         f"{a.ksr_min_region} points, k = 1, λ = 0.5, all six bounding-box sides forced outside; run twice, with the "
         "scan's normals (they point at the scanners, so KSR's solid is the furniture) and with them reversed (its solid "
         "is then the room's air, the truth's); the run closer to the truth is the one in the tables (column `KSR normals`)",
         "- Accuracy by `hsr eval --truth truth.obj` for both (mean distances, % of the points' bbox diagonal); faces = "
         "output polygons; regions = `hsr eval`'s `regions`: per connected set of coplanar faces sharing edges, one plus "
         "one per hole, as the truth's `polygon_faces` of planes.json count its faces (a floor with n holes is n + 1 "
         "however it is cut into simple polygons), so the target compares regions; wall time and peak RSS of the whole "
         "process (os.wait4), each run alone under the machine's measurement lock", ""]
    L += ["## At about 500 and 1,000 planes (targets)", "",
          "| truth planes | points | method | valid | faces | regions (truth's) | truth → mesh % | mesh → truth % | wall s | peak MB | load |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    checks = []
    for r in rows:
        for m in ("hsr", "ksr"):
            x = r[m]
            label = m if m == "hsr" else f"KSR (normals {x.get('normals', '')})"
            if x.get("status") != "ok":
                L.append(f"| {r['truth_planes']} | {r['points']} | {label} | {x.get('status', '')} | | | | | "
                         f"{f(x.get('wall_s'), '%.1f')} | {f(x.get('peak_mb'), '%.0f')} | {f(x.get('load'), '%.1f')} |")
                continue
            L.append(f"| {r['truth_planes']} | {r['points']} | {label} | {'yes' if x['valid'] else 'no'} | {x['faces']} | "
                     f"{x.get('regions')} ({r['truth_faces']}) | {x['truth_to_mesh_pct']:.4f} | {x['mesh_to_truth_pct']:.4f} | "
                     f"{x['wall_s']:.1f} | {x['peak_mb']:.0f} | {x['load']:.1f} |")
        h, k = r["hsr"], r["ksr"]
        if h.get("status") == "ok":
            c = [f"valid {yes(h['valid'])}",
                 f"regions {h['regions']} vs {r['truth_faces']} ({100 * (h['regions'] / r['truth_faces'] - 1):+.1f} %, within 5 %: "
                 f"{yes(abs(h['regions'] / r['truth_faces'] - 1) <= TARGET['faces_within'])}; {h['faces']} polygons)",
                 f"truth → mesh {h['truth_to_mesh_pct']:.4f} % (<= 0.03 %: {yes(h['truth_to_mesh_pct'] <= TARGET['truth_to_mesh_pct'])})"]
            if k.get("wall_s") and k.get("status") == "ok":
                c += [f"wall {h['wall_s'] / k['wall_s']:.2f}x KSR's (<= 0.5: {yes(h['wall_s'] <= TARGET['wall_ratio'] * k['wall_s'])})",
                      f"peak memory {h['peak_mb'] / k['peak_mb']:.2f}x KSR's (<= 1: {yes(h['peak_mb'] <= k['peak_mb'])})"]
            checks.append(f"- {r['truth_planes']} planes: " + "; ".join(c))
        else:
            checks.append(f"- {r['truth_planes']} planes: hsr {h.get('status')}")
    L += [""] + checks + [""]
    L += ["Per-stage seconds (hsr: report `seconds`; KSR: the driver's steps):", "",
          "| truth planes | method | stages |", "|---|---|---|"]
    for r in rows + [s for s in sweep_rows if s not in rows]:
        for m in ("hsr", "ksr"):
            st = r[m].get("stages")
            if st:
                L.append(f"| {r['truth_planes']} | {m} | " + ", ".join(f"{k} {v:.2f}" for k, v in st.items() if k != "total") + " |")
    L += ["", "## Time and memory against the plane count", "",
          "| truth planes | points | hsr valid | hsr faces | hsr regions (truth's) | hsr truth → mesh % | hsr wall s | hsr peak MB | hsr cells | "
          "KSR wall s | KSR peak MB | KSR truth → mesh % | load |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in sweep_rows:
        h, k = r["hsr"], r["ksr"]
        L.append(f"| {r['truth_planes']} | {r['points']} | {('yes' if h.get('valid') else 'no') if h.get('status') == 'ok' else h.get('status')} | "
                 f"{h.get('faces', '')} | {h.get('regions', '')} ({r['truth_faces']}) | {f(h.get('truth_to_mesh_pct'), '%.4f')} | {f(h.get('wall_s'), '%.1f')} | "
                 f"{f(h.get('peak_mb'), '%.0f')} | {h.get('cells', '')} | {f(k.get('wall_s'), '%.1f') if k.get('status') == 'ok' else k.get('status', '')} | "
                 f"{f(k.get('peak_mb'), '%.0f')} | {f(k.get('truth_to_mesh_pct'), '%.4f')} | {f(h.get('load'), '%.1f')} |")
    ok = [r for r in sweep_rows if r["hsr"].get("status") == "ok"]
    xs = [r["truth_planes"] for r in ok]
    L.append("")
    for m, label in (("hsr", "hsr"), ("ksr", "KSR")):
        okm = [r for r in sweep_rows if r[m].get("status") == "ok"]
        et = fit_exponent([r["truth_planes"] for r in okm], [r[m]["wall_s"] for r in okm])
        em = fit_exponent([r["truth_planes"] for r in okm], [r[m]["peak_mb"] for r in okm])
        if et is not None:
            goal = f" (goal < 1.5: {yes(et < TARGET['exponent'])})" if m == "hsr" else ""
            L.append(f"- {label}: wall time ∝ planes^{et:.2f}{goal}, peak memory ∝ planes^{em:.2f} "
                     f"({len(okm)} sizes, {min(r['truth_planes'] for r in okm)}–{max(r['truth_planes'] for r in okm)} planes)")
    if ok:
        for stage in ("structure", "visibility", "partition", "extraction"):
            ys = [r["hsr"]["stages"].get(stage) for r in ok]
            e = fit_exponent(xs, ys)
            if e is not None:
                L.append(f"- hsr {stage}: seconds ∝ planes^{e:.2f}")
    L.append("")
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hsr", default=os.path.join(ROOT, "build", "hsr"))
    ap.add_argument("--ksr", default=os.environ.get("HSR_KSR", ""), help="the KSR driver (default $HSR_KSR)")
    ap.add_argument("--ksr-min-region", type=int, default=40)
    ap.add_argument("--lock", default=os.environ.get("HSR_HEAVY_LOCK", ""), help="lock file held by each timed run")
    ap.add_argument("--planes", type=int, nargs="*", default=[500, 1000], help="the checked cases")
    ap.add_argument("--sweep", type=int, nargs="*", default=[100, 250, 500, 1000, 2000])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--hsr-extra", default="", help="more reconstruct options (default none: the defaults)")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "bench-indoor"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "indoor.md"))
    ap.add_argument("--csv", default=os.path.join(ROOT, "bench", "results", "indoor.csv"))
    ap.add_argument("--png", default="", help="folder for cutaway pictures of the checked cases' meshes (hsr, KSR, truth)")
    a = ap.parse_args()
    a.command = "/usr/bin/python3 bench/indoor/run.py " + " ".join(sys.argv[1:])
    if not a.ksr or not os.access(a.ksr, os.X_OK):
        print(f"indoor bench: no KSR driver ({a.ksr or 'give --ksr PATH or set HSR_KSR'}): KSR is not run", file=sys.stderr)
    os.makedirs(a.work, exist_ok=True)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    done = {}
    for n in sorted(set(a.planes) | set(a.sweep)):
        d, truth = make_hall(a.hsr, n, a.seed, a.work)
        row = {"planes_asked": n, "truth_planes": len(truth["planes"]), "truth_faces": truth["polygon_faces"],
               "points": truth["points"], "blocks": len(truth.get("blocks", []))}
        row["hsr"] = run_hsr(a, d, a.lock)
        row["ksr"] = run_ksr(a, d, a.lock)
        done[n] = row
        h, k = row["hsr"], row["ksr"]
        print(f"hall {n}: {row['truth_planes']} planes, hsr {h.get('status')} {f(h.get('wall_s'), '%.1f')} s "
              f"{f(h.get('peak_mb'), '%.0f')} MB faces {h.get('faces')} t2m {f(h.get('truth_to_mesh_pct'), '%.4f')}; "
              f"KSR {k.get('status')} {f(k.get('wall_s'), '%.1f')} s {f(k.get('peak_mb'), '%.0f')} MB "
              f"t2m {f(k.get('truth_to_mesh_pct'), '%.4f')}", flush=True)
        if a.png and n in a.planes:
            os.makedirs(a.png, exist_ok=True)
            for m, mesh in (("hsr", os.path.join(d, "hsr.obj")), ("ksr", row["ksr"].get("mesh", "")),
                            ("truth", os.path.join(d, "truth.obj"))):
                if mesh and os.path.exists(mesh):
                    subprocess.run([a.hsr, "-q", "render", mesh, "-o", os.path.join(a.png, f"indoor_hall_{n}_{m}.png"),
                                    "--view", "cutaway", "--width", "960", "--height", "640"])
    rows = [done[n] for n in a.planes]
    sweep_rows = [done[n] for n in sorted(a.sweep)]
    text = report(a, rows, sweep_rows, commit)
    for path, content in ((a.out, text),):
        tmp = path + ".tmp"
        open(tmp, "w").write(content)
        os.replace(tmp, path)
    fields = ["planes_asked", "truth_planes", "truth_faces", "points", "method", "status", "valid", "faces", "regions",
              "truth_to_mesh_pct", "mesh_to_truth_pct", "p2m_pct", "wall_s", "peak_mb", "load", "planes", "cells", "stages"]
    tmp = a.csv + ".tmp"
    with open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for n in sorted(done):
            for m in ("hsr", "ksr"):
                x = dict(done[n][m])
                x.update({k: done[n][k] for k in ("planes_asked", "truth_planes", "truth_faces", "points")}, method=m)
                if "stages" in x:
                    x["stages"] = json.dumps({k: round(v, 3) for k, v in x["stages"].items()})
                w.writerow(x)
    os.replace(tmp, a.csv)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
