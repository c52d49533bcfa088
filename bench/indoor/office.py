#!/usr/bin/python3
"""Office bench (issue 41 item 2): `hsr synth office` at several seeds and room counts, reconstructed by hsr with
DEFAULT options beside KSR in the same run (as bench/indoor/run.py runs it; without a KSR driver its columns say
"not run"), with the pieces counted against the truth.

Per case: validity, output faces, truth -> mesh and mesh -> truth (mean, % of the diagonal, `hsr eval --truth`),
wall time and peak memory of the whole process, and the pieces present (`office_pieces`, built beside hsr in
build/bench/indoor: a piece is present when at least --share (0.8) of its seen truth surface, sampled every 2 cm,
lies within --within (0.05 m) of the model; its faces on planes without points are not asked for). Targets
(issue 41): valid, truth -> mesh <= 0.02 %, mesh -> truth <= 0.05 %, every partition, table and chair present,
wall <= 0.5 x KSR's, memory <= 1 x KSR's.

    /usr/bin/python3 bench/indoor/office.py [--ksr DRIVER] [--lock /tmp/heavy.lock] [--seeds 1 2 3]
        [--rooms 1 3 6] [--out bench/results/indoor_office.md] [--png docs/images/office]
"""
import argparse, json, os, platform, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
from run import run_hsr, run_ksr  # noqa: E402  (the indoor bench's runs: one implementation)

TARGET = {"truth_to_mesh_pct": 0.02, "mesh_to_truth_pct": 0.05, "wall_ratio": 0.5, "memory_ratio": 1.0}
KINDS = ["partition", "doorway", "table", "chair", "desk", "cabinet", "shelf", "pillar"]


def make_office(hsr, rooms, seed, work):
    d = os.path.join(work, f"office_r{rooms}_s{seed}")
    if not os.path.exists(os.path.join(d, "planes.json")):
        subprocess.run([hsr, "-q", "synth", "office", "--rooms", str(rooms), "--seed", str(seed), "-o", d], check=True)
    return d, json.load(open(os.path.join(d, "planes.json")))


def count_pieces(a, mesh, d):
    r = subprocess.run([a.pieces, mesh, d, "--within", str(a.within), "--share", str(a.share)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return {"error": r.stderr.strip()[-120:]}
    return json.loads(r.stdout)


def render(a, mesh, d, name):
    if not a.png:
        return
    os.makedirs(a.png, exist_ok=True)
    subprocess.run([a.hsr, "-q", "render", mesh, os.path.join(d, "points.ply"), "--view", "cutaway",
                    "-o", os.path.join(a.png, name + ".png")], capture_output=True)


def pieces_cell(p, kind):
    s = p.get("summary", {}).get(kind)
    return f"{s['present']}/{s['total']}" if s else ""


def report(a, rows, commit):
    L = ["# Indoor scenes: the synth office (issue 41)", "",
         f"- Date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; machine: {platform.machine()}, "
         f"{os.cpu_count()} cores, shared (load average at each timed run in the table); hsr commit {commit}",
         f"- Command: `{a.command}`",
         "- Scenes: `hsr synth office --rooms N --seed S` (defaults: 12 cm partitions with doorways, per room 2 tables on "
         "four legs, 4 chairs on one post, an L-shaped desk, a cabinet, an open shelf, a round pillar, all turned at "
         "random; 2 stations per room; 80 points/m²; 1 cm noise)",
         "- hsr: `hsr reconstruct points.ply -o hsr.obj`, default options" + (f" plus `{a.hsr_extra}`" if a.hsr_extra else "") +
         "; KSR as in bench/indoor/run.py (" + ("driver " + a.ksr if a.ksr and os.access(a.ksr, os.X_OK) else
                                               "**not run: no KSR driver on this machine**") + ")",
         "- Accuracy: `hsr eval --truth` (means, % of the points' bbox diagonal). Pieces present/total (`office_pieces`): a "
         f"piece is present when at least {a.share:.0%} of its seen truth surface (faces on planes with points, sampled "
         f"every 2 cm) lies within {a.within * 100:.0f} cm of the model; partitions are the slabs between rooms "
         "(both faces, doorway reveals and lintel)", ""]
    L += ["| rooms | seed | points | truth planes | method | valid | faces | truth → mesh % | mesh → truth % | wall s | peak MB | load | "
          + " | ".join(KINDS) + " |", "|" + "---|" * (12 + len(KINDS))]
    for r in rows:
        for m in ("hsr", "ksr"):
            x = r[m]
            if x.get("status") != "ok":
                L.append(f"| {r['rooms']} | {r['seed']} | {r['points']} | {r['planes']} | {m} | {x.get('status', '')} |" + " |" * (6 + len(KINDS)))
                continue
            p = x.get("pieces", {})
            L.append(f"| {r['rooms']} | {r['seed']} | {r['points']} | {r['planes']} | {m} | {'yes' if x['valid'] else 'no'} | "
                     f"{x['faces']} | {x['truth_to_mesh_pct']:.4f} | {x['mesh_to_truth_pct']:.4f} | {x['wall_s']:.1f} | "
                     f"{x['peak_mb']:.0f} | {x['load']:.1f} | " + " | ".join(pieces_cell(p, k) for k in KINDS) + " |")
    L += ["", "Targets (hsr):", ""]
    for r in rows:
        h = r["hsr"]
        if h.get("status") != "ok":
            L.append(f"- {r['rooms']} rooms, seed {r['seed']}: {h.get('status')}")
            continue
        s = h.get("pieces", {}).get("summary", {})
        missing = [f"{k} {s[k]['total'] - s[k]['present']}" for k in ("partition", "table", "chair") if k in s and s[k]["present"] < s[k]["total"]]
        L.append(f"- {r['rooms']} rooms, seed {r['seed']}: valid {'met' if h['valid'] else '**not met**'}; truth → mesh "
                 f"{h['truth_to_mesh_pct']:.4f} % ({'met' if h['truth_to_mesh_pct'] <= TARGET['truth_to_mesh_pct'] else '**not met**'}); "
                 f"mesh → truth {h['mesh_to_truth_pct']:.4f} % ({'met' if h['mesh_to_truth_pct'] <= TARGET['mesh_to_truth_pct'] else '**not met**'}); "
                 f"partitions, tables, chairs all present: {'met' if not missing else '**not met** (missing: ' + ', '.join(missing) + ')'}")
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hsr", default=os.path.join(ROOT, "build", "hsr"))
    ap.add_argument("--pieces", default=os.path.join(ROOT, "build", "bench", "indoor", "office_pieces"))
    ap.add_argument("--ksr", default=os.environ.get("HSR_KSR", ""), help="the KSR driver (default $HSR_KSR)")
    ap.add_argument("--ksr-min-region", type=int, default=40)
    ap.add_argument("--lock", default=os.environ.get("HSR_HEAVY_LOCK", ""), help="lock file held by each timed run")
    ap.add_argument("--seeds", type=int, nargs="*", default=[1, 2, 3])
    ap.add_argument("--rooms", type=int, nargs="*", default=[1, 3, 6])
    ap.add_argument("--within", type=float, default=0.05, help="metres: a truth sample this near the model is covered")
    ap.add_argument("--share", type=float, default=0.8, help="share of a piece's samples covered for it to be present")
    ap.add_argument("--hsr-extra", default="", help="more reconstruct options (default none: the defaults)")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--work", default=os.path.join(ROOT, "build", "bench-office"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "indoor_office.md"))
    ap.add_argument("--json", default="", help="also write the rows as JSON here")
    ap.add_argument("--png", default="", help="folder for cutaway pictures (hsr's mesh with the points, and the truth)")
    a = ap.parse_args()
    a.command = "/usr/bin/python3 bench/indoor/office.py " + " ".join(sys.argv[1:])
    os.makedirs(a.work, exist_ok=True)
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    rows = []
    for rooms in a.rooms:
        for seed in a.seeds:
            d, truth = make_office(a.hsr, rooms, seed, a.work)
            row = {"rooms": rooms, "seed": seed, "points": truth["points"], "planes": len(truth["planes"])}
            row["hsr"] = run_hsr(a, d, a.lock)
            if row["hsr"].get("status") == "ok":
                row["hsr"]["pieces"] = count_pieces(a, os.path.join(d, "hsr.obj"), d)
                render(a, os.path.join(d, "hsr.obj"), d, f"office_r{rooms}_s{seed}_hsr")
            row["ksr"] = run_ksr(a, d, a.lock)
            if row["ksr"].get("status") == "ok":
                row["ksr"]["pieces"] = count_pieces(a, row["ksr"]["mesh"], d)
            if seed == a.seeds[0]:
                render(a, os.path.join(d, "truth.obj"), d, f"office_r{rooms}_s{seed}_truth")
            rows.append(row)
            h = row["hsr"]
            print(f"rooms {rooms} seed {seed}: hsr {h.get('status')} t->m {h.get('truth_to_mesh_pct', float('nan')):.4f} % "
                  f"m->t {h.get('mesh_to_truth_pct', float('nan')):.4f} % {h.get('wall_s', 0):.1f} s "
                  f"{json.dumps(h.get('pieces', {}).get('summary', {}))}", flush=True)
    text = report(a, rows, commit)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    print(text)


if __name__ == "__main__":
    main()
