#!/usr/bin/python3
"""Distributions of airborne.py's CSVs (issue 42's Must show): per variant and group, hsr's and City3D's p2m
over the same buildings (median, and on how many hsr's is lower), City3D → hsr on hsr's own ground and on
City3D's ground (quartiles, 90th percentile, max, share above 3 %), the unexplained share (median, 90th
percentile, max, count above the 5 % warning), and the worst five of each with their figures.

    /usr/bin/python3 bench/building/distributions.py shared.csv sub50.csv rot.csv noise.csv [--names shared,sub50,rot,noise]
"""
import argparse, csv, os, re, statistics

GROUPS = [("AHN3", ("AHN3",)), ("DALES", ("Dales3d",)), ("Vaihingen", ("Vaihingen",)),
          ("AHN3 + Vaihingen", ("AHN3", "Vaihingen")), ("all", ("AHN3", "Dales3d", "Vaihingen"))]


def num(r, k):
    try:
        return float(r[k])
    except (KeyError, TypeError, ValueError):
        return None


def q(xs, p):
    """The p-quantile (0..1) by linear interpolation between order statistics."""
    xs = sorted(xs)
    if not xs:
        return None
    t = p * (len(xs) - 1)
    i = int(t)
    return xs[i] if i + 1 >= len(xs) else xs[i] + (t - i) * (xs[i + 1] - xs[i])


def f(x, d=2):
    return "" if x is None else f"{x:.{d}f}"


def table(name, rows):
    out = [f"### {name}", "",
           "| group | models / n | p2m median hsr / City3D (same buildings) | hsr lower on | City3D → hsr own ground: q25, median, q75, q90, max | above 3 % | "
           "on City3D's ground: median, q90, max | above 3 % | unexplained %: median, q90, max | above 5 % |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for label, prefixes in GROUPS:
        rs = [r for r in rows if r["input"].startswith(prefixes)]
        ok = [r for r in rs if num(r, "p2m") is not None]
        if not rs:
            continue
        h, c = [num(r, "p2m") for r in ok], [num(r, "city3d_p2m") for r in ok]
        lower = sum(a < b for a, b in zip(h, c))
        own = [num(r, "city3d_to_hsr") for r in ok]
        at = [x for x in (num(r, "city3d_to_hsr_at_city3d_ground") for r in ok) if x is not None]
        un = [x for x in (num(r, "unexplained") for r in ok) if x is not None]
        worse = " (worse)" if h and statistics.median(h) > statistics.median(c) else ""
        out.append(f"| {label} | {len(ok)} / {len(rs)} | {f(statistics.median(h))} / {f(statistics.median(c))}{worse} | "
                   f"{lower} | {', '.join(f(q(own, p)) for p in (0.25, 0.5, 0.75, 0.9, 1.0))} | "
                   f"{sum(x > 3 for x in own) + len(rs) - len(ok)} | {', '.join(f(q(at, p)) for p in (0.5, 0.9, 1.0))} | "
                   f"{sum(x > 3 for x in at)} | {', '.join(f(q(un, p), 1) for p in (0.5, 0.9, 1.0))} | {sum(x > 5 for x in un)} |")
    ok = [r for r in rows if num(r, "p2m") is not None]
    worst = lambda key, k=5: sorted((r for r in ok if key(r) is not None), key=lambda r: -key(r))[:k]
    out += ["", "Worst five, City3D → hsr on City3D's ground: " + ", ".join(
                f"{r['input']} {num(r, 'city3d_to_hsr_at_city3d_ground'):.2f} %" for r in worst(lambda r: num(r, "city3d_to_hsr_at_city3d_ground"))),
            "", "Worst five, unexplained share: " + ", ".join(
                f"{r['input']} {num(r, 'unexplained'):.1f} %" for r in worst(lambda r: num(r, "unexplained"))),
            "", "Worst five, p2m over City3D's: " + ", ".join(
                f"{r['input']} {num(r, 'p2m'):.2f} / {num(r, 'city3d_p2m'):.2f} %" for r in worst(lambda r: num(r, "p2m") - num(r, "city3d_p2m"))),
            ""]
    failed = [r for r in rows if num(r, "p2m") is None]
    if failed:
        why = lambda e: re.sub(r" in \S+?: ", ": ", e or "").split(" (try")[0]  # the message without the path and the advice
        out += ["No model: " + ", ".join(f"{r['input']} ({r['points']} points; {why(r.get('error'))})" for r in failed), ""]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--names", help="comma-separated names of the CSVs (default: their file names)")
    a = ap.parse_args()
    names = a.names.split(",") if a.names else [os.path.basename(p)[:-4] for p in a.csv]
    out = []
    for name, path in zip(names, a.csv):
        out += table(name, list(csv.DictReader(open(path))))
    print("\n".join(out))


if __name__ == "__main__":
    main()
