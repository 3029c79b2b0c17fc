//! The receivers a year is counted for ([`Columns`]: all of the scene's, or a range of them, a
//! batch of a city's) and where its time went ([`YearStages`]).

use std::ops::Range;

use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::scene::Scene;
use crate::year::samples::Timesteps;

/// The receivers a year is counted for, a range of the scene's, and their schedule so far.
pub(in crate::year) struct Columns {
    /// The scene's index of the schedule's first column.
    pub(super) first: usize,
    /// One column a receiver of the range.
    pub schedule: Schedule,
    /// Where the time went.
    pub stages: YearStages,
}

impl Columns {
    /// Zeros for the scene's `receivers`; refused where the range leaves the scene.
    pub(super) fn new(scene: &Scene, receivers: Range<usize>, timesteps: Timesteps) -> Result<Self> {
        let Some(chosen) = scene.receivers.get(receivers.clone()) else {
            return Err(Error::argument(
                "receivers",
                format!("{}..{} leaves the scene's {} receivers", receivers.start, receivers.end, scene.receivers.len()),
            ));
        };
        let names = chosen.iter().map(|r| r.name.clone()).collect();
        Ok(Columns { first: receivers.start, schedule: Schedule::zeros(names, timesteps), stages: YearStages::default() })
    }

    /// The scene's receivers these columns are.
    pub(in crate::year) fn range(&self) -> Range<usize> {
        self.first..self.first + self.schedule.names.len()
    }

    /// Sets the value of the scene's receiver `receiver` at `row`.
    pub(in crate::year) fn set(&mut self, row: usize, receiver: usize, value: f32) {
        self.schedule.set(row, receiver - self.first, value);
    }
}

/// Where a year's time went, in seconds of wall time, and the views each stage counted; the view
/// stages' CPU seconds too (every thread of the process: CPU / wall is the cores kept busy).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct YearStages {
    /// Counting the sample views (a dense or periodic year: all its views).
    pub sampling: f64,
    /// CPU seconds of the spline year's sample views.
    pub sampling_cpu: f64,
    /// Sample views counted.
    pub sample_views: usize,
    /// Fitting the splines and evaluating them at every timestep.
    pub fitting: f64,
    /// Settling refined steps by certificate (and proving interpolated ones never dark).
    pub certifying: f64,
    /// Counting the refined steps left (by bisection in days, [`crate::year::refine`]).
    pub refining: f64,
    /// CPU seconds of the spline year's refined steps.
    pub refining_cpu: f64,
    /// Refined steps counted.
    pub refined_views: usize,
}

impl YearStages {
    /// The two added, stage by stage.
    pub fn add(&mut self, other: &YearStages) {
        self.sampling += other.sampling;
        self.sampling_cpu += other.sampling_cpu;
        self.sample_views += other.sample_views;
        self.fitting += other.fitting;
        self.certifying += other.certifying;
        self.refining += other.refining;
        self.refining_cpu += other.refining_cpu;
        self.refined_views += other.refined_views;
    }
}
