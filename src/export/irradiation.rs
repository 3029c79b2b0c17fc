//! Solar irradiation per receiver: beam, sky diffuse and ground-reflected, per timestep (W/m²,
//! the `--irradiance` CSV) and summed over the year (kWh/m², the summary).
//!
//! Owns how the three parts are combined at a timestep, from the weather's hour
//! ([`crate::sun::weather`]), the year's sunlit fractions ([`Schedule`]) and the receiver's sky
//! views ([`crate::sky::views`]):
//! - beam: DNI·cos θ·fraction;
//! - sky diffuse: the Perez 1990 sky ([`crate::sky::perez`]): isotropic part weighted by the
//!   visible patches, circumsolar part shaded like the beam, horizon band by its visibility; or,
//!   with views kept for a luminance distribution ([`crate::sky::model`]), each patch's radiance
//!   that hour times the receiver's visible ∫cos dΩ of it;
//! - ground-reflected: GHI·albedo·(1 − cos tilt)/2, unobstructed, as EnergyPlus does it.
//!
//! **Instants.** The sun is [`shading_sun_day`]'s day at the timestep's instant (mid-hour with
//! one timestep an hour, else each timestep's end), and a timestep counts only with that sun up
//! (cos zenith ≥ [`MIN_COS_INCIDENCE`], EnergyPlus's rule); at other times nothing is incident.
//! The beam's incidence is that of the sun the fractions were counted for
//! ([`Schedule::fraction_sun`]): the same sun, except under EnergyPlus's `Periodic` update, where
//! EnergyPlus's incident beam is `BeamSolarRad · SunlitFrac · CosIncAng`, both factors from the
//! period's sun (`CalcPerSolarBeam`; HeatBalanceSurfaceManager.cc's `InitSolarHeatGains`), while
//! whether the sun is up is the weather's calendar day (`SunIsUp`). The sky and ground keep the
//! calendar day's sun. The weather's hour is held over its timesteps ([`Weather::at`]): each
//! hour's energy is kept whatever the timestep count.
//!
//! The per-surface summary (mean fraction; direct, sky diffuse, ground-reflected, total and
//! unshaded total irradiation; sky view factor; EnergyPlus's two diffuse shading ratios) is
//! written as JSON or CSV.

use std::fmt::Write as _;

use crate::count::MIN_COS_INCIDENCE;
use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::scene::{Receiver, Scene};
pub use crate::sky::energyplus::EnergyPlusRatios;
use crate::sky::perez::PerezSky;
use crate::sky::views::SkyViews;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::sun::weather::Weather;
use crate::year::annual::shading_sun_day;
use crate::year::season::LeafCalendar;

/// What total irradiance needs beside the fractions: the weather, the sky views and the leaf
/// calendar the views follow.
#[derive(Debug, Clone, Copy)]
pub struct Solar<'a> {
    /// Hourly DNI, DHI, GHI and albedo.
    pub weather: &'a Weather,
    /// Every receiver's sky views (receivers in the scene's order).
    pub sky: &'a SkyViews,
    /// The leaf calendar (foliage between bare and full leaf).
    pub calendar: &'a LeafCalendar,
}

/// One receiver's irradiance at one timestep, W/m².
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Incident {
    /// Beam, shaded.
    pub direct: f64,
    /// Beam with nothing in the way.
    pub unshaded_direct: f64,
    /// Sky diffuse, shaded.
    pub sky_diffuse: f64,
    /// Ground-reflected (unobstructed).
    pub ground_reflected: f64,
    /// Beam, sky and ground with nothing in the way.
    pub unshaded_total: f64,
}

impl Incident {
    /// Beam, sky and ground, shaded.
    pub fn total(&self) -> f64 {
        self.direct + self.sky_diffuse + self.ground_reflected
    }
}

/// Calls `each(row, column, incident)` for every receiver at every timestep with the sun up.
/// Columns are the scene's receivers, in order.
fn for_each_incident(
    scene: &Scene,
    schedule: &Schedule,
    location: &Location,
    solar: &Solar<'_>,
    each: impl FnMut(usize, usize, &Incident),
) -> Result<()> {
    check_columns(scene, schedule)?;
    for_each_incident_from(scene, 0, schedule, location, solar, each)
}

/// [`for_each_incident`] for a schedule whose columns are the scene's receivers from `first`
/// on (a batch of a city's, [`summarize_from`]); `each` gets the schedule's column.
fn for_each_incident_from(
    scene: &Scene,
    first: usize,
    schedule: &Schedule,
    location: &Location,
    solar: &Solar<'_>,
    mut each: impl FnMut(usize, usize, &Incident),
) -> Result<()> {
    let receivers = columns_from(scene, first, schedule)?;
    if solar.sky.receivers() != scene.receivers.len() {
        return Err(Error::argument("sky", format!("sky views of {} receivers for {}", solar.sky.receivers(), scene.receivers.len())));
    }
    let distribution = solar.sky.model().on(&solar.sky.patches);
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        // The calendar day's sun says whether it is up (EnergyPlus's SunIsUp) and places the
        // sky; the beam's incidence is that of the sun the fractions were counted for (its
        // CosIncAng), which differs under a Periodic update.
        let sun = sun_direction(location, shading_sun_day(instant.day), instant.hour);
        if sun.z < MIN_COS_INCIDENCE {
            continue;
        }
        let beam_sun = schedule.fraction_sun(location, row);
        let hour = solar.weather.at(schedule.timesteps, row);
        let perez = PerezSky::new(hour.dni, hour.dhi, sun.z, location.elevation);
        let radiances = distribution.as_ref().and_then(|d| d.radiances(hour.dni, hour.dhi, sun, instant.day));
        let leaves = solar.calendar.fraction(f64::from(instant.day));
        for (c, receiver) in receivers.iter().enumerate() {
            let fraction = f64::from(schedule.get(row, c));
            // The sky views are the whole scene's.
            let r = first + c;
            let cos = receiver.normal.dot(sun).max(0.0);
            let sin_tilt = receiver.normal.truncate().length();
            let ground = hour.ghi * hour.albedo * (1.0 - receiver.normal.z) / 2.0;
            let (sky, unshaded_sky) = match (&radiances, perez) {
                (Some(radiances), _) => (solar.sky.distribution_diffuse(r, leaves, radiances), solar.sky.distribution_open(r, radiances)),
                (None, _) if distribution.is_some() => (0.0, 0.0),
                (None, Some(p)) => (
                    p.diffuse(hour.dhi, cos, solar.sky.isotropic(r, leaves), fraction, sin_tilt, solar.sky.horizon(r, leaves)),
                    p.diffuse(hour.dhi, cos, solar.sky.unobstructed(r), if cos > 0.0 { 1.0 } else { 0.0 }, sin_tilt, 1.0),
                ),
                (None, None) => (0.0, 0.0),
            };
            let unshaded_direct = hour.dni * receiver.normal.dot(beam_sun).max(0.0);
            let incident = Incident {
                direct: unshaded_direct * fraction,
                unshaded_direct,
                sky_diffuse: sky,
                ground_reflected: ground,
                unshaded_total: unshaded_direct + unshaded_sky + ground,
            };
            each(row, c, &incident);
        }
    }
    Ok(())
}

fn check_columns(scene: &Scene, schedule: &Schedule) -> Result<()> {
    if schedule.names.len() != scene.receivers.len() {
        return Err(Error::argument(
            "schedule",
            format!("{} columns for {} receivers of the scene", schedule.names.len(), scene.receivers.len()),
        ));
    }
    Ok(())
}

/// The scene's receivers that `schedule`'s columns are, from `first` on: refused where they
/// leave the scene.
fn columns_from<'a>(scene: &'a Scene, first: usize, schedule: &Schedule) -> Result<&'a [Receiver]> {
    let columns = schedule.names.len();
    scene.receivers.get(first..first + columns).ok_or_else(|| {
        Error::argument("schedule", format!("columns {first}..{} for {} receivers of the scene", first + columns, scene.receivers.len()))
    })
}

/// Total incident solar (W/m², shaded) per receiver per timestep, in the schedule's layout:
/// a header `Surface Name,NAME,…,`, then ` MM/DD HH:MM,v,…,` per row (2 decimals).
pub fn irradiance_csv(scene: &Scene, schedule: &Schedule, location: &Location, solar: &Solar<'_>) -> Result<Vec<u8>> {
    let columns = schedule.names.len();
    let mut totals = vec![0.0f64; schedule.timesteps.rows() * columns];
    for_each_incident(scene, schedule, location, solar, |row, c, incident| totals[row * columns + c] = incident.total())?;
    let mut text = String::with_capacity(totals.len() * 8 + 64);
    text.push_str("Surface Name,");
    for name in &schedule.names {
        text.push_str(name);
        text.push(',');
    }
    text.push('\n');
    for (row, values) in totals.chunks_exact(columns.max(1)).enumerate() {
        text.push_str(&schedule.timesteps.stamp(row));
        for v in values {
            let _ = write!(text, ",{v:.2}");
        }
        text.push_str(",\n");
    }
    Ok(text.into_bytes())
}

/// A receiver's year in one line.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceSummary {
    /// Column name.
    pub name: String,
    /// m².
    pub area: f64,
    /// Mean sunlit fraction over the year's sun-up timesteps (sun above the horizon).
    pub mean_fraction: f64,
    /// Σ DNI·cos θ·fraction·Δt, kWh/m² (with weather): the beam, shaded.
    pub irradiation: Option<f64>,
    /// Σ DNI·cos θ·Δt, kWh/m²: the same surface with nothing in the way.
    pub unshaded_irradiation: Option<f64>,
    /// Sky diffuse, shaded, kWh/m².
    pub sky_diffuse: Option<f64>,
    /// Ground-reflected, kWh/m².
    pub ground_reflected: Option<f64>,
    /// Beam + sky diffuse + ground-reflected, shaded, kWh/m².
    pub total: Option<f64>,
    /// The same with nothing in the way, kWh/m².
    pub unshaded_total: Option<f64>,
    /// View factor to the visible sky (the year's mean over the leaf calendar).
    pub sky_view_factor: Option<f64>,
    /// EnergyPlus's `DifShdgRatioIsoSky` and `DifShdgRatioHoriz` from the casters it sees.
    pub energyplus: Option<EnergyPlusRatios>,
}

/// Every column's summary. `scene` gives each column's normal and area (columns are the scene's
/// receivers, in order); `sky` the sky views (for the sky view factor) and `solar` the weather
/// (irradiation fields are `None` without it); `energyplus` EnergyPlus's ratios per receiver.
pub fn summarize(
    scene: &Scene,
    schedule: &Schedule,
    location: &Location,
    sky: Option<(&SkyViews, &LeafCalendar)>,
    weather: Option<&Weather>,
    energyplus: &[Option<EnergyPlusRatios>],
) -> Result<Vec<SurfaceSummary>> {
    check_columns(scene, schedule)?;
    summarize_from(scene, 0, schedule, location, sky, weather, energyplus)
}

/// [`summarize`] for a schedule whose columns are the scene's receivers from `first` on: a batch
/// of a city's receivers, its year counted alone ([`crate::year::annual::annual_receivers_with`]).
/// Each column's sums run over the rows in the same order, so a receiver's summary is the one
/// the whole schedule gives it, bit for bit. `sky` holds the whole scene's views and
/// `energyplus` the whole scene's ratios.
pub fn summarize_from(
    scene: &Scene,
    first: usize,
    schedule: &Schedule,
    location: &Location,
    sky: Option<(&SkyViews, &LeafCalendar)>,
    weather: Option<&Weather>,
    energyplus: &[Option<EnergyPlusRatios>],
) -> Result<Vec<SurfaceSummary>> {
    let receivers = columns_from(scene, first, schedule)?;
    let columns = schedule.names.len();
    let hours_per_step = 1.0 / f64::from(schedule.timesteps.per_hour());
    let (mut fraction_sums, mut sun_up_rows) = (vec![0.0; columns], 0usize);
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        if sun_direction(location, shading_sun_day(instant.day), instant.hour).z < MIN_COS_INCIDENCE {
            continue;
        }
        sun_up_rows += 1;
        for (c, sum) in fraction_sums.iter_mut().enumerate() {
            *sum += f64::from(schedule.get(row, c));
        }
    }
    let mut sums = vec![Incident::default(); columns];
    let energy = match (sky, weather) {
        (Some((views, calendar)), Some(weather)) => {
            let solar = Solar { weather, sky: views, calendar };
            for_each_incident_from(scene, first, schedule, location, &solar, |_, c, i| {
                let s = &mut sums[c];
                s.direct += i.direct;
                s.unshaded_direct += i.unshaded_direct;
                s.sky_diffuse += i.sky_diffuse;
                s.ground_reflected += i.ground_reflected;
                s.unshaded_total += i.unshaded_total;
            })?;
            true
        }
        (None, Some(_)) => return Err(Error::argument("sky", "irradiation needs the receivers' sky views")),
        _ => false,
    };
    let kwh = |wh: f64| energy.then_some(wh * hours_per_step / 1000.0);
    let days = schedule.timesteps.days();
    Ok(receivers
        .iter()
        .enumerate()
        .map(|(c, r)| {
            let s = &sums[c];
            SurfaceSummary {
                name: schedule.names[c].clone(),
                area: r.area,
                mean_fraction: if sun_up_rows == 0 { 0.0 } else { fraction_sums[c] / sun_up_rows as f64 },
                irradiation: kwh(s.direct),
                unshaded_irradiation: kwh(s.unshaded_direct),
                sky_diffuse: kwh(s.sky_diffuse),
                ground_reflected: kwh(s.ground_reflected),
                total: kwh(s.total()),
                unshaded_total: kwh(s.unshaded_total),
                sky_view_factor: sky.map(|(views, calendar)| {
                    (1..=days).map(|d| views.isotropic(first + c, calendar.fraction(f64::from(d)))).sum::<f64>() / f64::from(days)
                }),
                energyplus: energyplus.get(first + c).copied().flatten(),
            }
        })
        .collect())
}

/// The summary as JSON: `{"units":…, "surfaces":[{"name","area","mean_fraction","direct",
/// "irradiation" (= direct), "unshaded_irradiation", "sky_diffuse", "ground_reflected", "total",
/// "unshaded_total", "sky_view_factor", "energyplus_iso_sky_ratio", "energyplus_horizon_ratio"}]}`
/// (irradiation in kWh/m², `null` without weather; the ratios `null` for a receiver EnergyPlus
/// does not have).
pub fn summary_json(summaries: &[SurfaceSummary]) -> String {
    let surfaces: Vec<serde_json::Value> = summaries
        .iter()
        .map(|s| {
            serde_json::json!({
                "name": s.name,
                "area": s.area,
                "mean_fraction": s.mean_fraction,
                "direct": s.irradiation,
                "irradiation": s.irradiation,
                "unshaded_irradiation": s.unshaded_irradiation,
                "sky_diffuse": s.sky_diffuse,
                "ground_reflected": s.ground_reflected,
                "total": s.total,
                "unshaded_total": s.unshaded_total,
                "sky_view_factor": s.sky_view_factor,
                "energyplus_iso_sky_ratio": s.energyplus.map(|e| e.iso_sky),
                "energyplus_horizon_ratio": s.energyplus.map(|e| e.horizon),
            })
        })
        .collect();
    let units = serde_json::json!({ "area": "m2", "irradiation": "kWh/m2", "sky_view_factor": "1", "energyplus_iso_sky_ratio": "1" });
    let mut text = serde_json::json!({ "units": units, "surfaces": surfaces }).to_string();
    text.push('\n');
    text
}

/// The CSV summary's header: the first five columns as before, the split after them.
pub const SUMMARY_CSV_HEADER: &str = "name,area_m2,mean_fraction,irradiation_kwh_m2,unshaded_irradiation_kwh_m2,direct_kwh_m2,\
sky_diffuse_kwh_m2,ground_reflected_kwh_m2,total_kwh_m2,unshaded_total_kwh_m2,sky_view_factor,energyplus_iso_sky_ratio,energyplus_horizon_ratio";

/// The summary as CSV: a header, then one line per surface (empty fields where a value is
/// `null` in the JSON). Names cannot hold commas or quotes ([`Schedule::validate`] refuses them).
pub fn summary_csv(summaries: &[SurfaceSummary]) -> String {
    let mut text = String::from(SUMMARY_CSV_HEADER);
    text.push('\n');
    let energy = |v: Option<f64>| v.map(|v| format!("{v:.4}")).unwrap_or_default();
    let ratio = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
    for s in summaries {
        let _ = writeln!(
            text,
            "{},{:.6},{:.6},{},{},{},{},{},{},{},{},{},{}",
            s.name,
            s.area,
            s.mean_fraction,
            energy(s.irradiation),
            energy(s.unshaded_irradiation),
            energy(s.irradiation),
            energy(s.sky_diffuse),
            energy(s.ground_reflected),
            energy(s.total),
            energy(s.unshaded_total),
            ratio(s.sky_view_factor),
            ratio(s.energyplus.map(|e| e.iso_sky)),
            ratio(s.energyplus.map(|e| e.horizon)),
        );
    }
    text
}

#[cfg(test)]
#[path = "irradiation_tests.rs"]
mod tests;
