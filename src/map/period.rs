//! When the map is evaluated: a year, a date range, one day at minute steps, one instant.
//!
//! The sun comes from [`crate::sun::position::sun_direction`] on the day
//! [`crate::year::annual::shading_sun_day`] gives, as `sunlit annual` computes it, so a map's
//! instants see the sun the schedule does. Year and date-range instants are EnergyPlus's
//! timesteps ([`Timesteps::instant`]: mid-hour at one an hour, the timestep's end otherwise), each
//! standing for `1/N` h; a day's instants are the middles of its steps, each standing for the step.

use crate::error::{Error, Result};
use crate::year::samples::{DAYS, Timesteps};
use crate::year::season::parse_day;

/// A period of evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Period {
    /// Days `first..=last` (days of the year, 1..=365) at `per_hour` EnergyPlus timesteps an hour;
    /// `1..=365` is the whole year.
    Days {
        /// First day of the year.
        first: u32,
        /// Last day of the year (inclusive).
        last: u32,
        /// Timesteps an hour (one EnergyPlus accepts).
        per_hour: u32,
    },
    /// One day between two times (minutes after midnight, local standard time) in steps.
    Day {
        /// Day of the year.
        day: u32,
        /// Start, minutes (0..=1440).
        from: u32,
        /// End, minutes (`from < to <= 1440`).
        to: u32,
        /// Step, minutes (1..=60, dividing `to − from`).
        step: u32,
    },
    /// One instant (sun hours over it are 0; its visibility is what counts).
    At {
        /// Day of the year.
        day: u32,
        /// Minutes after midnight, local standard time (0..1440).
        minute: u32,
    },
}

/// One instant of a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Day of the year.
    pub day: u32,
    /// Local standard time, hours.
    pub hour: f64,
    /// Hours this instant stands for.
    pub hours: f64,
    /// The EPW hour (0..8760) whose irradiance applies.
    pub epw_hour: usize,
}

impl Period {
    /// The whole year at `per_hour` timesteps an hour.
    pub fn annual(per_hour: u32) -> Result<Self> {
        Self::days(1, DAYS, per_hour)
    }

    /// Days `first..=last` at `per_hour` timesteps an hour; refuses a range that runs backwards
    /// and timesteps EnergyPlus does not accept.
    pub fn days(first: u32, last: u32, per_hour: u32) -> Result<Self> {
        Timesteps::new(per_hour).map_err(|_| {
            Error::argument(
                "step",
                format!(
                    "{} min: over days the step must be an EnergyPlus timestep (60, 30, 20, 15, 12, 10, 6, 5, 4, 3, 2 or 1 min)",
                    60.0 / f64::from(per_hour.max(1))
                ),
            )
        })?;
        if !(1..=DAYS).contains(&first) || !(first..=DAYS).contains(&last) {
            return Err(Error::argument("period", format!("days {first}..{last}: the first must not come after the last")));
        }
        Ok(Self::Days { first, last, per_hour })
    }

    /// One day from `from` to `to` (minutes) at `step` minutes; refuses `from ≥ to`, times past
    /// 24:00, a step outside 1..=60 or one that does not divide the window.
    pub fn day(day: u32, from: u32, to: u32, step: u32) -> Result<Self> {
        if !(1..=DAYS).contains(&day) {
            return Err(Error::argument("period", format!("day {day} is not in 1..=365")));
        }
        if to > 24 * 60 || from >= to {
            return Err(Error::argument("from", format!("{} is not before {}", clock(from), clock(to))));
        }
        if !(1..=60).contains(&step) {
            return Err(Error::argument("step", format!("{step} min: a day's step must be 1 to 60 minutes")));
        }
        if !(to - from).is_multiple_of(step) {
            return Err(Error::argument("step", format!("{step} min does not divide {}–{} ({} min)", clock(from), clock(to), to - from)));
        }
        Ok(Self::Day { day, from, to, step })
    }

    /// One instant; refuses a time outside the day.
    pub fn at(day: u32, minute: u32) -> Result<Self> {
        if !(1..=DAYS).contains(&day) || minute >= 24 * 60 {
            return Err(Error::argument("at", format!("day {day} at {} does not exist", clock(minute))));
        }
        Ok(Self::At { day, minute })
    }

    /// Every instant, in time order.
    pub fn samples(&self) -> Vec<Sample> {
        match *self {
            Self::Days { first, last, per_hour } => {
                let Ok(timesteps) = Timesteps::new(per_hour) else { return Vec::new() };
                let per_day = 24 * per_hour as usize;
                let rows = (first as usize - 1) * per_day..last as usize * per_day;
                rows.map(|row| {
                    let i = timesteps.instant(row);
                    Sample { day: i.day, hour: i.hour, hours: 1.0 / f64::from(per_hour), epw_hour: row / per_hour as usize }
                })
                .collect()
            }
            Self::Day { day, from, to, step } => (0..(to - from) / step)
                .map(|k| {
                    let hour = (f64::from(from) + (f64::from(k) + 0.5) * f64::from(step)) / 60.0;
                    Sample { day, hour, hours: f64::from(step) / 60.0, epw_hour: epw_hour(day, hour) }
                })
                .collect(),
            Self::At { day, minute } => {
                let hour = f64::from(minute) / 60.0;
                vec![Sample { day, hour, hours: 0.0, epw_hour: epw_hour(day, hour) }]
            }
        }
    }

    /// The day, for a one-day period or an instant.
    pub fn single_day(&self) -> Option<u32> {
        match *self {
            Self::Day { day, .. } | Self::At { day, .. } => Some(day),
            Self::Days { first, last, .. } => (first == last).then_some(first),
        }
    }
}

/// The EPW record holding `hour` of `day` (an EPW record covers the hour before its stamp).
fn epw_hour(day: u32, hour: f64) -> usize {
    (day as usize - 1) * 24 + (hour.floor() as usize).min(23)
}

/// `HH:MM` of minutes after midnight.
pub fn clock(minutes: u32) -> String {
    format!("{:02}:{:02}", minutes / 60, minutes % 60)
}

/// Parses `HH:MM` (00:00..=24:00) into minutes after midnight; `what` names the parameter.
pub fn parse_clock(what: &str, text: &str) -> Result<u32> {
    let bad = || Error::argument(what, format!("'{text}' is not a time HH:MM between 00:00 and 24:00"));
    let (h, m) = text.trim().split_once(':').ok_or_else(bad)?;
    let (h, m): (u32, u32) = (h.parse().map_err(|_| bad())?, m.parse().map_err(|_| bad())?);
    if m >= 60 || h > 24 || (h == 24 && m > 0) {
        return Err(bad());
    }
    Ok(h * 60 + m)
}

/// Parses `MM-DD` into a day of the year (365-day year); `what` names the parameter.
pub fn parse_date(what: &str, text: &str) -> Result<u32> {
    if !text.contains('-') {
        return Err(Error::argument(what, format!("'{text}' is not a date MM-DD")));
    }
    parse_day(text).map(|d| d as u32).map_err(|_| Error::argument(what, format!("'{text}' is not a date MM-DD that exists (365-day year)")))
}
