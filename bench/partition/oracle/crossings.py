#!/usr/bin/python3
"""Oracle for issue 17: which polygons' events-B crossings does the accuracy need?

Not a rule hsr can use (it measures the p2m of every choice against the points); it bounds what any rule
that chooses *which polygons may cross non-adjacent polygons on the way to their bounds* can reach.

Needs the scratch hooks of crossings.patch (environment variables read by the partition and the bench;
never on main):
    git apply bench/partition/oracle/crossings.patch && make -C build bench_partition_scans
    /usr/bin/python3 bench/partition/oracle/crossings.py --mode single cgal_b9.ply synth_house ...
    git apply -R bench/partition/oracle/crossings.patch

Every run is `bench_partition_scans` with hierarchical + wait-at-bounds + trim and HSR_CROSS_ONLY = the
polygons (partition polygon indices, printed by HSR_POLY_LOG) allowed to cross; the others stop at every
collision. Modes, per input:
  single    each polygon alone allowed; then every polygon whose single run lowered p2m by > 0.002 together
  forward   greedy: add the polygon that lowers p2m most, while it lowers it by > 0.003 (at most 6)
  backward  from "all may cross": drop every polygon whose removal alone raises p2m by <= 0.001 and saves
            cells (if the batch raises p2m by more than 0.002, drop only the best one); up to 4 rounds
Prints, per input, (cells, mean p2m % of the bbox diagonal) for all / none / the chosen set.

two_pass_rule.patch (apply it instead of crossings.patch, which it contains) adds the two-pass rule of
bench/results/partition_ablation.md ("A two-pass rule that does move off that curve"): HSR_RULE_D=TAU
HSR_RULE_D_MIN=M build/bench/partition/bench_partition_scans --data ../shared/data --synth all --variant
wt=hierarchical,wait-at-bounds=1,trim=1
"""
import argparse
import os
import re
import subprocess

VARIANT = ['--variant', 'wt=hierarchical,wait-at-bounds=1,trim=1']


def input_args(name, data):
    return ['--synth', name[len('synth_'):]] if name.startswith('synth_') else ['--data', data, '--files', name]


def run(bench, data, name, env):
    e = dict(os.environ)
    e.update(env)
    r = subprocess.run([bench] + input_args(name, data) + VARIANT, capture_output=True, text=True, env=e, check=True)
    last = r.stdout.strip().splitlines()[-1].split()
    return int(last[2]), float(last[6]), r.stderr


def allowed(ids):
    return {'HSR_CROSS_ONLY': ','.join(map(str, ids)) or '-1'}


def single(go, n):
    c0, p0 = go([])
    gains = [(i,) + tuple(a - b for a, b in zip(go([i]), (c0, p0))) for i in range(n)]
    good = [i for i, _, dp in gains if dp < -0.002]
    return good, go(good)


def forward(go, n):
    chosen, (c, p) = [], go([])
    for _ in range(6):
        trials = [(go(chosen + [i]), i) for i in range(n) if i not in chosen]
        if not trials:
            break
        (ci, pi), i = min(trials, key=lambda t: t[0][1])
        if pi - p > -0.003:
            break
        chosen, c, p = chosen + [i], ci, pi
    return chosen, (c, p)


def backward(go, n):
    keep = list(range(n))
    c, p = go(keep)
    for _ in range(4):
        effects = []
        for i in keep:
            ci, pi = go([j for j in keep if j != i])
            effects.append((pi - p, c - ci, i))
        cheap = [e for e in effects if e[0] <= 0.001 and e[1] > 0]
        if not cheap:
            break
        trial = [j for j in keep if j not in {e[2] for e in cheap}]
        ct, pt = go(trial)
        if pt - p > 0.002:
            best = min(cheap, key=lambda e: e[0] - 1e-4 * e[1])
            trial = [j for j in keep if j != best[2]]
            ct, pt = go(trial)
        keep, c, p = trial, ct, pt
    return keep, (c, p)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('inputs', nargs='+', help='file names in --data, or synth_<model>')
    ap.add_argument('--mode', choices=['single', 'forward', 'backward'], default='single')
    ap.add_argument('--bench', default='build/bench/partition/bench_partition_scans')
    ap.add_argument('--data', default='../shared/data')
    a = ap.parse_args()
    for name in a.inputs:
        _, _, log = run(a.bench, a.data, name, {'HSR_POLY_LOG': '1'})
        n = len(re.findall(r'^POLY ', log, re.M))
        go = lambda ids: run(a.bench, a.data, name, allowed(ids))[:2]  # noqa: E731
        every, none = go(list(range(n))), go([])
        chosen, res = {'single': single, 'forward': forward, 'backward': backward}[a.mode](go, n)
        print(f'{name}\tpolygons {n}\tall {every}\tnone {none}\t{a.mode} {chosen} {res}', flush=True)


if __name__ == '__main__':
    main()
