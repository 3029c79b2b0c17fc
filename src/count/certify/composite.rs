//! Composite casters for the dark proof: opaque panels of any objects that lie in one plane and
//! together form one flat convex polygon with no gap (a facade of per-floor walls, each with a
//! hole, and the windows filling the holes; the faces of two blocks built flush), so they shade
//! as that one polygon would. No single panel covers a neighbouring receiver; their union may.
//!
//! Owns which panels combine and the proof that their union is the polygon. The proof is exact,
//! with no tolerance:
//! - **One plane, exactly.** Only panels in an axis-aligned plane combine: every corner of every
//!   triangle has the same coordinate along that axis, bit for bit. A facade turned off the axes
//!   is not combined (its corners' rounding would bend the sheet), and its panels prove only what
//!   each proves alone.
//! - **No gap.** In the plane (the two other coordinates, an exact projection) every triangle
//!   has positive area with one orientation. Their edges are cut at every corner of the panels
//!   that lies on them (a T-junction: a window's corner on the wall strip below it), and the
//!   pieces, corners bit for bit, summed as a chain: a piece run once each way cancels. What is
//!   left, the *boundary*, must be one closed loop, each piece run once, that turns one way
//!   only, once round: a convex polygon `P`. Then, for almost every point `x` of the plane, the
//!   number of triangles holding `x` is the winding number of their boundaries' sum about `x`,
//!   which is the loop's: 1 inside `P`, 0 outside. The closed triangles cover `P`, and a ray that
//!   crosses the plane inside `P` meets an opaque triangle. A gap between panels, however thin,
//!   leaves pieces that do not cancel: the panels are not combined.
//! - Whether a corner lies on an edge, and the loop's turns, are tested in `f64` on the corners
//!   as stored (for corners read from `f32`, whose differences' products `f64` holds exactly,
//!   these are exact). Where rounding could make either answer wrong, the polygon differs from
//!   the panels by a sliver at rounding's scale; the dark proof asks every receiver point to lie
//!   inside the caster's shadow by the cover margin (1e-6 of the scene's extent), far more.
//! - Components of more than 20,000 triangles (a tiled ground) are not tried.
//!
//! Transmitting or foliage triangles never combine (a see-through panel proves nothing dark);
//! nor do panels of one convex object alone (it is a caster already).

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::count::exact::engine::ExactEngine;

/// A corner's position, bit for bit.
type Key = [u64; 3];

/// The composite casters of a scene.
#[derive(Debug, Default)]
pub(crate) struct Composites {
    /// Per composite: its polygon's corners (world), collinear corners dropped.
    corners: Vec<Vec<DVec3>>,
    /// Triangle position → composite, for the positions in one.
    of: HashMap<u32, u32>,
}

impl Composites {
    /// Finds the composites among `index`'s opaque triangles.
    pub(crate) fn new(index: &ExactEngine) -> Self {
        let mut panels: Vec<(Plane, u32)> = (0..index.triangles.len())
            .filter(|&p| {
                let veil = index.veils[p];
                veil.rank < 0.0 && veil.transmittance == 0.0
            })
            .filter_map(|p| Plane::of(&index.triangles[p]).map(|plane| (plane, p as u32)))
            .collect();
        panels.sort_unstable();
        let mut out = Composites::default();
        for group in panels.chunk_by(|a, b| a.0 == b.0) {
            if group.len() < 2 {
                continue;
            }
            let plane = group[0].0;
            for component in connected(index, group.iter().map(|g| g.1)) {
                if component.len() < 2 || one_convex_object(index, &component) {
                    continue;
                }
                if let Some(corners) = convex_outline(index, plane, &component) {
                    let c = out.corners.len() as u32;
                    out.corners.push(corners);
                    out.of.extend(component.iter().map(|&p| (p, c)));
                }
            }
        }
        out
    }

    /// The composite the triangle at `position` belongs to, if any.
    pub(super) fn of(&self, position: usize) -> Option<u32> {
        u32::try_from(position).ok().and_then(|p| self.of.get(&p).copied())
    }

    /// Composite `c`'s polygon's corners (world).
    pub(super) fn corners(&self, c: u32) -> &[DVec3] {
        &self.corners[c as usize]
    }

    /// How many composites were found.
    pub(crate) fn len(&self) -> usize {
        self.corners.len()
    }

    /// Whether `p` lies in composite `c`'s closed polygon, exactly: on its plane bit for bit, and
    /// on the inner side of, or on, each of its edges. Only an edge running along a coordinate
    /// axis of the plane (its two corners share that coordinate bit for bit, as a facade's
    /// rectangle's do) may hold `p` on it, since comparing one coordinate is exact; across any
    /// other edge `p` must lie `margin` inside. So a point this accepts is a point of the panels
    /// (a boundary edge is a union of the panels' own edges, [`convex_outline`]): a receiver's
    /// corner lying on a facade that meets its plane at an inner corner.
    pub(super) fn holds(&self, c: u32, p: DVec3, margin: f64) -> bool {
        let corners = self.corners(c);
        let Some(axis) = (0..3).find(|&a| corners.iter().all(|q| q[a].to_bits() == corners[0][a].to_bits())) else { return false };
        if corners.len() < 3 || p[axis].to_bits() != corners[0][axis].to_bits() {
            return false;
        }
        let q: Vec<DVec2> = corners.iter().map(|c| flat(*c, axis as u8)).collect();
        let at = flat(p, axis as u8);
        let n = q.len();
        // Twice the polygon's signed area: which side of each edge is inside.
        let turn = (0..n).map(|k| q[k].perp_dot(q[(k + 1) % n])).sum::<f64>().signum();
        (0..n).all(|k| {
            let (a, b) = (q[k], q[(k + 1) % n]);
            if a.x.to_bits() == b.x.to_bits() {
                // Inside lies on the side of x = a.x that the edge's direction turns towards.
                turn * (b.y - a.y).signum() * (a.x - at.x) >= 0.0
            } else if a.y.to_bits() == b.y.to_bits() {
                turn * (b.x - a.x).signum() * (at.y - a.y) >= 0.0
            } else {
                turn * (b - a).perp_dot(at - a) >= margin * (b - a).length()
            }
        })
    }
}

/// An axis-aligned plane a triangle lies in exactly, with the side its front faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Plane {
    /// The axis the plane is normal to (0, 1, 2).
    axis: u8,
    /// Whether the triangle winds counter-clockwise in [`flat`]'s coordinates.
    positive: bool,
    /// The plane's coordinate along `axis`, bit for bit.
    at: u64,
}

impl Plane {
    /// The plane of `t` where its three corners share a coordinate bit for bit and it has area
    /// in the other two.
    fn of(t: &[DVec3; 3]) -> Option<Self> {
        (0..3).find_map(|axis| {
            let at = t[0][axis].to_bits();
            if t[1][axis].to_bits() != at || t[2][axis].to_bits() != at {
                return None;
            }
            let area = twice_area(t.map(|p| flat(p, axis as u8)));
            (area != 0.0 && area.is_finite()).then_some(Plane { axis: axis as u8, positive: area > 0.0, at })
        })
    }
}

/// A point's two coordinates other than `axis`, in cyclic order (so a triangle facing +axis
/// winds counter-clockwise): an exact projection onto the plane.
fn flat(p: DVec3, axis: u8) -> DVec2 {
    match axis {
        0 => DVec2::new(p.y, p.z),
        1 => DVec2::new(p.z, p.x),
        _ => DVec2::new(p.x, p.y),
    }
}

fn twice_area([a, b, c]: [DVec2; 3]) -> f64 {
    (b - a).perp_dot(c - a)
}

fn key(p: DVec3) -> Key {
    p.to_array().map(f64::to_bits)
}

/// The triangles of `positions` grouped by shared corners (bit for bit), each group's positions
/// in ascending order.
fn connected(index: &ExactEngine, positions: impl Iterator<Item = u32>) -> Vec<Vec<u32>> {
    let positions: Vec<u32> = positions.collect();
    let mut parent: Vec<usize> = (0..positions.len()).collect();
    let mut first: HashMap<Key, usize> = HashMap::new();
    for (i, &p) in positions.iter().enumerate() {
        for corner in index.triangles[p as usize] {
            let other = *first.entry(key(corner)).or_insert(i);
            let (a, b) = (root(&mut parent, other), root(&mut parent, i));
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut groups: HashMap<usize, Vec<u32>> = HashMap::new();
    for (i, &p) in positions.iter().enumerate() {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(p);
    }
    let mut out: Vec<Vec<u32>> = groups.into_values().collect();
    out.sort_unstable();
    out
}

fn root(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Whether every triangle of `component` belongs to one convex object (which casts as one).
fn one_convex_object(index: &ExactEngine, component: &[u32]) -> bool {
    let first = index.objects.of(component[0] as usize);
    first.is_some() && component.iter().all(|&p| index.objects.of(p as usize) == first)
}

/// Components with more triangles than this are not combined: finding the corners that lie on
/// each edge is quadratic in the worst case (a tiled ground).
const MAX_PANEL_TRIANGLES: usize = 20_000;

/// The corners of the convex polygon that `component`'s triangles (all in `plane`, wound one
/// way) tile exactly, in order, collinear corners dropped; None where they do not (see the
/// module doc).
fn convex_outline(index: &ExactEngine, plane: Plane, component: &[u32]) -> Option<Vec<DVec3>> {
    if component.len() > MAX_PANEL_TRIANGLES {
        return None;
    }
    let mut points: HashMap<Key, DVec3> = HashMap::new();
    for &p in component {
        points.extend(index.triangles[p as usize].map(|c| (key(c), c)));
    }
    let on_edges = CornersOnEdges::new(points.values().copied(), plane.axis);
    // The triangles' boundaries summed as a chain of pieces between corners: per piece (its
    // ends in key order) the net number of times it is run from the first end to the second.
    let mut chain: HashMap<(Key, Key), i32> = HashMap::with_capacity(3 * component.len());
    for &p in component {
        let t = index.triangles[p as usize];
        for k in 0..3 {
            let run = on_edges.pieces(t[k], t[(k + 1) % 3]);
            for w in run.windows(2) {
                let (a, b) = (key(w[0]), key(w[1]));
                let (piece, step) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
                *chain.entry(piece).or_insert(0) += step;
            }
        }
    }
    // What does not cancel is the boundary: each piece run once, one leaving each corner.
    let mut next: HashMap<Key, Key> = HashMap::new();
    for (&(a, b), &net) in &chain {
        let (from, to) = match net {
            0 => continue,
            1 => (a, b),
            -1 => (b, a),
            _ => return None,
        };
        if next.insert(from, to).is_some() {
            return None;
        }
    }
    let &start = next.keys().min()?;
    let mut lp = vec![start];
    let mut at = *next.get(&start)?;
    while at != start {
        if lp.len() > next.len() {
            return None;
        }
        lp.push(at);
        at = *next.get(&at)?;
    }
    if lp.len() != next.len() {
        // More than one loop: a hole, or pieces touching at a corner.
        return None;
    }
    let corners: Vec<DVec3> = lp.iter().map(|k| points[k]).collect();
    turns_once_convex(&corners, plane).then(|| without_collinear(&corners, plane))
}

/// A component's corners, to find those lying on an edge (a T-junction: a panel's corner on
/// its neighbour's edge), sorted along the plane's first coordinate.
struct CornersOnEdges {
    axis: u8,
    sorted: Vec<(DVec2, DVec3)>,
}

impl CornersOnEdges {
    fn new(points: impl Iterator<Item = DVec3>, axis: u8) -> Self {
        let mut sorted: Vec<(DVec2, DVec3)> = points.map(|p| (flat(p, axis), p)).collect();
        sorted.sort_unstable_by(|a, b| a.0.x.total_cmp(&b.0.x).then(a.0.y.total_cmp(&b.0.y)));
        Self { axis, sorted }
    }

    /// The edge from `a` to `b` cut at every corner that lies on it (exactly on its line, as
    /// `f64` tells, strictly between its ends), in order from `a`.
    fn pieces(&self, a: DVec3, b: DVec3) -> Vec<DVec3> {
        let (qa, qb) = (flat(a, self.axis), flat(b, self.axis));
        let (lo, hi) = (qa.x.min(qb.x), qa.x.max(qb.x));
        let first = self.sorted.partition_point(|(q, _)| q.x < lo);
        let mut between: Vec<(f64, DVec3)> = self.sorted[first..]
            .iter()
            .take_while(|(q, _)| q.x <= hi)
            .filter(|(q, _)| (qb - qa).perp_dot(*q - qa) == 0.0)
            .map(|(q, p)| ((*q - qa).dot(qb - qa), *p))
            .filter(|(t, _)| *t > 0.0 && *t < (qb - qa).length_squared())
            .collect();
        between.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        [a].into_iter().chain(between.into_iter().map(|(_, p)| p)).chain([b]).collect()
    }
}

/// Whether the closed loop `corners` turns only one way (counter-clockwise for a front facing
/// `plane`'s positive side, as its triangles wind), never back along itself, and once round.
fn turns_once_convex(corners: &[DVec3], plane: Plane) -> bool {
    let n = corners.len();
    if n < 3 {
        return false;
    }
    let sign = if plane.positive { 1.0 } else { -1.0 };
    let q: Vec<DVec2> = corners.iter().map(|p| flat(*p, plane.axis)).collect();
    let mut turned = 0.0;
    for k in 0..n {
        let (e0, e1) = (q[(k + 1) % n] - q[k], q[(k + 2) % n] - q[(k + 1) % n]);
        let (cross, dot) = (sign * e0.perp_dot(e1), e0.dot(e1));
        if cross < 0.0 || (cross == 0.0 && dot <= 0.0) || !cross.is_finite() {
            return false;
        }
        turned += cross.atan2(dot);
    }
    // Each turn lies in [0, π), so the total is a whole number of turns; one is convex.
    (turned - std::f64::consts::TAU).abs() < 1.0
}

/// The loop's corners without those where it runs straight on.
fn without_collinear(corners: &[DVec3], plane: Plane) -> Vec<DVec3> {
    let n = corners.len();
    let q: Vec<DVec2> = corners.iter().map(|p| flat(*p, plane.axis)).collect();
    (0..n).filter(|&k| (q[k] - q[(k + n - 1) % n]).perp_dot(q[(k + 1) % n] - q[k]) != 0.0).map(|k| corners[k]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SceneBuilder, SourceMesh};

    /// A vertical panel at y = `y` facing −y, x in [x0, x1], z in [z0, z1].
    fn panel(x0: f32, x1: f32, z0: f32, z1: f32, y: f32) -> SourceMesh {
        SourceMesh { positions: vec![[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], indices: vec![0, 1, 2, 0, 2, 3] }
    }

    /// How many composites the panels form, each panel added as a receiver: a receiver keeps its
    /// own mesh, so each panel is its own convex object, as nyt-blocks' walls and windows are.
    /// (Added as plain casters, the builder bakes them into one mesh, where panels sharing
    /// corners are one object, a convex one where they tile a rectangle: no composite needed.)
    fn composites(panels: &[SourceMesh]) -> usize {
        let mut b = SceneBuilder::new();
        for (k, m) in panels.iter().enumerate() {
            b.add_object("test", &format!("P{k}"), m.clone(), true);
        }
        let index = ExactEngine::new(&b.build().unwrap());
        let objects: std::collections::BTreeSet<Option<u32>> = (0..index.triangles.len()).map(|p| index.objects.of(p)).collect();
        assert_eq!(objects.len(), panels.len(), "each panel must be its own object, or the composite rule is not exercised");
        Composites::new(&index).len()
    }

    /// Four panels tiling a rectangle combine, and so do three meeting at a T-junction (two
    /// corners on the third's edge, as a wall strip under a window and its jambs); one with a
    /// 1 mm gap, one with a corner 1 mm off its neighbour's edge, an L of three and two facing
    /// opposite ways do not.
    #[test]
    fn only_panels_tiling_a_convex_polygon_without_a_gap_combine() {
        let tiled = [
            panel(0.0, 2.0, 0.0, 3.0, 0.0),
            panel(2.0, 5.0, 0.0, 3.0, 0.0),
            panel(0.0, 2.0, 3.0, 4.0, 0.0),
            panel(2.0, 5.0, 3.0, 4.0, 0.0),
        ];
        assert_eq!(composites(&tiled), 1);
        let gap = [panel(0.0, 2.0, 0.0, 3.0, 0.0), panel(2.001, 5.0, 0.0, 3.0, 0.0)];
        assert_eq!(composites(&gap), 0);
        let t_junction = [panel(0.0, 2.0, 0.0, 3.0, 0.0), panel(0.0, 1.0, 3.0, 4.0, 0.0), panel(1.0, 2.0, 3.0, 4.0, 0.0)];
        assert_eq!(composites(&t_junction), 1);
        let off_edge = [panel(0.0, 2.0, 0.0, 3.0, 0.0), panel(0.0, 1.0, 3.0, 4.0, 0.0), panel(1.0, 2.0, 3.001, 4.0, 0.0)];
        assert_eq!(composites(&off_edge), 0);
        let l_shape = [panel(0.0, 2.0, 0.0, 3.0, 0.0), panel(2.0, 5.0, 0.0, 3.0, 0.0), panel(0.0, 2.0, 3.0, 4.0, 0.0)];
        assert_eq!(composites(&l_shape), 0);
        let mut back = panel(2.0, 5.0, 0.0, 3.0, 0.0);
        back.indices = vec![0, 2, 1, 0, 3, 2];
        assert_eq!(composites(&[panel(0.0, 2.0, 0.0, 3.0, 0.0), back]), 0);
    }
}
