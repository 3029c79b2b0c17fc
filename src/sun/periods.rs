//! EnergyPlus's Periodic shading update: one sun for every day of a period.
//!
//! Owns the sun a model's shading sees when its `ShadowCalculation` updates periodically (the
//! `Periodic` update frequency method, EnergyPlus's default with a frequency of 20 days when a model
//! has no `ShadowCalculation`). `PerformSolarCalculations` (SolarShading.cc) then computes the
//! shading once a period, on its first day, for a sun whose sine of declination and equation of
//! time are the means of `SUN3` over the period's days (`SumDec / ShadowingDaysLeft`,
//! `SumET / ShadowingDaysLeft`, cos δ = √(1 − mean sin²δ)), and uses those fractions (and that
//! sun's `SUNCOSTS` for dark and lit) on every day of the period. Periods start on the run
//! period's first day, every `days` days, the last one shortened to the run's end. Measured on
//! EnergyPlus 25.2 (docs/energyplus-fidelity.md, "The Timestep 6 noon crossing"): a sunlit year
//! counted for this sun has no timestep dark in one and lit in the other at the plane crossings,
//! where the calendar day's sun had hundreds.

use glam::DVec3;

use super::location::Location;
use super::position::{declination_and_equation_of_time, sun_direction_from};

/// A Periodic shading update over a run period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShadingPeriods {
    /// Days a period (the update frequency), at least 1.
    pub days: u32,
    /// The run period's first day of the year (1-based).
    pub first_day: u32,
    /// Days in the run period.
    pub run_days: u32,
}

impl ShadingPeriods {
    /// The period holding calendar day `day` (1-based) of a year of `year_days` days: its first
    /// day and length. A day outside the run period (a run that starts or ends within the year)
    /// is a period of its own.
    pub fn period_of(&self, day: u32, year_days: u32) -> (u32, u32) {
        let days = self.days.max(1);
        let offset = (day + year_days - self.first_day.min(year_days)) % year_days.max(1);
        if offset >= self.run_days {
            return (day, 1);
        }
        let start = offset / days * days;
        ((self.first_day + start - 1) % year_days.max(1) + 1, days.min(self.run_days - start))
    }

    /// The sun EnergyPlus's shading uses on calendar day `day` at local standard hour `hour`:
    /// the means of the period's declination and equation of time.
    pub fn sun(&self, location: &Location, day: u32, year_days: u32, hour: f64) -> DVec3 {
        let (sin_declination, equation_of_time) = self.mean_sun(day, year_days);
        sun_direction_from(location, sin_declination, equation_of_time, hour)
    }

    /// Mean sine of declination and equation of time (hours) over the period of `day`, each day
    /// at its integer day of year as EnergyPlus passes it (`PerDayOfYear`, counting on past the
    /// year's end as EnergyPlus's loop does).
    pub fn mean_sun(&self, day: u32, year_days: u32) -> (f64, f64) {
        let (start, length) = self.period_of(day, year_days);
        let (sum_sin, sum_eot) = (start..start + length)
            .map(|d| declination_and_equation_of_time(f64::from(d)))
            .fold((0.0, 0.0), |(s, e), (ds, de)| (s + ds, e + de));
        (sum_sin / f64::from(length), sum_eot / f64::from(length))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const YEAR: ShadingPeriods = ShadingPeriods { days: 7, first_day: 1, run_days: 365 };

    /// Periods of 7 days from 1 January: 1–7, 8–14, …, and the last one (day 365) alone.
    #[test]
    fn periods_start_on_the_run_period_and_end_with_it() {
        assert_eq!(YEAR.period_of(1, 365), (1, 7));
        assert_eq!(YEAR.period_of(7, 365), (1, 7));
        assert_eq!(YEAR.period_of(8, 365), (8, 7));
        assert_eq!(YEAR.period_of(364, 365), (358, 7));
        assert_eq!(YEAR.period_of(365, 365), (365, 1));
        // 15 March (day 74) to 21 October (day 294).
        let summer = ShadingPeriods { days: 20, first_day: 74, run_days: 221 };
        assert_eq!(summer.period_of(74, 365), (74, 20));
        assert_eq!(summer.period_of(100, 365), (94, 20));
        assert_eq!(summer.period_of(293, 365), (274, 20));
        assert_eq!(summer.period_of(294, 365), (294, 1), "the run's last period: one day");
        assert_eq!(summer.period_of(10, 365), (10, 1), "before the run: its own day");
        assert_eq!(summer.period_of(300, 365), (300, 1), "after the run");
    }

    /// The period's sun is the mean of SUN3 over its days, not any one day's: in June the
    /// equation of time falls by about 12 s a day, so the mean of days 155–161 is that of day 158.
    #[test]
    fn the_sun_is_averaged_over_the_period() {
        let (sin, eot) = YEAR.mean_sun(160, 365);
        let days: Vec<(f64, f64)> = (155..=161).map(|d| declination_and_equation_of_time(f64::from(d))).collect();
        assert!((sin - days.iter().map(|d| d.0).sum::<f64>() / 7.0).abs() < 1e-15);
        assert!((eot - days.iter().map(|d| d.1).sum::<f64>() / 7.0).abs() < 1e-15);
        assert!((eot - days[3].1).abs() < 0.2 / 60.0, "near the middle day's");
        assert!((eot - days[0].1).abs() > 0.4 / 60.0, "and not the first day's");
        let one_day = ShadingPeriods { days: 1, ..YEAR };
        assert_eq!(one_day.mean_sun(160, 365), declination_and_equation_of_time(160.0));
    }
}
