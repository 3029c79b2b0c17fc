//! The JS API's `engine` option (`createEngine({ engine })`): which engine answers a page's views,
//! and the page's `auto`, routed by a measured profile as natively.
//!
//! Owns the split of a batch of views between the exact engine and the GPU lane on the web:
//! - the exact share goes to the JS pool of clipping workers (`www/pool.js`, each with its own
//!   wasm instance and scene) through one callback, started before the GPU's share is counted so
//!   both run at once; without a pool it is clipped here;
//! - `auto` routes by a [`Profile`] measured by the native calibration's own probes
//!   ([`probe_exact`], [`probe_gpu`]) on the model's own views, keyed like the native cache
//!   ([`adapter_threads_key`], [`cpu_key`]) with the pool's size as the clipping threads. A
//!   profile handed in (pinned by the caller, or the page's IndexedDB cache) is used when it
//!   parses and belongs to this model and device ([`profile_for`]); otherwise it is refused by
//!   name (see [`Chosen::refused`]) and measured anew. Sun and sky views ([`ViewKind`]) each
//!   have their own profile, handed in, kept and measured apart, the sky's keys ending in
//!   `; sky views` ([`views_key`]), as natively. Routing is [`Profile::route`]: a pure
//!   function of the loads, the profile and the run's size, so the same inputs with the same
//!   profile give the same answers byte for byte, whatever the pool's size.

use std::cell::{Cell, OnceCell, RefCell};

use js_sys::{Float64Array, Function, Promise, Reflect};
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::JsFuture;

use crate::count::exact::engine::{ExactEngine, ViewLoad};
use crate::count::gpu::CounterOptions;
use crate::count::hybrid::{
    EngineKind, PROBE_EXACT_VIEWS, Profile, Route, Split, adapter_threads_key, cpu_key, gpu_worth_probing, probe_exact, probe_gpu,
    probe_views, profile_for, views_key,
};
use crate::count::lanes::Lane;
use crate::count::{Engine, ViewAnswer, ViewKind, ViewRequest, check_receivers};
use crate::error::{Error, Result};
use crate::scene::Scene;

use super::lazy::Upload;

/// Numbers per packed request handed to the pool: receiver, sun x, y, z, leaf fraction.
pub(super) const PACKED: usize = 5;

/// How the caller routes: its pool of clipping workers and a profile to try first.
#[derive(Default)]
pub(super) struct Routing {
    /// `clip(Float64Array of packed requests) → Promise<Float64Array of fractions>`.
    pool: Option<Function>,
    /// Threads that clip: the pool's workers (1 without a pool).
    threads: usize,
    /// Per kind of views (sun, sky: [`kind_index`]), a profile's JSON text and where it came
    /// from (`pinned`, `cache`).
    given: [Option<(String, String)>; 2],
}

impl Routing {
    /// Reads `{ clip, workers, profile, profileSource, skyProfile, skyProfileSource }` (each
    /// optional) from the JS object: `profile` routes the sun views, `skyProfile` the sky views.
    pub(super) fn from_js(value: &JsValue) -> Result<Self> {
        if value.is_undefined() || value.is_null() {
            return Ok(Self { threads: 1, ..Default::default() });
        }
        let get = |key: &str| Reflect::get(value, &JsValue::from(key)).ok().filter(|v| !v.is_undefined() && !v.is_null());
        let pool = match get("clip") {
            Some(f) => Some(f.dyn_into::<Function>().map_err(|_| Error::argument("clip", "not a function"))?),
            None => None,
        };
        let threads = match get("workers").and_then(|w| w.as_f64()) {
            Some(w) if w >= 1.0 && w.fract() == 0.0 => w as usize,
            Some(w) => return Err(Error::argument("workers", format!("{w} is not a whole number of at least 1"))),
            None => 1,
        };
        let text = |p: JsValue| p.as_string().unwrap_or_else(|| js_sys::JSON::stringify(&p).ok().map(String::from).unwrap_or_default());
        let given = |profile: &str, source: &str| {
            let source = get(source).and_then(|s| s.as_string()).unwrap_or_else(|| "pinned".into());
            get(profile).map(|p| (text(p), source))
        };
        Ok(Self { pool, threads, given: [given("profile", "profileSource"), given("skyProfile", "skyProfileSource")] })
    }
}

/// Where a kind of views keeps its state here: sun views 0, sky views 1.
fn kind_index(views: ViewKind) -> usize {
    match views {
        ViewKind::Sun => 0,
        ViewKind::Sky => 1,
    }
}

/// What `auto` learns about one kind of views ([`ViewKind`]): sun and sky views cost the
/// engines differently, so each kind is routed by its own profile, as natively.
struct Routed {
    /// The profile's keys: with the adapter, and exact-only (when the side allows one); the
    /// sky's say `sky views` ([`views_key`]), so a sun profile is never taken for a sky one.
    keys: (String, Option<String>),
    profile: OnceCell<(Profile, &'static str)>,
    refused: RefCell<Option<String>>,
}

/// The chosen engine over one model for one call: its exact engine and its GPU lane (each made on
/// first use; no lane without WebGPU), the caller's routing, and what routing learnt per kind of
/// views.
pub(super) struct Chosen<'a> {
    kind: EngineKind,
    scene: &'a Scene,
    exact: &'a OnceCell<ExactEngine>,
    /// The way onto the GPU (none without WebGPU), and the lane once a view needed it.
    gpu: Option<Upload<'a>>,
    lane: OnceCell<Lane<'a>>,
    routing: &'a Routing,
    /// Per kind of views ([`kind_index`]).
    routed: [Routed; 2],
    /// The kind of views being asked for now ([`Engine::views_of`]).
    views: Cell<ViewKind>,
    /// Why the pool failed, as the pool said it (its `code`, the worker's index), for the caller.
    pool_error: RefCell<Option<JsValue>>,
    run_views: Cell<usize>,
}

impl<'a> Chosen<'a> {
    /// The engine `kind` over `scene`; `gpu` its way onto the GPU (None without WebGPU).
    pub(super) fn new(
        kind: EngineKind,
        scene: &'a Scene,
        exact: &'a OnceCell<ExactEngine>,
        gpu: Option<Upload<'a>>,
        options: &CounterOptions,
        routing: &'a Routing,
    ) -> Self {
        let adapter = gpu.as_ref().map(|g| g.gpu.info());
        let routed = |views| Routed {
            keys: profile_keys(scene, views, adapter, options, routing.threads),
            profile: OnceCell::new(),
            refused: RefCell::new(None),
        };
        Self {
            kind,
            scene,
            exact,
            gpu,
            lane: OnceCell::new(),
            routing,
            routed: [routed(ViewKind::Sun), routed(ViewKind::Sky)],
            views: Cell::new(ViewKind::Sun),
            pool_error: RefCell::new(None),
            run_views: Cell::new(0),
        }
    }

    /// What routing learnt about the kind of views being asked for now.
    fn now(&self) -> &Routed {
        &self.routed[kind_index(self.views.get())]
    }

    fn exact(&self) -> &ExactEngine {
        self.exact.get_or_init(|| ExactEngine::new(self.scene))
    }

    /// The GPU lane, its device opened and the scene uploaded on first use.
    async fn lane(&self) -> Result<&Lane<'a>> {
        let Some(upload) = &self.gpu else {
            return Err(Error::argument(
                "engine",
                "the GPU engine is missing: this browser offers no WebGPU ('exact' and 'auto' clip without it)",
            ));
        };
        if self.lane.get().is_none() {
            let lane = upload.lane().await?;
            let _ = self.lane.set(lane);
        }
        self.lane.get().ok_or_else(|| Error::argument("engine", "the GPU lane went missing"))
    }

    /// Whether `auto` clips every view whatever its load, so the loads need not be walked here
    /// (the pool walks them as it clips): a profile without a GPU cost, or no GPU, and nothing
    /// see-through in the scene. [`Profile::route`] would send every view to the exact engine.
    fn clips_everything(&self) -> bool {
        let exact_only = self.now().profile.get().is_some_and(|(p, _)| p.gpu.is_none() || self.gpu.is_none());
        exact_only && self.scene.see_through_triangles == 0
    }

    /// The profile `auto` routed `views` by, as JSON, and where it came from (`pinned`, `cache`,
    /// `probe`).
    pub(super) fn profile(&self, views: ViewKind) -> Option<(String, &'static str)> {
        let routed = &self.routed[kind_index(views)];
        routed.profile.get().and_then(|(p, source)| serde_json::to_string(p).ok().map(|t| (t, *source)))
    }

    /// Why a profile handed in for `views` was refused (it was then measured anew).
    pub(super) fn refused(&self, views: ViewKind) -> Option<String> {
        self.routed[kind_index(views)].refused.borrow().clone()
    }

    /// The pool's own error, when the pool failed: the caller gets it as the pool threw it.
    pub(super) fn take_pool_error(&self) -> Option<JsValue> {
        self.pool_error.borrow_mut().take()
    }

    /// The profile for these views (of the kind being asked for): the one handed in for that
    /// kind if it fits, else measured on them.
    async fn routing_profile(&self, requests: &[ViewRequest], loads: &[ViewLoad]) -> Result<&Profile> {
        let now = self.now();
        if let Some((p, _)) = now.profile.get() {
            return Ok(p);
        }
        let keys: Vec<&str> = [Some(now.keys.0.as_str()), now.keys.1.as_deref()].into_iter().flatten().collect();
        let given = self.routing.given[kind_index(self.views.get())].as_ref();
        let found = given.map(|(text, source)| (profile_for(text, &given_name(source, self.views.get()), &keys), source));
        let chosen = match found {
            Some((Ok(p), source)) => (p, if source == "cache" { "cache" } else { "pinned" }),
            Some((Err(e), _)) => {
                *now.refused.borrow_mut() = Some(e.to_string());
                (self.measure(requests, loads).await?, "probe")
            }
            None => (self.measure(requests, loads).await?, "probe"),
        };
        let _ = now.profile.set(chosen);
        now.profile.get().map(|(p, _)| p).ok_or_else(|| Error::argument("engine", "profile went missing"))
    }

    /// The native calibration on this page: the exact engine timed on one thread (a pool
    /// worker's speed) and spread over the pool's workers; the GPU only where it could pay, and
    /// never a CPU fallback adapter ([`cpu_adapter`]).
    /// The device is opened before the GPU is timed, so its start-up is not in the profile (0 s).
    async fn measure(&self, requests: &[ViewRequest], loads: &[ViewLoad]) -> Result<Profile> {
        let probe = probe_views(loads, PROBE_EXACT_VIEWS);
        let (exact, mean_us) = probe_exact(self.exact(), requests, loads, &probe, self.routing.threads);
        let gpu = if self.gpu.as_ref().is_some_and(|g| !cpu_adapter(g.gpu.info())) && gpu_worth_probing(mean_us, loads) {
            Some(probe_gpu(std::slice::from_ref(self.lane().await?), requests, loads).await?)
        } else {
            None
        };
        let keys = &self.now().keys;
        let device = match (&gpu, &keys.1) {
            (None, Some(cpu)) => cpu.clone(),
            _ => keys.0.clone(),
        };
        // The page probes its one lane's kernel (the raster kernel under `auto`).
        Ok(Profile { device, exact, gpu, gpu_startup_seconds: gpu.map(|_| 0.0), compute: None, compute_startup_seconds: None })
    }

    /// Starts the pool on `requests` (its promise runs while the GPU counts).
    fn start_pool(&self, pool: &Function, requests: &[ViewRequest]) -> Result<JsFuture> {
        let packed: Vec<f64> =
            requests.iter().flat_map(|r| [f64::from(r.receiver), r.sun.x, r.sun.y, r.sun.z, f64::from(r.leaves)]).collect();
        let promise = pool.call1(&JsValue::NULL, &Float64Array::from(packed.as_slice())).map_err(|e| self.pool_failed(e))?;
        let promise = promise.dyn_into::<Promise>().map_err(|_| Error::argument("clip", "did not return a promise"))?;
        Ok(JsFuture::from(promise))
    }

    async fn finish_pool(&self, pending: JsFuture, views: usize) -> Result<Vec<f64>> {
        let value = pending.await.map_err(|e| self.pool_failed(e))?;
        let fractions = Float64Array::new(&value).to_vec();
        if fractions.len() != views {
            return Err(Error::argument("clip", format!("answered {} views of {views}", fractions.len())));
        }
        Ok(fractions)
    }

    /// Keeps the pool's error for the caller; the library sees a cancellation (stop counting).
    fn pool_failed(&self, error: JsValue) -> Error {
        *self.pool_error.borrow_mut() = Some(error);
        Error::Cancelled
    }
}

/// Whether the page's adapter is the browser's fallback, drawing on the CPU (SwiftShader; wgpu
/// reports it as [`wgpu::DeviceType::Cpu`]). `auto` does not probe it: it would draw on the cores
/// the pool of clipping workers already fills, and probing uploads the scene, which on
/// nyt-blocks held 315 MB more in the GPU process besides the engine's staging
/// (docs/page-speed.md, "Where the memory goes"); every profile measured on it was exact-only.
fn cpu_adapter(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu
}

/// How a refusal names a profile handed in: the pinned one, or the page's stored one (where),
/// and for which views when they are the sky's.
fn given_name(source: &str, views: ViewKind) -> String {
    let name = match source {
        "cache" => "the profile stored in IndexedDB (database 'sunlit', store 'engine-profiles')".into(),
        other => format!("the {other} profile"),
    };
    match views {
        ViewKind::Sun => name,
        ViewKind::Sky => format!("{name} for sky views"),
    }
}

/// The keys a profile of this model's `views` may carry: measured with the adapter, and
/// exact-only.
fn profile_keys(
    scene: &Scene,
    views: ViewKind,
    adapter: Option<&wgpu::AdapterInfo>,
    options: &CounterOptions,
    threads: usize,
) -> (String, Option<String>) {
    let scene = views_key(scene, views);
    let with_adapter = format!("{}; {scene}", adapter_threads_key(adapter, options, threads));
    (with_adapter, cpu_key(options, threads).map(|k| format!("{k}; {scene}")))
}

/// The key under which the page keeps this model's profile for `views`: the adapter's (None:
/// no WebGPU).
pub(super) fn store_key(
    scene: &Scene,
    views: ViewKind,
    adapter: Option<&wgpu::AdapterInfo>,
    options: &CounterOptions,
    threads: usize,
) -> String {
    profile_keys(scene, views, adapter, options, threads).0
}

impl Engine for Chosen<'_> {
    /// The model's exact engine, built once a page thread and shared: the year's certificates
    /// use it (without it they built a second index of the model on the engine's thread, beside
    /// the one that encodes the convex objects for the workers; docs/page-speed.md).
    fn index(&self) -> Option<&ExactEngine> {
        Some(self.exact())
    }

    fn batch(&self) -> usize {
        // A GPU's atlas where views go to the GPU; else a batch every worker of a pool gets views
        // of. Each batch is a round trip to the pool, so `auto` clipping by the atlas's batch was
        // 0.5 s slower than `exact` on blaas-louvres' year (2.7 s against 2.1 s, bench-web).
        let gpu_routed = match self.kind {
            EngineKind::Gpu | EngineKind::Compute => true,
            EngineKind::Auto => self.now().profile.get().is_some_and(|(p, _)| p.gpu.is_some()),
            EngineKind::Exact => false,
        };
        match &self.gpu {
            Some(g) if gpu_routed => g.gpu.tiles_per_batch(),
            _ => 256,
        }
    }

    fn expect(&self, views: usize) {
        self.run_views.set(views);
    }

    fn views_of(&self, kind: ViewKind) {
        self.views.set(kind);
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        check_receivers(self.scene.receivers.len(), requests)?;
        let (routes, loads) = match self.kind {
            EngineKind::Gpu | EngineKind::Compute => return self.lane().await?.answer(requests).await,
            EngineKind::Exact => (vec![Route::Exact; requests.len()], None),
            EngineKind::Auto if self.clips_everything() => (vec![Route::Exact; requests.len()], None),
            EngineKind::Auto => {
                let loads = self.exact().loads(requests);
                let profile = self.routing_profile(requests, &loads).await?;
                let mut routes = profile.route(&loads, self.run_views.get());
                if self.gpu.is_none() {
                    // No WebGPU: see-through views are clipped as opaque, as `exact` does.
                    routes.iter_mut().for_each(|r| *r = Route::Exact);
                }
                (routes, Some(loads))
            }
        };
        let split = Split::new(requests, &routes, loads.as_deref());
        let pooled = match &self.routing.pool {
            Some(pool) if !split.exact_reqs.is_empty() => Some(self.start_pool(pool, &split.exact_reqs)?),
            _ => None,
        };
        let gpu = if split.gpu_reqs.is_empty() { Vec::new() } else { self.lane().await?.answer(&split.gpu_reqs).await? };
        let exact = match pooled {
            Some(pending) => self.finish_pool(pending, split.exact_reqs.len()).await?,
            None if split.exact_reqs.is_empty() => Vec::new(),
            None => split.exact_fractions(self.exact()),
        };
        Ok(split.merge(self.scene, requests, exact, gpu))
    }
}

/// Unpacks the pool's requests ([`PACKED`] numbers each), refusing a receiver the scene lacks.
pub(super) fn unpack(packed: &[f64], receivers: usize) -> Result<Vec<ViewRequest>> {
    if !packed.len().is_multiple_of(PACKED) {
        return Err(Error::argument("requests", format!("{} numbers is not a multiple of {PACKED}", packed.len())));
    }
    let requests: Vec<ViewRequest> = packed
        .chunks_exact(PACKED)
        .map(|p| ViewRequest::new(p[0] as u32, glam::DVec3::new(p[1], p[2], p[3])).with_leaves(p[4] as f32))
        .collect();
    check_receivers(receivers, &requests)?;
    Ok(requests)
}
