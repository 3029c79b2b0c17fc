"""Independent numpy ray caster for tests/inside.rs: a box room [0,W]x[0,D]x[0,H] with one
window in its south wall (y = 0) and an optional horizontal overhang outside it.

A point sees the sun when its ray towards the sun leaves the room through the window (the first
wall plane it meets, y = 0, within the window's rectangle) and then passes the overhang's plane
outside its rectangle. Nothing here comes from sunlit: only the geometry's numbers.

stdin: JSON {room: [W, D, H], window: [x0, x1, z0, z1], overhang: [x0, x1, depth, z] | null,
points: [[x, y, z]...], normal: [nx, ny, nz], suns: [[sx, sy, sz]...], lux: [...] | null,
vt: float}
stdout: JSON {lit: [[0|1 per point] per sun]} without lux; with lux (one per sun)
{hours_over: [per point hours with lux * vt * cos * lit > 1000]}.
"""
import json
import sys

import numpy as np


def lit(points, sun, window, overhang):
    """Per point: 1 when the ray towards `sun` leaves through the window and misses the overhang."""
    if sun[1] >= 0 or sun[2] <= 0:
        return np.zeros(len(points), dtype=bool)
    t = -points[:, 1] / sun[1]
    hit = points + t[:, None] * sun
    x0, x1, z0, z1 = window
    through = (hit[:, 0] >= x0) & (hit[:, 0] <= x1) & (hit[:, 2] >= z0) & (hit[:, 2] <= z1)
    if overhang is not None:
        ox0, ox1, depth, oz = overhang
        to = (oz - points[:, 2]) / sun[2]
        at = points + to[:, None] * sun
        under = (to > t) & (at[:, 1] <= 0) & (at[:, 1] >= -depth) & (at[:, 0] >= ox0) & (at[:, 0] <= ox1)
        through &= ~under
    return through


def main():
    q = json.load(sys.stdin)
    points = np.array(q["points"], dtype=float)
    suns = np.array(q["suns"], dtype=float)
    normal = np.array(q["normal"], dtype=float)
    if q.get("lux") is None:
        out = {"lit": [lit(points, s, q["window"], q.get("overhang")).astype(int).tolist() for s in suns]}
    else:
        hours = np.zeros(len(points))
        for s, lux in zip(suns, q["lux"]):
            cos = max(float(normal @ s), 0.0)
            if lux * q["vt"] * cos > 1000.0:
                hours += lit(points, s, q["window"], q.get("overhang"))
        out = {"hours_over": hours.tolist()}
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
