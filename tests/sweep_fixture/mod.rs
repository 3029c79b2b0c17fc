//! The sweep tests' variants: the example office with louvres of two depths (generated here with
//! the library's glb writer) at three orientations, at small settings so a variant takes seconds.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sunlit::model::glb_write::GlbWriter;
use sunlit::model::office::office;

/// Louvre depths (cm) and orientations (degrees of `north`).
pub const DEPTHS: [u32; 2] = [20, 50];
pub const NORTHS: [u32; 3] = [0, 90, 180];
/// `annual` options every variant shares.
pub const SMALL: &str =
    r#""location": "46.5,11.35,1", "days-per-year": 3, "samples-per-day": 5, "resolution": 64, "timesteps-per-hour": 1"#;

pub fn sunlit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).output().expect("run sunlit")
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh folder `sunlit-NAME-PID`: removed when the test passes, kept for a look when it fails.
pub fn scratch(name: &str) -> crate::common::Scratch {
    crate::common::Scratch::named(name)
}

/// Six slats `depth` m deep in front of the office's south windows (x 1.25–8.75 m, sill 1 m to
/// head 2.5 m), 0.1 m out from the wall: a context file that only casts shadows.
pub fn louvres(depth: f32) -> Vec<u8> {
    let (w, t) = (7.5f32, 0.02f32);
    let c = |i: usize| [if i & 1 == 0 { 0.0 } else { w }, if i & 2 == 0 { -depth } else { 0.0 }, if i & 4 == 0 { 0.0 } else { t }];
    let positions: Vec<[f32; 3]> = (0..8).map(c).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let indices: Vec<u32> = quads.iter().flat_map(|q: &[u32; 4]| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect();
    let mut glb = GlbWriter::new();
    let mesh = glb.add_mesh("SLAT", &positions, &indices);
    for k in 0..6 {
        glb.add_node(&format!("SLAT_{k}"), mesh, [1.25, -0.1, 1.0 + 0.25 * k as f32 + 0.1], None);
    }
    glb.to_glb()
}

/// Writes the models and returns the manifest's lines: `d{depth}_n{north}`, depth × north.
pub fn variants(dir: &Path) -> Vec<String> {
    std::fs::write(dir.join("office.glb"), office(0).to_glb()).unwrap();
    let mut lines = Vec::new();
    for d in DEPTHS {
        std::fs::write(dir.join(format!("louvres-{d}.glb")), louvres(d as f32 / 100.0)).unwrap();
        for n in NORTHS {
            lines.push(format!(r#"{{"id": "d{d}_n{n}", "models": ["office.glb", "louvres-{d}.glb"], "north": {n}, {SMALL}}}"#));
        }
    }
    lines
}

pub fn write_manifest(dir: &Path, name: &str, lines: &[String]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path
}

/// The ids of `lines`, in order.
pub fn ids(lines: &[String]) -> Vec<String> {
    lines.iter().map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["id"].as_str().unwrap().to_string()).collect()
}

/// Every file under `dir` whose name says it is a write in progress.
pub fn partial_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.to_string_lossy().ends_with(".partial") {
                found.push(p);
            }
        }
    }
    found
}

/// Modification times of the done records, by id.
pub fn record_times(out: &Path, ids: &[String]) -> Vec<Option<std::time::SystemTime>> {
    ids.iter().map(|id| std::fs::metadata(out.join(".done").join(format!("{id}.json"))).and_then(|m| m.modified()).ok()).collect()
}

/// An EPW at 46.5 N with a direct normal irradiance that varies by the hour.
pub fn varying_epw() -> String {
    let mut text = String::from("LOCATION,Bolzano,BZ,ITA,test,0,46.5,11.35,1.0,262\n");
    text.push_str("DESIGN CONDITIONS,0\nTYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n");
    text.push_str("COMMENTS 1,synthetic\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n");
    let month_days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    let mut n = 0u32;
    for (m, days) in month_days.iter().enumerate() {
        for d in 1..=*days {
            for h in 1..=24 {
                let dni = 200 + (n * 37) % 600;
                n += 1;
                text.push_str(&format!(
                    "1999,{},{d},{h},60,x,10,5,50,80000,0,1300,300,500,{dni},100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0\n",
                    m + 1
                ));
            }
        }
    }
    text
}

/// A district run's tile records in `out`: each surface's area, direct, sky-diffuse,
/// ground-reflected and total irradiation, sun hours and mean fraction, at full precision.
pub fn tile_rows(out: &Path) -> std::collections::BTreeMap<String, Vec<f64>> {
    let mut rows = std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(out.join(".done")).unwrap() {
        let done: serde_json::Value = serde_json::from_slice(&std::fs::read(entry.unwrap().path()).unwrap()).unwrap();
        for r in done["rows"].as_array().unwrap() {
            let values = ["area", "direct", "sky_diffuse", "ground_reflected", "total", "sun_hours", "mean_fraction"]
                .map(|k| r[k].as_f64().unwrap());
            rows.insert(r["surface"].as_str().unwrap().to_string(), values.to_vec());
        }
    }
    rows
}

/// A CityJSON 2.0 city of boxes `(id, [x0, y0, z0], [x1, y1, z1])`, each a `Building` with an
/// LoD2 `Solid`: roof, ground and four walls, millimetre vertices.
pub fn boxes_city(boxes: &[(&str, [f64; 3], [f64; 3])]) -> String {
    let mut vertices: Vec<[i64; 3]> = Vec::new();
    let mut objects = serde_json::Map::new();
    for (id, lo, hi) in boxes {
        let base = vertices.len();
        for k in 0..8 {
            let pick = |axis: usize| if k >> axis & 1 == 1 { hi[axis] } else { lo[axis] };
            vertices.push([0, 1, 2].map(|a| (pick(a) * 1000.0).round() as i64));
        }
        // Corners by bits (x, y, z); each face counter-clockwise seen from outside.
        let faces: [([usize; 4], &str); 6] = [
            ([4, 5, 7, 6], "RoofSurface"),
            ([0, 2, 3, 1], "GroundSurface"),
            ([0, 1, 5, 4], "WallSurface"),
            ([2, 6, 7, 3], "WallSurface"),
            ([0, 4, 6, 2], "WallSurface"),
            ([1, 3, 7, 5], "WallSurface"),
        ];
        let boundaries: Vec<Vec<Vec<usize>>> = faces.iter().map(|(f, _)| vec![f.iter().map(|i| base + i).collect()]).collect();
        let values: Vec<usize> =
            faces.iter().map(|(_, t)| ["RoofSurface", "GroundSurface", "WallSurface"].iter().position(|k| k == t).unwrap()).collect();
        objects.insert(
            id.to_string(),
            serde_json::json!({"type": "Building", "geometry": [{"type": "Solid", "lod": "2.2", "boundaries": [boundaries],
                "semantics": {"surfaces": [{"type": "RoofSurface"}, {"type": "GroundSurface"}, {"type": "WallSurface"}], "values": [values]}}]}),
        );
    }
    serde_json::json!({"type": "CityJSON", "version": "2.0", "transform": {"scale": [0.001, 0.001, 0.001], "translate": [85000.0, 446000.0, 0.0]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/7415"}, "CityObjects": objects, "vertices": vertices})
    .to_string()
}
