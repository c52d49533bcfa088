#!/usr/bin/python3
"""Where the memory of `hsr city` / `hsr batch` is, process by process (DECISIONS #244).

    /usr/bin/python3 bench/city/process_roles.py OUT.json -- hsr city TILE --footprints F --id-field id -j 1 -q -o O.jsonl

Runs the command and samples every 50 ms (as tile_bench.py's "all processes" figure) each process of its tree by
role: driver (the command), launcher (its child), monitor (a child of the launcher: a slot's), worker (a monitor's
child), other; with smaps_rollup's Rss, Pss, Pss_Anon, Pss_File and the thread count. Prints the peak of the summed
Pss and each process at that sample, each role's largest summed Pss and each process's largest; OUT.json keeps
every sample."""
import os, sys, time, json, subprocess, threading
out = sys.argv[1]; cmd = sys.argv[sys.argv.index('--')+1:]
def ppid_map():
    ch = {}
    for d in os.listdir('/proc'):
        if d.isdigit():
            try:
                with open('/proc/%s/stat' % d) as f: pp = int(f.read().rsplit(')',1)[1].split()[1])
                ch.setdefault(pp, []).append(int(d))
            except Exception: pass
    return ch
def roll(pid):
    r = {}
    try:
        with open('/proc/%d/smaps_rollup' % pid) as f:
            for l in f:
                p = l.split()
                if p[0] in ('Rss:','Pss:','Pss_Anon:','Pss_File:','Anonymous:','Private_Dirty:'): r[p[0][:-1]] = int(p[1])
        with open('/proc/%d/status' % pid) as f:
            for l in f:
                if l.startswith('Threads:'): r['thr'] = int(l.split()[1])
    except Exception: return None
    return r
p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL)
t0 = time.monotonic(); samples = []
done = threading.Event()
def sample():
    while not done.wait(0.05):
        ch = ppid_map(); s = {'t': time.monotonic()-t0, 'p': []}
        drv = p.pid
        def add(pid, role):
            r = roll(pid)
            if r: r['role'] = role; r['pid'] = pid; s['p'].append(r)
        add(drv, 'driver')
        for L in ch.get(drv, []):
            add(L, 'launcher')
            for S in ch.get(L, []):
                kids = ch.get(S, [])
                add(S, 'monitor')
                for W in kids:
                    add(W, 'worker')
                    for x in ch.get(W, []): add(x, 'other')
        samples.append(s)
th = threading.Thread(target=sample); th.start()
p.wait(); done.set(); th.join()
wall = time.monotonic()-t0
json.dump(samples, open(out, 'w'))
def tot(s, k='Pss'): return sum(x.get(k,0) for x in s['p'])
pk = max(samples, key=tot)
print('wall %.2f s  peak summed Pss %.1f MB at t=%.2f' % (wall, tot(pk)/1024, pk['t']))
for x in sorted(pk['p'], key=lambda x: x['role']):
    print('  %-8s pid %d Rss %.1f Pss %.1f Pss_Anon %.1f Pss_File %.1f thr %s' % (x['role'], x['pid'], x['Rss']/1024, x['Pss']/1024, x.get('Pss_Anon',0)/1024, x.get('Pss_File',0)/1024, x.get('thr')))
roles = {}
for s in samples:
    agg = {}
    for x in s['p']: agg[x['role']] = agg.get(x['role'],0)+x['Pss']
    for k,v in agg.items(): roles[k] = max(roles.get(k,0), v)
print('  role max summed Pss MB:', {k: round(v/1024,1) for k,v in roles.items()})
mx = {}
for s in samples:
    for x in s['p']: mx[x['pid']] = max(mx.get(x['pid'],(0,''))[0], x['Pss']), x['role']
print('  per pid max Pss MB:', sorted([(r, round(v/1024,1)) for pid,(v,r) in mx.items()]))
