//! Culling on the GPU (shaders/cull_clusters.wgsl): the scene's clusters
//! ([`crate::count::cull::Culling::clusters`], at most 128 triangles each, with boxes) tested
//! against every view of a batch in one compute pass, the kept (view, cluster) pairs compacted
//! into one list, and the indirect draw that would make each pair one instance of a single draw
//! per batch written beside it. What the CPU then does per batch is one dispatch and one draw,
//! not a BVH walk and draws per view.
//!
//! Two forms: one list of every kept pair of a batch in the order the GPU appended them
//! ([`Counter::cull_clusters`], what `sunlit bench --gpu-cull` times and tests hold to a CPU
//! truth), and the form the raster kernel draws from ([`super::pulled`]): each view's pairs in
//! cluster order, one segment and one indirect draw a view.
//!
//! A list too small for a batch is never truncated: the pass counts every pair it needed, the
//! host reads that count back and runs the batch again with a list that large
//! ([`CulledPairs::reruns`]).

use glam::DMat4;

use super::Counter;
use super::pipelines::{buffer, compute_pipeline, entry, storage_entry, uniform_entry};
use crate::count::cull::{CLUSTER_TRIANGLES, Cluster};
use crate::error::{GpuError, Result};
use crate::platform;

pub(super) const CULL_CLUSTERS_WGSL: &str = include_str!("../../../shaders/cull_clusters.wgsl");
/// Invocations a workgroup of the cull pass (the shader's GROUP).
const GROUP: u32 = 64;
/// Bytes of the args buffer: wgpu's DrawIndirectArgs (4 words) and the pairs needed.
const ARGS_BYTES: u64 = 5 * 4;

/// A cluster as the shaders read it (`Cluster` in cull_clusters.wgsl and may_shade.wgsl): its
/// triangles and a box.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuCluster {
    pub(super) lo: [f32; 3],
    pub(super) first: u32,
    pub(super) hi: [f32; 3],
    pub(super) count: u32,
}

/// The first three rows of a view's clip transform (`ClipRows`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuClipRows {
    rows: [[f32; 4]; 3],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CullParams {
    views: u32,
    clusters: u32,
    capacity: u32,
    vertices: u32,
}

/// A scene's clusters on the device, with the pass that culls them: into one list
/// ([`Counter::cull_clusters`]), or per view for the draw ([`super::pulled`]).
pub struct GpuClusters {
    clusters: wgpu::Buffer,
    count: u32,
    layout: wgpu::BindGroupLayout,
    cull: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    /// The per-view form: its layout and its three passes (count, lay out, write).
    view_layout: wgpu::BindGroupLayout,
    view_passes: [wgpu::ComputePipeline; 3],
}

/// The per-view cull pass's buffers for a batch of up to `views` views and `capacity` pairs.
pub(super) struct ViewCullBuffers {
    views: wgpu::Buffer,
    params: wgpu::Buffer,
    /// Each view's kept clusters, view by view (`vec2(view, cluster)`), in cluster order.
    pub(super) pairs: wgpu::Buffer,
    /// Where each view's clusters start in `pairs`.
    pub(super) heads: wgpu::Buffer,
    /// One indirect draw a view.
    pub(super) draws: wgpu::Buffer,
    /// DrawIndirectArgs (unused here) and, at byte 16, the pairs the batch needed.
    pub(super) args: wgpu::Buffer,
    bind: wgpu::BindGroup,
    /// Pairs `pairs` holds.
    pub(super) capacity: u32,
}

/// What the cull pass kept of a batch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CulledPairs {
    /// (view, cluster) pairs, in the order the GPU appended them (not sorted).
    pub pairs: Vec<[u32; 2]>,
    /// The indirect draw as the GPU wrote it: vertex count (3 × [`CLUSTER_TRIANGLES`]), instance
    /// count (the pairs), first vertex, first instance.
    pub draw: [u32; 4],
    /// Times the batch was run again because its list was too small.
    pub reruns: u32,
}

impl GpuClusters {
    /// Uploads `clusters` to `counter`'s device and builds the pass.
    pub fn new(counter: &Counter, clusters: &[Cluster]) -> Self {
        let device = &counter.device;
        let gpu: Vec<GpuCluster> =
            clusters.iter().map(|c| GpuCluster { lo: c.lo.to_array(), first: c.first, hi: c.hi.to_array(), count: c.count }).collect();
        let clusters_buffer = init(device, "clusters", bytemuck::cast_slice(&gpu), wgpu::BufferUsages::STORAGE);
        let cs = wgpu::ShaderStages::COMPUTE;
        let entries = [
            storage_entry(0, cs, true),
            storage_entry(1, cs, true),
            uniform_entry(2, cs),
            storage_entry(3, cs, false),
            storage_entry(4, cs, false),
        ];
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("cull clusters"), entries: &entries });
        let make = |layout, e| compute_pipeline(device, layout, "cull_clusters.wgsl", CULL_CLUSTERS_WGSL, e);
        let view_entries: Vec<_> = entries.iter().cloned().chain((5..8).map(|b| storage_entry(b, cs, false))).collect();
        let view_layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("cull clusters per view"), entries: &view_entries });
        let view_passes = ["view_count_main", "view_layout_main", "view_write_main"].map(|e| make(&view_layout, e));
        Self {
            clusters: clusters_buffer,
            count: clusters.len() as u32,
            cull: make(&layout, "cull_main"),
            finish: make(&layout, "finish_main"),
            layout,
            view_layout,
            view_passes,
        }
    }

    /// The clusters' buffer (`Cluster`s, as the shaders read them).
    pub(super) fn buffer(&self) -> &wgpu::Buffer {
        &self.clusters
    }

    /// Buffers for the per-view pass over batches of up to `views` views, `capacity` pairs.
    pub(super) fn view_buffers(&self, counter: &Counter, views: u32, capacity: u32) -> ViewCullBuffers {
        let d = &counter.device;
        let (storage, copy_dst) = (wgpu::BufferUsages::STORAGE, wgpu::BufferUsages::COPY_DST);
        let rows = buffer(d, "cull views", views as u64 * size_of::<GpuClipRows>() as u64, storage | copy_dst);
        let params = buffer(d, "cull params", size_of::<CullParams>() as u64, wgpu::BufferUsages::UNIFORM | copy_dst);
        let pairs = buffer(d, "culled pairs per view", capacity as u64 * 8, storage);
        // The batch draw's indirect draw and the pairs needed.
        let args = buffer(d, "cull needed", ARGS_BYTES, storage | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::INDIRECT);
        let kept = buffer(d, "kept per view", views as u64 * 4, storage);
        let heads = buffer(d, "view heads", views as u64 * 4, storage);
        let draws = buffer(d, "view draws", views as u64 * 16, storage | wgpu::BufferUsages::INDIRECT);
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cull clusters per view"),
            layout: &self.view_layout,
            entries: &[
                entry(0, self.clusters.as_entire_binding()),
                entry(1, rows.as_entire_binding()),
                entry(2, params.as_entire_binding()),
                entry(3, pairs.as_entire_binding()),
                entry(4, args.as_entire_binding()),
                entry(5, kept.as_entire_binding()),
                entry(6, heads.as_entire_binding()),
                entry(7, draws.as_entire_binding()),
            ],
        });
        ViewCullBuffers { views: rows, params, pairs, heads, draws, args, bind, capacity }
    }

    /// Records the per-view pass over `views` (at most the buffers' views) into `encoder`, each
    /// view's draw `vertices` vertices an instance.
    pub(super) fn encode_view_cull(
        &self,
        counter: &Counter,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &ViewCullBuffers,
        views: &[DMat4],
        vertices: u32,
    ) {
        let rows = clip_rows(views);
        let params = CullParams { views: rows.len() as u32, clusters: self.count, capacity: buffers.capacity, vertices };
        counter.queue.write_buffer(&buffers.views, 0, bytemuck::cast_slice(&rows));
        counter.queue.write_buffer(&buffers.params, 0, bytemuck::bytes_of(&params));
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("cull clusters per view"), timestamp_writes: None });
        pass.set_bind_group(0, &buffers.bind, &[]);
        let [count, layout, write] = &self.view_passes;
        let n = rows.len().max(1) as u32;
        pass.set_pipeline(count);
        pass.dispatch_workgroups(n, 1, 1);
        pass.set_pipeline(layout);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(write);
        pass.dispatch_workgroups(n, 1, 1);
    }
}

/// The first three rows of each view's clip transform, in f32.
fn clip_rows(views: &[DMat4]) -> Vec<GpuClipRows> {
    views
        .iter()
        .map(|m| {
            let t = m.as_mat4().transpose();
            GpuClipRows { rows: [t.x_axis.to_array(), t.y_axis.to_array(), t.z_axis.to_array()] }
        })
        .collect()
}

impl Counter {
    /// Culls `clusters` against every view of `views` (clip transforms of scene coordinates
    /// relative to the origin) on the GPU, starting with room for `capacity` pairs and running
    /// again with as many as were needed when that was too few.
    pub async fn cull_clusters(&self, clusters: &GpuClusters, views: &[DMat4], capacity: u32) -> Result<CulledPairs> {
        let limit = self.device.limits().max_compute_workgroups_per_dimension;
        if views.len() > limit as usize {
            let need = views.len() as u64;
            return Err(GpuError::OverLimit { limit_name: "max_compute_workgroups_per_dimension", need, limit: limit as u64 }.into());
        }
        let rows = clip_rows(views);
        let mut capacity = capacity.max(1);
        let mut reruns = 0;
        loop {
            let (needed, culled) = self.cull_once(clusters, &rows, capacity).await?;
            if needed <= capacity {
                return Ok(CulledPairs { reruns, ..culled });
            }
            let max_pairs = self.device.limits().max_storage_buffer_binding_size / 8;
            if needed as u64 > max_pairs {
                let (need, limit) = (needed as u64 * 8, max_pairs * 8);
                return Err(GpuError::OverLimit { limit_name: "max_storage_buffer_binding_size", need, limit }.into());
            }
            capacity = needed;
            reruns += 1;
        }
    }

    /// One run of the pass with room for `capacity` pairs: the pairs it needed, and what it kept.
    async fn cull_once(&self, clusters: &GpuClusters, rows: &[GpuClipRows], capacity: u32) -> Result<(u32, CulledPairs)> {
        let d = &self.device;
        let params = CullParams { views: rows.len() as u32, clusters: clusters.count, capacity, vertices: 3 * CLUSTER_TRIANGLES };
        let storage = wgpu::BufferUsages::STORAGE;
        let views = init(d, "cull views", bytemuck::cast_slice(rows), storage);
        let params_buffer = init(d, "cull params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let pair_bytes = capacity as u64 * 8;
        let pairs = buffer(d, "culled pairs", pair_bytes, storage | wgpu::BufferUsages::COPY_SRC);
        let args_usage = storage | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC;
        let args = init(d, "cull draw args", &[0u8; ARGS_BYTES as usize], args_usage);
        let readback = buffer(d, "cull readback", ARGS_BYTES + pair_bytes, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cull clusters"),
            layout: &clusters.layout,
            entries: &[
                entry(0, clusters.clusters.as_entire_binding()),
                entry(1, views.as_entire_binding()),
                entry(2, params_buffer.as_entire_binding()),
                entry(3, pairs.as_entire_binding()),
                entry(4, args.as_entire_binding()),
            ],
        });
        let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("cull clusters") });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("cull clusters"), timestamp_writes: None });
        pass.set_bind_group(0, &bind, &[]);
        pass.set_pipeline(&clusters.cull);
        // Clusters over x (and z where they pass one dimension's limit), views over y.
        let groups = clusters.count.div_ceil(GROUP).max(1);
        let across = groups.min(d.limits().max_compute_workgroups_per_dimension);
        pass.dispatch_workgroups(across, rows.len().max(1) as u32, groups.div_ceil(across));
        pass.set_pipeline(&clusters.finish);
        pass.dispatch_workgroups(1, 1, 1);
        drop(pass);
        encoder.copy_buffer_to_buffer(&args, 0, &readback, 0, ARGS_BYTES);
        encoder.copy_buffer_to_buffer(&pairs, 0, &readback, ARGS_BYTES, pair_bytes);
        self.queue.submit([encoder.finish()]);
        let bytes = platform::read_buffer(d, &readback, ARGS_BYTES + pair_bytes).await;
        self.check_errors("culling clusters")?;
        let bytes = bytes?;
        let words: &[u32] = bytemuck::try_cast_slice(&bytes).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
        let (head, rest) = words.split_at(ARGS_BYTES as usize / 4);
        let needed = head[4];
        let kept = needed.min(capacity) as usize;
        let pairs = rest.chunks_exact(2).take(kept).map(|p| [p[0], p[1]]).collect();
        Ok((needed, CulledPairs { pairs, draw: [head[0], head[1], head[2], head[3]], reruns: 0 }))
    }
}

pub(super) fn init(device: &wgpu::Device, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    // A binding may not be empty.
    let contents = if contents.is_empty() { &[0u8; 16][..] } else { contents };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
}
