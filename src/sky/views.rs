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
//!
//! For a sky model that is a luminance distribution ([`SkyModel::is_distribution`]) the views
//! also keep, per item and patch, the visible ∫cos dΩ (weight × visibility) and the open one, so
//! that each hour's patch radiances can be summed over what the item sees of them.
//!
//! [`Seen`] is that combination patch by patch, and [`SkyViews`] holds its results for any list
//! of items: the receivers here, a map's points in [`crate::map::sky`] (each point's own patch
//! visibility, from shadow rays instead of fractions).

use crate::count::{Engine, ViewKind, ViewRequest};
use crate::error::Result;
use crate::scene::Scene;
use crate::sky::model::SkyModel;
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
    /// The sky model the views are kept for.
    model: SkyModel,
    /// For a distribution, per leaf state, per item, per patch: weight × visibility (sr).
    patch_seen: Vec<Vec<Vec<f32>>>,
    /// For a distribution, per item, per patch: the weight (sr).
    patch_open: Vec<Vec<f32>>,
}

impl SkyViews {
    /// The views of items (receivers or points) from their patch visibilities as [`Seen`]
    /// gathered them: per leaf state, per item. `unobstructed` is each item's Σ weight / π.
    pub(crate) fn from_seen(patches: &SkyPatches, leaf_states: Vec<f32>, seen: &[Vec<Seen>], unobstructed: Vec<f64>) -> Self {
        Self {
            patches: patches.clone(),
            leaf_states,
            isotropic: seen.iter().map(|state| state.iter().map(Seen::isotropic).collect()).collect(),
            horizon: seen.iter().map(|state| state.iter().map(Seen::horizon).collect()).collect(),
            unobstructed,
            model: SkyModel::EnergyPlus,
            patch_seen: Vec::new(),
            patch_open: Vec::new(),
        }
    }

    /// The views kept for a luminance distribution `model`: `seen[state][item][patch]` is the
    /// item's weight × visibility of the patch and `open[item][patch]` its weight.
    pub(crate) fn with_patches(mut self, model: SkyModel, seen: Vec<Vec<Vec<f32>>>, open: Vec<Vec<f32>>) -> Self {
        self.model = model;
        self.patch_seen = seen;
        self.patch_open = open;
        self
    }

    /// The sky model the views are kept for ([`SkyModel::EnergyPlus`] unless counted for another).
    pub fn model(&self) -> SkyModel {
        self.model
    }

    /// Item `r`'s sky diffuse (W/m²) under patch `radiances` (W/m²/sr) at leaf fraction
    /// `leaves`: Σ radiance × visible ∫cos dΩ. 0 for views kept without patches.
    pub fn distribution_diffuse(&self, r: usize, leaves: f64, radiances: &[f64]) -> f64 {
        let dot = |patches: &[f32]| -> f64 { patches.iter().zip(radiances).map(|(&w, l)| f64::from(w) * l).sum() };
        match self.patch_seen.as_slice() {
            [only] => dot(&only[r]),
            [bare, full, ..] => {
                let t = leaves.clamp(0.0, 1.0);
                dot(&bare[r]) * (1.0 - t) + dot(&full[r]) * t
            }
            [] => 0.0,
        }
    }

    /// Item `r`'s Σ over leaf states and patches of `per_state[state][patch]` × its visible
    /// ∫cos dΩ of the patch at that state: a period's sky diffuse from its radiance × hours summed
    /// per patch and weighted by leaf state. 0 for views kept without patches.
    pub fn distribution_sum(&self, r: usize, per_state: &[Vec<f64>]) -> f64 {
        self.patch_seen
            .iter()
            .zip(per_state)
            .map(|(state, totals)| state[r].iter().zip(totals).map(|(&w, t)| f64::from(w) * t).sum::<f64>())
            .sum()
    }

    /// Item `r`'s sky diffuse (W/m²) under patch `radiances` with nothing in the way.
    pub fn distribution_open(&self, r: usize, radiances: &[f64]) -> f64 {
        self.patch_open.get(r).map_or(0.0, |open| open.iter().zip(radiances).map(|(&w, l)| f64::from(w) * l).sum())
    }

    /// Receivers covered (points, for a map's views).
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

/// Counts the sky views of every receiver of `scene` with `engine`, for the `energyplus` sky.
pub async fn sky_views(
    engine: &impl Engine,
    scene: &Scene,
    patches: &SkyPatches,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<SkyViews> {
    sky_views_for(engine, scene, patches, SkyModel::EnergyPlus, progress).await
}

/// Counts the sky views of every receiver of `scene` with `engine`, kept for sky `model` (per
/// patch for a distribution).
pub async fn sky_views_for(
    engine: &impl Engine,
    scene: &Scene,
    patches: &SkyPatches,
    model: SkyModel,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<SkyViews> {
    let leaf_states: Vec<f32> = if scene.has_foliage() { vec![0.0, 1.0] } else { vec![1.0] };
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
    let mut seen = vec![vec![Seen::default(); receivers]; leaf_states.len()];
    let keep = model.is_distribution();
    let mut patch_seen = vec![vec![vec![0.0f32; if keep { patches.len() } else { 0 }]; receivers]; leaf_states.len()];
    for ((state, kept), fractions) in seen.iter_mut().zip(patch_seen.iter_mut()).zip(fractions.chunks(lit.len().max(1))) {
        for (&(r, p), &f) in lit.iter().zip(fractions) {
            state[r].add(weights[r][p].weight, f, patches.patches[p].band == 0);
            if keep {
                kept[r][p] = (weights[r][p].weight * f) as f32;
            }
        }
    }
    let views = SkyViews::from_seen(patches, leaf_states, &seen, unobstructed);
    if !keep {
        return Ok(views);
    }
    let open = weights.iter().map(|w| w.iter().map(|pw| pw.weight as f32).collect()).collect();
    Ok(views.with_patches(model, patch_seen, open))
}

/// What one item (a receiver, a map's point) sees of the sky, gathered patch by patch: Σ
/// weight·visibility over every patch, and over the horizon band Σ weight·visibility and Σ weight.
/// Patches of weight 0 (behind the item) need not be added.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Seen {
    visible: f64,
    band_visible: f64,
    band: f64,
}

impl Seen {
    /// Adds a patch of `weight` (∫ cos dΩ in front of the item) seen with `visibility` (0..1);
    /// `horizon`: the patch is in the band nearest the horizon.
    pub fn add(&mut self, weight: f64, visibility: f64, horizon: bool) {
        self.visible += weight * visibility;
        if horizon {
            self.band_visible += weight * visibility;
            self.band += weight;
        }
    }

    /// Sums two partial gatherings of the same item (over different patches).
    pub fn merge(&mut self, other: &Seen) {
        self.visible += other.visible;
        self.band_visible += other.band_visible;
        self.band += other.band;
    }

    /// The view factor to the visible sky, Σ visibility·weight / π.
    pub fn isotropic(&self) -> f64 {
        self.visible / std::f64::consts::PI
    }

    /// The horizon band's weight-averaged visibility; 1 where no band patch has weight.
    pub fn horizon(&self) -> f64 {
        if self.band <= 0.0 { 1.0 } else { self.band_visible / self.band }
    }
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
    progress(Progress::counting(0, requests.len()))?;
    engine.expect(requests.len());
    for chunk in requests.chunks(engine.batch().max(1) * BATCHES_PER_REPORT) {
        out.extend(engine.answer(chunk).await?.into_iter().map(|a| a.fraction));
        progress(Progress::counting(out.len(), requests.len()))?;
    }
    Ok(out)
}
