//! A year for a model whose EnergyPlus shading updates periodically ([`Method::Periodic`]).
//!
//! Owns counting the year as EnergyPlus's `Periodic` update does: every day of a period gets the
//! fractions of one sun, the means of the period's declination and equation of time
//! ([`ShadingPeriods`]). So the year has one day's timesteps a period to count, each counted
//! directly (no spline: a period's fractions are its first day's, and counting them all costs a
//! period's length less than a dense year), and every day of the period repeats them. A hooked
//! model keeps the same update (`export::hook`), and EnergyPlus then reads each period's first
//! day of the CSV for the whole period, as its own clipping would have computed it.
//!
//! [`Method::Periodic`]: super::annual::Method::Periodic

use std::collections::HashMap;

use super::annual::{Columns, Progress, Views, as_energyplus, sun_is_up};
use super::season::LeafCalendar;
use crate::count::{Engine, ViewRequest, is_dark};
use crate::error::Result;
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::periods::ShadingPeriods;

/// Counts the year of `year`'s receivers under `periods`' suns: each period's timesteps of one day once,
/// written to every day of it. Foliage takes the period's first day's leaves (EnergyPlus reads a
/// shade's schedules on the day it computes the period's shading).
pub(super) async fn periodic_year(
    views: &Views<'_, impl Engine>,
    scene: &Scene,
    location: &Location,
    periods: ShadingPeriods,
    calendar: &LeafCalendar,
    year: &mut Columns,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<()> {
    let timesteps = year.schedule.timesteps;
    let year_days = timesteps.days();
    let per_day = timesteps.rows() / year_days as usize;
    // (period's first day, timestep of the day, receiver) → the request's index.
    let mut counted: HashMap<(u32, usize, usize), usize> = HashMap::new();
    let mut requests = Vec::new();
    let mut cells = Vec::new();
    for (row, instant) in timesteps.instants().enumerate() {
        let (start, _) = periods.period_of(instant.day, year_days);
        let sun = periods.sun(location, instant.day, year_days, instant.hour);
        if !sun_is_up(sun) {
            continue;
        }
        for column in year.range() {
            if is_dark(scene.receivers[column].normal, sun) {
                continue;
            }
            let index = *counted.entry((start, row % per_day, column)).or_insert_with(|| {
                requests.push(ViewRequest::new(column as u32, sun).with_leaves(calendar.fraction(f64::from(start)) as f32));
                requests.len() - 1
            });
            cells.push((row, column, index));
        }
    }
    // Later passes weigh these fractions by this sun's incidence, as EnergyPlus does.
    year.schedule.periods = Some(periods);
    let values = views.count(&requests, progress).await?;
    year.stages.sample_views += requests.len();
    for (row, column, index) in cells {
        year.set(row, column, as_energyplus(values[index]));
    }
    Ok(())
}
