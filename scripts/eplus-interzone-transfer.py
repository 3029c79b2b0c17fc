#!/usr/bin/env python3
"""What the beam through 4ZoneWithShading_Simple_1's interzone pane is worth (docs/energyplus-fidelity.md).

Usage: scripts/eplus-interzone-transfer.py SUNLIT ENERGYPLUS EPW OUTDIR

OUTDIR is scripts/eplus-interior-beam.py's (its clipping.idf and its `interior-beam` hooked copy,
fed EnergyPlus's own fractions), run with a sunlit whose balance takes back only the faces' beam
(main 4777366 and before; docs/energyplus-fidelity.md has its figures): the experiments below are
what led to the balance taking back all the beam let in, and on a later build's OUTDIR they would
count the beam on the windows twice. EnergyPlus's own run sends the beam that falls on the interzone
pane's back on into the next zone as diffuse (SolarShading.cc, CalcInteriorSolarDistribution:
`EnclSolDBIntWin(adjEnclosureNum) += BOverlap * TransBeamWin`) and takes it, with what the pane's
glass absorbs, off its own zone's diffuse (`BABSZone += BOverlap * (AbsBeamTotWin + TransBeamWin)`);
sunlit's interior beam skips interzone windows by name, so that beam stays in its own zone's
diffuse. This experiment hands the transfer over with what 25.2 can take: the clipping run again
with each zone's `Enclosure Interior Windows Total Transmitted Beam Solar Radiation Rate` at every
timestep (EnergyPlus's own figure, as an oracle), added to the receiving zone's balance schedule
and taken off the sending zone's (W over the balance window's area; a window's inside
absorptance is 0 there, so it all moves between the zones' diffuse), then the hooked copy run
again. Prints the site energy gap before and after, against the clipping run; then, to say
where the interior beam's gap differs from FullExterior's (the glass absorption alone), the same
building set back to FullExterior, run with its own clipping and hooked (its own fractions), and
per zone the ideal loads' heating and cooling gap (GJ) of each hooked run against its clipping
run.
"""
import csv
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eplus_hooked import columns, own_fractions, site  # noqa: E402

sunlit, energyplus, epw, out = sys.argv[1:5]
VAR = "Enclosure Interior Windows Total Transmitted Beam Solar Radiation Rate"
# The one interzone pair of the model: what enters one zone through it leaves the other.
PAIR = ("ZONE 3", "ZONE 4")


def run(idf, d):
    # A run OUTDIR already holds is not made again (the experiment is rerun piece by piece).
    if os.path.exists(os.path.join(d, "eplusout.end")) and os.path.getmtime(os.path.join(d, "eplusout.end")) > os.path.getmtime(idf):
        return
    subprocess.run([energyplus, "-r", "-w", epw, "-d", d, idf], check=True, capture_output=True)


def loads(d):
    """Per zone, the year's ideal loads heating + cooling (GJ), from the RunPeriod row."""
    rows = list(csv.reader(open(os.path.join(d, "eplusout.csv"))))
    out = {}
    for i, h in enumerate(rows[0]):
        if "Ideal Loads Zone Total" in h and "(RunPeriod)" in h and rows[-1][i].strip():
            zone = h.split(" IDEAL LOADS")[0].strip().upper()
            out[zone] = out.get(zone, 0.0) + float(rows[-1][i]) / 1e9
    return out


clip_idf = os.path.join(out, "clipping-transfer.idf")
open(clip_idf, "w").write(open(os.path.join(out, "clipping.idf")).read() + f"\nOutput:Variable, *, {VAR}, Timestep;\n")
clip = os.path.join(out, "clipping-transfer")
run(clip_idf, clip)
rows = list(csv.reader(open(os.path.join(clip, "eplusout.csv"))))
head = [h.strip().upper() for h in rows[0]]
into = {}
for zone in PAIR:
    i = head.index(f"{zone}:{VAR.upper()} [W](TIMESTEP)")
    into[zone] = [float(r[i]) for r in rows[1:] if i < len(r) and r[i].strip()]

# The balance schedules: zone → (column in the interior beam CSV, window, its area).
hooked = open(os.path.join(out, "interior-beam-own.idf")).read()
areas, zone = {}, None
for line in open(os.path.join(clip, "eplusout.eio")):
    f = [x.strip() for x in line.split(",")]
    if f[0] == "Zone Surfaces":
        zone = f[1]
    elif f[0] == "HeatTransfer Surface" and f[2] == "Window":
        areas[f[1].upper()] = float(f[9])
balance = {}
balance_all = {}
for z in ("ZONE 1", "ZONE 2", "ZONE 3", "ZONE 4"):
    column = int(re.search(rf"Schedule:File,\s*SUNLIT INSIDE BALANCE {z},[^;]*?,\s*(\d+),\s*1,", hooked, re.S).group(1))
    window = re.search(rf"SurfaceProperty:SolarIncidentInside,\s*SUNLIT INSIDE BALANCE {z},\s*([^,]+),", hooked).group(1).strip()
    balance_all[z] = (column, window, areas[window.upper()])
for z in PAIR:
    column = int(re.search(rf"Schedule:File,\s*SUNLIT INSIDE BALANCE {z},[^;]*?,\s*(\d+),\s*1,", hooked, re.S).group(1))
    window = re.search(rf"SurfaceProperty:SolarIncidentInside,\s*SUNLIT INSIDE BALANCE {z},\s*([^,]+),", hooked).group(1).strip()
    balance[z] = (column, window, areas[window.upper()])
beam_csv = os.path.join(out, "interior-beam.interior-beam.csv")
lines = open(beam_csv).read().splitlines()
assert len(lines) - 1 == len(into[PAIR[0]]), (len(lines), len(into[PAIR[0]]))
moved = 0.0
text = [lines[0]]
for t, line in enumerate(lines[1:]):
    cells = line.split(",")
    for z, other in (PAIR, PAIR[::-1]):
        column, _, area = balance[z]
        cells[column - 1] = "%.4f" % (float(cells[column - 1]) + (into[z][t] - into[other][t]) / area)
    moved += into[PAIR[1]][t] + into[PAIR[0]][t]
    text.append(",".join(cells))
new_csv = os.path.join(out, "transfer.interior-beam.csv")
open(new_csv, "w").write("\n".join(text) + "\n")
idf = os.path.join(out, "transfer-own.idf")
open(idf, "w").write(hooked.replace(os.path.realpath(beam_csv), os.path.realpath(new_csv)))
run(idf, os.path.join(out, "transfer"))

# Second: as EnergyPlus's FullInterior books it (`BABSZone += BOverlap * (AbsBeamTotWin +
# TransBeamWin)` for a back surface that is a window), the beam that lands on the back of each of
# a zone's windows, exterior or interzone (EnergyPlus's own `Surface Inside Face Exterior Windows
# Incident Beam Solar Radiation Rate per Area` on the window), taken off the zone's diffuse, and
# the interzone pane's transmitted share handed to the next zone as above.
own = columns(os.path.join(out, "clipping", "eplusout.csv"))
key = ":SURFACE INSIDE FACE EXTERIOR WINDOWS INCIDENT BEAM SOLAR RADIATION RATE PER AREA [W/M2](TIMESTEP)"
on_windows = {}
for name, area in areas.items():
    if name + key in own:
        z = "ZONE %d" % int(name[2:5])
        series = own[name + key]
        prior = on_windows.get(z, [0.0] * len(series))
        on_windows[z] = [p + v * area for p, v in zip(prior, series)]
text = [lines[0]]
removed = 0.0
for t, line in enumerate(lines[1:]):
    cells = line.split(",")
    for z, (column, _, area) in balance_all.items():
        taken = on_windows.get(z, [0.0] * len(lines))[t]
        removed += taken
        cells[column - 1] = "%.4f" % (float(cells[column - 1]) + (into.get(z, [0.0] * len(lines))[t] - taken) / area)
    text.append(",".join(cells))
windows_csv = os.path.join(out, "windows.interior-beam.csv")
open(windows_csv, "w").write("\n".join(text) + "\n")
idf = os.path.join(out, "windows-own.idf")
open(idf, "w").write(hooked.replace(os.path.realpath(beam_csv), os.path.realpath(windows_csv)))
run(idf, os.path.join(out, "windows"))
base = site(os.path.join(out, "clipping"))
for name in ("interior-beam", "transfer", "windows"):
    s = site(os.path.join(out, name))
    print(f"{name}: site energy {s} GJ against the clipping run's {base} GJ: {100 * (s - base) / base:+.3f} %")
print(f"beam moved through the interzone pane: {moved / 4000:.1f} kWh a year (both ways); balances {balance}")
print(f"beam on the zones' windows' backs taken off their diffuse: {removed / 4000:.1f} kWh a year")

# FullExterior: its own clipping and its Scheduled hook fed its own fractions.
fe_idf = os.path.join(out, "clipping-fe.idf")
text = open(os.path.join(out, "clipping.idf")).read()
assert "FullInteriorAndExterior," in text
open(fe_idf, "w").write(text.replace("FullInteriorAndExterior,", "FullExterior,", 1))
run(fe_idf, os.path.join(out, "clipping-fe"))
shading, hooked_fe = os.path.join(out, "scheduled-fe.csv"), os.path.join(out, "scheduled-fe.idf")
subprocess.run([sunlit, "annual", fe_idf, "--epw", epw, "--engine", "exact", "-o", shading, "--idf-out", hooked_fe], check=True, capture_output=True)
run(own_fractions(shading, hooked_fe, os.path.join(out, "clipping-fe"), "scheduled-fe", out), os.path.join(out, "scheduled-fe"))
fe = site(os.path.join(out, "clipping-fe"))
print(f"FullExterior scheduled: {site(os.path.join(out, 'scheduled-fe'))} GJ against its clipping run's {fe} GJ: "
      f"{100 * (site(os.path.join(out, 'scheduled-fe')) - fe) / fe:+.3f} %")
pairs = {"FullExterior scheduled": ("clipping-fe", "scheduled-fe"), "FullInteriorAndExterior scheduled": ("clipping", "scheduled"),
         "  with --interior-beam": ("clipping", "interior-beam"), "  and the interzone transfer": ("clipping", "transfer"),
         "  and the beam on windows taken off": ("clipping", "windows")}
print("per zone, ideal loads heating + cooling gap against the run's own clipping (GJ a year)")
for label, (c, h) in pairs.items():
    a, b = loads(os.path.join(out, c)), loads(os.path.join(out, h))
    print(f"{label:36s} " + "  ".join(f"{z} {b[z] - a[z]:+.4f}" for z in sorted(a)) + f"  total {sum(b.values()) - sum(a.values()):+.4f}")
