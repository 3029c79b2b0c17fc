//! `sunlit annual --summary`: annual direct irradiation through the whole pipeline (glb, GPU
//! counting, spline, EPW weather) against the closed-form integral for a horizontal roof.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::runtime_dir;

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

use sunlit::model::glb_write::GlbWriter;
use sunlit::sun::position::declination_and_equation_of_time;
use sunlit::year::samples::month_day;

const LATITUDE: f64 = 39.74;
const DNI: f64 = 700.0;

fn sunlit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).env("XDG_RUNTIME_DIR", runtime_dir()).output().expect("run sunlit")
}

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("irradiation", name)
}

/// An EPW with a constant direct normal irradiance (field 15) every hour.
fn constant_epw(dni: f64) -> String {
    let mut text = format!("LOCATION,Golden,CO,USA,test,0,{LATITUDE},-105.18,-7.0,1800\n");
    text.push_str("DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n");
    text.push_str("COMMENTS 1,synthetic\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
    for h in 0..8760u32 {
        let (month, day) = month_day(h / 24 + 1);
        let _ = writeln!(
            text,
            "1999,{month},{day},{},60,x,10,5,50,80000,0,1300,300,500,{dni},100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0",
            h % 24 + 1
        );
    }
    text
}

/// Two 2 m² roofs: ROOF_A open, ROOF_B with an opaque sheet 1 cm above its western half.
fn roofs(dir: &Path) -> String {
    let mut glb = GlbWriter::new();
    let roof = glb.add_mesh("roof", &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2, 0, 2, 3]);
    glb.add_node("ROOF_A", roof, [10.0, 0.0, 0.0], None);
    glb.add_node("ROOF_B", roof, [-10.0, 0.0, 0.0], None);
    let sheet =
        glb.add_mesh("sheet", &[[-15.0, -3.0, 0.01], [-9.0, -3.0, 0.01], [-9.0, 4.0, 0.01], [-15.0, 4.0, 0.01]], &[0, 1, 2, 0, 2, 3]);
    glb.add_node("SHEET", sheet, [0.0, 0.0, 0.0], None);
    let path = dir.join("roofs.glb");
    std::fs::write(&path, glb.to_glb()).unwrap();
    path.display().to_string()
}

/// B·Σ_days (24/π)(ω₀ sin φ sin δ + cos φ cos δ sin ω₀) / 1000: kWh/m² on a horizontal surface,
/// with the sun model's declination held over each day.
fn closed_form_kwh() -> f64 {
    let phi = LATITUDE.to_radians();
    (1..=365)
        .map(|day| {
            let delta = declination_and_equation_of_time(f64::from(day)).0.asin();
            let omega0 = (-phi.tan() * delta.tan()).clamp(-1.0, 1.0).acos();
            DNI * 24.0 / std::f64::consts::PI * (omega0 * phi.sin() * delta.sin() + phi.cos() * delta.cos() * omega0.sin())
        })
        .sum::<f64>()
        / 1000.0
}

#[test]
fn summary_irradiation_matches_the_closed_form() {
    let dir = scratch("roofs");
    let model = roofs(&dir);
    let epw = dir.join("constant.epw");
    std::fs::write(&epw, constant_epw(DNI)).unwrap();
    let (csv, json, table) = (dir.join("s.csv"), dir.join("summary.json"), dir.join("summary.csv"));
    let run = |summary: &Path| {
        let out = sunlit(&[
            "annual",
            &model,
            "--receivers",
            "ROOF*",
            "--epw",
            epw.to_str().unwrap(),
            "--timesteps-per-hour",
            "1",
            "--resolution",
            "128",
            "-o",
            csv.to_str().unwrap(),
            "--summary",
            summary.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    run(&json);
    let value: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let surfaces = value["surfaces"].as_array().unwrap();
    let field = |name: &str, key: &str| {
        surfaces.iter().find(|s| s["name"] == name).unwrap_or_else(|| panic!("{name} in {value}"))[key].as_f64().unwrap()
    };
    let expected = closed_form_kwh();
    eprintln!(
        "closed form {expected:.2} kWh/m²; ROOF_A {:.2} (unshaded {:.2}); ROOF_B {:.2} (unshaded {:.2}), mean fraction {:.4}",
        field("ROOF_A", "irradiation"),
        field("ROOF_A", "unshaded_irradiation"),
        field("ROOF_B", "irradiation"),
        field("ROOF_B", "unshaded_irradiation"),
        field("ROOF_B", "mean_fraction"),
    );
    for name in ["ROOF_A", "ROOF_B"] {
        let unshaded = field(name, "unshaded_irradiation");
        assert!((unshaded / expected - 1.0).abs() < 0.005, "{name}: unshaded {unshaded} vs closed form {expected}");
        assert!((field(name, "area") - 2.0).abs() < 1e-6);
    }
    // Open roof: fully sunlit whenever the sun is up.
    assert!((field("ROOF_A", "irradiation") / expected - 1.0).abs() < 0.005);
    assert!((field("ROOF_A", "mean_fraction") - 1.0).abs() < 0.002);
    // Half covered: half, up to the sheet's 1 cm edge shadow (odd in the sun's east-west
    // component, so it cancels between morning and afternoon to first order).
    let half = field("ROOF_B", "irradiation") / field("ROOF_B", "unshaded_irradiation");
    assert!((half - 0.5).abs() < 0.01, "ROOF_B shaded/unshaded {half}");
    // The same as CSV.
    run(&table);
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "name,area_m2,mean_fraction,irradiation_kwh_m2,unshaded_irradiation_kwh_m2,direct_kwh_m2,sky_diffuse_kwh_m2,\
             ground_reflected_kwh_m2,total_kwh_m2,unshaded_total_kwh_m2,sky_view_factor,energyplus_iso_sky_ratio,energyplus_horizon_ratio"
        )
    );
    let row: Vec<&str> = lines.find(|l| l.starts_with("ROOF_B,")).unwrap().split(',').collect();
    assert!((row[3].parse::<f64>().unwrap() - field("ROOF_B", "irradiation")).abs() < 1e-3, "{row:?}");
}

#[test]
fn summary_refuses_unknown_formats_and_bad_weather_before_counting() {
    let dir = scratch("bad");
    let model = roofs(&dir);
    let csv = dir.join("s.csv");
    let args = |epw: &str, summary: &str| {
        vec![
            "annual".to_string(),
            model.clone(),
            "--epw".into(),
            epw.into(),
            "-o".into(),
            csv.display().to_string(),
            "--summary".into(),
            summary.into(),
        ]
    };
    let run = |a: Vec<String>| sunlit(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let good = dir.join("good.epw");
    std::fs::write(&good, constant_epw(100.0)).unwrap();
    let out = run(args(good.to_str().unwrap(), dir.join("summary.txt").to_str().unwrap()));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(1) && err.contains("--summary") && err.contains("summary.txt"), "{err}");
    let short = dir.join("short.epw");
    std::fs::write(&short, constant_epw(100.0).lines().take(500).collect::<Vec<_>>().join("\n")).unwrap();
    let out = run(args(short.to_str().unwrap(), dir.join("summary.json").to_str().unwrap()));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(1) && err.contains("short.epw") && err.contains("492 hourly data records"), "{err}");
    assert!(!csv.exists() && !dir.join("summary.json").exists(), "nothing written after a refusal");
}
