//! Maps: per point shadow rays held to analytic shadow lines (an overhang, a slot in a screen),
//! a fine grid's area mean held to the exact reference's sunlit fraction, sun hours held to the
//! day's length, points from CSV and the inputs that are refused.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use glam::DVec3;
use sunlit::count::{ViewRequest, exact};
use sunlit::map::study;
use sunlit::map::{Mapper, Period, Site, from_csv, grid, lit};
use sunlit::scene::{Scene, SceneBuilder, SourceMesh};
use sunlit::sun::location::Location;
use sunlit::sun::position::{daylight, sun_direction};
use sunlit::year::annual::shading_sun_day;
use sunlit::year::season::LeafCalendar;
use sunlit::{Error, Result};

fn quad(p: [[f64; 3]; 4]) -> SourceMesh {
    SourceMesh { positions: p.iter().map(|v| v.map(|x| x as f32)).collect(), indices: vec![0, 1, 2, 0, 2, 3] }
}

/// A south wall (receiver, facing −y) on y = 0, x in 0..4, z in 0..3.
fn wall() -> SourceMesh {
    quad([[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]])
}

fn scene(parts: Vec<(&str, SourceMesh, bool)>) -> Scene {
    let mut b = SceneBuilder::new();
    for (name, mesh, receiver) in parts {
        b.add_object("test", name, mesh, receiver);
    }
    b.build().unwrap()
}

fn all(scene: &Scene) -> Vec<u32> {
    (0..scene.receivers.len() as u32).collect()
}

/// Sun from the south-south-west/east, `altitude` degrees up, `off` degrees off the wall's normal.
fn sun(altitude: f64, off: f64) -> DVec3 {
    let (a, g) = (altitude.to_radians(), off.to_radians());
    DVec3::new(a.cos() * g.sin(), -a.cos() * g.cos(), a.sin())
}

/// An overhang of depth d at the wall's top (z = h = 3), much wider than the wall: a point at
/// height z is shaded iff z > h − d · tan(profile angle), tan(profile) = s_z / (−s_y).
#[test]
fn overhang_shadow_line_is_exact() {
    let d = 0.83;
    let overhang = quad([[-20., 0., 3.], [-20., -d, 3.], [24., -d, 3.], [24., 0., 3.]]);
    let s = scene(vec![("WALL", wall(), true), ("OVERHANG", overhang, false)]);
    let points = grid(&s, 0.1, &all(&s)).unwrap();
    assert_eq!(points.len(), 40 * 30);
    for (altitude, off) in [(20.0, 0.0), (35.0, 10.0), (50.0, -40.0), (62.0, 25.0)] {
        let sun = sun(altitude, off);
        let line = 3.0 - d * sun.z / -sun.y;
        let vis = lit(&s, &points, sun, 1.0).unwrap();
        let mut shaded = 0;
        for (i, v) in vis.iter().enumerate() {
            let z = points.position(i).z;
            let expect = if z > line { 0.0 } else { 1.0 };
            assert_eq!(*v, expect, "sun {altitude}°/{off}°: point at z {z} (shadow line {line})");
            shaded += usize::from(*v == 0.0);
        }
        assert!(shaded > 0 && shaded < points.len(), "the line crosses the wall at {line}");
    }
    // The sun behind the wall: nothing is lit.
    assert!(lit(&s, &points, DVec3::new(0.0, 0.6, 0.8), 1.0).unwrap().iter().all(|&v| v == 0.0));
}

/// A screen 1 m in front of the wall with a horizontal slot z in (1.2, 1.6): a point at height z
/// sees the sun iff the ray's height at the screen, z + tan(profile), falls in the slot.
#[test]
fn slot_in_a_screen_lets_one_band_through() {
    let below = quad([[-30., -1., -5.], [34., -1., -5.], [34., -1., 1.2], [-30., -1., 1.2]]);
    let above = quad([[-30., -1., 1.6], [34., -1., 1.6], [34., -1., 9.], [-30., -1., 9.]]);
    let s = scene(vec![("WALL", wall(), true), ("SCREEN_LOW", below, false), ("SCREEN_HIGH", above, false)]);
    let points = grid(&s, 0.05, &all(&s)).unwrap();
    for (altitude, off) in [(25.0, 0.0), (40.0, 30.0), (12.0, -20.0)] {
        let sun = sun(altitude, off);
        let rise = sun.z / -sun.y;
        let vis = lit(&s, &points, sun, 1.0).unwrap();
        let mut band = 0;
        for (i, v) in vis.iter().enumerate() {
            let z = points.position(i).z + rise;
            let expect = if z > 1.2 && z < 1.6 { 1.0 } else { 0.0 };
            assert_eq!(*v, expect, "sun {altitude}°/{off}°: point at z {} (ray at the screen {z})", points.position(i).z);
            band += usize::from(*v == 1.0);
        }
        assert!(band > 0, "some points see through the slot");
    }
}

/// Five horizontal slats (boxes) in front of the wall: the area mean of a grid converges to the
/// exact reference's fraction, within half the shadow edges' length × spacing / area (each cell
/// an edge crosses is off by at most half its area) and within 0.01 at 2.5 cm.
#[test]
fn fine_grid_mean_converges_to_the_exact_fraction() {
    let mut parts = vec![("WALL", wall(), true)];
    let names = ["S0", "S1", "S2", "S3", "S4"];
    for (k, name) in names.iter().enumerate() {
        let z = 0.3 + 0.55 * k as f64;
        parts.push((name, box_mesh(DVec3::new(-1.0, -0.45, z), DVec3::new(5.0, -0.05, z + 0.06)), false));
    }
    let s = scene(parts);
    for sun in [sun(30.0, 15.0), sun(48.0, -35.0), sun(62.0, 5.0)] {
        let truth = exact::sunlit_fraction(&s, ViewRequest::new(0, sun));
        assert!(truth > 0.05 && truth < 0.95, "a partly shaded wall ({truth})");
        let mut last = f64::INFINITY;
        for spacing in [0.2, 0.1, 0.05, 0.025] {
            let points = grid(&s, spacing, &all(&s)).unwrap();
            let vis = lit(&s, &points, sun, 1.0).unwrap();
            let mean = vis.iter().map(|&v| f64::from(v)).sum::<f64>() / vis.len() as f64;
            let error = (mean - truth).abs();
            // Ten slat edges at most 6 m long (lines across the wall: 4 m each) on 12 m².
            let bound = 0.5 * 10.0 * 4.0 * spacing / 12.0;
            assert!(error <= bound, "spacing {spacing}: mean {mean} vs exact {truth} (bound {bound})");
            last = error;
        }
        assert!(last <= 0.01, "at 2.5 cm the mean is within 0.01 of the exact fraction ({last})");
    }
}

fn box_mesh(lo: DVec3, hi: DVec3) -> SourceMesh {
    let c = |i: usize| [if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z }];
    let positions = (0..8).map(|i| c(i).map(|x| x as f32)).collect();
    #[rustfmt::skip]
    let indices = vec![
        0, 2, 1, 1, 2, 3, // z−
        4, 5, 6, 5, 7, 6, // z+
        0, 1, 4, 1, 5, 4, // y−
        2, 6, 3, 3, 6, 7, // y+
        0, 4, 2, 2, 4, 6, // x−
        1, 3, 5, 3, 7, 5, // x+
    ];
    SourceMesh { positions, indices }
}

/// A grid leaves a receiver's hole empty and puts every point on its receiver's plane.
#[test]
fn grid_leaves_holes_out() {
    // A 4 × 3 wall around a 2 × 1 window hole (x 1..3, z 1..2), as eight triangles.
    let p = [[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.], [1., 0., 1.], [3., 0., 1.], [3., 0., 2.], [1., 0., 2.]];
    let positions = p.iter().map(|v| v.map(|x| x as f32)).collect();
    let indices = vec![0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7];
    let s = scene(vec![("WALL", SourceMesh { positions, indices }, true)]);
    let points = grid(&s, 0.1, &all(&s)).unwrap();
    assert_eq!(points.len(), 40 * 30 - 20 * 10);
    for i in 0..points.len() {
        let q = points.position(i);
        assert!(q.y.abs() < 1e-6, "on the plane");
        assert!(!(q.x > 1.0 && q.x < 3.0 && q.z > 1.0 && q.z < 2.0), "{q} in the hole");
    }
}

/// An unobstructed roof's sun hours over a day are the day's length (the sun above the
/// geometric horizon, as the shading sun is), to a step.
#[test]
fn open_roof_sun_hours_are_the_day_length() {
    let roof = quad([[0., 0., 0.], [2., 0., 0.], [2., 2., 0.], [0., 2., 0.]]);
    let s = scene(vec![("ROOF", roof, true)]);
    let points = grid(&s, 0.5, &all(&s)).unwrap();
    let location = Location::new(51.5, -0.1, 0.0).unwrap();
    let calendar = LeafCalendar::evergreen();
    let site = Site { location: &location, calendar: &calendar, weather: None, sky: None };
    for day in [80, 172, 355] {
        let period = Period::day(day, 0, 24 * 60, 1).unwrap();
        let values = Mapper::new(&s, &points).unwrap().accumulate(&period.samples(), site, &mut |_, _| {}).unwrap();
        let (rise, set) = daylight(&location, shading_sun_day(day)).unwrap();
        for h in &values.sun_hours {
            assert!((h - (set - rise)).abs() <= 2.0 / 60.0, "day {day}: {h} h of sun, daylight {} h", set - rise);
        }
    }
}

/// A tall wall south of a yard on 21 March (London): the BRE rule's per point hours agree with
/// each point's own lit minutes, and points right behind the wall get none.
#[test]
#[allow(clippy::needless_range_loop)] // Points index several parallel arrays.
fn bre_ground_study_on_a_yard_behind_a_wall() {
    let yard = quad([[0., 0., 0.], [10., 0., 0.], [10., 10., 0.], [0., 10., 0.]]);
    let wall = box_mesh(DVec3::new(-30.0, -0.3, 0.0), DVec3::new(40.0, 0.0, 8.0));
    let s = scene(vec![("YARD", yard, true), ("WALL", wall, false)]);
    let points = grid(&s, 1.0, &all(&s)).unwrap();
    let location = Location::new(51.5, -0.1, 0.0).unwrap();
    let calendar = LeafCalendar::evergreen();
    let site = Site { location: &location, calendar: &calendar, weather: None, sky: None };
    let rule = study::preset("bre-ground").unwrap();
    let period = Period::day(rule.default_day, 0, 24 * 60, 2).unwrap();
    let samples = period.samples();
    let mapper = Mapper::new(&s, &points).unwrap();
    let series = mapper.lit_series(&samples, site, rule.min_altitude_deg, &mut |_, _| {});
    let result = study::evaluate(&rule, rule.default_day, &samples, &series, &points.receivers);
    // The equinox noon sun stands 38.5° up: 8 m of wall shades about 10 m behind it at noon,
    // so the first row (y = 0.5) gets next to no sun, the last (y = 9.5) hours of it.
    let by_instant_sun: Vec<DVec3> =
        samples.iter().map(|sample| sun_direction(&location, shading_sun_day(sample.day), sample.hour)).collect();
    let by_instant: Vec<Vec<f32>> = by_instant_sun.iter().map(|&sun| mapper.visibility(sun, 1.0)).collect();
    for i in 0..points.len() {
        let p = points.position(i);
        let mut by_hand = 0.0;
        for (k, sample) in samples.iter().enumerate() {
            let v = by_instant[k][i];
            assert_eq!(series.lit(i, k), v >= 0.5, "point {p} at {}", sample.hour);
            by_hand += if v >= 0.5 { sample.hours } else { 0.0 };
        }
        assert!((result.hours[i] - by_hand).abs() < 1e-9);
        if p.y < 1.0 {
            // Only the sun grazing past the wall's ends, or just north of east and west, at
            // sunrise or sunset reaches them: over the wall it would need to stand ~84° up. On
            // 21 March (declination ≈ +0.2° with the calendar day's sun) that is a few minutes
            // each side, always within 2° of the horizon.
            for (k, sample) in samples.iter().enumerate() {
                if series.lit(i, k) {
                    let altitude = by_instant_sun[k].z.asin().to_degrees();
                    assert!(altitude < 2.0, "{p} lit at {} h with the sun {altitude:.2}° up", sample.hour);
                }
            }
            assert!(result.hours[i] <= 0.25, "{p}: {} h", result.hours[i]);
        }
    }
    let area = &result.areas[0];
    let share = result.hours.iter().filter(|&&h| h >= 2.0).count() as f64 / points.len() as f64;
    assert_eq!(area.shares[0], share);
    assert_eq!(area.passes, share >= 0.5);
    assert!(share > 0.0 && share < 1.0, "part of the yard gets 2 h ({share})");
}

/// Points from CSV land on the receiver they lie on (the nearer face of a thin slab), and lit
/// agrees with the same points on a grid.
#[test]
fn csv_points_are_assigned_and_answered() {
    let front = quad([[0., 0., 0.], [4., 0., 0.], [4., 0., 3.], [0., 0., 3.]]);
    let back = quad([[0., 0.02, 0.], [0., 0.02, 3.], [4., 0.02, 3.], [4., 0.02, 0.]]);
    let s = scene(vec![("FRONT", front, true), ("BACK", back, true)]);
    let text = "x,y,z,nx,ny,nz\n1.0,0.004,1.5,0,-1,0\n2.0,0.02,1.0,0,2,0\n";
    let points = from_csv(&s, "p.csv", text, &all(&s)).unwrap();
    assert_eq!(points.receivers, vec![0, 1]);
    assert_eq!(points.normal(1), DVec3::Y);
    let vis = lit(&s, &points, sun(30.0, 0.0), 1.0).unwrap();
    assert_eq!(vis, vec![1.0, 0.0], "the front sees the southern sun, the back does not");
}

fn refused<T: std::fmt::Debug>(r: Result<T>, what: &str, says: &str) {
    match r {
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains(what) && text.contains(says), "'{text}' should name {what} and say {says}");
        }
        Ok(v) => panic!("accepted {v:?}; expected an error naming {what}"),
    }
}

#[test]
fn bad_input_is_refused_with_its_name() {
    let s = scene(vec![("WALL", wall(), true)]);
    let ids = all(&s);
    refused(grid(&s, 0.0, &ids), "spacing", "positive");
    refused(grid(&s, -1.0, &ids), "spacing", "positive");
    refused(grid(&s, f64::NAN, &ids), "spacing", "positive");
    refused(grid(&s, 1e-4, &ids), "spacing", "1200000000 points");
    refused(from_csv(&s, "p.csv", "x,y,z\n1,0,1\n", &ids), "p.csv", "header");
    refused(from_csv(&s, "p.csv", "x,y,z,nx,ny,nz\n1,0,1,0,-1,0\n1,0,1,0,0,0\n", &ids), "line 3", "zero length");
    refused(from_csv(&s, "p.csv", "x,y,z,nx,ny,nz\n1,0.5,1,0,-1,0\n", &ids), "line 2", "no chosen receiver");
    refused(from_csv(&s, "p.csv", "x,y,z,nx,ny,nz\n1,0,1,0,1,0\n", &ids), "line 2", "no chosen receiver");
    refused(from_csv(&s, "p.csv", "x,y,z,nx,ny,nz\n1,zero,1,0,-1,0\n", &ids), "line 2", "six finite numbers");
    refused(Period::day(80, 600, 540, 10), "from", "not before");
    refused(Period::day(80, 540, 600, 7), "step", "does not divide");
    refused(Period::day(80, 0, 1440, 0), "step", "1 to 60");
    refused(Period::days(100, 90, 1), "period", "first");
    refused(Period::days(1, 365, 7), "step", "EnergyPlus timestep");
    refused(sunlit::map::period::parse_date("period", "02-30"), "period", "exists");
    refused(sunlit::map::period::parse_clock("from", "25:00"), "from", "HH:MM");
    refused(study::preset("sunny"), "study", "not a study");
    refused(study::preset("en17037").unwrap().check_day(100), "study", "outside");
    assert!(matches!(grid(&s, 0.0, &ids), Err(Error::Argument { .. })));
}

/// The CLI on the example office: a points CSV with the contract's columns and a map glb that
/// Khronos's glTF-Validator passes; `--at` writes `lit`; a study writes its reports; refused input
/// names the flag and its value and writes nothing.
#[test]
fn cli_writes_points_glb_and_studies_and_refuses_bad_input() {
    use std::path::PathBuf;
    use std::process::Command;
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!("sunlit-maps-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let office = root.join("examples/office.glb");
    let run =
        |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_sunlit")).arg("map").arg(&office).args(args).current_dir(&dir).output().unwrap();

    let out =
        run(&["--grid", "0.5", "--location", "39.74,-105.18,-7", "--period", "06-21", "-o", "day.csv", "--glb-out", "day.glb", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let csv = std::fs::read_to_string(dir.join("day.csv")).unwrap();
    assert!(csv.starts_with("receiver,x,y,z,nx,ny,nz,sun_hours\n"), "{}", &csv[..60]);
    assert_eq!(csv.lines().count() - 1, summary["points"].as_u64().unwrap() as usize);
    assert_eq!(summary["instants"], 144);

    let validator = root.join("node_modules/gltf-validator");
    assert!(validator.exists(), "node_modules/gltf-validator is missing: run `npm ci` (scripts/setup.sh does)");
    let v = Command::new("node").arg(root.join("tests/gltf/validate.mjs")).arg(dir.join("day.glb")).output().unwrap();
    assert!(v.status.success(), "validate.mjs: {}", String::from_utf8_lossy(&v.stderr));
    let report: serde_json::Value = serde_json::from_slice(v.stdout.split(|&b| b == b'\n').next().unwrap()).unwrap();
    assert_eq!(report["errors"], 0, "gltf-validator: {report}");

    let out = run(&["--grid", "1", "--location", "39.74,-105.18,-7", "--at", "03-21", "12:00", "-o", "at.csv"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let at = std::fs::read_to_string(dir.join("at.csv")).unwrap();
    assert!(at.starts_with("receiver,x,y,z,nx,ny,nz,lit\n"));
    assert!(at.lines().skip(1).all(|l| l.ends_with(",0") || l.ends_with(",1")));

    let out = run(&["--grid", "1", "--location", "51.5,-0.1,0", "--study", "bre-ground", "-o", "study.csv"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("study.study-bre-ground.json")).unwrap()).unwrap();
    assert_eq!(report["rule"]["day"], "03-21");
    assert!(report["areas"].as_array().unwrap().iter().all(|a| a["passes"].is_boolean()));

    for (args, says) in [
        (vec!["--grid", "0", "--location", "0,0,0"], "--grid"),
        (vec!["--grid", "0.00001", "--location", "0,0,0"], "points"),
        (vec!["--location", "0,0,0", "--period", "02-30"], "--period"),
        (vec!["--location", "0,0,0", "--period", "03-01", "--from", "14:00", "--to", "10:00"], "--from"),
        (vec!["--location", "0,0,0", "--period", "03-01", "--step", "7"], "--step"),
        (vec!["--location", "0,0,0", "--study", "sunny"], "--study"),
        (vec!["--location", "0,0,0", "--study", "en17037", "--period", "annual"], "--study"),
        (vec!["--location", "0,0,0", "--study", "en17037", "--period", "06-21"], "--study"),
    ] {
        let mut all = args.clone();
        all.extend(["-o", "bad.csv"]);
        let out = run(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!dir.join("bad.csv").exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
