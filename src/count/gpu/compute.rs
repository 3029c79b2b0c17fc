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
//! The node pool is sized for the batch ahead; a batch that needed more is counted again with a
//! pool that large (never truncated): [`super::readback`] reads the pool's count with the counts.

use std::ops::Range;
use std::sync::Mutex;

use super::pipelines::{COUNTS_PER_MEMBER, buffer, compute_pipeline, entry, storage_entry, uniform_entry};
use super::plan::{SceneLayout, Tile, tile_origin};
use super::{Counter, GpuScene, Kernel};
use crate::count::ViewRequest;
use crate::error::{GpuError, Result};
use crate::scene::{Scene, shifted_rank};

pub(super) const COMPUTE_RASTER_WGSL: &str = include_str!("../../../shaders/compute_raster.wgsl");
/// Side of the kernel's raster tile (one workgroup), in pixels: the shader's TILE.
pub const RASTER_TILE: u32 = 32;
/// Bits of quantized depth in the kernel's per-pixel word (the low 3 hold the class).
pub const DEPTH_BITS: u32 = 29;
/// Nodes the pool starts with (8 bytes each).
const FIRST_CAPACITY: u32 = 1 << 18;
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
    _pad: [u32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ComputeParams {
    capacity: u32,
    count_edges: u32,
    dump: u32,
    _pad: u32,
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

/// The per-batch buffers, grown as batches need.
pub(super) struct ComputeBins {
    views: wgpu::Buffer,
    ranges: wgpu::Buffer,
    heads: wgpu::Buffer,
    nodes: wgpu::Buffer,
    params: wgpu::Buffer,
    /// Nodes `nodes` holds.
    pub(super) capacity: u32,
    /// Batches counted again because the pool was too small (benchmarks and tests).
    pub(super) reruns: u64,
    /// Tests: write each pixel's class and coverage into `heads` too.
    dump: bool,
}

const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST);

impl ComputeBins {
    pub(super) fn new(device: &wgpu::Device, capacity: u32) -> Self {
        Self {
            views: buffer(device, "compute views", 0, STORAGE),
            ranges: buffer(device, "compute ranges", 0, STORAGE),
            heads: buffer(device, "compute heads", 0, STORAGE | wgpu::BufferUsages::COPY_SRC),
            nodes: buffer(device, "compute nodes", capacity as u64 * 8, STORAGE),
            params: buffer(
                device,
                "compute params",
                size_of::<ComputeParams>() as u64,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            ),
            capacity,
            reruns: 0,
            dump: false,
        }
    }

    /// Grows the pool to hold `needed` nodes (a power of two at least), within `limit` bytes.
    pub(super) fn grow(&mut self, device: &wgpu::Device, needed: u64, limit: u64) -> Result<()> {
        let nodes = needed.next_power_of_two().max(self.capacity as u64);
        if nodes * 8 > limit || nodes > u32::MAX as u64 {
            return Err(GpuError::OverLimit { limit_name: "max_storage_buffer_binding_size", need: nodes * 8, limit }.into());
        }
        self.nodes = buffer(device, "compute nodes", nodes * 8, STORAGE);
        self.capacity = nodes as u32;
        self.reruns += 1;
        Ok(())
    }
}

/// `buf` if it holds `bytes`, else a new buffer twice as large as asked.
fn fit(device: &wgpu::Device, buf: &mut wgpu::Buffer, bytes: u64, label: &str, usage: wgpu::BufferUsages) {
    if buf.size() < bytes {
        *buf = buffer(device, label, bytes * 2, usage);
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

    /// Records the batch's two compute passes; the members' counts land in the batch's counts
    /// buffer as the count pass's do, and the pool's count in `pool` (4 bytes: buffer, offset).
    pub(super) fn encode_compute(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        requests: &[ViewRequest],
        batch: &[Tile],
        side: u32,
        pool: (&wgpu::Buffer, u64),
    ) -> Result<()> {
        let Some(triangles) = scene.compute.as_ref() else { return Ok(()) };
        let per_view = side.div_ceil(RASTER_TILE).pow(2);
        let mut views = Vec::with_capacity(batch.len());
        let mut ranges: Vec<[u32; 2]> = Vec::new();
        let mut first_member = 0u32;
        for (slot, tile) in batch.iter().enumerate() {
            let first_range = ranges.len() as u32;
            let list: Vec<Range<u32>> = scene.layout.culling.list_ranges(&tile.draws);
            ranges.extend(list.iter().filter(|r| !r.is_empty()).map(|r| [r.start, r.len() as u32]));
            views.push(ComputeView {
                view_proj: tile.view.view_proj.as_mat4().to_cols_array_2d(),
                tile: tile_origin(self.atlas_side, slot, side),
                side,
                leaves: requests[tile.requests[0]].leaves,
                first_member,
                member_count: tile.requests.len() as u32,
                first_range,
                range_count: ranges.len() as u32 - first_range,
                first_head: slot as u32 * per_view,
                _pad: [0; 3],
            });
            first_member += tile.requests.len() as u32;
        }
        self.record_compute(encoder, triangles, &views, &ranges, per_view, pool)
    }

    /// Writes a batch's views and ranges and records its bin and raster passes.
    fn record_compute(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        triangles: &ComputeScene,
        views: &[ComputeView],
        ranges: &[[u32; 2]],
        per_view: u32,
        pool: (&wgpu::Buffer, u64),
    ) -> Result<()> {
        let Some(state) = self.compute.as_ref() else { return Ok(()) };
        let mut bins = state.bins.lock().map_err(|_| GpuError::Validation { doing: "binning".into(), message: "poisoned".into() })?;
        let ranges = if ranges.is_empty() { &[[0, 0]][..] } else { ranges };
        let heads = 1 + views.len() as u64 * per_view as u64;
        let side = views.first().map_or(0, |v| v.side) as u64;
        let dump = if bins.dump { heads } else { 0 };
        let head_bytes = 4 * (heads + if bins.dump { views.len() as u64 * side * side } else { 0 });
        let d = &self.device;
        fit(d, &mut bins.views, size_of_val(views) as u64, "compute views", STORAGE);
        fit(d, &mut bins.ranges, size_of_val(ranges) as u64, "compute ranges", STORAGE);
        fit(d, &mut bins.heads, head_bytes, "compute heads", STORAGE | wgpu::BufferUsages::COPY_SRC);
        let params =
            ComputeParams { capacity: bins.capacity, count_edges: self.options.accuracy.is_some() as u32, dump: dump as u32, _pad: 0 };
        self.queue.write_buffer(&bins.views, 0, bytemuck::cast_slice(views));
        self.queue.write_buffer(&bins.ranges, 0, bytemuck::cast_slice(ranges));
        self.queue.write_buffer(&bins.params, 0, bytemuck::bytes_of(&params));
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compute raster"),
            layout: &state.pipelines.layout,
            entries: &[
                entry(0, triangles.positions.as_entire_binding()),
                entry(1, triangles.attributes.as_entire_binding()),
                entry(2, bins.views.as_entire_binding()),
                entry(3, bins.ranges.as_entire_binding()),
                entry(4, self.batch.members.as_entire_binding()),
                entry(5, self.batch.counts.as_entire_binding()),
                entry(6, bins.heads.as_entire_binding()),
                entry(7, bins.nodes.as_entire_binding()),
                entry(8, bins.params.as_entire_binding()),
            ],
        });
        encoder.clear_buffer(&self.batch.counts, 0, None);
        encoder.clear_buffer(&bins.heads, 0, Some(head_bytes));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("compute raster"), timestamp_writes: None });
        pass.set_bind_group(0, &bind, &[]);
        pass.set_pipeline(&state.pipelines.bin);
        pass.dispatch_workgroups(1, views.len() as u32, 1);
        pass.set_pipeline(&state.pipelines.raster);
        pass.dispatch_workgroups(per_view, views.len() as u32, 1);
        drop(pass);
        encoder.copy_buffer_to_buffer(&bins.heads, 0, pool.0, pool.1, 4);
        Ok(())
    }

    /// Nodes the compute kernel's pool holds now, and how many batches were counted again
    /// because it was too small (0, 0 for the raster kernel).
    pub fn bin_pool(&self) -> (u32, u64) {
        self.compute.as_ref().and_then(|c| c.bins.lock().ok().map(|b| (b.capacity, b.reruns))).unwrap_or((0, 0))
    }

    /// Grows the pool after a batch asked for `needed` nodes.
    pub(super) fn grow_pool(&self, needed: u64) -> Result<()> {
        let Some(state) = self.compute.as_ref() else { return Ok(()) };
        let mut bins = state.bins.lock().map_err(|_| GpuError::Validation { doing: "binning".into(), message: "poisoned".into() })?;
        bins.grow(&self.device, needed, self.device.limits().max_storage_buffer_binding_size)
    }

    /// Sets the pool's size (tests force an overflow with a small one).
    #[cfg(feature = "test-hooks")]
    pub fn set_bin_capacity(&self, nodes: u32) {
        if let Some(state) = self.compute.as_ref()
            && let Ok(mut bins) = state.bins.lock()
        {
            *bins = ComputeBins::new(&self.device, nodes.max(1));
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
        if let Some(state) = self.compute.as_ref()
            && let Ok(mut bins) = state.bins.lock()
        {
            bins.dump = on;
        }
    }

    /// The last batch's pixels, `views` views at side `side`, view after view, row by row: the
    /// class (member k, 7 for a caster, 6 for nothing) | the members covering it << 3.
    pub async fn read_dump(&self, views: usize, side: u32) -> Result<Vec<u32>> {
        let Some(state) = self.compute.as_ref() else { return Ok(Vec::new()) };
        let per_view = side.div_ceil(RASTER_TILE).pow(2) as u64;
        let first = 4 * (1 + views as u64 * per_view);
        let bytes = 4 * views as u64 * side as u64 * side as u64;
        let target = buffer(&self.device, "dump readback", bytes, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read dump") });
        {
            let bins = state.bins.lock().map_err(|_| GpuError::Readback("poisoned".into()))?;
            encoder.copy_buffer_to_buffer(&bins.heads, first, &target, 0, bytes);
        }
        self.queue.submit([encoder.finish()]);
        let read = crate::platform::read_buffer(&self.device, &target, bytes).await?;
        self.check_errors("reading the compute dump")?;
        // The mapped bytes' Vec need not be aligned for u32: copied, not cast in place.
        Ok(bytemuck::pod_collect_to_vec(&read))
    }

    /// Runs the compute kernel on `triangles` given in the pixels of one view of side `side` (x
    /// right, y down, z the depth in [0, 1]), triangle k carrying receiver id `ids[k]`, counting
    /// `members`: per member (visible, covered, edge pairs), and the pixels as [`Self::read_dump`]
    /// gives them. The pool grows and the view is counted again until its lists fit.
    pub async fn compute_pixels(
        &self,
        triangles: &[[[f32; 3]; 3]],
        ids: &[u32],
        members: &[u32],
        side: u32,
    ) -> Result<(Vec<[u32; 3]>, Vec<u32>)> {
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
        let view = ComputeView {
            view_proj: view_proj.to_cols_array_2d(),
            tile: [0, 0],
            side,
            leaves: 1.0,
            first_member: 0,
            member_count: members.len() as u32,
            first_range: 0,
            range_count: 1,
            first_head: 0,
            _pad: [0; 3],
        };
        let per_view = side.div_ceil(RASTER_TILE).pow(2);
        self.dump_pixels(true);
        loop {
            self.queue.write_buffer(&self.batch.members, 0, bytemuck::cast_slice(members));
            let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("compute test") });
            self.record_compute(&mut encoder, &scene, &[view], &[[0, triangles.len() as u32]], per_view, (&self.batch.readback, 0))?;
            encoder.copy_buffer_to_buffer(
                &self.batch.counts,
                0,
                &self.batch.readback,
                super::encode::POOL_BYTES,
                count_bytes(members.len()),
            );
            self.queue.submit([encoder.finish()]);
            let read =
                crate::platform::read_buffer(&self.device, &self.batch.readback, super::encode::POOL_BYTES + count_bytes(members.len()))
                    .await?;
            self.check_errors("compute test")?;
            let words: Vec<u32> = bytemuck::pod_collect_to_vec(&read);
            if words[0] > self.bin_pool().0 {
                self.grow_pool(words[0] as u64)?;
                continue;
            }
            let counts = words[super::readback::BATCHES_PER_READBACK..].chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let dump = self.read_dump(1, side).await?;
            self.dump_pixels(false);
            return Ok((counts, dump));
        }
    }
}
