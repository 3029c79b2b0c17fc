//! Window studies as planning rules state them, per reference point (a window's centre on its
//! outside face, or its sill), each against its own truth in `tests/planning.rs`:
//! - [`vsc`]: BRE 209's vertical sky component under the CIE standard overcast sky;
//! - [`apsh`]: BRE 209's annual and winter probable sunlight hours, approximated from an EPW's
//!   direct normal irradiance;
//! - [`gb50180`]: GB 50180-2018's sunlight hours on 大寒日 or 冬至日 in true solar time;
//! - [`en17037`]: EN 17037's sunlight exposure, hours of sun on one day of 1 February – 21 March;
//! - [`bre_lines`]: BRE 209's 25° and 45° pre-checks, exact on the scene's triangles;
//! - [`compare`]: each rule's pass/fail, alone and against the existing scene's values
//!   (BRE's 0.8 × former value and 4-point APSH loss);
//! - [`mask`]: what a point sees of the sky and the sun's paths, for its stereographic diagram;
//! - [`run`]: every study asked, on one scene, sharing its shadow-ray tree;
//! - [`window_points`]: each window's reference point or sill, found from its geometry;
//! - [`sill_widths`]: each window's own 满窗 sill width, read from a CSV (or given by name);
//! - [`sill_lines`]: each window's own 满窗 sill line, measured from its geometry.
//!
//! The points are [`Windows`]: any list of directions is asked of them (not a period's suns),
//! answered by shadow rays through a BVH of the scene ([`crate::count::rays`]), or by the
//! exact engine's shadows, as for every map, where casters are see-through.

pub mod apsh;
pub mod bre_lines;
pub mod compare;
pub mod en17037;
pub mod gb50180;
pub mod mask;
pub mod run;
pub mod sill_lines;
pub mod sill_widths;
pub mod vsc;
pub mod window_points;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::{LitSeries, Mapper, Points};
use crate::count::MIN_COS_INCIDENCE;
use crate::count::rays::RayCaster;
use crate::error::{Error, Result};
use crate::scene::Scene;

/// One direction to ask every point about: towards `direction` (unit), at leaf fraction `leaves`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ask {
    /// Unit vector, world axes (x east, y north, z up).
    pub direction: DVec3,
    /// Foliage's leaf fraction (0 bare, 1 full).
    pub leaves: f32,
}

/// One scene's shadow-ray tree, built once and shared by every point set asked of that scene;
/// `None` inside where its casters are see-through (the points then take the exact engine's
/// shadows, see [`Windows::by_shadows`]).
#[derive(Clone)]
pub struct SceneRays(Option<Arc<RayCaster>>);

impl SceneRays {
    /// Indexes every triangle of `scene` (the costly part of [`Windows::new`]).
    pub fn new(scene: &Scene) -> Self {
        Self(RayCaster::new(scene).map(Arc::new))
    }
}

/// The points a window study asks about, indexed once for all its directions.
///
/// Opaque scenes (foliage included) are answered by shadow rays ([`RayCaster`]): a study asks a
/// thousand points about thousands of directions, and a ray costs the tree's nodes along one
/// line where a shadow view costs the whole sun prism of the point's receiver. A scene with
/// see-through casters keeps the exact engine's shadows ([`Mapper`]), which count a convex
/// see-through object once; both answer the same for opaque casters (`tests/planning.rs`).
pub struct Windows {
    caster: Caster,
    /// Each point's own normal (the studies weigh directions by it).
    normals: Vec<DVec3>,
}

enum Caster {
    Rays {
        rays: Arc<RayCaster>,
        /// Each point projected into its receiver's plane (where the shadow path puts it).
        origins: Vec<DVec3>,
        /// Each point's receiver's normal (which directions it faces) and id (which triangles
        /// never shade it).
        planes: Vec<(DVec3, u32)>,
    },
    Shadows(Box<Mapper>),
}

impl Windows {
    /// Indexes `points` on `scene`; refuses a point whose receiver is not in the scene.
    pub fn new(scene: &Scene, points: &Points) -> Result<Self> {
        Self::on(scene, &SceneRays::new(scene), points)
    }

    /// Indexes `points` on `scene` with its already built tree, so that several studies (and
    /// gb50180's sill samples) of one scene share one tree instead of each building its own.
    pub fn on(scene: &Scene, tree: &SceneRays, points: &Points) -> Result<Self> {
        let Some(rays) = tree.0.clone() else { return Self::by_shadows(scene, points) };
        let normals = (0..points.len()).map(|i| points.normal(i)).collect();
        let mut origins = Vec::with_capacity(points.len());
        let mut planes = Vec::with_capacity(points.len());
        for (i, &r) in points.receivers.iter().enumerate() {
            let receiver = scene.receivers.get(r as usize).ok_or_else(|| {
                Error::argument("points", format!("point {i} names receiver {r}; the scene has {}", scene.receivers.len()))
            })?;
            let Some(on) = receiver.triangles.first().map(|t| t[0]) else {
                return Err(Error::argument("points", format!("receiver '{}' has no area to put points on", receiver.name)));
            };
            let (p, n) = (points.position(i), receiver.normal);
            origins.push(p - n * n.dot(p - on));
            planes.push((n, r));
        }
        Ok(Self { caster: Caster::Rays { rays, origins, planes }, normals })
    }

    /// The same points answered by the exact engine's shadows whatever the casters (what
    /// [`Self::new`] does where casters are see-through; the rays are held to it).
    pub fn by_shadows(scene: &Scene, points: &Points) -> Result<Self> {
        let normals = (0..points.len()).map(|i| points.normal(i)).collect();
        Ok(Self { caster: Caster::Shadows(Box::new(Mapper::new(scene, points)?)), normals })
    }

    /// Whether the points are answered by rays ([`Self::new`] on an opaque scene).
    pub fn by_rays(&self) -> bool {
        matches!(self.caster, Caster::Rays { .. })
    }

    /// How many points.
    pub fn len(&self) -> usize {
        self.normals.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.normals.is_empty()
    }

    /// Point `i`'s normal.
    pub fn normal(&self, i: usize) -> DVec3 {
        self.normals[i]
    }

    /// Each point's visibility along each of `asks`, handed to `record(state, k, point,
    /// visibility)` with a thread's own state; a point whose receiver faces away from (or grazes)
    /// `asks[k]` is skipped (it sees nothing of it). Spread over every core; the states come
    /// back, one per thread.
    fn sweep<S: Send>(
        &self,
        asks: &[Ask],
        progress: &mut dyn FnMut(usize, usize),
        state: impl Fn() -> S + Sync,
        record: impl Fn(&mut S, usize, usize, f32) + Sync,
    ) -> Vec<S> {
        match &self.caster {
            Caster::Rays { rays, origins, planes } => {
                // Point by point: one point's thousands of rays keep its part of the tree warm.
                let next = AtomicUsize::new(0);
                let done = AtomicUsize::new(0);
                let work = || {
                    let mut s = state();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let (Some(&origin), Some(&(normal, receiver))) = (origins.get(i), planes.get(i)) else { break };
                        for (k, ask) in asks.iter().enumerate() {
                            if normal.dot(ask.direction) > MIN_COS_INCIDENCE {
                                let blocked = rays.blocked(origin, normal, receiver, ask.direction, ask.leaves);
                                record(&mut s, k, i, if blocked { 0.0 } else { 1.0 });
                            }
                        }
                        done.fetch_add(1, Ordering::Relaxed);
                    }
                    s
                };
                super::run_on_every_core(origins.len(), &done, progress, work)
            }
            Caster::Shadows(mapper) => sweep_shadows(mapper, asks, progress, state, |s, k, members, vis| {
                for (&i, &v) in members.iter().zip(vis) {
                    record(s, k, i as usize, v);
                }
            }),
        }
    }
}

/// [`Windows::sweep`] by the exact engine's shadows: direction by direction, every receiver's
/// points at once.
fn sweep_shadows<S: Send>(
    mapper: &Mapper,
    asks: &[Ask],
    progress: &mut dyn FnMut(usize, usize),
    state: impl Fn() -> S + Sync,
    record: impl Fn(&mut S, usize, &[u32], &[f32]) + Sync,
) -> Vec<S> {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let work = || {
        let mut s = state();
        let mut scratch = mapper.engine.point_scratch();
        let mut vis: Vec<f32> = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(ask) = asks.get(k) else { break };
            // A receiver facing away (or grazed) sees nothing of the direction: no rays needed.
            for g in mapper.groups.iter().filter(|g| g.normal.dot(ask.direction) > MIN_COS_INCIDENCE) {
                vis.resize(g.members.len(), 0.0);
                mapper.engine.visibility(&g.plane, ask.direction, ask.leaves, &mut scratch, &mut vis);
                record(&mut s, k, &g.members, &vis);
            }
            done.fetch_add(1, Ordering::Relaxed);
        }
        s
    };
    super::run_on_every_core(asks.len(), &done, progress, work)
}

/// Which of `asks` each point sees (visibility ≥ 0.5, the studies' rule), as a [`LitSeries`];
/// a direction below the horizon is seen by none.
fn lit_bits(windows: &Windows, asks: &[Ask], progress: &mut dyn FnMut(usize, usize)) -> LitSeries {
    let words = asks.len().div_ceil(64);
    let n = windows.len();
    let parts = windows.sweep(
        asks,
        progress,
        || vec![0u64; n * words],
        |bits, k, i, v| {
            if asks[k].direction.z >= MIN_COS_INCIDENCE && v >= 0.5 {
                bits[i * words + k / 64] |= 1 << (k % 64);
            }
        },
    );
    let mut bits = vec![0u64; n * words];
    for part in parts {
        for (a, b) in bits.iter_mut().zip(&part) {
            *a |= b;
        }
    }
    LitSeries { words, instants: asks.len(), bits }
}

/// A scene of one receiver, the polygon `corners` (counter-clockwise seen from outside) fanned
/// from its first corner: the window the sill and window-point tests measure.
#[cfg(test)]
#[allow(clippy::unwrap_used)]
pub(crate) fn test_window(corners: &[DVec3]) -> crate::scene::Scene {
    use crate::scene::{SceneBuilder, SourceMesh};
    let positions: Vec<[f32; 3]> = corners.iter().map(|c| c.as_vec3().to_array()).collect();
    let indices: Vec<u32> = (1..corners.len() as u32 - 1).flat_map(|i| [0, i, i + 1]).collect();
    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", SourceMesh { positions, indices }, true);
    b.build().unwrap()
}
