//! `sunlit sweep` run locally: each variant's CSV equals a separate `sunlit annual`, the summary
//! has a row per variant and surface, a second run counts nothing, a changed line is counted
//! again, bad lines are all reported with their numbers, and a killed sweep leaves no partial file.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
mod sweep_fixture;
use sweep_fixture::*;

use std::path::Path;
use std::time::{Duration, Instant};

use sunlit::export::Schedule;

/// The separate `annual` run of a variant line (the same options on the command line).
fn separate_annual(dir: &Path, out: &Path, d: u32, n: u32) -> Vec<u8> {
    let csv = out.join(format!("d{d}_n{n}.csv"));
    let office = dir.join("office.glb").display().to_string();
    let louvres = dir.join(format!("louvres-{d}.glb")).display().to_string();
    let (csv_s, north) = (csv.display().to_string(), n.to_string());
    let args = [
        "annual",
        &office,
        &louvres,
        "--north",
        &north,
        "--location",
        "46.5,11.35,1",
        "--days-per-year",
        "3",
        "--samples-per-day",
        "5",
        "--resolution",
        "64",
        "--timesteps-per-hour",
        "1",
        "-o",
        &csv_s,
    ];
    let run = sunlit(&args);
    assert!(run.status.success(), "{}", stderr(&run));
    std::fs::read(csv).unwrap()
}

#[test]
fn sweep_equals_separate_runs_resumes_and_recounts_a_changed_line() {
    let dir = scratch("sweep-local");
    let mut lines = variants(&dir);
    let ids = ids(&lines);
    let manifest = write_manifest(&dir, "sweep.jsonl", &lines);
    let out = dir.join("out");
    let (m, o) = (manifest.display().to_string(), out.display().to_string());
    let run = sunlit(&["sweep", &m, "-o", &o, "--jobs", "2"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("counted 6, finished before 0, failed 0"), "{}", stderr(&run));

    // Byte for byte what separate annual runs write.
    let separate = dir.join("separate");
    std::fs::create_dir_all(&separate).unwrap();
    let mut means_differ = std::collections::HashSet::new();
    for d in DEPTHS {
        for n in NORTHS {
            let id = format!("d{d}_n{n}");
            let swept = std::fs::read(out.join(format!("{id}.csv"))).unwrap();
            assert!(swept == separate_annual(&dir, &separate, d, n), "{id}: the sweep's CSV differs from a separate annual run");
            means_differ.insert(String::from_utf8(swept).unwrap().len());
        }
    }

    // summary.csv: a row per variant and surface (the office has 10), with the settings.
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let rows: Vec<&str> = summary.lines().collect();
    assert_eq!(
        rows[0],
        "id,surface,mean_sunlit_fraction,sunup_timesteps,days-per-year,location,models,north,resolution,samples-per-day,timesteps-per-hour"
    );
    assert_eq!(rows.len(), 1 + 6 * 10);
    let win_s1 = |id: &str| -> f64 {
        let row = rows.iter().find(|r| r.starts_with(&format!("{id},WIN_S1,"))).unwrap_or_else(|| panic!("{id} WIN_S1 in {summary}"));
        row.split(',').nth(2).unwrap().parse().unwrap()
    };
    // Deeper louvres shade the south windows more; the means are those of the CSV itself.
    assert!(win_s1("d50_n0") < win_s1("d20_n0"), "{} vs {}", win_s1("d50_n0"), win_s1("d20_n0"));
    let csv = Schedule::from_csv("d20_n0.csv", &std::fs::read_to_string(out.join("d20_n0.csv")).unwrap()).unwrap();
    let location = sunlit::sun::location::Location::parse("46.5,11.35,1").unwrap();
    let col = csv.names.iter().position(|n| n == "WIN_S1").unwrap();
    let mean = sunlit::sweep::summary::means(&csv, &location)[col].mean_fraction;
    assert!((mean - win_s1("d20_n0")).abs() < 1e-6);
    assert!(rows[1].contains("\"46.5,11.35,1\",office.glb;louvres-20.glb,0,64,5,1"), "{}", rows[1]);

    // A second run counts nothing and touches no record.
    let before = record_times(&out, &ids);
    assert!(before.iter().all(Option::is_some));
    let again = sunlit(&["sweep", &m, "-o", &o, "--jobs", "2"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert!(stderr(&again).contains("counted 0, finished before 6, failed 0"), "{}", stderr(&again));
    assert_eq!(record_times(&out, &ids), before);

    // A changed line (d20_n90 turned to 45°) is counted again, and only it.
    let old = std::fs::read(out.join("d20_n90.csv")).unwrap();
    lines[1] = lines[1].replace("\"north\": 90", "\"north\": 45");
    write_manifest(&dir, "sweep.jsonl", &lines);
    let changed = sunlit(&["sweep", &m, "-o", &o]);
    assert!(changed.status.success(), "{}", stderr(&changed));
    assert!(stderr(&changed).contains("counted 1, finished before 5, failed 0"), "{}", stderr(&changed));
    let after = record_times(&out, &ids);
    for (k, id) in ids.iter().enumerate() {
        assert_eq!(after[k] == before[k], id != "d20_n90", "{id}: record rewritten only for the changed line");
    }
    assert_ne!(std::fs::read(out.join("d20_n90.csv")).unwrap(), old, "45° shades differently from 90°");
    assert!(partial_files(&dir).is_empty());
}

/// A variant with an EPW gets irradiation columns in summary.csv: its annual run writes
/// `<id>.summary.json`, whose values are those of a separate `annual --summary` run; a variant
/// without weather leaves them empty; a line may not set `summary` itself.
#[test]
fn summary_has_irradiation_for_variants_with_an_epw() {
    let dir = scratch("sweep-irradiation");
    let lines = variants(&dir);
    std::fs::write(dir.join("site.epw"), varying_epw()).unwrap();
    let with_epw = lines[0].replace("\"location\": \"46.5,11.35,1\"", "\"epw\": \"site.epw\"").replace("d20_n0", "d20_n0_epw");
    let manifest = write_manifest(&dir, "sweep.jsonl", &[with_epw.clone(), lines[3].clone()]);
    let out = dir.join("out");
    let run = sunlit(&["sweep", &manifest.display().to_string(), "-o", &out.display().to_string()]);
    assert!(run.status.success(), "{}", stderr(&run));

    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let rows: Vec<Vec<&str>> = summary.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0][..6],
        ["id", "surface", "mean_sunlit_fraction", "sunup_timesteps", "irradiation_kwh_m2", "unshaded_irradiation_kwh_m2"]
    );
    assert_eq!(rows.len(), 1 + 2 * 10);

    // The same run by hand, with its own summary.
    let separate = dir.join("separate.json");
    let csv = dir.join("separate.csv");
    let (office, louvres, epw) = (dir.join("office.glb"), dir.join("louvres-20.glb"), dir.join("site.epw"));
    let args = [
        "annual",
        &office.display().to_string(),
        &louvres.display().to_string(),
        "--north",
        "0",
        "--epw",
        &epw.display().to_string(),
        "--days-per-year",
        "3",
        "--samples-per-day",
        "5",
        "--resolution",
        "64",
        "--timesteps-per-hour",
        "1",
        "-o",
        &csv.display().to_string(),
        "--summary",
        &separate.display().to_string(),
    ];
    let annual = sunlit(&args);
    assert!(annual.status.success(), "{}", stderr(&annual));
    let by_hand: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&separate).unwrap()).unwrap();
    let mut shaded = 0;
    for s in by_hand["surfaces"].as_array().unwrap() {
        let name = s["name"].as_str().unwrap();
        let row = rows.iter().find(|r| r[0] == "d20_n0_epw" && r[1] == name).unwrap_or_else(|| panic!("{name} in {summary}"));
        let (irradiation, unshaded) = (s["irradiation"].as_f64().unwrap(), s["unshaded_irradiation"].as_f64().unwrap());
        assert!((row[4].parse::<f64>().unwrap() - irradiation).abs() < 1e-4, "{name}: {} vs {irradiation}", row[4]);
        assert!((row[5].parse::<f64>().unwrap() - unshaded).abs() < 1e-4, "{name}: {} vs {unshaded}", row[5]);
        shaded += usize::from(irradiation < unshaded - 1.0);
    }
    assert!(shaded >= 2, "the louvres shade some surfaces: {summary}");
    // The variant with a location only: empty irradiation cells.
    assert!(rows.iter().filter(|r| r[0] == "d50_n0").all(|r| r[4].is_empty() && r[5].is_empty()), "{summary}");
    assert!(out.join("d20_n0_epw.summary.json").is_file());

    // A second run finds both finished (the summary JSON is one of the outputs it checks).
    let again = sunlit(&["sweep", &manifest.display().to_string(), "-o", &out.display().to_string()]);
    assert!(stderr(&again).contains("counted 0, finished before 2, failed 0"), "{}", stderr(&again));

    let bad = write_manifest(&dir, "bad.jsonl", &[with_epw.replace("\"north\": 0", "\"north\": 0, \"summary\": \"x.json\"")]);
    let refused = sunlit(&["sweep", &bad.display().to_string(), "-o", &dir.join("out2").display().to_string()]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(stderr(&refused).contains("line 1: summary is set by the sweep"), "{}", stderr(&refused));
}

#[test]
fn every_bad_line_is_reported_with_its_number_before_counting() {
    let dir = scratch("sweep-bad");
    let good = variants(&dir).remove(0);
    let lines: Vec<String> = vec![
        good.clone(),
        good.replace("\"north\": 0", "\"nrth\": 0"),
        good.clone(),
        good.replace("d20_n0", "d20/../x"),
        good.replace("office.glb", "missing.glb").replace("d20_n0", "m"),
        good.replace("\"north\": 0", "\"north\": \"east\"").replace("d20_n0", "e"),
        good.replace("\"days-per-year\": 3", "\"days-per-year\": 1").replace("d20_n0", "few"),
        "{not json".into(),
        good.replace("46.5,11.35,1", "146.5,11.35,1").replace("d20_n0", "lat"),
    ];
    let manifest = write_manifest(&dir, "bad.jsonl", &lines);
    let out = dir.join("out");
    let run = sunlit(&["sweep", &manifest.display().to_string(), "-o", &out.display().to_string()]);
    let err = stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in [
        "8 bad lines, nothing run",
        "line 2: unknown key 'nrth'",
        "line 3: id 'd20_n0' is already used on line 1",
        "line 4: id 'd20/../x' is not a safe file name",
        "line 5: models: no file",
        "line 6: invalid value 'east' for '--north",
        // (the parameter's name depends on whether the library names flags or parameters)
        "line 7: invalid ",
        "1 is outside 3..=365",
        "line 8: not JSON",
        "line 9: invalid ",
        "latitude 146.5 is outside",
    ] {
        assert!(err.contains(needle), "expected '{needle}' in: {err}");
    }
    assert!(!err.contains("line 1:"), "{err}");
    assert!(!out.join("d20_n0.csv").exists(), "nothing counted, not even the good line");
}

/// Processes whose command line mentions `needle` (the sweep's children).
fn processes_mentioning(needle: &str) -> usize {
    std::fs::read_dir("/proc")
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().chars().all(|c| c.is_ascii_digit()))
        .filter(|e| std::fs::read(e.path().join("cmdline")).is_ok_and(|c| String::from_utf8_lossy(&c).contains(needle)))
        .count()
}

#[test]
fn a_killed_sweep_loses_only_the_variants_in_flight_and_leaves_no_partial_file() {
    let dir = scratch("sweep-kill");
    // More samples a variant, so the kill lands while variants are counting.
    let lines: Vec<String> = variants(&dir).iter().map(|l| l.replace("\"samples-per-day\": 5", "\"samples-per-day\": 30")).collect();
    let ids = ids(&lines);
    let manifest = write_manifest(&dir, "kill.jsonl", &lines);
    let out = dir.join("out");
    let (m, o) = (manifest.display().to_string(), out.display().to_string());
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args(["sweep", &m, "-o", &o, "--jobs", "2"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait for the first finished variant, then SIGKILL the sweep with the next ones in flight.
    let start = Instant::now();
    while record_times(&out, &ids).iter().all(Option::is_none) {
        assert!(start.elapsed() < Duration::from_secs(300), "no variant finished in 300 s");
        assert!(child.try_wait().unwrap().is_none(), "the sweep ended before it could be killed");
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // Its annual children get SIGTERM with it, remove their temporary files and exit.
    let start = Instant::now();
    while processes_mentioning(&o) > 0 {
        assert!(start.elapsed() < Duration::from_secs(30), "annual runs outlived the killed sweep");
        std::thread::sleep(Duration::from_millis(100));
    }
    assert!(partial_files(&dir).is_empty(), "{:?}", partial_files(&dir));
    let done: Vec<&String> = ids.iter().zip(record_times(&out, &ids)).filter(|(_, t)| t.is_some()).map(|(id, _)| id).collect();
    assert!(!done.is_empty() && done.len() < ids.len(), "killed mid-sweep: {done:?}");
    // Every CSV there is whole (a year of rows, read back).
    for id in &ids {
        let path = out.join(format!("{id}.csv"));
        if path.exists() {
            Schedule::from_csv(id, &std::fs::read_to_string(&path).unwrap()).unwrap();
        }
    }
    // The next run counts exactly what was not finished.
    let rerun = sunlit(&["sweep", &m, "-o", &o, "--jobs", "2"]);
    assert!(rerun.status.success(), "{}", stderr(&rerun));
    let expected = format!("counted {}, finished before {}, failed 0", ids.len() - done.len(), done.len());
    assert!(stderr(&rerun).contains(&expected), "{expected} in {}", stderr(&rerun));
}
