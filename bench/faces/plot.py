#!/usr/bin/python3
"""Facets against mean p2m per input group (issue 14): hsr at each --detail level (one line per group's
median), PolyFit and Poisson+QEM (bench/results/results.csv) and KSR (../shared/ANCHORS.md), one panel per
group (buildings, CAD, indoor, airborne buildings). Needs Debian's python3-matplotlib (scripts/install-deps.sh installs it).

    /usr/bin/python3 bench/faces/plot.py [--csv bench/results/faces.csv] [-o docs/images/faces_tradeoff.png]
"""
import argparse, csv, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import ksr_usable, med, read_anchors, read_ksr_lambdas, read_peers  # noqa: E402  (the table's readers)

import matplotlib  # noqa: E402
matplotlib.use("Agg")  # no display: write the file only
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

GROUPS = [("building", "buildings"), ("cad", "CAD parts"), ("indoor", "indoor"), ("airborne", "airborne buildings")]


def hsr_curve(rows, settings, inputs):
    """hsr's (median p2m, median facets) over the given inputs at each detail setting."""
    xs, ys = [], []
    for s in settings:
        rs = [r for r in rows if r["input"] in inputs and r["setting"] == s]
        xs.append(med([float(r["p2m_pct"]) for r in rs]))
        ys.append(med([int(r["facets"]) for r in rs]))
    return xs, ys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--csv", default="bench/results/faces.csv")
    ap.add_argument("--anchors", default=os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "ANCHORS.md"))
    ap.add_argument("--peers", default="bench/results/results.csv")
    ap.add_argument("--ksr-csv", default="bench/results/faces_ksr.csv",
                    help="KSR at several λ (bench/faces/ksr.py); when present it replaces ANCHORS.md's single points")
    ap.add_argument("-o", "--out", default="docs/images/faces_tradeoff.png")
    a = ap.parse_args()
    ksr_l = read_ksr_lambdas(a.ksr_csv)
    rows = [r for r in csv.DictReader(open(a.csv)) if r["status"] == "ok"]
    ksr, peers = read_anchors(a.anchors), read_peers(a.peers)
    settings = list(dict.fromkeys(r["setting"] for r in rows))
    groups = [g for g in GROUPS if any(r["kind"] == g[0] for r in rows)]
    fig, axes = plt.subplots(1, len(groups), figsize=(4.4 * len(groups), 4.2))
    for ax, (g, title) in zip(axes, groups):
        inputs = sorted({r["input"] for r in rows if r["kind"] == g})
        ksr_valid = [i for i in inputs if i in ksr and ksr[i][0]]
        xs, ys = hsr_curve(rows, settings, inputs)
        ax.plot(xs, ys, "o-", color="tab:blue", label="hsr, all %d (--detail %s)" % (len(inputs), " → ".join(settings)))
        for x, y, s in zip(xs, ys, settings):
            ax.annotate(s, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        if not ksr_l and ksr_valid and len(ksr_valid) < len(inputs):  # like for like with KSR: the same inputs
            xs, ys = hsr_curve(rows, settings, ksr_valid)
            ax.plot(xs, ys, "o--", color="tab:cyan", mfc="none", label="hsr on KSR's %d valid" % len(ksr_valid))
        for m, colour, label in (("polyfit", "tab:green", "PolyFit"), ("poisson_qem", "tab:orange", "Poisson+QEM")):
            vs = [peers[(i, m)] for i in inputs if (i, m) in peers]
            if vs:
                ax.plot([med([v[2] for v in vs])], [med([v[1] for v in vs])], "s", color=colour,
                        label="%s (%d of %d inputs)" % (label, len(vs), len(inputs)))
        lams = sorted({k[1] for k in ksr_l})
        pts = [(l, ksr_usable(ksr_l, inputs, l)) for l in lams]
        pts = [(l, keep) for l, keep in pts if keep]
        if pts:  # KSR's λ curve (each point over its usable outputs), and hsr's on KSR's usable inputs at λ 0.5
            kx = [med([ksr_l[(i, l)][2] for i in keep]) for l, keep in pts]
            ky = [med([ksr_l[(i, l)][1] for i in keep]) for l, keep in pts]
            ax.plot(kx, ky, "^-", color="tab:red", label="KSR λ %s (no box outputs)" % " → ".join("%g" % l for l, _ in pts))
            for x, y, (l, keep) in zip(kx, ky, pts):
                ax.annotate("λ %g: %d" % (l, len(keep)), (x, y), textcoords="offset points", xytext=(4, -9),
                            fontsize=7, color="tab:red")
            keep = dict(pts).get(0.5, [])
            if keep and len(keep) < len(inputs):
                xs, ys = hsr_curve(rows, settings, keep)
                ax.plot(xs, ys, "s--", color="tab:purple", mfc="none", label="hsr on KSR's %d usable at λ 0.5" % len(keep))
        ks = [ksr[i] for i in inputs if i in ksr and ksr[i][0]]
        if ks and not ksr_l:
            ax.plot([med([k[2] for k in ks])], [med([k[1] for k in ks])], "^", color="tab:red",
                    label="KSR, valid (%d of %d inputs)" % (len(ks), len(inputs)))
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title("%s (%d inputs)" % (title, len(inputs)))
        ax.set_xlabel("median p2m, % of the bbox diagonal (log)")
        ax.set_ylabel("median facets")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Facets against accuracy on the shared scans and the airborne buildings (bench/results/faces.csv; medians per group)", fontsize=10)
    fig.tight_layout()
    tmp = a.out + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, a.out)
    print("plot:", a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
