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
//!
//! The same for a map's points (`map --grid --pvlib --sam`), tests/pv/check_points.py: read by
//! both tools, and every point's shading at every hour, the set's loss and each cell of SAM's
//! azimuth × altitude table recounted by an independent numpy ray cast against the one box that
//! shades them; and the same for a district's roof points (`district --grid --pv`), merged from
//! two tiles.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
mod sweep_fixture;

use std::path::PathBuf;

use sweep_fixture::{boxes_city, scratch, stderr, sunlit, varying_epw};

const BLOCK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/city/block.city.json");

/// The Python with pvlib and PySAM: `SUNLIT_PV_PYTHON`, else .venv-pv's; `None` when neither is.
fn pv_python() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SUNLIT_PV_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let venv = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv-pv/bin/python");
    venv.exists().then_some(venv)
}

/// Runs tests/pv/SCRIPT on `setup` (written to DIR/setup.json) and returns what it printed, once
/// the versions it ran are the ones the layouts were checked against.
fn check(python: &std::path::Path, dir: &std::path::Path, script: &str, setup: &serde_json::Value) -> serde_json::Value {
    let path = dir.join("setup.json");
    std::fs::write(&path, setup.to_string()).unwrap();
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/pv").join(script);
    let run = std::process::Command::new(python).arg(script).arg(&path).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let got: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    println!("{got}");
    assert_eq!(got["pvlib_version"], "0.16.1", "the layout was checked against pvlib 0.16.1");
    assert!(got["pysam_version"].as_str().unwrap().starts_with("7.1.1"), "{}", got["pysam_version"]);
    got
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
    let setup = serde_json::json!({"epw": e, "pvlib": csv, "sam": sam, "summary": summary, "normals": normals});
    let got = check(&python, &dir, "check.py", &setup);

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

/// A 20 m × 20 m roof at z = 0 (the receiver, object `site`, group `roof`) and north of nothing
/// but a 12.1 m box to its south (object `tower`, its corners [`TOWER`]), z up. The box's edges
/// fall between the 2 m grid's points.
const TOWER: [[f64; 3]; 2] = [[6.4, -8.2, 0.0], [13.3, -2.3, 12.1]];

fn roof_and_tower_obj() -> String {
    let [[x0, y0, z0], [x1, y1, z1]] = TOWER;
    let mut text = String::from("v 0 0 0\nv 20 0 0\nv 20 20 0\nv 0 20 0\no site\ng roof\nf 1 2 3 4\no tower\n");
    for (x, y, z) in [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)] {
        text.push_str(&format!("v {x} {y} {z}\n"));
    }
    // Outward faces: bottom, top, south, east, north, west.
    text.push_str("f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n");
    text
}

#[test]
fn map_points_pvlib_and_sam_match_a_numpy_ray_cast() {
    let Some(python) = pv_python() else {
        eprintln!("SKIPPED: pvlib and NREL-PySAM not found: run `SUNLIT_PV=1 . scripts/setup.sh` (npm test does) or set SUNLIT_PV_PYTHON");
        return;
    };
    let dir = scratch("pv-points");
    let (epw, obj) = (dir.join("bolzano.epw"), dir.join("roof.obj"));
    std::fs::write(&epw, varying_epw()).unwrap();
    std::fs::write(&obj, roof_and_tower_obj()).unwrap();
    let path = |name: &str| dir.join(name).display().to_string();
    let (e, o, points, csv, sam) =
        (epw.display().to_string(), obj.display().to_string(), path("points.csv"), path("pvlib.csv"), path("sam.json"));
    #[rustfmt::skip]
    let out = sunlit(&[
        "map", &o, "--up", "z", "--receivers", "site/roof", "--epw", &e, "--grid", "2", "-o", &points, "--pvlib", &csv, "--sam", &sam,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let setup = serde_json::json!({"epw": e, "pvlib": csv, "sam": sam, "points": points, "box": TOWER});
    let got = check(&python, &dir, "check_points.py", &setup);
    let f = |key: &str| got[key].as_f64().unwrap_or_else(|| panic!("{key}: {got}"));

    assert_eq!(got["index_equal"], true, "the CSV's index is read_epw's");
    assert_eq!(got["columns"], serde_json::json!(["point_0", "point_1", 100]), "a column per point of the 2 m grid");
    assert_eq!(got["sam_points"], 100);
    assert!(f("shaded_cells") > 0.05 * f("cells"), "the tower shades the roof: {got}");
    // Every point at every hour as the ray cast has it, but for the few a shadow edge crosses
    // between the two suns (sunlit's and pvlib's SPA); an hour late is far off.
    assert!(f("cell_agreement") > 0.995, "{got}");
    assert!(f("cell_agreement_hour_later") < f("cell_agreement") - 0.01, "{got}");

    assert!(f("sam_timestep_max_error") < 1e-6, "SAM applies the timestep table as written: {got}");
    assert!(f("sam_set_loss_mean") > 0.05, "{got}");
    assert!(f("sam_set_loss_error") < 0.005 && f("sam_set_loss_error") < f("sam_set_loss_hour_later_error") / 4.0, "{got}");
    let diffuse_loss = f("sam_diffuse_loss_percent");
    assert!(diffuse_loss > 0.1, "the tower hides some sky: {got}");
    assert!((f("sam_diffuse_factor") - (1.0 - diffuse_loss / 100.0)).abs() < 1e-5, "{got}");
    assert!(f("azal_shaded_cells") > 10.0, "{got}");
    assert!(f("azal_max_error_percent") < 1e-6, "each table cell is the ray cast's loss along its direction: {got}");
}

/// Two 10 m × 10 m flat roofs 3 m up, side by side 4 m apart, each in its own 12 m tile, with a
/// 15 m tower south of them in a third (model coordinates, before the translate).
const DISTRICT: [(&str, [f64; 3], [f64; 3]); 3] =
    [("A", [0.0, 10.0, 0.0], [10.0, 20.0, 3.0]), ("B", [14.0, 10.0, 0.0], [24.0, 20.0, 3.0]), ("T", [6.3, -2.0, 0.0], [17.3, 4.0, 15.0])];

/// `district --grid --pv`: each tile's files and the merged ones, the latter read by pvlib and
/// PySAM and recounted by the numpy ray cast against the tower (the roofs cannot shade each
/// other's tops), as the map's points are above.
#[test]
fn district_roof_points_pvlib_and_sam_per_tile_and_merged_match_a_numpy_ray_cast() {
    let Some(python) = pv_python() else {
        eprintln!("SKIPPED: pvlib and NREL-PySAM not found: run `SUNLIT_PV=1 . scripts/setup.sh` (npm test does) or set SUNLIT_PV_PYTHON");
        return;
    };
    let dir = scratch("pv-district");
    let (epw, city, out) = (dir.join("bolzano.epw"), dir.join("d.city.json"), dir.join("out"));
    std::fs::write(&epw, varying_epw()).unwrap();
    std::fs::write(&city, boxes_city(&DISTRICT)).unwrap();
    let (e, c, o) = (epw.display().to_string(), city.display().to_string(), out.display().to_string());
    #[rustfmt::skip]
    let run = sunlit(&[
        "district", &c, "--epw", &e, "-o", &o, "--tile", "12", "--context", "100", "--buildings", "A,B", "--receivers", "RoofSurface",
        "--engine", "exact", "--days-per-year", "4", "--samples-per-day", "5", "--grid", "2", "--pv",
    ]);
    assert!(run.status.success(), "{}", stderr(&run));

    // Tiles 1 (A) and 2 (B) have 25 points each and their own files; tile 0 (the tower) none.
    let header = |path: std::path::PathBuf| std::fs::read_to_string(path).unwrap().lines().next().unwrap().to_string();
    for (k, building) in [(1, "A"), (2, "B")] {
        let names: Vec<String> = (0..25).map(|j| format!("{building}/RoofSurface/0/p{j}")).collect();
        assert_eq!(header(out.join(format!("pv/tile-{k}-pvlib.csv"))), format!("time,{}", names.join(",")));
        let sam: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join(format!("pv/tile-{k}-sam.json"))).unwrap()).unwrap();
        assert_eq!(sam["sunlit"]["points"], serde_json::json!(names));
        assert_eq!(sam["Shading"]["subarray1_shading_timestep"].as_array().unwrap().len(), 8760);
    }
    assert!(!out.join("pv/tile-0-pvlib.csv").exists(), "the tower's tile has no points");

    // The points CSV as check_points.py reads it: in the model's coordinates, the roofs' normal.
    let points_csv = std::fs::read_to_string(out.join("cadastre-points.csv")).unwrap();
    let mut points = String::from("x,y,z,nx,ny,nz\n");
    for line in points_csv.lines().skip(1) {
        let v: Vec<&str> = line.split(',').collect();
        points.push_str(&format!("{},{},{},0,0,1\n", v[2], v[3], v[4]));
    }
    let points_path = dir.join("points.csv");
    std::fs::write(&points_path, points).unwrap();
    let (_, [x0, y0, z0], [x1, y1, z1]) = DISTRICT[2];
    let tower = [[x0 + 85_000.0, y0 + 446_000.0, z0], [x1 + 85_000.0, y1 + 446_000.0, z1]];
    let path = |name: &str| out.join(name).display().to_string();
    #[rustfmt::skip]
    let setup = serde_json::json!({"epw": e, "pvlib": path("cadastre-points-pvlib.csv"), "sam": path("cadastre-points-sam.json"),
        "points": points_path.display().to_string(), "box": tower});
    let got = check(&python, &dir, "check_points.py", &setup);
    let f = |key: &str| got[key].as_f64().unwrap_or_else(|| panic!("{key}: {got}"));

    assert_eq!(got["index_equal"], true, "the CSV's index is read_epw's");
    assert_eq!(got["columns"], serde_json::json!(["A/RoofSurface/0/p0", "A/RoofSurface/0/p1", 50]), "the points CSV's order");
    assert_eq!(got["sam_points"], 50, "the two tiles' points as one array");
    assert!(f("shaded_cells") > 0.02 * f("cells"), "the tower shades the roofs: {got}");
    assert!(f("cell_agreement") > 0.995, "{got}");
    assert!(f("cell_agreement_hour_later") < f("cell_agreement") - 0.005, "{got}");
    assert!(f("sam_timestep_max_error") < 1e-6, "SAM applies the timestep table as written: {got}");
    assert!(f("sam_set_loss_error") < 0.005 && f("sam_set_loss_error") < f("sam_set_loss_hour_later_error") / 4.0, "{got}");
    let diffuse_loss = f("sam_diffuse_loss_percent");
    assert!(diffuse_loss > 0.1, "the tower hides some sky: {got}");
    assert!((f("sam_diffuse_factor") - (1.0 - diffuse_loss / 100.0)).abs() < 1e-5, "{got}");
    assert!(f("azal_shaded_cells") > 10.0, "{got}");
    assert!(f("azal_max_error_percent") < 1e-6, "each table cell is the ray cast's loss along its direction: {got}");
}

/// `map --pvlib`, `--sam` cover a year counted by rays: anything else is refused, naming the
/// option, and nothing is written. Needs neither tool.
#[test]
fn map_pv_outputs_refuse_what_they_cannot_be_made_from() {
    let dir = scratch("pv-points-bad");
    let (epw, obj) = (dir.join("w.epw"), dir.join("roof.obj"));
    std::fs::write(&epw, varying_epw()).unwrap();
    std::fs::write(&obj, roof_and_tower_obj()).unwrap();
    let (e, o) = (epw.display().to_string(), obj.display().to_string());
    let (points, csv, sam) = (dir.join("p.csv"), dir.join("pv.csv"), dir.join("sam.json"));
    let (p, c, s) = (points.display().to_string(), csv.display().to_string(), sam.display().to_string());
    let base = ["map", &o, "--up", "z", "--receivers", "site/roof", "--grid", "2", "-o", &p];
    let cases: [(&[&str], &str); 4] = [
        (&["--epw", &e, "--pvlib", &c, "--period", "06-21"], "pvlib"),
        (&["--epw", &e, "--pvlib", &c, "--at", "06-21", "12:00"], "pvlib"),
        (&["--epw", &e, "--sam", &s, "--engine", "gpu"], "sam"),
        (&["--location", "46.5,11.35,1", "--sam", &s], "sam"),
    ];
    for (more, flag) in cases {
        let args: Vec<&str> = base.iter().chain(more).copied().collect();
        let out = sunlit(&args);
        let text = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {text}");
        assert!(text.contains(&format!("--{flag}")), "{args:?} names --{flag}: {text}");
        assert!(!points.exists() && !csv.exists() && !sam.exists(), "{args:?} wrote nothing");
    }
}
