//! BRE 209's quick pre-checks (3rd ed., 2022), exact on the scene's triangles, per reference
//! point (BRE draws both from the centre of the lowest window of the wall; the points are given):
//! - **25° line** (2.2.5): in the vertical section perpendicular to the window wall through the
//!   point, the highest angle above the horizontal at which anything stands in front of it. BRE:
//!   if the new development subtends more than 25° there, the diffuse daylight may be affected
//!   (a VSC check is then due). Each triangle is cut by the section plane; along a straight cut
//!   the angle seen from the point changes monotonically, so its largest value is at one of the
//!   cut's ends (kept in front of the wall).
//! - **45° lines** (2.2.16, for an extension beside the window): on plan, a line at 45° from the
//!   extension's far end back to the wall; in elevation, a line at 45° down from its top towards
//!   the window; the window is likely affected when its centre lies on the extension's side of
//!   both. In the point's own axes (x along the wall, y out from it, z up from the point) that is
//!   some part of the obstruction with y ≥ |x| (within 45° of the normal on plan) and z ≥ |x|
//!   (above the 45° lines in elevation): for a block standing on the wall, of depth D, offset a
//!   from the point and top H above it, exactly BRE's "a ≤ D and a ≤ H". Each triangle is
//!   clipped to that convex wedge; any remainder is an obstruction within the lines.
//!
//! Geometry in the wall's own plane (within [`FRONT`] of it: the wall, the window) is not in front
//! of the point and never counts.
//!
//! BRE draws the 25° line to the *new development* only: the window's own building (its
//! overhangs, fins, balconies) is not the development. Given the existing scene,
//! [`development`] is the proposed scene's geometry the existing one lacks (triangle by triangle,
//! corners matched to [`MATCH`]), and [`section_angles`] on it is BRE's angle; without it the
//! section holds everything, the window's own building too.

use std::collections::HashMap;

use glam::DVec3;

use crate::scene::Scene;

/// BRE's 25° line.
pub const LINE_25_DEG: f64 = 25.0;
/// How far in front of the wall's plane geometry must be to count, metres.
pub const FRONT: f64 = 1e-3;
/// Corners closer than this (metres, per axis) are the same corner when the proposed scene's
/// triangles are matched to the existing scene's.
pub const MATCH: f64 = 1e-3;

/// Per point, the 25° and 45° tests' values.
#[derive(Debug, Clone, PartialEq)]
pub struct LineValues {
    /// The highest obstruction angle in the perpendicular section, degrees (0 with nothing in
    /// front).
    pub angle_deg: Vec<f64>,
    /// Whether some obstruction lies within both 45° lines.
    pub within_45: Vec<bool>,
    /// With the existing scene known: the highest angle of the [`development`] alone, BRE's
    /// 25° angle (the window's own building left out).
    pub development_deg: Option<Vec<f64>>,
}

/// The point's axes: x along the wall (horizontal), y out of it (the normal's horizontal part),
/// z up. `None` for a point facing straight up or down (no wall, no section).
fn axes(normal: DVec3) -> Option<(DVec3, DVec3)> {
    let out = DVec3::new(normal.x, normal.y, 0.0);
    (out.length() > 1e-9).then(|| {
        let out = out.normalize();
        (DVec3::new(out.y, -out.x, 0.0), out)
    })
}

/// Both tests at every point of `positions`/`normals` against every triangle of `scene`.
pub fn evaluate(scene: &Scene, positions: &[DVec3], normals: &[DVec3]) -> LineValues {
    let triangles: Vec<[DVec3; 3]> = scene.world_triangles().map(|(t, _)| t).collect();
    let (angle_deg, within_45) = positions.iter().zip(normals).map(|(&p, &n)| point_lines(&triangles, p, n)).unzip();
    LineValues { angle_deg, within_45, development_deg: None }
}

/// The 25° section's highest angle (degrees) at each point against `triangles` alone (e.g. the
/// [`development`]).
pub fn section_angles(triangles: &[[DVec3; 3]], positions: &[DVec3], normals: &[DVec3]) -> Vec<f64> {
    positions.iter().zip(normals).map(|(&p, &n)| point_lines(triangles, p, n).0).collect()
}

/// One point's highest section angle (degrees) and whether anything is within its 45° lines.
fn point_lines(triangles: &[[DVec3; 3]], origin: DVec3, normal: DVec3) -> (f64, bool) {
    let Some((along, out)) = axes(normal) else { return (0.0, false) };
    let local = |p: DVec3| {
        let d = p - origin;
        DVec3::new(d.dot(along), d.dot(out), d.z)
    };
    let mut angle = 0.0f64;
    let mut within = false;
    for t in triangles {
        let l = t.map(local);
        if let Some(a) = section_angle(&l) {
            angle = angle.max(a);
        }
        within = within || in_wedge(&l);
    }
    (angle.to_degrees(), within)
}

/// The triangles of `proposed` that `existing` does not hold (the same three corners, each
/// within [`MATCH`] per axis, in any order): the new development, without the buildings that
/// stand in both. The existing triangles are binned by their centroids in 1 cm cells, and each
/// proposed triangle looks in the cells its centroid could fall in given [`MATCH`] (the two
/// scenes' f32 vertices are stored about their own centres, so the same corner may differ in
/// its last bits).
pub fn development(proposed: &Scene, existing: &Scene) -> Vec<[DVec3; 3]> {
    const CELL: f64 = 0.01;
    let cell = |p: DVec3| (p / CELL).floor().as_i64vec3().to_array();
    let centroid = |t: &[DVec3; 3]| (t[0] + t[1] + t[2]) / 3.0;
    let mut old: HashMap<[i64; 3], Vec<[DVec3; 3]>> = HashMap::new();
    for (t, _) in existing.world_triangles() {
        old.entry(cell(centroid(&t))).or_default().push(t);
    }
    let same = |a: &[DVec3; 3], b: &[DVec3; 3]| a.iter().all(|p| b.iter().any(|q| (*p - *q).abs().max_element() <= MATCH));
    let held = |t: &[DVec3; 3]| {
        let c = centroid(t);
        let (lo, hi) = (cell(c - DVec3::splat(MATCH)), cell(c + DVec3::splat(MATCH)));
        (lo[0]..=hi[0])
            .any(|x| (lo[1]..=hi[1]).any(|y| (lo[2]..=hi[2]).any(|z| old.get(&[x, y, z]).is_some_and(|v| v.iter().any(|o| same(t, o))))))
    };
    proposed.world_triangles().map(|(t, _)| t).filter(|t| !held(t)).collect()
}

/// The largest angle above the horizontal (radians, ≥ 0 counted from 0) of the triangle's cut by
/// the section x = 0, in front of the wall; `None` where it does not cross the section there.
fn section_angle(t: &[DVec3; 3]) -> Option<f64> {
    // The cut's ends: where the edges cross x = 0 (a vertex on it is its own end).
    let mut ends: Vec<(f64, f64)> = Vec::with_capacity(3);
    for k in 0..3 {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        if a.x == 0.0 {
            ends.push((a.y, a.z));
        }
        if (a.x < 0.0 && b.x > 0.0) || (a.x > 0.0 && b.x < 0.0) {
            let s = a.x / (a.x - b.x);
            ends.push((a.y + s * (b.y - a.y), a.z + s * (b.z - a.z)));
        }
    }
    // Keep the part of each piece of the cut in front of the wall (y ≥ FRONT); a triangle lying
    // in the section gives three ends, each pair an edge.
    let clip = |inside: (f64, f64), outside: (f64, f64)| {
        let s = (inside.0 - FRONT) / (inside.0 - outside.0);
        (FRONT, inside.1 + s * (outside.1 - inside.1))
    };
    let segment = |p: (f64, f64), q: (f64, f64)| -> Option<f64> {
        let (p, q) = match (p.0 >= FRONT, q.0 >= FRONT) {
            (false, false) => return None,
            (true, true) => (p, q),
            (true, false) => (p, clip(p, q)),
            (false, true) => (clip(q, p), q),
        };
        Some(p.1.atan2(p.0).max(q.1.atan2(q.0)))
    };
    match ends.as_slice() {
        [] => None,
        [p] => segment(*p, *p),
        _ => {
            let n = ends.len();
            (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j))).filter_map(|(i, j)| segment(ends[i], ends[j])).reduce(f64::max)
        }
    }
}

/// Whether the triangle has any part in the wedge y ≥ |x|, z ≥ |x|, y ≥ [`FRONT`] (a convex
/// region: the triangle is clipped by each of its five half-spaces in turn).
fn in_wedge(t: &[DVec3; 3]) -> bool {
    let planes: [fn(DVec3) -> f64; 5] = [|p| p.y - p.x, |p| p.y + p.x, |p| p.z - p.x, |p| p.z + p.x, |p| p.y - FRONT];
    let mut polygon: Vec<DVec3> = t.to_vec();
    for side in planes {
        polygon = clip(&polygon, side);
        if polygon.is_empty() {
            return false;
        }
    }
    true
}

/// Sutherland–Hodgman: the part of `polygon` where `side` ≥ 0 (points on the plane kept).
fn clip(polygon: &[DVec3], side: fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(polygon.len() + 2);
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        let (sa, sb) = (side(a), side(b));
        if sa >= 0.0 {
            out.push(a);
        }
        if (sa >= 0.0) != (sb >= 0.0) {
            out.push(a + (b - a) * (sa / (sa - sb)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_section_cut_keeps_its_front_part() {
        // A vertical plate across the section 10 m out, 0..6 m high: 6 m above the point.
        let plate = [DVec3::new(-5.0, 10.0, 0.0), DVec3::new(5.0, 10.0, 0.0), DVec3::new(0.0, 10.0, 6.0)];
        let a = section_angle(&plate).map(f64::to_degrees);
        assert!(a.is_some_and(|a| (a - 6f64.atan2(10.0).to_degrees()).abs() < 1e-9), "{a:?}");
        // Behind the wall: nothing.
        let behind = plate.map(|p| DVec3::new(p.x, -p.y, p.z));
        assert_eq!(section_angle(&behind), None);
        // A triangle off the section: nothing.
        let aside = plate.map(|p| p + DVec3::new(20.0, 0.0, 0.0));
        assert_eq!(section_angle(&aside), None);
    }
}
