"""Independent numpy ray caster for tests/inside.rs: a box room [0,W]x[0,D]x[0,H] with one
window in its south wall (y = 0) and an optional horizontal overhang outside it.

A point sees the sun when its ray towards the sun leaves the room through the window (the first
wall plane it meets, y = 0, within the window's rectangle) and then passes the overhang's plane
outside its rectangle. Nothing here comes from sunlit: only the geometry's numbers.

stdin: JSON {room: [W, D, H], window: [x0, x1, z0, z1], overhang: [x0, x1, depth, z] | null,
points: [[x, y, z]...], normal: [nx, ny, nz], suns: [[sx, sy, sz]...], lux: [...] | null,
vt: float, angular: "E" | null}
stdout: JSON {lit: [[0|1 per point] per sun], visible: [[vt at the sun's incidence on the window
per lit point, 0 unlit] per sun]} without lux; with lux (one per sun) {hours_over: [per point hours
with lux * vt * cos * lit > 1000]}. With angular "E" the window's transmittance at incidence theta
is vt times EnergyPlus's simple glazing curve E of cos theta (Engineering Reference, "Simple
Window Model": the curve of a glazing with U under 3.4 W/m2K and SHGC over 0.55); a list of
[degrees, transmittance] pairs (a glTF material's measured curve, first at 0): vt times the
curve's share of its normal value, linear in the angle, falling linearly to 0 at 90 past the last
pair; null: vt.

Second mode, any closed room of planar polygons (an L-shaped zone): stdin JSON {faces: [{name,
vertices: [[x, y, z]...], holes: [window outlines in it]}...] (the room's boundary; a wall's
outline includes its windows, its samples leave them out),
windows: [{vertices, tau}...] (tau one number, or one per beam: the glass's transmittance at
that beam's incidence), beams: [[sx, sy, sz, dni]...], spacing: float}. Each face is
sampled on a square grid of that spacing in its own plane (cell centres inside the polygon); a
sample sees the sun through a window when its ray meets the window's polygon before any face
(a hit on a face inside a window's outline is the window). stdout: JSON {incident: {name: sum
over beams of dni * tau * cos * lit share}} with cos against the face's inward normal (faces
are listed counter-clockwise seen from outside, as EnergyPlus lists them).
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


# EnergyPlus Engineering Reference, "Simple Window Model", curve E: T(c) = 1.51c + 2.49c^2 -
# 5.87c^3 + 2.88c^4, set to 1 at normal incidence.
CURVE_E = (1.51, 2.49, -5.87, 2.88)


def window_vt(vt, sun, angular):
    """The window's transmittance for the beam along `sun` (the window faces -y)."""
    if angular is None:
        return vt
    c = min(max(-float(sun[1]), 0.0), 1.0)
    if isinstance(angular, list):
        degrees = [float(a) for a, _ in angular]
        values = [float(t) for _, t in angular]
        if degrees[-1] < 90.0:
            degrees.append(90.0)
            values.append(0.0)
        theta = np.degrees(np.arccos(c))
        return vt * float(np.interp(theta, degrees, values)) / values[0]
    if c >= 1.0:
        return vt
    a, b, d, e = CURVE_E
    return vt * max(a * c + b * c**2 + d * c**3 + e * c**4, 0.0)


def frame(vertices):
    """Origin, in-plane axes and unit normal of a planar polygon (Newell's normal)."""
    v = np.asarray(vertices, dtype=float)
    n = np.zeros(3)
    for a, b in zip(v, np.roll(v, -1, axis=0)):
        n += np.cross(a, b)
    n /= np.linalg.norm(n)
    u = v[1] - v[0]
    u -= n * (u @ n)
    u /= np.linalg.norm(u)
    return v[0], u, np.cross(n, u), n


def inside_2d(pts, poly):
    """Even-odd test of 2D points against a 2D polygon."""
    x, y = pts[:, 0], pts[:, 1]
    out = np.zeros(len(pts), dtype=bool)
    for (x1, y1), (x2, y2) in zip(poly, np.roll(poly, -1, axis=0)):
        crosses = (y1 > y) != (y2 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        out ^= crosses & (x < xs)
    return out


def hits(points, sun, vertices):
    """Distance along `sun` at which each point's ray meets the polygon (inf where it misses)."""
    o, u, w, n = frame(vertices)
    d = sun @ n
    t = np.full(len(points), np.inf)
    if abs(d) < 1e-12:
        return t
    tt = ((o - points) @ n) / d
    at = points + tt[:, None] * sun - o
    flat = np.stack([at @ u, at @ w], axis=1)
    poly = np.stack([(np.asarray(vertices) - o) @ u, (np.asarray(vertices) - o) @ w], axis=1)
    ok = (tt > 1e-9) & inside_2d(flat, poly)
    t[ok] = tt[ok]
    return t


def room(q):
    faces, windows, spacing = q["faces"], q["windows"], q["spacing"]
    out = {}
    for f in faces:
        o, u, w, n = frame(f["vertices"])
        n = -n  # listed counter-clockwise seen from outside (as EnergyPlus lists them): inward
        v = np.asarray(f["vertices"], dtype=float) - o
        poly = np.stack([v @ u, v @ w], axis=1)
        lo, hi = poly.min(axis=0), poly.max(axis=0)
        gu = np.arange(lo[0] + spacing / 2, hi[0], spacing)
        gw = np.arange(lo[1] + spacing / 2, hi[1], spacing)
        grid = np.array([(a, b) for a in gu for b in gw])
        grid = grid[inside_2d(grid, poly)]
        for hole in f.get("holes", []):
            h = np.asarray(hole, dtype=float) - o
            grid = grid[~inside_2d(grid, np.stack([h @ u, h @ w], axis=1))]
        pts = o + grid[:, :1] * u + grid[:, 1:] * w + n * 1e-7
        total = 0.0
        for k, (sx, sy, sz, dni) in enumerate(q["beams"]):
            sun = np.array([sx, sy, sz])
            cos = sun @ n
            if cos <= 0:
                continue
            walls = [hits(pts, sun, g["vertices"]) for g in faces if g is not f]
            for win in windows:
                tw = hits(pts, sun, win["vertices"])
                # Lit: the ray leaves through the window and meets no face, inside or out (the
                # building shades its own windows), but the wall that holds the window, there.
                blocked = np.any([np.isfinite(t) & (np.abs(t - tw) > 1e-9) for t in walls], axis=0)
                lit = np.isfinite(tw) & ~blocked
                tau = win["tau"][k] if isinstance(win["tau"], list) else win["tau"]
                total += dni * tau * cos * lit.mean()
        out[f["name"]] = total
    return {"incident": out}


def main():
    q = json.load(sys.stdin)
    if "faces" in q:
        json.dump(room(q), sys.stdout)
        return
    points = np.array(q["points"], dtype=float)
    suns = np.array(q["suns"], dtype=float)
    normal = np.array(q["normal"], dtype=float)
    if q.get("lux") is None:
        lits = [lit(points, s, q["window"], q.get("overhang")) for s in suns]
        out = {"lit": [l.astype(int).tolist() for l in lits]}
        if q.get("vt") is not None:
            out["visible"] = [(l * window_vt(q["vt"], s, q.get("angular"))).tolist() for l, s in zip(lits, suns)]
    else:
        hours = np.zeros(len(points))
        for s, lux in zip(suns, q["lux"]):
            cos = max(float(normal @ s), 0.0)
            if lux * window_vt(q["vt"], s, q.get("angular")) * cos > 1000.0:
                hours += lit(points, s, q["window"], q.get("overhang"))
        out = {"hours_over": hours.tolist()}
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
