//! Sky views: for every receiver and sky patch, the unobstructed fraction of the receiver seen
//! from the patch, asked of the same engines as the sun ([`crate::count::Engine`]) through
//! ordinary [`ViewRequest`]s, with the patch's lit direction in place of the sun.
//!
//! Owns when they are counted and how they are combined:
//! - once per model, since they depend on the geometry only; with foliage once at bare and once
//!   at full leaf, and in between linear in the leaf fraction (as the leaf calendar ramps it);
//! - a patch with no part in front of a receiver (weight 0) is not asked for: it is dark;
//! - the receiver's isotropic sky factor Σ visibility·weight / π (its view factor to the visible
//!   sky: (1 + cos tilt)/2 with nothing in the way), its unobstructed twin Σ weight / π, and its
//!   horizon-band visibility (the weight-averaged visibility of the band nearest the horizon,
//!   1 where the receiver sees none of that band), the three things the Perez sky needs.

use crate::count::{Engine, ViewKind, ViewRequest};
use crate::error::Result;
use crate::scene::Scene;
use crate::sky::patches::SkyPatches;
use crate::year::annual::Progress;

/// Views handed to the engine between progress reports, in units of its batch.
const BATCHES_PER_REPORT: usize = 4;

/// Per receiver, what it sees of each leaf state's sky.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyViews {
    /// The patch layout.
    pub patches: SkyPatches,
    /// Leaf fractions counted: `[1.0]` without foliage, `[0.0, 1.0]` with.
    pub leaf_states: Vec<f32>,
    /// Per leaf state, per receiver: Σ visibility·weight / π.
    isotropic: Vec<Vec<f64>>,
    /// Per leaf state, per receiver: the horizon band's weighted visibility.
    horizon: Vec<Vec<f64>>,
    /// Per receiver: Σ weight / π.
    unobstructed: Vec<f64>,
}

impl SkyViews {
    /// Receivers covered.
    pub fn receivers(&self) -> usize {
        self.unobstructed.len()
    }

    /// Receiver `r`'s view factor to the visible sky at leaf fraction `leaves`.
    pub fn isotropic(&self, r: usize, leaves: f64) -> f64 {
        self.between(&self.isotropic, r, leaves)
    }

    /// Receiver `r`'s view factor to the sky with nothing in the way, (1 + cos tilt)/2.
    pub fn unobstructed(&self, r: usize) -> f64 {
        self.unobstructed[r]
    }

    /// Receiver `r`'s horizon-band visibility at leaf fraction `leaves`.
    pub fn horizon(&self, r: usize, leaves: f64) -> f64 {
        self.between(&self.horizon, r, leaves)
    }

    /// Linear in the leaf fraction between the bare and full-leaf states.
    fn between(&self, values: &[Vec<f64>], r: usize, leaves: f64) -> f64 {
        match values {
            [only] => only[r],
            [bare, full, ..] => {
                let t = leaves.clamp(0.0, 1.0);
                bare[r] * (1.0 - t) + full[r] * t
            }
            [] => 0.0,
        }
    }
}

/// Counts the sky views of every receiver of `scene` with `engine`.
pub async fn sky_views(
    engine: &impl Engine,
    scene: &Scene,
    patches: &SkyPatches,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<SkyViews> {
    let leaf_states: Vec<f32> = if scene.has_foliage() { vec![0.0, 1.0] } else { vec![1.0] };
    let horizon_patches: Vec<usize> = patches.horizon_band().map(|(i, _)| i).collect();
    let weights: Vec<_> = scene.receivers.iter().map(|r| patches.weights(r.normal)).collect();
    // One request per lit (receiver, patch) and leaf state; `lit` remembers which they were.
    let lit: Vec<(usize, usize)> = weights
        .iter()
        .enumerate()
        .flat_map(|(r, w)| w.iter().enumerate().filter(|(_, pw)| pw.weight > 0.0).map(move |(p, _)| (r, p)))
        .collect();
    let mut requests = Vec::with_capacity(lit.len() * leaf_states.len());
    for &leaves in &leaf_states {
        requests.extend(lit.iter().map(|&(r, p)| ViewRequest::new(r as u32, weights[r][p].direction).with_leaves(leaves)));
    }
    let fractions = count(engine, &requests, progress).await?;
    let receivers = scene.receivers.len();
    let unobstructed: Vec<f64> = weights.iter().map(|w| w.iter().map(|pw| pw.weight).sum::<f64>() / std::f64::consts::PI).collect();
    let (mut isotropic, mut horizon) = (Vec::new(), Vec::new());
    for state in fractions.chunks(lit.len().max(1)).take(leaf_states.len()) {
        let mut visible = vec![vec![0.0f64; patches.len()]; receivers];
        for (&(r, p), &f) in lit.iter().zip(state) {
            visible[r][p] = f;
        }
        isotropic.push(
            (0..receivers)
                .map(|r| weights[r].iter().zip(&visible[r]).map(|(pw, v)| pw.weight * v).sum::<f64>() / std::f64::consts::PI)
                .collect(),
        );
        horizon.push((0..receivers).map(|r| band_visibility(&horizon_patches, &weights[r], &visible[r])).collect());
    }
    if lit.is_empty() {
        isotropic = vec![vec![0.0; receivers]; leaf_states.len()];
        horizon = vec![vec![1.0; receivers]; leaf_states.len()];
    }
    Ok(SkyViews { patches: patches.clone(), leaf_states, isotropic, horizon, unobstructed })
}

/// The weight-averaged visibility of `band`'s patches; 1 where none has weight.
fn band_visibility(band: &[usize], weights: &[crate::sky::patches::PatchWeight], visible: &[f64]) -> f64 {
    let total: f64 = band.iter().map(|&p| weights[p].weight).sum();
    if total <= 0.0 {
        return 1.0;
    }
    band.iter().map(|&p| weights[p].weight * visible[p]).sum::<f64>() / total
}

/// The engine's fractions for `requests` (sky directions: the engine is told so, and told sun
/// views follow again afterwards), reporting progress between chunks.
pub(crate) async fn count(
    engine: &impl Engine,
    requests: &[ViewRequest],
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Vec<f64>> {
    engine.views_of(ViewKind::Sky);
    let counted = count_sky(engine, requests, progress).await;
    engine.views_of(ViewKind::Sun);
    counted
}

async fn count_sky(engine: &impl Engine, requests: &[ViewRequest], progress: &mut dyn FnMut(Progress) -> Result<()>) -> Result<Vec<f64>> {
    let mut out = Vec::with_capacity(requests.len());
    progress(Progress { done: 0, total: requests.len() })?;
    engine.expect(requests.len());
    for chunk in requests.chunks(engine.batch().max(1) * BATCHES_PER_REPORT) {
        out.extend(engine.answer(chunk).await?.into_iter().map(|a| a.fraction));
        progress(Progress { done: out.len(), total: requests.len() })?;
    }
    Ok(out)
}
