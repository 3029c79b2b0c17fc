//! How often an EnergyPlus model's own shading calculation is updated, read from its
//! `ShadowCalculation` and `RunPeriod`.
//!
//! Owns the reading; the sun that follows from it is [`crate::sun::periods`]. `Timestep` updates,
//! or `Periodic` every day, give each day its own sun. A model without a `ShadowCalculation` is
//! read as updating every timestep too, as sunlit always has (and as its hook writes), although
//! EnergyPlus itself would update such a model every 20 days: the committed round trips rely on
//! it, and a model that wants the Periodic sun says so.

use crate::model::idf::{IdfObject, version};
use crate::sun::periods::ShadingPeriods;

/// EnergyPlus's default update frequency, in days (a `ShadowCalculation` that leaves it blank).
const DEFAULT_DAYS: u32 = 20;

/// The model's Periodic update over its run period, or `None` when each day gets its own sun
/// (`Timestep` updates, a frequency of 1 day, no `ShadowCalculation`, or a shading method that
/// reads fractions from a schedule already). 9.3 and later give the update method and frequency in the second and third
/// fields; 9.0–9.2 and earlier give `AverageOverDaysInFrequency` or `TimestepFrequency` and the
/// frequency in the first two.
pub fn periodic_update(objects: &[IdfObject]) -> Option<ShadingPeriods> {
    let field = |o: &IdfObject, i: usize| o.field(i).trim().to_ascii_lowercase();
    let days = |text: String| if text.is_empty() { Some(DEFAULT_DAYS) } else { text.parse::<f64>().ok().map(|d| d.max(1.0) as u32) };
    let update = match objects.iter().find(|o| o.is("ShadowCalculation")) {
        None => None,
        Some(o) => match field(o, 0).as_str() {
            "averageoverdaysinfrequency" => days(field(o, 1)),
            "timestepfrequency" | "scheduled" | "imported" => None,
            _ => match field(o, 1).as_str() {
                "" | "periodic" => days(field(o, 2)),
                _ => None,
            },
        },
    };
    let (first_day, run_days) = run_period_days(objects);
    update.filter(|&d| d > 1).map(|days| ShadingPeriods { days, first_day, run_days })
}

/// The first `RunPeriod`'s first day of the year and its length in days (a non-leap year; a
/// period that wraps over New Year counts on into the next), or the whole year without one.
fn run_period_days(objects: &[IdfObject]) -> (u32, u32) {
    let Some(o) = objects.iter().find(|o| o.is("RunPeriod")) else { return (1, 365) };
    // Before 9.0 there were no year fields: End Month follows Begin Day.
    let old = version(objects).and_then(|v| v.split('.').next().and_then(|m| m.trim().parse::<u32>().ok())).is_some_and(|major| major < 9);
    let end_month = if old { 3 } else { 4 };
    let number = |i: usize, default: u32| o.field(i).trim().parse::<f64>().map_or(default, |v| v as u32);
    let (first, last) = (day_of_year(number(1, 1), number(2, 1)), day_of_year(number(end_month, 12), number(end_month + 1, 31)));
    (first, if last >= first { last - first + 1 } else { last + 365 - first + 1 })
}

/// Day of a non-leap year (1-based) of a month and day, clamped to the year.
fn day_of_year(month: u32, day: u32) -> u32 {
    const BEFORE: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];
    (BEFORE[(month.clamp(1, 12) - 1) as usize] + day.max(1)).min(365)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::idf::parse_idf;

    fn periods(text: &str) -> Option<ShadingPeriods> {
        periodic_update(&parse_idf("m.idf", text).unwrap())
    }

    #[test]
    fn the_models_own_update_and_run_period() {
        let year = |days| Some(ShadingPeriods { days, first_day: 1, run_days: 365 });
        assert_eq!(periods("Version, 25.2;\n"), None, "no ShadowCalculation: every timestep, as the hook writes");
        assert_eq!(periods("Version, 25.2;\nShadowCalculation, PixelCounting, Periodic, 7, , , 1024;\n"), year(7));
        assert_eq!(periods("Version, 25.2;\nShadowCalculation, PolygonClipping;\n"), year(20));
        assert_eq!(periods("Version, 25.2;\nShadowCalculation, PolygonClipping, Timestep, 1;\n"), None);
        assert_eq!(periods("Version, 25.2;\nShadowCalculation, PolygonClipping, Periodic, 1;\n"), None);
        assert_eq!(periods("Version, 25.2;\nShadowCalculation, Scheduled, Periodic, 7;\n"), None);
        assert_eq!(periods("Version, 9.1;\nShadowCalculation, AverageOverDaysInFrequency, 7;\n"), year(7));
        assert_eq!(periods("Version, 9.1;\nShadowCalculation, TimestepFrequency, 7;\n"), None);
        let summer =
            periods("Version, 25.2;\nRunPeriod, R, 3, 15, 2006, 10, 20, 2006, Sunday;\nShadowCalculation, PolygonClipping, Periodic, 7;\n");
        assert_eq!(summer, Some(ShadingPeriods { days: 7, first_day: 74, run_days: 220 }));
        let json = r#"{"Version": {"Version 1": {"version_identifier": "25.2"}}, "ShadowCalculation": {"ShadowCalculation 1": {"shading_calculation_method": "PolygonClipping", "shading_calculation_update_frequency_method": "Timestep", "shading_calculation_update_frequency": 1}}}"#;
        let objects = crate::model::epjson::parse_epjson("m.epJSON", json).unwrap();
        assert_eq!(periodic_update(&objects), None, "epJSON: read by field name");
        let periodic = json.replace("\"Timestep\"", "\"Periodic\"").replace("frequency\": 1", "frequency\": 7");
        assert_eq!(periodic_update(&crate::model::epjson::parse_epjson("m.epJSON", &periodic).unwrap()), year(7));
        let old = periods("Version, 8.4;\nRunPeriod, R, 3, 15, 10, 20, UseWeatherFile;\nShadowCalculation, AverageOverDaysInFrequency;\n");
        assert_eq!(old, Some(ShadingPeriods { days: 20, first_day: 74, run_days: 220 }));
    }
}
