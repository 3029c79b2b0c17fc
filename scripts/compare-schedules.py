#!/usr/bin/env python3
"""Compares two sunlit CSVs (EnergyPlus's shading layout) step by step: how many steps are dark
(0) in one and lit in the other, the largest per-surface mean |d| over steps either calls lit,
and the overall mean. Usage: compare-schedules.py A.csv B.csv [N] [--before OLD.csv] (N: list
the first N disagreements; --before: also compare OLD.csv against B.csv and count the surfaces
whose mean |d| A made worse or better than OLD's, B being the truth, e.g. a --dense year).
Standard library only."""
import csv, sys

def load(p):
    with open(p) as f:
        r = csv.reader(f); h = [x for x in next(r) if x]; rows = [list(map(float, x[1:len(h)])) for x in r]
    return h[1:], rows

def against(a, b, ncol):
    """Per surface: mean |d| over steps either calls lit; the disagreements; the overall mean."""
    dis = []; sums = [0.0]*ncol; cnt = [0]*ncol
    for i, (ra, rb) in enumerate(zip(a, b)):
        for c in range(ncol):
            x, y = ra[c], rb[c]
            if (x > 0) != (y > 0): dis.append((i, c, x, y))
            if x > 0 or y > 0:
                sums[c] += abs(x - y); cnt[c] += 1
    return [s / max(n, 1) for s, n in zip(sums, cnt)], dis, sum(sums) / max(sum(cnt), 1)

args = sys.argv[1:]
before = None
if '--before' in args:
    i = args.index('--before')
    if i + 1 >= len(args): sys.exit("compare-schedules.py: --before needs the earlier CSV after it")
    before = args[i + 1]; del args[i:i + 2]
if len(args) < 2: sys.exit("usage: compare-schedules.py A.csv B.csv [N] [--before OLD.csv]")
na, a = load(args[0]); nb, b = load(args[1])
assert na == nb
ncol = len(na)
means, dis, tot = against(a, b, ncol)
m = max(range(ncol), key=lambda c: means[c])
print(f"disagreements {len(dis)}; largest per-surface mean |d| {means[m]:.4f} ({na[m]}); overall mean {tot:.5f}")
if before:
    no, o = load(before)
    assert no == nb
    old, old_dis, _ = against(o, b, ncol)
    worse = sum(1 for c in range(ncol) if means[c] > old[c] + 1e-12)
    better = sum(1 for c in range(ncol) if means[c] < old[c] - 1e-12)
    k = max(range(ncol), key=lambda c: old[c])
    print(f"before: disagreements {len(old_dis)}; largest per-surface mean |d| {old[k]:.5f} ({na[k]}); "
          f"now {means[m]:.5f}; surfaces worse {worse}, better {better}, same {ncol - worse - better}")
if len(args) > 2:
    for i, c, x, y in dis[:int(args[2])]:
        day = i // 96 + 1; hr = (i % 96 + 1) / 4
        print(f"row {i} day {day} {hr:.2f}h {na[c]} a={x} b={y}")
