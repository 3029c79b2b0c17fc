//! The sweep's summary: per variant and surface, the mean sunlit fraction over the year's sun-up
//! timesteps, beside the variant's settings, as `summary.csv`.
//!
//! The means are taken once, when a variant finishes, from its CSV (read back with
//! [`Schedule::from_csv`]) and the sun at each timestep, and kept in its done record; the summary
//! is assembled from the records. A variant with an EPW also has annual irradiation (direct and
//! its unshaded twin, sky diffuse, ground-reflected, total, unshaded total, kWh/m²) and the sky
//! view factor and EnergyPlus's diffuse shading ratios: its annual run writes them per surface
//! ([`Variant::surface_summary`], the scene's normals and the weather are the run's), read back
//! here beside the means; summary.csv has their columns when any finished variant has them.

use std::path::Path;

use super::manifest::Variant;
use super::record::{Done, SOLAR_KEYS, Solar, SurfaceMean};
use crate::count::MIN_COS_INCIDENCE;
use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// The summary's file name in the output folder.
pub const SUMMARY: &str = "summary.csv";

/// Where the variant's sun is: its `epw` file's LOCATION, else its `location` setting.
pub fn location(variant: &Variant) -> Result<Location> {
    match (variant.arg("epw"), variant.arg("location")) {
        (Some(epw), _) => crate::sun::weather::location_from_epw(Path::new(epw)),
        (None, Some(text)) => Location::parse(text),
        (None, None) => Err(Error::argument(format!("variant '{}'", variant.id), "has neither epw nor location")),
    }
}

/// Per column of `schedule`, the mean over the timesteps with the sun up (EnergyPlus's rule:
/// cosine of the zenith at least [`MIN_COS_INCIDENCE`]).
pub fn means(schedule: &Schedule, location: &Location) -> Vec<SurfaceMean> {
    let columns = schedule.names.len();
    let mut sums = vec![0.0f64; columns];
    let mut up = 0usize;
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        // The sun the fractions were counted for (EnergyPlus's day rule, `shading_sun_day`).
        if sun_direction(location, shading_sun_day(instant.day), instant.hour).z < MIN_COS_INCIDENCE {
            continue;
        }
        up += 1;
        for (c, sum) in sums.iter_mut().enumerate() {
            *sum += schedule.get(row, c) as f64;
        }
    }
    schedule
        .names
        .iter()
        .zip(sums)
        .map(|(name, sum)| SurfaceMean {
            surface: name.clone(),
            mean_fraction: sum / up.max(1) as f64,
            sunup_timesteps: up,
            irradiation: None,
            unshaded_irradiation: None,
            solar: Solar::default(),
        })
        .collect()
}

/// The means of the variant's CSV in `dir`.
pub fn means_of(dir: &Path, variant: &Variant) -> Result<Vec<SurfaceMean>> {
    let path = variant.csv(dir);
    let text = std::fs::read_to_string(&path).map_err(|source| Error::Io { path: path.clone(), source })?;
    let schedule = Schedule::from_csv(&path.display().to_string(), &text)?;
    let mut surfaces = means(&schedule, &location(variant)?);
    if let Some(summary) = variant.surface_summary(dir) {
        add_irradiation(&mut surfaces, &summary)?;
    }
    Ok(surfaces)
}

/// Fills each surface's irradiation from the annual run's summary JSON (`surfaces[]` with
/// `name`, `irradiation`, `unshaded_irradiation`; see `export::irradiation::summary_json`).
fn add_irradiation(surfaces: &mut [SurfaceMean], path: &Path) -> Result<()> {
    let label = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::model(&label, e.to_string()))?;
    let listed = json["surfaces"].as_array().ok_or_else(|| Error::model(&label, "no surfaces array"))?;
    for s in surfaces.iter_mut() {
        let Some(entry) = listed.iter().find(|e| e["name"].as_str() == Some(s.surface.as_str())) else {
            return Err(Error::model(&label, format!("no surface '{}' (a column of the CSV)", s.surface)));
        };
        s.irradiation = entry["irradiation"].as_f64();
        s.unshaded_irradiation = entry["unshaded_irradiation"].as_f64();
        s.solar = Solar(SOLAR_KEYS.iter().map(|k| entry[*k].as_f64()).collect());
    }
    Ok(())
}

/// summary.csv's columns for [`SOLAR_KEYS`], after the direct irradiation's.
const SOLAR_COLUMNS: [&str; 7] = [
    "sky_diffuse_kwh_m2",
    "ground_reflected_kwh_m2",
    "total_kwh_m2",
    "unshaded_total_kwh_m2",
    "sky_view_factor",
    "energyplus_iso_sky_ratio",
    "energyplus_horizon_ratio",
];

/// The summary's text: a header, then a row per finished variant and surface, in manifest order.
/// Settings columns are every key any variant sets, sorted; a variant without it leaves it empty.
pub fn summary_csv(finished: &[(&Variant, &Done)]) -> String {
    let mut keys: Vec<&str> = finished.iter().flat_map(|(v, _)| v.settings.iter().map(|(k, _)| k.as_str())).collect();
    keys.sort_unstable();
    keys.dedup();
    // Irradiation columns only where some variant has weather: a sweep of locations keeps its shape.
    let energy = finished.iter().any(|(_, d)| d.surfaces.iter().any(|s| s.irradiation.is_some()));
    let mut header = vec!["id", "surface", "mean_sunlit_fraction", "sunup_timesteps"];
    if energy {
        header.extend(["irradiation_kwh_m2", "unshaded_irradiation_kwh_m2"]);
        header.extend(SOLAR_COLUMNS);
    }
    header.extend(&keys);
    let mut out = header.iter().map(|h| field(h)).collect::<Vec<_>>().join(",");
    out.push('\n');
    for (variant, done) in finished {
        let settings: Vec<String> = keys.iter().map(|k| field(variant.setting(k).unwrap_or(""))).collect();
        for s in &done.surfaces {
            let mut row = vec![field(&variant.id), field(&s.surface), format!("{:.6}", s.mean_fraction), s.sunup_timesteps.to_string()];
            if energy {
                let optional = |v: Option<f64>| v.map(|v| format!("{v:.4}")).unwrap_or_default();
                row.extend([optional(s.irradiation), optional(s.unshaded_irradiation)]);
                row.extend((0..SOLAR_KEYS.len()).map(|k| optional(s.solar.0.get(k).copied().flatten())));
            }
            row.extend(settings.iter().cloned());
            out.push_str(&row.join(","));
            out.push('\n');
        }
    }
    out
}

/// A CSV field, quoted when it holds a comma, quote or line break.
fn field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::year::samples::Timesteps;

    #[test]
    fn means_count_only_sun_up_timesteps() {
        // Golden, CO: 1.0 by day and 0.5 by night means 1.0 over the sun-up rows.
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let t = Timesteps::new(1).unwrap();
        let mut s = Schedule::zeros(vec!["A".into(), "B".into()], t);
        let mut up = 0;
        for (row, i) in t.instants().enumerate() {
            let day = sun_direction(&location, shading_sun_day(i.day), i.hour).z >= MIN_COS_INCIDENCE;
            up += day as usize;
            s.set(row, 0, if day { 1.0 } else { 0.5 });
            s.set(row, 1, if day && row % 2 == 0 { 1.0 } else { 0.0 });
        }
        let m = means(&s, &location);
        assert!((4300..4500).contains(&up), "about half the hours of a year: {up}");
        assert_eq!(m[0].mean_fraction, 1.0);
        assert_eq!(m[0].sunup_timesteps, up);
        assert!((m[1].mean_fraction - 0.5).abs() < 0.01, "{}", m[1].mean_fraction);
    }

    #[test]
    fn fields_with_commas_are_quoted() {
        assert_eq!(field("46.5,11.35,1"), "\"46.5,11.35,1\"");
        assert_eq!(field("a,\"b\""), "\"a,\"\"b\"\"\"");
        assert_eq!(field("WIN_S1"), "WIN_S1");
    }
}
