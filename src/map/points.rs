//! Where the map is evaluated: a grid on every receiver, or points read from a CSV.

use glam::{DVec2, DVec3};

use super::Points;
use crate::error::{Error, Result};
use crate::scene::{Receiver, Scene};

/// Most points a map holds: each costs about 60 bytes over a run (position, normal, receiver,
/// its index, two f64 sums, a visibility per thread), so 20 million stay near 1.2 GiB.
pub const MAX_POINTS: usize = 20_000_000;

/// A CSV point belongs to a receiver when it lies within this distance (m) of its plane and,
/// in the plane, within it of one of its triangles: a reference point given to the centimetre.
pub const ON_SURFACE_TOLERANCE: f64 = 0.01;

/// A receiver's plane axes for its grid: `e1` horizontal on walls (x on flat surfaces), `e2`
/// completing them with the normal, so grid rows follow a façade's courses.
fn grid_axes(normal: DVec3) -> (DVec3, DVec3) {
    let e1 = if normal.z.abs() < 0.9 { DVec3::Z.cross(normal).normalize() } else { (DVec3::X - normal * normal.x).normalize() };
    (e1, normal.cross(e1))
}

/// A grid at `spacing` metres on each of `receivers` (ids into `scene.receivers`): the centres of
/// a square lattice's cells in the receiver's plane (rows horizontal on walls) that fall inside
/// one of its triangles, so its holes (triangulated out) stay empty and each point stands for
/// `spacing²` of surface. Refuses a spacing that is not a positive finite number, or one that
/// would make more than [`MAX_POINTS`] points (counted from the receivers' areas first).
pub fn grid(scene: &Scene, spacing: f64, receivers: &[u32]) -> Result<Points> {
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(Error::argument("spacing", format!("{spacing} m: a grid spacing must be a positive number of metres")));
    }
    let chosen: Vec<(u32, &Receiver)> = receivers
        .iter()
        .map(|&id| {
            scene.receivers.get(id as usize).map(|r| (id, r)).ok_or_else(|| Error::argument("receiver", format!("id {id} out of range")))
        })
        .collect::<Result<_>>()?;
    let estimate: f64 = chosen.iter().map(|(_, r)| r.area / (spacing * spacing)).sum();
    if estimate > MAX_POINTS as f64 {
        return Err(Error::argument(
            "spacing",
            format!("{spacing} m would make about {estimate:.0} points on {} receivers; at most {MAX_POINTS} fit", chosen.len()),
        ));
    }
    let mut points = Points { spacing: Some(spacing), ..Points::default() };
    for (id, r) in chosen {
        grid_on(r, spacing, |p| points.push(p, r.normal, id));
        if points.len() > MAX_POINTS {
            return Err(Error::argument("spacing", format!("{spacing} m makes more than {MAX_POINTS} points")));
        }
    }
    Ok(points)
}

/// Calls `emit` with every grid point of one receiver, row by row.
fn grid_on(r: &Receiver, spacing: f64, mut emit: impl FnMut(DVec3)) {
    let Some(origin) = r.triangles.first().map(|t| t[0]) else { return };
    let (e1, e2) = grid_axes(r.normal);
    let flat = |p: DVec3| DVec2::new((p - origin).dot(e1), (p - origin).dot(e2));
    let triangles: Vec<[DVec2; 3]> = r.triangles.iter().map(|t| t.map(flat)).collect();
    let (lo, hi) = triangles.iter().flatten().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    if !(lo.is_finite() && hi.is_finite()) {
        return;
    }
    let rows = ((hi.y - lo.y) / spacing).ceil().max(1.0) as usize;
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for row in 0..rows {
        let v = lo.y + (row as f64 + 0.5) * spacing;
        spans.clear();
        spans.extend(triangles.iter().filter_map(|t| row_span(t, v)));
        spans.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Merged spans, so a point on an edge two triangles share comes out once.
        let mut last_column: Option<i64> = None;
        for &(a, b) in &spans {
            let first = ((a - lo.x) / spacing - 0.5).ceil() as i64;
            let end = ((b - lo.x) / spacing - 0.5).floor() as i64;
            let first = last_column.map_or(first, |l| first.max(l + 1));
            for column in first..=end {
                let u = lo.x + (column as f64 + 0.5) * spacing;
                emit(origin + e1 * u + e2 * v);
                last_column = Some(column);
            }
        }
    }
}

/// Where the line at height `v` crosses a triangle: its `u` interval, if it does.
fn row_span(t: &[DVec2; 3], v: f64) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for i in 0..3 {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        if (a.y <= v && v <= b.y) || (b.y <= v && v <= a.y) {
            if a.y == b.y {
                lo = lo.min(a.x.min(b.x));
                hi = hi.max(a.x.max(b.x));
            } else {
                let u = a.x + (b.x - a.x) * (v - a.y) / (b.y - a.y);
                lo = lo.min(u);
                hi = hi.max(u);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Points read from CSV text with the header `x,y,z,nx,ny,nz` (world axes: x east, y north, z up,
/// metres), each assigned to the receiver among `receivers` it lies on: within
/// [`ON_SURFACE_TOLERANCE`] of its plane and of its triangles, facing the same side (normal ·
/// the receiver's normal > 0); the nearest plane wins. `file_label` names the source in errors,
/// which give the line: a malformed number, a normal of zero length, a point on no receiver.
pub fn from_csv(scene: &Scene, file_label: &str, text: &str, receivers: &[u32]) -> Result<Points> {
    let mut points = Points::default();
    for (line, p, n) in csv_rows(file_label, text)? {
        let Some(id) = receiver_under(scene, receivers, p, n) else {
            return Err(Error::object(
                file_label,
                format!("line {line}"),
                format!("point ({}, {}, {}) lies on no chosen receiver facing its normal (within {ON_SURFACE_TOLERANCE} m)", p.x, p.y, p.z),
            ));
        };
        points.push(p, n, id);
    }
    Ok(points)
}

/// The rows of a points CSV (see [`from_csv`]): line number (1-based), position, unit normal.
/// Refuses another header, a malformed row, a normal of zero length, no rows, and more than
/// [`MAX_POINTS`].
pub(crate) fn csv_rows(file_label: &str, text: &str) -> Result<Vec<(usize, DVec3, DVec3)>> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let header: Vec<String> = lines.next().map(|(_, l)| l.split(',').map(|f| f.trim().to_ascii_lowercase()).collect()).unwrap_or_default();
    if header != ["x", "y", "z", "nx", "ny", "nz"] {
        return Err(Error::model(file_label, format!("the header is '{}', expected 'x,y,z,nx,ny,nz'", header.join(","))));
    }
    let mut rows = Vec::new();
    for (index, line) in lines {
        let at = || format!("line {}", index + 1);
        let values: Vec<f64> = line
            .split(',')
            .map(|f| f.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| Error::object(file_label, at(), format!("'{}' is not six finite numbers", line.trim())))?;
        if values.len() != 6 {
            return Err(Error::object(file_label, at(), format!("{} values, expected 6 (x,y,z,nx,ny,nz)", values.len())));
        }
        let p = DVec3::new(values[0], values[1], values[2]);
        let n = DVec3::new(values[3], values[4], values[5]);
        if n.length() < 1e-9 {
            return Err(Error::object(file_label, at(), "the normal (nx,ny,nz) has zero length"));
        }
        rows.push((index + 1, p, n.normalize()));
        if rows.len() > MAX_POINTS {
            return Err(Error::model(file_label, format!("more than {MAX_POINTS} points")));
        }
    }
    if rows.is_empty() {
        return Err(Error::model(file_label, "no points after the header"));
    }
    Ok(rows)
}

/// The points of `points` that lie on one of `receivers` of `scene` (placed as [`from_csv`]
/// places a row), and where each sits in `points`: the same reference points on another scene,
/// as the existing scene beside the proposed one. A point on none of them is left out.
pub fn place_on(scene: &Scene, points: &Points, receivers: &[u32]) -> (Points, Vec<usize>) {
    let mut kept = Points::default();
    let mut index = Vec::new();
    for i in 0..points.len() {
        let (p, n) = (points.position(i), points.normal(i));
        if let Some(id) = receiver_under(scene, receivers, p, n) {
            kept.push(p, n, id);
            index.push(i);
        }
    }
    (kept, index)
}

/// The receiver `p` lies on (see [`from_csv`]), if any.
pub(crate) fn receiver_under(scene: &Scene, receivers: &[u32], p: DVec3, n: DVec3) -> Option<u32> {
    let mut best: Option<(f64, u32)> = None;
    for &id in receivers {
        let Some(r) = scene.receivers.get(id as usize) else { continue };
        let Some(origin) = r.triangles.first().map(|t| t[0]) else { continue };
        let h = r.normal.dot(p - origin);
        if h.abs() > ON_SURFACE_TOLERANCE || r.normal.dot(n) <= 0.0 {
            continue;
        }
        let (e1, e2) = grid_axes(r.normal);
        let flat = |q: DVec3| DVec2::new((q - origin).dot(e1), (q - origin).dot(e2));
        let q = flat(p);
        let near = r.triangles.iter().any(|t| distance_to_triangle(q, &t.map(flat)) <= ON_SURFACE_TOLERANCE);
        if near && best.is_none_or(|(d, _)| h.abs() < d) {
            best = Some((h.abs(), id));
        }
    }
    best.map(|(_, id)| id)
}

/// Distance from `q` to a 2D triangle (0 inside).
fn distance_to_triangle(q: DVec2, t: &[DVec2; 3]) -> f64 {
    let side = |a: DVec2, b: DVec2| (b - a).perp_dot(q - a);
    let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
    if s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0) {
        return 0.0;
    }
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let ab = b - a;
            let k = if ab.length_squared() > 0.0 { ((q - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
            (q - (a + ab * k)).length()
        })
        .fold(f64::INFINITY, f64::min)
}
