use super::*;

/// A footprint is left out only where no direction of the cone casts its triangle within
/// the disc's radius of the polygon's bounds, and one kept holds every shadow point. A
/// triangle 10 m in front of a 2 m window, whose shadow along the cone's axis falls 1.3 m
/// beside the window but along one edge of the cone reaches it, is kept: a reject on the
/// axis alone, without the generators' slack, drops it and fails here. One farther aside is
/// left out, and no direction brings it near (brute force over the cone's scaled directions).
#[test]
fn a_footprint_is_left_out_only_where_no_direction_of_the_cone_brings_it_near() {
    let corner = |x: f64, z: f64| DVec3::new(x, 0.0, z);
    let window = [[corner(0.0, 0.0), corner(2.0, 0.0), corner(2.0, 2.0)], [corner(0.0, 0.0), corner(2.0, 2.0), corner(0.0, 2.0)]];
    let outline = Outline::new(&window, -DVec3::Y).expect("a square has area");
    let scaled = |tx: f64, tz: f64| DVec3::new(tx, -1.0, tz);
    let edges = [(0.0, 0.3), (0.3, 0.3), (0.0, 0.32), (0.3, 0.32)];
    let cone = DirectionCone::enclosing(&edges.map(|(tx, tz)| scaled(tx, tz).normalize())).expect("a narrow cone");
    let onto = outline.onto(&cone);
    let r = outline.radius;
    let (mut kept, mut left_out) = (0, 0);
    for x in [4.8, 10.0] {
        let t = [DVec3::new(x, -10.0, 4.0), DVec3::new(x + 0.2, -10.0, 4.0), DVec3::new(x, -10.0, 4.5)];
        let footprint = outline.footprint(&t, &onto, 1e-9, r);
        for k in 0..=30 {
            for (tz, p) in [(0.3, 0), (0.32, 1), (0.31, 2)] {
                let shadow = outline.flat(t[p] - scaled(0.3 * f64::from(k) / 30.0, tz) * 10.0);
                let near = !outline.apart(shadow, shadow, r);
                match &footprint {
                    Some(f) => assert!(!f.distance_at_least(shadow, 1e-9), "the footprint at x = {x} misses the shadow {shadow}"),
                    None => assert!(!near, "left out at x = {x}, yet the shadow {shadow} comes within the disc of the window"),
                }
            }
        }
        // What a reject on the axis alone would have said: both apart.
        let (lo, hi) = bounds(&t.map(|p| outline.flat(p - onto.axis * 10.0)));
        assert!(outline.apart(lo, hi, r), "the triangle at x = {x} is near the window along the axis: the case tests nothing");
        if footprint.is_some() { kept += 1 } else { left_out += 1 }
    }
    assert_eq!((kept, left_out), (1, 1));
}

/// A cell's suns (14 days by an hour of steps every 15 minutes, in order of rows, as the year
/// hands them over) are halved across their widest extent: along that axis of the chart each
/// half spans at most 60 % of the whole, where the rows' own halves (the first and last seven
/// days) each span over 90 % of it, the hour's sweep; and the order is a permutation of the
/// set. Spring, summer and winter cells of a south and an east window.
#[test]
fn a_sets_halves_are_taken_across_its_widest_extent() {
    let location = crate::count::certify::tests::golden();
    let mut tried = 0;
    for (first, hour, normal) in [(60, 10.0, -DVec3::Y), (160, 13.0, -DVec3::Y), (330, 11.0, -DVec3::Y), (172, 8.0, DVec3::X)] {
        let suns: Vec<DVec3> = (first..first + 14)
            .flat_map(|day| (0..5).map(move |k| (day, hour + 0.25 * f64::from(k))))
            .map(|(day, h)| crate::sun::position::sun_direction(&location, f64::from(day), h))
            .filter(|s| s.z > 0.1 && s.dot(normal) > 0.1)
            .collect();
        assert_eq!(suns.len(), 70, "day {first}: every step up and in front");
        let axis = suns.iter().copied().sum::<DVec3>().normalize();
        let (u, v) = perpendicular_basis(axis);
        let chart = |d: DVec3| DVec2::new(d.dot(u), d.dot(v)) / d.dot(axis);
        let span = |set: &[usize], along: DVec2| {
            let at: Vec<f64> = set.iter().map(|&i| chart(suns[i]).dot(along)).collect();
            at.iter().copied().fold(f64::NEG_INFINITY, f64::max) - at.iter().copied().fold(f64::INFINITY, f64::min)
        };
        let rows: Vec<usize> = (0..suns.len()).collect();
        let along = if span(&rows, DVec2::X) >= span(&rows, DVec2::Y) { DVec2::X } else { DVec2::Y };
        let whole = span(&rows, along);
        let mut set = rows.clone();
        split_widest(&suns, &mut set);
        let mut sorted = set.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, rows, "not a permutation");
        let (low, high) = set.split_at(set.len() / 2);
        assert!(span(low, along) <= 0.6 * whole && span(high, along) <= 0.6 * whole, "day {first}: halves not across the widest extent");
        let (early, late) = rows.split_at(rows.len() / 2);
        assert!(span(early, along) > 0.9 * whole && span(late, along) > 0.9 * whole, "day {first}: the rows' halves already halve it");
        tried += 1;
    }
    assert_eq!(tried, 4);
}

/// The hull-free test ([`separated`]) agrees with the distance to the hull wherever it
/// decides, and decides most cases: random point sets (thin bands like a louvre's shadow,
/// blobs, one or two points), points and radii about them, against the brute-force distance
/// (inside the hull, or the least distance to its edges). A separating line accepted short
/// of `r` (or the wrong side of `q`) says "apart" where the hull comes within `r`, and fails.
#[test]
fn a_footprint_is_apart_without_its_hull_exactly_where_the_hull_is_apart() {
    let mut next = crate::count::certify::tests::random(41);
    let (mut decided, mut cases, mut near) = (0, 0, 0);
    for _ in 0..4000 {
        let n = 1 + (next() * 40.0) as usize;
        let (sx, sy) = (0.1 + next() * 3.0, if next() < 0.5 { 0.02 + next() * 0.1 } else { 0.1 + next() * 3.0 });
        let points: Vec<DVec2> = (0..n).map(|_| DVec2::new(next() * sx, next() * sy)).collect();
        let q = DVec2::new(next() * 4.0 - 0.5, next() * 4.0 - 0.5);
        let r = next() * 0.5;
        let hull = convex_hull(&points);
        let m = hull.len();
        let inside = m >= 3 && (0..m).all(|k| (hull[(k + 1) % m] - hull[k]).perp_dot(q - hull[k]) >= 0.0);
        let distance =
            if inside { 0.0 } else { (0..m).map(|k| segment_distance(q, hull[k], hull[(k + 1) % m])).fold(f64::INFINITY, f64::min) };
        cases += 1;
        near += usize::from(distance < r);
        if let Some(apart) = separated(&points, q, r) {
            decided += 1;
            assert_eq!(apart, distance >= r, "{n} points, q {q}, r {r}: the hull is {distance} away");
        }
    }
    assert!(near > cases / 10, "only {near} of {cases} cases near: the test shows nothing");
    assert!(decided * 10 > cases * 9, "only {decided} of {cases} decided without the hull");
}

/// One footprint for a whole convex caster holds every point any of its triangles shades
/// at any direction of the cone, and is a convex polygon wound counter-clockwise. A box
/// (a scrim's rod, 12 triangles) 0.6 m in front of a window, over a wide cone (so the hull
/// over the generators is taken, not the axis's dilation) and a narrow one (the dilation):
/// brute force over the box's surface points and the cone's scaled directions. A footprint
/// from the box's corners moved along the axis alone, without the generators, would miss
/// shadow points of the wide cone by about 0.26 m; one from only the face nearest the
/// window, those of its far face by about 0.04 m.
#[test]
fn a_casters_one_footprint_holds_every_shadow_of_its_triangles_and_is_convex() {
    let corner = |x: f64, z: f64| DVec3::new(x, 0.0, z);
    let window = [[corner(0.0, 0.0), corner(2.0, 0.0), corner(2.0, 2.0)], [corner(0.0, 0.0), corner(2.0, 2.0), corner(0.0, 2.0)]];
    let outline = Outline::new(&window, -DVec3::Y).expect("a square has area");
    let (lo, hi) = (DVec3::new(-0.5, -0.65, 0.9), DVec3::new(2.5, -0.6, 0.95));
    let corners: Vec<DVec3> = (0..8).map(|i| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2])).collect();
    let scaled = |tx: f64, tz: f64| DVec3::new(tx, -1.0, tz);
    for (wide, edges) in
        [(true, [(-0.4, 0.2), (0.4, 0.2), (-0.4, 0.8), (0.4, 0.8)]), (false, [(0.1, 0.5), (0.1005, 0.5), (0.1, 0.5005), (0.1005, 0.5005)])]
    {
        let cone = DirectionCone::enclosing(&edges.map(|(tx, tz)| scaled(tx, tz).normalize())).expect("a cone");
        let onto = outline.onto(&cone);
        let footprint = outline.caster_footprint(&corners, &onto, 1e-9, outline.radius).expect("wholly in front").expect("near the window");
        assert_eq!(footprint.slack > 0.0, !wide, "the wide cone takes the generators' hull, the narrow one the axis's dilation");
        let hull = footprint.hull();
        let n = hull.len();
        assert!(n >= 3, "a box's footprint has area");
        for k in 0..n {
            let (a, b, c) = (hull[k], hull[(k + 1) % n], hull[(k + 2) % n]);
            assert!((b - a).perp_dot(c - b) > 0.0, "the footprint's hull turns right at {b}: not convex counter-clockwise");
        }
        // Every point of the box's surface (its faces sampled), along every sampled direction.
        let steps = 12;
        let mut tried = 0;
        for (a, b) in edges.iter().zip(edges.iter().skip(1).chain(edges.first())) {
            for s in 0..=steps {
                let w = f64::from(s) / f64::from(steps);
                let d = scaled(a.0 + (b.0 - a.0) * w, a.1 + (b.1 - a.1) * w);
                for i in 0..=steps {
                    for j in 0..=steps {
                        let (u, v) = (f64::from(i) / f64::from(steps), f64::from(j) / f64::from(steps));
                        let faces = [
                            DVec3::new(lo.x + u * (hi.x - lo.x), lo.y, lo.z + v * (hi.z - lo.z)),
                            DVec3::new(lo.x + u * (hi.x - lo.x), hi.y, lo.z + v * (hi.z - lo.z)),
                            DVec3::new(lo.x + u * (hi.x - lo.x), lo.y + v * (hi.y - lo.y), lo.z),
                            DVec3::new(lo.x + u * (hi.x - lo.x), lo.y + v * (hi.y - lo.y), hi.z),
                        ];
                        for p in faces {
                            let height = (p - outline.origin).dot(outline.normal);
                            let shadow = outline.flat(p - d * height);
                            assert!(
                                !footprint.distance_at_least(shadow, 1e-9),
                                "wide {wide}: the shadow {shadow} of {p} falls outside the footprint"
                            );
                            tried += 1;
                        }
                    }
                }
            }
        }
        assert!(tried > 10_000);
    }
}
