//! Canopies: whether what a receiver sees of the sun over a set of suns (the volume its points
//! sweep along the cone holding them, as for the lit proof) is crossed by many small casters,
//! such as a tree's leaves, rather than by one long edge such as an overhang's or a fin's.
//!
//! This is not a proof of any fraction; the year uses it to choose how closely it follows the
//! spline ([`crate::year::refine`]). A canopy's hundreds of small shadows make the fraction wander
//! a percent or two from one sample to the next nearly everywhere, so a tight test for a kink
//! counts much and gains little there; one shadow edge entering a window makes a single kink
//! that the tight test is for.
//!
//! A caster is *small* when it is one of the exact engine's convex objects (a leaf, a flat
//! convex polygon, a closed convex solid; [`crate::count::exact`]) whose corners fit in a box
//! with a diagonal no longer than [`SMALL_SHARE`] of the receiver's size (the square root of its
//! area). Triangles of a caster
//! that is not convex never count as small: a finely tessellated curved overhang is made of
//! small triangles but throws one long edge. The volume is under a canopy when at least
//! [`MANY`] distinct small casters lie in it (the lit proof's exact test, `misses`); large
//! casters may lie there too.

use glam::DVec3;

use super::{CHUNK, Certifier};
use crate::count::exact::engine::{parallel_chunks, worker_threads};
use crate::count::view;

/// A convex caster no wider than this share of its receiver's size (square root of its area)
/// is small. blaas-trees-summer's leaves (triangles of side 0.1 m) against its 6 × 2 m windows:
/// about 0.04; a louvre slat (6.2 m long) against the same windows: 1.8; the 100-zone file's
/// overhangs (2.44 or 1.22 m by 0.76 m) against its windows and walls: 0.21 to 0.42.
pub const SMALL_SHARE: f64 = 0.125;

/// Distinct small casters in a receiver's swept volume that make it a canopy's.
pub const MANY: usize = 32;

impl Certifier<'_> {
    /// For many sets at once (receiver, its suns), in order: [`Self::under_canopy`]; natively
    /// over every core.
    pub fn under_canopy_all(&self, sets: &[(usize, &[DVec3])]) -> Vec<bool> {
        let threads = worker_threads().min(sets.len().div_ceil(CHUNK)).max(1);
        parallel_chunks(sets.len(), threads, CHUNK, || (), |i, _| self.under_canopy(sets[i].0, sets[i].1))
    }

    /// Whether at least [`MANY`] distinct small casters lie in the volume `receiver` sweeps
    /// along the cone holding `suns` (module doc). False where no such cone exists (a sun
    /// behind the receiver or below the horizon).
    pub fn under_canopy(&self, receiver: usize, suns: &[DVec3]) -> bool {
        let Some((shape, cone)) = self.cone_of(receiver, suns) else { return false };
        let widest = SMALL_SHARE * area(&shape.points).sqrt();
        let corners = self.swept_corners(&shape.points, &cone, self.reach(&cone));
        let view = view::fit(&corners, cone.axis(), self.index.bounds, self.index.origin, 64);
        let (mut small, mut w) = (Vec::with_capacity(MANY), Vec::new());
        self.index.culling.visit_triangles(&view.view_proj, |r| {
            for p in r {
                if small.len() >= MANY {
                    return;
                }
                let Some(o) = self.index.objects.of(p) else { continue };
                if small.contains(&o) || !self.no_wider(o, widest) || self.misses(shape, &cone, &self.index.triangles[p], &mut w) {
                    continue;
                }
                small.push(o);
            }
        });
        small.len() >= MANY
    }

    /// Whether object `o`'s corners fit in a box whose diagonal is at most `widest` (stops at
    /// the first corner that widens it past that: a large object is told after a few).
    fn no_wider(&self, o: u32, widest: f64) -> bool {
        let mut corners = self.index.objects.corners(o).iter().map(|&c| self.index.corner(c));
        let Some(first) = corners.next() else { return true };
        let (mut lo, mut hi) = (first, first);
        corners.all(|c| {
            (lo, hi) = (lo.min(c), hi.max(c));
            lo.distance(hi) <= widest
        })
    }
}

/// The area of a receiver's triangles (its vertices three by three).
fn area(points: &[DVec3]) -> f64 {
    points.chunks_exact(3).map(|t| (t[1] - t[0]).cross(t[2] - t[0]).length() / 2.0).sum()
}

#[cfg(test)]
pub(crate) mod tests;
