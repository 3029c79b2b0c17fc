//! GB 50180's 满窗 (whole window) rule along each window's own sill line, measured from its
//! geometry (`sunlit::map::planning::sill_lines`, `--window-width sill`), against analytic
//! truths: a rectangular window facing a long slab sees what the analytic canyon says, over its
//! whole sill; a window whose sill's east half is in a fin's shadow fails the whole-window rule
//! where its centre passes, each within a minute of the minutes a continuous sill sees the sun
//! (the slab's faces intersected with each minute's sun ray, in closed form). And the CLI:
//! the report's widths, before and after, and bad input refused naming the option, nothing
//! written.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::{TestScene, south_rect};

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use serde_json::Value;
use sunlit::map::Points;
use sunlit::map::planning::compare;
use sunlit::map::planning::gb50180::{self, Gb50180Rule, StandardDay};
use sunlit::map::planning::sill_lines::sill_lines;
use sunlit::map::planning::window_points::{WindowPoint, window_points};
use sunlit::scene::Scene;
use sunlit::sun::location::Location;

const BEIJING: (f64, f64, f64) = (39.9, 116.4, 8.0);

/// A box in front of a south wall: x from `x0` to `x1`, its front face `distance` m south of the
/// wall (y = −distance), `depth` deep (southwards), from the ground up to `height`. A fin
/// standing out of the wall is one at distance 0.
#[derive(Clone, Copy)]
struct Slab {
    x0: f64,
    x1: f64,
    distance: f64,
    depth: f64,
    height: f64,
}

impl Slab {
    /// Whether the ray from `p` (on the wall, y = 0) towards the sun `d` meets the box: the ray's
    /// stretch between the front and back faces' planes (d.y < 0) is a parameter interval, each of
    /// the box's other bounds (x between x0 and x1, z at most the height; z rises) another, and
    /// the ray meets the box where they overlap.
    fn blocks(&self, p: DVec3, d: DVec3) -> bool {
        if d.y >= 0.0 {
            return false;
        }
        let (mut lo, mut hi) = (self.distance / -d.y, (self.distance + self.depth) / -d.y);
        let mut keep = |a: f64, b: f64| {
            lo = lo.max(a);
            hi = hi.min(b);
        };
        if d.x.abs() < 1e-12 {
            if p.x < self.x0 || p.x > self.x1 {
                return false;
            }
        } else {
            let (a, b) = ((self.x0 - p.x) / d.x, (self.x1 - p.x) / d.x);
            keep(a.min(b), a.max(b));
        }
        if d.z > 0.0 {
            keep(f64::NEG_INFINITY, (self.height - p.z) / d.z);
        }
        lo <= hi
    }
}

/// Hours of the rule's minutes on `day` at Beijing at which every one of `xs` (on a south sill at
/// height `z`) sees the sun: in front of the wall, above the horizon, and no slab in the way.
fn truth_hours(day: StandardDay, slabs: &[Slab], xs: &[f64], z: f64) -> f64 {
    let lit = |d: DVec3| d.y < -1e-5 && d.z > 1e-5 && xs.iter().all(|&x| slabs.iter().all(|s| !s.blocks(DVec3::new(x, 0.0, z), d)));
    let minutes =
        gb50180::instants(day).iter().filter(|s| lit(gb50180::sun_at_true_solar_time(BEIJING.0, day.declination_deg(), s.hour))).count();
    minutes as f64 / 60.0
}

/// A continuous sill from `x0` to `x1`, as many points as a millimetre grid would need to see a
/// shadow edge (every 5 mm).
fn along(x0: f64, x1: f64) -> Vec<f64> {
    let n = ((x1 - x0) / 0.005).ceil() as usize;
    (0..=n).map(|k| x0 + (x1 - x0) * k as f64 / n as f64).collect()
}

/// A south wall with one window `WIN` (x in `x0..x1`, z in `z0..z1`) and the slabs.
fn scene(window: (f64, f64, f64, f64), slabs: &[Slab]) -> Scene {
    let (x0, x1, z0, z1) = window;
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(-20.0, 20.0, 0.0, 8.0, 0.0), false);
    s.polygon("WIN", &south_rect(x0, x1, z0, z1, 0.0), true);
    for (i, slab) in slabs.iter().enumerate() {
        s.cuboid(
            &format!("SLAB{i}"),
            DVec3::new(slab.x0, -slab.distance - slab.depth, 0.0),
            DVec3::new(slab.x1, -slab.distance, slab.height),
        );
    }
    s.build()
}

/// gb50180 at the window's sill point with its sill line measured from the geometry: (the point's
/// hours, the whole window's hours, the sill's width).
fn whole_window(scene: &Scene, day: StandardDay) -> (f64, f64, f64) {
    let win = common::receiver_id(scene, "WIN");
    let sills: Points = window_points(scene, &[win], WindowPoint::Sill).unwrap();
    let lines = sill_lines(scene, &sills, Some(WindowPoint::Sill), None).unwrap();
    let width = lines[0].width();
    let mut rule = Gb50180Rule::new(day);
    rule.sill_lines = Some(lines);
    let beijing = Location::new(BEIJING.0, BEIJING.1, BEIJING.2).unwrap();
    let got = gb50180::evaluate(scene, &sills, &beijing, &rule, &mut |_, _| {}).unwrap();
    (got.hours[0], got.whole_window_hours.unwrap()[0], width)
}

/// A rectangular window 2.4 m wide facing a long slab: its whole sill, measured from the window,
/// sees the sun exactly when the analytic canyon says (every sill point alike along an endless
/// slab), on both days, for three heights of the slab.
#[test]
fn a_sill_facing_a_long_slab_sees_the_analytic_canyon_along_its_whole_width() {
    let (sill_z, distance) = (0.9, 20.0);
    for day in [StandardDay::Dahan, StandardDay::Dongzhi] {
        let (from, to) = day.window();
        for k in [0.25f64, 0.4, 0.5] {
            let slab = Slab { x0: -1000.0, x1: 1000.0, distance, depth: 2.0, height: sill_z + k * distance };
            let scene = scene((-1.2, 1.2, sill_z, 2.4), &[slab]);
            let (point, whole, width) = whole_window(&scene, day);
            assert!((width - 2.4).abs() < 1e-5, "the sill is the window's bottom side: {width}");
            // The closed form: the sill sees the sun while |h| < h₀ (tests/planning.rs derives it).
            let (sp, cp) = BEIJING.0.to_radians().sin_cos();
            let (sd, cd) = day.declination_deg().to_radians().sin_cos();
            let h0 = (-sd * (sp + k * cp) / (cd * (cp - k * sp))).clamp(-1.0, 1.0).acos().to_degrees() / 15.0;
            let canyon = 2.0 * h0.min((to - from) / 2.0);
            assert!((whole - canyon).abs() <= 1.0 / 60.0, "{} k = {k}: {whole:.4} h vs the canyon's {canyon:.4} h", day.name());
            assert!((point - canyon).abs() <= 1.0 / 60.0, "{} k = {k}: the point {point:.4} h", day.name());
            let ray_truth = truth_hours(day, &[slab], &along(-1.2, 1.2), sill_z);
            assert!((ray_truth - canyon).abs() <= 1.0 / 60.0, "the truths agree: {ray_truth:.4} vs {canyon:.4}");
        }
    }
}

/// A window 3 m wide facing a long slab 20 m out (k = 0.55: the canyon leaves the sill 2.63 h
/// about noon), with a tall fin standing 3 m out of the wall 1.8 m east of the sill's middle: the
/// fin's morning shadow covers the sill's east half, not its middle. The centre keeps the
/// canyon's hours and passes 大寒日's 2 h; the whole sill sees the sun only while its east end
/// does (1.67 h) and fails the 满窗 rule. Both within a minute of the minutes the continuous sill
/// (and its middle) sees the sun.
#[test]
fn a_window_whose_sill_is_half_in_shadow_fails_the_whole_window_rule() {
    let sill_z = 0.9;
    let slab = Slab { x0: -1000.0, x1: 1000.0, distance: 20.0, depth: 2.0, height: sill_z + 0.55 * 20.0 };
    let fin = Slab { x0: 1.8, x1: 2.0, distance: 0.0, depth: 3.0, height: 1000.0 };
    let scene = scene((-1.5, 1.5, sill_z, 2.4), &[slab, fin]);
    let day = StandardDay::Dahan;
    let (point, whole, width) = whole_window(&scene, day);
    assert!((width - 3.0).abs() < 1e-5, "{width}");
    let point_truth = truth_hours(day, &[slab, fin], &[0.0], sill_z);
    let whole_truth = truth_hours(day, &[slab, fin], &along(-1.5, 1.5), sill_z);
    assert!((point - point_truth).abs() <= 1.0 / 60.0, "the centre: {point:.4} h vs {point_truth:.4} h");
    assert!((whole - whole_truth).abs() <= 1.0 / 60.0, "the whole sill: {whole:.4} h vs {whole_truth:.4} h");
    let required = Gb50180Rule::new(day).required_hours;
    assert!(compare::hours(point, required).passes, "the centre passes: {point:.3} h");
    assert!(!compare::hours(whole, required).passes, "the whole window fails: {whole:.3} h");
    assert!(whole < point - 0.75, "the east half loses over 45 min: {whole:.3} h vs {point:.3} h");
}

fn run_map(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).arg("map").args(args).current_dir(dir).output().unwrap()
}

/// An OBJ (z up) of named polygons, each a face of its corners.
fn obj(polygons: &[(&str, Vec<DVec3>)]) -> String {
    let mut text = String::new();
    let mut next = 1;
    for (name, corners) in polygons {
        text.push_str(&format!("o {name}\n"));
        for c in corners {
            text.push_str(&format!("v {} {} {}\n", c.x, c.y, c.z));
        }
        let face: Vec<String> = (next..next + corners.len()).map(|i| i.to_string()).collect();
        text.push_str(&format!("f {}\n", face.join(" ")));
        next += corners.len();
    }
    text
}

/// A fresh scratch directory.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sunlit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `--window-points sill --window-width sill` on a wall with a 1.5 m and a 3 m window, before and
/// after a proposed slab: the report states each window's measured width and how it was taken,
/// each window keeps its sill against the existing scene, and the whole window sees no more than
/// its point. Bad input is refused naming the option, and nothing is written: the sill line
/// without the windows' sills (given points, the centres), a width that is not positive or not a
/// number, both the sill and a widths file, and a window whose lowest point is a corner.
#[test]
fn cli_measures_each_windows_sill_and_refuses_bad_input() {
    let dir = fresh_dir("planning-sills");
    let wall = south_rect(-10.0, 10.0, 0.0, 6.0, 0.0);
    let windows = [("WIN_A", south_rect(-4.0, -2.5, 0.9, 2.4, 0.0)), ("WIN_B", south_rect(1.0, 4.0, 1.2, 2.4, 0.0))];
    let mut existing: Vec<(&str, Vec<DVec3>)> = vec![("WALL", wall)];
    existing.extend(windows.iter().cloned());
    std::fs::write(dir.join("existing.obj"), obj(&existing)).unwrap();
    // The proposal: a slab's face 8 m south, 6 m high, running east from x = 2.5 (behind half of
    // WIN_B's sill).
    let slab = vec![DVec3::new(2.5, -8.0, 0.0), DVec3::new(40.0, -8.0, 0.0), DVec3::new(40.0, -8.0, 6.0), DVec3::new(2.5, -8.0, 6.0)];
    std::fs::write(dir.join("proposal.obj"), obj(&[("SLAB", slab)])).unwrap();
    let options = ["--up", "z", "--receivers", "WIN_*", "--study", "gb50180", "--location", "39.9,116.4,8"];
    let run = |models: &[&str], extra: &[&str]| run_map(&dir, &[models, &options[..], extra].concat());
    let out = run(
        &["existing.obj", "proposal.obj"],
        &["--window-points", "sill", "--window-width", "sill", "--before", "existing.obj", "-o", "s.csv", "--json"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("s.study-gb50180.json")).unwrap()).unwrap();
    assert_eq!(report["rule"]["whole_window_widths_m"], serde_json::json!([1.5, 3.0]), "{}", report["rule"]);
    assert!(report["rule"]["whole_window_sill"].as_str().unwrap().contains("lowest edge"), "{}", report["rule"]);
    let points = report["points"].as_array().unwrap();
    for p in points {
        let (hours, whole) = (p["hours"].as_f64().unwrap(), p["hours_whole_window"].as_f64().unwrap());
        assert!(whole <= hours + 1e-9, "{p}");
        assert!(p["hours_whole_window_before"].as_f64().unwrap() >= whole - 1e-9, "the slab adds no sun: {p}");
    }
    let b = &points[1];
    assert!(b["hours_whole_window"].as_f64().unwrap() < b["hours"].as_f64().unwrap() - 0.5, "WIN_B's east half is behind the slab: {b}");

    std::fs::write(dir.join("widths.csv"), "receiver,width\nWIN_A,1.5\nWIN_B,3\n").unwrap();
    std::fs::write(dir.join("points.csv"), "x,y,z,nx,ny,nz\n-3.25,0,0.9,0,-1,0\n").unwrap();
    let diamond = vec![DVec3::new(6.0, 0.0, 1.0), DVec3::new(6.5, 0.0, 1.5), DVec3::new(6.0, 0.0, 2.0), DVec3::new(5.5, 0.0, 1.5)];
    std::fs::write(dir.join("diamond.obj"), obj(&[("WIN_D", diamond)])).unwrap();
    let pair = ["existing.obj", "proposal.obj"];
    for (models, args, says) in [
        (pair, vec!["--points", "points.csv", "--window-width", "sill"], "--window-width: 'sill' measures each window's own sill line"),
        (pair, vec!["--window-points", "centre", "--window-width", "sill"], "the windows' centres are not their sills"),
        (pair, vec!["--window-points", "sill", "--window-width", "0"], "--window-width: 0 m is not in (0, 20]"),
        (pair, vec!["--window-points", "sill", "--window-width=-1.5"], "--window-width: -1.5 m is not in (0, 20]"),
        (pair, vec!["--window-points", "sill", "--window-width", "wide"], "--window-width: 'wide' is neither a width"),
        (
            pair,
            vec!["--window-points", "sill", "--window-width", "sill", "--window-widths", "widths.csv"],
            "--window-widths: give each window's width or measure its sill",
        ),
        (["existing.obj", "diamond.obj"], vec!["--window-points", "sill", "--window-width", "sill"], "window 'WIN_D'"),
    ] {
        let mut all = args.clone();
        all.extend(["-o", "bad.csv", "--html", "bad.html"]);
        let out = run(&models, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        if models[1] == "diamond.obj" {
            assert!(err.contains("--window-width") && err.contains("no horizontal lowest edge"), "{err}");
        }
        assert!(!dir.join("bad.csv").exists() && !dir.join("bad.html").exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
