//! Sun samples in time: EnergyPlus's timestep instants and the sparse sampling plan.
//!
//! Owns *when* fractions are wanted and *when* they are counted:
//! - [`Timesteps`]: the 8760·N instants EnergyPlus asks for. Rows run day → hour → timestep over
//!   365 days; with N > 1 a timestep's value holds at its end, t = h − 1 + ts/N (local standard
//!   time), with N = 1 at mid-hour, t = h − 0.5 (EnergyPlus's own convention). Each row is
//!   stamped ` MM/DD HH:MM` at the end of its timestep, as in EnergyPlus's eplusshading.csv.
//! - [`SamplingPlan`]: D days evenly over the (periodic) year on the [`SeasonAxis`], and S
//!   normalised times per lit piece of a day at the Chebyshev nodes
//!   τ_j = ½ − ½·cos(π(j + ½)/S), where τ = 0 is where the surface's lit piece begins (sunrise, or
//!   the sun coming round in front of it) and τ = 1 where it ends. The nodes crowd towards both
//!   ends, where shadows move fastest (low sun, grazing incidence): on the example office this
//!   halves the RMS error of uniform times. They never touch the ends themselves, where every
//!   fraction is 0 by definition and the spline would see a jump.
//! - [`SeasonAxis`]: the year coordinate the days are spaced on. A static scene's fraction depends
//!   only on the sun's direction, and with times placed within each lit piece the sample's
//!   direction depends only on the day's declination (the equation of time shifts the clock, not
//!   the hour angle). Every declination but the extremes occurs twice a year, so days placed in
//!   pairs of equal declination need only half the views. The axis is the declination's *phase*:
//!   sin δ = m + h·cos ψ, ψ running once round the year from the June solstice; days evenly
//!   spaced in ψ and symmetric about ψ = 0 pair up exactly ([`SamplingPlan::twin`]). ψ follows the
//!   calendar to within a few days (Earth's orbit is nearly circular), so the spline's spacing is
//!   still even in days to that extent.

use crate::error::{Error, Result};
use crate::sun::position::declination_and_equation_of_time;

/// The timestep counts per hour EnergyPlus accepts.
pub const VALID_TIMESTEPS: [u32; 12] = [1, 2, 3, 4, 5, 6, 10, 12, 15, 20, 30, 60];
/// Days in EnergyPlus's annual schedule year (no leap day).
pub const DAYS: u32 = 365;
const MONTH_DAYS: [u32; 12] = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];

/// Timesteps per hour, checked against what EnergyPlus accepts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timesteps(u32);

/// One output row's instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instant {
    /// Day of year, 1..=365.
    pub day: u32,
    /// Local standard time in hours at which the value holds.
    pub hour: f64,
}

impl Timesteps {
    /// `per_hour` must be one of [`VALID_TIMESTEPS`].
    pub fn new(per_hour: u32) -> Result<Self> {
        if VALID_TIMESTEPS.contains(&per_hour) {
            Ok(Self(per_hour))
        } else {
            Err(Error::argument("timesteps_per_hour", format!("{per_hour} is not one EnergyPlus accepts ({VALID_TIMESTEPS:?})")))
        }
    }

    /// Timesteps per hour.
    pub fn per_hour(self) -> u32 {
        self.0
    }

    /// Rows in a year: 8760·N.
    pub fn rows(self) -> usize {
        (DAYS * 24 * self.0) as usize
    }

    /// The instant of row `row` (0-based).
    pub fn instant(self, row: usize) -> Instant {
        let n = self.0 as usize;
        let day = (row / (24 * n)) as u32 + 1;
        let hour = (row / n) % 24 + 1;
        let ts = row % n + 1;
        let t = if n == 1 { hour as f64 - 0.5 } else { (hour - 1) as f64 + ts as f64 / n as f64 };
        Instant { day, hour: t }
    }

    /// All instants in row order.
    pub fn instants(self) -> impl Iterator<Item = Instant> {
        (0..self.rows()).map(move |r| self.instant(r))
    }

    /// ` MM/DD HH:MM` at the end of row `row`'s timestep (the last row of a day reads `24:00`).
    pub fn stamp(self, row: usize) -> String {
        let n = self.0 as usize;
        let day = row / (24 * n) + 1;
        let minutes = ((row % (24 * n)) + 1) * 60 / n;
        let (month, dom) = month_day(day as u32);
        format!(" {month:02}/{dom:02} {:02}:{:02}", minutes / 60, minutes % 60)
    }
}

/// Month and day of month (1-based) of a day of a non-leap year.
pub fn month_day(day_of_year: u32) -> (u32, u32) {
    let mut d = day_of_year.clamp(1, DAYS);
    for (m, len) in MONTH_DAYS.iter().enumerate() {
        if d <= *len {
            return (m as u32 + 1, d);
        }
        d -= len;
    }
    (12, 31)
}

/// Days per year × samples per day.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SamplingPlan {
    /// Sampled days, evenly over the year.
    pub days: usize,
    /// Samples per day, evenly over daylight.
    pub per_day: usize,
}

impl Default for SamplingPlan {
    fn default() -> Self {
        Self { days: 27, per_day: 19 }
    }
}

impl SamplingPlan {
    /// Checks the ranges: 3..=365 days (a periodic quadratic needs three), 3..=240 per day.
    pub fn new(days: usize, per_day: usize) -> Result<Self> {
        if !(3..=DAYS as usize).contains(&days) {
            return Err(Error::argument("days_per_year", format!("{days} is outside 3..=365")));
        }
        if !(3..=240).contains(&per_day) {
            return Err(Error::argument("samples_per_day", format!("{per_day} is outside 3..=240")));
        }
        Ok(Self { days, per_day })
    }

    /// [`SeasonAxis`] coordinate of the first sample; the others follow every 365/D. With D odd
    /// the first sample is the June solstice (its own twin); with D even the solstice falls
    /// half a spacing before it, so every sample has a distinct twin.
    pub fn first_day(&self) -> f64 {
        let offset = if self.days % 2 == 0 { 0.5 } else { 0.0 };
        SeasonAxis::new().june_solstice() + offset * self.spacing()
    }

    /// Spacing of the sample days on the [`SeasonAxis`].
    pub fn spacing(&self) -> f64 {
        DAYS as f64 / self.days as f64
    }

    /// [`SeasonAxis`] coordinates of the sampled days.
    pub fn sample_coordinates(&self) -> Vec<f64> {
        (0..self.days).map(|d| self.first_day() + d as f64 * self.spacing()).collect()
    }

    /// Sampled days of year (fractional, in [1, 366)).
    pub fn sample_days(&self) -> Vec<f64> {
        let axis = SeasonAxis::new();
        self.sample_coordinates().into_iter().map(|y| axis.day(y)).collect()
    }

    /// The sample day with the same declination as day `d` (`d` itself at the solstice): ψ_d
    /// and −ψ_d, i.e. d ↔ D − d (D odd) or d ↔ D − 1 − d (D even).
    pub fn twin(&self, d: usize) -> usize {
        let n = self.days;
        if n % 2 == 0 { n - 1 - d } else { (n - d) % n }
    }

    /// Normalised times τ of the samples within each lit piece (Chebyshev nodes on (0, 1)).
    pub fn taus(&self) -> Vec<f64> {
        (0..self.per_day).map(|j| 0.5 - 0.5 * (std::f64::consts::PI * (j as f64 + 0.5) / self.per_day as f64).cos()).collect()
    }
}

/// The year coordinate of [`SamplingPlan`]'s days: see the module doc. A coordinate y stands for
/// declination phase ψ = 2π·(y − y₀)/365, y₀ the June solstice's day; it grows by 365 a year and
/// equals the day of year at both solstices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeasonAxis {
    /// Day of the largest and of the smallest declination.
    june: f64,
    december: f64,
    /// sin δ = middle + half·cos ψ.
    middle: f64,
    half: f64,
}

impl Default for SeasonAxis {
    fn default() -> Self {
        Self::new()
    }
}

impl SeasonAxis {
    /// Finds the solstices of the sun model (a scan, then golden-section refinement).
    pub fn new() -> Self {
        let june = extreme_day(1.0);
        let december = extreme_day(-1.0);
        let (top, bottom) = (sine_declination(june), sine_declination(december));
        Self { june, december, middle: 0.5 * (top + bottom), half: 0.5 * (top - bottom) }
    }

    /// Day of year of the June solstice (the largest declination).
    pub fn june_solstice(&self) -> f64 {
        self.june
    }

    /// The coordinate of a day (any real day; the year repeats every 365 days).
    pub fn coordinate(&self, day: f64) -> f64 {
        let year = DAYS as f64;
        let since = (day - self.june).rem_euclid(year);
        let falling = (self.december - self.june).rem_euclid(year);
        let x = ((sine_declination(day) - self.middle) / self.half).clamp(-1.0, 1.0);
        // cos ψ = x, with ψ in [0, π] while the declination falls and in [π, 2π] while it rises.
        let psi = if since <= falling { x.acos() } else { std::f64::consts::TAU - x.acos() };
        day - since + psi * year / std::f64::consts::TAU
    }

    /// The day of year (in [1, 366)) at a coordinate: the inverse of [`Self::coordinate`].
    pub fn day(&self, coordinate: f64) -> f64 {
        // The coordinate never strays from the day by more than a few days; bisect a month.
        let (mut lo, mut hi) = (coordinate - 30.0, coordinate + 30.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.coordinate(mid) < coordinate {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (0.5 * (lo + hi) - 1.0).rem_euclid(DAYS as f64) + 1.0
    }
}

/// Sine of the declination on any real day, the year taken as 365 days from day 1.
fn sine_declination(day: f64) -> f64 {
    declination_and_equation_of_time((day - 1.0).rem_euclid(DAYS as f64) + 1.0).0
}

/// The day where `sign`·sin δ is largest.
fn extreme_day(sign: f64) -> f64 {
    let f = |d: f64| sign * sine_declination(d);
    let best = (0..4 * DAYS).map(|k| 1.0 + k as f64 / 4.0).max_by(|a, b| f(*a).total_cmp(&f(*b))).unwrap_or(1.0);
    // Golden section on the bracketing quarter days.
    let (mut a, mut b) = (best - 0.25, best + 0.25);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if f(c) > f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_and_instants_follow_energyplus() {
        let ts = Timesteps::new(4).unwrap();
        assert_eq!(ts.rows(), 35_040);
        assert_eq!(ts.stamp(0), " 01/01 00:15");
        assert_eq!(ts.stamp(3), " 01/01 01:00");
        assert_eq!(ts.stamp(95), " 01/01 24:00");
        assert_eq!(ts.stamp(96), " 01/02 00:15");
        assert_eq!(ts.stamp(ts.rows() - 1), " 12/31 24:00");
        assert_eq!(ts.instant(0), Instant { day: 1, hour: 0.25 });
        assert_eq!(ts.instant(95), Instant { day: 1, hour: 24.0 });
        let one = Timesteps::new(1).unwrap();
        assert_eq!(one.rows(), 8760);
        assert_eq!(one.instant(12), Instant { day: 1, hour: 12.5 });
        assert_eq!(one.stamp(12), " 01/01 13:00");
        assert_eq!(one.stamp(8759), " 12/31 24:00");
        assert_eq!(Timesteps::new(60).unwrap().stamp(0), " 01/01 00:01");
        assert_eq!(month_day(59), (2, 28));
        assert_eq!(month_day(60), (3, 1));
    }

    #[test]
    fn bad_plans_and_timesteps_are_refused() {
        for n in [0, 7, 8, 9, 11, 120] {
            assert!(Timesteps::new(n).unwrap_err().to_string().contains("timesteps_per_hour"));
        }
        assert!(SamplingPlan::new(2, 19).is_err());
        assert!(SamplingPlan::new(27, 1).is_err());
        let plan = SamplingPlan::new(27, 19).unwrap();
        let days = plan.sample_days();
        assert!(days.iter().all(|d| (1.0..366.0).contains(d)));
        assert!(plan.taus().iter().all(|t| *t > 0.0 && *t < 1.0));
    }

    #[test]
    fn season_axis_follows_the_calendar_and_inverts() {
        let axis = SeasonAxis::new();
        // EnergyPlus's series puts the solstices near 21 June (172) and 21 December (355).
        assert!((axis.june_solstice() - 172.0).abs() < 3.0, "{}", axis.june_solstice());
        assert!((axis.december - 355.0).abs() < 3.0, "{}", axis.december);
        let mut previous = f64::NEG_INFINITY;
        for k in 0..3650 {
            let day = 1.0 + k as f64 * 0.1;
            let y = axis.coordinate(day);
            // Monotone, within a few days of the calendar, and inverted by `day`.
            assert!(y > previous - 1e-9, "not monotone at {day}");
            previous = y;
            assert!((y - day).abs() < 6.0, "{day} → {y}");
            let back = axis.day(y);
            assert!((back - day).abs() < 1e-6, "{day} → {y} → {back}");
        }
    }

    #[test]
    fn twin_days_have_the_same_declination() {
        for n in [3, 14, 27, 53] {
            let plan = SamplingPlan::new(n, 19).unwrap();
            let days = plan.sample_days();
            let distinct: std::collections::HashSet<usize> = (0..n).map(|d| d.min(plan.twin(d))).collect();
            assert_eq!(distinct.len(), n.div_ceil(2), "{n}");
            let mut unequal = 0;
            for d in 0..n {
                let t = plan.twin(d);
                assert_eq!(plan.twin(t), d);
                let (a, b) = (declination_and_equation_of_time(days[d]).0, declination_and_equation_of_time(days[t]).0);
                // The sun model's year is 366 days and the schedule's 365, so its declination
                // jumps by a day's change at New Year; a sample there has no exact twin.
                if (a - b).abs() > 1e-9 {
                    assert!((a - b).abs() < 3e-4, "{n}: day {} and {} differ: {a} vs {b}", days[d], days[t]);
                    unequal += 1;
                }
                // Evenly spaced on the axis.
                if d > 0 {
                    let step = SeasonAxis::new().coordinate(days[d]) - SeasonAxis::new().coordinate(days[d - 1]);
                    assert!((step.rem_euclid(365.0) - 365.0 / n as f64).abs() < 0.5, "{n}: step {step}");
                }
            }
            assert!(unequal <= 2, "{n}: {unequal} samples without an exact twin");
        }
    }
}
