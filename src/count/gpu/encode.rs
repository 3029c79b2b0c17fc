//! Encoding a batch: the per-batch buffers and atlas, the tiles' views and members written for
//! the shaders, the render pass (each tile's members alone into green, then what lies in front
//! of them, depth-tested, into red) and the count pass, one submission per batch.

use std::ops::Range;
use std::sync::atomic::Ordering;

use super::masks::{GpuPoints, MaskBatch};
use super::pipelines::{
    COUNTS_PER_MEMBER, DEPTH_FORMAT, GpuTileView, GpuView, ID_FORMAT, Pipelines, ROWS_PER_GROUP, attachment, buffer, entry,
    subpixels_per_half_tile,
};
use super::plan::{Tile, tile_origin};
use super::readback::BATCHES_PER_READBACK;
use super::upload::StaticChunk;
use super::{Counter, GpuScene};
use crate::count::ViewRequest;
use crate::count::group::MAX_MEMBERS;
use crate::error::Result;
use crate::platform::Stopwatch;

pub(super) struct Atlas {
    pub(super) ids: wgpu::TextureView,
    pub(super) depth: wgpu::TextureView,
}

/// The atlas and the buffers one batch is written to and counted into, sized for a batch at the
/// smallest side used.
pub(super) struct BatchBuffers {
    pub(super) atlas: Atlas,
    /// Per tile, where and whom the count pass counts.
    pub(super) views: wgpu::Buffer,
    /// The same views as the vertex shaders read them: one uniform per tile, `tile_stride` apart,
    /// bound at a dynamic offset by `tile_bind`.
    pub(super) tile_views: wgpu::Buffer,
    pub(super) tile_bind: wgpu::BindGroup,
    pub(super) tile_stride: u32,
    /// Receiver ids of the tiles' members (the count pass's `members`).
    pub(super) members: wgpu::Buffer,
    pub(super) counts: wgpu::Buffer,
    /// Where counts land for mapping: [`BATCHES_PER_READBACK`] batches' worth.
    pub(super) readback: wgpu::Buffer,
}

impl BatchBuffers {
    pub(super) fn new(device: &wgpu::Device, pipelines: &Pipelines, atlas_side: u32, smallest: u32) -> Self {
        let atlas = Atlas {
            ids: attachment(device, "ids", atlas_side, ID_FORMAT, true),
            depth: attachment(device, "depth", atlas_side, DEPTH_FORMAT, false),
        };
        let tiles = ((atlas_side / smallest) as u64).pow(2);
        let entries = tiles * MAX_MEMBERS as u64;
        let views =
            buffer(device, "views", tiles * size_of::<GpuView>() as u64, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
        let tile_stride = (size_of::<GpuTileView>() as u32).next_multiple_of(device.limits().min_uniform_buffer_offset_alignment);
        let tile_views =
            buffer(device, "tile views", tiles * tile_stride as u64, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let tile_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tile view"),
            layout: &pipelines.tile_layout,
            entries: &[entry(
                0,
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &tile_views,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<GpuTileView>() as u64),
                }),
            )],
        });
        let members = buffer(device, "members", entries * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
        let counts = buffer(
            device,
            "counts",
            entries * COUNTS_PER_MEMBER * 4,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let readback = buffer(
            device,
            "readback",
            entries * COUNTS_PER_MEMBER * 4 * BATCHES_PER_READBACK as u64,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        Self { atlas, views, tile_views, tile_bind, tile_stride, members, counts, readback }
    }
}

/// The compute passes a batch runs after its render.
pub(super) struct Passes<'a> {
    /// The count pass.
    pub(super) count: bool,
    /// The mask pass for these map points and views; its words land in the points' readback
    /// from this word on.
    pub(super) masks: Option<(&'a GpuPoints, &'a MaskBatch, u64)>,
    /// The batch's place in its readback chunk (where the GPU's culling reports its pairs
    /// needed).
    pub(super) batch_in_chunk: usize,
}

impl Counter {
    /// Renders one batch of tiles and runs `passes` over it: the count (member counts land in
    /// `readback` from entry `first_entry` on) and the masks. Returns the number of member
    /// entries.
    pub(super) fn submit_batch(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        batch: &[Tile],
        side: u32,
        first_entry: usize,
        passes: Passes<'_>,
    ) -> Result<usize> {
        let Passes { count, masks, batch_in_chunk } = passes;
        let encoding = Stopwatch::start();
        // Each tile twice, for its two readers: where and whom to count (the count pass), and the
        // view to draw it with (the render, a uniform per tile at `tile_stride`).
        let mut members: Vec<u32> = Vec::with_capacity(batch.len());
        let mut views: Vec<GpuView> = Vec::with_capacity(batch.len());
        let stride = self.batch.tile_stride as usize;
        let mut tile_views = vec![0u8; batch.len() * stride];
        for ((slot, tile), at) in batch.iter().enumerate().zip(tile_views.chunks_exact_mut(stride)) {
            let first_member = members.len() as u32;
            members.extend(tile.requests.iter().map(|&i| scene.layout.receivers[requests[i].receiver as usize].gpu_id));
            let tile_origin = tile_origin(self.atlas_side, slot, side);
            views.push(GpuView { tile: tile_origin, first_member, member_count: tile.requests.len() as u32, side, _pad: 0 });
            let view = GpuTileView {
                view_proj: tile.view.view_proj.as_mat4().to_cols_array_2d(),
                leaves: requests[tile.requests[0]].leaves,
                slot: slot as u32,
                snap: subpixels_per_half_tile(side),
                _pad: 0,
            };
            at[..size_of::<GpuTileView>()].copy_from_slice(bytemuck::bytes_of(&view));
        }
        self.queue.write_buffer(&self.batch.views, 0, bytemuck::cast_slice(&views));
        self.queue.write_buffer(&self.batch.tile_views, 0, &tile_views);
        self.queue.write_buffer(&self.batch.members, 0, bytemuck::cast_slice(&members));
        let recording = Stopwatch::start();
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("batch") });
        if let Some(pulled) = scene.pulled.as_ref().filter(|_| batch.iter().any(|t| t.draws.is_none())) {
            self.encode_gpu_cull(&mut encoder, scene, pulled, requests, batch, batch_in_chunk);
        }
        self.render_tiles(&mut encoder, scene, requests, batch, side);
        if count {
            encoder.clear_buffer(&self.batch.counts, 0, None);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("count"), timestamp_writes: None });
            pass.set_pipeline(&self.pipelines.count);
            pass.set_bind_group(0, &scene.count_bind, &[]);
            pass.dispatch_workgroups(side.div_ceil(ROWS_PER_GROUP), batch.len() as u32, 1);
            drop(pass);
        }
        if count {
            let entry_bytes = COUNTS_PER_MEMBER * 4;
            let bytes = members.len() as u64 * entry_bytes;
            let at = first_entry as u64 * entry_bytes;
            encoder.copy_buffer_to_buffer(&self.batch.counts, 0, &self.batch.readback, at, bytes);
        }
        if let Some((points, mask_batch, first_word)) = masks {
            self.encode_masks(&mut encoder, points, mask_batch, first_word);
        }
        let commands = encoder.finish();
        self.stages.recording.fetch_add(recording.nanos(), Ordering::Relaxed);
        self.stages.encoding.fetch_add(encoding.nanos(), Ordering::Relaxed);
        let submitting = Stopwatch::start();
        self.queue.submit([commands]);
        self.stages.submitting.fetch_add(submitting.nanos(), Ordering::Relaxed);
        Ok(members.len())
    }

    pub(super) fn render_tiles(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        requests: &[ViewRequest],
        batch: &[Tile],
        side: u32,
    ) {
        let no_receiver = crate::scene::NO_RECEIVER as f64;
        // Green too starts at NO_RECEIVER: receiver 0 is a valid id there.
        let clear_id = wgpu::Color { r: no_receiver, g: no_receiver, b: 0.0, a: 0.0 };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sun views"),
            color_attachments: &[color(&self.batch.atlas.ids, clear_id)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.batch.atlas.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_bind_group(0, &scene.render_bind, &[]);
        if batch.iter().all(|t| t.draws.is_none()) && self.draw_batch(&mut pass, scene, requests, batch, side) {
            return;
        }
        for (slot, tile) in batch.iter().enumerate() {
            let [x, y] = tile_origin(self.atlas_side, slot, side);
            pass.set_viewport(x as f32, y as f32, side as f32, side as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, side, side);
            pass.set_bind_group(1, &self.batch.tile_bind, &[slot as u32 * self.batch.tile_stride]);
            // The members alone, each writing its id: their coverage, the denominators.
            for &i in &tile.requests {
                let r = &scene.layout.receivers[requests[i].receiver as usize];
                if r.static_triangles.is_empty() {
                    pass.set_pipeline(&self.pipelines.view.mask);
                    let mesh = &scene.meshes[r.mesh];
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(r.indices.clone(), 0, r.slot..r.slot + 1);
                } else {
                    pass.set_pipeline(&self.pipelines.view.static_mask);
                    draw_static(&mut pass, &scene.static_chunks, &r.static_triangles, r.slot);
                }
            }
            // What lies in the prisms in front of them, depth-tested: where a member's id
            // survives, it is sunlit.
            let Some(draws) = &tile.draws else {
                if let Some(pulled) = &scene.pulled {
                    self.draw_gpu_culled(&mut pass, pulled, slot);
                }
                continue;
            };
            pass.set_pipeline(&self.pipelines.view.static_scene);
            draw_static(&mut pass, &scene.static_chunks, &draws.static_triangles, scene.layout.culling.static_slot());
            pass.set_pipeline(&self.pipelines.view.scene);
            let mut bound = None;
            for (m, slots) in &draws.instances {
                let mesh = &scene.meshes[*m];
                if mesh.index_count == 0 {
                    continue;
                }
                if bound != Some(*m) {
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    bound = Some(*m);
                }
                pass.draw_indexed(0..mesh.index_count, 0, slots.clone());
            }
        }
    }
}

/// Draws ranges of the static mesh's triangles (culling order), split across its buffers.
fn draw_static(pass: &mut wgpu::RenderPass<'_>, chunks: &[StaticChunk], ranges: &[Range<u32>], slot: u32) {
    let mut bound = None;
    for r in ranges {
        for (c, chunk) in chunks.iter().enumerate() {
            let (a, b) = (r.start.max(chunk.triangles.start), r.end.min(chunk.triangles.end));
            if a >= b {
                continue;
            }
            if bound != Some(c) {
                pass.set_vertex_buffer(0, chunk.vertices.slice(..));
                pass.set_index_buffer(chunk.indices.slice(..), wgpu::IndexFormat::Uint32);
                bound = Some(c);
            }
            let o = chunk.triangles.start;
            pass.draw_indexed(3 * (a - o)..3 * (b - o), 0, slot..slot + 1);
        }
    }
}

fn color(view: &wgpu::TextureView, clear: wgpu::Color) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
    })
}
