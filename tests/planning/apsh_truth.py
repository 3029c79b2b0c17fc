"""Independent truth for `sunlit map --study bre-apsh`: a numpy ray caster over an EPW's hours.

Reads the EPW itself (field 15, direct normal irradiance), takes the hours with DNI >= 120 W/m2
and the sun up at mid-hour (local standard time HH - 0.5 for the record stamped HH), places the
sun by Spencer's (1971) declination and equation of time (not EnergyPlus's SUN3, which sunlit
uses), and casts a ray from each point towards each such sun against axis-aligned boxes (slab
test). Prints JSON: annual and winter (21 Sep - 21 Mar) probable hours and, per point, APSH and
WPSH in % of the annual probable hours.

usage: apsh_truth.py EPW CASE.json   (CASE: {"points": [[x,y,z,nx,ny,nz]...], "boxes": [[lo, hi]...]})
"""
import json
import sys

import numpy as np

epw, case = sys.argv[1], json.load(open(sys.argv[2]))
lines = open(epw).read().splitlines()
head = lines[0].split(",")
lat, lon, tz = float(head[6]), float(head[7]), float(head[8])
rows = [l.split(",") for l in lines[8:] if l.strip()]
dni = np.array([float(r[14]) for r in rows])
month = np.array([int(r[1]) for r in rows])
dom = np.array([int(r[2]) for r in rows])
stamp = np.array([int(r[3]) for r in rows])
starts = np.cumsum([0, 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30])
day = starts[month - 1] + dom
hour = stamp - 0.5

g = 2 * np.pi * (day - 1 + (hour - 12) / 24) / 365
decl = (0.006918 - 0.399912 * np.cos(g) + 0.070257 * np.sin(g) - 0.006758 * np.cos(2 * g)
        + 0.000907 * np.sin(2 * g) - 0.002697 * np.cos(3 * g) + 0.00148 * np.sin(3 * g))
eot = 229.18 * (0.000075 + 0.001868 * np.cos(g) - 0.032077 * np.sin(g) - 0.014615 * np.cos(2 * g) - 0.040849 * np.sin(2 * g))
tst = hour + eot / 60 + (lon - 15 * tz) / 15
h = np.radians(15 * (tst - 12))
phi = np.radians(lat)
sun = np.stack([-np.cos(decl) * np.sin(h),
                np.cos(phi) * np.sin(decl) - np.sin(phi) * np.cos(decl) * np.cos(h),
                np.sin(phi) * np.sin(decl) + np.cos(phi) * np.cos(decl) * np.cos(h)], axis=1)
sunny = (dni >= 120) & (sun[:, 2] > 0)
winter = (day >= 264) | (day <= 80)
s = sun[sunny]
w = winter[sunny]
total = len(s)


def blocked(p, d, lo, hi):
    """Whether rays p + t d (t > 0, one per row of d) meet the box [lo, hi]."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - p) / d
        t2 = (hi - p) / d
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    return (far >= np.maximum(near, 0)) & (far > 0)


out = []
for x, y, z, nx, ny, nz in case["points"]:
    n = np.array([nx, ny, nz])
    p = np.array([x, y, z]) + 1e-3 * n
    lit = s @ n > 0
    for lo, hi in case["boxes"]:
        lit &= ~blocked(p, s, np.array(lo, float), np.array(hi, float))
    out.append({"apsh": 100 * lit.sum() / total, "wpsh": 100 * (lit & w).sum() / total})
print(json.dumps({"annual_hours": int(total), "winter_hours": int(w.sum()), "points": out}))
