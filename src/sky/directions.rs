//! Sunlit fractions for given sun directions, every receiver facing each: what SAM's azimuth ×
//! altitude shading table is made of ([`crate::export::pv`]). The engine counts them as sky
//! views are counted (a direction, not a timestep); a receiver facing away or a sun below the
//! horizon is 0 without a view.

use glam::DVec3;

use crate::count::{Engine, ViewRequest, is_dark};
use crate::error::Result;
use crate::scene::Scene;
use crate::sky::views::count;
use crate::year::annual::Progress;

/// `fractions[d][r]`: receiver `r`'s sunlit fraction for a sun towards `directions[d]`.
pub async fn direction_fractions(
    engine: &impl Engine,
    scene: &Scene,
    directions: &[DVec3],
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Vec<Vec<f64>>> {
    let mut requests = Vec::new();
    let mut at = Vec::new();
    for (d, &sun) in directions.iter().enumerate() {
        for (r, receiver) in scene.receivers.iter().enumerate() {
            if !is_dark(receiver.normal, sun) {
                requests.push(ViewRequest::new(r as u32, sun));
                at.push((d, r));
            }
        }
    }
    let counted = count(engine, &requests, progress).await?;
    let mut out = vec![vec![0.0; scene.receivers.len()]; directions.len()];
    for ((d, r), f) in at.into_iter().zip(counted) {
        out[d][r] = f;
    }
    Ok(out)
}
