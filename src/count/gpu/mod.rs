//! The GPU pixel counter (wgpu; Vulkan/lavapipe natively, WebGPU in the browser).
//!
//! Owns the device, the pipelines and the atlas. For each (receiver, sun) view it renders, into
//! one tile of an atlas, the receiver alone (coverage mask, no depth test) and then the scene
//! (depth-tested receiver ids; only what lies in the prism in front of it, see [`super::cull`]);
//! a compute pass counts per tile the pixels where the receiver is visible and where it is covered. The sunlit fraction is visible / covered: the covered
//! count is the pixel estimate of the projected area A·cosθ/Ap of the paper's formula, measured
//! with the same rasterisation rule, so edge aliasing on unshaded edges cancels and an unshaded
//! surface gives exactly 1. Many views share one submission (tiles of the atlas).
//!
//! Requests for receivers of one view group ([`super::group`]: a wall and the windows in it) at
//! the same sun and leaf fraction share a tile: the mask pass draws each requested member with its
//! own id, the scene is drawn once, and the count pass counts each member apart.
//!
//! Foliage and see-through casters ([`crate::scene::Veil`]) are decided on the GPU, so one upload
//! serves every day: each view carries its day's leaf fraction and the vertex shader drops the
//! leaves whose rank is not below it; a see-through fragment is discarded (lets the sun through)
//! where a per-pixel hash threshold falls below its transmittance.
//!
//! Adaptive resolution ([`CounterOptions::accuracy`]): every tile is first counted at a small
//! side; the count pass also counts each member's shadow-edge pixel pairs, from which
//! [`error_estimate`] predicts the count's error, and tiles predicted worse than the target are
//! counted again at the side predicted to reach it (up to `resolution`). Fully lit and fully
//! shaded views, most of a year, then cost a small tile; views crossed by many shadow edges get
//! the full side.
//!
//! The parts, in the order a count goes through them:
//! - `device`: opening the adapter and device within its limits; uncaptured errors and device
//!   loss, surfaced as typed errors per stage;
//! - `pipelines`: the WGSL programs, the structs they read, bind group layouts and pipelines;
//! - `upload`: a scene's buffers (static mesh in chunks within the device's buffer limit);
//! - [`plan`]: CPU only — which views need a render, tiles, their cameras, adaptive sides;
//! - `encode`: the per-batch buffers, render and count passes, one submission per batch;
//! - [`masks`]: map points uploaded per receiver and the mask pass that reads, after the count
//!   pass and from the same atlas, whether each point sees the sun;
//! - `readback`: mapping the counts (and masks) and turning them into fractions.
//! - [`cluster_cull`]: culling on the GPU, clusters against a batch's views into (view, cluster)
//!   pairs and indirect draws;
//! - `pulled`: counting from that culling ([`CounterOptions::gpu_cull`]): one indirect draw a
//!   tile whose vertices pull the kept clusters' corners from storage;
//! - `batched`: drawing a GPU-culled batch with one draw, tiles placed by the vertex shader;
//! - [`shade`]: the culling's shading test on the GPU (does anything a view draws shade its
//!   receiver?), exact where f32 can decide, the CPU's test where it cannot.
//!
//! Test hooks (reading the atlas, forcing a device loss, …) are compiled only with the
//! `test-hooks` feature, which the crate's own tests enable.

mod batched;
pub mod cluster_cull;
pub mod compute;
mod device;
mod encode;
#[cfg(feature = "test-hooks")]
mod hooks;
pub mod masks;
mod pipelines;
pub mod plan;
mod pulled;
mod readback;
pub mod shade;
mod upload;

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

pub use self::device::Adapter;
use self::device::Faults;
use self::encode::BatchBuffers;
#[cfg(feature = "test-hooks")]
pub use self::hooks::mask_truth;
use self::pipelines::Pipelines;
pub use self::pipelines::SHADERS;
use self::plan::{SceneLayout, Tile, finer_side, fit_tile, plan_tiles, sides, tiles_at};
use self::upload::{GpuMesh, StaticChunk};
use super::{ViewAnswer, ViewRequest};
use crate::error::Result;
use crate::platform::Stopwatch;

/// The side adaptive counting starts at: ~2,000 pixels on the receiver, enough that a view
/// without shadow edges is within 0.001 and the edge count is a fair guide for the others.
pub const ADAPTIVE_FIRST_SIDE: u32 = 64;

/// Which adapter a [`Counter`] opens.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Backend {
    /// The platform's: the browser's WebGPU, natively Vulkan, Metal or DX12 (`WGPU_BACKEND`).
    #[default]
    Platform,
    /// wgpu's no-op backend (native only): passes are recorded and submitted but never run and
    /// reads return zeros, so what a count costs is the host's work alone. Its counts are
    /// meaningless; only `sunlit bench` uses it, to time the host.
    Noop,
}

/// Which kernel counts a view's pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Kernel {
    /// The graphics pipeline: the members' masks and the scene rendered into an atlas tile, then
    /// a compute pass counting the tile's pixels.
    #[default]
    Raster,
    /// The compute rasterizer ([`compute`]): triangles binned into 32×32 tiles and rasterized in
    /// workgroup memory with the hardware's rules; no atlas.
    Compute,
}

/// Which limits the device is asked for: all the adapter offers, or no more than a named
/// device class offers, so the paths that class would take (smaller atlases, more buffer chunks)
/// are measured on any adapter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LimitsProfile {
    /// Everything the adapter offers.
    #[default]
    Adapter,
    /// Mesa's lavapipe as measured here (Debian 12, Mesa 22.3.6): see [`lavapipe_limits`].
    Lavapipe,
    /// WebGPU's core limits (what a browser grants without asking): [`wgpu::Limits::default`].
    WebGpuCore,
}

impl LimitsProfile {
    /// The profile's limits, `None` for the adapter's own.
    pub fn limits(self) -> Option<wgpu::Limits> {
        match self {
            LimitsProfile::Adapter => None,
            LimitsProfile::Lavapipe => Some(lavapipe_limits()),
            LimitsProfile::WebGpuCore => Some(wgpu::Limits::default()),
        }
    }
}

/// The limits the counter depends on as lavapipe reports them (Debian 12's Mesa 22.3.6 through
/// wgpu 30; `sunlit bench --engine gpu MODEL` prints them on its adapter line): a 16,384 texture
/// side, 128 MiB storage bindings and buffers up to 2^31 − 1 bytes; the rest as WebGPU's core
/// limits, which lavapipe meets or exceeds.
pub fn lavapipe_limits() -> wgpu::Limits {
    wgpu::Limits {
        max_texture_dimension_1d: 16_384,
        max_texture_dimension_2d: 16_384,
        max_storage_buffer_binding_size: 128 << 20,
        max_buffer_size: (1 << 31) - 1,
        ..wgpu::Limits::default()
    }
}

/// Settings of a [`Counter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CounterOptions {
    /// Tile size in pixels (square); 512 gives about three decimals. With `accuracy`, the
    /// largest side a view gets.
    pub resolution: u32,
    /// Largest atlas side in pixels; tiles per submission = (atlas / resolution)².
    pub max_atlas: u32,
    /// Target |error| of each fraction: `Some` counts every view at
    /// [`ADAPTIVE_FIRST_SIDE`] first and again, at a side up to `resolution`, only where the
    /// estimated error is larger ([`error_estimate`]). `None`: every view at `resolution`.
    pub accuracy: Option<f64>,
    /// Which adapter to open.
    pub backend: Backend,
    /// Which limits to ask the device for.
    pub limits: LimitsProfile,
    /// Which kernel counts.
    pub kernel: Kernel,
    /// Cull on the GPU (the raster kernel): the views' casters come from the GPU's culling
    /// pass, one indirect draw a tile, where the adapter and scene allow ([`pulled`]); the CPU
    /// only fits views. Off by default: on lavapipe its brute-force pass costs more than the
    /// CPU's walk, and on real GPUs it is not measured yet.
    pub gpu_cull: bool,
    /// With `gpu_cull`: draw each batch with one draw (instances are the culling's (view,
    /// cluster) pairs, each placed in its tile by the vertex shader, [`batched`]) rather than
    /// one draw a tile. Off by default: on lavapipe its counts equal the per-tile draws' on the
    /// bench models but for one pixel on some louvre views (see `batched`).
    pub batch_draw: bool,
    /// The compute kernel counts its raster tiles' walk ([`compute::WalkStats`], benchmarks):
    /// atomics a tile that cost a little, so off unless asked for.
    pub walk_stats: bool,
}

impl Default for CounterOptions {
    fn default() -> Self {
        Self {
            resolution: 512,
            max_atlas: 2048,
            accuracy: None,
            backend: Backend::Platform,
            limits: LimitsProfile::Adapter,
            kernel: Kernel::Raster,
            gpu_cull: false,
            batch_draw: false,
            walk_stats: false,
        }
    }
}

/// Estimated |error| of a fraction counted from `covered` pixels with `edges` shadow-edge pixel
/// pairs: each boundary pixel is decided by its centre and is off by up to half a pixel. Were
/// these errors independent they would add like a random walk, sqrt(edges/12) pixels; along a
/// straight edge they are not (a nearly axis-aligned edge repeats its sub-pixel offsets), and on
/// louvre shadows, many parallel straight edges, the exact reference showed errors up to
/// 2.6·sqrt(edges) pixels. The estimate takes 3·sqrt(edges), plus one pixel for the receiver's
/// own outline, over the covered pixels.
pub fn error_estimate(covered: u32, edges: u32) -> f64 {
    if covered == 0 {
        return f64::INFINITY;
    }
    (3.0 * (edges as f64).sqrt() + 1.0) / covered as f64
}

/// The host's time a [`Counter`] has spent counting, by stage, in seconds (natively; the web
/// build has no clock here and reports zeros). What is left of a count's wall time beyond their
/// sum is the GPU's own work that the host did not wait for. `culling` is part of `planning` and
/// `recording` part of `encoding` (their rest: fitting and packing tiles; writing buffers).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct HostStages {
    /// Fitting views, culling what each draws and packing tiles (CPU only).
    pub planning: f64,
    /// Of `planning`: culling, the BVH walk choosing what each tile draws and the test whether
    /// anything in it can shade the receiver.
    pub culling: f64,
    /// Writing each batch's buffers and recording its passes.
    pub encoding: f64,
    /// Of `encoding`: recording the passes (the raster kernel's render pass, a draw per member
    /// and per merged range, and its count pass; the compute kernel's dispatches).
    pub recording: f64,
    /// `Queue::submit`.
    pub submitting: f64,
    /// Waiting for a readback to map (the GPU finishing, and the round trip).
    pub waiting: f64,
    /// Turning the counts read back into fractions.
    pub unpacking: f64,
}

impl HostStages {
    /// Stage by stage, `f` of the two.
    fn zip(self, other: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self {
            planning: f(self.planning, other.planning),
            culling: f(self.culling, other.culling),
            encoding: f(self.encoding, other.encoding),
            recording: f(self.recording, other.recording),
            submitting: f(self.submitting, other.submitting),
            waiting: f(self.waiting, other.waiting),
            unpacking: f(self.unpacking, other.unpacking),
        }
    }
}

impl std::ops::Add for HostStages {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        self.zip(other, |a, b| a + b)
    }
}

impl std::ops::Sub for HostStages {
    type Output = Self;
    fn sub(self, other: Self) -> Self {
        self.zip(other, |a, b| a - b)
    }
}

/// [`HostStages`] as a counter accumulates them, in nanoseconds, from any lane's thread.
#[derive(Default)]
struct StageClock {
    planning: AtomicU64,
    culling: AtomicU64,
    encoding: AtomicU64,
    recording: AtomicU64,
    submitting: AtomicU64,
    waiting: AtomicU64,
    unpacking: AtomicU64,
}

impl StageClock {
    fn read(&self) -> HostStages {
        let s = |a: &AtomicU64| a.load(Ordering::Relaxed) as f64 * 1e-9;
        HostStages {
            planning: s(&self.planning),
            culling: s(&self.culling),
            encoding: s(&self.encoding),
            recording: s(&self.recording),
            submitting: s(&self.submitting),
            waiting: s(&self.waiting),
            unpacking: s(&self.unpacking),
        }
    }
}

/// One counted view. A view that needed no render (sun down, facing away, or nothing in front
/// of the receiver) has `covered == 0`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Counted {
    /// Sunlit fraction in [0, 1].
    pub fraction: f64,
    /// Cosine of incidence (normal · sun).
    pub cos_incidence: f64,
    /// Pixels where the receiver is visible from the sun (0 when not rendered).
    pub visible: u32,
    /// Pixels the receiver covers in its tile (0 when not rendered).
    pub covered: u32,
    /// Area per pixel on the view plane (m²; 0 when not rendered).
    pub pixel_area: f64,
    /// Side of the tile it was counted in (0 when not rendered).
    pub side: u32,
    /// Shadow-edge pixel pairs on the receiver (counted only with an accuracy target).
    pub edges: u32,
}

impl Counted {
    /// [`error_estimate`] of this count (0 when not rendered: exact by construction).
    pub fn error_estimate(&self) -> f64 {
        if self.side == 0 { 0.0 } else { error_estimate(self.covered, self.edges) }
    }

    /// The common answer; `edges_counted`: whether the count pass counted shadow edges (only
    /// with an accuracy target), without which a rendered view has no error estimate.
    pub fn answer(&self, edges_counted: bool) -> ViewAnswer {
        let rendered = self.side > 0;
        ViewAnswer {
            fraction: self.fraction,
            cos_incidence: self.cos_incidence,
            covered: rendered.then_some(self.covered),
            side: rendered.then_some(self.side),
            error_estimate: (!rendered || edges_counted).then(|| self.error_estimate()),
        }
    }
}

/// The device, pipelines and atlas; reusable across scenes.
pub struct Counter {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    options: CounterOptions,
    /// The atlas's side in pixels: a whole number of tiles at every side used.
    atlas_side: u32,
    pipelines: Pipelines,
    batch: BatchBuffers,
    /// Tiles rendered and triangles drawn in them since the counter was made (benchmarks).
    tiles_rendered: AtomicU64,
    triangles_drawn: AtomicU64,
    /// Views in the tiles rendered (before the GPU's culling settles unshaded ones as unrendered).
    views_drawn: AtomicU64,
    /// GPU-culled tiles whose shading test the host ran (the GPU could not decide, or has no
    /// test for the scene).
    shading_on_cpu: AtomicU64,
    /// Host time by stage since the counter was made (benchmarks).
    stages: StageClock,
    faults: Faults,
    /// The compute kernel's passes and bins (`None` with the raster kernel).
    compute: Option<compute::ComputeState>,
    /// The draw from the GPU's culling (`None` without [`CounterOptions::gpu_cull`], or where
    /// the adapter cannot run it).
    pulled: Option<pulled::PulledPipelines>,
}

/// A scene uploaded to a [`Counter`]'s device.
pub struct GpuScene {
    meshes: Vec<GpuMesh>,
    /// The static mesh's triangles in the culling's spatial order, in buffers within the device's
    /// size limit, each indexed into its distinct vertices (the scene pass draws ranges of it).
    static_chunks: Vec<StaticChunk>,
    /// What planning reads: receivers' outlines and draws, view groups, the culling.
    layout: SceneLayout,
    render_bind: wgpu::BindGroup,
    count_bind: wgpu::BindGroup,
    /// The triangles as the compute kernel reads them (`None` with the raster kernel, or where
    /// they do not fit its bindings).
    compute: Option<compute::ComputeScene>,
    /// Clusters and corners for the GPU's culling (`None` without it, or where they do not fit).
    pulled: Option<pulled::PulledScene>,
}

impl Counter {
    /// Opens a device and builds the pipelines and atlas.
    pub async fn new(options: CounterOptions) -> Result<Self> {
        Self::on(&Adapter::request(&options).await?, options).await
    }

    /// Opens a device on `adapter` (requested for these `options`) and builds the pipelines and
    /// atlas.
    pub async fn on(adapter: &Adapter, options: CounterOptions) -> Result<Self> {
        let device::Opened { device, queue, info, tiles_per_side, downlevel } = device::open_on(adapter).await?;
        let faults = Faults::watch(&device);
        let pipelines = Pipelines::new(&device);
        let atlas_side = tiles_per_side * options.resolution;
        // Buffers hold a batch at the smallest side used.
        let smallest = sides(&options).first().copied().unwrap_or(options.resolution);
        let batch = BatchBuffers::new(&device, &pipelines, atlas_side, smallest);
        let compute = compute::ComputeState::new(&device, options.kernel);
        let culls_on_gpu = options.gpu_cull && options.kernel == Kernel::Raster;
        let pulled = culls_on_gpu.then(|| pulled::PulledPipelines::new(&device, &pipelines, downlevel, options.batch_draw)).flatten();
        let counter = Self {
            device,
            queue,
            info,
            options,
            atlas_side,
            pipelines,
            batch,
            tiles_rendered: AtomicU64::new(0),
            triangles_drawn: AtomicU64::new(0),
            views_drawn: AtomicU64::new(0),
            shading_on_cpu: AtomicU64::new(0),
            stages: StageClock::default(),
            faults,
            compute,
            pulled,
        };
        counter.check_errors("setting up the GPU")?;
        Ok(counter)
    }

    /// The adapter in use (name, backend, device type).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// The limits its device was opened with (the adapter's, or a [`LimitsProfile`]'s).
    pub fn limits(&self) -> wgpu::Limits {
        self.device.limits()
    }

    /// The options it was made with.
    pub fn options(&self) -> CounterOptions {
        self.options
    }

    /// Tile resolution in pixels.
    pub fn resolution(&self) -> u32 {
        self.options.resolution
    }

    /// Views rendered per submission at `resolution`.
    pub fn tiles_per_batch(&self) -> usize {
        tiles_at(self.atlas_side, self.options.resolution)
    }

    /// Tiles a batch holds at the smallest side used (what the per-batch buffers are sized for).
    fn batch_tiles(&self) -> usize {
        tiles_at(self.atlas_side, sides(&self.options).first().copied().unwrap_or(self.options.resolution))
    }

    /// Tiles rendered since this counter was made (a tile counts one request, or several of one
    /// view group), and the triangles drawn in them by the scene pass.
    pub fn rendered(&self) -> (u64, u64) {
        (self.tiles_rendered.load(Ordering::Relaxed), self.triangles_drawn.load(Ordering::Relaxed))
    }

    /// Views drawn since this counter was made: the requests of the tiles rendered, counted
    /// when their tile is, so also those the GPU's culling then settles as unshaded without
    /// their count (on the noop backend, whose verdicts read back as "nothing can shade", all).
    pub fn views_drawn(&self) -> u64 {
        self.views_drawn.load(Ordering::Relaxed)
    }

    /// Host time spent by stage since this counter was made (native builds; zeros on the web).
    pub fn host_stages(&self) -> HostStages {
        self.stages.read()
    }

    /// The first GPU failure since the last check, as the error of stage `doing`.
    fn check_errors(&self, doing: &str) -> Result<()> {
        self.faults.check(doing, self.options.resolution)
    }

    /// A new counter with the same options on a new device (after [`crate::Error::DeviceLost`]).
    pub async fn recreate(&self) -> Result<Counter> {
        Counter::new(self.options).await
    }

    /// Sunlit fractions for many views, each at its own leaf fraction (the leaves whose rank is
    /// below it cast shadows); dark views (sun down, facing away) cost nothing, the others are
    /// rendered in batches of atlas tiles.
    pub async fn fractions(&self, scene: &GpuScene, requests: &[ViewRequest]) -> Result<Vec<Counted>> {
        let mut out = vec![Counted::default(); requests.len()];
        let ladder = sides(&self.options);
        let first = ladder.first().copied().unwrap_or(self.options.resolution);
        let planning = Stopwatch::start();
        let mut culling = 0;
        let tiles = plan_tiles(&scene.layout, requests, first, &mut out, &mut culling, self.culls_on_gpu(scene))?;
        self.stages.planning.fetch_add(planning.nanos(), Ordering::Relaxed);
        self.stages.culling.fetch_add(culling, Ordering::Relaxed);
        // Tiles waiting to be counted, by side; each round counts the smallest side waiting.
        let mut waiting: BTreeMap<u32, Vec<Tile>> = BTreeMap::from([(first, tiles)]);
        while let Some((side, tiles)) = waiting.pop_first() {
            self.count_tiles(scene, requests, &tiles, side, &mut out, None).await?;
            let Some(target) = self.options.accuracy else { continue };
            let planning = Stopwatch::start();
            for tile in tiles {
                let worst = tile.requests.iter().map(|&i| out[i].error_estimate()).fold(0.0, f64::max);
                if let Some(next) = finer_side(&ladder, side, worst, target) {
                    let view = fit_tile(&scene.layout, requests, &tile.requests, next);
                    waiting.entry(next).or_default().push(Tile { view, ..tile });
                }
            }
            self.stages.planning.fetch_add(planning.nanos(), Ordering::Relaxed);
        }
        Ok(out)
    }

    /// [`Self::fractions`] as the common answer ([`ViewAnswer`]).
    pub async fn answer(&self, scene: &GpuScene, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        let counted = self.fractions(scene, requests).await?;
        let edges_counted = self.options.accuracy.is_some();
        Ok(counted.iter().map(|c| c.answer(edges_counted)).collect())
    }
}

impl GpuScene {
    /// World origin the GPU coordinates are relative to.
    pub fn origin(&self) -> DVec3 {
        self.layout.origin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_estimate_falls_with_fewer_edges_and_more_pixels() {
        assert_eq!(error_estimate(0, 0), f64::INFINITY);
        assert_eq!(error_estimate(1000, 0), 0.001, "one pixel of outline");
        assert!(error_estimate(4000, 200) < error_estimate(1000, 100));
    }
}
