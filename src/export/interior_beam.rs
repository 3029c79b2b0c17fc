//! The interior beam handed to EnergyPlus: the CSV of [`InteriorBeam`] (W/m² on each inside face
//! per timestep, and each zone's balance) and the `Schedule:File` and
//! `SurfaceProperty:SolarIncidentInside` objects that read it, appended to a model the Scheduled
//! hook ([`super::hook`]) has patched.

use std::fmt::Write as _;

use super::hook::object;
use crate::year::interior_beam::InteriorBeam;
use crate::year::samples::Timesteps;

/// Schedule type limits of the interior beam schedules: none (the balance is negative).
const INSIDE_LIMITS: &str = "SUNLIT INSIDE SOLAR";

/// The interior beam CSV: a time stamp column as the sunlit fraction CSV's, then one column per
/// inside face and one per zone balance (W/m², 3 decimals), headed by the surface names.
pub fn interior_beam_csv(beam: &InteriorBeam, timesteps: Timesteps) -> String {
    let mut out = String::from("Date/Time");
    for name in beam.faces.iter().map(|f| &f.surface).chain(beam.balances.iter().map(|b| &b.window)) {
        out.push(',');
        out.push_str(name);
    }
    out.push('\n');
    let columns: Vec<&Vec<f64>> = beam.faces.iter().map(|f| &f.watts_m2).chain(beam.balances.iter().map(|b| &b.watts_m2)).collect();
    for row in 0..timesteps.rows() {
        out.push_str(&timesteps.stamp(row));
        for c in &columns {
            // + 0.0: a value rounding to zero prints as 0.000, never -0.000.
            let _ = write!(out, ",{:.3}", (c[row] * 1000.0).round() / 1000.0 + 0.0);
        }
        out.push('\n');
    }
    out
}

/// The objects that make EnergyPlus read the interior beam CSV at `csv`: per column a
/// `Schedule:File` and a `SurfaceProperty:SolarIncidentInside` for its surface and construction.
///
/// What EnergyPlus 25.2 does with them (SolarShading.cc `CalcInteriorSolarDistribution`, and
/// measured on a box room: a constant 100 W/m² on a wall whose inside absorptance is 0.7 adds
/// 70 W/m² absorbed on it while the sun is up, and 0 at night):
/// - the value is the solar incident on the inside face, W/m²; EnergyPlus applies the
///   construction's inside solar absorptance itself, and the reflected rest joins the zone's
///   diffuse;
/// - it *replaces* what EnergyPlus's own distribution put on that face (`AISurf = value · α`),
///   and is read only while the sun is up;
/// - the transmitted beam still enters the zone by EnergyPlus's own path: under the Scheduled
///   method with `FullInteriorAndExterior` all of it becomes diffuse (no back surfaces), so the
///   beam would count twice. The zone's balance column takes it back: on one exterior window
///   (whose inside absorptance EnergyPlus takes as 0, so all of it goes to the zone's diffuse) it
///   is minus all the beam the zone's exterior windows let in, in W/m² of that window. The zone
///   then keeps EnergyPlus's own transmitted beam where sunlit found it landing on its faces; what
///   lands on the back of a window leaves, as FullInterior books it.
pub fn interior_beam_objects(csv: &str, beam: &InteriorBeam, timesteps: Timesteps) -> String {
    let minutes = (60 / timesteps.per_hour()).to_string();
    let hours = (24 * timesteps.days()).to_string();
    let mut out = format!("\n! ---- Added by sunlit: the beam through exterior windows onto inside faces, from {csv} ----\n");
    object(&mut out, "ScheduleTypeLimits", &[INSIDE_LIMITS, "", "", "Continuous"]);
    let pairs = beam
        .faces
        .iter()
        .map(|f| (f.surface.as_str(), f.construction.as_str(), format!("SUNLIT INSIDE {}", f.surface)))
        .chain(beam.balances.iter().map(|b| (b.window.as_str(), b.construction.as_str(), format!("SUNLIT INSIDE BALANCE {}", b.zone))));
    for (k, (surface, construction, schedule)) in pairs.enumerate() {
        let column = (k + 2).to_string();
        object(&mut out, "Schedule:File", &[&schedule, INSIDE_LIMITS, csv, &column, "1", &hours, "Comma", "No", &minutes, "No"]);
        object(&mut out, "SurfaceProperty:SolarIncidentInside", &[&schedule, surface, construction, &schedule]);
    }
    out
}
