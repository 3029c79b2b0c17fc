#!/usr/bin/env python3
"""Where Radiance's gendaymtx puts the sun: the independent truth for sunlit's patch order.

Test scaffolding (tests/radiance.rs runs it with the .venv-rad python; nothing here ships).

Crafted weather (direct normal 800 W/m², no diffuse) at sites from the equator to the poles, so
that the year's suns cross every part of the sky, north included, goes through gendaymtx twice:
``-d`` (direct only) gives the sky matrix with each sun put into its patches (gendaymtx spreads a
sun over the patches whose centres are nearest it, the nearest weighted most), and ``-D`` writes
the same suns as Radiance sources, so each sun's direction is Radiance's own (no solar position
model of ours enters). Output: a JSON list with, per sun that is up, its direction (x east,
y north, z up) and the matrix rows that received it, largest first.

The matrix is read here, not by a library: its header runs to the first blank line, then come
NROWS rows (row 0 the ground, rows 1.. the sky patches) of NCOLS steps of NCOMP floats.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

# (latitude °N, hour offset): from the south pole's summer to the north pole's, so that the sun
# is seen in the north (southern sites), overhead (tropics) and circling low (polar sites). The
# offsets put each site's suns at other minutes, so the sites fill each other's gaps.
SITES = [(-89.0, 0.0), (-75.0, 0.2), (-60.0, 0.4), (-45.0, 0.6), (-23.0, 0.8), (-10.0, 0.1), (0.0, 0.3), (12.0, 0.5),
         (23.4, 0.7), (35.0, 0.9), (50.0, 0.15), (66.0, 0.35), (80.0, 0.55), (89.0, 0.75)]
DAY_STEP = 3
DNI = 800.0
DAYS_BEFORE = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334]  # a non-leap year


def radiance_bin():
    import pyradiance
    return os.path.join(os.path.dirname(pyradiance.__file__), "bin")


def month_day(doy):
    month = max(m for m in range(12) if DAYS_BEFORE[m] < doy)
    return month + 1, doy - DAYS_BEFORE[month]


def write_wea(path, latitude, offset):
    """Every DAY_STEP-th day, every hour + offset, at longitude 0 in UTC; the step's minute of the
    year per column (gendaymtx names its -D suns by it)."""
    minutes = []
    with open(path, "w") as f:
        f.write(f"place site{latitude}\nlatitude {latitude}\nlongitude 0\ntime_zone 0\nsite_elevation 0\n")
        f.write("weather_data_file_units 1\n")
        for doy in range(1, 366, DAY_STEP):
            month, day = month_day(doy)
            for h in range(24):
                hour = h + offset
                f.write(f"{month} {day} {hour:.2f} {DNI} 0\n")
                minutes.append(round((doy - 1) * 1440 + hour * 60))
    return minutes


def run(command, stdout):
    """Runs a Radiance tool; its warnings (a bright low sun, every polar hour) are shown only when
    it fails."""
    done = subprocess.run(command, stdout=stdout, stderr=subprocess.PIPE)
    if done.returncode != 0:
        sys.exit(f"{command[0]} failed ({done.returncode}): {done.stderr.decode(errors='replace')[-2000:]}")


def read_matrix(path):
    """A float matrix as (rows, cols, comps), its header parsed here."""
    with open(path, "rb") as f:
        header = {}
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: header never ends")
            if line.strip() == b"":
                break
            if b"=" in line:
                key, value = line.strip().split(b"=", 1)
                header[key.decode()] = value.decode()
        rows, cols, comps = int(header["NROWS"]), int(header["NCOLS"]), int(header["NCOMP"])
        if header.get("FORMAT") != "float":
            sys.exit(f"{path}: format {header.get('FORMAT')}, expected float")
        data = np.frombuffer(f.read(), dtype="<f4")
    if data.size != rows * cols * comps:
        sys.exit(f"{path}: {data.size} values, header says {rows}x{cols}x{comps}")
    return data.reshape(rows, cols, comps)


def read_suns(path):
    """Radiance's -D suns: per minute of the year (from the source's name), its direction."""
    words = open(path).read().split()
    suns = {}
    for i, w in enumerate(words):
        if w == "source" and words[i + 1].startswith("sun"):
            minute = int(words[i + 1][3:])
            # name 0 0 4 x y z angle
            x, y, z = (float(v) for v in words[i + 5:i + 8])
            suns[minute] = (x, y, z)
    return suns


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--mf", type=int, required=True, help="Reinhart subdivision (1: Tregenza)")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()
    bin_dir = radiance_bin()
    gendaymtx = os.path.join(bin_dir, "gendaymtx")
    out = []
    with tempfile.TemporaryDirectory(prefix="sunlit-patch-order-") as work:
        for latitude, offset in SITES:
            wea = os.path.join(work, "w.wea")
            minutes = write_wea(wea, latitude, offset)
            mtx = os.path.join(work, "d.mtx")
            with open(mtx, "wb") as f:
                run([gendaymtx, "-m", str(args.mf), "-d", "-O1", "-of", wea], f)
            suns_rad, suns_mod = os.path.join(work, "suns.rad"), os.path.join(work, "suns.mod")
            run([gendaymtx, "-m", str(args.mf), "-O1", "-D", suns_rad, "-M", suns_mod, wea], subprocess.DEVNULL)
            matrix = read_matrix(mtx)[:, :, 0]
            suns = read_suns(suns_rad)
            if matrix.shape[1] != len(minutes):
                sys.exit(f"gendaymtx: {matrix.shape[1]} columns, wrote {len(minutes)} steps")
            for col, minute in enumerate(minutes):
                if minute not in suns:
                    continue
                column = matrix[:, col]
                lit = [int(r) for r in np.argsort(-column) if column[r] > 0][:6]
                out.append({"latitude": latitude, "minute": minute, "sun": suns[minute],
                            "rows": [[r, float(column[r])] for r in lit]})
    with open(args.output, "w") as f:
        json.dump({"rows": int(matrix.shape[0]), "suns": out}, f)


if __name__ == "__main__":
    main()
