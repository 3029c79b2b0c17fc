//! BRE 209 (3rd ed., 2022), 3.2: annual and winter probable sunlight hours (APSH, WPSH) at a
//! window's reference point.
//!
//! BRE's probable sunlight hours are the hours a year the sun is expected to shine on
//! unobstructed ground, from long-term sunshine records (about 1,486 h in London). From an EPW
//! they are **approximated** here by the hours whose direct normal irradiance reaches the WMO's
//! sunshine-duration threshold, [`SUNSHINE_THRESHOLD`] = 120 W/m² (WMO CIMO Guide, 8.1.1), with
//! the sun up, at the EPW hour's middle (the sun `sunlit annual` uses, EnergyPlus's model). A
//! point's APSH is the share (%) of those hours it sees the sun (visibility-weighted, so a
//! see-through caster counts its transmittance); its WPSH the share of the *annual* hours that
//! fall from 21 September to 21 March ([`WINTER`]) and that it sees.
//!
//! BRE assesses windows facing within 90° of due south ([`faces_the_equator`]: due north south
//! of the equator); the values are computed for every point and the report says which are
//! assessed. Foliage follows the leaf calendar of the latitude, as for every map.

use glam::DVec3;

use super::{Ask, Windows};
use crate::count::MIN_COS_INCIDENCE;
use crate::error::{Error, Result};
use crate::map::{Period, Site};
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;
use crate::year::samples::Timesteps;

/// WMO's threshold of direct normal irradiance for an hour of sunshine, W/m².
pub const SUNSHINE_THRESHOLD: f64 = 120.0;
/// BRE's winter: 21 September (day 264) to 21 March (day 80) of a 365-day year, inclusive.
pub const WINTER: (u32, u32) = (264, 80);

/// Each point's probable sunlight hours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ApshValues {
    /// Annual probable sunlight hours seen, % of the annual probable hours.
    pub apsh: Vec<f64>,
    /// Winter (21 Sep – 21 Mar) probable sunlight hours seen, % of the annual probable hours.
    pub wpsh: Vec<f64>,
    /// Whether BRE assesses the point: its normal within 90° of due south (north south of the
    /// equator).
    pub assessed: Vec<bool>,
    /// The annual probable sunlight hours (the denominator).
    pub annual_hours: f64,
    /// Of them, the winter ones.
    pub winter_hours: f64,
}

/// Whether a window facing `normal` faces within 90° of the equator (due south at or north of
/// it, due north south of it); a horizontal one (a roof light) does.
pub fn faces_the_equator(normal: DVec3, latitude: f64) -> bool {
    let towards = if latitude >= 0.0 { -normal.y } else { normal.y };
    normal.truncate().length() < 1e-9 || towards >= -1e-9
}

/// Whether day of the year `day` is in BRE's winter.
pub fn in_winter(day: u32) -> bool {
    day >= WINTER.0 || day <= WINTER.1
}

/// The probable sunlight hours of `site`'s weather: each hour's sun (mid-hour) and whether it is
/// a winter one. Refuses a site without weather, and weather none of whose hours reach the
/// threshold (a file without direct normal irradiance).
pub fn probable_hours(site: Site<'_>) -> Result<(Vec<Ask>, Vec<bool>)> {
    let weather = site.weather.ok_or_else(|| {
        Error::argument("epw", "bre-apsh needs a weather file: its probable sunlight hours come from the direct normal irradiance")
    })?;
    let hourly = Timesteps::new(1)?;
    let mut asks = Vec::new();
    let mut winter = Vec::new();
    for s in Period::annual(1)?.samples() {
        let sun = sun_direction(site.location, shading_sun_day(s.day), s.hour);
        if sun.z >= MIN_COS_INCIDENCE && weather.at(hourly, s.epw_hour).dni >= SUNSHINE_THRESHOLD {
            asks.push(Ask { direction: sun, leaves: site.calendar.fraction(f64::from(s.day)) as f32 });
            winter.push(in_winter(s.day));
        }
    }
    if asks.is_empty() {
        return Err(Error::argument(
            "epw",
            format!("no hour's direct normal irradiance reaches {SUNSHINE_THRESHOLD} W/m² (field 15): bre-apsh needs a file with DNI"),
        ));
    }
    Ok((asks, winter))
}

/// Every point's APSH and WPSH under `site`'s weather; `progress(done, total)` counts hours.
pub fn apsh(windows: &Windows, site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> Result<ApshValues> {
    let (asks, winter) = probable_hours(site)?;
    let n = windows.len();
    let parts = windows.sweep(
        &asks,
        progress,
        || (vec![0.0f64; n], vec![0.0f64; n]),
        |(year, cold), k, i, v| {
            year[i] += f64::from(v);
            if winter[k] {
                cold[i] += f64::from(v);
            }
        },
    );
    let (mut year, mut cold) = (vec![0.0; n], vec![0.0; n]);
    for (a, b) in parts {
        crate::map::add_into(&mut year, &a);
        crate::map::add_into(&mut cold, &b);
    }
    let annual_hours = asks.len() as f64;
    let percent = |v: Vec<f64>| v.into_iter().map(|h| 100.0 * h / annual_hours).collect();
    Ok(ApshValues {
        apsh: percent(year),
        wpsh: percent(cold),
        assessed: (0..n).map(|i| faces_the_equator(windows.normal(i), site.location.latitude)).collect(),
        annual_hours,
        winter_hours: winter.iter().filter(|&&w| w).count() as f64,
    })
}
