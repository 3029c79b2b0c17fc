//! Objects for the fast exact engine: which triangles of a mesh form one convex solid or one flat
//! convex polygon, so their shadows can be merged into one silhouette before the union.
//!
//! Owns the grouping and the convexity test. An *object* is a connected group of a mesh's
//! triangles (sharing vertex positions, bit for bit) that also share their surface id and veil,
//! so an object never mixes a receiver with other geometry, nor leaves of different ranks. An
//! object is *convex* when it is
//! - a closed convex polyhedron: every edge is used by exactly two of its triangles and every
//!   triangle's plane has all the object's vertices on one side (boxes, slats); or
//! - a convex polyhedron with open *caps*: the same, except that the edges used once form closed
//!   loops, each a convex polygon in a plane with all the object's vertices on one side (an
//!   extruded rod or tube exported without its ends, a box without its bottom); or
//! - a flat convex polygon: all vertices in one plane, no edge used more than twice, and its
//!   triangles' areas add up to the area of their convex hull (quads, leaves).
//!
//! The shadow of a closed convex object's part in front of a plane is the convex hull of its
//! clipped vertices' projections, exactly the union of its triangles' shadows: a sun ray through
//! the solid crosses its surface, and at most one of those crossings lies on the cutting plane.
//! With caps the surface and the caps together bound the solid, and a ray through it that meets
//! no triangle enters through one cap and leaves through another: so the hull is still the
//! shadow in every view where no two caps' projections overlap and no part of the object lies
//! behind the plane (whose cut would be one more opening). The engine checks that per view
//! (`ExactEngine::caps_overlap`) and otherwise casts the object's triangles one by one.
//! Larger objects (above [`MAX_CONVEX_TRIANGLES`]) take a linear test instead
//! ([`large_convexity`]): corners are one only when equal bit for bit, and the triangles must
//! lie in at most [`MAX_LARGE_FACES`] planes (a panelled facade, a block of panelled walls and
//! its roof); others stay per-triangle.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

/// Objects with more triangles than this are not tested for convexity (the test is quadratic).
pub(super) const MAX_CONVEX_TRIANGLES: usize = 64;
/// Objects with more triangles than this are not tested at all.
const MAX_LARGE_TRIANGLES: usize = 1 << 16;
/// A large object is convex only if its triangles lie in at most this many planes.
const MAX_LARGE_FACES: usize = 64;
/// Two triangles of a large object share a plane when their unit normals' dot product is
/// above 1 minus this (and their offsets agree within the tolerance).
const SAME_PLANE_COS: f64 = 1e-9;
/// Relative tolerance (of the object's size) of the convexity and flatness tests.
const CONVEX_TOLERANCE: f64 = 1e-9;
/// Tolerance of the same tests relative to the object's largest coordinate: positions are `f32`,
/// and a box whose faces were written each with its own corners (`lo + x + y` on one face,
/// `lo + y + x − …` on another) has corners that differ in the last bits. Within this many
/// `f32` roundings two corners are one, and a face may bend that much and still count as flat:
/// the hull's shadow then differs from the triangles' by slivers far thinner than the model's
/// own precision.
const F32_ROUNDINGS: f64 = 16.0 * f32::EPSILON as f64;
/// Relative difference allowed between a flat object's area and its hull's.
const FLAT_AREA_TOLERANCE: f64 = 1e-6;

/// A mesh's triangles grouped into objects.
#[derive(Debug, Default)]
pub(super) struct MeshObjects {
    /// Per triangle of the mesh: its object.
    pub object_of: Vec<u32>,
    /// Per object: whether it is convex (see the module doc).
    pub convex: Vec<bool>,
    /// Per object: its triangles (indices into the mesh's triangle list), flattened.
    pub triangles: Vec<u32>,
    /// Per object: its range in `triangles`.
    pub ranges: Vec<std::ops::Range<u32>>,
    /// Per object: its caps, a range of `caps` (empty unless convex with open caps).
    pub cap_ranges: Vec<std::ops::Range<u32>>,
    /// Per cap: its corners in order, a range of `cap_corners`.
    pub caps: Vec<std::ops::Range<u32>>,
    /// A cap's corners: the mesh triangle holding one and which of its corners (0–2).
    pub cap_corners: Vec<(u32, u8)>,
}

/// How an object's triangles bound a convex set, if they do (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Convexity {
    /// Neither a convex polyhedron, with or without caps, nor a flat convex polygon.
    No,
    /// A closed convex polyhedron or a flat convex polygon.
    Closed,
    /// A convex polyhedron with open caps: per cap its corners in order, each an index into the
    /// object's corners taken triangle by triangle (`3 · triangle + corner`).
    Caps(Vec<Vec<usize>>),
}

/// Groups `triangles` (mesh coordinates, with a key per triangle that objects must share: surface
/// id and veil) into objects and tests each for convexity.
pub(super) fn group(triangles: &[[[f32; 3]; 3]], keys: &[u64]) -> MeshObjects {
    let n = triangles.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    // First triangle seen at each (vertex position, key): later ones join its object.
    let mut first: HashMap<([u32; 3], u64), u32> = HashMap::with_capacity(n * 2);
    for (t, tri) in triangles.iter().enumerate() {
        for p in tri {
            let bits = p.map(f32::to_bits);
            let other = *first.entry((bits, keys[t])).or_insert(t as u32);
            union(&mut parent, other, t as u32);
        }
    }
    let mut object_of = vec![0u32; n];
    let mut index_of_root: HashMap<u32, u32> = HashMap::new();
    let mut members: Vec<Vec<u32>> = Vec::new();
    for t in 0..n as u32 {
        let root = find(&mut parent, t);
        let next = members.len() as u32;
        let o = *index_of_root.entry(root).or_insert(next);
        if o == next {
            members.push(Vec::new());
        }
        members[o as usize].push(t);
        object_of[t as usize] = o;
    }
    let mut out = MeshObjects { object_of, ..Default::default() };
    for m in &members {
        let tris: Vec<[DVec3; 3]> = m.iter().map(|&t| triangles[t as usize].map(|p| DVec3::from_array(p.map(f64::from)))).collect();
        let convexity = match tris.len() {
            n if n <= MAX_CONVEX_TRIANGLES => convexity(&tris),
            n if n <= MAX_LARGE_TRIANGLES => large_convexity(&tris),
            _ => Convexity::No,
        };
        out.convex.push(convexity != Convexity::No);
        let first_cap = out.caps.len() as u32;
        if let Convexity::Caps(caps) = convexity {
            for cap in caps {
                let start = out.cap_corners.len() as u32;
                out.cap_corners.extend(cap.iter().map(|&c| (m[c / 3], (c % 3) as u8)));
                out.caps.push(start..out.cap_corners.len() as u32);
            }
        }
        out.cap_ranges.push(first_cap..out.caps.len() as u32);
        let start = out.triangles.len() as u32;
        out.triangles.extend(m);
        out.ranges.push(start..out.triangles.len() as u32);
    }
    out
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[rb.max(ra) as usize] = rb.min(ra);
    }
}

/// Whether the triangles form a convex polyhedron (closed or with caps) or a flat convex polygon.
#[cfg(test)]
pub(super) fn is_convex(tris: &[[DVec3; 3]]) -> bool {
    convexity(tris) != Convexity::No
}

/// How the triangles bound a convex set (see the module doc).
pub(super) fn convexity(tris: &[[DVec3; 3]]) -> Convexity {
    let points: Vec<DVec3> = tris.iter().flatten().copied().collect();
    let Some(size) = extent(&points) else { return Convexity::No };
    let magnitude = points.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tol = (CONVEX_TOLERANCE * size).max(F32_ROUNDINGS * magnitude).max(f64::MIN_POSITIVE);
    // Corners within `tol` of each other are one (welded to the first seen); `first` holds the
    // index in `points` of each welded corner's first point.
    let mut corners: Vec<DVec3> = Vec::new();
    let mut first: Vec<usize> = Vec::new();
    let mut welded = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let c = corners.iter().position(|c| (*c - p).abs().max_element() <= tol).unwrap_or_else(|| {
            corners.push(p);
            first.push(i);
            corners.len() - 1
        });
        welded.push(c);
    }
    let Some(uses) = edge_uses(&welded) else { return Convexity::No };
    let mut flat = true;
    for t in tris {
        let normal = (t[1] - t[0]).cross(t[2] - t[0]);
        let length = normal.length();
        if length <= tol * size {
            return Convexity::No;
        }
        let Some(in_plane) = one_side(normal / length, t[0], &points, tol) else { return Convexity::No };
        flat &= in_plane;
    }
    closed_or_caps(tris, &points, flat, &uses, (&corners, &first), tol)
}

/// Edges by their welded corners, undirected: how many triangles use each; None where a
/// triangle has two equal corners or an edge is used more than twice.
fn edge_uses(welded: &[usize]) -> Option<HashMap<(usize, usize), u32>> {
    let mut uses: HashMap<(usize, usize), u32> = HashMap::new();
    for c in welded.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            if a == b {
                return None;
            }
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    uses.values().all(|&u| u <= 2).then_some(uses)
}

/// The end of both convexity tests, once every triangle's plane has the object on one side
/// (`flat` when on none): a flat convex polygon, a closed polyhedron, or one with convex caps.
/// `corners` are the welded corners and, for each, the index in `points` of its first point.
fn closed_or_caps(
    tris: &[[DVec3; 3]],
    points: &[DVec3],
    flat: bool,
    uses: &HashMap<(usize, usize), u32>,
    (corners, first): (&[DVec3], &[usize]),
    tol: f64,
) -> Convexity {
    if flat {
        return if flat_polygon_is_covered(tris, points) { Convexity::Closed } else { Convexity::No };
    }
    let mut open: Vec<(usize, usize)> = uses.iter().filter(|(_, u)| **u == 1).map(|(e, _)| *e).collect();
    // In a fixed order, so every run finds the same loops.
    open.sort_unstable();
    if open.is_empty() {
        return Convexity::Closed;
    }
    let Some(loops) = edge_loops(&open, corners.len()) else { return Convexity::No };
    let caps_are_faces = loops.iter().all(|l| {
        let loop_points: Vec<DVec3> = l.iter().map(|&c| corners[c]).collect();
        is_convex_face(&loop_points, points, tol)
    });
    if !caps_are_faces {
        return Convexity::No;
    }
    Convexity::Caps(loops.iter().map(|l| l.iter().map(|&c| first[c]).collect()).collect())
}

/// [`convexity`] in linear time, for objects of many triangles: corners are one only when equal
/// bit for bit (as the grouping joins them), and the triangles' planes are merged into faces, at
/// most [`MAX_LARGE_FACES`], so each corner is tested against each face rather than each
/// triangle. A panelled block without a floor is convex with one cap; anything else that is
/// convex but rounds its shared corners apart is refused (it stays per-triangle).
pub(super) fn large_convexity(tris: &[[DVec3; 3]]) -> Convexity {
    let points: Vec<DVec3> = tris.iter().flatten().copied().collect();
    let Some(size) = extent(&points) else { return Convexity::No };
    let magnitude = points.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tol = (CONVEX_TOLERANCE * size).max(F32_ROUNDINGS * magnitude).max(f64::MIN_POSITIVE);
    let mut index: HashMap<[u64; 3], usize> = HashMap::with_capacity(points.len());
    let (mut corners, mut first) = (Vec::new(), Vec::new());
    let welded: Vec<usize> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *index.entry(p.to_array().map(f64::to_bits)).or_insert_with(|| {
                corners.push(*p);
                first.push(i);
                corners.len() - 1
            })
        })
        .collect();
    let Some(mut uses) = edge_uses(&welded) else { return Convexity::No };
    if !close_t_junctions(&mut uses, &corners, tol) {
        return Convexity::No;
    }
    let mut faces: Vec<(DVec3, DVec3)> = Vec::new();
    for t in tris {
        let normal = (t[1] - t[0]).cross(t[2] - t[0]);
        let length = normal.length();
        if length <= tol * size {
            return Convexity::No;
        }
        let n = normal / length;
        if !faces.iter().any(|(m, q)| m.dot(n) > 1.0 - SAME_PLANE_COS && m.dot(t[0] - *q).abs() <= tol) {
            if faces.len() == MAX_LARGE_FACES {
                return Convexity::No;
            }
            faces.push((n, t[0]));
        }
    }
    let mut flat = true;
    for (n, q) in &faces {
        let Some(in_plane) = one_side(*n, *q, &corners, tol) else { return Convexity::No };
        flat &= in_plane;
    }
    closed_or_caps(tris, &points, flat, &uses, (&corners, &first), tol)
}

/// Whether `points` lie on one side of the plane through `q` with unit normal `n` (within
/// `tol`): None if on both, else whether all lie in it.
fn one_side(n: DVec3, q: DVec3, points: &[DVec3], tol: f64) -> Option<bool> {
    let (mut below, mut above) = (false, false);
    for p in points {
        let h = n.dot(*p - q);
        below |= h < -tol;
        above |= h > tol;
    }
    (!(below && above)).then_some(!below && !above)
}

/// Splits every edge used once at the corners of other once-used edges lying on it, so that a
/// long edge meeting a row of short ones (a roof quad over a wall of panels: a T-junction seam,
/// not an opening) is closed piece by piece: each piece is then used twice. False where a
/// piece ends up used more than twice (overlapping triangles).
fn close_t_junctions(uses: &mut HashMap<(usize, usize), u32>, corners: &[DVec3], tol: f64) -> bool {
    let open: Vec<(usize, usize)> = uses.iter().filter(|(_, u)| **u == 1).map(|(e, _)| *e).collect();
    let mut on_open: Vec<usize> = open.iter().flat_map(|&(a, b)| [a, b]).collect();
    on_open.sort_unstable();
    on_open.dedup();
    for (a, b) in open {
        let (pa, pb) = (corners[a], corners[b]);
        let Some(along) = (pb - pa).try_normalize() else { continue };
        let length = (pb - pa).length();
        let mut inner: Vec<(f64, usize)> = on_open
            .iter()
            .filter_map(|&c| {
                let t = (corners[c] - pa).dot(along);
                let off = (corners[c] - pa).reject_from_normalized(along).length();
                (t > tol && t < length - tol && off <= tol).then_some((t, c))
            })
            .collect();
        if inner.is_empty() {
            continue;
        }
        inner.sort_by(|x, y| x.0.total_cmp(&y.0));
        uses.remove(&(a, b));
        let chain: Vec<usize> = std::iter::once(a).chain(inner.into_iter().map(|(_, c)| c)).chain(std::iter::once(b)).collect();
        for w in chain.windows(2) {
            *uses.entry((w[0].min(w[1]), w[0].max(w[1]))).or_insert(0) += 1;
        }
    }
    uses.values().all(|&u| u <= 2)
}

/// The closed loops formed by `edges` (undirected, between welded corners below `corners`),
/// each in order from its lowest corner; `None` unless every corner on them has exactly two
/// (loops touching at a corner are refused).
fn edge_loops(edges: &[(usize, usize)], corners: usize) -> Option<Vec<Vec<usize>>> {
    const NONE: usize = usize::MAX;
    let mut next = vec![[NONE; 2]; corners];
    for &(a, b) in edges {
        for (from, to) in [(a, b), (b, a)] {
            let slot = next[from].iter_mut().find(|n| **n == NONE)?;
            *slot = to;
        }
    }
    let mut seen = vec![false; corners];
    let mut loops = Vec::new();
    for start in 0..corners {
        if seen[start] || next[start][0] == NONE {
            continue;
        }
        let (mut before, mut at) = (NONE, start);
        let mut cycle = Vec::new();
        loop {
            let n = next[at];
            if n[1] == NONE || seen[at] {
                return None;
            }
            seen[at] = true;
            cycle.push(at);
            let step = if n[0] != before { n[0] } else { n[1] };
            (before, at) = (at, step);
            if at == start {
                break;
            }
        }
        loops.push(cycle);
    }
    Some(loops)
}

/// Whether the loop `cap` (in order) is a convex polygon in a plane with every point of `all` on
/// one side: then it is a face of their convex hull.
fn is_convex_face(cap: &[DVec3], all: &[DVec3], tol: f64) -> bool {
    if cap.len() < 3 {
        return false;
    }
    // Newell's normal: its length is twice the loop's area.
    let newell = (0..cap.len()).fold(DVec3::ZERO, |n, i| n + cap[i].cross(cap[(i + 1) % cap.len()]));
    let length = newell.length();
    if length.is_nan() || length <= 0.0 {
        return false;
    }
    let normal = newell / length;
    let (mut below, mut above) = (false, false);
    for p in all {
        let h = normal.dot(*p - cap[0]);
        if h.abs() <= tol {
            continue;
        }
        below |= h < 0.0;
        above |= h > 0.0;
    }
    let in_plane = cap.iter().all(|p| normal.dot(*p - cap[0]).abs() <= tol);
    if !in_plane || (below && above) {
        return false;
    }
    // Convex: every turn the same way round the normal.
    (0..cap.len()).all(|i| {
        let (a, b, c) = (cap[i], cap[(i + 1) % cap.len()], cap[(i + 2) % cap.len()]);
        (b - a).cross(c - b).dot(normal) >= -tol * (b - a).length().max((c - b).length())
    })
}

/// A flat object is its convex hull when its triangles' areas add up to the hull's area (and no
/// edge is used more than twice, checked by the caller, so they do not overlap).
fn flat_polygon_is_covered(tris: &[[DVec3; 3]], points: &[DVec3]) -> bool {
    let t = tris[0];
    let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    let flat: Vec<DVec2> = points.iter().map(|p| DVec2::new((*p - t[0]).dot(e1), (*p - t[0]).dot(e2))).collect();
    let mut hull = Vec::new();
    convex_hull(&mut flat.clone(), &mut hull);
    let hull_area = polygon_area(&hull);
    let sum: f64 = tris.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()).sum();
    hull_area > 0.0 && (sum - hull_area).abs() <= FLAT_AREA_TOLERANCE * hull_area
}

fn extent(points: &[DVec3]) -> Option<f64> {
    let (lo, hi) = points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).length();
    size.is_finite().then_some(size)
}

/// Sorts three values in place by `less` (a strict total order; equal values are the same value).
pub(super) fn sort3<T>(a: &mut T, b: &mut T, c: &mut T, less: impl Fn(&T, &T) -> bool) {
    if less(b, a) {
        std::mem::swap(a, b);
    }
    if less(c, b) {
        std::mem::swap(b, c);
    }
    if less(b, a) {
        std::mem::swap(a, b);
    }
}

/// Signed area of a polygon (positive counter-clockwise).
pub(super) fn polygon_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    0.5 * (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>()
}

/// Andrew's monotone chain: the hull of `points` (sorted in place) into `hull`, counter-clockwise,
/// without collinear points or a repeated first point.
pub(super) fn convex_hull(points: &mut [DVec2], hull: &mut Vec<DVec2>) {
    hull.clear();
    let order = |a: &DVec2, b: &DVec2| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y));
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    // A leaf's triangle, most of what a canopy casts: sorted by three swaps, and its hull read
    // off the two turns the chain below would test (the same points in the same order).
    if let [a, b, c] = points {
        sort3(a, b, c, |x, y| order(x, y).is_lt());
        let (turn, back) = (cross(*a, *b, *c), cross(*c, *b, *a));
        if turn > 0.0 && back <= 0.0 {
            hull.extend_from_slice(&[*a, *b, *c]);
            return;
        }
        if turn < 0.0 && back > 0.0 {
            hull.extend_from_slice(&[*a, *c, *b]);
            return;
        }
    }
    points.sort_unstable_by(order);
    if points.len() < 3 {
        hull.extend_from_slice(points);
        return;
    }
    for &q in points.iter() {
        while hull.len() >= 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
            hull.pop();
        }
        hull.push(q);
    }
    let lower = hull.len() + 1;
    for &q in points.iter().rev().skip(1) {
        while hull.len() >= lower && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0 {
            hull.pop();
        }
        hull.push(q);
    }
    hull.pop();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A w × d × h block of panels (n along each side, one per metre of height), with a roof of
    /// one quad and no floor, as the benchmark's city blocks are built; `notch` pushes one
    /// panel of the south face 1 m in, which makes it concave.
    fn panelled_block(w: f64, d: f64, h: usize, n: usize, notch: bool) -> Vec<[DVec3; 3]> {
        let mut out = Vec::new();
        let mut quad = |a: DVec3, b: DVec3, c: DVec3, e: DVec3| out.extend([[a, b, c], [a, c, e]]);
        let walls = [
            (DVec3::ZERO, DVec3::X * w),
            (DVec3::X * w, DVec3::Y * d),
            (DVec3::new(w, d, 0.0), -DVec3::X * w),
            (DVec3::Y * d, -DVec3::Y * d),
        ];
        for (k, (o, side)) in walls.iter().enumerate() {
            for f in 0..h {
                for c in 0..n {
                    let (s0, s1) = (c as f64 / n as f64, (c + 1) as f64 / n as f64);
                    let (z0, z1) = (DVec3::Z * f as f64, DVec3::Z * (f + 1) as f64);
                    let dent = if notch && k == 0 && c == 1 && f == 1 { DVec3::Y } else { DVec3::ZERO };
                    quad(
                        *o + *side * s0 + z0 + dent,
                        *o + *side * s1 + z0 + dent,
                        *o + *side * s1 + z1 + dent,
                        *o + *side * s0 + z1 + dent,
                    );
                }
            }
        }
        let top = DVec3::Z * h as f64;
        quad(top, top + DVec3::Y * d, top + DVec3::new(w, d, 0.0), top + DVec3::X * w);
        out
    }

    /// Large objects take the linear test: a panelled block without a floor is convex with one
    /// cap (its floor's outline), a panelled facade is flat and convex, and a block with one
    /// panel pushed in is neither; the small test agrees where both apply.
    #[test]
    fn panelled_blocks_are_convex_with_a_cap_and_a_dented_one_is_not() {
        let block = panelled_block(8.0, 4.0, 6, 4, false);
        assert!(block.len() > MAX_CONVEX_TRIANGLES);
        assert!(matches!(large_convexity(&block), Convexity::Caps(ref caps) if caps.len() == 1));
        assert_eq!(large_convexity(&panelled_block(8.0, 4.0, 6, 4, true)), Convexity::No);
        let facade: Vec<[DVec3; 3]> = block[..2 * 6 * 4].to_vec();
        assert_eq!(large_convexity(&facade), Convexity::Closed);
        let small = panelled_block(8.0, 4.0, 2, 2, false);
        assert!(small.len() <= MAX_CONVEX_TRIANGLES);
        // The small test refuses the roof's T-junctions; the large one closes them.
        assert_eq!(convexity(&small), Convexity::No);
        assert!(matches!(large_convexity(&small), Convexity::Caps(ref caps) if caps.len() == 1));
        assert_eq!(large_convexity(&cube()), Convexity::Closed);
    }

    fn cube() -> Vec<[DVec3; 3]> {
        let c = |i: usize| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let quads: [[usize; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect()
    }

    #[test]
    fn boxes_and_quads_are_convex_open_or_concave_shapes_are_not() {
        let cube = cube();
        assert!(is_convex(&cube));
        assert!(!is_convex(&cube[..6]), "three faces of a cube are open");
        assert!(is_convex(&cube[..2]), "one face, a flat square");
        // An L of three unit squares in one plane: flat, but its hull is larger than it.
        let sq = |x: f64, y: f64| {
            let p = |dx: f64, dy: f64| DVec3::new(x + dx, y + dy, 0.0);
            [[p(0., 0.), p(1., 0.), p(1., 1.)], [p(0., 0.), p(1., 1.), p(0., 1.)]]
        };
        let l: Vec<[DVec3; 3]> = [sq(0., 0.), sq(1., 0.), sq(0., 1.)].concat();
        assert!(!is_convex(&l));
        // Two cubes side by side sharing no vertex are two objects; glued into a 2×1 box with
        // the shared face left inside, edges are used more than twice.
        let shifted: Vec<[DVec3; 3]> = cube.iter().map(|t| t.map(|p| p + DVec3::X)).collect();
        assert!(!is_convex(&[cube.clone(), shifted].concat()));
    }

    #[test]
    fn a_box_whose_faces_round_their_corners_apart_is_still_convex() {
        // A slat written face by face in f32 (as the bench's generator does): corners reached
        // along different sums differ in their last bits, so no edge matches bit for bit.
        let (lo, size) = ([-0.1f32, -0.45, 0.0], [6.2f32, 0.25, 0.02]);
        let mut tris: Vec<[DVec3; 3]> = Vec::new();
        for (k, t) in cube().iter().enumerate() {
            tris.push(t.map(|p| {
                let q: [f32; 3] = std::array::from_fn(|i| {
                    let v = lo[i] + size[i] * p[i] as f32;
                    // Every other face nudges its corners by one f32 step.
                    if k % 4 < 2 { v } else { f32::from_bits(v.to_bits() + 1) }
                });
                DVec3::from_array(q.map(f64::from))
            }));
        }
        assert!(is_convex(&tris));
        // A real dent is still seen: one corner pushed 1 mm into the slat.
        let mut dented = tris.clone();
        for t in &mut dented {
            for p in t.iter_mut() {
                if p.z > 0.01 && p.x > 6.0 && p.y > -0.25 {
                    p.z -= 0.001;
                }
            }
        }
        assert!(!is_convex(&dented));
    }

    #[test]
    fn objects_are_connected_triangles_with_one_key() {
        let to_f32 = |t: &[DVec3; 3]| t.map(|p| p.as_vec3().to_array());
        let mut tris: Vec<[[f32; 3]; 3]> = cube().iter().map(to_f32).collect();
        tris.extend(cube().iter().map(|t| to_f32(&t.map(|p| p + DVec3::splat(5.0)))));
        let mut keys = vec![0u64; tris.len()];
        let objects = group(&tris, &keys);
        assert_eq!(objects.ranges.len(), 2);
        assert_eq!(objects.convex, vec![true, true]);
        // A different key on one face splits it off: the rest is a box open on one side (a cup,
        // convex with one cap), the face a flat square.
        keys[0] = 1;
        keys[1] = 1;
        let objects = group(&tris, &keys);
        assert_eq!(objects.ranges.len(), 3);
        assert_eq!(objects.convex, vec![true, true, true]);
        assert_eq!(objects.cap_ranges.iter().map(|r| r.len()).collect::<Vec<_>>(), vec![0, 1, 0], "the cup's cap");
        assert_eq!(objects.caps.len(), 1);
        assert_eq!(objects.cap_corners.len(), 4);
        // Two adjacent faces split off: the four left of the cube leave one loop that is not
        // flat, so they are not convex.
        keys[4] = 2;
        keys[5] = 2;
        let objects = group(&tris, &keys);
        assert_eq!(objects.convex.iter().filter(|c| **c).count(), 3, "two squares and the other cube");
    }

    #[test]
    fn tubes_and_cups_are_convex_with_caps_open_shells_are_not() {
        let cube = cube();
        // Faces 2 and 3 are y = 0 and y = 1: without them a square tube along y.
        let tube: Vec<[DVec3; 3]> = [&cube[..4], &cube[8..]].concat();
        let Convexity::Caps(caps) = convexity(&tube) else { panic!("a tube has two caps") };
        assert_eq!(caps.len(), 2);
        let points: Vec<DVec3> = tube.iter().flatten().copied().collect();
        let mut ends: Vec<f64> = caps
            .iter()
            .map(|cap| {
                assert_eq!(cap.len(), 4, "a square end");
                let y = points[cap[0]].y;
                assert!(cap.iter().all(|&c| points[c].y == y), "a cap's corners lie in its plane");
                y
            })
            .collect();
        ends.sort_by(f64::total_cmp);
        assert_eq!(ends, vec![0.0, 1.0]);
        // Without its top (face 1): a cup, one cap.
        let cup: Vec<[DVec3; 3]> = [&cube[..2], &cube[4..]].concat();
        assert!(matches!(convexity(&cup), Convexity::Caps(c) if c.len() == 1));
        assert_eq!(convexity(&cube), Convexity::Closed);
        // Three faces meeting at a corner leave one loop that is not flat.
        assert_eq!(convexity(&cube[..6]), Convexity::No);
        // A tube with one side dented inwards is not convex, caps or not.
        let mut dented = tube.clone();
        for t in &mut dented {
            for p in t.iter_mut() {
                if p.x == 1.0 && p.y == 1.0 && p.z == 1.0 {
                    p.x = 0.8;
                }
            }
        }
        assert_eq!(convexity(&dented), Convexity::No);
    }
}
