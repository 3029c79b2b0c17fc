//! Counting with the GPU's culling ([`super::CounterOptions::gpu_cull`], the raster kernel): the
//! host fits each tile's view and nothing more; per batch, the culling pass
//! ([`super::cluster_cull`], its per-view form) writes each tile's kept clusters in triangle
//! order and one indirect draw a tile, and the scene pass draws each tile with that one draw
//! (`vs_pulled` in shaders/sun_view.wgsl), its triangles' corners pulled from storage. What the
//! host records per tile is its viewport, its members' masks and one indirect draw from a
//! single buffer, instead of a BVH walk and a draw per merged range.
//!
//! With [`super::CounterOptions::batch_draw`] (the default) a batch is drawn by one draw
//! instead ([`super::batched`]), each tile placed in the atlas by the vertex shader; the per-tile
//! draws here remain for batches that form does not take.
//!
//! Where it is not used (the reason logged once, the CPU's culling counting instead): an adapter
//! without indirect draws or storage buffers in vertex shaders, fewer than 8 storage buffers a
//! stage, or a scene whose corners do not fit one storage binding. A batch whose pair list
//! overflows is counted again with the CPU's culling ([`Counter::count_tiles`]): never
//! truncated.

use super::batched::{BatchPipelines, BatchScene, PulledBuffers, RunPlacements};
use super::cluster_cull::GpuClusters;
use super::pipelines::{GpuVertex, Pipelines, buffer, entry, pulled_scene_pipeline, storage_entry};
use super::plan::{SceneLayout, Tile, shade_test};
use super::readback::BATCHES_PER_READBACK;
use super::shade::{ShadePass, ShadeScene};
use super::upload::{distinct_vertices, gpu_vertices};
use super::{Counter, GpuScene};
use crate::count::ViewRequest;
use crate::count::cull::{CLUSTER_TRIANGLES, ShadeTest, TriangleRun};
use crate::scene::Scene;

/// Pairs a scene's list holds at most (8 bytes each): far more than a batch keeps on the bench
/// models (nyt-blocks: ~160 a view, 1,024 views a batch at 64²).
const MOST_PAIRS: u64 = 1 << 22;
/// Storage buffers `vs_pulled` reads: the instances and the seven of the pulled bind group.
const VERTEX_STORAGE_BUFFERS: u32 = 8;

/// A run as `vs_pulled` reads it (`Run` in sun_view.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuRun {
    first: u32,
    per_instance: u32,
    first_slot: u32,
    index_base: u32,
    vertex_base: u32,
    placed: u32,
    _pad: [u32; 2],
}

/// The pulled scene pipeline and its bind group layout, where the adapter can run them, and
/// the shading test's pass.
pub(super) struct PulledPipelines {
    layout: wgpu::BindGroupLayout,
    pub(super) scene: wgpu::RenderPipeline,
    shade: ShadePass,
    /// The batch draw's (`None` without [`super::CounterOptions::batch_draw`]).
    pub(super) batch: Option<BatchPipelines>,
}

impl PulledPipelines {
    /// `None`, the reason logged, where the adapter lacks what the pulled draw needs.
    pub(super) fn new(device: &wgpu::Device, pipelines: &Pipelines, downlevel: wgpu::DownlevelFlags, batch_draw: bool) -> Option<Self> {
        let stage_buffers = device.limits().max_storage_buffers_per_shader_stage;
        let missing = if !downlevel.contains(wgpu::DownlevelFlags::INDIRECT_EXECUTION) {
            Some("indirect draws".to_string())
        } else if !downlevel.contains(wgpu::DownlevelFlags::VERTEX_STORAGE) {
            Some("storage buffers in vertex shaders".to_string())
        } else if stage_buffers < VERTEX_STORAGE_BUFFERS {
            Some(format!("{VERTEX_STORAGE_BUFFERS} storage buffers a stage (it has {stage_buffers})"))
        } else {
            None
        };
        if let Some(missing) = missing {
            log::warn!("GPU culling dropped: this adapter has no {missing}; culling on the CPU");
            return None;
        }
        let vs = wgpu::ShaderStages::VERTEX;
        let entries: Vec<_> = (0..7).map(|b| storage_entry(b, vs, true)).collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("pulled"), entries: &entries });
        let scene = pulled_scene_pipeline(device, pipelines, &layout);
        let batch = batch_draw.then(|| BatchPipelines::new(device, pipelines));
        Some(Self { layout, scene, shade: ShadePass::new(device), batch })
    }
}

/// A scene's clusters, corners and per-batch culling buffers on the device.
pub(super) struct PulledScene {
    pub(super) clusters: GpuClusters,
    /// Group 2 of the pulled scene pipeline.
    pub(super) bind: wgpu::BindGroup,
    /// The cull pass's buffers for a batch.
    pub(super) batch: super::cluster_cull::ViewCullBuffers,
    /// What the host reads of a chunk's batches: each batch's pairs needed (one word a batch,
    /// [`BATCHES_PER_READBACK`] words), then each batch's views' shading verdicts (the batch's
    /// tiles' words each).
    pub(super) answers: wgpu::Buffer,
    /// Tiles a batch holds at most (words of verdicts a batch in `answers`).
    pub(super) tiles: usize,
    /// The shading test's buffers (`None` where the corners do not fit: the CPU tests).
    pub(super) shade: Option<ShadeScene>,
    /// The batch draw's state (`None` where this counter draws a tile at a time).
    pub(super) batched: Option<BatchScene>,
}

impl Counter {
    /// The scene's clusters and corners for the GPU's culling, or `None` (the reason logged)
    /// where this counter does not cull on the GPU or the scene does not fit its bindings.
    /// `pairs`: room for that many (view, cluster) pairs a batch instead of the default.
    pub(super) fn upload_pulled(&self, scene: &Scene, layout: &SceneLayout, pairs: Option<u32>) -> Option<PulledScene> {
        let pipelines = self.pulled.as_ref()?;
        let d = &self.device;
        let (vertices, indices, runs, run_meshes) = pulled_geometry(scene, layout);
        let limits = d.limits();
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let need = (vertices.len() * size_of::<GpuVertex>()).max(indices.len() * 4) as u64;
        if need > binding {
            log::warn!(
                "GPU culling dropped: the scene's corners need {need} bytes in one storage binding, over this device's {binding}; \
                 culling on the CPU"
            );
            return None;
        }
        let clusters = layout.culling.clusters();
        let cluster_runs: Vec<u32> =
            clusters.iter().map(|c| runs.partition_point(|r| r.first <= c.first).saturating_sub(1) as u32).collect();
        let tiles = self.batch_tiles() as u64;
        let default = (tiles * clusters.len() as u64).min(MOST_PAIRS).min(binding / 8) as u32;
        let capacity = pairs.unwrap_or(default).max(1);
        let clusters_on_device = GpuClusters::new(self, &clusters);
        let batch = clusters_on_device.view_buffers(self, tiles as u32, capacity);
        let storage = wgpu::BufferUsages::STORAGE;
        let init = |label, bytes: &[u8]| super::cluster_cull::init(d, label, bytes, storage);
        let (vertex_buffer, index_buffer) =
            (init("pulled vertices", bytemuck::cast_slice(&vertices)), init("pulled indices", bytemuck::cast_slice(&indices)));
        let (runs_buffer, cluster_runs_buffer) =
            (init("runs", bytemuck::cast_slice(&runs)), init("cluster runs", bytemuck::cast_slice(&cluster_runs)));
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pulled"),
            layout: &pipelines.layout,
            entries: &[
                entry(0, batch.pairs.as_entire_binding()),
                entry(1, batch.heads.as_entire_binding()),
                entry(2, clusters_on_device.buffer().as_entire_binding()),
                entry(3, cluster_runs_buffer.as_entire_binding()),
                entry(4, runs_buffer.as_entire_binding()),
                entry(5, vertex_buffer.as_entire_binding()),
                entry(6, index_buffer.as_entire_binding()),
            ],
        });
        let answer_bytes = 4 * BATCHES_PER_READBACK as u64 * (1 + tiles);
        let answers = buffer(d, "culling answers", answer_bytes, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let shade = ShadeScene::new(d, &pipelines.shade, &layout.culling, tiles as u32);
        let tested = if shade.is_some() { "on the GPU" } else { "on the CPU" };
        let corners = PulledBuffers {
            pairs: &batch.pairs,
            clusters: clusters_on_device.buffer(),
            cluster_runs: &cluster_runs_buffer,
            runs: &runs_buffer,
            vertices: &vertex_buffer,
            indices: &index_buffer,
        };
        let batched = self.upload_batched(&layout.receivers, &run_meshes, corners);
        let drawn = if batched.is_some() { "one draw a batch" } else { "one draw a tile" };
        log::info!("culling on the GPU: {} clusters, {capacity} pairs a batch; shading test {tested}; {drawn}", clusters.len());
        Some(PulledScene { clusters: clusters_on_device, bind, batch, answers, tiles: tiles as usize, shade, batched })
    }

    /// Whether `tiles` are counted with the GPU's culling: this counter and scene have it, and
    /// the raster kernel counts them.
    pub(super) fn culls_on_gpu(&self, scene: &GpuScene) -> bool {
        self.pulled.is_some() && scene.pulled.is_some() && !self.counts_by_compute(scene, false)
    }

    /// Whether `scene`'s views are culled on the GPU: the option, the adapter and the scene
    /// allow it (benchmarks and tests say which path they measured).
    pub fn culls_on_gpu_for(&self, scene: &GpuScene) -> bool {
        self.culls_on_gpu(scene)
    }

    /// Records the culling pass and the shading test for `batch` (tile `slot` is view `slot`),
    /// the `at`th batch of its readback chunk: its pairs needed copied to word `at` of the
    /// scene's `answers`, its verdicts to its place after them.
    pub(super) fn encode_gpu_cull(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        pulled: &PulledScene,
        requests: &[ViewRequest],
        batch: &[Tile],
        at: usize,
    ) {
        let views: Vec<glam::DMat4> = batch.iter().map(|t| t.view.view_proj).collect();
        pulled.clusters.encode_view_cull(self, encoder, &pulled.batch, &views, 3 * CLUSTER_TRIANGLES);
        encoder.copy_buffer_to_buffer(&pulled.batch.args, 16, &pulled.answers, at as u64 * 4, 4);
        let (Some(shade), Some(pipelines)) = (pulled.shade.as_ref(), self.pulled.as_ref()) else { return };
        let tests: Vec<ShadeTest> = batch.iter().map(|t| shade_test(&scene.layout, requests, &t.requests, &t.view)).collect();
        shade.encode(self, &pipelines.shade, encoder, &tests);
        let verdicts_at = 4 * (BATCHES_PER_READBACK + at * pulled.tiles) as u64;
        encoder.copy_buffer_to_buffer(&shade.verdicts, 0, &pulled.answers, verdicts_at, 4 * batch.len() as u64);
    }

    /// Draws tile `slot`'s casters as the GPU's culling kept them: one indirect draw.
    pub(super) fn draw_gpu_culled(&self, pass: &mut wgpu::RenderPass<'_>, pulled: &PulledScene, slot: usize) {
        let Some(pipelines) = self.pulled.as_ref() else { return };
        pass.set_pipeline(&pipelines.scene);
        pass.set_bind_group(2, &pulled.bind, &[]);
        pass.draw_indirect(&pulled.batch.draws, slot as u64 * 16);
    }
}

/// Every run's corners as `vs_pulled` reads them: the vertices and indices of the static mesh
/// (its triangles in the culling's order, indexed into their distinct vertices, as the static
/// chunks hold them) and of each shared mesh (as its vertex and index buffers hold them), and the
/// runs pointing into them, with each run's mesh and placements' slots.
fn pulled_geometry(scene: &Scene, layout: &SceneLayout) -> (Vec<GpuVertex>, Vec<u32>, Vec<GpuRun>, Vec<RunPlacements>) {
    let (mut vertices, mut indices, mut runs, mut run_meshes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for run in layout.culling.runs() {
        let TriangleRun { mesh, first, per_instance, ref slots } = run;
        let Some(m) = scene.meshes.get(mesh) else { continue };
        let (index_base, vertex_base) = (indices.len() as u32, vertices.len() as u32);
        if mesh == 0 {
            let order = layout.culling.static_order();
            let corners = order.iter().flat_map(|&t| (0..3).map(move |k| m.indices[3 * t as usize + k]));
            let (v, i) = distinct_vertices(corners.map(|v| super::upload::gpu_vertex(m, v as usize)));
            vertices.extend(v);
            indices.extend(i);
        } else {
            vertices.extend(gpu_vertices(m, 0..m.positions.len()));
            indices.extend_from_slice(&m.indices);
        }
        let placed = (mesh != 0) as u32;
        runs.push(GpuRun { first, per_instance, first_slot: slots.start, index_base, vertex_base, placed, _pad: [0; 2] });
        run_meshes.push((mesh, slots.clone()));
    }
    (vertices, indices, runs, run_meshes)
}
