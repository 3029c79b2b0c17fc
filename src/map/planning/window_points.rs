//! A window study's points found from the windows themselves, one per window (each receiver is
//! one window, as `--receivers 'WIN_*'` chooses them), instead of points given in a CSV:
//! - [`WindowPoint::Centre`]: BRE 209's reference point, the centre of the window on its outside
//!   face (the area centroid of its triangles);
//! - [`WindowPoint::Sill`]: GB 50180's 底层窗台面, the middle of the window's lowest edge: the
//!   lowest vertices (within [`EDGE_TOLERANCE`] of the lowest height), from the one furthest
//!   left to the one furthest right along the wall. A window whose bottom is one corner (a
//!   diamond) has that corner as its sill.
//!
//! [`floor_sills`] takes GB 50180's sill at [`SILL_HEIGHT`] above a given ground-floor level
//! where a window reaches lower (a 落地窗, reaching the floor, has no sill of its own): its point
//! is raised within the window's plane, above the middle of its lowest edge.
//!
//! Each point sits [`OFFSET`] out of the window's plane along its outward normal: on the outside
//! face, and within the map's on-surface tolerance ([`crate::map::points::ON_SURFACE_TOLERANCE`]) so that
//! `--before` finds the same window in the existing scene. The studies answer a point from its
//! projection onto its receiver's plane (as every map's points), so the offset changes no
//! answer; it says where the point is meant to be.

use glam::DVec3;

use crate::error::{Error, Result};
use crate::geometry::triangle_area;
use crate::map::Points;
use crate::scene::{Receiver, Scene};

/// How far (m) a window's point sits out of its plane, on the outside.
pub const OFFSET: f64 = 0.005;

/// Vertices within this height (m) of a window's lowest vertex are on its lowest edge (its
/// triangulation may put the edge's ends a rounding apart).
pub const EDGE_TOLERANCE: f64 = 0.001;

/// GB 50180's sill height above the ground floor's level (m), where a window reaches lower.
pub const SILL_HEIGHT: f64 = 0.9;

/// A window whose normal is within this of vertical (|n_z| above it) lies flat and has no sill.
const FLAT: f64 = 0.999;

/// Which point of each window a study is asked at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowPoint {
    /// BRE 209's reference point: the window's centre on its outside face.
    Centre,
    /// GB 50180's ground-floor sill: the middle of the window's lowest edge.
    Sill,
}

impl WindowPoint {
    /// The names [`Self::parse`] reads.
    pub const NAMES: [&'static str; 2] = ["centre", "sill"];

    /// Reads `centre` (or `center`) or `sill`; refuses another, naming `window_points`.
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "centre" | "center" => Ok(Self::Centre),
            "sill" => Ok(Self::Sill),
            other => Err(Error::argument("window_points", format!("'{other}' is not one of {}", Self::NAMES.join(", ")))),
        }
    }

    /// The name, as [`Self::parse`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Centre => "centre",
            Self::Sill => "sill",
        }
    }

    /// What the point is, for a report.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Centre => "each window's centre on its outside face (BRE 209's reference point)",
            Self::Sill => "the middle of each window's lowest edge on its outside face (GB 50180's 底层窗台面)",
        }
    }
}

/// One point per receiver of `receivers` (ids into `scene.receivers`, in that order) at `at`,
/// [`OFFSET`] out of its plane, with its normal. Refuses a receiver without area, and for
/// [`WindowPoint::Sill`] one lying flat (a roof light has no lowest edge), naming it.
pub fn window_points(scene: &Scene, receivers: &[u32], at: WindowPoint) -> Result<Points> {
    let mut points = Points::default();
    for &id in receivers {
        let r = scene.receivers.get(id as usize).ok_or_else(|| Error::argument("receiver", format!("id {id} out of range")))?;
        if r.triangles.is_empty() || r.area.is_nan() || r.area <= 0.0 {
            return Err(Error::argument("window_points", format!("receiver '{}' ({}) has no area to put a point on", r.name, r.origin)));
        }
        let on = match at {
            WindowPoint::Centre => centroid(r),
            WindowPoint::Sill => sill(r)?,
        };
        points.push(on + r.normal * OFFSET, r.normal, id);
    }
    Ok(points)
}

/// GB 50180's sill points of `receivers` with the ground floor at `floor` (m, the world's z):
/// each window's [`WindowPoint::Sill`], raised within its plane to `floor` + [`SILL_HEIGHT`]
/// where its lowest edge is lower (a window reaching the floor). Refuses, naming `floor_level`, a
/// window whose top is below that height (it has no point there).
pub fn floor_sills(scene: &Scene, receivers: &[u32], floor: f64) -> Result<Points> {
    let sills = window_points(scene, receivers, WindowPoint::Sill)?;
    let height = floor + SILL_HEIGHT;
    let mut points = Points::default();
    for (i, &id) in receivers.iter().enumerate() {
        let r = scene.receivers.get(id as usize).ok_or_else(|| Error::argument("receiver", format!("id {id} out of range")))?;
        let mut p = sills.position(i);
        if p.z < height - EDGE_TOLERANCE {
            let top = r.triangles.iter().flatten().map(|v| v.z).fold(f64::NEG_INFINITY, f64::max);
            if top < height {
                return Err(Error::argument(
                    "floor_level",
                    format!(
                        "window '{}' ({}) reaches {top:.3} m, below its sill height {height:.3} m ({floor} + {SILL_HEIGHT})",
                        r.name, r.origin
                    ),
                ));
            }
            // Up the window's plane (vertical for a wall's window), to the sill height.
            let up = (DVec3::Z - r.normal * r.normal.z).normalize();
            p += up * ((height - p.z) / up.z);
        }
        points.push(p, r.normal, id);
    }
    Ok(points)
}

/// The area centroid of a receiver's triangles.
fn centroid(r: &Receiver) -> DVec3 {
    let (mut sum, mut area) = (DVec3::ZERO, 0.0);
    for t in &r.triangles {
        let a = triangle_area(t);
        sum += (t[0] + t[1] + t[2]) / 3.0 * a;
        area += a;
    }
    sum / area
}

/// The middle of a receiver's lowest edge (see the module's docs).
fn sill(r: &Receiver) -> Result<DVec3> {
    lowest_edge(r).map(|(a, b)| (a + b) / 2.0)
}

/// A receiver's lowest edge, its ends left and right along the wall (seen from outside): the
/// lowest vertices, within [`EDGE_TOLERANCE`] of the lowest height, furthest apart along the
/// wall (one corner at both ends where the window stands on it). Refuses a receiver lying flat,
/// naming `window_points`.
pub fn lowest_edge(r: &Receiver) -> Result<(DVec3, DVec3)> {
    if r.normal.z.abs() > FLAT {
        return Err(Error::argument(
            "window_points",
            format!("receiver '{}' ({}) lies flat: it has no lowest edge to be a sill", r.name, r.origin),
        ));
    }
    // Along the wall, horizontal: which way is left and right on the sill.
    let along = DVec3::Z.cross(r.normal).normalize();
    let vertices = || r.triangles.iter().flatten();
    let lowest = vertices().map(|p| p.z).fold(f64::INFINITY, f64::min);
    let bottom = || vertices().filter(|p| p.z <= lowest + EDGE_TOLERANCE);
    let left = bottom().min_by(|a, b| a.dot(along).total_cmp(&b.dot(along)));
    let right = bottom().max_by(|a, b| a.dot(along).total_cmp(&b.dot(along)));
    match left.zip(right) {
        Some((a, b)) => Ok((*a, *b)),
        None => Err(Error::argument("window_points", format!("receiver '{}' ({}) has no finite vertices", r.name, r.origin))),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::map::planning::test_window as window;

    #[test]
    fn a_rectangles_sill_is_its_lowest_edges_middle_and_its_centre_the_middle() {
        // A south window 1.5 m wide, 0.9..2.4 m up, drawn from a top corner so the fan's triangles
        // do not start on the sill.
        let south = [DVec3::new(2.5, 0.0, 2.4), DVec3::new(1.0, 0.0, 2.4), DVec3::new(1.0, 0.0, 0.9), DVec3::new(2.5, 0.0, 0.9)];
        let scene = window(&south);
        let n = scene.receivers[0].normal;
        assert!((n - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-5, "{n}");
        let sill = window_points(&scene, &[0], WindowPoint::Sill).unwrap();
        assert!((sill.position(0) - DVec3::new(1.75, -OFFSET, 0.9)).length() < 1e-5, "{}", sill.position(0));
        assert!((sill.normal(0) - n).length() < 1e-5);
        let centre = window_points(&scene, &[0], WindowPoint::Centre).unwrap();
        assert!((centre.position(0) - DVec3::new(1.75, -OFFSET, 1.65)).length() < 1e-5, "{}", centre.position(0));
    }

    #[test]
    fn a_window_reaching_the_floor_is_counted_at_the_sill_height_above_it() {
        // A south door-window 0..2.4 m, the ground floor at 0: its sill point is 0.9 m up; one
        // 0.9..2.4 m up keeps its own sill; one reaching only 0.8 m has none.
        let floor_window =
            window(&[DVec3::new(2.5, 0.0, 2.4), DVec3::new(1.0, 0.0, 2.4), DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.5, 0.0, 0.0)]);
        let raised = floor_sills(&floor_window, &[0], 0.0).unwrap();
        assert!((raised.position(0) - DVec3::new(1.75, -OFFSET, SILL_HEIGHT)).length() < 1e-5, "{}", raised.position(0));
        let lowest = window_points(&floor_window, &[0], WindowPoint::Sill).unwrap();
        assert!((lowest.position(0).z).abs() < 1e-5, "without a floor level: the lowest edge");
        let sill_window =
            window(&[DVec3::new(2.5, 0.0, 2.4), DVec3::new(1.0, 0.0, 2.4), DVec3::new(1.0, 0.0, 0.9), DVec3::new(2.5, 0.0, 0.9)]);
        assert!((floor_sills(&sill_window, &[0], -0.5).unwrap().position(0).z - 0.9).abs() < 1e-5, "a sill above 0.9 m stays");
        let low = window(&[DVec3::new(2.5, 0.0, 0.8), DVec3::new(1.0, 0.0, 0.8), DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.5, 0.0, 0.0)]);
        let error = floor_sills(&low, &[0], 0.0).unwrap_err();
        assert_eq!(error.parameter(), Some("floor_level"));
        assert!(error.to_string().contains("WIN"), "{error}");
    }

    #[test]
    fn a_diamonds_sill_is_its_lowest_corner_and_a_flat_window_has_none() {
        // A window facing east turned 45°: its lowest point is one corner.
        let east = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.5, 1.5), DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, -0.5, 1.5)];
        let scene = window(&east);
        let sill = window_points(&scene, &[0], WindowPoint::Sill).unwrap();
        assert!((sill.position(0) - DVec3::new(OFFSET, 0.0, 1.0)).length() < 1e-5, "{}", sill.position(0));
        let flat = window(&[DVec3::new(0.0, 0.0, 3.0), DVec3::new(1.0, 0.0, 3.0), DVec3::new(1.0, 1.0, 3.0), DVec3::new(0.0, 1.0, 3.0)]);
        let error = window_points(&flat, &[0], WindowPoint::Sill).unwrap_err();
        assert_eq!(error.parameter(), Some("window_points"));
        assert!(error.to_string().contains("WIN") && error.to_string().contains("flat"), "{error}");
        assert!(window_points(&flat, &[0], WindowPoint::Centre).is_ok(), "a roof light still has a centre");
        assert_eq!(WindowPoint::parse("middle").unwrap_err().parameter(), Some("window_points"));
        for at in [WindowPoint::Centre, WindowPoint::Sill] {
            assert_eq!(WindowPoint::parse(at.name()).unwrap(), at);
        }
    }
}
