//! A map's sky: each point's own view of every sky patch, the per-point twin of the receivers'
//! [`crate::sky::views`], so that sky-diffuse irradiation can be summed point by point.
//!
//! Owns how a point's patch visibility is found, the same way a receiver's is:
//! - the patch layout is [`SkyPatches`] (Tregenza's 145 or Reinhart's MF:n);
//! - each patch is cut into [`SUBDIVISION`]² sub-patches ([`Patch::split`]), and each sub-patch's
//!   visibility is asked as the surface views ask a patch's: along the one direction that stands
//!   for its part in front of the receiver ([`Patch::weight`]'s cos-weighted mean direction), here
//!   by the exact engine's shadow rays ([`Mapper`]'s [`crate::count::exact::rays`]) from every
//!   point of the receiver at once: 0 or 1, or the transmittance of see-through casters. A
//!   surface's fraction is an area mean, smooth in the direction, so one direction a patch does
//!   for it; a point's visibility is a step in the direction (a louvre gap is a few degrees
//!   wide), and one ray per 12° Tregenza patch put points behind louvres 15–17 % off Radiance's
//!   sky (docs/maps.md);
//! - the sub-patch's weight is the point's own (∫ cos dΩ for the point's normal, the receiver's
//!   for a grid), and the visibilities are combined as the surfaces' are ([`Seen`], each
//!   sub-patch in its patch's band): view factor to the visible sky, horizon-band visibility, and
//!   the unobstructed view factor;
//! - with foliage, once at bare and once at full leaf ([`SkyViews`] interpolates between them as
//!   the leaf calendar ramps, as for surfaces).
//!
//! For a sky model that is a luminance distribution ([`crate::sky::model`]) each point also keeps
//! its visible ∫cos dΩ per patch (the sub-patches summed into their patch), and its sky diffuse is
//! the period's radiance per patch and leaf state summed over them ([`distribution_diffuse`]).
//!
//! Per timestep, [`SkyPlan`] adds each point's Perez sky diffuse ([`PerezSky`]) with its own
//! view factors and its circumsolar part shaded by its own sun visibility, as a receiver's
//! ([`crate::export::irradiation`]); where the max(0, …) of the Perez sum cannot bind for any
//! point of a plane, the parts every point shares are summed once per plane and timestep.
//!
//! The area mean of a grid's patch visibility is the receiver's patch fraction in the limit of a
//! fine grid (each is the shadow-free share of the receiver along the same direction), so the
//! grid's mean sky factor converges to the receiver's.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::Mapper;
use crate::count::MIN_COS_INCIDENCE;
use crate::sky::model::SkyModel;
use crate::sky::patches::{Patch, PatchWeight, SkyPatches};
use crate::sky::perez::PerezSky;
use crate::sky::views::{Seen, SkyViews};

/// Rows and columns each sky patch is cut into for a point's view of it.
pub const SUBDIVISION: usize = 6;

/// One receiver's points split by normal (a grid has one; CSV points may each have their own),
/// each normal with its patch weights.
struct NormalClasses {
    /// Per distinct normal, its patch weights.
    weights: Vec<Vec<PatchWeight>>,
    /// Per member of the group, its class.
    class: Vec<u32>,
}

/// Every point's sky views on `patches`, through `mapper`'s shadow rays, for the `energyplus`
/// sky. Spread over every core (natively; on the web the calling thread alone);
/// `progress(done, total)` counts patch views.
pub fn point_sky(mapper: &Mapper, patches: &SkyPatches, progress: &mut dyn FnMut(usize, usize)) -> SkyViews {
    point_sky_for(mapper, patches, SkyModel::EnergyPlus, progress)
}

/// [`point_sky`] kept for sky `model` (per patch for a distribution).
pub fn point_sky_for(mapper: &Mapper, patches: &SkyPatches, model: SkyModel, progress: &mut dyn FnMut(usize, usize)) -> SkyViews {
    let keep = if model.is_distribution() { patches.len() } else { 0 };
    let per_patch = SUBDIVISION * SUBDIVISION;
    let leaf_states: Vec<f32> = if mapper.foliage { vec![0.0, 1.0] } else { vec![1.0] };
    let fine: Vec<Patch> = patches.patches.iter().flat_map(|p| p.split(SUBDIVISION)).collect();
    let weights_of = |normal: DVec3| -> Vec<PatchWeight> { fine.iter().map(|p| p.weight(normal)).collect() };
    let receiver_weights: Vec<Vec<PatchWeight>> = mapper.groups.iter().map(|g| weights_of(g.normal)).collect();
    let classes: Vec<NormalClasses> = mapper.groups.iter().map(|g| classes(mapper, &g.members, &weights_of)).collect();
    // One job per (leaf state, group, patch in front of the receiver).
    let jobs: Vec<(usize, usize, usize)> = (0..leaf_states.len())
        .flat_map(|s| {
            receiver_weights
                .iter()
                .enumerate()
                .flat_map(move |(g, w)| w.iter().enumerate().filter(|(_, pw)| pw.weight > 0.0).map(move |(p, _)| (s, g, p)))
        })
        .collect();
    let n = mapper.points;
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let work = || {
        let mut seen = vec![vec![Seen::default(); n]; leaf_states.len()];
        let mut kept = vec![vec![0.0f32; n * keep]; leaf_states.len()];
        let mut scratch = mapper.engine.point_scratch();
        let mut vis: Vec<f32> = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(&(s, g, p)) = jobs.get(k) else { break (seen, kept) };
            let group = &mapper.groups[g];
            vis.resize(group.members.len(), 0.0);
            let direction = receiver_weights[g][p].direction;
            mapper.engine.visibility(&group.plane, direction, leaf_states[s], &mut scratch, &mut vis);
            let horizon = fine[p].band == 0;
            let c = &classes[g];
            for ((&i, &v), &class) in group.members.iter().zip(&vis).zip(&c.class) {
                let weight = c.weights[class as usize][p].weight;
                if weight > 0.0 {
                    seen[s][i as usize].add(weight, f64::from(v), horizon);
                    if keep > 0 {
                        kept[s][i as usize * keep + p / per_patch] += (weight * f64::from(v)) as f32;
                    }
                }
            }
            done.fetch_add(1, Ordering::Relaxed);
        }
    };
    let parts = super::run_on_every_core(jobs.len(), &done, progress, work);
    let mut seen = vec![vec![Seen::default(); n]; leaf_states.len()];
    let mut kept = vec![vec![0.0f32; n * keep]; leaf_states.len()];
    for (part, part_kept) in parts {
        for (into, from) in seen.iter_mut().zip(part) {
            for (a, b) in into.iter_mut().zip(&from) {
                a.merge(b);
            }
        }
        for (into, from) in kept.iter_mut().zip(&part_kept) {
            for (a, b) in into.iter_mut().zip(from) {
                *a += b;
            }
        }
    }
    let mut unobstructed = vec![0.0; n];
    for (g, c) in mapper.groups.iter().zip(&classes) {
        for (&i, &class) in g.members.iter().zip(&c.class) {
            unobstructed[i as usize] = c.weights[class as usize].iter().map(|w| w.weight).sum::<f64>() / std::f64::consts::PI;
        }
    }
    let views = SkyViews::from_seen(patches, leaf_states, &seen, unobstructed);
    if keep == 0 {
        return views;
    }
    // Each point's open weight per patch: its class's sub-patch weights summed into their patch.
    let mut open = vec![Vec::new(); n];
    for (g, c) in mapper.groups.iter().zip(&classes) {
        let sums: Vec<Vec<f32>> =
            c.weights.iter().map(|w| w.chunks(per_patch).map(|sub| sub.iter().map(|pw| pw.weight).sum::<f64>() as f32).collect()).collect();
        for (&i, &class) in g.members.iter().zip(&c.class) {
            open[i as usize].clone_from(&sums[class as usize]);
        }
    }
    let seen_per_point = kept.into_iter().map(|state| state.chunks(keep).map(<[f32]>::to_vec).collect()).collect();
    views.with_patches(model, seen_per_point, open)
}

/// Each point's sky diffuse (kWh/m²) over `samples` under the distribution its views were kept
/// for: the period's Σ radiance × hours per patch and leaf state, once for every point, then per
/// point Σ over patches of that times the point's visible ∫cos dΩ. `None` for views kept for the
/// `energyplus` sky.
pub(super) fn distribution_diffuse(mapper: &Mapper, site: super::Site<'_>, samples: &[super::Sample]) -> Option<Vec<f64>> {
    let (sky, weather) = (site.sky?, site.weather?);
    let distribution = sky.model().on(&sky.patches)?;
    let hourly = crate::year::samples::Timesteps::new(1).ok()?;
    let states = sky.leaf_states.len();
    let mut totals = vec![vec![0.0f64; sky.patches.len()]; states];
    for s in samples {
        let sun = mapper.sun(site, s);
        if sun.z < MIN_COS_INCIDENCE {
            continue;
        }
        let hour = weather.at(hourly, s.epw_hour);
        let Some(radiances) = distribution.radiances(hour.dni, hour.dhi, sun, s.day) else { continue };
        let t = site.calendar.fraction(f64::from(s.day)).clamp(0.0, 1.0);
        let weights = if states == 1 { [1.0, 0.0] } else { [1.0 - t, t] };
        for (total, w) in totals.iter_mut().zip(weights) {
            for (a, r) in total.iter_mut().zip(&radiances) {
                *a += r * w * s.hours / 1000.0;
            }
        }
    }
    Some((0..mapper.points).map(|i| sky.distribution_sum(i, &totals)).collect())
}

/// The distinct normals of a group's members and their weights.
fn classes(mapper: &Mapper, members: &[u32], weights_of: &dyn Fn(DVec3) -> Vec<PatchWeight>) -> NormalClasses {
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut weights = Vec::new();
    let class = members
        .iter()
        .map(|&i| {
            let normal = mapper.normals[i as usize];
            *index.entry(normal.to_array().map(f64::to_bits)).or_insert_with(|| {
                weights.push(weights_of(normal));
                (weights.len() - 1) as u32
            })
        })
        .collect();
    NormalClasses { weights, class }
}

/// What the per-timestep sky sums share per group of points ([`SkySums`]).
pub(super) struct SkyPlan<'a> {
    sky: &'a SkyViews,
    groups: Vec<GroupSky>,
}

/// One group's points as the sky sums see them.
struct GroupSky {
    /// The members' common normal; `None` when they differ (CSV points), then each point is
    /// summed on its own.
    normal: Option<DVec3>,
    /// The range of the members' view factors and horizon visibilities over the leaf states.
    isotropic: (f64, f64),
    horizon: (f64, f64),
}

/// A thread's running sky-diffuse sums, kWh/m²: per point, and per group and leaf state the
/// isotropic and horizon terms, which are the same for every point of a plane and are multiplied
/// by each point's view factors at the end.
pub(super) struct SkySums {
    per_point: Vec<f64>,
    shared: Vec<[f64; 2]>,
}

impl<'a> SkyPlan<'a> {
    pub(super) fn new(mapper: &Mapper, sky: &'a SkyViews) -> Self {
        let states: Vec<f64> = sky.leaf_states.iter().map(|&s| f64::from(s)).collect();
        let groups = mapper
            .groups
            .iter()
            .map(|g| {
                let first = g.members.first().map(|&i| mapper.normals[i as usize]);
                let normal = first.filter(|n| g.members.iter().all(|&i| mapper.normals[i as usize] == *n));
                let range = |value: &dyn Fn(usize, f64) -> f64| {
                    g.members
                        .iter()
                        .flat_map(|&i| states.iter().map(move |&s| value(i as usize, s)))
                        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
                };
                GroupSky { normal, isotropic: range(&|i, s| sky.isotropic(i, s)), horizon: range(&|i, s| sky.horizon(i, s)) }
            })
            .collect();
        Self { sky, groups }
    }

    pub(super) fn sums(&self, points: usize) -> SkySums {
        SkySums { per_point: vec![0.0; points], shared: vec![[0.0; 2]; self.groups.len() * self.sky.leaf_states.len()] }
    }

    /// Weights of the leaf states at leaf fraction `leaves` ([`SkyViews`] is linear between them).
    fn state_weights(&self, leaves: f64) -> [f64; 2] {
        if self.sky.leaf_states.len() == 1 {
            [1.0, 0.0]
        } else {
            let t = leaves.clamp(0.0, 1.0);
            [1.0 - t, t]
        }
    }

    /// Adds one timestep (`hours` long, sky `perez` with diffuse horizontal `dhi` W/m², sun `sun`,
    /// leaf fraction `leaves`) on group `g` whose points see the sun with `visibility` (empty:
    /// none sees it).
    #[allow(clippy::too_many_arguments)] // One timestep's state, handed down from the sweep.
    pub(super) fn add(
        &self,
        sums: &mut SkySums,
        mapper: &Mapper,
        g: usize,
        perez: &PerezSky,
        dhi: f64,
        sun: DVec3,
        leaves: f64,
        hours: f64,
        visibility: &[f32],
    ) {
        let group = &mapper.groups[g];
        let plan = &self.groups[g];
        let scale = hours / 1000.0;
        if let Some(normal) = plan.normal {
            let terms = perez.terms(dhi, normal.dot(sun).max(0.0), normal.truncate().length());
            // The circumsolar part is ≥ 0, so when the isotropic and horizon parts cannot make any
            // point's sum negative, Perez's max(0, …) never binds and the sum is linear: the
            // shared parts are summed once for the group.
            let low = (terms.isotropic * plan.isotropic.0).min(terms.isotropic * plan.isotropic.1)
                + (terms.horizon * plan.horizon.0).min(terms.horizon * plan.horizon.1);
            if low >= 0.0 {
                let states = self.sky.leaf_states.len();
                for (s, w) in self.state_weights(leaves).iter().take(states).enumerate() {
                    let shared = &mut sums.shared[g * states + s];
                    shared[0] += terms.isotropic * w * scale;
                    shared[1] += terms.horizon * w * scale;
                }
                for (&i, &v) in group.members.iter().zip(visibility) {
                    if v > 0.0 {
                        sums.per_point[i as usize] += terms.circumsolar * f64::from(v) * scale;
                    }
                }
                return;
            }
        }
        let dark = [0.0f32];
        let shades = group.members.iter().enumerate().map(|(k, _)| visibility.get(k).unwrap_or(&dark[0]));
        for (&i, &v) in group.members.iter().zip(shades) {
            let i = i as usize;
            let normal = mapper.normals[i];
            let terms = perez.terms(dhi, normal.dot(sun).max(0.0), normal.truncate().length());
            sums.per_point[i] += terms.diffuse(self.sky.isotropic(i, leaves), f64::from(v), self.sky.horizon(i, leaves)) * scale;
        }
    }

    /// Each point's sky diffuse (kWh/m²) from the threads' sums.
    pub(super) fn finish(&self, mapper: &Mapper, parts: impl IntoIterator<Item = SkySums>) -> Vec<f64> {
        let mut total = self.sums(mapper.points);
        for part in parts {
            super::add_into(&mut total.per_point, &part.per_point);
            for (a, b) in total.shared.iter_mut().zip(&part.shared) {
                a[0] += b[0];
                a[1] += b[1];
            }
        }
        let states = &self.sky.leaf_states;
        for (g, group) in mapper.groups.iter().enumerate() {
            for (s, &state) in states.iter().enumerate() {
                let [isotropic, horizon] = total.shared[g * states.len() + s];
                if isotropic == 0.0 && horizon == 0.0 {
                    continue;
                }
                let state = f64::from(state);
                for &i in &group.members {
                    let i = i as usize;
                    total.per_point[i] += isotropic * self.sky.isotropic(i, state) + horizon * self.sky.horizon(i, state);
                }
            }
        }
        total.per_point
    }
}
