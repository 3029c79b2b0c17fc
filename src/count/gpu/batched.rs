//! One draw a batch (with the GPU's culling and [`super::CounterOptions::batch_draw`]): the masks of
//! every tile of a batch in one instanced draw, and its scene in one indirect draw whose
//! instances are the culling's (view, cluster) pairs of the whole batch (`vs_batch_mask` and
//! `vs_batch` in shaders/sun_view.wgsl). The whole atlas is the viewport: each corner is placed
//! as in the tile's own draw (the same `shade_at`, so mask and scene share their positions bit
//! for bit, `@invariant`) and moved into its tile by whole subpixels, and fragments outside the
//! tile are discarded (`fs_tiled`), so every pixel is the one the tile's own viewport and scissor
//! give. What the host records a batch is then a handful of commands, not a viewport, a bind
//! group, the members' masks and an indirect draw a tile.
//!
//! On lavapipe the counts equal the per-tile draws' pixel for pixel and texel for texel on
//! blaas-buildings and on placed see-through trees, but not everywhere: on blaas-louvres' 3×5
//! year at 64², 55 of the 620 views count one pixel more or fewer lit (the covered counts
//! equal), and 16 grazing views one form renders fully lit the other settles unrendered as
//! unshaded (fraction 1 both). The cause is the tile's viewport, not depth: lavapipe clips x and
//! y at the viewport (no guard band while a depth buffer is bound), so the per-tile draws cut
//! every caster crossing the tile's edge with corners interpolated in the tile's clip
//! coordinates, where this draw's viewport is the atlas; a re-snapped clipped edge moves a pixel
//! centre lying within a rounding of it. Given the atlas as their viewport, the per-tile draws
//! count exactly these pixels, but then a view's pixels depend on its atlas slot (clipped at the
//! atlas's edges, as this draw is: counted in reverse order, 16 of those 620 views change
//! fraction here and none with the per-tile draws). One draw cannot clip at each tile's edge, so
//! the forms stay a lit pixel apart on lavapipe and this is not the default (tests/gpu_cull.rs;
//! docs/benchmarks-gpu.md).
//!
//! The tile clip is a fragment discard on every adapter. `clip_distances` would spare the
//! rasterizer the fragments outside the tile, but its new corners on the tile's edges would be
//! interpolated in the atlas's clip coordinates, not the tile's as lavapipe's viewport clip does
//! (so still not the same roundings), and an adapter with a guard band makes no such corners at
//! all: not used (not tried either).
//!
//! One instanced draw and one indirect draw are core WebGPU: the same form natively and in the
//! browser (multi-draw adds nothing where one draw already holds every pair). Where it is not
//! used, the per-tile draws count ([`super::pulled`]): members' triangles that do not fit the
//! batch's mask list (a batch at a time), or a device with fewer than 8 storage buffers a stage.

use std::ops::Range;

use super::pipelines::{Pipelines, batch_view_pipeline, buffer, entry, storage_entry};
use super::plan::{ReceiverView, Tile, tile_origin};
use super::{Counter, GpuScene};
use crate::count::ViewRequest;
use crate::count::cull::CLUSTER_TRIANGLES;
use crate::count::group::MAX_MEMBERS;

/// A run's mesh and its placements' slots.
pub(super) type RunPlacements = (usize, Range<u32>);

/// Mask items a batch's list holds at most (32 bytes each).
const MOST_ITEMS: u64 = 1 << 18;

/// A view as `vs_batch` reads it (`BatchView` in sun_view.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuBatchView {
    view_proj: [[f32; 4]; 4],
    leaves: f32,
    snap: f32,
    side: f32,
    atlas: f32,
    origin: [f32; 2],
    _pad: [f32; 2],
}

/// Triangles of one placement of a run, a member's mask in one view (`MaskItem`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuMaskItem {
    view: u32,
    run: u32,
    first: u32,
    count: u32,
    placement: u32,
    _pad: [u32; 3],
}

/// The batch draw's pipelines and the layouts of groups 1 (views; and mask items) and 2 (what
/// the scene and the mask pull their corners from).
pub(super) struct BatchPipelines {
    views_layout: wgpu::BindGroupLayout,
    mask_views_layout: wgpu::BindGroupLayout,
    scene_layout: wgpu::BindGroupLayout,
    mask_layout: wgpu::BindGroupLayout,
    scene: wgpu::RenderPipeline,
    mask: wgpu::RenderPipeline,
}

impl BatchPipelines {
    pub(super) fn new(device: &wgpu::Device, pipelines: &Pipelines) -> Self {
        let layout = |label, bindings: &[u32]| {
            let entries: Vec<_> = bindings.iter().map(|&b| storage_entry(b, wgpu::ShaderStages::VERTEX, true)).collect();
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
        };
        // Bindings as sun_view.wgsl declares them: group 1 views (1) and mask items (2); group 2
        // the pulled draw's, but the per-view heads (1) the batch draw does not read.
        let views_layout = layout("batch views", &[1]);
        let mask_views_layout = layout("batch views and masks", &[1, 2]);
        let scene_layout = layout("batch scene corners", &[0, 2, 3, 4, 5, 6]);
        let mask_layout = layout("batch mask corners", &[4, 5, 6]);
        let scene = batch_view_pipeline(device, pipelines, [&views_layout, &scene_layout], "vs_batch", true);
        let mask = batch_view_pipeline(device, pipelines, [&mask_views_layout, &mask_layout], "vs_batch_mask", false);
        Self { views_layout, mask_views_layout, scene_layout, mask_layout, scene, mask }
    }
}

/// The pulled scene's buffers that the batch draw binds (made by `upload_pulled`).
pub(super) struct PulledBuffers<'a> {
    pub(super) pairs: &'a wgpu::Buffer,
    pub(super) clusters: &'a wgpu::Buffer,
    pub(super) cluster_runs: &'a wgpu::Buffer,
    pub(super) runs: &'a wgpu::Buffer,
    pub(super) vertices: &'a wgpu::Buffer,
    pub(super) indices: &'a wgpu::Buffer,
}

/// A scene's batch draw: each receiver's mask items (view 0), the per-batch views and items,
/// and the bind groups.
pub(super) struct BatchScene {
    /// Receiver `r`'s mask items are `items[of_receiver[r]]`.
    items: Vec<GpuMaskItem>,
    of_receiver: Vec<Range<u32>>,
    views: wgpu::Buffer,
    batch_items: wgpu::Buffer,
    item_capacity: usize,
    views_bind: wgpu::BindGroup,
    mask_views_bind: wgpu::BindGroup,
    scene_bind: wgpu::BindGroup,
    mask_bind: wgpu::BindGroup,
}

/// The mask items of a receiver: its triangles as ranges of its run's placement `slot`, at most
/// [`CLUSTER_TRIANGLES`] a range. `runs[i]`: run `i`'s mesh, first placement slot and slots.
pub(super) fn receiver_items(r: &ReceiverView, runs: &[RunPlacements]) -> Vec<GpuMaskItem> {
    let found = runs.iter().position(|(mesh, slots)| *mesh == r.mesh && slots.contains(&r.slot));
    let Some(run) = found else { return Vec::new() };
    // The static mesh's triangles by position in the culling's order; a placed mesh's by index.
    let own = r.indices.start / 3..r.indices.end / 3;
    let ranges = if r.static_triangles.is_empty() { std::slice::from_ref(&own) } else { &r.static_triangles[..] };
    let placement = r.slot - runs[run].1.start;
    let mut items = Vec::new();
    for range in ranges.iter().cloned() {
        let mut first = range.start;
        while first < range.end {
            let count = (range.end - first).min(CLUSTER_TRIANGLES);
            items.push(GpuMaskItem { view: 0, run: run as u32, first, count, placement, _pad: [0; 3] });
            first += count;
        }
    }
    items
}

impl Counter {
    /// The batch draw's state for a scene culled on the GPU (`None` where this counter does not
    /// draw by batch).
    pub(super) fn upload_batched(
        &self,
        receivers: &[ReceiverView],
        runs: &[RunPlacements],
        pulled: PulledBuffers<'_>,
    ) -> Option<BatchScene> {
        let pipelines = self.pulled.as_ref()?.batch.as_ref()?;
        let d = &self.device;
        let (mut items, mut of_receiver) = (Vec::new(), Vec::with_capacity(receivers.len()));
        let mut most = 0;
        for r in receivers {
            let start = items.len() as u32;
            items.extend(receiver_items(r, runs));
            most = most.max(items.len() - start as usize);
            of_receiver.push(start..items.len() as u32);
        }
        let tiles = self.batch_tiles() as u64;
        let item_capacity = (tiles * MAX_MEMBERS as u64 * most.max(1) as u64).min(MOST_ITEMS) as usize;
        let (storage, copy_dst) = (wgpu::BufferUsages::STORAGE, wgpu::BufferUsages::COPY_DST);
        let views = buffer(d, "batch views", tiles * size_of::<GpuBatchView>() as u64, storage | copy_dst);
        let batch_items = buffer(d, "batch mask items", item_capacity as u64 * size_of::<GpuMaskItem>() as u64, storage | copy_dst);
        let bind = |label, layout, entries: &[wgpu::BindGroupEntry<'_>]| {
            d.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries })
        };
        let views_bind = bind("batch views", &pipelines.views_layout, &[entry(1, views.as_entire_binding())]);
        let mask_views_bind = bind(
            "batch views and masks",
            &pipelines.mask_views_layout,
            &[entry(1, views.as_entire_binding()), entry(2, batch_items.as_entire_binding())],
        );
        let corners = [
            entry(4, pulled.runs.as_entire_binding()),
            entry(5, pulled.vertices.as_entire_binding()),
            entry(6, pulled.indices.as_entire_binding()),
        ];
        let mut scene_entries = vec![
            entry(0, pulled.pairs.as_entire_binding()),
            entry(2, pulled.clusters.as_entire_binding()),
            entry(3, pulled.cluster_runs.as_entire_binding()),
        ];
        scene_entries.extend(corners.iter().cloned());
        let scene_bind = bind("batch scene corners", &pipelines.scene_layout, &scene_entries);
        let mask_bind = bind("batch mask corners", &pipelines.mask_layout, &corners);
        Some(BatchScene { items, of_receiver, views, batch_items, item_capacity, views_bind, mask_views_bind, scene_bind, mask_bind })
    }

    /// Draws `batch` (every tile culled on the GPU) at `side` with one mask draw and one scene
    /// draw, its views and mask items written first; `false` (nothing recorded) where the
    /// batch's mask items do not fit its list, for the per-tile draws to count it.
    pub(super) fn draw_batch(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &GpuScene,
        requests: &[ViewRequest],
        batch: &[Tile],
        side: u32,
    ) -> bool {
        let (Some(pulled), Some(pipelines)) = (scene.pulled.as_ref(), self.pulled.as_ref().and_then(|p| p.batch.as_ref())) else {
            return false;
        };
        let Some(state) = pulled.batched.as_ref() else { return false };
        let (mut views, mut items) = (Vec::with_capacity(batch.len()), Vec::new());
        let snap = super::pipelines::subpixels_per_half_tile(side);
        for (slot, tile) in batch.iter().enumerate() {
            let [x, y] = tile_origin(self.atlas_side, slot, side);
            views.push(GpuBatchView {
                view_proj: tile.view.view_proj.as_mat4().to_cols_array_2d(),
                leaves: requests[tile.requests[0]].leaves,
                snap,
                side: side as f32,
                atlas: self.atlas_side as f32,
                origin: [x as f32, y as f32],
                _pad: [0.0; 2],
            });
            for &i in &tile.requests {
                let mine = state.of_receiver[requests[i].receiver as usize].clone();
                items.extend(state.items[mine.start as usize..mine.end as usize].iter().map(|&m| GpuMaskItem { view: slot as u32, ..m }));
            }
        }
        if items.len() > state.item_capacity {
            return false;
        }
        self.queue.write_buffer(&state.views, 0, bytemuck::cast_slice(&views));
        self.queue.write_buffer(&state.batch_items, 0, bytemuck::cast_slice(&items));
        // The members alone first (their coverage), then what the culling kept, depth-tested.
        let most = items.iter().map(|m| m.count).max().unwrap_or(0);
        pass.set_pipeline(&pipelines.mask);
        pass.set_bind_group(1, &state.mask_views_bind, &[]);
        pass.set_bind_group(2, &state.mask_bind, &[]);
        pass.draw(0..3 * most, 0..items.len() as u32);
        pass.set_pipeline(&pipelines.scene);
        pass.set_bind_group(1, &state.views_bind, &[]);
        pass.set_bind_group(2, &state.scene_bind, &[]);
        pass.draw_indirect(&pulled.batch.args, 0);
        true
    }
}

impl Counter {
    /// Whether `scene`'s batches are drawn with one draw each: culled on the GPU, and this
    /// counter and scene have the batch draw (tests and benchmarks say which path they measured).
    pub fn draws_by_batch_for(&self, scene: &GpuScene) -> bool {
        self.culls_on_gpu(scene) && scene.pulled.as_ref().is_some_and(|p| p.batched.is_some())
    }
}
