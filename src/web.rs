//! The browser's entry points (wasm-bindgen): the same pipeline as the CLI, driven from
//! JavaScript on the browser's WebGPU.
//!
//! Owns the translation between JS values and the library: model files or typed arrays in,
//! fractions and annual schedules out, the settings object into the library's resolver
//! ([`crate::year::settings`]), library errors into JS `Error`s with a stable `code` and the
//! option named as the JS API spells it, progress as a JS callback and cancellation by an
//! `AbortSignal`. Nothing here blocks: every GPU read is awaited (see `platform`), so the page
//! (or the worker running this) stays live and an abort is seen at the next progress report.
//! The hand-written ES module `www/sunlit.js` wraps these bindings for users; its types are in
//! `www/sunlit.d.ts`.

use std::rc::Rc;

mod choice;
mod clipper;
mod embed;
mod inside;
mod lazy;
mod map;
mod map_options;
mod study;
mod study_options;

use js_sys::{Array, Float32Array, Float64Array, Function, Int32Array, Promise, Uint8Array};
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::future_to_promise;

use crate::count::exact::engine::ExactEngine;
use crate::count::gpu::{CounterOptions, GpuScene, Kernel};
use crate::count::hybrid::EngineKind;
use crate::count::{Engine as _, ViewKind, ViewRequest};
use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::export::hook::{Hook, HookPlan, hook_for, patch_model};
use crate::model::arrays::{Arrays, scene_from_arrays};
use crate::model::calendar::{WeatherDays, check_model};
use crate::model::run_year::{choose, is_leap};
use crate::model::schedule::RunCalendar;
use crate::model::shading_update::periodic_update;
use crate::model::{EnergyPlusInput, LoadOptions, load_bytes_all, parse_transmittance};
use crate::scene::Scene;
use crate::sky::patches::SkyPatches;
use crate::sky::views::sky_views_for;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::sun::weather::Weather;
use crate::year::annual::{Progress, annual_fitted_with};
use crate::year::settings::AnnualSettings;
use crate::year::transmitting::VaryingShades;

/// A library error as a JS `Error` whose message names the file, object or option (as the JS API
/// spells it: `timestepsPerHour`) and the reason. Its properties: `code` ([`Error::code`], what
/// programs switch on, never the message), and where known `file`, `object`, `option` and, for
/// `code: 'gpu'`, `gpu` ([`crate::error::GpuError::code`], e.g. `out-of-memory`).
fn js_error(error: Error) -> JsValue {
    let js = js_sys::Error::new(&error.render(&js_option));
    let set = |key: &str, value: &str| {
        // Setting a property of a fresh Error cannot fail; were it to, the message still tells.
        let _ = js_sys::Reflect::set(&js, &key.into(), &value.into());
    };
    set("code", error.code());
    if let Some(file) = error.file() {
        set("file", &file);
    }
    if let Some(object) = error.object_name() {
        set("object", object);
    }
    if let Some(option) = error.parameter() {
        set("option", &js_option(option));
    }
    if let Error::Gpu(gpu) = &error {
        set("gpu", gpu.code());
    }
    js.into()
}

/// The JS API's name for a library parameter: camelCase (`timesteps_per_hour` →
/// `timestepsPerHour`), as the settings object and `loadFiles`' options spell them.
pub fn js_option(param: &str) -> String {
    let mut out = String::with_capacity(param.len());
    let mut upper = false;
    for c in param.chars() {
        match c {
            '_' => upper = true,
            c if upper => {
                out.extend(c.to_uppercase());
                upper = false;
            }
            c => out.push(c),
        }
    }
    out
}

/// Exact engines (indexes of a model) this wasm instance has built so far
/// ([`ExactEngine::indexes_built`]): the page's thread gives it as `engine.timings.indexesBuilt`,
/// so a test can tell that the engine's thread indexes a model once for all it does with it.
#[wasm_bindgen(js_name = exactIndexesBuilt)]
pub fn exact_indexes_built() -> usize {
    ExactEngine::indexes_built()
}

/// The page's WebGPU adapter, its device opened when a view is first routed to it ([`lazy`];
/// none where the browser has no WebGPU: then views are clipped only).
#[wasm_bindgen]
pub struct Engine {
    gpu: Option<Rc<lazy::Gpu>>,
    options: CounterOptions,
    /// Which engine answers views (`auto`, `gpu`, `exact`, `compute`; see [`choice`]).
    kind: EngineKind,
}

#[wasm_bindgen]
impl Engine {
    /// Finds the WebGPU adapter; its device is opened when a view is first routed to the GPU
    /// ([`lazy`]), not here. `resolution`: pixels along a view's side (default 512);
    /// `accuracy`: a target |error| per view, counting each at 64² first and finer, up to
    /// `resolution`, only where its shadow edges need it (default: every view at `resolution`);
    /// `engine`: `auto` (default), `gpu`, `exact` or `compute` ([`choice`]); `gpu: false` (no
    /// WebGPU in this browser) makes no device: views are clipped, and `gpu` and `compute` are
    /// refused. `exact` asks for no adapter (it never draws).
    pub async fn create(
        resolution: Option<u32>,
        accuracy: Option<f64>,
        engine: Option<String>,
        gpu: Option<bool>,
    ) -> Result<Engine, JsValue> {
        let kind = engine.as_deref().map_or(Ok(EngineKind::Auto), EngineKind::parse).map_err(js_error)?;
        // The page's GPU lane counts with the compute rasterizer when asked for it by name.
        let kernel = if kind == EngineKind::Compute { Kernel::Compute } else { Kernel::Raster };
        let options = CounterOptions {
            resolution: resolution.unwrap_or(CounterOptions::default().resolution),
            accuracy,
            kernel,
            ..Default::default()
        };
        // `exact` never draws, so it asks for no adapter: on a fresh browser that request held
        // `createEngine` back by up to 1.4 s (docs/page-speed.md, "The first visit").
        if gpu == Some(false) || kind == EngineKind::Exact {
            if kind.gpu_only() {
                return Err(js_error(Error::argument(
                    "engine",
                    format!("'{}' needs WebGPU, which this browser does not offer; 'exact' and 'auto' clip without it", kind.name()),
                )));
            }
            if let Some(a) = accuracy
                && !(a > 0.0 && a < 1.0)
            {
                return Err(js_error(Error::argument("accuracy", format!("{a} is not a fraction error in (0, 1)"))));
            }
            return Ok(Engine { gpu: None, options, kind });
        }
        let gpu = lazy::Gpu::request(options).await.map_err(js_error)?;
        Ok(Engine { gpu: Some(Rc::new(gpu)), options, kind })
    }

    /// Opens the GPU device now rather than when a view is first routed to it (nothing without
    /// WebGPU): `createEngine({ device })` does, so the caller's device is taken, and its error
    /// handler chained, while the caller's adapter stands in for the browser's.
    #[wasm_bindgen(js_name = openDevice)]
    pub fn open_device(&self) -> Promise {
        let gpu = self.gpu.clone();
        future_to_promise(async move {
            if let Some(gpu) = gpu {
                gpu.counter().await.map_err(js_error)?;
            }
            Ok(JsValue::UNDEFINED)
        })
    }

    /// The key under which this model's `auto` profile for sun views is kept (IndexedDB in the
    /// page), as the native cache keys it: adapter, driver, `workers` clipping threads, side,
    /// scene size.
    #[wasm_bindgen(js_name = profileKey)]
    pub fn profile_key(&self, model: &Model, workers: usize) -> String {
        self.key_of(model, ViewKind::Sun, workers)
    }

    /// The same for sky views (the key says `sky views`): they are routed by their own profile.
    #[wasm_bindgen(js_name = skyProfileKey)]
    pub fn sky_profile_key(&self, model: &Model, workers: usize) -> String {
        self.key_of(model, ViewKind::Sky, workers)
    }

    fn key_of(&self, model: &Model, views: ViewKind, workers: usize) -> String {
        choice::store_key(&model.inner.scene, views, self.gpu.as_ref().map(|g| g.info()), &self.options, workers.max(1))
    }

    /// Which engine answers views: `auto`, `gpu`, `exact` or `compute`.
    #[wasm_bindgen(getter)]
    pub fn engine(&self) -> String {
        self.kind.name().into()
    }

    /// The adapter's name and backend, for the page's status line.
    #[wasm_bindgen(getter)]
    pub fn adapter(&self) -> String {
        let Some(gpu) = &self.gpu else {
            if self.kind == EngineKind::Exact {
                return "none (engine 'exact' clips every view, without a GPU)".into();
            }
            return "none (no WebGPU: views are clipped only)".into();
        };
        // Browsers hide the adapter's name unless asked; say what is known.
        let info = gpu.info();
        if info.name.is_empty() { "the browser's WebGPU".into() } else { format!("{} ({:?})", info.name, info.backend) }
    }

    /// Pixels along a view's side.
    #[wasm_bindgen(getter)]
    pub fn resolution(&self) -> u32 {
        self.options.resolution
    }

    /// Whether the engine holds a WebGPU adapter: false where the browser has no WebGPU, and with
    /// engine `exact`, which never draws and asks for none; its device is opened when a view is
    /// first routed to it.
    #[wasm_bindgen(getter, js_name = hasGpu)]
    pub fn has_gpu(&self) -> bool {
        self.gpu.is_some()
    }

    /// Reads model files (glb/gltf with embedded buffers, IDF, epJSON); the scene is uploaded when
    /// a view is first routed to the GPU.
    /// `names[i]` labels `contents[i]` in messages and picks its reader by extension.
    #[wasm_bindgen(js_name = loadFiles)]
    /// `receivers` and `foliage` are comma-separated globs over node names; `transmittance` a
    /// comma-separated list of `GLOB=T`.
    #[allow(clippy::too_many_arguments)]
    pub fn load_files(
        &self,
        names: Vec<String>,
        contents: Array,
        receivers: Option<String>,
        north: Option<f64>,
        foliage: Option<String>,
        transmittance: Option<String>,
    ) -> Result<Model, JsValue> {
        let kept = (names.clone(), contents.clone());
        let (loaded, variants, reload, options) =
            load_files(names, contents, receivers, north, foliage, transmittance).map_err(js_error)?;
        let model = self.model(loaded.scene, loaded.energyplus, loaded.notes)?;
        let mut inner = Rc::try_unwrap(model.inner).map_err(|_| js_error(Error::argument("model", "shared while loading")))?;
        inner.variants.extend(variants.into_iter().map(Variant::new));
        inner.reload = reload;
        // A mesh model's rooms are read again from its files when an inside map marks them
        // (`interior`, `glazing`); an EnergyPlus model's zones need no files.
        if inner.energyplus.is_none() {
            inner.source = Some(inside::Source { names: kept.0, contents: kept.1, options });
        }
        Ok(Model { inner: Rc::new(inner) })
    }

    /// Builds a scene from typed arrays (see `model::arrays`).
    #[wasm_bindgen(js_name = fromArrays)]
    pub fn from_arrays(
        &self,
        positions: &[f32],
        indices: &[u32],
        triangle_receivers: &[i32],
        names: Vec<String>,
        y_up: bool,
    ) -> Result<Model, JsValue> {
        let arrays = Arrays { positions, indices, triangle_receivers, names: &names, y_up };
        self.model(scene_from_arrays(&arrays).map_err(js_error)?, None, Vec::new())
    }

    fn model(&self, scene: Scene, energyplus: Option<EnergyPlusInput>, notes: Vec<String>) -> Result<Model, JsValue> {
        let gpu = Default::default();
        let inner = ModelInner {
            scene,
            gpu,
            energyplus,
            notes,
            exact: Default::default(),
            maps: Default::default(),
            inside: Default::default(),
            source: None,
            variants: Vec::new(),
            reload: None,
        };
        Ok(Model { inner: Rc::new(inner) })
    }

    /// Promise of every receiver's sunlit fraction (Float64Array, receiver order) for one sun
    /// direction: a unit vector towards the sun, x east, y north, z up. `routing`: the pool and
    /// profile ([`choice::Routing`]).
    pub fn fractions(&self, model: &Model, sun_x: f64, sun_y: f64, sun_z: f64, routing: JsValue) -> Promise {
        let (gpu, model, kind, options) = (self.gpu.clone(), model.inner.clone(), self.kind, self.options);
        future_to_promise(async move {
            let routing = choice::Routing::from_js(&routing).map_err(js_error)?;
            let sun = glam::DVec3::new(sun_x, sun_y, sun_z);
            if !sun.is_finite() || sun.length() < 1e-9 {
                return Err(js_error(Error::argument("sun", format!("({sun_x}, {sun_y}, {sun_z}) is not a direction"))));
            }
            let sun = sun.normalize();
            let requests: Vec<ViewRequest> =
                (0..model.scene.receivers.len() as u32).map(|receiver| ViewRequest::new(receiver, sun)).collect();
            let chosen = model.chosen(kind, gpu.as_deref(), &options, &routing);
            let answers = chosen.answer(&requests).await.map_err(|e| chosen.take_pool_error().unwrap_or_else(|| js_error(e)))?;
            let fractions: Vec<f64> = answers.iter().map(|a| a.fraction).collect();
            Ok(Float64Array::from(fractions.as_slice()).into())
        })
    }

    /// Promise of the year's schedule ([`Annual`]). `settings` is a plain object (see
    /// [`AnnualSettings`]); `progress(done, total, counted)` is called as views are decided (counted, or
    /// settled without counting: see [`Progress`]), stage by stage (the year, then its sky views); an aborted
    /// `signal` rejects the promise with an `Error` whose `code` is `cancelled`. `routing`: the
    /// pool of clipping workers and a profile to try ([`choice::Routing`]); a failing pool's
    /// error comes back as the pool threw it.
    pub fn annual(
        &self,
        model: &Model,
        settings: JsValue,
        progress: Option<Function>,
        signal: Option<web_sys::AbortSignal>,
        routing: JsValue,
    ) -> Promise {
        let (gpu, model, kind, counter_options) = (self.gpu.clone(), model.inner.clone(), self.kind, self.options);
        future_to_promise(async move {
            let routing = choice::Routing::from_js(&routing).map_err(js_error)?;
            let given = settings_from_js(&settings).map_err(js_error)?;
            let settings = given.resolve().map_err(js_error)?;
            let energyplus = model.energyplus.as_ref();
            let periods = energyplus.and_then(|ep| periodic_update(&ep.objects));
            let mut options = settings.model_options(energyplus.and_then(EnergyPlusInput::timesteps), periods).map_err(js_error)?;
            options.timesteps = options.timesteps.leap_year(is_leap_run(&given, model.energyplus.as_ref()));
            let (location, calendar) = (settings.location, settings.calendar);
            // The weather file's holidays and daylight saving period, as the CLI reads them; the
            // run's calendar checked as EnergyPlus places it at a run's start.
            let epw_name = given.epw_name.as_deref().unwrap_or("EPW");
            let days = given.epw.as_deref().map(|text| WeatherDays::from_epw_text(epw_name, text)).transpose().map_err(js_error)?;
            if let Some(ep) = &model.energyplus {
                check_model(&ep.file, &ep.objects, options.timesteps.is_leap(), days.as_ref()).map_err(js_error)?;
            }
            // A model that cannot be hooked (e.g. a Version before 9.3) still has its year
            // counted: the refusal is kept for `hookedModel`, the only call that needs the hook.
            let hook = model.energyplus.as_ref().map(|ep| hook_for(ep, &model.scene, None, options.timesteps).map_err(js_error));
            let mut report = |p: Progress| {
                if signal.as_ref().is_some_and(|s| s.aborted()) {
                    return Err(Error::Cancelled);
                }
                if let Some(f) = &progress {
                    // A throwing progress callback is the caller's bug, not a reason to stop.
                    let (done, total, counted) = (p.done as f64, p.total as f64, p.counted() as f64);
                    let _ = f.call3(&JsValue::NULL, &JsValue::from(done), &JsValue::from(total), &JsValue::from(counted));
                }
                Ok(())
            };
            let chosen = model.chosen(kind, gpu.as_deref(), &counter_options, &routing);
            let local = choice::Routing::from_js(&JsValue::UNDEFINED).map_err(js_error)?;
            // Shades mixed by τ: the one-scene passes (the sky views) see each at its mean τ over
            // this run, read with the run's calendar as the CLI reads it.
            let mut sky_transmittance = None;
            let (schedule, fitted) = match (&model.energyplus, model.variants.is_empty()) {
                (Some(ep), false) => {
                    // Shades whose τ changes in time: a year per variant (each such shade opaque
                    // or removed), mixed per timestep; the variants' scenes are not the pool's, so
                    // their exact share is clipped here.
                    let varying = VaryingShades::for_run(&ep.file, &ep.shades, options.timesteps, days.as_ref()).map_err(js_error)?;
                    sky_transmittance = varying.as_ref().map(VaryingShades::mean_transmittance);
                    let mut years = Vec::new();
                    for v in &model.variants {
                        let upload = upload(kind, gpu.as_deref(), &v.scene, &v.gpu);
                        let engine = choice::Chosen::new(kind, &v.scene, &v.exact, upload, &counter_options, &local);
                        years.push(
                            annual_fitted_with(&engine, &v.scene, &location, &options, &calendar, &mut report).await.map_err(js_error)?.0,
                        );
                    }
                    let mixed = match varying {
                        Some(varying) => varying.mix(&years).map_err(js_error)?,
                        None => return Err(js_error(Error::argument("model", "its shades' schedules do not change in time"))),
                    };
                    (mixed, None)
                }
                _ => annual_fitted_with(&chosen, &model.scene, &location, &options, &calendar, &mut report)
                    .await
                    .map_err(|e| chosen.take_pool_error().unwrap_or_else(|| js_error(e)))?,
            };
            let routed = |views| Routed { profile: chosen.profile(views), refused: chosen.refused(views) };
            let means = daylight_means(&schedule, &location);
            let weather = given.epw.as_deref().map(|text| Weather::from_epw_text(given.epw_name.as_deref().unwrap_or("EPW"), text));
            // The sky views (the same engine, Tregenza's patches, the sky model asked) only when there is weather to weigh them.
            let sky = match &weather {
                Some(Ok(_)) => {
                    let run_scene = match (&sky_transmittance, &model.reload) {
                        (Some(t), Some(reload)) => Some(Variant::new(reload.scene_with(t.clone()).map_err(js_error)?)),
                        _ => None,
                    };
                    let patches = SkyPatches::tregenza();
                    Some(match &run_scene {
                        Some(v) => {
                            let upload = upload(kind, gpu.as_deref(), &v.scene, &v.gpu);
                            let engine = choice::Chosen::new(kind, &v.scene, &v.exact, upload, &counter_options, &local);
                            sky_views_for(&engine, &v.scene, &patches, settings.sky_model, &mut report)
                                .await
                                .map_err(|e| engine.take_pool_error().unwrap_or_else(|| js_error(e)))?
                        }
                        None => sky_views_for(&chosen, &model.scene, &patches, settings.sky_model, &mut report)
                            .await
                            .map_err(|e| chosen.take_pool_error().unwrap_or_else(|| js_error(e)))?,
                    })
                }
                _ => None,
            };
            let extra = embed::Extra::new(&model.scene, &schedule, &location, weather, sky.as_ref().map(|s| (s, &calendar)), fitted);
            let routed = [routed(ViewKind::Sun), routed(ViewKind::Sky)];
            Ok(Annual { schedule, means, hook, model, extra, routed }.into())
        })
    }
}

/// Reads model files (see [`Engine::load_files`]) into a scene, on any thread of the page.
fn load_files(
    names: Vec<String>,
    contents: Array,
    receivers: Option<String>,
    north: Option<f64>,
    foliage: Option<String>,
    transmittance: Option<String>,
) -> Result<(crate::model::Loaded, Vec<Scene>, Option<Reload>, LoadOptions)> {
    if names.len() != contents.length() as usize {
        return Err(Error::argument("files", format!("{} names for {} contents", names.len(), contents.length())));
    }
    let files: Vec<(String, Vec<u8>)> =
        names.into_iter().zip(contents.iter()).map(|(name, bytes)| (name, Uint8Array::new(&bytes).to_vec())).collect();
    let transmittance = list(transmittance.as_deref()).iter().map(|t| parse_transmittance(t)).collect::<Result<Vec<_>>>()?;
    let options = LoadOptions {
        receivers: list(receivers.as_deref()),
        north: north.unwrap_or(0.0),
        foliage: list(foliage.as_deref()),
        transmittance,
        ..Default::default()
    };
    let mut loaded = load_bytes_all(&files, &options)?;
    let Some(ep) = &loaded.energyplus else { return Ok((loaded, Vec::new(), None, options)) };
    // Which shades vary does not depend on the run's calendar. The scene shown has each at its
    // mean τ over hourly values without the weather file's holidays (not known yet); a year's
    // one-scene passes reload it with the run's ([`Reload`]).
    let hourly = RunCalendar { per_hour: 1, leap: false, weather: None };
    let Some(varying) = VaryingShades::new(&ep.file, &ep.shades, hourly)? else { return Ok((loaded, Vec::new(), None, options)) };
    let reload = Reload { files, options: options.clone() };
    loaded.scene = reload.scene_with(varying.mean_transmittance())?;
    let variants = (0..varying.variants()).map(|v| reload.scene_with(varying.shade_transmittance(v))).collect::<Result<Vec<_>>>()?;
    Ok((loaded, variants, Some(reload), options))
}

/// A model's files and load options, kept when its shades are mixed by τ: a year's one-scene
/// passes take the shades' mean τ over that run's calendar (its timesteps, leap day, the weather
/// file's holidays and daylight saving), known only when the year is asked for.
struct Reload {
    files: Vec<(String, Vec<u8>)>,
    options: LoadOptions,
}

impl Reload {
    /// The scene with the shades named at the τ given.
    fn scene_with(&self, shade_transmittance: Vec<(String, f64)>) -> Result<Scene> {
        Ok(load_bytes_all(&self.files, &LoadOptions { shade_transmittance, ..self.options.clone() })?.scene)
    }
}

/// A comma-separated setting (globs, `GLOB=T` items); empty when not given.
fn list(text: Option<&str>) -> Vec<String> {
    text.unwrap_or("").split(',').map(str::trim).filter(|p| !p.is_empty()).map(String::from).collect()
}

/// A scene on the engine's device. Only valid with the engine that made it.
#[wasm_bindgen]
pub struct Model {
    inner: Rc<ModelInner>,
}

struct ModelInner {
    scene: Scene,
    /// The scene on the GPU, uploaded when a view is first routed to it (never without WebGPU).
    gpu: std::cell::OnceCell<GpuScene>,
    energyplus: Option<EnergyPlusInput>,
    /// What loading chose that the user should hear (e.g. many default receivers).
    notes: Vec<String>,
    /// The exact engine over `scene`, made when a view is first routed to it.
    exact: std::cell::OnceCell<ExactEngine>,
    /// The last points `engine.map` was asked for, indexed for shadow rays ([`map`]).
    maps: std::cell::RefCell<Option<map::MapCache>>,
    /// The inside scene of the last inside map, for the rooms, glass and points it was made for
    /// ([`inside`]).
    inside: std::cell::RefCell<Option<(inside::InsideKey, Rc<inside::InsideScene>)>>,
    /// A mesh model's files and load options, from which an inside map reads its rooms ([`inside`]).
    source: Option<inside::Source>,
    /// With EnergyPlus shades whose transmittance changes in time: the scene with each such
    /// shade opaque or removed, in [`VaryingShades`]'s order (empty otherwise).
    variants: Vec<Variant>,
    /// With such shades: the files to load the scene again at a run's mean τ.
    reload: Option<Reload>,
}

/// One of [`ModelInner::variants`]: a scene, its upload and its exact engine.
struct Variant {
    scene: Scene,
    gpu: std::cell::OnceCell<GpuScene>,
    exact: std::cell::OnceCell<ExactEngine>,
}

impl Variant {
    fn new(scene: Scene) -> Self {
        Self { scene, gpu: Default::default(), exact: Default::default() }
    }
}

impl ModelInner {
    /// The engine `kind` over this model, on the page's GPU (if any), routed by `routing`.
    fn chosen<'a>(
        &'a self,
        kind: EngineKind,
        gpu: Option<&'a lazy::Gpu>,
        options: &CounterOptions,
        routing: &'a choice::Routing,
    ) -> choice::Chosen<'a> {
        choice::Chosen::new(kind, &self.scene, &self.exact, upload(kind, gpu, &self.scene, &self.gpu), options, routing)
    }
}

/// `scene`'s way onto the page's GPU, if any. `exact` never draws: no upload, which for a large
/// model is as much wasm memory again as its scene (nyt-blocks: 1,103 MB with the upload, 620 MB
/// without; docs/page-speed.md).
fn upload<'a>(
    kind: EngineKind,
    gpu: Option<&'a lazy::Gpu>,
    scene: &'a Scene,
    uploaded: &'a std::cell::OnceCell<GpuScene>,
) -> Option<lazy::Upload<'a>> {
    gpu.filter(|_| kind != EngineKind::Exact).map(|gpu| lazy::Upload { gpu, scene, uploaded })
}

#[wasm_bindgen]
impl Model {
    /// What loading chose that the user should hear, e.g. that the default rule (every named
    /// node) chose many receivers, and how to narrow it. Empty when there is nothing to say.
    #[wasm_bindgen(getter)]
    pub fn notes(&self) -> Vec<String> {
        self.inner.notes.clone()
    }

    /// The scene, encoded ([`Scene::to_bytes`]) for the pool's clipping workers
    /// (`Clipper.fromScene`): they build their copies from it without reading the model files.
    #[wasm_bindgen(js_name = sceneBytes)]
    pub fn scene_bytes(&self) -> Vec<u8> {
        self.inner.scene.to_bytes()
    }

    /// The exact engine's convex objects, encoded ([`ExactEngine::objects_bytes`]) for the pool's
    /// clipping workers beside [`Self::scene_bytes`]: a worker takes them instead of grouping the
    /// scene's triangles, the step that set its peak memory (docs/page-speed.md). Builds this
    /// model's exact engine if it has none yet (`auto` builds it for its first batch anyway), so
    /// call it after `sceneBytes`: the scene's encoding is then already out of this instance.
    #[wasm_bindgen(js_name = objectsBytes)]
    pub fn objects_bytes(&self) -> Vec<u8> {
        self.inner.exact.get_or_init(|| ExactEngine::new(&self.inner.scene)).objects_bytes()
    }

    /// The exact fractions of packed requests (as the pool's workers take them: receiver, sun x,
    /// y, z, leaf fraction), clipped in this thread with this model's exact engine: where the
    /// memory budget kept fewer workers than asked, the engine's thread clips beside them.
    #[wasm_bindgen(js_name = clipHere)]
    pub fn clip_here(&self, packed: &[f64]) -> Result<Float64Array, JsValue> {
        let exact = self.inner.exact.get_or_init(|| ExactEngine::new(&self.inner.scene));
        clipper::clip(exact, self.inner.scene.receivers.len(), packed)
    }

    /// Receiver names: the CSV's columns, in order.
    #[wasm_bindgen(getter, js_name = receiverNames)]
    pub fn receiver_names(&self) -> Vec<String> {
        self.inner.scene.receivers.iter().map(|r| r.name.clone()).collect()
    }

    /// Receiver areas, m².
    #[wasm_bindgen(getter, js_name = receiverAreas)]
    pub fn receiver_areas(&self) -> Float64Array {
        let areas: Vec<f64> = self.inner.scene.receivers.iter().map(|r| r.area).collect();
        Float64Array::from(areas.as_slice())
    }

    /// Triangle count of everything drawn.
    #[wasm_bindgen(getter)]
    pub fn triangles(&self) -> usize {
        self.inner.scene.triangle_count()
    }

    /// Leaves of the foliage (connected groups of triangles), 0 without foliage.
    #[wasm_bindgen(getter)]
    pub fn leaves(&self) -> usize {
        self.inner.scene.leaves
    }

    /// Triangles that let part of the beam through (transmittance below 1).
    #[wasm_bindgen(getter, js_name = seeThroughTriangles)]
    pub fn see_through_triangles(&self) -> usize {
        self.inner.scene.see_through_triangles
    }

    /// Whether an EnergyPlus model was among the files (then [`Annual::hooked_model`] works).
    #[wasm_bindgen(getter, js_name = hasEnergyPlus)]
    pub fn has_energyplus(&self) -> bool {
        self.inner.energyplus.is_some()
    }

    /// The EnergyPlus model's Timestep (rows per hour), if one was loaded: the CSV must match it.
    #[wasm_bindgen(getter, js_name = modelTimesteps)]
    pub fn model_timesteps(&self) -> Option<u32> {
        self.inner.energyplus.as_ref().and_then(EnergyPlusInput::timesteps)
    }

    /// The EnergyPlus model's own Site:Location as `[latitude, longitude, time zone]`, if it has
    /// one: the page uses it unless an EPW or other coordinates are given.
    #[wasm_bindgen(getter, js_name = siteLocation)]
    pub fn site_location(&self) -> Result<Option<Vec<f64>>, JsValue> {
        let Some(ep) = self.inner.energyplus.as_ref() else { return Ok(None) };
        let site = crate::model::site::site_location(&ep.file, &ep.objects).map_err(js_error)?;
        Ok(site.map(|l| vec![l.latitude, l.longitude, l.time_zone]))
    }

    /// Every triangle in world coordinates (x east, y north, z up; 9 floats each), for drawing.
    #[wasm_bindgen(js_name = worldPositions)]
    pub fn world_positions(&self) -> Float32Array {
        let mut out = Vec::with_capacity(self.inner.scene.triangle_count() * 9);
        for (t, _) in self.inner.scene.world_triangles() {
            out.extend(t.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]));
        }
        Float32Array::from(out.as_slice())
    }

    /// Per triangle of [`Self::world_positions`]: its receiver index, or −1 for shading geometry.
    #[wasm_bindgen(js_name = worldReceivers)]
    pub fn world_receivers(&self) -> Int32Array {
        let ids: Vec<i32> = self.inner.scene.world_triangles().map(|(_, r)| r.map_or(-1, |r| r as i32)).collect();
        Int32Array::from(ids.as_slice())
    }
}

/// The JS settings object as the library's [`AnnualSettings`] (its camelCase keys are the JS
/// API's), refused with a message when it is missing or not a plain object.
fn settings_from_js(value: &JsValue) -> Result<AnnualSettings> {
    if value.is_undefined() || value.is_null() {
        return Err(Error::argument("settings", "give at least a location (latitude, longitude, timeZone) or an EPW"));
    }
    let text = js_sys::JSON::stringify(value).map_err(|_| Error::argument("settings", "not a plain object"))?;
    serde_json::from_str(&String::from(text)).map_err(|e| Error::argument("settings", e.to_string()))
}

/// Whether the year is a leap year, as the CLI chooses it: the `year` setting, else the
/// EnergyPlus model's RunPeriod, else the EPW's Feb 29 record.
fn is_leap_run(given: &AnnualSettings, energyplus: Option<&EnergyPlusInput>) -> bool {
    let objects = energyplus.map(|ep| ep.objects.as_slice());
    choose(given.year, objects, given.epw.as_deref()).is_some_and(|(year, _)| is_leap(year))
}

/// Each column's mean over the year's sun-up timesteps: the page's colour per surface.
fn daylight_means(schedule: &Schedule, location: &Location) -> Vec<f64> {
    let columns = schedule.names.len();
    let mut sums = vec![0.0; columns];
    let mut rows = 0usize;
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        if sun_direction(location, f64::from(instant.day), instant.hour).z <= 0.0 {
            continue;
        }
        rows += 1;
        for (c, sum) in sums.iter_mut().enumerate() {
            *sum += f64::from(schedule.get(row, c));
        }
    }
    sums.into_iter().map(|s| if rows == 0 { 0.0 } else { s / rows as f64 }).collect()
}

/// A year's sunlit fractions for every receiver.
#[wasm_bindgen]
pub struct Annual {
    schedule: Schedule,
    means: Vec<f64>,
    /// The hook form, or why this model cannot be hooked (None: no EnergyPlus model).
    hook: Option<Result<Hook, JsValue>>,
    model: Rc<ModelInner>,
    extra: embed::Extra,
    /// Sun views', then sky views' (none without weather).
    routed: [Routed; 2],
}

/// How `auto` routed a year: the profile (JSON) and its source, and a profile refused.
struct Routed {
    profile: Option<(String, &'static str)>,
    refused: Option<String>,
}

#[wasm_bindgen]
impl Annual {
    /// Column names.
    #[wasm_bindgen(getter)]
    pub fn names(&self) -> Vec<String> {
        self.schedule.names.clone()
    }

    /// Timesteps per hour.
    #[wasm_bindgen(getter, js_name = timestepsPerHour)]
    pub fn timesteps_per_hour(&self) -> u32 {
        self.schedule.timesteps.per_hour()
    }

    /// Rows: 8760 × timesteps per hour.
    #[wasm_bindgen(getter)]
    pub fn rows(&self) -> usize {
        self.schedule.timesteps.rows()
    }

    /// One receiver's fraction at every timestep.
    pub fn column(&self, index: usize) -> Result<Float32Array, JsValue> {
        let columns = self.schedule.names.len();
        if index >= columns {
            return Err(js_error(Error::argument("column", format!("{index} is not below {columns}"))));
        }
        let values: Vec<f32> = self.schedule.values.iter().skip(index).step_by(columns).copied().collect();
        Ok(Float32Array::from(values.as_slice()))
    }

    /// Each receiver's mean fraction over sun-up timesteps.
    #[wasm_bindgen(getter)]
    pub fn means(&self) -> Float64Array {
        Float64Array::from(self.means.as_slice())
    }

    /// The profile `auto` routed the sun views by (JSON, as `createEngine({ profile })` takes
    /// it); `undefined` for `gpu` and `exact`.
    #[wasm_bindgen(getter)]
    pub fn profile(&self) -> Option<String> {
        self.routed[0].profile.as_ref().map(|(p, _)| p.clone())
    }

    /// Where that profile came from: `pinned`, `cache` or `probe` (measured in this run).
    #[wasm_bindgen(getter, js_name = profileSource)]
    pub fn profile_source(&self) -> Option<String> {
        self.routed[0].profile.as_ref().map(|(_, s)| (*s).to_string())
    }

    /// Why a profile handed in was refused (it was measured anew), naming it and the reason.
    #[wasm_bindgen(getter, js_name = profileRefused)]
    pub fn profile_refused(&self) -> Option<String> {
        self.routed[0].refused.clone()
    }

    /// The profile `auto` routed the sky views by (as `createEngine({ skyProfile })` takes it):
    /// measured on sky views, as natively; `undefined` without weather (no sky views) and for
    /// `gpu` and `exact`.
    #[wasm_bindgen(getter, js_name = skyProfile)]
    pub fn sky_profile(&self) -> Option<String> {
        self.routed[1].profile.as_ref().map(|(p, _)| p.clone())
    }

    /// Where the sky views' profile came from: `pinned`, `cache` or `probe`.
    #[wasm_bindgen(getter, js_name = skyProfileSource)]
    pub fn sky_profile_source(&self) -> Option<String> {
        self.routed[1].profile.as_ref().map(|(_, s)| (*s).to_string())
    }

    /// Why a sky profile handed in was refused (it was measured anew).
    #[wasm_bindgen(getter, js_name = skyProfileRefused)]
    pub fn sky_profile_refused(&self) -> Option<String> {
        self.routed[1].refused.clone()
    }

    /// The EnergyPlus CSV (the layout EnergyPlus writes as eplusshading.csv).
    pub fn csv(&self) -> Result<String, JsValue> {
        self.schedule.to_csv().map_err(js_error)
    }

    /// With an EnergyPlus model among the files: its text with this CSV hooked in, expecting
    /// the CSV beside it as `csv_name`.
    #[wasm_bindgen(js_name = hookedModel)]
    pub fn hooked_model(&self, csv_name: &str) -> Result<String, JsValue> {
        let (Some(ep), Some(hook)) = (&self.model.energyplus, &self.hook) else {
            return Err(js_error(Error::argument("hookedModel", "no EnergyPlus model (.idf or .epJSON) was loaded")));
        };
        let hook = hook.clone()?;
        // The year was counted for the model's Periodic suns, if it updates periodically.
        let periods = periodic_update(&ep.objects);
        let plan = HookPlan { csv: csv_name, columns: &self.schedule.names, timesteps: self.schedule.timesteps, hook, periods };
        patch_model(ep, &plan).map_err(js_error)
    }
}
