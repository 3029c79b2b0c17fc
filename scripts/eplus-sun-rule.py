#!/usr/bin/env python3
"""Which day's sun EnergyPlus's shading uses, read off one of its runs.

Applies EnergyPlus's SUN3 (declination and equation of time, SolarShading.cc) and SUN4 (hour angle)
for the calendar day, and for the day before, at each timestep's end (mid-hour with one timestep an
hour) and at the weather file's location, to every exterior surface's outward normal (from the
eio's HeatTransfer Surface lines), and counts the timesteps EnergyPlus reports lit
(`Surface Outside Face Sunlit Fraction` > 0) where the rule says dark (sun down or behind the
surface, cos < 1e-5). A rule that is EnergyPlus's gives 0.

The run needs `Output:Variable, *, Surface Outside Face Sunlit Fraction, Timestep;` and `-r`
(ReadVarsESO) so that eplusout.csv exists.

    scripts/eplus-sun-rule.py RUN_DIR WEATHER.epw TIMESTEPS_PER_HOUR [FIRST_DAY_OF_YEAR]
"""
import csv
import math
import sys

SINE_DECLINATION = [0.00561800, 0.0657911, -0.392779, 0.00064440, -0.00618495, -0.00010101, -0.00007951, -0.00011691, 0.00002096]
EQUATION_OF_TIME = [0.00021971, -0.122649, 0.00762856, -0.156308, -0.0530028, -0.00388702, -0.00123978, -0.00270502, -0.00167992]
THRESHOLD = 1e-5


def sun3(day):
    x = 0.017167 * day
    s1, c1 = math.sin(x), math.cos(x)
    s2, c2 = 2 * s1 * c1, c1 * c1 - s1 * s1
    s3, c3 = s1 * c2 + c1 * s2, c1 * c2 - s1 * s2
    s4, c4 = 2 * s2 * c2, c2 * c2 - s2 * s2
    terms = [1, s1, c1, s2, c2, s3, c3, s4, c4]
    return sum(a * b for a, b in zip(SINE_DECLINATION, terms)), sum(a * b for a, b in zip(EQUATION_OF_TIME, terms))


def sun4(lat, lon, tz, day, hour):
    sin_dec, eot = sun3(day)
    cos_dec = math.sqrt(1 - sin_dec * sin_dec)
    h = math.radians(15 * (12 - (hour + eot)) + (tz * 15 - lon))
    sl, cl = math.sin(math.radians(lat)), math.cos(math.radians(lat))
    return (cos_dec * math.sin(h), sin_dec * cl - cos_dec * sl * math.cos(h), sin_dec * sl + cos_dec * cl * math.cos(h))


def main():
    run, epw, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
    first_day = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    fields = open(epw, encoding="utf-8", errors="replace").readline().split(",")
    lat, lon, tz = float(fields[6]), float(fields[7]), float(fields[8])
    normals = {}
    for line in open(f"{run}/eplusout.eio", errors="replace"):
        if line.startswith("HeatTransfer Surface,"):
            f = line.split(",")
            if f[17] == "ExternalEnvironment" and f[20] == "SunExposed":
                az, tilt = math.radians(float(f[12])), math.radians(float(f[13]))
                normals[f[1].upper()] = (math.sin(az) * math.sin(tilt), math.cos(az) * math.sin(tilt), math.cos(tilt))
    rows = list(csv.reader(open(f"{run}/eplusout.csv")))
    suffix = ":SURFACE OUTSIDE FACE SUNLIT FRACTION [](TIMESTEP)"
    columns = {h.upper()[: -len(suffix)]: i for i, h in enumerate(rows[0]) if h.upper().endswith(suffix) and h.upper()[: -len(suffix)] in normals}
    for shift, label in [(0, "calendar day"), (-1, "previous day")]:
        wrong, day, previous = 0, first_day - 1, None
        for row in rows[1:]:
            date, clock = row[0].split()
            if date != previous:
                day, previous = day + 1, date
            hour = int(clock[:2]) + int(clock[3:5]) / 60 if n > 1 else int(clock[:2]) - 0.5
            sun = sun4(lat, lon, tz, day + shift, hour)
            for name, i in columns.items():
                if i >= len(row) or not row[i].strip() or float(row[i]) <= 0:
                    continue
                normal = normals[name]
                if sun[2] < THRESHOLD or sum(a * b for a, b in zip(normal, sun)) < THRESHOLD:
                    wrong += 1
        print(f"{label}'s sun: {wrong} timesteps EnergyPlus reports lit where the rule says dark ({len(columns)} surfaces)")


if __name__ == "__main__":
    main()
