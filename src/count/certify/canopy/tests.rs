use glam::DVec3;

use crate::count::certify::Certifier;
use crate::count::exact::engine::ExactEngine;
use crate::count::{MIN_COS_INCIDENCE, ViewRequest};
use crate::scene::{Scene, SceneBuilder, SourceMesh};
use crate::sun::location::Location;
use crate::sun::position::sun_direction;

/// What stands in front of the test window ([`window_and`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Caster {
    /// A tree's crown of this many leaves (separate triangles of side 0.1 m) in the window's
    /// winter-noon path.
    Leaves(usize),
    /// The same crown behind the window's plane.
    LeavesBehind(usize),
    /// An overhang 2.4 × 0.8 m over the window: one quad.
    Overhang,
    /// The same overhang as 24 × 8 small quads sharing their corners (one flat convex object).
    TessellatedOverhang,
    /// The same small quads corrugated (every other row of corners 5 cm lower): not convex.
    CorrugatedOverhang,
}

/// A south-facing window, 2 × 1.5 m (receiver 0), with `caster`, and its suns every 15 minutes
/// from 11:00 to 13:00 over the first two weeks of January in Golden, Colorado.
pub(crate) fn window_and(caster: Caster) -> (Scene, Vec<DVec3>) {
    let mut b = SceneBuilder::new();
    let window = vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [2.0, 0.0, 2.5], [0.0, 0.0, 2.5]];
    b.add_object("test", "WIN", SourceMesh { positions: window, indices: vec![0, 1, 2, 0, 2, 3] }, true);
    let mesh = match caster {
        Caster::Leaves(n) => crown([1.0, -8.0, 5.5], n),
        Caster::LeavesBehind(n) => crown([1.0, 8.0, 5.5], n),
        Caster::Overhang => overhang(1, 1, 0.0),
        Caster::TessellatedOverhang => overhang(24, 8, 0.0),
        Caster::CorrugatedOverhang => overhang(24, 8, 0.05),
    };
    b.add_object("test", "CASTER", mesh, false);
    let location = Location::new(39.74, -105.18, -7.0).expect("a valid location");
    let suns = (1..15)
        .flat_map(|day| (0..=8).map(move |k| (day, 11.0 + 0.25 * f64::from(k))))
        .map(|(day, hour)| sun_direction(&location, f64::from(day), hour))
        .filter(|s| s.z > MIN_COS_INCIDENCE && s.dot(-DVec3::Y) > MIN_COS_INCIDENCE)
        .collect();
    (b.build().expect("a valid scene"), suns)
}

/// `n` leaves, each a triangle of side 0.1 m with its own corners, at random in a ball of
/// radius 2.5 m about `centre` (a fixed seed).
fn crown(centre: [f32; 3], n: usize) -> SourceMesh {
    let mut state = 2011u64;
    let mut next = move || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    let mut mesh = SourceMesh { positions: Vec::new(), indices: Vec::new() };
    while mesh.positions.len() < 3 * n {
        let p = [next(), next(), next()];
        if p.iter().map(|x| x * x).sum::<f32>() > 1.0 {
            continue;
        }
        let at = |k: usize, d: [f32; 3]| [0, 1, 2].map(|i| centre[i] + 2.5 * p[i] + d[i] * f32::from(u8::from(k > 0)));
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([at(0, [0.0; 3]), at(1, [0.1, 0.0, 0.0]), at(2, [0.05, 0.05 * next(), 0.087])]);
        mesh.indices.extend([base, base + 1, base + 2]);
    }
    mesh
}

/// The overhang over the window (x in [−0.2, 2.2], y in [−0.8, 0], 2.7 m up) as `nx` × `ny`
/// quads sharing corners, every other row of corners `dip` lower.
fn overhang(nx: u32, ny: u32, dip: f32) -> SourceMesh {
    let corner = |i: u32, j: u32| {
        let z = 2.7 - if j % 2 == 1 { dip } else { 0.0 };
        [-0.2 + 2.4 * i as f32 / nx as f32, -0.8 * j as f32 / ny as f32, z]
    };
    let positions = (0..=ny).flat_map(|j| (0..=nx).map(move |i| corner(i, j))).collect();
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let indices = (0..ny)
        .flat_map(|j| (0..nx).flat_map(move |i| [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)]))
        .collect();
    SourceMesh { positions, indices }
}

/// A crown of leaves in the window's path is a canopy; too few leaves, the crown behind the
/// window, or an overhang (one quad, finely tessellated, or corrugated so that it is not convex)
/// is not. The exact engine agrees that the crown and the overhangs do shade the window at some
/// of these suns, so each is in its path.
#[test]
fn a_crown_of_leaves_is_a_canopy_and_an_overhang_is_not_however_it_is_cut() {
    let under = |caster| {
        let (scene, suns) = window_and(caster);
        Certifier::new(&scene).under_canopy(0, &suns)
    };
    assert!(under(Caster::Leaves(2000)), "a crown of 2,000 leaves");
    assert!(!under(Caster::Leaves(10)), "ten leaves");
    assert!(!under(Caster::LeavesBehind(2000)), "the crown behind the window");
    assert!(!under(Caster::Overhang), "an overhang");
    assert!(!under(Caster::TessellatedOverhang), "a tessellated overhang");
    assert!(!under(Caster::CorrugatedOverhang), "a corrugated overhang");
    for caster in [Caster::Leaves(2000), Caster::Overhang, Caster::CorrugatedOverhang] {
        let (scene, suns) = window_and(caster);
        let requests: Vec<ViewRequest> = suns.iter().map(|s| ViewRequest::new(0, *s)).collect();
        assert!(ExactEngine::new(&scene).fractions(&requests).iter().any(|f| *f < 0.99), "{caster:?} shades the window");
    }
    let (scene, suns) = window_and(Caster::Leaves(2000));
    let sets = [(0, suns.as_slice()), (0, &suns[..0])];
    assert_eq!(Certifier::new(&scene).under_canopy_all(&sets), vec![true, false], "no suns, no cone");
}
