#!/usr/bin/python3
"""compare_shared.py BEFORE AFTER [--md OUT.md] — the before/after table of bench/scale/shared.sh runs.

One row per scan: planes, output facets and p2m (mean point-to-mesh distance, % of the bbox diagonal)
before and after, and whether the output mesh files are byte-identical.
"""
import csv, os, sys


def load(d):
    with open(os.path.join(d, "summary.tsv")) as f:
        return {r["file"]: r for r in csv.DictReader(f, delimiter="\t")}


def same_bytes(a, b):
    try:
        with open(a, "rb") as fa, open(b, "rb") as fb:
            return fa.read() == fb.read()
    except OSError:
        return False


def main():
    args = sys.argv[1:]
    out = None
    if "--md" in args:
        i = args.index("--md")
        out = args[i + 1]
        del args[i:i + 2]
    before, after = args
    b, a = load(before), load(after)
    lines = ["| scan | planes before | planes after | facets before | facets after | p2m % before | p2m % after |"
             " valid after | same bytes |", "|---|---|---|---|---|---|---|---|---|"]
    same = worse = 0
    for name in b:
        rb, ra = b[name], a.get(name, {})
        stem = os.path.splitext(name)[0]
        identical = same_bytes(os.path.join(before, stem + ".obj"), os.path.join(after, stem + ".obj"))
        same += identical
        try:
            if float(ra["p2m_pct"]) > float(rb["p2m_pct"]) + 1e-9 or ra["valid"] != "yes":
                worse += 1
        except (KeyError, ValueError):
            worse += 1
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            name, rb["planes"], ra.get("planes", "-"), rb["facets"], ra.get("facets", "-"), rb["p2m_pct"],
            ra.get("p2m_pct", "-"), ra.get("valid", "-"), "yes" if identical else "no"))
    lines.append("")
    lines.append("%d of %d outputs byte-identical; %d with a larger p2m or not valid." % (same, len(b), worse))
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if out:
        with open(out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
