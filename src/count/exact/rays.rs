//! Point queries: is the sun seen from a point on a receiver, exactly, for one sun direction?
//!
//! A shadow ray from a point `p` on receiver `r` towards the sun meets a caster exactly when `p`
//! lies inside that caster's shadow on `r`'s plane. So the rays share the exact engine's view
//! work ([`ExactEngine::keep_shadows`]): one BVH walk of the receiver's sun prism, the casters in
//! front of its plane projected along the sun, a convex object's hull as one shadow, the
//! receiver's own triangles never casting. What changes is the last step: instead of integrating
//! `receiver − ∪ shadows`, each point is tested against the shadows that reach its bin (a uniform
//! grid over the receiver's points, built once), and a bin wholly inside a shadow takes the shadow
//! without a test per point. A point on the edge of the shadows' union counts as lit (the edge has
//! no area, so the area mean of a fine grid is unaffected), but a point inside the union is dark
//! even where it lies on the edges of the shadows that make it up: a ray exactly through the edge
//! two opaque casters share (the corner where a room's two walls meet, a wall's triangulation)
//! meets the casters, it does not pass between them. Such a point is tested after the shadows:
//! the directions around it that each opaque shadow touching it covers (an arc of the circle)
//! are joined, and it is dark when they close the circle ([`closes_circle`]).
//!
//! Foliage: a leaf casts when the request's leaf fraction says it does, as in the engine. A
//! see-through caster (transmittance `t > 0`) lets `t` of the sun through: a point's visibility is
//! the product of the transmittances of the shadows it lies in (0 as soon as one is opaque). A
//! convex see-through object is one shadow, so its two faces count once (the GPU's per-pixel
//! dither, seeded per object, keeps or drops both faces together: the same expectation).

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::{DVec2, DVec3};

use super::engine::{ExactEngine, Scratch};
use crate::count::ViewRequest;

/// A point this close to a shadow's edge (times `1 +` the largest coordinate of the shadow's
/// corners, in the receiver's frame) lies on it: rounding moves the ends of an edge two casters
/// share by about 1e-15 of the coordinates.
const ON_EDGE: f64 = 1e-9;
/// Arcs of directions closer than this (radians) touch: edges two shadows share are the same
/// corners' differences, or collinear pieces of them.
const ARC_GAP: f64 = 1e-9;

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
    /// The current shadow's edges as inward half-planes `n·p > c`, with `ON_EDGE`'s distance
    /// times `|n|`.
    edges: Vec<(DVec2, f64, f64)>,
    /// Per point on an opaque shadow's edge (not strictly inside it): the point and the arc of
    /// directions the shadow covers around it (start, end in radians, end ≥ start).
    touching: Vec<(u32, f64, f64)>,
    /// One point's arcs, for [`closes_circle`].
    arcs: Vec<(f64, f64)>,
    /// The current shadow in the bins' axes.
    turned: Vec<DVec2>,
}

impl ExactEngine {
    /// Fresh per-thread memory for [`Self::visibility`].
    pub fn point_scratch(&self) -> PointScratch {
        PointScratch { view: self.scratch(), edges: Vec::new(), touching: Vec::new(), arcs: Vec::new(), turned: Vec::new() }
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
        let PointScratch { view, edges, touching, arcs, turned } = scratch;
        touching.clear();
        // Each shadow is applied as soon as it is cast; once every point is dark (0 times any
        // transmittance stays 0) the remaining casters cannot change an answer and are skipped.
        let mut applied = 0;
        let mut lit = out.len();
        let seen = self.keep_shadows(request, view, |view| {
            for (range, transmittance) in &view.kept[applied..] {
                let shadow = Shadow { corners: &view.kept_points[range.clone()], transmittance: *transmittance };
                lit -= apply_shadow(points, shadow, edges, touching, turned, out);
            }
            applied = view.kept.len();
            lit == 0
        });
        if !seen {
            out.fill(0.0);
        } else if lit > 0 {
            close_cracks(touching, arcs, out);
        }
    }
}

/// One kept shadow: its corners in the receiver's frame and the share of the sun it lets by.
#[derive(Clone, Copy)]
struct Shadow<'a> {
    corners: &'a [DVec2],
    transmittance: f32,
}

/// Multiplies the visibility of the points inside one kept shadow (in the receiver's frame) by
/// its transmittance; returns how many points it turned dark. A point on an opaque shadow's edge
/// adds the shadow's arc around it to `touching`.
fn apply_shadow(
    points: &PlanePoints,
    shadow: Shadow<'_>,
    edges: &mut Vec<(DVec2, f64, f64)>,
    touching: &mut Vec<(u32, f64, f64)>,
    turned: &mut Vec<DVec2>,
    out: &mut [f32],
) -> usize {
    turned.clear();
    turned.extend(shadow.corners.iter().map(|&q| turn(points.axis, q)));
    let polygon = &turned[..];
    if !inward_edges(polygon, edges) {
        return 0;
    }
    let (lo, hi) = polygon.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let Some(((c0, r0), (c1, r1))) = points.bins_over(lo, hi) else { return 0 };
    let opaque = shadow.transmittance == 0.0;
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
                if out[i] <= 0.0 {
                    continue;
                }
                let side = if whole { Side::Inside } else { side_of(edges, points.flat[i]) };
                match side {
                    Side::Inside => {
                        out[i] *= shadow.transmittance;
                        darkened += usize::from(out[i] == 0.0);
                    }
                    Side::Edge if opaque => {
                        if let Some((start, end)) = arc_at(edges, points.flat[i]) {
                            touching.push((i as u32, start, end));
                        }
                    }
                    Side::Edge | Side::Outside => {}
                }
            }
        }
    }
    darkened
}

/// Where a point lies against a convex shadow.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Side {
    /// Strictly inside every edge (as [`inside`] finds it).
    Inside,
    /// On an edge (within [`ON_EDGE`]) and inside the others.
    Edge,
    Outside,
}

/// [`inside`], telling a point on an edge from one outside.
fn side_of(edges: &[(DVec2, f64, f64)], p: DVec2) -> Side {
    let mut side = Side::Inside;
    for &(n, c, near) in edges {
        let d = n.dot(p) - c;
        if d > 0.0 {
            continue;
        }
        if d < -near {
            return Side::Outside;
        }
        side = Side::Edge;
    }
    side
}

/// The directions from `p` (on the shadow's edge) into the shadow, as an arc (start, end in
/// radians): the half-planes of the edges through `p` (within [`ON_EDGE`]) intersected. `None`
/// when they leave no direction.
fn arc_at(edges: &[(DVec2, f64, f64)], p: DVec2) -> Option<(f64, f64)> {
    let mut arc: Option<(f64, f64)> = None;
    for &(n, c, near) in edges {
        if n.dot(p) - c > near {
            continue;
        }
        // The half-plane n·d ≥ 0: the half circle centred on n's angle, unwrapped to lie within
        // half a turn of the first one's so that intersecting is taking the inner ends.
        let mut angle = n.y.atan2(n.x);
        if let Some((start, end)) = arc {
            let centre = 0.5 * (start + end);
            angle += std::f64::consts::TAU * ((centre - angle) / std::f64::consts::TAU).round();
            let (s, e) = (start.max(angle - FRAC_PI_2), end.min(angle + FRAC_PI_2));
            if s > e {
                return None;
            }
            arc = Some((s, e));
        } else {
            arc = Some((angle - FRAC_PI_2, angle + FRAC_PI_2));
        }
    }
    arc
}

/// Darkens each point still lit whose opaque shadows' arcs around it close the circle: it lies
/// inside their union, on a crack between shadows that share an edge or a corner.
fn close_cracks(touching: &mut [(u32, f64, f64)], arcs: &mut Vec<(f64, f64)>, out: &mut [f32]) {
    touching.sort_unstable_by_key(|t| t.0);
    for group in touching.chunk_by(|a, b| a.0 == b.0) {
        let i = group[0].0 as usize;
        if group.len() < 2 || out[i] <= 0.0 {
            continue;
        }
        arcs.clear();
        arcs.extend(group.iter().map(|&(_, s, e)| (s, e)));
        if closes_circle(arcs) {
            out[i] = 0.0;
        }
    }
}

/// Whether arcs (start, end in radians, each shorter than a turn) cover every direction, gaps
/// under [`ARC_GAP`] closed: `[0, 2π]` swept with each arc also a turn earlier and later.
fn closes_circle(arcs: &mut Vec<(f64, f64)>) -> bool {
    let n = arcs.len();
    for k in 0..n {
        let (s, e) = arcs[k];
        let turns = (s / TAU).floor();
        let (s, e) = (s - turns * TAU, e - turns * TAU);
        arcs[k] = (s, e);
        arcs.push((s - TAU, e - TAU));
        arcs.push((s + TAU, e + TAU));
    }
    arcs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let mut reach = 0.0f64;
    for &(s, e) in arcs.iter() {
        if s > reach + ARC_GAP {
            return false;
        }
        reach = reach.max(e);
        if reach >= TAU - ARC_GAP {
            return true;
        }
    }
    false
}

/// `q` in axes turned so that `axis` is the first.
fn turn(axis: DVec2, q: DVec2) -> DVec2 {
    DVec2::new(q.dot(axis), axis.perp_dot(q))
}

/// The convex polygon's edges as inward half-planes (either orientation), each with its
/// [`ON_EDGE`] distance times `|n|`; `false` for a polygon without area.
fn inward_edges(polygon: &[DVec2], edges: &mut Vec<(DVec2, f64, f64)>) -> bool {
    edges.clear();
    let n = polygon.len();
    let twice_area: f64 = (0..n).map(|i| polygon[i].perp_dot(polygon[(i + 1) % n])).sum();
    if twice_area == 0.0 || !twice_area.is_finite() {
        return false;
    }
    let sign = twice_area.signum();
    let scale = 1.0 + polygon.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        // perp of (b − a) points left of the edge: inside for a counter-clockwise polygon.
        let normal = (b - a).perp() * sign;
        if normal == DVec2::ZERO {
            continue;
        }
        edges.push((normal, normal.dot(a), ON_EDGE * scale * normal.length()));
    }
    true
}

/// Strictly inside every half-plane (a point on an edge is outside: lit).
fn inside(edges: &[(DVec2, f64, f64)], p: DVec2) -> bool {
    edges.iter().all(|(n, c, _)| n.dot(p) > *c)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    use glam::DVec2;

    use super::{Side, arc_at, closes_circle, inward_edges, side_of};

    fn closes(arcs: &[(f64, f64)]) -> bool {
        closes_circle(&mut arcs.to_vec())
    }

    #[test]
    fn arcs_close_the_circle_only_when_no_direction_is_left() {
        // Two half-planes on either side of a shared edge, and on the same side (a fold).
        assert!(closes(&[(0.0, PI), (PI, TAU)]));
        assert!(!closes(&[(0.0, PI), (0.0, PI)]));
        // Three walls' wedges at a vertex, one arc wrapping past a full turn.
        assert!(closes(&[(-FRAC_PI_2, FRAC_PI_2), (FRAC_PI_2, PI), (PI, 1.5 * PI)]));
        assert!(closes(&[(0.0, 0.1), (1.0, 4.0), (3.5, 7.5)]));
        // A gap wider than rounding stays open.
        assert!(!closes(&[(0.0, PI), (PI + 1e-6, TAU)]));
    }

    #[test]
    fn a_point_on_a_shadows_edge_gets_the_directions_into_it() {
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let mut edges = Vec::new();
        assert!(inward_edges(&square, &mut edges));
        assert_eq!(side_of(&edges, DVec2::splat(0.5)), Side::Inside);
        assert_eq!(side_of(&edges, DVec2::new(0.5, 0.0)), Side::Edge);
        assert_eq!(side_of(&edges, DVec2::new(0.5, -1e-6)), Side::Outside);
        // On the bottom edge: the upper half circle; at the corner (0, 0): the first quadrant.
        let (s, e) = arc_at(&edges, DVec2::new(0.5, 0.0)).unwrap();
        assert!((s - 0.0).abs() < 1e-12 && (e - PI).abs() < 1e-12, "{s} {e}");
        let (s, e) = arc_at(&edges, DVec2::ZERO).unwrap();
        assert!((s.rem_euclid(TAU)).abs() < 1e-12 && (e - s - FRAC_PI_2).abs() < 1e-12, "{s} {e}");
    }
}
