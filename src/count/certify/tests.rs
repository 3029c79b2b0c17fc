use super::*;
use crate::count::ViewRequest;
use crate::scene::{SceneBuilder, SourceMesh};
use crate::sun::location::Location;
use crate::sun::position::sun_direction;

/// A closed box [lo, hi], 12 triangles wound outward.
pub(crate) fn block(lo: [f32; 3], hi: [f32; 3]) -> SourceMesh {
    let c = |i: u32| [[lo[0], hi[0]][(i & 1) as usize], [lo[1], hi[1]][(i >> 1 & 1) as usize], [lo[2], hi[2]][(i >> 2) as usize]];
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    SourceMesh { positions: (0..8).map(c).collect(), indices: quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect() }
}

/// A south-facing window (normal −y) at y = `y`, x in [x0, x1], z in [z0, z1].
pub(crate) fn window(x0: f32, x1: f32, z0: f32, z1: f32, y: f32) -> SourceMesh {
    SourceMesh { positions: vec![[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], indices: vec![0, 1, 2, 0, 2, 3] }
}

/// A south-facing window 2 m wide, 10 m north of two 30 m blocks whose faces meet at x = 1
/// (behind the window's middle) where `east_from` is 1, or leave a slot from 1 to `east_from`.
pub(crate) fn street(east_from: f32) -> Scene {
    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
    b.add_object("test", "WEST", block([-30.0, -14.0, 0.0], [1.0, -10.0, 30.0]), false);
    b.add_object("test", "EAST", block([east_from, -14.0, 0.0], [30.0, -10.0, 30.0]), false);
    b.build().unwrap()
}

pub(super) fn golden() -> Location {
    Location::new(39.74, -105.18, -7.0).unwrap()
}

/// Sun directions every 15 minutes over a block of days and hours, those up and in front of `normal`.
fn suns(days: std::ops::Range<u32>, hours: (f64, f64), normal: DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for day in days {
        for k in 0..=((hours.1 - hours.0) * 4.0).round() as usize {
            let s = sun_direction(&golden(), f64::from(day), hours.0 + 0.25 * k as f64);
            if s.z >= MIN_COS_INCIDENCE && s.dot(normal) > MIN_COS_INCIDENCE {
                out.push(s);
            }
        }
    }
    out
}

/// A south-facing window 10 m north of a 30 m block: dark through winter middays (the block
/// alone covers it); with no block, lit. The certificates say so, and the exact engine agrees at
/// every sun.
#[test]
fn a_block_proves_a_window_dark_and_an_empty_street_proves_it_lit() {
    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
    b.add_object("test", "BLOCK", block([-40.0, -14.0, 0.0], [40.0, -10.0, 30.0]), false);
    let scene = b.build().unwrap();
    let certifier = Certifier::new(&scene);
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    assert_eq!(certifier.certify(0, &winter, both), Some(Certificate::Dark));
    let exact = ExactEngine::new(&scene);
    let requests: Vec<ViewRequest> = winter.iter().map(|s| ViewRequest::new(0, *s)).collect();
    assert!(exact.fractions(&requests).iter().all(|f| *f == 0.0));
    // Not looking for dark, nothing is proved: the block is in the swept volume.
    assert_eq!(certifier.certify(0, &winter, Wanted { dark: false, lit: true }), None);

    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
    b.add_object("test", "HOUSE", block([-1.0, 0.0, 0.0], [3.0, 8.0, 3.0]), false);
    let ground = SourceMesh {
        positions: vec![[-50.0, -50.0, 0.0], [50.0, -50.0, 0.0], [50.0, 50.0, 0.0], [-50.0, 50.0, 0.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    b.add_object("test", "GROUND", ground, false);
    let scene = b.build().unwrap();
    assert_eq!(Certifier::new(&scene).certify(0, &winter, both), Some(Certificate::Lit));
}

/// A reproducible uniform draw in [0, 1).
pub(super) fn random(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Four random south-facing windows and twelve random blocks south of them, each block
/// `width.0 · u + width.1` long and `depth.0 · u + depth.1` deep, up to 31 m high.
fn random_street(next: &mut impl FnMut() -> f64, width: (f64, f64), depth: (f64, f64)) -> Scene {
    let mut b = SceneBuilder::new();
    for k in 0..4 {
        let x = (next() * 20.0 - 10.0) as f32;
        let z = (next() * 10.0) as f32;
        b.add_object("test", &format!("W{k}"), window(x, x + 1.0 + next() as f32, z, z + 1.0, (next() * 4.0) as f32), true);
    }
    for k in 0..12 {
        let (x, y) = ((next() * 40.0 - 25.0) as f32, (next() * 25.0 - 30.0) as f32);
        let (w, d, h) = ((next() * width.0 + width.1) as f32, (next() * depth.0 + depth.1) as f32, (next() * 30.0 + 1.0) as f32);
        b.add_object("test", &format!("B{k}"), block([x, y, 0.0], [x + w, y + d, h]), false);
    }
    b.build().unwrap()
}

/// Brute force against the exact engine: random blocks round random windows, random cells of
/// suns; wherever a certificate is given, every sun of its cell is counted and must agree
/// (0 for dark, 1 for lit); and enough are given that the test means something.
#[test]
fn certificates_agree_with_the_exact_engine_at_every_sun_of_their_cell() {
    let mut next = random(7);
    let (mut dark, mut lit, mut checked) = (0, 0, 0);
    for _ in 0..8 {
        let scene = random_street(&mut next, (20.0, 0.5), (6.0, 0.5));
        let certifier = Certifier::new(&scene);
        let exact = ExactEngine::new(&scene);
        for _ in 0..60 {
            let first = 1 + (next() * 350.0) as u32;
            let start = 6.0 + (next() * 10.0).floor() * 0.5;
            let receiver = (next() * 4.0) as usize;
            let cell = suns(first..first + 14, (start, start + 1.0), scene.receivers[receiver].normal);
            if cell.is_empty() {
                continue;
            }
            let Some(certificate) = certifier.certify(receiver, &cell, Wanted { dark: true, lit: true }) else { continue };
            let requests: Vec<ViewRequest> = cell.iter().map(|s| ViewRequest::new(receiver as u32, *s)).collect();
            for (f, s) in exact.fractions(&requests).into_iter().zip(&cell) {
                let want = if certificate == Certificate::Dark { 0.0 } else { 1.0 };
                assert!((f - want).abs() < 1e-9, "{certificate:?} for receiver {receiver} at {s}: the exact engine says {f}");
                checked += 1;
            }
            match certificate {
                Certificate::Dark => dark += 1,
                Certificate::Lit => lit += 1,
            }
        }
    }
    println!("{dark} dark and {lit} lit cells, {checked} suns checked");
    assert!(dark >= 10 && lit >= 10, "{dark} dark and {lit} lit cells");
}

/// A panelled block without a floor (hundreds of triangles, one open cap) proves a window above
/// the ground dark, as a closed box would; a window at ground level, on the cap's plane, is not
/// proved (a ray could pass under the walls), and the exact engine agrees with what is proved.
#[test]
fn a_panelled_block_without_a_floor_proves_a_window_above_the_ground_dark() {
    let mut m = SourceMesh::default();
    for (o, side) in
        [([-40.0f32, -14.0], [80.0f32, 0.0]), ([40.0, -14.0], [0.0, 4.0]), ([40.0, -10.0], [-80.0, 0.0]), ([-40.0, -10.0], [0.0, -4.0])]
    {
        for f in 0..10 {
            for c in 0..8 {
                let at = |s: f32, z: f32| [o[0] + side[0] * s, o[1] + side[1] * s, z];
                let (s0, s1, z0, z1) = (c as f32 / 8.0, (c + 1) as f32 / 8.0, 3.0 * f as f32, 3.0 * (f + 1) as f32);
                let base = m.positions.len() as u32;
                m.positions.extend([at(s0, z0), at(s1, z0), at(s1, z1), at(s0, z1)]);
                m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            }
        }
    }
    let base = m.positions.len() as u32;
    m.positions.extend([[-40.0, -14.0, 30.0], [-40.0, -10.0, 30.0], [40.0, -10.0, 30.0], [40.0, -14.0, 30.0]]);
    m.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
    b.add_object("test", "FOOT", window(4.0, 6.0, 0.0, 1.0, 0.0), true);
    b.add_object("test", "BLOCK", m, false);
    let scene = b.build().unwrap();
    let certifier = Certifier::new(&scene);
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    assert_eq!(certifier.certify(0, &winter, both), Some(Certificate::Dark));
    assert_eq!(certifier.certify(1, &winter, both), None);
    let requests: Vec<ViewRequest> = winter.iter().map(|s| ViewRequest::new(0, *s)).collect();
    assert!(ExactEngine::new(&scene).fractions(&requests).iter().all(|f| *f == 0.0));
}

/// Brute force for the partly-lit proof: random blocks round random windows, random cells of
/// suns; every sun [`Certifier::unproved_lit`] leaves out (proved) must find the window's
/// fraction, counted by the exact engine, at least [`MIN_LIT_SHARE`] (the lit disc), so above
/// EnergyPlus's 1e-5; and the bisection proves
/// most suns while leaving some to count, so the test means something.
#[test]
fn suns_proved_not_dark_are_lit_by_the_exact_engine() {
    let mut next = random(11);
    let (mut proved, mut unproved, mut dark_found) = (0, 0, 0);
    for _ in 0..6 {
        let scene = random_street(&mut next, (3.0, 0.3), (3.0, 0.3));
        let certifier = Certifier::new(&scene);
        let exact = ExactEngine::new(&scene);
        let cells: Vec<(usize, Vec<DVec3>)> = (0..40)
            .map(|_| {
                let first = 1 + (next() * 350.0) as u32;
                let start = 6.0 + (next() * 10.0).floor() * 0.5;
                let receiver = (next() * 4.0) as usize;
                (receiver, suns(first..first + 14, (start, start + 1.0), scene.receivers[receiver].normal))
            })
            .collect();
        let sets: Vec<(usize, &[DVec3])> = cells.iter().map(|(r, s)| (*r, s.as_slice())).collect();
        for ((receiver, cell), left) in cells.iter().zip(certifier.unproved_lit(&sets)) {
            let requests: Vec<ViewRequest> = cell.iter().map(|s| ViewRequest::new(*receiver as u32, *s)).collect();
            for (k, f) in exact.fractions(&requests).into_iter().enumerate() {
                if left.contains(&k) {
                    unproved += 1;
                    dark_found += usize::from(f < 1e-5);
                } else {
                    assert!(f >= MIN_LIT_SHARE, "receiver {receiver} proved partly lit at {}: the exact engine says {f}", cell[k]);
                    proved += 1;
                }
            }
        }
    }
    println!("{proved} suns proved partly lit, {unproved} left to count ({dark_found} of them dark)");
    assert!(proved > 3 * unproved && dark_found >= 10, "{proved} proved, {unproved} left, {dark_found} dark");
}

/// A 3 × 2 m window behind a scrim of horizontal rods 0.6 m in front (4 cm thick, every 16 cm),
/// cut into triangles three ways (a fan from either of two corners, and round a centre point).
/// No single rod covers the window, but no patch's swept volume is empty either: the disc is
/// found between the rods' footprints. Every sun proved is lit by the exact engine (at least
/// [`MIN_LIT_SHARE`]), most single suns and short runs are proved, and the three cuts prove the
/// very same suns: the proof sees the polygon, not its triangles.
#[test]
fn a_scrim_leaves_a_window_proved_lit_between_its_rods_however_the_window_is_cut() {
    let corners = [[0.0, 0.0, 0.4], [3.0, 0.0, 0.4], [3.0, 0.0, 2.4], [0.0, 0.0, 2.4], [1.5, 0.0, 1.4]];
    let cuts: [Vec<u32>; 3] = [vec![0, 1, 2, 0, 2, 3], vec![1, 2, 3, 1, 3, 0], vec![0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4]];
    let scene = |cut: &[u32]| {
        let mut b = SceneBuilder::new();
        b.add_object("test", "WIN", SourceMesh { positions: corners.to_vec(), indices: cut.to_vec() }, true);
        for k in 0..16 {
            let z = 0.3 + 0.16 * k as f32;
            b.add_object("test", &format!("ROD_{k}"), block([-2.0, -0.62, z], [5.0, -0.58, z + 0.04]), false);
        }
        b.build().unwrap()
    };
    let scenes: Vec<Scene> = cuts.iter().map(|c| scene(c)).collect();
    let mut sets: Vec<Vec<DVec3>> = Vec::new();
    for day in [20, 100, 172, 260, 330] {
        let all = suns(day..day + 1, (8.0, 16.0), -DVec3::Y);
        sets.extend(all.iter().map(|s| vec![*s]));
        sets.extend(all.chunks(3).map(|c| c.to_vec()));
    }
    let asked: Vec<(usize, &[DVec3])> = sets.iter().map(|s| (0, s.as_slice())).collect();
    let answers: Vec<Vec<Vec<usize>>> = scenes.iter().map(|s| Certifier::new(s).unproved_lit(&asked)).collect();
    assert!(answers.iter().all(|a| *a == answers[0]), "another cut proves other suns");
    let exact = ExactEngine::new(&scenes[0]);
    let (mut proved, mut left) = (0, 0);
    for (set, unproved) in sets.iter().zip(&answers[0]) {
        let requests: Vec<ViewRequest> = set.iter().map(|s| ViewRequest::new(0, *s)).collect();
        for (k, f) in exact.fractions(&requests).into_iter().enumerate() {
            if unproved.contains(&k) {
                left += 1;
            } else {
                assert!(f >= MIN_LIT_SHARE, "proved lit at {}: the exact engine says {f}", set[k]);
                proved += 1;
            }
        }
    }
    println!("behind the scrim: {proved} suns proved partly lit, {left} left to count");
    assert!(proved > 4 * left, "{proved} proved, {left} left");
}

/// The winter middays of a south-facing window 10 m north of two blocks built flush (their north
/// faces meet at x = 1, corners shared bit for bit): at the cell's morning suns only the west
/// block covers the window, at its afternoon suns only the east one, around noon neither alone.
/// Their north faces together are one flat convex caster: the cell is proved dark, and the exact
/// engine finds every sun of it dark. With a 0.3 m slot between the blocks the faces do not
/// combine, sun passes the slot at some step, and nothing is proved.
#[test]
fn two_blocks_built_flush_hand_the_cover_over_within_a_cell() {
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    let requests: Vec<ViewRequest> = winter.iter().map(|s| ViewRequest::new(0, *s)).collect();

    let flush = street(1.0);
    let certifier = Certifier::new(&flush).with_many_casters();
    assert_eq!(certifier.certify(0, &winter, both), Some(Certificate::Dark));
    assert!(ExactEngine::new(&flush).fractions(&requests).iter().all(|f| *f == 0.0));
    // Neither block alone covers the window at every sun of the cell.
    let (first, last) = (&winter[..1], &winter[winter.len() - 1..]);
    assert_eq!(certifier.certify(0, first, both), Some(Certificate::Dark));
    assert_eq!(certifier.certify(0, last, both), Some(Certificate::Dark));
    let cone = DirectionCone::enclosing(&winter).unwrap();
    let shape = &certifier.shapes[0];
    let objects: Vec<u32> = (0..certifier.index.triangles.len()).filter_map(|p| certifier.opaque_convex(p)).collect();
    assert!(!objects.is_empty() && objects.iter().all(|o| !certifier.covers(shape, &cone, Caster::Object(*o))));

    let slot = street(1.3);
    assert_eq!(Certifier::new(&slot).with_many_casters().certify(0, &winter, both), None);
    assert!(ExactEngine::new(&slot).fractions(&requests).iter().any(|f| *f > 0.0), "no sun passes the slot: the variant shows nothing");
}

/// A screen 3 m in front of a south-facing window, made of two flat panels that meet at x = 1
/// (corners shared bit for bit), each its own object (receivers, as a tower's panels are), proves
/// the window dark through winter middays, as the exact engine and rays from the window agree;
/// the same panels 1 mm apart, or one f32 step apart (x = 1 and the next f32 above it, 1.2e-7 m),
/// let a sliver through at some sun, and prove nothing.
#[test]
fn coplanar_panels_with_a_gap_do_not_prove_dark() {
    let screen = |east_from: f32| {
        let panel = |x0: f32, x1: f32| SourceMesh {
            positions: vec![[x0, -3.0, 0.0], [x1, -3.0, 0.0], [x1, -3.0, 15.0], [x0, -3.0, 15.0]],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        let mut b = SceneBuilder::new();
        b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
        b.add_object("test", "WEST", panel(-20.0, 1.0), true);
        b.add_object("test", "EAST", panel(east_from, 20.0), true);
        b.build().unwrap()
    };
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    let requests: Vec<ViewRequest> = winter.iter().map(|s| ViewRequest::new(0, *s)).collect();
    let joined = screen(1.0);
    let certifier = Certifier::new(&joined).with_many_casters();
    let objects: std::collections::BTreeSet<u32> =
        (0..certifier.index.triangles.len()).filter_map(|p| certifier.opaque_convex(p)).collect();
    assert_eq!(objects.len(), 3, "the panels are one object: the composite rule is not exercised");
    assert_eq!(certifier.certify(0, &winter, both), Some(Certificate::Dark));
    for (f, s) in ExactEngine::new(&joined).fractions(&requests).into_iter().zip(&winter) {
        assert!(f == 0.0, "proved dark at {s}: the exact engine says {f}");
        assert_eq!(lit_grid_points(&joined, 0, *s), 0, "proved dark at {s}: a ray escapes");
    }
    for east_from in [1.001, f32::from_bits(1.0f32.to_bits() + 1)] {
        let gap = screen(east_from);
        assert_eq!(Certifier::new(&gap).with_many_casters().certify(0, &winter, both), None, "gap from x = {east_from}");
        assert!(
            ExactEngine::new(&gap).fractions(&requests).iter().any(|f| *f > 0.0),
            "no sun passes the gap from x = {east_from}: the test shows nothing"
        );
    }
}

/// The composite casters are found once per scene, not once per certifier: a city's year builds
/// a certifier per batch of receivers over one shared index, and finding them walks every
/// triangle of the scene. Two certifiers over one index use the very same composites (the
/// index's), and both prove the window behind the joined screen dark with them.
#[test]
fn certifiers_sharing_an_index_share_its_composites() {
    let panel = |x0: f32, x1: f32| SourceMesh {
        positions: vec![[x0, -3.0, 0.0], [x1, -3.0, 0.0], [x1, -3.0, 15.0], [x0, -3.0, 15.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let mut b = SceneBuilder::new();
    b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
    b.add_object("test", "WEST", panel(-20.0, 1.0), true);
    b.add_object("test", "EAST", panel(1.0, 20.0), true);
    let scene = b.build().unwrap();
    let index = ExactEngine::new(&scene);
    let (first, second) = (Certifier::sharing(&scene, &index).with_many_casters(), Certifier::sharing(&scene, &index).with_many_casters());
    assert_eq!(first.composites().len(), 1, "the two panels must form one composite, or sharing is not exercised");
    assert!(std::ptr::eq(first.composites(), second.composites()), "each certifier found its own composites");
    assert!(std::ptr::eq(first.composites(), index.composites()), "the composites are not the index's");
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    assert_eq!(first.certify(0, &winter, both), Some(Certificate::Dark));
    assert_eq!(second.certify(0, &winter, both), Some(Certificate::Dark));
}

/// Brute force for composite casters: streets of blocks built flush (whole-metre widths, so
/// neighbours share corners bit for bit), mostly of one height, some with 5 cm slots between them,
/// and random south-facing windows across the street; every dark certificate of a random cell is
/// checked by the exact engine at every sun of it, and enough are given, some where no one block
/// covers the whole cell (a composite does, or halves of it), that the test means something.
#[test]
fn dark_certificates_over_flush_blocks_agree_with_the_exact_engine() {
    let mut next = random(31);
    let (mut dark, mut beyond_one, mut checked) = (0, 0, 0);
    for _ in 0..8 {
        let mut b = SceneBuilder::new();
        for k in 0..4 {
            let x = (next() * 20.0 - 10.0) as f32;
            let z = (next() * 10.0) as f32;
            b.add_object("test", &format!("W{k}"), window(x, x + 1.0 + next() as f32, z, z + 1.0, (next() * 4.0) as f32), true);
        }
        let heights = [(8.0 + next() * 10.0).round() as f32, (18.0 + next() * 12.0).round() as f32];
        let mut x = -40.0f32;
        for k in 0..14 {
            let w = (1.0 + next() * 6.0).round() as f32;
            // Mostly one height: a run of flush blocks combines only where its north faces'
            // union is convex (one height), and a street of mixed heights tests that it is not.
            let h = heights[usize::from(next() < 0.1)];
            b.add_object("test", &format!("B{k}"), block([x, -14.0, 0.0], [x + w, -10.0, h]), false);
            x += w;
            if next() < 0.15 {
                x += 0.05;
            }
        }
        let scene = b.build().unwrap();
        let certifier = Certifier::new(&scene).with_many_casters();
        let exact = ExactEngine::new(&scene);
        let objects: Vec<u32> = (0..certifier.index.triangles.len()).filter_map(|p| certifier.opaque_convex(p)).collect();
        for _ in 0..80 {
            let first = 1 + (next() * 350.0) as u32;
            let start = 9.0 + (next() * 6.0).floor() * 0.5;
            let receiver = (next() * 4.0) as usize;
            let cell = suns(first..first + 14, (start, start + 1.0), scene.receivers[receiver].normal);
            if cell.is_empty() || certifier.certify(receiver, &cell, Wanted { dark: true, lit: false }) != Some(Certificate::Dark) {
                continue;
            }
            let requests: Vec<ViewRequest> = cell.iter().map(|s| ViewRequest::new(receiver as u32, *s)).collect();
            for (f, s) in exact.fractions(&requests).into_iter().zip(&cell) {
                assert!(f == 0.0, "dark for receiver {receiver} at {s}: the exact engine says {f}");
                checked += 1;
            }
            dark += 1;
            let cone = DirectionCone::enclosing(&cell).unwrap();
            let shape = &certifier.shapes[receiver];
            beyond_one += usize::from(!objects.iter().any(|o| certifier.covers(shape, &cone, Caster::Object(*o))));
        }
    }
    println!("{dark} dark cells ({beyond_one} where no one block covers the whole), {checked} suns checked");
    assert!(dark >= 20 && beyond_one >= 5, "{dark} dark cells, {beyond_one} where no one block covers the whole");
}

/// Ten floors of a facade facing east at x = 15, y from −27 to `−27 + width`, as nyt-blocks
/// builds its tower: per floor a wall of four strips round a hole and a window filling it, each a
/// receiver (so each its own object, none covering a neighbour alone), the window's corners on
/// the strips' edges (T-junctions). `skip`: a floor whose window is left out.
fn facade(b: &mut SceneBuilder, skip: Option<usize>, width: f32) {
    let rect = |s0: f32, s1: f32, t0: f32, t1: f32| SourceMesh {
        positions: vec![[15.0, -27.0 + s0, t0], [15.0, -27.0 + s1, t0], [15.0, -27.0 + s1, t1], [15.0, -27.0 + s0, t1]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    for f in 0..10 {
        let z = 4.0 * f as f32;
        let mut wall = SourceMesh::default();
        for (s0, s1, t0, t1) in [(0.0, width, 0.0, 0.8), (0.0, width, 3.2, 4.0), (0.0, 0.5, 0.8, 3.2), (width - 0.5, width, 0.8, 3.2)] {
            let r = rect(s0, s1, z + t0, z + t1);
            let base = wall.positions.len() as u32;
            wall.positions.extend(r.positions);
            wall.indices.extend(r.indices.iter().map(|i| i + base));
        }
        b.add_object("test", &format!("F{f}_WALL"), wall, true);
        if skip != Some(f) {
            b.add_object("test", &format!("F{f}_WIN"), rect(0.5, width - 0.5, z + 0.8, z + 3.2), true);
        }
    }
}

/// A scene of a wall facing south at y = −15, x from `from` to 27, z from 4 to 8 (receiver 0),
/// and [`facade`].
fn wall_and_facade(from: f32, skip: Option<usize>, width: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let wall = SourceMesh {
        positions: vec![[from, -15.0, 4.0], [27.0, -15.0, 4.0], [27.0, -15.0, 8.0], [from, -15.0, 8.0]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    b.add_object("test", "WALL", wall, true);
    facade(&mut b, skip, width);
    b.build().unwrap()
}

/// Whether the ray from `o` along `d` meets triangle `t` beyond `o` (Möller–Trumbore, f64): an
/// independent truth for the tests, sharing nothing with either engine.
fn ray_hits(o: DVec3, d: DVec3, t: &[DVec3; 3]) -> bool {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-15 {
        return false;
    }
    let s = o - t[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && e2.dot(q) / det > 1e-9
}

/// Points of a 59 × 59 grid strictly inside receiver `r` (a rectangle in a plane of constant y)
/// whose ray towards `sun` meets no triangle of another receiver or caster.
fn lit_grid_points(scene: &Scene, r: usize, sun: DVec3) -> usize {
    let own = Some(scene.receivers[r].gpu_id);
    let triangles: Vec<[DVec3; 3]> = scene.world_triangles().filter(|(_, id)| *id != own).map(|(t, _)| t).collect();
    let t = &scene.receivers[r].triangles;
    let (lo, hi) = t.iter().flatten().fold((DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)), |(l, h), p| (l.min(*p), h.max(*p)));
    let mut lit = 0;
    for i in 1..60 {
        for j in 1..60 {
            let p = DVec3::new(lo.x + (hi.x - lo.x) * f64::from(i) / 60.0, lo.y, lo.z + (hi.z - lo.z) * f64::from(j) / 60.0);
            lit += usize::from(!triangles.iter().any(|tri| ray_hits(p, sun, tri)));
        }
    }
    lit
}

/// A wall facing south (the second floor's height) west of a facade of walls and windows facing
/// east ([`facade`]: nyt-blocks' pattern, T-junctions and all), through summer afternoons when
/// the sun comes from the west-south-west:
/// - the facade standing 0.5 m clear of the wall's plane (y up to −15.5), the wall from x = 19:
///   the facade, one composite of its walls and windows, covers the wall over the cell where no
///   one object does: proved dark. At every sun of the cell the reference engine finds it dark
///   and so do rays from a grid of its points, tested against every triangle (a truth sharing
///   nothing with the engines); the fast exact engine finds at most 1e-9 of it lit, slivers its
///   integer grid leaves at the facade's T-junctions (the CSV's 8 decimals print both as 0);
/// - the same with one floor's window left out: the facade has a hole, sun comes through it at
///   some step (the engine and the rays agree), and nothing is proved;
/// - the facade reaching the wall's plane (y up to −15), meeting the wall (from x = 15) at an
///   inner corner: rays find the wall dark, but no proof is given with the shadow's edge on the
///   receiver's own edge ([`Certifier::covers`]).
#[test]
fn a_facade_proves_a_wall_clear_of_it_dark_but_not_one_it_touches() {
    let afternoons = suns(160..174, (14.0, 15.0), -DVec3::Y);
    assert!(afternoons.len() > 40);
    let both = Wanted { dark: true, lit: true };
    let requests: Vec<ViewRequest> = afternoons.iter().map(|s| ViewRequest::new(0, *s)).collect();
    let clear = wall_and_facade(19.0, None, 11.5);
    let certifier = Certifier::new(&clear).with_many_casters();
    assert_eq!(certifier.certify(0, &afternoons, both), Some(Certificate::Dark));
    let cone = DirectionCone::enclosing(&afternoons).unwrap();
    let objects: Vec<u32> = (0..certifier.index.triangles.len()).filter_map(|p| certifier.opaque_convex(p)).collect();
    assert!(objects.iter().all(|o| !certifier.covers(&certifier.shapes[0], &cone, Caster::Object(*o))), "one object covers the wall");
    for (f, s) in ExactEngine::new(&clear).fractions(&requests).into_iter().zip(&afternoons) {
        assert!(f < 1e-9, "proved dark at {s}: the exact engine says {f}");
        let reference = crate::count::exact::sunlit_fraction(&clear, ViewRequest::new(0, *s));
        assert!(reference == 0.0, "proved dark at {s}: the reference engine says {reference}");
        assert_eq!(lit_grid_points(&clear, 0, *s), 0, "proved dark at {s}: a ray escapes");
    }

    let holed = wall_and_facade(19.0, Some(3), 11.5);
    assert_eq!(Certifier::new(&holed).with_many_casters().certify(0, &afternoons, both), None);
    assert!(ExactEngine::new(&holed).fractions(&requests).iter().any(|f| *f > 1e-3), "no sun passes the hole: the variant shows nothing");
    assert!(afternoons.iter().any(|s| lit_grid_points(&holed, 0, *s) > 0), "no ray passes the hole");

    let corner_suns = suns(160..174, (15.0, 16.0), -DVec3::Y);
    let touching = wall_and_facade(15.0, None, 12.0);
    assert_eq!(Certifier::new(&touching).with_many_casters().certify(0, &corner_suns, both), None);
    assert!(
        corner_suns.iter().all(|s| lit_grid_points(&touching, 0, *s) == 0),
        "a ray escapes at the inner corner: the variant shows nothing"
    );
}

/// A south-facing window behind a near block to the west (10–14 m south, up to x = 3) and a
/// farther one to the east (20–24 m south, from x = −1): through winter middays the near one
/// covers the window at the morning suns, the far one at the afternoon suns, and around noon
/// both do; neither alone at every sun. The cell is proved dark in halves, and the exact engine
/// finds every sun of it dark. With the far block moved to start at x = 8, light passes between
/// them at some sun, and nothing is proved.
#[test]
fn the_cover_passes_from_a_near_block_to_a_far_one_within_a_cell() {
    let street = |far_from: f32| {
        let mut b = SceneBuilder::new();
        b.add_object("test", "WIN", window(0.0, 2.0, 1.0, 2.5, 0.0), true);
        b.add_object("test", "NEAR", block([-30.0, -14.0, 0.0], [3.0, -10.0, 30.0]), false);
        b.add_object("test", "FAR", block([far_from, -24.0, 0.0], [40.0, -20.0, 40.0]), false);
        b.build().unwrap()
    };
    let winter = suns(1..14, (11.0, 13.0), -DVec3::Y);
    let both = Wanted { dark: true, lit: true };
    let requests: Vec<ViewRequest> = winter.iter().map(|s| ViewRequest::new(0, *s)).collect();
    let overlapping = street(-1.0);
    let certifier = Certifier::new(&overlapping).with_many_casters();
    assert_eq!(certifier.certify(0, &winter, both), Some(Certificate::Dark));
    assert!(ExactEngine::new(&overlapping).fractions(&requests).iter().all(|f| *f == 0.0));
    let cone = DirectionCone::enclosing(&winter).unwrap();
    assert!(!certifier.one_caster_covers(&certifier.shapes[0], &cone), "one block covers the whole cell: the test shows nothing");
    let apart = street(8.0);
    assert_eq!(Certifier::new(&apart).with_many_casters().certify(0, &winter, both), None);
    assert!(
        ExactEngine::new(&apart).fractions(&requests).iter().any(|f| *f > 0.0),
        "no sun passes between the blocks: the variant shows nothing"
    );
}

/// The wall of [`a_facade_proves_a_wall_clear_of_it_dark_but_not_one_it_touches`] 1 m east of
/// the inner corner where the facade meets its plane (the facade reaching y = −15, the wall from
/// x = 16), through the summer afternoons when the facade shades it. The facade comes nearer the
/// wall's plane than the margin, so without the many-caster proofs nothing is proved; with them
/// its part twice the margin in front (clipped, [`clipped_in_front`]) covers the wall: proved
/// dark, and at every sun the reference engine and rays from a grid of the wall's points find it
/// dark. (That a facade with a hole proves nothing is
/// [`a_facade_proves_a_wall_clear_of_it_dark_but_not_one_it_touches`]'s: a facade with a hole
/// is no composite, clipped or not.)
#[test]
fn a_facade_meeting_the_walls_plane_at_an_inner_corner_proves_the_wall_beside_it_dark() {
    let corner_suns = suns(160..174, (15.0, 16.0), -DVec3::Y);
    assert!(corner_suns.len() > 40);
    let both = Wanted { dark: true, lit: true };
    let apart = wall_and_facade(16.0, None, 12.0);
    assert_eq!(Certifier::new(&apart).certify(0, &corner_suns, both), None);
    let certifier = Certifier::new(&apart).with_many_casters();
    assert_eq!(certifier.certify(0, &corner_suns, both), Some(Certificate::Dark));
    let requests: Vec<ViewRequest> = corner_suns.iter().map(|s| ViewRequest::new(0, *s)).collect();
    for (f, s) in ExactEngine::new(&apart).fractions(&requests).into_iter().zip(&corner_suns) {
        assert!(f < 1e-9, "proved dark at {s}: the exact engine says {f}");
        let reference = crate::count::exact::sunlit_fraction(&apart, ViewRequest::new(0, *s));
        assert!(reference == 0.0, "proved dark at {s}: the reference engine says {reference}");
        assert_eq!(lit_grid_points(&apart, 0, *s), 0, "proved dark at {s}: a ray escapes");
    }
}

/// A box crossing the plane z = 1 (normal +z), tilted or not: the clipped corners lie in the box
/// and at least the height in front, and span exactly the box's part above it (their bounds are
/// the part's bounds); a box wholly below gives none, and one with too many pairs none.
#[test]
fn a_caster_clipped_in_front_is_its_part_above_the_height() {
    let corners = |lo: DVec3, hi: DVec3| -> Vec<DVec3> {
        (0..8).map(|i| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2])).collect()
    };
    let (lo, hi) = (DVec3::new(-1.0, 2.0, -3.0), DVec3::new(4.0, 5.0, 6.0));
    let part = clipped_in_front(&corners(lo, hi), DVec3::Z, 1.0).unwrap();
    let (plo, phi) = part.iter().fold((DVec3::MAX, DVec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    assert!((plo - DVec3::new(-1.0, 2.0, 1.0)).abs().max_element() < 1e-12, "{plo}");
    assert!((phi - hi).abs().max_element() < 1e-12, "{phi}");
    // Tilted: a box turned about x and y, cut at height 1; every clipped corner lies on or above
    // the height and inside the turned box, and the highest and lowest reach what the box does.
    let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.5, 0.2);
    let box_corners: Vec<DVec3> = corners(lo, hi).into_iter().map(|c| turn * c).collect();
    let part = clipped_in_front(&box_corners, DVec3::Z, 1.0).unwrap();
    for p in &part {
        assert!(p.z >= 1.0 - 1e-12, "{p} below the height");
        let local = turn.inverse() * *p;
        assert!(local.cmpge(lo - 1e-9).all() && local.cmple(hi + 1e-9).all(), "{p} outside the box");
    }
    let top = box_corners.iter().map(|c| c.z).fold(f64::MIN, f64::max);
    assert!((part.iter().map(|p| p.z).fold(f64::MIN, f64::max) - top).abs() < 1e-12);
    assert!((part.iter().map(|p| p.z).fold(f64::MAX, f64::min) - 1.0).abs() < 1e-12);
    assert!(clipped_in_front(&corners(lo, DVec3::new(4.0, 5.0, 0.5)), DVec3::Z, 1.0).is_none());
    let many: Vec<DVec3> = (0..200).map(|i| DVec3::new(f64::from(i), 0.0, f64::from(i % 2) * 4.0 - 1.0)).collect();
    assert!(clipped_in_front(&many, DVec3::Z, 1.0).is_none());
}

/// A wall facing south at y = −15 from the inner corner (x = 15) to x = 27, z over `wall_z`
/// (receiver 0), and [`facade`] of `width` meeting its plane at the corner.
fn inner_corner(wall_z: (f32, f32), width: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let (z0, z1) = wall_z;
    let wall = SourceMesh {
        positions: vec![[15.0, -15.0, z0], [27.0, -15.0, z0], [27.0, -15.0, z1], [15.0, -15.0, z1]],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    b.add_object("test", "WALL", wall, true);
    facade(&mut b, None, width);
    b.build().unwrap()
}

/// Whether a ray towards `sun` from a point of receiver 0 (at y = −15) at most 1e-5 m from the
/// inner corner (x = 15) at height `z` meets no other triangle: light along the corner, which a
/// grid of the wall's points would not reach.
fn escapes_at_the_corner(scene: &Scene, z: f64, sun: DVec3) -> bool {
    let own = Some(scene.receivers[0].gpu_id);
    let triangles: Vec<[DVec3; 3]> = scene.world_triangles().filter(|(_, id)| *id != own).map(|(t, _)| t).collect();
    [1e-7, 1e-6, 1e-5].iter().any(|d| {
        let p = DVec3::new(15.0 + d, -15.0, z);
        !triangles.iter().any(|t| ray_hits(p, sun, t))
    })
}

/// The inner corner of [`a_facade_meeting_the_walls_plane_at_an_inner_corner_proves_the_wall_beside_it_dark`]
/// with the wall reaching into it (from x = 15, where the facade of the tower's other arm meets
/// its plane), as nyt-blocks' wall strips do, over the summer afternoons when the facade shades
/// it:
/// - the many-caster proofs alone cannot prove it (the wall's edge lies in the facade's clipped
///   band); with [`Certifier::with_inner_corners`], its two corners on the facade are covered
///   with no margin and it is proved dark. At every sun the reference engine finds it dark, the
///   fast exact engine below 1e-9, and no ray escapes, from a grid of its points nor from points
///   within 1e-5 m of the corner;
/// - the facade stopping one f32 step short of the wall's plane (y = −15.000001): a ray along
///   the corner escapes through the gap at some sun, and nothing is proved (a proof trusting a
///   facade within any tolerance of the corner would prove it);
/// - the wall reaching above the facade's top (z up to 42 against 40): its upper corner is on
///   the corner's line but not on the facade, light passes over the top, and nothing is proved.
#[test]
fn an_inner_corner_is_proved_dark_only_where_the_wall_s_corners_lie_on_the_facade() {
    let corner_suns = suns(160..174, (15.0, 16.0), -DVec3::Y);
    assert!(corner_suns.len() > 40);
    let both = Wanted { dark: true, lit: true };
    let requests: Vec<ViewRequest> = corner_suns.iter().map(|s| ViewRequest::new(0, *s)).collect();
    let proved = |scene: &Scene| Certifier::new(scene).with_many_casters().with_inner_corners().certify(0, &corner_suns, both);

    let touching = inner_corner((4.0, 8.0), 12.0);
    assert_eq!(Certifier::new(&touching).with_many_casters().certify(0, &corner_suns, both), None, "proved without the option");
    assert_eq!(proved(&touching), Some(Certificate::Dark));
    for (f, s) in ExactEngine::new(&touching).fractions(&requests).into_iter().zip(&corner_suns) {
        assert!(f < 1e-9, "proved dark at {s}: the exact engine says {f}");
        let reference = crate::count::exact::sunlit_fraction(&touching, ViewRequest::new(0, *s));
        assert!(reference == 0.0, "proved dark at {s}: the reference engine says {reference}");
        assert_eq!(lit_grid_points(&touching, 0, *s), 0, "proved dark at {s}: a ray escapes");
        assert!(!escapes_at_the_corner(&touching, 6.0, *s), "proved dark at {s}: a ray escapes along the corner");
    }

    let short = inner_corner((4.0, 8.0), f32::from_bits(12.0f32.to_bits() - 1));
    assert_eq!(proved(&short), None, "proved across a gap of one f32 step");
    assert!(corner_suns.iter().any(|s| escapes_at_the_corner(&short, 6.0, *s)), "no ray passes the gap: the variant shows nothing");

    let above = inner_corner((38.0, 42.0), 12.0);
    assert_eq!(proved(&above), None, "proved above the facade's top");
    assert!(corner_suns.iter().any(|s| lit_grid_points(&above, 0, *s) > 0), "no ray passes over the top: the variant shows nothing");
}

/// Certifying many sets at once, a receiver's cells one after another as the year hands them
/// over (each thread then reuses the casters it made ready for the receiver before), gives what
/// certifying each set alone gives, with and without the many-caster proofs. Failed when a
/// thread kept the last receiver's casters for the next receiver (proofs from another window's
/// corners: floor 5 of nyt-blocks proved 55,532 steps dark instead of 70,913).
#[test]
fn certifying_sets_together_gives_what_each_gives_alone() {
    let mut next = random(11);
    let mut proved = 0;
    for _ in 0..4 {
        let scene = random_street(&mut next, (20.0, 0.5), (6.0, 0.5));
        for many in [false, true] {
            let certifier = if many { Certifier::new(&scene).with_many_casters() } else { Certifier::new(&scene) };
            let mut cells: Vec<(usize, Vec<DVec3>)> = Vec::new();
            for receiver in 0..4 {
                for _ in 0..24 {
                    let first = 1 + (next() * 350.0) as u32;
                    let start = 6.0 + (next() * 10.0).floor() * 0.5;
                    let cell = suns(first..first + 14, (start, start + 1.0), scene.receivers[receiver].normal);
                    if !cell.is_empty() {
                        cells.push((receiver, cell));
                    }
                }
            }
            let sets: Vec<(usize, &[DVec3], Wanted)> =
                cells.iter().map(|(r, c)| (*r, c.as_slice(), Wanted { dark: true, lit: true })).collect();
            let together: Vec<Option<Certificate>> = certifier.certify_all(&sets).into_iter().map(|p| p.map(|p| p.certificate)).collect();
            let alone: Vec<Option<Certificate>> = sets.iter().map(|(r, c, w)| certifier.certify(*r, c, *w)).collect();
            assert_eq!(together, alone, "many-caster proofs {many}");
            proved += alone.iter().filter(|c| c.is_some()).count();
        }
    }
    assert!(proved >= 40, "{proved} sets proved");
}
