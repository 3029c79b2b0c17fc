//! What each view draws: only the geometry in the sun-aligned prism in front of the receiver.
//!
//! Owns the spatial index over the scene and the per-view choice of what to draw:
//! - the merged static mesh is cut into spatial chunks of a few dozen triangles (a bounding volume
//!   hierarchy by median splits, [`LEAF_TRIANGLES`] or [`CPU_LEAF_TRIANGLES`] a leaf), and its
//!   triangles are reordered so every BVH node is one contiguous range; the GPU stores them in
//!   that order;
//! - the instances of each shared mesh get the same treatment, with instances as items: they are
//!   ordered spatially within their mesh's slot range, so a BVH node is one instance range;
//! - a view draws the leaves whose boxes reach into its clip volume (the camera's side planes
//!   are parallel to the sun and enclose the receiver, its far plane lies just behind it), merged
//!   into as few triangle and instance ranges as the order allows. What lies outside would be clipped
//!   by the GPU anyway, so the pixels are the same as drawing everything;
//! - a view whose leaves hold no triangle that can shade the receiver needs no render at all: its
//!   fraction is exactly 1. A triangle can only shade the receiver if part of it lies in front of
//!   the receiver's plane and its shadow, cast along the sun onto that plane, overlaps the
//!   receiver. Projection along the sun is affine, so the shadow of the in-front part lies inside
//!   the bounding box of the projections of all three vertices; if that box misses the receiver's
//!   box for every triangle, nothing shades it.
//!
//! Cost on the CPU is a tree walk and a few triangle tests per view (microseconds), against
//! about 0.3 µs per triangle drawn on lavapipe.

use std::ops::Range;

use glam::{DMat4, DVec2, DVec3, Vec3};

use crate::scene::{NO_RECEIVER, Scene};

/// Triangles per BVH leaf: small enough that a view draws little beyond its prism, large enough
/// that a view's draws stay few (each leaf range costs one draw call unless adjacent ranges merge).
/// On lavapipe, NYT-like flat rods at 128² (600 views): leaves of 1,024 triangles drew 15,651 a
/// view in 2.6 s, 256 drew 7,808 in 1.7–2.0 s, 64 drew 4,159 in 1.1–1.2 s, 16 drew 2,228 in 1.0 s.
/// A GPU pays per draw call rather than per triangle, so this larger size is the default there.
pub const LEAF_TRIANGLES: u32 = 64;

/// Leaf size for CPU rasterizers (lavapipe), which pay about 0.3 µs per triangle drawn: hexagonal
/// rods at 128² (800 views) drew 6,326 triangles a view in 4.2 s with 16, 9,392 in 5.1 s with 64.
pub const CPU_LEAF_TRIANGLES: u32 = 16;

/// Slack in clip units for the box test, so rounding never culls what the GPU would draw.
pub const CLIP_SLACK: f64 = 1e-4;

/// The most triangles a cluster ([`Culling::clusters`]) holds: a BVH node is a cluster when it
/// holds at most this many and its parent more, so a cluster of the static mesh holds 64–128
/// (median splits halve a node).
pub const CLUSTER_TRIANGLES: u32 = 128;

/// A run of triangles of [`Culling::triangles`], spatially compact, with its box (scene
/// coordinates relative to the origin): what the GPU's culling pass tests against each view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cluster {
    /// Its first triangle in [`Culling::triangles`]' order.
    pub first: u32,
    /// Its triangles (at most [`CLUSTER_TRIANGLES`]).
    pub count: u32,
    /// Its box's lowest corner.
    pub lo: Vec3,
    /// Its box's highest corner.
    pub hi: Vec3,
}

/// Triangles of [`Culling::triangles`] placed one way ([`Culling::runs`]): `slots.len()`
/// placements of mesh `mesh`'s `per_instance` triangles, from position `first` on, placement
/// by placement.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleRun {
    /// The mesh (0: the static mesh, placed once, its triangles in [`Culling::static_order`]).
    pub mesh: usize,
    /// Its first triangle's position.
    pub first: u32,
    /// Triangles a placement.
    pub per_instance: u32,
    /// The placements' slots.
    pub slots: Range<u32>,
}

/// A bounding volume hierarchy over items stored contiguously in BVH order.
#[derive(Debug, Default)]
struct Bvh {
    nodes: Vec<Node>,
}

#[derive(Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    items: Range<u32>,
    /// Index of the second child (the first follows the node); `None` for a leaf.
    right: Option<u32>,
}

/// An item to index: its box and the centre it is sorted by.
#[derive(Debug, Clone, Copy)]
struct Item {
    lo: Vec3,
    hi: Vec3,
    index: u32,
}

impl Item {
    fn centre(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }
}

impl Bvh {
    /// Builds over `items` (reordered in place into BVH order), at most `per_leaf` items a leaf.
    fn build(items: &mut [Item], per_leaf: usize) -> Self {
        let mut bvh = Self::default();
        if !items.is_empty() {
            bvh.split(items, 0, per_leaf.max(1));
        }
        bvh
    }

    fn split(&mut self, items: &mut [Item], first: u32, per_leaf: usize) -> u32 {
        let (lo, hi) = items.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), i| (lo.min(i.lo), hi.max(i.hi)));
        let at = self.nodes.len() as u32;
        self.nodes.push(Node { lo, hi, items: first..first + items.len() as u32, right: None });
        if items.len() <= per_leaf {
            return at;
        }
        // Median split along the longest axis of the centres.
        let (clo, chi) = items.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), i| (lo.min(i.centre()), hi.max(i.centre())));
        let extent = chi - clo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |a, b| a.centre()[axis].total_cmp(&b.centre()[axis]));
        let (left, right) = items.split_at_mut(mid);
        self.split(left, first, per_leaf);
        let r = self.split(right, first + mid as u32, per_leaf);
        self.nodes[at as usize].right = Some(r);
        at
    }

    /// Calls `f`, in item order, with the item range and box of every highest node holding at
    /// most `most` triangles (`per_item` an item), or of a leaf holding more: the ranges cover
    /// every item once, and each node's box holds every leaf box below it.
    fn cut(&self, most: usize, per_item: usize, mut f: impl FnMut(Range<u32>, [Vec3; 2])) {
        let mut stack = if self.nodes.is_empty() { Vec::new() } else { vec![0u32] };
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            match node.right {
                Some(r) if node.items.len() * per_item > most => stack.extend([r, n + 1]),
                _ => f(node.items.clone(), [node.lo, node.hi]),
            }
        }
    }

    /// Calls `f` with the item range of every leaf whose box reaches into `clip`, in item order.
    fn visit(&self, clip: &ClipVolume, mut f: impl FnMut(Range<u32>)) {
        self.visit_while(clip, |r| {
            f(r);
            true
        });
    }

    /// [`Self::visit`] until `f` returns false.
    fn visit_while(&self, clip: &ClipVolume, mut f: impl FnMut(Range<u32>) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !clip.touches(node.lo, node.hi) {
                continue;
            }
            match node.right {
                // Right pushed first so the left (lower items) comes out first.
                Some(r) => stack.extend([r, n + 1]),
                None if f(node.items.clone()) => {}
                None => return,
            }
        }
    }
}

/// A view's clip volume: x, y in [−1, 1] and depth in [0, 1] of an orthographic view-projection.
struct ClipVolume {
    rows: [[f64; 4]; 3],
}

impl ClipVolume {
    fn new(view_proj: &DMat4) -> Self {
        let m = view_proj.transpose();
        Self { rows: [m.x_axis.to_array(), m.y_axis.to_array(), m.z_axis.to_array()] }
    }

    /// Whether the box may reach into the volume (the view is affine: centre ± |M|·half extent).
    fn touches(&self, lo: Vec3, hi: Vec3) -> bool {
        let c = (0.5 * (lo + hi)).as_dvec3();
        let e = (0.5 * (hi - lo)).as_dvec3();
        let range = |r: &[f64; 4]| {
            let centre = r[0] * c.x + r[1] * c.y + r[2] * c.z + r[3];
            let radius = r[0].abs() * e.x + r[1].abs() * e.y + r[2].abs() * e.z;
            (centre - radius, centre + radius)
        };
        let (x0, x1) = range(&self.rows[0]);
        let (y0, y1) = range(&self.rows[1]);
        let (z0, z1) = range(&self.rows[2]);
        let s = CLIP_SLACK;
        x0 <= 1.0 + s && x1 >= -1.0 - s && y0 <= 1.0 + s && y1 >= -1.0 - s && z0 <= 1.0 + s && z1 >= -s
    }
}

/// The instances of one shared mesh: a slot range and a BVH over it.
#[derive(Debug)]
struct Group {
    mesh: usize,
    slots: Range<u32>,
    bvh: Bvh,
    /// Where this group's triangles start in [`Culling::triangles`] (slot order).
    first_triangle: usize,
    triangles_per_instance: usize,
}

/// What one view draws in the scene pass.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct DrawList {
    /// Triangle ranges of the static mesh, in the order of [`Culling::static_order`].
    pub static_triangles: Vec<Range<u32>>,
    /// Instance slot ranges (absolute slots) with the shared mesh they place.
    pub instances: Vec<(usize, Range<u32>)>,
}

impl DrawList {
    /// Triangles this list draws (for benchmarks).
    pub fn triangles(&self, culling: &Culling) -> usize {
        let statics: usize = self.static_triangles.iter().map(|r| r.len()).sum();
        let instanced: usize = self
            .instances
            .iter()
            .map(|(mesh, slots)| culling.groups.iter().find(|g| g.mesh == *mesh).map_or(0, |g| g.triangles_per_instance) * slots.len())
            .sum();
        statics + instanced
    }
}

/// A receiver as the culling needs it.
pub struct Target<'a> {
    /// Vertices, world coordinates.
    pub points: &'a [DVec3],
    /// Outward unit normal.
    pub normal: DVec3,
    /// Its GPU id: its own triangles never shade it.
    pub gpu_id: u32,
}

/// The scene's spatial index: the GPU layout's order and the per-view selection.
#[derive(Debug)]
pub struct Culling {
    /// Slot → scene instance index: instances grouped by mesh, spatially ordered within a mesh.
    slot_order: Vec<usize>,
    /// Static mesh (mesh 0): BVH position → original triangle index.
    static_order: Vec<u32>,
    static_bvh: Bvh,
    static_slot: u32,
    groups: Vec<Group>,
    /// Every triangle relative to the scene origin: the static mesh's in BVH order, then each
    /// group's instances in slot order.
    triangles: Vec<[Vec3; 3]>,
    ids: Vec<u32>,
    origin: DVec3,
    /// Distance (m) within which a vertex counts as on the receiver's plane (coplanar geometry
    /// never shades it, as in the exact reference).
    eps: f64,
}

impl Culling {
    /// Indexes a scene: orders the static mesh's triangles and each shared mesh's instances,
    /// about `leaf_triangles` triangles a BVH leaf.
    pub fn new(scene: &Scene, leaf_triangles: u32) -> Self {
        let origin = scene.origin;
        let to_scene = DMat4::from_translation(-origin);
        let mut triangles = Vec::new();
        let mut ids = Vec::new();
        // The static mesh: triangles are items.
        let placed = |inst: usize| to_scene * scene.instances[inst].transform;
        let mut static_order = Vec::new();
        let mut static_bvh = Bvh::default();
        if let Some(mesh) = scene.meshes.first() {
            let m = placed(0).as_mat4();
            let tris: Vec<[Vec3; 3]> = mesh
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]].map(|i| m.transform_point3(Vec3::from_array(mesh.positions[i as usize]))))
                .collect();
            let mut items: Vec<Item> = tris
                .iter()
                .enumerate()
                .map(|(i, t)| Item { lo: t[0].min(t[1]).min(t[2]), hi: t[0].max(t[1]).max(t[2]), index: i as u32 })
                .collect();
            static_bvh = Bvh::build(&mut items, leaf_triangles as usize);
            static_order = items.iter().map(|i| i.index).collect();
            for &t in &static_order {
                triangles.push(tris[t as usize]);
                let surface = mesh.surfaces[mesh.indices[3 * t as usize] as usize];
                ids.push(surface_id(surface, scene.instances.first().map_or(0, |i| i.receiver_base)));
            }
        }
        // Shared meshes: instances are items, grouped by mesh.
        let mut by_mesh: Vec<Vec<usize>> = vec![Vec::new(); scene.meshes.len()];
        for (i, inst) in scene.instances.iter().enumerate() {
            by_mesh[inst.mesh].push(i);
        }
        let mut slot_order: Vec<usize> = Vec::with_capacity(scene.instances.len());
        let mut static_slot = 0;
        let mut groups = Vec::new();
        for (mesh_index, instances) in by_mesh.iter().enumerate() {
            if mesh_index == 0 {
                static_slot = slot_order.len() as u32;
                slot_order.extend(instances);
                continue;
            }
            if instances.is_empty() {
                continue;
            }
            let mesh = &scene.meshes[mesh_index];
            let local: Vec<Vec3> = mesh.positions.iter().map(|p| Vec3::from_array(*p)).collect();
            let boxes: Vec<(Vec3, Vec3)> = instances
                .iter()
                .map(|&i| {
                    let m = placed(i).as_mat4();
                    local.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                        let w = m.transform_point3(*p);
                        (lo.min(w), hi.max(w))
                    })
                })
                .collect();
            let mut items: Vec<Item> = boxes.iter().enumerate().map(|(k, (lo, hi))| Item { lo: *lo, hi: *hi, index: k as u32 }).collect();
            let per_instance = mesh.indices.len() / 3;
            let per_leaf = (leaf_triangles as usize / per_instance.max(1)).max(1);
            let bvh = Bvh::build(&mut items, per_leaf);
            let start = slot_order.len() as u32;
            let first_triangle = triangles.len();
            for item in &items {
                let i = instances[item.index as usize];
                slot_order.push(i);
                let m = placed(i).as_mat4();
                let base = scene.instances[i].receiver_base;
                for t in mesh.indices.chunks_exact(3) {
                    triangles.push([t[0], t[1], t[2]].map(|v| m.transform_point3(local[v as usize])));
                    ids.push(surface_id(mesh.surfaces[t[0] as usize], base));
                }
            }
            let slots = start..slot_order.len() as u32;
            groups.push(Group { mesh: mesh_index, slots, bvh, first_triangle, triangles_per_instance: per_instance });
        }
        let extent = (scene.bounds.1 - scene.bounds.0).length();
        Self { slot_order, static_order, static_bvh, static_slot, groups, triangles, ids, origin, eps: 1e-6 * (1.0 + extent) }
    }

    /// Slot → scene instance index (the GPU's instance buffer order).
    pub fn slot_order(&self) -> &[usize] {
        &self.slot_order
    }

    /// The static mesh's triangles in BVH order: position → original triangle index. The GPU
    /// stores them in this order, so every BVH node is one contiguous range.
    pub fn static_order(&self) -> &[u32] {
        &self.static_order
    }

    /// The slot that places the static mesh.
    pub fn static_slot(&self) -> u32 {
        self.static_slot
    }

    /// What to draw for a view of `target` with clip transform `view_proj` (scene coordinates
    /// relative to the origin), or `None` when nothing can shade it (fraction 1, no render).
    pub fn select(&self, view_proj: &DMat4, target: &Target<'_>, sun: DVec3) -> Option<DrawList> {
        let clip = ClipVolume::new(view_proj);
        let prism = Prism::new(target, sun, self.origin, self.eps);
        let mut list = DrawList::default();
        let mut shaded = false;
        self.static_bvh.visit(&clip, |r| {
            shaded = shaded || self.any_shades(&prism, target.gpu_id, r.start as usize..r.end as usize);
            push_merged(&mut list.static_triangles, r);
        });
        for g in &self.groups {
            g.bvh.visit(&clip, |r| {
                let n = g.triangles_per_instance;
                let tris = g.first_triangle + r.start as usize * n..g.first_triangle + r.end as usize * n;
                shaded = shaded || self.any_shades(&prism, target.gpu_id, tris);
                let slots = g.slots.start + r.start..g.slots.start + r.end;
                match list.instances.last_mut() {
                    Some((m, last)) if *m == g.mesh && last.end == slots.start => last.end = slots.end,
                    _ => list.instances.push((g.mesh, slots)),
                }
            });
        }
        shaded.then_some(list)
    }

    /// Whether anything a view of `target` with clip transform `view_proj` draws can shade it:
    /// [`Self::select`]'s test alone (`select` is `None` exactly where this is false), stopping
    /// at the first triangle that can.
    pub fn may_be_shaded(&self, view_proj: &DMat4, target: &Target<'_>, sun: DVec3) -> bool {
        let clip = ClipVolume::new(view_proj);
        let prism = Prism::new(target, sun, self.origin, self.eps);
        let mut shaded = false;
        self.static_bvh.visit_while(&clip, |r| {
            shaded = self.any_shades(&prism, target.gpu_id, r.start as usize..r.end as usize);
            !shaded
        });
        for g in &self.groups {
            if shaded {
                break;
            }
            let n = g.triangles_per_instance;
            g.bvh.visit_while(&clip, |r| {
                shaded =
                    self.any_shades(&prism, target.gpu_id, g.first_triangle + r.start as usize * n..g.first_triangle + r.end as usize * n);
                !shaded
            });
        }
        shaded
    }

    /// Calls `f` with the triangle positions (see [`Self::triangle_sources`]) of every leaf that
    /// reaches into the clip volume of `view_proj`, in position order: what a view would draw,
    /// for engines that clip polygons instead of drawing them.
    pub fn visit_triangles(&self, view_proj: &DMat4, mut f: impl FnMut(Range<usize>)) {
        let clip = ClipVolume::new(view_proj);
        self.static_bvh.visit(&clip, |r| f(r.start as usize..r.end as usize));
        for g in &self.groups {
            let n = g.triangles_per_instance;
            g.bvh.visit(&clip, |r| f(g.first_triangle + r.start as usize * n..g.first_triangle + r.end as usize * n));
        }
    }

    /// For every triangle position of [`Self::visit_triangles`]: the scene instance that places it
    /// and its triangle's index in that instance's mesh.
    pub fn triangle_sources(&self) -> Vec<(usize, u32)> {
        let mut out: Vec<(usize, u32)> = self.static_order.iter().map(|&t| (0, t)).collect();
        for g in &self.groups {
            let n = g.triangles_per_instance as u32;
            for slot in g.slots.clone() {
                let instance = self.slot_order[slot as usize];
                out.extend((0..n).map(|t| (instance, t)));
            }
        }
        out
    }

    /// Every triangle relative to the scene origin and its receiver id ([`NO_RECEIVER`] for a
    /// caster), in the order [`Self::visit_triangles`] and [`Self::list_ranges`] index.
    pub fn triangles(&self) -> (&[[Vec3; 3]], &[u32]) {
        (&self.triangles, &self.ids)
    }

    /// A draw list as ranges of [`Self::triangles`] (what a compute rasterizer reads).
    pub fn list_ranges(&self, list: &DrawList) -> Vec<Range<u32>> {
        let mut out = list.static_triangles.clone();
        for (mesh, slots) in &list.instances {
            let Some(g) = self.groups.iter().find(|g| g.mesh == *mesh) else { continue };
            let n = g.triangles_per_instance as u32;
            let first = g.first_triangle as u32 + (slots.start - g.slots.start) * n;
            out.push(first..first + slots.len() as u32 * n);
        }
        out
    }

    /// The triangles cut into clusters of at most [`CLUSTER_TRIANGLES`], in triangle order: BVH
    /// nodes of the static mesh and of each shared mesh's instances; a leaf of one instance with
    /// more triangles than that is cut into even runs of it.
    pub fn clusters(&self) -> Vec<Cluster> {
        self.clusters_and_reach().into_iter().map(|(c, _)| c).collect()
    }

    /// [`Self::clusters`], each with the box of the BVH node it was cut from (`[lo, hi]`): it
    /// holds the box of every leaf any of the cluster's triangles belongs to, so a cluster whose
    /// node box misses a view's clip volume holds no triangle [`Self::may_be_shaded`] tests for
    /// that view (a cluster's own box can be smaller, where an instance of more than
    /// [`CLUSTER_TRIANGLES`] triangles is a leaf cut in pieces).
    pub fn clusters_and_reach(&self) -> Vec<(Cluster, [Vec3; 2])> {
        let most = CLUSTER_TRIANGLES as usize;
        let mut out = Vec::new();
        self.static_bvh.cut(most, 1, |r, reach| self.push_clusters(&mut out, r.start as usize..r.end as usize, reach));
        for g in &self.groups {
            let n = g.triangles_per_instance;
            let at = |i: u32| g.first_triangle + i as usize * n;
            g.bvh.cut(most, n, |r, reach| self.push_clusters(&mut out, at(r.start)..at(r.end), reach));
        }
        out
    }

    /// What [`Self::may_be_shaded`] decides a view by, for a test made elsewhere (the GPU's,
    /// shaders/may_shade.wgsl): the clip volume's rows and the receiver's prism.
    pub fn shade_test(&self, view_proj: &DMat4, target: &Target<'_>, sun: DVec3) -> ShadeTest {
        let prism = Prism::new(target, sun, self.origin, self.eps);
        let Prism { p0, normal, u, v, lo, hi, sun, along, eps } = prism;
        ShadeTest { clip_rows: ClipVolume::new(view_proj).rows, p0, normal, u, v, lo, hi, sun, along, eps, own: target.gpu_id }
    }

    /// The runs of [`Self::triangles`] each placed one way: the static mesh (one placement, at
    /// [`Self::static_slot`]) and then each shared mesh's instances in slot order, in triangle
    /// order. A cluster never straddles two runs. What a draw that pulls triangles by position
    /// needs to find a triangle's mesh, corners and placement.
    pub fn runs(&self) -> Vec<TriangleRun> {
        let mut out = Vec::with_capacity(self.groups.len() + 1);
        if !self.static_order.is_empty() {
            let n = self.static_order.len() as u32;
            out.push(TriangleRun { mesh: 0, first: 0, per_instance: n, slots: self.static_slot..self.static_slot + 1 });
        }
        for g in &self.groups {
            let per_instance = g.triangles_per_instance as u32;
            out.push(TriangleRun { mesh: g.mesh, first: g.first_triangle as u32, per_instance, slots: g.slots.clone() });
        }
        out
    }

    fn push_clusters(&self, out: &mut Vec<(Cluster, [Vec3; 2])>, range: Range<usize>, reach: [Vec3; 2]) {
        let pieces = range.len().div_ceil(CLUSTER_TRIANGLES as usize);
        for k in 0..pieces {
            let (a, b) = (range.start + range.len() * k / pieces, range.start + range.len() * (k + 1) / pieces);
            let (lo, hi) =
                self.triangles[a..b].iter().flatten().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
            out.push((Cluster { first: a as u32, count: (b - a) as u32, lo, hi }, reach));
        }
    }

    fn any_shades(&self, prism: &Prism, own: u32, range: Range<usize>) -> bool {
        self.triangles[range.clone()].iter().zip(&self.ids[range]).any(|(t, id)| (*id != own || own == NO_RECEIVER) && prism.may_shade(t))
    }
}

fn surface_id(surface: u32, base: u32) -> u32 {
    if surface == NO_RECEIVER || base == NO_RECEIVER { NO_RECEIVER } else { base + surface }
}

fn push_merged(ranges: &mut Vec<Range<u32>>, r: Range<u32>) {
    match ranges.last_mut() {
        Some(last) if last.end == r.start => last.end = r.end,
        _ => ranges.push(r),
    }
}

/// [`Culling::may_be_shaded`]'s inputs for one view, as the GPU's test reads them (scene
/// coordinates relative to the origin): a triangle of a leaf whose box reaches into the clip
/// volume (`clip_rows`, x, y in [−1, 1], depth in [0, 1], [`CLIP_SLACK`]) may shade the
/// receiver when it is not the receiver's own (`own`), a corner lies more than `eps` in front of
/// the plane through `p0` with normal `normal`, and the box of its corners cast along `sun` onto
/// that plane (`along` = normal · sun), in the plane's axes `u`, `v`, meets the receiver's box
/// `lo`..`hi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeTest {
    /// Rows x, y and z of the view's clip transform.
    pub clip_rows: [[f64; 4]; 3],
    /// A point of the receiver's plane (its owner's first corner).
    pub p0: DVec3,
    /// The receiver's outward unit normal.
    pub normal: DVec3,
    /// The plane's first axis.
    pub u: DVec3,
    /// The plane's second axis.
    pub v: DVec3,
    /// The receiver's box in the plane's axes: lowest corner.
    pub lo: DVec2,
    /// Highest corner.
    pub hi: DVec2,
    /// Towards the sun (unit).
    pub sun: DVec3,
    /// `normal · sun`.
    pub along: f64,
    /// Heights within this of the plane are on it.
    pub eps: f64,
    /// The receiver's GPU id (its own triangles never shade it).
    pub own: u32,
}

/// The receiver's plane and box, for the per-triangle "can its shadow reach?" test.
struct Prism {
    p0: DVec3,
    normal: DVec3,
    u: DVec3,
    v: DVec3,
    lo: DVec2,
    hi: DVec2,
    sun: DVec3,
    along: f64,
    eps: f64,
}

impl Prism {
    fn new(target: &Target<'_>, sun: DVec3, origin: DVec3, eps: f64) -> Self {
        let normal = target.normal;
        let p0 = target.points.first().map_or(DVec3::ZERO, |p| *p - origin);
        let helper = if normal.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let u = (helper - normal * helper.dot(normal)).normalize();
        let v = normal.cross(u);
        let mut prism = Self { p0, normal, u, v, lo: DVec2::MAX, hi: DVec2::MIN, sun, along: normal.dot(sun), eps };
        for p in target.points {
            let q = prism.flat(*p - origin);
            prism.lo = prism.lo.min(q);
            prism.hi = prism.hi.max(q);
        }
        prism
    }

    fn flat(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.p0).dot(self.u), (p - self.p0).dot(self.v))
    }

    /// Whether the triangle (relative to the origin) may cast a shadow on the receiver.
    fn may_shade(&self, t: &[Vec3; 3]) -> bool {
        let h = t.map(|p| (p.as_dvec3() - self.p0).dot(self.normal));
        if h.iter().all(|h| *h <= self.eps) {
            return false;
        }
        let (mut a, mut b) = (DVec2::MAX, DVec2::MIN);
        for (p, h) in t.iter().zip(h) {
            let q = self.flat(p.as_dvec3() - self.sun * (h / self.along));
            a = a.min(q);
            b = b.max(q);
        }
        a.x <= self.hi.x && b.x >= self.lo.x && a.y <= self.hi.y && b.y >= self.lo.y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::count::view;
    use crate::scene::{SceneBuilder, SourceMesh};

    fn square(x0: f32, y0: f32, z: f32, size: f32) -> SourceMesh {
        SourceMesh {
            positions: vec![[x0, y0, z], [x0 + size, y0, z], [x0 + size, y0 + size, z], [x0, y0 + size, z]],
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    fn select(scene: &Scene, culling: &Culling, sun: DVec3) -> Option<DrawList> {
        let roof = &scene.receivers[0];
        let points: Vec<DVec3> = roof.triangles.iter().flatten().copied().collect();
        let view = view::fit(&points, sun, scene.bounds, scene.origin, 64);
        let target = Target { points: &points, normal: roof.normal, gpu_id: roof.gpu_id };
        let list = culling.select(&view.view_proj, &target, sun);
        assert_eq!(culling.may_be_shaded(&view.view_proj, &target, sun), list.is_some(), "the test alone agrees");
        list
    }

    #[test]
    fn only_geometry_whose_shadow_can_reach_the_receiver_counts() {
        let mut b = SceneBuilder::new();
        b.add_object("test", "ROOF", square(0.0, 0.0, 0.0, 1.0), true);
        b.add_object("test", "PLATE", square(3.0, 0.0, 1.0, 1.0), false);
        b.add_object("test", "BELOW", square(0.0, 0.0, -1.0, 1.0), false);
        let scene = b.build().unwrap();
        let culling = Culling::new(&scene, LEAF_TRIANGLES);
        // Overhead sun: the plate is 2 m to the east, the other square below: nothing shades.
        assert!(select(&scene, &culling, DVec3::Z).is_none());
        // Sun low in the east: the plate's shadow falls on the roof.
        assert!(select(&scene, &culling, DVec3::new(1.0, 0.0, 0.4).normalize()).is_some());
        // Sun low in the west: the plate's shadow goes the other way.
        assert!(select(&scene, &culling, DVec3::new(-1.0, 0.0, 0.4).normalize()).is_none());
    }

    #[test]
    fn a_view_draws_only_the_chunks_and_instances_in_its_prism() {
        // A receiver under one plate, a row of 5,000 small plates (static) from 10 m to 60 m east
        // and 3,000 instanced ones from 60 m to 90 m east, all 1 m up: an overhead sun draws none
        // of the far ones; a sun 1 in 75 above the eastern horizon draws some instances (those
        // whose shadow can reach the roof) but not all, and no more static chunks than two leaves.
        let mut b = SceneBuilder::new();
        b.add_object("test", "ROOF", square(0.0, 0.0, 0.0, 1.0), true);
        b.add_object("test", "PLATE", square(0.0, 0.0, 1.0, 1.0), false);
        let mut row = SourceMesh::default();
        for k in 0..5000u32 {
            let s = square(10.0 + 0.01 * k as f32, 0.0, 1.0, 0.005);
            row.indices.extend(s.indices.iter().map(|i| i + row.positions.len() as u32));
            row.positions.extend(s.positions);
        }
        b.add_object("test", "ROW", row, false);
        let shared = b.add_mesh("tile", square(0.0, 0.0, 0.0, 0.005));
        for k in 0..3000 {
            let transform = DMat4::from_translation(DVec3::new(60.0 + 0.01 * k as f64, 0.0, 1.0));
            let name = format!("T{k}");
            b.add_node(crate::scene::SourceNode { origin: name.clone(), name, mesh: shared, transform, receiver: false });
        }
        let scene = b.build().unwrap();
        let culling = Culling::new(&scene, LEAF_TRIANGLES);
        assert_eq!(culling.static_order().len(), 4 + 10_000);
        let overhead = select(&scene, &culling, DVec3::Z).unwrap();
        assert!(overhead.triangles(&culling) <= LEAF_TRIANGLES as usize, "{}", overhead.triangles(&culling));
        assert!(overhead.instances.is_empty());
        let low = select(&scene, &culling, DVec3::new(75.0, 0.0, 1.0).normalize()).unwrap();
        let slots: usize = low.instances.iter().map(|(_, s)| s.len()).sum();
        assert!(slots > 0 && slots < 3000, "{slots} instances drawn");
        let statics: usize = low.static_triangles.iter().map(|r| r.len()).sum();
        assert!(statics <= 2 * LEAF_TRIANGLES as usize, "{statics} static triangles drawn");
    }

    #[test]
    fn clusters_cover_every_triangle_once_within_their_boxes() {
        // 10,000 static triangles, 3,000 instances of 2 and two of a 300-triangle mesh (a mesh
        // placed once is merged into the static mesh).
        let mut b = SceneBuilder::new();
        let mut row = SourceMesh::default();
        for k in 0..5000u32 {
            let s = square(0.01 * k as f32, (k % 7) as f32, 1.0, 0.005);
            row.indices.extend(s.indices.iter().map(|i| i + row.positions.len() as u32));
            row.positions.extend(s.positions);
        }
        b.add_object("test", "ROW", row, false);
        let shared = b.add_mesh("tile", square(0.0, 0.0, 0.0, 0.005));
        let mut big = SourceMesh::default();
        for k in 0..150u32 {
            let s = square(0.0, k as f32, 0.0, 0.5);
            big.indices.extend(s.indices.iter().map(|i| i + big.positions.len() as u32));
            big.positions.extend(s.positions);
        }
        let big = b.add_mesh("big", big);
        for (k, mesh) in (0..3002).map(|k| (k, if k >= 3000 { big } else { shared })) {
            let transform = DMat4::from_translation(DVec3::new(60.0 + 0.01 * k as f64, 0.0, 1.0));
            let name = format!("T{k}");
            b.add_node(crate::scene::SourceNode { origin: name.clone(), name, mesh, transform, receiver: false });
        }
        let culling = Culling::new(&b.build().unwrap(), LEAF_TRIANGLES);
        let clusters = culling.clusters();
        let (triangles, _) = culling.triangles();
        assert_eq!(triangles.len(), 10_000 + 6_000 + 600);
        let mut next = 0;
        for c in &clusters {
            assert_eq!(c.first, next, "in order, no gap or overlap");
            assert!(c.count >= 1 && c.count <= CLUSTER_TRIANGLES, "{c:?}");
            for p in triangles[c.first as usize..(c.first + c.count) as usize].iter().flatten() {
                assert!(p.cmpge(c.lo).all() && p.cmple(c.hi).all(), "{p} outside {c:?}");
            }
            next += c.count;
        }
        assert_eq!(next as usize, triangles.len());
        // The static mesh's clusters are BVH nodes of 64-128 triangles.
        let statics: Vec<u32> = clusters.iter().filter(|c| c.first < 10_000).map(|c| c.count).collect();
        assert!(statics.iter().all(|&n| (64..=128).contains(&n)), "{statics:?}");
        // Each large instance is cut into even runs: 100 + 100 + 100.
        assert_eq!(clusters.iter().rev().take(6).map(|c| c.count).collect::<Vec<_>>(), [100; 6]);
        // The runs: the static mesh, then each shared mesh's placements; every cluster in one.
        let runs = culling.runs();
        let spans: Vec<(u32, u32, usize)> = runs.iter().map(|r| (r.first, r.per_instance, r.slots.len())).collect();
        assert_eq!(spans, [(0, 10_000, 1), (10_000, 2, 3000), (16_000, 300, 2)]);
        for c in &clusters {
            let inside = |r: &TriangleRun| c.first >= r.first && c.first + c.count <= r.first + r.per_instance * r.slots.len() as u32;
            assert_eq!(runs.iter().filter(|r| inside(r)).count(), 1, "{c:?} in one run");
        }
    }
}
