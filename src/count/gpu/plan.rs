//! Planning, on the CPU alone: which views need a render, which share a tile, where each tile
//! sits in the atlas, how its camera is fitted, what it draws, and at which sides adaptive
//! counting counts it. No device here, so all of it is unit-tested without a GPU.
//!
//! Requests for receivers of one view group ([`crate::count::group`]: a wall and the windows in
//! it) at the same sun and leaf fraction share a tile: the mask pass draws each requested member
//! with its own id, the scene is drawn once, and the count pass counts each member apart.

use std::borrow::Cow;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::ops::Range;

use glam::DVec3;

use super::{ADAPTIVE_FIRST_SIDE, Counted, CounterOptions};
use crate::count::cull::{Culling, DrawList, ShadeTest, Target};
use crate::count::group::{MAX_MEMBERS, ViewGroups};
use crate::count::view::{self, SunView};
use crate::count::{ViewRequest, check_receivers, cos_incidence, is_dark};
use crate::error::Result;
use crate::platform::Stopwatch;
use crate::scene::Scene;

/// The CPU side of an uploaded scene: what planning reads.
pub(super) struct SceneLayout {
    pub(super) receivers: Vec<ReceiverView>,
    pub(super) groups: ViewGroups,
    pub(super) bounds: (DVec3, DVec3),
    pub(super) origin: DVec3,
    /// The spatial index that picks what each view draws; its slot order is the order the
    /// instances are uploaded in, its static order the static mesh's triangles'.
    pub(super) culling: Culling,
}

impl SceneLayout {
    /// Indexes `scene` (leaves of `leaf_triangles` triangles) and fits each receiver's view
    /// inputs to that order. Slots: instances grouped by mesh and ordered spatially within it,
    /// so each BVH node of a mesh's placements is one instance range; the static mesh's
    /// triangles likewise.
    pub(super) fn new(scene: &Scene, leaf_triangles: u32) -> Self {
        let culling = Culling::new(scene, leaf_triangles);
        let mut slot_of = vec![0u32; culling.slot_order().len()];
        for (slot, &i) in culling.slot_order().iter().enumerate() {
            slot_of[i] = slot as u32;
        }
        let mut position = vec![0u32; culling.static_order().len()];
        for (p, &t) in culling.static_order().iter().enumerate() {
            position[t as usize] = p as u32;
        }
        let receivers = scene
            .receivers
            .iter()
            .map(|r| ReceiverView {
                gpu_id: r.gpu_id,
                mesh: scene.instances[r.draw.instance].mesh,
                indices: r.draw.indices.clone(),
                static_triangles: if r.draw.instance == 0 { static_ranges(&position, &r.draw.indices) } else { Vec::new() },
                slot: slot_of[r.draw.instance],
                points: distinct_points(r.triangles.iter().flatten()),
                normal: r.normal,
            })
            .collect();
        Self { receivers, groups: ViewGroups::find(scene), bounds: scene.bounds, origin: scene.origin, culling }
    }
}

/// The corners of a receiver's triangles, each bitwise-distinct one once, in first-seen order.
/// Fitting a view (hull, extents, depth) and the culling's prism (first corner, extents) give
/// bit for bit what the corners with their repeats give, for a half to two thirds fewer corners
/// (a triangulated polygon repeats each corner in several triangles): each tile's view is fitted
/// from these, which with the GPU's culling is most of the host's work a view.
pub(super) fn distinct_points<'a>(corners: impl Iterator<Item = &'a DVec3>) -> Vec<DVec3> {
    let mut seen = std::collections::HashSet::new();
    corners.filter(|p| seen.insert(p.to_array().map(f64::to_bits))).copied().collect()
}

/// What a view of one receiver needs: where to draw it alone, and how to fit the camera.
pub(super) struct ReceiverView {
    /// The id its pixels carry (its own, or the mirrored surface's).
    pub(super) gpu_id: u32,
    pub(super) mesh: usize,
    pub(super) indices: Range<u32>,
    /// For a receiver in the static mesh: its triangles' ranges in the culling's order.
    pub(super) static_triangles: Vec<Range<u32>>,
    pub(super) slot: u32,
    pub(super) points: Vec<DVec3>,
    pub(super) normal: DVec3,
}

/// One tile to render: requests of one view group at one sun and leaf fraction.
pub(super) struct Tile {
    /// Request indices, their receivers distinct, the group's owner first.
    pub(super) requests: Vec<usize>,
    pub(super) view: SunView,
    /// What its scene pass draws, as the CPU's culling chose it; `None` where the GPU's culling
    /// chooses ([`super::pulled`]).
    pub(super) draws: Option<DrawList>,
}

/// The sides views are counted at: with an accuracy target, ADAPTIVE_FIRST_SIDE doubling up to
/// `resolution` (which ends the ladder whatever it is); without, `resolution` alone.
pub(super) fn sides(options: &CounterOptions) -> Vec<u32> {
    let mut ladder = Vec::new();
    if options.accuracy.is_some() {
        let mut side = ADAPTIVE_FIRST_SIDE;
        while side < options.resolution {
            ladder.push(side);
            side *= 2;
        }
    }
    ladder.push(options.resolution);
    ladder
}

/// The side to count a tile again at, or None when its worst member's estimate meets the target
/// or it already had the largest side. The estimate falls about as side^1.5 (edge pixels grow as
/// the side, covered pixels as its square), so the predicted side is side·(worst/target)^(2/3);
/// at least the next step of the ladder, so every round makes progress.
pub(super) fn finer_side(ladder: &[u32], side: u32, worst: f64, target: f64) -> Option<u32> {
    if worst <= target {
        return None;
    }
    let predicted = side as f64 * (worst / target).powf(2.0 / 3.0);
    let mut finer = ladder.iter().copied().filter(|&s| s > side);
    let next = finer.clone().next()?;
    Some(finer.find(|&s| s as f64 >= predicted).unwrap_or_else(|| ladder.last().copied().unwrap_or(next)).max(next))
}

/// Tiles per submission at side `side` in an atlas of side `atlas_side`.
pub(super) fn tiles_at(atlas_side: u32, side: u32) -> usize {
    ((atlas_side / side) as usize).pow(2)
}

/// Where tile `slot` of a batch at side `side` sits in the atlas (its top-left pixel): row by
/// row.
pub(super) fn tile_origin(atlas_side: u32, slot: usize, side: u32) -> [u32; 2] {
    let (t, per_row) = (slot as u32, atlas_side / side);
    [(t % per_row) * side, (t / per_row) * side]
}

/// The outline points of a tile's members: the owner's alone, or the union of several.
fn tile_points<'a>(scene: &'a SceneLayout, requests: &[ViewRequest], members: &[usize]) -> Cow<'a, [DVec3]> {
    if let [only] = members {
        Cow::Borrowed(&scene.receivers[requests[*only].receiver as usize].points)
    } else {
        Cow::Owned(members.iter().flat_map(|&i| scene.receivers[requests[i].receiver as usize].points.iter().copied()).collect())
    }
}

/// The view of a tile's members (the union of their outlines) at side `side`.
pub(super) fn fit_tile(scene: &SceneLayout, requests: &[ViewRequest], members: &[usize], side: u32) -> SunView {
    let points = tile_points(scene, requests, members);
    view::fit(&points, requests[members[0]].sun, scene.bounds, scene.origin, side)
}

/// A multiply-rotate hasher (FxHash's) for [`plan_tiles`]' keys, a word at a time: the keys are
/// ids and sun bits the program made, so SipHash's guard against chosen keys buys nothing, and it
/// was a twentieth of planning a view.
#[derive(Default)]
struct WordHasher(u64);

impl Hasher for WordHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for word in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..word.len()].copy_from_slice(word);
            self.write_u64(u64::from_le_bytes(w));
        }
    }

    fn write_u64(&mut self, n: u64) {
        self.0 = (self.0.rotate_left(5) ^ n).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_u32(&mut self, n: u32) {
        self.write_u64(n as u64);
    }

    fn write_usize(&mut self, n: usize) {
        self.write_u64(n as u64);
    }
}

/// The open tile of each (view group, sun bits, leaf fraction bits).
type TileKeys = HashMap<(u32, [u64; 3], u32), usize, BuildHasherDefault<WordHasher>>;

/// Sorts the requests into tiles: dark ones get their cosine only, the others join the tile
/// of their view group, sun and leaf fraction (bitwise: the sampler asks for a wall and its
/// windows at the very same sun vectors). Each tile's view is fitted to its requested
/// members; a tile with nothing in front of any member gets fraction 1 without a render.
/// `culling_nanos` gains the time spent in the culling (a part of the planning, timed apart).
/// `gpu_culled`: the GPU's culling picks what each tile draws, so none is culled here and every
/// tile is rendered (one with nothing that shades its members counts all their pixels lit).
pub(super) fn plan_tiles(
    scene: &SceneLayout,
    requests: &[ViewRequest],
    side: u32,
    out: &mut [Counted],
    culling_nanos: &mut u64,
    gpu_culled: bool,
) -> Result<Vec<Tile>> {
    let mut open: TileKeys = TileKeys::with_capacity_and_hasher(requests.len(), Default::default());
    let mut pending: Vec<Vec<usize>> = Vec::new();
    check_receivers(scene.receivers.len(), requests)?;
    for (i, req) in requests.iter().enumerate() {
        let r = &scene.receivers[req.receiver as usize];
        out[i].cos_incidence = cos_incidence(r.normal, req.sun);
        if is_dark(r.normal, req.sun) {
            continue;
        }
        let (group, _) = scene.groups.place(req.receiver);
        let key = (group, req.sun.to_array().map(f64::to_bits), req.leaves.to_bits());
        // A receiver asked for twice (or a full tile) opens another tile.
        let joins = |t: &Vec<usize>| t.len() < MAX_MEMBERS && t.iter().all(|&j| requests[j].receiver != req.receiver);
        match open.get(&key) {
            Some(&t) if joins(&pending[t]) => pending[t].push(i),
            _ => {
                open.insert(key, pending.len());
                pending.push(vec![i]);
            }
        }
    }
    let mut tiles = Vec::with_capacity(pending.len());
    for mut members in pending {
        // The owner (largest outline) first: its plane and id guide the culling.
        members.sort_by_key(|&i| scene.groups.place(requests[i].receiver).1);
        let view = fit_tile(scene, requests, &members, side);
        if gpu_culled {
            tiles.push(Tile { requests: members, view, draws: None });
            continue;
        }
        let culling = Stopwatch::start();
        let selected = cull_on_cpu(scene, requests, &members, &view);
        *culling_nanos += culling.nanos();
        match selected {
            Some(draws) => tiles.push(Tile { requests: members, view, draws: Some(draws) }),
            // Nothing in the prism in front of any member: all fully sunlit, no render needed.
            None => members.iter().for_each(|&i| out[i].fraction = 1.0),
        }
    }
    Ok(tiles)
}

/// Whether anything in front of the tile of `members` (owner first) seen by `view` can shade
/// any of them: [`cull_on_cpu`]'s test alone.
pub(super) fn may_be_shaded(scene: &SceneLayout, requests: &[ViewRequest], members: &[usize], view: &SunView) -> bool {
    let owner = &scene.receivers[requests[members[0]].receiver as usize];
    let points = tile_points(scene, requests, members);
    let target = Target { points: &points, normal: owner.normal, gpu_id: owner.gpu_id };
    scene.culling.may_be_shaded(&view.view_proj, &target, requests[members[0]].sun)
}

/// What [`may_be_shaded`] decides the tile of `members` (owner first) seen by `view` by, for
/// the GPU's test ([`super::shade`]).
pub(super) fn shade_test(scene: &SceneLayout, requests: &[ViewRequest], members: &[usize], view: &SunView) -> ShadeTest {
    let owner = &scene.receivers[requests[members[0]].receiver as usize];
    let points = tile_points(scene, requests, members);
    let target = Target { points: &points, normal: owner.normal, gpu_id: owner.gpu_id };
    scene.culling.shade_test(&view.view_proj, &target, requests[members[0]].sun)
}

/// What the CPU's culling has the tile of `members` (owner first) seen by `view` draw, or `None`
/// when nothing can shade any of them.
pub(super) fn cull_on_cpu(scene: &SceneLayout, requests: &[ViewRequest], members: &[usize], view: &SunView) -> Option<DrawList> {
    let owner = &scene.receivers[requests[members[0]].receiver as usize];
    let points = tile_points(scene, requests, members);
    // The union of the members: the draw list covers every member's prism.
    let target = Target { points: &points, normal: owner.normal, gpu_id: owner.gpu_id };
    scene.culling.select(&view.view_proj, &target, requests[members[0]].sun)
}

/// A static receiver's triangles (an index range of the static mesh) as ranges of positions in
/// the culling's order.
fn static_ranges(position: &[u32], indices: &Range<u32>) -> Vec<Range<u32>> {
    let mut at: Vec<u32> = (indices.start / 3..indices.end / 3).map(|t| position[t as usize]).collect();
    at.sort_unstable();
    let mut ranges: Vec<Range<u32>> = Vec::new();
    for p in at {
        match ranges.last_mut() {
            Some(r) if r.end == p => r.end = p + 1,
            _ => ranges.push(p..p + 1),
        }
    }
    ranges
}

/// The triangles the culling would have each view draw, summed, and the number of views that
/// draw anything: what `sunlit bench` reports of the CPU's planning (each view alone, at side
/// `side`).
pub fn planned_triangles(scene: &super::GpuScene, requests: &[ViewRequest], side: u32) -> (usize, usize) {
    let layout = &scene.layout;
    let (mut sum, mut n) = (0usize, 0usize);
    for req in requests {
        let Some(r) = layout.receivers.get(req.receiver as usize) else { continue };
        if is_dark(r.normal, req.sun) {
            continue;
        }
        let v = view::fit(&r.points, req.sun, layout.bounds, layout.origin, side);
        let target = Target { points: &r.points, normal: r.normal, gpu_id: r.gpu_id };
        if let Some(list) = layout.culling.select(&v.view_proj, &target, req.sun) {
            sum += list.triangles(&layout.culling);
            n += 1;
        }
    }
    (sum, n)
}

/// The clip transform of each view of `requests` that faces the sun, each view alone at side
/// `side` (as [`planned_triangles`] fits them): what the GPU's culling pass
/// ([`super::cluster_cull`]) is timed on by `sunlit bench`.
pub fn planned_views(scene: &super::GpuScene, requests: &[ViewRequest], side: u32) -> Vec<glam::DMat4> {
    let layout = &scene.layout;
    let lit = |req: &&ViewRequest| layout.receivers.get(req.receiver as usize).is_some_and(|r| !is_dark(r.normal, req.sun));
    requests
        .iter()
        .filter(lit)
        .map(|req| view::fit(&layout.receivers[req.receiver as usize].points, req.sun, layout.bounds, layout.origin, side).view_proj)
        .collect()
}

/// The scene's clusters ([`crate::count::cull::Culling::clusters`]) in the uploaded order.
pub fn clusters(scene: &super::GpuScene) -> Vec<crate::count::cull::Cluster> {
    scene.layout.culling.clusters()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(resolution: u32, accuracy: Option<f64>) -> CounterOptions {
        CounterOptions { resolution, accuracy, ..Default::default() }
    }

    #[test]
    fn sides_double_from_the_first_up_to_the_resolution() {
        assert_eq!(sides(&options(512, None)), [512]);
        assert_eq!(sides(&options(512, Some(0.002))), [64, 128, 256, 512]);
        assert_eq!(sides(&options(300, Some(0.002))), [64, 128, 256, 300]);
        assert_eq!(sides(&options(48, Some(0.002))), [48]);
    }

    #[test]
    fn a_finer_side_is_predicted_from_the_estimate_and_always_progresses() {
        let ladder = sides(&options(512, Some(0.002)));
        assert_eq!(finer_side(&ladder, 64, 0.001, 0.002), None, "within the target");
        assert_eq!(finer_side(&ladder, 64, 0.0021, 0.002), Some(128), "just above: the next step");
        // 64·(0.015/0.002)^(2/3) = 245: the first side at least that.
        assert_eq!(finer_side(&ladder, 64, 0.015, 0.002), Some(256));
        assert_eq!(finer_side(&ladder, 64, f64::INFINITY, 0.002), Some(512), "no pixels: straight to the largest");
        assert_eq!(finer_side(&ladder, 512, 0.1, 0.002), None, "nothing finer");
    }

    // Planning without a GPU: a south wall, a window in it (a hole, so they form a view group),
    // an overhang in front of both, and a roof far away that nothing shades.
    use crate::count::cull::LEAF_TRIANGLES;
    use crate::scene::{SceneBuilder, SourceMesh};

    fn quad(corners: [[f32; 3]; 4]) -> SourceMesh {
        SourceMesh { positions: corners.to_vec(), indices: vec![0, 1, 2, 0, 2, 3] }
    }

    /// Wall x ∈ [0, 4], z ∈ [0, 3] at y = 0 facing south (−y), with a hole x ∈ [0.5, 3.5],
    /// z ∈ [0.5, 2.5] (half its outline) that the window fills; an overhang above; a roof 100 m
    /// east.
    fn scene() -> Scene {
        let mut b = SceneBuilder::new();
        let mut wall = SourceMesh::default();
        for [x0, z0, x1, z1] in [[0., 0., 4., 0.5], [0., 2.5, 4., 3.], [0., 0.5, 0.5, 2.5], [3.5, 0.5, 4., 2.5]] {
            let base = wall.positions.len() as u32;
            wall.positions.extend([[x0, 0., z0], [x1, 0., z0], [x1, 0., z1], [x0, 0., z1]]);
            wall.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
        }
        b.add_object("test", "Wall", wall, true);
        b.add_object("test", "Window", quad([[0.5, 0., 0.5], [3.5, 0., 0.5], [3.5, 0., 2.5], [0.5, 0., 2.5]]), true);
        b.add_object("test", "Overhang", quad([[0., -1., 2.9], [4., -1., 2.9], [4., 0., 2.9], [0., 0., 2.9]]), false);
        b.add_object("test", "Roof", quad([[100., 0., 5.], [101., 0., 5.], [101., 1., 5.], [100., 1., 5.]]), true);
        b.build().unwrap()
    }

    fn south(altitude: f64) -> DVec3 {
        let a = altitude.to_radians();
        DVec3::new(0.0, -a.cos(), a.sin())
    }

    fn plan(layout: &SceneLayout, requests: &[ViewRequest]) -> (Vec<Tile>, Vec<Counted>) {
        let mut out = vec![Counted::default(); requests.len()];
        let tiles = plan_tiles(layout, requests, 64, &mut out, &mut 0, false).unwrap();
        (tiles, out)
    }

    #[test]
    fn a_wall_and_its_window_share_one_tile_at_one_sun_and_leaf_fraction() {
        let scene = scene();
        let layout = SceneLayout::new(&scene, LEAF_TRIANGLES);
        let (wall, window) = (scene.receiver("Wall").unwrap().0, scene.receiver("Window").unwrap().0);
        let sun = south(40.0);
        let requests = [ViewRequest::new(window, sun), ViewRequest::new(wall, sun)];
        let (tiles, out) = plan(&layout, &requests);
        assert_eq!(tiles.len(), 1, "one tile for the group");
        assert_eq!(tiles[0].requests, [1, 0], "the owner (the wall, largest outline) first");
        assert!(out.iter().all(|c| c.cos_incidence > 0.7), "{out:?}");
        // Another leaf fraction, or the same receiver asked again, is another tile.
        let requests = [ViewRequest::new(wall, sun), ViewRequest::new(window, sun).with_leaves(0.5), ViewRequest::new(wall, sun)];
        assert_eq!(plan(&layout, &requests).0.len(), 3);
    }

    #[test]
    fn dark_views_and_views_with_nothing_in_front_need_no_render() {
        let scene = scene();
        let layout = SceneLayout::new(&scene, LEAF_TRIANGLES);
        let (wall, roof) = (scene.receiver("Wall").unwrap().0, scene.receiver("Roof").unwrap().0);
        let north = DVec3::new(0.0, 0.8, 0.6);
        let requests = [
            ViewRequest::new(wall, north),       // behind the wall
            ViewRequest::new(wall, south(-5.0)), // below the horizon
            ViewRequest::new(roof, south(40.0)), // nothing in front of it
            ViewRequest::new(wall, south(40.0)), // the overhang in front
        ];
        let (tiles, out) = plan(&layout, &requests);
        assert_eq!(tiles.len(), 1);
        assert_eq!(tiles[0].requests, [3]);
        assert!(out[0].cos_incidence < 0.0 && out[0].fraction == 0.0 && out[0].side == 0);
        assert_eq!((out[1].fraction, out[1].side), (0.0, 0));
        assert_eq!((out[2].fraction, out[2].side), (1.0, 0), "unshaded without a render");
        assert!(tiles[0].draws.as_ref().unwrap().triangles(&layout.culling) > 0, "the overhang is drawn");
    }

    #[test]
    fn an_unknown_receiver_is_refused() {
        let scene = scene();
        let layout = SceneLayout::new(&scene, LEAF_TRIANGLES);
        let mut out = vec![Counted::default(); 1];
        let e = plan_tiles(&layout, &[ViewRequest::new(9, south(40.0))], 64, &mut out, &mut 0, false).err().unwrap();
        assert_eq!(e.to_string(), "invalid receiver: id 9 out of range (3 receivers)");
    }

    #[test]
    fn tiles_fill_the_atlas_row_by_row() {
        assert_eq!(tiles_at(256, 64), 16);
        assert_eq!(tiles_at(2048, 512), 16);
        assert_eq!(tile_origin(256, 0, 64), [0, 0]);
        assert_eq!(tile_origin(256, 3, 64), [192, 0]);
        assert_eq!(tile_origin(256, 5, 64), [64, 64]);
    }
}
