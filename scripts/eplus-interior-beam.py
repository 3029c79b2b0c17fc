#!/usr/bin/env python3
"""The interior beam's figures on 4ZoneWithShading_Simple_1 (docs/energyplus-fidelity.md).

Usage: scripts/eplus-interior-beam.py SUNLIT ENERGYPLUS EPW OUTDIR

The test file set to FullInteriorAndExterior and run annually with EnergyPlus's own clipping
(Timestep updates); then hooked by `sunlit annual --idf-out` without and with
`--interior-beam`, each hooked copy fed EnergyPlus's *own* reported sunlit fractions (so only
the Scheduled method's own gap is left), and run. Prints annual site energy against the clipping
run, and per inside surface the annual beam EnergyPlus's clipping reports (`Surface Inside Face
Exterior Windows Incident Beam Solar Radiation Rate per Area`) against sunlit's schedule.
Then the gap term by term: per zone, each run's annual ideal-loads heating and cooling and the
solar terms EnergyPlus reports (RunPeriod sums, GJ) — where the interior beam's change lands.
"""
import csv
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from eplus_hooked import columns, own_fractions, site  # noqa: E402

sunlit, energyplus, epw, out = sys.argv[1:5]
here = os.path.dirname(os.path.abspath(__file__))
os.makedirs(out, exist_ok=True)


# The terms of the site energy and of the zones' solar balance, summed over the year (J).
TERMS = (
    "Zone Ideal Loads Zone Total Heating Energy",
    "Zone Ideal Loads Zone Total Cooling Energy",
    "Enclosure Exterior Windows Total Transmitted Beam Solar Radiation Energy",
    "Enclosure Exterior Windows Total Transmitted Diffuse Solar Radiation Energy",
    "Enclosure Interior Windows Total Transmitted Beam Solar Radiation Energy",
    "Enclosure Interior Windows Total Transmitted Diffuse Solar Radiation Energy",
    "Surface Inside Face Interior Windows Incident Beam Solar Radiation Energy",
    "Surface Window Total Glazing Layers Absorbed Solar Radiation Energy",
    "Surface Window Heat Gain Energy",
    "Surface Window Heat Loss Energy",
    "Surface Inside Face Solar Radiation Heat Gain Energy",
)


def model():
    t = open(os.path.join(here, "../tests/energyplus_testfiles/4ZoneWithShading_Simple_1.idf")).read()
    dd = "    Yes,                     !- Run Simulation for Sizing Periods\n    No,                      !- Run Simulation for Weather File Run Periods"
    wf = "    No,                      !- Run Simulation for Sizing Periods\n    Yes,                     !- Run Simulation for Weather File Run Periods"
    assert dd in t and "FullExterior," in t, "the test file is not in the layout expected here"
    t = t.replace(dd, wf, 1)
    t = t.replace("FullExterior,", "FullInteriorAndExterior,", 1)
    t += "\nShadowCalculation, PolygonClipping, Timestep, 1, 15000, SutherlandHodgman, 512, SimpleSkyDiffuseModeling, Yes;\n"
    t += "Output:Table:SummaryReports, AllSummary;\nOutputControl:Table:Style, Comma;\n"
    t += "Output:Variable, *, Surface Outside Face Sunlit Fraction, Timestep;\n"
    t += "Output:Variable, *, Surface Inside Face Exterior Windows Incident Beam Solar Radiation Rate per Area, Timestep;\n"
    for name in TERMS:
        t += f"Output:Variable, *, {name}, RunPeriod;\n"
    return t


def run(idf, d):
    subprocess.run([energyplus, "-r", "-w", epw, "-d", d, idf], check=True, capture_output=True)


clip_idf = os.path.join(out, "clipping.idf")
open(clip_idf, "w").write(model())
clip = os.path.join(out, "clipping")
run(clip_idf, clip)
gaps = {}
for name, extra in (("scheduled", []), ("interior-beam", ["--interior-beam"])):
    shading, hooked = os.path.join(out, name + ".csv"), os.path.join(out, name + ".idf")
    subprocess.run([sunlit, "annual", clip_idf, "--epw", epw, "--engine", "exact", "-o", shading, "--idf-out", hooked] + extra,
                   check=True, capture_output=True)
    run(own_fractions(shading, hooked, clip, name, out), os.path.join(out, name))
    gaps[name] = 100 * (site(os.path.join(out, name)) - site(clip)) / site(clip)
    print(f"{name}: site energy {site(os.path.join(out, name))} GJ against the clipping run's {site(clip)} GJ: {gaps[name]:+.3f} %")
theirs = columns(os.path.join(clip, "eplusout.csv"))
ours = columns(os.path.join(out, "interior-beam.interior-beam.csv"))
key = ":SURFACE INSIDE FACE EXTERIOR WINDOWS INCIDENT BEAM SOLAR RADIATION RATE PER AREA [W/M2](TIMESTEP)"
print("inside face, annual incident beam kWh/m2: EnergyPlus's clipping, sunlit")
for name, values in ours.items():
    if name + key in theirs:
        e, s = sum(theirs[name + key]) / 4000, sum(values) / 4000
        if e > 0.5 or s > 0.5:
            print(f"{name:22s} {e:8.2f} {s:8.2f} ({100 * (s - e) / e:+.1f} %)")


def sums(d):
    """Each RunPeriod term of run `d` (GJ) by (variable, object), from eplusout.csv's last row."""
    rows = list(csv.reader(open(os.path.join(d, "eplusout.csv"))))
    out = {}
    for i, h in enumerate(rows[0][1:], 1):
        if "(RunPeriod)" in h and rows[-1][i].strip():
            obj, var = h.rsplit(":", 1)
            out[(var.split(" [")[0].strip(), obj.strip().upper())] = float(rows[-1][i]) / 1e9
    return out


runs = {"clipping": sums(clip), "scheduled": sums(os.path.join(out, "scheduled")), "interior-beam": sums(os.path.join(out, "interior-beam"))}
print("term (GJ a year), object: clipping, scheduled, interior-beam (interior-beam − clipping)")
for key in sorted(set().union(*runs.values())):
    v = [runs[r].get(key, 0.0) for r in runs]
    if max(abs(x) for x in v) > 1e-4:
        print(f"{key[0]:72s} {key[1]:30s} {v[0]:9.4f} {v[1]:9.4f} {v[2]:9.4f} ({v[2] - v[0]:+.4f})")
