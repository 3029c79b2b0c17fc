//! The boundary step against closed forms and the reference clipper.

use super::*;
use crate::count::exact::{Contour, sunlit_ratio};

/// A grid where multiples of 1/4 in [−8, 8] land exactly on grid points (scale 2^26), so
/// shared and collinear edges stay exactly so after snapping.
fn snap() -> Snap {
    Snap::new(DVec2::splat(-8.0), DVec2::splat(8.0)).unwrap()
}

fn ratio(receiver: &[Vec<DVec2>], shadows: &[Vec<DVec2>]) -> f64 {
    let s = snap();
    let mut b = Boundary::default();
    for r in receiver {
        b.push(&s, r, true);
    }
    let whole = b.uncovered_area();
    for sh in shadows {
        b.push(&s, sh, false);
    }
    let lit = b.uncovered_area();
    if whole <= 0.0 { 0.0 } else { (lit / whole).clamp(0.0, 1.0) }
}

fn contour(p: &[DVec2]) -> Contour {
    let area: f64 = (0..p.len()).map(|i| p[i].perp_dot(p[(i + 1) % p.len()])).sum();
    let mut c: Contour = p.iter().map(|q| q.to_array()).collect();
    if area < 0.0 {
        c.reverse();
    }
    c
}

fn reference(receiver: &[Vec<DVec2>], shadows: &[Vec<DVec2>]) -> f64 {
    let r: Vec<Contour> = receiver.iter().map(|p| contour(p)).collect();
    let s: Vec<Contour> = shadows.iter().map(|p| contour(p)).collect();
    sunlit_ratio(&r, &s, 0.0)
}

fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
    vec![DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(x1, y1), DVec2::new(x0, y1)]
}

fn tri(p: [[f64; 2]; 3]) -> Vec<DVec2> {
    p.iter().map(|&[x, y]| DVec2::new(x, y)).collect()
}

/// A 4 × 3 wall as two triangles.
fn wall() -> Vec<Vec<DVec2>> {
    vec![tri([[0., 0.], [4., 0.], [4., 3.]]), tri([[0., 0.], [4., 3.], [0., 3.]])]
}

/// The wall with a 2 × 1 hole at [1, 3] × [1, 2], as eight triangles.
fn holed_wall() -> Vec<Vec<DVec2>> {
    let t = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| tri([a, b, c]);
    vec![
        t([0., 0.], [4., 0.], [3., 1.]),
        t([0., 0.], [3., 1.], [1., 1.]),
        t([4., 0.], [4., 3.], [3., 2.]),
        t([4., 0.], [3., 2.], [3., 1.]),
        t([4., 3.], [0., 3.], [1., 2.]),
        t([4., 3.], [1., 2.], [3., 2.]),
        t([0., 3.], [0., 0.], [1., 1.]),
        t([0., 3.], [1., 1.], [1., 2.]),
    ]
}

fn assert_agrees(receiver: &[Vec<DVec2>], shadows: &[Vec<DVec2>], what: &str) -> f64 {
    let (got, want) = (ratio(receiver, shadows), reference(receiver, shadows));
    assert!((got - want).abs() < 1e-6, "{what}: boundary {got}, reference {want}");
    got
}

#[test]
fn degenerate_arrangements_match_closed_forms_and_the_reference() {
    let w = wall();
    let a = square(1., 1., 2., 2.);
    // Identical shadows, each alone and both: one square metre of twelve.
    assert!((assert_agrees(&w, &[a.clone(), a.clone(), a.clone()], "identical") - 11. / 12.).abs() < 1e-12);
    // Sharing an edge (opposite directions), and overlapping along a collinear edge (same direction).
    assert!((assert_agrees(&w, &[a.clone(), square(2., 1., 3., 2.)], "shared edge") - 10. / 12.).abs() < 1e-12);
    assert!((assert_agrees(&w, &[a.clone(), square(1.5, 1., 3., 1.5)], "collinear overlap") - (12. - 1.5) / 12.).abs() < 1e-12);
    // Touching at a vertex; nested; along the wall's own edge and its diagonal; beyond it.
    assert!((assert_agrees(&w, &[a.clone(), square(2., 2., 3., 3.)], "vertex") - 10. / 12.).abs() < 1e-12);
    assert!((assert_agrees(&w, &[square(0.5, 0.5, 3., 2.5), a.clone()], "nested") - 7. / 12.).abs() < 1e-12);
    assert!((assert_agrees(&w, &[square(0., 0., 4., 1.)], "on the wall's edge") - 8. / 12.).abs() < 1e-12);
    assert!((assert_agrees(&w, &[tri([[0., 0.], [4., 3.], [0., 3.]])], "the upper triangle itself") - 0.5).abs() < 1e-12);
    assert!((assert_agrees(&w, &[square(-1., -1., 5., 4.)], "all of it")).abs() < 1e-12);
    assert!((assert_agrees(&w, &[square(-2., 1., 6., 2.)], "beyond both sides") - 8. / 12.).abs() < 1e-12);
    assert_eq!(assert_agrees(&w, &[square(5., 0., 6., 3.)], "beside it"), 1.0);
    // The holed wall (10 m²): a shadow over the hole shades only its frame.
    let h = holed_wall();
    assert!((assert_agrees(&h, &[square(0.5, 0.5, 3.5, 2.5)], "over the hole") - 6. / 10.).abs() < 1e-12);
    assert!((assert_agrees(&h, &[square(1., 1., 3., 2.)], "the hole itself") - 1.0).abs() < 1e-12);
    assert!((assert_agrees(&h, &[square(1., 1., 3., 2.5)], "the hole's top edge and above") - 9. / 10.).abs() < 1e-12);
}

/// Deterministic pseudo-random numbers (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The hull of a few random points: on a coarse lattice (so edges coincide, overlap, touch)
/// or anywhere.
fn random_convex(rng: &mut Rng, lattice: bool) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = (0..3 + rng.below(6))
        .map(|_| {
            if lattice {
                DVec2::new(rng.below(25) as f64 * 0.25 - 1.0, rng.below(19) as f64 * 0.25 - 1.0)
            } else {
                DVec2::new(rng.unit() * 6.0 - 1.0, rng.unit() * 5.0 - 1.0)
            }
        })
        .collect();
    let mut h = Vec::new();
    super::super::objects::convex_hull(&mut pts, &mut h);
    h
}

#[test]
fn random_convex_shadows_agree_with_the_reference() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut partly = 0;
    for case in 0..400 {
        let receiver = if case % 2 == 0 { wall() } else { holed_wall() };
        let lattice = case % 3 != 0;
        let count = 1 + rng.below(if case % 5 == 0 { 80 } else { 12 }) as usize;
        let mut shadows: Vec<Vec<DVec2>> = Vec::new();
        for _ in 0..count {
            let s = random_convex(&mut rng, lattice);
            if s.len() < 3 {
                continue;
            }
            match rng.below(6) {
                // A copy of an earlier shadow, or one reversed (same polygon, other start).
                0 if !shadows.is_empty() => {
                    let k = rng.below(shadows.len() as u64) as usize;
                    let mut copy = shadows[k].clone();
                    copy.rotate_left(1);
                    shadows.push(copy);
                }
                // One nested in an earlier one: shrunk about its centre.
                1 if !shadows.is_empty() => {
                    let k = rng.below(shadows.len() as u64) as usize;
                    let c = shadows[k].iter().copied().sum::<DVec2>() / shadows[k].len() as f64;
                    shadows.push(shadows[k].iter().map(|&p| c + (p - c) * 0.5).collect());
                }
                _ => shadows.push(s),
            }
        }
        let got = assert_agrees(&receiver, &shadows, &format!("case {case}"));
        partly += usize::from(got > 0.01 && got < 0.99);
    }
    assert!(partly > 200, "only {partly} cases partly shaded");
}

/// Pushes `receiver` and `shadows`, returns the area (m²) and the polygons kept after it.
fn area_and_kept(receiver: &[Vec<DVec2>], shadows: &[Vec<DVec2>]) -> (f64, usize) {
    let s = snap();
    let mut b = Boundary::default();
    for r in receiver {
        b.push(&s, r, true);
    }
    for sh in shadows {
        b.push(&s, sh, false);
    }
    let area = b.uncovered_area() / s.area_scale();
    (area, b.len())
}

#[test]
fn polygons_inside_one_shadow_are_dropped_and_the_area_is_unchanged() {
    let w = wall();
    let big = square(0.5, 0.5, 3., 2.5);
    // Alone: 12 − 5 m² lit, two receiver triangles and the shadow kept.
    assert_eq!(area_and_kept(&w, std::slice::from_ref(&big)), (7.0, 3));
    // Nested, touching its edges from inside, an identical copy before and after: all go,
    // whichever is pushed first, and the area is the same.
    let inside = [square(1., 1., 2., 2.), square(0.5, 0.5, 3., 1.), tri([[0.5, 0.5], [3., 0.5], [3., 2.5]])];
    for first in [false, true] {
        let mut shadows: Vec<Vec<DVec2>> = inside.to_vec();
        shadows.insert(if first { 0 } else { shadows.len() }, big.clone());
        shadows.push(big.clone());
        assert_eq!(area_and_kept(&w, &shadows), (7.0, 3), "big first: {first}");
    }
    // Sticking out by a quarter on one side: kept, and its sliver is shaded too.
    let (area, kept) = area_and_kept(&w, &[big.clone(), square(1., 1., 3.25, 2.)]);
    assert_eq!((area, kept), (12. - 5. - 0.25, 4));
    // Within the bounds of a triangular shadow but beside it: kept.
    let half = tri([[0.5, 0.5], [3., 0.5], [3., 2.5]]);
    assert_eq!(area_and_kept(&w, &[half, square(0.5, 2., 1., 2.5)]), (12. - 2.5 - 0.25, 4));
    // A receiver triangle in full shade (its diagonal on the shadow's edge) goes; the other
    // stays, all lit.
    let upper = tri([[-1., -0.75], [5., 3.75], [-1., 3.75]]);
    assert_eq!(area_and_kept(&w, &[upper]), (6.0, 2));
    // Everything in shade: no receiver left, nothing lit.
    assert_eq!(area_and_kept(&w, &[square(-1., -1., 5., 4.), big]), (0.0, 1));
}

#[test]
fn leaves_inside_a_wide_shadow_are_dropped_with_buckets_and_agree() {
    // A wall's shadow over the left half, 300 leaves: inside it, across its edge, beyond it.
    let mut rng = Rng(11);
    let mut shadows = vec![square(-0.5, -0.5, 2., 3.5)];
    for _ in 0..300 {
        let c = DVec2::new(rng.below(33) as f64 * 0.125, rng.below(25) as f64 * 0.125);
        let r = 0.125 * (1 + rng.below(2)) as f64;
        shadows.push(vec![c + DVec2::new(-r, 0.), c + DVec2::new(0., -r), c + DVec2::new(r, 0.), c + DVec2::new(0., r)]);
    }
    let receiver = holed_wall();
    let got = assert_agrees(&receiver, &shadows, "leaves and a wall's shadow");
    assert!(got > 0.0 && got < 0.5, "{got}");
    let inside = shadows[1..].iter().filter(|l| l.iter().all(|p| p.x <= 2. && p.y >= -0.5 && p.y <= 3.5)).count();
    let (_, kept) = area_and_kept(&receiver, &shadows);
    assert!(shadows.len() > SCAN_ALL && inside > 100, "{inside} inside");
    // Kept: the receiver's triangles that reach out of the shade, the wide shadow, and at
    // most the leaves not inside it.
    assert!(kept <= receiver.len() + 1 + shadows.len() - 1 - inside, "{kept} kept of {} ({inside} inside)", shadows.len());
}

#[test]
fn a_long_facade_with_many_leaves_agrees() {
    // A 15 × 1 façade (a 15:1 window, the buckets square and sized by the leaves): leaves on
    // a lattice (so they share edges and vertices, and touch bucket borders), copies, and a
    // few wide shadows, against the reference.
    let facade = vec![tri([[-7.5, 0.], [7.5, 0.], [7.5, 1.]]), tri([[-7.5, 0.], [7.5, 1.], [-7.5, 1.]])];
    let mut rng = Rng(23);
    for case in 0..6 {
        let mut shadows: Vec<Vec<DVec2>> = Vec::new();
        for _ in 0..200 + 150 * case {
            let c = DVec2::new(rng.below(121) as f64 * 0.125 - 7.5, rng.below(9) as f64 * 0.125);
            let r = 0.125 * (1 + rng.below(2)) as f64;
            let leaf = if rng.below(2) == 0 {
                vec![c + DVec2::new(-r, 0.), c + DVec2::new(r, -r), c + DVec2::new(0., r)]
            } else {
                vec![c + DVec2::new(-r, 0.), c + DVec2::new(0., -r), c + DVec2::new(r, 0.), c + DVec2::new(0., r)]
            };
            if rng.below(8) == 0 {
                shadows.push(leaf.clone());
            }
            shadows.push(leaf);
        }
        shadows.insert(17, square(-3., -0.5, -1., 1.5));
        shadows.push(tri([[-8., 0.25], [8., 0.5], [-8., 0.75]]));
        let got = assert_agrees(&facade, &shadows, &format!("façade case {case}"));
        assert!(got > 0.0 && got < 1.0, "case {case}: {got}");
    }
}

#[test]
fn many_shadows_use_buckets_and_agree() {
    // Leaves: 600 small shadows, some overlapping, some identical, and two wide ones.
    let mut rng = Rng(7);
    let mut shadows = Vec::new();
    for _ in 0..600 {
        let c = DVec2::new(rng.below(33) as f64 * 0.125, rng.below(25) as f64 * 0.125);
        let r = 0.125 * (1 + rng.below(3)) as f64;
        shadows.push(vec![c + DVec2::new(-r, 0.), c + DVec2::new(0., -r), c + DVec2::new(r, 0.), c + DVec2::new(0., r)]);
    }
    // A few wide shadows among them (a branch, a wall's): kept out of the buckets.
    shadows.insert(100, square(-0.5, 0.25, 4.5, 0.5));
    shadows.push(tri([[-1., 1.0], [5., 1.2], [-1., 1.4]]));
    let receiver = holed_wall();
    let got = assert_agrees(&receiver, &shadows, "leaves");
    assert!(got > 0.0 && got < 1.0, "{got}");
    let mut b = Boundary::default();
    for sh in &shadows {
        b.push(&snap(), sh, false);
    }
    assert!(b.len() > SCAN_ALL);
}

#[test]
fn a_dense_canopy_off_the_lattice_agrees() {
    // Leaves anywhere (not on a lattice), several deep over most of the wall: most edges lie
    // inside the union, covered by several leaves together and by none alone, where an edge
    // stops being integrated once its covers hold all of it; the rest bound small gaps. Against
    // the reference, which has no such shortcut.
    let mut rng = Rng(0x5eed_1eaf);
    for case in 0..4 {
        let mut shadows: Vec<Vec<DVec2>> = Vec::new();
        for _ in 0..150 + 60 * case {
            let c = DVec2::new(rng.unit() * 4.6 - 0.3, rng.unit() * 3.6 - 0.3);
            let r = 0.15 + 0.35 * rng.unit();
            let turn = rng.unit() * std::f64::consts::TAU;
            let corners = 3 + rng.below(3) as usize;
            shadows.push(
                (0..corners)
                    .map(|k| {
                        let a = turn + std::f64::consts::TAU * k as f64 / corners as f64;
                        c + r * DVec2::new(a.cos(), a.sin())
                    })
                    .collect(),
            );
        }
        let receiver = if case % 2 == 0 { wall() } else { holed_wall() };
        let got = assert_agrees(&receiver, &shadows, &format!("canopy case {case}"));
        assert!(got > 0.0 && got < 0.5, "case {case}: {got}");
    }
}

#[test]
fn shadows_apart_from_every_receiver_go_and_the_area_is_the_same_to_the_bit() {
    // A wall with a window's hole (10 m²) and a stripe of shadow across its foot (1 m²).
    let w = holed_wall();
    let across = square(-1., 0.5, 5., 0.75);
    let (alone, kept) = area_and_kept(&w, std::slice::from_ref(&across));
    assert_eq!((alone, kept), (9.0, 9));
    // Shadows in the hole and beyond the wall's side, before and after the stripe: their boxes
    // meet no receiver triangle's, so they go, and the area is the stripe's alone, bit for bit.
    let hole = [square(1.25, 1.25, 2.75, 1.75), tri([[1.5, 1.1], [2.5, 1.1], [2., 1.9]])];
    let mut shadows = hole.to_vec();
    shadows.extend([across.clone(), square(4.25, 0., 6., 3.)]);
    assert_eq!(area_and_kept(&w, &shadows), (alone, kept));
    // One filling the hole exactly touches the ring's boxes: kept, and it still shades nothing.
    assert_eq!(area_and_kept(&w, &[square(1., 1., 3., 2.), across.clone()]), (9.0, 10));

    // Many: 20 × 16 quarter squares over and around the wall (buckets), a third of them in the
    // hole or off the wall. Those wholly inside the hole or beyond the wall are left out of a
    // second run: the same area to the bit, and the reference's.
    let leaves: Vec<Vec<DVec2>> = (0..320)
        .filter(|k| k % 3 != 1)
        .map(|k| {
            let (x, y) = (-0.75 + 0.25 * (k % 22) as f64, -0.5 + 0.25 * (k / 22) as f64);
            square(x, y, x + 0.125, y + 0.125)
        })
        .collect();
    let apart = |p: &Vec<DVec2>| {
        let (lo, hi) = p.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
        let in_hole = lo.x > 1. && hi.x < 3. && lo.y > 1. && hi.y < 2.;
        let off = hi.x < 0. || lo.x > 4. || hi.y < 0. || lo.y > 3.;
        in_hole || off
    };
    let near: Vec<Vec<DVec2>> = leaves.iter().filter(|p| !apart(p)).cloned().collect();
    assert!(leaves.len() - near.len() > 60 && near.len() > 48, "{} leaves, {} near", leaves.len(), near.len());
    let (all, kept_all) = area_and_kept(&w, &leaves);
    let (some, kept_some) = area_and_kept(&w, &near);
    assert_eq!((all, kept_all), (some, kept_some));
    assert_agrees(&w, &leaves, "leaves over a holed wall");
}
