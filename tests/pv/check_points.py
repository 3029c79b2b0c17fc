"""Reads `sunlit map --pvlib/--sam` (a grid's points) with pvlib and NREL-PySAM, and recounts the
shading with an independent numpy ray cast against the test's one box caster: each point's ray
towards the sun (pvlib's SPA at the middle of the hour, or the SAM table's own direction) through
a slab test. Prints what it found as JSON (tests/pv.rs holds the numbers to their truths).

Usage: python check_points.py SETUP.json,
SETUP = {"epw", "pvlib", "sam", "points" (the map's points CSV), "box": [[x0, y0, z0], [x1, y1, z1]]}.
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
points = pd.read_csv(setup["points"])
P = points[["x", "y", "z"]].to_numpy()
N = points[["nx", "ny", "nz"]].to_numpy()
lo, hi = (np.array(c, dtype=float) for c in setup["box"])


def visible(d):
    """1 where a point's ray along d (unit, towards the sun) misses the box, else 0."""
    d = np.where(np.abs(d) < 1e-12, 1e-12, d)
    t1, t2 = (lo - P) / d, (hi - P) / d
    near = np.minimum(t1, t2).max(axis=1)
    far = np.maximum(t1, t2).min(axis=1)
    return (~(far >= np.maximum(near, 1e-9))).astype(float)


def direction(azimuth_deg, zenith_deg):
    az, zen = math.radians(azimuth_deg), math.radians(zenith_deg)
    return np.array([math.sin(az) * math.sin(zen), math.cos(az) * math.sin(zen), math.cos(zen)])


# pvlib: the CSV on the weather's own index; each point's shaded fraction against the ray cast.
shaded = pd.read_csv(setup["pvlib"], index_col="time", parse_dates=True)
weather, meta = pvlib.iotools.read_epw(setup["epw"], coerce_year=shaded.index[0].year)
out["index_equal"] = bool(shaded.index.equals(weather.index))
out["columns"] = list(shaded.columns[:2]) + [len(shaded.columns)]
sun = pvlib.solarposition.get_solarposition(shaded.index + pd.Timedelta(minutes=30), meta["latitude"], meta["longitude"])
values = shaded.to_numpy()
# Hours with the sun clearly up (1° or more), so the two suns agree on which hours count.
up = np.flatnonzero(sun["zenith"].to_numpy() < 89)
truth = np.zeros((len(up), len(P)))
set_truth = np.zeros(len(up))
for k, row in enumerate(up):
    d = direction(sun["azimuth"].iloc[row], sun["zenith"].iloc[row])
    cos = N @ d
    v = visible(d)
    truth[k] = np.where(cos > 0, 1 - v, 0)
    front = cos > 0
    set_truth[k] = 1 - (cos * v)[front].sum() / cos[front].sum() if front.any() else 0
out["cells"] = int(truth.size)
out["shaded_cells"] = int((truth > 0.5).sum())
out["cell_agreement"] = float((np.abs(values[up] - truth) < 0.5).mean())
out["cell_agreement_hour_later"] = float((np.abs(values[up - 1] - truth) < 0.5).mean())

# SAM: the Shading group as written; what pvsamv1 applies; the set's loss against the ray cast.
sam = json.load(open(setup["sam"]))
out["sam_points"] = len(sam["sunlit"]["points"])
sam = sam["Shading"]
timestep, factor, loss = pysam_run.applied(setup["epw"], sam, out)
out["sam_set_loss_error"] = float(np.abs(loss[up] - set_truth).mean())
out["sam_set_loss_hour_later_error"] = float(np.abs(loss[up - 1] - set_truth).mean())
out["sam_set_loss_mean"] = float(set_truth.mean())

# The azimuth × altitude table: each cell recounted along its own direction (the 0° row at 1°).
azal = np.array(sam["subarray1_shading_azal"])
errors = []
for i, altitude in enumerate(azal[1:, 0]):
    for j, azimuth in enumerate(azal[0, 1:]):
        d = direction(azimuth, 90 - max(altitude, 1.0))
        cos = N @ d
        front = cos > 1e-5
        truth_loss = 100 * (1 - (cos * visible(d))[front].sum() / cos[front].sum()) if front.any() else 0
        errors.append(abs(azal[i + 1, j + 1] - truth_loss))
out["azal_max_error_percent"] = float(max(errors))
out["azal_shaded_cells"] = int((azal[1:, 1:] > 0).sum())
print(json.dumps(out))
