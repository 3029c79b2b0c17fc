//! Maps: where on each surface the sun falls, point by point.
//!
//! Owns the points a map is evaluated at and what is summed over them:
//! - [`Points`]: positions, normals and receiver ids as flat arrays (`3n` f32, `3n` f32, `n`
//!   u32), made by [`grid`] (a grid at a spacing on every chosen receiver, holes left out) or
//!   [`from_csv`] (`x,y,z,nx,ny,nz` rows, each assigned to the receiver it lies on);
//! - [`Mapper`]: the points indexed per receiver for the exact engine's shadow rays
//!   ([`crate::count::exact::rays`]). [`Mapper::visibility`] answers one instant
//!   ([`lit`] for a one-off), [`Mapper::accumulate`] sums sun hours and irradiation (direct;
//!   with the points' sky views, sky diffuse, ground-reflected and total) over a [`Period`],
//!   [`Mapper::lit_series`] keeps each point's lit instants for the sun-hours [`study`] rules;
//! - [`sky`]: each point's own sky patch visibility ([`point_sky`]), combined per timestep with
//!   the Perez sky exactly as a receiver's is ([`crate::export::irradiation`]);
//! - [`period`]: years at EnergyPlus timesteps, date ranges, one day at minute steps, an instant,
//!   with the sun `sunlit annual` uses;
//! - [`planning`]: window studies (BRE 209's VSC and APSH/WPSH, GB 50180's sunlight hours),
//!   their pass/fail alone and against an existing scene, and each point's sky mask;
//! - [`series`]: each point's visibility at every instant and its unshaded sky (what PV tools
//!   read, [`crate::export::pv`]);
//! - [`MapGpu`]: the same sweeps with each point answered by its texel in the GPU counter's tile
//!   of its receiver (`gpu`, [`crate::count::gpu::masks`]): `*_gpu` methods of [`Mapper`].
//!
//! Every point is counted directly at every instant (a shadow ray is cheap once a receiver's
//! casters are culled), never interpolated: a point's visibility jumps when a shadow edge
//! crosses it, which a spline over sparse samples (what [`crate::year`] fits to surface fractions,
//! smooth in time) would blur. Per instant and receiver the casters are culled once (the
//! receiver's sun prism through the exact engine's BVH) and every point of that receiver is
//! tested against them; instants are spread over every core.
//!
//! A point's own receiver never shades it. A point's visibility is 1 (sun seen), 0 (shaded, sun
//! down, or behind the receiver), or the product of see-through casters' transmittances.
//!
//! Irradiation per point is a receiver's ([`crate::export::irradiation`]) with the point in the
//! receiver's place: at each sun-up instant (cos zenith ≥ [`MIN_COS_INCIDENCE`]) beam DNI·cos θ·v
//! (v the point's visibility of the sun), Perez 1990 sky diffuse from the point's own sky views
//! with its circumsolar part shaded by v, ground-reflected GHI·albedo·(1 − cos tilt)/2
//! unobstructed; the weather's hour holds over its instants.

mod gpu;
pub mod inside;
pub mod period;
pub mod planning;
pub mod points;
pub mod series;
pub mod sky;
pub mod study;

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use glam::DVec3;

pub use gpu::MapGpu;
pub use period::{Period, Sample};
pub use points::{from_csv, grid};
pub use sky::{point_sky, point_sky_for};

use crate::count::MIN_COS_INCIDENCE;
use crate::count::exact::engine::ExactEngine;
use crate::count::exact::rays::PlanePoints;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::sky::perez::PerezSky;
use crate::sky::views::SkyViews;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::sun::weather::Weather;
use crate::year::annual::shading_sun_day;
use crate::year::season::LeafCalendar;

/// Points on receivers, as flat arrays (what the web hands to JS as typed arrays).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Points {
    /// `x, y, z` per point, world axes (x east, y north, z up), metres.
    pub positions: Vec<f32>,
    /// Unit normal per point (`nx, ny, nz`): the receiver's for a grid, as given for a CSV.
    pub normals: Vec<f32>,
    /// The receiver (index into `Scene::receivers`) each point lies on.
    pub receivers: Vec<u32>,
    /// The grid spacing (m) when the points are a grid (each stands for `spacing²` of surface).
    pub spacing: Option<f64>,
}

impl Points {
    /// How many points.
    pub fn len(&self) -> usize {
        self.receivers.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.receivers.is_empty()
    }

    /// Position of point `i`.
    pub fn position(&self, i: usize) -> DVec3 {
        DVec3::new(self.positions[3 * i].into(), self.positions[3 * i + 1].into(), self.positions[3 * i + 2].into())
    }

    /// Normal of point `i`.
    pub fn normal(&self, i: usize) -> DVec3 {
        DVec3::new(self.normals[3 * i].into(), self.normals[3 * i + 1].into(), self.normals[3 * i + 2].into())
    }

    pub(crate) fn push(&mut self, p: DVec3, n: DVec3, receiver: u32) {
        self.positions.extend(p.to_array().map(|v| v as f32));
        self.normals.extend(n.to_array().map(|v| v as f32));
        self.receivers.push(receiver);
    }
}

/// The weather and site a period is evaluated under.
#[derive(Debug, Clone, Copy)]
pub struct Site<'a> {
    /// Where (the sun's path).
    pub location: &'a Location,
    /// The foliage's leaf fraction through the year.
    pub calendar: &'a LeafCalendar,
    /// The weather (DNI, DHI, GHI, albedo) that gives irradiation; `None`: sun hours only.
    pub weather: Option<&'a Weather>,
    /// The points' sky views ([`point_sky`], one per point in order): with `weather`, adds sky
    /// diffuse, ground-reflected and total irradiation.
    pub sky: Option<&'a SkyViews>,
}

/// Per point sums over a period.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MapValues {
    /// Hours of sun seen (visibility × hours, sun up and in front of the surface).
    pub sun_hours: Vec<f64>,
    /// Direct irradiation on the point's plane (kWh/m²): visibility · DNI · cos incidence ·
    /// hours; `None` without DNI.
    pub direct_kwh_m2: Option<Vec<f64>>,
    /// Sky-diffuse irradiation (kWh/m², Perez 1990, shaded by the point's sky views); `None`
    /// without weather or sky views.
    pub sky_diffuse_kwh_m2: Option<Vec<f64>>,
    /// Ground-reflected irradiation (kWh/m², unobstructed); `None` as for the sky.
    pub ground_reflected_kwh_m2: Option<Vec<f64>>,
    /// Direct + sky diffuse + ground-reflected (kWh/m²); `None` as for the sky.
    pub total_kwh_m2: Option<Vec<f64>>,
    /// The view factor to the visible sky (the period's mean over the leaf calendar; (1 + cos
    /// tilt)/2 with nothing in the way); `None` as for the sky.
    pub sky_view_factor: Option<Vec<f64>>,
    /// Instants in the period, and those with the sun up (each counted at every point).
    pub instants: usize,
    /// Instants with the sun up.
    pub sun_up: usize,
}

impl MapValues {
    /// Adds the sums of `other` (another stretch of the same points' period).
    pub fn merge(&mut self, other: &MapValues) {
        add_into(&mut self.sun_hours, &other.sun_hours);
        // A mean over instants: weighted by each stretch's instants.
        if let (Some(a), Some(b)) = (self.sky_view_factor.as_mut(), other.sky_view_factor.as_ref()) {
            let (na, nb) = (self.instants as f64, other.instants as f64);
            if na + nb > 0.0 {
                a.iter_mut().zip(b).for_each(|(a, b)| *a = (*a * na + b * nb) / (na + nb));
            }
        }
        for (into, from) in [
            (&mut self.direct_kwh_m2, &other.direct_kwh_m2),
            (&mut self.sky_diffuse_kwh_m2, &other.sky_diffuse_kwh_m2),
            (&mut self.ground_reflected_kwh_m2, &other.ground_reflected_kwh_m2),
            (&mut self.total_kwh_m2, &other.total_kwh_m2),
        ] {
            if let (Some(a), Some(b)) = (into.as_mut(), from.as_ref()) {
                add_into(a, b);
            }
        }
        self.instants += other.instants;
        self.sun_up += other.sun_up;
    }
}

/// One receiver's points, indexed for the rays, and where they sit in [`Points`].
struct Group {
    /// Its place in [`Mapper`]'s groups.
    index: usize,
    plane: PlanePoints,
    members: Vec<u32>,
    normal: DVec3,
}

/// Points indexed for the exact engine's shadow rays. Build once, ask many instants.
pub struct Mapper {
    engine: ExactEngine,
    groups: Vec<Group>,
    points: usize,
    normals: Vec<DVec3>,
    /// Whether the scene has foliage (sky views then need two leaf states).
    foliage: bool,
}

impl Mapper {
    /// Indexes `points` on `scene`; refuses a point whose receiver is not in the scene.
    pub fn new(scene: &Scene, points: &Points) -> Result<Self> {
        let engine = ExactEngine::new(scene);
        let mut by_receiver: Vec<Vec<u32>> = vec![Vec::new(); scene.receivers.len()];
        for (i, &r) in points.receivers.iter().enumerate() {
            by_receiver
                .get_mut(r as usize)
                .ok_or_else(|| Error::argument("points", format!("point {i} names receiver {r}; the scene has {}", scene.receivers.len())))?
                .push(i as u32);
        }
        let mut groups = Vec::new();
        for (r, members) in by_receiver.into_iter().enumerate() {
            if members.is_empty() {
                continue;
            }
            let world: Vec<DVec3> = members.iter().map(|&i| points.position(i as usize)).collect();
            let Some(plane) = engine.plane_points(r as u32, &world, scene.receivers[r].normal) else {
                return Err(Error::argument("points", format!("receiver '{}' has no area to put points on", scene.receivers[r].name)));
            };
            groups.push(Group { index: groups.len(), plane, members, normal: scene.receivers[r].normal });
        }
        let normals = (0..points.len()).map(|i| points.normal(i)).collect();
        Ok(Self { engine, groups, points: points.len(), normals, foliage: scene.has_foliage() })
    }

    /// Each point's visibility of the sun along `sun` (unit, towards the sun) at leaf fraction
    /// `leaves`: 1 lit, 0 shaded or dark.
    pub fn visibility(&self, sun: DVec3, leaves: f32) -> Vec<f32> {
        let mut out = vec![0.0f32; self.points];
        let mut scratch = self.engine.point_scratch();
        let mut buffer = Vec::new();
        for g in &self.groups {
            buffer.resize(g.members.len(), 0.0);
            self.engine.visibility(&g.plane, sun, leaves, &mut scratch, &mut buffer);
            for (&i, &v) in g.members.iter().zip(&buffer) {
                out[i as usize] = v;
            }
        }
        out
    }

    /// Sun hours and irradiation per point over `samples` (see [`MapValues`] for which parts
    /// `site` gives); `progress(done, total)` is called now and then from the calling thread.
    /// Instants are shared over every core; the sums do not depend on how. Refuses sky views
    /// made for other points.
    pub fn accumulate(&self, samples: &[Sample], site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> Result<MapValues> {
        let sums = Sums::new(self, site)?;
        let parts = self.sweep(
            samples,
            site,
            sums.dark_too(),
            progress,
            || sums.state(),
            |acc, _, s, sun, g, vis| sums.record(acc, s, sun, g, vis),
        );
        Ok(sums.finish(parts, samples))
    }

    /// [`Self::accumulate`] with the points answered by GPU masks ([`MapGpu`]) instead of rays.
    pub async fn accumulate_gpu(
        &self,
        gpu: &MapGpu<'_>,
        samples: &[Sample],
        site: Site<'_>,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<MapValues> {
        let sums = Sums::new(self, site)?;
        let parts =
            gpu.sweep(self, samples, site, progress, || sums.state(), |acc, _, s, sun, g, vis| sums.record(acc, s, sun, g, vis)).await?;
        Ok(sums.finish(parts, samples))
    }

    /// Which instants of `samples` each point sees the sun at (visibility ≥ 0.5) with the sun
    /// at least `min_altitude_deg` above the horizon: for the study rules, which need the order
    /// of lit instants (continuous periods), not just their sum.
    pub fn lit_series(
        &self,
        samples: &[Sample],
        site: Site<'_>,
        min_altitude_deg: f64,
        progress: &mut dyn FnMut(usize, usize),
    ) -> LitSeries {
        let bits = LitBits::new(self.points, samples.len(), min_altitude_deg);
        self.sweep(samples, site, false, progress, || (), |_, k, _, sun, g, vis| bits.record(k, sun, g, vis));
        bits.finish()
    }

    /// [`Self::lit_series`] with the points answered by GPU masks ([`MapGpu`]).
    pub async fn lit_series_gpu(
        &self,
        gpu: &MapGpu<'_>,
        samples: &[Sample],
        site: Site<'_>,
        min_altitude_deg: f64,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<LitSeries> {
        let bits = LitBits::new(self.points, samples.len(), min_altitude_deg);
        gpu.sweep(self, samples, site, progress, || (), |_, k, _, sun, g, vis| bits.record(k, sun, g, vis)).await?;
        Ok(bits.finish())
    }

    /// [`Self::visibility`] answered by GPU masks ([`MapGpu`]): 1 lit, 0 shaded or dark.
    pub async fn visibility_gpu(&self, gpu: &MapGpu<'_>, sun: DVec3, leaves: f32) -> Result<Vec<f32>> {
        let mut out = vec![0.0f32; self.points];
        gpu.instant(self, sun, leaves, |g, vis| {
            for (&i, &v) in g.members.iter().zip(vis) {
                out[i as usize] = v;
            }
        })
        .await?;
        Ok(out)
    }

    pub(crate) fn sun(&self, site: Site<'_>, s: &Sample) -> DVec3 {
        sun_direction(site.location, shading_sun_day(s.day), s.hour)
    }

    /// Every sun-up instant's visibility per receiver, handed to `record` with a thread's own
    /// state (made by `state`); the states come back, one per thread (natively every core, on
    /// the web the calling thread alone). Receivers facing away from the sun are skipped unless
    /// `dark_too` (then handed zeros: the sky still lights them).
    fn sweep<S: Send>(
        &self,
        samples: &[Sample],
        site: Site<'_>,
        dark_too: bool,
        progress: &mut dyn FnMut(usize, usize),
        state: impl Fn() -> S + Sync,
        record: impl Fn(&mut S, usize, &Sample, DVec3, &Group, &[f32]) + Sync,
    ) -> Vec<S> {
        let next = AtomicUsize::new(0);
        let done = AtomicUsize::new(0);
        let work = || {
            let mut s = state();
            let mut scratch = self.engine.point_scratch();
            let mut vis: Vec<f32> = Vec::new();
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(sample) = samples.get(k) else { break s };
                let sun = self.sun(site, sample);
                if sun.z >= MIN_COS_INCIDENCE {
                    let leaves = site.calendar.fraction(f64::from(sample.day)) as f32;
                    for g in &self.groups {
                        vis.resize(g.members.len(), 0.0);
                        if crate::count::is_dark(g.normal, sun) {
                            if !dark_too {
                                continue;
                            }
                            vis.fill(0.0);
                        } else {
                            self.engine.visibility(&g.plane, sun, leaves, &mut scratch, &mut vis);
                        }
                        record(&mut s, k, sample, sun, g, &vis);
                    }
                }
                done.fetch_add(1, Ordering::Relaxed);
            }
        };
        run_on_every_core(samples.len(), &done, progress, work)
    }
}

/// What [`Mapper::accumulate`] sums per point, shared by the rays' and the GPU masks' sweeps: sun
/// hours, and with weather the direct and (with sky views) the sky's parts.
struct Sums<'a> {
    mapper: &'a Mapper,
    site: Site<'a>,
    weather: Option<(&'a Weather, crate::year::samples::Timesteps)>,
    sky: Option<&'a SkyViews>,
    plan: Option<sky::SkyPlan<'a>>,
}

/// A thread's running sums (see [`Sums`]).
struct Acc {
    hours: Vec<f64>,
    direct: Option<Vec<f64>>,
    sky: Option<sky::SkySums>,
}

impl<'a> Sums<'a> {
    /// Refuses sky views made for other points.
    fn new(mapper: &'a Mapper, site: Site<'a>) -> Result<Self> {
        let n = mapper.points;
        let hourly = crate::year::samples::Timesteps::new(1).ok();
        let weather = site.weather.zip(hourly);
        let sky = match (weather, site.sky) {
            (Some(_), Some(sky)) if sky.receivers() != n => {
                return Err(Error::argument("sky", format!("sky views of {} points for {n}", sky.receivers())));
            }
            (Some(_), sky) => sky,
            (None, _) => None,
        };
        // A luminance distribution is summed per patch over the period in `finish`, not per step.
        let plan = sky.filter(|sky| !sky.model().is_distribution()).map(|sky| sky::SkyPlan::new(mapper, sky));
        Ok(Self { mapper, site, weather, sky, plan })
    }

    /// Whether receivers facing away from the sun must be visited too (the sky's shared terms).
    fn dark_too(&self) -> bool {
        self.plan.is_some()
    }

    fn state(&self) -> Acc {
        let n = self.mapper.points;
        Acc { hours: vec![0.0; n], direct: self.weather.is_some().then(|| vec![0.0; n]), sky: self.plan.as_ref().map(|p| p.sums(n)) }
    }

    fn record(&self, acc: &mut Acc, s: &Sample, sun: DVec3, g: &Group, vis: &[f32]) {
        let hour = self.weather.map(|(w, t)| w.at(t, s.epw_hour));
        let dni = hour.map_or(0.0, |h| h.dni);
        // Facing away from the sun every visibility is 0: only the sky's shared terms count.
        let dark = crate::count::is_dark(g.normal, sun);
        for (&i, &v) in g.members.iter().zip(vis).filter(|_| !dark) {
            if v > 0.0 {
                let i = i as usize;
                acc.hours[i] += f64::from(v) * s.hours;
                if let Some(direct) = acc.direct.as_mut() {
                    let cos = self.mapper.normals[i].dot(sun).max(0.0);
                    direct[i] += f64::from(v) * dni * cos * s.hours / 1000.0;
                }
            }
        }
        if let (Some(plan), Some(sums), Some(hour)) = (&self.plan, acc.sky.as_mut(), hour)
            && let Some(perez) = PerezSky::new(hour.dni, hour.dhi, sun.z, self.site.location.elevation)
        {
            let leaves = self.site.calendar.fraction(f64::from(s.day));
            plan.add(sums, self.mapper, g.index, &perez, hour.dhi, sun, leaves, s.hours, if dark { &[] } else { vis });
        }
    }

    fn finish(self, parts: Vec<Acc>, samples: &[Sample]) -> MapValues {
        let (mapper, site, n) = (self.mapper, self.site, self.mapper.points);
        let mut total = Acc { hours: vec![0.0; n], direct: self.weather.is_some().then(|| vec![0.0; n]), sky: None };
        let mut sky_parts = Vec::new();
        for part in parts {
            add_into(&mut total.hours, &part.hours);
            if let (Some(a), Some(b)) = (total.direct.as_mut(), part.direct.as_ref()) {
                add_into(a, b);
            }
            sky_parts.extend(part.sky);
        }
        let sky_diffuse = match self.plan {
            Some(p) => Some(p.finish(mapper, sky_parts)),
            None => sky::distribution_diffuse(mapper, site, samples),
        };
        let sun_up: Vec<&Sample> = samples.iter().filter(|s| mapper.sun(site, s).z >= MIN_COS_INCIDENCE).collect();
        let mut values = MapValues { sun_hours: total.hours, instants: samples.len(), sun_up: sun_up.len(), ..MapValues::default() };
        values.direct_kwh_m2 = total.direct;
        if let (Some((w, t)), Some(sky_diffuse)) = (self.weather, sky_diffuse) {
            // Ground-reflected light is unobstructed: GHI·albedo summed once, times each point's
            // view factor to the ground (1 − cos tilt)/2.
            let ground_horizontal: f64 = sun_up
                .iter()
                .map(|s| {
                    let hour = w.at(t, s.epw_hour);
                    hour.ghi * hour.albedo * s.hours / 1000.0
                })
                .sum();
            let ground: Vec<f64> = mapper.normals.iter().map(|n| ground_horizontal * (1.0 - n.z) / 2.0).collect();
            let direct = values.direct_kwh_m2.as_deref().unwrap_or_default();
            values.total_kwh_m2 = Some((0..n).map(|i| direct.get(i).copied().unwrap_or(0.0) + sky_diffuse[i] + ground[i]).collect());
            values.sky_diffuse_kwh_m2 = Some(sky_diffuse);
            values.ground_reflected_kwh_m2 = Some(ground);
            if let Some(sky) = self.sky {
                // The views are linear in the leaf fraction: the mean view is the view at the mean.
                let leaves = samples.iter().map(|s| site.calendar.fraction(f64::from(s.day))).sum::<f64>() / samples.len().max(1) as f64;
                values.sky_view_factor = Some((0..n).map(|i| sky.isotropic(i, leaves)).collect());
            }
        }
        values
    }
}

fn add_into(into: &mut [f64], from: &[f64]) {
    for (a, b) in into.iter_mut().zip(from) {
        *a += b;
    }
}

/// What [`Mapper::lit_series`] records: a bit per point and lit instant, shared by threads.
struct LitBits {
    words: usize,
    instants: usize,
    min_z: f64,
    bits: Vec<AtomicU64>,
}

impl LitBits {
    fn new(points: usize, instants: usize, min_altitude_deg: f64) -> Self {
        let words = instants.div_ceil(64);
        let bits = (0..points * words).map(|_| AtomicU64::new(0)).collect();
        Self { words, instants, min_z: min_altitude_deg.to_radians().sin(), bits }
    }

    fn record(&self, k: usize, sun: DVec3, g: &Group, vis: &[f32]) {
        if sun.z < self.min_z {
            return;
        }
        for (&i, &v) in g.members.iter().zip(vis) {
            if v >= 0.5 {
                self.bits[i as usize * self.words + k / 64].fetch_or(1 << (k % 64), Ordering::Relaxed);
            }
        }
    }

    fn finish(self) -> LitSeries {
        LitSeries { words: self.words, instants: self.instants, bits: self.bits.into_iter().map(AtomicU64::into_inner).collect() }
    }
}

/// Runs `work` on every core (natively; on the web once, on the calling thread: it has no
/// threads to spawn) and returns what each run returned. `done` counts finished units of
/// `total`, reported through `progress` from the calling thread every 100 ms. The calling thread
/// wakes as soon as the last run ends (each says so on a channel), not at its next report: a
/// window study runs a dozen short sweeps, and a sleep's remainder after each was wall time.
fn run_on_every_core<S: Send>(
    total: usize,
    done: &AtomicUsize,
    progress: &mut dyn FnMut(usize, usize),
    work: impl Fn() -> S + Sync,
) -> Vec<S> {
    if cfg!(target_arch = "wasm32") {
        let s = work();
        progress(total, total);
        return vec![s];
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, total.max(1));
    let (ended, ends) = std::sync::mpsc::channel::<()>();
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                let (ended, work) = (ended.clone(), &work);
                scope.spawn(move || {
                    let s = work();
                    // The receiver outlives every worker (the scope joins them first).
                    let _ = ended.send(());
                    s
                })
            })
            .collect();
        // Only the workers hold senders now: a worker that unwinds drops its own, so the channel
        // closes once every worker has ended either way.
        drop(ended);
        let mut running = threads;
        while running > 0 {
            progress(done.load(Ordering::Relaxed), total);
            match ends.recv_timeout(std::time::Duration::from_millis(100)) {
                Ok(()) => running -= 1,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                // Every sender gone: each worker has ended or unwound (join says which).
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
            }
        }
        progress(total, total);
        workers.into_iter().filter_map(|w| w.join().ok()).collect()
    })
}

/// Per point, which instants of a period it saw the sun at (see [`Mapper::lit_series`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LitSeries {
    words: usize,
    instants: usize,
    bits: Vec<u64>,
}

impl LitSeries {
    /// Whether point `i` saw the sun at instant `k`.
    pub fn lit(&self, i: usize, k: usize) -> bool {
        k < self.instants && self.bits[i * self.words + k / 64] >> (k % 64) & 1 == 1
    }

    /// Instants in the period.
    pub fn instants(&self) -> usize {
        self.instants
    }
}

/// Each point's visibility of the sun along `sun` at leaf fraction `leaves` (a one-off
/// [`Mapper::visibility`]).
pub fn lit(scene: &Scene, points: &Points, sun: DVec3, leaves: f32) -> Result<Vec<f32>> {
    Ok(Mapper::new(scene, points)?.visibility(sun, leaves))
}

/// Sun hours and irradiation per point over `period` (a one-off [`Mapper::accumulate`]).
pub fn accumulate(scene: &Scene, points: &Points, period: &Period, site: Site<'_>) -> Result<MapValues> {
    Mapper::new(scene, points)?.accumulate(&period.samples(), site, &mut |_, _| {})
}
