//! The sun inside rooms (`sunlit::map::inside`, `map --inside`): a box room with one south window
//! against the analytic sun patch, an independent numpy ray caster (points, and LEED ASE on the
//! Golden EPW's hours), and the refusals. (The glTF rooms and the panes' curves are in
//! tests/inside_gltf.rs, the glass as EnergyPlus reads it in tests/inside_glass.rs; the box room
//! they share in tests/common/box_room.rs.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

#[path = "common/box_room.rs"]
mod box_room;
mod common;
use box_room::*;
use common::Scratch;
use common::inside::{golden_epw, numpy_reference};

use std::collections::BTreeMap;

use glam::DVec3;
use serde_json::{Value, json};
use sunlit::map::Mapper;
use sunlit::map::inside::{self, InsideMap, RoomPoints};
use sunlit::map::{Period, Site};
use sunlit::model::inside::{Rooms, inside_scene, rooms};
use sunlit::model::{self, LoadOptions};
use sunlit::scene::Scene;
use sunlit::sun::location::Location;
use sunlit::sun::position::sun_direction;
use sunlit::sun::weather::Weather;
use sunlit::year::annual::shading_sun_day;
use sunlit::year::season::LeafCalendar;

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

/// Per face, its points lit at `sun` (count) and the lit cells' edges that border no lit cell of
/// the same face (a neighbour unlit or off the face): the lit cells' outline, in cells.
fn lit_cells_per_face(scene: &Scene, rooms: &Rooms, at: &RoomPoints, sun: DVec3, spacing: f64) -> BTreeMap<String, (usize, usize)> {
    let mapper = Mapper::new(scene, &at.points).unwrap();
    let lit = inside::instant(InsideMap { mapper: &mapper, rooms, at }, sun, 1.0).lit;
    let lit: Vec<usize> = (0..lit.len()).filter(|&i| lit[i] == 1.0).collect();
    let face = |i: usize| scene.receivers[at.points.receivers[i] as usize].name.clone();
    let mut out = BTreeMap::new();
    for &i in &lit {
        let neighbours = lit
            .iter()
            .filter(|&&j| face(j) == face(i) && (at.points.position(j).distance(at.points.position(i)) - spacing).abs() < 1e-6)
            .count();
        let entry = out.entry(face(i)).or_insert((0, 0));
        *entry = (entry.0 + 1, entry.1 + 4 - neighbours);
    }
    out
}

/// `face_grid` (`map --inside --faces`, the page at an instant): the floor's grid and one at the
/// same spacing on every other inside face, each point standing for spacing² of its face (the
/// south wall's net of its window). On 21 December in Golden at 13:00 (floor, east and north
/// walls lit) and 15:00 (the east wall), each face's lit points × spacing² match the exact sun
/// patch (`sun_patches`, the polygon clipping) within half a cell along the lit cells' outline; a
/// face lit exactly but with no lit point only for a sliver under two cells.
#[test]
fn face_grid_maps_the_sun_patch_on_every_inside_face() {
    let (mut scene, rooms) = load(&room_idf(WINDOW, false, "")).unwrap();
    let s = 0.25;
    let at = inside::face_grid(&mut scene, &rooms, s, 0.0).unwrap();
    let mut count: BTreeMap<String, usize> = BTreeMap::new();
    for &r in &at.points.receivers {
        *count.entry(scene.receivers[r as usize].name.clone()).or_default() += 1;
    }
    let expected = [("East", 15.0), ("Floor", 20.0), ("North", 12.0), ("Roof", 20.0), ("South", 12.0 - 3.0), ("West", 15.0)];
    let expected: BTreeMap<String, usize> = expected.iter().map(|(n, a)| (format!("{n}:inside"), (a / (s * s)).round() as usize)).collect();
    assert_eq!(count, expected, "points per inside face: its area (net of the window) over spacing²");
    let floor = inside::floor_grid(&mut scene, &rooms, s, 0.0).unwrap().points.positions;
    assert!(at.points.positions[..floor.len()] == floor[..], "the floor's points come first, as the floor grid's");
    let location = Location::parse("39.74,-105.18,-7").unwrap();
    for hour in [13.0, 15.0] {
        let sun = sun_direction(&location, shading_sun_day(355), hour);
        let exact: BTreeMap<String, f64> =
            inside::sun_patches(&scene, &rooms, sun, 1.0).into_iter().map(|p| (p.surface, p.area_m2)).collect();
        let cells = lit_cells_per_face(&scene, &rooms, &at, sun, s);
        eprintln!("{hour}:00 exact {exact:?}, lit cells and outline edges {cells:?}");
        assert!(exact.get("East:inside").is_some_and(|&a| a > 0.5), "{hour}:00: the beam reaches the east wall: {exact:?}");
        for face in exact.keys().chain(cells.keys()) {
            let (lit, edges) = cells.get(face).copied().unwrap_or((0, 0));
            let (mapped, x) = (lit as f64 * s * s, exact.get(face).copied().unwrap_or(0.0));
            if lit == 0 {
                assert!(x < 2.0 * s * s, "{hour}:00 {face}: the exact patch {x} m² has no lit point");
            } else {
                let tolerance = edges as f64 * s * s / 2.0;
                assert!((mapped - x).abs() <= tolerance, "{hour}:00 {face}: {mapped} m² mapped against {x} m² exact (± {tolerance})");
            }
        }
    }
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
