//! The views a spline year counts at its samples: which receiver at which sun, and which cell of
//! which regime's sample grid each count fills ([`super::annual`] fits the grids).
//!
//! Owns listing them (twin days sharing views), ordering them by sun, and numbering the cells of
//! a range of the scene's receivers, so a year may be counted a batch of receivers at a time.

use std::ops::Range;

use super::{MAX_PIECES, Regime, sun_day};
use crate::count::{MIN_COS_INCIDENCE, ViewRequest};
use crate::error::Result;
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::{declination_and_equation_of_time, lit_intervals, solar_noon_hour, sun_direction};
use crate::year::samples::SamplingPlan;

/// The views the sample grids need, and where each count goes.
pub(super) struct SampleViews {
    /// Each at its regime's leaf fraction.
    pub requests: Vec<ViewRequest>,
    /// (request, regime, cell): the count of `request` fills `cell` of `regime`'s samples.
    pub cells: Vec<(usize, usize, usize)>,
}

/// Lists the views of every regime's samples for the scene's `receivers`: per receiver, sample
/// day, lit piece and time of day. A day whose twin (same declination, see [`SeasonAxis`](crate::year::samples::SeasonAxis)) has
/// been listed and whose lit pieces are the twin's, shifted by the difference in solar noon,
/// takes the twin's views: the sun directions are the same, so the counts would be. A cell is
/// numbered from the range's first receiver; a view names the scene's receiver.
pub(super) fn sample_views(scene: &Scene, receivers: Range<usize>, location: &Location, regimes: &[Regime], taus: &[f64]) -> SampleViews {
    let mut out = SampleViews { requests: Vec::new(), cells: Vec::new() };
    for (g, regime) in regimes.iter().enumerate() {
        let per_piece = regime.days.len() * taus.len();
        for (local, id) in receivers.clone().enumerate() {
            let r = &scene.receivers[id];
            // First request of each (day, piece), to share with the twin day.
            let mut first: Vec<Vec<(f64, f64, usize)>> = vec![Vec::new(); regime.days.len()];
            for (d, &day) in regime.days.iter().enumerate() {
                let day = sun_day(day);
                let noon = solar_noon_hour(location, day);
                let pieces: Vec<(f64, f64)> =
                    lit_intervals(location, r.normal, day, MIN_COS_INCIDENCE).into_iter().take(MAX_PIECES).collect();
                let twin = regime.twins[d];
                let shared = twin < d && same_declination(day, sun_day(regime.days[twin])) && same_pieces(&first[twin], &pieces, noon);
                for (p, (start, end)) in pieces.into_iter().enumerate() {
                    let base = if shared { first[twin][p].2 } else { out.requests.len() };
                    first[d].push((start - noon, end - noon, base));
                    for (j, tau) in taus.iter().enumerate() {
                        if !shared {
                            let sun = sun_direction(location, day, start + tau * (end - start));
                            out.requests.push(ViewRequest::new(id as u32, sun).with_leaves(regime.leaves[d]));
                        }
                        out.cells.push((base + j, g, (local * MAX_PIECES + p) * per_piece + d * taus.len() + j));
                    }
                }
            }
        }
    }
    by_sun(out)
}

/// Reorders the views so that those at one sun (and leaf fraction) are adjacent: receivers of
/// one view group (a wall and its windows, [`crate::count::group`]) then share a tile even when
/// the views are counted a batch at a time.
fn by_sun(views: SampleViews) -> SampleViews {
    let key = |k: usize| {
        let r = views.requests[k];
        (r.sun.x.to_bits(), r.sun.y.to_bits(), r.sun.z.to_bits(), r.leaves.to_bits(), r.receiver)
    };
    let mut order: Vec<usize> = (0..views.requests.len()).collect();
    order.sort_by_key(|&k| key(k));
    let mut new_index = vec![0; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new;
    }
    SampleViews {
        requests: order.iter().map(|&k| views.requests[k]).collect(),
        cells: views.cells.into_iter().map(|(request, g, cell)| (new_index[request], g, cell)).collect(),
    }
}

/// Whether two days have the same declination (to rounding): no twin exists across New Year,
/// where the sun model's 366-day series meets the schedule's 365-day year.
fn same_declination(a: f64, b: f64) -> bool {
    (declination_and_equation_of_time(a).0 - declination_and_equation_of_time(b).0).abs() < 1e-10
}

/// Whether a day's lit pieces (clock hours, solar noon at `noon`) are the twin's (hours from its
/// solar noon): the same hour angles, so the same sun directions. They differ only where a piece
/// is cut at midnight (polar day), which the equation of time moves.
fn same_pieces(twin: &[(f64, f64, usize)], pieces: &[(f64, f64)], noon: f64) -> bool {
    const HOURS: f64 = 1e-6;
    twin.len() == pieces.len()
        && twin.iter().zip(pieces).all(|(t, p)| (t.0 - (p.0 - noon)).abs() < HOURS && (t.1 - (p.1 - noon)).abs() < HOURS)
}

/// The views the spline pass counts for a scene without foliage: the plan's samples, a day that
/// shares its twin's views listed once. What `sunlit bench` times.
pub fn sample_requests(scene: &Scene, location: &Location, plan: SamplingPlan) -> Result<Vec<ViewRequest>> {
    let taus = plan.taus();
    let regime = Regime::year(plan, &taus, 1.0)?;
    Ok(sample_views(scene, 0..scene.receivers.len(), location, std::slice::from_ref(&regime), &taus).requests)
}
