//! Maps on the GPU: per-texel lit masks ([`sunlit::count::gpu::masks`], `shaders/point_masks.wgsl`)
//! held to their CPU truth on the same atlas, to the exact engine's shadow rays on a louvred
//! wall (every point farther than 1.5 texels from a shadow edge agrees), to analytic shadow lines
//! (an overhang, a slot in a screen), and a fine grid's area mean to the exact fraction, from both
//! engines. These need a GPU adapter (lavapipe in CI) and never skip.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;

use common::*;
use glam::{DVec2, DVec3, DVec4};
use sunlit::count::gpu::Counter;
use sunlit::count::gpu::masks::{MaskTile, PointMask};
use sunlit::count::{ViewRequest, exact};
use sunlit::map::{MapGpu, Mapper, Points, grid, lit};
use sunlit::scene::{Scene, SourceMesh};

/// Tile side of these tests: a 4 m wall gets about 0.9 cm texels.
const SIDE: u32 = 512;

/// The distance, in texels, beyond which a point's mask must agree with the exact answer: the
/// point's texel centre is within √2/2 ≈ 0.71 texel of it, so a shadow edge farther than that
/// cannot separate them; 1.5 leaves room for f32 rounding and the rasteriser's own rule.
const SAFE_TEXELS: f64 = 1.5;

/// A 4 × 3 m south wall (y = 0) with a 2 × 1 m window (x 1..3, z 1..2) in a hole of it: one view
/// group, so both share a tile.
fn wall_and_window(s: &mut TestScene) {
    let p = [[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.], [1., 0., 1.], [3., 0., 1.], [3., 0., 2.], [1., 0., 2.]];
    let positions = p.iter().map(|v: &[f64; 3]| v.map(|x| x as f32)).collect();
    let indices = vec![0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7];
    s.mesh("WALL", SourceMesh { positions, indices }, true);
    s.polygon("WIN", &south_rect(1.0, 3.0, 1.0, 2.0, 0.0), true);
}

/// The wall and window behind eight louvre slats and a fin: shadow edges along and across.
fn louvred() -> Scene {
    let mut s = TestScene::new();
    wall_and_window(&mut s);
    for k in 0..8 {
        let z = 0.2 + 0.36 * k as f64;
        s.cuboid(&format!("SLAT{k}"), DVec3::new(-1.0, -0.5, z), DVec3::new(5.0, -0.1, z + 0.05));
    }
    s.cuboid("FIN", DVec3::new(2.3, -0.6, -0.5), DVec3::new(2.35, -0.05, 3.5));
    s.build()
}

fn all(scene: &Scene) -> Vec<u32> {
    (0..scene.receivers.len() as u32).collect()
}

/// The tile's pixels per world offset `v` (linear part of the camera; y downwards).
fn to_pixels(tile: &MaskTile, v: DVec3) -> DVec2 {
    let c = tile.view.view_proj * v.extend(0.0);
    DVec2::new(c.x, -c.y) * (0.5 * tile.side as f64)
}

/// The world offset on a plane (normal `n`) that the tile shows `px` pixels away, along the sun.
fn on_plane(tile: &MaskTile, px: DVec2, sun: DVec3, n: DVec3) -> DVec3 {
    let ndc = DVec2::new(px.x, -px.y) * (2.0 / tile.side as f64);
    let d = (tile.view.view_proj.inverse() * DVec4::new(ndc.x, ndc.y, 0.0, 0.0)).truncate();
    d - sun * (d.dot(n) / sun.dot(n))
}

/// One rendered view per request, on one fresh counter, with its points' masks as 0/1 per point
/// (indices as given), and each point's tile.
struct GpuAnswer {
    lit: Vec<bool>,
    tile: Vec<Option<MaskTile>>,
}

fn gpu_answer(counter: &Counter, scene: &Scene, points: &Points, sun: DVec3) -> GpuAnswer {
    let gpu = counter.upload(scene).unwrap();
    let uploaded = counter.upload_points(&gpu, &points.positions, &points.receivers).unwrap();
    let requests: Vec<ViewRequest> = (0..scene.receivers.len() as u32).map(|r| ViewRequest::new(r, sun)).collect();
    let masks = pollster::block_on(counter.masks(&gpu, &uploaded, &requests, true)).unwrap();
    let mut out = GpuAnswer { lit: vec![false; points.len()], tile: vec![None; points.len()] };
    for (i, req) in requests.iter().enumerate() {
        for (j, &p) in uploaded.points_of(req.receiver).iter().enumerate() {
            out.lit[p as usize] = masks.lit(i, j);
            if let PointMask::Rendered { tile, .. } = &masks.masks[i] {
                out.tile[p as usize] = Some(*tile);
            }
        }
    }
    out
}

/// The mask pass against its CPU truth on the very atlas it read: every point's bit is the one
/// the CPU finds by the same steps, but for points within 1e-3 texel of a texel border (f32
/// rounding may put them either side).
#[test]
fn masks_match_their_cpu_truth_on_the_same_atlas() {
    let scene = louvred();
    let points = grid(&scene, 0.02, &all(&scene)).unwrap();
    let counter = counter(SIDE);
    let gpu = counter.upload(&scene).unwrap();
    let uploaded = counter.upload_points(&gpu, &points.positions, &points.receivers).unwrap();
    // Three suns, two receivers sharing each tile: three tiles, one batch, so the atlas read
    // afterwards holds all of them.
    let suns = [sun(180.0, 35.0), sun(215.0, 50.0), sun(150.0, 20.0)];
    let requests: Vec<ViewRequest> = suns.iter().flat_map(|&s| (0..2).map(move |r| ViewRequest::new(r, s))).collect();
    assert!(requests.len() <= counter.tiles_per_batch());
    let masks = pollster::block_on(counter.masks(&gpu, &uploaded, &requests, true)).unwrap();
    let (atlas_side, atlas) = pollster::block_on(counter.read_atlas()).unwrap();
    let (mut checked, mut lit, mut borderline) = (0, 0, 0);
    for (i, req) in requests.iter().enumerate() {
        let PointMask::Rendered { tile, .. } = &masks.masks[i] else { panic!("request {i} was not rendered: {:?}", masks.masks[i]) };
        assert_eq!(tile.side, SIDE);
        let id = gpu.gpu_id(req.receiver);
        for (j, &p) in uploaded.points_of(req.receiver).iter().enumerate() {
            let (truth, pixel) = sunlit::count::gpu::mask_truth(&atlas, atlas_side, tile, id, gpu.origin(), points.position(p as usize));
            if pixel.iter().any(|c| (c - c.round()).abs() < 1e-3) {
                borderline += 1;
                continue;
            }
            assert_eq!(masks.lit(i, j), truth, "request {i}, point {} at pixel {pixel:?}", points.position(p as usize));
            checked += 1;
            lit += usize::from(truth);
        }
    }
    assert!(borderline * 100 < checked, "{borderline} borderline of {checked}");
    assert!(lit > checked / 10 && lit < checked * 9 / 10, "partly shaded: {lit} of {checked} lit");
    // The same tiles counted: the fractions are those of a plain count.
    let fractions = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap();
    for (a, b) in masks.counted.iter().zip(&fractions) {
        assert_eq!((a.visible, a.covered), (b.visible, b.covered));
        assert!(a.covered > 1000 && a.side == SIDE, "{a:?}");
    }
}

/// GPU masks against the exact engine's shadow rays on the louvred wall: every point whose exact
/// answer is the same over a disc of 1.5 texels around it (sampled on two rings, in the tile's own
/// pixels carried back onto the wall along the sun) agrees, and the points that disagree are few:
/// a point disagrees only when a shadow edge passes between it and its texel's centre, within
/// 0.71 texel, so at most about half the points within 1.5 texels of an edge.
#[test]
fn masks_agree_with_exact_rays_away_from_shadow_edges() {
    let scene = louvred();
    let points = grid(&scene, 0.025, &all(&scene)).unwrap();
    let counter = counter(SIDE);
    for s in [sun(180.0, 35.0), sun(215.0, 50.0), sun(150.0, 20.0), sun(245.0, 28.0)] {
        let gpu = gpu_answer(&counter, &scene, &points, s);
        let exact = lit(&scene, &points, s, 1.0).unwrap();
        // Around each point: 16 samples 1.5 texels out, 8 at 0.75.
        let rings: Vec<DVec2> = (0..16)
            .map(|k| DVec2::from_angle(k as f64 * std::f64::consts::TAU / 16.0) * SAFE_TEXELS)
            .chain((0..8).map(|k| DVec2::from_angle(k as f64 * std::f64::consts::TAU / 8.0) * SAFE_TEXELS / 2.0))
            .collect();
        let mut around = Points::default();
        for i in 0..points.len() {
            let tile = gpu.tile[i].expect("every point of a partly shaded wall is rendered");
            let r = points.receivers[i];
            let n = scene.receivers[r as usize].normal;
            for &px in &rings {
                let q = points.position(i) + on_plane(&tile, px, s, n);
                around.positions.extend(q.to_array().map(|v| v as f32));
                around.normals.extend(n.to_array().map(|v| v as f32));
                around.receivers.push(r);
            }
        }
        let ring_exact = lit(&scene, &around, s, 1.0).unwrap();
        let (mut near, mut disagree, mut far) = (0usize, 0usize, 0usize);
        for i in 0..points.len() {
            let e = exact[i] >= 0.5;
            let steady = ring_exact[i * rings.len()..(i + 1) * rings.len()].iter().all(|&v| (v >= 0.5) == e);
            if steady {
                far += 1;
                assert_eq!(gpu.lit[i], e, "sun {s}: point {} is {SAFE_TEXELS} texels from any shadow edge", points.position(i));
            } else {
                near += 1;
                disagree += usize::from(gpu.lit[i] != e);
            }
        }
        let share = disagree as f64 / points.len() as f64;
        eprintln!("sun {s}: {} points, {far} far from edges, {near} near, {disagree} disagree ({:.3} %)", points.len(), share * 100.0);
        assert!(near > 0 && far > points.len() / 2, "the louvres cast edges over the wall ({near} near)");
        assert!(2 * disagree <= near, "{disagree} of {near} points near an edge disagree");
        assert!(share < 0.02, "disagreement share {share}");
    }
}

/// The pixel distance, in the tile, from `p` to the line through `a` along `dir` (both on the
/// receiver's plane).
fn texels_from_line(tile: &MaskTile, p: DVec3, a: DVec3, dir: DVec3) -> f64 {
    let (d, u) = (to_pixels(tile, p - a), to_pixels(tile, dir));
    d.perp_dot(u).abs() / u.length()
}

/// An overhang of depth d over a bare wall: points more than 1.5 texels above the analytic
/// shadow line z = h − d·tan(profile) are shaded, those as far below are lit.
#[test]
fn overhang_shadow_line_on_the_gpu() {
    let d = 0.83;
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(0.0, 4.0, 0.0, 3.0, 0.0), true);
    s.polygon("OVERHANG", &flat_rect(-20.0, 24.0, -d, 0.0, 3.0), false);
    let scene = s.build();
    let points = grid(&scene, 0.05, &all(&scene)).unwrap();
    let counter = counter(SIDE);
    for (azimuth, altitude) in [(180.0, 20.0), (190.0, 35.0), (140.0, 50.0), (205.0, 62.0)] {
        let sun = sun(azimuth, altitude);
        let line = 3.0 - d * sun.z / -sun.y;
        let gpu = gpu_answer(&counter, &scene, &points, sun);
        let (mut shaded, mut lit, mut undecided) = (0, 0, 0);
        for i in 0..points.len() {
            let p = points.position(i);
            let tile = gpu.tile[i].unwrap();
            if texels_from_line(&tile, p, DVec3::new(0.0, 0.0, line), DVec3::X) <= SAFE_TEXELS {
                undecided += 1;
                continue;
            }
            let expect = p.z < line;
            assert_eq!(gpu.lit[i], expect, "sun {azimuth}/{altitude}: point at z {} (line {line})", p.z);
            shaded += usize::from(!expect);
            lit += usize::from(expect);
        }
        assert!(shaded > 0 && lit > 0 && undecided < points.len() / 10, "{shaded} shaded, {lit} lit, {undecided} near the line");
    }
}

/// A screen 1 m in front of the wall with a slot z in (1.2, 1.6): only the points in the slot's
/// sun patch on the wall (z + rise in the slot) are lit, but within 1.5 texels of its two lines.
#[test]
fn slot_in_a_screen_on_the_gpu() {
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(0.0, 4.0, 0.0, 3.0, 0.0), true);
    s.polygon("SCREEN_LOW", &south_rect(-30.0, 34.0, -5.0, 1.2, -1.0), false);
    s.polygon("SCREEN_HIGH", &south_rect(-30.0, 34.0, 1.6, 9.0, -1.0), false);
    let scene = s.build();
    let points = grid(&scene, 0.02, &all(&scene)).unwrap();
    let counter = counter(SIDE);
    for (azimuth, altitude) in [(180.0, 25.0), (210.0, 40.0), (160.0, 12.0)] {
        let sun = sun(azimuth, altitude);
        let rise = sun.z / -sun.y;
        let gpu = gpu_answer(&counter, &scene, &points, sun);
        let mut band = 0;
        for i in 0..points.len() {
            let p = points.position(i);
            let tile = gpu.tile[i].unwrap();
            let near = [1.2, 1.6].iter().any(|&z| texels_from_line(&tile, p, DVec3::new(0.0, 0.0, z - rise), DVec3::X) <= SAFE_TEXELS);
            if near {
                continue;
            }
            let expect = p.z + rise > 1.2 && p.z + rise < 1.6;
            assert_eq!(gpu.lit[i], expect, "sun {azimuth}/{altitude}: point at z {} (ray at the screen {})", p.z, p.z + rise);
            band += usize::from(expect);
        }
        assert!(band > 0, "some points see through the slot");
    }
}

/// Five slats in front of a bare wall: each engine's grid mean converges to the exact engine's
/// fraction. The rays' mean is within L·s/(2A) (each cell an edge crosses is off by at most half
/// its area; L the shadow edges' length, A the wall's area); the masks differ from the rays only
/// within 0.71 texel of an edge, adding at most L·(1.42·t)/A for texels of at most t metres on the
/// wall. Both are within 0.01 at 2.5 cm.
#[test]
fn fine_grid_means_converge_to_the_exact_fraction_on_both_engines() {
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(0.0, 4.0, 0.0, 3.0, 0.0), true);
    for k in 0..5 {
        let z = 0.3 + 0.55 * k as f64;
        s.cuboid(&format!("S{k}"), DVec3::new(-1.0, -0.45, z), DVec3::new(5.0, -0.05, z + 0.06));
    }
    let scene = s.build();
    let counter = counter(SIDE);
    for sun in [sun(195.0, 30.0), sun(145.0, 48.0), sun(185.0, 62.0)] {
        let truth = exact::sunlit_fraction(&scene, ViewRequest::new(0, sun));
        assert!(truth > 0.05 && truth < 0.95, "a partly shaded wall ({truth})");
        let mut last = (f64::INFINITY, f64::INFINITY);
        for spacing in [0.2, 0.1, 0.05, 0.025] {
            let points = grid(&scene, spacing, &all(&scene)).unwrap();
            let rays = lit(&scene, &points, sun, 1.0).unwrap();
            let gpu = gpu_answer(&counter, &scene, &points, sun);
            let mean_rays = rays.iter().map(|&v| f64::from(v)).sum::<f64>() / rays.len() as f64;
            let mean_gpu = gpu.lit.iter().filter(|&&l| l).count() as f64 / points.len() as f64;
            // The longest a texel reaches on the wall, over its two sides.
            let tile = gpu.tile[0].unwrap();
            let n = scene.receivers[0].normal;
            let texel = [DVec2::X, DVec2::Y].iter().map(|&px| on_plane(&tile, px, sun, n).length()).fold(0.0, f64::max);
            // Ten slat edges across the wall (4 m each) on 12 m².
            let (length, area) = (10.0 * 4.0, 12.0);
            let bound_rays = 0.5 * length * spacing / area;
            let bound_gpu = bound_rays + length * 1.42 * texel / area;
            let (e_rays, e_gpu) = ((mean_rays - truth).abs(), (mean_gpu - truth).abs());
            assert!(e_rays <= bound_rays, "spacing {spacing}: rays' mean {mean_rays} vs exact {truth} (bound {bound_rays})");
            assert!(e_gpu <= bound_gpu, "spacing {spacing}: masks' mean {mean_gpu} vs exact {truth} (bound {bound_gpu}, texel {texel} m)");
            last = (e_rays, e_gpu);
        }
        assert!(last.0 <= 0.01 && last.1 <= 0.01, "at 2.5 cm both means are within 0.01 of the exact fraction ({last:?})");
    }
}

/// The map's own sweep on the GPU (what `sunlit map --engine gpu` runs) against the rays over a
/// day: per point sun hours agree but for the instants a shadow edge passed within a texel, and
/// the receivers' total is within a step a point.
#[test]
fn a_days_sun_hours_on_the_gpu_match_the_rays() {
    use sunlit::map::{Period, Site};
    use sunlit::sun::location::Location;
    use sunlit::year::season::LeafCalendar;
    let scene = louvred();
    let points = grid(&scene, 0.1, &all(&scene)).unwrap();
    let location = Location::new(46.5, 11.35, 1.0).unwrap();
    let calendar = LeafCalendar::evergreen();
    let site = Site { location: &location, calendar: &calendar, weather: None, sky: None };
    let period = Period::day(80, 6 * 60, 18 * 60, 20).unwrap();
    let samples = period.samples();
    let mapper = Mapper::new(&scene, &points).unwrap();
    let counter = counter(SIDE);
    let gpu = MapGpu::new(&counter, &scene, &points).unwrap();
    let rays = mapper.accumulate(&samples, site, &mut |_, _| {}).unwrap();
    let masks = pollster::block_on(mapper.accumulate_gpu(&gpu, &samples, site, &mut |_, _| {})).unwrap();
    assert_eq!((rays.instants, rays.sun_up), (masks.instants, masks.sun_up));
    assert!(gpu.rendered() > 0, "the louvres shade the wall: views were rendered");
    let step = 20.0 / 60.0;
    let mut differ = 0;
    for (a, b) in rays.sun_hours.iter().zip(&masks.sun_hours) {
        // An edge passing within a texel flips a point at that instant only.
        assert!((a - b).abs() <= 2.0 * step + 1e-9, "{a} h by rays, {b} h by masks");
        differ += usize::from((a - b).abs() > 1e-9);
    }
    let (total_rays, total_masks): (f64, f64) = (rays.sun_hours.iter().sum(), masks.sun_hours.iter().sum());
    eprintln!("{} points: {differ} differ; totals {total_rays:.2} h (rays) and {total_masks:.2} h (masks)", points.len());
    assert!(total_rays > 0.0 && (total_rays - total_masks).abs() <= 0.01 * total_rays);
    assert!(differ * 10 < points.len(), "{differ} of {} points differ", points.len());
    // The studies' lit instants and one instant's visibility, on the GPU, against the rays.
    let series_rays = mapper.lit_series(&samples, site, 10.0, &mut |_, _| {});
    let series_gpu = pollster::block_on(mapper.lit_series_gpu(&gpu, &samples, site, 10.0, &mut |_, _| {})).unwrap();
    let (mut same, mut lit) = (0, 0);
    for i in 0..points.len() {
        for k in 0..samples.len() {
            same += usize::from(series_rays.lit(i, k) == series_gpu.lit(i, k));
            lit += usize::from(series_rays.lit(i, k));
        }
    }
    let all = points.len() * samples.len();
    assert!(lit > all / 50 && same * 100 >= all * 99, "{same} of {all} lit instants agree ({lit} lit by rays)");
    let sun = sunlit::sun::position::sun_direction(&location, sunlit::year::annual::shading_sun_day(80), 11.5);
    let at_rays = mapper.visibility(sun, 1.0);
    let at_gpu = pollster::block_on(mapper.visibility_gpu(&gpu, sun, 1.0)).unwrap();
    let differ = at_rays.iter().zip(&at_gpu).filter(|(a, b)| a != b).count();
    assert!(at_rays.contains(&0.0) && at_rays.contains(&1.0) && differ * 50 <= points.len(), "{differ} points differ at 11:30");
}

/// `sunlit map --engine gpu` on the example office: the summary's engine split says the GPU
/// answered, its per point sun hours are the rays' but within a few steps, and a bad `--engine`
/// or `--resolution` is refused by name with nothing written.
#[test]
fn cli_maps_on_the_gpu_and_refuses_bad_engine_options() {
    use std::path::PathBuf;
    use std::process::Command;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("sunlit-map-gpu-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let office = root.join("examples/office.glb");
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_sunlit"))
            .arg("map")
            .arg(&office)
            .args(["--grid", "0.5", "--location", "39.74,-105.18,-7", "--period", "06-21", "--step", "15"])
            .args(args)
            .env("XDG_RUNTIME_DIR", runtime_dir())
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let mut hours = Vec::new();
    for engine in ["exact", "gpu"] {
        let out = run(&["--engine", engine, "-o", &format!("{engine}.csv"), "--json"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let point_instants = summary["points"].as_u64().unwrap() * summary["instants"].as_u64().unwrap();
        let (rays, masks) = (summary["engine"]["exact_rays"].as_u64().unwrap(), summary["engine"]["gpu_masks"].as_u64().unwrap());
        assert_eq!(if engine == "gpu" { (0, point_instants) } else { (point_instants, 0) }, (rays, masks), "{summary}");
        let csv = std::fs::read_to_string(dir.join(format!("{engine}.csv"))).unwrap();
        hours.push(csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse::<f64>().unwrap()).collect::<Vec<_>>());
    }
    assert_eq!(hours[0].len(), hours[1].len());
    let differ = hours[0].iter().zip(&hours[1]).filter(|(a, b)| (*a - *b).abs() > 1e-9).count();
    let worst = hours[0].iter().zip(&hours[1]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(differ * 20 <= hours[0].len() && worst <= 1.0, "{differ} of {} points differ, by up to {worst} h", hours[0].len());
    for (args, says) in [(vec!["--engine", "fast"], "--engine"), (vec!["--engine", "gpu", "--resolution", "4"], "resolution")] {
        let mut all = args.clone();
        all.extend(["-o", "bad.csv"]);
        let out = run(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!dir.join("bad.csv").exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
