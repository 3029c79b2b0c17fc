//! Test hooks (feature `test-hooks`): what the crate's own tests need to look inside a counter
//! (the id atlas, where tiles sit, the culling and the view groups, a forced device loss, a small
//! static-mesh chunk). Not part of the API the CLI and the web use.

use glam::{DVec3, Vec4};

use super::masks::MaskTile;
use super::plan::tile_origin;
use super::{Counter, GpuScene, pipelines::buffer};
use crate::count::cull::Culling;
use crate::count::group::ViewGroups;
use crate::error::{GpuError, Result};
use crate::platform;
use crate::scene::Scene;

impl Counter {
    /// Tests only: a function that destroys this counter's device, as a driver reset would lose
    /// it, from wherever it is called (a progress callback, mid-run).
    pub fn device_loss_trigger(&self) -> impl Fn() + 'static {
        let device = self.device.clone();
        move || device.destroy()
    }

    /// [`Counter::upload`] with at most `max_triangles` static triangles a vertex buffer (tests
    /// exercise the split with small values).
    pub fn upload_in_chunks(&self, scene: &Scene, max_triangles: u32) -> Result<GpuScene> {
        self.upload_chunked(scene, max_triangles)
    }

    /// Uploads `scene` with room for only `pairs` (view, cluster) pairs a batch in the GPU's
    /// culling, so that tests can force its overflow.
    pub fn upload_with_pairs(&self, scene: &Scene, pairs: u32) -> Result<GpuScene> {
        self.upload_with(scene, self.static_chunk_triangles(), Some(pairs))
    }

    /// Reads back the red channel of the id atlas: the visible surface ids (for tests comparing
    /// the compute count with a CPU count).
    pub async fn read_ids(&self) -> Result<(u32, Vec<u32>)> {
        let (side, texels) = self.read_atlas().await?;
        Ok((side, texels.iter().map(|t| t[0]).collect()))
    }

    /// Reads back the id atlas: per pixel the visible surface id (red) and the covering member's
    /// id (green, `NO_RECEIVER` where no member covers it).
    pub async fn read_atlas(&self) -> Result<(u32, Vec<[u32; 2]>)> {
        let side = self.atlas_side;
        let bytes_per_row = side * 8;
        let size = (bytes_per_row * side) as u64;
        let target = buffer(&self.device, "ids readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read ids") });
        let texture = self.batch.atlas.ids.texture();
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &target,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(bytes_per_row), rows_per_image: None },
            },
            texture.size(),
        );
        self.queue.submit([encoder.finish()]);
        let bytes = platform::read_buffer(&self.device, &target, size).await?;
        self.check_errors("reading the id atlas")?;
        let texels: &[[u32; 2]] = bytemuck::try_cast_slice(&bytes).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
        Ok((side, texels.to_vec()))
    }

    /// Where tile `slot` of the last batch was drawn (top-left pixel) when its side was `side`.
    /// Tiles follow the order of their first request.
    pub fn tile_of(&self, slot: usize, side: u32) -> [u32; 2] {
        tile_origin(self.atlas_side, slot, side)
    }
}

/// Tests only: the CPU truth of `shaders/point_masks.wgsl` for one point: whether `position`
/// (world) on the receiver whose pixels carry `id` is lit in `tile` of an id atlas of side
/// `atlas_side` read by [`Counter::read_atlas`] (scene origin `origin`). The same steps as the
/// shader, in f32: the nearest texel's red id is the receiver's, or, where the receiver does not
/// cover that texel, the first neighbour's (row by row) that it covers. Also returns the point's
/// pixel coordinates in the tile, so a test can tell points too close to a texel border for f32
/// rounding to agree.
pub fn mask_truth(atlas: &[[u32; 2]], atlas_side: u32, tile: &MaskTile, id: u32, origin: DVec3, position: DVec3) -> (bool, [f32; 2]) {
    let q = (position - origin).as_vec3();
    let clip = tile.view.view_proj.as_mat4() * Vec4::new(q.x, q.y, q.z, 1.0);
    let side = tile.side as f32;
    let pixel = [(clip.x / clip.w * 0.5 + 0.5) * side, (0.5 - clip.y / clip.w * 0.5) * side];
    let at = pixel.map(|p| p.floor().clamp(0.0, side - 1.0) as i64);
    let texel = |x: i64, y: i64| atlas[((tile.atlas[1] as i64 + y) * atlas_side as i64 + tile.atlas[0] as i64 + x) as usize];
    let here = texel(at[0], at[1]);
    if here[1] == id {
        return (here[0] == id, pixel);
    }
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (x, y) = (at[0] + dx, at[1] + dy);
            if (dx == 0 && dy == 0) || x < 0 || y < 0 || x >= tile.side as i64 || y >= tile.side as i64 {
                continue;
            }
            let n = texel(x, y);
            if n[1] == id {
                return (n[0] == id, pixel);
            }
        }
    }
    (false, pixel)
}

impl GpuScene {
    /// The receivers that share a view (a wall and the windows in it).
    pub fn view_groups(&self) -> &ViewGroups {
        &self.layout.groups
    }

    /// The id receiver `receiver`'s pixels carry (its own, or the mirrored surface's).
    pub fn gpu_id(&self, receiver: u32) -> u32 {
        self.layout.receivers[receiver as usize].gpu_id
    }

    /// The spatial index that picks what each view draws (benchmarks report what it saves).
    pub fn culling(&self) -> &Culling {
        &self.layout.culling
    }
}
