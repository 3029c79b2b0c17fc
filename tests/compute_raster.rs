//! The compute rasterizer (`Kernel::Compute`, shaders/compute_raster.wgsl) against its CPU truth
//! pixel for pixel (the hardware's rules written here again in plain i64), the fill rule on
//! shared edges through pixel centres, depth ties, a node pool forced to overflow, and real views
//! against the exact reference and the raster kernel (per-view histogram of differing pixels);
//! and the GPU culling pass (shaders/cull_clusters.wgsl) against its CPU truth, with a pair list
//! forced to overflow.
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;

use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use sunlit::count::gpu::{Counted, Counter, CounterOptions, Kernel};
use sunlit::count::{ViewRequest, exact};
use sunlit::scene::{NO_RECEIVER, Scene};

const CASTER: u32 = 7;
const NOTHING: u32 = 6;

fn compute_counter(resolution: u32) -> Counter {
    pollster::block_on(Counter::new(CounterOptions { resolution, kernel: Kernel::Compute, ..Default::default() }))
        .expect("a GPU adapter (lavapipe: apt-get install mesa-vulkan-drivers) — GPU tests never skip")
}

/// The CPU truth of one view: per pixel, row by row, the class of the nearest triangle (member
/// k, CASTER, NOTHING) | the members covering it << 3, with the hardware's rules: vertices
/// snapped to 1/256 pixel (ties to even), coverage at pixel centres, top-left fill rule, depth
/// in [0, 1] quantized to 29 bits, ties to the member. Triangles are in pixels, x right, y down.
fn truth(triangles: &[[[f32; 3]; 3]], ids: &[u32], members: &[u32], side: u32) -> Vec<u32> {
    let n = (side * side) as usize;
    let mut nearest = vec![u32::MAX; n];
    let mut cover = vec![0u32; n];
    for (t, id) in triangles.iter().zip(ids) {
        let class = members.iter().position(|m| m == id).map_or(CASTER, |k| k as u32);
        let snap = |v: f32| ((v * 256.0).round_ties_even() as i64).clamp(-(1 << 29), 1 << 29);
        let mut p: Vec<(i64, i64, f32)> = t.iter().map(|v| (snap(v[0]), snap(v[1]), v[2])).collect();
        let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
        if area == 0 {
            continue;
        }
        if area < 0 {
            p.swap(1, 2);
        }
        for y in 0..side {
            for x in 0..side {
                let (px, py) = (x as i64 * 256 + 128, y as i64 * 256 + 128);
                let inside = (0..3).all(|k| {
                    let (a, b) = (p[k], p[(k + 1) % 3]);
                    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                    let e = dx * (py - a.1) - dy * (px - a.0);
                    let top_left = (dy == 0 && dx > 0) || dy < 0;
                    e > 0 || (e == 0 && top_left)
                });
                // Constant depth per triangle in these tests: the plane is exact.
                let z = p[0].2;
                if !inside || !(0.0..=1.0).contains(&z) {
                    continue;
                }
                let q = ((z * 536_870_912.0) as u32).min((1 << 29) - 1);
                let at = (y * side + x) as usize;
                nearest[at] = nearest[at].min(q << 3 | class);
                if class != CASTER {
                    cover[at] |= 1 << class;
                }
            }
        }
    }
    nearest.iter().zip(&cover).map(|(&w, &c)| if w == u32::MAX { NOTHING } else { w & 7 } | c << 3).collect()
}

/// Per member (visible, covered) from pixels as `truth` gives them.
fn counts(pixels: &[u32], members: usize) -> Vec<[u32; 2]> {
    (0..members as u32)
        .map(|k| [pixels.iter().filter(|&&p| p & 7 == k).count() as u32, pixels.iter().filter(|&&p| p >> 3 & 1 << k != 0).count() as u32])
        .collect()
}

/// A coordinate on a 1/64-pixel grid: exact in f32 through the view transform, so the kernel's
/// and the truth's snapped vertices are the same numbers.
fn grid(rng: &mut SmallRng, lo: f32, hi: f32) -> f32 {
    (rng.random_range(lo..hi) * 64.0).round() / 64.0
}

#[test]
fn the_compute_rasterizer_matches_its_cpu_truth_pixel_for_pixel() {
    let counter = compute_counter(64);
    let mut rng = SmallRng::seed_from_u64(32);
    let members = [10u32, 11, 12];
    let side = 80; // not a multiple of the 32-pixel raster tile: partial tiles at the edges
    let mut differing = 0;
    for round in 0..6 {
        let mut triangles = Vec::new();
        let mut ids = Vec::new();
        // A mesh of shared edges: a jittered grid, corners on pixel centres half the time.
        let cells = 6;
        let step = side as f32 / cells as f32;
        let corner = |rng: &mut SmallRng, i: usize, j: usize| {
            let (x, y) = (i as f32 * step - 4.0, j as f32 * step - 4.0);
            if rng.random_bool(0.5) {
                [x.floor() + 0.5, y.floor() + 0.5]
            } else {
                [grid(rng, x - 3.0, x + 3.0), grid(rng, y - 3.0, y + 3.0)]
            }
        };
        let corners: Vec<Vec<[f32; 2]>> = (0..=cells).map(|i| (0..=cells).map(|j| corner(&mut rng, i, j)).collect()).collect();
        let z = 0.75;
        for i in 0..cells {
            for j in 0..cells {
                let [a, b, c, d] = [corners[i][j], corners[i + 1][j], corners[i + 1][j + 1], corners[i][j + 1]];
                let id = members[(i + j + round) % members.len()];
                for t in [[a, b, c], [a, c, d]] {
                    triangles.push(t.map(|p| [p[0], p[1], z]));
                    ids.push(id);
                }
            }
        }
        // Casters in front and behind, some beyond the view, some crossing depth 0 or 1.
        for _ in 0..30 {
            let z = [0.25, 0.5, 0.9, -0.1, 1.5][rng.random_range(0..5)];
            let t = [0; 3].map(|_| [grid(&mut rng, -40.0, 120.0), grid(&mut rng, -40.0, 120.0), z]);
            triangles.push(t);
            ids.push(if rng.random_bool(0.8) { NO_RECEIVER } else { members[0] });
        }
        let (gpu_counts, dump) = pollster::block_on(counter.compute_pixels(&triangles, &ids, &members, side)).unwrap();
        let want = truth(&triangles, &ids, &members, side);
        differing += dump.iter().zip(&want).filter(|(a, b)| a != b).count();
        let first = dump.iter().zip(&want).position(|(a, b)| a != b);
        assert_eq!(first, None, "round {round}: first differing pixel (x, y) = {:?}", first.map(|i| (i as u32 % side, i as u32 / side)));
        let truth_counts = counts(&want, members.len());
        for (k, (g, t)) in gpu_counts.iter().zip(&truth_counts).enumerate() {
            assert_eq!([g[0], g[1]], *t, "round {round}, member {k}: (visible, covered)");
        }
        assert!(truth_counts.iter().all(|c| c[1] > 500), "every member covers pixels: {truth_counts:?}");
    }
    assert_eq!(differing, 0);
}

#[test]
fn shared_edges_through_pixel_centres_count_each_pixel_once() {
    // A 32 × 32-pixel square, corners on pixel centres, cut into 4 × 4 cells of two triangles
    // each, the members alternating: every inner edge runs through pixel centres (axis-aligned
    // ones through a whole row or column, diagonals through one centre a pixel). With the
    // top-left rule each pixel belongs to exactly one triangle: 32² pixels in all, none twice.
    let counter = compute_counter(64);
    let members = [1u32, 2];
    let (x0, cell) = (8.5f32, 8.0f32);
    let mut triangles = Vec::new();
    let mut ids = Vec::new();
    for i in 0..4 {
        for j in 0..4 {
            let (x, y) = (x0 + i as f32 * cell, x0 + j as f32 * cell);
            let [a, b, c, d] = [[x, y], [x + cell, y], [x + cell, y + cell], [x, y + cell]];
            // Both diagonals' directions, and both windings.
            let pair = if (i + j) % 2 == 0 { [[a, b, c], [a, c, d]] } else { [[b, a, d], [b, d, c]] };
            for (k, t) in pair.into_iter().enumerate() {
                triangles.push(t.map(|p| [p[0], p[1], 0.5]));
                ids.push(members[k]);
            }
        }
    }
    let (gpu_counts, dump) = pollster::block_on(counter.compute_pixels(&triangles, &ids, &members, 64)).unwrap();
    let both = dump.iter().filter(|&&p| p >> 3 == 3).count();
    let covered: u32 = gpu_counts.iter().map(|c| c[1]).sum();
    assert_eq!(both, 0, "pixels drawn by both members");
    assert_eq!(covered, 32 * 32, "pixels covered: {gpu_counts:?}");
    assert_eq!(gpu_counts.iter().map(|c| c[0]).sum::<u32>(), 32 * 32, "every pixel visible once");
    let want = truth(&triangles, &ids, &members, 64);
    let first = dump.iter().zip(&want).position(|(a, b)| a != b);
    assert_eq!(first, None, "first pixel unlike the CPU truth (x, y) = {:?}", first.map(|i| (i % 64, i / 64)));
}

#[test]
fn depth_ties_go_to_the_member_and_nearer_casters_win() {
    let counter = compute_counter(64);
    let square =
        |x: f32, z: f32| [[[x, 4.0, z], [x + 16.0, 4.0, z], [x + 16.0, 20.0, z]], [[x, 4.0, z], [x + 16.0, 20.0, z], [x, 20.0, z]]];
    let step = 1.0 / (1u32 << 29) as f32;
    // Left: a caster at the member's very depth (tied: the member is seen); middle: a caster
    // a quarter step nearer, in the same quantization step (the same word: tied too); right: one
    // two steps
    // nearer (it shades). Near depth 2^-8, where f32 resolves steps finer than 2^-29 (from
    // 2^-6 on, f32's own spacing is coarser than the quantization, which then loses nothing).
    let member_z = 1.0 / 256.0 + step / 2.0;
    let mut triangles = Vec::new();
    let mut ids = Vec::new();
    for (x, caster_z) in [(0.0, member_z), (20.0, member_z - step / 4.0), (40.0, member_z - 2.0 * step)] {
        assert!(caster_z < member_z || x == 0.0, "representable in f32");
        for (z, id) in [(member_z, 3u32), (caster_z, NO_RECEIVER)] {
            triangles.extend(square(x + 0.5, z));
            ids.extend([id, id]);
        }
    }
    let (gpu_counts, _) = pollster::block_on(counter.compute_pixels(&triangles, &ids, &[3], 64)).unwrap();
    assert_eq!(gpu_counts[0][1], 3 * 256, "covered");
    assert_eq!(gpu_counts[0][0], 2 * 256, "visible: the two tied squares");
}

#[test]
fn tiles_that_stop_early_count_what_walking_every_triangle_counts() {
    // A 96² view (3 × 3 raster tiles). Two members tile the left two columns; the right column
    // has none, so its tiles stop at once. A caster in front covers the left column whole, so
    // its tiles stop once that caster is drawn; hundreds of small casters (many chunks of the
    // walk) lie over all three columns, in front of the members, behind them and tied with them,
    // so a tile that stopped while a member still showed, or skipped a caster it needed, counts
    // more visible pixels than the truth.
    let counter = compute_counter(96);
    let mut rng = SmallRng::seed_from_u64(29);
    let members = [10u32, 11];
    let side = 96;
    let rect =
        |x0: f32, y0: f32, x1: f32, y1: f32, z: f32| [[[x0, y0, z], [x1, y0, z], [x1, y1, z]], [[x0, y0, z], [x1, y1, z], [x0, y1, z]]];
    for round in 0..4 {
        let (mut triangles, mut ids) = (Vec::new(), Vec::new());
        for (k, x) in [0.0f32, 32.0].into_iter().enumerate() {
            triangles.extend(rect(x + 0.25, 0.25, x + 32.25, 96.25, 0.75));
            ids.extend([members[(k + round) % 2]; 2]);
        }
        triangles.extend(rect(-4.0, -4.0, 33.0, 100.0, 0.25));
        ids.extend([NO_RECEIVER; 2]);
        for _ in 0..400 {
            let (x, y) = (grid(&mut rng, -8.0, 100.0), grid(&mut rng, -8.0, 100.0));
            let z = [0.5, 0.75, 0.9][rng.random_range(0..3)];
            let t = [0; 3].map(|_| [x + grid(&mut rng, -6.0, 6.0), y + grid(&mut rng, -6.0, 6.0), z]);
            triangles.push(t);
            ids.push(NO_RECEIVER);
        }
        let want = counts(&truth(&triangles, &ids, &members, side), members.len());
        let early = pollster::block_on(counter.compute_counts(&triangles, &ids, &members, side)).unwrap();
        let (whole, _) = pollster::block_on(counter.compute_pixels(&triangles, &ids, &members, side)).unwrap();
        for k in 0..members.len() {
            assert_eq!([early[k][0], early[k][1]], want[k], "round {round}, member {k}: (visible, covered), stopping early");
            assert_eq!(early[k], whole[k], "round {round}, member {k}: stopping early against walking everything");
        }
        let visible: u32 = want.iter().map(|c| c[0]).sum();
        assert!(visible > 500 && visible < 32 * 96, "some of the middle column shaded, some not: {want:?}");
    }
}

/// Requests over a generated bench model: `suns` sun positions of its year at which `receiver`
/// faces the sun.
fn bench_scene(name: &str) -> (Scene, sunlit::sun::location::Location) {
    let model = sunlit::bench::models::generate(name).unwrap();
    let bytes = model.glb.to_glb();
    let scene = sunlit::model::load_bytes(&[(format!("{name}.glb"), bytes)], &Default::default()).unwrap();
    (scene, model.location)
}

fn spread_requests(scene: &Scene, location: &sunlit::sun::location::Location, at_most: usize) -> Vec<ViewRequest> {
    let all = sunlit::year::annual::sample_requests(scene, location, sunlit::year::samples::SamplingPlan::new(9, 9).unwrap()).unwrap();
    sunlit::bench::spread(&all, at_most)
}

/// 60 views of blaas-louvres at 128², counted by a compute counter with the default pool.
fn louvres_counted_once() -> (Scene, Vec<ViewRequest>, Counter, Vec<Counted>) {
    let (scene, location) = bench_scene("blaas-louvres");
    let requests = spread_requests(&scene, &location, 60);
    let counter = compute_counter(128);
    let counted = common::gpu_fractions(&counter, &scene, &requests);
    (scene, requests, counter, counted)
}

#[test]
fn an_overflowing_node_pool_is_grown_and_the_batch_counted_again() {
    let (scene, requests, roomy, want) = louvres_counted_once();
    assert_eq!(roomy.bin_pool().1, 0, "the default pool holds these views");
    let tight = compute_counter(128);
    tight.set_bin_capacity(64);
    let got = common::gpu_fractions(&tight, &scene, &requests);
    let (capacity, reruns) = tight.bin_pool();
    assert!(reruns >= 1 && capacity > 64, "grown to {capacity} after {reruns} reruns");
    assert!(want.iter().any(|c| c.visible > 0 && c.visible < c.covered), "some views partly shaded");
    assert_eq!(got, want, "counted again in full, never truncated");
}

#[test]
fn many_small_batches_count_what_one_batch_counts_and_size_their_pool_ahead() {
    // The same views in one batch and in batches of 7 views: no count may depend on which batch
    // a view lands in (the atlas origin, the pool, the jobs), and after the first batch each
    // batch's pool is sized from the one before, so none is counted twice.
    let (scene, requests, one, want) = louvres_counted_once();
    let (batches, views) = one.compute_batches();
    assert_eq!(batches, 1, "{views} views in one batch");
    let many = compute_counter(128);
    many.set_batch_views(7);
    let got = common::gpu_fractions(&many, &scene, &requests);
    let (batches, counted) = many.compute_batches();
    assert_eq!(counted, views);
    assert!(batches >= 3 && batches == views.div_ceil(7), "{batches} batches of {views} views");
    assert_eq!(many.bin_pool().1, 0, "no batch counted twice");
    assert!(want.iter().any(|c| c.visible > 0 && c.visible < c.covered), "some views partly shaded");
    assert_eq!(got, want);
    // A pool far too small and nothing planned for it: the first batch is counted again, and
    // the pool of every batch after it is planned from the nodes a triangle took before.
    let tight = compute_counter(128);
    tight.set_batch_views(7);
    tight.set_bin_capacity(64);
    let got = common::gpu_fractions(&tight, &scene, &requests);
    let (capacity, reruns) = tight.bin_pool();
    println!("{} batches, pool {capacity} nodes after {reruns} reruns", tight.compute_batches().0);
    assert_eq!(reruns, 1, "only the first batch counted twice");
    assert_eq!(got, want);
}

/// Raster and compute counts of the same requests, and per rendered view the pixels where the two
/// kernels disagree on the member's visibility or coverage (one batch: at most 16 views at 512²).
fn kernels_side_by_side(scene: &Scene, requests: &[ViewRequest], side: u32) -> (Vec<Counted>, Vec<Counted>, Vec<usize>) {
    let raster = common::counter(side);
    let raster_scene = raster.upload(scene).unwrap();
    let by_raster = pollster::block_on(raster.fractions(&raster_scene, requests)).unwrap();
    let (atlas_side, atlas) = pollster::block_on(raster.read_atlas()).unwrap();
    let compute = compute_counter(side);
    let compute_scene = compute.upload(scene).unwrap();
    compute.dump_pixels(true);
    let by_compute = pollster::block_on(compute.fractions(&compute_scene, requests)).unwrap();
    let rendered: Vec<usize> = (0..requests.len()).filter(|&i| by_raster[i].side > 0).collect();
    assert!(rendered.len() <= raster.tiles_per_batch(), "one batch");
    let dump = pollster::block_on(compute.read_dump(rendered.len(), side)).unwrap();
    let mut differing = Vec::new();
    for (slot, &i) in rendered.iter().enumerate() {
        let id = raster_scene.gpu_id(requests[i].receiver);
        let [x0, y0] = raster.tile_of(slot, side);
        let mut n = 0;
        for y in 0..side {
            for x in 0..side {
                let [red, green] = atlas[((y0 + y) * atlas_side + x0 + x) as usize];
                let c = dump[(slot as u32 * side * side + y * side + x) as usize];
                n += ((red == id) != (c & 7 == 0) || (green == id) != (c >> 3 & 1 == 1)) as usize;
            }
        }
        differing.push(n);
    }
    (by_raster, by_compute, differing)
}

/// Pixels a view's compute count may differ from the raster path's, out of 512² (see
/// docs/benchmarks-gpu.md, "The compute rasterizer"): both sample pixel centres with 8-bit
/// snapping and the top-left rule, but the raster path transforms a placed mesh in two f32 steps
/// on the GPU where the compute kernel reads corners placed once on the host, and interpolates
/// depth its own way; either moves a snapped corner by a subpixel now and then, which flips the
/// pixels whose centres lie within that subpixel of an edge.
const DIFFERING_PIXELS_BOUND: usize = 16;

#[test]
fn bench_views_compute_raster_and_exact_agree() {
    // blaas-buildings (the bench model tests/cli.rs checks): 16 views one per sun, each its own
    // tile, so both kernels count them in one batch and the pixels can be compared.
    let (scene, location) = bench_scene("blaas-buildings");
    let all = spread_requests(&scene, &location, 400);
    let mut requests: Vec<ViewRequest> = Vec::new();
    for r in &all {
        let n = scene.receivers[r.receiver as usize].normal;
        if requests.len() < 16 && r.sun.dot(n) > 0.3 && r.sun.z > 0.2 && requests.iter().all(|q| q.sun != r.sun) {
            requests.push(*r);
        }
    }
    let (by_raster, by_compute, differing) = kernels_side_by_side(&scene, &requests, 512);
    let truth = exact::sunlit_fractions(&scene, &requests);
    let mut worst = [0.0f64; 2];
    for (i, e) in truth.iter().enumerate() {
        worst[0] = worst[0].max((by_raster[i].fraction - e).abs());
        worst[1] = worst[1].max((by_compute[i].fraction - e).abs());
    }
    let mut histogram = std::collections::BTreeMap::new();
    for &n in &differing {
        *histogram.entry(n).or_insert(0) += 1;
    }
    println!(
        "blaas-buildings, {} views at 512²: max |raster − exact| {:.5}, max |compute − exact| {:.5}",
        requests.len(),
        worst[0],
        worst[1]
    );
    println!("pixels differing compute vs raster, per view: {differing:?}; histogram (pixels: views) {histogram:?}");
    assert!(truth.iter().filter(|e| **e > 0.02 && **e < 0.98).count() >= 4, "partly shaded views: {truth:?}");
    assert!(worst[0] <= 0.001 && worst[1] <= 0.001, "max |error| raster {}, compute {}", worst[0], worst[1]);
    assert!(differing.iter().all(|&n| n <= DIFFERING_PIXELS_BOUND), "{differing:?}");
}

/// A city of 3,000 random boxes (36,000 triangles, ~400 clusters) and 40 views fitted to random
/// squares at random suns, as the counter fits them; the clusters and their clip transforms.
fn culling_case() -> (Vec<sunlit::count::cull::Cluster>, Vec<glam::DMat4>) {
    use glam::DVec3;
    let mut rng = SmallRng::seed_from_u64(32);
    let mut s = common::TestScene::new();
    for k in 0..3000 {
        let lo = DVec3::new(rng.random_range(0.0..200.0), rng.random_range(0.0..200.0), 0.0);
        let size = DVec3::new(rng.random_range(1.0..8.0), rng.random_range(1.0..8.0), rng.random_range(2.0..30.0));
        s.cuboid(&format!("B{k}"), lo, lo + size);
    }
    let scene = s.build();
    let culling = sunlit::count::cull::Culling::new(&scene, sunlit::count::cull::LEAF_TRIANGLES);
    let views = (0..40)
        .map(|_| {
            let at = DVec3::new(rng.random_range(0.0..200.0), rng.random_range(0.0..200.0), rng.random_range(0.0..20.0));
            let points = [at, at + DVec3::X * 3.0, at + DVec3::new(3.0, 0.0, 3.0), at + DVec3::Z * 3.0];
            let (azimuth, altitude) = (rng.random_range(0.0..360.0f64).to_radians(), rng.random_range(5.0..85.0f64).to_radians());
            let sun = DVec3::new(azimuth.sin() * altitude.cos(), -azimuth.cos() * altitude.cos(), altitude.sin());
            sunlit::count::view::fit(&points, sun, scene.bounds, scene.origin, 64).view_proj
        })
        .collect();
    (culling.clusters(), views)
}

/// The CPU truth of the cull pass, written apart from both culls: a cluster is kept where the
/// clip coordinates of its box's eight corners span a range that meets x, y in [−1 − s, 1 + s]
/// and depth in [−s, 1 + s].
fn culled_truth(clusters: &[sunlit::count::cull::Cluster], views: &[glam::DMat4], s: f64) -> std::collections::BTreeSet<[u32; 2]> {
    let mut kept = std::collections::BTreeSet::new();
    for (v, m) in views.iter().enumerate() {
        for (c, cluster) in clusters.iter().enumerate() {
            let (lo, hi) = (cluster.lo.as_dvec3(), cluster.hi.as_dvec3());
            let corners = (0..8).map(|i| {
                m.project_point3(glam::DVec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                ))
            });
            let (a, b) = corners.fold((glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
            if a.x <= 1.0 + s && b.x >= -1.0 - s && a.y <= 1.0 + s && b.y >= -1.0 - s && a.z <= 1.0 + s && b.z >= -s {
                kept.insert([v as u32, c as u32]);
            }
        }
    }
    kept
}

#[test]
fn the_gpu_cull_keeps_the_pairs_its_cpu_truth_keeps_and_writes_their_draw() {
    use sunlit::count::cull::{CLIP_SLACK, CLUSTER_TRIANGLES};
    use sunlit::count::gpu::cluster_cull::GpuClusters;
    let (clusters, views) = culling_case();
    assert!(clusters.len() > 5 * 64, "several workgroups of clusters: {}", clusters.len());
    let counter = common::counter(64);
    let gpu = GpuClusters::new(&counter, &clusters);
    let culled = pollster::block_on(counter.cull_clusters(&gpu, &views, 1 << 16)).unwrap();
    assert_eq!(culled.reruns, 0);
    let got: std::collections::BTreeSet<[u32; 2]> = culled.pairs.iter().copied().collect();
    assert_eq!(got.len(), culled.pairs.len(), "each pair once");
    // f32 on the GPU against f64 here: pairs within 1e-5 of the slack's edge may go either way.
    let (must, may) = (culled_truth(&clusters, &views, CLIP_SLACK - 1e-5), culled_truth(&clusters, &views, CLIP_SLACK + 1e-5));
    assert!(must.len() > views.len() && may.len() < views.len() * clusters.len() / 4, "a cull that keeps some: {}", must.len());
    assert!(must.is_subset(&got), "missed: {:?}", must.difference(&got).take(5).collect::<Vec<_>>());
    assert!(got.is_subset(&may), "kept beyond the volume: {:?}", got.difference(&may).take(5).collect::<Vec<_>>());
    assert_eq!(culled.draw, [3 * CLUSTER_TRIANGLES, culled.pairs.len() as u32, 0, 0], "one instance a pair");
}

#[test]
fn an_overflowing_pair_list_is_run_again_never_truncated() {
    use sunlit::count::gpu::cluster_cull::GpuClusters;
    let (clusters, views) = culling_case();
    let counter = common::counter(64);
    let gpu = GpuClusters::new(&counter, &clusters);
    let roomy = pollster::block_on(counter.cull_clusters(&gpu, &views, 1 << 16)).unwrap();
    let tight = pollster::block_on(counter.cull_clusters(&gpu, &views, 16)).unwrap();
    assert!(roomy.pairs.len() > 16);
    assert_eq!(tight.reruns, 1, "run again once, with as many pairs as it needed");
    let sorted = |p: &[[u32; 2]]| p.iter().copied().collect::<std::collections::BTreeSet<_>>();
    assert_eq!(sorted(&tight.pairs), sorted(&roomy.pairs));
    assert_eq!(tight.draw, roomy.draw);
}

#[test]
fn the_walk_counts_each_tiles_entries_rows_and_pixels() {
    // A 64² view (2 × 2 raster tiles) covered by one member's square (two triangles whose boxes
    // hold every pixel centre of every tile) and one small caster in the first tile whose box
    // holds 8 × 8 pixel centres. Each tile sets up the square's two triangles (one a half of the
    // workgroup), 32 rows of 32 pixel centres each; the first tile also walks the caster (one
    // half), 8 rows of 8; then every tile has nothing left to walk.
    let options = CounterOptions { resolution: 64, kernel: Kernel::Compute, walk_stats: true, ..Default::default() };
    let counter = pollster::block_on(Counter::new(options)).expect("a GPU adapter");
    let (a, b, c, d) = ([-1.0, -1.0, 0.5], [65.0, -1.0, 0.5], [65.0, 65.0, 0.5], [-1.0, 65.0, 0.5]);
    let triangles = vec![[a, b, c], [a, c, d], [[2.0, 2.0, 0.25], [10.0, 2.0, 0.25], [2.0, 10.0, 0.25]]];
    let ids = [10, 10, NO_RECEIVER];
    let counts = pollster::block_on(counter.compute_counts(&triangles, &ids, &[10], 64)).unwrap();
    let walk = counter.walk_stats();
    assert_eq!([walk.tiles, walk.entries, walk.set_up], [4, 9, 9], "{walk:?}");
    assert_eq!([walk.rows, walk.pixels], [4 * 64 + 8, 4 * 2048 + 64], "{walk:?}");
    // Counting the walk changes no count.
    let plain = pollster::block_on(compute_counter(64).compute_counts(&triangles, &ids, &[10], 64)).unwrap();
    assert_eq!(counts, plain);
    assert_eq!(counts[0][1], 64 * 64, "the square covers the view");
    assert_eq!(compute_counter(64).walk_stats(), Default::default(), "nothing counted unless asked for");
}
