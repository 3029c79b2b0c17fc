//! The fast exact engine: the reference's polygon clipping ([`super`]), fast enough to answer
//! views in production.
//!
//! Owns the per-view work and its scheduling over threads. What differs from the reference:
//! - a view clips only the triangles of the BVH leaves in its prism ([`Culling::visit_triangles`],
//!   the walk the GPU path draws from), not every triangle of the scene;
//! - the triangles of one convex object ([`super::objects`]: a box, a slat, a rod or tube even
//!   without its ends, a leaf) cast one shadow, the hull of their clipped vertices' projections,
//!   so the union sees a few dozen convex polygons instead of hundreds of triangles (an object
//!   with open ends casts its triangles one by one in the views where the sun may pass through
//!   it: its ends' projections overlap, or the receiver's plane cuts it);
//! - an object whose corners say it casts nothing on the receiver (none in front of its plane, or
//!   their projections' box, widened past rounding, clear of the receiver's) is dropped before its
//!   triangles are clipped (83 % of the objects a district view's walk reaches); a whole BVH
//!   leaf, or an object, whose world box says so is dropped before its corners are even
//!   projected ([`super::reach`]: one projected centre, and only where the corners would say so);
//! - a view stops as soon as one shadow covers the whole receiver (the answer is then 0, as the
//!   union would find), and the object that covered a receiver last is cast first in its next
//!   views, taken back out unless it covers again, so the shadows are summed in the walk's order;
//! - each receiver's 2D outline is made once, the scratch memory (polygon buffers, the overlay's
//!   graph) is per thread and reused, so no triangle allocates;
//! - natively, views are spread over every core (threads take chunks of views in turn); a view's
//!   answer depends only on the view, never on the thread that computed it.
//!
//! The boolean step is not the reference's overlay graph: every polygon here is convex (receiver
//! triangles, clipped triangles, hulls), so [`super::boundary`] integrates `x dy` along the parts of
//! their edges that bound `receiver − ∪ shadows`, on a 2^30 integer grid fitted to the
//! receiver's window with exact orientation tests. It needs no graph, no sorting of segments
//! and no allocation, and it stays within ~1e-9 of the reference.

use std::ops::Range;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};

use glam::{DVec2, DVec3};

use super::boundary::{Boundary, Snap};
use super::objects;
use super::placed::PlacedObjects;
use super::reach::Reach;
use super::{AREA_EPS, PLANE_EPS, PlaneFrame, Rect, WINDOW_MARGIN};
use crate::count::certify::composite::Composites;
use crate::count::cull::{CPU_LEAF_TRIANGLES, Culling};
use crate::count::{ViewRequest, is_dark, view};
use crate::error::{Error, Result};
use crate::scene::{NO_RECEIVER, Scene, Veil, shifted_rank};

/// Side passed to [`view::fit`] for a view's clip volume: the margin it adds (a pixel at this
/// side) only lets a few more triangles through the walk, which the shadow test then drops.
const PRISM_SIDE: u32 = 512;
/// Views a thread takes at a time.
const CHUNK: usize = 16;
/// Indexes built so far in this process (or wasm instance): see [`ExactEngine::indexes_built`].
static INDEXES_BUILT: AtomicUsize = AtomicUsize::new(0);

/// A receiver as the engine needs it, made once: its plane frame's axes and its 2D outline.
struct Outline {
    /// The receiver's triangles in its plane frame, snapped to its grid.
    lit: Vec<[[i64; 2]; 3]>,
    /// The grid over its window (a receiver's window does not depend on the sun).
    snap: Snap,
    /// Area of the union of its triangles, grid units².
    whole: f64,
    bounds: Rect,
    window: Rect,
    /// Its vertices (world), for the view's clip volume.
    points: Vec<DVec3>,
    normal: DVec3,
    gpu_id: u32,
    /// Its index among the scene's receivers.
    index: usize,
}

/// The fast exact engine over one scene. Build once, then ask [`Self::fractions`].
pub struct ExactEngine {
    outlines: Vec<Option<Outline>>,
    frames: Vec<Option<PlaneFrame>>,
    pub(crate) culling: Culling,
    /// Per triangle position (the culling's order): the world triangle, as the reference makes it.
    pub(crate) triangles: Vec<[DVec3; 3]>,
    /// Per position: the receiver it belongs to ([`NO_RECEIVER`] for shading geometry).
    pub(crate) owner: Vec<u32>,
    /// Per position: its veil (leaf rank already shifted by its instance).
    pub(crate) veils: Vec<Veil>,
    /// The convex objects among those triangles.
    pub(crate) objects: PlacedObjects,
    /// World boxes of the objects and BVH leaves, to drop what casts nothing without its corners.
    reach: Reach,
    /// Prefix counts of see-through triangles by position (the exact engine counts them as opaque).
    see_through_before: Vec<u32>,
    pub(crate) bounds: (DVec3, DVec3),
    pub(crate) origin: DVec3,
    area_eps: f64,
    /// Per receiver: the convex object whose shadow alone last covered it ([`NO_HINT`]: none
    /// yet), cast first in its next views. Only how soon a covered view stops depends on it,
    /// never an answer, so threads share it without ordering.
    cover_hints: Vec<AtomicU32>,
    /// The composite casters of the certificates' dark proofs, found on first use
    /// ([`Self::composites`]) and kept with the index, so that every certifier sharing it (one
    /// per year, one per batch of a city's receivers) shares them.
    composites: OnceLock<Composites>,
}

/// No object has covered the receiver yet.
const NO_HINT: u32 = u32::MAX;

/// Per-thread memory, reused from view to view.
pub struct Scratch {
    /// Per convex object: the view that last cast its shadow.
    stamp: Vec<u32>,
    epoch: u32,
    in_front: Vec<DVec3>,
    clipped: Vec<DVec3>,
    flat: Vec<DVec2>,
    hull: Vec<DVec2>,
    window_a: Vec<DVec2>,
    window_b: Vec<DVec2>,
    /// The view's BVH walk: the triangle ranges it reached, clipped after the load is known.
    reached: Vec<Range<usize>>,
    /// One object's caps projected along the sun, and each cap's range of them.
    cap_points: Vec<DVec2>,
    cap_ranges: Vec<Range<usize>>,
    /// Shadows cast in this view.
    shadows: usize,
    /// The receiver's triangles and the view's shadows on the grid.
    boundary: Boundary,
    /// Set for a point query ([`super::rays`]): shadows are kept as polygons, not integrated.
    keep: bool,
    /// The receiver whose triangles cast nothing in this view besides the view's own (an
    /// opening's glass, for [`ExactEngine::fractions_through`]).
    open: Option<u32>,
    /// Transmittance of the caster whose shadow is being cast (0: opaque).
    casting: f32,
    /// The convex object being cast ([`NO_HINT`] for a lone triangle).
    casting_object: u32,
    /// Set when a shadow alone covers the whole receiver: the view is dark whatever else is cast.
    covered: bool,
    /// Kept shadows' corners (receiver frame), and per shadow its range of them and transmittance.
    pub(super) kept_points: Vec<DVec2>,
    pub(super) kept: Vec<(Range<usize>, f32)>,
}

/// What a convex object's corners say of its shadow in one view ([`ExactEngine::project_corners`]).
enum Corners {
    /// It casts none on the receiver.
    Miss,
    /// Some corner lies behind the receiver's plane: its triangles are clipped one by one.
    Cut,
    /// Every corner lies in front of the plane or on it: the hull of their projections.
    InFront,
}

/// What a view costs the exact engine, known before clipping: from the BVH walk alone.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewLoad {
    /// Triangles in the leaves that reach into the view's prism (0 for a dark view).
    pub triangles: usize,
    /// Of those, see-through ones (the exact engine counts them as opaque).
    pub see_through: usize,
}

/// The lowest of `sorted` (ascending triangle positions, as an object keeps them) that lies in
/// one of `reached`: per range a binary search, since a city's object may have thousands of
/// triangles and a view's walk reach thousands of ranges (a scan of every pair was 45 % of
/// nyt-blocks' sample views).
fn first_reached(sorted: &[u32], reached: &[Range<usize>]) -> Option<u32> {
    let (&lo, &hi) = (sorted.first()?, sorted.last()?);
    reached
        .iter()
        .filter(|r| r.start <= hi as usize && r.end > lo as usize)
        .filter_map(|r| {
            let k = sorted.partition_point(|&p| (p as usize) < r.start);
            sorted.get(k).copied().filter(|&p| (p as usize) < r.end)
        })
        .min()
}

impl ExactEngine {
    /// Indexes `scene`: world triangles in BVH order, objects and their convexity, outlines.
    pub fn new(scene: &Scene) -> Self {
        // Grouping cannot fail; only decoded objects can.
        match Self::build::<std::convert::Infallible>(scene, |sources, triangles| Ok(PlacedObjects::new(scene, sources, triangles))) {
            Ok(engine) => engine,
            Err(never) => match never {},
        }
    }

    /// As [`Self::new`], taking the convex objects another engine over the same scene encoded
    /// ([`Self::objects_bytes`]) instead of grouping the scene's triangles: a page's clipping
    /// worker skips the grouping's memory this way. Refuses bytes that are not such objects or
    /// that do not fit this scene's triangles ([`Error::SceneBytes`]).
    pub fn with_objects(scene: &Scene, objects: &[u8]) -> Result<Self> {
        Self::build(scene, |_, triangles| PlacedObjects::from_bytes(objects, triangles)).map_err(Error::SceneBytes)
    }

    /// This engine's convex objects, encoded for [`Self::with_objects`].
    pub fn objects_bytes(&self) -> Vec<u8> {
        self.objects.to_bytes()
    }

    /// Exact engines built so far in this process (natively) or wasm instance (the page's
    /// thread, a clipping worker): what a page's first visit pays per index of its model, so a
    /// test can tell that one thread indexes a model once (docs/page-speed.md).
    pub fn indexes_built() -> usize {
        INDEXES_BUILT.load(Ordering::Relaxed)
    }

    /// Indexes `scene`, its convex objects made by `objects` from each position's source and
    /// world triangle.
    fn build<E>(
        scene: &Scene,
        objects: impl FnOnce(&[(usize, u32)], &[[DVec3; 3]]) -> std::result::Result<PlacedObjects, E>,
    ) -> std::result::Result<Self, E> {
        INDEXES_BUILT.fetch_add(1, Ordering::Relaxed);
        let culling = Culling::new(scene, CPU_LEAF_TRIANGLES);
        let sources = culling.triangle_sources();
        let extent = (scene.bounds.1 - scene.bounds.0).length();
        let scale = if extent.is_finite() { 1.0 + extent } else { 1.0 };
        let eps = PLANE_EPS * scale;
        let n = sources.len();
        let (mut triangles, mut owner, mut veils) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        let mut see_through_before = Vec::with_capacity(n + 1);
        see_through_before.push(0u32);
        for &(i, t) in &sources {
            let inst = &scene.instances[i];
            let mesh = &scene.meshes[inst.mesh];
            let idx = &mesh.indices[3 * t as usize..3 * t as usize + 3];
            let p = |v: u32| inst.transform.transform_point3(DVec3::from_array(mesh.positions[v as usize].map(f64::from)));
            triangles.push([p(idx[0]), p(idx[1]), p(idx[2])]);
            let surface = mesh.surfaces[idx[0] as usize];
            owner.push(if surface == NO_RECEIVER || inst.receiver_base == NO_RECEIVER {
                NO_RECEIVER
            } else {
                inst.receiver_base + surface
            });
            let mut veil = mesh.veils.get(idx[0] as usize).copied().unwrap_or_default();
            if veil.rank >= 0.0 {
                veil.rank = shifted_rank(veil.rank, inst.leaf_shift);
            }
            let last = *see_through_before.last().unwrap_or(&0);
            see_through_before.push(last + u32::from(veil.transmittance > 0.0));
            veils.push(veil);
        }
        let objects = objects(&sources, &triangles)?;
        drop(sources);
        let reach = Reach::new(&culling, &triangles, &objects, |c| triangles[c as usize / 3][c as usize % 3]);
        let frames: Vec<Option<PlaneFrame>> = scene.receivers.iter().map(|r| PlaneFrame::new(r, DVec3::Z, eps)).collect();
        let outlines =
            scene.receivers.iter().zip(&frames).enumerate().map(|(i, (r, f))| f.as_ref().and_then(|f| outline(r, i, f, eps))).collect();
        Ok(Self {
            outlines,
            frames,
            culling,
            triangles,
            owner,
            veils,
            objects,
            reach,
            see_through_before,
            bounds: scene.bounds,
            origin: scene.origin,
            area_eps: AREA_EPS * scale * scale,
            cover_hints: scene.receivers.iter().map(|_| AtomicU32::new(NO_HINT)).collect(),
            composites: OnceLock::new(),
        })
    }

    /// The scene's composite casters ([`Composites`]), found the first time they are asked for.
    pub(crate) fn composites(&self) -> &Composites {
        self.composites.get_or_init(|| {
            let found = Composites::new(self);
            log::debug!("certificates: {} composite casters (coplanar panels)", found.len());
            found
        })
    }

    /// Fresh scratch memory for one thread.
    pub fn scratch(&self) -> Scratch {
        Scratch {
            stamp: vec![0; self.objects.len()],
            epoch: 0,
            in_front: Vec::new(),
            clipped: Vec::new(),
            flat: Vec::new(),
            hull: Vec::new(),
            window_a: Vec::new(),
            window_b: Vec::new(),
            reached: Vec::new(),
            cap_points: Vec::new(),
            cap_ranges: Vec::new(),
            shadows: 0,
            boundary: Boundary::default(),
            keep: false,
            open: None,
            casting: 0.0,
            casting_object: NO_HINT,
            covered: false,
            kept_points: Vec::new(),
            kept: Vec::new(),
        }
    }

    /// Convex objects found (shadows merged per object).
    pub fn convex_objects(&self) -> usize {
        self.objects.convex()
    }

    /// Triangles indexed.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Sunlit fractions of `requests`, each at its leaf fraction. Natively over every core.
    pub fn fractions(&self, requests: &[ViewRequest]) -> Vec<f64> {
        self.fractions_walking(requests, |_| true)
    }

    /// As [`Self::fractions`], for views whose [`Self::load`]s are known: a view whose walk
    /// reaches no triangle is not walked again (most of a light model's views; the answer is the
    /// same, since that walk would visit nothing).
    pub fn fractions_loaded(&self, requests: &[ViewRequest], loads: &[ViewLoad]) -> Vec<f64> {
        self.fractions_walking(requests, |i| loads.get(i).is_none_or(|l| l.triangles > 0))
    }

    /// As [`Self::fractions`], each view seeing through one opening: the triangles of receiver
    /// `open[i]` (an opening's glass) cast nothing in view `i`, as if that opening were left out
    /// of the scene (None: every caster casts). One scene then answers the views through each of
    /// its windows, instead of one scene per window.
    pub fn fractions_through(&self, requests: &[ViewRequest], open: &[Option<u32>]) -> Vec<f64> {
        self.each_view(requests.len(), |i, scratch| {
            scratch.open = open.get(i).copied().flatten();
            let f = self.fraction(requests[i], requests[i].leaves, true, scratch);
            scratch.open = None;
            f
        })
    }

    /// The views' fractions, walking the BVH for those `walk` says.
    fn fractions_walking(&self, requests: &[ViewRequest], walk: impl Fn(usize) -> bool + Sync) -> Vec<f64> {
        self.each_view(requests.len(), |i, scratch| self.fraction(requests[i], requests[i].leaves, walk(i), scratch))
    }

    /// Every view's [`Self::load`] and, unless `defer` claims that load, its fraction: one BVH
    /// walk a view, for routing that clips most views and leaves the rest to be decided by
    /// load. Natively over every core.
    pub fn fractions_unless(&self, requests: &[ViewRequest], defer: impl Fn(ViewLoad) -> bool + Sync) -> Vec<(ViewLoad, Option<f64>)> {
        self.each_view(requests.len(), |i, scratch| self.clip(requests[i], requests[i].leaves, true, &defer, scratch))
    }

    /// `one(i, scratch)` for views `0..n`, in order; natively over every core.
    fn each_view<T: Send + Default + Clone>(&self, n: usize, one: impl Fn(usize, &mut Scratch) -> T + Sync) -> Vec<T> {
        let threads = worker_threads().min(n.div_ceil(CHUNK)).max(1);
        if threads == 1 {
            let mut scratch = self.scratch();
            return (0..n).map(|i| one(i, &mut scratch)).collect();
        }
        parallel_chunks(n, threads, CHUNK, || self.scratch(), one)
    }

    /// [`Self::load`] of every request, natively over every core.
    pub fn loads(&self, requests: &[ViewRequest]) -> Vec<ViewLoad> {
        let threads = worker_threads().min(requests.len().div_ceil(4 * CHUNK)).max(1);
        parallel_chunks(requests.len(), threads, 4 * CHUNK, || (), |i, _| self.load(requests[i]))
    }

    /// What a view costs before clipping: the triangles its BVH walk reaches.
    pub fn load(&self, request: ViewRequest) -> ViewLoad {
        let Some(Some(outline)) = self.outlines.get(request.receiver as usize) else { return ViewLoad::default() };
        if !request.sun.is_finite() || is_dark(outline.normal, request.sun) {
            return ViewLoad::default();
        }
        self.walk(outline, request.sun, |_| {})
    }

    /// The BVH walk of one view's prism: what it reaches, each range handed to `reached`.
    fn walk(&self, outline: &Outline, sun: DVec3, mut reached: impl FnMut(Range<usize>)) -> ViewLoad {
        let view = view::fit(&outline.points, sun, self.bounds, self.origin, PRISM_SIDE);
        let mut load = ViewLoad::default();
        self.culling.visit_triangles(&view.view_proj, |r| {
            load.triangles += r.len();
            load.see_through += (self.see_through_before[r.end] - self.see_through_before[r.start]) as usize;
            reached(r);
        });
        load
    }

    /// Sunlit fraction of one view with leaf fraction `leaves`; `walk` false skips the BVH walk
    /// (for a view known to reach no triangle).
    pub fn fraction(&self, request: ViewRequest, leaves: f32, walk: bool, scratch: &mut Scratch) -> f64 {
        self.clip(request, leaves, walk, |_| false, scratch).1.unwrap_or(0.0)
    }

    /// One view: its load (what its walk reached; none when `walk` is false or the view is dark)
    /// and, unless `defer` claims that load, its sunlit fraction.
    fn clip(
        &self,
        request: ViewRequest,
        leaves: f32,
        walk: bool,
        defer: impl Fn(ViewLoad) -> bool,
        scratch: &mut Scratch,
    ) -> (ViewLoad, Option<f64>) {
        let sun = request.sun;
        let (Some(Some(outline)), Some(Some(frame))) =
            (self.outlines.get(request.receiver as usize), self.frames.get(request.receiver as usize))
        else {
            return (ViewLoad::default(), Some(0.0));
        };
        if !sun.is_finite() || is_dark(outline.normal, sun) {
            return (ViewLoad::default(), Some(0.0));
        }
        scratch.reached.clear();
        let load = if walk { self.walk(outline, sun, |r| scratch.reached.push(r)) } else { ViewLoad::default() };
        if defer(load) {
            return (load, None);
        }
        (load, Some(self.clip_reached(outline, &frame.towards(sun), leaves, scratch, |_| false)))
    }

    /// The sunlit fraction of `outline` under the shadows of the triangles in `s.reached`. When
    /// shadows are kept, `enough` sees the scratch after each caster that added some and may stop
    /// the walk over the rest (the fraction is then meaningless; point queries never read it).
    fn clip_reached(
        &self,
        outline: &Outline,
        frame: &PlaneFrame,
        leaves: f32,
        scratch: &mut Scratch,
        mut enough: impl FnMut(&Scratch) -> bool,
    ) -> f64 {
        scratch.epoch = scratch.epoch.wrapping_add(1);
        if scratch.epoch == 0 {
            scratch.stamp.fill(0);
            scratch.epoch = 1;
        }
        scratch.shadows = 0;
        scratch.covered = false;
        scratch.boundary.clear();
        if !scratch.keep {
            for t in &outline.lit {
                scratch.boundary.push_points(t, true);
            }
            if self.hinted_cover(outline, frame, leaves, scratch) {
                return 0.0;
            }
        }
        // Taken out for the walk over it, which needs the rest of the scratch mutably.
        let reached = std::mem::take(&mut scratch.reached);
        let casting = reached.iter().filter(|r| !self.reach.leaf(r).is_some_and(|b| frame.box_casts_nothing(b, &outline.bounds)));
        for p in casting.flat_map(|r| r.clone()) {
            if !self.casts(p, outline, leaves, scratch) {
                continue;
            }
            scratch.casting = self.veils[p].transmittance;
            let kept = scratch.kept.len();
            match self.objects.of(p) {
                None => {
                    scratch.casting_object = NO_HINT;
                    self.triangle_shadow(frame, outline, p, scratch);
                }
                Some(o) => {
                    if scratch.stamp[o as usize] != scratch.epoch {
                        scratch.stamp[o as usize] = scratch.epoch;
                        scratch.casting_object = o;
                        self.object_shadow(frame, outline, o, scratch);
                    }
                }
            }
            if scratch.covered || (scratch.kept.len() > kept && enough(scratch)) {
                break;
            }
        }
        scratch.reached = reached;
        if scratch.keep {
            return 1.0;
        }
        if scratch.covered {
            // What `sunlit_ratio` would find: every receiver polygon inside one shadow, no area.
            if scratch.casting_object != NO_HINT {
                self.cover_hints[outline.index].store(scratch.casting_object, Ordering::Relaxed);
            }
            return 0.0;
        }
        self.sunlit_ratio(outline, scratch)
    }

    /// Whether the triangle at position `p` casts a shadow in this view: not the receiver's own,
    /// not the opening looked through, and present at the view's leaf fraction.
    fn casts(&self, p: usize, outline: &Outline, leaves: f32, scratch: &Scratch) -> bool {
        self.owner[p] != outline.gpu_id && scratch.open != Some(self.owner[p]) && self.veils[p].present(0.0, leaves)
    }

    /// Casts first the object that last covered this receiver, when this view's walk reached it
    /// and the view casts it: `true` when its shadow alone covers the receiver again (the view is
    /// dark, as the whole walk would find). Otherwise its shadow is taken back out, so the walk
    /// pushes the view's shadows in the same order as without the hint (the sums' rounding
    /// follows that order), and casts it again in its place.
    fn hinted_cover(&self, outline: &Outline, frame: &PlaneFrame, leaves: f32, scratch: &mut Scratch) -> bool {
        let o = self.cover_hints[outline.index].load(Ordering::Relaxed);
        if o == NO_HINT {
            return false;
        }
        let Some(first) = first_reached(self.objects.triangles(o), &scratch.reached) else { return false };
        if !self.casts(first as usize, outline, leaves, scratch) {
            return false;
        }
        let mark = scratch.boundary.mark();
        scratch.casting_object = o;
        self.object_shadow(frame, outline, o, scratch);
        if scratch.covered {
            return true;
        }
        scratch.boundary.truncate(mark);
        scratch.shadows = 0;
        false
    }

    /// Keeps one view's shadows on its receiver's plane as convex polygons in the receiver's
    /// frame (`s.kept`, `s.kept_points`), cast exactly as [`Self::fraction`] casts them, for point
    /// queries; `false` (nothing kept) when the view is dark: the sun is down or behind the
    /// receiver, or the receiver is unknown. `enough` sees the shadows kept so far each time some
    /// are added and returns `true` to stop casting the rest (every point already dark).
    pub(super) fn keep_shadows(&self, request: ViewRequest, s: &mut Scratch, enough: impl FnMut(&Scratch) -> bool) -> bool {
        let sun = request.sun;
        let (Some(Some(outline)), Some(Some(frame))) =
            (self.outlines.get(request.receiver as usize), self.frames.get(request.receiver as usize))
        else {
            return false;
        };
        s.kept.clear();
        s.kept_points.clear();
        if !sun.is_finite() || is_dark(outline.normal, sun) {
            return false;
        }
        s.reached.clear();
        self.walk(outline, sun, |r| s.reached.push(r));
        s.keep = true;
        self.clip_reached(outline, &frame.towards(sun), request.leaves, s, enough);
        s.keep = false;
        true
    }

    /// A point's orthogonal projection into `receiver`'s plane frame (the frame of its kept
    /// shadows); `None` for an unknown receiver.
    pub(super) fn to_plane(&self, receiver: u32, p: DVec3) -> Option<DVec2> {
        self.frames.get(receiver as usize)?.as_ref().map(|f| f.to_2d(p))
    }

    /// The box around `receiver`'s outline in its plane frame, the window beyond which kept
    /// shadows are clipped; `None` for an unknown receiver.
    pub(super) fn plane_window(&self, receiver: u32) -> Option<(DVec2, DVec2)> {
        self.outlines.get(receiver as usize)?.as_ref().map(|o| (o.window.min, o.window.max))
    }

    /// The shadow of one triangle, as the reference casts it.
    fn triangle_shadow(&self, frame: &PlaneFrame, outline: &Outline, p: usize, s: &mut Scratch) {
        s.flat.clear();
        push_projected(frame, &self.triangles[p], &mut s.in_front, &mut s.clipped, &mut s.flat);
        self.push_shadow(outline, false, s);
    }

    /// The shadow of a convex object: the hull of its in-front vertices' projections, or, when the
    /// sun may pass through its open caps, its triangles' shadows one by one.
    fn object_shadow(&self, frame: &PlaneFrame, outline: &Outline, o: u32, s: &mut Scratch) {
        s.flat.clear();
        let triangles = self.objects.triangles(o);
        let cut = match self.project_corners(frame, outline, o, s) {
            Corners::Miss => return,
            Corners::Cut => true,
            Corners::InFront => false,
        };
        if cut {
            s.flat.clear();
            for &p in triangles {
                push_projected(frame, &self.triangles[p as usize], &mut s.in_front, &mut s.clipped, &mut s.flat);
            }
        }
        // The plane's cut is an opening too, so an object with caps that crosses it goes triangle
        // by triangle.
        if self.objects.has_caps(o) && (cut || self.caps_overlap(frame, o, s)) {
            for &p in triangles {
                self.triangle_shadow(frame, outline, p as usize, s);
            }
            return;
        }
        self.push_shadow(outline, true, s);
    }

    /// Projects object `o`'s distinct corners along the sun into `s.flat` (the points its
    /// triangles would give, each once: a rod's 12 instead of 36) and says what its shadow needs:
    /// - [`Corners::Miss`] when it can cast none on the receiver, known from its corners alone
    ///   (exactly what casting its triangles would find, so the view's answer is the same):
    ///   none lies in front of the plane (every triangle is behind or on it), or their
    ///   projections' box, widened by more than rounding can move a clipped triangle's crossing
    ///   points, misses the receiver's bounds (a clipped triangle's projection lies within the
    ///   hull of its corners' projections: the projection is affine and a crossing lies between
    ///   two corners);
    /// - [`Corners::Cut`] when a corner lies behind the plane (`s.flat` unusable: its triangles
    ///   must be clipped);
    /// - [`Corners::InFront`] otherwise, `s.flat` holding the projections.
    fn project_corners(&self, frame: &PlaneFrame, outline: &Outline, o: u32, s: &mut Scratch) -> Corners {
        // What the loop below would find, from the object's box alone (most objects a view reaches).
        if self.reach.object(o).is_some_and(|b| frame.box_casts_nothing(b, &outline.bounds)) {
            return Corners::Miss;
        }
        let (mut above, mut behind) = (false, false);
        let (mut lo, mut hi) = (DVec2::MAX, DVec2::MIN);
        for &c in self.objects.corners(o) {
            let (h, q) = frame.corner_projection(self.corner(c));
            above |= h > 0.0;
            behind |= h < 0.0;
            (lo, hi) = (lo.min(q), hi.max(q));
            s.flat.push(q);
        }
        if !above || frame.projections_miss(lo, hi, &outline.bounds) {
            return Corners::Miss;
        }
        if behind { Corners::Cut } else { Corners::InFront }
    }

    /// Whether the projections along the sun of two of object `o`'s caps overlap (so some ray
    /// through the object may meet none of its triangles). Separated or touching caps do not.
    fn caps_overlap(&self, frame: &PlaneFrame, o: u32, s: &mut Scratch) -> bool {
        s.cap_points.clear();
        s.cap_ranges.clear();
        for corners in self.objects.caps(o) {
            let start = s.cap_points.len();
            s.cap_points.extend(corners.iter().map(|&c| frame.project_along_sun(self.corner(c))));
            s.cap_ranges.push(start..s.cap_points.len());
        }
        let n = s.cap_ranges.len();
        (0..n).any(|a| (a + 1..n).any(|b| convex_overlap(&s.cap_points[s.cap_ranges[a].clone()], &s.cap_points[s.cap_ranges[b].clone()])))
    }

    /// A corner `3 · position + k`: corner `k` of the triangle at that position.
    pub(crate) fn corner(&self, c: u32) -> DVec3 {
        self.triangles[c as usize / 3][c as usize % 3]
    }

    /// Adds the polygon in `s.flat` (a projected triangle, or an object's projected points to
    /// take the hull of) to the view's shadows, clipped to the receiver's window.
    fn push_shadow(&self, outline: &Outline, hull: bool, s: &mut Scratch) {
        if s.flat.len() < 3 || !s.flat.iter().all(|p| p.is_finite()) {
            return;
        }
        let (lo, hi) = s.flat.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        if !(Rect { min: lo, max: hi }).overlaps(&outline.bounds) {
            return;
        }
        if hull {
            objects::convex_hull(&mut s.flat, &mut s.hull);
            std::mem::swap(&mut s.flat, &mut s.hull);
        }
        // Inside the window (most shadows of a view), clipping would give the polygon back as it is.
        let inside = outline.window.min.cmple(lo).all() && hi.cmple(outline.window.max).all();
        if inside {
            s.window_a.clear();
            s.window_a.extend_from_slice(&s.flat);
        } else {
            clip_to_window(&outline.window, &s.flat, &mut s.window_a, &mut s.window_b);
        }
        let polygon = &s.window_a;
        if polygon.len() < 3 {
            return;
        }
        let area = objects::polygon_area(polygon);
        if area.abs() <= self.area_eps {
            return;
        }
        if s.keep {
            let start = s.kept_points.len();
            s.kept_points.extend_from_slice(polygon);
            s.kept.push((start..s.kept_points.len(), s.casting));
            s.shadows += 1;
            return;
        }
        let before = s.boundary.mark();
        s.boundary.push(&outline.snap, polygon, false);
        s.shadows += 1;
        s.covered |= s.boundary.mark() != before && s.boundary.last_covers_receivers();
    }

    /// `area(receiver − ∪ shadows) / area(∪ receiver)`, as the reference computes it.
    fn sunlit_ratio(&self, outline: &Outline, s: &mut Scratch) -> f64 {
        let area_eps = self.area_eps * outline.snap.area_scale();
        if outline.whole <= area_eps {
            return 0.0;
        }
        if s.shadows == 0 {
            return 1.0;
        }
        let lit = s.boundary.uncovered_area();
        // A lit area below the noise level is none (as in the reference).
        if lit <= area_eps {
            return 0.0;
        }
        (lit / outline.whole).clamp(0.0, 1.0)
    }
}

impl PlaneFrame {
    /// The same frame with the sun's shift set for `sun` (its axes do not depend on the sun).
    fn towards(&self, sun: DVec3) -> PlaneFrame {
        let shift_per_height = -DVec2::new(sun.dot(self.e1), sun.dot(self.e2)) / self.normal.dot(sun);
        PlaneFrame { shift_per_height, ..*self }
    }
}

/// The receiver's outline in its frame: its triangles on the grid of its window, their union's
/// area, bounds and the window shadows are clipped to (as in the reference).
fn outline(r: &crate::scene::Receiver, index: usize, frame: &PlaneFrame, eps: f64) -> Option<Outline> {
    let flat: Vec<Vec<DVec2>> =
        r.triangles.iter().filter_map(|t| frame.receiver_contour(t)).map(|c| c.iter().map(|&p| DVec2::from(p)).collect()).collect();
    let bounds = Rect::around(flat.iter().flatten().copied())?;
    let window = bounds.expanded(WINDOW_MARGIN * bounds.size().length() + eps);
    let snap = Snap::new(window.min, window.max)?;
    let lit: Vec<[[i64; 2]; 3]> = flat.iter().filter_map(|t| Boundary::snapped(&snap, t).try_into().ok()).collect();
    let mut whole = Boundary::default();
    for t in &lit {
        whole.push_points(t, true);
    }
    let whole = whole.uncovered_area();
    Some(Outline {
        lit,
        snap,
        whole,
        bounds,
        window,
        points: r.triangles.iter().flatten().copied().collect(),
        normal: r.normal,
        gpu_id: r.gpu_id,
        index,
    })
}

/// Appends the projections of the part of `tri` in front of the plane to `flat` (nothing when
/// none of it is in front), clipping as the reference does; `true` when a part lies behind it.
fn push_projected(
    frame: &PlaneFrame,
    tri: &[DVec3; 3],
    in_front: &mut Vec<DVec3>,
    clipped: &mut Vec<DVec3>,
    flat: &mut Vec<DVec2>,
) -> bool {
    let h = tri.map(|p| frame.height(p));
    if h.iter().all(|&h| h <= 0.0) {
        return h.iter().any(|&h| h < 0.0);
    }
    if h.iter().all(|&h| h >= 0.0) {
        flat.extend(tri.iter().zip(h).map(|(&p, h)| frame.to_2d(p) + frame.shift_per_height * h));
        return false;
    }
    in_front.clear();
    in_front.extend_from_slice(tri);
    clip_into(in_front, clipped, |p| frame.height(*p));
    flat.extend(clipped.iter().map(|&p| frame.project_along_sun(p)));
    true
}

/// Whether two convex polygons (either orientation, possibly flat) share interior points:
/// [`crate::geometry::convex_apart`] with no gap (touching polygons do not overlap).
fn convex_overlap(a: &[DVec2], b: &[DVec2]) -> bool {
    !crate::geometry::convex_apart(a, b, 0.0)
}

/// A convex polygon clipped to the window box, into `a` (`b` is scratch).
fn clip_to_window(window: &Rect, polygon: &[DVec2], a: &mut Vec<DVec2>, b: &mut Vec<DVec2>) {
    a.clear();
    a.extend_from_slice(polygon);
    clip_into(a, b, |p| p.x - window.min.x);
    clip_into(b, a, |p| window.max.x - p.x);
    clip_into(a, b, |p| p.y - window.min.y);
    clip_into(b, a, |p| window.max.y - p.y);
}

/// The reference's Sutherland–Hodgman step ([`super::clip_half_space`]) into a reused buffer.
fn clip_into<P>(polygon: &[P], out: &mut Vec<P>, dist: impl Fn(&P) -> f64)
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    out.clear();
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (da, db) = (dist(&a), dist(&b));
        if da >= 0.0 {
            out.push(a);
        }
        if da > 0.0 && db < 0.0 {
            out.push(super::crossing(a, da, b, db));
        } else if da < 0.0 && db > 0.0 {
            out.push(super::crossing(b, db, a, da));
        }
    }
}

/// Threads for exact views: every core natively, one on the web (no threads to block there).
pub(crate) fn worker_threads() -> usize {
    if cfg!(target_arch = "wasm32") { 1 } else { std::thread::available_parallelism().map_or(1, |n| n.get()) }
}

/// `job(i, scratch)` for every `i < n`, over `threads` threads taking `chunk` items at a time, in
/// item order whatever thread ran each.
#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn parallel_chunks<S, T: Send + Default + Clone>(
    n: usize,
    threads: usize,
    chunk: usize,
    scratch: impl Fn() -> S + Sync,
    job: impl Fn(usize, &mut S) -> T + Sync,
) -> Vec<T> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let parts: Vec<Vec<(usize, Vec<T>)>> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut s = scratch();
                    let mut done = Vec::new();
                    loop {
                        let start = next.fetch_add(chunk, Ordering::Relaxed);
                        if start >= n {
                            break done;
                        }
                        done.push((start, (start..(start + chunk).min(n)).map(|i| job(i, &mut s)).collect()));
                    }
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap_or_default()).collect()
    });
    let mut out = vec![T::default(); n];
    for (start, values) in parts.into_iter().flatten() {
        for (k, v) in values.into_iter().enumerate() {
            out[start + k] = v;
        }
    }
    out
}

/// One thread on the web.
#[cfg(target_arch = "wasm32")]
pub(crate) fn parallel_chunks<S, T: Send + Default + Clone>(
    n: usize,
    _threads: usize,
    _chunk: usize,
    scratch: impl Fn() -> S + Sync,
    job: impl Fn(usize, &mut S) -> T + Sync,
) -> Vec<T> {
    let mut s = scratch();
    (0..n).map(|i| job(i, &mut s)).collect()
}

#[cfg(test)]
#[path = "engine_tests.rs"]
mod tests;
