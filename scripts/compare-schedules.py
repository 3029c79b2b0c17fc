#!/usr/bin/env python3
"""Compares two sunlit CSVs (EnergyPlus's shading layout) step by step: how many steps are dark
(0) in one and lit in the other, the largest per-surface mean |d| over steps either calls lit,
and the overall mean. Usage: compare-schedules.py A.csv B.csv [N] (N: list the first N
disagreements). Standard library only."""
import csv, sys
def load(p):
    with open(p) as f:
        r = csv.reader(f); h = [x for x in next(r) if x]; rows = [list(map(float, x[1:len(h)])) for x in r]
    return h[1:], rows
na, a = load(sys.argv[1]); nb, b = load(sys.argv[2])
assert na == nb
ncol = len(na); dis = []; worst = 0; worstname = None
sums = [0.0]*ncol; cnt = [0]*ncol
for i, (ra, rb) in enumerate(zip(a, b)):
    for c in range(ncol):
        x, y = ra[c], rb[c]
        if (x > 0) != (y > 0): dis.append((i, na[c], x, y))
        if x > 0 or y > 0:
            sums[c] += abs(x - y); cnt[c] += 1
means = [s / max(n, 1) for s, n in zip(sums, cnt)]
m = max(range(ncol), key=lambda c: means[c])
tot = sum(sums) / max(sum(cnt), 1)
print(f"disagreements {len(dis)}; largest per-surface mean |d| {means[m]:.4f} ({na[m]}); overall mean {tot:.5f}")
if len(sys.argv) > 3:
    for d in dis[:int(sys.argv[3])]:
        i = d[0]; day = i // 96 + 1; hr = (i % 96 + 1) / 4
        print(f"row {i} day {day} {hr:.2f}h {d[1]} a={d[2]} b={d[3]}")
