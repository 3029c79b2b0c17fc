//! Point queries: is the sun seen from a point on a receiver, exactly, for one sun direction?
//!
//! A shadow ray from a point `p` on receiver `r` towards the sun meets a caster exactly when `p`
//! lies inside that caster's shadow on `r`'s plane. So the rays share the exact engine's view
//! work ([`ExactEngine::keep_shadows`]): one BVH walk of the receiver's sun prism, the casters in
//! front of its plane projected along the sun, a convex object's hull as one shadow, the
//! receiver's own triangles never casting. What changes is the last step: instead of integrating
//! `receiver − ∪ shadows`, each point is tested against the shadows that reach its bin (a uniform
//! grid over the receiver's points, built once), and a bin wholly inside a shadow takes the shadow
//! without a test per point. A point on a shadow's edge counts as lit (the edge has no area, so
//! the area mean of a fine grid is unaffected).
//!
//! Foliage: a leaf casts when the request's leaf fraction says it does, as in the engine. A
//! see-through caster (transmittance `t > 0`) lets `t` of the sun through: a point's visibility is
//! the product of the transmittances of the shadows it lies in (0 as soon as one is opaque). A
//! convex see-through object is one shadow, so its two faces count once (the GPU's per-pixel
//! dither, seeded per object, keeps or drops both faces together: the same expectation).

use glam::{DVec2, DVec3};

use super::engine::{ExactEngine, Scratch};
use crate::count::ViewRequest;

/// Points a bin holds on average: few enough that a partly covered bin costs little, enough
/// that a large shadow does not walk many empty bins.
const POINTS_PER_BIN: f64 = 4.0;

/// The points of one receiver, in its plane frame and binned, made once for many suns.
#[derive(Debug, Clone)]
pub struct PlanePoints {
    receiver: u32,
    /// The bins' axes in the receiver's frame: `axis` and its perpendicular. Horizontal on walls,
    /// so the shadows of horizontal slats and overhangs (horizontal strips) meet few bins.
    axis: DVec2,
    /// The points in the bins' axes.
    flat: Vec<DVec2>,
    lo: DVec2,
    /// Bin size (m) along the frame's axes.
    cell: DVec2,
    columns: usize,
    rows: usize,
    /// Per bin its range in `order` (`start[b]..start[b + 1]`).
    start: Vec<u32>,
    order: Vec<u32>,
}

impl PlanePoints {
    /// The receiver these points lie on.
    pub fn receiver(&self) -> u32 {
        self.receiver
    }

    /// How many points.
    pub fn len(&self) -> usize {
        self.flat.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.flat.is_empty()
    }

    fn bin_of(&self, p: DVec2) -> (usize, usize) {
        let c = ((p - self.lo) / self.cell).floor();
        (c.x.clamp(0.0, (self.columns - 1) as f64) as usize, c.y.clamp(0.0, (self.rows - 1) as f64) as usize)
    }

    /// Bin range covering `lo..hi` (clamped), or `None` when the box misses every bin.
    fn bins_over(&self, lo: DVec2, hi: DVec2) -> Option<((usize, usize), (usize, usize))> {
        let top = self.lo + self.cell * DVec2::new(self.columns as f64, self.rows as f64);
        if hi.x < self.lo.x || hi.y < self.lo.y || lo.x > top.x || lo.y > top.y {
            return None;
        }
        Some((self.bin_of(lo), self.bin_of(hi)))
    }
}

/// Per-thread memory for point queries.
pub struct PointScratch {
    view: Scratch,
    /// The current shadow's edges as inward half-planes `n·p > c`.
    edges: Vec<(DVec2, f64)>,
    /// The current shadow in the bins' axes.
    turned: Vec<DVec2>,
}

impl ExactEngine {
    /// Fresh per-thread memory for [`Self::visibility`].
    pub fn point_scratch(&self) -> PointScratch {
        PointScratch { view: self.scratch(), edges: Vec::new(), turned: Vec::new() }
    }

    /// Indexes points lying on `receiver` (world positions; each is projected orthogonally into
    /// the receiver's plane; `normal` is the receiver's) for [`Self::visibility`]. `None` for an unknown receiver or one
    /// without area.
    pub fn plane_points(&self, receiver: u32, points: &[DVec3], normal: DVec3) -> Option<PlanePoints> {
        self.plane_window(receiver)?;
        let horizontal = if normal.z.abs() < 0.9 { DVec3::Z.cross(normal) } else { DVec3::X };
        let axis = (self.to_plane(receiver, horizontal)? - self.to_plane(receiver, DVec3::ZERO)?).normalize_or(DVec2::X);
        let flat: Vec<DVec2> = points.iter().map(|&p| self.to_plane(receiver, p).map(|q| turn(axis, q))).collect::<Option<_>>()?;
        let (lo, hi) = flat.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let size = (hi - lo).max(DVec2::splat(1e-9));
        // Bins about square, POINTS_PER_BIN points each on average.
        let bins = (flat.len() as f64 / POINTS_PER_BIN).max(1.0);
        let side = (size.x * size.y / bins).sqrt().max(1e-9);
        let columns = ((size.x / side).ceil() as usize).clamp(1, 1 << 14);
        let rows = ((size.y / side).ceil() as usize).clamp(1, 1 << 14);
        let cell = size / DVec2::new(columns as f64, rows as f64);
        let mut index =
            PlanePoints { receiver, axis, flat, lo, cell, columns, rows, start: vec![0; columns * rows + 1], order: Vec::new() };
        let bin_ids: Vec<usize> = index
            .flat
            .iter()
            .map(|&p| {
                let (c, r) = index.bin_of(p);
                r * columns + c
            })
            .collect();
        for &b in &bin_ids {
            index.start[b + 1] += 1;
        }
        for b in 0..columns * rows {
            index.start[b + 1] += index.start[b];
        }
        let mut fill = index.start.clone();
        index.order = vec![0; bin_ids.len()];
        for (i, &b) in bin_ids.iter().enumerate() {
            index.order[fill[b] as usize] = i as u32;
            fill[b] += 1;
        }
        Some(index)
    }

    /// The sun's visibility from each of `points` (into `out`, one per point, in their order):
    /// 1 lit, 0 shaded or dark (sun down or behind the receiver), in between behind see-through
    /// casters only. `sun` is a unit vector towards the sun, `leaves` the leaf fraction.
    pub fn visibility(&self, points: &PlanePoints, sun: DVec3, leaves: f32, scratch: &mut PointScratch, out: &mut [f32]) {
        let request = ViewRequest::new(points.receiver, sun).with_leaves(leaves);
        out.fill(1.0);
        let PointScratch { view, edges, turned } = scratch;
        // Each shadow is applied as soon as it is cast; once every point is dark (0 times any
        // transmittance stays 0) the remaining casters cannot change an answer and are skipped.
        let mut applied = 0;
        let mut lit = out.len();
        let seen = self.keep_shadows(request, view, |view| {
            for (range, transmittance) in &view.kept[applied..] {
                lit -= apply_shadow(points, &view.kept_points[range.clone()], *transmittance, edges, turned, out);
            }
            applied = view.kept.len();
            lit == 0
        });
        if !seen {
            out.fill(0.0);
        }
    }
}

/// Multiplies the visibility of the points inside one kept shadow (`shadow`, in the receiver's
/// frame) by its `transmittance`; returns how many points it turned dark.
fn apply_shadow(
    points: &PlanePoints,
    shadow: &[DVec2],
    transmittance: f32,
    edges: &mut Vec<(DVec2, f64)>,
    turned: &mut Vec<DVec2>,
    out: &mut [f32],
) -> usize {
    turned.clear();
    turned.extend(shadow.iter().map(|&q| turn(points.axis, q)));
    let polygon = &turned[..];
    if !inward_edges(polygon, edges) {
        return 0;
    }
    let (lo, hi) = polygon.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let Some(((c0, r0), (c1, r1))) = points.bins_over(lo, hi) else { return 0 };
    let mut darkened = 0;
    for row in r0..=r1 {
        for column in c0..=c1 {
            let b = row * points.columns + column;
            let members = &points.order[points.start[b] as usize..points.start[b + 1] as usize];
            if members.is_empty() {
                continue;
            }
            let corner = points.lo + points.cell * DVec2::new(column as f64, row as f64);
            let whole = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].iter().all(|k| inside(edges, corner + points.cell * *k));
            for &i in members {
                let i = i as usize;
                if out[i] > 0.0 && (whole || inside(edges, points.flat[i])) {
                    out[i] *= transmittance;
                    darkened += usize::from(out[i] == 0.0);
                }
            }
        }
    }
    darkened
}

/// `q` in axes turned so that `axis` is the first.
fn turn(axis: DVec2, q: DVec2) -> DVec2 {
    DVec2::new(q.dot(axis), axis.perp_dot(q))
}

/// The convex polygon's edges as inward half-planes (either orientation); `false` for a polygon
/// without area.
fn inward_edges(polygon: &[DVec2], edges: &mut Vec<(DVec2, f64)>) -> bool {
    edges.clear();
    let n = polygon.len();
    let twice_area: f64 = (0..n).map(|i| polygon[i].perp_dot(polygon[(i + 1) % n])).sum();
    if twice_area == 0.0 || !twice_area.is_finite() {
        return false;
    }
    let sign = twice_area.signum();
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        // perp of (b − a) points left of the edge: inside for a counter-clockwise polygon.
        let normal = (b - a).perp() * sign;
        if normal == DVec2::ZERO {
            continue;
        }
        edges.push((normal, normal.dot(a)));
    }
    true
}

/// Strictly inside every half-plane (a point on an edge is outside: lit).
fn inside(edges: &[(DVec2, f64)], p: DVec2) -> bool {
    edges.iter().all(|(n, c)| n.dot(p) > *c)
}
