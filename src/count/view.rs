//! Fitting an orthographic sun view to one receiver: the camera looks along the sun's rays.
//!
//! Owns the view geometry shared by every counting backend:
//! - the side planes are parallel to the rays and enclose the receiver's projection with the
//!   smallest-area rectangle (rotating calipers on its convex hull), so long thin or steeply
//!   inclined surfaces still fill the tile; pixels may be non-square, which counting does not mind;
//! - a margin of at least one pixel on every side, so no receiver pixel touches the tile edge;
//! - depth runs from the scene's bound towards the sun (near) to just behind the receiver (far):
//!   nothing outside the scene can shade, and geometry behind the receiver is clipped away.

use glam::{DMat4, DVec2, DVec3, DVec4};

/// The pixel grid is turned by this angle (radians) against the receiver's bounding rectangle.
/// Architecture is full of shadow edges parallel to the receiver's edges (louvres, overhangs,
/// fins); on an aligned grid each such edge falls at one sub-pixel offset along its whole length
/// and its error (up to half a row) does not average out, so many slats add up to ~0.01. Turned,
/// each edge crosses rows at every offset and the error averages away, for ~15% fewer pixels.
pub const GRID_ROTATION: f64 = 0.1;

/// An orthographic view of one receiver along one sun direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunView {
    /// Scene coordinates *relative to the scene origin* → clip space (x, y in [−1, 1], z in [0, 1]).
    pub view_proj: DMat4,
    /// Area on the view plane covered by one pixel (m²).
    pub pixel_area: f64,
}

/// Fits the view. `points` are the receiver's vertices and `bounds` the scene's, both in world
/// coordinates; `sun` points towards the sun (unit); `resolution` is the tile size in pixels.
pub fn fit(points: &[DVec3], sun: DVec3, bounds: (DVec3, DVec3), origin: DVec3, resolution: u32) -> SunView {
    fit_to(points, sun, bounds, origin, resolution, false)
}

/// [`fit`] with its depth ending at the farthest of `points` towards the sun, not at the
/// scene's bound: a box about the points alone (one slab of a volume swept towards the sun).
pub fn fit_slab(points: &[DVec3], sun: DVec3, bounds: (DVec3, DVec3), origin: DVec3, resolution: u32) -> SunView {
    fit_to(points, sun, bounds, origin, resolution, true)
}

fn fit_to(points: &[DVec3], sun: DVec3, bounds: (DVec3, DVec3), origin: DVec3, resolution: u32, slab: bool) -> SunView {
    let (u0, v0) = perpendicular_basis(sun);
    // One buffer a view, not three: this runs once a tile, and on the GPU's culling it is most of
    // the host's work a view.
    let flat: Vec<DVec2> = points.iter().map(|p| *p - origin).map(|p| DVec2::new(p.dot(u0), p.dot(v0))).collect();
    let (angle, lo, hi) = min_area_rectangle(&flat);
    let (c, s) = (angle.cos(), angle.sin());
    let u = u0 * c + v0 * s;
    let v = v0 * c - u0 * s;

    let res = resolution.max(4) as f64;
    let extent = (bounds.1 - bounds.0).length().max(1e-3);
    // The rectangle's half sizes, kept above zero for surfaces seen almost edge-on.
    let (uc, uh) = (0.5 * (lo.x + hi.x), (0.5 * (hi.x - lo.x)).max(extent * 1e-9));
    let (vc, vh) = (0.5 * (lo.y + hi.y), (0.5 * (hi.y - lo.y)).max(extent * 1e-9));
    // In the rectangle's normalised square, turn the pixel grid by GRID_ROTATION and shrink it so
    // the square's corners stay a pixel inside the tile.
    let (gc, gs) = (GRID_ROTATION.cos(), GRID_ROTATION.sin());
    let k = (res - 2.0) / (res * (gc + gs));
    let a = (u / uh, -uc / uh);
    let b = (v / vh, -vc / vh);
    let row_x = ((a.0 * gc - b.0 * gs) * k).extend((a.1 * gc - b.1 * gs) * k);
    let row_y = ((a.0 * gs + b.0 * gc) * k).extend((a.1 * gs + b.1 * gc) * k);

    let ends: &[DVec3] = if slab { points } else { &corners(bounds) };
    let near = ends.iter().map(|p| (*p - origin).dot(sun)).fold(f64::NEG_INFINITY, f64::max);
    let far = points.iter().map(|p| (*p - origin).dot(sun)).fold(f64::INFINITY, f64::min);
    // Pads keep the scene's nearest point and the receiver's farthest point strictly inside [0, 1].
    let pad = extent * 1e-4;
    let (near, far) = (near + pad, far - pad);
    let depth = (near - far).max(pad);

    let rows = [row_x, row_y, (-sun / depth).extend(near / depth), DVec4::W];
    let view_proj = DMat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
    // The tile is 2 × 2 in clip space; its preimage on the view plane has area 4·uh·vh / k².
    SunView { view_proj, pixel_area: 4.0 * uh * vh / (k * k * res * res) }
}

/// Two unit vectors completing `w` to a right-handed orthonormal basis.
pub(crate) fn perpendicular_basis(w: DVec3) -> (DVec3, DVec3) {
    let helper = if w.z.abs() < 0.9 { DVec3::Z } else { DVec3::X };
    let u = helper.cross(w).normalize();
    (u, w.cross(u))
}

fn corners((lo, hi): (DVec3, DVec3)) -> [DVec3; 8] {
    std::array::from_fn(|i| {
        DVec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z })
    })
}

/// Smallest-area enclosing rectangle: its rotation angle and its extents in the rotated frame.
/// One side of the optimum lies along a hull edge, so trying every hull edge finds it.
fn min_area_rectangle(points: &[DVec2]) -> (f64, DVec2, DVec2) {
    let hull = convex_hull(points);
    let mut best = (f64::INFINITY, 0.0, DVec2::ZERO, DVec2::ZERO);
    // The axis-aligned frame first, then each hull edge's.
    let edges = (0..hull.len()).map(|i| hull[(i + 1) % hull.len()] - hull[i]).filter(|e| e.length_squared() > 0.0);
    for angle in std::iter::once(0.0).chain(edges.map(|e| e.y.atan2(e.x))) {
        let (lo, hi) = rotated_extents(points, angle);
        let area = (hi.x - lo.x) * (hi.y - lo.y);
        // Prefer strictly smaller areas so near-ties keep the first (axis-aligned) frame.
        if area < best.0 * (1.0 - 1e-12) {
            best = (area, angle, lo, hi);
        }
    }
    (best.1, best.2, best.3)
}

fn rotated_extents(points: &[DVec2], angle: f64) -> (DVec2, DVec2) {
    let (c, s) = (angle.cos(), angle.sin());
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in points {
        let q = DVec2::new(c * p.x + s * p.y, -s * p.x + c * p.y);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (lo, hi)
}

/// Andrew's monotone chain; returns the hull counter-clockwise without repeating the first point.
pub(crate) fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    // The lower chain left to right, then the upper right to left.
    let chain = |hull: &mut Vec<DVec2>, points: &mut dyn Iterator<Item = &DVec2>| {
        let start = hull.len();
        for &q in points {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    };
    chain(&mut hull, &mut p.iter());
    chain(&mut hull, &mut p.iter().rev());
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(view: &SunView, p: DVec3) -> DVec3 {
        view.view_proj.transform_point3(p)
    }

    #[test]
    fn receiver_fills_the_tile_with_a_pixel_margin() {
        // A 4 m × 1 m south wall, sun from the south-west, low.
        let pts = [DVec3::new(0., 0., 0.), DVec3::new(4., 0., 0.), DVec3::new(4., 0., 1.), DVec3::new(0., 0., 1.)];
        let sun = DVec3::new(-0.5, -0.7, 0.3).normalize();
        let bounds = (DVec3::new(-5., -5., 0.), DVec3::new(5., 5., 3.));
        let origin = DVec3::new(1.0, 2.0, 0.5);
        let view = fit(&pts, sun, bounds, origin, 512);
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in pts {
            let c = clip(&view, p - origin);
            lo = lo.min(c);
            hi = hi.max(c);
        }
        // Inside the tile by at least a pixel (2/512 in clip units), and filling most of it.
        let inner = 1.0 - 2.0 / 512.0 + 1e-9;
        assert!(lo.x >= -inner && hi.x <= inner && lo.y >= -inner && hi.y <= inner, "{lo} {hi}");
        assert!(hi.x - lo.x > 1.5 && hi.y - lo.y > 1.5, "{lo} {hi}");
        assert!(lo.z > 0.0 && hi.z < 1.0);
        // Projected area = A·cosθ; the rectangle here is the projected parallelogram's box,
        // so pixel count of the full tile interior ≥ projected area.
        let cos = DVec3::new(0., -1., 0.).dot(sun);
        assert!(view.pixel_area * 510.0 * 510.0 >= 4.0 * cos - 1e-9);
    }

    #[test]
    fn every_scene_point_lies_in_front_of_the_near_plane() {
        let pts = [DVec3::new(0., 0., 0.), DVec3::new(1., 0., 0.), DVec3::new(0., 0., 1.)];
        let sun = DVec3::new(0.2, -0.9, 0.4).normalize();
        let bounds = (DVec3::new(-10., -10., 0.), DVec3::new(10., 10., 30.));
        let view = fit(&pts, sun, bounds, DVec3::ZERO, 256);
        for c in corners(bounds) {
            assert!(clip(&view, c).z > 0.0);
        }
        // Closer to the sun means smaller depth.
        assert!(clip(&view, sun).z < clip(&view, DVec3::ZERO).z);
    }

    #[test]
    fn hull_and_rectangle_of_a_rotated_square() {
        let a = 0.3f64;
        let pts: Vec<DVec2> = [(0., 0.), (1., 0.), (1., 1.), (0., 1.), (0.5, 0.5)]
            .iter()
            .map(|&(x, y)| DVec2::new(x * a.cos() - y * a.sin(), x * a.sin() + y * a.cos()))
            .collect();
        assert_eq!(convex_hull(&pts).len(), 4);
        let (_, lo, hi) = min_area_rectangle(&pts);
        assert!(((hi.x - lo.x) * (hi.y - lo.y) - 1.0).abs() < 1e-9);
    }
}
