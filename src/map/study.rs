//! Sun-hours studies as planning rules state them: per point, hours of direct sun on a day above
//! a minimum sun altitude, counting only continuous periods of a minimum length (optionally only
//! the longest N of them); per area (a receiver's points), the share of points reaching a
//! threshold, and whether that share passes.
//!
//! Presets:
//! - `bre-ground`: BRE 209 (3rd edition, 2022), "Site layout planning for daylight and sunlight",
//!   section 3.3 sun on the ground: an amenity area (garden, park) passes when at least half of
//!   it can receive at least 2 hours of sunlight on 21 March. No minimum altitude or period.
//! - `en17037`: EN 17037:2018 (+A1:2021), sunlight exposure (clause 5.4 and Annex A.6): a
//!   reference point (the inner face of the window opening, centred, at least 1.2 m above the
//!   floor) receives the sun for at least 1.5 h (minimum), 3 h (medium) or 4 h (high) on a chosen
//!   day between 1 February and 21 March, counting the sun only above a minimum altitude that the
//!   standard tabulates by site (its national annex/table); we default that altitude to 10°
//!   (adjustable) — see docs/maps.md. A room passes a level when its reference point reaches it:
//!   here every point of an area must (share 1).

use super::{LitSeries, Sample};
use crate::error::{Error, Result};

/// A sun-hours rule.
#[derive(Debug, Clone, PartialEq)]
pub struct SunRule {
    /// Preset name or `custom`.
    pub name: String,
    /// Where the rule comes from, in words.
    pub source: String,
    /// The sun counts only at or above this altitude (degrees).
    pub min_altitude_deg: f64,
    /// Only continuous lit periods at least this long count (minutes; 0: every instant).
    pub min_period_minutes: f64,
    /// Only the longest N qualifying periods count (`None`: all).
    pub longest: Option<usize>,
    /// Named levels (hours a point must reach), lowest first; the first is the pass threshold.
    pub levels: Vec<(String, f64)>,
    /// Share of an area's points that must reach the first level for the area to pass.
    pub share: f64,
    /// Days of the year the rule allows (inclusive).
    pub days: (u32, u32),
    /// The day it evaluates when none is chosen.
    pub default_day: u32,
}

/// The preset rules' names.
pub const PRESETS: [&str; 2] = ["bre-ground", "en17037"];

/// Default minimum sun altitude for `en17037` (degrees); see the module doc.
pub const EN17037_MIN_ALTITUDE: f64 = 10.0;

/// A preset rule by name.
pub fn preset(name: &str) -> Result<SunRule> {
    match name {
        "bre-ground" => Ok(SunRule {
            name: name.into(),
            source: "BRE 209, 3rd ed. (2022), 3.3 sun on the ground: at least half of an amenity area receives at least 2 h of sunlight on 21 March".into(),
            min_altitude_deg: 0.0,
            min_period_minutes: 0.0,
            longest: None,
            levels: vec![("pass".into(), 2.0)],
            share: 0.5,
            days: (80, 80),
            default_day: 80,
        }),
        "en17037" => Ok(en17037()),
        other => Err(Error::argument("study", format!("'{other}' is not a study (known: {})", PRESETS.join(", ")))),
    }
}

/// EN 17037's sunlight exposure rule: the `en17037` preset, and the levels and days of the
/// window study [`crate::map::planning::en17037`].
pub fn en17037() -> SunRule {
    SunRule {
        name: "en17037".into(),
        source: "EN 17037:2018, sunlight exposure at the reference point on a day between 1 February and 21 March: minimum 1.5 h, medium 3 h, high 4 h, sun above a minimum altitude".into(),
        min_altitude_deg: EN17037_MIN_ALTITUDE,
        min_period_minutes: 0.0,
        longest: None,
        levels: vec![("minimum".into(), 1.5), ("medium".into(), 3.0), ("high".into(), 4.0)],
        share: 1.0,
        days: (32, 80),
        default_day: 80,
    }
}

impl SunRule {
    /// Refuses a day the rule does not allow.
    pub fn check_day(&self, day: u32) -> Result<()> {
        if (self.days.0..=self.days.1).contains(&day) {
            return Ok(());
        }
        let (a, b) = (crate::year::samples::month_day(self.days.0), crate::year::samples::month_day(self.days.1));
        Err(Error::argument(
            "study",
            format!("{} evaluates a day from {:02}-{:02} to {:02}-{:02}; day {day} is outside", self.name, a.0, a.1, b.0, b.1),
        ))
    }

    /// One point's hours under the rule from its lit instants (consecutive instants of one day).
    pub fn hours(&self, samples: &[Sample], series: &LitSeries, point: usize) -> f64 {
        let mut periods: Vec<f64> = Vec::new();
        let mut run = 0.0;
        for (k, s) in samples.iter().enumerate() {
            if series.lit(point, k) {
                run += s.hours;
            } else if run > 0.0 {
                periods.push(run);
                run = 0.0;
            }
        }
        if run > 0.0 {
            periods.push(run);
        }
        periods.retain(|&h| h * 60.0 + 1e-9 >= self.min_period_minutes);
        periods.sort_by(|a, b| b.total_cmp(a));
        periods.iter().take(self.longest.unwrap_or(usize::MAX)).sum()
    }

    /// The highest level `hours` reaches, if any.
    pub fn level(&self, hours: f64) -> Option<&str> {
        self.levels.iter().rev().find(|(_, h)| hours + 1e-9 >= *h).map(|(name, _)| name.as_str())
    }
}

/// One area's result.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaResult {
    /// The receiver.
    pub receiver: u32,
    /// Its points.
    pub points: usize,
    /// Share of its points reaching each level, in the rule's order.
    pub shares: Vec<f64>,
    /// Whether the share reaching the first level is at least the rule's share.
    pub passes: bool,
}

/// A study's results: per point hours and per area shares.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyResult {
    /// The rule.
    pub rule: SunRule,
    /// The day evaluated.
    pub day: u32,
    /// Per point hours.
    pub hours: Vec<f64>,
    /// Per receiver with points, in receiver order.
    pub areas: Vec<AreaResult>,
}

/// Evaluates `rule` for points on `receivers` (one per point) from their lit series over
/// `samples` (one day).
pub fn evaluate(rule: &SunRule, day: u32, samples: &[Sample], series: &LitSeries, receivers: &[u32]) -> StudyResult {
    let hours: Vec<f64> = (0..receivers.len()).map(|i| rule.hours(samples, series, i)).collect();
    let mut ids: Vec<u32> = receivers.to_vec();
    ids.sort_unstable();
    ids.dedup();
    let areas = ids
        .into_iter()
        .map(|r| {
            let mine: Vec<f64> = receivers.iter().zip(&hours).filter(|(id, _)| **id == r).map(|(_, h)| *h).collect();
            let shares: Vec<f64> = rule
                .levels
                .iter()
                .map(|(_, need)| mine.iter().filter(|&&h| h + 1e-9 >= *need).count() as f64 / mine.len() as f64)
                .collect();
            let passes = shares.first().is_some_and(|&s| s + 1e-12 >= rule.share);
            AreaResult { receiver: r, points: mine.len(), shares, passes }
        })
        .collect();
    StudyResult { rule: rule.clone(), day, hours, areas }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A day of ten-minute instants, lit where `pattern` has a `#`.
    fn series(pattern: &str) -> (Vec<Sample>, LitSeries) {
        let samples: Vec<Sample> =
            (0..pattern.len()).map(|k| Sample { day: 80, hour: k as f64 / 6.0, hours: 1.0 / 6.0, epw_hour: 0 }).collect();
        let mut bits = vec![0u64; pattern.len().div_ceil(64)];
        for (k, c) in pattern.chars().enumerate() {
            if c == '#' {
                bits[k / 64] |= 1 << (k % 64);
            }
        }
        (samples, LitSeries { words: bits.len(), instants: pattern.len(), bits })
    }

    #[test]
    fn continuous_periods_and_the_longest_n() {
        // Periods of 30, 10, 60 and 20 minutes.
        let (samples, lit) = series("..###..#..######.##...");
        let mut rule = preset("bre-ground").unwrap_or_else(|e| panic!("{e}"));
        assert!((rule.hours(&samples, &lit, 0) - 2.0).abs() < 1e-9);
        rule.min_period_minutes = 20.0;
        assert!((rule.hours(&samples, &lit, 0) - 110.0 / 60.0).abs() < 1e-9);
        rule.longest = Some(2);
        assert!((rule.hours(&samples, &lit, 0) - 1.5).abs() < 1e-9);
        assert_eq!(rule.level(1.5), None);
        assert_eq!(rule.level(2.0), Some("pass"));
    }
}
