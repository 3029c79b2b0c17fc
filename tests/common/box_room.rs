//! The box room the tests of the sun inside share (tests/inside.rs, tests/inside_gltf.rs): a 4 m
//! × 5 m × 3 m EnergyPlus zone with one south window (and an overhang when asked), loaded as the
//! library loads it, with the numpy ray caster's checks of its points and LEED ASE, and the CLI.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

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

use crate::common::inside::{golden_epw, numpy_reference};

/// Room 4 m (x) × 5 m (y) × 3 m, window x 1–3 m, z 1–2.5 m in the south wall (y = 0).
pub const ROOM: [f64; 3] = [4.0, 5.0, 3.0];
pub const WINDOW: [f64; 4] = [1.0, 3.0, 1.0, 2.5];
/// Overhang x 0.5–3.5 m, 0.8 m deep, at z 2.7 m.
pub const OVERHANG: [f64; 4] = [0.5, 3.5, 0.8, 2.7];
pub const VT: f64 = 0.7;

pub fn surface(name: &str, kind: &str, boundary: &str, corners: &[[f64; 3]]) -> String {
    let v: Vec<String> = corners.iter().map(|c| format!("{},{},{}", c[0], c[1], c[2])).collect();
    let sun = if boundary == "Outdoors" { "SunExposed,WindExposed" } else { "NoSun,NoWind" };
    format!("BuildingSurface:Detailed,{name},{kind},Opaque,Office,,{boundary},,{sun},,{},{};\n", corners.len(), v.join(","))
}

/// The box room's IDF; `window` gives the window's corners (x0, x1, z0, z1) and `extra` more objects.
pub fn room_idf(window: [f64; 4], overhang: bool, extra: &str) -> String {
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
pub const EAST_PLANE_WINDOW: &str = "4,1,2.5,4,1,1,4,3,1,4,3,2.5";
/// The window turned 18° about its sill: its head 0.5 m out of the south wall.
pub const TILTED_WINDOW: &str = "1,-0.5,2.5,1,0,1,3,0,1,3,-0.5,2.5";

/// The box room with the window's four corners as written (`x,y,z` × 4, upper left first).
pub fn room_idf_with_window(corners: &str, overhang: bool, extra: &str) -> String {
    let [x0, x1, z0, z1] = WINDOW;
    let written = format!("{x0},0,{z1},{x0},0,{z0},{x1},0,{z0},{x1},0,{z1};");
    let idf = room_idf(WINDOW, overhang, extra);
    assert!(idf.contains(&written));
    idf.replace(&written, &format!("{corners};"))
}

pub fn load(idf: &str) -> sunlit::Result<(Scene, Rooms)> {
    let loaded = model::load_bytes_all(&[("room.idf".to_string(), idf.as_bytes().to_vec())], &LoadOptions::default())?;
    let ep = loaded.energyplus.unwrap();
    Ok((inside_scene(&ep)?, rooms(&ep, None)?))
}

/// The sun patch the window casts on the floor: the window projected along the sun onto z = 0,
/// area × |n_window · s| / |n_floor · s|.
pub fn analytic_floor_patch(sun: DVec3) -> f64 {
    let [x0, x1, z0, z1] = WINDOW;
    (x1 - x0) * (z1 - z0) * sun.y.abs() / sun.z
}

pub fn positions(at: &RoomPoints) -> Vec<[f64; 3]> {
    (0..at.points.len()).map(|i| at.points.position(i).to_array()).collect()
}

/// Each sun's instant on `at` against the numpy ray caster's (its query's window, overhang and
/// `extra` fields): at most 1 % of the points differ, and over 100 are lit. Per sun the sun, our
/// answer and numpy's `lit`; and numpy's whole answer.
pub fn lit_against_numpy(
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

/// LEED ASE of the rooms' work plane over Golden's occupied hours, and numpy's ASE (%) of the
/// same points and hours (its query's `extra` fields give the glass).
pub fn ase_against_numpy(scene: &mut Scene, rooms: &Rooms, extra: Value) -> (inside::AseResult, f64) {
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

pub fn sunlit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).output().unwrap()
}
