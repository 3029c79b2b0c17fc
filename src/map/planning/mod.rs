//! Window studies as planning rules state them, per reference point (a window's centre on its
//! outside face, or its sill), each against its own truth in `tests/planning.rs`:
//! - [`vsc`]: BRE 209's vertical sky component under the CIE standard overcast sky;
//! - [`apsh`]: BRE 209's annual and winter probable sunlight hours, approximated from an EPW's
//!   direct normal irradiance;
//! - [`gb50180`]: GB 50180-2018's sunlight hours on 大寒日 or 冬至日 in true solar time;
//! - [`compare`]: each rule's pass/fail, alone and against the existing scene's values
//!   (BRE's 0.8 × former value and 4-point APSH loss);
//! - [`mask`]: what a point sees of the sky and the sun's paths, for its stereographic diagram.
//!
//! The points are [`Mapper`]'s, answered by the same exact shadow rays as every map; what is new
//! here is only which directions are asked ([`sweep_directions`]: any list of directions, not a
//! period's suns) and how the answers are weighed.

pub mod apsh;
pub mod compare;
pub mod gb50180;
pub mod mask;
pub mod vsc;

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DVec3;

use super::{Group, LitSeries, Mapper};
use crate::count::MIN_COS_INCIDENCE;

/// One direction to ask every point about: towards `direction` (unit), at leaf fraction `leaves`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ask {
    /// Unit vector, world axes (x east, y north, z up).
    pub direction: DVec3,
    /// Foliage's leaf fraction (0 bare, 1 full).
    pub leaves: f32,
}

/// Each point's visibility along each of `asks`, handed to `record(state, k, group, visibility)`
/// with a thread's own state; groups whose receiver faces away from (or grazes) `asks[k]` are
/// skipped (their points see nothing of it). Spread over every core; the states come back, one
/// per thread.
fn sweep_directions<S: Send>(
    mapper: &Mapper,
    asks: &[Ask],
    progress: &mut dyn FnMut(usize, usize),
    state: impl Fn() -> S + Sync,
    record: impl Fn(&mut S, usize, &Group, &[f32]) + Sync,
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
                record(&mut s, k, g, &vis);
            }
            done.fetch_add(1, Ordering::Relaxed);
        }
        s
    };
    super::run_on_every_core(asks.len(), &done, progress, work)
}

/// Which of `asks` each point sees (visibility ≥ 0.5, the studies' rule), as a [`LitSeries`];
/// a direction below the horizon is seen by none.
fn lit_bits(mapper: &Mapper, asks: &[Ask], progress: &mut dyn FnMut(usize, usize)) -> LitSeries {
    let words = asks.len().div_ceil(64);
    let n = mapper.points;
    let parts = sweep_directions(
        mapper,
        asks,
        progress,
        || vec![0u64; n * words],
        |bits, k, g, vis| {
            if asks[k].direction.z < MIN_COS_INCIDENCE {
                return;
            }
            for (&i, &v) in g.members.iter().zip(vis) {
                if v >= 0.5 {
                    bits[i as usize * words + k / 64] |= 1 << (k % 64);
                }
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
