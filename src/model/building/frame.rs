//! A surface's own frame as EnergyPlus builds it: in-plane axes from azimuth and tilt, the frame
//! simple subsurfaces are placed in (origin at the base's vertex 2), a window's frame within its
//! wall for overhangs and fins, and `DetermineAzimuthAndTilt`'s rule. Pure geometry, no IDF.

use glam::DVec3;

use crate::geometry::newell;

/// EnergyPlus's rectangle from a lower-left corner: upper-left, lower-left, lower-right,
/// upper-right, with "right" = (−cos a, sin a, 0) and "up" = (−cos t sin a, −cos t cos a, sin t).
pub(super) fn rectangle(corner: DVec3, azimuth: f64, tilt: f64, length: f64, height: f64) -> Vec<DVec3> {
    let axes = SurfaceAxes::new(azimuth, tilt);
    let (right, up) = (axes.right * length, axes.up * height);
    vec![corner + up, corner, corner + right, corner + right + up]
}

/// In-plane axes of a surface of given azimuth and tilt (degrees), as EnergyPlus builds them.
#[derive(Debug, Clone, Copy)]
pub(super) struct SurfaceAxes {
    pub(super) right: DVec3,
    pub(super) up: DVec3,
}

impl SurfaceAxes {
    pub(super) fn new(azimuth: f64, tilt: f64) -> Self {
        let (sa, ca) = azimuth.to_radians().sin_cos();
        let (st, ct) = tilt.to_radians().sin_cos();
        SurfaceAxes { right: DVec3::new(-ca, sa, 0.0), up: DVec3::new(-ct * sa, -ct * ca, st) }
    }
}

/// A base surface's frame for simple subsurfaces: origin at its vertex 2, axes from its azimuth
/// and tilt.
#[derive(Debug, Clone, Copy)]
pub(super) struct SurfaceFrame {
    pub(super) origin: DVec3,
    pub(super) azimuth: f64,
    pub(super) tilt: f64,
    pub(super) axes: SurfaceAxes,
}

impl SurfaceFrame {
    pub(super) fn of(vertices: &[DVec3]) -> Self {
        let (azimuth, tilt) = azimuth_tilt(vertices);
        let origin = vertices.get(1).or(vertices.first()).copied().unwrap_or(DVec3::ZERO);
        SurfaceFrame { origin, azimuth, tilt, axes: SurfaceAxes::new(azimuth, tilt) }
    }

    /// The point at (x, z) in the surface's plane.
    pub(super) fn at(&self, x: f64, z: f64) -> DVec3 {
        self.origin + self.axes.right * x + self.axes.up * z
    }

    /// (x, z) of a point in the plane.
    pub(super) fn coords(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.origin;
        (d.dot(self.axes.right), d.dot(self.axes.up))
    }
}

/// A window or door in its base surface's frame, for overhangs and fins.
pub(super) struct WindowFrame {
    pub(super) base: SurfaceFrame,
    pub(super) own: SurfaceFrame,
    pub(super) x: f64,
    pub(super) z: f64,
    pub(super) width: f64,
    pub(super) height: f64,
}

impl WindowFrame {
    pub(super) fn of(window: &[DVec3], base: &[DVec3]) -> Self {
        let base = SurfaceFrame::of(base);
        let own = SurfaceFrame::of(window);
        let (x, z) = base.coords(own.origin);
        let at = |i: usize| window.get(i).copied().unwrap_or(own.origin);
        WindowFrame { base, own, x, z, width: at(2).distance(at(1)), height: at(1).distance(at(0)) }
    }
}

/// Whether four vertices are an upright rectangle in the base surface's frame listed upper-left,
/// lower-left, lower-right, upper-right (to 1 mm): the shape EnergyPlus's reveal shading takes a
/// four-sided set-back window to be (see `mesh::reveal_problem`).
pub(super) fn upright_from_upper_left(sub: &[DVec3], base: &[DVec3]) -> bool {
    const TOLERANCE: f64 = 1e-3;
    let [a, b, c, d] = sub else { return false };
    let frame = SurfaceFrame::of(base);
    let [(u1, v1), (u2, v2), (u3, v3), (u4, v4)] = [a, b, c, d].map(|p| frame.coords(*p));
    let same = |x: f64, y: f64| (x - y).abs() <= TOLERANCE;
    same(u1, u2) && same(u3, u4) && u1 < u3 && same(v1, v4) && same(v2, v3) && v1 > v2
}

/// Azimuth (degrees clockwise from north, 0..360) and tilt (degrees from up) of a surface, as
/// EnergyPlus's `DetermineAzimuthAndTilt`: from the normal, except for horizontal surfaces, whose
/// azimuth puts "right" along their vertex 2 → 3 edge (so a skylight placed on a flat roof lines
/// up with the roof's edges; checked against EnergyPlus 25.2).
pub(super) fn azimuth_tilt(vertices: &[DVec3]) -> (f64, f64) {
    let n = newell(vertices).normalize_or_zero();
    let tilt = n.z.clamp(-1.0, 1.0).acos().to_degrees();
    let edge = match (vertices.get(1), vertices.get(2)) {
        (Some(a), Some(b)) => *b - *a,
        _ => DVec3::X,
    };
    let azimuth = if n.x.hypot(n.y) > 1e-8 { n.x.atan2(n.y) } else { edge.y.atan2(-edge.x) };
    (azimuth.to_degrees().rem_euclid(360.0), tilt)
}
