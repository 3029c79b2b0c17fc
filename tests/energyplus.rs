//! The EnergyPlus round trip against the real thing: EnergyPlus 25.2 (installed by `npm test`
//! into .venv-ep, or wherever `ENERGYPLUS` points). These never skip: without EnergyPlus they fail
//! and say how to get it.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use sunlit::model::office_idf::{Shading, office_idf};

mod common;
use common::Scratch;
use common::energyplus::{columns, energyplus, leap_weather};

fn weather() -> PathBuf {
    energyplus().parent().unwrap().join("WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw")
}

/// A scratch folder for one test's runs (an annual EnergyPlus run writes tens of MB): removed
/// when the test passes, kept when it fails.
fn scratch(name: &str) -> Scratch {
    Scratch::new("ep", name)
}

/// Runs EnergyPlus (with ReadVarsESO) and returns its .err text.
fn run_energyplus(idf: &Path, out: &Path) -> String {
    let status = Command::new(energyplus()).arg("-r").arg("-w").arg(weather()).arg("-d").arg(out).arg(idf).output().unwrap();
    let err = std::fs::read_to_string(out.join("eplusout.err")).unwrap_or_default();
    assert!(status.status.success() || err.contains("Severe"), "EnergyPlus failed to start: {}", String::from_utf8_lossy(&status.stderr));
    err
}

fn severe_count(err: &str) -> usize {
    err.lines().filter(|l| l.contains("** Severe  **") || l.contains("**  Fatal  **")).count()
}

/// A fresh folder with the generated office as `office.idf`, run by EnergyPlus's own
/// PolygonClipping into `clipping/`; returns the folder, the model and the .err text.
fn clipping_run(name: &str, louvres: usize, concave: bool) -> (Scratch, PathBuf, String) {
    let dir = scratch(name);
    let idf = dir.join("office.idf");
    std::fs::write(&idf, office_idf(louvres, concave, Shading::PolygonClipping)).unwrap();
    let err = run_energyplus(&idf, &dir.join("clipping"));
    (dir, idf, err)
}

/// `sunlit annual IDF --epw (Golden) -o DIR/shading.csv --idf-out DIR/hooked.idf EXTRA…`; returns
/// the CSV's and the hooked model's paths.
fn sunlit_annual(idf: &Path, dir: &Path, extra: &[&str]) -> (PathBuf, PathBuf) {
    let (csv, hooked) = (dir.join("shading.csv"), dir.join("hooked.idf"));
    let mut command = Command::new(env!("CARGO_BIN_EXE_sunlit"));
    command.arg("annual").arg(idf).arg("--epw").arg(weather()).arg("-o").arg(&csv).arg("--idf-out").arg(&hooked).args(extra);
    let out = command.output().unwrap();
    assert!(out.status.success(), "sunlit annual {}: {}", idf.display(), String::from_utf8_lossy(&out.stderr));
    (csv, hooked)
}

/// The column of eplusout.csv for `key:variable` (case-insensitive, frequency ignored).
fn output<'a>(cols: &'a HashMap<String, Vec<f64>>, key: &str, variable: &str) -> &'a [f64] {
    let prefix = format!("{}:{}", key.to_uppercase(), variable.to_uppercase());
    let (_, v) = cols.iter().find(|(k, _)| k.starts_with(&prefix)).unwrap_or_else(|| panic!("no output {prefix}"));
    v
}

/// PolygonClipping on the convex louvre office, then sunlit's CSV for the same model, then
/// EnergyPlus again with sunlit's fractions hooked in.
#[test]
fn round_trip_with_polygon_clipping_as_reference() {
    let (dir, idf, err) = clipping_run("roundtrip", 10, false);
    let reference = dir.join("clipping");
    assert_eq!(severe_count(&err), 0, "{err}");

    // 1. sunlit's CSV against the sunlit fractions EnergyPlus reports (and uses) with its own
    // clipping. Not eplusshading.csv: EnergyPlus writes a day's rows there at the start of the
    // day, so they hold the previous day's values (docs/energyplus-fidelity.md).
    let (csv, hooked) = sunlit_annual(&idf, &dir, &[]);
    let ours = columns(&csv);
    let reported = columns(&reference.join("eplusout.csv"));
    let theirs: HashMap<String, Vec<f64>> = ["WALL_S", "WALL_E", "WALL_N", "WALL_W", "ROOF", "WIN_S", "WIN_E"]
        .iter()
        .map(|n| (n.to_string(), output(&reported, n, "Surface Outside Face Sunlit Fraction").to_vec()))
        .collect();
    // Sun-up timesteps: the unobstructed flat roof is lit in either run.
    let sun_up: Vec<bool> = ours["ROOF"].iter().zip(&theirs["ROOF"]).map(|(a, b)| *a > 0.0 || *b > 0.0).collect();
    assert!(sun_up.iter().filter(|u| **u).count() > 15_000);
    for name in ["WALL_S", "WALL_E", "WALL_N", "WALL_W", "ROOF", "WIN_S", "WIN_E"] {
        let (a, b) = (&ours[name], &theirs[name]);
        assert_eq!(a.len(), b.len(), "{name}: rows");
        let diffs: Vec<(f64, bool)> =
            a.iter().zip(b).zip(&sun_up).filter(|(_, up)| **up).map(|((x, y), _)| ((x - y).abs(), *x > 0.0 || *y > 0.0)).collect();
        let mean = diffs.iter().map(|d| d.0).sum::<f64>() / diffs.len() as f64;
        let lit: Vec<f64> = diffs.iter().filter(|d| d.1).map(|d| d.0).collect();
        let lit_mean = lit.iter().sum::<f64>() / lit.len().max(1) as f64;
        println!(
            "{name}: mean |sunlit − PolygonClipping| {mean:.4} over {} sun-up timesteps ({lit_mean:.4} over the {} lit)",
            diffs.len(),
            lit.len()
        );
        assert!(lit.len() > 1000 && mean <= 0.02, "{name}: mean {mean}");
    }

    // 1b. Both say the same timesteps are dark (sun down, or behind the surface), sunrise, sunset
    // and grazing sun included: sunlit takes EnergyPlus's shading sun (the calendar day's
    // declination and equation of time, at each timestep's end). Unshaded surfaces, so only the
    // sun decides.
    for name in ["ROOF", "WALL_E", "WALL_W", "WALL_N", "WIN_E"] {
        let differ = ours[name].iter().zip(&theirs[name]).filter(|(a, b)| (**a > 0.0) != (**b > 0.0)).count();
        println!("{name}: {differ} timesteps lit in one and dark in the other");
        assert_eq!(differ, 0, "{name}: sunlit and EnergyPlus disagree on which timesteps are dark");
    }

    // 2. EnergyPlus with sunlit's fractions: no severe error, no "not found", the fractions used.
    let run = dir.join("hooked");
    let err = run_energyplus(&hooked, &run);
    assert_eq!(severe_count(&err), 0, "{err}");
    assert!(!err.to_lowercase().contains("not found"), "{err}");
    let out = columns(&run.join("eplusout.csv"));
    let used = output(&out, "WIN_S", "Surface Outside Face Sunlit Fraction");
    let given = &ours["WIN_S"];
    assert_eq!(used.len(), given.len());
    assert!(used.iter().any(|v| *v > 0.0 && *v < 0.99), "EnergyPlus's WIN_S fractions are not all ones or zeros");
    let worst = used.iter().zip(given).filter(|(u, _)| **u > 0.0).map(|(u, g)| (u - g).abs()).fold(0.0, f64::max);
    println!("WIN_S: EnergyPlus used sunlit's fractions, max |difference| {worst:.2e}");
    assert!(worst < 1e-4, "EnergyPlus did not use the CSV's WIN_S values (max difference {worst})");

    // 3. The window's annual transmitted beam+diffuse solar within 2% of PolygonClipping's.
    let clipping = columns(&reference.join("eplusout.csv"));
    let variable = "Enclosure Windows Total Transmitted Solar Radiation Energy";
    let (a, b) = (output(&out, "OFFICE", variable)[0], output(&clipping, "OFFICE", variable)[0]);
    println!("annual window transmitted solar: sunlit {a:.4e} J, PolygonClipping {b:.4e} J ({:+.2}%)", 100.0 * (a - b) / b);
    assert!(((a - b) / b).abs() <= 0.02, "{a} vs {b}");
}

/// The Imported form: the CSV carries every column of EnergyPlus's own eplusshading.csv (shading
/// surfaces and their Mir- back faces included) and EnergyPlus reads it without a severe error.
/// (25.2 then ignores the values, the name-lookup bug this form is not the default for.)
#[test]
fn imported_form_has_every_column_energyplus_writes() {
    let (dir, idf, _) = clipping_run("imported", 3, false);
    let reference = dir.join("clipping");
    let quick = ["--hook", "imported", "--days-per-year", "3", "--samples-per-day", "3", "--resolution", "64", "--refine", "1"];
    let (csv, hooked) = sunlit_annual(&idf, &dir, &quick);
    let header = |p: &Path| -> Vec<String> {
        let text = std::fs::read_to_string(p).unwrap();
        let mut names: Vec<String> =
            text.lines().next().unwrap().split(',').skip(1).filter(|n| !n.is_empty()).map(|n| n.to_uppercase()).collect();
        names.sort();
        names
    };
    assert_eq!(header(&csv), header(&reference.join("eplusshading.csv")));
    // The louvres are horizontal plates facing up: the top of the highest is lit most of the time
    // the sun is up (the wall shades it when the sun is behind the building), their undersides
    // (the Mir- faces) never, in both files. A 3×3-sample year at 64² is coarse near the ends of
    // the day, so the counts of mostly lit timesteps agree to a few percent, not exactly.
    let (ours, theirs) = (columns(&csv), columns(&reference.join("eplusshading.csv")));
    let lit = |v: &[f64]| v.iter().filter(|x| **x > 0.5).count() as f64;
    let (a, b) = (lit(&ours["LOUVER_2"]), lit(&theirs["LOUVER_2"]));
    println!("LOUVER_2 mostly lit in {a} timesteps (sunlit), {b} (EnergyPlus) of {}", ours["LOUVER_2"].len());
    assert!(b > 12_000.0 && (a - b).abs() < 0.04 * b, "LOUVER_2 mostly lit: sunlit {a} vs EnergyPlus {b} timesteps");
    assert!(ours["MIR-LOUVER_0"].iter().chain(&theirs["MIR-LOUVER_0"]).all(|v| *v == 0.0));
    // The header rules a reader of this form relies on whatever its EnergyPlus version (PR #11445
    // upper-cases schedule names on import, so names match case-insensitively): the time stamp
    // column first, then one column per surface (any order: they are looked up by name), each
    // shading surface with its `Mir-` back face spelled so, and a full year of rows (8760 × 4 here) with the same stamps.
    let text = std::fs::read_to_string(&csv).unwrap();
    let first: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    assert_eq!(first[0], "Surface Name");
    for name in first.iter().filter(|n| n.to_uppercase().starts_with("LOUVER_")) {
        assert!(first.contains(&format!("Mir-{name}").as_str()), "{name} has its Mir- column: {first:?}");
    }
    assert!(ours.values().chain(theirs.values()).all(|v| v.len() == 8760 * 4));
    let reference = std::fs::read_to_string(reference.join("eplusshading.csv")).unwrap();
    let stamps = |t: &str| t.lines().skip(1).map(|l| l.split(',').next().unwrap().trim().to_string()).collect::<Vec<_>>();
    assert_eq!(stamps(&text), stamps(&reference));
    let err = run_energyplus(&hooked, &dir.join("hooked"));
    assert_eq!(severe_count(&err), 0, "{err}");
    assert!(std::fs::read_to_string(&hooked).unwrap().contains("Schedule:File:Shading,"));
}

/// A concave caster: EnergyPlus's clipping cannot cast it; with sunlit's fractions it runs and shades.
#[test]
fn concave_shading_runs_with_sunlit_fractions() {
    let (dir, idf, clipping_err) = clipping_run("concave", 0, true);
    let refusal = clipping_err.lines().find(|l| l.contains("Severe") && l.contains("non-convex"));
    println!("PolygonClipping on the L-shaped canopy: {}", refusal.unwrap_or("(accepted)").trim());
    assert!(refusal.is_some(), "EnergyPlus's own clipping refuses the concave caster:\n{clipping_err}");
    let (_, hooked) = sunlit_annual(&idf, &dir, &[]);
    let run = dir.join("hooked");
    let err = run_energyplus(&hooked, &run);
    assert_eq!(severe_count(&err), 0, "{err}");
    let out = columns(&run.join("eplusout.csv"));
    let used = output(&out, "WIN_E", "Surface Outside Face Sunlit Fraction");
    let shaded = used.iter().filter(|v| **v > 0.0 && **v < 0.95).count();
    assert!(shaded > 500, "the canopy shades the east window part of the time: {shaded} timesteps");
}

/// Windows off their wall's plane, as EnergyPlus places them: WIN_S set back 0.15 m into the
/// wall (a reveal, whose sides shade it) and WIN_E 0.1 m proud of it (drawn in the wall's plane).
/// Both are cut out of their walls. Against EnergyPlus's own clipping of the same model.
#[test]
fn inset_and_proud_windows_follow_energyplus() {
    let dir = scratch("inset");
    let office = office_idf(3, false, Shading::PolygonClipping);
    let set_back = "  2,0.15,2.5,\n  2,0.15,1,\n  8,0.15,1,\n  8,0.15,2.5;";
    let proud = "  10.1,2,2.4,\n  10.1,2,1,\n  10.1,6,1,\n  10.1,6,2.4;";
    let text = office.replacen("  2,0,2.5,\n  2,0,1,\n  8,0,1,\n  8,0,2.5;", set_back, 1).replacen(
        "  10,2,2.4,\n  10,2,1,\n  10,6,1,\n  10,6,2.4;",
        proud,
        1,
    );
    assert!(text.contains(set_back) && text.contains(proud));
    let idf = dir.join("office.idf");
    std::fs::write(&idf, &text).unwrap();
    let err = run_energyplus(&idf, &dir.join("clipping"));
    assert_eq!(severe_count(&err), 0, "{err}");
    let (csv, hooked) = sunlit_annual(&idf, &dir, &["--resolution", "256"]);
    let (ours, theirs) = (columns(&csv), columns(&dir.join("clipping/eplusshading.csv")));
    // The reveal's own shade: EnergyPlus's WIN_S is darker than a flush window's, but lit.
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(mean(&theirs["WIN_S"]) > 0.1, "EnergyPlus lights the set-back window");
    for name in ["WIN_S", "WIN_E", "WALL_S", "WALL_E"] {
        let (a, b) = (&ours[name], &theirs[name]);
        assert_eq!(a.len(), b.len(), "{name}: rows");
        let lit: Vec<f64> = a.iter().zip(b).filter(|(x, y)| **x > 0.0 || **y > 0.0).map(|(x, y)| (x - y).abs()).collect();
        let m = mean(&lit);
        println!("{name}: mean |sunlit − EnergyPlus| {m:.4} over {} lit timesteps (means {:.4} vs {:.4})", lit.len(), mean(a), mean(b));
        assert!(lit.len() > 1000 && m <= 0.02, "{name}: mean |Δ| {m}");
    }
    let err = run_energyplus(&hooked, &dir.join("hooked"));
    assert_eq!(severe_count(&err), 0, "{err}");
}

/// The hooked model names its CSV so that EnergyPlus finds it wherever it is started from and
/// wherever the model is moved to: here the model is copied to another folder and EnergyPlus is
/// started from a third, with a relative path to the model.
#[test]
fn hooked_model_finds_its_csv_from_any_folder() {
    let dir = scratch("anywhere");
    let idf = dir.join("office.idf");
    std::fs::write(&idf, office_idf(2, false, Shading::None)).unwrap();
    let quick = ["--days-per-year", "3", "--samples-per-day", "3", "--resolution", "64", "--refine", "1"];
    let (csv, hooked) = sunlit_annual(&idf, &dir, &quick);
    let (moved, start) = (dir.join("moved"), dir.join("start"));
    std::fs::create_dir_all(&moved).unwrap();
    std::fs::create_dir_all(&start).unwrap();
    std::fs::copy(&hooked, moved.join("hooked.idf")).unwrap();
    let out = Command::new(energyplus())
        .current_dir(&start)
        .args(["-r", "-w"])
        .arg(weather())
        .args(["-d", "run", "../moved/hooked.idf"])
        .output()
        .unwrap();
    let err = std::fs::read_to_string(start.join("run/eplusout.err")).unwrap_or_default();
    assert!(out.status.success() && severe_count(&err) == 0, "{err}");
    let used = columns(&start.join("run/eplusout.csv"));
    let used = output(&used, "WIN_S", "Surface Outside Face Sunlit Fraction");
    let given = &columns(&csv)["WIN_S"];
    let worst = used.iter().zip(given).filter(|(u, _)| **u > 0.0).map(|(u, g)| (u - g).abs()).fold(0.0, f64::max);
    assert!(used.iter().any(|v| *v > 0.0 && *v < 0.99) && worst < 1e-4, "EnergyPlus did not use the CSV (max |Δ| {worst})");
}

/// A leap year: a RunPeriod in 2020 with an actual-year 2020 weather file. sunlit writes
/// 8784 × 4 rows and hooks them as 8784 hours; EnergyPlus runs 366 days without a severe error
/// and uses the CSV's fractions on every lit timestep, Feb 29 and Dec 31 included.
#[test]
fn leap_year_runs_366_days_in_energyplus() {
    let dir = scratch("leap");
    let epw = leap_weather(&weather(), &dir);
    let office = office_idf(2, false, Shading::None);
    let year = "RunPeriod, YEAR, 1, 1, 2020, 12, 31, 2020, , No, No, No, Yes, Yes, No;";
    let text = office.replacen("RunPeriod, YEAR, 1, 1, , 12, 31, , , No, No, No, Yes, Yes, No;", year, 1);
    assert!(text.contains(year));
    let idf = dir.join("office.idf");
    std::fs::write(&idf, &text).unwrap();
    let (csv, hooked) = (dir.join("shading.csv"), dir.join("hooked.idf"));
    let quick = ["--days-per-year", "5", "--samples-per-day", "5", "--resolution", "64", "--refine", "1"];
    let out = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .arg("annual")
        .arg(&idf)
        .arg("--epw")
        .arg(&epw)
        .arg("-o")
        .arg(&csv)
        .arg("--idf-out")
        .arg(&hooked)
        .args(quick)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && stderr.contains("year: 2020"), "{stderr}");
    let given = &columns(&csv)["WIN_S"];
    assert_eq!(given.len(), 8784 * 4);
    let csv_text = std::fs::read_to_string(&csv).unwrap();
    assert!(csv_text.contains("\n 02/29 12:00,") && csv_text.trim_end().lines().last().unwrap().starts_with(" 12/31 24:00,"));
    let run = dir.join("hooked");
    let status = Command::new(energyplus()).arg("-r").arg("-w").arg(&epw).arg("-d").arg(&run).arg(&hooked).output().unwrap();
    let err = std::fs::read_to_string(run.join("eplusout.err")).unwrap_or_default();
    assert!(status.status.success() && severe_count(&err) == 0, "{err}");
    let used = columns(&run.join("eplusout.csv"));
    let used = output(&used, "WIN_S", "Surface Outside Face Sunlit Fraction");
    assert_eq!(used.len(), 8784 * 4, "EnergyPlus ran 366 days");
    let day = |d: usize| (d - 1) * 96..d * 96;
    for (label, rows) in [("Feb 29", day(60)), ("Dec 31", day(366)), ("year", 0..8784 * 4)] {
        let lit: Vec<usize> = rows.filter(|&r| used[r] > 0.0).collect();
        let worst = lit.iter().map(|&r| (used[r] - given[r]).abs()).fold(0.0, f64::max);
        println!("{label}: {} lit timesteps, max |EnergyPlus − CSV| {worst:.2e}", lit.len());
        assert!(lit.len() >= 20 && lit.iter().any(|&r| used[r] < 0.99) && worst < 1e-4, "{label}: max |Δ| {worst}");
    }
}
