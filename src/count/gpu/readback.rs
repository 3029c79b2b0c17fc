//! Reading counts back: batches' member counts are copied into one mappable buffer, mapped once
//! per [`BATCHES_PER_READBACK`] batches (awaited, so the web never blocks), and turned into
//! [`Counted`] fractions in request order.

use std::sync::atomic::Ordering;

use super::pipelines::COUNTS_PER_MEMBER;
use super::plan::{Tile, tiles_at};
use super::{Counted, Counter, GpuScene};
use crate::count::ViewRequest;
use crate::error::{GpuError, Result};
use crate::platform;

/// Batches read back per map: bounds latency and memory while keeping the GPU fed.
pub(super) const BATCHES_PER_READBACK: usize = 32;

impl Counter {
    /// Renders and counts `tiles` at side `side` and writes their members' counts into `out`.
    pub(super) async fn count_tiles(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        tiles: &[Tile],
        side: u32,
        out: &mut [Counted],
    ) -> Result<()> {
        let per_batch = tiles_at(self.atlas_side, side);
        for chunk in tiles.chunks(per_batch * BATCHES_PER_READBACK) {
            // Each batch's counts land in the readback right after the previous batch's.
            let mut entries = 0;
            for batch in chunk.chunks(per_batch) {
                entries += self.submit_batch(scene, requests, batch, side, entries)?;
            }
            let counts = platform::read_buffer(&self.device, &self.batch.readback, entries as u64 * COUNTS_PER_MEMBER * 4).await;
            // A failed read on a lost device is the loss, not a read error.
            self.check_errors("counting pixels")?;
            let counts = counts?;
            let counts: &[u32] = bytemuck::try_cast_slice(&counts).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
            let members = chunk.iter().flat_map(|t| t.requests.iter().map(move |&i| (i, t.view.pixel_area)));
            for ((i, pixel_area), c) in members.zip(counts.chunks_exact(COUNTS_PER_MEMBER as usize)) {
                let (visible, covered, edges) = (c[0], c[1], c[2]);
                let o = &mut out[i];
                o.visible = visible;
                o.covered = covered;
                o.edges = edges;
                o.side = side;
                o.pixel_area = pixel_area;
                o.fraction = if covered == 0 { 0.0 } else { (visible as f64 / covered as f64).clamp(0.0, 1.0) };
            }
            let drawn: usize = chunk.iter().map(|t| t.draws.triangles(&scene.layout.culling)).sum();
            self.tiles_rendered.fetch_add(chunk.len() as u64, Ordering::Relaxed);
            self.triangles_drawn.fetch_add(drawn as u64, Ordering::Relaxed);
        }
        Ok(())
    }
}
