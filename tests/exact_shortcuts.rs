//! The fast exact engine's shortcuts leave every answer as the whole walk gives it: an object
//! dropped from its corners alone, a view stopped once one shadow covers its receiver, and the
//! object that covered a receiver cast first in its next views (docs/district.md, "The exact
//! clipping made cheaper"). Held to the reference's polygon clipping, and to itself bit for bit
//! whatever order the views come in (so whatever the hints are).

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use glam::{DMat4, DVec3};
use sunlit::count::ViewRequest;
use sunlit::count::exact::engine::ExactEngine;
use sunlit::scene::{SceneBuilder, SourceMesh, SourceNode};

/// A box [lo, hi] as 12 triangles, outward.
fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> SourceMesh {
    let c =
        |i: u32| [if i & 1 == 0 { lo[0] } else { hi[0] }, if i & 2 == 0 { lo[1] } else { hi[1] }, if i & 4 == 0 { lo[2] } else { hi[2] }];
    let quads: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    SourceMesh { positions: (0..8).map(c).collect(), indices: quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect() }
}

/// A 4 × 3 m wall facing south (−y) behind one large box 3 m out and 40 slats just before it:
/// the box covers the whole wall for suns nearly behind it, part of it for others, and the slats
/// shade it in strips.
#[test]
fn covered_views_stop_early_with_the_answers_of_the_whole_walk() {
    let mut b = SceneBuilder::new();
    let wall = SourceMesh { positions: vec![[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]], indices: vec![0, 1, 2, 0, 2, 3] };
    b.add_object("test", "WALL", wall, true);
    b.add_object("test", "BLOCK", cuboid([-1.0, -4.0, -1.0], [5.0, -3.0, 4.0]), false);
    let slat = b.add_mesh("slat", cuboid([-0.5, -0.3, 0.0], [4.5, -0.1, 0.04]));
    for k in 0..40 {
        let transform = DMat4::from_translation(DVec3::new(0.0, 0.0, 0.075 * k as f64));
        let name = format!("S{k}");
        b.add_node(SourceNode { origin: name.clone(), name, mesh: slat, transform, receiver: false });
    }
    let scene = b.build().unwrap();
    let mut requests = Vec::new();
    for az in (0..24).map(|k| 110.0 + 140.0 * k as f64 / 23.0) {
        for alt in [2.0f64, 6.0, 12.0, 20.0, 35.0, 50.0, 70.0] {
            let (a, h) = (f64::to_radians(az), alt.to_radians());
            requests.push(ViewRequest::new(0, DVec3::new(h.cos() * a.sin(), h.cos() * a.cos(), h.sin())));
        }
    }
    // In order (each view's hint the last covering object) and backwards on a fresh engine: the
    // hints differ, the answers may not, bit for bit.
    let forward = ExactEngine::new(&scene).fractions(&requests);
    let reversed: Vec<ViewRequest> = requests.iter().rev().copied().collect();
    let backward: Vec<f64> = ExactEngine::new(&scene).fractions(&reversed).into_iter().rev().collect();
    let reference = sunlit::count::exact::sunlit_fractions(&scene, &requests);
    for (((f, b), r), q) in forward.iter().zip(&backward).zip(&reference).zip(&requests) {
        assert_eq!(f.to_bits(), b.to_bits(), "{q:?}: {f} in order, {b} backwards");
        assert!((f - r).abs() < 1e-6, "{q:?}: fast {f}, reference {r}");
    }
    let dark = reference.iter().filter(|r| **r == 0.0).count();
    let partly = reference.iter().filter(|r| **r > 0.01 && **r < 0.99).count();
    assert!(dark >= 10 && partly >= 20, "{dark} covered and {partly} partly shaded views");
}
