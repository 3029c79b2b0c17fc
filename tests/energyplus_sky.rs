//! sunlit's sky against EnergyPlus 25.2's own (installed by `npm test` into .venv-ep, or wherever
//! `ENERGYPLUS` points; these never skip):
//! - per surface, the diffuse shading ratios EnergyPlus computes once per run over its 144 sky
//!   patches (`Debug Surface Solar Shading Model DifShdgRatioIsoSky` / `…DifShdgRatioHoriz`)
//!   against the summary's `energyplus_iso_sky_ratio` / `energyplus_horizon_ratio`, |Δ| ≤ 0.005, on
//!   the committed test files (overhangs, fins, detached shading; a turned building) and the
//!   round-trip office with louvres;
//! - on the office's unshaded surfaces (both ratios 1 in EnergyPlus), the year's incident sky
//!   diffuse and ground-reflected solar EnergyPlus reports (`Surface Outside Face Incident Sky
//!   Diffuse Solar Radiation Rate per Area`, `… Ground Diffuse …`) against the summary's
//!   `sky_diffuse` and `ground_reflected`: the same Perez 1990 model from the same weather, written
//!   by other people. Timestep 1 in both, so that EnergyPlus's sun is at each hour's middle and it
//!   takes each hour's weather as it is.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde_json::Value;
use sunlit::model::office_idf::{Shading, office_idf};

mod common;
use common::Scratch;
use common::energyplus::{columns, energyplus};

const ISO: &str = "Debug Surface Solar Shading Model DifShdgRatioIsoSky";
const HORIZ: &str = "Debug Surface Solar Shading Model DifShdgRatioHoriz";
const SKY: &str = "Surface Outside Face Incident Sky Diffuse Solar Radiation Rate per Area";
const GROUND: &str = "Surface Outside Face Incident Ground Diffuse Solar Radiation Rate per Area";
/// EnergyPlus's ground reflectance when a model has no Site:GroundReflectance; sunlit is given it.
const ALBEDO: &str = "0.2";

fn weather(name: &str) -> PathBuf {
    energyplus().parent().unwrap().join("WeatherData").join(name)
}
const CHICAGO: &str = "USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw";
const GOLDEN: &str = "USA_CO_Golden-NREL.724666_TMY3.epw";

/// A scratch folder for one test's runs: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> Scratch {
    Scratch::new("epsky", name)
}

fn testfile(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/energyplus_testfiles").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Writes `text` plus the ratio (and incident) outputs as DIR/NAME.idf, runs EnergyPlus with
/// `epw` into DIR/NAME and returns eplusout.csv's columns and the model's path.
fn run_energyplus(dir: &Path, name: &str, text: &str, epw: &str) -> (HashMap<String, Vec<f64>>, PathBuf) {
    let idf = dir.join(format!("{name}.idf"));
    let outputs = [ISO, HORIZ, SKY, GROUND].map(|v| format!("Output:Variable, *, {v}, RunPeriod;\n")).concat();
    std::fs::write(&idf, format!("{text}\n{outputs}")).unwrap();
    let out = dir.join(name);
    let start = Instant::now();
    let status = Command::new(energyplus()).arg("-r").arg("-w").arg(weather(epw)).arg("-d").arg(&out).arg(&idf).output().unwrap();
    let err = std::fs::read_to_string(out.join("eplusout.err")).unwrap_or_default();
    let severe = err.lines().filter(|l| l.contains("** Severe  **") || l.contains("**  Fatal  **")).count();
    assert!(status.status.success() && severe == 0, "EnergyPlus on {}:\n{err}", idf.display());
    eprintln!("EnergyPlus {name}: {:.1} s", start.elapsed().as_secs_f64());
    (columns(&out.join("eplusout.csv")), idf)
}

/// `sunlit annual IDF --epw … --albedo 0.2 --summary`: per upper-cased surface name, its fields.
fn sunlit_summary(idf: &Path, dir: &Path, epw: &str) -> HashMap<String, Value> {
    let (csv, summary) = (dir.join("shading.csv"), dir.join("summary.json"));
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .arg("annual")
        .arg(idf)
        .arg("--epw")
        .arg(weather(epw))
        .args(["--albedo", ALBEDO, "-o"])
        .arg(&csv)
        .arg("--summary")
        .arg(&summary)
        .output()
        .unwrap();
    assert!(out.status.success(), "sunlit annual {}: {}", idf.display(), String::from_utf8_lossy(&out.stderr));
    eprintln!("sunlit annual {}: {:.1} s", idf.display(), start.elapsed().as_secs_f64());
    let value: Value = serde_json::from_slice(&std::fs::read(&summary).unwrap()).unwrap();
    value["surfaces"].as_array().unwrap().iter().map(|s| (s["name"].as_str().unwrap().to_uppercase(), s.clone())).collect()
}

/// EnergyPlus's RunPeriod value of `variable` for surface `key` (the last environment's: the
/// ratios are the same in every one).
fn ep_value(cols: &HashMap<String, Vec<f64>>, key: &str, variable: &str) -> Option<f64> {
    let prefix = format!("{key}:{}", variable.to_uppercase());
    cols.iter().find(|(k, _)| k.starts_with(&prefix)).and_then(|(_, v)| v.last().copied())
}

fn field(surface: &Value, key: &str, name: &str) -> f64 {
    surface[key].as_f64().unwrap_or_else(|| panic!("{name}: no number '{key}' in sunlit's summary: {surface}"))
}

/// Every sunlit surface's ratios against EnergyPlus's; returns (surfaces, max |Δ| iso, max |Δ| horizon).
fn compare_ratios(label: &str, ours: &HashMap<String, Value>, theirs: &HashMap<String, Vec<f64>>) -> (usize, f64, f64) {
    let mut names: Vec<&String> = ours.keys().collect();
    names.sort();
    let (mut worst_iso, mut worst_horiz, mut failures) = (0.0f64, 0.0f64, Vec::new());
    for name in &names {
        let s = &ours[*name];
        let ep_iso = ep_value(theirs, name, ISO).unwrap_or_else(|| panic!("{label}: EnergyPlus reports no {ISO} for {name}"));
        let ep_horiz = ep_value(theirs, name, HORIZ).unwrap();
        let (iso, horiz) = (field(s, "energyplus_iso_sky_ratio", name), field(s, "energyplus_horizon_ratio", name));
        eprintln!("{label} {name:>32}: iso sky {iso:.4} vs EnergyPlus {ep_iso:.4}; horizon {horiz:.4} vs {ep_horiz:.4}");
        worst_iso = worst_iso.max((iso - ep_iso).abs());
        worst_horiz = worst_horiz.max((horiz - ep_horiz).abs());
        if (iso - ep_iso).abs() > 0.005 || (horiz - ep_horiz).abs() > 0.005 {
            failures.push(format!("{name}: iso sky {iso:.4} vs {ep_iso:.4}, horizon {horiz:.4} vs {ep_horiz:.4}"));
        }
    }
    eprintln!("{label}: {} surfaces, max |Δ| iso sky {worst_iso:.4}, horizon {worst_horiz:.4}", names.len());
    assert!(failures.is_empty(), "{label}: ratios off by more than 0.005:\n{}", failures.join("\n"));
    (names.len(), worst_iso, worst_horiz)
}

/// A test file as EnergyPlus ships it (4ZoneWithShading_Simple_1 runs its design days only: the
/// ratios are computed once per run, whatever the run period).
#[test]
fn test_file_ratios_match_energyplus() {
    for (file, epw) in [("4ZoneWithShading_Simple_1.idf", CHICAGO), ("5ZoneAirCooled.idf", CHICAGO)] {
        let dir = scratch(file.trim_end_matches(".idf"));
        let (theirs, idf) = run_energyplus(&dir, "energyplus", &testfile(file), epw);
        let ours = sunlit_summary(&idf, &dir, epw);
        let (count, _, _) = compare_ratios(file, &ours, &theirs);
        assert!(count >= 10, "{file}: only {count} surfaces compared");
    }
}

/// The round-trip office with ten louvres over its south window, at one timestep per hour: the
/// ratios on every surface, and on the unshaded ones the year's incident sky diffuse and ground
/// reflected solar.
#[test]
fn office_ratios_and_unshaded_diffuse_match_energyplus() {
    let dir = scratch("office");
    let text = office_idf(10, false, Shading::PolygonClipping);
    assert!(text.contains("Timestep, 4;"));
    let text = text.replacen("Timestep, 4;", "Timestep, 1;", 1);
    let (theirs, idf) = run_energyplus(&dir, "energyplus", &text, GOLDEN);
    let ours = sunlit_summary(&idf, &dir, GOLDEN);
    compare_ratios("office", &ours, &theirs);
    let hours = 8760.0;
    let (mut unshaded, mut failures) = (0, Vec::new());
    let mut names: Vec<&String> = ours.keys().collect();
    names.sort();
    for name in names {
        let ratios = [ep_value(&theirs, name, ISO).unwrap(), ep_value(&theirs, name, HORIZ).unwrap()];
        if ratios.iter().any(|r| (r - 1.0).abs() > 1e-9) {
            continue;
        }
        unshaded += 1;
        let s = &ours[name];
        // RunPeriod values of a rate are its mean over the year's hours: × 8760 h / 1000 is kWh/m².
        let ep_sky = ep_value(&theirs, name, SKY).unwrap() * hours / 1000.0;
        let ep_ground = ep_value(&theirs, name, GROUND).unwrap() * hours / 1000.0;
        let (sky, ground) = (field(s, "sky_diffuse", name), field(s, "ground_reflected", name));
        let dsky = 100.0 * (sky / ep_sky - 1.0);
        let dground = if ep_ground > 0.0 { 100.0 * (ground / ep_ground - 1.0) } else { 0.0 };
        eprintln!(
            "office {name:>8} (unshaded): sky diffuse {sky:.1} vs EnergyPlus {ep_sky:.1} kWh/m² ({dsky:+.2}%); ground {ground:.1} vs {ep_ground:.1} ({dground:+.2}%)"
        );
        if dsky.abs() > 1.0 {
            failures.push(format!("{name}: sky diffuse {sky:.1} vs EnergyPlus {ep_sky:.1} kWh/m² ({dsky:+.2}%)"));
        }
        if dground.abs() > 1.5 && (ground - ep_ground).abs() >= 0.5 {
            failures.push(format!("{name}: ground {ground:.1} vs EnergyPlus {ep_ground:.1} kWh/m² ({dground:+.2}%)"));
        }
    }
    assert!(failures.is_empty(), "office, unshaded surfaces:\n{}", failures.join("\n"));
    assert!(unshaded >= 3, "only {unshaded} unshaded surfaces (the office's roof, east, north and west walls expected)");
}
