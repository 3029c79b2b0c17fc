//! Planar geometry shared by the model readers, the scene, the view groups and the EnergyPlus
//! hook: Newell's area vector, a polygon's plane with in-plane axes, point-in-polygon, convexity,
//! and ear-clipped triangulation with holes.
//!
//! Knows nothing of files, receivers or suns: only points in metres. Polygons are lists of
//! vertices in order, closed implicitly (no repeated first point); counter-clockwise about a
//! normal means counter-clockwise seen from the side it points to.

use glam::{DVec2, DVec3};

/// Newell's area vector: the normal × the area of a polygon, pointing to the side from which its
/// vertices run counter-clockwise. Exact for planar polygons, a best fit for nearly planar ones.
pub fn newell(v: &[DVec3]) -> DVec3 {
    // About the centroid: the same vector as about the origin, with less cancellation far from it.
    let c = centroid(v);
    let mut sum = DVec3::ZERO;
    for (i, a) in v.iter().enumerate() {
        let b = v[(i + 1) % v.len()];
        sum += (*a - c).cross(b - c);
    }
    sum * 0.5
}

/// The mean of the vertices (the origin for none).
pub fn centroid(v: &[DVec3]) -> DVec3 {
    if v.is_empty() { DVec3::ZERO } else { v.iter().copied().sum::<DVec3>() / v.len() as f64 }
}

/// Largest distance (m) of a vertex from the plane through the centroid with Newell's normal.
pub fn plane_deviation(v: &[DVec3]) -> f64 {
    let plane = Plane::of_polygon(v);
    v.iter().map(|p| (*p - plane.origin).dot(plane.normal).abs()).fold(0.0, f64::max)
}

/// Area of a triangle.
pub fn triangle_area(t: &[DVec3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Unit normal of a triangle (counter-clockwise about it), zero for a degenerate one.
pub fn triangle_normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}

/// A plane: a point on it, its unit normal and in-plane axes (u, v, normal right-handed, so
/// counter-clockwise about the normal is counter-clockwise in (u, v)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// A point on the plane; in-plane coordinates are relative to it.
    pub origin: DVec3,
    /// Unit normal (zero for a degenerate polygon).
    pub normal: DVec3,
    /// First in-plane axis.
    pub u: DVec3,
    /// Second in-plane axis, `normal × u`.
    pub v: DVec3,
}

impl Plane {
    /// The plane through `origin` with `normal` (made unit); `u` is the world axis least along the
    /// normal, projected into the plane, so the axes are the same for every polygon of a plane.
    pub fn through(origin: DVec3, normal: DVec3) -> Self {
        let normal = normal.normalize_or_zero();
        let helper = if normal.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let u = (helper - normal * helper.dot(normal)).normalize_or_zero();
        Plane { origin, normal, u, v: normal.cross(u) }
    }

    /// A polygon's plane: through its centroid, with Newell's normal.
    pub fn of_polygon(v: &[DVec3]) -> Self {
        Self::through(centroid(v), newell(v))
    }

    /// In-plane coordinates of `p` (its orthogonal projection).
    pub fn project(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// `p` moved along the normal onto the plane.
    pub fn flatten(&self, p: DVec3) -> DVec3 {
        p - self.normal * (p - self.origin).dot(self.normal)
    }

    /// Signed distance of `p` from the plane, positive on the normal's side.
    pub fn height(&self, p: DVec3) -> f64 {
        (p - self.origin).dot(self.normal)
    }
}

/// Whether `p` lies inside `polygon` or within `tolerance` of its outline (even-odd rule).
pub fn inside_or_on(p: DVec2, polygon: &[DVec2], tolerance: f64) -> bool {
    let n = polygon.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if segment_distance(p, a, b) <= tolerance {
            return true;
        }
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + ab * t)
}

/// Whether an edge of either of two convex polygons (either orientation, possibly flat)
/// separates them by at least `gap`: they are then at least that far apart. With no gap,
/// touching polygons are apart; the test errs towards overlap (a flattened polygon across the
/// other is not apart), which only costs its callers time.
pub fn convex_apart(a: &[DVec2], b: &[DVec2], gap: f64) -> bool {
    let separates = |edges: &[DVec2]| {
        (0..edges.len()).any(|i| {
            let axis = (edges[(i + 1) % edges.len()] - edges[i]).perp();
            let span =
                |p: &[DVec2]| p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| (lo.min(axis.dot(*q)), hi.max(axis.dot(*q))));
            let ((a0, a1), (b0, b1)) = (span(a), span(b));
            // The gap in the axis's own units (it is not normalised).
            let slack = gap * axis.length();
            axis != DVec2::ZERO && (a1 + slack <= b0 || b1 + slack <= a0)
        })
    };
    separates(a) || separates(b)
}

/// Whether every turn of the polygon goes the same way as its normal.
pub fn is_convex(v: &[DVec3]) -> bool {
    let n = newell(v);
    (0..v.len()).all(|i| {
        let (a, b, c) = (v[i], v[(i + 1) % v.len()], v[(i + 2) % v.len()]);
        (b - a).cross(c - b).dot(n) >= -1e-12 * n.length()
    })
}

/// Ear-clipped triangles of a planar polygon with holes. `points` holds the outline, then each
/// hole's vertices; `hole_starts` where each hole begins. Returns indices into `points`, each
/// triangle wound counter-clockwise about `plane.normal`; none where ear clipping fails (a
/// self-intersecting outline).
pub fn triangulate(plane: &Plane, points: &[DVec3], hole_starts: &[usize]) -> Vec<[usize; 3]> {
    let flat: Vec<[f64; 2]> = points.iter().map(|p| plane.project(*p).to_array()).collect();
    let mut indices: Vec<usize> = Vec::new();
    earcut::Earcut::new().earcut(flat.iter().copied(), hole_starts, &mut indices);
    indices.chunks_exact(3).map(|t| wind(points, [t[0], t[1], t[2]], plane.normal)).collect()
}

/// Triangle `t` (indices into `points`) wound counter-clockwise about `normal`.
pub fn wind(points: &[DVec3], t: [usize; 3], normal: DVec3) -> [usize; 3] {
    let facing = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]).dot(normal);
    if facing < 0.0 { [t[0], t[2], t[1]] } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 × 3 rectangle in the plane y = 2, counter-clockwise seen from −y (facing south).
    fn south_wall() -> Vec<DVec3> {
        [(0., 0.), (4., 0.), (4., 3.), (0., 3.)].iter().map(|&(x, z)| DVec3::new(x, 2.0, z)).collect()
    }

    #[test]
    fn newell_gives_the_normal_times_the_area() {
        assert!((newell(&south_wall()) - DVec3::new(0.0, -12.0, 0.0)).length() < 1e-12);
        let plane = Plane::of_polygon(&south_wall());
        assert!((plane.normal - DVec3::NEG_Y).length() < 1e-12);
        assert!((plane.u.cross(plane.v) - plane.normal).length() < 1e-12, "right-handed");
        assert_eq!(plane_deviation(&south_wall()), 0.0);
        let mut bent = south_wall();
        bent[2].y += 0.1;
        assert!((plane_deviation(&bent) - 0.025).abs() < 0.01, "{}", plane_deviation(&bent));
    }

    #[test]
    fn a_wall_with_a_window_hole_keeps_the_net_area_and_faces_out() {
        let wall = south_wall();
        let hole: Vec<DVec3> = [(1., 1.), (1., 2.), (3., 2.), (3., 1.)].iter().map(|&(x, z)| DVec3::new(x, 2.0, z)).collect();
        let plane = Plane::of_polygon(&wall);
        let points: Vec<DVec3> = wall.iter().chain(&hole).copied().collect();
        let triangles = triangulate(&plane, &points, &[4]);
        let tris: Vec<[DVec3; 3]> = triangles.iter().map(|t| t.map(|i| points[i])).collect();
        let area: f64 = tris.iter().map(triangle_area).sum();
        assert!((area - 10.0).abs() < 1e-9, "12 − 2 = {area}");
        assert!(tris.iter().all(|t| triangle_normal(t).dot(plane.normal) > 0.999));
    }

    #[test]
    fn convexity_and_containment() {
        let wall = south_wall();
        assert!(is_convex(&wall));
        let mut notched = wall.clone();
        notched.insert(3, DVec3::new(2.0, 2.0, 1.0));
        assert!(!is_convex(&notched));
        let plane = Plane::of_polygon(&wall);
        let flat: Vec<DVec2> = wall.iter().map(|p| plane.project(*p)).collect();
        assert!(inside_or_on(plane.project(DVec3::new(2.0, 2.0, 1.5)), &flat, 1e-4));
        assert!(inside_or_on(plane.project(DVec3::new(4.0, 2.0, 1.5)), &flat, 1e-4), "on the edge");
        assert!(!inside_or_on(plane.project(DVec3::new(5.0, 2.0, 1.5)), &flat, 1e-4));
    }
}
