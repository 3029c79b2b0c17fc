//! EN 17037:2018 (+A1:2021), *Daylight in buildings*, exposure to sunlight (clause 5.4, Annex
//! A.6) as a window study: per reference point, the hours the sun can reach it on one chosen day
//! from 1 February to 21 March, counting the sun only at or above a minimum altitude; the room
//! reaches *minimum* at 1.5 h, *medium* at 3 h and *high* at 4 h ([`crate::map::study`]'s
//! `en17037` preset holds those levels and the allowed days, once, for this study and the area
//! study alike).
//!
//! The standard tabulates the minimum altitude by site; that table could not be read here, so
//! the altitude is a parameter (default [`crate::map::study::EN17037_MIN_ALTITUDE`]) that the
//! report states. The sun is `sunlit annual`'s (EnergyPlus's, the day's declination and equation
//! of time) at the middle of every minute of the day in local standard time; the hours are the
//! minutes it reaches the point over 60, every minute counting (the standard sets no minimum
//! period).

use super::{Ask, LitSeries, Windows, lit_bits};
use crate::error::{Error, Result};
use crate::map::period::Period;
use crate::map::study::{self, SunRule};
use crate::map::{Sample, Site};
use crate::year::samples::month_day;

/// Minutes between instants; each stands for its minute.
pub const STEP_MINUTES: u32 = 1;

/// The rule as evaluated: the day and the minimum sun altitude.
#[derive(Debug, Clone, PartialEq)]
pub struct En17037Rule {
    /// Day of a 365-day year, 32 (1 February) to 80 (21 March).
    pub day: u32,
    /// The sun counts at or above this altitude, degrees.
    pub min_altitude_deg: f64,
}

impl En17037Rule {
    /// The rule on `day` (default 21 March) with `min_altitude_deg` (default
    /// [`study::EN17037_MIN_ALTITUDE`]); refuses a day outside 1 February – 21 March (naming
    /// `period`) and an altitude outside 0..90 (naming `min_altitude`).
    pub fn new(day: Option<u32>, min_altitude_deg: Option<f64>) -> Result<Self> {
        let rule = Self {
            day: day.unwrap_or(study::en17037().default_day),
            min_altitude_deg: min_altitude_deg.unwrap_or(study::EN17037_MIN_ALTITUDE),
        };
        rule.check()?;
        Ok(rule)
    }

    /// Refuses parameters outside their sense, naming them.
    pub fn check(&self) -> Result<()> {
        let (first, last) = study::en17037().days;
        if !(first..=last).contains(&self.day) {
            let ((m0, d0), (m1, d1), (m, d)) = (month_day(first), month_day(last), month_day(self.day.clamp(1, 365)));
            return Err(Error::argument(
                "period",
                format!("{m:02}-{d:02}: EN 17037 evaluates one day from {m0:02}-{d0:02} to {m1:02}-{d1:02}"),
            ));
        }
        if !(0.0..90.0).contains(&self.min_altitude_deg) {
            return Err(Error::argument("min_altitude", format!("{}° is not in 0..90", self.min_altitude_deg)));
        }
        Ok(())
    }

    /// The preset's rule with this altitude: its levels, from the lowest ("minimum").
    pub fn sun_rule(&self) -> SunRule {
        SunRule { min_altitude_deg: self.min_altitude_deg, ..study::en17037() }
    }
}

/// Each point's hours under the rule.
#[derive(Debug, Clone, PartialEq)]
pub struct En17037Values {
    /// The rule evaluated.
    pub rule: En17037Rule,
    /// Hours of sun per point.
    pub hours: Vec<f64>,
}

/// The day's instants with the sun at or above the rule's altitude: the middle of each minute,
/// local standard time.
pub fn instants(rule: &En17037Rule, site: Site<'_>) -> Result<(Vec<Sample>, Vec<Ask>)> {
    let min_z = rule.min_altitude_deg.to_radians().sin();
    let leaves = site.calendar.fraction(f64::from(rule.day)) as f32;
    let mut kept = (Vec::new(), Vec::new());
    for s in Period::day(rule.day, 0, 24 * 60, STEP_MINUTES)?.samples() {
        let sun = crate::sun::position::sun_direction(site.location, crate::year::annual::shading_sun_day(s.day), s.hour);
        if sun.z >= min_z {
            kept.0.push(s);
            kept.1.push(Ask { direction: sun, leaves });
        }
    }
    Ok(kept)
}

/// Evaluates `rule` at `windows` of a scene at `site`; `progress(done, total)` counts points.
pub fn evaluate(windows: &Windows, site: Site<'_>, rule: &En17037Rule, progress: &mut dyn FnMut(usize, usize)) -> Result<En17037Values> {
    rule.check()?;
    let (samples, asks) = instants(rule, site)?;
    let lit: LitSeries = lit_bits(windows, &asks, progress);
    let periods = rule.sun_rule();
    let hours = (0..windows.len()).map(|i| periods.hours(&samples, &lit, i)).collect();
    Ok(En17037Values { rule: rule.clone(), hours })
}
