//! Window studies against independent truths: BRE 209's VSC against the closed form of a
//! vertical point facing an infinitely long obstruction and against Radiance's `rtrace -I`
//! (tests/planning/vsc_radiance.py), and the `cie-overcast` and `uniform` sky models against the
//! same Radiance; APSH/WPSH against a numpy ray caster
//! over the same EPW hours (tests/planning/apsh_truth.py, its own sun); GB 50180's sunlight
//! hours against the analytic canyon (a sill facing a long slab); true solar time against a
//! published equation-of-time table; the CLI's output contract, before/after and refusals.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::energyplus::energyplus;
use common::{TestScene, radiance_python, south_rect};

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;

use glam::DVec3;
use serde_json::Value;
use sunlit::map::planning::gb50180::{self, Gb50180Rule, StandardDay};
use sunlit::map::planning::{Windows, apsh, bre_lines, compare, vsc};
use sunlit::map::{Mapper, Points, Site, from_csv, point_sky_for};
use sunlit::scene::Scene;
use sunlit::sky::model::SkyModel;
use sunlit::sky::patches::SkyPatches;
use sunlit::sun::location::Location;
use sunlit::sun::weather::Weather;
use sunlit::year::season::LeafCalendar;

/// VSC (%) of a vertical point facing an infinitely long horizontal edge at elevation θ in its
/// normal's plane. Directions d = (sin a, cos a cos ψ, cos a sin ψ) (a across the normal's
/// vertical plane, ψ up from the normal within it), dΩ = cos a da dψ; the sky is seen for
/// ψ > θ. With L/Lz = (1 + 2 cos a sin ψ)/3 and cos incidence cos a cos ψ:
/// E = ∫θ^{π/2} cos ψ [∫cos²a da + 2 sin ψ ∫cos³a da]/3 dψ = [π/2 (1 − sin θ) + 4/3 cos²θ]/3,
/// over the horizontal 7π/9.
fn vsc_closed_form(theta: f64) -> f64 {
    let e = (PI / 2.0 * (1.0 - theta.sin()) + 4.0 / 3.0 * theta.cos().powi(2)) / 3.0;
    100.0 * e / (7.0 * PI / 9.0)
}

/// A south façade (receiver) x in −5..5, z in 0..6 at y = 0, and in front of it, `distance` m to
/// the south, a 2 km long slab rising `height` m above the ground.
fn canyon(distance: f64, height: Option<f64>) -> Scene {
    let mut s = TestScene::new();
    s.polygon("FACADE", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), true);
    if let Some(h) = height {
        s.cuboid("SLAB", DVec3::new(-1000.0, -distance - 2.0, 0.0), DVec3::new(1000.0, -distance, h));
    }
    s.build()
}

fn points(scene: &Scene, rows: &[[f64; 6]]) -> Points {
    let mut text = String::from("x,y,z,nx,ny,nz\n");
    for r in rows {
        text.push_str(&r.map(|v| v.to_string()).join(","));
        text.push('\n');
    }
    from_csv(scene, "test", &text, &(0..scene.receivers.len() as u32).collect::<Vec<_>>()).unwrap()
}

#[test]
fn vsc_matches_the_closed_form_of_a_long_obstruction() {
    assert!((vsc_closed_form(0.0) - 39.62).abs() < 0.01, "the closed form's unobstructed value is BRE's 39.6 %");
    let open = canyon(10.0, None);
    let v = vsc::vsc(&Windows::new(&open, &points(&open, &[[0.0, 0.0, 1.5, 0.0, -1.0, 0.0]])).unwrap(), &mut |_, _| {});
    assert!((v.vsc[0] - 39.6).abs() <= 0.2, "unobstructed VSC {}", v.vsc[0]);
    assert!((v.unobstructed[0] - v.vsc[0]).abs() < 1e-9);
    for theta_deg in [10.0f64, 25.0, 40.0, 60.0] {
        let distance = 10.0;
        let point_z = 1.5;
        let scene = canyon(distance, Some(point_z + distance * theta_deg.to_radians().tan()));
        // Three points along the façade: the same elevation, so the same VSC.
        let rows: Vec<[f64; 6]> = [-2.0, 0.0, 2.0].iter().map(|&x| [x, 0.0, point_z, 0.0, -1.0, 0.0]).collect();
        let v = vsc::vsc(&Windows::new(&scene, &points(&scene, &rows)).unwrap(), &mut |_, _| {});
        let truth = vsc_closed_form(theta_deg.to_radians());
        for (i, got) in v.vsc.iter().enumerate() {
            assert!((got - truth).abs() <= 0.5, "θ = {theta_deg}°, point {i}: VSC {got:.3} vs closed form {truth:.3}");
        }
    }
}

/// The boxes and façade points both Radiance tests below use: a long low slab and a tower off to
/// one side, south of a south façade.
const BOXES: [([f64; 3], [f64; 3]); 2] = [([-1000.0, -12.0, 0.0], [1000.0, -10.0, 6.0]), ([4.0, -30.0, 0.0], [14.0, -20.0, 25.0])];
const ROWS: [[f64; 6]; 3] = [[0.0, 0.0, 1.5, 0.0, -1.0, 0.0], [3.0, 0.0, 1.5, 0.0, -1.0, 0.0], [0.0, 0.0, 4.0, 0.0, -1.0, 0.0]];

fn boxes_scene() -> Scene {
    let mut s = TestScene::new();
    s.polygon("FACADE", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), true);
    for (k, (lo, hi)) in BOXES.iter().enumerate() {
        s.cuboid(&format!("BOX{k}"), DVec3::from_array(*lo), DVec3::from_array(*hi));
    }
    s.build()
}

/// Radiance's irradiance at [`ROWS`] over the unobstructed horizontal's, in %, under `sky`
/// (cie-overcast or uniform: tests/planning/vsc_radiance.py), and that horizontal.
fn radiance_ratios(sky: &str) -> (Vec<f64>, f64) {
    let dir = std::env::temp_dir().join(format!("sunlit-vsc-radiance-{sky}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("case.json");
    let boxes_json: Vec<Value> = BOXES.iter().map(|(lo, hi)| serde_json::json!([lo, hi])).collect();
    std::fs::write(&case, serde_json::json!({"points": ROWS, "boxes": boxes_json, "sky": sky}).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/planning/vsc_radiance.py");
    let run = Command::new(radiance_python()).arg(script).arg(&case).output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(run.status.success(), "vsc_radiance.py: {}", String::from_utf8_lossy(&run.stderr));
    let truth: Value = serde_json::from_slice(&run.stdout).unwrap();
    (truth["vsc"].as_array().unwrap().iter().map(|t| t.as_f64().unwrap()).collect(), truth["horizontal"].as_f64().unwrap())
}

/// Radiance's `rtrace -I` (tests/planning/vsc_radiance.py: black boxes, a glow of the CIE
/// overcast luminance above the horizon, 2^17 ambient divisions) on a long low slab and a tower
/// off to one side: each point's VSC within 0.5 points.
#[test]
fn vsc_matches_radiance_rtrace_on_boxes() {
    let scene = boxes_scene();
    let got = vsc::vsc(&Windows::new(&scene, &points(&scene, &ROWS)).unwrap(), &mut |_, _| {});
    let (truth, horizontal) = radiance_ratios("cie-overcast");
    assert!((horizontal - 7.0 * PI / 9.0).abs() < 0.01, "Radiance's horizontal is 7π/9: {horizontal}");
    for (i, t) in truth.iter().enumerate() {
        assert!((got.vsc[i] - t).abs() <= 0.5, "point {i}: VSC {:.3} vs Radiance {t:.3}", got.vsc[i]);
    }
}

/// The `cie-overcast` and `uniform` sky models as a map applies them (each point's visible
/// ∫cos dΩ per Tregenza patch, [`point_sky_for`], times the model's patch radiances for 1 W/m² of
/// diffuse horizontal) against Radiance's `rtrace -I` under the same luminance on the boxes: the
/// points' sky diffuse per unit DHI, in %, within 0.5 points, and an open roof's exactly 100 %.
#[test]
fn cie_overcast_and_uniform_sky_models_match_radiance_on_boxes() {
    let scene = boxes_scene();
    let pts = points(&scene, &ROWS);
    let mapper = Mapper::new(&scene, &pts).unwrap();
    let patches = SkyPatches::tregenza();
    for (model, sky) in [(SkyModel::CieOvercast, "cie-overcast"), (SkyModel::Uniform, "uniform")] {
        let views = point_sky_for(&mapper, &patches, model, &mut |_, _| {});
        let radiances = model.on(&patches).unwrap().radiances(0.0, 1.0, DVec3::Z, 1).unwrap();
        let open_roof: f64 = patches.patches.iter().zip(&radiances).map(|(p, r)| r * p.weight(DVec3::Z).weight).sum();
        assert!((open_roof - 1.0).abs() < 1e-9, "{sky}: an open roof gets {open_roof} of DHI");
        let (truth, _) = radiance_ratios(sky);
        for (i, t) in truth.iter().enumerate() {
            let got = 100.0 * views.distribution_diffuse(i, 1.0, &radiances);
            assert!((got - t).abs() <= 0.5, "{sky}, point {i}: {got:.3} % of DHI vs Radiance's {t:.3} %");
        }
    }
}

/// BRE 209's 25° line against the canyon's closed form: a long slab `distance` m out rising
/// `height` m subtends atan((height − z)/distance) in the section from a point at z (within 1e-4°:
/// the mesh holds f32 positions); the
/// pre-check passes at 25° and below. Geometry behind the wall or beside the section never counts.
#[test]
fn bre_25deg_line_is_the_canyons_elevation() {
    let south = DVec3::new(0.0, -1.0, 0.0);
    let open = canyon(10.0, None);
    let v = bre_lines::evaluate(&open, &[DVec3::new(0.0, 0.0, 1.5)], &[south]);
    assert_eq!(v.angle_deg, [0.0], "nothing in front");
    for (theta_deg, passes) in [(10.0f64, true), (24.9, true), (25.1, false), (40.0, false)] {
        let (distance, z) = (12.0, 1.5);
        let scene = canyon(distance, Some(z + distance * theta_deg.to_radians().tan()));
        let origins = [DVec3::new(-3.0, 0.0, z), DVec3::new(0.0, 0.0, z), DVec3::new(4.0, 0.0, z)];
        let v = bre_lines::evaluate(&scene, &origins, &[south; 3]);
        for (i, &got) in v.angle_deg.iter().enumerate() {
            assert!((got - theta_deg).abs() < 1e-4, "θ = {theta_deg}°, point {i}: {got}°");
            assert_eq!(compare::line_25(got).passes, passes, "θ = {theta_deg}°");
        }
        // The same slab behind a north-facing wall is not in front of it.
        let v = bre_lines::evaluate(&scene, &[DVec3::new(0.0, 0.0, z)], &[-south]);
        assert_eq!(v.angle_deg, [0.0], "behind the wall");
    }
}

/// BRE draws the 25° line to the new development only. A window under its own overhang (1 m
/// deep, 1.0–1.2 m above the point: where its top meets the wall, 1 mm out, it stands at
/// atan(1.2/0.001) = 89.95°) faces a proposed long slab at θ: against the existing scene (the façade
/// and its overhang) the angle is the slab's, θ, and the overhang's is `angle_deg_all`; without
/// it everything counts.
#[test]
fn bre_25deg_line_is_drawn_to_the_development_alone() {
    use sunlit::map::planning::run::{self, Rules};
    let (distance, z) = (12.0, 1.5);
    let overhang_deg = 1.2f64.atan2(bre_lines::FRONT).to_degrees();
    let building = |slab: Option<f64>| {
        let mut s = TestScene::new();
        s.polygon("FACADE", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), true);
        s.cuboid("OVERHANG", DVec3::new(-2.0, -1.0, z + 1.0), DVec3::new(2.0, 0.0, z + 1.2));
        if let Some(h) = slab {
            s.cuboid("SLAB", DVec3::new(-1000.0, -distance - 2.0, 0.0), DVec3::new(1000.0, -distance, h));
        }
        s.build()
    };
    let existing = building(None);
    let studies = ["bre-25deg".to_string()];
    for (theta_deg, passes) in [(20.0f64, true), (24.9, true), (25.1, false), (30.0, false)] {
        let proposed = building(Some(z + distance * theta_deg.to_radians().tan()));
        let pts = points(&proposed, &[[0.0, 0.0, z, 0.0, -1.0, 0.0], [1.0, 0.0, z, 0.0, -1.0, 0.0]]);
        let rules = Rules::default();
        let (now, _) =
            run::before_after(&studies, &proposed, &pts, Some((&existing, "test")), None, rules, &mut |_| {}, &mut |_| {}).unwrap();
        let lines = now.lines.unwrap();
        let development = lines.development_deg.unwrap();
        assert_eq!(development.len(), 2);
        for (i, (&angle, &all)) in development.iter().zip(&lines.angle_deg).enumerate() {
            assert!((angle - theta_deg).abs() < 1e-4, "θ = {theta_deg}°, point {i}: {angle}°");
            assert!((all - overhang_deg).abs() < 1e-4, "everything: {all}°");
            assert_eq!(compare::line_25(angle).passes, passes, "θ = {theta_deg}°");
        }
        // Without the existing scene the overhang stands in the section and fails every window.
        let (alone, _) = run::before_after(&studies, &proposed, &pts, None, None, rules, &mut |_| {}, &mut |_| {}).unwrap();
        let alone = alone.lines.unwrap();
        assert!(alone.development_deg.is_none() && (alone.angle_deg[0] - overhang_deg).abs() < 1e-4);
    }
    // The existing scene loaded apart (its own centre, so its f32 corners round differently) still
    // holds every triangle of the building: the development is the slab's 12 triangles.
    let proposed = building(Some(8.0));
    assert_eq!(sunlit::map::planning::bre_lines::development(&proposed, &existing).len(), 12);
}

/// BRE 209's 45° lines against their plan and elevation construction: a block standing on the
/// wall beside the window, `offset` m from the window's centre to its near side, `depth` m out
/// and `top` m above the centre, is within both lines exactly when offset ≤ depth (plan) and
/// offset ≤ top (elevation).
#[test]
fn bre_45deg_lines_follow_plan_and_elevation() {
    let south = DVec3::new(0.0, -1.0, 0.0);
    let z = 1.5;
    for (offset, depth, top, within) in
        [(2.0, 3.0, 3.0, true), (2.0, 1.9, 3.0, false), (2.0, 3.0, 1.9, false), (4.0, 6.0, 4.5, true), (4.0, 3.5, 4.5, false)]
    {
        for side in [1.0, -1.0] {
            let mut s = TestScene::new();
            s.polygon("FACADE", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), true);
            let (x0, x1) = if side > 0.0 { (offset, offset + 3.0) } else { (-offset - 3.0, -offset) };
            s.cuboid("EXTENSION", DVec3::new(x0, -depth, 0.0), DVec3::new(x1, 0.0, z + top));
            let scene = s.build();
            let v = bre_lines::evaluate(&scene, &[DVec3::new(0.0, 0.0, z)], &[south]);
            assert_eq!(v.within_45, [within], "offset {offset}, depth {depth}, top {top}, side {side}");
            assert_eq!(compare::line_45(within).passes, !within);
        }
    }
}

/// The shadow rays ([`Windows::new`] on an opaque scene) against the exact engine's shadows
/// ([`Windows::by_shadows`]) on a street of boxes, slats and tilted plates seen from two walls'
/// windows: every VSC within 0.05 points (directions only on a shadow's edge may differ).
#[test]
fn shadow_rays_answer_as_the_exact_engines_shadows() {
    let mut s = TestScene::new();
    s.polygon("SOUTH", &south_rect(0.0, 20.0, 0.0, 15.0, 0.0), true);
    let east = [DVec3::new(22.0, -12.0, 0.0), DVec3::new(22.0, -2.0, 0.0), DVec3::new(22.0, -2.0, 12.0), DVec3::new(22.0, -12.0, 12.0)];
    s.polygon("EAST", &east, true);
    s.cuboid("BLOCK", DVec3::new(-10.0, -22.0, 0.0), DVec3::new(8.0, -12.0, 12.0));
    s.cuboid("TOWER", DVec3::new(30.0, -15.0, 0.0), DVec3::new(36.0, -9.0, 40.0));
    for k in 0..12 {
        let z = 2.0 + 1.1 * f64::from(k);
        s.cuboid(&format!("SLAT{k}"), DVec3::new(9.0, -1.2, z), DVec3::new(19.0, -0.6, z + 0.08));
    }
    let plate = [DVec3::new(12.0, -9.0, 3.0), DVec3::new(20.0, -9.0, 3.0), DVec3::new(20.0, -5.0, 9.0), DVec3::new(12.0, -5.0, 9.0)];
    s.polygon("PLATE", &plate, false);
    let scene = s.build();
    let rows = [
        [2.0, 0.0, 1.5, 0.0, -1.0, 0.0],
        [10.0, 0.0, 4.5, 0.0, -1.0, 0.0],
        [14.0, 0.0, 7.3, 0.0, -1.0, 0.0],
        [18.0, 0.0, 13.0, 0.0, -1.0, 0.0],
        [22.0, -4.0, 2.0, 1.0, 0.0, 0.0],
        [22.0, -10.0, 9.0, 1.0, 0.0, 0.0],
    ];
    let pts = points(&scene, &rows);
    let rays = Windows::new(&scene, &pts).unwrap();
    assert!(rays.by_rays(), "an opaque scene is answered by rays");
    let shadows = Windows::by_shadows(&scene, &pts).unwrap();
    let (a, b) = (vsc::vsc(&rays, &mut |_, _| {}), vsc::vsc(&shadows, &mut |_, _| {}));
    for i in 0..rows.len() {
        assert!((a.vsc[i] - b.vsc[i]).abs() <= 0.05, "point {i}: rays {:.4} vs shadows {:.4}", a.vsc[i], b.vsc[i]);
    }
    assert!(a.vsc.iter().zip(&a.unobstructed).any(|(v, u)| u - v > 5.0), "the casters take sky: {:?}", a.vsc);
}

fn golden_epw() -> PathBuf {
    let epw = energyplus().parent().unwrap().join("WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw");
    assert!(epw.exists(), "{} missing from the EnergyPlus wheel", epw.display());
    epw
}

#[test]
fn apsh_matches_a_numpy_ray_caster_on_the_same_epw_hours() {
    let boxes = [([-10.0, -22.0, 0.0], [8.0, -12.0, 12.0]), ([15.0, -8.0, 0.0], [40.0, -5.0, 6.0])];
    let mut s = TestScene::new();
    s.polygon("SOUTH", &south_rect(0.0, 20.0, 0.0, 15.0, 0.0), true);
    let north = [DVec3::new(20.0, 10.0, 0.0), DVec3::new(0.0, 10.0, 0.0), DVec3::new(0.0, 10.0, 15.0), DVec3::new(20.0, 10.0, 15.0)];
    s.polygon("NORTH", &north, true);
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        s.cuboid(&format!("BLOCK{k}"), DVec3::from_array(*lo), DVec3::from_array(*hi));
    }
    let scene = s.build();
    let rows = [
        [2.0, 0.0, 1.5, 0.0, -1.0, 0.0],
        [6.0, 0.0, 1.5, 0.0, -1.0, 0.0],
        [10.0, 0.0, 4.5, 0.0, -1.0, 0.0],
        [14.0, 0.0, 1.5, 0.0, -1.0, 0.0],
        [18.0, 0.0, 10.5, 0.0, -1.0, 0.0],
        [10.0, 10.0, 1.5, 0.0, 1.0, 0.0],
    ];
    let pts = points(&scene, &rows);
    let epw = golden_epw();
    let weather = Weather::from_epw(&epw).unwrap();
    let calendar = LeafCalendar::for_latitude(weather.location.latitude);
    let site = Site { location: &weather.location, calendar: &calendar, weather: Some(&weather), sky: None };
    let got = apsh::apsh(&Windows::new(&scene, &pts).unwrap(), site, &mut |_, _| {}).unwrap();

    let dir = std::env::temp_dir().join(format!("sunlit-apsh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join("case.json");
    let boxes_json: Vec<Value> = boxes.iter().map(|(lo, hi)| serde_json::json!([lo, hi])).collect();
    std::fs::write(&case, serde_json::json!({"points": rows, "boxes": boxes_json}).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/planning/apsh_truth.py");
    let run = Command::new(radiance_python()).arg(script).arg(&epw).arg(&case).output().unwrap();
    assert!(run.status.success(), "apsh_truth.py: {}", String::from_utf8_lossy(&run.stderr));
    let truth: Value = serde_json::from_slice(&run.stdout).unwrap();
    let _ = std::fs::remove_dir_all(&dir);

    let hours = truth["annual_hours"].as_f64().unwrap();
    assert!((got.annual_hours - hours).abs() <= 0.01 * hours, "probable hours {} vs numpy's {hours}", got.annual_hours);
    for (i, t) in truth["points"].as_array().unwrap().iter().enumerate() {
        let (a, w) = (t["apsh"].as_f64().unwrap(), t["wpsh"].as_f64().unwrap());
        assert!((got.apsh[i] - a).abs() <= 1.0, "point {i}: APSH {:.2} vs numpy {a:.2}", got.apsh[i]);
        assert!((got.wpsh[i] - w).abs() <= 1.0, "point {i}: WPSH {:.2} vs numpy {w:.2}", got.wpsh[i]);
    }
    // The case can fail: the blocks take a real share of some windows' sun.
    let south: Vec<f64> = got.apsh[..5].to_vec();
    let (lo, hi) = south.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    assert!(hi - lo > 10.0, "the blocks shade some points: {south:?}");
    assert_eq!(got.assessed, vec![true, true, true, true, true, false], "only windows within 90° of due south are assessed");
}

/// A sill facing south at latitude φ, a slab `distance` m away rising `k · distance` above the
/// sill: the sill sees the sun when its profile angle clears the slab, U > k·(−N) with the sun
/// U = sin φ sin δ + cos φ cos δ cos h, N = cos φ sin δ − sin φ cos δ cos h, i.e.
/// cos h · cos δ (cos φ − k sin φ) > −sin δ (sin φ + k cos φ): |h| < h₀. Hours: the part of the
/// window (|h| ≤ 15° · half-width) inside ±h₀.
fn canyon_hours(latitude: f64, declination: f64, k: f64, half_window_hours: f64) -> f64 {
    let (sp, cp) = latitude.to_radians().sin_cos();
    let (sd, cd) = declination.to_radians().sin_cos();
    let ratio = -sd * (sp + k * cp) / (cd * (cp - k * sp));
    let h0 = ratio.clamp(-1.0, 1.0).acos().to_degrees() / 15.0;
    2.0 * h0.min(half_window_hours)
}

#[test]
fn gb50180_matches_the_analytic_canyon_within_a_minute() {
    let beijing = Location::new(39.9, 116.4, 8.0).unwrap();
    for day in [StandardDay::Dahan, StandardDay::Dongzhi] {
        let (from, to) = day.window();
        for k in [0.25f64, 0.4, 0.5] {
            let distance = 20.0;
            let sill = 0.9;
            let scene = canyon(distance, Some(sill + k * distance));
            let pts = points(&scene, &[[0.0, 0.0, sill, 0.0, -1.0, 0.0], [3.0, 0.0, sill, 0.0, -1.0, 0.0]]);
            let mut rule = Gb50180Rule::new(day);
            rule.whole_window = Some(1.5);
            let got = gb50180::evaluate(&scene, &pts, &beijing, &rule, &mut |_, _| {}).unwrap();
            let truth = canyon_hours(beijing.latitude, day.declination_deg(), k, (to - from) / 2.0);
            for (i, h) in got.hours.iter().enumerate() {
                assert!((h - truth).abs() <= 1.0 / 60.0, "{} k = {k}, point {i}: {h:.4} h vs {truth:.4} h", day.name());
            }
            // Along an infinitely long slab the whole sill sees what its centre sees.
            assert_eq!(got.whole_window_hours.as_ref().unwrap(), &got.hours);
        }
    }
    assert!((StandardDay::Dongzhi.declination_deg() + 23.44).abs() < 1e-9);
    assert!((StandardDay::Dahan.declination_deg() + 20.15).abs() < 0.01, "{}", StandardDay::Dahan.declination_deg());
    assert!(StandardDay::parse("06-21").unwrap_err().to_string().contains("day"));
}

/// EN 17037's sunlight exposure at a south window facing the canyon's slab (height over distance
/// `k`), in the day's declination δ: the sun reaches the window while it is in front of the wall
/// (cos h > tan δ / tan φ), above the slab (as [`canyon_hours`]) and at or above the minimum
/// altitude a (sin φ sin δ + cos φ cos δ cos h ≥ sin a); each bound is |h| below an angle, so the
/// hours are 2 acos(the largest cosine)/15. The whole day counts (no window in time).
fn en17037_canyon_hours(latitude: f64, declination: f64, k: f64, min_altitude: f64) -> f64 {
    let (sp, cp) = latitude.to_radians().sin_cos();
    let (sd, cd) = declination.to_radians().sin_cos();
    let slab = -sd * (sp + k * cp) / (cd * (cp - k * sp));
    let altitude = (min_altitude.to_radians().sin() - sp * sd) / (cp * cd);
    let front = (sd / cd) * (cp / sp);
    let bound = slab.max(altitude).max(front);
    if bound >= 1.0 { 0.0 } else { 2.0 * bound.max(-1.0).acos().to_degrees() / 15.0 }
}

/// EN 17037 as a window study against the analytic canyon within a minute, at London on 1
/// February, 1 March and 21 March, with the default minimum altitude (10°) and two others; the
/// slab decides some cases and the altitude others, and both are seen to (the bounds differ by
/// more than a minute between the cases). The declination is sunlit's own for the day (the sun
/// model is held to EnergyPlus elsewhere); the geometry and the counting are what is checked.
#[test]
fn en17037_matches_the_analytic_canyon_within_a_minute() {
    use sunlit::map::planning::en17037::{self, En17037Rule};
    let london = Location::new(51.5, -0.12, 0.0).unwrap();
    let calendar = LeafCalendar::for_latitude(london.latitude);
    let site = Site { location: &london, calendar: &calendar, weather: None, sky: None };
    let (distance, z) = (20.0, 1.5);
    let mut decided_by = (0, 0);
    for k in [0.1f64, 0.3, 0.5] {
        let scene = canyon(distance, Some(z + k * distance));
        let pts = points(&scene, &[[0.0, 0.0, z, 0.0, -1.0, 0.0], [-4.0, 0.0, z, 0.0, -1.0, 0.0]]);
        let windows = Windows::new(&scene, &pts).unwrap();
        for (day, min_altitude) in [(32u32, 10.0f64), (60, 10.0), (80, 10.0), (80, 5.0), (60, 15.0)] {
            let rule = En17037Rule::new(Some(day), Some(min_altitude)).unwrap();
            let got = en17037::evaluate(&windows, site, &rule, &mut |_, _| {}).unwrap();
            let (sin_declination, _) = sunlit::sun::position::declination_and_equation_of_time(f64::from(day));
            let declination = sin_declination.asin().to_degrees();
            let truth = en17037_canyon_hours(london.latitude, declination, k, min_altitude);
            let no_slab = en17037_canyon_hours(london.latitude, declination, 0.0, min_altitude);
            if truth < no_slab - 2.0 / 60.0 {
                decided_by.0 += 1
            } else {
                decided_by.1 += 1
            }
            for (i, h) in got.hours.iter().enumerate() {
                assert!((h - truth).abs() <= 1.0 / 60.0, "day {day}, k = {k}, {min_altitude}°, point {i}: {h:.4} h vs {truth:.4} h");
            }
        }
    }
    assert!(decided_by.0 >= 3 && decided_by.1 >= 3, "slab-decided and altitude-decided cases: {decided_by:?}");
    assert!(En17037Rule::new(Some(81), None).unwrap_err().to_string().contains("period"));
    assert!(En17037Rule::new(None, Some(-1.0)).unwrap_err().to_string().contains("min_altitude"));
}

/// GB 50180 counts at the ground-floor window sill: given a window (not a point), the study finds
/// its sill, the middle of its lowest edge. A south window 0.9..2.4 m up in a wall faces a long
/// garden wall 20 m away, 12.3 m high, whose shadow on 大寒日 at Beijing covers the sill for all
/// but 1.29 h of the analytic canyon (k = 11.4/20) and the window's centre for less (k =
/// 10.65/20, 3.35 h): the window fails at its sill and would pass at its centre.
#[test]
fn gb50180_finds_the_sill_of_a_window_and_fails_there() {
    use sunlit::map::planning::window_points::{OFFSET, WindowPoint, window_points};
    let (distance, height, sill_z, centre_z) = (20.0, 12.3, 0.9, 1.65);
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), false);
    s.polygon("WIN", &south_rect(-0.75, 0.75, sill_z, 2.4, 0.0), true);
    s.cuboid("GARDEN_WALL", DVec3::new(-1000.0, -distance - 2.0, 0.0), DVec3::new(1000.0, -distance, height));
    let scene = s.build();
    let win = common::receiver_id(&scene, "WIN");
    let sill = window_points(&scene, &[win], WindowPoint::Sill).unwrap();
    let centre = window_points(&scene, &[win], WindowPoint::Centre).unwrap();
    assert!((sill.position(0) - DVec3::new(0.0, -OFFSET, sill_z)).length() < 1e-5, "the sill: {}", sill.position(0));
    assert!((centre.position(0) - DVec3::new(0.0, -OFFSET, centre_z)).length() < 1e-5, "the centre: {}", centre.position(0));
    let beijing = Location::new(39.9, 116.4, 8.0).unwrap();
    let day = StandardDay::Dahan;
    let rule = Gb50180Rule::new(day);
    let half = (day.window().1 - day.window().0) / 2.0;
    let at = |points: &Points, z: f64| {
        let got = gb50180::evaluate(&scene, points, &beijing, &rule, &mut |_, _| {}).unwrap().hours[0];
        let truth = canyon_hours(beijing.latitude, day.declination_deg(), (height - z) / distance, half);
        assert!((got - truth).abs() <= 1.0 / 60.0, "at z = {z}: {got:.4} h vs the canyon's {truth:.4} h");
        (got, compare::hours(got, rule.required_hours).passes)
    };
    let (sill_hours, sill_passes) = at(&sill, sill_z);
    let (centre_hours, centre_passes) = at(&centre, centre_z);
    assert!(sill_hours < 1.5 && !sill_passes, "the sill is shaded: {sill_hours:.3} h");
    assert!(centre_hours > 3.0 && centre_passes, "the centre is not: {centre_hours:.3} h");
}

/// A window reaching the floor (落地窗, 0..2.4 m, the ground floor at 0) is counted by GB 50180
/// 0.9 m above the floor: with `floor_sills` its point is there, and its hours are the analytic
/// canyon's at 0.9 m (k = 11.4/20, 1.29 h) within a minute, where its lowest edge (k = 12.3/20)
/// would see less.
#[test]
fn gb50180_counts_a_window_reaching_the_floor_at_0_9_m() {
    use sunlit::map::planning::window_points::{OFFSET, SILL_HEIGHT, WindowPoint, floor_sills, window_points};
    let (distance, height) = (20.0, 12.3);
    let mut s = TestScene::new();
    s.polygon("WALL", &south_rect(-5.0, 5.0, 0.0, 6.0, 0.0), false);
    s.polygon("WIN", &south_rect(-0.75, 0.75, 0.0, 2.4, 0.0), true);
    s.cuboid("GARDEN_WALL", DVec3::new(-1000.0, -distance - 2.0, 0.0), DVec3::new(1000.0, -distance, height));
    let scene = s.build();
    let win = common::receiver_id(&scene, "WIN");
    let raised = floor_sills(&scene, &[win], 0.0).unwrap();
    assert!((raised.position(0) - DVec3::new(0.0, -OFFSET, SILL_HEIGHT)).length() < 1e-5, "{}", raised.position(0));
    let lowest = window_points(&scene, &[win], WindowPoint::Sill).unwrap();
    let beijing = Location::new(39.9, 116.4, 8.0).unwrap();
    let day = StandardDay::Dahan;
    let rule = Gb50180Rule::new(day);
    let half = (day.window().1 - day.window().0) / 2.0;
    let hours = |points: &Points| gb50180::evaluate(&scene, points, &beijing, &rule, &mut |_, _| {}).unwrap().hours[0];
    let canyon = |z: f64| canyon_hours(beijing.latitude, day.declination_deg(), (height - z) / distance, half);
    let (at_sill, at_floor) = (hours(&raised), hours(&lowest));
    assert!((at_sill - canyon(SILL_HEIGHT)).abs() <= 1.0 / 60.0, "{at_sill:.4} h vs the canyon's {:.4} h", canyon(SILL_HEIGHT));
    assert!((at_floor - canyon(0.0)).abs() <= 1.0 / 60.0 && at_floor < at_sill - 0.1, "the floor sees less: {at_floor:.4} h");
}

/// 满窗 with each window's own width: a south window's sill beside a tall fin standing out of the
/// wall `depth` m, `gap` m east of the sill's centre. A sill point x m east of the centre sees the
/// sun (d, in front of the wall) unless the ray meets the fin's face, x = gap, within its depth:
/// d.x > 0 and (gap − x)·|d.y|/d.x ≤ depth. The sample nearest the fin is the last lit, so the whole
/// sill of width w is lit exactly when its east end (x = w/2) is: the truth, counted over the
/// rule's minutes. Two windows, 1.2 m and 3 m wide, each read its own width from a CSV.
#[test]
fn gb50180_whole_window_takes_each_windows_own_width() {
    use sunlit::map::planning::sill_widths::sill_widths;
    use sunlit::map::planning::window_points::{WindowPoint, window_points};
    let (gap, depth, sill_z) = (2.0, 3.0, 0.9);
    let windows = [("WIN_A", 0.0, 1.2), ("WIN_B", 100.0, 3.0)];
    let mut s = TestScene::new();
    for (name, x, width) in windows {
        s.polygon(name, &south_rect(x - width / 2.0, x + width / 2.0, sill_z, 2.4, 0.0), true);
        s.cuboid(&format!("FIN_{name}"), DVec3::new(x + gap, -depth, 0.0), DVec3::new(x + gap + 0.2, 0.0, 1000.0));
    }
    let scene = s.build();
    let ids: Vec<u32> = windows.iter().map(|(name, ..)| common::receiver_id(&scene, name)).collect();
    let sills = window_points(&scene, &ids, WindowPoint::Sill).unwrap();
    let csv = "receiver,width\nWIN_B,3.0\nWIN_A,1.2\n";
    let widths = sill_widths(&scene, &sills, "widths.csv", csv).unwrap();
    assert_eq!(widths, vec![1.2, 3.0], "by each point's window, in the points' order");
    let beijing = Location::new(39.9, 116.4, 8.0).unwrap();
    let day = StandardDay::Dahan;
    let mut rule = Gb50180Rule::new(day);
    rule.window_widths = Some(widths);
    let got = gb50180::evaluate(&scene, &sills, &beijing, &rule, &mut |_, _| {}).unwrap();
    let whole = got.whole_window_hours.unwrap();
    let lit_minutes = |x: f64| {
        let instants = gb50180::instants(day);
        let lit = |d: DVec3| {
            let in_front = -d.y > 1e-5 && d.z >= 1e-5;
            in_front && !(d.x > 0.0 && (gap - x) * -d.y / d.x <= depth && sill_z + d.z * (gap - x) / d.x <= 1000.0)
        };
        instants.iter().filter(|s| lit(gb50180::sun_at_true_solar_time(39.9, day.declination_deg(), s.hour))).count() as f64 / 60.0
    };
    for (i, (name, _, width)) in windows.iter().enumerate() {
        let truth = lit_minutes(width / 2.0);
        assert!((whole[i] - truth).abs() <= 1.0 / 60.0, "{name} ({width} m): {:.4} h vs {truth:.4} h", whole[i]);
        assert!((got.hours[i] - lit_minutes(0.0)).abs() <= 1.0 / 60.0, "{name}'s centre: {:.4} h", got.hours[i]);
    }
    assert!(whole[1] < whole[0] - 0.25, "the wider sill reaches nearer the fin and sees less: {whole:?}");

    // Bad widths files are refused naming the file, the line and the reason.
    let refused = |text: &str| sill_widths(&scene, &sills, "widths.csv", text).unwrap_err().to_string();
    for (text, says) in [
        ("window,width\nWIN_A,1\n", "expected 'receiver,width'"),
        ("receiver,width\nWIN_A,1\nWIN_B,wide\n", "line 3"),
        ("receiver,width\nWIN_A,0\nWIN_B,1\n", "line 2"),
        ("receiver,width\nWIN_A,1\nWIN_B,1,2\n", "line 3"),
        ("receiver,width\nWIN_A,1\nWIN_C,1\n", "'WIN_C' is not one of the model's chosen receivers"),
        ("receiver,width\nWIN_A,1\nWIN_A,2\n", "given a width twice"),
        ("receiver,width\nWIN_A,1\n", "no row gives the width of window 'WIN_B'"),
    ] {
        let error = refused(text);
        assert!(error.contains("widths.csv") && error.contains(says), "{text:?}: {error}");
    }
}

/// True solar time = standard time + EoT + (longitude − 15° · zone)/15, with EoT from the
/// equation-of-time table of K. Krisciunas (Texas A&M, "Equation of time", values by day of a
/// non-leap year from Meeus's approximate formula, stated within 30 s):
/// faculty.physics.tamu.edu/krisciunas/equation_of_time.html.
#[test]
fn true_solar_time_follows_a_published_equation_of_time_table() {
    let table = [(1u32, -3.6069), (20, -10.9144), (32, -13.6686), (44, -14.5996), (60, -13.0538), (80, -7.8437), (92, -4.0191)];
    let site = Location::new(39.9, 116.4, 8.0).unwrap();
    for (day, eot_minutes) in table {
        // 12:00 true solar time on the day, in standard time, from the table.
        let expected = 12.0 - eot_minutes / 60.0 - (site.longitude - 120.0) / 15.0;
        let got = gb50180::standard_time(&site, day, 12.0);
        assert!((got - expected).abs() * 60.0 <= 0.75, "day {day}: {got:.4} h vs the table's {expected:.4} h");
    }
}

fn run_map(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).arg("map").args(args).current_dir(dir).output().unwrap()
}

/// A .gltf of one closed box `lo`..`hi` (world axes: x east, y north, z up; glTF's are x, up,
/// south) in an embedded buffer, its node named `name`.
fn box_gltf(name: &str, lo: DVec3, hi: DVec3) -> String {
    use base64::Engine as _;
    let corner = |i: usize| {
        let w =
            DVec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z });
        [w.x as f32, w.z as f32, -w.y as f32]
    };
    let positions: Vec<[f32; 3]> = (0..8).map(corner).collect();
    let quads: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let indices: Vec<u32> = quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let pos_len = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let (min, max) = (
        (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MAX, f32::min).to_string()).collect::<Vec<_>>().join(","),
        (0..3).map(|k| positions.iter().map(|p| p[k]).fold(f32::MIN, f32::max).to_string()).collect::<Vec<_>>().join(","),
    );
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":{len}}}],
        "bufferViews":[{{"buffer":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{pos_len},"byteLength":{idx_len}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":[{min}],"max":[{max}]}},{{"bufferView":1,"componentType":5125,"count":36,"type":"SCALAR"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"nodes":[{{"mesh":0,"name":"{name}"}}],"scenes":[{{"nodes":[0]}}]}}"#,
        data = base64::engine::general_purpose::STANDARD.encode(&bin),
        len = bin.len(),
        idx_len = bin.len() - pos_len,
    )
}

/// An EPW of one hour repeated with no direct normal irradiance (DHI 100, GHI 100).
fn epw_without_dni() -> String {
    use std::fmt::Write as _;
    let mut text = String::from("LOCATION,Golden,CO,USA,test,0,39.74,-105.18,-7.0,1800\n");
    text.push_str("DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n");
    text.push_str("COMMENTS 1,synthetic\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
    for h in 0..8760u32 {
        let (month, day) = sunlit::year::samples::month_day(h / 24 + 1);
        let _ = writeln!(
            text,
            "1999,{month},{day},{},60,x,10,5,50,80000,0,1300,300,100,0,100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0.2,0,0",
            h % 24 + 1
        );
    }
    text
}

/// The CLI: every window study at once before and after a proposal block, the output contract
/// (points in input order, numeric values, verdicts apart), the pictures, and the refusals
/// (named, nothing written).
#[test]
fn cli_window_studies_before_and_after_and_bad_input() {
    let dir = std::env::temp_dir().join(format!("sunlit-planning-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let office = root.join("examples/office.glb");
    let office = office.to_str().unwrap();
    let epw = golden_epw();
    let epw = epw.to_str().unwrap();
    // One point per window of the office, from a 0.5 m grid (the first point on each).
    let out = run_map(&dir, &[office, "--grid", "0.5", "--location", "39.74,-105.18,-7", "--at", "03-21", "12:00", "-o", "grid.csv"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let grid = std::fs::read_to_string(dir.join("grid.csv")).unwrap();
    let mut csv = String::from("x,y,z,nx,ny,nz\n");
    let mut seen = Vec::new();
    for line in grid.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f[0].starts_with("WIN_") && !seen.contains(&f[0]) {
            seen.push(f[0]);
            csv.push_str(&f[1..7].join(","));
            csv.push('\n');
        }
    }
    assert_eq!(seen, ["WIN_S1", "WIN_S2", "WIN_E", "WIN_N", "WIN_W"]);
    std::fs::write(dir.join("windows.csv"), &csv).unwrap();
    // The proposal: a 12 m block 6 m south of the office.
    std::fs::write(dir.join("block.gltf"), box_gltf("BLOCK", DVec3::new(-10.0, -14.0, 0.0), DVec3::new(40.0, -8.0, 12.0))).unwrap();
    let out = run_map(
        &dir,
        &[
            office,
            "block.gltf",
            "--receivers",
            "WIN_*",
            "--points",
            "windows.csv",
            "--epw",
            epw,
            "--study",
            "bre-vsc",
            "--study",
            "bre-apsh",
            "--study",
            "gb50180",
            "--window-width",
            "1.0",
            "--study",
            "en17037",
            "--before",
            office,
            "--mask",
            "1,4",
            "--html",
            "report.html",
            "-o",
            "w.csv",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["points"], 5);
    assert_eq!(summary["points_before"], 5);
    let table = std::fs::read_to_string(dir.join("w.csv")).unwrap();
    assert!(table.starts_with("receiver,x,y,z,nx,ny,nz,vsc,apsh,wpsh,hours,hours_whole_window,hours_en17037\n"), "{table}");
    let read = |name: &str| -> Value { serde_json::from_str(&std::fs::read_to_string(dir.join(name)).unwrap()).unwrap() };
    let vsc = read("w.study-bre-vsc.json");
    let apsh = read("w.study-bre-apsh.json");
    let gb = read("w.study-gb50180.json");
    let en = read("w.study-en17037.json");
    for report in [&vsc, &apsh, &gb, &en] {
        let points = report["points"].as_array().unwrap();
        assert_eq!(points.len(), 5, "one entry per input row");
        for (p, name) in points.iter().zip(&seen) {
            assert_eq!(p["receiver"], *name, "points in the input's order");
            assert!(p["passes"].is_boolean() || p["passes"].is_null());
        }
        assert!(report["rule"].is_object() && report["source"].is_string() && report["areas"].is_array());
    }
    assert_eq!(gb["rule"]["day"], "大寒日");
    assert_eq!((en["rule"]["day"].as_str(), en["rule"]["min_altitude_deg"].as_f64()), (Some("03-21"), Some(10.0)));
    for p in en["points"].as_array().unwrap() {
        let (now, before) = (p["hours"].as_f64().unwrap(), p["hours_before"].as_f64().unwrap());
        assert!(now <= before + 1e-9, "the block adds no sun: {p}");
        for (key, need) in [("passes", 1.5), ("passes_medium", 3.0), ("passes_high", 4.0)] {
            assert_eq!(p[key], now + 1e-9 >= need, "{key}: {p}");
        }
        assert!(p["passes_relative"].is_null(), "EN 17037 has no relative test");
    }
    assert!((gb["rule"]["declination_deg"].as_f64().unwrap() + 20.15).abs() < 0.01);
    for p in vsc["points"].as_array().unwrap() {
        let (now, before) = (p["vsc"].as_f64().unwrap(), p["vsc_before"].as_f64().unwrap());
        assert!(now <= before + 1e-9 && p["vsc_ratio"].as_f64().unwrap() <= 1.0 + 1e-9);
        assert!(p["passes_absolute"].is_boolean() && p["passes_relative"].is_boolean());
    }
    let s1 = &vsc["points"][0];
    assert!(s1["vsc"].as_f64().unwrap() < s1["vsc_before"].as_f64().unwrap() - 3.0, "the block takes sky from the south windows: {s1}");
    let north = &apsh["points"][3];
    assert_eq!(north["assessed"], false);
    assert!(north["passes"].is_null() && north["apsh"].is_number() && north["wpsh"].is_number());
    let south = &apsh["points"][0];
    assert!(south["apsh"].as_f64().unwrap() < south["apsh_before"].as_f64().unwrap());
    let svg = std::fs::read_to_string(dir.join("w.mask-1.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("fill=\"#555\" stroke=\"none\" d=\"M"), "the block shows in the mask");
    assert!(dir.join("w.mask-4.svg").exists() && !dir.join("w.mask-2.svg").exists());
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert!(html.contains("<table") && html.contains("bre-apsh") && html.contains("<svg") && html.contains("GB 50180"));

    // BRE's pre-checks, before and after: the 25° angle is the block's alone (the new
    // development; the south windows' own overhangs are in `angle_deg_all`, before and after),
    // none behind the north window, and the block lowers no angle of everything in the section.
    let windows_of_both = [office, "block.gltf", "--receivers", "WIN_*", "--points", "windows.csv"];
    let lines = ["--study", "bre-25deg", "--study", "bre-45deg", "--before", office, "-o", "lines.csv"];
    let out = run_map(&dir, &[&windows_of_both[..], &lines[..]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let line25 = read("lines.study-bre-25deg.json");
    let line45 = read("lines.study-bre-45deg.json");
    for p in line25["points"].as_array().unwrap() {
        let (now, all) = (p["angle_deg"].as_f64().unwrap(), p["angle_deg_all"].as_f64().unwrap());
        assert!(all >= now && all >= p["angle_deg_all_before"].as_f64().unwrap() && p["passes"] == (now <= 25.0), "{p}");
        assert_eq!(p["angle_deg_before"], 0.0, "no development before: {p}");
    }
    let s1 = &line25["points"][0];
    assert!(s1["passes"] == false && s1["angle_deg"].as_f64().unwrap() > 45.0, "{s1}");
    let n = &line25["points"][3];
    assert!(n["angle_deg"] == 0.0 && n["passes"] == true && n["angle_deg_all"] == n["angle_deg_all_before"], "{n}");
    assert!(line45["points"].as_array().unwrap().iter().all(|p| p["within_45deg"].is_number() && p["passes"].is_boolean()));
    assert_eq!(line25["rule"]["line_deg"], 25.0);

    // Each window's own 满窗 width from a CSV: the report states them per point.
    std::fs::write(dir.join("widths.csv"), "receiver,width\nWIN_S1,1.5\nWIN_S2,3\nWIN_E,1\nWIN_N,1\nWIN_W,2\n").unwrap();
    let gb_widths = ["--study", "gb50180", "--location", "39.9,116.4,8", "--window-widths", "widths.csv", "-o", "widths-out.csv"];
    let out = run_map(&dir, &[&windows_of_both[..], &gb_widths[..]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let widths = read("widths-out.study-gb50180.json");
    assert_eq!(widths["rule"]["whole_window_widths_m"], serde_json::json!([1.5, 3.0, 1.0, 1.0, 2.0]), "{}", widths["rule"]);
    assert!(widths["points"].as_array().unwrap().iter().all(|p| p["hours_whole_window"].as_f64().unwrap() <= p["hours"].as_f64().unwrap()));
    std::fs::write(dir.join("bad-widths.csv"), "receiver,width\nWIN_S1,1.5\nWIN_S2,wide\n").unwrap();

    std::fs::write(dir.join("dull.epw"), epw_without_dni()).unwrap();
    // A window far away: a receiver of the same name pattern, but none of the points on it.
    std::fs::write(dir.join("elsewhere.gltf"), box_gltf("WIN_FAR", DVec3::new(500.0, 500.0, 0.0), DVec3::new(501.0, 501.0, 1.0))).unwrap();
    for (args, says) in [
        (vec!["--study", "bre-vsc", "--min-period", "5"], "--min-period"),
        (vec!["--study", "bre-vsc", "--before", "elsewhere.gltf"], "--before"),
        (vec!["--study", "bre-apsh", "--location", "39.74,-105.18,-7"], "--epw"),
        (vec!["--study", "bre-apsh", "--epw", "dull.epw"], "--epw"),
        (vec!["--study", "gb50180", "--location", "39.9,116.4,8", "--day", "06-21"], "--day"),
        (vec!["--study", "bre-vsc", "--sky-model", "perez-all-weather"], "--sky-model"),
        (vec!["--study", "bre-vsc", "--period", "03-21"], "--period"),
        (vec!["--study", "bre-vsc", "--study", "en17037", "--location", "51.5,0,0", "--period", "06-21"], "--period"),
        (vec!["--study", "bre-vsc", "--study", "en17037", "--location", "51.5,0,0", "--min-altitude", "90"], "--min-altitude"),
        (vec!["--study", "bre-vsc", "--study", "en17037"], "--location"),
        (vec!["--study", "bre-vsc", "--min-altitude", "12"], "--min-altitude"),
        (vec!["--study", "bre-vsc", "--study", "bre-ground", "--location", "0,0,0"], "--study"),
        (vec!["--study", "bre-vsc", "--mask", "9"], "--mask"),
        (vec!["--study", "gb50180", "--location", "39.9,116.4,8", "--floor-level", "0"], "--floor-level"),
        (vec!["--study", "gb50180", "--location", "39.9,116.4,8", "--window-widths", "bad-widths.csv"], "bad-widths.csv: line 3"),
        (
            vec!["--study", "gb50180", "--location", "39.9,116.4,8", "--window-widths", "widths.csv", "--window-width", "1"],
            "--window-widths",
        ),
        (vec!["--study", "bre-vsc", "--window-widths", "widths.csv"], "--window-widths"),
    ] {
        let mut all = vec![office, "--receivers", "WIN_*", "--points", "windows.csv"];
        all.extend(args.iter().copied());
        all.extend(["-o", "bad.csv", "--html", "bad.html"]);
        let out = run_map(&dir, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!dir.join("bad.csv").exists() && !dir.join("bad.html").exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An empty scratch directory `sunlit-NAME-PID` and the office example's path.
fn fresh_dir_and_office(name: &str) -> (PathBuf, String) {
    let dir = std::env::temp_dir().join(format!("sunlit-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let office = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/office.glb");
    (dir, office.to_str().unwrap().to_string())
}

/// `--window-points`: one point per window, found from its geometry (BRE's centre, GB 50180's
/// sill), before and after, with the reports saying which; its refusals name it.
#[test]
fn cli_window_points_are_found_on_each_window() {
    let (dir, office) = fresh_dir_and_office("planning-window-points");
    let office = office.as_str();
    std::fs::write(dir.join("block.gltf"), box_gltf("BLOCK", DVec3::new(-10.0, -14.0, 0.0), DVec3::new(40.0, -8.0, 12.0))).unwrap();
    let rows = |at: &str| -> (Value, Vec<Vec<String>>) {
        let file = format!("{at}.csv");
        let windows = [office, "block.gltf", "--receivers", "WIN_*", "--window-points", at, "--location", "39.9,116.4,8"];
        let out = run_map(&dir, &[&windows[..], &["--study", "gb50180", "--before", office, "-o", &file, "--json"]].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
        let csv = std::fs::read_to_string(dir.join(format!("{at}.csv"))).unwrap();
        (summary, csv.lines().skip(1).map(|l| l.split(',').map(String::from).collect()).collect())
    };
    let (summary, sills) = rows("sill");
    let (_, centres) = rows("centre");
    assert_eq!((summary["points"].as_u64(), summary["points_before"].as_u64()), (Some(5), Some(5)), "{summary}");
    assert_eq!(sills.iter().map(|r| r[0].as_str()).collect::<Vec<_>>(), ["WIN_S1", "WIN_S2", "WIN_E", "WIN_N", "WIN_W"]);
    let number = |r: &[String], k: usize| r[k].parse::<f64>().unwrap();
    for (s, c) in sills.iter().zip(&centres) {
        assert_eq!(s[0], c[0]);
        assert!(number(s, 3) < number(c, 3) - 0.3, "the sill lies below the centre: {s:?} {c:?}");
        assert!((4..7).all(|k| number(s, k) == number(c, k)), "one window, one normal: {s:?} {c:?}");
    }
    let report: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("sill.study-gb50180.json")).unwrap()).unwrap();
    assert_eq!(report["inputs"]["points"]["window_points"], "sill", "{}", report["inputs"]);
    assert!(report["points"].as_array().unwrap().iter().all(|p| p["hours_before"].is_number()), "the existing scene has the same sills");
    for (args, says) in [
        (vec!["--window-points", "middle", "--study", "gb50180", "--location", "39.9,116.4,8"], "--window-points"),
        (vec!["--window-points", "sill", "--grid", "1", "--study", "gb50180", "--location", "39.9,116.4,8"], "--window-points"),
        (vec!["--window-points", "sill", "--location", "39.9,116.4,8", "--period", "03-21"], "--window-points"),
    ] {
        let mut all = vec![office, "--receivers", "WIN_*"];
        all.extend(args.iter().copied());
        all.extend(["-o", "bad.csv"]);
        let out = run_map(&dir, &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!dir.join("bad.csv").exists(), "{args:?} wrote its output");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--sky-model` on `annual` and `map`: an unknown name, or a model without the weather its light
/// comes from, is refused naming the option, and nothing is written.
#[test]
fn sky_model_refusals_name_the_option() {
    let (dir, office) = fresh_dir_and_office("sky-model-refusals");
    let office = office.as_str();
    let epw = golden_epw();
    let epw = epw.to_str().unwrap();
    let annual = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_sunlit")).arg("annual").args(args).current_dir(&dir).output().unwrap();
    let cases: Vec<(std::process::Output, &str)> = vec![
        (annual(&[office, "--epw", epw, "--summary", "s.json", "--sky-model", "perez", "-o", "a.csv"]), "'perez' is not a sky model"),
        (
            annual(&[office, "--location", "39.74,-105.18,-7", "--summary", "s.json", "--sky-model", "uniform", "-o", "a.csv"]),
            "needs a weather file",
        ),
        (
            run_map(&dir, &[office, "--grid", "1", "--epw", epw, "--sky-model", "gendaymtx", "-o", "m.csv"]),
            "'gendaymtx' is not a sky model",
        ),
        (
            run_map(&dir, &[office, "--grid", "1", "--location", "39.74,-105.18,-7", "--sky-model", "cie-overcast", "-o", "m.csv"]),
            "needs a weather file",
        ),
    ];
    for (out, why) in cases {
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains("--sky-model") && stderr.contains(why), "{stderr}");
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
    let _ = std::fs::remove_dir_all(&dir);
}
