//! The leaf calendar: what fraction of a deciduous canopy is in leaf on a day of the year.
//!
//! Owns the rule the foliage layer follows (see [`crate::scene::Veil`]): the leaf fraction is 0
//! in winter, rises linearly over leaf-out, is 1 in summer and falls linearly over leaf fall, as
//! the number of leaves was varied in the paper's Blaas case. The phases are the regimes the
//! annual fit is split by (`crate::year::annual`): within each the fraction is smooth in the day.

use crate::error::{Error, Result};
use crate::year::samples::DAYS;

const YEAR: f64 = DAYS as f64;

/// Which part of the leaf year a day is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// No leaves (fraction 0).
    Bare,
    /// Leaves coming out (fraction rising from 0 to 1).
    LeafOut,
    /// Full leaf (fraction 1).
    Full,
    /// Leaves falling (fraction falling from 1 to 0).
    LeafFall,
}

/// Leaf-out and leaf-fall periods, as days of the year (1-based, a period may run over New Year),
/// or evergreen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeafCalendar {
    /// First and last day of leaf-out.
    pub leaf_out: (f64, f64),
    /// First and last day of leaf fall.
    pub leaf_fall: (f64, f64),
    /// Leaves all year (the dates are ignored).
    pub evergreen: bool,
}

/// Northern temperate deciduous trees: leaf-out 15 April – 31 May, leaf fall 1 October – 15 November.
pub const NORTHERN: LeafCalendar = LeafCalendar { leaf_out: (105.0, 151.0), leaf_fall: (274.0, 319.0), evergreen: false };

impl Default for LeafCalendar {
    fn default() -> Self {
        NORTHERN
    }
}

impl LeafCalendar {
    /// The default calendar at a latitude: [`NORTHERN`], or half a year later south of the equator.
    pub fn for_latitude(latitude: f64) -> Self {
        if latitude < 0.0 { NORTHERN.shifted(YEAR / 2.0) } else { NORTHERN }
    }

    /// Every leaf on every day.
    pub fn evergreen() -> Self {
        Self { evergreen: true, ..NORTHERN }
    }

    /// Checks that each period has a length and that leaf-out ends before leaf fall begins and
    /// leaf fall ends before the next leaf-out (around the year).
    pub fn new(leaf_out: (f64, f64), leaf_fall: (f64, f64)) -> Result<Self> {
        let calendar =
            Self { leaf_out: (wrap(leaf_out.0), wrap(leaf_out.1)), leaf_fall: (wrap(leaf_fall.0), wrap(leaf_fall.1)), evergreen: false };
        let (out, full, fall) = calendar.offsets();
        let ordered = out > 0.0 && full >= out && fall > full && fall < YEAR;
        if !leaf_out.0.is_finite() || !leaf_out.1.is_finite() || !leaf_fall.0.is_finite() || !leaf_fall.1.is_finite() || !ordered {
            return Err(Error::argument(
                "leaf_out/leaf_fall",
                "leaf-out and leaf fall must each last at least a day, in the order leaf-out, summer, leaf fall, winter".to_string(),
            ));
        }
        Ok(calendar)
    }

    fn shifted(self, days: f64) -> Self {
        let s = |(a, b): (f64, f64)| (wrap(a + days), wrap(b + days));
        Self { leaf_out: s(self.leaf_out), leaf_fall: s(self.leaf_fall), evergreen: self.evergreen }
    }

    /// Days after leaf-out begins at which leaf-out ends, leaf fall begins and leaf fall ends.
    fn offsets(&self) -> (f64, f64, f64) {
        let after = |d: f64| (d - self.leaf_out.0).rem_euclid(YEAR);
        (after(self.leaf_out.1), after(self.leaf_fall.0), after(self.leaf_fall.1))
    }

    /// The phase of day-of-year `day` (fractional; any real, taken around the year).
    pub fn phase(&self, day: f64) -> Phase {
        if self.evergreen {
            return Phase::Full;
        }
        let (out, full, fall) = self.offsets();
        let x = (day - self.leaf_out.0).rem_euclid(YEAR);
        if x < out {
            Phase::LeafOut
        } else if x <= full {
            Phase::Full
        } else if x < fall {
            Phase::LeafFall
        } else {
            Phase::Bare
        }
    }

    /// The leaf fraction on day `day`, in [0, 1].
    pub fn fraction(&self, day: f64) -> f64 {
        let (out, full, fall) = self.offsets();
        let x = (day - self.leaf_out.0).rem_euclid(YEAR);
        match self.phase(day) {
            Phase::Bare => 0.0,
            Phase::Full => 1.0,
            Phase::LeafOut => x / out,
            Phase::LeafFall => 1.0 - (x - full) / (fall - full),
        }
    }

    /// A ramp as (first day, length in days), the first day as given (may be past 365 − length).
    pub fn ramp(&self, phase: Phase) -> Option<(f64, f64)> {
        let (out, full, fall) = self.offsets();
        match phase {
            Phase::LeafOut if !self.evergreen => Some((self.leaf_out.0, out)),
            Phase::LeafFall if !self.evergreen => Some((self.leaf_fall.0, fall - full)),
            _ => None,
        }
    }
}

/// A day of year taken into (0, 365].
fn wrap(day: f64) -> f64 {
    let d = day.rem_euclid(YEAR);
    if d == 0.0 { YEAR } else { d }
}

/// Parses `MM-DD` (or a day of the year, `1`–`365`) into a day of the year.
pub fn parse_day(text: &str) -> Result<f64> {
    let bad = || Error::argument("date", format!("'{text}' is not MM-DD or a day of the year (1–365)"));
    let text = text.trim();
    if let Some((m, d)) = text.split_once('-') {
        let (m, d): (u32, u32) = (m.parse().map_err(|_| bad())?, d.parse().map_err(|_| bad())?);
        let lengths = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
        if !(1..=12).contains(&m) || d == 0 || d > lengths[m as usize - 1] {
            return Err(bad());
        }
        return Ok((lengths[..m as usize - 1].iter().sum::<u32>() + d) as f64);
    }
    let day: f64 = text.parse().map_err(|_| bad())?;
    if (1.0..=YEAR).contains(&day) { Ok(day) } else { Err(bad()) }
}

/// Parses `START,END` (two dates for [`parse_day`]).
pub fn parse_period(text: &str) -> Result<(f64, f64)> {
    let (a, b) =
        text.split_once(',').ok_or_else(|| Error::argument("date period", format!("'{text}' is not START,END (e.g. 04-15,05-31)")))?;
    Ok((parse_day(a)?, parse_day(b)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fraction_ramps_between_bare_and_full() {
        let c = NORTHERN;
        assert_eq!(c.fraction(1.0), 0.0);
        assert_eq!(c.fraction(105.0), 0.0);
        assert!((c.fraction(128.0) - 0.5).abs() < 1e-12);
        assert_eq!(c.fraction(151.0), 1.0);
        assert_eq!(c.fraction(200.0), 1.0);
        assert!((c.fraction(296.5) - 0.5).abs() < 1e-12);
        assert_eq!(c.fraction(319.0), 0.0);
        assert_eq!(c.phase(120.0), Phase::LeafOut);
        assert_eq!(c.phase(300.0), Phase::LeafFall);
        assert_eq!(c.phase(365.0), Phase::Bare);
        let ramp: Vec<f64> = (105..=151).map(|d| c.fraction(d as f64)).collect();
        assert!(ramp.windows(2).all(|w| w[1] > w[0]), "leaf-out rises every day");
    }

    #[test]
    fn the_south_is_half_a_year_later_and_evergreens_keep_their_leaves() {
        let south = LeafCalendar::for_latitude(-33.9);
        assert_eq!(south.fraction(200.0), 0.0, "July is winter in Sydney");
        assert_eq!(south.fraction(15.0), 1.0, "January is summer");
        assert!((south.fraction(128.0 + 182.5) - 0.5).abs() < 1e-12);
        assert_eq!(LeafCalendar::evergreen().fraction(1.0), 1.0);
    }

    #[test]
    fn periods_may_cross_new_year_and_bad_ones_are_refused() {
        let c = LeafCalendar::new((parse_day("12-01").unwrap(), parse_day("01-31").unwrap()), (150.0, 200.0)).unwrap();
        assert!((c.fraction(365.0) - 30.0 / 61.0).abs() < 1e-12);
        assert_eq!(c.fraction(100.0), 1.0);
        assert_eq!(c.ramp(Phase::LeafOut), Some((335.0, 61.0)));
        assert!(LeafCalendar::new((200.0, 150.0), (100.0, 120.0)).is_err(), "leaf fall inside leaf-out's year order");
        assert!(LeafCalendar::new((100.0, 100.0), (200.0, 220.0)).is_err(), "zero-length leaf-out");
        assert_eq!(parse_day("04-15").unwrap(), 105.0);
        assert!(parse_day("02-30").is_err() && parse_day("0").is_err() && parse_day("x").is_err());
        assert_eq!(parse_period("04-15,05-31").unwrap(), (105.0, 151.0));
    }
}
