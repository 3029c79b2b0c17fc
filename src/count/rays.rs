//! Shadow rays from single points: a bounding volume hierarchy over every triangle of a scene,
//! walked once per ray and left at the first triangle that blocks it (any hit, not the closest).
//!
//! Why beside the exact engine's shadow polygons ([`super::exact`]): a window study asks a few
//! points about thousands of directions. The shadow path pays one walk of a receiver's whole sun
//! prism per direction, however few points lie on the receiver, and every caster in that prism
//! is projected; a ray pays only the nodes along one line, and a blocked ray stops at its first
//! blocker. The answer is the same for opaque casters: a point is lit when no caster triangle
//! lies on the open segment from it towards the sun (a point on a shadow's edge counts as lit in
//! both, an event of no area).
//!
//! - The receiver's own triangles never cast (as in the engine), and hits within
//!   [`PLANE_SLACK`] of the receiver's plane are ignored: coplanar neighbours (a wall's other
//!   parts) would otherwise shade their own wall through rounding.
//! - A leaf blocks when its (shifted) rank is below the leaf fraction, the engine's test.
//! - See-through casters are not answered here ([`RayCaster::new`] gives `None`): a convex
//!   see-through object must let `t` through once, not once per face a ray crosses, and the
//!   shadow path knows the objects. Callers fall back to it for such scenes.
//!
//! The tree: binned surface-area heuristic (16 bins, up to [`LEAF_TRIANGLES`] per leaf), f32
//! boxes rounded outwards so that no f64 triangle leaves its box, f64 triangles tested by
//! Möller–Trumbore.

use glam::{DVec3, Vec3};

use crate::scene::{NO_RECEIVER, Scene};

/// Most triangles in a leaf.
pub const LEAF_TRIANGLES: usize = 4;
/// Hits nearer than this to the receiver's plane (metres, along its normal) do not block.
pub const PLANE_SLACK: f64 = 1e-6;
/// Every box is padded by this times the scene's largest coordinate (after the offset), so the
/// f32 rounding of a ray's origin and of the slab products never loses a hit (points lie within
/// the scene's reach; a looser box only costs a test).
const BOX_SLACK: f32 = 8.0 * f32::EPSILON;
/// SAH bins per split.
const BINS: usize = 16;
/// Deepest walk (the tree is far shallower: splits always separate).
const STACK: usize = 96;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// A leaf's first triangle, or an inner node's first child (the second follows it).
    start: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

#[derive(Debug, Clone, Copy)]
struct Triangle {
    a: DVec3,
    ab: DVec3,
    ac: DVec3,
    /// The receiver it belongs to, or [`NO_RECEIVER`].
    owner: u32,
    /// Leaf rank (already shifted by its instance), negative for geometry that always casts.
    rank: f32,
}

/// The scene's triangles in a BVH, for [`Self::blocked`]. Build once per scene.
#[derive(Debug, Clone)]
pub struct RayCaster {
    nodes: Vec<Node>,
    triangles: Vec<Triangle>,
    /// Subtracted before the boxes' f32 arithmetic, so georeferenced scenes keep millimetres.
    offset: DVec3,
    /// Levels of the tree (a walk holds at most one pending node per level, plus one).
    depth: usize,
}

struct Item {
    lo: Vec3,
    hi: Vec3,
    centre: Vec3,
    index: u32,
}

impl RayCaster {
    /// Indexes every triangle of `scene`; `None` when the scene has see-through casters (see the
    /// module doc).
    pub fn new(scene: &Scene) -> Option<Self> {
        let mut source = Vec::new();
        for (t, id, veil) in scene.veiled_triangles() {
            if veil.transmittance > 0.0 {
                return None;
            }
            let ab = t[1] - t[0];
            let ac = t[2] - t[0];
            if ab.cross(ac).length_squared() == 0.0 {
                continue; // no area: blocks nothing
            }
            source.push(Triangle { a: t[0], ab, ac, owner: id.unwrap_or(NO_RECEIVER), rank: veil.rank });
        }
        let offset = scene.origin;
        let mut items: Vec<Item> = source
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let (a, b, c) = (t.a - offset, t.a + t.ab - offset, t.a + t.ac - offset);
                let lo = down(a.min(b).min(c));
                let hi = up(a.max(b).max(c));
                Item { lo, hi, centre: (lo + hi) * 0.5, index: i as u32 }
            })
            .collect();
        let mut nodes = vec![Node { lo: Vec3::ZERO, hi: Vec3::ZERO, start: 0, count: 0 }];
        // Each node's bounds come with it (the root's from one pass, a child's from its parent's
        // bins), so a split reads its items twice: once to bin them, once to part them.
        let mut todo = vec![(0usize, 0usize, items.len(), 1usize, Span::of(&items))];
        let mut depth = 1;
        while let Some((node, from, to, level, span)) = todo.pop() {
            depth = depth.max(level);
            nodes[node].lo = span.lo;
            nodes[node].hi = span.hi;
            match split(&mut items[from..to], &span) {
                Some((mid, left, right)) => {
                    let first = nodes.len();
                    nodes.push(nodes[node]);
                    nodes.push(nodes[node]);
                    nodes[node].start = first as u32;
                    nodes[node].count = 0;
                    todo.push((first, from, from + mid, level + 1, left));
                    todo.push((first + 1, from + mid, to, level + 1, right));
                }
                None => {
                    nodes[node].start = from as u32;
                    nodes[node].count = (to - from) as u32;
                }
            }
        }
        let reach = nodes[0].lo.abs().max(nodes[0].hi.abs()).max_element().max(1.0);
        let pad = Vec3::splat(reach * BOX_SLACK);
        for n in &mut nodes {
            n.lo -= pad;
            n.hi += pad;
        }
        let triangles = items.iter().map(|it| source[it.index as usize]).collect();
        Some(Self { nodes, triangles, offset, depth })
    }

    /// Triangles indexed.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Levels of the tree.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Whether a caster blocks the ray from `origin` (on receiver `receiver`'s plane, whose unit
    /// normal is `normal`) along unit `direction` at leaf fraction `leaves`. The caller has
    /// checked that `direction` is in front of the plane.
    pub fn blocked(&self, origin: DVec3, normal: DVec3, receiver: u32, direction: DVec3, leaves: f32) -> bool {
        if self.triangles.is_empty() {
            return false; // and the root is no box to walk
        }
        let t_min = PLANE_SLACK / normal.dot(direction).max(1e-12);
        let o = (origin - self.offset).as_vec3();
        let inv = Vec3::new(inverse(direction.x), inverse(direction.y), inverse(direction.z));
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !enters(node.lo, node.hi, o, inv) {
                continue;
            }
            if node.count > 0 {
                let range = node.start as usize..(node.start + node.count) as usize;
                for t in &self.triangles[range] {
                    if t.owner == receiver && receiver != NO_RECEIVER {
                        continue;
                    }
                    if t.rank >= 0.0 && t.rank >= leaves {
                        continue;
                    }
                    if hits(t, origin, direction, t_min) {
                        return true;
                    }
                }
            } else if top + 2 <= STACK {
                stack[top] = node.start;
                stack[top + 1] = node.start + 1;
                top += 2;
            }
        }
        false
    }
}

/// 1/x, with a huge finite value for 0 (so slab tests stay free of NaN).
fn inverse(x: f64) -> f32 {
    if x.abs() < 1e-30 { 1e30f32.copysign(x as f32) } else { (1.0 / x) as f32 }
}

/// Whether the ray from `o` (inverse direction `inv`) meets the box at some t ≥ 0 (the boxes are
/// padded at build, see [`BOX_SLACK`]).
fn enters(lo: Vec3, hi: Vec3, o: Vec3, inv: Vec3) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    near <= far * (1.0 + 8.0 * f32::EPSILON) && far >= 0.0
}

/// Möller–Trumbore: whether the ray meets the triangle's interior at t > `t_min`.
fn hits(t: &Triangle, origin: DVec3, direction: DVec3, t_min: f64) -> bool {
    let p = direction.cross(t.ac);
    let det = t.ab.dot(p);
    if det.abs() < 1e-300 {
        return false; // the ray runs in the triangle's plane: no area to block it
    }
    let inv = 1.0 / det;
    let s = origin - t.a;
    let u = s.dot(p) * inv;
    if u <= 0.0 || u >= 1.0 {
        return false;
    }
    let q = s.cross(t.ab);
    let v = direction.dot(q) * inv;
    if v <= 0.0 || u + v >= 1.0 {
        return false;
    }
    t.ac.dot(q) * inv > t_min
}

/// The f32 value at or below `x`, per axis.
fn down(x: DVec3) -> Vec3 {
    let f = x.as_vec3();
    Vec3::new(next_down(f.x, x.x), next_down(f.y, x.y), next_down(f.z, x.z))
}

/// The f32 value at or above `x`, per axis.
fn up(x: DVec3) -> Vec3 {
    -down(-x)
}

fn next_down(f: f32, x: f64) -> f32 {
    if f64::from(f) <= x { f } else { f.next_down() }
}

/// A set of items' bounds: their boxes' (`lo`..`hi`) and their centres' (`clo`..`chi`).
#[derive(Debug, Clone, Copy)]
struct Span {
    lo: Vec3,
    hi: Vec3,
    clo: Vec3,
    chi: Vec3,
}

impl Span {
    /// Nothing: the identity of [`Self::add`].
    const EMPTY: Self = Self { lo: Vec3::MAX, hi: Vec3::MIN, clo: Vec3::MAX, chi: Vec3::MIN };

    fn of(items: &[Item]) -> Self {
        items.iter().fold(Self::EMPTY, |s, it| s.add(it))
    }

    fn add(self, it: &Item) -> Self {
        Self { lo: self.lo.min(it.lo), hi: self.hi.max(it.hi), clo: self.clo.min(it.centre), chi: self.chi.max(it.centre) }
    }

    fn union(self, o: Self) -> Self {
        Self { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi), clo: self.clo.min(o.clo), chi: self.chi.max(o.chi) }
    }
}

fn area(lo: Vec3, hi: Vec3) -> f32 {
    let d = (hi - lo).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// Splits `items` (bounded by `span`) in place by the binned surface-area heuristic: the first
/// part's length and each part's bounds (min and max are exact, so a part's bounds gathered from
/// its bins are the ones its items would give), or `None` for a leaf.
fn split(items: &mut [Item], span: &Span) -> Option<(usize, Span, Span)> {
    if items.len() <= LEAF_TRIANGLES {
        return None;
    }
    let (clo, chi) = (span.clo, span.chi);
    let extent = chi - clo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    if extent[axis] <= 0.0 {
        return None; // every centre in one place: no split separates them
    }
    let scale = BINS as f32 / extent[axis];
    let bin = |it: &Item| (((it.centre[axis] - clo[axis]) * scale) as usize).min(BINS - 1);
    let mut counts = [0usize; BINS];
    let mut boxes = [Span::EMPTY; BINS];
    for it in items.iter() {
        let b = bin(it);
        counts[b] += 1;
        boxes[b] = boxes[b].add(it);
    }
    // Costs of splitting after bin k: left areas from the left, right ones from the right.
    let mut right = [0.0f32; BINS];
    let (mut acc, mut n) = (Span::EMPTY, 0usize);
    for k in (1..BINS).rev() {
        acc = acc.union(boxes[k]);
        n += counts[k];
        right[k] = area(acc.lo, acc.hi) * n as f32;
    }
    let (mut best, mut best_cost) = (0usize, f32::MAX);
    let (mut acc, mut n) = (Span::EMPTY, 0usize);
    for k in 0..BINS - 1 {
        acc = acc.union(boxes[k]);
        n += counts[k];
        let cost = area(acc.lo, acc.hi) * n as f32 + right[k + 1];
        if n > 0 && n < items.len() && cost < best_cost {
            best_cost = cost;
            best = k;
        }
    }
    if best_cost == f32::MAX {
        return None;
    }
    let mut mid = 0;
    for i in 0..items.len() {
        if bin(&items[i]) <= best {
            items.swap(i, mid);
            mid += 1;
        }
    }
    let left = boxes[..=best].iter().fold(Span::EMPTY, |a, &b| a.union(b));
    let right = boxes[best + 1..].iter().fold(Span::EMPTY, |a, &b| a.union(b));
    Some((mid, left, right))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SceneBuilder, SourceMesh};

    /// Many small squares hanging over a ground receiver; a ray is blocked exactly when a brute
    /// force test over every triangle finds a hit.
    #[test]
    fn the_tree_finds_what_a_brute_force_loop_finds() {
        let mut b = SceneBuilder::new();
        let ground = SourceMesh {
            positions: vec![[-20.0, -20.0, 0.0], [20.0, -20.0, 0.0], [20.0, 20.0, 0.0], [-20.0, 20.0, 0.0]],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        b.add_object("test", "GROUND", ground, true);
        let mut state = 12345u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 33) as f64 / (1u64 << 31) as f64) as f32
        };
        let mut positions = Vec::new();
        let mut indices = Vec::new();
        for _ in 0..400 {
            let (x, y, z) = (rnd() * 30.0 - 15.0, rnd() * 30.0 - 15.0, rnd() * 8.0 + 0.5);
            let s = 0.2 + rnd();
            let base = positions.len() as u32;
            positions.extend([[x, y, z], [x + s, y, z], [x + s, y + s, z + 0.3 * s], [x, y + s, z]]);
            indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        b.add_object("test", "SQUARES", SourceMesh { positions, indices }, false);
        let scene = b.build().unwrap();
        let rays = RayCaster::new(&scene).unwrap();
        let all: Vec<([DVec3; 3], Option<u32>)> = scene.world_triangles().collect();
        let mut blocked = 0;
        for k in 0..2000 {
            let (x, y) = (rnd() as f64 * 30.0 - 15.0, rnd() as f64 * 30.0 - 15.0);
            let (alt, az) = (0.05 + rnd() as f64 * 1.5, rnd() as f64 * std::f64::consts::TAU);
            let d = DVec3::new(alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin());
            let o = DVec3::new(x, y, 0.0);
            let truth = all.iter().any(|(t, id)| {
                *id != Some(0)
                    && hits(&Triangle { a: t[0], ab: t[1] - t[0], ac: t[2] - t[0], owner: 0, rank: -1.0 }, o, d, PLANE_SLACK / d.z)
            });
            assert_eq!(rays.blocked(o, DVec3::Z, 0, d, 1.0), truth, "ray {k}");
            blocked += usize::from(truth);
        }
        assert!(blocked > 300 && blocked < 1700, "{blocked} of 2000 blocked: the case must have both");
    }
}
