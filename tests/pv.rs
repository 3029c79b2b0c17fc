//! What PV tools read (`annual --pvlib`, `--sam`), read by the tools themselves: pvlib 0.16.1 and
//! NREL-PySAM 7.1.1 (`SUNLIT_PV=1 . scripts/setup.sh` installs them in .venv-pv; without them the
//! test says so and skips). tests/pv/check.py loads the files as docs/district.md shows and
//! reports what reached the tools:
//! - pvlib: the CSV's index is the one `pvlib.iotools.read_epw` gives the same weather, and the
//!   beam pvlib puts on each roof, shaded by the CSV, is sunlit's own direct irradiation (whose
//!   sun and fractions are sunlit's, the sun pvlib's SPA): within 0.5 %, where the same shade an
//!   hour late is not;
//! - SAM: pvsamv1's beam shading factor is 1 − the timestep table's loss at every hour; its
//!   diffuse factor is 1 − `_diff`; the azimuth × altitude and month × hour tables, enabled
//!   instead, give nearly the same beam factors, and closer than the same tables mirrored east
//!   to west or an hour late.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod sweep_fixture;

use std::path::PathBuf;

use sweep_fixture::{scratch, stderr, sunlit, varying_epw};

const BLOCK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/city/block.city.json");

/// The Python with pvlib and PySAM: `SUNLIT_PV_PYTHON`, else .venv-pv's; `None` when neither is.
fn pv_python() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SUNLIT_PV_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let venv = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv-pv/bin/python");
    venv.exists().then_some(venv)
}

#[test]
fn pvlib_and_sam_read_the_shading_as_meant() {
    let Some(python) = pv_python() else {
        eprintln!("SKIPPED: pvlib and NREL-PySAM not found: run `SUNLIT_PV=1 . scripts/setup.sh` (npm test does) or set SUNLIT_PV_PYTHON");
        return;
    };
    let dir = scratch("pv");
    let epw = dir.join("bolzano.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let path = |name: &str| dir.join(name).display().to_string();
    let (e, csv, sam, summary) = (epw.display().to_string(), path("pvlib.csv"), path("sam.json"), path("summary.json"));
    #[rustfmt::skip]
    let out = sunlit(&[
        "annual", BLOCK, "--receivers", "RoofSurface", "--epw", &e, "--engine", "exact", "--timesteps-per-hour", "1",
        "-o", &path("f.csv"), "--pvlib", &csv, "--sam", &sam, "--summary", &summary,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let info = sunlit(&["info", BLOCK, "--receivers", "RoofSurface", "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let normals: serde_json::Map<String, serde_json::Value> =
        info["receivers"].as_array().unwrap().iter().map(|r| (r["name"].as_str().unwrap().to_string(), r["normal"].clone())).collect();
    let setup = dir.join("setup.json");
    let value = serde_json::json!({"epw": e, "pvlib": csv, "sam": sam, "summary": summary, "normals": normals});
    std::fs::write(&setup, value.to_string()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/pv/check.py");
    let run = std::process::Command::new(&python).arg(script).arg(&setup).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let got: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    println!("{got}");
    assert_eq!(got["pvlib_version"], "0.16.1", "the layout was checked against pvlib 0.16.1");
    assert!(got["pysam_version"].as_str().unwrap().starts_with("7.1.1"), "{}", got["pysam_version"]);

    assert_eq!(got["index_equal"], true, "the CSV's index is read_epw's");
    let summary: serde_json::Value = serde_json::from_slice(&std::fs::read(&summary).unwrap()).unwrap();
    let mut shaded_somewhere = false;
    for s in summary["surfaces"].as_array().unwrap() {
        let name = s["name"].as_str().unwrap();
        let pv = &got["surfaces"][name];
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        let (direct, open) = (s["direct"].as_f64().unwrap(), s["unshaded_irradiation"].as_f64().unwrap());
        assert!(rel(pv["unshaded_kwh_m2"].as_f64().unwrap(), open) < 0.005, "{name}: {pv} against {s}");
        assert!(rel(pv["shaded_kwh_m2"].as_f64().unwrap(), direct) < 0.005, "{name}: {pv} against {s}");
        if open - direct > 0.02 * open {
            shaded_somewhere = true;
            assert!(rel(pv["shaded_hour_later_kwh_m2"].as_f64().unwrap(), direct) > 0.005, "an hour late would show: {name}: {pv}");
        }
    }
    assert!(shaded_somewhere, "the block shades one of its roofs by more than 2 %: {summary}");

    assert!(got["sam_timestep_max_error"].as_f64().unwrap() < 1e-6, "{got}");
    let diffuse_loss = got["sam_diffuse_loss_percent"].as_f64().unwrap();
    assert!(diffuse_loss > 0.1, "the block's roofs lose some sky: {got}");
    assert!((got["sam_diffuse_factor"].as_f64().unwrap() - (1.0 - diffuse_loss / 100.0)).abs() < 1e-5, "{got}");
    let (azal, mirrored) = (got["sam_azal_error"].as_f64().unwrap(), got["sam_azal_mirrored_error"].as_f64().unwrap());
    assert!(azal < 0.02 && azal < mirrored / 2.0, "{got}");
    let (mxh, later) = (got["sam_mxh_error"].as_f64().unwrap(), got["sam_mxh_hour_later_error"].as_f64().unwrap());
    assert!(mxh < 0.02 && mxh < later / 2.0, "{got}");
}
