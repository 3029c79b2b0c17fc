//! A convex cone of sun directions enclosing a finite set of them: a convex polygon in a
//! gnomonic chart (directions projected from the origin onto the plane one unit along the
//! cone's axis, where great circles are straight lines).
//!
//! Owns the enclosure and its margin. Convex here means spanned by direction vectors: every
//! direction between two of the cone's is in it. That is not convexity in azimuth and altitude,
//! nor in hour angle and declination: a day's arc is a small circle of the sky, which in the
//! chart bends away from its chord (nearer the equator it bulges outward), so the cone of a
//! cell's corner directions misses the sun in between. The sets enclosed here are the very sun
//! directions a cell's timesteps take, computed as the views would be, so the hull holds them
//! all and no bound on an arc's bulge, nor a split at the solstices, is needed.

use glam::{DVec2, DVec3};

use crate::count::view::{convex_hull, perpendicular_basis};

/// Chart units (tangents of angles from the axis) by which every enclosed direction is widened:
/// far above the rounding of the chart's arithmetic (about 1e-16) even where two suns of a cell
/// nearly coincide (a solstice's days), far below any angle that shading can tell (1e-7 rad
/// moves a shadow 10 µm at 100 m). Each direction ends up at least 0.2 of it inside.
pub const MARGIN: f64 = 1e-7;

/// Directions further than this from the cone's axis (its cosine below) are not enclosed: the
/// chart stretches without bound towards 90°.
const MIN_COS_AXIS: f64 = 0.25;

/// A convex cone of directions: its generators (unit vectors along the polygon's corners, counter-
/// clockwise about the axis) and the outward unit normals of its faces.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionCone {
    axis: DVec3,
    u: DVec3,
    v: DVec3,
    generators: Vec<DVec3>,
    faces: Vec<DVec3>,
}

impl DirectionCone {
    /// The smallest cone (up to [`MARGIN`]) holding every direction of `directions` strictly
    /// inside: the convex hull of their chart points, each widened to a diamond of half-diagonal
    /// [`MARGIN`]. None for no directions, a non-finite one, or directions spread too wide
    /// for one chart.
    pub fn enclosing(directions: &[DVec3]) -> Option<Self> {
        let units: Vec<DVec3> = directions.iter().map(|d| d.try_normalize()).collect::<Option<_>>()?;
        let axis = units.iter().copied().sum::<DVec3>().try_normalize()?;
        if units.iter().any(|d| d.dot(axis) < MIN_COS_AXIS) {
            return None;
        }
        let (u, v) = perpendicular_basis(axis);
        let diamond = [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y].map(|o| o * MARGIN);
        let points: Vec<DVec2> = units.iter().flat_map(|d| diamond.map(|o| chart(*d, axis, u, v) + o)).collect();
        Self::of_polygon(axis, u, v, convex_hull(&points))
    }

    /// A cone holding every direction of `directions` at least [`MARGIN`] inside (up to the
    /// dropped short edges' slivers, as [`Self::enclosing`]), with at most eight generators: in
    /// the chart, the octagon bounded by the points' least and greatest extent along four
    /// directions 45° apart, each pushed out by [`MARGIN`]. Looser than the hull, but built
    /// without sorting, and a footprint over it is taken from eight generators however many
    /// directions it holds: for the long runs of a receiver's suns (a day's arc, many days).
    /// None as for [`Self::enclosing`].
    pub fn bounding(directions: &[DVec3]) -> Option<Self> {
        let units: Vec<DVec3> = directions.iter().map(|d| d.try_normalize()).collect::<Option<_>>()?;
        let axis = units.iter().copied().sum::<DVec3>().try_normalize()?;
        if units.iter().any(|d| d.dot(axis) < MIN_COS_AXIS) {
            return None;
        }
        let (u, v) = perpendicular_basis(axis);
        let normals = [
            DVec2::X,
            DVec2::new(1.0, 1.0) * std::f64::consts::FRAC_1_SQRT_2,
            DVec2::Y,
            DVec2::new(-1.0, 1.0) * std::f64::consts::FRAC_1_SQRT_2,
        ];
        let mut extent = [(f64::INFINITY, f64::NEG_INFINITY); 4];
        for d in &units {
            let q = chart(*d, axis, u, v);
            for (e, n) in extent.iter_mut().zip(normals) {
                let t = q.dot(n);
                *e = (e.0.min(t), e.1.max(t));
            }
        }
        // Each direction's chart point is MARGIN inside every half-plane, so MARGIN inside the
        // octagon. The big square clipped down to it: every chart point lies within 1 / 0.25
        // (MIN_COS_AXIS) of the origin.
        let mut polygon = vec![DVec2::new(-8.0, -8.0), DVec2::new(8.0, -8.0), DVec2::new(8.0, 8.0), DVec2::new(-8.0, 8.0)];
        for (n, (lo, hi)) in normals.into_iter().zip(extent) {
            polygon = clip(&polygon, n, hi + MARGIN);
            polygon = clip(&polygon, -n, -(lo - MARGIN));
        }
        Self::of_polygon(axis, u, v, polygon)
    }

    /// The cone over a convex chart polygon (counter-clockwise) about `axis` in the frame `u, v`.
    fn of_polygon(axis: DVec3, u: DVec3, v: DVec3, polygon: Vec<DVec2>) -> Option<Self> {
        let hull = without_short_edges(polygon, 0.5 * MARGIN);
        if hull.len() < 3 || hull.iter().any(|q| !q.is_finite()) {
            return None;
        }
        let lift = |q: DVec2| q.x * u + q.y * v;
        let generators: Vec<DVec3> = hull.iter().map(|q| (axis + lift(*q)).normalize()).collect();
        let faces = (0..hull.len())
            .map(|k| {
                // The plane through the origin and the chart's edge from corner k to k + 1, its
                // normal turned to the polygon's outside (the hull runs counter-clockwise).
                let (q, e) = (hull[k], hull[(k + 1) % hull.len()] - hull[k]);
                let h = (axis + lift(q)).cross(lift(e)).normalize();
                if h.dot(lift(DVec2::new(e.y, -e.x))) < 0.0 { -h } else { h }
            })
            .collect();
        Some(Self { axis, u, v, generators, faces })
    }

    /// The cone's axis: the unit mean of the directions it encloses.
    pub fn axis(&self) -> DVec3 {
        self.axis
    }

    /// Unit vectors along the cone's edges: every direction in the cone is a non-negative
    /// combination of them.
    pub fn generators(&self) -> &[DVec3] {
        &self.generators
    }

    /// Outward unit normals of the cone's faces: a direction is in the cone where it has no
    /// positive component along any of them.
    pub fn faces(&self) -> &[DVec3] {
        &self.faces
    }

    /// Whether `direction` lies in the cone (on its boundary counts).
    pub fn contains(&self, direction: DVec3) -> bool {
        direction.dot(self.axis) > 0.0 && self.faces.iter().all(|h| h.dot(direction) <= 0.0)
    }

    /// `vector`'s point in the cone's chart; None unless it points into the chart's half-space
    /// by at least `min_cos` of its length.
    pub fn chart(&self, vector: DVec3, min_cos: f64) -> Option<DVec2> {
        let along = vector.dot(self.axis);
        (along > min_cos * vector.length()).then(|| chart(vector, self.axis, self.u, self.v))
    }

    /// The direction of a chart point.
    pub fn direction(&self, point: DVec2) -> DVec3 {
        self.axis + point.x * self.u + point.y * self.v
    }
}

/// The polygon without corners closer than `shortest` to the previous one kept: a face between
/// two nearly equal corners would have a normal made of rounding. Dropping such a corner cuts
/// off a sliver no deeper than `shortest`.
fn without_short_edges(polygon: Vec<DVec2>, shortest: f64) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(polygon.len());
    for q in polygon {
        if out.last().is_none_or(|last| last.distance(q) >= shortest) {
            out.push(q);
        }
    }
    while out.len() > 1 && out[out.len() - 1].distance(out[0]) < shortest {
        out.pop();
    }
    out
}

/// The part of the convex `polygon` (counter-clockwise) where `q · n ≤ limit`: still convex and
/// counter-clockwise.
fn clip(polygon: &[DVec2], n: DVec2, limit: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (k, a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        let (da, db) = (a.dot(n) - limit, b.dot(n) - limit);
        if da <= 0.0 {
            out.push(*a);
        }
        if (da <= 0.0) != (db <= 0.0) {
            out.push(*a + (b - *a) * (da / (da - db)));
        }
    }
    out
}

fn chart(d: DVec3, axis: DVec3, u: DVec3, v: DVec3) -> DVec2 {
    DVec2::new(d.dot(u), d.dot(v)) / d.dot(axis)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sun::location::Location;
    use crate::sun::position::sun_direction;

    /// Sun directions of a block of days and hours (a sample cell's timesteps), every 15 minutes.
    fn cell(location: &Location, days: std::ops::RangeInclusive<u32>, hours: (f64, f64)) -> Vec<DVec3> {
        let mut out = Vec::new();
        for day in days {
            let mut h = hours.0;
            while h <= hours.1 + 1e-9 {
                out.push(sun_direction(location, f64::from(day), h));
                h += 0.25;
            }
        }
        out
    }

    /// The cone of a cell's timesteps holds every one of them strictly inside, across a solstice
    /// too; the cone of only its four corner timesteps misses some of them: a day's arc bulges
    /// beyond its chord.
    #[test]
    fn the_cone_holds_every_sun_of_its_cell_and_the_corners_alone_do_not() {
        let location = Location::new(39.74, -105.18, -7.0).unwrap();
        let mut corners_missed = 0;
        for (days, hours) in [(160..=185, (10.0, 12.0)), (60..=74, (7.0, 8.5)), (340..=365, (13.0, 15.0)), (1..=14, (11.0, 13.0))] {
            let suns = cell(&location, days.clone(), hours);
            let cone = DirectionCone::enclosing(&suns).unwrap();
            assert!(suns.iter().all(|d| cone.contains(*d)), "{days:?} {hours:?}");
            for d in &suns {
                // Strictly inside: a direction nudged by a tenth of the margin stays in.
                let q = cone.chart(*d, 0.0).unwrap();
                for o in [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y] {
                    assert!(cone.contains(cone.direction(q + 0.1 * MARGIN * o)));
                }
            }
            let per_day = ((hours.1 - hours.0) / 0.25).round() as usize + 1;
            let corners = [suns[0], suns[per_day - 1], suns[suns.len() - per_day], suns[suns.len() - 1]];
            let four = DirectionCone::enclosing(&corners).unwrap();
            corners_missed += suns.iter().filter(|d| !four.contains(**d)).count();
        }
        assert!(corners_missed > 0, "the corners' cone held every timestep");
    }

    /// Brute force: directions drawn at random within a random convex combination of the set
    /// are inside; directions a little outside every face are not.
    #[test]
    fn combinations_of_the_directions_are_inside_and_the_margin_is_thin() {
        let location = Location::new(-33.9, 18.4, 2.0).unwrap();
        let suns = cell(&location, 100..=113, (8.0, 9.0));
        let cone = DirectionCone::enclosing(&suns).unwrap();
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let d: DVec3 = suns.iter().map(|s| *s * next().powi(8)).sum();
            assert!(cone.contains(d));
        }
        // A direction 1e-6 outside a face (in the chart) is outside.
        let g = cone.generators();
        for k in 0..g.len() {
            let mid = 0.5 * (g[k] + g[(k + 1) % g.len()]);
            assert!(!cone.contains(mid + 1e-6 * cone.faces()[k]));
        }
        assert!(DirectionCone::enclosing(&[]).is_none());
        assert!(DirectionCone::enclosing(&[DVec3::X, -DVec3::X]).is_none());
    }
}
