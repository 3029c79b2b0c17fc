//! The GPU pixel counter against analytic truths and the exact polygon-clipping reference.
//! These need a GPU adapter (lavapipe in CI) and never skip.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;

use common::*;
use glam::DVec3;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use sunlit::count::{ViewRequest, exact};
use sunlit::scene::{Scene, SourceMesh};

/// Pixel counting at 512² is good to about three decimals.
const TOL: f64 = 0.005;

fn check(scene: &Scene, cases: &[(&str, DVec3, f64)]) {
    let counter = counter(512);
    let requests: Vec<ViewRequest> = cases.iter().map(|(n, s, _)| ViewRequest::new(receiver_id(scene, n), *s)).collect();
    let gpu = gpu_fractions(&counter, scene, &requests);
    for ((name, sun, want), got) in cases.iter().zip(&gpu) {
        let exact = exact::sunlit_fraction(scene, ViewRequest::new(receiver_id(scene, name), *sun));
        // Scene vertices are f32: the exact reference agrees with the analytic value to ~1e-8.
        assert!((exact - want).abs() < 1e-6, "{name} sun {sun}: exact {exact} vs analytic {want}");
        assert!((got.fraction - want).abs() < TOL, "{name} sun {sun}: gpu {} vs analytic {want} ({got:?})", got.fraction);
    }
}

/// 2 m × 1 m south window (z 1..2) with an overhang of depth d at its top, wider than the window.
fn overhang_scene(depth: f64) -> Scene {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.0, 1.0, 2.0, 0.0), true);
    s.polygon("OVERHANG", &flat_rect(-5.0, 7.0, -depth, 0.0, 2.0), false);
    s.build()
}

#[test]
fn overhang_due_south() {
    // Shadow depth on the wall = d·tanα below the top edge.
    let d = 0.5;
    let scene = overhang_scene(d);
    let cases: Vec<(&str, DVec3, f64)> = [10.0f64, 30.0, 45.0, 60.0, 63.0, 70.0]
        .iter()
        .map(|&alt| ("WIN", sun(180.0, alt), 1.0 - (d * alt.to_radians().tan()).min(1.0)))
        .collect();
    check(&scene, &cases);
}

#[test]
fn overhang_oblique_sun() {
    // A long overhang: shadow depth on the wall = d·tanα / cosγ, γ the azimuth off the normal.
    let d = 0.4;
    let scene = overhang_scene(d);
    let cases: Vec<(&str, DVec3, f64)> = [(200.0f64, 40.0f64), (150.0, 50.0), (240.0, 25.0)]
        .iter()
        .map(|&(az, alt)| {
            let gamma = (az - 180.0f64).to_radians();
            ("WIN", sun(az, alt), 1.0 - (d * alt.to_radians().tan() / gamma.cos()).min(1.0))
        })
        .collect();
    check(&scene, &cases);
}

#[test]
fn side_fin() {
    // 1 m × 2 m window (x 0..1, z 0..2) with a fin at x = 1.0 sticking out 0.5 m to the south,
    // full height. Sun from the south-east at azimuth 180 − γ: the fin's shadow is a vertical
    // band of width 0.5·tanγ from x = 1 westwards.
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 1.0, 0.0, 2.0, 0.0), true);
    s.polygon(
        "FIN",
        &[DVec3::new(1.0, -0.5, -1.0), DVec3::new(1.0, 0.0, -1.0), DVec3::new(1.0, 0.0, 5.0), DVec3::new(1.0, -0.5, 5.0)],
        false,
    );
    let scene = s.build();
    let cases: Vec<(&str, DVec3, f64)> =
        [20.0f64, 45.0, 60.0].iter().map(|&g| ("WIN", sun(180.0 - g, 30.0), 1.0 - (0.5 * g.to_radians().tan()).min(1.0))).collect();
    check(&scene, &cases);
}

#[test]
fn concave_l_shaped_receiver_and_wall_with_window_hole() {
    // L-shaped roof: the 2×2 square minus its north-east quarter, z = 0, as three unit squares.
    let mut s = TestScene::new();
    let l = SourceMesh {
        positions: vec![[0., 0., 0.], [1., 0., 0.], [2., 0., 0.], [0., 1., 0.], [1., 1., 0.], [2., 1., 0.], [0., 2., 0.], [1., 2., 0.]],
        indices: vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4, 3, 4, 7, 3, 7, 6],
    };
    s.mesh("ROOF_L", l, true);
    // A plate over the western half (x 0..1) at 1 m: with the sun overhead it hides 2 of 3 m².
    s.polygon("PLATE", &flat_rect(0.0, 1.0, 0.0, 2.0, 1.0), false);
    // A 4 × 3 wall (x 10..14, z 0..3) at y = 0 with a 2 × 1 hole (x 11..13, z 1..2) holding a window.
    let wall = SourceMesh {
        positions: [(10., 0.), (14., 0.), (14., 3.), (10., 3.), (11., 1.), (13., 1.), (13., 2.), (11., 2.)]
            .iter()
            .map(|&(x, z)| [x as f32, 0.0, z as f32])
            .collect(),
        // Four trapezoids around the hole, counter-clockwise seen from the south (−y).
        indices: vec![0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7],
    };
    s.mesh("WALL", wall, true);
    s.polygon("WIN", &south_rect(11.0, 13.0, 1.0, 2.0, 0.0), true);
    // Overhang 1 m deep at z = 3 over the whole wall; sun due south at 45°: shadow 1 m deep.
    s.polygon("OVERHANG", &flat_rect(9.0, 15.0, -1.0, 0.0, 3.0), false);
    let scene = s.build();
    check(
        &scene,
        &[
            ("ROOF_L", DVec3::Z, 1.0 / 3.0),
            // Wall: 12 − 2 = 10 m²; shaded z 2..3 = 4 m² → 0.6. Window (z 1..2) just clear → 1.
            ("WALL", sun(180.0, 45.0), 0.6),
            ("WIN", sun(180.0, 45.0), 1.0),
            // At atan(1.5): shadow 1.5 m deep: wall loses 4 + 0.5·4 − 0.5·2 = 5 m² → 0.5; window half.
            ("WALL", sun(180.0, 1.5f64.atan().to_degrees()), 0.5),
            ("WIN", sun(180.0, 1.5f64.atan().to_degrees()), 0.5),
        ],
    );
}

#[test]
fn back_facing_sun_down_and_geometry_behind() {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.0, 0.0, 2.0, 0.0), true);
    // A big box north of (behind) the window, taller than it: it must not shade.
    s.cuboid("BEHIND", DVec3::new(-3.0, 0.5, -1.0), DVec3::new(5.0, 4.0, 6.0));
    let scene = s.build();
    check(
        &scene,
        &[("WIN", sun(0.0, 30.0), 0.0), ("WIN", sun(180.0, -5.0), 0.0), ("WIN", sun(180.0, 30.0), 1.0), ("WIN", sun(120.0, 10.0), 1.0)],
    );
}

#[test]
fn instanced_and_baked_occluders_shade_alike() {
    use glam::DMat4;
    use sunlit::scene::{SceneBuilder, SourceNode};
    // Two identical slats placed by one shared mesh vs the same slats as separate meshes.
    let slat = |y: f32| SourceMesh {
        positions: vec![[-5., y - 0.3, 1.5], [7., y - 0.3, 1.5], [7., y, 1.5], [-5., y, 1.5]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let window = SourceMesh { positions: vec![[0., 0., 0.], [2., 0., 0.], [2., 0., 2.], [0., 0., 2.]], indices: vec![0, 1, 2, 0, 2, 3] };
    let node = |name: &str, mesh, dz: f64, receiver| SourceNode {
        name: name.into(),
        origin: format!("test: node '{name}'"),
        mesh,
        transform: DMat4::from_translation(DVec3::new(0.0, 0.0, dz)),
        receiver,
    };
    let mut shared = SceneBuilder::new();
    let w = shared.add_mesh("w", window.clone());
    let m = shared.add_mesh("slat", slat(0.0));
    shared.add_node(node("WIN", w, 0.0, true));
    shared.add_node(node("S0", m, 0.0, false));
    shared.add_node(node("S1", m, -1.0, false));
    let shared = shared.build().unwrap();
    assert!(shared.meshes.len() == 2 && shared.instances.len() == 3, "slats stay instanced");
    let mut baked = SceneBuilder::new();
    let w = baked.add_mesh("w", window);
    let a = baked.add_mesh("a", slat(0.0));
    let b = baked.add_mesh("b", slat(0.0));
    baked.add_node(node("WIN", w, 0.0, true));
    baked.add_node(node("S0", a, 0.0, false));
    baked.add_node(node("S1", b, -1.0, false));
    let baked = baked.build().unwrap();
    let counter = counter(512);
    let requests: Vec<ViewRequest> =
        [(180.0, 30.0), (200.0, 50.0), (150.0, 20.0)].iter().map(|&(az, alt)| ViewRequest::new(0, sun(az, alt))).collect();
    let a = gpu_fractions(&counter, &shared, &requests);
    let b = gpu_fractions(&counter, &baked, &requests);
    let e = exact::sunlit_fractions(&shared, &requests);
    for i in 0..requests.len() {
        assert_eq!(a[i].visible, b[i].visible, "same pixels either way");
        assert!((a[i].fraction - e[i]).abs() < TOL, "{} vs exact {}", a[i].fraction, e[i]);
        assert!(e[i] > 0.05 && e[i] < 0.95, "the case shades partly: {}", e[i]);
    }
}

/// A random planar quad: a parallelogram with random centre, orientation and sides.
fn random_quad(rng: &mut SmallRng, centre_box: f64, size: (f64, f64)) -> Vec<DVec3> {
    let c =
        DVec3::new(rng.random_range(-centre_box..centre_box), rng.random_range(-centre_box..centre_box), rng.random_range(0.0..centre_box));
    let a = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize()
        * rng.random_range(size.0..size.1);
    let b0 = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let b = (b0 - a * (b0.dot(a) / a.length_squared())).normalize() * rng.random_range(size.0..size.1);
    vec![c - a - b, c + a - b, c + a + b, c - a + b]
}

#[test]
fn random_scenes_match_the_exact_reference() {
    let counter = counter(512);
    let mut errors: Vec<f64> = Vec::new();
    let mut partial = 0;
    for seed in 0..12u64 {
        let mut rng = SmallRng::seed_from_u64(seed);
        let mut s = TestScene::new();
        for r in 0..4 {
            s.polygon(&format!("R{r}"), &random_quad(&mut rng, 3.0, (0.5, 2.5)), true);
        }
        for o in 0..30 {
            let q = random_quad(&mut rng, 4.0, (0.1, 1.0));
            // Mix triangles and quads.
            let corners = if o % 2 == 0 { q[..3].to_vec() } else { q };
            s.polygon(&format!("O{o}"), &corners, false);
        }
        let scene = s.build();
        let suns: Vec<DVec3> = (0..6).map(|_| sun(rng.random_range(0.0..360.0), rng.random_range(5.0..85.0))).collect();
        let requests: Vec<ViewRequest> =
            suns.iter().flat_map(|&sun| (0..scene.receivers.len() as u32).map(move |receiver| ViewRequest::new(receiver, sun))).collect();
        let gpu = gpu_fractions(&counter, &scene, &requests);
        let exact = exact::sunlit_fractions(&scene, &requests);
        for (g, e) in gpu.iter().zip(&exact) {
            errors.push((g.fraction - e).abs());
            partial += (*e > 0.01 && *e < 0.99) as usize;
        }
    }
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let max = errors.iter().cloned().fold(0.0, f64::max);
    println!("GPU vs exact at 512²: {} views ({partial} partly shaded), mean |error| {mean:.5}, max {max:.5}", errors.len());
    assert!(partial > 50, "the random cases must exercise partial shading, got {partial}");
    assert!(mean <= 0.002, "mean |error| {mean}");
    assert!(max <= 0.005, "max |error| {max}");
}

#[test]
fn culled_views_of_a_large_scene_match_the_exact_reference() {
    // Enough geometry for several BVH leaves: 4,000 small baked triangles and 400 instanced
    // boxes over 24 m × 24 m, above and among 6 receivers. Each view draws only the leaves in
    // its prism; the fractions must still match the exact reference, which clips everything.
    use glam::DMat4;
    use sunlit::count::cull::Target;
    use sunlit::count::view;
    use sunlit::scene::{SceneBuilder, SourceNode};
    let mut rng = SmallRng::seed_from_u64(99);
    let mut b = SceneBuilder::new();
    for r in 0..6 {
        let q = random_quad(&mut rng, 8.0, (1.0, 2.0));
        let positions = q.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
        b.add_object("test", &format!("R{r}"), SourceMesh { positions, indices: vec![0, 1, 2, 0, 2, 3] }, true);
    }
    let mut cloud = SourceMesh::default();
    for t in 0..4000u32 {
        let q = random_quad(&mut rng, 12.0, (0.05, 0.3));
        cloud.positions.extend(q[..3].iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]));
        cloud.indices.extend([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    b.add_object("test", "CLOUD", cloud, false);
    let cube = common::cube_mesh(0.25);
    let mesh = b.add_mesh("cube", cube);
    for k in 0..400 {
        let at = DVec3::new(rng.random_range(-12.0..12.0), rng.random_range(-12.0..12.0), rng.random_range(0.5..8.0));
        let name = format!("C{k}");
        b.add_node(SourceNode { origin: name.clone(), name, mesh, transform: DMat4::from_translation(at), receiver: false });
    }
    let scene = b.build().unwrap();
    let suns: Vec<DVec3> = (0..8).map(|_| sun(rng.random_range(0.0..360.0), rng.random_range(15.0..85.0))).collect();
    let requests: Vec<ViewRequest> =
        suns.iter().flat_map(|&sun| (0..scene.receivers.len() as u32).map(move |receiver| ViewRequest::new(receiver, sun))).collect();
    let counter = counter(512);
    let gpu = counter.upload(&scene).unwrap();
    let counted = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap();
    // The static mesh split over buffers of 1,000 triangles (as for a device with a small buffer
    // limit) draws the same pixels.
    let split = counter.upload_in_chunks(&scene, 1000).unwrap();
    let again = pollster::block_on(counter.fractions(&split, &requests)).unwrap();
    for (a, b) in counted.iter().zip(&again) {
        assert_eq!((a.visible, a.covered), (b.visible, b.covered));
    }
    let exact = exact::sunlit_fractions(&scene, &requests);
    let (mut drawn, mut rendered, mut partial, mut max) = (0usize, 0usize, 0usize, 0.0f64);
    let mut sum = 0.0;
    for ((req, g), e) in requests.iter().zip(&counted).zip(&exact) {
        let err = (g.fraction - e).abs();
        sum += err;
        max = max.max(err);
        partial += (*e > 0.01 && *e < 0.99) as usize;
        let r = &scene.receivers[req.receiver as usize];
        if g.covered > 0 {
            let points: Vec<DVec3> = r.triangles.iter().flatten().copied().collect();
            let v = view::fit(&points, req.sun, scene.bounds, scene.origin, 512);
            let list =
                gpu.culling().select(&v.view_proj, &Target { points: &points, normal: r.normal, gpu_id: r.gpu_id }, req.sun).unwrap();
            drawn += list.triangles(gpu.culling());
            rendered += 1;
        }
    }
    let mean = sum / requests.len() as f64;
    let share = drawn as f64 / (rendered.max(1) * scene.triangle_count()) as f64;
    println!(
        "culled GPU vs exact: {} views ({rendered} rendered, {partial} partly shaded), mean |error| {mean:.5}, max {max:.5}; \
         {:.0}% of {} triangles drawn per rendered view",
        requests.len(),
        100.0 * share,
        scene.triangle_count()
    );
    assert!(partial > 10, "the cases must exercise partial shading, got {partial}");
    assert!(share < 0.3, "culling must leave most of the scene out, drew {share}");
    assert!(mean <= 0.002, "mean |error| {mean}");
    assert!(max <= 0.005, "max |error| {max}");
}

#[test]
fn compute_count_equals_a_cpu_count_of_the_id_atlas() {
    // CPU reference of count_pixels.wgsl: count target ids in each tile of the read-back atlas.
    let scene = overhang_scene(0.6);
    let counter = counter(128);
    let requests: Vec<ViewRequest> = (0..10).map(|i| ViewRequest::new(0, sun(150.0 + 6.0 * i as f64, 20.0 + 5.0 * i as f64))).collect();
    let gpu = counter.upload(&scene).unwrap();
    let counted = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap();
    let (side, ids) = pollster::block_on(counter.read_ids()).unwrap();
    let res = counter.resolution();
    for (slot, c) in counted.iter().enumerate() {
        let [x0, y0] = counter.tile_of(slot, res);
        let mut n = 0;
        for y in y0..y0 + res {
            for x in x0..x0 + res {
                n += (ids[(y * side + x) as usize] == 0) as u32;
            }
        }
        assert_eq!(c.visible, n, "view {slot}");
        assert!(c.covered >= c.visible && c.covered > 0);
        // Covered pixels estimate the projected area A·cosθ / Ap (the paper's denominator).
        let projected = c.covered as f64 * c.pixel_area;
        let expect = 2.0 * c.cos_incidence;
        assert!((projected / expect - 1.0).abs() < 0.02, "covered·Ap {projected} vs A·cosθ {expect}");
    }
}

#[test]
fn louvre_slats_parallel_to_the_window_edges() {
    // Ten thin slats parallel to the window's edges: on a pixel grid aligned with the window their
    // edge errors add up (0.007 seen at 512²); the turned grid must keep every view within TOL.
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.5, 1.0, 2.5, 0.0), true);
    for i in 0..10 {
        let z = 1.05 + 0.15 * i as f64;
        s.cuboid(&format!("SLAT{i}"), DVec3::new(-2.0, -0.35, z), DVec3::new(4.5, -0.1, z + 0.02));
    }
    let scene = s.build();
    let suns: Vec<DVec3> = (0..24).map(|i| sun(130.0 + 4.0 * i as f64, 10.0 + 2.5 * i as f64)).collect();
    let requests: Vec<ViewRequest> = suns.iter().map(|&sun| ViewRequest::new(0, sun)).collect();
    let gpu = gpu_fractions(&counter(512), &scene, &requests);
    let exact = exact::sunlit_fractions(&scene, &requests);
    let worst = gpu.iter().zip(&exact).map(|(g, e)| (g.fraction - e).abs()).fold(0.0, f64::max);
    println!("louvres: max |gpu − exact| {worst:.5}");
    assert!(exact.iter().filter(|e| **e > 0.02 && **e < 0.98).count() > 10, "mostly partial shading: {exact:?}");
    assert!(worst <= TOL, "max |error| {worst}");
}

/// The louvre window of [`louvre_slats_parallel_to_the_window_edges`] and 60 suns over it.
fn louvre_window() -> (Scene, Vec<ViewRequest>) {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.5, 1.0, 2.5, 0.0), true);
    for i in 0..10 {
        let z = 1.05 + 0.15 * i as f64;
        s.cuboid(&format!("SLAT{i}"), DVec3::new(-2.0, -0.35, z), DVec3::new(4.5, -0.1, z + 0.02));
    }
    // A post beside the window: one straight shadow edge for the suns from the west.
    s.cuboid("POST", DVec3::new(2.6, -1.0, 0.0), DVec3::new(2.8, -0.8, 3.0));
    let requests = (0..60).map(|i| ViewRequest::new(0, sun(100.0 + 2.7 * i as f64, 5.0 + 1.1 * i as f64))).collect();
    (s.build(), requests)
}

#[test]
fn adaptive_resolution_meets_its_accuracy_against_the_exact_reference() {
    // With a target, each view is counted at 64² and again, finer, where its shadow edges make
    // the estimated error larger than the target. Every view must then be within the target, and
    // the sides must differ between views (the point: few pixels where few are needed).
    let (scene, requests) = louvre_window();
    let exact = exact::sunlit_fractions(&scene, &requests);
    let target = 0.002;
    let adaptive = gpu_fractions(&adaptive_counter(512, target), &scene, &requests);
    let coarse = gpu_fractions(&counter(64), &scene, &requests);
    let error =
        |counted: &[sunlit::count::gpu::Counted]| counted.iter().zip(&exact).map(|(g, e)| (g.fraction - e).abs()).fold(0.0, f64::max);
    let mut sides: Vec<u32> = adaptive.iter().map(|c| c.side).filter(|&s| s > 0).collect();
    sides.sort();
    sides.dedup();
    println!("adaptive ±{target}: max |error| {:.5} at sides {sides:?}; fixed 64²: {:.5}", error(&adaptive), error(&coarse));
    assert!(exact.iter().filter(|e| **e > 0.02 && **e < 0.98).count() > 20, "mostly partial shading: {exact:?}");
    assert!(error(&coarse) > target, "64² alone must miss the target, or the test shows nothing");
    assert!(error(&adaptive) <= target, "adaptive counting missed its target: {}", error(&adaptive));
    assert!(sides.len() >= 2 && sides[0] < 512, "one side for all views: {sides:?}");
    for (c, e) in adaptive.iter().zip(&exact) {
        assert!(c.side == 512 || c.error_estimate() <= target, "{c:?} stopped above its target");
        assert!((c.fraction - e).abs() <= c.error_estimate().max(1e-9) || c.side == 512, "{c:?}: exact {e}, beyond its estimate");
    }
}

#[test]
fn edge_counts_equal_a_cpu_count_of_the_id_atlas() {
    // CPU reference of count_pixels.wgsl's edge pairs: right and lower neighbours both covered by
    // the member, one visible and one not. (Resolution 64 with a target: one side, edges on.)
    let (scene, requests) = louvre_window();
    let requests = &requests[..12];
    let counter = adaptive_counter(64, 0.5);
    let gpu = counter.upload(&scene).unwrap();
    let counted = pollster::block_on(counter.fractions(&gpu, requests)).unwrap();
    let (side, atlas) = pollster::block_on(counter.read_atlas()).unwrap();
    let id = scene.receivers[0].gpu_id;
    let mut edged = 0;
    // Tiles follow the rendered views in order.
    for (slot, c) in counted.iter().filter(|c| c.side > 0).enumerate() {
        let [x0, y0] = counter.tile_of(slot, 64);
        let texel = |x: u32, y: u32| atlas[((y0 + y) * side + x0 + x) as usize];
        let pair = |a: [u32; 2], b: [u32; 2]| (a[1] == id && b[1] == id && (a[0] == id) != (b[0] == id)) as u32;
        let mut edges = 0;
        for y in 0..64 {
            for x in 0..64 {
                if x + 1 < 64 {
                    edges += pair(texel(x, y), texel(x + 1, y));
                }
                if y + 1 < 64 {
                    edges += pair(texel(x, y), texel(x, y + 1));
                }
            }
        }
        assert_eq!(c.edges, edges, "view {slot}");
        edged += (edges > 0) as usize;
    }
    assert!(edged > 6, "most views have shadow edges: {edged}");
}

/// A 4 × 3 m south wall (x 0..4, z 0..3, y = 0) with two 1.6 × 2.2 m holes (x 0.2..1.8 and
/// 2.2..3.8, z 0.4..2.6) holding the windows WIN_A and WIN_B (29% of the wall's outline each,
/// enough to share its view), an overhang 0.8 m deep along its top and five louvre slats in
/// front of the windows.
fn facade_scene() -> Scene {
    let mut wall = SourceMesh::default();
    for (x0, x1, z0, z1) in [(0.0, 4.0, 0.0, 0.4), (0.0, 4.0, 2.6, 3.0), (0.0, 0.2, 0.4, 2.6), (1.8, 2.2, 0.4, 2.6), (3.8, 4.0, 0.4, 2.6)] {
        let base = wall.positions.len() as u32;
        wall.positions.extend(south_rect(x0, x1, z0, z1, 0.0).iter().map(|p| p.as_vec3().to_array()));
        wall.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    }
    let mut s = TestScene::new();
    s.mesh("WALL", wall, true);
    s.polygon("WIN_A", &south_rect(0.2, 1.8, 0.4, 2.6, 0.0), true);
    s.polygon("WIN_B", &south_rect(2.2, 3.8, 0.4, 2.6, 0.0), true);
    s.polygon("OVERHANG", &flat_rect(-1.0, 5.0, -0.8, 0.0, 3.0), false);
    for i in 0..5 {
        let z = 0.6 + 0.4 * i as f64;
        s.cuboid(&format!("SLAT{i}"), DVec3::new(0.0, -0.45, z), DVec3::new(4.0, -0.25, z + 0.03));
    }
    s.build()
}

fn facade_suns() -> Vec<DVec3> {
    (0..8).map(|i| sun(120.0 + 15.0 * i as f64, 15.0 + 7.0 * i as f64)).collect()
}

#[test]
fn a_wall_and_its_windows_counted_in_one_view_match_the_exact_reference() {
    let scene = facade_scene();
    let [wall, a, b] = ["WALL", "WIN_A", "WIN_B"].map(|n| receiver_id(&scene, n));
    let counter = counter(512);
    let gpu = counter.upload(&scene).unwrap();
    let shared: Vec<Vec<u32>> = gpu.view_groups().shared().map(|m| m.to_vec()).collect();
    assert_eq!(shared, vec![vec![wall, a, b]], "the wall owns the group, the windows follow");
    // Every sun for all three; then, at the same suns, partial groups: a window alone, and the
    // wall with one window (a receiver asked for twice at one sun opens another tile).
    let suns = facade_suns();
    let mut requests: Vec<ViewRequest> =
        suns.iter().flat_map(|&sun| [wall, a, b].map(|receiver| ViewRequest::new(receiver, sun))).collect();
    requests.extend(suns.iter().step_by(2).map(|&sun| ViewRequest::new(a, sun)));
    requests.extend(suns.iter().skip(1).step_by(2).flat_map(|&sun| [b, wall].map(|receiver| ViewRequest::new(receiver, sun))));
    let (tiles_before, _) = counter.rendered();
    let got = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap();
    let tiles = counter.rendered().0 - tiles_before;
    let lit = got.iter().filter(|c| c.covered > 0).count();
    assert_eq!(lit, requests.len(), "every view is rendered (the overhang is always in front)");
    assert_eq!(tiles as usize, 8 + 4 + 4, "one tile per sun and group");
    let exact = exact::sunlit_fractions(&scene, &requests);
    let mut worst: f64 = 0.0;
    for ((req, g), e) in requests.iter().zip(&got).zip(&exact) {
        assert!(
            (g.fraction - e).abs() < TOL,
            "{} sun {}: gpu {} vs exact {e}",
            scene.receivers[req.receiver as usize].name,
            req.sun,
            g.fraction
        );
        worst = worst.max((g.fraction - e).abs());
    }
    println!("facade, grouped: max |gpu − exact| {worst:.5} over {} views in {tiles} tiles", requests.len());
    assert!(exact.iter().filter(|e| **e > 0.05 && **e < 0.95).count() > 20, "mostly partial shading: {exact:?}");
    // The windows' views alone (ungrouped tiles) agree with their grouped counts.
    let alone: Vec<ViewRequest> = suns.iter().map(|&sun| ViewRequest::new(b, sun)).collect();
    let single = pollster::block_on(counter.fractions(&gpu, &alone)).unwrap();
    for (k, s) in single.iter().enumerate() {
        let grouped = got[3 * k + 2];
        assert!((s.fraction - grouped.fraction).abs() < TOL, "WIN_B alone {} vs grouped {}", s.fraction, grouped.fraction);
        assert!(s.covered > 2 * grouped.covered, "alone it has its own tile");
    }
}

#[test]
fn grouped_compute_counts_equal_a_cpu_count_of_the_id_atlas() {
    // CPU reference of count_pixels.wgsl for tiles of several members: per member, visible where
    // red is its id and covered where green is its id.
    let scene = facade_scene();
    let ids = ["WALL", "WIN_A", "WIN_B"].map(|n| receiver_id(&scene, n));
    let counter = counter(128);
    let gpu = counter.upload(&scene).unwrap();
    // Tiles follow their first request; members the group's order (wall first). Sun 2 counts
    // the windows only.
    let suns = &facade_suns();
    let members = |k: usize| if k == 2 { &ids[1..] } else { &ids[..] };
    let requests: Vec<ViewRequest> =
        (0..suns.len()).flat_map(|k| members(k).iter().rev().map(move |&receiver| ViewRequest::new(receiver, suns[k]))).collect();
    let counted = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap();
    let (side, atlas) = pollster::block_on(counter.read_atlas()).unwrap();
    let res = counter.resolution();
    let mut next = 0;
    for k in 0..suns.len() {
        let [x0, y0] = counter.tile_of(k, res);
        let tile: Vec<[u32; 2]> =
            (y0..y0 + res).flat_map(|y| (x0..x0 + res).map(move |x| (y * side + x) as usize)).map(|i| atlas[i]).collect();
        for &r in members(k).iter().rev() {
            let c = counted[next];
            next += 1;
            let id = scene.receivers[r as usize].gpu_id;
            let visible = tile.iter().filter(|t| t[0] == id).count() as u32;
            let covered = tile.iter().filter(|t| t[1] == id).count() as u32;
            assert_eq!((c.visible, c.covered), (visible, covered), "sun {k}, receiver {r}");
            assert!(covered > 0 && visible <= covered);
        }
        // Nothing but the tile's members in green.
        assert!(tile.iter().all(|t| t[1] == sunlit::scene::NO_RECEIVER || members(k).contains(&t[1])));
    }
}
