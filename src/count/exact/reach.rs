//! Boxes around what a view's walk reaches, for the fast exact engine ([`super::engine`]): a
//! world box per convex object (its corners) and per BVH leaf (every object with a triangle in
//! the leaf, whole, and the leaf's lone triangles), and the test that says from a box alone that
//! nothing inside it casts a shadow on a receiver in a view.
//!
//! Owns only that test and the boxes it reads. Why: most of what a district view's walk reaches
//! casts nothing (behind the receiver's plane, or projected beside it), and the engine found that
//! out corner by corner, triangle by triangle. The box test answers for a whole object or leaf
//! with one projected centre, and only ever where the corner test would have answered "casts
//! nothing" ([`PlaneFrame::box_casts_nothing`]), so every view's answer stays bit for bit what it
//! was: a skipped object or leaf is one whose shadows the engine would have dropped unpushed.

use std::ops::Range;

use glam::{DMat4, DVec2, DVec3, DVec4};

use super::placed::PlacedObjects;
use super::{PlaneFrame, Rect};
use crate::count::cull::Culling;

/// No leaf starts at this position.
const NO_LEAF: u32 = u32::MAX;
/// Relative slack on the box test, far above the rounding of a corner's projection (a few ulps
/// of its coordinates); only how often a box decides depends on it, never an answer.
const SLACK: f64 = 1e-12;

/// An axis-aligned world box, its corners exactly the extremes of the points it was made around.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct WorldBox {
    lo: DVec3,
    hi: DVec3,
}

impl WorldBox {
    /// The box around some points; `None` when there are none or one is not finite (no box then
    /// decides anything).
    fn around(points: impl IntoIterator<Item = DVec3>) -> Option<Self> {
        let mut out: Option<Self> = None;
        for p in points {
            if !p.is_finite() {
                return None;
            }
            out = Some(out.map_or(Self { lo: p, hi: p }, |b| Self { lo: b.lo.min(p), hi: b.hi.max(p) }));
        }
        out
    }

    /// The box around both.
    fn union(&self, other: &Self) -> Self {
        Self { lo: self.lo.min(other.lo), hi: self.hi.max(other.hi) }
    }
}

/// The boxes of a scene's convex objects and BVH leaves, built once with the engine.
#[derive(Debug, Default)]
pub(super) struct Reach {
    objects: Vec<Option<WorldBox>>,
    /// Per triangle position: the leaf whose range starts there, or [`NO_LEAF`].
    leaf_at: Vec<u32>,
    /// Per leaf: the end of its range and its box.
    leaves: Vec<(usize, Option<WorldBox>)>,
}

impl Reach {
    /// The boxes of `objects` (whose corners are `corner(c)`) and of `culling`'s leaves over the
    /// world `triangles` (by position).
    pub(super) fn new(culling: &Culling, triangles: &[[DVec3; 3]], objects: &PlacedObjects, corner: impl Fn(u32) -> DVec3) -> Self {
        let object_boxes: Vec<Option<WorldBox>> =
            (0..objects.len() as u32).map(|o| WorldBox::around(objects.corners(o).iter().map(|&c| corner(c)))).collect();
        let mut leaf_at = vec![NO_LEAF; triangles.len() + 1];
        let mut leaves = Vec::new();
        // A view that touches every box: every point maps to the clip volume's centre.
        let everything = DMat4::from_cols(DVec4::ZERO, DVec4::ZERO, DVec4::ZERO, DVec4::new(0.0, 0.0, 0.5, 1.0));
        culling.visit_triangles(&everything, |r| {
            let Some(slot) = leaf_at.get_mut(r.start) else { return };
            let boxes = r.clone().map(|p| match objects.of(p) {
                Some(o) => object_boxes[o as usize],
                None => WorldBox::around(triangles[p]),
            });
            let whole = boxes.reduce(|a, b| a.zip(b).map(|(a, b)| a.union(&b))).flatten();
            *slot = leaves.len() as u32;
            leaves.push((r.end, whole));
        });
        Self { objects: object_boxes, leaf_at, leaves }
    }

    /// Object `o`'s box (`None`: not finite, or unknown).
    pub(super) fn object(&self, o: u32) -> Option<&WorldBox> {
        self.objects.get(o as usize)?.as_ref()
    }

    /// The box of the leaf covering exactly the positions `r` (`None` when `r` is no leaf's
    /// range, or its box is not finite).
    pub(super) fn leaf(&self, r: &Range<usize>) -> Option<&WorldBox> {
        let &leaf = self.leaf_at.get(r.start)?;
        let (end, b) = self.leaves.get(leaf as usize)?;
        if *end == r.end { b.as_ref() } else { None }
    }
}

impl PlaneFrame {
    /// Whether no corner inside `b` casts anything on a receiver of `bounds` in this frame's view
    /// as [`super::engine`]'s corner test decides it (then casting the triangles would push no
    /// shadow either): the box lies on or behind the plane, or its projection along the sun,
    /// widened by the corner test's own margin, misses `bounds`. Sound, not tight: each bound
    /// below holds every corner's projection *as the corner test computes it*, so `true` only
    /// where that test says Miss for every corner set inside the box.
    ///
    /// For a corner `p` in the box (centre `c`, half extents `e`, `d = c − origin`): its height
    /// `n·(p − origin)` is at most `n·d + |n|·e`, and its projection's x is `(e1 + sx·n)·(p −
    /// origin)` within `|sx|·eps` (a height within `eps` of the plane is taken as 0), so within
    /// `|e1 + sx·n|·e` of that at `d` (and alike in y). `SLACK` covers both sides' rounding.
    pub(super) fn box_casts_nothing(&self, b: &WorldBox, bounds: &Rect) -> bool {
        let s = self.shift_per_height;
        // Centre ± half holds [lo, hi] to an ulp of the coordinates, which the slack covers.
        let (center, half) = (0.5 * (b.lo + b.hi), 0.5 * (b.hi - b.lo));
        let scale = center.abs().element_sum() + self.origin.abs().element_sum() + half.element_sum();
        let slack = SLACK * scale * (1.0 + s.x.abs() + s.y.abs());
        let d = center - self.origin;
        let height = self.normal.dot(d);
        if height + self.normal.abs().dot(half) + slack <= self.eps {
            return true;
        }
        let (ax, ay) = (self.e1 + self.normal * s.x, self.e2 + self.normal * s.y);
        let centre = DVec2::new(self.e1.dot(d) + s.x * height, self.e2.dot(d) + s.y * height);
        let reach = DVec2::new(ax.abs().dot(half), ay.abs().dot(half)) + s.abs() * self.eps + DVec2::splat(slack);
        let (lo, hi) = (centre - reach, centre + reach);
        // The corner test's own, at this box's larger extremes (a margin never less than at the
        // corners').
        self.projections_miss(lo, hi, bounds)
    }

    /// A corner's height above the plane and its projection along the sun, as the corner test
    /// takes them.
    pub(super) fn corner_projection(&self, p: DVec3) -> (f64, DVec2) {
        let h = self.height(p);
        (h, self.to_2d(p) + self.shift_per_height * h)
    }

    /// The corner test's verdict on the box `lo..hi` of some corners' projections: it misses
    /// `bounds` even widened by more than rounding can move a clipped triangle's crossing points
    /// (a clipped triangle's projection lies within the hull of its corners': the projection is
    /// affine and a crossing lies between two corners). `false` when not finite.
    pub(super) fn projections_miss(&self, lo: DVec2, hi: DVec2, bounds: &Rect) -> bool {
        if !(lo.is_finite() && hi.is_finite()) {
            return false;
        }
        let margin = self.eps * (1.0 + self.shift_per_height.length()) + 1e-9 * lo.abs().max(hi.abs()).max_element();
        !(Rect { min: lo, max: hi }).expanded(margin).overlaps(bounds)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// A repeatable xorshift in [0, 1).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn within(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }

        fn unit(&mut self) -> DVec3 {
            loop {
                let v = DVec3::new(self.within(-1.0, 1.0), self.within(-1.0, 1.0), self.within(-1.0, 1.0));
                if (0.1..1.0).contains(&v.length()) {
                    return v.normalize();
                }
            }
        }
    }

    /// The engine's corner test (`ExactEngine::project_corners`): no corner in front of the
    /// plane, or their projections' box misses the receiver's bounds.
    fn corners_miss(frame: &PlaneFrame, corners: &[DVec3], bounds: &Rect) -> bool {
        let (mut above, mut lo, mut hi) = (false, DVec2::MAX, DVec2::MIN);
        for &p in corners {
            let (h, q) = frame.corner_projection(p);
            above |= h > 0.0;
            (lo, hi) = (lo.min(q), hi.max(q));
        }
        !above || frame.projections_miss(lo, hi, bounds)
    }

    /// Objects placed right at the edges where the corner test changes its mind: their
    /// projections' box a margin or two from the receiver's bounds, or their highest corner
    /// within a few `eps` of the plane (on it, as a district's neighbouring walls are). Wherever
    /// the box test says "nothing cast", the corners must say so too; and it must say so often.
    #[test]
    fn a_box_says_nothing_is_cast_only_where_its_corners_say_so() {
        let mut rng = Rng(0x5eed_1234_abcd);
        let (mut decided, cases) = (0, 20_000);
        let axes = [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, -DVec3::Y];
        for case in 0..cases {
            let normal = if case % 2 == 0 { axes[case / 2 % axes.len()] } else { rng.unit() };
            let e1 = normal.any_orthonormal_vector();
            let e2 = normal.cross(e1);
            let sun = loop {
                let s = rng.unit();
                if normal.dot(s) > 0.02 {
                    break s;
                }
            };
            let origin = DVec3::new(rng.within(-400.0, 400.0), rng.within(-400.0, 400.0), rng.within(0.0, 30.0));
            let shift_per_height = -DVec2::new(sun.dot(e1), sun.dot(e2)) / normal.dot(sun);
            let frame = PlaneFrame { origin, normal, e1, e2, shift_per_height, eps: 1e-9 * 1700.0 };
            let bounds = Rect {
                min: DVec2::new(rng.within(-2.0, 0.0), rng.within(-2.0, 0.0)),
                max: DVec2::new(rng.within(3.0, 12.0), rng.within(2.0, 8.0)),
            };
            // An object of 3–8 corners within a few metres, half of them flat (one axis fixed).
            let centre = origin + DVec3::new(rng.within(-20.0, 20.0), rng.within(-20.0, 20.0), rng.within(-10.0, 10.0));
            let flat_axis = (case / 3) % 4;
            let mut corners: Vec<DVec3> = (0..3 + case % 6)
                .map(|_| {
                    let mut d = DVec3::new(rng.within(-4.0, 4.0), rng.within(-4.0, 4.0), rng.within(-4.0, 4.0));
                    if flat_axis < 3 {
                        d[flat_axis] = 0.0;
                    }
                    centre + d
                })
                .collect();
            let highest = corners.iter().map(|&p| normal.dot(p - origin)).fold(f64::MIN, f64::max);
            let (_, q_first) = frame.corner_projection(corners[0]);
            let (lo, hi) = corners.iter().fold((q_first, q_first), |(lo, hi), &p| {
                let q = frame.corner_projection(p).1;
                (lo.min(q), hi.max(q))
            });
            let margin = frame.eps * (1.0 + shift_per_height.length()) + 1e-9 * lo.abs().max(hi.abs()).max_element();
            match case % 4 {
                // The highest corner a few eps from the plane, on either side.
                0 => corners.iter_mut().for_each(|p| *p -= normal * (highest - frame.eps * rng.within(-3.0, 3.0))),
                // The projections' box a margin or two beside the bounds, along e1 (q.x moves with it).
                1 => corners.iter_mut().for_each(|p| *p += e1 * (bounds.max.x - lo.x + margin * rng.within(-2.0, 3.0))),
                // Or along e2, below them.
                2 => corners.iter_mut().for_each(|p| *p += e2 * (bounds.min.y - hi.y - margin * rng.within(-2.0, 3.0))),
                _ => {}
            }
            let b = WorldBox::around(corners.iter().copied()).unwrap();
            if frame.box_casts_nothing(&b, &bounds) {
                decided += 1;
                assert!(
                    corners_miss(&frame, &corners, &bounds),
                    "case {case}: the box says nothing is cast, the corners do not: {corners:?}"
                );
            }
        }
        assert!(decided > cases / 4, "the box decided {decided} of {cases} cases");
    }
}
