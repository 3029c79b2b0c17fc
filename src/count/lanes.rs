//! Counting on several devices side by side.
//!
//! Owns the split of a run's views over counters. On lavapipe one device records, shades the
//! vertices of, clips and bins every triangle on its queue's single thread; only rasterisation
//! fans out over the cores. Views heavy in triangles and light in pixels (NYT-like models, ~6,000
//! triangles in a small tile) therefore leave cores idle, and a second device — its own queue
//! thread, its own copy of the scene — fills them. Each lane counts a contiguous share of the
//! requests; results come back in request order, the same as one lane's to pixel noise (each
//! view is rendered alone in its tile; only the tile's place in the atlas, which rounds its
//! edges, may differ).
//!
//! On the web there is one GPU and one lane; lanes there would run one after the other.

use super::gpu::{Counted, Counter, GpuScene};
use super::{Engine, ViewAnswer, ViewRequest};
use crate::error::Result;
use crate::platform;

/// A counter and the scene uploaded to it.
#[derive(Clone, Copy)]
pub struct Lane<'a> {
    /// The device that counts.
    pub counter: &'a Counter,
    /// The scene, uploaded to that device.
    pub gpu: &'a GpuScene,
}

/// Lanes a CPU rasterizer gets by default: two where the machine has two cores or more (each
/// lane's queue thread then has a core; more lanes only multiply the scene's memory), else one.
/// A hardware GPU gets one: it has its own parallelism, and one queue feeds it.
pub fn default_lanes(info: &wgpu::AdapterInfo) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if info.device_type == wgpu::DeviceType::Cpu && cores >= 2 { 2 } else { 1 }
}

/// Counts `requests` over the lanes, each a contiguous share of whole atlas batches.
pub async fn fractions_side_by_side(lanes: &[Lane<'_>], requests: &[ViewRequest]) -> Result<Vec<Counted>> {
    let Some(first) = lanes.first() else { return Ok(Vec::new()) };
    let batch = first.counter.tiles_per_batch().max(1);
    // Whole batches per lane, so no lane submits a part-filled atlas it need not.
    let share = requests.len().div_ceil(lanes.len()).div_ceil(batch) * batch;
    let parts: Vec<(Lane<'_>, &[ViewRequest])> = lanes.iter().copied().zip(requests.chunks(share.max(1))).collect();
    let counted = platform::side_by_side(&parts, |(lane, part)| lane.counter.fractions(lane.gpu, part)).await;
    let mut out = Vec::with_capacity(requests.len());
    for part in counted {
        out.extend(part?);
    }
    Ok(out)
}

/// One device as an [`Engine`].
impl Engine for Lane<'_> {
    fn batch(&self) -> usize {
        self.counter.tiles_per_batch()
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        self.counter.answer(self.gpu, requests).await
    }
}

/// Several devices side by side as one [`Engine`].
#[derive(Clone, Copy)]
pub struct Lanes<'a>(pub &'a [Lane<'a>]);

impl Engine for Lanes<'_> {
    fn batch(&self) -> usize {
        self.0.first().map_or(1, |l| l.counter.tiles_per_batch()) * self.0.len().max(1)
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        let edges_counted = self.0.first().is_some_and(|l| l.counter.options().accuracy.is_some());
        Ok(fractions_side_by_side(self.0, requests).await?.iter().map(|c| c.answer(edges_counted)).collect())
    }
}
