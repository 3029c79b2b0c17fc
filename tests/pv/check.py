"""Reads sunlit's PV outputs with pvlib and NREL-PySAM, as docs/district.md shows, and prints
what reached them as JSON (tests/pv.rs holds the numbers to their truths).

Usage: python check.py SETUP.json, SETUP = {"epw", "pvlib", "sam", "summary", "normals": {name: [x, y, z]}}.
"""
import json
import math
import sys

import numpy as np
import pandas as pd
import pvlib
import PySAM

import pysam_run

setup = json.load(open(sys.argv[1]))
out = {"pvlib_version": pvlib.__version__, "pysam_version": PySAM.__version__}

# pvlib: the CSV on the weather's own index, the beam on each surface shaded by it.
shaded = pd.read_csv(setup["pvlib"], index_col="time", parse_dates=True)
weather, meta = pvlib.iotools.read_epw(setup["epw"], coerce_year=shaded.index[0].year)
out["index_equal"] = bool(shaded.index.equals(weather.index))
# Each row holds for its hour; the sun at its middle.
sun = pvlib.solarposition.get_solarposition(shaded.index + pd.Timedelta(minutes=30), meta["latitude"], meta["longitude"])
sun.index = shaded.index
out["surfaces"] = {}
for name, (x, y, z) in setup["normals"].items():
    tilt, azimuth = math.degrees(math.acos(z)), math.degrees(math.atan2(x, y)) % 360
    aoi = pvlib.irradiance.aoi(tilt, azimuth, sun["zenith"], sun["azimuth"])
    cos = np.cos(np.radians(aoi)).clip(lower=0).where(sun["zenith"] < 90, 0)
    beam = weather["dni"] * cos
    out["surfaces"][name] = {
        "shaded_kwh_m2": float((beam * (1 - shaded[name])).sum() / 1000),
        "unshaded_kwh_m2": float(beam.sum() / 1000),
        "shaded_hour_later_kwh_m2": float((beam * (1 - shaded[name].shift(1, fill_value=0))).sum() / 1000),
    }

# SAM: the Shading group assigned as written; what pvsamv1 then applies.
sam = json.load(open(setup["sam"]))["Shading"]


def run(**change):
    return pysam_run.run(setup["epw"], sam, **change)


timestep, factor, loss = pysam_run.applied(setup["epw"], sam, out)
beam = np.array(timestep.Outputs.subarray1_poa_eff_beam) > 1


def beam_error(**change):
    model = run(subarray1_shading_en_timestep=0, **change)
    other = np.array(model.Outputs.subarray1_beam_shading_factor)
    return float(np.abs(other[beam] - factor[beam]).mean())


azal = sam["subarray1_shading_azal"]
mxh = sam["subarray1_shading_mxh"]
out["sam_azal_error"] = beam_error(subarray1_shading_en_azal=1)
out["sam_azal_mirrored_error"] = beam_error(
    subarray1_shading_en_azal=1, subarray1_shading_azal=[azal[0]] + [[r[0]] + r[1:][::-1] for r in azal[1:]]
)
out["sam_mxh_error"] = beam_error(subarray1_shading_en_mxh=1)
out["sam_mxh_hour_later_error"] = beam_error(subarray1_shading_en_mxh=1, subarray1_shading_mxh=[r[-1:] + r[:-1] for r in mxh])
print(json.dumps(out))
