//! The fast exact engine's boolean step: `area(receiver − ∪ shadows)` when every polygon is
//! convex, by integrating along the boundary instead of building an overlay graph.
//!
//! Owns the integer grid a receiver's polygons are snapped to ([`Snap`]) and the area of the
//! region that is inside some *receiver* polygon and inside no *shadow* polygon. It is not a
//! general polygon boolean: it returns an area, never a shape, and needs convex polygons (the
//! engine's shadows are convex hulls, clipped triangles and receiver triangles).
//!
//! How: by Green's theorem the area of a region is `∮ x dy` over its boundary, and every piece of
//! that boundary lies on some polygon's edge. So for every edge of every polygon the parameter
//! interval where each other (convex) polygon covers it is found by clipping the segment against
//! that polygon's half-planes; between those intervals' ends, whether the region lies on the
//! edge's left and on its right is known, and `(left − right) · ∫ x dy` is added. A segment
//! where several edges lie on one line (shared or overlapping edges) is counted once, for the
//! polygon pushed first: a polygon with an edge on the same line covers only that edge's left
//! or right side there, and a segment lying on an earlier polygon's edge is that edge's to count.
//!
//! Robustness is the integer grid's, as in the reference: vertices are snapped to integers (a
//! 2^30 grid over the receiver's window), each snapped polygon is made convex again (an exact
//! hull), and every inside, outside or on-the-line decision is an exact `i64` orientation test.
//! Only where a segment crosses a line is computed in `f64`, so rounding can move a crossing
//! along its segment by an ulp, never change which polygons cover which side of it.
//!
//! Cost: each edge is tested only against polygons whose bounding boxes overlap its own (all of
//! them when there are few, a grid of square buckets about a typical polygon wide when there are
//! many, as leaves give; square whatever the window's shape, since a façade's window may be 10:1;
//! a polygon over many buckets, a wall's shadow, in coarse buckets of 4 × 4 of them),
//! so a view with `n` shadows of bounded overlap costs about `n` times their edges. A bucket's
//! polygons are copied into it (box and vertices) in the order of their boxes' left sides, so a
//! search stops at the first that starts right of its box, and a pair sharing several buckets is
//! met in one (the one holding their boxes' common lower corner) without marks. An edge stops
//! being integrated once covers that leave no region beside it (a shadow on both sides, or on
//! the outer side of a shadow's edge, or an earlier polygon's edge on its line) hold every one of
//! 64 slots of it: its pieces would all be 0 (under a canopy, the edges inside the union). A cover that
//! runs from an edge's start or to its end moves the counters without an event (a leaf's edges
//! lie across a receiver triangle end to end), so most edges sort only their leaf neighbours'
//! crossings. A shadow whose box meets no receiver polygon's (on a wall around a window, those in
//! the window's hole) is dropped first, then a polygon inside one shadow (most leaves of a
//! crowded canopy): neither can change the area. Polygons inside the union of several others
//! are not looked for: on `blaas-trees-summer`'s heaviest sky views (34,000 leaf shadows, none
//! inside one other) a grid of cells each inside one shadow (exact corner tests) found no
//! polygon whose cells were all covered, at cells of 1/3 to 1/16 of a leaf, and cost 16% more instructions: the canopy's
//! gaps put nearly every leaf on the union's boundary (docs/sky.md, "Benchmarks").

use glam::DVec2;

/// Half the grid's side: snapped coordinates lie in `[−HALF, HALF]`, so differences stay below
/// 2^30, products below 2^60 and orientation determinants below 2^61, inside `i64`.
const HALF: f64 = (1u64 << 29) as f64;
/// Up to this many polygons every edge is tested against all of them (a bounding-box check is
/// cheaper than building buckets); above, a grid of buckets.
const SCAN_ALL: usize = 48;
/// A bucket's side per typical polygon's box side (the median of their longer sides).
const BUCKET_PER_TYPICAL: f64 = 1.0;
/// Most buckets per polygon, and in all.
const BUCKETS_PER_POLYGON: f64 = 1.0;
const MAX_BUCKETS: usize = 1 << 16;
/// A polygon over more buckets than this (a receiver triangle, a wall's shadow) is kept out of
/// them, in coarse buckets of [`COARSE`]² buckets each: in every bucket it would be met again by
/// every query.
const BIG_SPAN: usize = 16;
/// Buckets per coarse bucket's side. A heavy sky view has a few dozen big polygons, and nine in
/// ten of them are far from any one leaf; tested by box alone they cost as many box tests as
/// every edge's own scan.
const COARSE: usize = 4;

type Point = [i64; 2];

/// Maps a receiver's window onto the integer grid: its centre to 0, its longer half-side to
/// [`HALF`].
#[derive(Debug, Clone, Copy)]
pub(super) struct Snap {
    center: DVec2,
    scale: f64,
}

impl Snap {
    /// `None` for an empty or non-finite window.
    pub(super) fn new(min: DVec2, max: DVec2) -> Option<Self> {
        let half = 0.5 * (max - min).max_element();
        let scale = HALF / half;
        (half > 0.0 && scale.is_finite() && min.is_finite() && max.is_finite()).then_some(Self { center: 0.5 * (min + max), scale })
    }

    /// Grid units² per unit² of the plane.
    pub(super) fn area_scale(&self) -> f64 {
        self.scale * self.scale
    }

    /// The nearest grid point (clamped to the grid: polygons are clipped to the window first, so
    /// only rounding reaches past it).
    fn point(&self, p: DVec2) -> Point {
        let q = ((p - self.center) * self.scale).clamp(DVec2::splat(-HALF), DVec2::splat(HALF)).round();
        [q.x as i64, q.y as i64]
    }
}

/// A polygon's vertices (a range of [`Boundary::points`]), bounding box and role.
#[derive(Debug, Clone, Copy)]
struct Poly {
    start: u32,
    end: u32,
    lo: Point,
    hi: Point,
    receiver: bool,
}

/// A candidate polygon for the current polygon's edges: its box, vertices and index, copied so
/// each edge's scan reads one contiguous array.
#[derive(Debug, Clone, Copy)]
struct Near {
    lo: Point,
    hi: Point,
    start: u32,
    end: u32,
    poly: u32,
    receiver: bool,
}

impl Near {
    fn of(i: usize, p: &Poly) -> Self {
        Self { lo: p.lo, hi: p.hi, start: p.start, end: p.end, poly: i as u32, receiver: p.receiver }
    }
}

/// How a convex polygon covers an edge over a parameter interval.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Side {
    /// Both sides: the interval runs through the polygon's interior.
    Both,
    /// Only the edge's left (the polygon has an edge on the same line, in the same direction).
    Left,
    /// Only the edge's right (an edge on the same line, in the opposite direction).
    Right,
}

/// Counters an interval moves while sweeping one edge.
const RECEIVER_LEFT: u8 = 1;
const RECEIVER_RIGHT: u8 = 2;
const SHADOW_LEFT: u8 = 4;
const SHADOW_RIGHT: u8 = 8;
const EARLIER_EDGE: u8 = 16;
/// Per set of counters (the bits above), which of eight lanes each moves (the last three never).
const COUNTER_BITS: [[i32; 8]; 32] = {
    let mut table = [[0; 8]; 32];
    let mut set = 0;
    while set < 32 {
        let mut bit = 0;
        while bit < 5 {
            table[set][bit] = (set as i32 >> bit) & 1;
            bit += 1;
        }
        set += 1;
    }
    table
};

/// The polygons of one view and the memory to integrate them, reused from view to view.
#[derive(Debug, Default)]
pub(super) struct Boundary {
    points: Vec<Point>,
    polys: Vec<Poly>,
    /// Scratch for snapping one polygon and taking its hull.
    snapped: Vec<Point>,
    /// One edge's interval ends: parameter, counters, +1 or −1.
    events: Vec<(f64, u8, i8)>,
    /// Buckets: per cell its range of `cell_items` (prefix sums), the polygons in each cell.
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    /// The same polygons' boxes and vertices (what each polygon's search for candidates reads).
    cell_near: Vec<Near>,
    /// Candidates of the current polygon (the others whose boxes overlap its box), their boxes
    /// copied beside their index so each edge's scan reads one contiguous array.
    candidates: Vec<Near>,
    /// Scratch for [`Self::build_buckets`]: each cell's next free slot.
    next_slot: Vec<u32>,
    buckets: Buckets,
    /// Polygons over more than [`BIG_SPAN`] buckets, not in any: per coarse bucket its range of
    /// `big_items` (prefix sums), the polygons whose boxes span it.
    big_start: Vec<u32>,
    big_items: Vec<u32>,
    /// Per polygon: the buckets its box spans, `[x0, y0, x1, y1]` (found once a build).
    spans: Vec<[usize; 4]>,
    /// Per polygon: whether it is kept (scratch for [`Self::drop_covered`]).
    keep: Vec<bool>,
    /// Scratch for [`Self::drop_apart`]: the receiver polygons' boxes.
    receiver_boxes: Vec<(Point, Point)>,
    /// Scratch: the polygons' longer box sides.
    sides: Vec<i64>,
}

/// The bucket grid: `n[0] × n[1]` square cells of `size` grid units from `origin`.
#[derive(Debug, Default, Clone, Copy)]
struct Buckets {
    n: [usize; 2],
    origin: Point,
    size: i64,
}

impl Boundary {
    /// Forgets the polygons (keeps the memory).
    pub(super) fn clear(&mut self) {
        self.points.clear();
        self.polys.clear();
    }

    /// Polygons pushed.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.polys.len()
    }

    /// Where the pushes stand: polygons and points so far, for [`Self::truncate`].
    pub(super) fn mark(&self) -> (usize, usize) {
        (self.polys.len(), self.points.len())
    }

    /// Forgets the polygons pushed after `mark` (as if they never were).
    pub(super) fn truncate(&mut self, (polys, points): (usize, usize)) {
        self.polys.truncate(polys);
        self.points.truncate(points);
    }

    /// Whether the polygon pushed last is a shadow that covers every receiver polygon (pushed
    /// before any shadow) as [`Self::uncovered_area`] drops polygons: then it drops them all and
    /// the area is 0, whatever else is pushed, so a caller may stop there.
    pub(super) fn last_covers_receivers(&self) -> bool {
        let Some(last) = self.polys.len().checked_sub(1) else { return false };
        let receivers = self.polys.iter().take_while(|p| p.receiver).count();
        receivers > 0 && !self.polys[last].receiver && (0..receivers).all(|p| self.covers(last, p))
    }

    /// Snaps a polygon's vertices to the grid and pushes their convex hull; a receiver polygon
    /// (part of the region) or a shadow (taken away from it). Nothing is pushed when the snapped
    /// hull has no area. Polygons are counted in the order they are pushed (the order decides
    /// which of two edges on one line counts the segment they share, not the result).
    pub(super) fn push(&mut self, snap: &Snap, polygon: &[DVec2], receiver: bool) {
        self.snapped.clear();
        self.snapped.extend(polygon.iter().map(|&p| snap.point(p)));
        self.push_snapped(receiver);
    }

    /// Pushes already snapped points (their hull).
    pub(super) fn push_points(&mut self, points: &[Point], receiver: bool) {
        self.snapped.clear();
        self.snapped.extend_from_slice(points);
        self.push_snapped(receiver);
    }

    fn push_snapped(&mut self, receiver: bool) {
        let start = self.points.len();
        hull(&mut self.snapped, &mut self.points);
        if self.points.len() - start < 3 {
            self.points.truncate(start);
            return;
        }
        let vertices = &self.points[start..];
        let lo = vertices.iter().fold([i64::MAX; 2], |m, p| [m[0].min(p[0]), m[1].min(p[1])]);
        let hi = vertices.iter().fold([i64::MIN; 2], |m, p| [m[0].max(p[0]), m[1].max(p[1])]);
        self.polys.push(Poly { start: start as u32, end: self.points.len() as u32, lo, hi, receiver });
    }

    /// Snapped points of a polygon as pushed (for outlines made once).
    pub(super) fn snapped(snap: &Snap, polygon: &[DVec2]) -> Vec<Point> {
        polygon.iter().map(|&p| snap.point(p)).collect()
    }

    /// Area (grid units²) of what lies inside some receiver polygon and inside no shadow.
    ///
    /// Forgets the polygons that cannot change it, now or after more pushes: those inside one
    /// shadow (a leaf's shadow within a wall's, a receiver triangle in full shade).
    pub(super) fn uncovered_area(&mut self) -> f64 {
        self.drop_apart();
        self.build_buckets();
        // In a crowded canopy most leaves' shadows lie inside another's; the boundary step's
        // cost grows with the polygons near each one, so those go first.
        if self.drop_covered() {
            self.build_buckets();
        }
        if !self.polys.iter().any(|p| p.receiver) {
            return 0.0;
        }
        let receivers = self.polys.iter().filter(|p| p.receiver).fold(([i64::MAX; 2], [i64::MIN; 2]), |(lo, hi), p| {
            ([lo[0].min(p.lo[0]), lo[1].min(p.lo[1])], [hi[0].max(p.hi[0]), hi[1].max(p.hi[1])])
        });
        let mut total = 0.0;
        for p in 0..self.polys.len() {
            let poly = self.polys[p];
            // A shadow counts only where a receiver lies on its outer side.
            if !poly.receiver && !boxes_overlap(poly.lo, poly.hi, receivers.0, receivers.1) {
                continue;
            }
            // The polygons near this one, once for all its edges.
            self.collect_candidates(p, poly.lo, poly.hi);
            for k in poly.start..poly.end {
                let a = self.points[k as usize];
                let b = self.points[if k + 1 == poly.end { poly.start } else { k + 1 } as usize];
                total += self.edge_integral(p, a, b);
            }
        }
        total
    }

    /// `∫ x dy` over the parts of polygon `p`'s edge `a → b` that bound the region, signed by
    /// which side the region is on; `self.candidates` holds the polygons near `p`.
    fn edge_integral(&mut self, p: usize, a: Point, b: Point) -> f64 {
        let own = self.polys[p];
        let lo = [a[0].min(b[0]), a[1].min(b[1])];
        let hi = [a[0].max(b[0]), a[1].max(b[1])];
        self.events.clear();
        // The polygon itself covers its edge's left side; so do those that cover it from its start.
        let mut count = [0i32; 8];
        count[if own.receiver { 0 } else { 2 }] = 1;
        let (events, points) = (&mut self.events, &self.points);
        // The counters that leave no region beside the edge: a shadow on its outer side for a
        // shadow's edge, on both sides for a receiver's.
        let zeroing = if own.receiver { SHADOW_LEFT | SHADOW_RIGHT } else { SHADOW_RIGHT };
        let mut shaded = 0u64;
        for near in &self.candidates {
            if !boxes_overlap(lo, hi, near.lo, near.hi) {
                continue;
            }
            let Some((t0, t1, side)) = cover(&points[near.start as usize..near.end as usize], a, b) else { continue };
            let (left, right) = if near.receiver { (RECEIVER_LEFT, RECEIVER_RIGHT) } else { (SHADOW_LEFT, SHADOW_RIGHT) };
            let mut counters = match side {
                Side::Both => left | right,
                Side::Left => left,
                Side::Right => right,
            };
            if side != Side::Both && (near.poly as usize) < p {
                counters |= EARLIER_EDGE;
            }
            // Where this cover holds, every piece is 0: once such covers hold all of the edge,
            // so is its integral, whatever the rest add.
            if counters & EARLIER_EDGE != 0 || counters & zeroing == zeroing {
                shaded |= slots_within(t0, t1);
                if shaded == u64::MAX {
                    return 0.0;
                }
            }
            // Ends at the edge's ends move the counters before or after every piece, so they
            // need no events (most leaves' edges lie across a receiver triangle, end to end).
            if t0 <= 0.0 {
                for (c, &m) in count.iter_mut().zip(&COUNTER_BITS[usize::from(counters & 31)]) {
                    *c += m;
                }
            } else {
                events.push((t0, counters, 1));
            }
            if t1 < 1.0 {
                events.push((t1, counters, -1));
            }
        }
        // Parameters are ≥ 0 (never −0: see `cover`), so their bits sort as they do.
        self.events.sort_unstable_by_key(|e| e.0.to_bits());
        let (ax, dx, dy) = (a[0] as f64, (b[0] - a[0]) as f64, (b[1] - a[1]) as f64);
        let piece = |count: &[i32; 8], t0: f64, t1: f64| -> f64 {
            if t1 <= t0 || count[4] > 0 {
                return 0.0;
            }
            let inside_left = count[0] > 0 && count[2] == 0;
            let inside_right = count[1] > 0 && count[3] == 0;
            let sign = f64::from(i8::from(inside_left) - i8::from(inside_right));
            if sign == 0.0 {
                return 0.0;
            }
            sign * (ax + 0.5 * (t0 + t1) * dx) * (t1 - t0) * dy
        };
        let mut total = 0.0;
        let mut at = 0.0;
        for &(t, counters, step) in &self.events {
            total += piece(&count, at, t);
            // Without branches (which counters move is unpredictable), eight lanes at once.
            let moved = &COUNTER_BITS[usize::from(counters & 31)];
            for (c, &m) in count.iter_mut().zip(moved) {
                *c += i32::from(step) * m;
            }
            if t > at {
                at = t;
            }
        }
        total + piece(&count, at, 1.0)
    }

    /// Drops every shadow whose box lies apart from every receiver polygon's box (on a wall
    /// around a window, the shadows that fall in the window's hole, and any in the margin the
    /// shadows are clipped to: a sixth of a city floor's), leaving the area the same to the bit.
    /// Such a shadow meets no receiver, so it takes no area away and its own edges add 0 (no
    /// receiver beside them); where it covers another polygon's edge no receiver lies within a
    /// grid unit, so its ends there only split pieces of that edge that add 0, and its covers
    /// only end early an edge whose pieces add 0. A shadow inside one of these is apart too, so
    /// [`Self::drop_covered`] loses no container it would have used.
    fn drop_apart(&mut self) {
        let mut boxes = std::mem::take(&mut self.receiver_boxes);
        boxes.clear();
        boxes.extend(self.polys.iter().filter(|p| p.receiver).map(|p| (p.lo, p.hi)));
        let near = |p: &Poly| p.receiver || boxes.iter().any(|&(lo, hi)| boxes_overlap(p.lo, p.hi, lo, hi));
        self.polys.retain(near);
        self.receiver_boxes = boxes;
    }

    /// Drops every polygon that lies inside one shadow (its bounds and its vertices, exactly on
    /// the grid); `true` when any was dropped (the buckets are then stale).
    ///
    /// The region `∪ receivers − ∪ shadows` stays the same set: a receiver inside a shadow adds
    /// nothing to it, a shadow inside another takes nothing more away. Of polygons that cover
    /// each other (equal sets) the first pushed stays, so a chain of containers always ends at
    /// one kept: each step goes to a strictly larger set or, an equal one, pushed earlier.
    fn drop_covered(&mut self) -> bool {
        let mut keep = std::mem::take(&mut self.keep);
        keep.clear();
        // Neighbouring leaves, pushed one after another, mostly lie inside the same shadow.
        let mut last = None;
        keep.extend((0..self.polys.len()).map(|p| {
            let container = last.filter(|&q| self.covers(q, p)).or_else(|| self.container(p));
            last = container.or(last);
            container.is_none()
        }));
        let dropped = keep.iter().any(|&k| !k);
        if dropped {
            let mut flags = keep.iter();
            self.polys.retain(|_| flags.next().copied().unwrap_or(true));
        }
        self.keep = keep;
        dropped
    }

    /// Whether shadow `q` covers polygon `p` so that `p` may go (see [`Self::drop_covered`]).
    fn covers(&self, q: usize, p: usize) -> bool {
        let (poly, other) = (&self.polys[p], &self.polys[q]);
        let inner = &self.points[poly.start as usize..poly.end as usize];
        let outer = &self.points[other.start as usize..other.end as usize];
        box_within(poly.lo, poly.hi, other.lo, other.hi)
            && q != p
            && !other.receiver
            && convex_contains(outer, inner)
            // Equal sets: only the later one goes.
            && (q < p || other.lo != poly.lo || other.hi != poly.hi || !convex_contains(inner, outer))
    }

    /// A shadow that covers polygon `p` (see [`Self::covers`]), if any.
    fn container(&self, p: usize) -> Option<usize> {
        let b = self.buckets;
        if b.n[0] == 0 {
            return (0..self.polys.len()).find(|&q| self.covers(q, p));
        }
        // A container's bounds hold `lo`, so it is in that point's cell or, if big, in that point's
        // coarse cell (a container of a big polygon spans at least as many cells, so is big too).
        let [cx, cy, _, _] = self.spans[p];
        let cell = cy * b.n[0] + cx;
        let bucketed = &self.cell_near[self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize];
        let coarse = (cy / COARSE) * b.coarse_columns() + cx / COARSE;
        let big = &self.big_items[self.big_start[coarse] as usize..self.big_start[coarse + 1] as usize];
        // The boxes first, here: most candidates fail them, and that test is cheaper inline.
        let (lo, hi) = (self.polys[p].lo, self.polys[p].hi);
        // Receivers (big, around most boxes) never contain: skipped before the call.
        let boxed = |q: usize| !self.polys[q].receiver && box_within(lo, hi, self.polys[q].lo, self.polys[q].hi);
        let found = |list: &[u32]| list.iter().map(|&q| q as usize).find(|&q| boxed(q) && self.covers(q, p));
        // A cell's polygons go by their boxes' left sides: past `lo`'s, none holds it.
        let in_cell = || {
            let holding = bucketed.iter().take_while(|n| n.lo[0] <= lo[0]);
            holding.filter(|n| !n.receiver && box_within(lo, hi, n.lo, n.hi)).map(|n| n.poly as usize).find(|&q| self.covers(q, p))
        };
        found(big).or_else(in_cell)
    }

    /// Polygons other than `own` whose boxes overlap `[lo, hi]` into `self.candidates`.
    fn collect_candidates(&mut self, own: usize, lo: Point, hi: Point) {
        self.candidates.clear();
        let b = self.buckets;
        if b.n[0] == 0 {
            let hits = self.polys.iter().enumerate().filter(|&(i, q)| i != own && boxes_overlap(lo, hi, q.lo, q.hi));
            self.candidates.extend(hits.map(|(i, q)| Near::of(i, q)));
            return;
        }
        let [x0, y0, x1, y1] = self.spans[own];
        self.collect_big(own, lo, hi);
        // A polygon sharing several buckets with `own` is taken in one: the bucket holding the
        // two boxes' common lower corner (as in `collect_big`).
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let cell = cy * b.n[0] + cx;
                for near in &self.cell_near[self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize] {
                    if near.lo[0] > hi[0] {
                        break;
                    }
                    if boxes_overlap(lo, hi, near.lo, near.hi) && near.poly as usize != own {
                        let [qx, qy, _, _] = self.spans[near.poly as usize];
                        if cx == x0.max(qx) && cy == y0.max(qy) {
                            self.candidates.push(*near);
                        }
                    }
                }
            }
        }
        // Not in push order, but the sums do not depend on the order the counters move in.
    }

    /// The big polygons other than `own` whose boxes overlap `[lo, hi]` into `self.candidates`.
    /// A big polygon lies in every coarse bucket its box spans, so it may share several with
    /// `own`; it is taken in one: the coarse bucket holding the two boxes' common lower corner
    /// (per axis the later of their first coarse buckets, as buckets are found by a monotone
    /// division: scanned here exactly when it is `own`'s first or the other's).
    fn collect_big(&mut self, own: usize, lo: Point, hi: Point) {
        let columns = self.buckets.coarse_columns();
        let [x0, y0, x1, y1] = self.spans[own].map(|c| c / COARSE);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let coarse = cy * columns + cx;
                for k in self.big_start[coarse]..self.big_start[coarse + 1] {
                    let q = self.big_items[k as usize] as usize;
                    let [qx, qy, _, _] = self.spans[q].map(|c| c / COARSE);
                    let met_here = (cx == x0 || cx == qx) && (cy == y0 || cy == qy);
                    let poly = &self.polys[q];
                    if met_here && q != own && boxes_overlap(lo, hi, poly.lo, poly.hi) {
                        self.candidates.push(Near::of(q, poly));
                    }
                }
            }
        }
    }

    /// Buckets the polygons by their boxes when there are many (else `buckets.n = [0, 0]`).
    fn build_buckets(&mut self) {
        let n = self.polys.len();
        if n <= SCAN_ALL {
            self.buckets = Buckets::default();
            return;
        }
        let lo = self.polys.iter().fold([i64::MAX; 2], |m, p| [m[0].min(p.lo[0]), m[1].min(p.lo[1])]);
        let hi = self.polys.iter().fold([i64::MIN; 2], |m, p| [m[0].max(p.hi[0]), m[1].max(p.hi[1])]);
        let extent = [(hi[0] - lo[0]).max(1), (hi[1] - lo[1]).max(1)];
        let buckets = Buckets::over(lo, extent, self.typical_side(), n);
        self.buckets = buckets;
        let cells = buckets.n[0] * buckets.n[1];
        self.spans.clear();
        self.spans.extend(self.polys.iter().map(|p| {
            let (c0, c1) = (buckets.cell(p.lo), buckets.cell(p.hi));
            [c0[0], c0[1], c1[0], c1[1]]
        }));
        let spans = &self.spans;
        let small = || spans.iter().enumerate().filter(|(_, s)| !is_big(s)).map(|(i, &s)| (i as u32, s));
        fill_cells(buckets.n[0], cells, small, &mut self.cell_start, &mut self.cell_items, &mut self.next_slot);
        self.cell_near.clear();
        let polys = &self.polys;
        self.cell_near.extend(self.cell_items.iter().map(|&q| Near::of(q as usize, &polys[q as usize])));
        for c in 0..cells {
            self.cell_near[self.cell_start[c] as usize..self.cell_start[c + 1] as usize].sort_unstable_by_key(|n| n.lo[0]);
        }
        // The big ones in coarse buckets of COARSE × COARSE buckets.
        let columns = buckets.coarse_columns();
        let coarse_cells = columns * buckets.n[1].div_ceil(COARSE);
        let big = || spans.iter().enumerate().filter(|(_, s)| is_big(s)).map(|(i, s)| (i as u32, s.map(|c| c / COARSE)));
        fill_cells(columns, coarse_cells, big, &mut self.big_start, &mut self.big_items, &mut self.next_slot);
    }

    /// The median of the polygons' longer box sides (the typical leaf's shadow among many).
    fn typical_side(&mut self) -> i64 {
        let mut sides = std::mem::take(&mut self.sides);
        sides.clear();
        sides.extend(self.polys.iter().map(|p| (p.hi[0] - p.lo[0]).max(p.hi[1] - p.lo[1])));
        let middle = sides.len() / 2;
        let typical = (*sides.select_nth_unstable(middle).1).max(1);
        self.sides = sides;
        typical
    }
}

impl Buckets {
    /// Square buckets over `extent` from `lo`: [`BUCKET_PER_TYPICAL`] of a typical polygon's side,
    /// fewer where that would make more than [`BUCKETS_PER_POLYGON`] a polygon or [`MAX_BUCKETS`].
    fn over(lo: Point, extent: Point, typical: i64, polygons: usize) -> Self {
        let area = extent[0] as f64 * extent[1] as f64;
        let most = (BUCKETS_PER_POLYGON * polygons as f64).min(MAX_BUCKETS as f64);
        let fewest = (area / most).sqrt().ceil();
        let size = ((typical as f64 * BUCKET_PER_TYPICAL).max(fewest) as i64).max(1);
        let along = |k: usize| (extent[k] / size + 1) as usize;
        Self { n: [along(0), along(1)], origin: lo, size }
    }

    /// Coarse buckets per row.
    fn coarse_columns(&self) -> usize {
        self.n[0].div_ceil(COARSE)
    }

    /// The cell holding grid point `p` (clamped to the grid of cells).
    fn cell(&self, p: Point) -> [usize; 2] {
        let c = |k: usize| (((p[k] - self.origin[k]) / self.size).max(0) as usize).min(self.n[k] - 1);
        [c(0), c(1)]
    }
}

/// Whether a polygon over these buckets (`[x0, y0, x1, y1]`) is kept out of them (see [`BIG_SPAN`]).
fn is_big(&[x0, y0, x1, y1]: &[usize; 4]) -> bool {
    (x1 - x0 + 1) * (y1 - y0 + 1) > BIG_SPAN
}

/// A counting sort of polygons into the cells of a grid `columns` wide: `start` gets per cell
/// its range of `items` (prefix sums), `items` each cell's polygons in the order `spans` gives
/// them. `spans` yields each polygon's index and the cells its box spans, `[x0, y0, x1, y1]`,
/// once to count and once to fill; `next` is scratch.
fn fill_cells<I: Iterator<Item = (u32, [usize; 4])>>(
    columns: usize,
    cells: usize,
    spans: impl Fn() -> I,
    start: &mut Vec<u32>,
    items: &mut Vec<u32>,
    next: &mut Vec<u32>,
) {
    start.clear();
    start.resize(cells + 1, 0);
    for (_, [x0, y0, x1, y1]) in spans() {
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                start[cy * columns + cx + 1] += 1;
            }
        }
    }
    for c in 0..cells {
        start[c + 1] += start[c];
    }
    items.clear();
    items.resize(start[cells] as usize, 0);
    next.clear();
    next.extend_from_slice(&start[..cells]);
    for (i, [x0, y0, x1, y1]) in spans() {
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let cell = cy * columns + cx;
                items[next[cell] as usize] = i;
                next[cell] += 1;
            }
        }
    }
}

/// Whether the box `[lo, hi]` lies within `[lo2, hi2]`.
fn box_within(lo: Point, hi: Point, lo2: Point, hi2: Point) -> bool {
    lo2[0] <= lo[0] && lo2[1] <= lo[1] && hi[0] <= hi2[0] && hi[1] <= hi2[1]
}

/// Whether every point of `inner` lies inside or on the convex counter-clockwise polygon
/// `outer` (so the hull of `inner` does); exact.
fn convex_contains(outer: &[Point], inner: &[Point]) -> bool {
    // Each edge from the vertex before, as in `cover`.
    let Some(&last) = outer.last() else { return true };
    let mut before = last;
    outer.iter().all(|&q1| {
        let q0 = std::mem::replace(&mut before, q1);
        inner.iter().all(|&v| orient(q0, q1, v) >= 0)
    })
}

/// The slots `[k/64, (k+1)/64]` of an edge's parameter that lie within `[t0, t1]`, as bits.
fn slots_within(t0: f64, t1: f64) -> u64 {
    // Truncation is the floor here (both are ≥ 0); the first whole slot starts at the ceiling.
    let (from, end) = (t0 * 64.0, (t1 * 64.0) as u32);
    let first = from as u32 + u32::from(f64::from(from as u32) < from);
    if first >= end {
        return 0;
    }
    let below_end = if end >= 64 { u64::MAX } else { (1u64 << end) - 1 };
    below_end & !((1u64 << first) - 1)
}

fn boxes_overlap(lo: Point, hi: Point, lo2: Point, hi2: Point) -> bool {
    lo[0] <= hi2[0] && lo2[0] <= hi[0] && lo[1] <= hi2[1] && lo2[1] <= hi[1]
}

/// Twice the signed area of `o, a, b` (positive when `b` lies left of `o → a`); exact.
fn orient(o: Point, a: Point, b: Point) -> i64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Where the convex counter-clockwise polygon `q` covers the segment `a → b`: the parameter
/// interval (`0` at `a`, `1` at `b`) and which sides, or `None` when it covers at most a point.
fn cover(q: &[Point], a: Point, b: Point) -> Option<(f64, f64, Side)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let mut side = Side::Both;
    // Each edge from the vertex before (the last closes on the first): no index arithmetic in
    // this loop, the hottest of the engine. The result does not depend on the edges' order.
    let mut before = *q.last()?;
    for &q1 in q {
        let q0 = std::mem::replace(&mut before, q1);
        let (oa, ob) = (orient(q0, q1, a), orient(q0, q1, b));
        if oa > 0 && ob > 0 {
            continue;
        }
        if oa <= 0 && ob <= 0 {
            if oa == 0 && ob == 0 {
                // On this edge's line: the polygon lies on the edge's left, so on the segment's
                // left when both run the same way.
                let same = (b[0] - a[0]) * (q1[0] - q0[0]) + (b[1] - a[1]) * (q1[1] - q0[1]) > 0;
                side = if same { Side::Left } else { Side::Right };
                continue;
            }
            return None;
        }
        // Signs differ: the segment crosses this edge's line once.
        let t = oa as f64 / (oa - ob) as f64;
        // Compared, not `min`/`max`: `t` may be −0 (where `oa` is 0), which must not replace 0.
        if oa > 0 {
            if t < t1 {
                t1 = t;
            }
        } else if t > t0 {
            t0 = t;
        }
        if t0 >= t1 {
            return None;
        }
    }
    Some((t0, t1, side))
}

/// Andrew's monotone chain on grid points (exact): the hull of `points` (sorted in place)
/// appended to `out`, counter-clockwise, without collinear or repeated points.
fn hull(points: &mut [Point], out: &mut Vec<Point>) {
    let base = out.len();
    // A triangle (most shadows): sorted by three swaps, turned counter-clockwise, as the chain
    // below would give it; collinear ones take the chain.
    if let [a, b, c] = points {
        super::objects::sort3(a, b, c, |x, y| x < y);
        match orient(*a, *b, *c).signum() {
            1 => return out.extend_from_slice(&[*a, *b, *c]),
            -1 => return out.extend_from_slice(&[*a, *c, *b]),
            _ => {}
        }
    }
    if points.is_empty() {
        return;
    }
    points.sort_unstable();
    let push = |out: &mut Vec<Point>, q: Point, floor: usize| {
        while out.len() >= floor + 2 && orient(out[out.len() - 2], out[out.len() - 1], q) <= 0 {
            out.pop();
        }
        out.push(q);
    };
    for &q in points.iter() {
        push(out, q, base);
    }
    let lower = out.len() - 1;
    for &q in points.iter().rev().skip(1) {
        push(out, q, lower);
    }
    out.pop();
    // Fewer than three distinct points: whatever is left has no area, the caller drops it.
}

#[cfg(test)]
mod tests;
