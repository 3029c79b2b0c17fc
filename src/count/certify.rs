//! Certificates: proofs, without counting a view, that a receiver is wholly dark or wholly lit
//! at every sun direction of a set (the timesteps of one cell of the year's sample grid).
//!
//! Owns the two proofs and which casters may take part in them. They are geometry over the
//! scene's casters, so they live with the counting stage and share its index (the exact engine's
//! culling, world triangles and convex objects, [`super::exact`]); they do not depend on how
//! either engine counts, so the GPU, the exact reference and the page use the same ones. The
//! year ([`crate::year`]) only decides which steps to ask about.
//!
//! Both start from a [`DirectionCone`] holding every sun of the set ([`cone`]).
//! - **Dark**: one opaque convex caster `O` lies wholly in front of the receiver's plane and, at
//!   every generator of the cone, the receiver's vertices project (along that direction) inside
//!   `O`'s projection by a margin. From a point outside a convex body the directions that hit it
//!   form a convex cone, so a receiver point hit at every generator is hit at every direction
//!   in between: the receiver is wholly shaded at every sun of the set. The fraction is 0.
//!   Where no one caster does, the set's suns are halved (across their widest extent, up to
//!   [`DARK_HALVINGS`] times) and each half proved so over its own cone: the cover may pass
//!   from one caster to another between two suns of the set. The casters may be composites
//!   ([`composite`]): coplanar panels that together form one convex polygon. With those
//!   many-caster proofs, a caster that comes nearer the receiver's plane than the margin (a
//!   facade meeting it at an inner corner) takes part by its convex part twice the margin in
//!   front ([`clipped_in_front`]), so its shadows are still cast the margin in front. With
//!   [`Certifier::with_inner_corners`] as well (off by default), a receiver's corners lying on
//!   such a composite (its edge along the inner corner) are covered with no margin, since every
//!   ray from them starts on the caster.
//! - **Lit**: no triangle but the receiver's own lies in the volume its points sweep along the
//!   cone's directions (`R + K`, convex, since the receiver's triangles and the cone are). A
//!   triangle `T` misses it when it lies behind the receiver's plane (within the exact engine's
//!   tolerance, as both engines treat it), below the receiver's lowest point while every sun is
//!   up, or when a plane through the origin separates the cone from the vectors `T − R` (a face
//!   of either cone in the chart). Every such triangle counts, see-through or leaf or not: the
//!   fraction is then exactly 1.
//! - Otherwise: no certificate, and the steps are counted.
//! - **Never dark** ([`Certifier::unproved_lit`], [`never_dark`]), for steps the year would
//!   interpolate: a disc of the receiver holding [`MIN_LIT_SHARE`] of its area is clear of every
//!   caster's footprint over the cone, so the fraction is above EnergyPlus's 1e-5 at every sun
//!   of the set. The disc is looked for past a union of casters, on the receiver's polygon, not
//!   its triangles.
//!
//! Which casters qualify for *dark*: objects the exact engine finds convex ([`super::exact`]'s
//! objects: a closed convex polyhedron or a flat convex polygon; up to 64 triangles any such,
//! up to 65,536 if they lie in at most 64 planes and share corners bit for bit, as a panelled
//! block does), opaque (no foliage, no transmittance); and *composite* casters ([`composite`]):
//! opaque panels of any objects, receivers or not, in one axis-aligned plane whose union is
//! proved to be one convex polygon with no gap (shared corners bit for bit, every inner edge
//! used twice): a facade of per-floor walls and windows, the faces of blocks built flush. One with open caps (a block without a
//! floor) qualifies only for a receiver strictly inside every cap's plane (above the ground),
//! since a ray could otherwise pass through the openings. A caster that is not convex, open to
//! the receiver, seen edge-on (its projection has no area) or see-through never proves a step
//! dark; it only stops a step being proved lit.

mod cells;
pub(crate) mod composite;
pub mod cone;
mod never_dark;

use std::rc::Rc;
use std::sync::Arc;

use glam::{DVec2, DVec3};

pub use cone::DirectionCone;
pub use never_dark::MIN_LIT_SHARE;
use never_dark::Outline;

use crate::count::MIN_COS_INCIDENCE;
use crate::count::exact::engine::{ExactEngine, parallel_chunks, worker_threads};
use crate::count::view::{self, convex_hull, perpendicular_basis};
use crate::scene::{NO_RECEIVER, Scene};

/// What a certificate proves for every sun of its set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Certificate {
    /// Wholly shaded: fraction 0.
    Dark,
    /// Nothing can shade it: fraction 1.
    Lit,
}

/// A certificate and how it was found: `alone` where the single-caster proofs would find it too
/// (a lit proof, or one convex object standing wholly in front of the receiver's plane covering
/// it over the whole cell), false where it needed the many-caster proofs
/// ([`Certifier::with_many_casters`]). The year keeps its refinement's pattern to what the
/// single-caster proofs settle, so the many-caster ones save views without moving a value
/// (docs/energyplus-fidelity.md, "Proofs that move no value").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Proof {
    /// What is proved.
    pub certificate: Certificate,
    /// Whether the single-caster proofs find it too.
    pub alone: bool,
}

/// Which certificates to look for (each costs a search; a caller skips one that its samples
/// make unlikely).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Wanted {
    /// Look for a convex caster that covers the receiver.
    pub dark: bool,
    /// Look for an empty swept volume.
    pub lit: bool,
}

/// Margin, in scene extents, by which a covered receiver lies inside its caster's shadow and
/// the caster in front of its plane: the GPU works in f32 relative to the scene's origin, so a
/// shadow edge within this of the receiver's could round either way (the culling's tolerance).
const COVER_MARGIN: f64 = 1e-6;

/// Heights above a receiver's plane within this many scene extents count as on it: the exact
/// engine's tolerance (`PLANE_EPS`), the smaller of the two engines', so what is ignored here
/// both engines ignore.
const PLANE_TOLERANCE: f64 = 1e-9;

/// Vectors of `T − R` whose cosine with the cone's axis is below this are not charted: the
/// separating faces of their cone are then looked for among the direction cone's faces only.
const MIN_CHART_COS: f64 = 1e-3;

/// A lit proof is not looked for where the swept volume reaches more triangles than this (a
/// city's street seen along a low sun): its cost would exceed the views it saves.
const MAX_SWEPT: usize = 20_000;

/// A swept volume is first searched this far (in scene extents, plus one unit) along the cone.
const NEAR_REACH: f64 = 0.02;

/// What a swept volume holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sweep {
    /// Nothing but the receiver.
    Empty,
    /// A triangle that may shade it.
    Blocked,
    /// More than [`MAX_SWEPT`] triangles: not searched.
    TooMany,
}

/// Times a dark proof halves a cell's suns where no one caster covers the receiver over all of
/// them (at most 2^(n+1) − 1 proofs a cell, fewer where a half fails).
const DARK_HALVINGS: usize = 3;

/// Sets of suns certified per thread hand-out.
const CHUNK: usize = 8;

/// A receiver as the certificates need it.
#[derive(Debug, Default)]
struct Shape {
    /// Its triangles' vertices.
    points: Vec<DVec3>,
    normal: DVec3,
    /// A vertex: the plane's origin and the frame's origin for projections.
    p0: DVec3,
    lowest: f64,
    gpu_id: u32,
    /// Its polygon for the never-dark proof ([`never_dark`]); None where it has no area.
    outline: Option<Outline>,
}

/// Whether the receiver has points and every one of `suns` is up and in front of it, as the
/// year's steps are.
fn up_and_in_front(shape: &Shape, suns: &[DVec3]) -> bool {
    !shape.points.is_empty() && suns.iter().all(|s| s.z >= MIN_COS_INCIDENCE && s.dot(shape.normal) > MIN_COS_INCIDENCE)
}

/// Whether the whole cone, not just the suns it was built on, lies in front of the receiver and
/// above the horizon (every proof assumes both).
fn in_front(shape: &Shape, cone: &DirectionCone) -> bool {
    cone.generators().iter().all(|g| g.dot(shape.normal) > 0.0 && g.z > 0.0)
}

/// The exact engine's index of the scene: the certifier's own, or one an engine built.
enum Index<'a> {
    Own(Box<ExactEngine>),
    Shared(&'a ExactEngine),
}

impl std::ops::Deref for Index<'_> {
    type Target = ExactEngine;

    fn deref(&self) -> &ExactEngine {
        match self {
            Index::Own(index) => index,
            Index::Shared(index) => index,
        }
    }
}

/// A caster that may prove a receiver dark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Caster {
    /// One of the exact engine's convex objects.
    Object(u32),
    /// Coplanar panels forming one flat convex polygon ([`composite`]).
    Composite(u32),
}

/// The certificates of one scene. Build once, then ask [`Self::certify`].
pub struct Certifier<'a> {
    index: Index<'a>,
    /// The receivers' shapes, shared with the single-caster view ([`Self::single_casters`]).
    shapes: Arc<Vec<Shape>>,
    extent: f64,
    /// Whether a dark proof may combine casters (composites, halves of a cell); the year asks
    /// for it by default (docs/energyplus-fidelity.md, "certs13").
    many_casters: bool,
    /// With `many_casters`: whether a receiver's corners lying on a composite that meets its
    /// plane count as covered by it ([`Self::with_inner_corners`]).
    inner_corners: bool,
}

/// The candidates of the last set one thread certified, made ready ([`Certifier::ready`]) for
/// its receiver: the next set of the same receiver (the next cell of its year) shares most of
/// them, and making a panelled block ready (gathering its corners, testing its caps) was nearly
/// half of a city's certificate stage. Both lists are sorted, so they are matched by one walk;
/// a hash map of every caster a receiver ever met cost more than it saved on blaas-trees-summer.
#[derive(Debug, Default)]
struct ReadyCache {
    receiver: Option<usize>,
    casters: Vec<(Caster, Option<Rc<Ready>>)>,
}

impl ReadyCache {
    /// `candidates` (sorted, distinct) made ready for `receiver` by `make`, those the last set of
    /// the same receiver had taken from it; it then holds these.
    fn ready(&mut self, receiver: usize, candidates: &[Caster], make: impl Fn(Caster) -> Option<Ready>) -> Vec<Rc<Ready>> {
        let last = std::mem::take(&mut self.casters);
        let last = if self.receiver == Some(receiver) { last } else { Vec::new() };
        self.receiver = Some(receiver);
        let mut old = last.into_iter().peekable();
        for &c in candidates {
            while old.next_if(|(o, _)| *o < c).is_some() {}
            let ready = match old.next_if(|(o, _)| *o == c) {
                Some((_, ready)) => ready,
                None => make(c).map(Rc::new),
            };
            self.casters.push((c, ready));
        }
        self.casters.iter().filter_map(|(_, r)| r.clone()).collect()
    }
}

/// A caster made ready for one receiver ([`Certifier::ready`]): what a cell's halves share.
#[derive(Debug)]
struct Ready {
    /// Its corners (clipped where it meets the receiver's plane), relative to the receiver's
    /// first vertex.
    corners: Vec<DVec3>,
    /// Per receiver point: whether it lies on the caster itself (an inner corner's contact,
    /// [`Certifier::with_inner_corners`]), so that every ray from it meets the caster at its
    /// start, whatever the sun. Empty where none does.
    on_caster: Vec<bool>,
    /// Whether the single-caster proofs would take it as it is: a convex object wholly in front
    /// of the receiver's plane by the margin, not clipped and not a composite.
    alone: bool,
}

impl Ready {
    /// Whether receiver point `k` lies on the caster.
    fn on_caster(&self, k: usize) -> bool {
        self.on_caster.get(k).copied().unwrap_or(false)
    }
}

impl Certifier<'static> {
    /// Indexes `scene` (the exact engine's culling and convex objects).
    pub fn new(scene: &Scene) -> Self {
        Certifier::with_index(scene, Index::Own(Box::new(ExactEngine::new(scene))))
    }
}

impl<'a> Certifier<'a> {
    /// Certifies over `index`, the exact engine's index of `scene` that an engine already built
    /// (on a city, building a second one cost as much as the proofs).
    pub fn sharing(scene: &Scene, index: &'a ExactEngine) -> Self {
        Certifier::with_index(scene, Index::Shared(index))
    }

    fn with_index(scene: &Scene, index: Index<'a>) -> Self {
        let extent = (scene.bounds.1 - scene.bounds.0).length();
        let extent = if extent.is_finite() { extent } else { 0.0 };
        let shapes = scene
            .receivers
            .iter()
            .map(|r| {
                let points: Vec<DVec3> = r.triangles.iter().flatten().copied().collect();
                let lowest = points.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
                let outline = Outline::new(&r.triangles, r.normal);
                Shape { p0: points.first().copied().unwrap_or_default(), points, normal: r.normal, lowest, gpu_id: r.gpu_id, outline }
            })
            .collect();
        Self { index, shapes: Arc::new(shapes), extent, many_casters: false, inner_corners: false }
    }

    /// Lets the dark proof combine casters: composite casters ([`composite`]), halves of a
    /// cell each covered by its own caster, and casters meeting the receiver's plane by their
    /// part clear of it ([`clipped_in_front`]). Exact either way; the year's default since
    /// certs13's paired gates (docs/energyplus-fidelity.md, "certs13").
    pub fn with_many_casters(mut self) -> Self {
        // The composites are found once per index, when a proof first asks for them (not here:
        // the year's pilot may drop these proofs before any does).
        self.many_casters = true;
        self
    }

    /// This certifier without the many-caster proofs (over the same index and shapes, built
    /// again for nothing): what it proves is what [`Proof::alone`] marks. The year tries the
    /// many-caster proofs on a sample of its cells and keeps them only where they pay there.
    pub fn single_casters(&self) -> Certifier<'_> {
        let index = Index::Shared(&self.index);
        Certifier { index, shapes: Arc::clone(&self.shapes), extent: self.extent, many_casters: false, inner_corners: false }
    }

    /// Whether the many-caster proofs are on ([`Self::with_many_casters`]).
    pub fn has_many_casters(&self) -> bool {
        self.many_casters
    }

    /// With the many-caster proofs ([`Self::with_many_casters`]): a receiver's corner that lies
    /// on a composite meeting the receiver's plane (the facade of a tower's other arm, at the
    /// inner corner: [`composite::Composites::holds`], exact, no tolerance) is covered by it at
    /// every sun, with no margin, and the receiver's other corners as before (inside the clipped
    /// part's shadow by the margin). The shadow of the composite's part in front of the plane is
    /// convex and holds both, so it holds the receiver: its lit area is 0. Off by default: the
    /// exact engines agree (the CSV unchanged), but the GPU's rounding along a shadow edge that
    /// is the receiver's own edge is not shown (docs/energyplus-fidelity.md, "certs13").
    pub fn with_inner_corners(mut self) -> Self {
        self.inner_corners = true;
        self
    }

    /// The scene's composite casters: its index's, found once however many certifiers share it.
    fn composites(&self) -> &composite::Composites {
        self.index.composites()
    }

    /// Certificates for many sets at once (receiver, its suns, what to look for), in order;
    /// natively over every core. A receiver's sets should come together: each thread keeps the
    /// casters it made ready for the last receiver it saw ([`ReadyCache`]).
    pub fn certify_all(&self, sets: &[(usize, &[DVec3], Wanted)]) -> Vec<Option<Proof>> {
        let threads = worker_threads().min(sets.len().div_ceil(CHUNK)).max(1);
        parallel_chunks(sets.len(), threads, CHUNK, ReadyCache::default, |i, cache| {
            self.certify_with(sets[i].0, sets[i].1, sets[i].2, cache)
        })
    }

    /// The receiver's shape and a cone holding `suns`, where a proof may be looked for: every
    /// sun up and in front of the receiver, and so the whole cone.
    fn cone_of(&self, receiver: usize, suns: &[DVec3]) -> Option<(&Shape, DirectionCone)> {
        let shape = self.shapes.get(receiver)?;
        if !up_and_in_front(shape, suns) {
            return None;
        }
        let cone = DirectionCone::enclosing(suns)?;
        in_front(shape, &cone).then_some((shape, cone))
    }

    /// A certificate that `receiver` is dark, or lit, at every one of `suns`; None where neither
    /// can be proved (count those views). Every sun must be up and in front of the receiver.
    pub fn certify(&self, receiver: usize, suns: &[DVec3], wanted: Wanted) -> Option<Certificate> {
        self.certify_with(receiver, suns, wanted, &mut ReadyCache::default()).map(|p| p.certificate)
    }

    /// [`Self::certify`], taking the casters made ready for `receiver` from `cache` where an
    /// earlier set of the same receiver made them ([`Self::ready`] does not depend on the suns).
    fn certify_with(&self, receiver: usize, suns: &[DVec3], wanted: Wanted, cache: &mut ReadyCache) -> Option<Proof> {
        if !(wanted.dark || wanted.lit) {
            return None;
        }
        let (shape, cone) = self.cone_of(receiver, suns)?;
        if wanted.lit && self.swept_is_empty(shape, &cone) {
            return Some(Proof { certificate: Certificate::Lit, alone: true });
        }
        if !wanted.dark {
            return None;
        }
        let candidates = self.cover_candidates(shape, &cone);
        // The halves are tried where the cell has two candidates or more, whether or not each
        // may cover this receiver at all (as before they were made ready once a cell).
        let halvings = if self.many_casters && candidates.len() >= 2 { DARK_HALVINGS } else { 0 };
        let ready = cache.ready(receiver, &candidates, |c| self.ready(shape, c));
        let dark = |alone| Some(Proof { certificate: Certificate::Dark, alone });
        // The single-caster proof first, so a certificate it finds says so.
        if ready.iter().any(|c| c.alone && self.covers_ready(shape, &cone, c)) {
            return dark(true);
        }
        // The rest (clipped casters, composites, then halves of the cell) only with the
        // many-caster proofs; the casters tried above are not tried over the whole cell again.
        if !self.many_casters {
            return None;
        }
        let mut set: Vec<usize> = (0..suns.len()).collect();
        let together = ready.iter().any(|c| !c.alone && self.covers_ready(shape, &cone, c))
            || self.halves_dark(shape, &ready, suns, &mut set, halvings);
        if together { dark(false) } else { None }
    }

    /// Whether the receiver is dark at every sun of `set` (indices into `suns`, enclosed by
    /// `cone`): one of `candidates` covers it over the whole cone, or, with `halvings` left, each
    /// half of the set (split across its widest extent, [`never_dark::split_widest`]) is so
    /// proved over its own cone. Each sun lies in a cone one caster covers, so it is dark: the
    /// cover may pass from one caster to another between the suns (a nearer block to a farther
    /// one). The halves try the whole cell's candidates (a search per half cost more than the
    /// proofs saved on a city): a caster that covers only a half and is not among them is
    /// missed, never wrongly trusted.
    ///
    /// `candidates` are made ready for the receiver ([`Self::ready`]): what does not depend on
    /// the cone is checked once a cell, not once a half.
    fn dark_in_parts(
        &self,
        shape: &Shape,
        candidates: &[Rc<Ready>],
        suns: &[DVec3],
        set: &mut [usize],
        cone: &DirectionCone,
        halvings: usize,
    ) -> bool {
        candidates.iter().any(|c| self.covers_ready(shape, cone, c)) || self.halves_dark(shape, candidates, suns, set, halvings)
    }

    /// With `halvings` left, whether each half of `set` is dark ([`Self::dark_in_parts`] over
    /// its own cone); false where none are left or the set has one sun.
    fn halves_dark(&self, shape: &Shape, candidates: &[Rc<Ready>], suns: &[DVec3], set: &mut [usize], halvings: usize) -> bool {
        if halvings == 0 || set.len() < 2 {
            return false;
        }
        never_dark::split_widest(suns, set);
        let (first, second) = set.split_at_mut(set.len() / 2);
        [first, second].into_iter().all(|half| {
            let part: Vec<DVec3> = half.iter().map(|&i| suns[i]).collect();
            // Inside the whole's cone, so in front of the receiver and above the horizon too.
            DirectionCone::enclosing(&part).is_some_and(|c| self.dark_in_parts(shape, candidates, suns, half, &c, halvings - 1))
        })
    }

    /// The opaque convex casters (objects and composites) that may cover the receiver over the
    /// cone: a caster that covers it at every direction of the cone is hit by the ray from each
    /// receiver point along the cone's axis, so it has a triangle in that one view's prism.
    fn cover_candidates(&self, shape: &Shape, cone: &DirectionCone) -> Vec<Caster> {
        let mut candidates: Vec<Caster> = Vec::new();
        let composites = self.many_casters.then(|| self.composites());
        let view = view::fit(&shape.points, cone.axis(), self.index.bounds, self.index.origin, 64);
        self.index.culling.visit_triangles(&view.view_proj, |r| {
            for p in r {
                if self.index.owner[p] == shape.gpu_id {
                    continue;
                }
                let object = self.opaque_convex(p).map(Caster::Object);
                let composite = composites.and_then(|c| c.of(p)).map(Caster::Composite);
                // An object's triangles come one after another: skip the repeats cheaply.
                for c in [object, composite].into_iter().flatten() {
                    if candidates.last() != Some(&c) {
                        candidates.push(c);
                    }
                }
            }
        });
        candidates.sort_unstable();
        candidates.dedup();
        candidates
    }

    #[cfg(test)]
    fn one_caster_covers(&self, shape: &Shape, cone: &DirectionCone) -> bool {
        self.cover_candidates(shape, cone).into_iter().any(|c| self.covers(shape, cone, c))
    }

    /// Whether no triangle but the receiver's own lies in the volume it sweeps along the cone;
    /// false (no proof) as well where that volume reaches more than [`MAX_SWEPT`] triangles.
    fn swept_is_empty(&self, shape: &Shape, cone: &DirectionCone) -> bool {
        self.sweep(shape, cone) == Sweep::Empty
    }

    /// What the volume the receiver sweeps along the cone holds. The first [`NEAR_REACH`] of it
    /// is looked at first: a caster close in front (a scrim's rod, a reveal) is found there with
    /// a small search, and whatever lies in that part lies in the whole.
    fn sweep(&self, shape: &Shape, cone: &DirectionCone) -> Sweep {
        let near = NEAR_REACH * (1.0 + self.extent);
        if near < self.reach(cone) && self.sweep_within(shape, cone, near) == Sweep::Blocked {
            return Sweep::Blocked;
        }
        self.sweep_within(shape, cone, self.reach(cone))
    }

    /// [`Self::sweep`] over the part of the volume within `reach` of the receiver along each
    /// generator (a convex volume holding every triangle point that far along the cone).
    fn sweep_within(&self, shape: &Shape, cone: &DirectionCone, reach: f64) -> Sweep {
        let view = view::fit(&self.swept_corners(&shape.points, cone, reach), cone.axis(), self.index.bounds, self.index.origin, 64);
        let mut reached = Vec::new();
        self.index.culling.visit_triangles(&view.view_proj, |r| reached.push(r));
        if reached.iter().map(|r| r.len()).sum::<usize>() > MAX_SWEPT {
            return Sweep::TooMany;
        }
        let mut w = Vec::new();
        let empty = reached.into_iter().flatten().all(|p| {
            (self.index.owner[p] == shape.gpu_id && shape.gpu_id != NO_RECEIVER)
                || self.misses(shape, cone, &self.index.triangles[p], &mut w)
        });
        if empty { Sweep::Empty } else { Sweep::Blocked }
    }

    /// How far along a generator the swept volume must reach to leave the scene's bounds.
    fn reach(&self, cone: &DirectionCone) -> f64 {
        // A direction d of the cone is Σ λ_k g_k with Σ λ_k ≤ |d| / min_k (g_k · axis); a point
        // of R + K in the bounds is at most the extent from its receiver point.
        let min_cos = cone.generators().iter().map(|g| g.dot(cone.axis())).fold(1.0, f64::min);
        (self.extent + 1.0) / min_cos * 1.01
    }

    /// Corners of a convex volume holding the part of `P + K` within `reach` along each
    /// generator, for the convex hull `P` of `points` (a receiver's vertices): the points and
    /// each moved along each generator by `reach`.
    fn swept_corners(&self, points: &[DVec3], cone: &DirectionCone, reach: f64) -> Vec<DVec3> {
        let mut out = points.to_vec();
        for g in cone.generators() {
            out.extend(points.iter().map(|p| *p + *g * reach));
        }
        out
    }

    /// The convex object at triangle position `p`, if it may prove a receiver dark: convex and
    /// opaque.
    fn opaque_convex(&self, p: usize) -> Option<u32> {
        let o = self.index.objects.of(p)?;
        let veil = self.index.veils[p];
        (veil.rank < 0.0 && veil.transmittance == 0.0).then_some(o)
    }

    /// Whether the receiver lies strictly inside the plane of each of object `o`'s open caps
    /// (by `margin`): a ray from it then crosses each cap's plane outward if at all, so it
    /// enters the convex solid through a triangle, never through an opening. A block without a
    /// floor, for any receiver above the ground.
    fn caps_face_away(&self, shape: &Shape, o: u32, margin: f64) -> bool {
        let corners = self.index.objects.corners(o);
        let centre = corners.iter().map(|&c| self.index.corner(c) - shape.p0).sum::<DVec3>() / corners.len().max(1) as f64;
        self.index.objects.caps(o).all(|cap| {
            let at: Vec<DVec3> = cap.iter().map(|&c| self.index.corner(c) - shape.p0).collect();
            // Newell's normal of the cap's loop, turned away from the solid.
            let newell = (0..at.len()).fold(DVec3::ZERO, |n, i| n + at[i].cross(at[(i + 1) % at.len()]));
            let Some(m) = newell.try_normalize() else { return false };
            let m = if m.dot(centre - at[0]) > 0.0 { -m } else { m };
            shape.points.iter().all(|p| m.dot(*p - shape.p0 - at[0]) < -margin)
        })
    }

    /// Whether triangle `t` lies outside the volume the receiver sweeps along the cone (so it
    /// shades no point of it at any of the cone's directions). `w` is scratch.
    fn misses(&self, shape: &Shape, cone: &DirectionCone, t: &[DVec3; 3], w: &mut Vec<DVec3>) -> bool {
        let tolerance = PLANE_TOLERANCE * (1.0 + self.extent);
        if t.iter().all(|p| (*p - shape.p0).dot(shape.normal) <= tolerance) {
            return true;
        }
        // Every generator rises (checked in `certify`), so rays from the receiver go up.
        if t.iter().all(|p| p.z <= shape.lowest) {
            return true;
        }
        w.clear();
        w.extend(t.iter().flat_map(|a| shape.points.iter().map(move |r| *a - *r)));
        if w.iter().any(|v| v.length_squared() == 0.0) {
            return false;
        }
        // A face of the direction cone with every vector of T − R on its far side.
        if cone.faces().iter().any(|h| w.iter().all(|v| h.dot(*v) >= 0.0)) {
            return true;
        }
        // A face of the cone of T − R with every generator on its far side (T − R charted).
        let Some(points) = w.iter().map(|v| cone.chart(*v, MIN_CHART_COS)).collect::<Option<Vec<DVec2>>>() else { return false };
        let hull = convex_hull(&points);
        if hull.len() < 3 {
            return false;
        }
        let inside = cone.direction(hull.iter().copied().sum::<DVec2>() / hull.len() as f64);
        (0..hull.len()).any(|k| {
            let f = cone.direction(hull[k]).cross(cone.direction(hull[(k + 1) % hull.len()]));
            let f = if f.dot(inside) < 0.0 { -f } else { f };
            // The hull's own rounding is not trusted: both sides are checked.
            cone.generators().iter().all(|g| f.dot(*g) <= 0.0) && w.iter().all(|v| f.dot(*v) >= 0.0)
        })
    }

    /// Whether `caster` shades the whole receiver at every generator of the cone (so at every
    /// direction of it): [`Self::ready`], then [`Self::covers_ready`].
    #[cfg(test)]
    fn covers(&self, shape: &Shape, cone: &DirectionCone, caster: Caster) -> bool {
        self.ready(shape, caster).is_some_and(|ready| self.covers_ready(shape, cone, &ready))
    }

    /// `caster`'s corners relative to the receiver's first vertex, where it may cover the
    /// receiver at some direction: it lies in front of the receiver's plane by [`COVER_MARGIN`]
    /// and is not open towards it. None otherwise. Nothing here depends on the sun, so a cell's
    /// halves share it.
    ///
    /// A caster that comes nearer the plane than the margin (a facade meeting the receiver's
    /// wall at an inner corner, a block built against it) is given no proof, except with the
    /// many-caster proofs: then only its part at least twice the margin in front is kept
    /// ([`clipped_in_front`]), itself convex, so every shadow it proves is cast at least the
    /// margin in front of the plane, as a caster standing clear casts it. A receiver reaching
    /// into the corner is still not proved: its edge there lies in the clipped-off band, outside
    /// the kept part's shadow; unless, with [`Self::with_inner_corners`], the caster is a
    /// composite and the receiver's corners in that band lie on it.
    fn ready(&self, shape: &Shape, caster: Caster) -> Option<Ready> {
        let margin = COVER_MARGIN * (1.0 + self.extent);
        let corners: Vec<DVec3> = match caster {
            Caster::Object(o) => self.index.objects.corners(o).iter().map(|&c| self.index.corner(c) - shape.p0).collect(),
            Caster::Composite(c) => self.composites().corners(c).iter().map(|&p| p - shape.p0).collect(),
        };
        if corners.len() < 3 {
            return None;
        }
        let whole = corners.iter().all(|c| c.dot(shape.normal) > margin);
        let (corners, on_caster) = if whole {
            (corners, Vec::new())
        } else if self.many_casters {
            let clipped = clipped_in_front(&corners, shape.normal, 2.0 * margin)?;
            (clipped, self.contact(shape, caster, margin))
        } else {
            return None;
        };
        let open_to_receiver = match caster {
            Caster::Object(o) => self.index.objects.has_caps(o) && !self.caps_face_away(shape, o, margin),
            Caster::Composite(_) => false,
        };
        let alone = whole && matches!(caster, Caster::Object(_));
        (!open_to_receiver).then_some(Ready { corners, on_caster, alone })
    }

    /// Per receiver point, whether it lies on `caster` ([`Self::with_inner_corners`]; only a
    /// composite's polygon is tested, exactly): empty where the option is off, the caster is an
    /// object, or no point does. Never every point: a receiver lying wholly on its caster has
    /// no area in front of it to prove.
    fn contact(&self, shape: &Shape, caster: Caster, margin: f64) -> Vec<bool> {
        let Caster::Composite(c) = caster else { return Vec::new() };
        if !self.inner_corners {
            return Vec::new();
        }
        let on: Vec<bool> = shape.points.iter().map(|p| self.composites().holds(c, *p, margin)).collect();
        if on.iter().all(|&x| x) || !on.iter().any(|&x| x) { Vec::new() } else { on }
    }

    /// Whether a caster made ready ([`Self::ready`]: its `corners`, relative to the receiver's
    /// first vertex) shades the whole receiver at every generator of the cone: at each, every
    /// receiver vertex projects inside the caster's projection by [`COVER_MARGIN`]. A vertex
    /// outside the projection's bounding box is outside the projection: that is looked at first,
    /// without building the hull (most candidates of a cell fail so, and a panelled block has
    /// hundreds of corners).
    ///
    /// A receiver point lying on the caster ([`Ready::on_caster`]) is covered at every sun and
    /// not tested.
    fn covers_ready(&self, shape: &Shape, cone: &DirectionCone, ready: &Ready) -> bool {
        let margin = COVER_MARGIN * (1.0 + self.extent);
        let corners = &ready.corners;
        let tested = || shape.points.iter().enumerate().filter(|(k, _)| !ready.on_caster(*k)).map(|(_, p)| p);
        let mut flat_corners: Vec<DVec2> = Vec::with_capacity(corners.len());
        cone.generators().iter().all(|g| {
            let (u, v) = perpendicular_basis(*g);
            let flat = |p: DVec3| DVec2::new(p.dot(u), p.dot(v));
            flat_corners.clear();
            flat_corners.extend(corners.iter().map(|c| flat(*c)));
            let (lo, hi) = flat_corners.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
            let in_box = |q: DVec2| q.cmpge(lo).all() && q.cmple(hi).all();
            if !tested().all(|p| in_box(flat(*p - shape.p0))) {
                return false;
            }
            let hull = convex_hull(&flat_corners);
            hull.len() >= 3
                && tested().all(|p| {
                    let q = flat(*p - shape.p0);
                    (0..hull.len()).all(|k| {
                        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
                        (b - a).perp_dot(q - a) >= margin * (b - a).length()
                    })
                })
        })
    }
}

/// Pairs of corners a clipped caster may be made from, at most: a panelled block meeting the
/// receiver's plane would otherwise cost more than the views it saves.
const MAX_CLIPPED_PAIRS: usize = 4_096;

/// The corners of the part of the convex hull of `corners` (relative to a point of the plane
/// with normal `normal`) at least `height` in front of that plane: the corners that high, and
/// where the segment between a corner below and a corner above crosses the height. Every point
/// of the part is a convex combination of these (a vertex of a convex polytope cut by a plane
/// is a corner or lies on an edge, and every edge is such a segment), and every one of these
/// lies in the hull, so their hull is the part, exactly. None where fewer than three remain, or
/// more than [`MAX_CLIPPED_PAIRS`] pairs would be crossed.
fn clipped_in_front(corners: &[DVec3], normal: DVec3, height: f64) -> Option<Vec<DVec3>> {
    let (above, below): (Vec<DVec3>, Vec<DVec3>) = corners.iter().partition(|c| c.dot(normal) >= height);
    if above.is_empty() || above.len() * below.len() > MAX_CLIPPED_PAIRS {
        return None;
    }
    let mut out = above.clone();
    for b in &below {
        let hb = b.dot(normal);
        for a in &above {
            let ha = a.dot(normal);
            // Rounding leaves the crossing within a hair of `height`, which is twice the margin
            // the proof needs: at least the margin in front either way.
            out.push(*b + (*a - *b) * ((height - hb) / (ha - hb)));
        }
    }
    (out.len() >= 3).then_some(out)
}

#[cfg(test)]
pub(crate) mod tests;
