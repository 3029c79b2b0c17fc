//! The CPU culling's shading test on the GPU (shaders/may_shade.wgsl): per view, whether anything
//! the view draws can shade its receiver ([`crate::count::cull::Culling::may_be_shaded`]), so
//! that with the GPU's culling ([`super::pulled`]) the host does no per-view geometric work.
//!
//! A view that nothing can shade gets fraction 1 without its render's count, as the CPU path
//! gives it (a view rendered at a grazing sun can lose an edge pixel of its receiver to a
//! neighbour, so the render's count is not always 1). The CPU decides in f64 on the scene's f32
//! corners; the pass reads the same corners and ids and computes in f32, so it answers
//! [`ShadeVerdict::Nothing`] or [`ShadeVerdict::Shaded`] only where every f32 rounding, bounded,
//! cannot change the CPU's answer, and [`ShadeVerdict::Undecided`] otherwise: the host runs the
//! CPU's test for those views alone. The counts stay the CPU path's exactly.
//!
//! The error bounds (shaders/may_shade.wgsl, in units of u = 2⁻²⁴, f32's unit roundoff, each
//! at least twice what the roundings add up to; they only widen the undecided band). With
//! `base` = |p0|∞ and `near` the triangle's largest |corner − p0|∞: p0 and the normal are rounded
//! to f32, the difference takes one rounding and the height three products and two sums, so
//! |δh| ≤ 2u·base + 10u·near (`err_h` = u·(4 base + 20 near + 2 eps)). The shadow divides the
//! height by `along` (2.5 ulp, `along` rounded), subtracts `sun`·s from the difference and takes a
//! dot product with a rounded axis: |δq| ≤ 1.8 |δh| / along + u·(1.8 base + 12 near + 21 |s|),
//! bounded by 2 err_h / along + u·(4 base + 24 near + 42 |s| + 4 box) (the receiver's box rounded
//! too). A clip row's interval over a box takes the rounded row and about six roundings of terms
//! no larger than |row|·(|centre| + half) + |w| (u·32 of that). Where `along` is below 10⁻³ the
//! host decides. The heights matter most: coplanar neighbours (the wall around a window) are told
//! apart from casters by `eps` (10⁻⁶ of the scene's extent), so the bound on δh must stay below
//! it. `tests/gpu_cull.rs` holds every decided view of three bench models' years to the CPU's
//! answer and bounds the undecided.
use std::sync::atomic::Ordering;

use super::cluster_cull::{GpuCluster, init};
use super::pipelines::{buffer, compute_pipeline, entry, storage_entry, uniform_entry};
use super::{Counter, GpuScene};
use crate::count::cull::{Culling, ShadeTest};
use crate::error::{GpuError, Result};
use crate::platform;

pub(super) const MAY_SHADE_WGSL: &str = include_str!("../../../shaders/may_shade.wgsl");

/// What the GPU's test says of a view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShadeVerdict {
    /// Nothing it draws can shade its receiver (the CPU's test is false): fraction 1.
    Nothing,
    /// f32 cannot decide: the host runs the CPU's test.
    Undecided,
    /// Something can (the CPU's test is true): the render's count stands.
    Shaded,
}

impl ShadeVerdict {
    pub(super) fn from_word(word: u32) -> Self {
        match word {
            0 => Self::Nothing,
            2 => Self::Shaded,
            _ => Self::Undecided,
        }
    }
}

/// [`ShadeTest`] as the shader reads it (`ShadeView`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuShadeView {
    rows: [[f32; 4]; 3],
    p0: [f32; 3],
    own: u32,
    normal: [f32; 3],
    along: f32,
    u: [f32; 3],
    eps: f32,
    v: [f32; 3],
    box_size: f32,
    sun: [f32; 3],
    _pad: u32,
    lo: [f32; 2],
    hi: [f32; 2],
}

impl From<&ShadeTest> for GpuShadeView {
    fn from(t: &ShadeTest) -> Self {
        let f3 = |v: glam::DVec3| v.as_vec3().to_array();
        let box_size = t.lo.abs().max(t.hi.abs()).max_element() as f32;
        Self {
            rows: t.clip_rows.map(|r| r.map(|x| x as f32)),
            p0: f3(t.p0),
            own: t.own,
            normal: f3(t.normal),
            along: t.along as f32,
            u: f3(t.u),
            eps: t.eps as f32,
            v: f3(t.v),
            box_size,
            sun: f3(t.sun),
            _pad: 0,
            lo: t.lo.as_vec2().to_array(),
            hi: t.hi.as_vec2().to_array(),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadeParams {
    views: u32,
    clusters: u32,
    _pad: [u32; 2],
}

/// The pass's pipeline and bind group layout.
pub(super) struct ShadePass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ShadePass {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let cs = wgpu::ShaderStages::COMPUTE;
        let entries = [
            storage_entry(0, cs, true),
            storage_entry(1, cs, true),
            storage_entry(2, cs, true),
            storage_entry(3, cs, true),
            uniform_entry(4, cs),
            storage_entry(5, cs, false),
        ];
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("may shade"), entries: &entries });
        let pipeline = compute_pipeline(device, &layout, "may_shade.wgsl", MAY_SHADE_WGSL, "may_shade_main");
        Self { layout, pipeline }
    }
}

/// A scene's clusters, corners and ids for the pass, with its per-batch buffers.
pub(super) struct ShadeScene {
    clusters: u32,
    views: wgpu::Buffer,
    params: wgpu::Buffer,
    /// One word a view of the batch (0 nothing, 1 undecided, 2 shaded).
    pub(super) verdicts: wgpu::Buffer,
    bind: wgpu::BindGroup,
}

impl ShadeScene {
    /// Uploads `culling`'s clusters, corners and ids for batches of up to `views` views, or
    /// `None` (the reason logged) where the corners do not fit one storage binding.
    pub(super) fn new(device: &wgpu::Device, pass: &ShadePass, culling: &Culling, views: u32) -> Option<Self> {
        let (triangles, ids) = culling.triangles();
        let limits = device.limits();
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let need = triangles.len() as u64 * 36;
        if need > binding {
            log::warn!(
                "GPU shading test dropped: the scene's corners need {need} bytes in one storage binding, over this device's {binding}; \
                 the CPU tests the views the GPU's culling leaves not fully lit"
            );
            return None;
        }
        // Each cluster with the box of the BVH node it was cut from.
        let reach: Vec<GpuCluster> = culling
            .clusters_and_reach()
            .iter()
            .map(|(c, [lo, hi])| GpuCluster { lo: lo.to_array(), first: c.first, hi: hi.to_array(), count: c.count })
            .collect();
        let storage = wgpu::BufferUsages::STORAGE;
        let clusters = init(device, "shade clusters", bytemuck::cast_slice(&reach), storage);
        let flat: Vec<f32> = triangles.iter().flatten().flat_map(|p| p.to_array()).collect();
        let corners = init(device, "shade corners", bytemuck::cast_slice(&flat), storage);
        let id_buffer = init(device, "shade ids", bytemuck::cast_slice(ids), storage);
        let copy_dst = wgpu::BufferUsages::COPY_DST;
        let view_buffer = buffer(device, "shade views", views as u64 * size_of::<GpuShadeView>() as u64, storage | copy_dst);
        let params = buffer(device, "shade params", size_of::<ShadeParams>() as u64, wgpu::BufferUsages::UNIFORM | copy_dst);
        let verdicts = buffer(device, "shade verdicts", views as u64 * 4, storage | wgpu::BufferUsages::COPY_SRC);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("may shade"),
            layout: &pass.layout,
            entries: &[
                entry(0, clusters.as_entire_binding()),
                entry(1, corners.as_entire_binding()),
                entry(2, id_buffer.as_entire_binding()),
                entry(3, view_buffer.as_entire_binding()),
                entry(4, params.as_entire_binding()),
                entry(5, verdicts.as_entire_binding()),
            ],
        });
        Some(Self { clusters: reach.len() as u32, views: view_buffer, params, verdicts, bind })
    }

    /// Records the pass over `tests` (at most the buffers' views): view k's verdict in word k
    /// of `verdicts`.
    pub(super) fn encode(&self, counter: &Counter, pass: &ShadePass, encoder: &mut wgpu::CommandEncoder, tests: &[ShadeTest]) {
        let views: Vec<GpuShadeView> = tests.iter().map(GpuShadeView::from).collect();
        let params = ShadeParams { views: views.len() as u32, clusters: self.clusters, _pad: [0; 2] };
        counter.queue.write_buffer(&self.views, 0, bytemuck::cast_slice(&views));
        counter.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("may shade"), timestamp_writes: None });
        compute.set_pipeline(&pass.pipeline);
        compute.set_bind_group(0, &self.bind, &[]);
        compute.dispatch_workgroups(views.len().max(1) as u32, 1, 1);
    }
}

impl Counter {
    /// The GPU's shading test of each of `tests` (made by [`Culling::shade_test`] on
    /// `culling`) on this counter's device, in one submission: what the GPU-culled count
    /// decides its views by, for tests against the CPU's [`Culling::may_be_shaded`].
    pub async fn may_shade_on_gpu(&self, culling: &Culling, tests: &[ShadeTest]) -> Result<Vec<ShadeVerdict>> {
        let limit = self.device.limits().max_compute_workgroups_per_dimension;
        if tests.len() > limit as usize {
            let need = tests.len() as u64;
            return Err(GpuError::OverLimit { limit_name: "max_compute_workgroups_per_dimension", need, limit: limit as u64 }.into());
        }
        let d = &self.device;
        let pass = ShadePass::new(d);
        let Some(scene) = ShadeScene::new(d, &pass, culling, tests.len() as u32) else {
            return Ok(vec![ShadeVerdict::Undecided; tests.len()]);
        };
        let bytes = tests.len().max(1) as u64 * 4;
        let readback = buffer(d, "shade readback", bytes, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut encoder = d.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("may shade") });
        scene.encode(self, &pass, &mut encoder, tests);
        encoder.copy_buffer_to_buffer(&scene.verdicts, 0, &readback, 0, bytes);
        self.queue.submit([encoder.finish()]);
        let read = platform::read_buffer(d, &readback, bytes).await;
        self.check_errors("the shading test")?;
        let read = read?;
        let words: &[u32] = bytemuck::try_cast_slice(&read).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
        Ok(words.iter().take(tests.len()).map(|&w| ShadeVerdict::from_word(w)).collect())
    }

    /// Views whose shading the host tested because the GPU could not decide, since this
    /// counter was made (benchmarks).
    pub fn shading_tested_on_cpu(&self) -> u64 {
        self.shading_on_cpu.load(Ordering::Relaxed)
    }

    /// Whether `scene`'s GPU-culled views are tested on the GPU.
    pub(super) fn shades_on_gpu(scene: &GpuScene) -> bool {
        scene.pulled.as_ref().is_some_and(|p| p.shade.is_some())
    }
}
