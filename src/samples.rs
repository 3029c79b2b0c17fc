//! Sun samples in time: EnergyPlus's timestep instants and the sparse sampling plan.
//!
//! Owns *when* fractions are wanted and *when* they are counted:
//! - [`Timesteps`]: the 8760·N instants EnergyPlus asks for. Rows run day → hour → timestep over
//!   365 days; with N > 1 a timestep's value holds at its end, t = h − 1 + ts/N (local standard
//!   time), with N = 1 at mid-hour, t = h − 0.5 (EnergyPlus's own convention). Each row is
//!   stamped ` MM/DD HH:MM` at the end of its timestep, as in EnergyPlus's eplusshading.csv.
//! - [`SamplingPlan`]: D days evenly over the (periodic) year at day-of-year 1 + (d + ½)·365/D,
//!   and S normalised times per lit piece of a day at the Chebyshev nodes
//!   τ_j = ½ − ½·cos(π(j + ½)/S), where τ = 0 is where the surface's lit piece begins (sunrise, or
//!   the sun coming round in front of it) and τ = 1 where it ends. The nodes crowd towards both
//!   ends, where shadows move fastest (low sun, grazing incidence): on the example office this
//!   halves the RMS error of uniform times. They never touch the ends themselves, where every
//!   fraction is 0 by definition and the spline would see a jump.

use crate::error::{Error, Result};

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
            Err(Error::argument("--timesteps-per-hour", format!("{per_hour} is not one EnergyPlus accepts ({VALID_TIMESTEPS:?})")))
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
            return Err(Error::argument("--days-per-year", format!("{days} is outside 3..=365")));
        }
        if !(3..=240).contains(&per_day) {
            return Err(Error::argument("--samples-per-day", format!("{per_day} is outside 3..=240")));
        }
        Ok(Self { days, per_day })
    }

    /// Day-of-year of the first sample; the others follow every 365/D days.
    pub fn first_day(&self) -> f64 {
        1.0 + 0.5 * DAYS as f64 / self.days as f64
    }

    /// Sampled days of year (fractional).
    pub fn sample_days(&self) -> Vec<f64> {
        (0..self.days).map(|d| self.first_day() + d as f64 * DAYS as f64 / self.days as f64).collect()
    }

    /// Normalised times τ of the samples within each lit piece (Chebyshev nodes on (0, 1)).
    pub fn taus(&self) -> Vec<f64> {
        (0..self.per_day).map(|j| 0.5 - 0.5 * (std::f64::consts::PI * (j as f64 + 0.5) / self.per_day as f64).cos()).collect()
    }
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
            assert!(Timesteps::new(n).unwrap_err().to_string().contains("--timesteps-per-hour"));
        }
        assert!(SamplingPlan::new(2, 19).is_err());
        assert!(SamplingPlan::new(27, 1).is_err());
        let plan = SamplingPlan::new(27, 19).unwrap();
        let days = plan.sample_days();
        assert!((days[0] - (1.0 + 365.0 / 54.0)).abs() < 1e-12 && days[26] < 366.0);
        assert!(plan.taus().iter().all(|t| *t > 0.0 && *t < 1.0));
    }
}
