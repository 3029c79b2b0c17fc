//! Annual direct (beam) irradiation per receiver: Σ DNI·cos θ·fraction·Δt over the year, from an
//! EPW weather file's direct normal irradiance and a year's sunlit-fraction [`Schedule`].
//!
//! Owns the EPW's hourly data records (only the direct normal irradiance column is read), how the
//! hourly values are taken per timestep, and the per-surface summary (mean fraction, irradiation,
//! unshaded irradiation) as JSON or CSV.
//!
//! **DNI per timestep.** An EPW's direct normal irradiance (field 15, Wh/m²) is the energy over
//! the hour *ending* at its hour stamp (hour 1 is 00:00–01:00). sunlit holds that value constant
//! over the hour: every timestep of hour h gets DNI_h (W/m², as a mean power), and the sun, cos θ
//! and the fraction are those at the timestep's instant (sunlit's and EnergyPlus's instants:
//! mid-hour with one timestep an hour, else each timestep's end). This keeps each hour's beam
//! energy as the weather file states it. EnergyPlus instead interpolates hourly weather between
//! the last and this hour per timestep; on an annual total the two differ by a fraction of a
//! percent (they shift energy within the hour, not between hours), and with one timestep an hour
//! they are the same.
//!
//! A timestep counts when the sun is above the horizon and in front of the surface (cos θ > 0);
//! at other times the beam falls on the back or not at all. Irradiation is in kWh/m².

use std::fmt::Write as _;
use std::path::Path;

use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::year::samples::{DAYS, Timesteps};

/// Lines before the first data record of an EPW (LOCATION … DATA PERIODS).
const EPW_HEADER_LINES: usize = 8;
/// The data record's direct normal irradiance field (0-based; the EPW dictionary's field 15).
const EPW_DNI_FIELD: usize = 14;
/// Hours of EnergyPlus's schedule year.
const YEAR_HOURS: usize = (DAYS * 24) as usize;
/// The EPW dictionary's "missing" value for radiation fields; also its upper bound.
const EPW_MISSING_RADIATION: f64 = 9999.0;

/// A year of hourly direct normal irradiance (Wh/m² over each hour), 8760 values.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectNormal {
    hourly: Vec<f64>,
}

impl DirectNormal {
    /// Reads an EPW file's direct normal irradiance column.
    pub fn from_epw(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        // Latin-1 city names must not make the ASCII numbers unreadable.
        Self::from_epw_text(&path.display().to_string(), &String::from_utf8_lossy(&bytes))
    }

    /// Reads the DNI column from EPW text; `file_label` names the source in errors. A leap-year
    /// file's 29 February is skipped (EnergyPlus's schedule year has 365 days).
    pub fn from_epw_text(file_label: &str, text: &str) -> Result<Self> {
        let mut hourly = Vec::with_capacity(YEAR_HOURS);
        for (index, line) in text.lines().enumerate().skip(EPW_HEADER_LINES) {
            let line_number = index + 1;
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() <= EPW_DNI_FIELD {
                return Err(record_error(
                    file_label,
                    line_number,
                    format!("{} fields, expected at least {}", fields.len(), EPW_DNI_FIELD + 1),
                ));
            }
            if fields[1] == "2" && fields[2] == "29" {
                continue;
            }
            hourly.push(dni_value(fields[EPW_DNI_FIELD]).map_err(|reason| record_error(file_label, line_number, reason))?);
        }
        if hourly.len() != YEAR_HOURS {
            return Err(Error::model(
                file_label,
                format!("{} hourly data records after the {EPW_HEADER_LINES} header lines; an EPW year has {YEAR_HOURS}", hourly.len()),
            ));
        }
        Ok(Self { hourly })
    }

    /// Constant DNI (W/m²) all year: for tests and what-if cases.
    pub fn constant(value: f64) -> Self {
        Self { hourly: vec![value; YEAR_HOURS] }
    }

    /// DNI in W/m² at `row` of a schedule with `timesteps`: its hour's value (see the module doc).
    pub fn at(&self, timesteps: Timesteps, row: usize) -> f64 {
        self.hourly.get(row / timesteps.per_hour() as usize).copied().unwrap_or(0.0)
    }
}

fn record_error(file_label: &str, line: usize, reason: String) -> Error {
    Error::object(file_label, format!("line {line}"), reason)
}

/// One DNI field as W/m² (Wh/m² over the hour), or why not.
fn dni_value(text: &str) -> std::result::Result<f64, String> {
    let value: f64 = text.parse().map_err(|_| format!("direct normal irradiance (field 15) '{text}' is not a number"))?;
    if !value.is_finite() || !(0.0..EPW_MISSING_RADIATION).contains(&value) {
        return Err(format!("direct normal irradiance (field 15) {value} is missing or outside 0..9999 Wh/m²"));
    }
    Ok(value)
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
    /// Σ DNI·cos θ·fraction·Δt, kWh/m² (with weather).
    pub irradiation: Option<f64>,
    /// Σ DNI·cos θ·Δt, kWh/m²: the same surface with nothing in the way.
    pub unshaded_irradiation: Option<f64>,
}

/// Every column's summary. `scene` gives each column's normal and area (columns are the scene's
/// receivers, in order); without `dni` the irradiation fields are `None`.
pub fn summarize(scene: &Scene, schedule: &Schedule, location: &Location, dni: Option<&DirectNormal>) -> Result<Vec<SurfaceSummary>> {
    if schedule.names.len() != scene.receivers.len() {
        return Err(Error::argument(
            "schedule",
            format!("{} columns for {} receivers of the scene", schedule.names.len(), scene.receivers.len()),
        ));
    }
    let columns = schedule.names.len();
    let hours_per_step = 1.0 / f64::from(schedule.timesteps.per_hour());
    let (mut fraction_sums, mut sun_up_rows) = (vec![0.0; columns], 0usize);
    let (mut shaded, mut unshaded) = (vec![0.0; columns], vec![0.0; columns]);
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        let sun = sun_direction(location, f64::from(instant.day), instant.hour);
        if sun.z <= 0.0 {
            continue;
        }
        sun_up_rows += 1;
        let beam = dni.map_or(0.0, |d| d.at(schedule.timesteps, row)) * hours_per_step;
        for (c, receiver) in scene.receivers.iter().enumerate() {
            let fraction = f64::from(schedule.get(row, c));
            fraction_sums[c] += fraction;
            let cos = receiver.normal.dot(sun);
            if cos > 0.0 && beam > 0.0 {
                unshaded[c] += beam * cos;
                shaded[c] += beam * cos * fraction;
            }
        }
    }
    let kwh = |wh: f64| dni.map(|_| wh / 1000.0);
    Ok(scene
        .receivers
        .iter()
        .enumerate()
        .map(|(c, r)| SurfaceSummary {
            name: schedule.names[c].clone(),
            area: r.area,
            mean_fraction: if sun_up_rows == 0 { 0.0 } else { fraction_sums[c] / sun_up_rows as f64 },
            irradiation: kwh(shaded[c]),
            unshaded_irradiation: kwh(unshaded[c]),
        })
        .collect())
}

/// The summary as JSON: `{"surfaces":[{"name","area","mean_fraction","irradiation","unshaded_irradiation"}]}`
/// (irradiation in kWh/m², `null` without weather).
pub fn summary_json(summaries: &[SurfaceSummary]) -> String {
    let surfaces: Vec<serde_json::Value> = summaries
        .iter()
        .map(|s| {
            serde_json::json!({
                "name": s.name,
                "area": s.area,
                "mean_fraction": s.mean_fraction,
                "irradiation": s.irradiation,
                "unshaded_irradiation": s.unshaded_irradiation,
            })
        })
        .collect();
    let mut text = serde_json::json!({ "units": { "area": "m2", "irradiation": "kWh/m2" }, "surfaces": surfaces }).to_string();
    text.push('\n');
    text
}

/// The summary as CSV: a header, then one line per surface (empty irradiation without weather).
/// Names cannot hold commas or quotes ([`Schedule::validate`] refuses them).
pub fn summary_csv(summaries: &[SurfaceSummary]) -> String {
    let mut text = String::from("name,area_m2,mean_fraction,irradiation_kwh_m2,unshaded_irradiation_kwh_m2\n");
    let optional = |v: Option<f64>| v.map(|v| format!("{v:.4}")).unwrap_or_default();
    for s in summaries {
        let _ = writeln!(
            text,
            "{},{:.6},{:.6},{},{}",
            s.name,
            s.area,
            s.mean_fraction,
            optional(s.irradiation),
            optional(s.unshaded_irradiation)
        );
    }
    text
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::scene::{SceneBuilder, SourceMesh};
    use crate::sun::position::declination_and_equation_of_time;

    /// A 1 m² horizontal roof (facing up).
    fn roof_scene() -> Scene {
        let mesh = SourceMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        let mut builder = SceneBuilder::new();
        builder.add_object("test", "ROOF", mesh, true);
        builder.build().unwrap()
    }

    fn filled(scene: &Scene, timesteps: Timesteps, value: f32) -> Schedule {
        let names = scene.receivers.iter().map(|r| r.name.clone()).collect();
        let mut s = Schedule::zeros(names, timesteps);
        s.values.iter_mut().for_each(|v| *v = value);
        s
    }

    /// Closed form, independent of the timestep code: a horizontal surface under a constant beam
    /// B gets B·∫ sin(altitude) dt a day = B·(24/π)·(ω₀·sin φ·sin δ + cos φ·cos δ·sin ω₀) Wh/m²,
    /// ω₀ the sunset hour angle, δ the day's (the sun model holds it over each integer day).
    fn closed_form_roof_kwh(latitude: f64, beam: f64) -> f64 {
        let phi = latitude.to_radians();
        (1..=DAYS)
            .map(|day| {
                let (sin_delta, _) = declination_and_equation_of_time(f64::from(day));
                let delta = sin_delta.asin();
                let omega0 = (-phi.tan() * delta.tan()).clamp(-1.0, 1.0).acos();
                beam * 24.0 / std::f64::consts::PI * (omega0 * phi.sin() * delta.sin() + phi.cos() * delta.cos() * omega0.sin())
            })
            .sum::<f64>()
            / 1000.0
    }

    #[test]
    fn unshaded_roof_matches_the_closed_form() {
        let scene = roof_scene();
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let expected = closed_form_roof_kwh(39.74, 800.0);
        for per_hour in [1, 4, 60] {
            let timesteps = Timesteps::new(per_hour).unwrap();
            let summary = summarize(&scene, &filled(&scene, timesteps, 1.0), &location, Some(&DirectNormal::constant(800.0))).unwrap();
            let (got, unshaded) = (summary[0].irradiation.unwrap(), summary[0].unshaded_irradiation.unwrap());
            assert_eq!(got, unshaded, "fraction 1 everywhere: shaded = unshaded");
            // Timestep sums vs the integral: within 0.5 % at N = 1 (mid-hour rule), closer finer.
            let tolerance = if per_hour == 1 { 0.005 } else { 0.002 };
            assert!((got / expected - 1.0).abs() < tolerance, "N={per_hour}: {got} kWh/m² vs closed form {expected}");
            assert_eq!(summary[0].mean_fraction, 1.0);
            assert!((summary[0].area - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn half_shaded_roof_gets_half() {
        let scene = roof_scene();
        let location = Location::new(-33.87, 151.21, 10.0).unwrap();
        let timesteps = Timesteps::new(4).unwrap();
        let dni = DirectNormal::constant(500.0);
        let summary = summarize(&scene, &filled(&scene, timesteps, 0.5), &location, Some(&dni)).unwrap();
        let expected = closed_form_roof_kwh(-33.87, 500.0);
        let (got, unshaded) = (summary[0].irradiation.unwrap(), summary[0].unshaded_irradiation.unwrap());
        assert!((got - unshaded / 2.0).abs() < 1e-9 && (unshaded / expected - 1.0).abs() < 0.002, "{got} {unshaded} {expected}");
        assert!((summary[0].mean_fraction - 0.5).abs() < 1e-6);
        // Without weather: mean fraction only.
        let bare = summarize(&scene, &filled(&scene, timesteps, 0.5), &location, None).unwrap();
        assert_eq!((bare[0].irradiation, bare[0].unshaded_irradiation), (None, None));
    }

    fn epw(records: usize, dni: &str) -> String {
        let mut text = String::from("LOCATION,Test,-,X,Y,0,40,-105,-7,0\n");
        for header in ["DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0", "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0"] {
            text.push_str(header);
            text.push('\n');
        }
        text.push_str("COMMENTS 1,\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday,1/1,12/31\n");
        for h in 0..records {
            let (day, hour) = (h / 24 + 1, h % 24 + 1);
            let (month, dom) = crate::year::samples::month_day(day as u32);
            let _ = writeln!(
                text,
                "1999,{month},{dom},{hour},60,x,10,5,50,80000,0,1000,300,400,{dni},100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0"
            );
        }
        text
    }

    #[test]
    fn epw_dni_column_is_read() {
        let dni = DirectNormal::from_epw_text("w.epw", &epw(8760, "612")).unwrap();
        assert_eq!(dni, DirectNormal::constant(612.0));
        let timesteps = Timesteps::new(4).unwrap();
        assert_eq!(dni.at(timesteps, 35_039), 612.0);
    }

    fn short_first_record() -> String {
        let text = epw(8760, "5");
        let mut lines: Vec<&str> = text.lines().collect();
        lines[8] = "1999,1,1,1,60,x,10,5,50,80000,0,1000,300,400";
        lines.join("\n")
    }

    #[test]
    fn bad_epw_records_name_file_line_and_reason() {
        let cases = [
            (epw(100, "5"), "w.epw: 100 hourly data records after the 8 header lines; an EPW year has 8760"),
            (epw(8760, "9999"), "w.epw: line 9: direct normal irradiance (field 15) 9999 is missing"),
            (epw(8760, "lots"), "w.epw: line 9: direct normal irradiance (field 15) 'lots' is not a number"),
            (epw(8760, "-3"), "w.epw: line 9: direct normal irradiance (field 15) -3 is missing"),
            (short_first_record(), "w.epw: line 9: 14 fields, expected at least 15"),
        ];
        for (text, needle) in cases {
            let e = DirectNormal::from_epw_text("w.epw", &text).unwrap_err().to_string();
            assert!(e.starts_with(needle), "{needle}: {e}");
        }
    }

    #[test]
    fn summary_formats() {
        let scene = roof_scene();
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let schedule = filled(&scene, Timesteps::new(1).unwrap(), 0.25);
        let s = summarize(&scene, &schedule, &location, Some(&DirectNormal::constant(100.0))).unwrap();
        let json: serde_json::Value = serde_json::from_str(&summary_json(&s)).unwrap();
        assert_eq!(json["surfaces"][0]["name"], "ROOF");
        assert!((json["surfaces"][0]["mean_fraction"].as_f64().unwrap() - 0.25).abs() < 1e-6);
        let csv = summary_csv(&s);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "name,area_m2,mean_fraction,irradiation_kwh_m2,unshaded_irradiation_kwh_m2");
        assert!(lines[1].starts_with("ROOF,1.000000,0.250000,"), "{}", lines[1]);
        let bare = summary_csv(&summarize(&scene, &schedule, &location, None).unwrap());
        assert!(bare.lines().nth(1).unwrap().ends_with("0.250000,,"), "{bare}");
    }
}
