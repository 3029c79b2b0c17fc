//! The never-dark proof: that at every sun of a set some disc of a receiver, holding at least
//! [`MIN_LIT_SHARE`] of its area, is lit, so its fraction is above EnergyPlus's 1e-5 at each.
//! What lets the year interpolate a step ([`crate::year`]): a sliver of shadow between the
//! samples may lower its fraction, but not to 0.
//!
//! Owns the receiver's outline and the search for a lit disc. Both are taken from the receiver's
//! polygon, never from its triangles: the outline is the triangles' boundary edges (an edge
//! that one triangle uses), sorted, in a frame fixed by the normal, so a polygon listed from
//! another corner (another triangulation) gives the same outline, the same discs tried and so
//! the same steps proved.
//!
//! The proof is exact geometry. A triangle `T` in front of the receiver's plane shades a point
//! of it at some direction of the cone `K` exactly where the point lies in `(T − K) ∩ plane`,
//! its *footprint*: convex, and the convex hull of `T`'s corners (clipped to the front) moved
//! along each generator onto the plane, since the rays `t − s·g` are the convex set's edges that
//! cross the plane. A disc at distance at least its radius from every footprint is lit at every
//! direction of the cone. So the search sees past a union of casters (a scrim's rods, a reveal
//! and a neighbour) where none alone would leave the receiver lit: it looks, along a few lines
//! across the receiver, for the widest stretch that no footprint dilated by the radius covers.
//! A candidate found against the casters near the receiver is then checked against every
//! triangle of the thin volume its own disc sweeps; a caster found there joins the footprints
//! and the search is run again, a few rounds at most. Every triangle counts, see-through or leaf
//! or not. Whether a disc clears a footprint is first asked without the footprint's hull: a line
//! separating the disc from the footprint's points ([`separated`]) proves it clear, a point of
//! their hull inside the disc proves it blocked; the hull is built only where neither is found
//! in a few steps (and for the line search's intervals).

use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;
use std::hash::{BuildHasherDefault, Hasher};

use glam::{DVec2, DVec3};

use super::{CHUNK, COVER_MARGIN, Certifier, DirectionCone, MAX_SWEPT, NEAR_REACH, PLANE_TOLERANCE, Shape};
use crate::count::exact::engine::{parallel_chunks, worker_threads};
use crate::count::view::{self, convex_hull, perpendicular_basis};
use crate::scene::NO_RECEIVER;
use aperture::Aperture;

/// Least share of the receiver's area the lit disc holds: ten times EnergyPlus's 1e-5 (a
/// fraction under it is written as 0), so a proved step is lit in the schedule with room for an
/// engine's rounding.
pub const MIN_LIT_SHARE: f64 = 1e-4;

/// Lines searched across the receiver in each of its two directions (plus one through its
/// centroid each way).
const LINES: usize = 5;

/// The search first tries the inner points of a grid of this many cells a side across the
/// polygon's bounds.
const GRID: usize = 4;

/// A footprint is taken along the cone's axis alone, dilated by how far the generators would
/// move it, where that is at most this share of the disc's radius.
const SLACK_SHARE: f64 = 0.25;

/// Discs proved lit that a receiver's next proofs try before a search: proofs over a block of
/// cells (see [`super::cells`]) come back to places its earlier blocks' discs proved.
const RECENT_DISCS: usize = 4;

/// Where the swept volume is cut along the cone, as shares of its reach, when one box about it
/// holds too many triangles ([`Certifier::reached`]).
const SECTIONS: [f64; 6] = [0.0, 1.0 / 256.0, 1.0 / 64.0, 1.0 / 16.0, 1.0 / 4.0, 1.0];

/// Most times a candidate disc is checked against its whole swept volume and, blocked there,
/// the search run again with what blocked it.
const ROUNDS: usize = 4;

/// A receiver's polygon in its own plane, independent of how it was cut into triangles.
#[derive(Debug)]
pub(super) struct Outline {
    origin: DVec3,
    u: DVec3,
    v: DVec3,
    normal: DVec3,
    /// Boundary edges, wound counter-clockwise about the normal, sorted.
    edges: Vec<(DVec2, DVec2)>,
    lo: DVec2,
    hi: DVec2,
    centroid: DVec2,
    /// The lit disc's radius: its area is [`MIN_LIT_SHARE`] of the polygon's.
    radius: f64,
}

/// A caster's footprint on the receiver's plane over a cone: within `slack` of a convex
/// polygon (counter-clockwise; one or two points where it has no area), with its bounds.
#[derive(Debug)]
struct Footprint {
    /// Points whose convex hull it is; the hull is built when first needed (most casters a
    /// candidate disc's volume reaches are ruled out by their bounds alone).
    points: Vec<DVec2>,
    hull: std::cell::OnceCell<Vec<DVec2>>,
    lo: DVec2,
    hi: DVec2,
    slack: f64,
}

/// A cone's directions scaled to rise one unit off the receiver's plane: a point that high
/// moves by minus such a vector onto the plane; a point at height `hp` moves by `−(hp − height)`
/// of one onto the plane of the disc ([`Aperture`]), `height` in front of the receiver's.
struct Onto {
    axis: DVec3,
    generators: Vec<DVec3>,
    /// How far the farthest generator lies from the axis.
    spread: f64,
    /// Where the disc is looked for: 0 on the receiver's plane.
    height: f64,
}

/// The casters a never-dark search has taken (or passed over as never near).
#[derive(Default)]
struct Seen {
    /// Convex casters, by object.
    casters: IntSet<u32>,
    /// Convex casters with a corner behind the receiver's plane: taken triangle by triangle.
    straddling: IntSet<u32>,
    /// Triangles taken one by one (not convex, or of a straddling caster), by position.
    triangles: IntSet<usize>,
}

/// A set of small integer keys (objects, triangle positions) hashed by one multiplication:
/// with the default SipHash its look-ups took a few per cent of a proof's time.
type IntSet<T> = HashSet<T, BuildHasherDefault<IntHasher>>;

/// See [`IntSet`]: the keys need no defence against chosen collisions.
#[derive(Default)]
struct IntHasher(u64);

impl Hasher for IntHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(u64::from(*b));
        }
    }

    fn write_u32(&mut self, n: u32) {
        self.write_u64(u64::from(n));
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }
}

/// What one never-dark search hands the next, over nearby suns of the same receiver: the
/// casters near the receiver, and the centres of the last few discs proved lit. Both only guide
/// the search.
#[derive(Debug, Default)]
pub(super) struct Hints {
    pub(super) near: Option<Vec<usize>>,
    /// Most recent first, at most [`RECENT_DISCS`].
    discs: Vec<DVec2>,
    /// Runs of several cells proved and not ([`super::cells`]).
    pub(super) runs_proved: usize,
    pub(super) runs_failed: usize,
    /// Proofs looked for (for the log).
    pub(super) proofs: usize,
    /// The aperture's height where one proved the last set ([`aperture`]): tried first.
    aperture: Option<f64>,
    /// Apertures' discs proved lit, as `discs`.
    aperture_discs: Vec<DVec2>,
    /// Aperture proofs that held (for the log).
    pub(super) apertures_proved: usize,
}

/// A bit-exact key of a point, for matching edges.
type Key = [u64; 3];

/// How many triangles use an undirected edge, and its ends as the first one winds it.
type EdgeUses = HashMap<(Key, Key), (usize, DVec3, DVec3)>;

fn key(p: DVec3) -> Key {
    p.to_array().map(f64::to_bits)
}

impl Outline {
    /// The outline of a flat receiver of `triangles` facing `normal`; None where it has no area.
    pub(super) fn new(triangles: &[[DVec3; 3]], normal: DVec3) -> Option<Self> {
        // An undirected edge that one triangle uses is on the boundary; two (a shared diagonal)
        // is inside. A T-junction leaves both its long and its short edges, which only makes
        // the distance test stricter and leaves the crossing parity right.
        let mut uses = EdgeUses::new();
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (ka, kb) = (key(a), key(b));
                if ka != kb {
                    uses.entry(if ka < kb { (ka, kb) } else { (kb, ka) }).and_modify(|e| e.0 += 1).or_insert((1, a, b));
                }
            }
        }
        let mut boundary: Vec<(DVec3, DVec3)> = uses.into_values().filter(|e| e.0 == 1).map(|e| (e.1, e.2)).collect();
        boundary.sort_by_key(|(a, b)| (key(*a), key(*b)));
        let origin = boundary.iter().map(|e| e.0).min_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)).then(a.z.total_cmp(&b.z)))?;
        let across = DVec3::Z.cross(normal);
        let u = if across.length() > 0.1 { across } else { DVec3::X.cross(normal) }.try_normalize()?;
        let v = normal.cross(u);
        let flat = |p: DVec3| DVec2::new((p - origin).dot(u), (p - origin).dot(v));
        let edges: Vec<(DVec2, DVec2)> = boundary.iter().map(|(a, b)| (flat(*a), flat(*b))).collect();
        let twice_area: f64 = edges.iter().map(|(a, b)| a.perp_dot(*b)).sum();
        if twice_area.is_nan() || twice_area <= 0.0 {
            return None;
        }
        let centroid = edges.iter().map(|(a, b)| (*a + *b) * a.perp_dot(*b)).sum::<DVec2>() / (3.0 * twice_area);
        let lo = edges.iter().fold(DVec2::INFINITY, |m, (a, _)| m.min(*a));
        let hi = edges.iter().fold(DVec2::NEG_INFINITY, |m, (a, _)| m.max(*a));
        let radius = (MIN_LIT_SHARE * 0.5 * twice_area / PI).sqrt();
        Some(Self { origin, u, v, normal, edges, lo, hi, centroid, radius })
    }

    fn flat(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.origin).dot(self.u), (p - self.origin).dot(self.v))
    }

    fn world(&self, q: DVec2) -> DVec3 {
        self.origin + q.x * self.u + q.y * self.v
    }

    /// The square of half-side `half` about `q`, in the world: it holds the disc there.
    fn square(&self, q: DVec2, half: f64) -> [DVec3; 4] {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| self.world(q + DVec2::new(x, y) * half))
    }

    /// The cone's directions scaled onto the receiver's plane, once per cone.
    #[cfg(test)]
    fn onto(&self, cone: &DirectionCone) -> Onto {
        self.onto_at(cone, 0.0)
    }

    /// The cone's directions scaled onto the plane `height` in front of the receiver's.
    fn onto_at(&self, cone: &DirectionCone, height: f64) -> Onto {
        let onto = |g: DVec3| g / g.dot(self.normal);
        let axis = onto(cone.axis());
        let generators: Vec<DVec3> = cone.generators().iter().map(|g| onto(*g)).collect();
        let spread = generators.iter().map(|g| (*g - axis).length()).fold(0.0, f64::max);
        Onto { axis, generators, spread, height }
    }

    /// The footprint of triangle `t` over the cone (`onto`, whose generators all face the
    /// plane); None where `t` lies on or behind the plane (within `tolerance`), as both engines
    /// ignore it, or where the footprint stays `r` or more outside the polygon's bounds
    /// ([`Self::footprint_of`]).
    #[cfg(test)]
    fn footprint(&self, t: &[DVec3; 3], onto: &Onto, tolerance: f64, r: f64) -> Option<Footprint> {
        self.footprint_near(t, onto, tolerance, r, (self.lo, self.hi))
    }

    /// [`Self::footprint`], left out where it stays `r` off the box `near` (the polygon's
    /// bounds, or one disc's centre).
    fn footprint_near(&self, t: &[DVec3; 3], onto: &Onto, tolerance: f64, r: f64, near: (DVec2, DVec2)) -> Option<Footprint> {
        let h = t.map(|p| (p - self.origin).dot(self.normal));
        if h.iter().all(|x| *x <= tolerance) {
            return None;
        }
        // The part in front (height ≥ 0); only it can be hit by rays leaving the plane forward.
        let mut front = [(DVec3::ZERO, 0.0); 4];
        let mut n = 0;
        for k in 0..3 {
            let (p, hp, q, hq) = (t[k], h[k], t[(k + 1) % 3], h[(k + 1) % 3]);
            if hp >= 0.0 {
                front[n] = (p, hp);
                n += 1;
            }
            if (hp >= 0.0) != (hq >= 0.0) {
                front[n] = (p + (q - p) * (hp / (hp - hq)), 0.0);
                n += 1;
            }
        }
        self.footprint_of(&front[..n], onto, r, near)
    }

    /// The footprint over the cone of a whole convex caster whose `corners` all lie on or in
    /// front of the plane (none below 0): the convex hull of its corners moved along each
    /// generator, since every ray of the cone that hits the solid leaves it through the hull of
    /// those points. It holds the footprint of every triangle of the caster (each lies in the
    /// hull), so one footprint stands for all of them: a rod's 12 triangles, a panelled block's
    /// thousands. None where it has no part in front (within `tolerance`), or where some
    /// corner lies behind the plane (its triangles are then taken one by one), or where it stays
    /// `r` off the polygon's bounds.
    #[cfg(test)]
    fn caster_footprint(&self, corners: &[DVec3], onto: &Onto, tolerance: f64, r: f64) -> Option<Option<Footprint>> {
        self.caster_footprint_near(corners, onto, tolerance, r, (self.lo, self.hi))
    }

    /// [`Self::caster_footprint`], left out where it stays `r` off the box `near`.
    fn caster_footprint_near(
        &self,
        corners: &[DVec3],
        onto: &Onto,
        tolerance: f64,
        r: f64,
        near: (DVec2, DVec2),
    ) -> Option<Option<Footprint>> {
        let front: Vec<(DVec3, f64)> = corners.iter().map(|p| (*p, (*p - self.origin).dot(self.normal))).collect();
        if front.iter().any(|(_, h)| *h < 0.0 || h.is_nan()) {
            return None;
        }
        if front.iter().all(|(_, h)| *h <= tolerance) {
            return Some(None);
        }
        Some(self.footprint_of(&front, onto, r, near))
    }

    /// The footprint over the cone of the convex hull of `front` (points on or in front of the
    /// plane, with their heights); None where it stays `r` or more outside the polygon's bounds,
    /// so that no disc of radius `r` on the polygon is near it: its hull is then never built.
    /// Most casters a swept volume reaches in a city are such (the culling is a box about the
    /// volume, and a scrim's rods above and below the window pass their shadows past its bounds).
    fn footprint_of(&self, front: &[(DVec3, f64)], onto: &Onto, r: f64, near: (DVec2, DVec2)) -> Option<Footprint> {
        // Along the axis alone, each corner moves at most `slack` from where a direction of the
        // cone would take it (the scaled directions are convex combinations of the scaled
        // generators). So a footprint whose corners moved along the axis stay `slack + r` off
        // the polygon's bounds is not near any disc: rejected before the generators are tried.
        // Heights above the disc's plane: a point below it (between it and the receiver's)
        // moves forward onto it, along the ray it would block on its way to the disc.
        let rise = |hp: f64| hp - onto.height;
        let highest = front.iter().map(|(_, hp)| rise(*hp).abs()).fold(0.0, f64::max);
        let slack = highest * onto.spread;
        let along_axis: Vec<DVec2> = front.iter().map(|(p, hp)| self.flat(*p - onto.axis * rise(*hp))).collect();
        let (lo, hi) = bounds(&along_axis);
        if !(lo.is_finite() && hi.is_finite()) || apart(near, lo, hi, r + slack) {
            return None;
        }
        // Where the slack is small (a short run of suns) the footprint is the corners moved
        // along the axis, dilated by it; else the hull over every generator.
        if slack <= SLACK_SHARE * self.radius {
            return Some(Footprint::new(along_axis, lo, hi, slack));
        }
        let moved: Vec<DVec2> =
            onto.generators.iter().flat_map(|g| front.iter().map(move |(p, hp)| self.flat(*p - *g * rise(*hp)))).collect();
        // The hull's bounds are the moved corners' bounds.
        let (lo, hi) = bounds(&moved);
        (!apart(near, lo, hi, r)).then(|| Footprint::new(moved, lo, hi, 0.0))
    }

    /// Whether the box `lo..hi` lies more than `reach` outside the polygon's bounds.
    #[cfg(test)]
    fn apart(&self, lo: DVec2, hi: DVec2, reach: f64) -> bool {
        apart((self.lo, self.hi), lo, hi, reach)
    }

    /// Whether `q` lies inside the polygon (even-odd rule over the boundary edges).
    fn contains(&self, q: DVec2) -> bool {
        self.edges.iter().filter(|(a, b)| (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y)).count() % 2
            == 1
    }

    /// Whether a disc of radius `r` at `q` on the aperture's plane lies, moved onto the
    /// receiver's, inside the polygon, and is clear of every footprint.
    fn clear(&self, q: DVec2, r: f64, footprints: &[Footprint], at: &Aperture) -> bool {
        self.contains(q - at.shift) && at.inside(self, q, r) && footprints.iter().all(|f| f.distance_at_least(q, r))
    }

    /// A point where a disc of radius `r` is inside the polygon and clear of every footprint,
    /// looked for at the centroid, then at the middle of the widest clear stretch of each line
    /// searched in turn; None where none is found.
    fn find(&self, footprints: &[Footprint], r: f64, at: &Aperture) -> Option<DVec2> {
        let centroid = self.centroid + at.shift;
        if self.clear(centroid, r, footprints, at) {
            return Some(centroid);
        }
        // A few points of a grid across the bounds, each checked without a hull where the
        // footprints allow ([`separated`]): a wide clear patch is found before any line.
        let grid = (1..GRID).flat_map(|i| (1..GRID).map(move |j| (i, j)));
        let point = |(i, j): (usize, usize)| self.lo + at.shift + (self.hi - self.lo) * DVec2::new(i as f64, j as f64) / GRID as f64;
        if let Some(q) = grid.map(point).find(|q| self.clear(*q, r, footprints, at)) {
            return Some(q);
        }
        // Line by line (the centroid's first), the widest clear stretch first.
        self.lines().into_iter().map(|(o, d)| (o + at.shift, d)).find_map(|(o, d)| {
            let mut stretches: Vec<(f64, DVec2)> =
                self.clear_stretches(o, d, r, footprints, at).into_iter().map(|(t0, t1)| (t1 - t0, o + d * (0.5 * (t0 + t1)))).collect();
            stretches.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.x.total_cmp(&b.1.x)).then(a.1.y.total_cmp(&b.1.y)));
            stretches.into_iter().map(|(_, q)| q).find(|q| self.clear(*q, r, footprints, at))
        })
    }

    /// The lines searched (a point and a unit direction): [`LINES`] evenly across the bounds in
    /// each direction, and one through the centroid each way.
    fn lines(&self) -> Vec<(DVec2, DVec2)> {
        let mut out = vec![(self.centroid, DVec2::Y), (self.centroid, DVec2::X)];
        for k in 0..LINES {
            let s = (k as f64 + 0.5) / LINES as f64;
            out.push((DVec2::new(self.lo.x + s * (self.hi.x - self.lo.x), self.lo.y), DVec2::Y));
            out.push((DVec2::new(self.lo.x, self.lo.y + s * (self.hi.y - self.lo.y)), DVec2::X));
        }
        out
    }

    /// Stretches (parameters along `o + t·d`, on the aperture's plane) of the line inside the
    /// polygon moved onto it, at least `r` from its boundary and from every footprint.
    fn clear_stretches(&self, o: DVec2, d: DVec2, r: f64, footprints: &[Footprint], at: &Aperture) -> Vec<(f64, f64)> {
        // Crossings with the polygon where it lies on this plane: the line moved back onto it.
        let below = o - at.shift;
        let side = |p: DVec2| d.perp_dot(p - below);
        let mut crossings: Vec<f64> = self
            .edges
            .iter()
            .filter(|(a, b)| (side(*a) > 0.0) != (side(*b) > 0.0))
            .map(|(a, b)| (*a + (*b - *a) * (side(*a) / (side(*a) - side(*b))) - below).dot(d))
            .collect();
        crossings.sort_by(f64::total_cmp);
        let mut blocked: Vec<(f64, f64)> = if at.walls.is_empty() {
            self.edges.iter().filter_map(|(a, b)| capsule_interval(o, d, *a, *b, r)).collect()
        } else {
            at.walls.iter().filter_map(|w| w.interval(o, d, r)).collect()
        };
        blocked.extend(footprints.iter().filter_map(|f| f.interval(o, d, r)));
        blocked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut out = Vec::new();
        for inside in crossings.chunks_exact(2) {
            let mut start = inside[0];
            for (b0, b1) in blocked.iter().filter(|(b0, b1)| *b1 > inside[0] && *b0 < inside[1]) {
                if *b0 > start {
                    out.push((start, *b0));
                }
                start = start.max(*b1);
            }
            if inside[1] > start {
                out.push((start, inside[1]));
            }
        }
        out
    }
}

impl Footprint {
    fn new(points: Vec<DVec2>, lo: DVec2, hi: DVec2, slack: f64) -> Self {
        Self { points, hull: std::cell::OnceCell::new(), lo, hi, slack }
    }

    /// The convex polygon, counter-clockwise (one or two points where it has no area).
    fn hull(&self) -> &[DVec2] {
        self.hull.get_or_init(|| convex_hull(&self.points))
    }

    /// Whether `q` is at least `r` from the footprint.
    fn distance_at_least(&self, q: DVec2, r: f64) -> bool {
        let r = r + self.slack;
        if q.x < self.lo.x - r || q.x > self.hi.x + r || q.y < self.lo.y - r || q.y > self.hi.y + r {
            return true;
        }
        // Most footprints near a disc are decided without their hull (whose sort was a tenth of
        // the proof's time): a separating line found among the points, or a point of the hull
        // within `r`. Only where neither is found in a few steps is the hull built.
        if let Some(apart) = separated(&self.points, q, r) {
            return apart;
        }
        let hull = self.hull();
        let n = hull.len();
        let inside = n >= 3 && (0..n).all(|k| (hull[(k + 1) % n] - hull[k]).perp_dot(q - hull[k]) >= 0.0);
        !inside && (0..n).all(|k| segment_distance(q, hull[k], hull[(k + 1) % n]) >= r)
    }

    /// The parameters along `o + t·d` (d a unit axis) within `r` of the footprint: one interval,
    /// the footprint dilated by a disc being convex, spanned by the edges' capsules (the line
    /// meets the footprint only between two points of its boundary).
    fn interval(&self, o: DVec2, d: DVec2, r: f64) -> Option<(f64, f64)> {
        let r = r + self.slack;
        let across = DVec2::new(-d.y, d.x);
        let (lo, hi) = ((self.lo - o).dot(across), (self.hi - o).dot(across));
        if lo.min(hi) > r || lo.max(hi) < -r {
            return None;
        }
        let hull = self.hull();
        let n = hull.len();
        (0..n).filter_map(|k| capsule_interval(o, d, hull[k], hull[(k + 1) % n], r)).reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
    }
}

/// Steps of Gilbert's distance iteration tried before a footprint's hull is built.
const SEPARATION_STEPS: usize = 8;

/// Whether the convex hull of `points` is at least `r` from `q`, decided without building it,
/// where a few steps of Gilbert's iteration decide it: `x`, a convex combination of the points
/// (so a point of the hull), moves towards `q` along the segment to the point of least extent
/// towards `q`. The line through `q` across `x − q` separates when every point lies at least `r`
/// beyond it along `x − q` (then every point of the hull does); `x` itself within `r` of `q`
/// shows the hull near. None where neither is shown.
fn separated(points: &[DVec2], q: DVec2, r: f64) -> Option<bool> {
    let first = *points.first()?;
    let mut x = points.iter().skip(1).fold(first, |s, p| s + *p) / points.len() as f64;
    for _ in 0..SEPARATION_STEPS {
        let to = x - q;
        let distance = to.length();
        if distance < r || !distance.is_finite() {
            return (distance < r).then_some(false);
        }
        let n = to / distance;
        let (s, least) = points.iter().map(|p| (*p, n.dot(*p - q))).fold((first, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        if !least.is_finite() {
            return None;
        }
        if least >= r {
            return Some(true);
        }
        let e = s - x;
        if e.length_squared() == 0.0 {
            return None;
        }
        x += e * ((q - x).dot(e) / e.length_squared()).clamp(0.0, 1.0);
    }
    None
}

/// Whether the box `lo..hi` lies more than `reach` outside the box `near`.
fn apart(near: (DVec2, DVec2), lo: DVec2, hi: DVec2, reach: f64) -> bool {
    lo.x > near.1.x + reach || lo.y > near.1.y + reach || hi.x < near.0.x - reach || hi.y < near.0.y - reach
}

/// The bounds of `points`.
fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), q| (lo.min(*q), hi.max(*q)))
}

/// Distance from `q` to the segment `ab`.
fn segment_distance(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    let e = b - a;
    let s = if e.length_squared() > 0.0 { ((q - a).dot(e) / e.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    q.distance(a + e * s)
}

/// The parameters along `o + t·d` (d unit) within `r` of the segment `ab`: the hull of the line's
/// intervals in the two end discs and the band between them.
fn capsule_interval(o: DVec2, d: DVec2, a: DVec2, b: DVec2, r: f64) -> Option<(f64, f64)> {
    let disc = |c: DVec2| {
        let along = (c - o).dot(d);
        let off = (c - o).perp_dot(d);
        (off.abs() <= r).then(|| {
            let half = (r * r - off * off).max(0.0).sqrt();
            (along - half, along + half)
        })
    };
    let band = || {
        let e = b - a;
        let length = e.length();
        if length == 0.0 {
            return None;
        }
        let (along, across) = (e / length, DVec2::new(-e.y, e.x) / length);
        // 0 ≤ (x − a)·along ≤ length and |(x − a)·across| ≤ r, with x = o + t·d.
        let mut range = (f64::NEG_INFINITY, f64::INFINITY);
        for (axis, low, high) in [(along, 0.0, length), (across, -r, r)] {
            let (base, rate) = ((o - a).dot(axis), d.dot(axis));
            if rate == 0.0 {
                if base < low || base > high {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((low - base) / rate, (high - base) / rate);
            range = (range.0.max(t0.min(t1)), range.1.min(t0.max(t1)));
        }
        (range.0 <= range.1).then_some(range)
    };
    [disc(a), disc(b), band()].into_iter().flatten().reduce(|x, y| (x.0.min(y.0), x.1.max(y.1)))
}

/// Orders `set` (indices into `suns`) along the wider of the two axes of the suns' gnomonic
/// chart about their mean, so that each half spans about half the sky the set does that way: a
/// cell's steps in order of rows split into its first and last days, which the sun's path
/// across an hour or so of each day spans much more widely. Only the order of trying changes.
pub(super) fn split_widest(suns: &[DVec3], set: &mut [usize]) {
    let Some(axis) = set.iter().map(|&i| suns[i]).sum::<DVec3>().try_normalize() else { return };
    let (u, v) = perpendicular_basis(axis);
    let chart = |i: usize| DVec2::new(suns[i].dot(u), suns[i].dot(v)) / suns[i].dot(axis);
    let (lo, hi) = bounds(&set.iter().map(|&i| chart(i)).collect::<Vec<_>>());
    let along = if hi.x - lo.x >= hi.y - lo.y { DVec2::X } else { DVec2::Y };
    set.sort_by(|a, b| chart(*a).dot(along).total_cmp(&chart(*b).dot(along)).then(a.cmp(b)));
}

impl Certifier<'_> {
    /// For many sets (receiver, its suns), in order, the suns of each at which the receiver is
    /// not proved partly lit ([`Self::not_dark`]): the set is tried whole, then in halves, down
    /// to single suns. Natively over every core.
    pub fn unproved_lit(&self, sets: &[(usize, &[DVec3])]) -> Vec<Vec<usize>> {
        let threads = worker_threads().min(sets.len().div_ceil(CHUNK)).max(1);
        parallel_chunks(
            sets.len(),
            threads,
            CHUNK,
            || (),
            |i, _| {
                let mut out = Vec::new();
                self.bisect_not_dark(sets[i].0, sets[i].1, 0, &mut Hints::default(), &mut out);
                out
            },
        )
    }

    /// Pushes onto `out` the indices (from `first`) of `suns` not proved by [`Self::not_dark`],
    /// halving the set where the whole is not proved: a shorter stretch of the sun's path sweeps
    /// thinner footprints, between which a disc may pass. `hints`: what the sets tried before
    /// found (the casters near the receiver, the last disc proved lit), tried first in its
    /// halves too.
    pub(super) fn bisect_not_dark(&self, receiver: usize, suns: &[DVec3], first: usize, hints: &mut Hints, out: &mut Vec<usize>) {
        let mut set: Vec<usize> = (0..suns.len()).collect();
        let start = out.len();
        self.bisect_set(receiver, suns, &mut set, hints, out);
        out[start..].sort_unstable();
        out[start..].iter_mut().for_each(|i| *i += first);
    }

    /// [`Self::bisect_not_dark`] over the suns at `set` (indices into `suns`), each half taken
    /// across the set's widest extent ([`split_widest`]).
    fn bisect_set(&self, receiver: usize, suns: &[DVec3], set: &mut [usize], hints: &mut Hints, out: &mut Vec<usize>) {
        if set.is_empty() {
            return;
        }
        let chosen: Vec<DVec3> = set.iter().map(|&i| suns[i]).collect();
        if self.not_dark_near(receiver, &chosen, hints) {
            return;
        }
        if let [only] = set {
            out.push(*only);
            return;
        }
        split_widest(suns, set);
        let (low, high) = set.split_at_mut(set.len() / 2);
        self.bisect_set(receiver, suns, low, hints, out);
        self.bisect_set(receiver, suns, high, hints, out);
    }

    /// Whether some disc of the receiver holding [`MIN_LIT_SHARE`] of its area is lit at every
    /// one of `suns` (see the module's doc): its fraction is then above EnergyPlus's 1e-5 at
    /// each, never dark.
    pub fn not_dark(&self, receiver: usize, suns: &[DVec3]) -> bool {
        self.not_dark_near(receiver, suns, &mut Hints::default())
    }

    /// [`Self::not_dark`] with the `hints` of the sets tried before.
    fn not_dark_near(&self, receiver: usize, suns: &[DVec3], hints: &mut Hints) -> bool {
        let Some((shape, cone)) = self.cone_of(receiver, suns) else { return false };
        self.not_dark_over(shape, &cone, hints)
    }

    /// Whether some disc of `shape` holding [`MIN_LIT_SHARE`] of its area is lit at every
    /// direction of `cone` (every one in front of the receiver and above the horizon): one on
    /// the receiver's plane, else one seen through an aperture in front of it ([`aperture`]);
    /// the aperture first where it proved the receiver's last set.
    pub(super) fn not_dark_over(&self, shape: &Shape, cone: &DirectionCone, hints: &mut Hints) -> bool {
        let Some(outline) = &shape.outline else { return false };
        hints.proofs += 1;
        let aperture_first = hints.aperture.is_some();
        if !aperture_first && self.lit_disc(shape, outline, cone, 0.0, &mut hints.discs, &mut hints.near) {
            return true;
        }
        let height = hints.aperture.or_else(|| self.aperture_height(outline, hints.near.as_deref().unwrap_or_default()));
        if let Some(height) = height.filter(|h| *h > 0.0) {
            if hints.aperture != Some(height) {
                hints.aperture_discs.clear();
            }
            if self.lit_disc(shape, outline, cone, height, &mut hints.aperture_discs, &mut hints.near) {
                hints.aperture = Some(height);
                hints.apertures_proved += 1;
                return true;
            }
            hints.aperture = None;
        }
        aperture_first && self.lit_disc(shape, outline, cone, 0.0, &mut hints.discs, &mut hints.near)
    }

    /// Whether a disc on the plane `height` in front of the receiver's (0: on it) is lit, moved
    /// along every direction of `cone` onto the receiver. The first candidate disc is the last
    /// one `discs` proved, then one looked for among the casters near the receiver (found here
    /// along the cone where `near_hint` has none). Neither hint decides anything: every caster
    /// in the volume the candidate disc's rays sweep is checked.
    #[allow(clippy::too_many_arguments)]
    fn lit_disc(
        &self,
        shape: &Shape,
        outline: &Outline,
        cone: &DirectionCone,
        height: f64,
        discs: &mut Vec<DVec2>,
        near_hint: &mut Option<Vec<usize>>,
    ) -> bool {
        let tolerance = PLANE_TOLERANCE * (1.0 + self.extent);
        // The GPU rounds in f32 about the scene's origin: the disc keeps this much clear too.
        let r = outline.radius + COVER_MARGIN * (1.0 + self.extent);
        let reach = self.reach(cone) + height;
        let onto = outline.onto_at(cone, height);
        let at = Aperture::of(outline, &onto);
        let mut footprints = Vec::new();
        // Footprints of the fresh casters among `positions` that may come near a disc, and
        // which casters those were (one position each).
        let add = |positions: &[usize], footprints: &mut Vec<Footprint>, kept: &mut Vec<usize>, seen: &mut Seen, near: (DVec2, DVec2)| {
            let own = |p: usize| self.index.owner[p] == shape.gpu_id && shape.gpu_id != NO_RECEIVER;
            let start = footprints.len();
            for &p in positions {
                if own(p) {
                    continue;
                }
                // A convex caster's footprint once for all its triangles, where it lies wholly
                // in front; else (or where it is not convex) the triangle's own.
                let footprint = match self.index.objects.of(p) {
                    Some(o) if !seen.straddling.contains(&o) => {
                        if !seen.casters.insert(o) {
                            continue;
                        }
                        let corners: Vec<DVec3> = self.index.objects.corners(o).iter().map(|&c| self.index.corner(c)).collect();
                        match outline.caster_footprint_near(&corners, &onto, tolerance, r, near) {
                            Some(footprint) => footprint,
                            None => {
                                seen.straddling.insert(o);
                                seen.triangles.insert(p);
                                outline.footprint_near(&self.index.triangles[p], &onto, tolerance, r, near)
                            }
                        }
                    }
                    _ => {
                        if !seen.triangles.insert(p) {
                            continue;
                        }
                        outline.footprint_near(&self.index.triangles[p], &onto, tolerance, r, near)
                    }
                };
                if let Some(f) = footprint {
                    footprints.push(f);
                    kept.push(p);
                }
            }
            start
        };
        // The last disc proved lit first, against only what its own volume reaches, each caster
        // stopping the check as soon as it comes near the disc (its footprint kept only near it).
        let hinted = discs.first().copied().filter(|q| outline.clear(*q, r, &[], &at));
        if let Some(found) = hinted.and_then(|q| Some((q, self.reached(&outline.aperture_square(q, r, &onto), cone, reach)?))) {
            let (q, found) = found;
            let (mut near_q, mut seen) = (Vec::new(), Seen::default());
            let blocked = found.chunks(1).any(|p| {
                let start = add(p, &mut near_q, &mut Vec::new(), &mut seen, (q, q));
                near_q[start..].iter().any(|f| !f.distance_at_least(q, r))
            });
            if !blocked {
                return true;
            }
            // Blocked by a caster of its own volume: not worth trying again over this cone.
            discs.remove(0);
        }
        // The casters near the receiver (a scrim's rods, a reveal) first, for a good candidate;
        // what the candidate's own volume holds decides. Found once per set, and only those
        // whose footprint came near the receiver are handed to its halves.
        let (listed, first) = match near_hint.take() {
            Some(listed) => (listed, false),
            None => (self.reached(&shape.points, cone, (NEAR_REACH * (1.0 + self.extent)).min(reach)).unwrap_or_default(), true),
        };
        let mut kept = Vec::new();
        let mut seen = Seen::default();
        let whole = (outline.lo + at.shift, outline.hi + at.shift);
        add(&listed, &mut footprints, &mut kept, &mut seen, whole);
        *near_hint = Some(if first { kept } else { listed });
        for _ in 0..ROUNDS {
            // A disc that proved a recent set, where it is still clear here; else a search.
            let last = discs.iter().copied().find(|q| outline.clear(*q, r, &footprints, &at));
            let Some(q) = last.or_else(|| outline.find(&footprints, r, &at)) else { return false };
            let Some(found) = self.reached(&outline.aperture_square(q, r, &onto), cone, reach) else { return false };
            let start = add(&found, &mut footprints, &mut Vec::new(), &mut seen, whole);
            discs.retain(|d| *d != q);
            if footprints[start..].iter().all(|f| f.distance_at_least(q, r)) {
                discs.insert(0, q);
                discs.truncate(RECENT_DISCS);
                return true;
            }
            // Blocked: the next round searches again with what blocked it.
        }
        false
    }

    /// The positions of the triangles the culling finds in the volume `points` sweep along the
    /// cone within `reach`; None past [`MAX_SWEPT`].
    fn reached(&self, points: &[DVec3], cone: &DirectionCone, reach: f64) -> Option<Vec<usize>> {
        let corners = self.swept_corners(points, cone, reach);
        let found = self.culled(&view::fit(&corners, cone.axis(), self.index.bounds, self.index.origin, 64));
        if found.len() <= MAX_SWEPT {
            return Some(found);
        }
        // The culling's box holds the volume's far cross-section all the way from the receiver,
        // where a city's scrims and facades stand: culled again in sections along the cone,
        // each box only as wide as its own part of the volume (and reaching on to the scene's
        // end, so each holds what lies beyond its part too).
        let mut found: Vec<usize> = SECTIONS
            .windows(2)
            .flat_map(|ends| {
                // The points moved along each generator to the slab's two ends.
                let corners: Vec<DVec3> = ends
                    .iter()
                    .flat_map(|&end| cone.generators().iter().flat_map(move |g| points.iter().map(move |p| *p + *g * (end * reach))))
                    .collect();
                self.culled(&view::fit_slab(&corners, cone.axis(), self.index.bounds, self.index.origin, 64))
            })
            .collect();
        found.sort_unstable();
        found.dedup();
        (found.len() <= MAX_SWEPT).then_some(found)
    }

    /// The positions of the triangles in `view`'s box (what the culling visits).
    fn culled(&self, view: &view::SunView) -> Vec<usize> {
        let mut reached = Vec::new();
        self.index.culling.visit_triangles(&view.view_proj, |r| reached.push(r));
        reached.into_iter().flatten().collect()
    }
}

mod aperture;
#[cfg(test)]
mod tests;
