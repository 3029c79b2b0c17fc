//! Reading counts back: batches' member counts are copied into one mappable buffer, mapped once
//! per [`BATCHES_PER_READBACK`] batches (awaited, so the web never blocks), and turned into
//! [`Counted`] fractions in request order.

use std::sync::atomic::Ordering;

use super::compute::count_bytes;
use super::encode::Passes;
use super::masks::{GpuPoints, MaskBatch, PointMask};
use super::pipelines::COUNTS_PER_MEMBER;
use super::plan::{Tile, tiles_at};
use super::shade::ShadeVerdict;
use super::{Counted, Counter, GpuScene};
use crate::count::ViewRequest;
use crate::error::{GpuError, Result};
use crate::platform::{self, Stopwatch};

/// Batches read back per map: bounds latency and memory while keeping the GPU fed.
pub(super) const BATCHES_PER_READBACK: usize = 32;

/// Where [`Counter::count_tiles`] puts map points' masks: the points, each request's mask, and
/// the words the rendered masks point into; `count`: whether the count pass runs too.
pub(super) struct MaskOut<'a> {
    pub(super) points: &'a GpuPoints,
    pub(super) answers: &'a mut [Option<PointMask>],
    pub(super) words: &'a mut Vec<u32>,
    pub(super) count: bool,
}

/// Maps `words` words of `points`'s readback (the masks of `batches`, in order) and hands each
/// view's words to its request.
async fn read_masks(
    counter: &Counter,
    points: &GpuPoints,
    batches: &[MaskBatch],
    words: u64,
    answers: &mut [Option<PointMask>],
    all_words: &mut Vec<u32>,
) -> Result<()> {
    if words == 0 {
        return Ok(());
    }
    let bytes = platform::read_buffer(&counter.device, &points.readback, words * 4).await;
    counter.check_errors("reading point masks")?;
    let bytes = bytes?;
    let read: &[u32] = bytemuck::try_cast_slice(&bytes).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
    let mut at = 0usize;
    for batch in batches {
        for ((view, &i), tile) in batch.views.iter().zip(&batch.requests).zip(&batch.tiles) {
            let n = view.point_count.div_ceil(32) as usize;
            let start = all_words.len();
            all_words.extend_from_slice(&read[at + view.first_word as usize..][..n]);
            answers[i] = Some(PointMask::Rendered { words: start..start + n, tile: *tile });
        }
        at += batch.words as usize;
    }
    Ok(())
}

impl Counter {
    /// Renders and counts `tiles` at side `side` and writes their members' counts into `out`.
    /// With `masks`, also each rendered member's map points' mask (into the request's slot,
    /// its words appended to the words); without its `count`, no pixels are counted and `out`
    /// keeps what planning wrote.
    pub(super) async fn count_tiles(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        tiles: &[Tile],
        side: u32,
        out: &mut [Counted],
        mut masks: Option<MaskOut<'_>>,
    ) -> Result<()> {
        if masks.is_none() && self.counts_by_compute(scene, false) {
            return self.count_tiles_compute(scene, requests, tiles, side, out).await;
        }
        let per_batch = tiles_at(self.atlas_side, side);
        for chunk in tiles.chunks(per_batch * BATCHES_PER_READBACK) {
            // Each batch's counts land in the readback right after the previous batch's, and so
            // do its masks.
            let (mut entries, mut words) = (0, 0u64);
            let mut mask_batches = Vec::new();
            let count = masks.as_ref().is_none_or(|m| m.count);
            for (batch_in_chunk, batch) in chunk.chunks(per_batch).enumerate() {
                let mask = masks.as_ref().map(|m| (m.points, self.mask_batch(scene, m.points, requests, batch, side)));
                let passes = Passes { count, masks: mask.as_ref().map(|(p, m)| (*p, m, words)), batch_in_chunk };
                entries += self.submit_batch(scene, requests, batch, side, entries, passes)?;
                if let Some((_, m)) = mask {
                    words += m.words;
                    mask_batches.push(m);
                }
            }
            if let Some(m) = masks.as_mut() {
                read_masks(self, m.points, &mask_batches, words, m.answers, m.words).await?;
            }
            if !count {
                self.note_rendered(scene, chunk);
                continue;
            }
            let waiting = Stopwatch::start();
            let counts = platform::read_buffer(&self.device, &self.batch.readback, count_bytes(entries)).await;
            self.stages.waiting.fetch_add(waiting.nanos(), Ordering::Relaxed);
            let unpacking = Stopwatch::start();
            // A failed read on a lost device is the loss, not a read error.
            self.check_errors("counting pixels")?;
            let counts = counts?;
            let counts: &[u32] = bytemuck::try_cast_slice(&counts).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
            self.note_rendered(scene, chunk);
            unpack(chunk, counts, side, out);
            self.stages.unpacking.fetch_add(unpacking.nanos(), Ordering::Relaxed);
            let answers = self.culling_answers(scene, chunk, per_batch).await?;
            if let Some(answers) = answers.as_ref() {
                self.settle_unshaded(scene, requests, chunk, answers, out);
            }
            let overflowed = answers.as_ref().map(|a| a.overflowed(chunk)).unwrap_or_default();
            if !overflowed.is_empty() {
                let again = self.cull_again_on_cpu(scene, requests, &overflowed, out);
                Box::pin(self.count_tiles(scene, requests, &again, side, out, None)).await?;
            }
        }
        Ok(())
    }

    /// What the GPU's culling answered of `chunk`'s batches (`per_batch` tiles each): each
    /// batch's pairs needed and each tile's shading verdict; `None` where no tile of `chunk` was
    /// culled on the GPU.
    async fn culling_answers(&self, scene: &GpuScene, chunk: &[Tile], per_batch: usize) -> Result<Option<CullingAnswers>> {
        let Some(pulled) = scene.pulled.as_ref().filter(|_| chunk.iter().any(|t| t.draws.is_none())) else { return Ok(None) };
        let batches = chunk.len().div_ceil(per_batch);
        let words = BATCHES_PER_READBACK + batches.saturating_sub(1) * pulled.tiles + (chunk.len() - (batches - 1) * per_batch);
        let bytes = platform::read_buffer(&self.device, &pulled.answers, words as u64 * 4).await;
        self.check_errors("reading the GPU culling's answers")?;
        let bytes = bytes?;
        let words: &[u32] = bytemuck::try_cast_slice(&bytes).map_err(|e| GpuError::Readback(format!("bad readback: {e}")))?;
        let (needed, verdicts) = words.split_at(BATCHES_PER_READBACK);
        let verdicts = Counter::shades_on_gpu(scene)
            .then(|| (0..chunk.len()).map(|k| ShadeVerdict::from_word(verdicts[(k / per_batch) * pulled.tiles + k % per_batch])).collect());
        Ok(Some(CullingAnswers { needed: needed[..batches].to_vec(), capacity: pulled.batch.capacity, per_batch, verdicts }))
    }

    /// Gives the GPU-culled tiles of `chunk` that nothing can shade fraction 1 without a
    /// render, as the CPU's culling does. The GPU's culling renders every tile, and at grazing
    /// suns a receiver's neighbour can take a pixel of its edge where nothing shades it; so each
    /// such tile with a member not counted fully lit is settled by the GPU's shading test
    /// ([`super::shade`]), or where it could not decide (or did not run) by the CPU's (the
    /// first triangle that can shade ends it): the counts stay the CPU path's exactly.
    fn settle_unshaded(&self, scene: &GpuScene, requests: &[ViewRequest], chunk: &[Tile], answers: &CullingAnswers, out: &mut [Counted]) {
        let started = Stopwatch::start();
        let mut on_cpu = 0;
        for (k, tile) in chunk.iter().enumerate() {
            let not_lit = tile.draws.is_none() && tile.requests.iter().any(|&i| out[i].visible < out[i].covered || out[i].covered == 0);
            if !not_lit {
                continue;
            }
            let unshaded = match answers.verdicts.as_ref().map_or(ShadeVerdict::Undecided, |v| v[k]) {
                ShadeVerdict::Nothing => true,
                ShadeVerdict::Shaded => false,
                ShadeVerdict::Undecided => {
                    on_cpu += 1;
                    !super::plan::may_be_shaded(&scene.layout, requests, &tile.requests, &tile.view)
                }
            };
            if unshaded {
                tile.requests.iter().for_each(|&i| out[i] = lit_without_render(out[i]));
            }
        }
        self.shading_on_cpu.fetch_add(on_cpu, Ordering::Relaxed);
        let nanos = started.nanos();
        self.stages.planning.fetch_add(nanos, Ordering::Relaxed);
        self.stages.culling.fetch_add(nanos, Ordering::Relaxed);
    }

    /// `tiles` culled on the CPU, to be counted again: those with nothing that can shade their
    /// members get fraction 1 in `out` without a render, as the CPU path gives them.
    fn cull_again_on_cpu(&self, scene: &GpuScene, requests: &[ViewRequest], tiles: &[&Tile], out: &mut [Counted]) -> Vec<Tile> {
        let mut again = Vec::new();
        for tile in tiles {
            match super::plan::cull_on_cpu(&scene.layout, requests, &tile.requests, &tile.view) {
                Some(draws) => again.push(Tile { requests: tile.requests.clone(), view: tile.view, draws: Some(draws) }),
                None => tile
                    .requests
                    .iter()
                    .for_each(|&i| out[i] = Counted { fraction: 1.0, cos_incidence: out[i].cos_incidence, ..Counted::default() }),
            }
        }
        again
    }

    /// Adds a counted chunk's tiles and triangles to the benchmark totals.
    pub(super) fn note_rendered(&self, scene: &GpuScene, chunk: &[Tile]) {
        // The GPU's culling's draws are not read back: their triangles are not counted.
        let drawn: usize = chunk.iter().filter_map(|t| t.draws.as_ref()).map(|d| d.triangles(&scene.layout.culling)).sum();
        self.tiles_rendered.fetch_add(chunk.len() as u64, Ordering::Relaxed);
        self.views_drawn.fetch_add(chunk.iter().map(|t| t.requests.len() as u64).sum(), Ordering::Relaxed);
        self.triangles_drawn.fetch_add(drawn as u64, Ordering::Relaxed);
    }
}

/// What the GPU's culling answered of a readback chunk.
struct CullingAnswers {
    /// Pairs each batch needed.
    needed: Vec<u32>,
    /// Pairs a batch's list holds.
    capacity: u32,
    per_batch: usize,
    /// Each tile's shading verdict (`None`: the GPU did not test).
    verdicts: Option<Vec<ShadeVerdict>>,
}

impl CullingAnswers {
    /// The tiles of the chunk's batches whose pair list overflowed: their scene pass drew
    /// nothing, so their counts are wrong and must be redone.
    fn overflowed<'t>(&self, chunk: &'t [Tile]) -> Vec<&'t Tile> {
        let capacity = self.capacity;
        let over = self.needed.iter().zip(chunk.chunks(self.per_batch)).filter(|(n, _)| **n > capacity);
        over.flat_map(|(n, batch)| {
            log::info!("GPU culling: {n} pairs needed, {capacity} held; counting the batch again with the CPU's culling");
            batch.iter()
        })
        .collect()
    }
}

/// A view's answer when nothing can shade it: fully lit, not rendered (as planning gives it).
fn lit_without_render(counted: Counted) -> Counted {
    Counted { fraction: 1.0, cos_incidence: counted.cos_incidence, ..Counted::default() }
}

/// Writes the members' counts of `chunk` (three words an entry, in tile and member order),
/// counted at side `side`, into their requests' places in `out`.
pub(super) fn unpack(chunk: &[Tile], counts: &[u32], side: u32, out: &mut [Counted]) {
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
}
