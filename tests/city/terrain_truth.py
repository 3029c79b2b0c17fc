"""A numpy ray cast, written independently of sunlit: the sunlit share of each RoofSurface of a
CityJSON file's Buildings, for suns given as azimuth (clockwise from north) and altitude in
degrees, every surface of every CityObject (terrain included) a caster.

Reads the file itself (vertices x transform.scale + translate), lays a fine grid on each roof's
plane (the roof's box in its plane's two longest directions, points inside its exterior ring
kept), and casts a ray from each point towards the sun against every triangle (Moeller-Trumbore,
both sides). Usage: python terrain_truth.py CITY.json AZ,ALT [AZ,ALT ...]; prints JSON
{"ROOF_NAME": [share at each sun]} with ROOF_NAME as OBJECT/RoofSurface/INDEX.
"""
import json
import sys

import numpy as np

N = 300  # points along each side of a roof's box


def surfaces(geometry):
    """Surfaces (lists of rings) of a geometry, flattened in file order."""
    depth = {"MultiSurface": 0, "CompositeSurface": 0, "Solid": 1, "MultiSolid": 2, "CompositeSolid": 2}[geometry["type"]]
    items = [geometry["boundaries"]]
    for _ in range(depth + 1):
        items = [x for i in items for x in i]
    return items


def semantic_types(geometry, count):
    values = geometry.get("semantics", {}).get("values")
    if values is None:
        return [None] * count
    kind = geometry["type"]
    depth = {"MultiSurface": 0, "CompositeSurface": 0, "Solid": 1, "MultiSolid": 2, "CompositeSolid": 2}[kind]
    for _ in range(depth):
        values = [x for v in values for x in v]
    names = geometry["semantics"]["surfaces"]
    return [None if v is None else names[v]["type"] for v in values]


def triangles(ring, vertices):
    """A convex ring fanned into triangles (the fixture's rings are convex)."""
    p = vertices[ring]
    return [(p[0], p[i], p[i + 1]) for i in range(1, len(p) - 1)]


def main():
    doc = json.load(open(sys.argv[1]))
    suns = [tuple(float(x) for x in s.split(",")) for s in sys.argv[2:]]
    scale = np.array(doc["transform"]["scale"])
    # Coordinates relative to the translate: the same shadows, better-conditioned sums.
    vertices = np.array(doc["vertices"], dtype=float) * scale
    tris, roofs = [], []
    for oid, obj in doc["CityObjects"].items():
        for geometry in obj.get("geometry", [])[:1]:
            found = surfaces(geometry)
            for index, (surface, kind) in enumerate(zip(found, semantic_types(geometry, len(found)))):
                for ring in surface:
                    tris += triangles(ring, vertices)
                if obj["type"] == "Building" and kind == "RoofSurface":
                    roofs.append((f"{oid}/RoofSurface/{index}", vertices[surface[0]]))
    a = np.array([t[0] for t in tris])
    e1 = np.array([t[1] for t in tris]) - a
    e2 = np.array([t[2] for t in tris]) - a
    out = {}
    for name, ring in roofs:
        normal = np.cross(ring[1] - ring[0], ring[2] - ring[0])
        normal /= np.linalg.norm(normal)
        u = ring[1] - ring[0]
        u /= np.linalg.norm(u)
        w = np.cross(normal, u)
        lo_u, hi_u = (ring - ring[0]) @ u, (ring - ring[0]) @ w
        s = (np.arange(N) + 0.5) / N
        gu = lo_u.min() + s * (lo_u.max() - lo_u.min())
        gw = hi_u.min() + s * (hi_u.max() - hi_u.min())
        uu, ww = np.meshgrid(gu, gw)
        points = ring[0] + uu.reshape(-1, 1) * u + ww.reshape(-1, 1) * w
        # The fixture's roofs fill their box (rectangles); a point off the plane is a bad fixture.
        assert np.allclose((points - ring[0]) @ normal, 0)
        points = points + 1e-6 * normal
        shares = []
        for azimuth, altitude in suns:
            az, alt = np.radians(azimuth), np.radians(altitude)
            d = np.array([np.sin(az) * np.cos(alt), np.cos(az) * np.cos(alt), np.sin(alt)])
            if d @ normal <= 0:
                shares.append(0.0)
                continue
            blocked = np.zeros(len(points), dtype=bool)
            for k in range(len(a)):
                p = np.cross(d, e2[k])
                det = e1[k] @ p
                if abs(det) < 1e-12:
                    continue
                t_vec = points - a[k]
                bu = (t_vec @ p) / det
                q = np.cross(t_vec, e1[k])
                bv = (q @ d) / det
                t = (q @ e2[k]) / det
                blocked |= (bu >= 0) & (bv >= 0) & (bu + bv <= 1) & (t > 1e-6)
            shares.append(float(1.0 - blocked.mean()))
        out[name] = shares
    print(json.dumps(out))


main()
