//! Where a window or door sits relative to its base surface's plane, as EnergyPlus 25.2 places it.
//!
//! Owns EnergyPlus's sub-surface rule: a sub-surface belongs to its base surface and is shadowed
//! in the base surface's plane (SolarShading.cc `SHDSBS` transforms its vertices into the base
//! surface's coordinates, `CTRANS`, and drops the depth), so the hole it makes in its wall is its
//! outline projected along the wall's normal onto the wall's plane, whatever its offset.
//! SurfaceGeometry.cc stores the offset as the sub-surface's *reveal* (the distance of its
//! vertex 2 behind the base plane, 0 within 0.2 mm) and `SHDRVL` shades a sub-surface by the
//! reveal's sides only when the reveal is positive, that is when it is set back:
//! - **Set back** (a reveal): it stays at its own depth, and the reveal's sides (one quad per edge,
//!   from its edge to that edge's projection on the wall's plane) are added as casters, so the
//!   light that reaches it has passed the opening in the wall and missed the sides;
//! - **Proud or flush**: it is flattened onto the wall's plane.
//!
//! Measured with EnergyPlus 25.2 (`tests/energyplus.rs`): a window set back 0.15 m gets the
//! reveal's shadow, a window 0.1 m proud of its wall gets exactly the flush window's fractions,
//! and neither changes its wall's fraction.

use glam::DVec3;

/// Offsets within this (m) count as flush (EnergyPlus's reveal threshold, 0.0002 m).
const FLUSH: f64 = 2e-4;

/// A sub-surface placed against its base surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// Drawn in the base surface's plane (these are its projected vertices).
    InPlane(Vec<DVec3>),
    /// Set back behind the base plane.
    SetBack {
        /// How far (m), EnergyPlus's reveal.
        depth: f64,
        /// The reveal's sides as triangles (casters).
        sides: Vec<[DVec3; 3]>,
    },
}

/// The base surface's plane: a point on it and its outward unit normal (Newell's).
fn plane(base: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let n = base.len();
    if n < 3 {
        return None;
    }
    let centre = base.iter().copied().sum::<DVec3>() / n as f64;
    let normal: DVec3 = (0..n).map(|i| (base[i] - centre).cross(base[(i + 1) % n] - centre)).sum();
    let normal = normal.try_normalize()?;
    Some((centre, normal))
}

/// How EnergyPlus places `sub` (counter-clockwise from outside) against `base`; None when the
/// base surface has no plane.
pub fn place(base: &[DVec3], sub: &[DVec3]) -> Option<Placement> {
    let (origin, normal) = plane(base)?;
    // EnergyPlus measures the reveal at vertex 2 (the lower-left corner once stored).
    let at = sub.get(1).or(sub.first())?;
    let reveal = -(*at - origin).dot(normal);
    let project = |p: DVec3| p - normal * (p - origin).dot(normal);
    if reveal <= FLUSH {
        return Some(Placement::InPlane(sub.iter().map(|p| project(*p)).collect()));
    }
    let sides = (0..sub.len())
        .flat_map(|i| {
            let (a, b) = (sub[i], sub[(i + 1) % sub.len()]);
            let (a_out, b_out) = (project(a), project(b));
            [[a, b, b_out], [a, b_out, a_out]]
        })
        .collect();
    Some(Placement::SetBack { depth: reveal, sides })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A south wall (facing −y) at y = 0, x 0–10, z 0–3.5, counter-clockwise from outside.
    fn wall() -> Vec<DVec3> {
        vec![DVec3::new(0., 0., 3.5), DVec3::new(0., 0., 0.), DVec3::new(10., 0., 0.), DVec3::new(10., 0., 3.5)]
    }

    fn window(y: f64) -> Vec<DVec3> {
        vec![DVec3::new(2., y, 2.5), DVec3::new(2., y, 1.), DVec3::new(8., y, 1.), DVec3::new(8., y, 2.5)]
    }

    #[test]
    fn proud_and_flush_windows_go_into_the_wall_plane() {
        for y in [0.0, 1e-4, -0.1, -1.0] {
            assert_eq!(place(&wall(), &window(y)), Some(Placement::InPlane(window(0.0))), "y = {y}");
        }
    }

    #[test]
    fn set_back_windows_keep_their_depth_and_get_the_reveal_sides() {
        let Some(Placement::SetBack { depth, sides }) = place(&wall(), &window(0.15)) else { panic!("set back") };
        assert!((depth - 0.15).abs() < 1e-12);
        // Four sides of 0.15 m depth around a 6 × 1.5 m window: 2·(6 + 1.5)·0.15 m².
        let area: f64 = sides.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum();
        assert!((area - 2.0 * 7.5 * 0.15).abs() < 1e-9, "{area}");
        assert!(sides.iter().flatten().all(|p| p.y >= -1e-12 && p.y <= 0.15 + 1e-12 && p.x >= 2.0 && p.x <= 8.0));
    }
}
