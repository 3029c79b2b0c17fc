//! Culling on the GPU (shaders/cull_clusters.wgsl): the scene's clusters
//! ([`crate::count::cull::Culling::clusters`], at most 128 triangles each, with boxes) tested
//! against every view of a batch in one compute pass, the kept (view, cluster) pairs compacted
//! into one list, and the indirect draw that would make each pair one instance of a single draw
//! per batch written beside it. What the CPU then does per batch is one dispatch and one draw,
//! not a BVH walk and draws per view.
//!
//! Status: the pass, its overflow handling and its CPU truth are built and tested
//! (tests/cluster_cull.rs); the raster kernel does not draw from its list yet (the vertex-pulling
//! draw per batch is not built), so no count depends on it.
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

/// A cluster as the shader reads it (`Cluster` in cull_clusters.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuCluster {
    lo: [f32; 3],
    first: u32,
    hi: [f32; 3],
    count: u32,
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

/// A scene's clusters on the device, with the pass that culls them.
pub struct GpuClusters {
    clusters: wgpu::Buffer,
    count: u32,
    layout: wgpu::BindGroupLayout,
    cull: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
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
        let make = |e| compute_pipeline(device, &layout, "cull_clusters.wgsl", CULL_CLUSTERS_WGSL, e);
        Self { clusters: clusters_buffer, count: clusters.len() as u32, cull: make("cull_main"), finish: make("finish_main"), layout }
    }
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
        let rows: Vec<GpuClipRows> = views
            .iter()
            .map(|m| {
                let t = m.as_mat4().transpose();
                GpuClipRows { rows: [t.x_axis.to_array(), t.y_axis.to_array(), t.z_axis.to_array()] }
            })
            .collect();
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

fn init(device: &wgpu::Device, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    // A binding may not be empty.
    let contents = if contents.is_empty() { &[0u8; 16][..] } else { contents };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
}
