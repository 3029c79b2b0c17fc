"""pvsamv1 on a weather file with a Shading group, for check.py and check_points.py."""
import PySAM.Pvsamv1 as Pvsamv1


def run(epw, shading, **change):
    """A flat array's pvsamv1 run with `shading` (changed by `change`) assigned as written."""
    model = Pvsamv1.default("FlatPlatePVNone")
    model.SolarResource.solar_resource_file = epw
    model.SystemDesign.subarray1_tilt = 0
    model.Losses.subarray1_soiling = [0] * 12  # the beam factor is shading × soiling
    model.Shading.assign(dict(shading, **change))
    model.execute(0)
    return model  # outputs live while the model does


def applied(epw, shading, out):
    """Runs pvsamv1 with `shading` and without its diffuse loss; records in `out` how far its beam
    shading factor is from 1 − the timestep table's loss at any hour, and the diffuse factor it
    applied. Returns the run, its beam factors and the table's losses (0..1)."""
    import numpy as np

    timestep = run(epw, shading)
    factor = np.array(timestep.Outputs.subarray1_beam_shading_factor)
    loss = np.array([row[0] for row in shading["subarray1_shading_timestep"]]) / 100
    out["sam_timestep_max_error"] = float(np.abs(factor - (1 - loss)).max())
    no_diffuse = run(epw, shading, subarray1_shading_en_diff=0)
    diffuse = np.array(timestep.Outputs.subarray1_poa_eff_diff)
    open_diffuse = np.array(no_diffuse.Outputs.subarray1_poa_eff_diff)
    lit = open_diffuse > 1
    out["sam_diffuse_factor"] = float((diffuse[lit] / open_diffuse[lit]).mean())
    out["sam_diffuse_loss_percent"] = shading["subarray1_shading_diff"]
    return timestep, factor, loss
