//! The compute rasterizer ([`Kernel::Compute`]): the same counts as the render and count passes,
//! from two compute passes (shaders/compute_raster.wgsl) instead of the graphics pipeline, so
//! GPUs whose raster hardware is a small part of the chip (data-centre parts) count on every SM.
//!
//! Owns the scene's triangles as the kernel reads them (positions and per-triangle attributes,
//! in the culling's order, so a view's draw list is a few ranges of them), the growable per-batch
//! buffers (views, ranges, list heads, the node pool) and the encoding of a batch's passes. The
//! planning, the members and the readback are the raster kernel's ([`super::plan`],
//! [`super::readback`]); a batch that also renders map-point masks is drawn by the raster kernel,
//! which leaves an atlas for them to read.
//!
//! Batches ([`Counter::count_tiles_compute`]): the kernel fills no atlas, so a batch is as many
//! views as its buffers allow ([`MAX_BATCH_VIEWS`], and the node pool within [`POOL_BUDGET`]),
//! counted in one submission and read back with the pool's count. The pool is sized before each
//! batch from the nodes a triangle took in the batch before ([`node_bound`] a triangle at most,
//! the bound the first batch is sized by), so in steady state no batch is counted twice; a batch
//! that still needed more is counted again with a pool that large (never truncated).
//!
//! Each view's members' own triangles are listed apart and drawn first by every raster tile, so
//! a tile can stop as soon as none of its pixels shows a member (none covers it, or casters have
//! shaded it whole): on a dense city most of a dark view's tiles stop after their first chunk.

use std::ops::Range;
use std::sync::Mutex;

use std::sync::atomic::Ordering;

use super::pipelines::{COUNTS_PER_MEMBER, buffer, compute_pipeline, entry, storage_entry, uniform_entry};
use super::plan::{SceneLayout, Tile, tile_origin, tiles_at};
use super::{Counted, Counter, GpuScene, Kernel};
use crate::count::ViewRequest;
use crate::error::{GpuError, Result};
use crate::platform::{self, Stopwatch};
use crate::scene::{Scene, shifted_rank};

pub(super) const COMPUTE_RASTER_WGSL: &str = include_str!("../../../shaders/compute_raster.wgsl");
/// Side of the kernel's raster tile (one workgroup), in pixels: the shader's TILE.
pub const RASTER_TILE: u32 = 32;
/// Bits of quantized depth in the kernel's per-pixel word (the low 3 hold the class).
pub const DEPTH_BITS: u32 = 29;
/// Nodes the pool starts with (8 bytes each).
const FIRST_CAPACITY: u32 = 1 << 18;
/// Triangles one binning workgroup takes (the shader's JOB).
pub const JOB_TRIANGLES: u32 = 256;
/// The fewest raster tiles a triangle's box may touch and go to its view's large list (the
/// shader's LARGE_TILES; see [`node_bound`]).
pub const LARGE_TILES: u32 = 8;

/// Raster tiles a triangle's box may touch and still be binned into each, in a view of side
/// `side` (the shader's large_tiles): a quarter of the view's raster tiles, at least
/// [`LARGE_TILES`]; a larger one takes two nodes in its view's large list. So a triangle takes
/// at most this many nodes. Every raster tile walks the large list, so it holds only triangles
/// over a quarter of the view (a tile rejects at most ~3 boxes for each it draws).
pub fn node_bound(side: u32) -> u32 {
    LARGE_TILES.max(side.div_ceil(RASTER_TILE).pow(2) / 4)
}

/// Lists a view has besides its raster tiles' (the shader's LARGE_LIST and MEMBER_LIST): its
/// large triangles', and its members' own triangles', which every raster tile draws first.
const VIEW_LISTS: u32 = 2;

/// List heads a view of side `side` has: one a raster tile, row by row, then [`VIEW_LISTS`].
fn heads_per_view(side: u32) -> u32 {
    raster_tiles(side) + VIEW_LISTS
}

/// Words of heads before the views' list heads (the shader's FIRST_HEAD): the pool's count, then
/// the walk's counters, five of 64 bits.
const FIRST_HEAD: u64 = 11;

/// What the raster pass's tiles did (benchmarks, with [`super::CounterOptions::walk_stats`]): a
/// tile's cost is mostly its walk over the casters binned to it (docs/benchmarks-gpu.md).
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct WalkStats {
    /// Raster tiles counted.
    pub tiles: u64,
    /// List entries the tiles visited (members', large and their own), each once a half of the
    /// workgroup (a half's 32 lanes walk the same entries).
    pub entries: u64,
    /// Of those, triangles set up (a large or member entry whose box holds the tile, every entry
    /// of the tile's own list).
    pub set_up: u64,
    /// Rows drawn: a lane's row inside a set-up triangle's bounding box.
    pub rows: u64,
    /// Pixel centres tested against a triangle's edges.
    pub pixels: u64,
}

impl WalkStats {
    /// One batch's counters, as the shader leaves them: five (low, high) word pairs.
    fn from_words(words: &[u32]) -> Self {
        let mut at = words.chunks_exact(2).map(|pair| u64::from(pair[0]) | u64::from(pair[1]) << 32);
        let mut next = || at.next().unwrap_or(0);
        Self { tiles: next(), entries: next(), set_up: next(), rows: next(), pixels: next() }
    }
}

impl std::ops::AddAssign for WalkStats {
    fn add_assign(&mut self, other: Self) {
        self.tiles += other.tiles;
        self.entries += other.entries;
        self.set_up += other.set_up;
        self.rows += other.rows;
        self.pixels += other.pixels;
    }
}

/// Raster tiles (workgroups of the raster pass) a view of side `side` has.
fn raster_tiles(side: u32) -> u32 {
    side.div_ceil(RASTER_TILE).pow(2)
}
/// The most views a batch counts: at 512² that is 262,144 raster workgroups, enough to keep a
/// data-centre GPU's SMs busy, and the batch's own buffers stay small (the heads 1 MiB).
pub const MAX_BATCH_VIEWS: usize = 1024;
/// The most bytes the pool is planned at (a view that needs more still gets them, up to the
/// device's binding limit): 32 M nodes, ~1,500 views of 10,000 triangles at the nodes a triangle
/// takes on nyt-blocks.
pub const POOL_BUDGET: u64 = 256 << 20;
/// Room planned over the previous batch's nodes a triangle.
const POOL_MARGIN: f64 = 1.25;
/// What the dither multiplies an instance slot by (sun_view.wgsl's seed mixing).
const SLOT_MIX: u32 = 0x9e37_79b9;

/// A view as the compute kernel reads it (compute_raster.wgsl's View).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComputeView {
    view_proj: [[f32; 4]; 4],
    tile: [u32; 2],
    side: u32,
    leaves: f32,
    first_member: u32,
    member_count: u32,
    first_range: u32,
    range_count: u32,
    first_head: u32,
    triangles: u32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComputeParams {
    capacity: u32,
    count_edges: u32,
    dump: u32,
    first_job: u32,
    jobs: u32,
    walk: u32,
    _pad: [u32; 2],
}

/// The two passes and their bindings.
pub(super) struct ComputePipelines {
    layout: wgpu::BindGroupLayout,
    bin: wgpu::ComputePipeline,
    raster: wgpu::ComputePipeline,
}

impl ComputePipelines {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let cs = wgpu::ShaderStages::COMPUTE;
        let mut entries: Vec<wgpu::BindGroupLayoutEntry> = (0..8).map(|b| storage_entry(b, cs, b < 5)).collect();
        entries.push(uniform_entry(8, cs));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("compute raster"), entries: &entries });
        let make = |entry| compute_pipeline(device, &layout, "compute_raster.wgsl", COMPUTE_RASTER_WGSL, entry);
        Self { bin: make("bin_main"), raster: make("raster_main"), layout }
    }
}

/// A scene's triangles for the compute kernel.
pub(super) struct ComputeScene {
    positions: wgpu::Buffer,
    attributes: wgpu::Buffer,
}

impl ComputeScene {
    /// Uploads triangles' corners (9 floats each) and attributes.
    fn new(device: &wgpu::Device, positions: &[f32], attributes: &[[u32; 4]]) -> Self {
        let init = |label, contents: &[u8]| {
            use wgpu::util::DeviceExt;
            // A binding may not be empty.
            let contents = if contents.is_empty() { &[0u8; 16][..] } else { contents };
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        Self {
            positions: init("triangle positions", bytemuck::cast_slice(positions)),
            attributes: init("triangle attributes", bytemuck::cast_slice(attributes)),
        }
    }
}

/// The per-batch buffers, grown as batches need, and what sizes the next batch.
pub(super) struct ComputeBins {
    views: wgpu::Buffer,
    /// The views' ranges, then the jobs.
    ranges: wgpu::Buffer,
    members: wgpu::Buffer,
    counts: wgpu::Buffer,
    heads: wgpu::Buffer,
    nodes: wgpu::Buffer,
    params: wgpu::Buffer,
    /// The pool's count and the members' counts, mapped after each batch.
    readback: wgpu::Buffer,
    /// Nodes `nodes` holds.
    pub(super) capacity: u32,
    /// Nodes a triangle took in the last batch counted (infinite before any: the bound,
    /// [`node_bound`], is planned for).
    per_triangle: f64,
    /// Batches counted again because the pool was too small (benchmarks and tests).
    pub(super) reruns: u64,
    /// Batches counted, and the views in them (benchmarks).
    batches: u64,
    views_counted: u64,
    /// Tests: write each pixel's class and coverage into `heads` too.
    dump: bool,
    /// The raster pass's walk, summed over the batches counted (with `walk_stats`).
    walk: WalkStats,
    /// Tests: the most views a batch takes (else [`MAX_BATCH_VIEWS`]).
    max_views: usize,
}

const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST);
const COUNTS: wgpu::BufferUsages = STORAGE.union(wgpu::BufferUsages::COPY_SRC);
const READBACK: wgpu::BufferUsages = wgpu::BufferUsages::MAP_READ.union(wgpu::BufferUsages::COPY_DST);

impl ComputeBins {
    pub(super) fn new(device: &wgpu::Device, capacity: u32) -> Self {
        Self {
            views: buffer(device, "compute views", 0, STORAGE),
            ranges: buffer(device, "compute ranges", 0, STORAGE),
            members: buffer(device, "compute members", 0, STORAGE),
            counts: buffer(device, "compute counts", 0, COUNTS),
            heads: buffer(device, "compute heads", 0, COUNTS),
            nodes: buffer(device, "compute nodes", capacity as u64 * 8, STORAGE),
            params: buffer(
                device,
                "compute params",
                size_of::<ComputeParams>() as u64,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            ),
            readback: buffer(device, "compute readback", 0, READBACK),
            capacity,
            per_triangle: f64::INFINITY,
            reruns: 0,
            batches: 0,
            views_counted: 0,
            dump: false,
            walk: WalkStats::default(),
            max_views: MAX_BATCH_VIEWS,
        }
    }

    /// Makes the pool hold `nodes` nodes (a power of two where that fits `limit` nodes), never
    /// fewer than now.
    fn resize(&mut self, device: &wgpu::Device, nodes: u64, limit: u64) {
        let nodes = nodes.next_power_of_two().min(limit).max(nodes.min(limit));
        if nodes > self.capacity as u64 {
            self.nodes = buffer(device, "compute nodes", nodes * 8, STORAGE);
            self.capacity = nodes.min(u32::MAX as u64) as u32;
        }
    }
}

/// The bytes one binding of the pool may have on `device`.
fn pool_limit(device: &wgpu::Device) -> u64 {
    let limits = device.limits();
    limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
}

/// `buf` if it holds `bytes`, else a new buffer twice as large as asked.
fn fit(device: &wgpu::Device, buf: &mut wgpu::Buffer, bytes: u64, label: &str, usage: wgpu::BufferUsages) {
    if buf.size() < bytes {
        *buf = buffer(device, label, bytes * 2, usage);
    }
}

/// One batch as the kernel reads it.
pub(super) struct ComputeBatch {
    views: Vec<ComputeView>,
    /// The views' ranges (first triangle, the view's triangles before it), then the jobs (view,
    /// its first triangle).
    words: Vec<[u32; 2]>,
    members: Vec<u32>,
    /// Triangles in the views' lists.
    triangles: u64,
    /// List heads a view has ([`heads_per_view`]).
    heads_per_view: u32,
    side: u32,
}

impl ComputeBatch {
    /// Starts a batch of views of side `side`.
    fn new(side: u32) -> Self {
        let heads_per_view = heads_per_view(side);
        Self { views: Vec::new(), words: Vec::new(), members: Vec::new(), triangles: 0, heads_per_view, side }
    }

    /// Adds a view drawing `ranges` of the triangles and counting `members`; `origin`: its tile's
    /// corner in the raster kernel's atlas (the viewport and the dither read it).
    fn push(&mut self, view_proj: glam::Mat4, origin: [u32; 2], leaves: f32, members: &[u32], ranges: &[Range<u32>]) {
        let slot = self.views.len() as u32;
        let first_range = self.words.len() as u32;
        let mut before = 0u32;
        for r in ranges.iter().filter(|r| !r.is_empty()) {
            self.words.push([r.start, before]);
            before += r.len() as u32;
        }
        self.views.push(ComputeView {
            view_proj: view_proj.to_cols_array_2d(),
            tile: origin,
            side: self.side,
            leaves,
            first_member: self.members.len() as u32,
            member_count: members.len() as u32,
            first_range,
            range_count: self.words.len() as u32 - first_range,
            first_head: slot * self.heads_per_view,
            triangles: before,
            _pad: [0; 2],
        });
        self.members.extend_from_slice(members);
        self.triangles += before as u64;
    }

    /// The views' ranges followed by their jobs (JOB_TRIANGLES triangles of one view each).
    fn ranges_and_jobs(&self) -> (Vec<[u32; 2]>, u32) {
        let mut words = self.words.clone();
        let first_job = words.len().max(1) as u32;
        words.resize(first_job as usize, [0, 0]);
        for (slot, view) in self.views.iter().enumerate() {
            words.extend((0..view.triangles).step_by(JOB_TRIANGLES as usize).map(|k| [slot as u32, k]));
        }
        (words, first_job)
    }

    /// Words of the heads buffer: the pool's count and every view's heads.
    fn head_words(&self) -> u64 {
        FIRST_HEAD + self.views.len() as u64 * self.heads_per_view as u64
    }
}

/// The kernel's state in a [`Counter`]: its passes and bins (`None` for the raster kernel).
pub(super) struct ComputeState {
    pub(super) pipelines: ComputePipelines,
    pub(super) bins: Mutex<ComputeBins>,
}

impl ComputeState {
    pub(super) fn new(device: &wgpu::Device, kernel: Kernel) -> Option<Self> {
        (kernel == Kernel::Compute)
            .then(|| Self { pipelines: ComputePipelines::new(device), bins: Mutex::new(ComputeBins::new(device, FIRST_CAPACITY)) })
    }
}

/// Per triangle of the culling's order: (receiver id, leaf rank shifted by its placement, its
/// transmittance, its dither seed mixed with its instance slot), as the raster path's vertex
/// shader derives them from the triangle's first (provoking) vertex.
pub(super) fn triangle_attributes(scene: &Scene, layout: &SceneLayout) -> Vec<[u32; 4]> {
    let culling = &layout.culling;
    let mut slot_of = vec![0u32; scene.instances.len()];
    for (slot, &i) in culling.slot_order().iter().enumerate() {
        slot_of[i] = slot as u32;
    }
    let (_, ids) = culling.triangles();
    culling
        .triangle_sources()
        .iter()
        .zip(ids)
        .map(|(&(instance, t), &id)| {
            let inst = &scene.instances[instance];
            let mesh = &scene.meshes[inst.mesh];
            let first = mesh.indices[3 * t as usize] as usize;
            let veil = mesh.veils.get(first).copied().unwrap_or_default();
            let rank = if veil.rank >= 0.0 { shifted_rank(veil.rank, inst.leaf_shift) } else { veil.rank };
            let slot = if inst.mesh == 0 { culling.static_slot() } else { slot_of[instance] };
            [id, rank.to_bits(), veil.transmittance.to_bits(), veil.seed ^ slot.wrapping_mul(SLOT_MIX)]
        })
        .collect()
}

impl Counter {
    /// The scene's triangles for the compute kernel, or `None` (with a warning naming the
    /// limit) where they do not fit one storage binding: the raster kernel counts instead.
    pub(super) fn upload_compute(&self, scene: &Scene, layout: &SceneLayout) -> Option<ComputeScene> {
        self.compute.as_ref()?;
        let (triangles, _) = layout.culling.triangles();
        let positions: Vec<f32> = triangles.iter().flat_map(|t| t.iter().flat_map(|p| p.to_array())).collect();
        let attributes = triangle_attributes(scene, layout);
        let limit = self.device.limits().max_storage_buffer_binding_size;
        let need = (positions.len() * 4).max(attributes.len() * 16) as u64;
        if need > limit {
            log::warn!(
                "compute kernel dropped: the scene's triangles need {need} bytes in one storage binding, over this device's \
                 max_storage_buffer_binding_size ({limit}); counting with the raster kernel"
            );
            return None;
        }
        Some(ComputeScene::new(&self.device, &positions, &attributes))
    }

    /// Whether this batch is counted by the compute kernel: it is this counter's kernel, the
    /// scene's triangles were uploaded for it, and no atlas is needed (no map-point masks).
    pub(super) fn counts_by_compute(&self, scene: &GpuScene, masks: bool) -> bool {
        self.compute.is_some() && scene.compute.is_some() && !masks
    }

    /// Counts `tiles` at side `side` with the compute kernel into `out`: batches of as many views
    /// as [`MAX_BATCH_VIEWS`] and the pool's budget allow, one submission and readback each.
    pub(super) async fn count_tiles_compute(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        tiles: &[Tile],
        side: u32,
        out: &mut [Counted],
    ) -> Result<()> {
        let Some(triangles) = scene.compute.as_ref() else { return Ok(()) };
        let per_atlas = tiles_at(self.atlas_side, side).max(1);
        let culling = &scene.layout.culling;
        let lists: Vec<Vec<Range<u32>>> =
            tiles.iter().map(|t| t.draws.as_ref().map_or_else(Vec::new, |d| culling.list_ranges(d))).collect();
        let sizes: Vec<u64> = lists.iter().map(|l| l.iter().map(|r| r.len() as u64).sum()).collect();
        let (mut at, mut most) = (0, usize::MAX);
        while at < tiles.len() {
            let encoding = Stopwatch::start();
            let n = self.plan_batch(&sizes[at..], side, most)?;
            let mut batch = ComputeBatch::new(side);
            for (i, (tile, list)) in tiles[at..at + n].iter().zip(&lists[at..]).enumerate() {
                let members: Vec<u32> =
                    tile.requests.iter().map(|&r| scene.layout.receivers[requests[r].receiver as usize].gpu_id).collect();
                // Where the raster kernel would have drawn it: the same viewport and dither.
                let origin = tile_origin(self.atlas_side, (at + i) % per_atlas, side);
                batch.push(tile.view.view_proj.as_mat4(), origin, requests[tile.requests[0]].leaves, &members, list);
            }
            self.stages.encoding.fetch_add(encoding.nanos(), Ordering::Relaxed);
            let Some(counts) = self.run_batch(triangles, &batch).await? else {
                // Its pool would not fit one binding: fewer views a batch from here on.
                most = n / 2;
                continue;
            };
            let unpacking = Stopwatch::start();
            let chunk = &tiles[at..at + n];
            self.note_rendered(scene, chunk);
            super::readback::unpack(chunk, &counts, side, out);
            self.stages.unpacking.fetch_add(unpacking.nanos(), Ordering::Relaxed);
            at += n;
        }
        Ok(())
    }

    fn bins(&self) -> Result<std::sync::MutexGuard<'_, ComputeBins>> {
        let state =
            self.compute.as_ref().ok_or_else(|| GpuError::Validation { doing: "binning".into(), message: "no compute kernel".into() })?;
        Ok(state.bins.lock().map_err(|_| GpuError::Validation { doing: "binning".into(), message: "poisoned".into() })?)
    }

    /// How many of the views ahead (`sizes`: their triangles) the next batch takes, at most
    /// `most`, and the pool grown for them: the nodes a triangle took in the batch before, with a
    /// margin, within [`POOL_BUDGET`] (a single view whatever it needs).
    fn plan_batch(&self, sizes: &[u64], side: u32, most: usize) -> Result<usize> {
        let mut bins = self.bins()?;
        let limit = pool_limit(&self.device);
        let budget = POOL_BUDGET.min(limit) / 8;
        let per_triangle = (bins.per_triangle * POOL_MARGIN).min(node_bound(side) as f64);
        let heads_per_view = heads_per_view(side) as u64;
        let most = most.min(bins.max_views).min((limit / 4 / heads_per_view) as usize).max(1);
        let (mut n, mut triangles) = (0usize, 0u64);
        for &s in sizes.iter().take(most) {
            if n > 0 && per_triangle * (triangles + s) as f64 > budget as f64 {
                break;
            }
            n += 1;
            triangles += s;
        }
        bins.resize(&self.device, (per_triangle * triangles as f64).ceil() as u64, limit / 8);
        Ok(n)
    }

    /// Counts a batch: its members' counts, three words an entry; counted again with a larger
    /// pool while the pool was too small. `None` when the pool it needs would not fit one
    /// binding and it has more than one view (split it).
    async fn run_batch(&self, triangles: &ComputeScene, batch: &ComputeBatch) -> Result<Option<Vec<u32>>> {
        let limit = pool_limit(&self.device) / 8;
        loop {
            let (readback, bytes) = self.submit_compute(triangles, batch)?;
            let waiting = Stopwatch::start();
            let read = platform::read_buffer(&self.device, &readback, bytes).await;
            self.stages.waiting.fetch_add(waiting.nanos(), Ordering::Relaxed);
            // A failed read on a lost device is the loss, not a read error.
            self.check_errors("counting pixels")?;
            // The mapped bytes' Vec need not be aligned for u32: copied, not cast in place.
            let mut words: Vec<u32> = bytemuck::pod_collect_to_vec(&read?);
            let needed = words.first().copied().unwrap_or(0) as u64;
            let mut bins = self.bins()?;
            if needed > bins.capacity as u64 {
                if needed > limit {
                    if batch.views.len() > 1 {
                        return Ok(None);
                    }
                    return Err(
                        GpuError::OverLimit { limit_name: "max_storage_buffer_binding_size", need: needed * 8, limit: limit * 8 }.into()
                    );
                }
                log::info!("compute kernel: {needed} bin nodes needed, {} held; counting the batch again", bins.capacity);
                bins.resize(&self.device, needed, limit);
                bins.reruns += 1;
                continue;
            }
            if batch.triangles > 0 {
                // Up at once, down by halves: one batch whose views culled most of their
                // triangles does not leave the next one's pool too small.
                let floor = if bins.per_triangle.is_finite() { bins.per_triangle / 2.0 } else { 0.0 };
                bins.per_triangle = (needed as f64 / batch.triangles as f64).max(floor);
            }
            bins.batches += 1;
            bins.views_counted += batch.views.len() as u64;
            let Some(walk) = words.get(1..FIRST_HEAD as usize) else {
                return Err(GpuError::Readback(format!(
                    "the compute kernel's readback has {} words, fewer than {FIRST_HEAD}",
                    words.len()
                ))
                .into());
            };
            bins.walk += WalkStats::from_words(walk);
            words.drain(..FIRST_HEAD as usize);
            return Ok(Some(words));
        }
    }

    /// Writes a batch's buffers, records its bin and raster passes and the copies into the
    /// readback, and submits them. Returns the readback and the bytes to map.
    fn submit_compute(&self, triangles: &ComputeScene, batch: &ComputeBatch) -> Result<(wgpu::Buffer, u64)> {
        let encoding = Stopwatch::start();
        let Some(state) = self.compute.as_ref() else { return Err(GpuError::Readback("no compute kernel".into()).into()) };
        let mut bins = self.bins()?;
        let (words, first_job) = batch.ranges_and_jobs();
        let jobs = words.len() as u32 - first_job;
        let views = batch.views.len() as u64;
        let head_words = batch.head_words();
        let dump = if bins.dump { head_words } else { 0 };
        let head_bytes = 4 * (head_words + if bins.dump { views * batch.side as u64 * batch.side as u64 } else { 0 });
        let entry_bytes = count_bytes(batch.members.len());
        let d = &self.device;
        fit(d, &mut bins.views, size_of_val(&batch.views[..]) as u64, "compute views", STORAGE);
        fit(d, &mut bins.ranges, size_of_val(&words[..]) as u64, "compute ranges", STORAGE);
        fit(d, &mut bins.members, size_of_val(&batch.members[..]) as u64, "compute members", STORAGE);
        fit(d, &mut bins.counts, entry_bytes, "compute counts", COUNTS);
        fit(d, &mut bins.heads, head_bytes, "compute heads", COUNTS);
        fit(d, &mut bins.readback, 4 * FIRST_HEAD + entry_bytes, "compute readback", READBACK);
        let params = ComputeParams {
            capacity: bins.capacity,
            count_edges: self.options.accuracy.is_some() as u32,
            dump: dump as u32,
            first_job,
            jobs,
            walk: self.options.walk_stats as u32,
            _pad: [0; 2],
        };
        self.queue.write_buffer(&bins.views, 0, bytemuck::cast_slice(&batch.views));
        self.queue.write_buffer(&bins.ranges, 0, bytemuck::cast_slice(&words));
        self.queue.write_buffer(&bins.members, 0, bytemuck::cast_slice(&batch.members));
        self.queue.write_buffer(&bins.params, 0, bytemuck::bytes_of(&params));
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compute raster"),
            layout: &state.pipelines.layout,
            entries: &[
                entry(0, triangles.positions.as_entire_binding()),
                entry(1, triangles.attributes.as_entire_binding()),
                entry(2, bins.views.as_entire_binding()),
                entry(3, bins.ranges.as_entire_binding()),
                entry(4, bins.members.as_entire_binding()),
                entry(5, bins.counts.as_entire_binding()),
                entry(6, bins.heads.as_entire_binding()),
                entry(7, bins.nodes.as_entire_binding()),
                entry(8, bins.params.as_entire_binding()),
            ],
        });
        let recording = Stopwatch::start();
        let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("compute batch") });
        encoder.clear_buffer(&bins.counts, 0, Some(entry_bytes.max(4)));
        encoder.clear_buffer(&bins.heads, 0, Some(head_bytes));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("compute raster"), timestamp_writes: None });
        pass.set_bind_group(0, &bind, &[]);
        pass.set_pipeline(&state.pipelines.bin);
        // Jobs over two dimensions where they pass one's limit; the shader skips the surplus.
        let across = jobs.clamp(1, d.limits().max_compute_workgroups_per_dimension);
        pass.dispatch_workgroups(across, jobs.div_ceil(across).max(1), 1);
        pass.set_pipeline(&state.pipelines.raster);
        pass.dispatch_workgroups(raster_tiles(batch.side), views as u32, 1);
        drop(pass);
        encoder.copy_buffer_to_buffer(&bins.heads, 0, &bins.readback, 0, 4 * FIRST_HEAD);
        if entry_bytes > 0 {
            encoder.copy_buffer_to_buffer(&bins.counts, 0, &bins.readback, 4 * FIRST_HEAD, entry_bytes);
        }
        let commands = encoder.finish();
        self.stages.recording.fetch_add(recording.nanos(), Ordering::Relaxed);
        self.stages.encoding.fetch_add(encoding.nanos(), Ordering::Relaxed);
        let submitting = Stopwatch::start();
        self.queue.submit([commands]);
        self.stages.submitting.fetch_add(submitting.nanos(), Ordering::Relaxed);
        Ok((bins.readback.clone(), 4 * FIRST_HEAD + entry_bytes))
    }

    /// The compute kernel's raster walk summed over the batches counted since the counter was
    /// made (zeros unless [`super::CounterOptions::walk_stats`], and for the raster kernel).
    pub fn walk_stats(&self) -> WalkStats {
        self.bins().map_or(WalkStats::default(), |b| b.walk)
    }

    /// Nodes the compute kernel's pool holds now, and how many batches were counted again
    /// because it was too small (0, 0 for the raster kernel).
    pub fn bin_pool(&self) -> (u32, u64) {
        self.bins().map_or((0, 0), |b| (b.capacity, b.reruns))
    }

    /// Batches the compute kernel has counted (each one submission, reruns aside) and the views
    /// in them (0, 0 for the raster kernel).
    pub fn compute_batches(&self) -> (u64, u64) {
        self.bins().map_or((0, 0), |b| (b.batches, b.views_counted))
    }

    /// Sets the pool's size and plans no more for it (tests force an overflow with a small one).
    #[cfg(feature = "test-hooks")]
    pub fn set_bin_capacity(&self, nodes: u32) {
        if let Ok(mut bins) = self.bins() {
            let max_views = bins.max_views;
            *bins = ComputeBins::new(&self.device, nodes.max(1));
            bins.per_triangle = 0.0;
            bins.max_views = max_views;
        }
    }

    /// Sets the most views a batch takes (tests cut a count into many batches).
    #[cfg(feature = "test-hooks")]
    pub fn set_batch_views(&self, views: usize) {
        if let Ok(mut bins) = self.bins() {
            bins.max_views = views.max(1);
        }
    }
}

/// Bytes of the members' counts of `entries` entries.
pub(super) fn count_bytes(entries: usize) -> u64 {
    entries as u64 * COUNTS_PER_MEMBER * 4
}

/// Looking inside the compute kernel (the crate's own tests only).
#[cfg(feature = "test-hooks")]
impl Counter {
    /// From now on, also write each pixel's class and coverage of every batch ([`Self::read_dump`]).
    pub fn dump_pixels(&self, on: bool) {
        if let Ok(mut bins) = self.bins() {
            bins.dump = on;
        }
    }

    /// The last batch's pixels, `views` views at side `side`, view after view, row by row: the
    /// class (member k, 7 for a caster, 6 for nothing) | the members covering it << 3.
    pub async fn read_dump(&self, views: usize, side: u32) -> Result<Vec<u32>> {
        if self.compute.is_none() {
            return Ok(Vec::new());
        }
        let heads_per_view = heads_per_view(side) as u64;
        let first = 4 * (FIRST_HEAD + views as u64 * heads_per_view);
        let bytes = 4 * views as u64 * side as u64 * side as u64;
        let target = buffer(&self.device, "dump readback", bytes, READBACK);
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read dump") });
        encoder.copy_buffer_to_buffer(&self.bins()?.heads, first, &target, 0, bytes);
        self.queue.submit([encoder.finish()]);
        let read = platform::read_buffer(&self.device, &target, bytes).await?;
        self.check_errors("reading the compute dump")?;
        // The mapped bytes' Vec need not be aligned for u32: copied, not cast in place.
        Ok(bytemuck::pod_collect_to_vec(&read))
    }

    /// Runs the compute kernel on `triangles` given in the pixels of one view of side `side` (x
    /// right, y down, z the depth in [0, 1]), triangle k carrying receiver id `ids[k]`, counting
    /// `members`: per member (visible, covered, edge pairs), and the pixels as [`Self::read_dump`]
    /// gives them. The pool grows and the view is counted again until its lists fit. A dump walks
    /// every triangle of every tile, so the pixels are the whole picture.
    pub async fn compute_pixels(
        &self,
        triangles: &[[[f32; 3]; 3]],
        ids: &[u32],
        members: &[u32],
        side: u32,
    ) -> Result<(Vec<[u32; 3]>, Vec<u32>)> {
        self.dump_pixels(true);
        let counts = self.count_pixels(triangles, ids, members, side).await;
        let dump = self.read_dump(1, side).await;
        self.dump_pixels(false);
        Ok((counts?, dump?))
    }

    /// [`Self::compute_pixels`]' counts alone, as a count runs: each raster tile stops walking
    /// once none of its pixels shows a member.
    pub async fn compute_counts(&self, triangles: &[[[f32; 3]; 3]], ids: &[u32], members: &[u32], side: u32) -> Result<Vec<[u32; 3]>> {
        self.dump_pixels(false);
        self.count_pixels(triangles, ids, members, side).await
    }

    async fn count_pixels(&self, triangles: &[[[f32; 3]; 3]], ids: &[u32], members: &[u32], side: u32) -> Result<Vec<[u32; 3]>> {
        let positions: Vec<f32> = triangles.iter().flatten().flatten().copied().collect();
        let attributes: Vec<[u32; 4]> = ids.iter().map(|&id| [id, (-1.0f32).to_bits(), 0, 0]).collect();
        let scene = ComputeScene::new(&self.device, &positions, &attributes);
        let s = 2.0 / side as f32;
        let view_proj = glam::Mat4::from_cols(
            glam::Vec4::new(s, 0., 0., 0.),
            glam::Vec4::new(0., -s, 0., 0.),
            glam::Vec4::Z,
            glam::Vec4::new(-1., 1., 0., 1.),
        );
        let mut batch = ComputeBatch::new(side);
        let all = 0..triangles.len() as u32;
        batch.push(view_proj, [0, 0], 1.0, members, std::slice::from_ref(&all));
        let counts = self.run_batch(&scene, &batch).await?.ok_or_else(|| GpuError::Readback("one view over the pool's limit".into()))?;
        Ok(counts.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
    }
}
