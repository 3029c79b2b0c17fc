//! Test hooks (feature `test-hooks`): what the crate's own tests need to look inside a counter
//! (the id atlas, where tiles sit, the culling and the view groups, a forced device loss, a small
//! static-mesh chunk). Not part of the API the CLI and the web use.

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

impl GpuScene {
    /// The receivers that share a view (a wall and the windows in it).
    pub fn view_groups(&self) -> &ViewGroups {
        &self.layout.groups
    }

    /// The spatial index that picks what each view draws (benchmarks report what it saves).
    pub fn culling(&self) -> &Culling {
        &self.layout.culling
    }
}
