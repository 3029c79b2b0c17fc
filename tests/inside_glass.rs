//! The glass of the sun inside as EnergyPlus 25.2 reads it (`sunlit::model::inside::rooms`):
//! simple glazing's transmittance at normal incidence and its angular dependence, each against
//! EnergyPlus's own output for tests/inside/glass.idf. (Split from tests/inside.rs, whose rooms,
//! points and studies stay there.)
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::Scratch;
use common::inside::golden_epw;

use std::path::Path;
use std::process::Command;

use sunlit::model::inside::rooms;
use sunlit::model::{self, LoadOptions};

/// EnergyPlus 25.2's own simple glazing numbers (eplusout.eio's WindowConstruction: solar and
/// visible transmittance at normal incidence) against the glass `rooms` reads, for U 2.0 / SHGC
/// 0.6 / VT 0.7 and U 5.0 / SHGC 0.4 / VT 0.5 (tests/inside/glass.idf, a one-day run).
#[test]
fn simple_glazing_transmittance_matches_energyplus() {
    let tmp = Scratch::new("inside", "simple_glazing_transmittance_matches_energyplus");
    let idf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inside/glass.idf");
    let out = tmp.join("glass-run");
    let run = Command::new(common::energyplus::energyplus())
        .args(["-w", golden_epw().to_str().unwrap(), "-d", out.to_str().unwrap(), idf.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stdout));
    let eio = std::fs::read_to_string(out.join("eplusout.eio")).unwrap();
    let text = std::fs::read_to_string(&idf).unwrap();
    let loaded = model::load_bytes_all(&[("glass.idf".to_string(), text.into_bytes())], &LoadOptions::default()).unwrap();
    let ours = rooms(&loaded.energyplus.unwrap(), None).unwrap();
    for (window, construction) in [("Win", "GLASS"), ("Win2", "GLASS2")] {
        let row: Vec<f64> = eio
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("WindowConstruction,{construction},")))
            .unwrap()
            .split(',')
            .filter_map(|f| f.trim().parse().ok())
            .collect();
        let (solar, visible) = (row[row.len() - 2], row[row.len() - 1]);
        let g = ours.glazing.iter().find(|g| g.name == window).unwrap();
        eprintln!("{window}: solar {} (EnergyPlus {solar}), visible {} (EnergyPlus {visible})", g.solar, g.visible);
        assert!((g.solar - solar).abs() <= 0.005, "{window}: solar {} against EnergyPlus's {solar}", g.solar);
        assert!((g.visible - visible).abs() <= 0.005, "{window}: visible {} against EnergyPlus's {visible}", g.visible);
    }
}

/// EnergyPlus 25.2's own angular dependence of simple glazing against `Glazing::solar_at`: the
/// south window of tests/inside/glass.idf over two June weeks in Golden (a high sun, so
/// incidence down to grazing), once with U 2.0 / SHGC 0.6 (EnergyPlus's curve E) and once with
/// U 5.0 / SHGC 0.4 (between curves D and BDCD),
/// its beam transmittance at each hour read from EnergyPlus's output (transmitted beam over
/// incident beam times the 3 m² of glass) at the incidence EnergyPlus reports.
#[test]
fn simple_glazing_angular_transmittance_matches_energyplus() {
    let tmp = Scratch::new("inside", "simple_glazing_angular_transmittance_matches_energyplus");
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inside/glass.idf")).unwrap();
    let outputs = "Output:Variable,Win,Surface Window Transmitted Beam Solar Radiation Rate,Timestep;\n\
                   Output:Variable,Win,Surface Outside Face Incident Beam Solar Radiation Rate per Area,Timestep;\n\
                   Output:Variable,Win,Surface Outside Face Beam Solar Incident Angle Cosine Value,Timestep;\n";
    let two_weeks = text.replace("RunPeriod,R,1,1,,1,1,", "RunPeriod,R,6,1,,6,14,") + outputs;
    assert_ne!(two_weeks, text.clone() + outputs, "the run period was not found");
    for (construction, case) in [("Glass", "curve E"), ("Glass2", "D to BDCD")] {
        let idf = two_weeks
            .replace("FenestrationSurface:Detailed,Win,Window,Glass,", &format!("FenestrationSurface:Detailed,Win,Window,{construction},"));
        let dir = tmp.join(format!("angular-{construction}"));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("glass.idf");
        std::fs::write(&path, &idf).unwrap();
        let run = Command::new(common::energyplus::energyplus())
            .args(["-r", "-w", golden_epw().to_str().unwrap(), "-d", dir.to_str().unwrap(), path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stdout));
        let table = std::fs::read_to_string(dir.join("eplusout.csv")).unwrap();
        let mut lines = table.lines();
        let head: Vec<String> = lines.next().unwrap().split(',').map(|h| h.to_uppercase()).collect();
        let column = |what: &str| head.iter().position(|h| h.starts_with("WIN:") && h.contains(&what.to_uppercase())).unwrap();
        let (transmitted, incident, cosine) = (
            column("Surface Window Transmitted Beam Solar Radiation Rate"),
            column("Incident Beam Solar Radiation Rate per Area"),
            column("Beam Solar Incident Angle Cosine"),
        );
        let loaded = model::load_bytes_all(&[("glass.idf".to_string(), idf.into_bytes())], &LoadOptions::default()).unwrap();
        let ours = rooms(&loaded.energyplus.unwrap(), None).unwrap();
        let win = ours.glazing.iter().find(|g| g.name == "Win").unwrap();
        let (mut worst, mut hours, mut lowest_cos) = (0.0_f64, 0, 1.0_f64);
        for line in lines {
            let f: Vec<f64> = line.split(',').skip(1).map(|v| v.trim().parse().unwrap_or(f64::NAN)).collect();
            let (t, i, c) = (f[transmitted - 1], f[incident - 1], f[cosine - 1]);
            if i.is_nan() || i <= 20.0 {
                continue;
            }
            let theirs = t / (i * 3.0);
            worst = worst.max((win.solar_at(c) - theirs).abs());
            hours += 1;
            lowest_cos = lowest_cos.min(c);
            // The curves matter here: EnergyPlus's value is well below the normal one.
            if c < 0.5 {
                assert!(theirs < 0.9 * win.solar, "{case}: {theirs} at cos {c} is not below the normal {}", win.solar);
            }
        }
        eprintln!("{case}: {hours} hours, cos down to {lowest_cos:.3}, largest |sunlit − EnergyPlus| {worst:.4}");
        assert!(hours > 50 && lowest_cos < 0.4, "{case}: {hours} hours, cos down to {lowest_cos}");
        assert!(worst <= 0.005, "{case}: transmittance differs from EnergyPlus's by up to {worst}");
    }
}
