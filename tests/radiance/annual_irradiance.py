#!/usr/bin/env python3
"""Annual irradiation per receiver computed by Radiance: the independent truth for `sunlit annual`.

Test scaffolding (tests/radiance.rs runs it with the .venv-rad python; nothing here ships).

Input: a scene JSON written by the Rust test from sunlit's own scene (world triangles and receivers
with their triangles and outward normals), an EPW and a ground reflectance. Output: a JSON with, per
receiver, annual kWh/m² of

- ``direct``: the beam. Every daytime hour's sun is an exact Radiance `source` of 0.533° whose
  radiance gives the EPW's direct normal irradiance, at the hour's middle (HH-0.5, as EnergyPlus and
  sunlit at one timestep per hour): at the directions given with --suns (the Rust test gives
  sunlit's), else gendaymtx's own (-D; Radiance's solar position, 0.43° from EnergyPlus's on
  average). `rcontrib -ab 0` sums every sun's contribution (cos, and a shadow ray to the sun) over
  points on the receiver.
- ``sky``: the sky without the sun: gendaymtx's Perez all-weather sky (-s: diffuse only) on
  Tregenza's 145 patches (-m 1), each patch's coefficient (the visible cos-weighted solid angle,
  `rcontrib -ab 1` over the same points) times the patch's annual radiance.
- ``ground``: gendaymtx's ground patch (row 0, radiance ρ·GHI/π) seen through the receiver's
  unobstructed lower hemisphere (as EnergyPlus and the issue define ground-reflected solar);
  ``ground_obstructed`` is the same through the scene, for information.
- ``sky_view_factor``: the view factor to the visible sky (the sky patches' coefficients / π).
- ``unshaded_*``: the same with no geometry at all (one point per receiver).

With --sensors FILE.csv (header x,y,z,nx,ny,nz: a map's points, e.g. `sunlit map`'s own), each
point is its own record instead of a receiver's average (named p0, p1, … in the file's order),
offset 1 mm along its own normal; ``unshaded_*`` are then the point's with no geometry.

Every surface in the scene is black (reflectance 0), as in Ladybug's RadiationStudy: only the sun,
the sky and the ground count. Points are quasi-random (Halton) over each receiver's triangles,
offset 1 mm along its normal, the same number per receiver (rcontrib -c averages them).

The matrix is read here, not by a library: gendaymtx's header runs to its first blank line, then
come NROWS rows (row 0 the ground, rows 1..145 Tregenza's patches) of NCOLS hours of NCOMP floats.
(ladybug-radiance 0.2.12 skips one header line too few and shifts every patch by one.)
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

OFFSET = 0.001  # metres along the normal: larger offsets move shadow patterns sideways.
PATCHES = 146  # Tregenza's 145 and the ground, gendaymtx -m 1 / reinhart.cal MF:1.


def radiance_paths():
    """The pyradiance wheel's binaries and its .cal library (reinhart.cal)."""
    import pyradiance

    root = os.path.dirname(pyradiance.__file__)
    return os.path.join(root, "bin"), os.path.join(root, "lib")


def run(args, env, stdin=None, stdout=None):
    done = subprocess.run(args, env=env, stdin=stdin, stdout=stdout or subprocess.PIPE, stderr=subprocess.PIPE)
    if done.returncode != 0:
        sys.exit(f"{args[0]} failed ({done.returncode}): {done.stderr.decode(errors='replace')}")
    return done.stdout


def read_matrix(path):
    """A Radiance matrix (ascii or float) as an array (rows, cols, comps), header parsed here."""
    with open(path, "rb") as f:
        header = {}
        first = f.readline()
        if not first.startswith(b"#?RADIANCE"):
            sys.exit(f"{path}: not a Radiance matrix")
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: header never ends")
            line = line.strip()
            if not line:
                break
            if b"=" in line:
                key, _, value = line.partition(b"=")
                header[key.decode()] = value.decode()
        rows, cols, comps = int(header["NROWS"]), int(header["NCOLS"]), int(header["NCOMP"])
        fmt = header.get("FORMAT", "ascii")
        if fmt == "float":
            data = np.frombuffer(f.read(), dtype="<f4")
        elif fmt == "ascii":
            data = np.array(f.read().split(), dtype=float)
        else:
            sys.exit(f"{path}: unexpected FORMAT={fmt}")
    if data.size != rows * cols * comps:
        sys.exit(f"{path}: {data.size} values, header says {rows}x{cols}x{comps}")
    return data.reshape(rows, cols, comps).astype(float)


def halton(index, base):
    result, f = 0.0, 1.0
    while index > 0:
        f /= base
        result += f * (index % base)
        index //= base
    return result


def receiver_points(receiver, count):
    """`count` quasi-random points on the receiver (Halton over its in-plane bounding box, kept when
    inside one of its triangles), offset along its normal."""
    tris = np.array(receiver["triangles"], dtype=float)
    normal = np.array(receiver["normal"], dtype=float)
    normal /= np.linalg.norm(normal)
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    origin = tris[0, 0]
    flat = np.stack([(tris - origin) @ u, (tris - origin) @ v], axis=-1)  # (n, 3, 2)
    lo, hi = flat.reshape(-1, 2).min(axis=0), flat.reshape(-1, 2).max(axis=0)
    a, b, c = flat[:, 0], flat[:, 1], flat[:, 2]

    def cross2(p, q):
        return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]

    area2 = cross2(b - a, c - a)
    points, index = [], 1
    while len(points) < count:
        if index > 200 * count + 10000:
            sys.exit(f"receiver {receiver['name']}: no area to place points on")
        p = lo + (hi - lo) * np.array([halton(index, 2), halton(index, 3)])
        index += 1
        w1 = cross2(b - p, c - p) / np.where(area2 == 0, 1, area2)
        w2 = cross2(c - p, a - p) / np.where(area2 == 0, 1, area2)
        w3 = 1.0 - w1 - w2
        inside = (area2 != 0) & (w1 >= 0) & (w2 >= 0) & (w3 >= 0)
        if inside.any():
            points.append(origin + p[0] * u + p[1] * v + OFFSET * normal)
    return np.array(points), normal


def read_sensors(path):
    """Points and unit normals from a CSV with the header x,y,z,nx,ny,nz."""
    with open(path) as f:
        header = f.readline().strip()
        if header != "x,y,z,nx,ny,nz":
            sys.exit(f"{path}: header {header!r}, expected x,y,z,nx,ny,nz")
        rows = [[float(v) for v in line.split(",")] for line in f if line.strip()]
    out = []
    for row in rows:
        point, normal = np.array(row[:3]), np.array(row[3:6])
        normal /= np.linalg.norm(normal)
        out.append((point, normal))
    return out


def write_scene(path, triangles):
    with open(path, "w") as f:
        f.write("void plastic black\n0\n0\n5 0 0 0 0 0\n")
        for i, tri in enumerate(triangles):
            coords = " ".join(f"{c:.6f}" for p in tri for c in p)
            f.write(f"black polygon t{i}\n0\n0\n9 {coords}\n")


SKY = "void glow skyglow\n0\n0\n4 1 1 1 0\n\nskyglow source skydome\n0\n0\n4 0 0 1 360\n"


def rays(points_and_normals):
    lines = []
    for points, normal in points_and_normals:
        for p in points:
            lines.append(f"{p[0]:.6f} {p[1]:.6f} {p[2]:.6f} {normal[0]:.9f} {normal[1]:.9f} {normal[2]:.9f}\n")
    return "".join(lines).encode()


def rcontrib_records(bin_dir, env, octree, modifiers, per_record, ray_text, records, extra):
    """rcontrib -I over the rays, averaging `per_record` consecutive rays; returns (records, columns)."""
    out = run(
        [os.path.join(bin_dir, "rcontrib"), "-I", "-h", "-faf", "-c", str(per_record), *extra, *modifiers, octree],
        env,
        stdin_bytes(ray_text),
    )
    values = np.frombuffer(out, dtype="<f4").astype(float)
    if values.size % (records * 3):
        sys.exit(f"rcontrib: {values.size} values for {records} records")
    return values.reshape(records, -1, 3)


def stdin_bytes(data):
    f = tempfile.TemporaryFile()
    f.write(data)
    f.seek(0)
    return f


def photopic(rgb):
    """Radiance's own weighting of its three channels (equal here: the sky colour is 1 1 1)."""
    return rgb @ np.array([0.265, 0.670, 0.065])


# Perez et al. 1990 brightness coefficients, as EnergyPlus's AnisoSkyViewFactors tabulates them.
PEREZ_EPSILON = [1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2]
PEREZ = np.array([
    [-0.0083117, 0.5877285, -0.0620636, -0.0596012, 0.0721249, -0.0220216],
    [0.1299457, 0.6825954, -0.1513752, -0.0189325, 0.0659650, -0.0288748],
    [0.3296958, 0.4868735, -0.2210958, 0.0554140, -0.0639588, -0.0260542],
    [0.5682053, 0.1874525, -0.2951290, 0.1088631, -0.1519229, -0.0139754],
    [0.8730280, -0.3920403, -0.3616149, 0.2255647, -0.4620442, 0.0012448],
    [1.1326077, -1.2367284, -0.4118494, 0.2877813, -0.8230357, 0.0558651],
    [1.0601591, -1.5999137, -0.3589221, 0.2642124, -1.1272340, 0.1310694],
    [0.6777470, -0.3272588, -0.2504286, 0.1561313, -1.3765031, 0.2506212],
])


def read_epw(path):
    """Latitude, longitude (° east), time zone (h), elevation and the hourly DNI, DHI, GHI."""
    with open(path, encoding="latin-1") as f:
        lines = f.read().splitlines()
    loc = lines[0].split(",")
    rows = [line.split(",") for line in lines[8:] if line.strip()]
    column = lambda i: np.array([float(r[i]) for r in rows])
    return float(loc[6]), float(loc[7]), float(loc[8]), float(loc[9]), column(14), column(15), column(13)


def sun_vectors(latitude, longitude, zone, hours):
    """Unit vectors (x east, y north, z up) to the sun at each hour's middle (local standard
    time), from the Spencer (1971) declination and equation of time: only for the closed-form
    Perez diagnostic, never for the truths."""
    day = np.floor(hours / 24) + 1
    clock = hours % 24 + 0.5
    g = 2 * np.pi * (day - 1) / 365
    decl = (0.006918 - 0.399912 * np.cos(g) + 0.070257 * np.sin(g) - 0.006758 * np.cos(2 * g)
            + 0.000907 * np.sin(2 * g) - 0.002697 * np.cos(3 * g) + 0.00148 * np.sin(3 * g))
    eot = 229.18 * (0.000075 + 0.001868 * np.cos(g) - 0.032077 * np.sin(g) - 0.014615 * np.cos(2 * g)
                    - 0.040849 * np.sin(2 * g)) / 60
    solar_time = clock + eot + (longitude - 15 * zone) / 15
    omega = np.radians(15 * (solar_time - 12))
    phi = np.radians(latitude)
    up = np.sin(phi) * np.sin(decl) + np.cos(phi) * np.cos(decl) * np.cos(omega)
    east = -np.cos(decl) * np.sin(omega)
    north = np.cos(phi) * np.sin(decl) - np.sin(phi) * np.cos(decl) * np.cos(omega)
    return np.stack([east, north, up], axis=-1)


def perez_1990_unshaded(epw, normals):
    """Annual kWh/m² of Perez 1990 sky diffuse on unobstructed planes with these normals: the
    closed form a correct sunlit must give on unobstructed surfaces (for the report: it shows how
    much of a difference to Radiance is the sky model, Perez 1990 against gendaymtx's Perez
    all-weather sky, and how much is sunlit)."""
    latitude, longitude, zone, elevation, dni, dhi, _ = read_epw(epw)
    sun = sun_vectors(latitude, longitude, zone, np.arange(dni.size, dtype=float))
    cos_z = sun[:, 2]
    up = (cos_z > 0) & (dhi > 0)
    zenith = np.arccos(np.clip(cos_z, -1, 1))
    z3 = 1.041 * zenith**3
    with np.errstate(divide="ignore", invalid="ignore"):
        epsilon = np.where(up, ((dhi + dni) / np.where(dhi > 0, dhi, 1) + z3) / (1 + z3), 1.0)
        air_mass = (1 - 0.1 * elevation / 1000) / (cos_z + 0.15 / np.power(np.maximum(93.9 - np.degrees(zenith), 1e-6), 1.253))
    delta = dhi * np.where(up, air_mass, 0) / 1353
    bins = np.searchsorted(PEREZ_EPSILON, epsilon, side="left")
    c = PEREZ[bins]
    f1 = np.maximum(0, c[:, 0] + c[:, 1] * delta + c[:, 2] * zenith)
    f2 = c[:, 3] + c[:, 4] * delta + c[:, 5] * zenith
    out = []
    for n in normals:
        n = np.asarray(n, dtype=float) / np.linalg.norm(n)
        cos_tilt = n[2]
        sin_tilt = np.sqrt(max(0.0, 1 - cos_tilt**2))
        cos_theta = np.maximum(0, sun @ n)
        sky = dhi * np.maximum(0, (1 + cos_tilt) / 2 * (1 - f1) + f1 * cos_theta / np.maximum(0.0871557, cos_z) + f2 * sin_tilt)
        out.append(float(np.where(up, sky, 0).sum() / 1000))
    return out


SUN_ANGLE = 0.533  # degrees, the sun's full angle (gendaymtx's)


def write_suns(path_rad, path_mod, suns_file, epw):
    """Radiance suns at the given directions (one line per hour: EPW hour index 0..8759, x y z),
    each with the radiance that gives that hour's EPW direct normal irradiance (as gendaymtx -D
    does: DNI over the disc's solid angle); hours without DNI are left out."""
    dni = read_epw(epw)[4]
    solid = 2 * np.pi * (1 - np.cos(np.radians(SUN_ANGLE / 2)))
    names = []
    with open(suns_file) as f, open(path_rad, "w") as rad:
        for line in f:
            if not line.strip():
                continue
            hour, x, y, z = line.split()
            hour = int(hour)
            if dni[hour] <= 0:
                continue
            radiance = dni[hour] / solid
            rad.write(f"void light solar{hour}\n0\n0\n3 {radiance:.6e} {radiance:.6e} {radiance:.6e}\n\n")
            rad.write(f"solar{hour} source sun{hour}\n0\n0\n4 {x} {y} {z} {SUN_ANGLE}\n\n")
            names.append(f"solar{hour}")
    with open(path_mod, "w") as mod:
        mod.write("\n".join(names) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", help="scene JSON: triangles, receivers (name, triangles, normal)")
    parser.add_argument("--epw", required=True)
    parser.add_argument("--albedo", type=float, required=True)
    parser.add_argument("--points", type=int, default=64, help="points per receiver")
    parser.add_argument("--ambient-divisions", type=int, default=512, help="rcontrib -ad for the sky")
    parser.add_argument("--processes", type=int, default=2, help="rcontrib -n")
    parser.add_argument("--suns", help="sun directions per hour (index x y z); default: gendaymtx's own suns")
    parser.add_argument("--sensors", help="points CSV (x,y,z,nx,ny,nz): one record per point instead of per receiver")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()

    bin_dir, lib_dir = radiance_paths()
    env = dict(os.environ, RAYPATH=f".{os.pathsep}{lib_dir}", PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}")
    with open(args.scene) as f:
        scene = json.load(f)
    receivers = scene["receivers"]
    timings = {}
    with tempfile.TemporaryDirectory(prefix="sunlit-radiance-") as work:
        def at(name):
            return os.path.join(work, name)

        start = time.monotonic()
        run([os.path.join(bin_dir, "epw2wea"), args.epw, at("weather.wea")], env)
        rho = f"{args.albedo}"
        gendaymtx = [os.path.join(bin_dir, "gendaymtx"), "-O1", "-of", "-m", "1", "-c", "1", "1", "1", "-g", rho, rho, rho]
        # -s: the sky without the sun, -O1: solar radiance in W/m²/sr. The suns come from a second run
        # with -D alone (this gendaymtx zeroes the -D suns under -s, and without -s its matrix holds
        # the sun too: that matrix is discarded).
        with open(at("sky.mtx"), "wb") as out:
            run([*gendaymtx, "-s", at("weather.wea")], env, stdout=out)
        if args.suns:
            write_suns(at("suns.rad"), at("suns.mod"), args.suns, args.epw)
        else:
            run([*gendaymtx, "-D", at("suns.rad"), "-M", at("suns.mod"), at("weather.wea")], env)
        sky = photopic(read_matrix(at("sky.mtx")))  # (146, hours) W/m²/sr
        if sky.shape[0] != PATCHES:
            sys.exit(f"gendaymtx: {sky.shape[0]} rows, expected {PATCHES}")
        patch_hours = sky.sum(axis=1)  # Σ over the year of each patch's radiance, W·h/m²/sr
        timings["gendaymtx_s"] = time.monotonic() - start

        write_scene(at("scene.rad"), scene["triangles"])
        with open(at("sky.rad"), "w") as f:
            f.write(SKY)
        oconv = os.path.join(bin_dir, "oconv")
        for name, parts in [("direct.oct", ["scene.rad", "suns.rad"]), ("sky.oct", ["scene.rad", "sky.rad"]),
                            ("open-direct.oct", ["suns.rad"]), ("open-sky.oct", ["sky.rad"])]:
            with open(at(name), "wb") as out:
                run([oconv, "-f", *[at(p) for p in parts]], env, stdout=out)

        if args.sensors:
            placed = [(np.array([p + OFFSET * nrm]), nrm) for p, nrm in read_sensors(args.sensors)]
            names = [f"p{i}" for i in range(len(placed))]
            per_record = 1
        else:
            placed = [receiver_points(r, args.points) for r in receivers]
            names = [r["name"] for r in receivers]
            per_record = args.points
        ray_text = rays(placed)
        one_ray = rays([(points[:1], normal) for points, normal in placed])
        n = len(placed)
        suns = ["-M", at("suns.mod")]
        # Every sun as a point source, every one tested (no thresholds, no jitter), no bounce.
        # -V+: contributions (times each sun's radiance), not coefficients.
        direct_opts = ["-V+", "-n", str(args.processes), "-ab", "0", "-dc", "1", "-dt", "0", "-dj", "0", "-ds", "0", "-dr", "0",
                       "-st", "0", "-ss", "0", "-lw", "1e-9"]
        sky_modifier = ["-e", "MF:1", "-f", "reinhart.cal", "-b", "rbin", "-bn", "Nrbins", "-m", "skyglow"]
        sky_opts = lambda ad: ["-n", str(args.processes), "-ab", "1", "-ad", str(ad), "-lw", f"{0.1 / ad:g}", "-dc", "1"]

        start = time.monotonic()
        direct = photopic(rcontrib_records(bin_dir, env, at("direct.oct"), suns, per_record, ray_text, n, direct_opts))
        timings["direct_s"] = time.monotonic() - start
        start = time.monotonic()
        coef = photopic(rcontrib_records(bin_dir, env, at("sky.oct"), sky_modifier, per_record, ray_text, n,
                                         sky_opts(args.ambient_divisions)))
        timings["sky_s"] = time.monotonic() - start
        start = time.monotonic()
        open_direct = photopic(rcontrib_records(bin_dir, env, at("open-direct.oct"), suns, 1, one_ray, n, direct_opts))
        open_coef = photopic(rcontrib_records(bin_dir, env, at("open-sky.oct"), sky_modifier, 1, one_ray, n,
                                              sky_opts(16384)))
        timings["unshaded_s"] = time.monotonic() - start
        if coef.shape[1] != PATCHES:
            sys.exit(f"rcontrib: {coef.shape[1]} sky bins, expected {PATCHES}")

    perez = perez_1990_unshaded(args.epw, [normal for _, normal in placed])
    # Every sun stands for one hour: W/m² summed over hours is Wh/m².
    kwh = lambda wh: wh / 1000.0
    results = []
    for i, name in enumerate(names):
        results.append({
            "name": name,
            "points": per_record,
            "direct": kwh(direct[i].sum()),
            "sky": kwh(coef[i, 1:] @ patch_hours[1:]),
            "ground": kwh(open_coef[i, 0] * patch_hours[0]),
            "ground_obstructed": kwh(coef[i, 0] * patch_hours[0]),
            "sky_view_factor": float(coef[i, 1:].sum() / np.pi),
            "unshaded_direct": kwh(open_direct[i].sum()),
            "unshaded_sky": kwh(open_coef[i, 1:] @ patch_hours[1:]),
            "unshaded_sky_view_factor": float(open_coef[i, 1:].sum() / np.pi),
            "perez_1990_unshaded_sky": perez[i],
        })
    report = {
        "epw": args.epw,
        "albedo": args.albedo,
        "ground_horizontal_kwh": kwh(np.pi * patch_hours[0] / args.albedo) if args.albedo > 0 else None,
        "timings": timings,
        "receivers": results,
    }
    tmp = args.output + ".tmp"
    with open(tmp, "w") as f:
        json.dump(report, f, indent=1)
    os.replace(tmp, args.output)


if __name__ == "__main__":
    main()
