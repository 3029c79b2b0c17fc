//! What PV tools read: the beam shaded fraction of a selected set of receivers (`annual`) or of
//! a map's points (`map`), per timestep, for pvlib (a CSV on pvlib's time index) and for SAM's
//! detailed PV model `pvsamv1` (its `subarray1_shading_*` inputs as JSON).
//!
//! Owns the definitions (docs/district.md shows the pvlib and PySAM code that reads them), over
//! a [`PvSet`] of members (receivers, or points with their own normals and visibilities):
//! - **beam shaded fraction** of a member at a timestep: 1 − its sunlit fraction (a point's
//!   visibility) while the sun is up and in front of it (cos zenith and cos incidence ≥
//!   [`MIN_COS_INCIDENCE`], the fractions' own rule); 0 otherwise, as there is no beam to lose;
//! - **a set's beam loss** (SAM's one array): 1 − Σ area·fraction·cos θ / Σ area·cos θ over its
//!   members facing the sun, i.e. the share of the set's unshaded beam that is shaded (for one
//!   member, its shaded fraction); 0 when none faces the sun. A grid's points each stand for
//!   spacing² of surface; points from a CSV weigh alike;
//! - **pvlib's time index**: each row labelled with the start of its timestep in local standard
//!   time with the UTC offset (`2023-01-01T00:00:00+01:00`), as `pvlib.iotools.read_epw` labels
//!   the EPW's hours (hour − 1). The value holds for the whole timestep; it was counted at its
//!   middle (one timestep an hour) or its end (more), the sun the shading schedules use;
//! - **SAM**: `subarray1_shading_timestep` (8760 × N rows of one column, beam loss %; a leap
//!   year's Feb 29 is left out, as SAM's years have 365 days), `_mxh` (12 × 24, each month's and
//!   clock hour's mean loss over its timesteps with the sun in front), `_azal` (SAM's table: first
//!   row azimuths 0..360° clockwise from north, first column altitudes, the rest beam loss % for
//!   a sun there, counted by the engine for each direction, [`azal_directions`]) and `_diff`
//!   (the sky-diffuse loss %: 1 − shaded / unshaded Perez sky diffuse over the year). Only the
//!   timestep table and the diffuse loss are enabled: SAM multiplies every enabled beam table,
//!   so the other two are there to be enabled instead, never beside it.

use std::fmt::Write as _;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use serde_json::json;

use super::Schedule;
use super::irradiation::SurfaceSummary;
use crate::count::MIN_COS_INCIDENCE;
use crate::error::{Error, Result};
use crate::map::Points;
use crate::model::run_year::is_leap;
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;
use crate::year::samples::{Timesteps, month_day_of};

/// SAM's azimuth × altitude table: azimuths every this many degrees from 0 to 360.
pub const AZAL_AZIMUTH_STEP: u32 = 10;
/// … and altitudes every this many degrees from 0 to 90.
pub const AZAL_ALTITUDE_STEP: u32 = 10;
/// The sun of the table's 0° row is counted this high: at 0° there is no beam on a roof, and a
/// loss of 0 there would pull SAM's interpolation towards no shade near the horizon.
pub const AZAL_LOWEST_ALTITUDE: f64 = 1.0;

/// The year labelling the time index when the run names none (`--year`, an EnergyPlus
/// RunPeriod's or a leap weather file's): one of 365 days, as such a run's.
pub const DEFAULT_YEAR: i32 = 2023;

/// The versions whose readers the layouts were checked against (tests/pv.rs).
pub const CHECKED_AGAINST: &str = "pvlib 0.16.1, NREL-PySAM 7.1.1.post1 (pvsamv1)";

/// The local standard time of a schedule row's start, ISO 8601 with the UTC offset.
fn timestamp(year: i32, leap: bool, row: usize, per_hour: u32, time_zone: f64) -> String {
    let n = per_hour as usize;
    let day = (row / (24 * n)) as u32 + 1;
    let minutes = (row % (24 * n)) * 60 / n;
    let (month, dom) = month_day_of(day, leap);
    let offset = (time_zone * 60.0).round() as i64;
    let sign = if offset < 0 { '-' } else { '+' };
    format!(
        "{year:04}-{month:02}-{dom:02}T{:02}:{:02}:00{sign}{:02}:{:02}",
        minutes / 60,
        minutes % 60,
        offset.abs() / 60,
        offset.abs() % 60
    )
}

/// One array's members as the PV outputs see them (surfaces of a schedule, or a map's points),
/// each with a name, a normal, an area and a sunlit fraction at each row of a year.
pub struct PvSet<'a> {
    /// What the members are ("surfaces" or "points"), for SAM's notes.
    pub kind: &'static str,
    /// Column names, one a member.
    pub names: Vec<String>,
    /// Each member's unit normal (x east, y north, z up).
    pub normals: Vec<DVec3>,
    /// Each member's area (m²): its weight in the array.
    pub areas: Vec<f64>,
    /// The rows' timesteps (a whole year).
    pub timesteps: Timesteps,
    /// `fraction(row, member)`: the member's sunlit fraction (a point's visibility) at a row.
    pub fraction: Box<dyn Fn(usize, usize) -> f32 + 'a>,
}

impl<'a> PvSet<'a> {
    /// The scene's receivers, their fractions the schedule's columns.
    pub fn surfaces(scene: &Scene, schedule: &'a Schedule) -> Result<Self> {
        if scene.receivers.len() != schedule.names.len() {
            return Err(Error::argument("schedule", format!("{} columns for {} receivers", schedule.names.len(), scene.receivers.len())));
        }
        Ok(Self {
            kind: "surfaces",
            names: schedule.names.clone(),
            normals: scene.receivers.iter().map(|r| r.normal).collect(),
            areas: scene.receivers.iter().map(|r| r.area).collect(),
            timesteps: schedule.timesteps,
            fraction: Box::new(|row, c| schedule.get(row, c)),
        })
    }

    /// A map's points named `point_I` (I the 0-based row of the map's points CSV), each standing
    /// for `spacing²` of surface (a grid) or 1 m² (points from a CSV: equal weights), their
    /// visibilities `series` (row-major: a row of every point per timestep of a 365-day year at
    /// `per_hour`, as [`crate::map::Mapper::visibility_series`] gives).
    pub fn points(points: &Points, series: &'a [f32], per_hour: u32) -> Result<Self> {
        let timesteps = Timesteps::new(per_hour)?;
        let n = points.len();
        if series.len() != timesteps.rows() * n {
            return Err(Error::argument("series", format!("{} values for {n} points × {} timesteps", series.len(), timesteps.rows())));
        }
        let area = points.spacing.map_or(1.0, |s| s * s);
        Ok(Self {
            kind: "points",
            names: (0..n).map(|i| format!("point_{i}")).collect(),
            normals: (0..n).map(|i| points.normal(i)).collect(),
            areas: vec![area; n],
            timesteps,
            fraction: Box::new(move |row, i| series[row * n + i]),
        })
    }

    fn len(&self) -> usize {
        self.names.len()
    }
}

/// The sun (unit vector) at each row, or `None` while it is down.
fn suns(set: &PvSet, location: &Location) -> Vec<Option<DVec3>> {
    set.timesteps
        .instants()
        .map(|i| Some(sun_direction(location, shading_sun_day(i.day), i.hour)).filter(|s| s.z >= MIN_COS_INCIDENCE))
        .collect()
}

fn check_year(set: &PvSet, year: i32) -> Result<()> {
    if is_leap(year) != set.timesteps.is_leap() {
        let days = set.timesteps.days();
        return Err(Error::argument("year", format!("{year} does not have the {}' {days} days", set.kind)));
    }
    Ok(())
}

/// A member's beam shaded fraction at a row (see the module doc).
fn shaded(normal: DVec3, sun: Option<DVec3>, fraction: f32) -> f64 {
    match sun {
        Some(s) if normal.dot(s) >= MIN_COS_INCIDENCE => 1.0 - f64::from(fraction).clamp(0.0, 1.0),
        _ => 0.0,
    }
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// The pvlib CSV: `time`, then one column per member (its name) of beam shaded fractions, one
/// row per timestep of `year` (see the module doc).
pub fn pvlib_csv(set: &PvSet, location: &Location, year: i32) -> Result<Vec<u8>> {
    check_year(set, year)?;
    let suns = suns(set, location);
    let columns = set.len();
    let mut text = String::with_capacity(suns.len() * (32 + 8 * columns));
    text.push_str("time");
    for name in &set.names {
        text.push(',');
        text.push_str(&field(name));
    }
    text.push('\n');
    let (leap, per_hour) = (set.timesteps.is_leap(), set.timesteps.per_hour());
    for (row, sun) in suns.iter().enumerate() {
        text.push_str(&timestamp(year, leap, row, per_hour, location.time_zone));
        for (c, normal) in set.normals.iter().enumerate() {
            let v = shaded(*normal, *sun, (set.fraction)(row, c));
            // Six decimals; never "-0".
            let _ = write!(text, ",{}", if v == 0.0 { "0".to_string() } else { format!("{v:.6}") });
        }
        text.push('\n');
    }
    Ok(text.into_bytes())
}

/// The set's beam sums for a sun, `[Σ area·cos θ·fraction, Σ area·cos θ]` over the members
/// facing it (see [`SamSums`]), from each member's fraction.
fn beam_sums(set: &PvSet, sun: DVec3, fraction: impl Fn(usize) -> f64) -> [f64; 2] {
    let (mut lit, mut all) = (0.0, 0.0);
    for (c, (normal, area)) in set.normals.iter().zip(&set.areas).enumerate() {
        let cos = normal.dot(sun);
        if cos >= MIN_COS_INCIDENCE && sun.z >= MIN_COS_INCIDENCE {
            lit += area * cos * fraction(c).clamp(0.0, 1.0);
            all += area * cos;
        }
    }
    [lit, all]
}

/// The sun directions of SAM's azimuth × altitude table, row by row (altitude) then azimuth:
/// `(azimuth°, altitude°, unit vector)`, x east, y north, z up.
pub fn azal_directions() -> Vec<(f64, f64, DVec3)> {
    let mut out = Vec::new();
    for alt in (0..=90).step_by(AZAL_ALTITUDE_STEP as usize) {
        for az in (0..=360).step_by(AZAL_AZIMUTH_STEP as usize) {
            let (a, h) = (f64::from(az), f64::from(alt));
            let (az_r, alt_r) = (a.to_radians(), h.max(AZAL_LOWEST_ALTITUDE).to_radians());
            out.push((a, h, DVec3::new(az_r.sin() * alt_r.cos(), az_r.cos() * alt_r.cos(), alt_r.sin())));
        }
    }
    out
}

/// Rounds a percentage to 4 decimals, never −0.
fn percent(loss: f64) -> f64 {
    let p = (loss * 1e6).round() / 1e4;
    if p == 0.0 { 0.0 } else { p }
}

/// What [`sam_json`] is made from besides the set's fractions.
pub struct SamInputs<'a> {
    /// The run's year (its length must be the set's).
    pub year: i32,
    /// The engine's fraction for each member (inner) and each of [`azal_directions`] (outer).
    pub azal_fractions: &'a [Vec<f64>],
    /// The set's sky diffuse over the year, shaded and unshaded: [`diffuse_sums`] of its members.
    pub diffuse: [f64; 2],
}

/// A set's beam and sky sums, from which SAM's inputs are made. They add over sets: the sums of
/// disjoint sets (a district's tiles) are the sums of their union, so a merge needs no member's
/// year. Each beam pair is `[Σ area·cos θ·fraction, Σ area·cos θ]` over the members facing the
/// sun (`[0, 0]` when none does or the sun is down); the loss is 1 − their ratio.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SamSums {
    /// What the members are ("surfaces" or "points").
    pub kind: String,
    /// The members' names, in order.
    pub names: Vec<String>,
    /// Their area, m².
    pub area: f64,
    /// Timesteps per hour of the rows.
    pub per_hour: u32,
    /// Whether the rows cover a leap year.
    pub leap: bool,
    /// One pair per row of the year.
    pub rows: Vec<[f64; 2]>,
    /// One pair per direction of [`azal_directions`].
    pub azal: Vec<[f64; 2]>,
    /// `[Σ area·shaded, Σ area·unshaded]` sky diffuse over the year.
    pub diffuse: [f64; 2],
}

impl SamSums {
    /// The set's sums at each row of its year and each of SAM's table directions.
    pub fn of(set: &PvSet, location: &Location, inputs: &SamInputs) -> Result<Self> {
        let directions = azal_directions();
        if inputs.azal_fractions.len() != directions.len() {
            return Err(Error::argument("azal_fractions", format!("{} directions, not {}", inputs.azal_fractions.len(), directions.len())));
        }
        let rows = suns(set, location)
            .iter()
            .enumerate()
            .map(|(row, sun)| sun.map_or([0.0; 2], |s| beam_sums(set, s, |c| f64::from((set.fraction)(row, c)))))
            .collect();
        let azal = directions
            .iter()
            .zip(inputs.azal_fractions)
            .map(|(&(_, _, sun), f)| beam_sums(set, sun, |c| f.get(c).copied().unwrap_or(0.0)))
            .collect();
        Ok(Self {
            kind: set.kind.to_string(),
            names: set.names.clone(),
            area: set.areas.iter().sum(),
            per_hour: set.timesteps.per_hour(),
            leap: set.timesteps.is_leap(),
            rows,
            azal,
            diffuse: inputs.diffuse,
        })
    }

    /// Adds another set's sums (same year and timesteps) to these: the sums of the two sets' union.
    pub fn add(&mut self, other: &SamSums) -> Result<()> {
        if (self.per_hour, self.leap) != (other.per_hour, other.leap)
            || self.rows.len() != other.rows.len()
            || self.azal.len() != other.azal.len()
        {
            return Err(Error::argument("sam", format!("sums of {} rows cannot join sums of {}", other.rows.len(), self.rows.len())));
        }
        let add = |a: &mut [f64; 2], b: &[f64; 2]| {
            a[0] += b[0];
            a[1] += b[1];
        };
        self.rows.iter_mut().zip(&other.rows).for_each(|(a, b)| add(a, b));
        self.azal.iter_mut().zip(&other.azal).for_each(|(a, b)| add(a, b));
        add(&mut self.diffuse, &other.diffuse);
        self.names.extend(other.names.iter().cloned());
        self.area += other.area;
        Ok(())
    }
}

/// The beam loss (0..1) of a pair of [`SamSums`]; `None` when no member faces the sun.
fn loss_of(sums: [f64; 2]) -> Option<f64> {
    let [lit, all] = sums;
    (all > 0.0).then(|| (1.0 - lit / all).clamp(0.0, 1.0))
}

/// SAM's `pvsamv1` shading inputs for the set's members taken as one array, as JSON:
/// `{"sunlit": {…what and how…}, "Shading": {"subarray1_shading_…": …}}`; `Shading` is what
/// PySAM's `Pvsamv1.Shading.assign` takes.
pub fn sam_json(set: &PvSet, location: &Location, inputs: &SamInputs) -> Result<Vec<u8>> {
    check_year(set, inputs.year)?;
    sam_json_of(&SamSums::of(set, location, inputs)?, inputs.year)
}

/// [`sam_json`] from a set's sums (a merge's, or one set's).
pub fn sam_json_of(sums: &SamSums, year: i32) -> Result<Vec<u8>> {
    let leap = sums.leap;
    if is_leap(year) != leap || sums.rows.len() != Timesteps::new(sums.per_hour)?.leap_year(leap).rows() {
        return Err(Error::argument("year", format!("{year} is not the year of the {}' {} rows", sums.kind, sums.rows.len())));
    }
    let per_hour = sums.per_hour as usize;
    let mut timestep = Vec::with_capacity(8760 * per_hour);
    let mut mxh = [[(0.0f64, 0usize); 24]; 12];
    for (row, &pair) in sums.rows.iter().enumerate() {
        let day = (row / (24 * per_hour)) as u32 + 1;
        let (month, dom) = month_day_of(day, leap);
        let loss = loss_of(pair);
        if let Some(l) = loss {
            let cell = &mut mxh[month as usize - 1][(row / per_hour) % 24];
            cell.0 += l;
            cell.1 += 1;
        }
        if !(month == 2 && dom == 29) {
            timestep.push(json!([percent(loss.unwrap_or(0.0))]));
        }
    }
    let mxh: Vec<Vec<f64>> =
        mxh.iter().map(|m| m.iter().map(|&(s, n)| if n == 0 { 0.0 } else { percent(s / n as f64) }).collect()).collect();
    let azal = azal_table(&azal_directions(), &sums.azal);
    let [shaded, unshaded] = sums.diffuse;
    let doc = json!({
        "sunlit": {
            "what": format!("pvsamv1 shading inputs for the {} below taken as one array (subarray 1): beam loss % = 100·(1 − shaded beam / unshaded beam)", sums.kind),
            sums.kind.as_str(): sums.names,
            "area_m2": sums.area,
            "year": year,
            "timesteps_per_hour": per_hour,
            "enabled": "subarray1_shading_timestep and _diff; _mxh and _azal are alternatives to the timestep table (SAM multiplies every enabled beam table)",
            "checked_against": CHECKED_AGAINST,
        },
        "Shading": {
            "subarray1_shading_en_timestep": 1,
            "subarray1_shading_timestep": timestep,
            "subarray1_shading_en_mxh": 0,
            "subarray1_shading_mxh": mxh,
            "subarray1_shading_en_azal": 0,
            "subarray1_shading_azal": azal,
            "subarray1_shading_en_diff": 1,
            "subarray1_shading_diff": percent(diffuse_loss_of(shaded, unshaded)),
        },
    });
    let mut text = serde_json::to_vec(&doc).map_err(|e| Error::model("SAM shading", e.to_string()))?;
    text.push(b'\n');
    Ok(text)
}

/// SAM's azimuth × altitude table: `[[0, az…], [alt, loss%…], …]`, from each direction's sums.
fn azal_table(directions: &[(f64, f64, DVec3)], sums: &[[f64; 2]]) -> Vec<Vec<f64>> {
    let columns = (360 / AZAL_AZIMUTH_STEP + 1) as usize;
    let mut table = vec![std::iter::once(0.0).chain(directions.iter().take(columns).map(|d| d.0)).collect::<Vec<f64>>()];
    for (chunk, pairs) in directions.chunks(columns).zip(sums.chunks(columns)) {
        table.push(std::iter::once(chunk[0].1).chain(pairs.iter().map(|&p| percent(loss_of(p).unwrap_or(0.0)))).collect());
    }
    table
}

/// A set's sky diffuse over the year from each member's `(area, shaded, unshaded)`:
/// `[Σ area·shaded, Σ area·unshaded]`.
pub fn diffuse_sums(members: impl IntoIterator<Item = (f64, f64, f64)>) -> [f64; 2] {
    members.into_iter().fold([0.0; 2], |[s, u], (area, shaded, unshaded)| [s + area * shaded, u + area * unshaded])
}

/// The sky-diffuse loss (0..1): 1 − shaded / unshaded (0 with no sky at all).
fn diffuse_loss_of(shaded: f64, unshaded: f64) -> f64 {
    if unshaded > 0.0 { (1.0 - shaded / unshaded).clamp(0.0, 1.0) } else { 0.0 }
}

/// The surfaces' sky diffuse over the year from their summaries ([`diffuse_sums`]).
pub fn surfaces_diffuse_sums(summaries: &[SurfaceSummary]) -> Result<[f64; 2]> {
    let need = |v: Option<f64>| v.ok_or_else(|| Error::argument("epw", "SAM's diffuse loss needs weather (irradiation)"));
    let members = summaries
        .iter()
        .map(|s| {
            // The unshaded total less the unshaded beam and the (never shaded) ground-reflected part.
            let open = need(s.unshaded_total)? - need(s.unshaded_irradiation)? - need(s.ground_reflected)?;
            Ok((s.area, need(s.sky_diffuse)?, open))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(diffuse_sums(members))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_start_each_timestep_in_local_standard_time() {
        assert_eq!(timestamp(2023, false, 0, 1, 1.0), "2023-01-01T00:00:00+01:00");
        assert_eq!(timestamp(2023, false, 8759, 1, -5.0), "2023-12-31T23:00:00-05:00");
        assert_eq!(timestamp(2024, true, 59 * 24, 1, 5.5), "2024-02-29T00:00:00+05:30");
        assert_eq!(timestamp(2023, false, 5, 4, 0.0), "2023-01-01T01:15:00+00:00");
    }

    #[test]
    fn azal_rows_run_from_the_horizon_up_and_azimuths_clockwise_from_north() {
        let d = azal_directions();
        assert_eq!(d.len(), 10 * 37);
        let east = d.iter().find(|x| x.0 == 90.0 && x.1 == 0.0).unwrap().2;
        assert!(east.x > 0.99 && east.z > 0.0 && east.z < 0.02);
        let south_60 = d.iter().find(|x| x.0 == 180.0 && x.1 == 60.0).unwrap().2;
        assert!((south_60.z - 60f64.to_radians().sin()).abs() < 1e-12 && south_60.y < 0.0);
    }
}
