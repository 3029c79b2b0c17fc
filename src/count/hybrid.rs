//! The hybrid engine: every view answered by the cheaper of exact clipping ([`ExactEngine`]) and
//! GPU pixels ([`Counter`]), routed by a cost model measured on the device.
//!
//! Owns the choice of engine ([`EngineKind`]), the cost model ([`Profile`]), its calibration and
//! cache, and the split of a batch of views between the engines:
//! - a view's *load* is what the BVH walk in its prism finds ([`ViewLoad`]): the triangles it
//!   reaches. Each engine's cost is modelled as `per_view + per_triangle × triangles` µs; the GPU's
//!   `per_view` holds its pixels at the run's side, so a profile belongs to one resolution;
//! - `auto` routes each view to the engine with the lower modelled cost; views with see-through
//!   geometry in their prism go to the GPU (the exact engine counts it as opaque); views with
//!   nothing in their prism or the sun behind the surface are exact at no cost. If the views
//!   routed to the GPU would save less than its start-up, they go to the exact engine too, and no
//!   device is made;
//! - routing depends only on the loads and the profile, never on timing during the run, so the
//!   same inputs with the same profile give the same answers byte for byte. The profile is
//!   measured once per device (a probe of the exact engine on the model's own views, a few ms,
//!   and of the GPU only where the exact engine's estimate exceeds a GPU's start-up), kept in a cache file keyed by adapter, driver, resolution, cores and the scene's size, and can be pinned
//!   with a profile file of its own;
//! - both engines run at once: natively the exact views on every core's threads while the GPU
//!   lanes count theirs; on the web the page's pool of workers clips while its GPU counts
//!   (`web::choice`), routed by the same profile, probed by the same functions
//!   ([`probe_exact`], [`probe_gpu`]) and keyed alike ([`adapter_threads_key`]); only where it
//!   is kept differs (IndexedDB there, a file here).

use std::cell::OnceCell;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::exact::engine::{ExactEngine, ViewLoad};
use super::gpu::{Counter, CounterOptions, GpuScene, Kernel};
use super::lanes::{Lane, Lanes, default_lanes};
use super::{Engine, ViewAnswer, ViewKind, ViewRequest, check_receivers, cos_incidence};
use crate::error::{Error, GpuError, Result};
use crate::platform::{self, CLOCK_FLOOR_S, seconds as now};
use crate::scene::Scene;

pub use keys::{
    adapter_key, adapter_threads_key, cpu_key, device_key, profile_file, profile_for, read_profile, scene_key, views_key, write_profile,
};
use keys::{cached, store_cached};

/// Views each engine is timed on when calibrating (spread over the loads).
pub const PROBE_EXACT_VIEWS: usize = 48;
/// Most time the exact probe may take (s); it stops early past it.
const PROBE_EXACT_SECONDS: f64 = 0.15;
/// Times each probed view is clipped (the fastest counts) ...
const PROBE_EXACT_REPEATS: usize = 3;
/// ... unless one run already took this long (s): then a preemption is a small part of it.
const PROBE_REPEAT_BELOW: f64 = 0.002;
/// Views per GPU probe batch (a light and a heavy batch).
const PROBE_GPU_VIEWS: usize = 64;
/// Start-up a GPU is assumed to cost (s) before one has been measured: below this much work
/// in total, `auto` answers everything exactly without making a device.
const ASSUMED_GPU_STARTUP: f64 = 0.5;

/// Which engine answers views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EngineKind {
    /// Per view, the cheaper of the two (see the module doc).
    #[default]
    Auto,
    /// GPU pixel counting only.
    Gpu,
    /// Exact polygon clipping only (see-through geometry counts as opaque).
    Exact,
    /// GPU pixel counting by the compute rasterizer only ([`crate::count::gpu::compute`]).
    Compute,
}

impl EngineKind {
    /// `auto`, `gpu`, `exact` or `compute`.
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "gpu" => Ok(Self::Gpu),
            "exact" => Ok(Self::Exact),
            "compute" => Ok(Self::Compute),
            other => Err(Error::argument("engine", format!("'{other}' is not one of auto, gpu, exact, compute"))),
        }
    }

    /// The name [`Self::parse`] takes.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Gpu => "gpu",
            Self::Exact => "exact",
            Self::Compute => "compute",
        }
    }

    /// Whether it counts on a GPU only (no exact engine is made).
    pub fn gpu_only(&self) -> bool {
        matches!(self, Self::Gpu | Self::Compute)
    }
}

/// One engine's modelled cost of a view: `per_view + per_triangle × triangles` µs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    /// µs a view costs whatever it holds (the GPU's pixels, the exact engine's set-up).
    pub per_view_us: f64,
    /// µs per triangle in the view's prism.
    pub per_triangle_us: f64,
}

impl Cost {
    /// Modelled µs of a view with `load`.
    pub fn of(&self, load: ViewLoad) -> f64 {
        self.per_view_us + self.per_triangle_us * load.triangles as f64
    }
}

/// A device's cost model: what `auto` routes by.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// The device it was measured on (adapter, driver, CPU threads, tile side; "exact only" and
    /// no adapter where no GPU was worth probing) and the scene's size.
    pub device: String,
    /// The exact engine on this machine's threads.
    pub exact: Cost,
    /// The GPU at the profile's side; `None` until measured (no view has needed it yet).
    pub gpu: Option<Cost>,
    /// Seconds to make the GPU device(s) and upload a scene, when measured.
    pub gpu_startup_seconds: Option<f64>,
    /// The compute rasterizer at the profile's side; `None` until measured (profiles kept
    /// before it existed have none, and route as they did).
    #[serde(default)]
    pub compute: Option<Cost>,
    /// Seconds to make its device(s) and upload the scene, when measured.
    #[serde(default)]
    pub compute_startup_seconds: Option<f64>,
}

/// Where a view is answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Exact polygon clipping.
    Exact,
    /// GPU pixel counting.
    Gpu,
    /// GPU pixel counting by the compute rasterizer.
    Compute,
}

impl Profile {
    /// Routes views with these loads, a batch of a run of `run_views` views in all (a GPU kernel's
    /// start-up is paid once a run, so this batch's saving is weighed as the run's: scaled by
    /// `run_views` over the batch's views): see the module doc. A pure function of its inputs.
    pub fn route(&self, loads: &[ViewLoad], run_views: usize) -> Vec<Route> {
        let mut routes: Vec<Route> = loads.iter().map(|&l| self.route_one(l)).collect();
        let runs_per_batch = (run_views as f64 / loads.len().max(1) as f64).max(1.0);
        // The compute kernel first: views it would save too little on go where they would go
        // without it; then the raster kernel's against clipping alone, as before.
        let kernels = [(Route::Compute, self.compute, self.compute_startup_seconds), (Route::Gpu, self.gpu, self.gpu_startup_seconds)];
        let bare = Profile { compute: None, compute_startup_seconds: None, ..self.clone() };
        for (route, cost, startup) in kernels {
            let without = |l: ViewLoad| if route == Route::Compute { bare.route_one(l) } else { Route::Exact };
            let needed = loads.iter().zip(&routes).any(|(l, r)| *r == route && l.see_through > 0 && without(*l) == Route::Exact);
            let saving_us: f64 = loads
                .iter()
                .zip(&routes)
                .filter(|(_, r)| **r == route)
                .map(|(&l, _)| self.cost_of(without(l), l) - cost.map_or(0.0, |c| c.of(l)))
                .sum();
            let startup_us = 1e6 * startup.unwrap_or(ASSUMED_GPU_STARTUP);
            if !needed && saving_us * runs_per_batch < startup_us {
                for (r, &l) in routes.iter_mut().zip(loads) {
                    if *r == route {
                        *r = without(l);
                    }
                }
            }
        }
        routes
    }

    /// Where one view goes on its own load (before [`Self::route`]'s rule for the whole batch):
    /// the engine with the lowest modelled cost; a view with see-through geometry to the
    /// cheaper GPU kernel (the exact engine counts it as opaque).
    pub fn route_one(&self, load: ViewLoad) -> Route {
        if load.triangles == 0 {
            return Route::Exact;
        }
        let kernels = [(Route::Gpu, self.gpu), (Route::Compute, self.compute)];
        let cheapest_gpu = kernels.iter().filter_map(|(r, c)| c.map(|c| (*r, c.of(load)))).min_by(|a, b| a.1.total_cmp(&b.1));
        match cheapest_gpu {
            Some((r, _)) if load.see_through > 0 => r,
            None if load.see_through > 0 => Route::Gpu,
            Some((r, us)) if us < self.exact.of(load) => r,
            _ => Route::Exact,
        }
    }

    /// Modelled µs of a view of `load` on `route` (0 for a kernel not measured).
    fn cost_of(&self, route: Route, load: ViewLoad) -> f64 {
        match route {
            Route::Exact => self.exact.of(load),
            Route::Gpu => self.gpu.map_or(0.0, |c| c.of(load)),
            Route::Compute => self.compute.map_or(0.0, |c| c.of(load)),
        }
    }
}

/// The requests `routes` sends to `route`, with their indices in `requests` (to put the answers
/// back in order).
fn routed_to(requests: &[ViewRequest], routes: &[Route], route: Route) -> (Vec<usize>, Vec<ViewRequest>) {
    let idx: Vec<usize> = (0..requests.len()).filter(|&i| routes[i] == route).collect();
    let reqs = idx.iter().map(|&i| requests[i]).collect();
    (idx, reqs)
}

/// Answers holding only each view's cosine of incidence, for the engines' counts to fill in.
fn unanswered(scene: &Scene, requests: &[ViewRequest]) -> Vec<ViewAnswer> {
    requests
        .iter()
        .map(|r| ViewAnswer {
            cos_incidence: scene.receivers.get(r.receiver as usize).map_or(0.0, |s| cos_incidence(s.normal, r.sun)),
            ..Default::default()
        })
        .collect()
}

/// One engine's part of a routed batch.
enum Counted {
    Exact(Vec<f64>),
    Gpu(Vec<ViewAnswer>),
    Compute(Vec<ViewAnswer>),
}

/// Requests split by route, natively and on the web alike: each part with its indices in the
/// original order, and the exact part's loads when routing walked them (so the exact engine does
/// not walk again where nothing was in front).
pub struct Split {
    /// Where the exact part's requests sit in the original order.
    pub exact_idx: Vec<usize>,
    /// The requests routed to the exact engine.
    pub exact_reqs: Vec<ViewRequest>,
    /// Empty when routing did not walk the views.
    exact_loads: Vec<ViewLoad>,
    /// Where the GPU part's requests sit in the original order.
    pub gpu_idx: Vec<usize>,
    /// The requests routed to the GPU.
    pub gpu_reqs: Vec<ViewRequest>,
    /// Where the compute kernel's part sits in the original order.
    pub compute_idx: Vec<usize>,
    /// The requests routed to the compute kernel.
    pub compute_reqs: Vec<ViewRequest>,
}

impl Split {
    /// Splits `requests` by `routes`; `loads` are the requests' own, if routing walked them.
    pub fn new(requests: &[ViewRequest], routes: &[Route], loads: Option<&[ViewLoad]>) -> Self {
        let (exact_idx, exact_reqs) = routed_to(requests, routes, Route::Exact);
        let exact_loads = loads.map_or_else(Vec::new, |l| exact_idx.iter().map(|&i| l[i]).collect());
        let (gpu_idx, gpu_reqs) = routed_to(requests, routes, Route::Gpu);
        let (compute_idx, compute_reqs) = routed_to(requests, routes, Route::Compute);
        Self { exact_idx, exact_reqs, exact_loads, gpu_idx, gpu_reqs, compute_idx, compute_reqs }
    }

    /// The exact part's fractions.
    pub fn exact_fractions(&self, exact: &ExactEngine) -> Vec<f64> {
        exact.fractions_loaded(&self.exact_reqs, &self.exact_loads)
    }

    /// The answers in the requests' order: exact ones carry their fraction and cosine (error 0),
    /// the GPU's their pixel counts too.
    pub fn merge(&self, scene: &Scene, requests: &[ViewRequest], exact: Vec<f64>, gpu: Vec<ViewAnswer>) -> Vec<ViewAnswer> {
        self.merge_all(scene, requests, exact, gpu, Vec::new())
    }

    /// [`Self::merge`] with the compute kernel's answers too.
    pub fn merge_all(
        &self,
        scene: &Scene,
        requests: &[ViewRequest],
        exact: Vec<f64>,
        gpu: Vec<ViewAnswer>,
        compute: Vec<ViewAnswer>,
    ) -> Vec<ViewAnswer> {
        let mut out = unanswered(scene, requests);
        for (&i, fraction) in self.exact_idx.iter().zip(exact) {
            out[i].fraction = fraction;
            out[i].error_estimate = Some(0.0);
        }
        for (&i, answer) in self.gpu_idx.iter().zip(gpu).chain(self.compute_idx.iter().zip(compute)) {
            out[i] = answer;
        }
        out
    }
}

/// Where the profile comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ProfileSource {
    /// The per-device cache file (made by a probe the first time).
    Cache,
    /// This file: read when it exists, else measured and written there (pins the routing).
    File(PathBuf),
    /// Measured now and kept nowhere.
    Probe,
}

/// Counts per engine and the wall time each took (they overlap when both run).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EngineStats {
    /// Views answered exactly (including dark views and views with nothing in front).
    pub exact_views: usize,
    /// Views counted on the GPU (by the raster kernel).
    pub gpu_views: usize,
    /// Views counted by the compute rasterizer.
    pub compute_views: usize,
    /// Wall seconds the exact engine worked.
    pub exact_seconds: f64,
    /// Wall seconds the GPU lanes worked.
    pub gpu_seconds: f64,
    /// Wall seconds the compute kernel's lanes worked.
    pub compute_seconds: f64,
    /// Seconds spent calibrating (probing both engines).
    pub calibration_seconds: f64,
    /// Seconds spent making GPU devices and uploading the scene.
    pub gpu_startup_seconds: f64,
}

/// Counts views of one scene with the engine chosen; the GPU is made only when a view needs it.
pub struct HybridEngine<'a> {
    scene: &'a Scene,
    kind: EngineKind,
    options: CounterOptions,
    lanes_wanted: Option<usize>,
    source: ProfileSource,
    exact: Option<ExactEngine>,
    gpu: OnceCell<Vec<(Counter, GpuScene)>>,
    /// The compute kernel's lanes, made when a view first needs them.
    compute: OnceCell<Vec<(Counter, GpuScene)>>,
    /// Per kind of views ([`ViewKind`], sun first), the profile `auto` routes them by.
    profiles: [OnceCell<(Profile, &'static str)>; 2],
    /// The kind of views being asked for now.
    views: std::cell::Cell<ViewKind>,
    stats: std::cell::Cell<EngineStats>,
    /// Views the caller expects to ask for in all ([`Engine::expect`]; 0: each batch alone).
    run_views: std::cell::Cell<usize>,
}

impl<'a> HybridEngine<'a> {
    /// An engine over `scene`; `options` and `lanes` (default: [`default_lanes`]) for the GPU.
    pub fn new(scene: &'a Scene, kind: EngineKind, options: CounterOptions, lanes: Option<usize>, source: ProfileSource) -> Result<Self> {
        if lanes == Some(0) {
            return Err(Error::argument("lanes", "must be at least 1"));
        }
        // Refused here too, as the GPU would: `auto` may never make a device.
        if let Some(a) = options.accuracy
            && !(a > 0.0 && a < 1.0)
        {
            return Err(Error::argument("accuracy", format!("{a} is not a fraction error in (0, 1)")));
        }
        let exact = (!kind.gpu_only()).then(|| ExactEngine::new(scene));
        Ok(Self {
            scene,
            kind,
            options,
            lanes_wanted: lanes,
            source,
            exact,
            gpu: OnceCell::new(),
            compute: OnceCell::new(),
            profiles: [OnceCell::new(), OnceCell::new()],
            views: Default::default(),
            stats: Default::default(),
            run_views: Default::default(),
        })
    }

    /// Uses `lanes` (counters with `scene` uploaded) instead of making them when first needed:
    /// the compute kernel's with [`EngineKind::Compute`], else the raster kernel's.
    pub fn with_lanes(self, lanes: Vec<(Counter, GpuScene)>) -> Self {
        let _ = if self.kind == EngineKind::Compute { self.compute.set(lanes) } else { self.gpu.set(lanes) };
        self
    }

    /// The engine chosen.
    pub fn kind(&self) -> EngineKind {
        self.kind
    }

    /// The profile `auto` routes the current kind of views by and where it came from (`cache`,
    /// `file`, `probe`), once known.
    pub fn profile(&self) -> Option<(&Profile, &'static str)> {
        self.profile_slot().get().map(|(p, s)| (p, *s))
    }

    /// The profile of the kind of views being asked for now.
    fn profile_slot(&self) -> &OnceCell<(Profile, &'static str)> {
        &self.profiles[match self.views.get() {
            ViewKind::Sun => 0,
            ViewKind::Sky => 1,
        }]
    }

    /// Views and seconds per engine so far.
    pub fn stats(&self) -> EngineStats {
        self.stats.get()
    }

    /// The GPU lanes, if made (the compute kernel's with [`EngineKind::Compute`]).
    pub fn lanes(&self) -> Option<&[(Counter, GpuScene)]> {
        if self.kind == EngineKind::Compute { self.compute.get() } else { self.gpu.get() }.map(Vec::as_slice)
    }

    /// The exact engine (absent with [`EngineKind::Gpu`]).
    pub fn exact(&self) -> Option<&ExactEngine> {
        self.exact.as_ref()
    }

    /// Drops the GPU lanes (after a lost device); the next view that needs one makes them anew.
    pub fn forget_gpu(&mut self) {
        self.gpu = OnceCell::new();
        self.compute = OnceCell::new();
    }

    fn add_stats(&self, f: impl FnOnce(&mut EngineStats)) {
        let mut s = self.stats.get();
        f(&mut s);
        self.stats.set(s);
    }

    async fn gpu_lanes(&self) -> Result<&[(Counter, GpuScene)]> {
        self.lanes_of(Kernel::Raster).await
    }

    /// The lanes of one kernel, made (and the scene uploaded) the first time they are asked for.
    async fn lanes_of(&self, kernel: Kernel) -> Result<&[(Counter, GpuScene)]> {
        let cell = if kernel == Kernel::Compute { &self.compute } else { &self.gpu };
        if let Some(lanes) = cell.get() {
            return Ok(lanes);
        }
        let start = now();
        let options = CounterOptions { kernel, ..self.options };
        let first = Counter::new(options).await?;
        let n = self.lanes_wanted.unwrap_or_else(|| default_lanes(first.adapter_info()));
        let mut counters = vec![first];
        for _ in 1..n {
            counters.push(Counter::new(options).await?);
        }
        let lanes = counters
            .into_iter()
            .map(|c| {
                let gpu = c.upload(self.scene)?;
                Ok((c, gpu))
            })
            .collect::<Result<Vec<_>>>()?;
        let seconds = now() - start;
        self.add_stats(|s| s.gpu_startup_seconds += seconds);
        let _ = cell.set(lanes);
        cell.get().map(Vec::as_slice).ok_or_else(|| Error::Gpu(GpuError::Device("GPU lanes went missing".into())))
    }

    /// Answers `requests`, each on the engine the choice (and for `auto` the profile) routes it to.
    pub async fn count(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        check_receivers(self.scene.receivers.len(), requests)?;
        let routes = match (self.kind, &self.exact) {
            (EngineKind::Compute, _) => vec![Route::Compute; requests.len()],
            (EngineKind::Gpu, _) | (_, None) => vec![Route::Gpu; requests.len()],
            (EngineKind::Exact, Some(_)) => vec![Route::Exact; requests.len()],
            (EngineKind::Auto, Some(exact)) => {
                let stored = self.stored_profile().await?;
                // One walk a view learns the GPU's views only once every view is walked, so the
                // engines then run one after the other: taken only where no view is expected to
                // go to the GPU (an exact-only profile, a run whose earlier batches were all
                // clipped, or a first batch none of whose sampled views the profile would send
                // there). Otherwise the loads are walked first, so both engines start at once.
                // Either path routes every view the same way.
                let stats = self.stats();
                if let Some(profile) = stored
                    && ((profile.gpu.is_none() && profile.compute.is_none())
                        || (stats.gpu_views + stats.compute_views == 0
                            && (stats.exact_views > 0 || !sample_may_go_to_gpu(exact, profile, requests))))
                {
                    return self.count_in_one_walk(exact, profile, requests).await;
                }
                let loads = exact.loads(requests);
                let profile = match stored {
                    Some(p) => p,
                    None => self.measure_profile(exact, requests, &loads).await?,
                };
                let routes = profile.route(&loads, self.run_views.get());
                return self.count_routed_loaded(requests, &routes, Some(&loads)).await;
            }
        };
        self.count_routed(requests, &routes).await
    }

    /// `auto` with a known profile, one BVH walk for most views: each view's walk gives its load,
    /// and a view the profile clips whatever the others do ([`Profile::route_one`]) is clipped at
    /// once from that walk. The rest follow [`Profile::route`] on all the loads, which only ever
    /// moves views from the GPU to the exact engine, so every view goes where routing by loads
    /// first would send it, with the same answer. The GPU's views wait for the whole walk.
    async fn count_in_one_walk(&self, exact: &ExactEngine, profile: &Profile, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        let start = now();
        let walked = exact.fractions_unless(requests, |load| profile.route_one(load) != Route::Exact);
        let seconds = now() - start;
        let loads: Vec<ViewLoad> = walked.iter().map(|(load, _)| *load).collect();
        let routes = profile.route(&loads, self.run_views.get());
        let clipped: Vec<usize> = (0..requests.len()).filter(|&i| walked[i].1.is_some()).collect();
        self.add_stats(|s| {
            s.exact_views += clipped.len();
            s.exact_seconds += seconds;
        });
        let rest: Vec<usize> = (0..requests.len()).filter(|&i| walked[i].1.is_none()).collect();
        let pick = |idx: &[usize]| -> Vec<ViewRequest> { idx.iter().map(|&i| requests[i]).collect() };
        let rest_routes: Vec<Route> = rest.iter().map(|&i| routes[i]).collect();
        let rest_loads: Vec<ViewLoad> = rest.iter().map(|&i| loads[i]).collect();
        let rest_answers = self.count_routed_loaded(&pick(&rest), &rest_routes, Some(&rest_loads)).await?;
        let mut out = unanswered(self.scene, requests);
        for &i in &clipped {
            out[i].fraction = walked[i].1.unwrap_or(0.0);
            out[i].error_estimate = Some(0.0);
        }
        for (&i, answer) in rest.iter().zip(rest_answers) {
            out[i] = answer;
        }
        Ok(out)
    }

    /// Counts each request on the engine `routes` names, both engines at once.
    pub async fn count_routed(&self, requests: &[ViewRequest], routes: &[Route]) -> Result<Vec<ViewAnswer>> {
        self.count_routed_loaded(requests, routes, None).await
    }

    /// As [`Self::count_routed`], with the requests' loads when routing has walked them already
    /// (the exact engine then does not walk again where nothing was in front).
    async fn count_routed_loaded(&self, requests: &[ViewRequest], routes: &[Route], loads: Option<&[ViewLoad]>) -> Result<Vec<ViewAnswer>> {
        let split = Split::new(requests, routes, loads);
        let lanes_for = async |kernel, reqs: &[ViewRequest]| -> Result<Vec<Lane<'_>>> {
            if reqs.is_empty() {
                return Ok(Vec::new());
            }
            Ok(self.lanes_of(kernel).await?.iter().map(|(counter, gpu)| Lane { counter, gpu }).collect())
        };
        let lanes = lanes_for(Kernel::Raster, &split.gpu_reqs).await?;
        let compute_lanes = lanes_for(Kernel::Compute, &split.compute_reqs).await?;
        let exact = match (&self.exact, split.exact_reqs.is_empty()) {
            (_, true) => None,
            (Some(e), false) => Some(e),
            (None, false) => return Err(Error::argument("engine", "views routed to the exact engine of a GPU-only engine")),
        };
        #[derive(Clone, Copy)]
        enum Part<'p> {
            Exact(&'p ExactEngine),
            Gpu,
            Compute,
        }
        let mut parts = Vec::new();
        if let Some(e) = exact {
            parts.push(Part::Exact(e));
        }
        if !split.gpu_reqs.is_empty() {
            parts.push(Part::Gpu);
        }
        if !split.compute_reqs.is_empty() {
            parts.push(Part::Compute);
        }
        let results = platform::side_by_side(&parts, |part| {
            let (part, lanes, compute_lanes, split) = (*part, &lanes, &compute_lanes, &split);
            async move {
                let start = now();
                let counted = match part {
                    Part::Exact(e) => Ok(Counted::Exact(split.exact_fractions(e))),
                    Part::Gpu => Lanes(lanes).answer(&split.gpu_reqs).await.map(Counted::Gpu),
                    Part::Compute => Lanes(compute_lanes).answer(&split.compute_reqs).await.map(Counted::Compute),
                };
                (counted, now() - start)
            }
        })
        .await;
        let (mut exact_fractions, mut gpu_answers, mut compute_answers) = (Vec::new(), Vec::new(), Vec::new());
        for (counted, seconds) in results {
            match counted? {
                Counted::Exact(fractions) => {
                    exact_fractions = fractions;
                    self.add_stats(|s| {
                        s.exact_views += split.exact_idx.len();
                        s.exact_seconds += seconds;
                    });
                }
                Counted::Gpu(answers) => {
                    gpu_answers = answers;
                    self.add_stats(|s| {
                        s.gpu_views += split.gpu_idx.len();
                        s.gpu_seconds += seconds;
                    });
                }
                Counted::Compute(answers) => {
                    compute_answers = answers;
                    self.add_stats(|s| {
                        s.compute_views += split.compute_idx.len();
                        s.compute_seconds += seconds;
                    });
                }
            }
        }
        Ok(split.merge_all(self.scene, requests, exact_fractions, gpu_answers, compute_answers))
    }

    /// The scene's size and the kind of views, as the profile's key names them: a profile is
    /// measured on the model's own views of that kind, and their loads cost differently per model
    /// (leaves overlap far more than slats) and per kind (see [`ViewKind`]).
    fn scene_key(&self) -> String {
        views_key(self.scene, self.views.get())
    }

    /// Where the current kind of views' profile is kept and how (see [`profile_file`]).
    fn source(&self) -> ProfileSource {
        match &self.source {
            ProfileSource::File(path) => ProfileSource::File(profile_file(path, self.views.get())),
            other => other.clone(),
        }
    }

    /// The profile to route by when one is known without measuring: already in use, pinned in a
    /// file that exists, or cached for this device (see [`ProfileSource`]).
    async fn stored_profile(&self) -> Result<Option<&Profile>> {
        if let Some((p, _)) = self.profile_slot().get() {
            return Ok(Some(p));
        }
        let scene = self.scene_key();
        let found = match &self.source() {
            ProfileSource::File(path) if path.exists() => Some((read_profile(path)?, "file")),
            ProfileSource::Cache => {
                // An exact-only profile is kept under the CPU's key: finding it asks no adapter.
                let cpu = cpu_key(&self.options, cpu_threads()).map(|k| format!("{k}; {scene}"));
                match cpu.as_deref().and_then(cached) {
                    Some(p) => Some((p, "cache")),
                    None => cached(&format!("{}; {scene}", device_key(&self.options).await?)).map(|p| {
                        // Kept by an older sunlit under its adapter's key: found without one next time.
                        if let (None, Some(cpu)) = (&p.gpu, &cpu) {
                            store_cached(cpu, &p);
                        }
                        (p, "cache")
                    }),
                }
            }
            _ => None,
        };
        Ok(found.and_then(|found| {
            let _ = self.profile_slot().set(found);
            self.profile_slot().get().map(|(p, _)| p)
        }))
    }

    /// The profile measured now on these views (none being known: [`Self::stored_profile`]),
    /// written where the source keeps it.
    async fn measure_profile(&self, exact: &ExactEngine, requests: &[ViewRequest], loads: &[ViewLoad]) -> Result<&Profile> {
        let profile = self.calibrate(exact, requests, loads, &self.scene_key()).await?;
        match &self.source() {
            ProfileSource::File(path) => write_profile(path, &profile)?,
            ProfileSource::Cache => store_cached(&profile.device, &profile),
            ProfileSource::Probe => {}
        }
        let _ = self.profile_slot().set((profile, "probe"));
        self.profile_slot().get().map(|(p, _)| p).ok_or_else(|| Error::argument("engine", "profile went missing"))
    }

    /// Measures both engines on a spread of these views (the GPU only if the exact engine alone
    /// would take longer than a GPU's start-up).
    /// `scene` names the scene's size, for the profile's key.
    async fn calibrate(&self, exact: &ExactEngine, requests: &[ViewRequest], loads: &[ViewLoad], scene: &str) -> Result<Profile> {
        let start = now();
        let probe = probe_views(loads, PROBE_EXACT_VIEWS);
        let (exact_cost, mean_us) = probe_exact(exact, requests, loads, &probe, cpu_threads());
        let mut profile = Profile {
            device: String::new(),
            exact: exact_cost,
            gpu: None,
            gpu_startup_seconds: None,
            compute: None,
            compute_startup_seconds: None,
        };
        let mut made_now = 0.0;
        if gpu_worth_probing(mean_us, loads) {
            let before = self.stats().gpu_startup_seconds;
            let lanes: Vec<Lane<'_>> = self.gpu_lanes().await?.iter().map(|(counter, gpu)| Lane { counter, gpu }).collect();
            made_now = self.stats().gpu_startup_seconds - before;
            // Lanes this run made earlier (for the other kind of views) cost their start-up all
            // the same to a later run that finds this profile: it is the run's, not 0.
            profile.gpu_startup_seconds = Some(if made_now > 0.0 { made_now } else { before });
            profile.gpu = Some(probe_gpu(&lanes, requests, loads).await?);
            // The compute kernel on devices of its own, probed on the same views.
            let before = self.stats().gpu_startup_seconds;
            let lanes: Vec<Lane<'_>> = self.lanes_of(Kernel::Compute).await?.iter().map(|(counter, gpu)| Lane { counter, gpu }).collect();
            let compute_made = self.stats().gpu_startup_seconds - before;
            made_now += compute_made;
            profile.compute_startup_seconds = Some(compute_made);
            profile.compute = Some(probe_gpu(&lanes, requests, loads).await?);
        }
        let device = match (&profile.gpu, cpu_key(&self.options, cpu_threads())) {
            (None, Some(cpu)) => cpu,
            _ => device_key(&self.options).await?,
        };
        profile.device = format!("{device}; {scene}");
        // The GPU's start-up is reported on its own (`gpu_startup_seconds`), not twice.
        let seconds = now() - start - made_now;
        self.add_stats(|s| s.calibration_seconds += seconds);
        Ok(profile)
    }
}

impl Engine for HybridEngine<'_> {
    fn index(&self) -> Option<&ExactEngine> {
        self.exact()
    }

    fn batch(&self) -> usize {
        // Enough views that both engines have work and the GPU whole atlases.
        self.lanes().and_then(|l| l.first()).map_or(1024, |(c, _)| (c.tiles_per_batch() * 16).max(1024))
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        self.count(requests).await
    }

    fn expect(&self, views: usize) {
        self.run_views.set(views);
    }

    fn views_of(&self, kind: ViewKind) {
        self.views.set(kind);
    }
}

/// Views of a batch whose loads are sampled to guess whether any goes to the GPU.
const GPU_SAMPLE_VIEWS: usize = 64;

/// Whether any of an even spread of [`GPU_SAMPLE_VIEWS`] of `requests` would go to the GPU on its
/// own load ([`Profile::route_one`]). A guess that only picks how the batch is walked.
fn sample_may_go_to_gpu(exact: &ExactEngine, profile: &Profile, requests: &[ViewRequest]) -> bool {
    let step = (requests.len() / GPU_SAMPLE_VIEWS).max(1);
    requests.iter().step_by(step).any(|&r| profile.route_one(exact.load(r)) != Route::Exact)
}

/// Indices of up to `n` views with something in their prism, spread evenly over their loads.
pub fn probe_views(loads: &[ViewLoad], n: usize) -> Vec<usize> {
    let mut loaded: Vec<usize> = (0..loads.len()).filter(|&i| loads[i].triangles > 0 && loads[i].see_through == 0).collect();
    loaded.sort_by_key(|&i| (loads[i].triangles, i));
    let stride = loaded.len().div_ceil(n.max(1)).max(1);
    loaded.into_iter().step_by(stride).collect()
}

/// `items` in an order that covers their range at ever finer steps: the first, the last, the
/// middle, the quarters, … (positions in bit-reversed order), each once.
fn coarse_to_fine<T: Copy>(items: &[T]) -> Vec<T> {
    let n = items.len();
    if n < 3 {
        return items.to_vec();
    }
    let bits = usize::BITS - (n - 1).leading_zeros();
    let mut order: Vec<usize> = vec![0, n - 1];
    order.extend((1..1usize << bits).map(|k| k.reverse_bits() >> (usize::BITS - bits)).filter(|&p| p > 0 && p < n - 1));
    order.into_iter().map(|p| items[p]).collect()
}

/// Times the exact engine view by view on one thread and fits its cost line; also the mean µs
/// of a probed view (both per thread: a view costs the machine its time over the `threads` that
/// clip: natively the cores, on the web the pool's workers).
pub fn probe_exact(exact: &ExactEngine, requests: &[ViewRequest], loads: &[ViewLoad], probe: &[usize], threads: usize) -> (Cost, f64) {
    let mut scratch = exact.scratch();
    let leaves_of = |i: usize| requests[i].leaves;
    // Warm caches and the scratch memory first, on the lightest views.
    for &i in probe.iter().take(4) {
        exact.fraction(requests[i], leaves_of(i), true, &mut scratch);
    }
    let started = now();
    let mut samples = Vec::new();
    // Coarse to fine over the sorted loads, so that a probe the time limit cuts short still
    // spans the light and the heavy views (in load order it timed only the light ones, and on a
    // dense model priced its heavy views at a tenth of what they cost).
    for i in coarse_to_fine(probe) {
        // The fastest of a few runs: a light view takes tens of µs, and one preemption by
        // another process would otherwise count as milliseconds of clipping.
        let mut best = f64::INFINITY;
        // Where the clock is coarse a timing is already a mean over many runs: one suffices.
        let repeats = if CLOCK_FLOOR_S > 0.0 { 1 } else { PROBE_EXACT_REPEATS };
        for _ in 0..repeats {
            best = best.min(time_view(|| exact.fraction(requests[i], leaves_of(i), true, &mut scratch)));
            if best > PROBE_REPEAT_BELOW {
                break;
            }
        }
        samples.push((loads[i].triangles as f64, 1e6 * best));
        if now() - started > PROBE_EXACT_SECONDS {
            break;
        }
    }
    // Work spreads over every thread: a view costs the machine its time over the threads.
    let threads = threads.max(1) as f64;
    let line = fit_line(&samples);
    let mean_us = samples.iter().map(|(_, us)| us).sum::<f64>() / samples.len().max(1) as f64;
    (Cost { per_view_us: line.per_view_us / threads, per_triangle_us: line.per_triangle_us / threads }, mean_us / threads)
}

/// Seconds one run of `view` takes: natively one run; where the clock is coarse (the web) the
/// mean of as many runs as fill [`CLOCK_FLOOR_S`], so a view shorter than a tick is not timed 0.
fn time_view<T>(mut view: impl FnMut() -> T) -> f64 {
    const MOST_RUNS: u32 = 10_000;
    let t0 = now();
    let mut runs = 0;
    loop {
        view();
        runs += 1;
        let elapsed = now() - t0;
        if elapsed >= CLOCK_FLOOR_S || runs == MOST_RUNS {
            return elapsed / f64::from(runs);
        }
    }
}

/// Times a light and a heavy batch of views on the GPU lanes and fits its cost line.
pub async fn probe_gpu(lanes: &[Lane<'_>], requests: &[ViewRequest], loads: &[ViewLoad]) -> Result<Cost> {
    let views = probe_views(loads, 6 * PROBE_GPU_VIEWS);
    let third = views.len() / 3;
    let batch = |part: &[usize]| -> (Vec<ViewRequest>, f64) {
        let reqs: Vec<ViewRequest> = part.iter().map(|&i| requests[i]).collect();
        let mean = part.iter().map(|&i| loads[i].triangles as f64).sum::<f64>() / part.len().max(1) as f64;
        (reqs, mean)
    };
    let light = &views[..third.min(PROBE_GPU_VIEWS)];
    let heavy = &views[views.len() - third.min(PROBE_GPU_VIEWS)..];
    // Warm-up (pipelines, first submission), not timed.
    let (warm, _) = batch(&views[..views.len().min(4)]);
    Lanes(lanes).answer(&warm).await?;
    let mut samples = Vec::new();
    for part in [light, heavy] {
        if part.is_empty() {
            continue;
        }
        let (reqs, mean) = batch(part);
        let t0 = now();
        Lanes(lanes).answer(&reqs).await?;
        samples.push((mean, 1e6 * (now() - t0) / part.len() as f64));
    }
    Ok(fit_line(&samples))
}

/// Least-squares line `per_view + per_triangle × x` through `(x, µs)` samples, both terms ≥ 0.
fn fit_line(samples: &[(f64, f64)]) -> Cost {
    let n = samples.len() as f64;
    if samples.is_empty() {
        return Cost { per_view_us: 0.0, per_triangle_us: 0.0 };
    }
    let (sx, sy) = samples.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = samples.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    let sxy: f64 = samples.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let slope = if sxx > 0.0 { (sxy / sxx).max(0.0) } else { 0.0 };
    let intercept = (my - slope * mx).max(0.0);
    // A negative intercept clamped to 0: refit the slope through the origin.
    let slope = if intercept == 0.0 && sxx > 0.0 {
        let s2: f64 = samples.iter().map(|(x, _)| x * x).sum();
        if s2 > 0.0 { samples.iter().map(|(x, y)| x * y).sum::<f64>() / s2 } else { slope }
    } else {
        slope
    };
    Cost { per_view_us: intercept, per_triangle_us: slope.max(0.0) }
}

/// Whether the exact engine's probe says a GPU could pay for itself on these views: the probe's
/// views are spread evenly over the sorted loads, so their mean time (`mean_us`, per thread) is
/// the loaded views' mean (a line through them extrapolates worse: most of a view's time is its
/// objects' shadows, not its triangles). Below a GPU's start-up for all of them, no GPU is
/// worth making or probing.
pub fn gpu_worth_probing(mean_us: f64, loads: &[ViewLoad]) -> bool {
    let loaded = loads.iter().filter(|l| l.triangles > 0).count() as f64;
    mean_us * loaded > 1e6 * ASSUMED_GPU_STARTUP
}

/// This machine's threads for clipping (1 where it cannot tell).
fn cpu_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

mod keys;
#[cfg(test)]
mod tests;
