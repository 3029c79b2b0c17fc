//! City models in, a solar cadastre out: the CityJSON and OBJ readers through the CLI (receivers
//! by semantic type and building, bad input refused with nothing written), the round trip of a
//! scene written as CityJSON and read back (the exact engine's fractions agree), and
//! `sunlit district`: tiles equal the one-process run, and the cadastre's CityJSON passes the
//! official validator `cjval` (installed by `SUNLIT_CITY=1 . scripts/setup.sh`).

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
mod sweep_fixture;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use common::{TestScene, flat_rect};
use glam::DVec3;
use sunlit::count::exact::Exact;
use sunlit::count::{Engine, ViewRequest};
use sweep_fixture::{boxes_city, scratch, stderr, sunlit, tile_rows, varying_epw};

const BLOCK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/city/block.city.json");

fn info(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["info", "--json"];
    all.extend(args);
    let out = sunlit(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn receiver_names(v: &serde_json::Value) -> Vec<String> {
    v["receivers"].as_array().unwrap().iter().map(|r| r["name"].as_str().unwrap().to_string()).collect()
}

#[test]
fn city_receivers_are_roofs_and_walls_by_default_and_chosen_by_type_or_building() {
    let all = info(&[BLOCK]);
    let names = receiver_names(&all);
    // 1 roof + 8 walls of the courtyard block, 2 roofs + 4 walls of the house part; no ground, no tree.
    assert_eq!(names.len(), 15, "{names:?}");
    assert!(names.iter().all(|n| n.contains("/RoofSurface/") || n.contains("/WallSurface/")), "{names:?}");
    assert!(all["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("grid north is taken as true north")));
    let roofs = receiver_names(&info(&[BLOCK, "--receivers", "RoofSurface"]));
    assert_eq!(roofs, ["NL.B.courtyard/RoofSurface/1", "NL.B.house.part/RoofSurface/5", "NL.B.house.part/RoofSurface/6"]);
    let house = receiver_names(&info(&[BLOCK, "--buildings", "NL.B.house"]));
    assert_eq!(house.len(), 6, "{house:?}");
    assert!(house.iter().all(|n| n.starts_with("NL.B.house.part/")));
    // The courtyard roof keeps its hole: 20 × 20 − 8 × 8 m².
    let roof = all["receivers"].as_array().unwrap().iter().find(|r| r["name"] == "NL.B.courtyard/RoofSurface/1").unwrap();
    assert!((roof["area"].as_f64().unwrap() - 336.0).abs() < 1e-6, "{roof}");
    let text = sunlit(&["info", BLOCK]);
    assert!(!String::from_utf8_lossy(&text.stdout).contains("-0.000"), "{}", String::from_utf8_lossy(&text.stdout));
    // Local coordinates: the 85 km translate is gone before anything became f32.
    assert!(all["bounds"]["max"][0].as_f64().unwrap() < 200.0, "{}", all["bounds"]);
}

#[test]
fn obj_groups_are_names_globs_select() {
    let dir = scratch("obj");
    let obj = dir.join("block.obj");
    let text = "v 0 0 0\nv 10 0 0\nv 10 0 -10\nv 0 0 -10\nv 0 3 0\nv 10 3 0\nv 10 3 -10\nv 0 3 -10\n\
                o house\ng roof\nf 5 6 7 8\ng south\nf 1 2 6 5\n";
    std::fs::write(&obj, text).unwrap();
    let v = info(&[obj.to_str().unwrap(), "--receivers", "*/roof", "--unit", "cm"]);
    assert_eq!(receiver_names(&v), ["house/roof"]);
    let roof = &v["receivers"][0];
    assert!((roof["area"].as_f64().unwrap() - 0.01).abs() < 1e-9, "10 cm × 10 cm: {roof}");
    assert!((roof["normal"][2].as_f64().unwrap() - 1.0).abs() < 1e-9, "y is up by default: {roof}");
    let z_up = info(&[obj.to_str().unwrap(), "--receivers", "house/south", "--up", "z"]);
    assert!((z_up["receivers"][0]["normal"][2].as_f64().unwrap() - 1.0).abs() < 1e-9, "{z_up}");
}

/// Bad city and OBJ input through `annual`: the file, the object and the reason, exit 1, and no
/// file written.
#[test]
fn bad_city_input_is_refused_with_nothing_written() {
    let dir = scratch("bad-city");
    let cases: [(&str, String, &str); 7] = [
        (
            // Found by the 10-minute mutation run: it was refused without the file's name.
            "empty.city.json",
            r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{},"vertices":[]}"#.into(),
            "empty.city.json: no CityObject has geometry to read (at the level of detail chosen)",
        ),
        (
            "version.city.json",
            r#"{"type":"CityJSON","version":"0.9","CityObjects":{},"vertices":[]}"#.into(),
            "version.city.json: CityJSON version \"0.9\" is not read (read: 1.1, 2.0)",
        ),
        (
            "range.city.json",
            r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{"b":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,5]]]}]}},"vertices":[[0,0,0],[1,0,0],[0,1,0]]}"#.into(),
            "range.city.json: CityObject 'b': geometry 0: surface 0, ring 0: vertex index 5 is out of range (3 vertices)",
        ),
        (
            "integers.city.json",
            r#"{"type":"CityJSON","version":"1.1","CityObjects":{},"vertices":[[0,0,0]]}"#.into(),
            "integers.city.json: no \"transform\", yet the vertices are integers",
        ),
        (
            "semantics.city.json",
            r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{"b":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,2]]],"semantics":{"surfaces":[{"type":"RoofSurface"}],"values":[3]}}]}},"vertices":[[0,0,0],[1,0,0],[0,1,0]]}"#.into(),
            "semantics.city.json: CityObject 'b': geometry 0: surface 0: semantic value 3 points nowhere (1 semantic surfaces)",
        ),
        (
            "ring.city.json",
            r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{"b":{"type":"Building","geometry":[{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,0,1]]]}]}},"vertices":[[0,0,0],[1,0,0],[0,1,0]]}"#.into(),
            "ring.city.json: CityObject 'b': geometry 0: surface 0, ring 0: has 2 distinct vertices; a ring needs at least 3",
        ),
        ("faces.obj", "v 0 0 0\nv 1 0 0\no shed\nf 1 2 9\n".into(), "faces.obj: 'shed' (line 4): vertex index 9 is missing (2 vertices read so far)"),
    ];
    for (name, text, message) in cases {
        let model = dir.join(name);
        std::fs::write(&model, text).unwrap();
        let csv = dir.join("out.csv");
        let out = sunlit(&["annual", model.to_str().unwrap(), "--location", "52,5,1", "-o", csv.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{name}");
        assert!(stderr(&out).contains(message), "{name}: {}", stderr(&out));
        let left: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "csv" || e == "partial"))
            .collect();
        assert!(left.is_empty(), "{name}: {left:?}");
    }
}

/// A scene of sunlit's own (boxes and a ground on a millimetre grid), written as CityJSON and read
/// back: every receiver's exact fraction is the area-weighted mean of its triangles' surfaces.
#[test]
fn a_scene_written_as_cityjson_and_read_back_gives_the_same_fractions() {
    let mut t = TestScene::new();
    t.polygon("ground", &flat_rect(-20.0, 20.0, -20.0, 20.0, 0.0), true)
        .cuboid("tower", DVec3::new(-3.0, 2.0, 0.0), DVec3::new(3.0, 6.0, 12.0))
        .polygon("terrace", &flat_rect(-6.0, 6.0, -8.0, 0.5, 2.5), true);
    let scene = t.build();
    let text = sunlit::model::city_write::scene_cityjson(&scene);
    let options = sunlit::model::LoadOptions { receivers: vec!["*".into()], ..Default::default() };
    let back = sunlit::model::load_bytes(&[("own.city.json".into(), text.into_bytes())], &options).unwrap();
    for (az, alt) in [(180.0, 30.0), (135.0, 15.0), (250.0, 50.0)] {
        let sun = common::sun(az, alt);
        let fractions = |s: &sunlit::scene::Scene| {
            let requests: Vec<ViewRequest> = (0..s.receivers.len() as u32).map(|r| ViewRequest::new(r, sun)).collect();
            pollster::block_on(Exact { scene: s }.answer(&requests)).unwrap().into_iter().map(|a| a.fraction).collect::<Vec<f64>>()
        };
        let (before, after) = (fractions(&scene), fractions(&back));
        let mut sums: HashMap<String, (f64, f64)> = HashMap::new();
        for (r, f) in back.receivers.iter().zip(&after) {
            let building = r.name.split('/').next().unwrap().to_string();
            let e = sums.entry(building).or_default();
            e.0 += f * r.area;
            e.1 += r.area;
        }
        for (i, (r, f)) in scene.receivers.iter().zip(&before).enumerate() {
            let (lit, area) = sums[&format!("R{i}")];
            assert!((area - r.area).abs() < 1e-9, "{}: area {area} against {}", r.name, r.area);
            assert!((lit / area - f).abs() < 1e-9, "{} at ({az}, {alt}): {} read back against {f}", r.name, lit / area);
        }
    }
}

/// The official validator `cjval` finds `path` valid.
fn assert_valid_cityjson(path: &Path) {
    let check = std::process::Command::new("cjval").arg("-s").arg(path).output();
    let check = check.expect("cjval, the official CityJSON validator, is missing: run SUNLIT_CITY=1 . scripts/setup.sh");
    let verdict = String::from_utf8_lossy(&check.stdout).into_owned() + &String::from_utf8_lossy(&check.stderr);
    assert!(check.status.success() && verdict.contains("valid") && !verdict.contains("invalid"), "{verdict}");
}

/// Runs `sunlit district` on `city` into `out` with the small settings every run here shares.
fn district(city: &Path, epw: &Path, out: &Path, more: &[&str]) -> std::process::Output {
    let mut args = vec!["district", city.to_str().unwrap(), "--epw", epw.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend(["--engine", "exact", "--days-per-year", "4", "--samples-per-day", "5", "--sky-patches", "tregenza"]);
    args.extend(more);
    sunlit(&args)
}

#[test]
fn district_tiles_equal_the_one_process_run_and_the_cadastre_is_valid_cityjson() {
    let dir = scratch("district");
    let city = dir.join("district.city.json");
    std::fs::write(&city, sunlit::model::city_write::district_cityjson(3, 3, 7)).unwrap();
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    // One tile holding the whole district, and tiles of 30 m whose context reaches across it
    // (the radius that holds every shadow: docs/district.md).
    let (one, tiled) = (dir.join("one"), dir.join("tiled"));
    let run = district(&city, &epw, &one, &["--tile", "1000", "--context", "1000"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let run = district(&city, &epw, &tiled, &["--tile", "30", "--context", "1000", "--jobs", "2"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(stderr(&run).contains("grid north is taken as true north"), "{}", stderr(&run));
    let tiles = std::fs::read_dir(tiled.join(".done")).unwrap().count();
    assert!(tiles >= 4, "{tiles} tiles");
    let (a, b) = (tile_rows(&one), tile_rows(&tiled));
    assert_eq!(a.len(), b.len());
    assert!(a.len() > 40, "{} surfaces", a.len());
    for (name, values) in &a {
        for (x, y) in values.iter().zip(&b[name]) {
            assert!((x - y).abs() <= 1e-9, "{name}: {values:?} one-process against {:?} tiled", b[name]);
        }
    }
    assert!(a.values().any(|v| v[4] > 100.0), "some surface gets real irradiation");
    // A second run finds every tile finished.
    let again = district(&city, &epw, &tiled, &["--tile", "30", "--context", "1000"]);
    assert!(stderr(&again).contains("0 to count"), "{}", stderr(&again));
    // A tile without its record (killed, failed): the merge lists it and fails; the next run
    // counts only it.
    std::fs::remove_file(tiled.join(".done/tile-1.json")).unwrap();
    let merge = district(&city, &epw, &tiled, &["--tile", "30", "--context", "1000", "--merge"]);
    assert_eq!(merge.status.code(), Some(1), "{}", stderr(&merge));
    assert!(stderr(&merge).contains("1 tile(s) unfinished") && stderr(&merge).contains("tile-1"), "{}", stderr(&merge));
    assert!(std::fs::read_to_string(tiled.join("failed.csv")).unwrap().starts_with("id,exit_code,reason\ntile-1,"));
    let resumed = district(&city, &epw, &tiled, &["--tile", "30", "--context", "1000"]);
    assert!(resumed.status.success() && stderr(&resumed).contains("1 to count"), "{}", stderr(&resumed));
    assert!(!tiled.join("failed.csv").exists());
    assert_eq!(tile_rows(&tiled), b, "the recounted tile is as before");
    // The cadastre: valid CityJSON with the values on its semantic surfaces; CSV; roofs.
    let cadastre = tiled.join("cadastre.city.json");
    assert_valid_cityjson(&cadastre);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&cadastre).unwrap()).unwrap();
    let semantics = &doc["CityObjects"]["B000000"]["geometry"][0]["semantics"];
    let valued: Vec<&serde_json::Value> =
        semantics["surfaces"].as_array().unwrap().iter().filter(|s| s.get("total_kwh_m2").is_some()).collect();
    assert!(!valued.is_empty(), "{semantics}");
    for key in ["direct_kwh_m2", "sky_diffuse_kwh_m2", "ground_reflected_kwh_m2", "sun_hours", "mean_sunlit_fraction"] {
        assert!(valued.iter().all(|s| s[key].is_number()), "{key}: {semantics}");
    }
    let csv = std::fs::read_to_string(tiled.join("cadastre.csv")).unwrap();
    assert_eq!(csv.lines().count(), a.len() + 1);
    let roofs: serde_json::Value = serde_json::from_slice(&std::fs::read(tiled.join("cadastre-roofs.geojson")).unwrap()).unwrap();
    let roof_rows = a.keys().filter(|n| n.contains("/RoofSurface/")).count();
    assert_eq!(roofs["features"].as_array().unwrap().len(), roof_rows);
    // RFC 7946: WGS84, reprojected from the model's EPSG:7415 (RD New + NAP), so in the Netherlands.
    assert!(roofs.get("crs").is_none() && roofs["sunlit"]["note"].as_str().unwrap().contains("EPSG:7415"), "{}", roofs["sunlit"]);
    let corner = &roofs["features"][0]["geometry"]["coordinates"][0][0];
    let (lon, lat) = (corner[0].as_f64().unwrap(), corner[1].as_f64().unwrap());
    assert!((3.0..7.5).contains(&lon) && (50.5..53.7).contains(&lat), "{corner}");
}

/// Every row of two district runs equal bit for bit (each value's f64 bits); the rows compared.
fn assert_rows_bit_equal(one: &Path, tiled: &Path) -> usize {
    let (a, b) = (tile_rows(one), tile_rows(tiled));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "the same surfaces");
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    for (name, values) in &a {
        assert_eq!(bits(values), bits(&b[name]), "{name}: {values:?} one-process against {:?} tiled", b[name]);
    }
    a.len()
}

/// A receiver's answer must not depend on which other surfaces receive in the same run, since a
/// tile's context never does. It did (docs/district.md, "A tile's rows are the one process's"):
/// the exact engine grouped a building whose surfaces did not receive into one closed object,
/// cast as its hull, and one whose surfaces received face by face; the same shadow, rounded
/// differently, and the year's refinement made a last bit a counted step.
#[test]
fn a_tiles_rows_are_the_one_process_rows_bit_for_bit_whoever_receives_beside_them() {
    let dir = scratch("district-bits");
    // 1. The 2,000-building district of the benchmarks, two of its buildings receiving, 190 m
    //    apart and in different tiles: B011031 (gabled) shades B012024's east wall at low morning
    //    suns. At Golden's sun path (sun hours do not depend on the weather) the wall had 2825.011
    //    sun hours in its tile, B011031 only context, and 2825.170 in one process.
    let city = dir.join("district.city.json");
    std::fs::write(&city, sunlit::model::city_write::district_cityjson(50, 40, 1)).unwrap();
    let bolzano = "LOCATION,Bolzano,BZ,ITA,test,0,46.5,11.35,1.0,262";
    let weather = varying_epw();
    assert!(weather.starts_with(bolzano));
    let golden = dir.join("golden.epw");
    std::fs::write(&golden, weather.replacen(bolzano, "LOCATION,Golden,CO,USA,test,0,39.74,-105.18,-7.0,1829", 1)).unwrap();
    let (one, tiled) = (dir.join("one"), dir.join("tiled"));
    for (out, tile) in [(&one, "100000"), (&tiled, "700")] {
        let (city, epw, out) = (city.to_str().unwrap(), golden.to_str().unwrap(), out.to_str().unwrap());
        let args = ["district", city, "--epw", epw, "-o", out, "--engine", "exact", "--buildings", "B012024,B011031"];
        let run = sunlit(&[&args[..], &["--tile", tile, "--context", "100000"]].concat());
        assert!(run.status.success(), "{}", stderr(&run));
    }
    let counted = std::fs::read_dir(tiled.join(".done"))
        .unwrap()
        .filter(|e| {
            let done: serde_json::Value = serde_json::from_slice(&std::fs::read(e.as_ref().unwrap().path()).unwrap()).unwrap();
            !done["rows"].as_array().unwrap().is_empty()
        })
        .count();
    assert_eq!(counted, 2, "the two buildings are in two tiles");
    assert_eq!(assert_rows_bit_equal(&one, &tiled), 11, "a flat roof and 4 walls, 2 roofs and 4 walls");
    // 2. Every receiver of a 4 × 4 district, in tiles of 30 m, at the small settings.
    let city = dir.join("small.city.json");
    std::fs::write(&city, sunlit::model::city_write::district_cityjson(4, 4, 7)).unwrap();
    let epw = dir.join("site.epw");
    std::fs::write(&epw, weather).unwrap();
    let (one, tiled) = (dir.join("small-one"), dir.join("small-tiled"));
    let run = district(&city, &epw, &one, &["--tile", "1000", "--context", "1000"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let run = district(&city, &epw, &tiled, &["--tile", "30", "--context", "1000", "--jobs", "2"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(std::fs::read_dir(tiled.join(".done")).unwrap().count() >= 4);
    assert!(assert_rows_bit_equal(&one, &tiled) > 90);
}

#[test]
fn a_tile_size_or_context_that_is_not_positive_is_refused() {
    let dir = scratch("district-bad");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    for (tile, context, flag) in [("0", "100", "--tile"), ("50", "-5", "--context"), ("nan", "100", "--tile")] {
        let out = dir.join("out");
        let run = district(Path::new(BLOCK), &epw, &out, &["--tile", tile, "--context", context]);
        assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
        assert!(stderr(&run).contains(flag) && stderr(&run).contains("positive"), "{}", stderr(&run));
        assert!(!out.exists(), "nothing written for --tile {tile} --context {context}");
    }
    for (more, flag, why) in
        [(["--grid", "0", "--min-kwh-m2", "1"], "--grid", "positive"), (["--grid", "1", "--min-kwh-m2", "-3"], "--min-kwh-m2", "0 or more")]
    {
        let out = dir.join("out");
        let mut args = vec!["--tile", "50", "--context", "50"];
        args.extend(more);
        let run = district(Path::new(BLOCK), &epw, &out, &args);
        assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
        assert!(stderr(&run).contains(flag) && stderr(&run).contains(why), "{}", stderr(&run));
        assert!(!out.exists(), "nothing written for {more:?}");
    }
}

/// The points of a district run's `cadastre-points.csv`: (y in the model, total kWh/m²).
fn points(out: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(out.join("cadastre-points.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "surface,building,x,y,z,direct_kwh_m2,sky_diffuse_kwh_m2,ground_reflected_kwh_m2,total_kwh_m2,sun_hours"
    );
    lines.map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap_or(f64::NAN)).collect::<Vec<f64>>()).map(|v| (v[3], v[8])).collect()
}

/// `--grid` and `--min-kwh-m2` against two analytic cases: a flat roof alone (every point alike,
/// all its area usable), and the same roof with a canopy 1 cm over its south half (sun and sky
/// reach under it only below about 1°): the north half keeps the open roof's year, the south half
/// gets almost nothing, so a threshold at half the open total makes exactly half the roof usable.
#[test]
fn roof_grids_and_usable_area_against_an_open_and_a_half_covered_roof() {
    let dir = scratch("district-grid");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let roof = ("A", [0.0, 0.0, 0.0], [10.0, 10.0, 3.0]);
    let canopy = ("S", [-1.0, -1.0, 3.01], [11.0, 5.0, 3.015]);
    let run = |name: &str, boxes: &[(&str, [f64; 3], [f64; 3])], min: &str| {
        let city = dir.join(format!("{name}.city.json"));
        std::fs::write(&city, boxes_city(boxes)).unwrap();
        let out = dir.join(name);
        let more =
            ["--tile", "100", "--context", "100", "--buildings", "A", "--receivers", "RoofSurface", "--grid", "1", "--min-kwh-m2", min];
        let r = district(&city, &epw, &out, &more);
        assert!(r.status.success(), "{}", stderr(&r));
        out
    };
    let open = run("open", &[roof], "0");
    let open_points = points(&open);
    assert_eq!(open_points.len(), 100, "a 10 m roof at 1 m");
    let total = open_points[0].1;
    assert!(total > 100.0 && open_points.iter().all(|p| (p.1 - total).abs() < 1e-3), "every point alike: {open_points:?}");
    let csv = std::fs::read_to_string(open.join("cadastre.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",usable_area_m2") && csv.lines().nth(1).unwrap().ends_with(",100.0000"), "{csv}");

    let min = format!("{}", total / 2.0);
    let covered = run("covered", &[roof, canopy], &min);
    let covered_points = points(&covered);
    assert_eq!(covered_points.len(), 100);
    for &(y, t) in &covered_points {
        // The model's y: the translate added back.
        let y = y - 446_000.0;
        if y > 5.0 {
            assert!((t - total).abs() < 0.01 * total, "north half at y {y}: {t} against the open {total}");
        } else {
            assert!(t < 0.05 * total, "south half at y {y}: {t} against the open {total}");
        }
    }
    let csv = std::fs::read_to_string(covered.join("cadastre.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().ends_with(",50.0000"), "half the roof: {csv}");
    let roofs: serde_json::Value = serde_json::from_slice(&std::fs::read(covered.join("cadastre-roofs.geojson")).unwrap()).unwrap();
    assert_eq!(roofs["features"][0]["properties"]["usable_area_m2"], 50.0, "{roofs}");
    let geo: serde_json::Value = serde_json::from_slice(&std::fs::read(covered.join("cadastre-points.geojson")).unwrap()).unwrap();
    assert_eq!(geo["features"].as_array().unwrap().len(), 100);
    let cadastre = covered.join("cadastre.city.json");
    assert_valid_cityjson(&cadastre);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&cadastre).unwrap()).unwrap();
    let surfaces = doc["CityObjects"]["A"]["geometry"][0]["semantics"]["surfaces"].as_array().unwrap().clone();
    assert!(surfaces.iter().any(|s| s["usable_area_m2"] == 50.0), "{surfaces:?}");
}

/// Terrain casts shadows: a TINRelief ridge (tests/city/terrain.city.json, valid by `cjval`)
/// 8 m south of a flat-roofed house shades its roof as a numpy ray cast written independently
/// (tests/city/terrain_truth.py: the file read by itself, a 300 × 300 grid of rays against every
/// triangle) says, for low suns from the south, south-east and south-west; a sun high or from the
/// east leaves it lit.
#[test]
fn tin_relief_terrain_shades_a_roof_as_a_numpy_ray_cast_does() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/city/terrain.city.json");
    assert_valid_cityjson(&fixture);
    let suns = [(180.0, 12.0), (150.0, 15.0), (210.0, 10.0), (180.0, 40.0), (90.0, 10.0)];
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/city/terrain_truth.py");
    let mut truth = std::process::Command::new(common::radiance_python());
    truth.arg(script).arg(&fixture).args(suns.iter().map(|(az, alt)| format!("{az},{alt}")));
    let out = truth.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let truth: HashMap<String, Vec<f64>> = serde_json::from_slice(&out.stdout).unwrap();
    let options = sunlit::model::LoadOptions { receivers: vec!["RoofSurface".into()], ..Default::default() };
    let bytes = std::fs::read(&fixture).unwrap();
    let scene = sunlit::model::load_bytes(&[("terrain.city.json".into(), bytes)], &options).unwrap();
    assert_eq!(scene.receivers.len(), 1, "the house's one roof");
    let roof = &scene.receivers[0];
    let expected = &truth[&roof.name];
    for ((az, alt), want) in suns.iter().zip(expected) {
        let requests = [ViewRequest::new(0, common::sun(*az, *alt))];
        let got = pollster::block_on(Exact { scene: &scene }.answer(&requests)).unwrap()[0].fraction;
        // The ray cast's grid puts a shadow edge within 1/300 of the roof's side.
        assert!((got - want).abs() < 0.005, "{} at ({az}, {alt}): sunlit {got}, the numpy ray cast {want}", roof.name);
    }
    assert!(expected.iter().any(|&f| f < 0.5), "the terrain shades the roof for some sun: {expected:?}");
}

/// `district --grid --pv` with more tiles than the process may open files (`ulimit -n 16`, for
/// this run alone): the merge opens the tiles' pvlib CSVs one at a time, so it writes the merged
/// files with every tile's columns. A merge holding a file open a tile (as it once did) fails here
/// with "Too many open files".
#[test]
fn district_pv_merges_more_tiles_than_the_open_file_limit() {
    const HOUSES: usize = 20;
    let dir = scratch("district-many-tiles");
    // 4 m × 4 m houses 10 m apart, each alone in its 10 m tile.
    let names: Vec<String> = (0..HOUSES).map(|i| format!("H{i}")).collect();
    let boxes: Vec<(&str, [f64; 3], [f64; 3])> = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let (x, y) = ((i % 5) as f64 * 10.0, (i / 5) as f64 * 10.0);
            (name.as_str(), [x + 3.0, y + 3.0, 0.0], [x + 7.0, y + 7.0, 3.0])
        })
        .collect();
    let (city, epw, out) = (dir.join("houses.city.json"), dir.join("site.epw"), dir.join("out"));
    std::fs::write(&city, boxes_city(&boxes)).unwrap();
    std::fs::write(&epw, varying_epw()).unwrap();
    let (c, e, o) = (city.display().to_string(), epw.display().to_string(), out.display().to_string());
    #[rustfmt::skip]
    let args = [
        "district", &c, "--epw", &e, "-o", &o, "--tile", "10", "--context", "1", "--receivers", "RoofSurface", "--engine", "exact",
        "--days-per-year", "3", "--samples-per-day", "3", "--grid", "2", "--pv", "--jobs", "2",
    ];
    let run = std::process::Command::new("sh")
        .args(["-c", "ulimit -n 16 && exec \"$@\"", "sh", env!("CARGO_BIN_EXE_sunlit")])
        .args(args)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(std::fs::read_dir(out.join(".done")).unwrap().count(), HOUSES);
    let merged = std::fs::read_to_string(out.join("cadastre-points-pvlib.csv")).unwrap();
    let header: Vec<&str> = merged.lines().next().unwrap().split(',').collect();
    assert_eq!(header.len(), 1 + 4 * HOUSES, "a column a point (4 a roof): {header:?}");
    assert!(names.iter().all(|n| header.contains(&format!("{n}/RoofSurface/0/p3").as_str())), "{header:?}");
    assert_eq!(merged.lines().count(), 1 + 8760);
}

/// `--buildings` takes a `Building`'s id or a `BuildingPart`'s, in `district` as in `info`; an id
/// that is neither is refused with the file, the id and the reason, and nothing is written. A
/// tile once narrowed its receivers to its buildings' root ids, so a part's id gave an empty
/// cadastre, and an unknown id was dropped without a word (an empty cadastre, exit 0).
#[test]
fn buildings_take_a_building_or_its_part_and_an_unknown_id_is_refused() {
    let dir = scratch("district-buildings");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let rows = |out: &Path| -> Vec<String> {
        let csv = std::fs::read_to_string(out.join("cadastre.csv")).unwrap();
        csv.lines().skip(1).map(|l| l.split(',').next().unwrap().to_string()).collect()
    };
    for (id, n) in [("NL.B.house.part", 6), ("NL.B.house", 6), ("NL.B.courtyard,NL.B.house.part", 15)] {
        let out = dir.join(id);
        let run = district(Path::new(BLOCK), &epw, &out, &["--tile", "50", "--context", "50", "--buildings", id]);
        assert!(run.status.success(), "{id}: {}", stderr(&run));
        let names = rows(&out);
        assert_eq!(names.len(), n, "{id}: {names:?}");
        assert_eq!(names.iter().filter(|s| s.starts_with("NL.B.house.part/")).count(), 6, "{id}: {names:?}");
    }
    let why = "invalid --buildings: 'NL.B.nope' is no Building or BuildingPart with geometry in ";
    let out = dir.join("unknown");
    let run = district(Path::new(BLOCK), &epw, &out, &["--tile", "50", "--context", "50", "--buildings", "NL.B.house,NL.B.nope"]);
    assert_eq!(run.status.code(), Some(1), "{}", stderr(&run));
    assert!(stderr(&run).contains(why) && stderr(&run).contains("block.city.json"), "{}", stderr(&run));
    assert!(!out.exists(), "nothing written");
    // The tree is a CityObject, not a building: it never receives, so it cannot be asked for.
    for args in [["--buildings", "NL.B.house,NL.B.nope"], ["--buildings", "tree-1"]] {
        let info = sunlit(&[&["info", BLOCK][..], &args].concat());
        assert_eq!(info.status.code(), Some(1), "{args:?}: {}", String::from_utf8_lossy(&info.stdout));
        assert!(
            stderr(&info).contains("is no Building or BuildingPart with geometry in") && stderr(&info).contains("block.city.json"),
            "{}",
            stderr(&info)
        );
    }
}

/// `district --receivers` that no surface of the city matches is refused as `annual` and `info`
/// refuse it, before anything is written (it once wrote an empty cadastre with exit 0); so are
/// patterns that match only surfaces outside the buildings asked for. A pattern matching a
/// semantic type still runs.
#[test]
fn receivers_no_city_surface_matches_are_refused_before_anything_is_written() {
    let dir = scratch("district-receivers");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let tiles = ["--tile", "50", "--context", "50"];
    for (extra, why) in [
        (&["--receivers", "NoSuchSurface*"][..], "no node name matches --receivers NoSuchSurface*"),
        (&["--receivers", "NL.B.courtyard/*", "--buildings", "NL.B.house"][..], "no node name matches --receivers NL.B.courtyard/*"),
    ] {
        let out = dir.join("none");
        let run = district(Path::new(BLOCK), &epw, &out, &[&tiles[..], extra].concat());
        assert_eq!(run.status.code(), Some(1), "{extra:?}: {}", stderr(&run));
        assert!(stderr(&run).contains(why), "{extra:?}: {}", stderr(&run));
        assert!(!out.exists(), "{extra:?}: nothing written");
    }
    let out = dir.join("roofs");
    let run = district(Path::new(BLOCK), &epw, &out, &[&tiles[..], &["--receivers", "roofsurface"]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    let csv = std::fs::read_to_string(out.join("cadastre.csv")).unwrap();
    assert!(csv.lines().skip(1).count() > 0 && csv.lines().skip(1).all(|l| l.contains("/RoofSurface/")), "{csv}");
}

/// A CityJSON roof whose ring is not planar (one corner 1 m up) is triangulated and split into
/// planar receivers `NAME#1`, `NAME#2` at the scene's tolerance (0.5°, 1 mm); one 0.5 mm off its
/// plane stays one. The cadastre has one row per city surface, its parts combined by area, and
/// the values on that surface in the CityJSON, which `cjval` still passes.
#[test]
fn a_non_planar_city_roof_is_split_into_planar_parts_and_merged_back_into_one_row() {
    let dir = scratch("district-non-planar");
    let quad = |x: f64, z: [f64; 4]| [[x, 0.0, z[0]], [x + 10.0, 0.0, z[1]], [x + 10.0, 10.0, z[2]], [x, 10.0, z[3]]];
    // Integers of 0.1 mm.
    let mm = |p: [f64; 3]| p.map(|v| (v * 10_000.0).round() as i64);
    let mut vertices = Vec::new();
    let mut objects = serde_json::Map::new();
    for (id, x, roof) in [("A", 0.0, [5.0, 5.0, 6.0, 5.0]), ("B", 20.0, [5.0, 5.0, 5.0005, 5.0])] {
        let base = vertices.len();
        vertices.extend(quad(x, [0.0; 4]).into_iter().chain(quad(x, roof)).map(mm));
        let (g, r) = ([base + 3, base + 2, base + 1, base], [base + 4, base + 5, base + 6, base + 7]);
        let wall = |a: usize, b: usize| [base + a, base + b, base + b + 4, base + a + 4];
        let boundaries = serde_json::json!([[g], [r], [wall(0, 1)], [wall(1, 2)], [wall(2, 3)], [wall(3, 0)]]);
        let semantics = serde_json::json!({"surfaces": [{"type": "GroundSurface"}, {"type": "RoofSurface"}, {"type": "WallSurface"}], "values": [0, 1, 2, 2, 2, 2]});
        let geometry = serde_json::json!([{"type": "MultiSurface", "lod": "2.2", "boundaries": boundaries, "semantics": semantics}]);
        objects.insert(id.into(), serde_json::json!({"type": "Building", "geometry": geometry}));
    }
    let doc = serde_json::json!({"type": "CityJSON", "version": "2.0", "transform": {"scale": [0.0001, 0.0001, 0.0001], "translate": [85000.0, 446000.0, 0.0]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/7415"}, "CityObjects": objects, "vertices": vertices});
    let city = dir.join("twisted.city.json");
    std::fs::write(&city, doc.to_string()).unwrap();
    assert_valid_cityjson(&city);
    let v = info(&[city.to_str().unwrap(), "--receivers", "RoofSurface"]);
    let parts: Vec<(String, f64)> =
        v["receivers"].as_array().unwrap().iter().map(|r| (r["name"].as_str().unwrap().to_string(), r["area"].as_f64().unwrap())).collect();
    let names: Vec<&str> = parts.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(names, ["A/RoofSurface/1#1", "A/RoofSurface/1#2", "B/RoofSurface/1"]);
    let twisted: f64 = parts[..2].iter().map(|p| p.1).sum();
    // Two triangles of a 10 m square with one corner 1 m up: 100.4975 or 100.4988 m² by the diagonal.
    assert!((100.49..100.50).contains(&twisted), "{parts:?}");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let out = dir.join("out");
    let run = district(&city, &epw, &out, &["--tile", "100", "--context", "100", "--receivers", "RoofSurface"]);
    assert!(run.status.success(), "{}", stderr(&run));
    // Exactly one cadastre, its CSV and its roofs (no tile writes one of its own).
    let mut files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with('.'))
        .collect();
    files.sort();
    assert_eq!(files, ["cadastre-roofs.geojson", "cadastre.city.json", "cadastre.csv"]);
    let csv = std::fs::read_to_string(out.join("cadastre.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.iter().map(|r| r[0]).collect::<Vec<_>>(), ["A/RoofSurface/1", "B/RoofSurface/1"], "{csv}");
    assert!((rows[0][2].parse::<f64>().unwrap() - twisted).abs() < 1e-3, "the parts' areas summed: {csv}");
    assert!(rows.iter().all(|r| r[6].parse::<f64>().unwrap() > 100.0), "both roofs get the sun: {csv}");
    let cadastre = out.join("cadastre.city.json");
    assert_valid_cityjson(&cadastre);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&cadastre).unwrap()).unwrap();
    let geometry = &doc["CityObjects"]["A"]["geometry"][0]["semantics"];
    let roof = &geometry["surfaces"][geometry["values"][1].as_u64().unwrap() as usize];
    assert_eq!(roof["type"], "RoofSurface");
    let total: f64 = rows[0][6].parse().unwrap();
    assert!((roof["total_kwh_m2"].as_f64().unwrap() - total).abs() < 1e-3, "{roof} against the CSV's {total}");
}

/// Geometry nested a level deeper: a building as a `CompositeSolid` of two boxes (x 0–10 m, 6 m
/// high; x 10–20 m, 9 m high) beside one as a `Solid`. Every roof and wall is a receiver named by
/// its place among the geometry's surfaces (solids and shells flattened in file order), and the
/// cadastre puts its values on the semantic surface that place points at, three levels down in a
/// `CompositeSolid`'s `values`, which `cjval` passes. (`MultiSolid`, which the reader takes too,
/// is no geometry a CityJSON 2.0 `Building` may have: `cjval` refuses it.)
#[test]
fn composite_solids_receive_and_get_their_values_back_in_place() {
    let dir = scratch("district-solids");
    let mut vertices: Vec<[i64; 3]> = Vec::new();
    // A box's six faces (ground, roof, four walls), outward, and their semantic values.
    let mut cube = |lo: [i64; 3], hi: [i64; 3]| {
        let base = vertices.len();
        for k in 0..8 {
            vertices.push([
                if k & 1 == 0 { lo[0] } else { hi[0] },
                if k & 2 == 0 { lo[1] } else { hi[1] },
                if k & 4 == 0 { lo[2] } else { hi[2] },
            ]);
        }
        let f = |q: [usize; 4]| serde_json::json!([q.map(|i| base + i)]);
        let faces = [f([0, 2, 3, 1]), f([4, 5, 7, 6]), f([0, 1, 5, 4]), f([1, 3, 7, 5]), f([3, 2, 6, 7]), f([2, 0, 4, 6])];
        (serde_json::json!([faces]), serde_json::json!([[0, 1, 2, 2, 2, 2]]))
    };
    let (a, a_values) = cube([0, 0, 0], [10_000, 10_000, 6_000]);
    let (b, b_values) = cube([10_000, 0, 0], [20_000, 10_000, 9_000]);
    let (c, c_values) = cube([40_000, 0, 0], [50_000, 10_000, 12_000]);
    let surfaces = serde_json::json!([{"type": "GroundSurface"}, {"type": "RoofSurface"}, {"type": "WallSurface"}]);
    let solid = |kind: &str, boundaries: Vec<serde_json::Value>, values: Vec<serde_json::Value>| serde_json::json!({"type": "Building", "geometry": [{"type": kind, "lod": "2", "boundaries": boundaries, "semantics": {"surfaces": surfaces, "values": values}}]});
    let doc = serde_json::json!({"type": "CityJSON", "version": "2.0", "transform": {"scale": [0.001, 0.001, 0.001], "translate": [85000.0, 446000.0, 0.0]},
        "metadata": {"referenceSystem": "https://www.opengis.net/def/crs/EPSG/0/7415"},
        "CityObjects": {"twin": solid("CompositeSolid", vec![a, b], vec![a_values, b_values]), "lone": solid("Solid", c.as_array().unwrap().clone(), c_values.as_array().unwrap().clone())},
        "vertices": vertices});
    let city = dir.join("solids.city.json");
    std::fs::write(&city, doc.to_string()).unwrap();
    assert_valid_cityjson(&city);
    let mut names = receiver_names(&info(&[city.to_str().unwrap()]));
    names.sort();
    let mut expected: Vec<String> = ["twin", "lone"]
        .iter()
        .flat_map(|id| {
            let solids = if *id == "twin" { 2 } else { 1 };
            (0..solids).flat_map(move |s| {
                (1..6).map(move |k| format!("{id}/{}/{}", if k == 1 { "RoofSurface" } else { "WallSurface" }, 6 * s + k))
            })
        })
        .collect();
    expected.sort();
    assert_eq!(names, expected);
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let out = dir.join("out");
    let run = district(&city, &epw, &out, &["--tile", "100", "--context", "100"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let rows = tile_rows(&out);
    assert_eq!(rows.keys().cloned().collect::<std::collections::BTreeSet<_>>(), expected.iter().cloned().collect());
    let cadastre = out.join("cadastre.city.json");
    assert_valid_cityjson(&cadastre);
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&cadastre).unwrap()).unwrap();
    for name in &expected {
        let mut parts = name.split('/');
        let (id, kind, index) = (parts.next().unwrap(), parts.next().unwrap(), parts.next().unwrap().parse::<usize>().unwrap());
        let semantics = &doc["CityObjects"][id]["geometry"][0]["semantics"];
        let value = if id == "twin" { &semantics["values"][index / 6][0][index % 6] } else { &semantics["values"][0][index] };
        let value = value.as_u64().unwrap_or_else(|| panic!("{name}: {semantics}"));
        let surface = &semantics["surfaces"][value as usize];
        assert_eq!(surface["type"], kind, "{name}: {surface}");
        let total = surface["total_kwh_m2"].as_f64().unwrap_or_else(|| panic!("{name}: {surface}"));
        assert!((total - rows[name][4]).abs() < 1e-3, "{name}: {total} in the CityJSON, {} in its tile", rows[name][4]);
    }
    // The roofs differ in height and the walls in facing, so a value in the wrong place shows.
    let totals: std::collections::BTreeSet<u64> = rows.values().map(|v| (v[4] * 1000.0) as u64).collect();
    assert!(totals.len() > 6, "{rows:?}");
}

/// Receivers by attribute (`--where`), one rule for `info`, `annual` and `district`: the block's
/// house part takes its `Building`'s `function` (a part sees its parents' attributes), the
/// courtyard's `measuredHeight` 10.0 meets `=10` (numbers compare as numbers, not as the text
/// `10.0`), the roofs' semantic surfaces' own `slope` selects them with `--receivers`, and a rule
/// that leaves no surface is refused naming its attribute, before anything is written.
#[test]
fn receivers_by_attribute_alike_in_info_annual_and_district() {
    assert_valid_cityjson(Path::new(BLOCK));
    let names = |args: &[&str]| receiver_names(&info(&[&[BLOCK][..], args].concat()));
    let house = names(&["--where", "function=residential"]);
    assert_eq!(house.len(), 6, "{house:?}");
    assert!(house.iter().all(|n| n.starts_with("NL.B.house.part/")), "{house:?}");
    assert_eq!(names(&["--where", "function = RESID*"]), house, "text is a case-insensitive glob");
    let courtyard = names(&["--where", "measuredHeight=10"]);
    assert_eq!(courtyard.len(), 9, "{courtyard:?}");
    assert!(courtyard.iter().all(|n| n.starts_with("NL.B.courtyard/")), "{courtyard:?}");
    assert_eq!(names(&["--where", "storeysAboveGround>=3"]), courtyard);
    assert_eq!(names(&["--where", "storeysAboveGround<3"]), house);
    assert_eq!(names(&["--where", "function!=office", "--where", "storeysAboveGround>1"]), house, "rules together");
    let steep = names(&["--receivers", "RoofSurface", "--where", "slope>30"]);
    assert_eq!(steep, ["NL.B.house.part/RoofSurface/5", "NL.B.house.part/RoofSurface/6"]);
    // The same rule in annual and district gives the same receivers; the cadastre stays valid.
    let dir = scratch("city-where");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let csv = dir.join("house.csv");
    let annual = sunlit(&[
        "annual",
        BLOCK,
        "--epw",
        epw.to_str().unwrap(),
        "-o",
        csv.to_str().unwrap(),
        "--where",
        "function=residential",
        "--engine",
        "exact",
        "--days-per-year",
        "4",
        "--samples-per-day",
        "5",
    ]);
    assert!(annual.status.success(), "{}", stderr(&annual));
    let header = std::fs::read_to_string(&csv).unwrap().lines().next().unwrap().to_string();
    assert_eq!(header, format!("Surface Name,{},", house.join(",")));
    let out = dir.join("house");
    let run = district(Path::new(BLOCK), &epw, &out, &["--tile", "50", "--context", "50", "--where", "function=residential"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let rows: Vec<String> = tile_rows(&out).keys().cloned().collect();
    let mut sorted = house.clone();
    sorted.sort();
    assert_eq!(rows, sorted);
    assert_valid_cityjson(&out.join("cadastre.city.json"));
}

/// A `--where` rule that leaves no surface is refused naming the rule and its attribute, in
/// `info`, `annual` (no CSV) and `district` (no folder: its first pass puts the rules to every
/// surface, as the load does, before anything is written); so is a malformed rule.
#[test]
fn a_where_rule_leaving_no_surface_is_refused_before_anything_is_written() {
    let dir = scratch("city-where-none");
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    for (rule, why) in [
        ("function=shop", "--where function=shop: of the 15 surfaces chosen, 15 have the attribute 'function', and none meets the rule"),
        ("usage=x", "--where usage=x: no surface of the 15 chosen has the attribute 'usage'"),
        ("storeysAboveGround<two", "invalid --where: 'storeysAboveGround<two': < compares numbers, and 'two' is not one"),
    ] {
        let info = sunlit(&["info", BLOCK, "--where", rule]);
        assert_eq!(info.status.code(), Some(1), "{rule}");
        assert!(stderr(&info).contains(why), "{rule}: {}", stderr(&info));
        let csv = dir.join("none.csv");
        let annual = sunlit(&["annual", BLOCK, "--location", "52,5,1", "-o", csv.to_str().unwrap(), "--where", rule]);
        assert_eq!(annual.status.code(), Some(1), "{rule}");
        assert!(stderr(&annual).contains(why) && !csv.exists(), "{rule}: {}", stderr(&annual));
        let out = dir.join("none");
        let run = district(Path::new(BLOCK), &epw, &out, &["--tile", "50", "--context", "50", "--where", rule]);
        assert_eq!(run.status.code(), Some(1), "{rule}");
        assert!(stderr(&run).contains(why) && !out.exists(), "{rule}: {}", stderr(&run));
    }
    let out = dir.join("none");
    let flat = ["--tile", "50", "--context", "50", "--receivers", "RoofSurface", "--where", "slope<30"];
    let run = district(Path::new(BLOCK), &epw, &out, &flat);
    assert_eq!(run.status.code(), Some(1));
    assert!(stderr(&run).contains("of the 3 surfaces chosen, 2 have the attribute 'slope', and none meets the rule"), "{}", stderr(&run));
    assert!(!out.exists());
}

/// `MultiSolid` geometry is read: CityJSON 2.0 gives it to no `Building`, so here it is an
/// `OtherConstruction`, two 9 m pillars 2 m × 2 m standing 1 m south of a 10 m × 10 m flat roof
/// 3 m high, with semantics nested a solid, a shell and a surface deep. Its 12 surfaces are
/// read with their types, and it shades the roof as the analytic shadow says: for the sun due
/// south at altitude a, each pillar darkens a 2 m wide strip of the roof min(10, 6 / tan a − 1) m
/// long.
#[test]
fn a_multisolid_is_read_and_shades_a_roof_as_its_analytic_shadow() {
    let dir = scratch("city-multisolid");
    let mut vertices: Vec<[i64; 3]> = Vec::new();
    let mut cube = |lo: [i64; 3], hi: [i64; 3]| {
        let base = vertices.len();
        for k in 0..8 {
            vertices.push([0, 1, 2].map(|a| if k >> a & 1 == 1 { hi[a] } else { lo[a] }));
        }
        // Roof, ground, then four walls; corners by bits (x, y, z), counter-clockwise from outside.
        let faces = [[4, 5, 7, 6], [0, 2, 3, 1], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        serde_json::json!([faces.map(|f| [f.map(|i| base + i)])])
    };
    let house = cube([0, 0, 0], [10_000, 10_000, 3_000]);
    let pillars = [cube([2_000, -3_000, 0], [4_000, -1_000, 9_000]), cube([6_000, -3_000, 0], [8_000, -1_000, 9_000])];
    let surfaces = serde_json::json!([{"type": "RoofSurface"}, {"type": "GroundSurface"}, {"type": "WallSurface"}]);
    let values = serde_json::json!([[0, 1, 2, 2, 2, 2]]);
    let doc = serde_json::json!({"type": "CityJSON", "version": "2.0", "transform": {"scale": [0.001, 0.001, 0.001], "translate": [85000.0, 446000.0, 0.0]},
        "CityObjects": {
            "H": {"type": "Building", "geometry": [{"type": "Solid", "lod": "2.2", "boundaries": house, "semantics": {"surfaces": surfaces, "values": values}}]},
            "P": {"type": "OtherConstruction", "geometry": [{"type": "MultiSolid", "lod": "2", "boundaries": pillars,
                "semantics": {"surfaces": surfaces, "values": [values, values]}}]}},
        "vertices": vertices});
    let city = dir.join("pillars.city.json");
    std::fs::write(&city, doc.to_string()).unwrap();
    assert_valid_cityjson(&city);
    let bytes = std::fs::read(&city).unwrap();
    let read = sunlit::model::cityjson::read_city("pillars.city.json", &bytes, None).unwrap();
    let pillar: Vec<&str> = read.surfaces.iter().filter(|s| s.object == "P").map(|s| s.name.as_str()).collect();
    assert_eq!(pillar.len(), 12, "{pillar:?}");
    assert_eq!((pillar[0], pillar[6], pillar[11]), ("P/RoofSurface/0", "P/RoofSurface/6", "P/WallSurface/11"));
    assert!(read.surfaces.iter().filter(|s| s.object == "P").all(|s| s.building.is_none()), "a pillar only casts");
    let options = sunlit::model::LoadOptions { receivers: vec!["RoofSurface".into()], ..Default::default() };
    let scene = sunlit::model::load_bytes(&[("pillars.city.json".into(), bytes)], &options).unwrap();
    assert_eq!(scene.receivers.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["H/RoofSurface/0"]);
    for altitude in [30.0_f64, 45.0, 60.0] {
        let strip = (6.0 / altitude.to_radians().tan() - 1.0).clamp(0.0, 10.0);
        let want = 1.0 - 2.0 * 2.0 * strip / 100.0;
        let requests = [ViewRequest::new(0, common::sun(180.0, altitude))];
        let got = pollster::block_on(Exact { scene: &scene }.answer(&requests)).unwrap()[0].fraction;
        assert!((got - want).abs() < 1e-4, "sun at {altitude}°: sunlit {got}, the analytic shadow {want}");
    }
}

/// `district --year-table` writes every receiver's whole-year table, `cadastre-year.csv`, and it
/// is the CSV `sunlit annual` writes of the city for the same receivers: the same header (the
/// same columns in the same order) and the same stamps, each value within 1e-9, with
/// `--engine exact` and a context reaching across the city (the radius that holds every shadow);
/// here from tiles of 30 m counted by two child processes a few receivers a batch, each batch's
/// table a part file of its tile. A second run counts nothing and writes the same table.
#[test]
fn district_year_tables_are_annuals_csv_of_the_same_receivers() {
    let dir = scratch("district-year-table");
    let city = dir.join("district.city.json");
    std::fs::write(&city, sunlit::model::city_write::district_cityjson(3, 3, 7)).unwrap();
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let annual_csv = dir.join("annual.csv");
    let (c, e, a) = (city.to_str().unwrap(), epw.to_str().unwrap(), annual_csv.to_str().unwrap());
    #[rustfmt::skip]
    let annual = sunlit(&[
        "annual", c, "--epw", e, "-o", a, "--engine", "exact", "--days-per-year", "4", "--samples-per-day", "5",
        "--timesteps-per-hour", "1",
    ]);
    assert!(annual.status.success(), "{}", stderr(&annual));
    let out = dir.join("tiled");
    let args = ["--tile", "30", "--context", "1000", "--jobs", "2", "--receiver-batch", "7", "--year-table"];
    let run = district(&city, &epw, &out, &args);
    assert!(run.status.success(), "{}", stderr(&run));
    let parts = std::fs::read_dir(out.join("year")).unwrap().count();
    let tiles = std::fs::read_dir(out.join(".done")).unwrap().count();
    assert!(tiles >= 4 && parts > tiles, "{parts} parts of {tiles} tiles");
    let table = std::fs::read_to_string(out.join("cadastre-year.csv")).unwrap();
    let whole = std::fs::read_to_string(&annual_csv).unwrap();
    let (mut t, mut w) = (table.lines(), whole.lines());
    let header = w.next().unwrap();
    assert_eq!(t.next().unwrap(), header);
    assert!(header.split(',').count() > 40, "{header}");
    let mut rows = 0;
    let mut differ = 0;
    for (x, y) in t.by_ref().zip(w.by_ref()) {
        let (xs, ys): (Vec<&str>, Vec<&str>) = (x.split(',').collect(), y.split(',').collect());
        assert_eq!((xs[0], xs.len()), (ys[0], ys.len()), "row {rows}");
        for (a, b) in xs[1..xs.len() - 1].iter().zip(&ys[1..]) {
            let (a, b): (f64, f64) = (a.parse().unwrap(), b.parse().unwrap());
            assert!((a - b).abs() <= 1e-9, "row {rows}: {a} tiled, {b} by annual");
        }
        differ += (x != y) as usize;
        rows += 1;
    }
    assert_eq!((rows, t.next(), w.next()), (8760, None, None));
    assert!(
        whole
            .lines()
            .skip(1)
            .any(|l| l.split(',').skip(1).any(|v| !v.is_empty() && v.parse::<f64>().unwrap() > 0.0 && v.parse::<f64>().unwrap() < 1.0)),
        "some partial shade"
    );
    // The same origin and the same views: the same bytes, too.
    assert_eq!(differ, 0, "rows that differ as text");
    // The cadastre written with the option passes cjval; a second run counts nothing, same table.
    assert_valid_cityjson(&out.join("cadastre.city.json"));
    let again = district(&city, &epw, &out, &args);
    assert!(again.status.success() && stderr(&again).contains("0 to count"), "{}", stderr(&again));
    assert!(std::fs::read_to_string(out.join("cadastre-year.csv")).unwrap() == table);
}
