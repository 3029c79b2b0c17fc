"""Per receiver: the area mean of a `sunlit map` grid's sun hours against the exact engine's
surface sun hours (Σ sunlit fraction × hours from `sunlit annual --dense --engine exact
--timesteps-per-hour 1`). Prints the largest and mean relative differences over receivers with
sun, as JSON.

    python3 scripts/compare_map_exact.py POINTS.csv ANNUAL.csv
"""
import csv
import json
import sys
from collections import defaultdict

points, annual = sys.argv[1], sys.argv[2]
sums, counts = defaultdict(float), defaultdict(int)
for r in csv.DictReader(open(points)):
    sums[r["receiver"]] += float(r["sun_hours"])
    counts[r["receiver"]] += 1
rows = list(csv.reader(open(annual)))
names = [n.strip() for n in rows[0][1:]]
exact = defaultdict(float)
for row in rows[1:]:
    for name, v in zip(names, row[1:]):
        if name and v.strip():
            exact[name] += float(v)
diffs = {}
for name, hours in exact.items():
    if counts.get(name) and hours > 10:
        diffs[name] = (sums[name] / counts[name] - hours) / hours
worst = max(diffs, key=lambda k: abs(diffs[k]))
print(json.dumps({
    "receivers": len(diffs),
    "mean_abs_relative_diff": round(sum(abs(d) for d in diffs.values()) / len(diffs), 5),
    "max_abs_relative_diff": round(abs(diffs[worst]), 5),
    "worst": worst,
}))
