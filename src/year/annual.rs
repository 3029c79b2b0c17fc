//! The annual schedule: count at sparse sun samples, fit the B-spline surface, evaluate it at
//! every EnergyPlus timestep ([`Method::Spline`]); or count every sun-up timestep ([`Method::Dense`],
//! the reference the spline is tested against). Any [`Engine`] answers the views
//! ([`annual_with`]); the GPU lanes are the usual one ([`annual_on`], [`annual_recovering`]).
//!
//! Owns the handling of the terminator. A surface's fraction drops to exactly 0 where it turns
//! away from the sun (cos θ ≤ 1e-5) or the sun sets; fitting through those zeros would make the
//! spline ring across the edge. So the spline is fitted only where the fraction is smooth: on
//! each day the surface's *lit pieces* (sun up and in front of it; one for most surfaces, two for
//! a north wall in summer) are found exactly from the sun model, the plan's S normalised times
//! are placed within each piece (τ = 0 where the piece begins, 1 where it ends), and each piece
//! gets its own spline surface over (day of year, τ). Days on which a piece does not exist borrow
//! the samples of the nearest day that has it, so the periodic fit stays defined; with refinement
//! on, the timesteps between such a day and its neighbour are counted, not extrapolated. At evaluation
//! the sun-up and facing tests are applied exactly per timestep; values are clamped to [0, 1].
//!
//! Foliage (a scene with leaves, [`crate::year::season`]): the fraction then changes with the leaf
//! cover as well as with the sun, and the leaf fraction has corners where leaf-out and leaf fall
//! begin and end, which a spline across them would round off. So the year is split into regimes
//! with a fit each: bare (no leaves) and full leaf, each fitted periodically over the whole year
//! at a fixed leaf fraction (0 or 1), and each ramp fitted over its own days: sampled from its
//! first to its last day at least [`RAMP_DAYS`] + 1 times, crowded where few leaves are out (see
//! [`DayMap::Ramp`]), with the samples mirrored at both ends so the same periodic fit applies.
//! A day takes the fit of its phase. Without foliage (or evergreen) there is one regime, all leaves.

use std::ops::Range;

use glam::DVec3;

use crate::count::gpu::{Counter, GpuScene};
use crate::count::lanes::{Lane, Lanes};
use crate::count::{Engine, MIN_COS_INCIDENCE, ViewRequest, is_dark};
use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::platform::{cpu_seconds, seconds as now};
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::periods::ShadingPeriods;
use crate::sun::position::{lit_intervals, sun_direction};
use crate::year::certified::{self, Rough, RowSuns, Rule, Smooth};
use crate::year::fitted::{FittedSurfaces, FittedYear};
use crate::year::refine;
use crate::year::samples::{DAYS, SamplingPlan, SeasonAxis, Timesteps};
use crate::year::season::{LeafCalendar, Phase};
use crate::year::spline::{AnnualGrid, AnnualSpline};
pub(super) use columns::Columns;
pub use columns::YearStages;
use fill::fill_dark;
pub use sampling::sample_requests;
use sampling::{SampleViews, sample_views};

/// How the year is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Count at the plan's samples, interpolate with the B-spline surface.
    Spline(SamplingPlan),
    /// Count every sun-up timestep directly (slow; the reference).
    Dense,
    /// EnergyPlus's Periodic shading update: one sun a period, counted directly
    /// ([`super::periodic`]).
    Periodic(crate::sun::periods::ShadingPeriods),
}

/// Settings of an annual run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnnualOptions {
    /// Output timesteps per hour.
    pub timesteps: Timesteps,
    /// Spline or dense.
    pub method: Method,
    /// With the spline: where the four samples around a timestep differ by more than this, a
    /// shadow edge sweeps through that cell of the sample grid faster than the samples can follow,
    /// so the timestep is counted directly instead of interpolated. 1 (or more) never refines.
    pub refine: f64,
    /// With refinement on: an interpolated timestep is kept only where a patch of the receiver is
    /// proved lit at its sun ([`certified::never_dark`]), and counted otherwise, so no shadow that
    /// passes wholly between samples is interpolated away (0 dark/lit disagreements against
    /// `Method::Dense` on `sunlit bench canyon-slots`, 29 without). Off by default: it costs about
    /// 7 µs an interpolated step, 2.1× the year's CPU on blaas-louvres, where it proves every
    /// step and saves no view (docs/energyplus-fidelity.md, "Certificates").
    pub prove_never_dark: bool,
    /// With refinement on: a dark proof may combine casters, coplanar panels that together form
    /// one convex polygon, halves of a cell each covered by its own caster, and casters that
    /// meet the receiver's plane by their part clear of it ([`crate::count::certify`]). Exact
    /// (no step proved dark is lit), and the steps only they prove stay in the sparse refinement
    /// as known zeros ([`crate::count::certify::Proof::alone`]), so the CSV is the one without
    /// them; with them the refinement's step-by-step spans are proved first too (`SpanProofs`).
    /// `None` (the default): a pilot of one cell in 16 decides them (`certified::prove_cells`;
    /// on a city they pay, on blaas-louvres they save nothing; docs/energyplus-fidelity.md).
    pub many_casters: Option<bool>,
    /// With `many_casters`: a receiver whose edge lies on a facade meeting its plane at an inner
    /// corner (a tower's other arm) may be proved dark by that facade, its corners there covered
    /// with no margin ([`crate::count::certify::Certifier::with_inner_corners`]). Exact for the
    /// exact engines; off by default until the GPU engine's rounding along that edge is shown to
    /// agree (docs/energyplus-fidelity.md, "certs13").
    pub inner_corners: bool,
}

/// With refinement on, a timestep whose sample cell has a corner under this lit fraction (a
/// shadow about to cover the whole surface, or just uncovering it), or whose fit comes out under
/// it, is counted directly: the spline cannot place the step at which the last sliver goes dark,
/// and EnergyPlus tells dark from lit exactly (its heat balance drops a scheduled value wherever
/// its own sun is behind; docs/energyplus-fidelity.md). Measured on 4ZoneWithShading_Simple_1
/// (Timestep 4): without it 341 timesteps a year were dark in one and lit in the other.
pub const NEAR_DARK: f64 = 0.05;

/// With refinement on, a timestep where the fitted spline and the bilinear interpolation of the
/// four samples around it differ by more than this is counted directly. Where the fraction is
/// smooth at the samples' spacing the two agree to second order; where a shadow edge enters or
/// leaves the surface inside the cell (a kink: the fraction stays at 1, or at a plateau, then
/// falls) the cubic spline rings over the neighbouring cells while the corners still differ by
/// less than the refinement threshold. Measured against EnergyPlus 25.2's clipping on
/// 4ZoneWithShading_Simple_1 (Timestep 6, 15 March – 20 October, default settings): the door
/// under its overhang and fins went from a mean |Δ| of 0.0059 to 0.0040 over lit steps for 7 %
/// more views (docs/energyplus-fidelity.md). 0.01 (from 0.03) since refined steps are counted
/// sparsely ([`super::refine`]): on NREL's 100-zone file at Timestep updates the north windows
/// went from 0.0075 to 0.0045 against counting every timestep, for 31 % more views.
pub const KINK: f64 = 0.01;

/// The default refinement threshold: 30% of the surface changing state between samples. On the
/// example office (N = 1) it takes the 27×19 RMS error from 0.017 to 0.006 for 37% more views.
pub const DEFAULT_REFINE: f64 = 0.3;

/// A run's work so far, in views (one receiver at one sun or sky direction). Most views are
/// counted by the engine; some are *settled* without it: a timestep the spline interpolates
/// (or a cell proven dark or lit) is work the run had to decide, but no view was counted for it.
/// A year's total is fixed from its start (its samples and every sun-up timestep a surface faces),
/// so a report can say how far the run is and how long it may take before the fit has said
/// which timesteps will be counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Progress {
    /// Views decided: counted or settled.
    pub done: usize,
    /// Views to decide in all.
    pub total: usize,
    /// Of `done`, the views settled without counting.
    pub settled: usize,
    /// Of the views not yet done, how many may still be settled without counting (a year's
    /// timesteps before its samples are fitted): the time left lies between that of counting
    /// `total - done - may_settle` views and that of counting `total - done`.
    pub may_settle: usize,
}

impl Progress {
    /// `done` of `total` views counted, every one of them by the engine.
    pub fn counting(done: usize, total: usize) -> Self {
        Progress { done, total, ..Default::default() }
    }

    /// Views an engine counted (`done` less the settled ones).
    pub fn counted(&self) -> usize {
        self.done.saturating_sub(self.settled)
    }
}

/// Atlas submissions per progress report: often enough that a cancel (an `Err` from the progress
/// callback) is seen within a second even on a software rasterizer, and each report still fills
/// whole atlases.
const BATCHES_PER_REPORT: usize = 4;

/// Each leaf ramp gets at least this many sample days, however few the plan gives the year: the
/// leaf fraction changes by a sixth of the canopy between them.
pub const RAMP_DAYS: usize = 6;

/// The year's schedule for every receiver of `scene`; foliage follows the default leaf calendar
/// of the location's hemisphere.
pub async fn annual(
    counter: &Counter,
    gpu: &GpuScene,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Schedule> {
    annual_with_leaves(counter, gpu, scene, location, options, &LeafCalendar::for_latitude(location.latitude), progress).await
}

/// As [`annual`], with foliage following `calendar`.
pub async fn annual_with_leaves(
    counter: &Counter,
    gpu: &GpuScene,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Schedule> {
    annual_on(&[Lane { counter, gpu }], scene, location, options, calendar, progress).await
}

/// As [`annual_with_leaves`], the views shared out over several counters side by side
/// ([`crate::count::lanes`]), each holding its own upload of `scene`.
pub async fn annual_on(
    lanes: &[Lane<'_>],
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Schedule> {
    annual_with(&Lanes(lanes), scene, location, options, calendar, progress).await
}

/// The year's schedule with any [`Engine`] answering the views (the GPU lanes, the exact
/// reference, or a mix).
pub async fn annual_with<E: Engine>(
    engine: &E,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Schedule> {
    Ok(annual_fitted_with(engine, scene, location, options, calendar, progress).await?.0)
}

/// As [`annual_with_leaves`], keeping the fitted surfaces too (None for [`Method::Dense`]), to
/// evaluate at any instant ([`FittedYear::fractions_at`], a viewer's time slider).
pub async fn annual_fitted(
    counter: &Counter,
    gpu: &GpuScene,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<(Schedule, Option<FittedYear>)> {
    annual_fitted_with(&Lanes(&[Lane { counter, gpu }]), scene, location, options, calendar, progress).await
}

/// As [`annual_with`], keeping the fitted surfaces too (None for [`Method::Dense`]).
pub async fn annual_fitted_with<E: Engine>(
    engine: &E,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<(Schedule, Option<FittedYear>)> {
    let mut year = Columns::new(scene, 0..scene.receivers.len(), options.timesteps)?;
    let calendar = year_calendar(scene, calendar);
    let fitted = count_columns(engine, scene, location, options, &calendar, &mut year, progress).await?;
    let days = year.schedule.timesteps.days();
    let fitted = fitted.map(|(surfaces, regime_of)| FittedYear::new(scene, location, calendar, surfaces, regime_of, days));
    year.schedule.validate()?;
    Ok((year.schedule, fitted))
}

/// The year of the scene's `receivers` alone (a range of them, in order), each answer what
/// [`annual_with`] gives that receiver, bit for bit: every view is the same receiver at the
/// same sun on the same engine, and each receiver's samples, fit, refined steps and
/// certificates are its own. Its schedule's columns are those receivers. A city's year is
/// counted so a batch at a time ([`crate::sweep::district`]): its memory then follows the batch,
/// not the city (the whole-year table alone is 4 bytes a receiver and timestep). With it, where
/// the year's time went ([`YearStages`]).
#[allow(clippy::too_many_arguments)] // As annual_with, and which receivers.
pub async fn annual_receivers_with<E: Engine>(
    engine: &E,
    scene: &Scene,
    receivers: Range<usize>,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<(Schedule, YearStages)> {
    let mut year = Columns::new(scene, receivers, options.timesteps)?;
    let calendar = year_calendar(scene, calendar);
    count_columns(engine, scene, location, options, &calendar, &mut year, progress).await?;
    year.schedule.validate()?;
    Ok((year.schedule, year.stages))
}

/// The leaf calendar a year follows: `calendar` where the scene has foliage, else evergreen
/// (one regime).
fn year_calendar(scene: &Scene, calendar: &LeafCalendar) -> LeafCalendar {
    if scene.has_foliage() { *calendar } else { LeafCalendar::evergreen() }
}

/// Counts the year of `year`'s receivers by `options`' method; a spline year's fitted surfaces
/// and which regime serves each leaf phase.
async fn count_columns<E: Engine>(
    engine: &E,
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    year: &mut Columns,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Option<(Vec<FittedSurfaces>, RegimeOf)>> {
    let views = Views { engine };
    match options.method {
        Method::Spline(plan) => Ok(Some(spline_year(&views, scene, location, plan, calendar, *options, year, progress).await?)),
        Method::Dense => {
            dense_year(&views, scene, location, calendar, year, progress).await?;
            Ok(None)
        }
        Method::Periodic(periods) => {
            let start = now();
            super::periodic::periodic_year(&views, scene, location, periods, calendar, year, progress).await?;
            year.stages.sampling += now() - start;
            Ok(None)
        }
    }
}

/// [`annual_on`] the lanes' counters, surviving one loss of a GPU device (a driver reset, a GPU
/// hang): on [`Error::DeviceLost`] it makes every lane a new counter with the same options,
/// uploads the scene again and counts the year once more from the start (progress starts again
/// at 0). A second loss is returned.
pub async fn annual_recovering(
    lanes: &mut [(Counter, GpuScene)],
    scene: &Scene,
    location: &Location,
    options: &AnnualOptions,
    calendar: &LeafCalendar,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Schedule> {
    let first = annual_on(&borrowed(lanes), scene, location, options, calendar, progress).await;
    match first {
        Err(Error::DeviceLost(why)) => {
            log::warn!("GPU device lost ({why}); making a new one and counting again");
            for (counter, gpu) in lanes.iter_mut() {
                *counter = counter.recreate().await?;
                *gpu = counter.upload(scene)?;
            }
            annual_on(&borrowed(lanes), scene, location, options, calendar, progress).await
        }
        other => other,
    }
}

fn borrowed(lanes: &[(Counter, GpuScene)]) -> Vec<Lane<'_>> {
    lanes.iter().map(|(counter, gpu)| Lane { counter, gpu }).collect()
}

/// The engine that turns view requests into fractions, with progress reports between chunks.
pub(super) struct Views<'a, E: Engine> {
    engine: &'a E,
}

impl<E: Engine> Views<'_, E> {
    /// Counts many views (each at its own leaf fraction), reporting progress as it goes.
    pub(super) async fn count(&self, requests: &[ViewRequest], progress: &mut dyn FnMut(Progress) -> Result<()>) -> Result<Vec<f64>> {
        let mut out = Vec::with_capacity(requests.len());
        progress(Progress::counting(0, requests.len()))?;
        self.engine.expect(requests.len());
        let per_report = self.engine.batch().max(1) * BATCHES_PER_REPORT;
        for chunk in requests.chunks(per_report) {
            out.extend(self.engine.answer(chunk).await?.into_iter().map(|c| c.fraction));
            progress(Progress::counting(out.len(), requests.len()))?;
        }
        Ok(out)
    }
}

/// A surface has at most this many lit pieces a day that get a fitted surface each: a north
/// wall in summer is lit in the morning and again in the evening.
pub(super) const MAX_PIECES: usize = 2;

/// The day of the sun model whose sun EnergyPlus's shading uses on calendar day `day` (1-based,
/// Feb 29 = day 60 in a leap year): that day itself, at every instant of it. This is the rule for
/// the whole project: every sun that must line up with EnergyPlus (schedules, irradiance) takes
/// its day from here.
///
/// EnergyPlus 25.2 with `ShadowCalculation` update method `Timestep` (what the hook writes) calls
/// `SUN3(DayOfYear)` in `PerformSolarCalculations` at every timestep (SolarShading.cc) and
/// `SUN4` at the timestep's end (`FigureSolarBeamAtTimestep`; mid-hour with one timestep an
/// hour), `DayOfYear` being the weather file's calendar day. Measured against the
/// `Surface Outside Face Sunlit Fraction` it reports and its heat balance uses
/// (tests/energyplus_testfiles.rs): no timestep a year where one side is dark and the other lit.
/// `eplusshading.csv` is no reference for this: `InitHeatBalance` writes a day's row at the start
/// of the day, when all but its first timestep still hold the previous day's values, so it lags
/// by one day (docs/energyplus-fidelity.md).
pub fn shading_sun_day(day: u32) -> f64 {
    f64::from(day)
}

/// The sun EnergyPlus shades for at `row` of `timesteps`: under a `Periodic` update the
/// period's mean sun ([`ShadingPeriods::sun`]), else the calendar day's ([`shading_sun_day`]).
/// Its beam on a surface, outside (`CosIncAng` beside `SunlitFrac`) and inside (the back-surface
/// overlaps), is of this sun, all from `CalcPerSolarBeam`; whether the sun is up is the calendar
/// day's (`SunIsUp`).
pub fn shaded_sun(location: &Location, timesteps: Timesteps, periods: Option<ShadingPeriods>, row: usize) -> DVec3 {
    let at = timesteps.instant(row);
    match periods {
        Some(p) => p.sun(location, at.day, timesteps.days(), at.hour),
        None => sun_direction(location, shading_sun_day(at.day), at.hour),
    }
}

/// A fraction as EnergyPlus stores its own: clamped to [0, 1], and 0 below 1e-5 (SolarShading.cc
/// zeroes sunlit fractions under 1e-5, so a sliver that small is dark in its heat balance too).
pub(super) fn as_energyplus(fraction: f64) -> f32 {
    energyplus_fraction(fraction) as f32
}

/// [`as_energyplus`] in f64, for the fitted surfaces' own evaluation.
pub(crate) fn energyplus_fraction(fraction: f64) -> f64 {
    let f = fraction.clamp(0.0, 1.0);
    if f < MIN_SUNLIT_FRACTION { 0.0 } else { f }
}

/// EnergyPlus's smallest non-zero sunlit fraction.
const MIN_SUNLIT_FRACTION: f64 = 1e-5;

/// Whether the sun counts as up (EnergyPlus's SunIsUp threshold on cos zenith).
pub(super) fn sun_is_up(sun: DVec3) -> bool {
    sun.z >= MIN_COS_INCIDENCE
}

async fn dense_year(
    views: &Views<'_, impl Engine>,
    scene: &Scene,
    location: &Location,
    calendar: &LeafCalendar,
    year: &mut Columns,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<()> {
    let start = now();
    let mut requests = Vec::new();
    let mut cells = Vec::new();
    for (row, column, sun, day) in facing_timesteps(scene, year.range(), location, year.schedule.timesteps) {
        requests.push(ViewRequest::new(column as u32, sun).with_leaves(calendar.fraction(f64::from(day)) as f32));
        cells.push((row, column));
    }
    let values = views.count(&requests, progress).await?;
    for ((row, column), v) in cells.into_iter().zip(values) {
        year.set(row, column, as_energyplus(v));
    }
    year.stages.sampling += now() - start;
    year.stages.sample_views += requests.len();
    Ok(())
}

/// Every sun-up timestep at which one of the scene's `receivers` faces the sun, as (row,
/// receiver, sun, calendar day): the views a dense year counts, and those a spline year settles
/// or counts.
fn facing_timesteps<'a>(
    scene: &'a Scene,
    receivers: Range<usize>,
    location: &'a Location,
    timesteps: Timesteps,
) -> impl Iterator<Item = (usize, usize, DVec3, u32)> + 'a {
    timesteps.instants().enumerate().flat_map(move |(row, instant)| {
        let sun = sun_direction(location, shading_sun_day(instant.day), instant.hour);
        let up = sun_is_up(sun);
        receivers
            .clone()
            .filter(move |&column| up && !is_dark(scene.receivers[column].normal, sun))
            .map(move |column| (row, column, sun, instant.day))
    })
}

/// A spline year's work as [`Progress`] reports it: its sample views, then its facing timesteps
/// ([`facing_timesteps`]), each of which the fit either settles (interpolated, or proven dark
/// or lit) or leaves to count. The total is known before the first view is counted.
#[derive(Debug, Clone, Copy)]
struct YearWork {
    samples: usize,
    timesteps: usize,
}

impl YearWork {
    /// While the samples are counted, any timestep may still be settled.
    fn sampling(self, p: Progress) -> Progress {
        Progress { done: p.done, total: self.samples + self.timesteps, settled: 0, may_settle: self.timesteps }
    }

    /// Once the fit leaves `to_count` timesteps to count, the others are settled; `p` counts those.
    fn refining(self, to_count: usize, p: Progress) -> Progress {
        let settled = self.timesteps.saturating_sub(to_count);
        Progress { done: self.samples + settled + p.done, total: self.samples + settled + to_count, settled, may_settle: 0 }
    }
}

/// One fit of the year: its sample days, their leaf fractions and the grid the fit lives on.
struct Regime {
    /// Days counted (day of year, possibly past 365 for a ramp over New Year).
    days: Vec<f64>,
    /// Leaf fraction on each counted day.
    leaves: Vec<f32>,
    /// Grid days → counted days: the identity, or for a ramp its days then their mirror images.
    grid_days: Vec<usize>,
    /// Counted day → the day with the same declination whose views it shares (itself if none).
    twins: Vec<usize>,
    grid: AnnualGrid,
    cells: SampleCells,
    /// Day of year → the grid's coordinate.
    map: DayMap,
}

/// How a regime's grid coordinate follows the day of year.
#[derive(Debug, Clone, Copy)]
pub(super) enum DayMap {
    /// The season axis's coordinate (periodic over the year; see [`SeasonAxis`]).
    Year(SeasonAxis),
    /// A ramp of `length` days from `start`, in u ∈ [0, 1] with leaf fraction u² (leaf-out) or
    /// (1 − u)² (leaf fall). A dense canopy closes over the first few percent of its leaves, so
    /// the fraction changes fastest where the leaf fraction is small: evenly spaced u crowds the
    /// sample days there, and a function of u² is flat at u = 0, which the mirror at that end
    /// assumes.
    Ramp { start: f64, length: f64, rising: bool },
}

impl DayMap {
    /// The grid coordinate of calendar day `day` (fractional allowed): the year's fit is over
    /// the sun's day, which is the calendar day ([`shading_sun_day`]), a foliage ramp's over the
    /// leaves' (calendar) day.
    pub(super) fn grid_day(self, day: f64) -> f64 {
        self.grid_coordinate(day)
    }

    fn grid_coordinate(self, day: f64) -> f64 {
        match self {
            DayMap::Year(axis) => axis.coordinate(day),
            DayMap::Ramp { start, length, rising } => {
                let x = ((day - start).rem_euclid(DAYS as f64) / length).clamp(0.0, 1.0);
                if rising { x.sqrt() } else { 1.0 - (1.0 - x).sqrt() }
            }
        }
    }

    /// The inverse of [`Self::grid_coordinate`] for a ramp's u.
    fn day(self, u: f64) -> f64 {
        match self {
            DayMap::Year(axis) => axis.day(u),
            DayMap::Ramp { start, length, rising } => start + length * if rising { u * u } else { 1.0 - (1.0 - u) * (1.0 - u) },
        }
    }
}

impl Regime {
    /// The whole year at the plan's days with one leaf fraction.
    fn year(plan: SamplingPlan, taus: &[f64], leaves: f64) -> Result<Self> {
        let days = plan.sample_days();
        let n = days.len();
        Ok(Regime {
            leaves: vec![leaves as f32; n],
            grid_days: (0..n).collect(),
            twins: (0..n).map(|d| plan.twin(d)).collect(),
            grid: AnnualGrid::new(plan.first_day(), DAYS as f64, n, taus)?,
            cells: SampleCells { first_day: plan.first_day(), spacing: plan.spacing(), days: n, taus: taus.to_vec() },
            map: DayMap::Year(SeasonAxis::new()),
            days,
        })
    }

    /// A leaf ramp of `length` days from `first`, on the grid u of [`DayMap::Ramp`]: n + 1 days at
    /// u = k/n, both ends included (leaf fraction exactly 0 and 1), n at least [`RAMP_DAYS`] or
    /// the plan's spacing if denser; mirrored at both ends into a periodic grid over u ∈ [0, 2).
    fn ramp(plan: SamplingPlan, taus: &[f64], calendar: &LeafCalendar, phase: Phase, (first, length): (f64, f64)) -> Result<Self> {
        let n = ((plan.days as f64 * length / DAYS as f64).ceil() as usize).max(RAMP_DAYS);
        let map = DayMap::Ramp { start: first, length, rising: phase == Phase::LeafOut };
        let days: Vec<f64> = (0..=n).map(|k| map.day(k as f64 / n as f64)).collect();
        let leaves = days.iter().map(|d| calendar.fraction(*d) as f32).collect();
        Ok(Regime {
            leaves,
            grid_days: (0..=n).chain((1..n).rev()).collect(),
            // The leaf fraction differs from day to day: nothing to share.
            twins: (0..=n).collect(),
            grid: AnnualGrid::new(0.0, 2.0, 2 * n, taus)?,
            cells: SampleCells { first_day: 0.0, spacing: 1.0 / n as f64, days: 2 * n, taus: taus.to_vec() },
            map,
            days,
        })
    }
}

/// Which regime serves a leaf phase.
pub(super) type RegimeOf = fn(Phase) -> usize;

/// The regimes of a year and which one serves each phase: one for every phase without foliage,
/// else bare, full leaf, leaf-out and leaf fall.
fn regimes(plan: SamplingPlan, taus: &[f64], calendar: &LeafCalendar) -> Result<(Vec<Regime>, RegimeOf)> {
    if calendar.evergreen {
        return Ok((vec![Regime::year(plan, taus, 1.0)?], |_| 0));
    }
    let mut out = vec![Regime::year(plan, taus, 0.0)?, Regime::year(plan, taus, 1.0)?];
    for phase in [Phase::LeafOut, Phase::LeafFall] {
        if let Some(ramp) = calendar.ramp(phase) {
            out.push(Regime::ramp(plan, taus, calendar, phase, ramp)?);
        }
    }
    let of = |phase: Phase| match phase {
        Phase::Bare => 0,
        Phase::Full => 1,
        Phase::LeafOut => 2,
        Phase::LeafFall => 3,
    };
    Ok((out, of))
}

/// A day of the year for the sun model: any real day taken into [1, 366).
fn sun_day(day: f64) -> f64 {
    (day - 1.0).rem_euclid(DAYS as f64) + 1.0
}

/// The spline year of `year`'s receivers, written into its schedule; their fitted surfaces by
/// regime and which regime serves each leaf phase.
#[allow(clippy::too_many_arguments)] // The year's inputs and its two outputs; grouping them would hide nothing.
async fn spline_year(
    views: &Views<'_, impl Engine>,
    scene: &Scene,
    location: &Location,
    plan: SamplingPlan,
    calendar: &LeafCalendar,
    options: AnnualOptions,
    year: &mut Columns,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<(Vec<FittedSurfaces>, RegimeOf)> {
    let (start, cpu) = (now(), cpu_seconds());
    let taus = plan.taus();
    let (regimes, regime_of) = regimes(plan, &taus, calendar)?;
    let receivers = year.range();
    let SampleViews { requests, cells } = sample_views(scene, receivers.clone(), location, &regimes, &taus);
    let timesteps = year.schedule.timesteps;
    let work = YearWork { samples: requests.len(), timesteps: facing_timesteps(scene, receivers.clone(), location, timesteps).count() };
    let counted = views.count(&requests, &mut |p| progress(work.sampling(p))).await?;
    year.stages.sample_views += requests.len();
    year.stages.sampling += now() - start;
    year.stages.sampling_cpu += cpu_seconds() - cpu;
    let start = now();
    // Each step below keeps only what the next reads, freed before the year is evaluated: a
    // city's views, counts and samples are a sixth of its peak memory (docs/district.md).
    drop(requests);
    let mut samples: Vec<Vec<Option<f64>>> =
        regimes.iter().map(|g| vec![None; receivers.len() * MAX_PIECES * g.days.len() * taus.len()]).collect();
    for (request, g, cell) in cells {
        samples[g][cell] = Some(counted[request]);
    }
    drop(counted);
    let mut fits = Vec::with_capacity(regimes.len());
    for (regime, samples) in regimes.iter().zip(&samples) {
        fits.push(fit_regime(regime, samples, taus.len())?);
    }
    drop(samples);
    let fitted: Vec<FittedRegime> = regimes.iter().zip(&fits).map(|(g, f)| FittedRegime { fits: f, cells: &g.cells, map: g.map }).collect();
    // Every row's sun once: the schedule's rows read it here, the refined steps' views below.
    let suns = RowSuns::new(location, timesteps);
    let (rough, smooth) = evaluate(scene, location, &suns, &fitted, &|day| regime_of(calendar.phase(day)), &options, year);
    year.stages.fitting += now() - start;
    let start = now();
    // Built only where a step is left to settle (without the engine's index it builds its own).
    let proofs = (options.many_casters, options.inner_corners);
    let certifier = (!(rough.is_empty() && smooth.is_empty())).then(|| certified::certifier(scene, views.engine.index(), proofs));
    let rough = match &certifier {
        Some(c) => certified::certify_steps(c, options.many_casters, &suns, rough, smooth, year),
        None => certified::ToCount { dark: vec![false; rough.len()], steps: rough, many_casters: false },
    };
    year.stages.certifying += now() - start;
    let (start, cpu) = (now(), cpu_seconds());
    // Certified timesteps are settled like interpolated ones: done, not counted.
    let rows_per_day = timesteps.rows() / timesteps.days() as usize;
    let request = |r: &Rough| ViewRequest::new(r.column, suns.sun(r.row)).with_leaves(calendar.fraction(suns.day(r.row)) as f32);
    // The last report says how many refined steps were counted in all.
    let mut refined_views = 0;
    // The spans' proofs come with the many-caster ones (asked for, or kept by the pilot).
    let span_proofs = certifier.as_ref().filter(|_| rough.many_casters).map(|c| certified::SpanProofs::new(c, &rough.steps, &suns));
    let prover = span_proofs.as_ref().map_or(&refine::NoProofs as &dyn refine::SpanProver, |p| p);
    let refined = refine::count_sparsely(views, &rough.steps, &rough.dark, rows_per_day, &request, prover, &mut |n, p| {
        refined_views = n;
        progress(work.refining(n, p))
    })
    .await?;
    for (r, v) in rough.steps.into_iter().zip(refined) {
        year.set(r.row as usize, r.column as usize, as_energyplus(v));
    }
    year.stages.refining += now() - start;
    year.stages.refining_cpu += cpu_seconds() - cpu;
    year.stages.refined_views += refined_views;
    let surfaces = regimes
        .iter()
        .zip(fits)
        .map(|(g, f)| FittedSurfaces { map: g.map, splines: f.into_iter().map(|p| p.map(|p| p.spline)).collect() })
        .collect();
    Ok((surfaces, regime_of))
}

/// Fits every (receiver, piece) of a regime from its samples (None where the piece is never lit).
fn fit_regime(regime: &Regime, samples: &[Option<f64>], per_day: usize) -> Result<Vec<Option<PieceFit>>> {
    samples
        .chunks(regime.days.len() * per_day)
        .map(|piece| {
            let Some(v) = fill_dark(piece, regime.days.len(), per_day) else { return Ok(None) };
            let v: Vec<f64> = regime.grid_days.iter().flat_map(|&d| v[d * per_day..(d + 1) * per_day].iter().copied()).collect();
            let borrowed = regime.grid_days.iter().map(|&d| piece[d * per_day..(d + 1) * per_day].iter().all(Option::is_none)).collect();
            Ok(Some(PieceFit { spline: regime.grid.fit(&v)?, samples: v, borrowed }))
        })
        .collect()
}

/// A regime's fitted pieces (by receiver and piece) and its sample grid.
struct FittedRegime<'a> {
    fits: &'a [Option<PieceFit>],
    cells: &'a SampleCells,
    map: DayMap,
}

/// A fitted lit piece: the spline and the (filled) samples it passes through.
struct PieceFit {
    spline: AnnualSpline,
    samples: Vec<f64>,
    /// Per grid day: the piece does not exist that day, so its samples are another day's
    /// ([`fill_dark`]).
    borrowed: Vec<bool>,
}

/// The sample grid's geometry, to find the cell of samples around any (day, τ).
struct SampleCells {
    first_day: f64,
    spacing: f64,
    days: usize,
    taus: Vec<f64>,
}

/// The four samples around a (day, τ) as [`SampleCells::cell`] sums them up.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell {
    /// Largest difference between them: how much the fraction changes across the cell.
    spread: f64,
    /// The lowest of them.
    lowest: f64,
    /// The highest of them.
    highest: f64,
    /// Its first sample day and sample time (indices): which cell it is.
    at: (usize, usize),
    /// Their bilinear interpolation at (day, τ) (τ outside the outermost nodes is held at the node).
    bilinear: f64,
    /// Whether either of its sample days lacks the piece, its samples borrowed from another day.
    borrowed: bool,
    /// Whether τ lies outside the outermost sample times, between one and its piece's end.
    beyond: bool,
}

impl SampleCells {
    /// The cell's first sample day and time (indices) around (day, τ).
    fn at(&self, day: f64, tau: f64) -> (usize, usize) {
        let x = (day - self.first_day) / self.spacing;
        let k0 = x.floor().rem_euclid(self.days as f64) as usize % self.days;
        let j0 = self.taus.partition_point(|t| *t <= tau).saturating_sub(1).min(self.taus.len().saturating_sub(2));
        (k0, j0)
    }

    /// The cell of samples around (day, τ) that the spline interpolates in.
    fn cell(&self, samples: &[f64], borrowed: &[bool], day: f64, tau: f64) -> Cell {
        let x = (day - self.first_day) / self.spacing;
        let u = x - x.floor();
        let (k0, j0) = self.at(day, tau);
        let k1 = (k0 + 1) % self.days;
        let s = self.taus.len();
        let j1 = (j0 + 1).min(s - 1);
        let corners = [samples[k0 * s + j0], samples[k0 * s + j1], samples[k1 * s + j0], samples[k1 * s + j1]];
        let (lo, hi) = corners.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        let v = if j1 > j0 { ((tau - self.taus[j0]) / (self.taus[j1] - self.taus[j0])).clamp(0.0, 1.0) } else { 0.0 };
        let bilinear = (1.0 - u) * ((1.0 - v) * corners[0] + v * corners[1]) + u * ((1.0 - v) * corners[2] + v * corners[3]);
        let beyond = self.taus.first().is_some_and(|&t| tau < t) || self.taus.last().is_some_and(|&t| tau > t);
        Cell { spread: hi - lo, lowest: lo, highest: hi, bilinear, at: (k0, j0), borrowed: borrowed[k0] || borrowed[k1], beyond }
    }
}

/// Fills every timestep of `schedule` from the fitted pieces of each day's regime (exact zeros
/// where dark; each row's sun from `suns`, as the refined steps' views take it) and returns the
/// timesteps to count directly: those whose sample cell spreads more than `options.refine`, and
/// (refinement on) those near dark ([`NEAR_DARK`]), where the spline leaves its cell's bilinear
/// interpolation ([`KINK`]), or dark at every sample of the year; and (refinement and
/// `options.prove_never_dark` on) the interpolated ones, which are kept only where
/// proved never dark ([`certified::never_dark`]).
fn evaluate(
    scene: &Scene,
    location: &Location,
    suns: &RowSuns,
    regimes: &[FittedRegime],
    regime_of: &dyn Fn(f64) -> usize,
    options: &AnnualOptions,
    year: &mut Columns,
) -> (Vec<Rough>, Vec<Smooth>) {
    let (refine, prove_never_dark) = (options.refine, options.prove_never_dark);
    let (mut rough, mut smooth) = (Vec::new(), Vec::new());
    // The fits and the schedule's columns are numbered from the range's first receiver, the
    // steps by the scene's receiver (what their views and certificates name).
    let first = year.first;
    let receivers = &scene.receivers[year.range()];
    let timesteps = year.schedule.timesteps;
    let rows_per_day = timesteps.rows() / timesteps.days() as usize;
    for day in 1..=timesteps.days() {
        let pieces: Vec<Vec<(f64, f64)>> =
            receivers.iter().map(|r| lit_intervals(location, r.normal, shading_sun_day(day), MIN_COS_INCIDENCE)).collect();
        let g = regime_of(day as f64);
        let regime = &regimes[g];
        let grid_day = regime.map.grid_day(day as f64);
        for row in (day as usize - 1) * rows_per_day..day as usize * rows_per_day {
            let instant = timesteps.instant(row);
            let sun = suns.sun(row as u32);
            if !sun_is_up(sun) {
                continue;
            }
            for (local, r) in receivers.iter().enumerate() {
                if is_dark(r.normal, sun) {
                    continue;
                }
                let column = first + local;
                let Some((fit, tau)) = fit_at(&pieces[local], local, instant.hour) else { continue };
                let Some(piece) = &regime.fits[fit] else {
                    // Dark at every sample: counted (or proved dark) with refinement on, not
                    // guessed dark, since a slot of sun may light it between them.
                    if refine < 1.0 {
                        let at = regime.cells.at(grid_day, tau);
                        rough.push(Rough::new(row, column, (g, fit, at.0, at.1), (0.0, 0.0), Rule::NoFit));
                    }
                    continue;
                };
                let value = piece.spline.eval(grid_day, tau);
                year.schedule.set(row, local, as_energyplus(value));
                let cell = regime.cells.cell(&piece.samples, &piece.borrowed, grid_day, tau);
                if let Some(rule) = counting_rule(&cell, value, refine) {
                    rough.push(Rough::new(row, column, (g, fit, cell.at.0, cell.at.1), (cell.lowest, cell.highest), rule));
                } else if refine < 1.0 && prove_never_dark {
                    smooth.push(Smooth::new(row, column, fit, g, cell.at));
                }
            }
        }
    }
    (rough, smooth)
}

/// The first rule that sends a fitted `value` in `cell` to counting, None where it is
/// interpolated: the spread rule, then, with refinement on, a sample day of the cell lacking the
/// lit piece, a time beyond the day's outermost samples, a near-dark corner ([`NEAR_DARK`]), a
/// near-dark fit, or the spline leaving the cell's bilinear interpolation ([`KINK`]). Why each
/// is counted is on its [`Rule`].
fn counting_rule(cell: &Cell, value: f64, refine: f64) -> Option<Rule> {
    Some(if cell.spread > refine {
        Rule::Spread
    } else if refine >= 1.0 {
        return None;
    } else if cell.borrowed {
        Rule::Borrowed
    } else if cell.beyond {
        Rule::BeyondSamples
    } else if cell.highest < NEAR_DARK {
        Rule::AllNearDark
    } else if cell.lowest < NEAR_DARK {
        Rule::SomeNearDark
    } else if value < NEAR_DARK {
        Rule::NearDarkFit
    } else if (value - cell.bilinear).abs() > KINK {
        Rule::Kink
    } else {
        return None;
    })
}

/// Which of a regime's fits (by receiver and piece) serves receiver `column` at time `t`, given
/// its lit pieces that day, and the normalised time within the piece.
pub(super) fn fit_at(pieces: &[(f64, f64)], column: usize, t: f64) -> Option<(usize, f64)> {
    let (p, tau) = piece_at(pieces, t)?;
    Some((column * MAX_PIECES + p.min(MAX_PIECES - 1), tau))
}

/// The lit piece holding time `t` (or the nearest one, for rounding at its ends) and the
/// normalised time within it.
fn piece_at(pieces: &[(f64, f64)], t: f64) -> Option<(usize, f64)> {
    let distance = |(a, b): (f64, f64)| {
        if t < a {
            a - t
        } else if t > b {
            t - b
        } else {
            0.0
        }
    };
    let (p, &(a, b)) = pieces.iter().enumerate().min_by(|x, y| distance(*x.1).total_cmp(&distance(*y.1)))?;
    Some((p, ((t - a) / (b - a).max(1e-9)).clamp(0.0, 1.0)))
}

/// Mean and max sunlit-fraction differences between two schedules over rows where either is lit.
pub fn compare(a: &Schedule, b: &Schedule) -> Result<(f64, f64, f64)> {
    if a.names != b.names || a.values.len() != b.values.len() {
        return Err(Error::argument("schedules", "different surfaces or timesteps"));
    }
    let (mut sum, mut sq, mut max, mut n) = (0.0, 0.0, 0.0f64, 0usize);
    for (x, y) in a.values.iter().zip(&b.values) {
        if *x > 0.0 || *y > 0.0 {
            let d = (*x as f64 - *y as f64).abs();
            sum += d;
            sq += d * d;
            max = max.max(d);
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    Ok((sum / n, (sq / n).sqrt(), max))
}

mod columns;
mod fill;
mod sampling;
#[cfg(test)]
mod tests;
