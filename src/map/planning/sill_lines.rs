//! Each window's own sill line for GB 50180's 满窗 (whole window) rule, measured from the
//! window's geometry instead of a width given per window ([`super::sill_widths`]) or one width for
//! all: the rule asks for the sun over the whole sill, and the sill is the window's.
//!
//! The sill line of a window (a receiver) is where its sill point
//! ([`super::window_points::WindowPoint::Sill`]) lies, across the whole window:
//! - its **lowest edge**: the vertices within [`EDGE_TOLERANCE`] of its lowest height, from the
//!   one furthest left to the one furthest right along the wall (horizontal in the window's
//!   plane); a rectangle's bottom side, a trapezoid's or an arched window's bottom, an L-shaped
//!   window's lowest side;
//! - with a ground-floor level ([`super::window_points::floor_sills`]) where the window reaches
//!   below the sill height (a 落地窗): the window's **chord at that height**, where the horizontal
//!   line in its plane at the sill height crosses its triangles, from the leftmost crossing to the
//!   rightmost.
//!
//! A window whose lowest point is a corner (a diamond, a round window's polygon on a vertex, a
//! sloping bottom) has no horizontal lowest edge: a sill under [`MIN_SILL_WIDTH`] is refused,
//! naming the window and `window_width`; give its width with `window_widths`. The line spans the
//! window's outline: a window made of two panes in one receiver has one line across both, gap
//! included (give each window its own receiver). Only the windows' own sill points have a sill
//! line: points given or on a grid, and the windows' centres, are refused naming `window_width`.

use glam::DVec3;

use super::window_points::{EDGE_TOLERANCE, SILL_HEIGHT, WindowPoint, lowest_edge};
use crate::error::{Error, Result};
use crate::map::Points;
use crate::scene::{Receiver, Scene};

/// The narrowest sill (m) a window's lowest edge may be: narrower, the window's lowest point is a
/// corner, not an edge.
pub const MIN_SILL_WIDTH: f64 = 0.01;

/// One window's sill, its ends in world axes (left to right along the wall, seen from outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SillLine {
    /// The left end (m).
    pub from: DVec3,
    /// The right end (m).
    pub to: DVec3,
}

impl SillLine {
    /// The sill's width (m).
    pub fn width(&self) -> f64 {
        (self.to - self.from).length()
    }
}

/// The sill line of each of `points`' windows (its receiver), in the points' order: the points
/// must be the windows' own sills (`at` = [`WindowPoint::Sill`]), raised above `floor` when one
/// was given as they were. Refuses, naming `window_width`, points that are not windows' sills,
/// and a window without a horizontal lowest edge.
pub fn sill_lines(scene: &Scene, points: &Points, at: Option<WindowPoint>, floor: Option<f64>) -> Result<Vec<SillLine>> {
    if at != Some(WindowPoint::Sill) {
        let which = at.map_or("points given or on a grid are not known to be any window's sill".to_string(), |at| {
            format!("the windows' {}s are not their sills", at.name())
        });
        return Err(Error::argument(
            "window_width",
            format!("'sill' measures each window's own sill line, so the points must be the windows' sills (window_points sill): {which}"),
        ));
    }
    points
        .receivers
        .iter()
        .map(|&id| {
            let r = scene.receivers.get(id as usize).ok_or_else(|| Error::argument("receiver", format!("id {id} out of range")))?;
            sill_line(r, floor)
        })
        .collect()
}

/// One window's sill line (see the module's docs).
pub fn sill_line(r: &Receiver, floor: Option<f64>) -> Result<SillLine> {
    let (from, to) = lowest_edge(r)?;
    let line = match floor.map(|f| f + SILL_HEIGHT) {
        Some(height) if (from.z + to.z) / 2.0 < height - EDGE_TOLERANCE => chord(r, height)?,
        _ => SillLine { from, to },
    };
    if line.width() < MIN_SILL_WIDTH {
        return Err(Error::argument(
            "window_width",
            format!(
                "window '{}' ({}) has no horizontal lowest edge to be its sill: its lowest point is a corner ({:.3} m wide); give its width with window_widths",
                r.name,
                r.origin,
                line.width()
            ),
        ));
    }
    Ok(line)
}

/// Where the horizontal line at `height` in the window's plane crosses its triangles, from the
/// leftmost crossing to the rightmost.
fn chord(r: &Receiver, height: f64) -> Result<SillLine> {
    let along = DVec3::Z.cross(r.normal).normalize();
    let mut crossings = Vec::new();
    for t in &r.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (da, db) = (a.z - height, b.z - height);
            if da == 0.0 {
                crossings.push(a);
            }
            if da * db < 0.0 {
                crossings.push(a + (b - a) * (da / (da - db)));
            }
        }
    }
    let left = crossings.iter().min_by(|a, b| a.dot(along).total_cmp(&b.dot(along)));
    let right = crossings.iter().max_by(|a, b| a.dot(along).total_cmp(&b.dot(along)));
    match left.zip(right) {
        Some((&from, &to)) => Ok(SillLine { from, to }),
        None => {
            Err(Error::argument("floor_level", format!("window '{}' ({}) does not reach its sill height {height:.3} m", r.name, r.origin)))
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::map::planning::test_window as window;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn a_rectangles_sill_is_its_bottom_side_and_a_trapezoids_its_bottom() {
        // A south window 1.5 m wide, 0.9..2.4 m up, drawn from a top corner (the fan's triangles
        // do not start on the sill); left to right seen from the south is west to east.
        let south = [DVec3::new(2.5, 0.0, 2.4), DVec3::new(1.0, 0.0, 2.4), DVec3::new(1.0, 0.0, 0.9), DVec3::new(2.5, 0.0, 0.9)];
        let line = sill_line(&window(&south).receivers[0], None).unwrap();
        assert!(close(line.from, DVec3::new(1.0, 0.0, 0.9)) && close(line.to, DVec3::new(2.5, 0.0, 0.9)), "{line:?}");
        assert!((line.width() - 1.5).abs() < 1e-6);
        // A trapezoid 2 m at the bottom, 1 m at the top, facing east.
        let east = [DVec3::new(0.0, -1.0, 1.0), DVec3::new(0.0, 1.0, 1.0), DVec3::new(0.0, 0.5, 2.0), DVec3::new(0.0, -0.5, 2.0)];
        let line = sill_line(&window(&east).receivers[0], None).unwrap();
        assert!((line.width() - 2.0).abs() < 1e-6 && (line.from.z - 1.0).abs() < 1e-9, "{line:?}");
    }

    #[test]
    fn a_window_reaching_the_floor_has_its_chord_at_the_sill_height() {
        // A trapezoid door-window, 3 m at the floor narrowing to 1 m at 2 m: 0.9 m above the
        // floor it is 3 − 2 · 0.9/2 = 2.1 m wide.
        let door = [DVec3::new(3.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 2.0), DVec3::new(1.0, 0.0, 2.0), DVec3::new(0.0, 0.0, 0.0)];
        let scene = window(&door);
        let line = sill_line(&scene.receivers[0], Some(0.0)).unwrap();
        assert!((line.width() - 2.1).abs() < 1e-5 && (line.from.z - 0.9).abs() < 1e-6 && (line.to.z - 0.9).abs() < 1e-6, "{line:?}");
        assert!((line.from.x - 0.45).abs() < 1e-5, "{line:?}");
        // A floor below the window's own sill height leaves its lowest edge.
        assert!((sill_line(&scene.receivers[0], Some(-2.0)).unwrap().width() - 3.0).abs() < 1e-6);
    }

    #[test]
    fn a_corner_is_no_sill_and_only_sill_points_have_lines() {
        let diamond = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.5, 1.5), DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, -0.5, 1.5)];
        let error = sill_line(&window(&diamond).receivers[0], None).unwrap_err();
        assert_eq!(error.parameter(), Some("window_width"));
        assert!(error.to_string().contains("WIN") && error.to_string().contains("no horizontal lowest edge"), "{error}");
        // A sloping bottom: 1 cm lower at one end than the other.
        let sloping = [DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 1.01), DVec3::new(1.0, 0.0, 2.0)];
        assert_eq!(sill_line(&window(&sloping).receivers[0], None).unwrap_err().parameter(), Some("window_width"));
        let south = [DVec3::new(2.5, 0.0, 2.4), DVec3::new(1.0, 0.0, 2.4), DVec3::new(1.0, 0.0, 0.9), DVec3::new(2.5, 0.0, 0.9)];
        let scene = window(&south);
        let mut points = Points::default();
        points.push(DVec3::new(1.75, -0.005, 0.9), scene.receivers[0].normal, 0);
        for at in [None, Some(WindowPoint::Centre)] {
            assert_eq!(sill_lines(&scene, &points, at, None).unwrap_err().parameter(), Some("window_width"), "{at:?}");
        }
        assert_eq!(sill_lines(&scene, &points, Some(WindowPoint::Sill), None).unwrap().len(), 1);
    }
}
