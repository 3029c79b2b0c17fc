//! The fast exact engine against the reference clipping, view by view.

use super::*;
use crate::scene::{SceneBuilder, SourceMesh, SourceNode};
use glam::DMat4;

/// A box [lo, hi] as 12 triangles, outward.
fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> SourceMesh {
    open_cuboid(lo, hi, &[])
}

/// A box [lo, hi] without the faces whose outward normal is in `open` (±1, ±2, ±3 for ±x,
/// ±y, ±z): a tube when two opposite faces are left out.
fn open_cuboid(lo: [f32; 3], hi: [f32; 3], open: &[i32]) -> SourceMesh {
    let c =
        |i: u32| [if i & 1 == 0 { lo[0] } else { hi[0] }, if i & 2 == 0 { lo[1] } else { hi[1] }, if i & 4 == 0 { lo[2] } else { hi[2] }];
    let quads: [([u32; 4], i32); 6] =
        [([0, 2, 3, 1], -3), ([4, 5, 7, 6], 3), ([0, 1, 5, 4], -2), ([2, 6, 7, 3], 2), ([0, 4, 6, 2], -1), ([1, 3, 7, 5], 1)];
    SourceMesh {
        positions: (0..8).map(c).collect(),
        indices: quads.iter().filter(|(_, n)| !open.contains(n)).flat_map(|(q, _)| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect(),
    }
}

fn wall() -> SourceMesh {
    SourceMesh { positions: vec![[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]], indices: vec![0, 1, 2, 0, 2, 3] }
}

/// A south wall under 40 instanced slats and some baked boxes, one straddling the wall's plane.
fn louvred_wall() -> Scene {
    let mut b = SceneBuilder::new();
    b.add_object("test", "WALL", wall(), true);
    b.add_object("test", "BOX", cuboid([1.0, -1.0, 2.0], [1.5, -0.5, 2.4]), false);
    b.add_object("test", "THROUGH", cuboid([2.5, -0.4, 1.0], [3.0, 0.3, 1.2]), false);
    let slat = b.add_mesh("slat", cuboid([-0.5, -0.3, 0.0], [4.5, -0.1, 0.04]));
    for k in 0..40 {
        let transform = DMat4::from_translation(DVec3::new(0.0, 0.0, 0.075 * k as f64));
        let name = format!("S{k}");
        b.add_node(SourceNode { origin: name.clone(), name, mesh: slat, transform, receiver: false });
    }
    b.build().unwrap()
}

#[test]
fn the_fast_engine_agrees_with_the_reference() {
    let scene = louvred_wall();
    let engine = ExactEngine::new(&scene);
    assert_eq!(engine.convex_objects(), 1 + 2 + 40, "the wall (flat, it shades other receivers), two boxes, the slats");
    let mut requests = Vec::new();
    for az in [120.0f64, 150.0, 180.0, 200.0, 240.0] {
        for alt in [5.0f64, 20.0, 35.0, 60.0] {
            let (a, h) = (az.to_radians(), alt.to_radians());
            requests.push(ViewRequest::new(0, DVec3::new(h.cos() * a.sin(), h.cos() * a.cos(), h.sin())));
        }
    }
    let fast = engine.fractions(&requests);
    let reference = super::super::sunlit_fractions(&scene, &requests);
    let mut partly = 0;
    for ((f, r), q) in fast.iter().zip(&reference).zip(&requests) {
        assert!((f - r).abs() < 1e-6, "{q:?}: fast {f}, reference {r}");
        partly += usize::from(*r > 0.01 && *r < 0.99);
    }
    assert!(partly >= 10, "only {partly} views partly shaded");
}

/// A roof under upright square tubes (both ends open), one of them through the roof's plane,
/// and a cup (a box open at the bottom).
fn tubes_over_a_roof() -> Scene {
    let roof = SourceMesh { positions: vec![[0., 0., 0.], [4., 0., 0.], [4., 3., 0.], [0., 3., 0.]], indices: vec![0, 1, 2, 0, 2, 3] };
    let mut b = SceneBuilder::new();
    b.add_object("test", "ROOF", roof, true);
    b.add_object("test", "TUBE", open_cuboid([0.5, 1.0, 0.5], [1.1, 1.6, 2.0], &[-3, 3]), false);
    b.add_object("test", "THROUGH", open_cuboid([2.0, 0.5, -0.5], [2.4, 0.9, 1.0], &[-3, 3]), false);
    b.add_object("test", "CUP", open_cuboid([2.8, 1.8, 0.9], [3.4, 2.4, 1.5], &[-3]), false);
    b.build().unwrap()
}

#[test]
fn open_tubes_cast_their_hull_unless_the_sun_looks_down_their_bore() {
    let scene = tubes_over_a_roof();
    let engine = ExactEngine::new(&scene);
    assert_eq!(engine.convex_objects(), 4, "the roof, the tubes and the cup are each one object");
    let sun = |az: f64, alt: f64| {
        let (a, h) = (az.to_radians(), alt.to_radians());
        DVec3::new(h.cos() * a.sin(), h.cos() * a.cos(), h.sin())
    };
    // Straight down the bores (the tubes' sides are edge-on: only the cup shades), just off
    // them (light through part of each bore) and well off them (the hull is the shadow).
    let mut suns = vec![DVec3::Z];
    for az in [0.0f64, 45.0, 100.0, 180.0, 250.0] {
        for alt in [89.5f64, 87.0, 80.0, 72.0, 70.0, 60.0, 30.0] {
            suns.push(sun(az, alt));
        }
    }
    let requests: Vec<ViewRequest> = suns.iter().map(|&s| ViewRequest::new(0, s)).collect();
    let fast = engine.fractions(&requests);
    let reference = super::super::sunlit_fractions(&scene, &requests);
    for ((f, r), q) in fast.iter().zip(&reference).zip(&requests) {
        assert!((f - r).abs() < 1e-6, "{q:?}: fast {f}, reference {r}");
    }
    let cup = 0.6 * 0.6 / 12.0;
    assert!((fast[0] - (1.0 - cup)).abs() < 1e-6, "overhead only the cup shades: {}", fast[0]);
    let partly = reference.iter().filter(|r| **r > 0.01 && **r < 0.99).count();
    assert!(partly >= 20, "only {partly} views partly shaded");
}

/// An open prism of `sides` faces around `axis` (no end faces), centred at `centre`.
fn open_prism(centre: DVec3, axis: DVec3, length: f64, radius: f64, sides: usize) -> SourceMesh {
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let ring = |k: usize, end: f64| {
        let a = std::f64::consts::TAU * k as f64 / sides as f64;
        let p = centre + (u * a.cos() + v * a.sin()) * radius + axis * (end * 0.5 * length);
        p.as_vec3().to_array()
    };
    let positions: Vec<[f32; 3]> = (0..sides).flat_map(|k| [ring(k, -1.0), ring(k, 1.0)]).collect();
    let indices = (0..sides as u32)
        .flat_map(|k| {
            let (a0, a1, b0, b1) = (2 * k, 2 * k + 1, 2 * ((k + 1) % sides as u32), 2 * ((k + 1) % sides as u32) + 1);
            [a0, b0, b1, a0, b1, a1]
        })
        .collect();
    SourceMesh { positions, indices }
}

#[test]
fn random_open_prisms_agree_with_the_reference() {
    // A small deterministic generator (SplitMix64), so a failure can be replayed.
    let mut state = 0x5eed_u64;
    let mut random = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut b = SceneBuilder::new();
    b.add_object("test", "WALL", wall(), true);
    for k in 0..40 {
        // Axes from any direction, a third of them nearly along the wall's normal (so some
        // suns look down their bores); a few reach through the wall's plane.
        let mut axis = DVec3::new(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
        if k % 3 == 0 {
            axis = (DVec3::new(0.0, -1.0, 0.0) + 0.2 * axis).normalize();
        }
        let centre = DVec3::new(4.0 * random(), -0.1 - 1.5 * random(), 3.0 * random());
        let sides = [3, 4, 6][k % 3];
        let mesh = open_prism(centre, axis, 0.3 + 1.2 * random(), 0.05 + 0.2 * random(), sides);
        b.add_object("test", &format!("PRISM{k}"), mesh, false);
    }
    let scene = b.build().unwrap();
    let engine = ExactEngine::new(&scene);
    assert_eq!(engine.convex_objects(), 41, "every prism is one object");
    let mut requests = Vec::new();
    for _ in 0..60 {
        let (az, alt) = ((100.0 + 160.0 * random()).to_radians(), (2.0 + 80.0 * random()).to_radians());
        requests.push(ViewRequest::new(0, DVec3::new(alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin())));
    }
    // And straight along the wall's normal, down the near-normal bores.
    requests.push(ViewRequest::new(0, DVec3::new(0.0, -1.0, 0.02).normalize()));
    let fast = engine.fractions(&requests);
    let reference = super::super::sunlit_fractions(&scene, &requests);
    for ((f, r), q) in fast.iter().zip(&reference).zip(&requests) {
        assert!((f - r).abs() < 1e-6, "{q:?}: fast {f}, reference {r}");
    }
    let partly = reference.iter().filter(|r| **r > 0.01 && **r < 0.99).count();
    assert!(partly >= 40, "only {partly} views partly shaded");
}

#[test]
fn convex_polygons_overlap_unless_an_edge_separates_them() {
    let square = |x: f64, y: f64| [DVec2::new(x, y), DVec2::new(x + 1.0, y), DVec2::new(x + 1.0, y + 1.0), DVec2::new(x, y + 1.0)];
    let mut clockwise = square(0.5, 0.5);
    clockwise.reverse();
    assert!(convex_overlap(&square(0.0, 0.0), &clockwise));
    assert!(!convex_overlap(&square(0.0, 0.0), &square(1.0, 0.0)), "touching along an edge");
    assert!(!convex_overlap(&square(0.0, 0.0), &square(1.0, 1.0)), "touching at a corner");
    // Separated only by a diagonal: an edge of the triangle.
    let triangle = [DVec2::new(1.2, 0.0), DVec2::new(0.0, 1.2), DVec2::new(1.2, 1.2)];
    assert!(convex_overlap(&square(0.0, 0.0), &triangle));
    let far = [DVec2::new(2.05, 0.0), DVec2::new(0.0, 2.05), DVec2::new(2.05, 2.05)];
    assert!(!convex_overlap(&square(0.0, 0.0), &far));
    // A flattened cap (the sun in its plane) across the other is reported as overlapping.
    let flat = [DVec2::new(-1.0, 0.5), DVec2::new(2.0, 0.5), DVec2::new(2.0, 0.5)];
    assert!(convex_overlap(&square(0.0, 0.0), &flat));
}

/// Suns from overhead to low, all round, with some straight down the tubes' bores.
fn suns_all_round() -> Vec<DVec3> {
    let mut suns = vec![DVec3::Z, DVec3::new(0.0, -1.0, 0.02).normalize()];
    for az in [0.0f64, 45.0, 100.0, 160.0, 180.0, 250.0] {
        for alt in [89.5f64, 87.0, 80.0, 70.0, 45.0, 20.0] {
            let (a, h) = (az.to_radians(), alt.to_radians());
            suns.push(DVec3::new(h.cos() * a.sin(), -h.cos() * a.cos(), h.sin()));
        }
    }
    suns
}

fn all_views(scene: &Scene) -> Vec<ViewRequest> {
    (0..scene.receivers.len() as u32).flat_map(|r| suns_all_round().into_iter().map(move |s| ViewRequest::new(r, s))).collect()
}

/// The lists of encoded objects (after magic and version): per position its object, the
/// objects' cap ranges, the caps, the cap corners; and the bytes rebuilt from such lists.
fn object_lists(bytes: &[u8]) -> Vec<Vec<u32>> {
    let mut at = 12;
    let mut lists = Vec::new();
    while at < bytes.len() {
        let n = u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or_default()) as usize;
        at += 8;
        lists.push(bytes[at..at + 4 * n].chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect());
        at += 4 * n;
    }
    lists
}

fn object_bytes(head: &[u8], lists: &[Vec<u32>]) -> Vec<u8> {
    let mut out = head[..12].to_vec();
    for list in lists {
        out.extend((list.len() as u64).to_le_bytes());
        list.iter().for_each(|x| out.extend(x.to_le_bytes()));
    }
    out
}

#[test]
fn an_engine_given_anothers_objects_answers_bit_for_bit() {
    let bits = |f: Vec<f64>| f.into_iter().map(f64::to_bits).collect::<Vec<_>>();
    for (what, scene) in [("tubes", tubes_over_a_roof()), ("louvres", louvred_wall())] {
        let engine = ExactEngine::new(&scene);
        let bytes = engine.objects_bytes();
        let given = ExactEngine::with_objects(&scene, &bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(given.objects_bytes(), bytes, "{what}: encoded again, the same bytes");
        assert_eq!(given.convex_objects(), engine.convex_objects(), "{what}");
        let requests = all_views(&scene);
        assert_eq!(bits(given.fractions(&requests)), bits(engine.fractions(&requests)), "{what}");
    }
    // The caps travel and matter: the tubes with their caps dropped (closed, as the bytes would
    // say if the encoding lost them) answer otherwise down their bores.
    let scene = tubes_over_a_roof();
    let bytes = ExactEngine::new(&scene).objects_bytes();
    let mut lists = object_lists(&bytes);
    assert!(!lists[3].is_empty(), "the tubes have open caps");
    lists[1].iter_mut().for_each(|x| *x = 0);
    let closed = ExactEngine::with_objects(&scene, &object_bytes(&bytes, &lists)).unwrap();
    let requests = all_views(&scene);
    assert_ne!(bits(closed.fractions(&requests)), bits(ExactEngine::new(&scene).fractions(&requests)));
}

#[test]
fn objects_that_do_not_fit_the_scene_are_refused_by_their_reason() {
    let scene = tubes_over_a_roof();
    let bytes = ExactEngine::new(&scene).objects_bytes();
    let why = |b: &[u8]| match ExactEngine::with_objects(&scene, b) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("{} bytes taken", b.len()),
    };
    for cut in (0..bytes.len()).step_by(7) {
        let reason = why(&bytes[..cut]);
        assert!(reason.contains("truncated") || reason.contains("SUNLITOB"), "{cut}: {reason}");
    }
    assert!(why(&[&bytes[..], &[0]].concat()).contains("1 bytes follow"), "trailing");
    let mut other = bytes.clone();
    other[8] = 2;
    assert!(why(&other).contains("version 2"), "{}", why(&other));
    let lists = object_lists(&bytes);
    let objects = (lists[1].len() / 2) as u32;
    let mut past = lists.clone();
    past[0][0] = objects;
    assert!(why(&object_bytes(&bytes, &past)).contains(&format!("object {objects} past the {objects} objects")));
    let mut corner = lists.clone();
    corner[3][0] = 3 * lists[0].len() as u32;
    assert!(why(&object_bytes(&bytes, &corner)).contains("past the"), "{}", why(&object_bytes(&bytes, &corner)));
    let mut odd = lists.clone();
    odd[2].pop();
    assert!(why(&object_bytes(&bytes, &odd)).contains("an odd number"));
    // Another scene's objects: its triangles are not this scene's.
    let louvres = ExactEngine::new(&louvred_wall()).objects_bytes();
    assert!(why(&louvres).contains("triangles, where the scene has"), "{}", why(&louvres));
}

/// The hint's search finds what a scan of every (triangle, range) pair finds: the lowest of an
/// object's triangles that the walk reached, or none, over overlapping, empty, unsorted ranges
/// and triangles at both ends of ranges.
#[test]
fn first_reached_is_the_lowest_reached_triangle_as_a_scan_finds_it() {
    let scan =
        |sorted: &[u32], reached: &[Range<usize>]| sorted.iter().copied().find(|&p| reached.iter().any(|r| r.contains(&(p as usize))));
    let mut seed = 7u64;
    let mut next = |n: u64| {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) % n
    };
    let mut found = 0;
    for _ in 0..2000 {
        let mut sorted: Vec<u32> = (0..next(12)).map(|_| next(60) as u32).collect();
        sorted.sort_unstable();
        sorted.dedup();
        let reached: Vec<Range<usize>> = (0..next(6))
            .map(|_| {
                let a = next(64) as usize;
                a..a + next(8) as usize
            })
            .collect();
        assert_eq!(first_reached(&sorted, &reached), scan(&sorted, &reached), "{sorted:?} {reached:?}");
        found += usize::from(scan(&sorted, &reached).is_some());
    }
    // Both answers are exercised.
    assert!(found > 200 && found < 1800, "{found}");
}

/// A box [lo, hi] with each face cut into `n` × `n` panels (welded corners, as a block's
/// panelled facade): one convex object of `6 · 2n²` triangles and many corners on its faces.
fn panelled_cuboid(lo: [f32; 3], hi: [f32; 3], n: u32) -> SourceMesh {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut indices = Vec::new();
    let at = |k: u32, a: usize| lo[a] + (hi[a] - lo[a]) * k as f32 / n as f32;
    // Each face: the fixed axis and side, and the two axes along it, wound outward.
    for (fixed, side, u, v) in [(2, 0, 1, 0), (2, 1, 0, 1), (1, 0, 0, 2), (1, 1, 2, 0), (0, 0, 2, 1), (0, 1, 1, 2)] {
        let base = positions.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let mut p = [0.0f32; 3];
                p[fixed] = if side == 0 { lo[fixed] } else { hi[fixed] };
                (p[u], p[v]) = (at(i, u), at(j, v));
                positions.push(p);
            }
        }
        let corner = |i: u32, j: u32| base + i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                let q = [corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)];
                indices.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
            }
        }
    }
    SourceMesh { positions, indices }
}

/// A panelled block keeps only its eight vertices among its corners (the rest lie on the lines
/// between them), and casts what the reference casts and what the same block in one panel a
/// face casts, at every sun; turned about a slanted axis (no corner then shares two coordinates
/// with another), it keeps every corner and agrees as well.
#[test]
fn a_panelled_block_is_its_eight_vertices_and_casts_what_the_reference_does() {
    let block = |b: &mut SceneBuilder, mesh: SourceMesh, transform: DMat4| {
        let m = b.add_mesh("block", mesh);
        b.add_node(SourceNode { origin: "BLOCK".into(), name: "BLOCK".into(), mesh: m, transform, receiver: false });
    };
    let scene = |mesh: SourceMesh, transform: DMat4| {
        let mut b = SceneBuilder::new();
        b.add_object("test", "WALL", wall(), true);
        block(&mut b, mesh, transform);
        b.build().unwrap()
    };
    // About its centre, about a slanted axis (a turn about the vertical alone would keep the
    // vertical lines of corners).
    let centre = DVec3::new(2.25, -2.0, 1.5);
    let turned = DMat4::from_translation(centre)
        * DMat4::from_axis_angle(DVec3::new(1.0, 0.5, 2.0).normalize(), 0.3)
        * DMat4::from_translation(-centre);
    let (lo, hi) = ([1.0, -3.0, 0.5], [3.5, -1.0, 2.5]);
    let panelled = scene(panelled_cuboid(lo, hi, 4), DMat4::IDENTITY);
    let plain = scene(cuboid(lo, hi), DMat4::IDENTITY);
    let panelled_turned = scene(panelled_cuboid(lo, hi, 4), turned);
    let corners = |engine: &ExactEngine| (0..engine.objects.len() as u32).map(|o| engine.objects.corners(o).len()).max();
    let mut partly = 0;
    for (scene, expected_corners) in [(&panelled, 8), (&panelled_turned, 98)] {
        let engine = ExactEngine::new(scene);
        assert_eq!(engine.convex_objects(), 2, "the wall and the block, each one object");
        assert_eq!(corners(&engine), Some(expected_corners));
        let requests = all_views(scene);
        let fast = engine.fractions(&requests);
        let reference = super::super::sunlit_fractions(scene, &requests);
        for ((f, r), q) in fast.iter().zip(&reference).zip(&requests) {
            assert!((f - r).abs() < 1e-6, "{q:?}: fast {f}, reference {r}");
            partly += usize::from(*r > 0.01 && *r < 0.99);
        }
    }
    let requests = all_views(&panelled);
    assert_eq!(ExactEngine::new(&panelled).fractions(&requests), ExactEngine::new(&plain).fractions(&requests), "bit for bit");
    assert!(partly >= 10, "only {partly} views partly shaded");
}
