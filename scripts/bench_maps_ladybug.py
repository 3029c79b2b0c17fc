"""Ladybug's DirectSunStudy (Radiance rcontrib via ladybug-radiance + pyradiance) on the points of
a `sunlit map` run: the same points and normals, the same sun vectors (EnergyPlus's SUN3/SUN4 at
mid-hour on the day before, as `sunlit annual` and `sunlit map` use them), the model's triangles
as context. Prints one JSON line: its time and how its sun hours compare with sunlit's per point.

    python3 scripts/bench_maps_ladybug.py MODEL.glb POINTS.csv LAT LON TZ

Pitfalls from /work/shared/notes/radiance.md: sensors offset 1 mm (not Grasshopper's 0.1 m);
Radiance does not count a sun within ~0.85 deg of a surface's plane, so those hours are counted
apart ("grazing").
"""
import csv
import json
import math
import struct
import sys
import time

import os

import pyradiance
from ladybug_geometry.geometry3d import Mesh3D, Point3D, Vector3D
from ladybug_radiance.config import folders

# pyradiance's wheel carries Radiance's binaries (bin/) and library (lib/): point Ladybug at
# them before its intersection module reads the paths.
folders.radiance_path = os.path.dirname(pyradiance.__file__)
from ladybug_radiance.study.directsun import DirectSunStudy  # noqa: E402

SINE_DECL = [0.00561800, 0.0657911, -0.392779, 0.00064440, -0.00618495, -0.00010101, -0.00007951, -0.00011691, 0.00002096]
EQ_TIME = [0.00021971, -0.122649, 0.00762856, -0.156308, -0.0530028, -0.00388702, -0.00123978, -0.00270502, -0.00167992]


def sun(lat, lon, tz, day, hour):
    """EnergyPlus SUN3/SUN4 (src/sun/position.rs): unit vector towards the sun, x east, y north, z up."""
    x = 0.017167 * day
    terms = [1, math.sin(x), math.cos(x), math.sin(2 * x), math.cos(2 * x), math.sin(3 * x), math.cos(3 * x), math.sin(4 * x), math.cos(4 * x)]
    sd = sum(a * b for a, b in zip(SINE_DECL, terms))
    eot = sum(a * b for a, b in zip(EQ_TIME, terms))
    cd = math.sqrt(1 - sd * sd)
    h = math.radians(15 * (12 - (hour + eot)) + (15 * tz - lon))
    sl, cl = math.sin(math.radians(lat)), math.cos(math.radians(lat))
    return (cd * math.sin(h), sd * cl - cd * sl * math.cos(h), sd * sl + cd * cl * math.cos(h))


def glb_triangles(path):
    """Triangles of a glb as sunlit's GlbWriter writes it (meshes of POSITION + u32 indices, root
    nodes with a translation), in sunlit axes."""
    data = open(path, "rb").read()
    n = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20:20 + n])
    binary = data[20 + n + 8:]

    def accessor(i):
        a = gltf["accessors"][i]
        v = gltf["bufferViews"][a["bufferView"]]
        off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        if a["componentType"] == 5126:
            k = {"VEC3": 3}[a["type"]]
            return [struct.unpack_from("<3f", binary, off + 12 * j) for j in range(a["count"])]
        fmt = {5125: "I", 5123: "H", 5121: "B"}[a["componentType"]]
        size = struct.calcsize(fmt)
        return [struct.unpack_from("<" + fmt, binary, off + size * j)[0] for j in range(a["count"])]

    tris = []
    for node in gltf["nodes"]:
        if "mesh" not in node:
            continue
        t = node.get("translation", [0, 0, 0])
        for prim in gltf["meshes"][node["mesh"]]["primitives"]:
            pos = accessor(prim["attributes"]["POSITION"])
            idx = accessor(prim["indices"]) if "indices" in prim else list(range(len(pos)))
            world = [(p[0] + t[0], -(p[2] + t[2]), p[1] + t[1]) for p in pos]
            tris.extend((world[idx[k]], world[idx[k + 1]], world[idx[k + 2]]) for k in range(0, len(idx), 3))
    return tris


def main():
    glb, points_csv, lat, lon, tz = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
    rows = list(csv.DictReader(open(points_csv)))
    pts = [tuple(float(r[k]) for k in "xyz") for r in rows]
    nrm = [tuple(float(r[k]) for k in ("nx", "ny", "nz")) for r in rows]
    ours = [float(r["sun_hours"]) for r in rows]

    suns = []
    for day in range(1, 366):
        for hour in range(24):
            s = sun(lat, lon, tz, day - 1, hour + 0.5)
            if s[2] >= 1e-5:
                suns.append(s)

    # Sensors: a 1 cm square per point (its centroid the point), normal the point's.
    verts, faces = [], []
    for p, n in zip(pts, nrm):
        nv = Vector3D(*n)
        e1 = Vector3D(0, 0, 1).cross(nv) if abs(n[2]) < 0.9 else Vector3D(1, 0, 0) - nv * n[0]
        e1 = e1.normalize() * 0.005
        e2 = nv.cross(e1)
        c = Point3D(*p)
        k = len(verts)
        verts += [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2]
        faces.append((k, k + 1, k + 2, k + 3))
    study = Mesh3D(verts, faces)
    tris = glb_triangles(glb)
    cverts, cfaces = [], []
    for t in tris:
        k = len(cverts)
        cverts += [Point3D(*v) for v in t]
        cfaces.append((k, k + 1, k + 2))
    context = Mesh3D(cverts, cfaces)

    start = time.time()
    # Ladybug's vectors point from the sun to the ground.
    vectors = [Vector3D(-s[0], -s[1], -s[2]) for s in suns]
    result = DirectSunStudy(vectors, study, [context], timestep=1, offset_distance=0.001).direct_sun_hours
    seconds = time.time() - start

    # Grazing suns (within 0.85 deg of a point's plane) Radiance never counts.
    grazing = [sum(1 for s in suns if 0 < sum(a * b for a, b in zip(s, n)) < math.sin(math.radians(0.85))) for n in nrm]
    diffs = [abs(a - b) for a, b in zip(result, ours)]
    diffs_ng = [abs(a + g - b) for a, b, g in zip(result, ours, grazing)]
    total = sum(ours)
    print(json.dumps({
        "tool": "ladybug-radiance DirectSunStudy",
        "points": len(pts),
        "sun_up_hours": len(suns),
        "context_triangles": len(tris),
        "seconds": round(seconds, 2),
        "sun_hours_total_ladybug": round(sum(result), 1),
        "sun_hours_total_sunlit": round(total, 1),
        "mean_abs_diff_hours": round(sum(diffs) / len(diffs), 3),
        "mean_abs_diff_hours_counting_grazing": round(sum(diffs_ng) / len(diffs_ng), 3),
        "relative_total_diff": round((sum(result) - total) / total, 5) if total else None,
    }))


if __name__ == "__main__":
    main()
