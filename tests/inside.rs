//! The sun inside rooms (`sunlit::map::inside`, `map --inside`): a box room with one south window
//! against the analytic sun patch, an independent numpy ray caster (points, and LEED ASE on the
//! Golden EPW's hours), and the refusals.
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::Scratch;
use common::inside::{golden_epw, numpy_reference};

use std::process::Command;

use glam::DVec3;
use serde_json::{Value, json};
use sunlit::map::Mapper;
use sunlit::map::inside::{self, InsideInstant, InsideMap, RoomPoints};
use sunlit::map::{Period, Site};
use sunlit::model::inside::{Rooms, inside_scene, rooms};
use sunlit::model::{self, LoadOptions};
use sunlit::scene::Scene;
use sunlit::sun::location::Location;
use sunlit::sun::position::sun_direction;
use sunlit::sun::weather::Weather;
use sunlit::year::annual::shading_sun_day;
use sunlit::year::season::LeafCalendar;

/// Room 4 m (x) × 5 m (y) × 3 m, window x 1–3 m, z 1–2.5 m in the south wall (y = 0).
const ROOM: [f64; 3] = [4.0, 5.0, 3.0];
const WINDOW: [f64; 4] = [1.0, 3.0, 1.0, 2.5];
/// Overhang x 0.5–3.5 m, 0.8 m deep, at z 2.7 m.
const OVERHANG: [f64; 4] = [0.5, 3.5, 0.8, 2.7];
const VT: f64 = 0.7;

fn surface(name: &str, kind: &str, boundary: &str, corners: &[[f64; 3]]) -> String {
    let v: Vec<String> = corners.iter().map(|c| format!("{},{},{}", c[0], c[1], c[2])).collect();
    let sun = if boundary == "Outdoors" { "SunExposed,WindExposed" } else { "NoSun,NoWind" };
    format!("BuildingSurface:Detailed,{name},{kind},Opaque,Office,,{boundary},,{sun},,{},{};\n", corners.len(), v.join(","))
}

/// The box room's IDF; `window` gives the window's corners (x0, x1, z0, z1) and `extra` more objects.
fn room_idf(window: [f64; 4], overhang: bool, extra: &str) -> String {
    let [w, d, h] = ROOM;
    let [x0, x1, z0, z1] = window;
    let mut idf = String::from(
        "Version,25.2;\nBuilding,Box,0,Suburbs,0.04,0.4,FullInteriorAndExterior,25,6;\n\
         GlobalGeometryRules,UpperLeftCorner,Counterclockwise,Relative;\nZone,Office,0,0,0,0;\n\
         Construction,Opaque,Layer;\nConstruction,Glass,SimpleGlass;\n\
         WindowMaterial:SimpleGlazingSystem,SimpleGlass,2.0,0.6,0.7;\n",
    );
    idf += &surface("South", "Wall", "Outdoors", &[[0.0, 0.0, h], [0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, 0.0, h]]);
    idf += &surface("North", "Wall", "Outdoors", &[[w, d, h], [w, d, 0.0], [0.0, d, 0.0], [0.0, d, h]]);
    idf += &surface("East", "Wall", "Outdoors", &[[w, 0.0, h], [w, 0.0, 0.0], [w, d, 0.0], [w, d, h]]);
    idf += &surface("West", "Wall", "Outdoors", &[[0.0, d, h], [0.0, d, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, h]]);
    idf += &surface("Floor", "Floor", "Ground", &[[w, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, d, 0.0], [w, d, 0.0]]);
    idf += &surface("Roof", "Roof", "Outdoors", &[[0.0, 0.0, h], [w, 0.0, h], [w, d, h], [0.0, d, h]]);
    idf += &format!("FenestrationSurface:Detailed,Win,Window,Glass,South,,,,1,4,{x0},0,{z1},{x0},0,{z0},{x1},0,{z0},{x1},0,{z1};\n");
    if overhang {
        let [ox0, ox1, depth, oz] = OVERHANG;
        idf += &format!("Shading:Building:Detailed,Overhang,,4,{ox0},0,{oz},{ox0},{},{oz},{ox1},{},{oz},{ox1},0,{oz};\n", -depth, -depth);
    }
    idf + extra
}

/// A window in the east wall's plane (x = 4), named on the south wall.
const EAST_PLANE_WINDOW: &str = "4,1,2.5,4,1,1,4,3,1,4,3,2.5";
/// The window turned 18° about its sill: its head 0.5 m out of the south wall.
const TILTED_WINDOW: &str = "1,-0.5,2.5,1,0,1,3,0,1,3,-0.5,2.5";

/// The box room with the window's four corners as written (`x,y,z` × 4, upper left first).
fn room_idf_with_window(corners: &str, overhang: bool, extra: &str) -> String {
    let [x0, x1, z0, z1] = WINDOW;
    let written = format!("{x0},0,{z1},{x0},0,{z0},{x1},0,{z0},{x1},0,{z1};");
    let idf = room_idf(WINDOW, overhang, extra);
    assert!(idf.contains(&written));
    idf.replace(&written, &format!("{corners};"))
}

fn load(idf: &str) -> sunlit::Result<(Scene, Rooms)> {
    let loaded = model::load_bytes_all(&[("room.idf".to_string(), idf.as_bytes().to_vec())], &LoadOptions::default())?;
    let ep = loaded.energyplus.unwrap();
    Ok((inside_scene(&ep)?, rooms(&ep, None)?))
}

/// The sun patch the window casts on the floor: the window projected along the sun onto z = 0,
/// area × |n_window · s| / |n_floor · s|.
fn analytic_floor_patch(sun: DVec3) -> f64 {
    let [x0, x1, z0, z1] = WINDOW;
    (x1 - x0) * (z1 - z0) * sun.y.abs() / sun.z
}

#[test]
fn floor_sun_patch_matches_the_analytic_projection_of_the_window() {
    let (scene, rooms) = load(&room_idf(WINDOW, false, "")).unwrap();
    for sun in [DVec3::new(0.2, -0.8, 0.7), DVec3::new(-0.3, -0.6, 0.9), DVec3::new(0.0, -0.5, 0.8)] {
        let sun = sun.normalize();
        let patches = inside::sun_patches(&scene, &rooms, sun, 1.0);
        let floor = patches.iter().find(|p| p.surface == "Floor:inside").unwrap();
        let expected = analytic_floor_patch(sun);
        eprintln!("sun {sun}: floor patch {} m², analytic {expected} m²", floor.area_m2);
        assert!((floor.area_m2 - expected).abs() <= 0.005 * expected, "sun {sun}: {} m² against {expected} m²", floor.area_m2);
        // Only the floor is lit: the beam misses the side walls and the window's own wall.
        assert_eq!(patches.len(), 1, "{patches:?}");
    }
    // A sun behind the window's wall lights nothing inside.
    assert!(inside::sun_patches(&scene, &rooms, DVec3::new(0.0, 0.6, 0.8), 1.0).is_empty());
}

fn positions(at: &RoomPoints) -> Vec<[f64; 3]> {
    (0..at.points.len()).map(|i| at.points.position(i).to_array()).collect()
}

/// Each sun's instant on `at` against the numpy ray caster's (its query's window, overhang and
/// `extra` fields): at most 1 % of the points differ, and over 100 are lit. Per sun the sun, our
/// answer and numpy's `lit`; and numpy's whole answer.
fn lit_against_numpy(
    scene: &Scene,
    rooms: &Rooms,
    at: &RoomPoints,
    suns: &[[f64; 3]],
    extra: Value,
) -> (Vec<(DVec3, InsideInstant, Vec<f64>)>, Value) {
    let mapper = Mapper::new(scene, &at.points).unwrap();
    let suns: Vec<DVec3> = suns.iter().map(|s| DVec3::from_array(*s).normalize()).collect();
    let mut query = json!({"window": WINDOW, "overhang": OVERHANG, "points": positions(at), "normal": [0, 0, 1],
        "suns": suns.iter().map(|s| s.to_array()).collect::<Vec<_>>()});
    query.as_object_mut().unwrap().extend(extra.as_object().unwrap().clone());
    let reference = numpy_reference(&query);
    let answers = suns
        .iter()
        .enumerate()
        .map(|(k, &sun)| {
            let ours = inside::instant(InsideMap { mapper: &mapper, rooms, at }, sun, 1.0);
            let theirs: Vec<f64> = reference["lit"][k].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            let differ = ours.lit.iter().zip(&theirs).filter(|(a, b)| a != b).count();
            let lit = theirs.iter().filter(|&&v| v == 1.0).count();
            eprintln!("sun {sun}: {lit} points lit by numpy, {differ} of {} differ", at.points.len());
            assert!(lit > 100, "sun {sun}: the reference lights only {lit} points");
            assert!(differ * 100 <= at.points.len(), "sun {sun}: {differ} of {} points differ", at.points.len());
            (sun, ours, theirs)
        })
        .collect();
    (answers, reference)
}

#[test]
fn work_plane_grid_agrees_with_a_numpy_ray_caster() {
    let (mut scene, rooms) = load(&room_idf(WINDOW, true, "")).unwrap();
    let at = inside::floor_grid(&mut scene, &rooms, 0.1, 0.76).unwrap();
    assert_eq!(at.points.len(), 40 * 50);
    let suns = [[0.2, -0.8, 0.7], [-0.5, -0.5, 0.5], [0.1, -0.9, 0.45], [0.35, -0.7, 0.6]];
    let (answers, reference) = lit_against_numpy(&scene, &rooms, &at, &suns, json!({"vt": VT, "angular": "E"}));
    for (k, (sun, ours, theirs)) in answers.into_iter().enumerate() {
        // Lit through glass: the weight is the glass's visible transmittance at the beam's
        // incidence on it, by EnergyPlus's curve E (numpy's own), not its normal value (these
        // suns meet the window at cos 0.58 to 0.89: E takes 1.6 % to 11 % off); the solar weight
        // falls off by the same share of the solar value.
        let visible: Vec<f64> = reference["visible"][k].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let solar = rooms.glazing[0].solar;
        for (i, (l, t)) in ours.lit.iter().zip(&ours.visible_transmittance).enumerate() {
            if *l != theirs[i] {
                continue;
            }
            let p = at.points.position(i);
            assert!((t - visible[i]).abs() < 1e-9, "sun {sun}: point {p} lit {l} with visible transmittance {t}, numpy {}", visible[i]);
            let s = ours.solar_transmittance[i];
            assert!((s / solar - t / VT).abs() < 1e-9, "sun {sun}: point {p}: solar weight {s} of {solar}, visible {t} of {VT}");
        }
        assert!(visible.iter().any(|&v| v > 0.0 && v < 0.995 * VT), "sun {sun}: the curve should take something off");
    }
}

/// LEED ASE of the rooms' work plane over Golden's occupied hours, and numpy's ASE (%) of the
/// same points and hours (its query's `extra` fields give the glass).
fn ase_against_numpy(scene: &mut Scene, rooms: &Rooms, extra: Value) -> (inside::AseResult, f64) {
    let at = inside::floor_grid(scene, rooms, inside::ASE_SPACING, inside::WORK_PLANE_HEIGHT).unwrap();
    let weather = Weather::from_epw(&golden_epw()).unwrap();
    let location: Location = weather.location.clone();
    let calendar = LeafCalendar::evergreen();
    let site = Site { location: &location, calendar: &calendar, weather: Some(&weather), sky: None };
    let samples = inside::occupied_hours(&Period::annual(1).unwrap().samples());
    assert_eq!(samples.len(), 3650);
    let mapper = Mapper::new(scene, &at.points).unwrap();
    let ours = inside::leed_ase(InsideMap { mapper: &mapper, rooms, at: &at }, &samples, site, &mut |_, _| {}).unwrap();
    let suns: Vec<[f64; 3]> = samples.iter().map(|s| sun_direction(&location, shading_sun_day(s.day), s.hour).to_array()).collect();
    let lux: Vec<f64> = samples.iter().map(|s| weather.direct_normal_illuminance(s.epw_hour).unwrap()).collect();
    let mut query = json!({"window": WINDOW, "overhang": OVERHANG, "points": positions(&at), "normal": [0, 0, 1],
        "suns": suns, "lux": lux});
    query.as_object_mut().unwrap().extend(extra.as_object().unwrap().clone());
    let hours: Vec<f64> = numpy_reference(&query)["hours_over"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let theirs = 100.0 * hours.iter().filter(|&&h| h > inside::ASE_HOURS).count() as f64 / hours.len() as f64;
    assert!(theirs > 5.0 && theirs < 95.0, "the case should split the room: numpy's ASE is {theirs} %");
    eprintln!("ASE {} % against numpy's {theirs} % ({} points)", ours.areas[0].ase, hours.len());
    (ours, theirs)
}

/// Golden, CO TMY3 from the EnergyPlus wheel (as the other EPW tests find it).
#[test]
fn leed_ase_matches_a_numpy_ray_caster_on_the_golden_epw() {
    let (mut scene, rooms) = load(&room_idf(WINDOW, true, "")).unwrap();
    let (ours, theirs) = ase_against_numpy(&mut scene, &rooms, json!({"vt": VT, "angular": "E"}));
    assert_eq!(ours.efficacy_hours, 0, "Golden's EPW has direct normal illuminance every hour");
    let area = &ours.areas[0];
    assert_eq!(area.zone, "OFFICE");
    assert!((area.ase - theirs).abs() <= 1.0, "ASE {} % against numpy's {theirs} %", area.ase);
}

#[test]
fn bad_rooms_are_refused_naming_the_object() {
    // A window that sticks out of its wall.
    let err = load(&room_idf([3.0, 4.5, 1.0, 2.5], false, "")).unwrap_err().to_string();
    assert!(err.contains("Win") && err.contains("not within its base surface"), "{err}");
    // A window drawn in the east wall's plane but named on the south wall: cast onto the south
    // wall it is a line on the wall's edge, so it opens nothing there and the room would be dark.
    let err = load(&room_idf_with_window(EAST_PLANE_WINDOW, false, "")).unwrap_err().to_string();
    assert!(err.contains("Win") && err.contains("does not lie in its base surface 'South'") && err.contains("90.0°"), "{err}");
    // Turned 18° out of its wall (its head 0.5 m out), its opening is still the hole in the wall.
    load(&room_idf_with_window(TILTED_WINDOW, false, "")).unwrap();
    // A glazing transmittance outside 0..1.
    let idf = room_idf(WINDOW, false, "").replace("SimpleGlass,2.0,0.6,0.7", "SimpleGlass,2.0,0.6,1.3");
    let err = load(&idf).unwrap_err().to_string();
    assert!(err.contains("SimpleGlass") && err.contains("Visible Transmittance 1.3"), "{err}");
    // A zone without a floor (its floor given to another zone).
    let idf = room_idf(WINDOW, false, "Zone,Attic,0,0,0,0;\n")
        + &surface("AtticRoof", "Roof", "Outdoors", &[[0.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 5.0, 4.0], [0.0, 5.0, 4.0]])
            .replace("Office", "Attic");
    let (mut scene, rooms) = load(&idf).unwrap();
    let err = inside::floor_grid(&mut scene, &rooms, 0.6, 0.76).unwrap_err().to_string();
    assert!(err.contains("ATTIC") && err.contains("no floor"), "{err}");
    // A free point outside every room.
    let (mut scene, rooms) = load(&room_idf(WINDOW, false, "")).unwrap();
    let err =
        inside::room_points_csv(&mut scene, &rooms, "p.csv", "x,y,z,nx,ny,nz\n2,2,0.76,0,0,1\n9,2,0.76,0,0,1\n").unwrap_err().to_string();
    assert!(err.contains("p.csv") && err.contains("line 3") && err.contains("no zone"), "{err}");
}

fn sunlit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).output().unwrap()
}

#[test]
fn map_inside_cli_writes_lit_weights_patches_and_ase() {
    let tmp = Scratch::new("inside", "map_inside_cli_writes_lit_weights_patches_and_ase");
    let idf = tmp.join("room.idf");
    std::fs::write(&idf, room_idf(WINDOW, false, "")).unwrap();
    let csv = tmp.join("at.csv");
    let out = sunlit(&[
        "map",
        idf.to_str().unwrap(),
        "--inside",
        "--grid",
        "0.25",
        "--location",
        "40,-105,-7",
        "--at",
        "03-21",
        "12:00",
        "-o",
        csv.to_str().unwrap(),
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    let location = Location::parse("40,-105,-7").unwrap();
    let sun = sun_direction(&location, shading_sun_day(80), 12.0);
    let floor = summary["sun_patches"].as_array().unwrap().iter().find(|p| p["surface"] == "Floor:inside").unwrap().clone();
    let expected = analytic_floor_patch(sun);
    let area = floor["area_m2"].as_f64().unwrap();
    assert!((area - expected).abs() <= 0.005 * expected, "{area} m² against {expected} m²");
    assert_eq!(floor["zone"], "OFFICE");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("receiver,x,y,z,nx,ny,nz,lit,solar_transmittance,visible_transmittance\n"), "{}", &text[..80]);
    assert!(text.lines().any(|l| l.starts_with("Floor:inside,") && l.contains(",1,")), "no lit floor point");

    // LEED ASE through the CLI: `POINTS.study-leed-ase.json` has `areas` with the zone and a
    // numeric `ase` (%), numpy's on the same 0.6 m work plane at 0.76 m and Golden's 3,650
    // occupied hours within 1 point; the CSV is its map, each point's hours over 1,000 lux, and
    // the share of points over 250 h is the room's `ase`.
    let (ase_idf, ase_csv) = (tmp.join("ase.idf"), tmp.join("ase.csv"));
    std::fs::write(&ase_idf, room_idf(WINDOW, true, "")).unwrap();
    let epw = golden_epw();
    let args = ["map", ase_idf.to_str().unwrap(), "--inside", "--epw", epw.to_str().unwrap(), "--study", "leed-ase"];
    let out = sunlit(&[&args[..], &["-o", ase_csv.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(tmp.join("ase.study-leed-ase.json")).unwrap()).unwrap();
    let areas = report["areas"].as_array().unwrap();
    assert_eq!((areas.len(), areas[0]["zone"].as_str()), (1, Some("OFFICE")), "{report}");
    let ase = areas[0]["ase"].as_f64().expect("a numeric ase");
    let (mut scene, rooms) = load(&room_idf(WINDOW, true, "")).unwrap();
    let (ours, theirs) = ase_against_numpy(&mut scene, &rooms, json!({"vt": VT, "angular": "E"}));
    assert!((ase - theirs).abs() <= 1.0, "the CLI's ASE {ase} % against numpy's {theirs} %");
    assert!((ase - ours.areas[0].ase).abs() < 1e-3 && areas[0]["points"] == ours.areas[0].points, "{report}");
    assert!(report["occupied"].as_str().unwrap().contains("no daylight saving shift"), "{report}");
    let text = std::fs::read_to_string(&ase_csv).unwrap();
    assert!(text.lines().next().unwrap().ends_with(",hours_over_1000_lux"), "{}", &text[..80]);
    let hours: Vec<f64> = text.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect();
    assert_eq!(hours.len(), ours.areas[0].points);
    let over = 100.0 * hours.iter().filter(|&&h| h > inside::ASE_HOURS).count() as f64 / hours.len() as f64;
    assert!((over - ase).abs() < 1e-3, "{over} % of the map's points over 250 h against ASE {ase} %");

    // Refused before anything is written: a glass transmittance outside 0..1, a study without --inside.
    let bad = tmp.join("bad.csv");
    for args in [
        vec!["--inside", "--glass-transmittance", "1.5", "--location", "40,-105,-7"],
        vec!["--study", "leed-ase", "--location", "40,-105,-7"],
    ] {
        let mut all = vec!["map", idf.to_str().unwrap(), "-o", bad.to_str().unwrap()];
        all.extend(args);
        let out = sunlit(&all);
        assert!(!out.status.success());
        assert!(!bad.exists());
    }
}

/// Each bad input of the issue through the CLI, as a user meets it under `--study leed-ase`: an
/// error naming the object (and why), and neither the points CSV nor the study's report written.
#[test]
fn map_inside_cli_refuses_each_bad_input_naming_it_and_writes_nothing() {
    let tmp = Scratch::new("inside", "map_inside_cli_refuses_each_bad_input_naming_it_and_writes_nothing");
    let epw = golden_epw();
    let outside = tmp.join("outside.csv");
    std::fs::write(&outside, "x,y,z,nx,ny,nz\n2,2,0.76,0,0,1\n9,2,0.76,0,0,1\n").unwrap();
    let attic = surface("AtticRoof", "Roof", "Outdoors", &[[0.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 5.0, 4.0], [0.0, 5.0, 4.0]])
        .replace("Office", "Attic");
    let good = room_idf(WINDOW, true, "");
    let cases: Vec<(String, Vec<&str>, Vec<&str>)> = vec![
        (room_idf([3.0, 4.5, 1.0, 2.5], true, ""), vec![], vec!["'Win'", "is not within its base surface 'South'"]),
        (room_idf_with_window(EAST_PLANE_WINDOW, true, ""), vec![], vec!["'Win'", "does not lie in its base surface 'South'"]),
        (good.replace("SimpleGlass,2.0,0.6,0.7", "SimpleGlass,2.0,0.6,1.3"), vec![], vec!["'SimpleGlass'", "Visible Transmittance 1.3"]),
        (
            good.replace("SimpleGlass,2.0,0.6,0.7", "SimpleGlass,2.0,1.6,0.7"),
            vec![],
            vec!["'SimpleGlass'", "Solar Heat Gain Coefficient 1.6"],
        ),
        (good.replace(",Glass,South,", ",Unread,South,"), vec!["--glass-transmittance", "-0.1"], vec!["glass_transmittance", "-0.1"]),
        (good.clone(), vec!["--points", outside.to_str().unwrap()], vec!["outside.csv", "line 3", "lies in no zone"]),
        (room_idf(WINDOW, true, &format!("Zone,Attic,0,0,0,0;\n{attic}")), vec![], vec!["'ATTIC'", "no floor"]),
    ];
    for (k, (idf, extra, needles)) in cases.into_iter().enumerate() {
        let (model, csv) = (tmp.join(format!("bad{k}.idf")), tmp.join(format!("bad{k}.csv")));
        std::fs::write(&model, idf).unwrap();
        let args = ["map", model.to_str().unwrap(), "--inside", "--epw", epw.to_str().unwrap(), "--study", "leed-ase"];
        let out = sunlit(&[&args[..], &extra[..], &["-o", csv.to_str().unwrap()]].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && needles.iter().all(|n| err.contains(n)), "case {k}: {err}");
        assert!(!csv.exists() && !tmp.join(format!("bad{k}.study-leed-ase.json")).exists(), "case {k} wrote output");
    }
}

/// With two zones, a free point belongs to the zone it lies in, a point on an inside face (within
/// 1 cm, facing its way) to that face, and a free point's normal says which way it looks: at
/// (2, 2, 0.5) a sun from the south-south-east reaches it through the window (its ray leaves the
/// south wall at z 2.0, inside the window's 1.0–2.5) when it faces south or up, and not when it
/// faces north.
#[test]
fn free_points_belong_to_the_zone_they_lie_in_and_look_along_their_normal() {
    // A second zone, a 4 × 5 × 3 m box 1 m north of the office, no window.
    let store: String = room_idf(WINDOW, false, "")
        .lines()
        .filter(|l| l.starts_with("BuildingSurface:Detailed"))
        .map(|l| {
            let (head, tail) = l.split_once(",4,").unwrap();
            let moved: Vec<String> = tail
                .trim_end_matches(';')
                .split(',')
                .enumerate()
                .map(|(i, v)| {
                    let v: f64 = v.parse().unwrap();
                    if i % 3 == 1 { format!("{}", v + 6.0) } else { format!("{v}") }
                })
                .collect();
            format!("{},4,{};\n", head.replacen("Detailed,", "Detailed,Store", 1).replace(",Office,", ",Store,"), moved.join(","))
        })
        .collect();
    let (mut scene, rooms) = load(&room_idf(WINDOW, false, &format!("Zone,Store,0,0,0,0;\n{store}"))).unwrap();
    let zone = |name: &str| rooms.rooms.iter().position(|r| r.name == name).unwrap() as u32;
    let text = "x,y,z,nx,ny,nz\n2,8,0.76,0,0,1\n2,2,0.5,0,-1,0\n2,2,0.5,0,1,0\n2,2,0.5,0,0,1\n2,2,0,0,0,1\n2,5.005,1.5,0,-1,0\n2,10.995,1.5,0,-1,0\n";
    let at = inside::room_points_csv(&mut scene, &rooms, "p.csv", text).unwrap();
    let (office, store) = (zone("OFFICE"), zone("STORE"));
    assert_eq!(at.room, [store, office, office, office, office, office, store]);
    let on = |i: usize| scene.receivers[at.points.receivers[i] as usize].name.clone();
    assert_eq!((on(4).as_str(), on(5).as_str(), on(6).as_str()), ("Floor:inside", "North:inside", "StoreNorth:inside"));
    assert!((0..4).all(|i| on(i).contains("free plane")), "{:?}", (0..4).map(on).collect::<Vec<_>>());
    let err = inside::room_points_csv(&mut scene, &rooms, "p.csv", "x,y,z,nx,ny,nz\n2,5.5,1.5,0,0,1\n").unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("no zone"), "{err}");
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    let sun = DVec3::new(0.2, -0.75, 0.5).normalize();
    let lit = inside::instant(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, sun, 1.0).lit;
    assert_eq!(lit[1..4], [1.0, 0.0, 1.0], "facing south, north, up");
    assert_eq!((lit[0], lit[6]), (0.0, 0.0), "the store has no window");
}

/// The box room and a back room north of it sharing its north wall, with an interzone window
/// pair in it written as EnergyPlus's `Window:Interzone` (each zone its copy, placed in its base
/// wall's own coordinates: both at x 1–3 m, z 0.5–2.5 m) of a construction sunlit cannot read.
fn back_room_idf() -> String {
    let [w, d, h] = ROOM;
    let (y0, y1) = (d, 2.0 * d);
    let back = |name: &str, kind: &str, boundary: &str, corners: &[[f64; 3]]| {
        surface(name, kind, boundary, corners).replace(",Opaque,Office,", ",Opaque,Back,")
    };
    let mut idf = room_idf(WINDOW, false, "Zone,Back,0,0,0,0;\n").replace(
        "BuildingSurface:Detailed,North,Wall,Opaque,Office,,Outdoors,,SunExposed,WindExposed,",
        "BuildingSurface:Detailed,North,Wall,Opaque,Office,,Surface,BackSouth,NoSun,NoWind,",
    );
    idf += &back("BackSouth", "Wall", "Surface", &[[0.0, y0, h], [0.0, y0, 0.0], [w, y0, 0.0], [w, y0, h]])
        .replace(",Surface,,NoSun", ",Surface,North,NoSun");
    idf += &back("BackNorth", "Wall", "Outdoors", &[[w, y1, h], [w, y1, 0.0], [0.0, y1, 0.0], [0.0, y1, h]]);
    idf += &back("BackEast", "Wall", "Outdoors", &[[w, y0, h], [w, y0, 0.0], [w, y1, 0.0], [w, y1, h]]);
    idf += &back("BackWest", "Wall", "Outdoors", &[[0.0, y1, h], [0.0, y1, 0.0], [0.0, y0, 0.0], [0.0, y0, h]]);
    idf += &back("BackFloor", "Floor", "Ground", &[[w, y0, 0.0], [0.0, y0, 0.0], [0.0, y1, 0.0], [w, y1, 0.0]]);
    idf += &back("BackRoof", "Roof", "Outdoors", &[[0.0, y0, h], [w, y0, h], [w, y1, h], [0.0, y1, h]]);
    idf + "Window:Interzone,IzA,Pane,North,IzB,1,1,0.5,2,2;\nWindow:Interzone,IzB,Pane,BackSouth,IzA,1,1,0.5,2,2;\n"
}

/// A beam that reaches the back room through the office's window and the interzone pane is
/// weighted by both: on every lit point of the back room's floor, the office glass's weight at
/// its incidence (curve E) × the pane's 0.5, the pane's two copies counted once; on the office's
/// floor the office glass alone. The sun (0.1, −1, 0.3) reaches the back floor 6.7–8.3 m from the
/// south wall through both openings, by hand.
#[test]
fn a_beam_through_an_interzone_window_is_weighted_by_every_pane_it_crosses() {
    let loaded = model::load_bytes_all(&[("back.idf".to_string(), back_room_idf().into_bytes())], &LoadOptions::default()).unwrap();
    let ep = loaded.energyplus.unwrap();
    let (mut scene, rooms) = (inside_scene(&ep).unwrap(), rooms(&ep, Some(0.5)).unwrap());
    let glazing: Vec<(&str, bool)> = rooms.glazing.iter().map(|g| (g.name.as_str(), g.interzone)).collect();
    assert_eq!(glazing, [("Win", false), ("IzA", true), ("IzB", true)]);
    assert_eq!((rooms.twin_of(1).map(|t| t.1), rooms.twin_of(2).map(|t| t.1), rooms.twin_of(0)), (Some(2), Some(1), None));
    let at = inside::floor_grid(&mut scene, &rooms, 0.25, 0.0).unwrap();
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    let sun = DVec3::new(0.1, -1.0, 0.3).normalize();
    let ours = inside::instant(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, sun, 1.0);
    let (win, back) = (&rooms.glazing[0], rooms.rooms.iter().position(|r| r.name == "BACK").unwrap() as u32);
    let cos = win.plane.normal.dot(sun).abs();
    let (mut in_back, mut in_office) = (0, 0);
    for i in (0..at.points.len()).filter(|&i| ours.lit[i] == 1.0) {
        let pane = if at.room[i] == back { 0.5 } else { 1.0 };
        *(if at.room[i] == back { &mut in_back } else { &mut in_office }) += 1;
        let (s, v) = (ours.solar_transmittance[i], ours.visible_transmittance[i]);
        let p = at.points.position(i);
        assert!((p.y - 7.5).abs() < 0.9 || at.room[i] != back, "back point {p} lit outside the strip drawn by hand");
        assert!(
            (s - win.solar_at(cos) * pane).abs() < 1e-12 && (v - win.visible_at(cos) * pane).abs() < 1e-12,
            "point {p}: weights {s} {v}, expected the window's {} {} × {pane}",
            win.solar_at(cos),
            win.visible_at(cos)
        );
    }
    assert!(in_back > 20 && in_office > 20, "{in_back} back and {in_office} office points lit");
}

#[test]
fn no_sky_line_is_all_of_an_open_room_and_none_behind_a_screen() {
    let patches = sunlit::sky::patches::SkyPatches::parse("tregenza").unwrap();
    let share = |idf: &str| {
        let (mut scene, rooms) = load(idf).unwrap();
        let at = inside::floor_grid(&mut scene, &rooms, 0.5, inside::NSL_WORK_PLANE).unwrap();
        let mapper = Mapper::new(&scene, &at.points).unwrap();
        inside::no_sky_line(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, &patches, &mut |_, _| {}).1[0].sees_sky
    };
    assert_eq!(share(&room_idf(WINDOW, false, "")), 100.0);
    // A 50 m high screen 0.3 m in front of the window hides every piece of sky.
    let screen = "Shading:Site:Detailed,Screen,,4,-50,-0.3,50,-50,-0.3,0,54,-0.3,0,54,-0.3,50;\n";
    assert_eq!(share(&room_idf(WINDOW, false, screen)), 0.0);
}

/// A ray exactly along a closed room's inside corner, edge or vertex (where two or three of its
/// faces meet) meets the shell: no sky through the crack between two walls. On a 0.25 m work
/// plane, suns along the north-east corner (16 points on its diagonal), the north wall's top edge
/// (a row) and the top north-east vertex light nothing, as numpy's caster (whose rays leave only
/// through the window) says point by point; a sun along the south-east corner agrees with it point
/// by point too. Behind a screen hiding all the sky no point sees sky, though Tregenza's 45°
/// sub-patches run along the corners' diagonals from this grid's points.
#[test]
fn no_ray_leaves_a_closed_room_through_the_crack_where_its_faces_meet() {
    let (mut scene, rooms) = load(&room_idf(WINDOW, false, "")).unwrap();
    let at = inside::floor_grid(&mut scene, &rooms, 0.25, 0.76).unwrap();
    let rise = ROOM[2] - 0.76;
    // Grid points lie at x, y = 0.125 + 0.25 k: (1.125, 2.875) sees the edge and the vertex.
    let suns = [[1.0, 1.0, 0.5], [0.0, ROOM[1] - 2.875, rise], [ROOM[0] - 1.125, ROOM[1] - 2.875, rise], [1.0, -1.0, 0.6]];
    let on_diagonal = positions(&at).iter().filter(|p| (p[1] - p[0] - 1.0).abs() < 1e-9).count();
    assert_eq!(on_diagonal, 16);
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    let suns: Vec<DVec3> = suns.iter().map(|s| DVec3::from_array(*s).normalize()).collect();
    let query = json!({"window": WINDOW, "overhang": null, "points": positions(&at), "normal": [0, 0, 1],
        "suns": suns.iter().map(|s| s.to_array()).collect::<Vec<_>>()});
    let reference = numpy_reference(&query);
    for (k, &sun) in suns.iter().enumerate() {
        let ours = inside::instant(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, sun, 1.0).lit;
        let theirs: Vec<f64> = reference["lit"][k].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let leaks: Vec<[f64; 3]> = (0..ours.len()).filter(|&i| ours[i] != theirs[i]).map(|i| at.points.position(i).to_array()).collect();
        assert!(leaks.is_empty(), "sun {sun}: {} points differ from numpy, e.g. {:?}", leaks.len(), &leaks[..leaks.len().min(4)]);
        assert_eq!(theirs.iter().sum::<f64>() > 0.0, k == 3, "sun {sun}: numpy lights points only through the window");
    }
    let patches = sunlit::sky::patches::SkyPatches::parse("tregenza").unwrap();
    let screen = "Shading:Site:Detailed,Screen,,4,-50,-0.3,50,-50,-0.3,0,54,-0.3,0,54,-0.3,50;\n";
    let (mut scene, rooms) = load(&room_idf(WINDOW, false, screen)).unwrap();
    let at = inside::floor_grid(&mut scene, &rooms, 0.25, inside::NSL_WORK_PLANE).unwrap();
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    let (sees, _) = inside::no_sky_line(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, &patches, &mut |_, _| {});
    let leaks: Vec<[f64; 3]> = (0..sees.len()).filter(|&i| sees[i]).map(|i| at.points.position(i).to_array()).collect();
    assert!(leaks.is_empty(), "{} points see sky behind the screen, e.g. {:?}", leaks.len(), &leaks[..leaks.len().min(4)]);
}

/// The proposed model's obstruction for the No-Sky Line: a wall 400 m long (x), `height` m high,
/// `distance` m south of the window's wall, so the line is drawn in the room's section alone.
fn long_wall(distance: f64, height: f64) -> String {
    let y = -distance;
    format!("Shading:Site:Detailed,Block,,4,-200,{y},{height},-200,{y},0,204,{y},0,204,{y},{height};\n")
}

/// By hand, in the room's section: a work-plane point `y` m from the window sees sky over the
/// long wall when the steepest ray through the window's head (z 2.5) clears the wall's top; the
/// margin (degrees of elevation in the section) by which it does, negative where it does not.
fn sky_margin_deg(y: f64, distance: f64, height: f64) -> f64 {
    let rise = WINDOW[3] - inside::NSL_WORK_PLANE;
    (rise / y).atan().to_degrees() - ((height - inside::NSL_WORK_PLANE) / (y + distance)).atan().to_degrees()
}

/// BRE 209's No-Sky Line before and after a long wall rises 6 m in front of the window, 5.8 m
/// high: by hand the line lies 1.65 × 6 / 3.3 = 3 m into the room (60 % of its 5 m depth), so
/// the room keeps 0.6 of its former area seeing sky and fails BRE's 0.8 rule. Every point more
/// than 4° (two Tregenza sub-patches, seen in the section) from the line is on its side of it;
/// the CLI's report has before, after, the ratio and the verdict.
#[test]
fn no_sky_line_before_and_after_matches_the_line_drawn_by_hand() {
    let tmp = Scratch::new("inside", "no_sky_line_before_and_after_matches_the_line_drawn_by_hand");
    const DISTANCE: f64 = 6.0;
    const HEIGHT: f64 = 5.8;
    let patches = sunlit::sky::patches::SkyPatches::parse("tregenza").unwrap();
    let (before, after) = (room_idf(WINDOW, false, ""), room_idf(WINDOW, false, &long_wall(DISTANCE, HEIGHT)));
    let nsl = |idf: &str| {
        let (mut scene, rooms) = load(idf).unwrap();
        let at = inside::floor_grid(&mut scene, &rooms, 0.3, inside::NSL_WORK_PLANE).unwrap();
        let mapper = Mapper::new(&scene, &at.points).unwrap();
        let (sees, areas) = inside::no_sky_line(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, &patches, &mut |_, _| {});
        (sees, areas, positions(&at))
    };
    let (_, was, _) = nsl(&before);
    let (sees, now, at) = nsl(&after);
    assert_eq!(was[0].sees_sky, 100.0);
    let (mut near, mut by_hand) = (0, 0);
    for (p, s) in at.iter().zip(&sees) {
        let margin = sky_margin_deg(p[1], DISTANCE, HEIGHT);
        by_hand += usize::from(margin > 0.0);
        if margin.abs() <= 4.0 {
            near += 1;
        } else {
            assert_eq!(*s, margin > 0.0, "point {p:?}: sees sky {s}, {margin:.2}° from the line by hand");
        }
    }
    let (hand, slack) = (100.0 * by_hand as f64 / at.len() as f64, 100.0 * near as f64 / at.len() as f64);
    eprintln!("No-Sky Line: {} % of the work plane sees sky, {hand} % by hand ({slack} % within 4° of the line)", now[0].sees_sky);
    assert!((hand - 60.0).abs() < 4.0, "the grid's share in front of the line at 3 m: {hand} %");
    assert!((now[0].sees_sky - hand).abs() <= slack, "{} % against {hand} % by hand", now[0].sees_sky);
    let change = &inside::nsl_before_after(&now, &was)[0];
    assert_eq!((change.before, change.passes), (Some(100.0), Some(false)));
    assert!((change.ratio.unwrap() - now[0].sees_sky / 100.0).abs() < 1e-12);

    let (old, new, csv) = (tmp.join("nsl-before.idf"), tmp.join("nsl-after.idf"), tmp.join("nsl.csv"));
    std::fs::write(&old, &before).unwrap();
    std::fs::write(&new, &after).unwrap();
    let args = ["map", new.to_str().unwrap(), "--inside", "--study", "bre-nsl", "--grid", "0.3", "--location", "51.5,-0.1,0"];
    let out = sunlit(&[&args[..], &["--before", old.to_str().unwrap(), "-o", csv.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(tmp.join("nsl.study-bre-nsl.json")).unwrap()).unwrap();
    let room = &report["areas"][0];
    assert_eq!(
        (room["zone"].as_str(), room["sees_sky_before"].as_f64(), room["passes"].as_bool()),
        (Some("OFFICE"), Some(100.0), Some(false))
    );
    assert!((room["sees_sky"].as_f64().unwrap() - now[0].sees_sky).abs() < 1e-3, "{room}");
    assert!((room["ratio"].as_f64().unwrap() - now[0].sees_sky / 100.0).abs() < 1e-4, "{room}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().next().unwrap().ends_with(",sees_sky,sees_sky_before"), "{}", &text[..80]);
    // `--before` with the other inside study is refused, before anything is written.
    let bad = tmp.join("nsl-bad.csv");
    let out = sunlit(&[
        "map",
        new.to_str().unwrap(),
        "--inside",
        "--study",
        "leed-ase",
        "--before",
        old.to_str().unwrap(),
        "-o",
        bad.to_str().unwrap(),
    ]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--before"));
    assert!(!bad.exists());
}

#[test]
fn free_csv_points_answer_as_the_work_plane_grid_does() {
    let (mut scene, rooms) = load(&room_idf(WINDOW, true, "")).unwrap();
    let grid = inside::floor_grid(&mut scene, &rooms, 0.2, 0.76).unwrap();
    let mut text = String::from("x,y,z,nx,ny,nz\n");
    for p in positions(&grid) {
        text += &format!("{},{},{},0,0,1\n", p[0], p[1], p[2]);
    }
    // On a fresh scene: the CSV's points are free (on no inside face) and get a plane of their own.
    let (mut fresh, _) = load(&room_idf(WINDOW, true, "")).unwrap();
    let free = inside::room_points_csv(&mut fresh, &rooms, "plane.csv", &text).unwrap();
    assert_eq!(free.points.len(), grid.points.len());
    assert!(fresh.receivers[free.points.receivers[0] as usize].name.contains("free plane"));
    let (a, b) = (Mapper::new(&scene, &grid.points).unwrap(), Mapper::new(&fresh, &free.points).unwrap());
    for sun in [DVec3::new(0.2, -0.8, 0.7), DVec3::new(-0.4, -0.6, 0.5)] {
        let sun = sun.normalize();
        let on_grid = inside::instant(InsideMap { mapper: &a, rooms: &rooms, at: &grid }, sun, 1.0);
        let on_free = inside::instant(InsideMap { mapper: &b, rooms: &rooms, at: &free }, sun, 1.0);
        assert!(on_grid.lit.iter().sum::<f64>() > 50.0);
        assert_eq!(on_grid, on_free, "sun {sun}");
    }
}

/// A day's sums are the instants' answers added up: beam = Σ DNI · cos · solar weight · hours,
/// illuminance = Σ lux · cos · visible weight · hours, and without the EPW's illuminance the
/// stated efficacy (every instant counted in `efficacy_hours`).
#[test]
fn a_days_sums_add_up_the_instants() {
    use sunlit::sun::weather::Hour;
    let (mut scene, rooms) = load(&room_idf(WINDOW, true, "")).unwrap();
    let at = inside::floor_grid(&mut scene, &rooms, 0.25, 0.76).unwrap();
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    let map = InsideMap { mapper: &mapper, rooms: &rooms, at: &at };
    let location = Location::new(39.74, -105.18, -7.0).unwrap();
    let plain = Weather::constant(location.clone(), Hour { dni: 800.0, dhi: 100.0, ghi: 600.0, albedo: 0.2 });
    let lit = plain.clone().with_direct_illuminance(vec![Some(90_000.0); 8760]);
    let calendar = LeafCalendar::evergreen();
    let samples = Period::day(355, 9 * 60, 15 * 60, 10).unwrap().samples();
    let (mut beam, mut klux) = (vec![0.0; at.points.len()], vec![0.0; at.points.len()]);
    for s in &samples {
        let sun = sun_direction(&location, shading_sun_day(s.day), s.hour);
        let one = inside::instant(map, sun, 1.0);
        for i in 0..at.points.len() {
            beam[i] += 800.0 * sun.z * one.solar_transmittance[i] * s.hours / 1000.0;
            klux[i] += 90_000.0 * sun.z * one.visible_transmittance[i] * s.hours / 1000.0;
        }
    }
    let site = Site { location: &location, calendar: &calendar, weather: Some(&lit), sky: None };
    let sums = inside::accumulate(map, &samples, site, &mut |_, _| {});
    assert!(beam.iter().sum::<f64>() > 10.0, "the winter sun reaches the work plane");
    assert_eq!(sums.efficacy_hours, 0);
    for i in 0..at.points.len() {
        assert!((sums.beam_kwh_m2.as_ref().unwrap()[i] - beam[i]).abs() < 1e-9);
        assert!((sums.direct_klux_h.as_ref().unwrap()[i] - klux[i]).abs() < 1e-9);
    }
    let site = Site { weather: Some(&plain), ..site };
    let sums = inside::accumulate(map, &samples, site, &mut |_, _| {});
    assert_eq!(sums.efficacy_hours, samples.len());
    let efficacy = klux.iter().zip(sums.direct_klux_h.unwrap()).map(|(k, d)| k / 90_000.0 * 800.0 * inside::BEAM_EFFICACY - d);
    assert!(efficacy.map(f64::abs).fold(0.0, f64::max) < 1e-9);
}

/// Quads (sunlit axes) as one mesh's positions and indices, each wound so its normal points
/// along the quad's `outward` direction.
fn mesh_of(quads: &[([[f64; 3]; 4], [f64; 3])]) -> (Vec<[f32; 3]>, Vec<u32>) {
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for (q, outward) in quads {
        let c = q.map(DVec3::from_array);
        let flip = (c[1] - c[0]).cross(c[2] - c[0]).dot(DVec3::from_array(*outward)) < 0.0;
        let base = positions.len() as u32;
        positions.extend(q.iter().map(|p| p.map(|v| v as f32)));
        let order: [u32; 6] = if flip { [0, 2, 1, 0, 3, 2] } else { [0, 1, 2, 0, 2, 3] };
        indices.extend(order.iter().map(|i| base + i));
    }
    (positions, indices)
}

/// The box room as a glb: node `Room`, its closed shell wound outwards with the window's opening
/// left in the south wall, node `Glass` (the pane in it), and node `Overhang` when asked.
fn room_glb(overhang: bool) -> Vec<u8> {
    let [w, d, h] = ROOM;
    let [x0, x1, z0, z1] = WINDOW;
    let rect_y =
        |y: f64, xa: f64, xb: f64, za: f64, zb: f64, out: f64| ([[xa, y, za], [xb, y, za], [xb, y, zb], [xa, y, zb]], [0.0, out, 0.0]);
    let shell = [
        // The south wall around the opening: left, right, below, above.
        rect_y(0.0, 0.0, x0, 0.0, h, -1.0),
        rect_y(0.0, x1, w, 0.0, h, -1.0),
        rect_y(0.0, x0, x1, 0.0, z0, -1.0),
        rect_y(0.0, x0, x1, z1, h, -1.0),
        rect_y(d, 0.0, w, 0.0, h, 1.0),
        ([[0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, d, h], [0.0, 0.0, h]], [-1.0, 0.0, 0.0]),
        ([[w, 0.0, 0.0], [w, d, 0.0], [w, d, h], [w, 0.0, h]], [1.0, 0.0, 0.0]),
        ([[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, d, 0.0], [0.0, d, 0.0]], [0.0, 0.0, -1.0]),
        ([[0.0, 0.0, h], [w, 0.0, h], [w, d, h], [0.0, d, h]], [0.0, 0.0, 1.0]),
    ];
    let mut glb = sunlit::model::glb_write::GlbWriter::new();
    let (p, i) = mesh_of(&shell);
    let room = glb.add_mesh("room", &p, &i);
    glb.add_node("Room", room, [0.0; 3], None);
    let (p, i) = mesh_of(&[rect_y(0.0, x0, x1, z0, z1, -1.0)]);
    let glass = glb.add_mesh("glass", &p, &i);
    glb.add_node("Glass", glass, [0.0; 3], None);
    if overhang {
        let [ox0, ox1, depth, oz] = OVERHANG;
        let (p, i) = mesh_of(&[([[ox0, 0.0, oz], [ox1, 0.0, oz], [ox1, -depth, oz], [ox0, -depth, oz]], [0.0, 0.0, 1.0])]);
        let slab = glb.add_mesh("overhang", &p, &i);
        glb.add_node("Overhang", slab, [0.0; 3], None);
    }
    glb.to_glb()
}

/// The glTF box room's scene and rooms, glass of transmittance `glass`.
fn load_glb(bytes: Vec<u8>, glass: f64) -> sunlit::Result<(Scene, Rooms)> {
    let options = LoadOptions { interior: vec!["room".into()], glazing: vec!["Glass".into()], ..Default::default() };
    let mut loaded = model::load_bytes_all(&[("room.glb".to_string(), bytes)], &options)?;
    let rooms = sunlit::model::inside::gltf::rooms(&mut loaded.scene, &loaded.interior, &loaded.glazing, Some(glass))?;
    Ok((loaded.scene, rooms))
}

/// A glTF room (`interior`) with a pane (`glazing`) answers as the IDF's zone does: the floor's
/// sun patch against the analytic projection of the window, the work plane's points against the
/// numpy ray caster (the glass's weight on each lit point), LEED ASE against numpy on Golden's
/// hours, and free points placed in the room by where they lie.
#[test]
fn a_gltf_room_with_glazing_answers_as_the_analytic_and_numpy_truths() {
    const T: f64 = 0.6;
    let (scene, rooms) = load_glb(room_glb(false), T).unwrap();
    assert_eq!(rooms.rooms.len(), 1);
    assert_eq!(rooms.rooms[0].name, "Room");
    assert_eq!(rooms.rooms[0].floors.len(), 1, "{:?}", rooms.rooms[0]);
    let floor = rooms.rooms[0].floors[0].clone();
    for sun in [DVec3::new(0.2, -0.8, 0.7), DVec3::new(-0.3, -0.6, 0.9), DVec3::new(0.0, -0.5, 0.8)] {
        let sun = sun.normalize();
        let patches = inside::sun_patches(&scene, &rooms, sun, 1.0);
        let expected = analytic_floor_patch(sun);
        let on_floor = patches.iter().find(|p| p.surface == floor).unwrap();
        eprintln!("glTF, sun {sun}: floor patch {} m², analytic {expected} m²", on_floor.area_m2);
        assert!((on_floor.area_m2 - expected).abs() <= 0.005 * expected, "sun {sun}: {} m² against {expected} m²", on_floor.area_m2);
        // Only the floor is lit (the glb's f32 vertices may leave a sliver of a nanometre square
        // on the east wall, where the beam grazes the opening's edge).
        assert!(patches.iter().all(|p| p.surface == floor || p.area_m2 < 1e-6), "{patches:?}");
        assert_eq!(on_floor.zone, "Room");
    }
    assert!(inside::sun_patches(&scene, &rooms, DVec3::new(0.0, 0.6, 0.8), 1.0).is_empty());

    let (mut scene, rooms) = load_glb(room_glb(true), T).unwrap();
    let at = inside::floor_grid(&mut scene, &rooms, 0.1, 0.76).unwrap();
    assert_eq!(at.points.len(), 40 * 50);
    let suns = [[0.2, -0.8, 0.7], [-0.5, -0.5, 0.5], [0.35, -0.7, 0.6]];
    for (_, ours, _) in lit_against_numpy(&scene, &rooms, &at, &suns, json!({"vt": T})).0 {
        // Every lit point's beam came through the one pane, once.
        for (l, (s, v)) in ours.lit.iter().zip(ours.solar_transmittance.iter().zip(&ours.visible_transmittance)) {
            assert!((l * T - s).abs() < 1e-12 && (l * T - v).abs() < 1e-12, "lit {l}: weights {s} {v}");
        }
    }

    let (ours, theirs) = ase_against_numpy(&mut scene, &rooms, json!({"vt": T}));
    assert_eq!(ours.areas[0].zone, "Room");
    assert!((ours.areas[0].ase - theirs).abs() <= 1.0, "ASE {} % against numpy's {theirs} %", ours.areas[0].ase);

    // Free points: one in the room (under the window's sill height) belongs to it, one beside it
    // in no room.
    let free = inside::room_points_csv(&mut scene, &rooms, "p.csv", "x,y,z,nx,ny,nz\n2,2,0.76,0,0,1\n1,0.5,1.5,0,1,0\n").unwrap();
    assert_eq!(free.room, [0, 0]);
    let err = inside::room_points_csv(&mut scene, &rooms, "p.csv", "x,y,z,nx,ny,nz\n2,2,0.76,0,0,1\n2,-1,0.76,0,0,1\n").unwrap_err();
    assert!(err.to_string().contains("line 3") && err.to_string().contains("no zone"), "{err}");
}

#[test]
fn map_inside_of_a_gltf_room_writes_its_sun_patch_and_refuses_bad_marks() {
    let tmp = Scratch::new("inside", "map_inside_of_a_gltf_room_writes_its_sun_patch_and_refuses_bad_marks");
    let glb = tmp.join("room.glb");
    std::fs::write(&glb, room_glb(false)).unwrap();
    let csv = tmp.join("glb-at.csv");
    let base = ["map", glb.to_str().unwrap(), "--inside", "--interior", "Room", "--location", "40,-105,-7", "-o", csv.to_str().unwrap()];
    let mut args = base.to_vec();
    args.extend(["--glazing", "Glass", "--glass-transmittance", "0.6", "--grid", "0.25", "--at", "03-21", "12:00", "--json"]);
    let out = sunlit(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    let sun = sun_direction(&Location::parse("40,-105,-7").unwrap(), shading_sun_day(80), 12.0);
    let patches: Vec<&Value> = summary["sun_patches"].as_array().unwrap().iter().filter(|p| p["area_m2"].as_f64() > Some(1e-6)).collect();
    assert_eq!(patches.len(), 1, "{patches:?}");
    let (area, expected) = (patches[0]["area_m2"].as_f64().unwrap(), analytic_floor_patch(sun));
    assert!((area - expected).abs() <= 0.005 * expected, "{area} m² against {expected} m²");
    assert_eq!(patches[0]["zone"], "Room");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().any(|l| l.ends_with(",0.00000,0.00000,1.00000,1,0.6000,0.6000")), "no floor point lit through the glass");
    assert!(!text.contains("-0.0000"), "a negative zero in the CSV");

    // Each refused by name, before anything is written.
    let bad = tmp.join("glb-bad.csv");
    let _ = std::fs::remove_file(&bad);
    for (extra, needle) in [
        (vec!["--glazing", "Pane*", "--glass-transmittance", "0.6"], "Pane*"),
        (vec!["--glazing", "Glass"], "Glass"),
        (vec!["--glazing", "Glass", "--glass-transmittance", "1.2"], "1.2"),
    ] {
        let mut args = base.to_vec();
        args[8] = bad.to_str().unwrap();
        args.extend(extra);
        let out = sunlit(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(needle), "{args:?}: {err}");
        assert!(!bad.exists());
    }
    // A node marked interior that encloses nothing (the pane) is no room.
    let out =
        sunlit(&["map", glb.to_str().unwrap(), "--inside", "--interior", "Glass", "--location", "40,-105,-7", "-o", bad.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("Glass") && err.contains("not a closed room"), "{err}");
    assert!(!bad.exists());
}

/// `glb` with a material carrying `extras` given to the mesh named `mesh` (the GLB's JSON chunk
/// rewritten, its BIN chunk kept).
fn with_material(glb: &[u8], mesh: &str, extras: Value) -> Vec<u8> {
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let mut doc: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    doc["materials"] = json!([{"name": "Pane", "extras": extras}]);
    for m in doc["meshes"].as_array_mut().unwrap().iter_mut().filter(|m| m["name"] == mesh) {
        m["primitives"].as_array_mut().unwrap().iter_mut().for_each(|p| p["material"] = json!(0));
    }
    let mut text = doc.to_string().into_bytes();
    text.resize(text.len().div_ceil(4) * 4, b' ');
    let rest = &glb[20 + json_len..];
    let mut out = Vec::new();
    out.extend_from_slice(&glb[0..8]);
    out.extend_from_slice(&((12 + 8 + text.len() + rest.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    out
}

/// A measured curve of transmittance by angle, on the pane's glTF material.
const CURVE: [[f64; 2]; 4] = [[0.0, 0.8], [30.0, 0.78], [50.0, 0.72], [70.0, 0.5]];

/// A glTF pane whose material gives a curve of transmittance by angle weights the beam by the
/// curve at the beam's incidence: at four angles the lit work-plane points' solar weight is the
/// curve's value worked by hand, the visible one the same share of its own normal value; numpy's
/// ray caster (its own interpolation of the same pairs) agrees point by point and on LEED ASE.
#[test]
fn a_gltf_panes_transmittance_curve_weights_the_beam_by_its_angle() {
    let tmp = Scratch::new("inside", "a_gltf_panes_transmittance_curve_weights_the_beam_by_its_angle");
    const VISIBLE: f64 = 0.85;
    // No glass transmittance given: the material gives the glass.
    let load = |overhang: bool| {
        let glb = with_material(
            &room_glb(overhang),
            "glass",
            json!({"sunlit": {"transmittance_curve": CURVE, "visible_transmittance": VISIBLE}}),
        );
        let options = LoadOptions { interior: vec!["Room".into()], glazing: vec!["Glass".into()], ..Default::default() };
        let mut loaded = model::load_bytes_all(&[("room.glb".to_string(), glb)], &options).unwrap();
        let rooms = sunlit::model::inside::gltf::rooms(&mut loaded.scene, &loaded.interior, &loaded.glazing, None).unwrap();
        let mut scene = loaded.scene;
        let at = inside::floor_grid(&mut scene, &rooms, 0.1, 0.76).unwrap();
        (scene, rooms, at)
    };
    let (scene, rooms, at) = load(false);
    let mapper = Mapper::new(&scene, &at.points).unwrap();
    // Suns in the plane x = 0 meet the south pane (normal −y) at θ from its normal: the curve by
    // hand there (linear between pairs, down to 0 at 90° past the last).
    for (theta, expected) in [
        (20.0_f64, 0.8 - 0.02 * 20.0 / 30.0),
        (45.0, 0.78 - 0.06 * 15.0 / 20.0),
        (60.0, 0.72 - 0.22 * 10.0 / 20.0),
        (75.0, 0.5 * 15.0 / 20.0),
    ] {
        let sun = DVec3::new(0.0, -theta.to_radians().cos(), theta.to_radians().sin());
        let one = inside::instant(InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, sun, 1.0);
        let lit = one.lit.iter().filter(|&&l| l == 1.0).count();
        assert!(lit > 50, "θ {theta}°: only {lit} points lit");
        for ((l, s), v) in one.lit.iter().zip(&one.solar_transmittance).zip(&one.visible_transmittance) {
            assert!((s - l * expected).abs() < 1e-9, "θ {theta}°: solar weight {s}, the curve gives {expected}");
            assert!((v - l * expected * VISIBLE / 0.8).abs() < 1e-9, "θ {theta}°: visible weight {v}");
        }
    }
    let (mut scene, rooms, at) = load(true);
    let suns = [[0.2, -0.8, 0.7], [-0.5, -0.5, 0.5], [0.35, -0.7, 0.6]];
    let (answers, reference) = lit_against_numpy(&scene, &rooms, &at, &suns, json!({"vt": VISIBLE, "angular": CURVE}));
    for (k, (sun, ours, theirs)) in answers.into_iter().enumerate() {
        let visible = reference["visible"][k].as_array().unwrap();
        for (i, (l, v)) in ours.lit.iter().zip(&ours.visible_transmittance).enumerate().filter(|(i, (l, _))| **l == theirs[*i]) {
            let numpy = visible[i].as_f64().unwrap();
            assert!((v - numpy).abs() < 1e-9, "sun {sun}: point {i} lit {l}: visible weight {v}, numpy {numpy}");
        }
    }
    let (ours, theirs) = ase_against_numpy(&mut scene, &rooms, json!({"vt": VISIBLE, "angular": CURVE}));
    assert!((ours.areas[0].ase - theirs).abs() <= 1.0, "ASE {} % against numpy's {theirs} %", ours.areas[0].ase);

    // A curve that rises with the angle, or leaves 0..1, is refused by file, material and field,
    // and `map` writes nothing.
    let out = tmp.join("curve-bad.csv");
    for (curve, needle) in [(json!([[0, 0.7], [40, 0.75]]), "rises"), (json!([[0, 1.3]]), "outside 0..=1")] {
        let glb = tmp.join("curve-bad.glb");
        std::fs::write(&glb, with_material(&room_glb(false), "glass", json!({"sunlit": {"transmittance_curve": curve}}))).unwrap();
        let run = sunlit(&[
            "map",
            glb.to_str().unwrap(),
            "--inside",
            "--interior",
            "Room",
            "--glazing",
            "Glass",
            "--location",
            "40,-105,-7",
            "--grid",
            "0.5",
            "--at",
            "03-21",
            "12:00",
            "-o",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&run.stderr);
        for word in ["curve-bad.glb", "material 0 'Pane'", "sunlit.transmittance_curve", needle] {
            assert!(!run.status.success() && err.contains(word), "{curve}: no '{word}' in: {err}");
        }
        assert!(!out.exists(), "{curve}: output written");
    }
}

/// An EnergyPlus window whose construction sunlit cannot read (two panes and a gap) takes the
/// curve `--glass-curve` gives (the glTF test's pairs): each lit work-plane point's solar weight
/// is the curve at its beam's incidence on the window, as numpy's caster interpolating the same
/// pairs says point by point, and its visible weight the given visible transmittance's share of
/// it. The CLI refuses a curve not starting at 0° naming the flag, and writes nothing.
#[test]
fn an_unread_idf_window_takes_the_curve_it_is_given() {
    use sunlit::model::inside::curve::TransmittanceCurve;
    use sunlit::model::inside::{UnreadGlass, rooms_with};
    let idf = room_idf(WINDOW, true, "").replace("Construction,Glass,SimpleGlass;", "Construction,Glass,Pane,Gap,Pane;");
    let loaded = model::load_bytes_all(&[("room.idf".to_string(), idf.as_bytes().to_vec())], &LoadOptions::default()).unwrap();
    let ep = loaded.energyplus.unwrap();
    let curve = TransmittanceCurve::parse("0:0.8,30:0.78,50:0.72,70:0.5").unwrap();
    assert!(rooms(&ep, None).is_err(), "without a transmittance or a curve the window is refused");
    let (mut scene, rooms) =
        (inside_scene(&ep).unwrap(), rooms_with(&ep, &UnreadGlass { transmittance: Some(0.6), curve: Some(curve) }).unwrap());
    assert_eq!((rooms.glazing[0].solar, rooms.glazing[0].visible), (0.8, 0.6));
    let at = inside::floor_grid(&mut scene, &rooms, 0.1, 0.76).unwrap();
    let suns = [[0.2, -0.8, 0.7], [-0.5, -0.5, 0.5], [0.35, -0.7, 0.6]];
    // numpy's `visible` at vt 0.8 (the curve's normal value) is the curve itself at the incidence.
    let (answers, reference) = lit_against_numpy(&scene, &rooms, &at, &suns, json!({"vt": 0.8, "angular": CURVE}));
    for (k, (sun, ours, theirs)) in answers.into_iter().enumerate() {
        let numpy = reference["visible"][k].as_array().unwrap();
        let mut weighted = 0;
        for i in (0..theirs.len()).filter(|&i| ours.lit[i] == theirs[i] && theirs[i] == 1.0) {
            let (s, v, t) = (ours.solar_transmittance[i], ours.visible_transmittance[i], numpy[i].as_f64().unwrap());
            assert!((s - t).abs() < 1e-9 && (v - 0.75 * t).abs() < 1e-9, "sun {sun}: point {i}: solar {s}, visible {v}, the curve {t}");
            weighted += usize::from(t < 0.795);
        }
        assert!(weighted > 100, "sun {sun}: the curve should take something off ({weighted} points)");
    }
    let tmp = Scratch::new("inside", "an_unread_idf_window_takes_the_curve_it_is_given");
    let (model_path, out) = (tmp.join("unread.idf"), tmp.join("unread.csv"));
    std::fs::write(&model_path, &idf).unwrap();
    let args = ["map", model_path.to_str().unwrap(), "--inside", "--at", "06-21", "12:00", "--location", "39.74,-105.18,-7"];
    let bad = sunlit(&[&args[..], &["--glass-curve", "10:0.8,40:0.7", "-o", out.to_str().unwrap()]].concat());
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("--glass-curve"), "{bad:?}");
    assert!(!out.exists());
}
