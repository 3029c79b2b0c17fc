//! Shading surfaces' `Transmittance Schedule Name`: which shades let how much of the beam
//! through, and when.
//!
//! Owns the link from `Shading:Site:Detailed`, `Shading:Building:Detailed` and
//! `Shading:Zone:Detailed` to their schedules ([`super::schedule`]), and the check that a
//! transmittance stays within 0..1. EnergyPlus's clipping counts a shade's shadow as (1 − τ) of
//! it, and shadows that overlap multiply their τ: the engines' see-through casters
//! ([`crate::scene::NodeVeil`]) do the same on average. A shade whose schedule is 0 all year is
//! an ordinary caster and one at 1 all year is left out; any other is counted opaque and removed
//! and the two mixed per timestep by its τ ([`crate::year::transmitting`]), which is exact on both
//! engines. A scene loaded as it is (for passes that take one scene) has such a shade as a
//! see-through caster of its constant τ, and opaque when τ changes.

use std::path::Path;

use super::idf::IdfObject;
use super::schedule::{RunCalendar, Schedule, Schedules};
use crate::error::{Error, Result};

/// Shades that share one transmittance schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadeGroup {
    /// The schedule.
    pub schedule: Schedule,
    /// The shading surfaces' names, as written.
    pub shades: Vec<String>,
}

impl ShadeGroup {
    /// The transmittance at every timestep of the run (row order); refused for a calendar date the
    /// run's year does not have.
    pub fn values(&self, calendar: RunCalendar<'_>) -> Result<Vec<f64>> {
        self.schedule.values(calendar)
    }

    /// The transmittance, when it is the same all year.
    pub fn constant(&self) -> Option<f64> {
        let values = self.schedule.all_values();
        let first = *values.first()?;
        values.iter().all(|v| *v == first).then_some(first)
    }
}

/// The field holding a shade class's transmittance schedule (0-based, after the class).
fn schedule_field(object: &IdfObject) -> Option<usize> {
    if object.is("Shading:Site:Detailed") || object.is("Shading:Building:Detailed") {
        Some(1)
    } else if object.is("Shading:Zone:Detailed") {
        Some(2)
    } else {
        None
    }
}

const FIELD: &str = "Transmittance Schedule Name";

/// Every shade with a transmittance schedule, grouped by schedule; refused with the shade, the
/// field and the reason when a schedule does not exist, cannot be read, breaks its limits or
/// leaves 0..1.
pub fn read_shade_schedules(file: &str, objects: &[IdfObject], dir: Option<&Path>) -> Result<Vec<ShadeGroup>> {
    let schedules = Schedules::new(file, objects, dir);
    let mut groups: Vec<ShadeGroup> = Vec::new();
    for object in objects {
        let Some(field) = schedule_field(object) else { continue };
        let name = object.field(field).trim();
        let Some(shade) = object.name().filter(|_| !name.is_empty()) else { continue };
        if let Some(group) = groups.iter_mut().find(|g| g.schedule.name.eq_ignore_ascii_case(name)) {
            group.shades.push(shade.to_string());
            continue;
        }
        let schedule = schedules.resolve(name, &object.label(), FIELD)?;
        if let Some(v) = schedule.all_values().into_iter().find(|v| !(0.0..=1.0).contains(v)) {
            return Err(Error::object(
                file,
                object.label(),
                format!("field '{FIELD}': {} takes the value {v}, outside 0..1 for a transmittance", schedule.label),
            ));
        }
        groups.push(ShadeGroup { schedule, shades: vec![shade.to_string()] });
    }
    Ok(groups)
}
