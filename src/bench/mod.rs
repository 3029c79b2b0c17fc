//! Benchmark scenes and timing: synthetic occluder clouds of a chosen size, street trees in front
//! of a facade (by leaf count), the example office, and models after the paper's case studies ([`models`]) timed over the views `sunlit annual`
//! counts for its samples.
//!
//! Owns what `sunlit bench` measures, so the figures in docs/benchmarks.md come from one place.

pub mod models;

use std::collections::BTreeMap;

use glam::DVec3;

use crate::count::ViewRequest;
use crate::count::gpu::cluster_cull::GpuClusters;
use crate::count::gpu::plan::{clusters, planned_triangles, planned_views};
use crate::count::gpu::{Counted, Counter, GpuScene, HostStages};
use crate::count::lanes::{Lane, fractions_side_by_side};
use crate::error::Result;
use crate::scene::{Scene, SceneBuilder, SourceMesh};

/// A 10 m × 10 m horizontal receiver at z = 0 under a cloud of `triangles` random small
/// triangles (0.05–0.5 m) between 0.5 m and 10 m up, spread over 20 m × 20 m.
pub fn occluder_cloud(triangles: usize, seed: u64) -> Result<Scene> {
    let mut rng = SplitMix64(seed);
    let mut b = SceneBuilder::new();
    let floor = SourceMesh { positions: vec![[0., 0., 0.], [10., 0., 0.], [10., 10., 0.], [0., 10., 0.]], indices: vec![0, 1, 2, 0, 2, 3] };
    b.add_object("bench", "FLOOR", floor, true);
    let mut cloud = SourceMesh::default();
    for t in 0..triangles {
        let centre = DVec3::new(rng.range(-5.0, 15.0), rng.range(-5.0, 15.0), rng.range(0.5, 10.0));
        let size = rng.range(0.05, 0.5);
        for _ in 0..3 {
            let d = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * size;
            let p = centre + d;
            cloud.positions.push([p.x as f32, p.y as f32, p.z as f32]);
        }
        cloud.indices.extend([3 * t as u32, 3 * t as u32 + 1, 3 * t as u32 + 2]);
    }
    b.add_object("bench", "cloud", cloud, false);
    b.build()
}

/// Trees along a street: a 30 m × 12 m south facade at y = 0 in three storeys (receivers
/// `STOREY_1`–`STOREY_3`), and five trees 6 m in front of it (opaque trunks, crowns of radius 3 m
/// centred 8 m up) whose crowns hold `leaves` square leaves of 0.2 m between them, each crown
/// marked as foliage in its extras. As a glb, so the bench reads it the way a user's model is read.
pub fn street_trees_glb(leaves: usize, seed: u64) -> Vec<u8> {
    use crate::model::glb_write::GlbWriter;
    let mut rng = SplitMix64(seed);
    let mut w = GlbWriter::new();
    let quad = |x0: f32, x1: f32, z0: f32, z1: f32| vec![[x0, 0.0, z0], [x1, 0.0, z0], [x1, 0.0, z1], [x0, 0.0, z1]];
    for storey in 0..3 {
        let z = 4.0 * storey as f32;
        let m = w.add_mesh(&format!("storey {}", storey + 1), &quad(0.0, 30.0, z, z + 4.0), &[0, 1, 2, 0, 2, 3]);
        w.add_node(&format!("STOREY_{}", storey + 1), m, [0.0; 3], Some(serde_json::json!({"sunlit": {"receiver": true}})));
    }
    let trunk = {
        let (lo, hi) = ([-0.2f32, -0.2, 0.0], [0.2f32, 0.2, 6.0]);
        let c = |i: usize| {
            [if i & 1 == 0 { lo[0] } else { hi[0] }, if i & 2 == 0 { lo[1] } else { hi[1] }, if i & 4 == 0 { lo[2] } else { hi[2] }]
        };
        let quads: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let indices: Vec<u32> = quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
        w.add_mesh("trunk", &(0..8).map(c).collect::<Vec<_>>(), &indices)
    };
    for tree in 0..5 {
        let x = 3.0 + 6.0 * tree as f32;
        w.add_node(&format!("TRUNK_{}", tree + 1), trunk, [x, -6.0, 0.0], None);
        let count = leaves / 5 + usize::from(tree < leaves % 5);
        let crown = crown_mesh(&mut rng, DVec3::new(x as f64, -6.0, 8.0), 3.0, count);
        let m = w.add_mesh(&format!("crown {}", tree + 1), &crown.positions, &crown.indices);
        w.add_node(&format!("CROWN_{}", tree + 1), m, [0.0; 3], Some(serde_json::json!({"sunlit": {"foliage": true}})));
    }
    w.to_glb()
}

/// `count` randomly tilted square leaves (0.2 m) in a ball; a quad (two triangles) per leaf.
fn crown_mesh(rng: &mut SplitMix64, centre: DVec3, radius: f64, count: usize) -> SourceMesh {
    let mut mesh = SourceMesh::default();
    for _ in 0..count {
        let p = loop {
            let p = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            if p.length_squared() <= 1.0 {
                break centre + radius * p;
            }
        };
        let normal = DVec3::new(rng.range(-0.7, 0.7), rng.range(-0.7, 0.7), 1.0).normalize();
        push_leaf(&mut mesh, p, normal, 0.1);
    }
    mesh
}

/// Appends a square leaf (a quad, two triangles) of half-side `half` at `centre`, facing `normal`.
pub fn push_leaf(mesh: &mut SourceMesh, centre: DVec3, normal: DVec3, half: f64) {
    let u = normal.any_orthonormal_vector() * half;
    let v = normal.cross(u);
    let base = mesh.positions.len() as u32;
    for c in [centre - u - v, centre + u - v, centre + u + v, centre - u + v] {
        mesh.positions.push([c.x as f32, c.y as f32, c.z as f32]);
    }
    mesh.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// `count` sun directions spread over the sky above 10° altitude (deterministic).
pub fn suns(count: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64(seed);
    (0..count)
        .map(|_| {
            let az = rng.range(0.0, std::f64::consts::TAU);
            let alt = rng.range(10f64.to_radians(), 85f64.to_radians());
            DVec3::new(az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin())
        })
        .collect()
}

/// Timing of one benchmark case.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Timing {
    /// Case name.
    pub case: String,
    /// Triangles drawn per view.
    pub triangles: usize,
    /// Views requested.
    pub views: usize,
    /// Views rendered (the others were dark, or had nothing in front of the receiver).
    pub rendered: usize,
    /// Views answered without a render.
    pub skipped: usize,
    /// Seconds for all views (after one warm-up call).
    pub seconds: f64,
    /// Rendered views per second.
    pub views_per_second: f64,
}

/// Times `Counter::fractions` over every receiver × sun of a scene; one warm-up call first.
pub async fn time_views(counter: &Counter, case: &str, scene: &Scene, suns: &[DVec3], now: impl Fn() -> f64) -> Result<Timing> {
    let gpu: GpuScene = counter.upload(scene)?;
    let requests: Vec<ViewRequest> =
        suns.iter().flat_map(|&sun| (0..scene.receivers.len() as u32).map(move |receiver| ViewRequest::new(receiver, sun))).collect();
    counter.fractions(&gpu, &requests[..requests.len().min(counter.tiles_per_batch())]).await?;
    let start = now();
    let counted = counter.fractions(&gpu, &requests).await?;
    let seconds = now() - start;
    let rendered = counted.iter().filter(|c| c.side > 0).count();
    Ok(Timing {
        case: case.to_string(),
        triangles: scene.triangle_count(),
        views: requests.len(),
        rendered,
        skipped: requests.len() - rendered,
        seconds,
        views_per_second: rendered as f64 / seconds.max(1e-9),
    })
}

/// An even spread of about `at_most` requests, so a long benchmark can time it and extrapolate:
/// every k-th sun with all its requests (those at one sun adjacent, as `sample_requests` lists them).
pub fn spread(requests: &[ViewRequest], at_most: usize) -> Vec<ViewRequest> {
    // Whole suns: the views of a wall and its windows at one sun share a tile, which picking
    // single views would break up.
    let suns: Vec<&[ViewRequest]> = requests.chunk_by(|a, b| a.sun == b.sun).collect();
    let per_sun = requests.len() as f64 / suns.len().max(1) as f64;
    let wanted = ((at_most as f64 / per_sun).floor() as usize).max(1);
    let stride = suns.len().div_ceil(wanted).max(1);
    suns.into_iter().step_by(stride).flatten().copied().collect()
}

/// Timing of a batch of views of one uploaded scene.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ViewTiming {
    /// Views timed.
    pub views: usize,
    /// Views rendered.
    pub rendered: usize,
    /// Views answered without a render (sun behind the surface, or nothing in front of it).
    pub skipped: usize,
    /// Views in the tiles the GPU drew: `rendered` and those the GPU's culling then settled as
    /// unshaded (on the noop backend, whose verdicts read as zeros, every drawn view; there
    /// `seconds / drawn` is the host's cost a view).
    pub drawn: u64,
    /// Seconds for the timed views (after a warm-up batch, not counted).
    pub seconds: f64,
    /// Views timed per second (rendered or not).
    pub views_per_second: f64,
    /// Of `seconds`, about this much is the CPU's planning: fitting each view and choosing what
    /// it draws (timed again on its own, since the GPU work overlaps it).
    pub planning_seconds: f64,
    /// Mean triangles drawn per rendered view (the culling's choice).
    pub mean_triangles_drawn: f64,
    /// Tiles rendered: a tile counts one view, or several of one view group (a wall and its
    /// windows at one sun).
    pub tiles_rendered: u64,
    /// Mean triangles the scene pass drew per tile rendered.
    pub mean_triangles_per_tile: f64,
    /// Rendered views by the tile side they were last counted at (one side without an
    /// accuracy target; with one, how far adaptive counting had to go).
    pub sides: BTreeMap<u32, usize>,
    /// The host's time by stage during the timed count, summed over the lanes.
    pub host_stages: HostStages,
    /// Every timed view's count.
    #[serde(skip)]
    pub counted: Vec<Counted>,
}

/// The GPU's culling pass ([`crate::count::gpu::cluster_cull`]) timed over a model's views.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GpuCullTiming {
    /// Views culled (those facing the sun).
    pub views: usize,
    /// The scene's clusters.
    pub clusters: usize,
    /// Fitting the views on the CPU (what the pass reads).
    pub fitting_seconds: f64,
    /// The pass itself: its batches recorded, submitted and read back.
    pub seconds: f64,
    /// (view, cluster) pairs kept a view.
    pub pairs_per_view: f64,
    /// Triangles the kept clusters hold, a view.
    pub triangles_per_view: f64,
    /// Batches run again because their pair list overflowed.
    pub reruns: u32,
}

/// Views a batch of [`time_gpu_cull`] culls: the raster kernel's largest batches at 64².
pub const CULL_BATCH_VIEWS: usize = 1024;

/// Times the GPU's culling pass over the views of `requests` (at side `side`), in batches of
/// [`CULL_BATCH_VIEWS`], on `counter` with `gpu` uploaded to it.
pub async fn time_gpu_cull(
    counter: &Counter,
    gpu: &GpuScene,
    requests: &[ViewRequest],
    side: u32,
    now: impl Fn() -> f64,
) -> Result<GpuCullTiming> {
    let clusters = clusters(gpu);
    let on_gpu = GpuClusters::new(counter, &clusters);
    let start = now();
    let views = planned_views(gpu, requests, side);
    let fitting_seconds = now() - start;
    let start = now();
    let (mut pairs, mut triangles, mut reruns) = (0usize, 0u64, 0);
    // Room for the pairs of the batch before, so in steady state no batch runs twice.
    let mut capacity = 1 << 16;
    for batch in views.chunks(CULL_BATCH_VIEWS) {
        let culled = counter.cull_clusters(&on_gpu, batch, capacity).await?;
        pairs += culled.pairs.len();
        triangles += culled.pairs.iter().map(|&[_, c]| clusters[c as usize].count as u64).sum::<u64>();
        reruns += culled.reruns;
        capacity = capacity.max(culled.pairs.len() as u32);
    }
    let seconds = now() - start;
    let per_view = |n: f64| n / views.len().max(1) as f64;
    Ok(GpuCullTiming {
        views: views.len(),
        clusters: clusters.len(),
        fitting_seconds,
        seconds,
        pairs_per_view: per_view(pairs as f64),
        triangles_per_view: per_view(triangles as f64),
        reruns,
    })
}

/// The lanes' host stages added up.
fn lanes_host_stages(lanes: &[Lane<'_>]) -> HostStages {
    lanes.iter().map(|l| l.counter.host_stages()).fold(HostStages::default(), |a, b| a + b)
}

/// Times counting `requests` over the lanes (side by side); one warm-up batch a lane first.
pub async fn time_requests(lanes: &[Lane<'_>], requests: &[ViewRequest], now: impl Fn() -> f64) -> Result<ViewTiming> {
    let Some(&Lane { counter, gpu }) = lanes.first() else { return Err(crate::error::Error::argument("lanes", "none to count on")) };
    // Warm every lane (pipelines, first submission) outside the timing.
    let warm = requests.len().min(counter.tiles_per_batch() * lanes.len());
    fractions_side_by_side(lanes, &requests[..warm]).await?;
    let start = now();
    let rendered_so_far = || lanes.iter().fold((0, 0), |(t, n), l| (t + l.counter.rendered().0, n + l.counter.rendered().1));
    let before = rendered_so_far();
    let drawn_so_far = || lanes.iter().map(|l| l.counter.views_drawn()).sum::<u64>();
    let drawn_before = drawn_so_far();
    let stages_before = lanes_host_stages(lanes);
    let counted = fractions_side_by_side(lanes, requests).await?;
    let seconds = now() - start;
    let after = rendered_so_far();
    let views_drawn = drawn_so_far() - drawn_before;
    let stages_after = lanes_host_stages(lanes);
    let host_stages = stages_after - stages_before;
    let (tiles, triangles) = (after.0 - before.0, after.1 - before.1);
    let rendered = counted.iter().filter(|c| c.side > 0).count();
    let start = now();
    let (drawn, planned) = planned_triangles(gpu, requests, counter.resolution());
    let planning_seconds = now() - start;
    Ok(ViewTiming {
        views: requests.len(),
        rendered,
        skipped: requests.len() - rendered,
        drawn: views_drawn,
        seconds,
        views_per_second: requests.len() as f64 / seconds.max(1e-9),
        planning_seconds,
        mean_triangles_drawn: drawn as f64 / planned.max(1) as f64,
        tiles_rendered: tiles,
        host_stages,
        mean_triangles_per_tile: triangles as f64 / tiles.max(1) as f64,
        sides: counted.iter().filter(|c| c.side > 0).fold(BTreeMap::new(), |mut m, c| {
            *m.entry(c.side).or_insert(0) += 1;
            m
        }),
        counted,
    })
}

/// Counted fractions against the exact CPU reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactCheck {
    /// Rendered views checked.
    pub views: usize,
    /// Mean |counted − exact|.
    pub mean: f64,
    /// Largest |counted − exact|.
    pub max: f64,
    /// Views whose |error| exceeded their own [`Counted::error_estimate`] (with an accuracy
    /// target: how often the estimate that chose the side was too hopeful).
    pub above_estimate: usize,
}

/// For answers of a hybrid run: an even spread of at most `at_most` GPU-counted views against the
/// exact reference (their error), and as many exactly clipped views with something in front
/// (the fast engine against the straightforward reference; should be ~0).
pub fn check_answers(
    scene: &Scene,
    requests: &[ViewRequest],
    answers: &[crate::count::ViewAnswer],
    at_most: usize,
) -> (ExactCheck, ExactCheck) {
    let check = |picked: Vec<usize>| {
        let stride = picked.len().div_ceil(at_most.max(1)).max(1);
        let picked: Vec<usize> = picked.into_iter().step_by(stride).collect();
        let chosen: Vec<ViewRequest> = picked.iter().map(|&i| requests[i]).collect();
        let exact = crate::count::exact::sunlit_fractions(scene, &chosen);
        let errors: Vec<f64> = picked.iter().zip(&exact).map(|(&i, e)| (answers[i].fraction - e).abs()).collect();
        ExactCheck {
            views: errors.len(),
            mean: mean_abs(errors.iter().copied()),
            max: errors.iter().copied().fold(0.0, f64::max),
            above_estimate: 0,
        }
    };
    let gpu = (0..requests.len()).filter(|&i| answers[i].side.is_some()).collect();
    // Exactly clipped views that were neither dark nor unshaded: where clipping did work.
    let exact =
        (0..requests.len()).filter(|&i| answers[i].side.is_none() && answers[i].fraction > 0.0 && answers[i].fraction < 1.0).collect();
    (check(gpu), check(exact))
}

/// The mean of absolute errors; 0 (never −0: an empty `f64` sum is −0.0, which JSON shows as
/// `-0.0`) when there are none, as when every view was clipped exactly.
fn mean_abs(errors: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = errors.fold((0.0, 0usize), |(sum, n), e| (sum + e, n + 1));
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// Checks an even spread of at most `at_most` of the rendered views against the exact CPU
/// reference (the others are exact by construction).
pub fn check_exact(scene: &Scene, requests: &[ViewRequest], counted: &[Counted], at_most: usize) -> ExactCheck {
    let rendered: Vec<usize> = (0..requests.len()).filter(|&i| counted[i].side > 0).collect();
    let stride = rendered.len().div_ceil(at_most.max(1)).max(1);
    let picked: Vec<usize> = rendered.into_iter().step_by(stride).collect();
    let chosen: Vec<ViewRequest> = picked.iter().map(|&i| requests[i]).collect();
    let exact = crate::count::exact::sunlit_fractions(scene, &chosen);
    let errors: Vec<(f64, f64)> =
        picked.iter().zip(&exact).map(|(&i, e)| ((counted[i].fraction - e).abs(), counted[i].error_estimate())).collect();
    ExactCheck {
        views: errors.len(),
        mean: mean_abs(errors.iter().map(|e| e.0)),
        max: errors.iter().map(|e| e.0).fold(0.0, f64::max),
        above_estimate: errors.iter().filter(|(error, estimate)| error > estimate).count(),
    }
}

/// A small deterministic generator: benchmarks must not depend on a random crate's versions.
pub(crate) struct SplitMix64(pub(crate) u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::mean_abs;

    #[test]
    fn the_mean_of_no_errors_is_zero_not_negative_zero() {
        let none = mean_abs(std::iter::empty());
        assert!(none == 0.0 && none.is_sign_positive(), "{none:?}");
        assert_eq!(serde_json::json!(none).to_string(), "0.0");
        assert_eq!(mean_abs([0.25, 0.75].into_iter()), 0.5);
    }
}
