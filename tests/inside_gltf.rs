//! The sun inside glTF rooms and panes (`sunlit::model::inside::gltf`, `map --inside --interior
//! --glazing`): the box room of tests/inside.rs as a glb answers as the IDF's zone does against
//! the analytic and numpy truths, a pane's transmittance curve (its material's extras, or
//! `--glass-curve` for an EnergyPlus window sunlit cannot read) weights the beam by its angle, and
//! bad marks are refused. (Split from tests/inside.rs.)
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

#[path = "common/box_room.rs"]
mod box_room;
mod common;
use box_room::*;
use common::Scratch;

use glam::DVec3;
use serde_json::{Value, json};
use sunlit::map::Mapper;
use sunlit::map::inside::{self, InsideMap};
use sunlit::model::inside::{Rooms, inside_scene, rooms};
use sunlit::model::{self, LoadOptions};
use sunlit::scene::Scene;
use sunlit::sun::location::Location;
use sunlit::sun::position::sun_direction;
use sunlit::year::annual::shading_sun_day;

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
