//! The sky: patch integration against the isotropic view factor, sky views against analytic view
//! factors (a courtyard's opening, an overhang), the exact and GPU engines against each other,
//! the annual sky diffuse against a closed-form Perez sky computed here, and the CLI's refusals
//! of bad weather, albedo and patch schemes (naming file, line and field, writing nothing).

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::{TestScene, closed_form_perez, counter, flat_rect, runtime_dir};

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

use glam::DVec3;
use sunlit::count::exact::Exact;
use sunlit::count::lanes::Lane;
use sunlit::export::Schedule;
use sunlit::export::irradiation::summarize;
use sunlit::model::glb_write::GlbWriter;
use sunlit::scene::Scene;
use sunlit::sky::patches::SkyPatches;
use sunlit::sky::views::{SkyViews, sky_views};
use sunlit::sun::location::Location;
use sunlit::sun::position::sun_direction;
use sunlit::sun::weather::{Hour, Weather};
use sunlit::year::annual::shading_sun_day;
use sunlit::year::samples::{Timesteps, month_day};
use sunlit::year::season::LeafCalendar;

/// A unit normal at `tilt` from up, facing `azimuth` (degrees clockwise from north).
fn normal(tilt: f64, azimuth: f64) -> DVec3 {
    let (t, a) = (tilt.to_radians(), azimuth.to_radians());
    DVec3::new(t.sin() * a.sin(), t.sin() * a.cos(), t.cos())
}

#[test]
fn patch_weights_integrate_to_the_isotropic_view_factor() {
    for sky in [SkyPatches::tregenza(), SkyPatches::reinhart(2)] {
        let mut worst = 0.0f64;
        for tilt in (0..=180).step_by(5) {
            for azimuth in [0.0, 17.0, 90.0, 133.0, 180.0, 271.0] {
                let n = normal(f64::from(tilt), azimuth);
                let sum: f64 = sky.weights(n).iter().map(|w| w.weight).sum::<f64>() / PI;
                let expected = (1.0 + n.z) / 2.0;
                worst = worst.max((sum - expected).abs());
                assert!((sum - expected).abs() < 0.001, "{} tilt {tilt} azimuth {azimuth}: {sum} vs {expected}", sky.name());
            }
        }
        eprintln!("{}: worst |Σ w/π − (1+cos tilt)/2| = {worst:.2e}", sky.name());
    }
}

/// View factor from a small horizontal element at the origin to the rectangle
/// [x1, x2] × [y1, y2] in the plane z = c above it (the corner formula, summed with signs).
fn rectangle_view_factor(x1: f64, x2: f64, y1: f64, y2: f64, c: f64) -> f64 {
    let corner = |a: f64, b: f64| {
        let (a, b) = (a / c, b / c);
        let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
        (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * PI)
    };
    corner(x2, y2) - corner(x1, y2) - corner(x2, y1) + corner(x1, y1)
}

fn exact_views(scene: &Scene, sky: &SkyPatches) -> SkyViews {
    pollster::block_on(sky_views(&Exact { scene }, scene, sky, &mut |_| Ok(()))).unwrap()
}

/// A 2 cm horizontal receiver at the origin.
fn small_floor(scene: &mut TestScene) {
    scene.polygon("FLOOR", &flat_rect(-0.01, 0.01, -0.01, 0.01, 0.0), true);
}

#[test]
fn a_courtyard_opening_and_an_overhang_match_analytic_view_factors() {
    let sky = SkyPatches::reinhart(6);
    // Courtyard: a 2 m × 2 m opening 1 m above the floor in a roof reaching 60 m out; the sky
    // seen is the opening's view factor plus the sliver beyond the roof's edges.
    let mut courtyard = TestScene::new();
    small_floor(&mut courtyard);
    let (r, h) = (60.0, 1.0);
    for (x0, x1, y0, y1) in [(-r, r, 1.0, r), (-r, r, -r, -1.0), (-r, -1.0, -1.0, 1.0), (1.0, r, -1.0, 1.0)] {
        // Facing down: the roof's underside towards the floor (winding reversed).
        let mut corners = flat_rect(x0, x1, y0, y1, h);
        corners.reverse();
        courtyard.polygon("ROOF", &corners, false);
    }
    let views = exact_views(&courtyard.build(), &sky);
    let expected = rectangle_view_factor(-1.0, 1.0, -1.0, 1.0, h) + (1.0 - rectangle_view_factor(-r, r, -r, r, h));
    let got = views.isotropic(0, 1.0);
    eprintln!("courtyard: sky view factor {got:.4} vs analytic {expected:.4}");
    assert!((got - expected).abs() < 0.01, "courtyard {got} vs {expected}");
    assert!((views.unobstructed(0) - 1.0).abs() < 1e-4);
    // Overhang: a roof 1 m up over y from −0.5 m to 60 m (60 m wide): it hides a little more than
    // half the sky.
    let mut overhang = TestScene::new();
    small_floor(&mut overhang);
    let mut corners = flat_rect(-r, r, -0.5, r, h);
    corners.reverse();
    overhang.polygon("OVERHANG", &corners, false);
    let views = exact_views(&overhang.build(), &sky);
    let expected = 1.0 - rectangle_view_factor(-r, r, -0.5, r, h);
    let got = views.isotropic(0, 1.0);
    eprintln!("overhang: sky view factor {got:.4} vs analytic {expected:.4}");
    assert!((got - expected).abs() < 0.01, "overhang {got} vs {expected}");
    // Its horizon band is hidden to the north, open to the south: about half.
    let horizon = views.horizon(0, 1.0);
    assert!((0.3..0.7).contains(&horizon), "{horizon}");
}

/// A street canyon: a south wall and a roof between two blocks, for engine comparisons.
fn canyon() -> Scene {
    let mut scene = TestScene::new();
    scene.polygon("WALL", &common::south_rect(0.0, 4.0, 0.0, 3.0, 0.0), true);
    scene.polygon("ROOF", &flat_rect(6.0, 8.0, -4.0, -2.0, 1.0), true);
    scene.cuboid("BLOCK", DVec3::new(-2.0, -9.0, 0.0), DVec3::new(10.0, -6.0, 5.0));
    scene.cuboid("FIN", DVec3::new(4.5, -3.0, 0.0), DVec3::new(5.0, 0.0, 4.0));
    scene.build()
}

#[test]
fn exact_and_gpu_sky_views_agree() {
    let scene = canyon();
    let sky = SkyPatches::tregenza();
    let exact = exact_views(&scene, &sky);
    let counter = counter(256);
    let gpu = counter.upload(&scene).unwrap();
    let lane = Lane { counter: &counter, gpu: &gpu };
    let counted = pollster::block_on(sky_views(&lane, &scene, &sky, &mut |_| Ok(()))).unwrap();
    for r in 0..scene.receivers.len() {
        let (e, g) = (exact.isotropic(r, 1.0), counted.isotropic(r, 1.0));
        eprintln!("{}: sky view factor exact {e:.4}, GPU {g:.4}", scene.receivers[r].name);
        assert!((e - g).abs() < 0.005, "{}: exact {e} vs GPU {g}", scene.receivers[r].name);
        assert!((exact.horizon(r, 1.0) - counted.horizon(r, 1.0)).abs() < 0.01);
        assert!(e < exact.unobstructed(r) - 0.02, "the block hides some sky");
    }
}

#[test]
fn an_unobstructed_surface_gets_the_closed_form_perez_sky() {
    // Golden, CO at its EPW's elevation: the air mass's elevation term must be applied.
    let mut location = Location::new(39.74, -105.18, -7.0).unwrap();
    location.elevation = 1829.0;
    let calendar = LeafCalendar::default();
    let timesteps = Timesteps::new(1).unwrap();
    for (dni, dhi) in [(0.0, 150.0), (300.0, 200.0), (850.0, 90.0), (600.0, 300.0)] {
        let weather = Weather::constant(location.clone(), Hour { dni, dhi, ghi: 0.0, albedo: 0.2 });
        for (tilt, azimuth) in [(0.0, 0.0), (30.0, 180.0), (90.0, 180.0), (90.0, 0.0), (90.0, 95.0), (60.0, 250.0), (135.0, 40.0)] {
            let n = normal(tilt, azimuth);
            let mut scene = TestScene::new();
            let (u, v) = (n.any_orthonormal_vector(), n.cross(n.any_orthonormal_vector()));
            let corners: Vec<DVec3> = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)].iter().map(|&(a, b)| u * a + v * b).collect();
            scene.polygon("S", &corners, true);
            let scene = scene.build();
            let views = exact_views(&scene, &SkyPatches::tregenza());
            // Fractions 1 where the sun is in front (nothing shades), as the annual run makes them.
            let mut schedule = Schedule::zeros(vec!["S".into()], timesteps);
            let mut expected = 0.0;
            for (row, instant) in timesteps.instants().enumerate() {
                let sun = sun_direction(&location, shading_sun_day(instant.day), instant.hour);
                if sun.z < 1e-5 {
                    continue;
                }
                schedule.set(row, 0, if scene.receivers[0].normal.dot(sun) > 1e-5 { 1.0 } else { 0.0 });
                if dhi > 0.0 {
                    expected += closed_form_perez(scene.receivers[0].normal, sun, dni, dhi, location.elevation) / 1000.0;
                }
            }
            let s = summarize(&scene, &schedule, &location, Some((&views, &calendar)), Some(&weather), &[]).unwrap();
            let got = s[0].sky_diffuse.unwrap();
            // Patch integration (< 1e-4 of the isotropic part) and the paper's rounded
            // coefficients (3 decimals) against EnergyPlus's 7: well within 0.5 %.
            assert!((got - expected).abs() <= 0.005 * expected + 1e-3, "dni {dni} dhi {dhi} tilt {tilt} az {azimuth}: {got} vs {expected}");
            // Unobstructed, the shaded sky is the unshaded one, up to the views the engines call
            // dark (cos θ ≤ 1e-5 at a patch's edge or the sun's grazing timesteps).
            let unshaded_sky = s[0].unshaded_total.unwrap() - s[0].unshaded_irradiation.unwrap();
            assert!((got - unshaded_sky).abs() <= 1e-4 * got + 1e-6, "tilt {tilt} az {azimuth}: shaded {got} vs unshaded {unshaded_sky}");
        }
    }
}

fn sunlit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).env("XDG_RUNTIME_DIR", runtime_dir()).output().expect("run sunlit")
}

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("sky", name)
}

/// An EPW whose records hold `dni`, `dhi`, `ghi` and `albedo`, with `bad` put in field
/// `field` (0-based) of hour `bad_hour`.
fn epw(bad: Option<(usize, usize, &str)>) -> String {
    let mut text = String::from("LOCATION,Golden,CO,USA,test,0,39.74,-105.18,-7.0,1800\n");
    text.push_str("DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n");
    text.push_str("COMMENTS 1,synthetic\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
    for h in 0..8760u32 {
        let (month, day) = month_day(h / 24 + 1);
        let mut fields: Vec<String> =
            format!("1999,{month},{day},{},60,x,10,5,50,80000,0,1300,300,500,600,100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0.2,0,0", h % 24 + 1)
                .split(',')
                .map(String::from)
                .collect();
        if let Some((_, field, value)) = bad.filter(|(hour, ..)| *hour == h as usize) {
            fields[field] = value.to_string();
        }
        let _ = writeln!(text, "{}", fields.join(","));
    }
    text
}

/// Two roofs (one under a sheet) in a glb.
fn model(dir: &Path) -> String {
    let mut glb = GlbWriter::new();
    let roof = glb.add_mesh("roof", &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2, 0, 2, 3]);
    glb.add_node("ROOF_A", roof, [10.0, 0.0, 0.0], None);
    glb.add_node("ROOF_B", roof, [-10.0, 0.0, 0.0], None);
    let path = dir.join("roofs.glb");
    std::fs::write(&path, glb.to_glb()).unwrap();
    path.display().to_string()
}

#[test]
fn bad_weather_albedo_and_patch_schemes_are_refused_before_anything_is_written() {
    let dir = scratch("bad");
    let model = model(&dir);
    let (csv, summary, irradiance) = (dir.join("s.csv"), dir.join("summary.json"), dir.join("irr.csv"));
    let run = |epw_text: &str, extra: &[&str]| {
        let epw = dir.join("w.epw");
        std::fs::write(&epw, epw_text).unwrap();
        let mut args = vec!["annual", &model, "--epw", epw.to_str().unwrap(), "--days-per-year", "3", "--samples-per-day", "3"];
        args.extend(["--resolution", "32", "-o", csv.to_str().unwrap(), "--summary", summary.to_str().unwrap()]);
        args.extend(["--irradiance", irradiance.to_str().unwrap()]);
        args.extend(extra);
        let out = sunlit(&args);
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert_eq!(out.status.code(), Some(1), "{extra:?}: {err}");
        assert!(!csv.exists() && !summary.exists() && !irradiance.exists(), "nothing written after a refusal: {err}");
        err
    };
    // Line 9 is the first data record (hour 0); hour 100 is line 109.
    let cases = [
        (Some((0, 15, "9999")), "w.epw: line 9: diffuse horizontal irradiance (field 16) is missing (9999)"),
        (Some((100, 13, "-5")), "w.epw: line 109: global horizontal irradiance (field 14) -5 is negative"),
        (Some((100, 14, "1600")), "w.epw: line 109: direct normal irradiance (field 15) 1600 W/m² is beyond the physical bound"),
        (Some((7, 32, "3")), "w.epw: line 16: albedo (field 33) 3 is outside 0..=1"),
    ];
    for (bad, needle) in cases {
        let err = run(&epw(bad), &[]);
        assert!(err.contains(needle), "{needle}: {err}");
    }
    let good = epw(None);
    let err = run(&good, &["--albedo", "1.2"]);
    assert!(err.contains("--albedo") && err.contains("1.2 is outside 0..=1"), "{err}");
    let err = run(&good, &["--sky-patches", "reinhart:9"]);
    assert!(err.contains("--sky-patches") && err.contains("'9' is not offered"), "{err}");
    let err = run(&good, &["--sky-patches", "klems"]);
    assert!(err.contains("--sky-patches") && err.contains("'klems' is not a patch scheme"), "{err}");
}

#[test]
fn the_cli_writes_the_split_and_the_irradiance_csv() {
    let dir = scratch("split");
    let model = model(&dir);
    let weather = dir.join("w.epw");
    std::fs::write(&weather, epw(None)).unwrap();
    let (csv, summary, irradiance) = (dir.join("s.csv"), dir.join("summary.json"), dir.join("irr.csv"));
    let out = sunlit(&[
        "annual",
        &model,
        "--epw",
        weather.to_str().unwrap(),
        "--days-per-year",
        "3",
        "--samples-per-day",
        "3",
        "--timesteps-per-hour",
        "1",
        "--resolution",
        "32",
        "--albedo",
        "0.3",
        "-o",
        csv.to_str().unwrap(),
        "--summary",
        summary.to_str().unwrap(),
        "--irradiance",
        irradiance.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&summary).unwrap()).unwrap();
    let roof = &json["surfaces"][0];
    let get = |k: &str| roof[k].as_f64().unwrap_or_else(|| panic!("{k} in {roof}"));
    let total = get("direct") + get("sky_diffuse") + get("ground_reflected");
    assert!((get("total") - total).abs() < 1e-6 * total, "{roof}");
    assert_eq!(get("direct"), get("irradiation"));
    assert!((get("sky_view_factor") - 1.0).abs() < 1e-3 && (get("energyplus_iso_sky_ratio") - 1.0).abs() < 1e-9, "{roof}");
    assert!((get("energyplus_horizon_ratio") - 1.0).abs() < 1e-9 && get("ground_reflected").abs() < 1e-9, "{roof}");
    // The irradiance CSV: the schedule's layout, and its rows sum to the total.
    let text = std::fs::read_to_string(&irradiance).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("Surface Name,ROOF_A,ROOF_B,"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 8760);
    assert!(rows[0].starts_with(" 01/01 01:00,"));
    let sum: f64 = rows.iter().map(|r| r.split(',').nth(1).unwrap().parse::<f64>().unwrap()).sum::<f64>() / 1000.0;
    assert!((sum - get("total")).abs() < 0.005 * get("total"), "CSV {sum} vs summary {}", get("total"));
}
