//! Maps on the GPU: each point answered by its texel in the tile the pixel counter renders for
//! its receiver ([`crate::count::gpu::masks`]), instead of by a shadow ray.
//!
//! A [`MapGpu`] holds a map's scene and points on a counter's device. Its sweeps ask the counter
//! for many (receiver, instant) views at once (every receiver with points that faces the sun, for
//! as many sun-up instants as fill [`REQUESTS_PER_CALL`]), and hand each view's points, as 0/1
//! visibilities, to the same per-point sums the exact rays feed ([`super::Mapper`]). One view
//! serves both the receiver's fraction and its points: the masks are read from the counting's
//! tiles.
//!
//! Asynchronous, as the counter is, so the same code runs natively (the CLI blocks on it) and on
//! the web (not wired to the page yet: the page maps with the exact rays).

use glam::DVec3;

use super::{Group, Mapper, Points, Sample, Site};
use crate::count::gpu::masks::GpuPoints;
use crate::count::gpu::{Counter, GpuScene};
use crate::count::{MIN_COS_INCIDENCE, ViewRequest, is_dark};
use crate::error::Result;
use crate::scene::Scene;

/// Views asked of the counter per call: enough to fill many atlas batches per read-back.
pub const REQUESTS_PER_CALL: usize = 2048;

/// A map's scene and points uploaded to a counter's device.
pub struct MapGpu<'a> {
    counter: &'a Counter,
    scene: GpuScene,
    points: GpuPoints,
    /// Point-instants answered by a rendered mask (the others were decided without a render:
    /// sun down, surface facing away, nothing in front).
    rendered: std::sync::atomic::AtomicU64,
}

impl<'a> MapGpu<'a> {
    /// Uploads `scene` and `points` to `counter`'s device.
    pub fn new(counter: &'a Counter, scene: &Scene, points: &Points) -> Result<Self> {
        let gpu_scene = counter.upload(scene)?;
        let gpu_points = counter.upload_points(&gpu_scene, &points.positions, &points.receivers)?;
        Ok(Self { counter, scene: gpu_scene, points: gpu_points, rendered: 0.into() })
    }

    /// Point-instants answered by a rendered mask so far.
    pub fn rendered(&self) -> u64 {
        self.rendered.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Every sun-up instant's visibility per receiver, handed to `record` with one state (made
    /// by `state`), as [`Mapper`]'s own sweep hands the rays' answers.
    pub(super) async fn sweep<S>(
        &self,
        mapper: &Mapper,
        samples: &[Sample],
        site: Site<'_>,
        progress: &mut dyn FnMut(usize, usize),
        state: impl Fn() -> S,
        record: impl Fn(&mut S, usize, &Sample, DVec3, &Group, &[f32]),
    ) -> Result<Vec<S>> {
        let mut s = state();
        let mut views: Vec<View> = Vec::new();
        let mut zeros: Vec<f32> = Vec::new();
        let mut k = 0;
        while k < samples.len() {
            views.clear();
            while k < samples.len() && views.len() < REQUESTS_PER_CALL {
                let sample = &samples[k];
                let sun = mapper.sun(site, sample);
                if sun.z >= MIN_COS_INCIDENCE {
                    let leaves = site.calendar.fraction(f64::from(sample.day)) as f32;
                    self.views_at(mapper, k, sun, leaves, &mut views);
                    // Receivers facing away are not rendered, but they are recorded (all shaded):
                    // the sky's shared terms still count for them, as in the rays' sweep.
                    for g in mapper.groups.iter().filter(|g| is_dark(g.normal, sun)) {
                        zeros.clear();
                        zeros.resize(g.members.len(), 0.0);
                        record(&mut s, k, sample, sun, g, &zeros);
                    }
                }
                k += 1;
            }
            self.answer(mapper, &views, |view, g, vis| record(&mut s, view.k, &samples[view.k], view.sun, g, vis)).await?;
            progress(k, samples.len());
        }
        Ok(vec![s])
    }

    /// One instant's visibility per receiver, handed to `record`.
    pub(super) async fn instant(&self, mapper: &Mapper, sun: DVec3, leaves: f32, mut record: impl FnMut(&Group, &[f32])) -> Result<()> {
        if sun.z < MIN_COS_INCIDENCE {
            return Ok(());
        }
        let mut views = Vec::new();
        self.views_at(mapper, 0, sun, leaves, &mut views);
        self.answer(mapper, &views, |_, g, vis| record(g, vis)).await
    }

    /// The views of instant `k`: every receiver with points that faces the sun.
    fn views_at(&self, mapper: &Mapper, k: usize, sun: DVec3, leaves: f32, views: &mut Vec<View>) {
        for (group, g) in mapper.groups.iter().enumerate() {
            if !is_dark(g.normal, sun) {
                views.push(View { k, sun, group, request: ViewRequest::new(g.plane.receiver(), sun).with_leaves(leaves) });
            }
        }
    }

    /// Renders `views` and hands each one's points' visibilities (in the group's order, which is
    /// the masks' order: both follow the points as given) to `record`.
    async fn answer(&self, mapper: &Mapper, views: &[View], mut record: impl FnMut(&View, &Group, &[f32])) -> Result<()> {
        if views.is_empty() {
            return Ok(());
        }
        let requests: Vec<ViewRequest> = views.iter().map(|v| v.request).collect();
        let masks = self.counter.masks(&self.scene, &self.points, &requests, false).await?;
        let mut vis: Vec<f32> = Vec::new();
        let mut rendered = 0u64;
        for (i, view) in views.iter().enumerate() {
            let g = &mapper.groups[view.group];
            vis.clear();
            vis.extend((0..g.members.len()).map(|j| if masks.lit(i, j) { 1.0 } else { 0.0 }));
            if matches!(masks.masks[i], crate::count::gpu::masks::PointMask::Rendered { .. }) {
                rendered += g.members.len() as u64;
            }
            record(view, g, &vis);
        }
        self.rendered.fetch_add(rendered, std::sync::atomic::Ordering::Relaxed);
        Ok(())
    }
}

/// One (receiver, instant) view of a sweep.
struct View {
    k: usize,
    sun: DVec3,
    group: usize,
    request: ViewRequest,
}
