//! Holds `www/sunlit.d.ts`, the hand-written types of the JS API, to the Rust types behind it
//! (tests only): the annual settings' keys are [`AnnualSettings`]'s serialised names, the map
//! options' keys and values are `web::map_options`' (read here natively, with `sunlit map`'s
//! defaults checked), and the error codes are [`Error::code`]'s and [`GpuError::code`]'s. A field
//! or code added on one side only fails here.

use std::collections::BTreeSet;

use crate::count::hybrid::EngineKind;
use crate::error::{Error, GpuError, NoReceivers};
use crate::sky::model::SkyModel;
use crate::year::settings::AnnualSettings;

const DTS: &str = include_str!("../www/sunlit.d.ts");

/// The body of `export interface NAME { … }`.
fn interface(name: &str) -> &'static str {
    let start = DTS.find(&format!("export interface {name} ")).unwrap_or_else(|| panic!("no interface {name} in sunlit.d.ts"));
    let body = &DTS[start..];
    let open = body.find('{').unwrap();
    let close = body.find("\n}").unwrap();
    &body[open + 1..close]
}

/// The names of an interface's fields (`name?: type;` or `name: type;` at the start of a line).
fn fields(body: &str) -> BTreeSet<String> {
    body.lines()
        .map(str::trim)
        .filter(|l| !l.starts_with("/**") && !l.starts_with('*') && !l.starts_with("readonly"))
        .filter_map(|l| l.split_once(':').map(|(name, _)| name.trim_end_matches('?').to_string()))
        .filter(|name| name.chars().all(|c| c.is_ascii_alphanumeric()) && !name.is_empty())
        .collect()
}

/// The string literals of the union after `field` in an interface body (`'a' | 'b' | …`).
fn union(body: &str, field: &str) -> BTreeSet<String> {
    let start = body.find(&format!("\n  {field}")).unwrap_or_else(|| panic!("no field {field}"));
    let rest = &body[start..];
    let end = rest.find(';').unwrap();
    rest[..end].split('\'').skip(1).step_by(2).map(str::to_string).collect()
}

#[test]
fn the_annual_settings_are_the_same_on_both_sides() {
    let rust: BTreeSet<String> = match serde_json::to_value(AnnualSettings::default()).unwrap() {
        serde_json::Value::Object(map) => map.keys().cloned().collect(),
        other => panic!("{other}"),
    };
    assert_eq!(fields(interface("AnnualSettings")), rust);
    assert!(rust.contains("timestepsPerHour") && rust.contains("leafOut"), "{rust:?}");
}

/// One error of each kind; the match makes a new variant fail to compile here until it is added.
fn every_error() -> Vec<Error> {
    let errors = vec![
        Error::Io { path: "a".into(), source: std::io::Error::other("x") },
        Error::model("f", "r"),
        Error::object("f", "o", "r"),
        Error::TimestepMismatch { file: "f".into(), object: "o".into(), model: 1, schedule: 2 },
        Error::DuplicateReceiver { name: "n".into(), first: "a".into(), second: "b".into() },
        Error::NoReceivers(NoReceivers::Unnamed),
        Error::argument("north", "r"),
        Error::Unmatched { what: "foliage".into(), pattern: "p".into() },
        Error::Gpu(GpuError::Device("d".into())),
        Error::DeviceLost("l".into()),
        Error::Cancelled,
        Error::SceneBytes(crate::error::SceneBytesError::NotAScene),
    ];
    for e in &errors {
        match e {
            Error::Io { .. }
            | Error::Model { .. }
            | Error::Object { .. }
            | Error::TimestepMismatch { .. }
            | Error::DuplicateReceiver { .. }
            | Error::NoReceivers(_)
            | Error::Argument { .. }
            | Error::Unmatched { .. }
            | Error::Gpu(_)
            | Error::DeviceLost(_)
            | Error::Cancelled
            | Error::SceneBytes(_) => {}
        }
    }
    errors
}

fn every_gpu_error() -> Vec<GpuError> {
    let errors = vec![
        GpuError::NoAdapter { hint: "h".into(), reason: "r".into() },
        GpuError::Device("d".into()),
        GpuError::OutOfMemory { doing: "d".into(), resolution: 1 },
        GpuError::OverLimit { limit_name: "max_buffer_size", need: 2, limit: 1 },
        GpuError::Validation { doing: "d".into(), message: "m".into() },
        GpuError::Readback("r".into()),
    ];
    for e in &errors {
        match e {
            GpuError::NoAdapter { .. }
            | GpuError::Device(_)
            | GpuError::OutOfMemory { .. }
            | GpuError::OverLimit { .. }
            | GpuError::Validation { .. }
            | GpuError::Readback(_) => {}
        }
    }
    errors
}

#[test]
fn the_error_codes_are_the_same_on_both_sides() {
    let body = interface("SunlitError");
    let mut rust: BTreeSet<String> = every_error().iter().map(|e| e.code().to_string()).collect();
    // Thrown by sunlit.js itself, before the wasm is reached: no WebGPU, a model too large for
    // wasm32's memory (refused by its size up front, or trapped while reading), and a failure
    // of one of the pool's clipping workers (pool.js); a map's files asked for after `free()`.
    for js_only in ["no-webgpu", "too-large", "worker", "freed"] {
        rust.insert(js_only.into());
    }
    assert_eq!(union(body, "code"), rust);
    let gpu: BTreeSet<String> = every_gpu_error().iter().map(|e| e.code().to_string()).collect();
    assert_eq!(union(body, "gpu"), gpu);
    // `worker` and `workerCode` come with the pool's `worker` code, set in pool.js.
    assert_eq!(fields(body), ["code", "file", "gpu", "object", "option", "worker", "workerCode"].map(String::from).into());
}

/// The string literals after the first `marker` in the file, up to its `;`.
fn literals_after(marker: &str) -> BTreeSet<String> {
    let start = DTS.find(marker).unwrap_or_else(|| panic!("no {marker} in sunlit.d.ts"));
    let rest = &DTS[start..];
    rest[..rest.find(';').unwrap()].split('\'').skip(1).step_by(2).map(str::to_string).collect()
}

#[test]
fn the_engine_names_are_the_same_on_both_sides() {
    // Every engine the page's wasm accepts (web.rs's `choice`), the compute rasterizer included.
    let rust: BTreeSet<String> = [EngineKind::Auto, EngineKind::Gpu, EngineKind::Exact, EngineKind::Compute]
        .iter()
        .map(|k| EngineKind::parse(k.name()).unwrap().name().to_string())
        .collect();
    assert_eq!(literals_after("  engine?: "), rust, "createEngine's option");
    assert_eq!(literals_after("  readonly engine: "), rust, "SunlitEngine.engine");
    let error = EngineKind::parse("fast").unwrap_err();
    assert_eq!((error.code(), error.parameter()), ("bad-option", Some("engine")));
}

#[test]
fn the_sky_model_names_are_the_same_on_both_sides() {
    // `skyModel` takes the names `--sky-model` takes: both are read by `SkyModel::parse`.
    let rust: BTreeSet<String> = SkyModel::ALL.iter().map(|m| SkyModel::parse(m.name()).unwrap().name().to_string()).collect();
    assert_eq!(rust.len(), 4);
    assert_eq!(union(interface("AnnualSettings"), "skyModel"), rust, "AnnualSettings.skyModel");
    assert_eq!(union(interface("MapOptions"), "skyModel"), rust, "MapOptions.skyModel");
    let with_epw =
        |name: &str| AnnualSettings { epw_file: Some("a.epw".into()), sky_model: Some(name.into()), ..AnnualSettings::default() };
    for model in SkyModel::ALL {
        assert_eq!(with_epw(model.name()).sky_model().unwrap(), model);
    }
    let error = with_epw("gendaymtx").sky_model().unwrap_err();
    assert_eq!((error.code(), error.parameter()), ("bad-option", Some("sky_model")));
}

/// The web's map options reader, compiled natively so that it is tested without a browser.
#[path = "web/map_options.rs"]
mod map_options;

use map_options::{INSIDE_KEYS, InsideAsk, InsideStudy, MAP_KEYS, MapRequest, MapValue, SITE_KEYS, Where};
use serde_json::json;

use crate::map::Period;

#[test]
fn the_map_options_are_the_same_on_both_sides() {
    let rust: BTreeSet<String> = MAP_KEYS.iter().chain(&SITE_KEYS).chain(&INSIDE_KEYS).map(|k| k.to_string()).collect();
    assert_eq!(fields(interface("MapOptions")), rust);
    let patch: BTreeSet<String> = ["surface", "zone", "areaM2", "fraction"].map(String::from).into();
    assert_eq!(fields(interface("SunPatch")), patch, "the patches' JSON keys (web/inside.rs)");
    let annual: BTreeSet<String> = match serde_json::to_value(AnnualSettings::default()).unwrap() {
        serde_json::Value::Object(map) => map.keys().cloned().collect(),
        other => panic!("{other}"),
    };
    assert!(SITE_KEYS.iter().all(|k| annual.contains(*k)), "the site keys are annual settings' keys");
    let all = [MapValue::SunHours, MapValue::Direct, MapValue::SkyDiffuse, MapValue::Total, MapValue::Lit];
    assert_eq!(all.map(MapValue::name), MapValue::NAMES);
    assert_eq!(all.map(|v| v.title().1), ["h", "kWh/m²", "kWh/m²", "kWh/m²", ""], "the units the legend shows");
    assert_eq!(all.map(MapValue::needs_weather), [false, true, true, true, false], "the irradiation values need an EPW");
    let values: BTreeSet<String> = MapValue::NAMES.iter().map(|v| v.to_string()).collect();
    assert_eq!(literals_after("  value?: "), values, "MapOptions.value");
    let shown: BTreeSet<String> = MapValue::NAMES.iter().chain(&MapValue::STUDY_NAMES).map(|v| v.to_string()).collect();
    assert_eq!(union(interface("SunlitMap"), "value"), shown, "SunlitMap.value: the values asked and the inside studies'");
    assert_eq!([MapValue::AseHours, MapValue::SeesSky].map(MapValue::name), MapValue::STUDY_NAMES);
    let studies: BTreeSet<String> = InsideStudy::NAMES.iter().map(|v| v.to_string()).collect();
    assert_eq!(union(interface("MapOptions"), "study"), studies, "MapOptions.study: the CLI's inside studies");
    let area: BTreeSet<String> = ["zone", "points", "ase", "seesSky"].map(String::from).into();
    assert_eq!(fields(interface("InsideArea")), area, "a study's rooms' JSON keys (web/inside.rs)");
}

fn request(extra: serde_json::Value) -> crate::error::Result<MapRequest> {
    let mut options = json!({"latitude": 39.74, "longitude": -105.18, "timeZone": -7});
    options.as_object_mut().unwrap().extend(extra.as_object().unwrap().clone());
    MapRequest::from_value(options)
}

#[test]
fn map_options_read_as_sunlit_map_reads_its_flags() {
    let plain = request(json!({})).unwrap();
    assert_eq!(plain.site.location.latitude, 39.74);
    assert!(plain.weather.is_none(), "no EPW, no irradiance");
    assert_eq!((plain.place, plain.period, plain.value), (Where::Grid(0.5), Period::annual(1).unwrap(), MapValue::SunHours));
    let day = request(json!({"grid": 1, "period": "03-21"})).unwrap();
    assert_eq!((day.place, day.period), (Where::Grid(1.0), Period::day(80, 0, 1440, 10).unwrap()));
    let window = request(json!({"period": "03-21", "step": 15, "from": "06:00", "to": "18:00"})).unwrap();
    assert_eq!(window.period, Period::day(80, 360, 1080, 15).unwrap());
    let range = request(json!({"period": "06-01..06-07", "step": 30})).unwrap();
    assert_eq!(range.period, Period::days(152, 158, 2).unwrap());
    let at = request(json!({"at": "03-21 09:30"})).unwrap();
    assert_eq!((at.period, at.value), (Period::at(80, 570).unwrap(), MapValue::Lit));
    let inside = request(json!({"at": "12-21 15:00", "inside": true, "workPlane": 0.76, "glassTransmittance": 0.6})).unwrap();
    assert_eq!(inside.inside, Some(InsideAsk { work_plane: 0.76, glass: Some(0.6), ..Default::default() }));
    let bare = Some(InsideAsk::default());
    assert_eq!(request(json!({"at": "12-21 15:00", "inside": true})).unwrap().inside, bare);
    // Inside over a period (`--inside --period`): the CLI's defaults, and its EPW read for the beam.
    let days = request(json!({"inside": true, "period": "12-01..12-07"})).unwrap();
    assert_eq!((days.inside, days.period, days.value), (bare, Period::days(335, 341, 1).unwrap(), MapValue::SunHours));
    let epw = year_epw();
    let beam = request(json!({"inside": true, "period": "12-21", "value": "direct", "epw": epw})).unwrap();
    assert!(beam.weather.is_some() && beam.value == MapValue::Direct);
    assert!(request(json!({"inside": true, "period": "12-21", "epw": epw})).unwrap().weather.is_some(), "sun hours and the beam, as --epw");
    // A study (`--study leed-ase`, `bre-nsl`): its grid, work plane, year and value.
    let ase = request(json!({"inside": true, "study": "leed-ase", "epw": epw})).unwrap();
    let ask = Some(InsideAsk { work_plane: 0.76, study: Some(InsideStudy::LeedAse), ..Default::default() });
    assert_eq!((ase.inside, ase.place, ase.period, ase.value), (ask, Where::Grid(0.6), Period::annual(1).unwrap(), MapValue::AseHours));
    let nsl = request(json!({"inside": true, "study": "bre-nsl", "grid": 0.25, "workPlane": 1.0})).unwrap();
    let ask = Some(InsideAsk { work_plane: 1.0, study: Some(InsideStudy::BreNsl), ..Default::default() });
    assert_eq!((nsl.inside, nsl.place, nsl.value), (ask, Where::Grid(0.25), MapValue::SeesSky));
    assert_eq!(request(json!({"inside": true, "study": "bre-nsl"})).unwrap().inside.map(|i| i.work_plane), Some(0.85));
    assert_eq!(request(json!({"at": "12-21 15:00", "inside": false})).unwrap().inside, None);
    // A mesh model's rooms and panes (`--interior`, `--glazing`), as text or an array of globs;
    // an EnergyPlus model's unread glass by its curve (`--glass-curve`).
    let rooms =
        request(json!({"at": "12-21 15:00", "inside": true, "interior": "Room*, Hall", "glazing": ["Glass*"], "glassTransmittance": 0.6}));
    let globs = |g: &[&str]| g.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let ask = InsideAsk { glass: Some(0.6), interior: globs(&["Room*", "Hall"]), glazing: globs(&["Glass*"]), ..Default::default() };
    assert_eq!(rooms.unwrap().inside, Some(ask));
    let curve = request(json!({"at": "12-21 15:00", "inside": true, "glassCurve": "0:0.6,60:0.5"})).unwrap().inside;
    assert_eq!(curve.and_then(|i| i.curve).as_deref(), Some("0:0.6,60:0.5"));
    let given = request(json!({"points": [1, 2, 3, 0, 0, 1]})).unwrap();
    assert_eq!(given.place, Where::Given(vec![1.0, 2.0, 3.0, 0.0, 0.0, 1.0]));
    assert_eq!(map_options::points_csv(&[1.0, 2.5, 3.0, 0.0, 0.0, 1.0]).unwrap(), "x,y,z,nx,ny,nz\n1.0,2.5,3.0,0.0,0.0,1.0\n");
}

/// A year of EPW rows at Golden (as tests/browser/epw.mjs's), enough for the map options' reader.
fn year_epw() -> String {
    let mut text = String::from("LOCATION,Golden,CO,USA,test,724666,39.74,-105.18,-7.0,1829\nDESIGN CONDITIONS,0\n");
    text.push_str("TYPICAL/EXTREME PERIODS,0\nGROUND TEMPERATURES,0\nHOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\nCOMMENTS 1,\n");
    text.push_str("COMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday,1/1,12/31\n");
    let days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    for (m, count) in days.iter().enumerate() {
        for d in 1..=*count {
            for h in 1..=24 {
                text.push_str(&format!(
                    "1999,{},{d},{h},60,x,20,10,50,101000,0,1300,300,500,600,100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0\n",
                    m + 1
                ));
            }
        }
    }
    text
}

#[test]
fn bad_map_options_are_refused_naming_the_option() {
    let named = |extra: serde_json::Value| request(extra).err().map(|e| (e.code(), e.parameter().map(String::from)));
    let bad = |option: &str| Some(("bad-option", Some(option.to_string())));
    assert_eq!(named(json!({"period": "02-30"})), bad("period"));
    assert_eq!(named(json!({"period": "03-21", "from": "15:00", "to": "09:00"})), bad("from"));
    assert_eq!(named(json!({"period": "03-21", "step": 7})), bad("step"));
    assert_eq!(named(json!({"period": "annual", "step": 7})), bad("step"));
    assert_eq!(named(json!({"period": "annual", "from": "08:00"})), bad("from"));
    assert_eq!(named(json!({"at": "03-21 25:00"})), bad("at"));
    assert_eq!(named(json!({"at": "03-21"})), bad("at"));
    assert_eq!(named(json!({"at": "03-21 09:30", "period": "03-21"})), bad("period"));
    assert_eq!(named(json!({"value": "lit"})), bad("value"));
    assert_eq!(named(json!({"value": "direct"})), bad("value"));
    assert_eq!(named(json!({"value": "skyDiffuse"})), bad("value"), "the sky needs an EPW");
    assert_eq!(named(json!({"value": "total"})), bad("value"), "the total needs an EPW");
    assert_eq!(named(json!({"value": "shade"})), bad("value"));
    assert_eq!(named(json!({"grid": 1, "points": [0, 0, 0, 0, 0, 1]})), bad("points"));
    assert_eq!(named(json!({"grid": "fine"})), bad("grid"));
    assert_eq!(named(json!({"skyModel": "uniform"})), bad("sky_model"), "a sky model needs an EPW");
    assert_eq!(named(json!({"skyModel": "perez"})), bad("sky_model"));
    assert_eq!(named(json!({"timestepsPerHour": 4})), bad("options"));
    assert_eq!(named(json!({"inside": true, "value": "total"})), bad("value"), "inside, no sky");
    assert_eq!(named(json!({"study": "leed-ase"})), bad("study"), "a study of the inside without inside");
    assert_eq!(named(json!({"inside": true, "study": "bre-vsc"})), bad("study"), "a window study is engine.study's");
    assert_eq!(named(json!({"inside": true, "study": "leed-ase"})), bad("study"), "ASE needs an EPW");
    assert_eq!(named(json!({"inside": true, "study": "bre-nsl", "period": "12-21"})), bad("period"));
    assert_eq!(named(json!({"inside": true, "study": "bre-nsl", "value": "sunHours"})), bad("value"));
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": "yes"})), bad("inside"));
    assert_eq!(named(json!({"at": "12-21 15:00", "workPlane": 0.76})), bad("workPlane"), "a work plane without inside");
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "glassTransmittance": "clear"})), bad("glassTransmittance"));
    assert_eq!(named(json!({"at": "12-21 15:00", "interior": "Room"})), bad("interior"), "rooms without inside");
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "glazing": "Glass"})), bad("glazing"), "panes without rooms");
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "interior": 3})), bad("interior"));
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "interior": ["Room", 1]})), bad("interior"));
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "glassCurve": "10:0.6"})), bad("glassCurve"), "not from 0°");
    assert_eq!(named(json!({"at": "12-21 15:00", "inside": true, "glassCurve": "0:0.5,40:0.6"})), bad("glassCurve"), "rising");
    let with_rooms = json!({"at": "12-21 15:00", "inside": true, "interior": "Room", "glassCurve": "0:0.6"});
    assert_eq!(named(with_rooms), bad("glassCurve"), "a glTF pane's curve is its material's");
    assert_eq!(MapRequest::from_value(json!({"grid": 1})).err().map(|e| e.code()), Some("bad-option"), "no location");
}

/// The web's study options reader, compiled natively so that it is tested without a browser.
#[path = "web/study_options.rs"]
mod study_options;

use study_options::{Masks, STUDY_KEYS, StudyPlace, StudyRequest};

use crate::map::planning::run::WINDOW_STUDIES;
use crate::map::planning::window_points::WindowPoint;

#[test]
fn the_study_options_are_the_same_on_both_sides() {
    let rust: BTreeSet<String> = STUDY_KEYS.iter().map(|k| k.to_string()).collect();
    assert_eq!(fields(interface("StudyOptions")), rust);
    let studies: BTreeSet<String> = WINDOW_STUDIES.iter().map(|s| s.to_string()).collect();
    assert_eq!(literals_after("export type StudyName "), studies, "StudyName: the window studies run.rs runs");
    let at: BTreeSet<String> = WindowPoint::NAMES.iter().map(|s| s.to_string()).collect();
    assert_eq!(union(interface("StudyOptions"), "windowPoints"), at, "StudyOptions.windowPoints");
    let sky: BTreeSet<String> = SkyModel::ALL.iter().map(|m| m.name().to_string()).collect();
    assert_eq!(union(interface("StudyOptions"), "skyModel"), sky, "StudyOptions.skyModel");
}

fn study(options: serde_json::Value) -> crate::error::Result<StudyRequest> {
    StudyRequest::from_value(options)
}

#[test]
fn study_options_read_as_sunlit_map_reads_its_flags() {
    let vsc = study(json!({"study": "bre-vsc", "windows": [0, 3]})).unwrap();
    assert_eq!((vsc.studies, vsc.place), (vec!["bre-vsc".to_string()], StudyPlace::Windows(vec![0, 3], WindowPoint::Centre)));
    assert!(vsc.location.is_none() && vsc.weather.is_none() && vsc.epw_name.is_none() && vsc.gb.is_none(), "bre-vsc needs no site");
    let gb = study(json!({"study": ["gb50180", "bre-vsc"], "windows": [1], "windowPoints": "sill", "latitude": 39.9, "longitude": 116.4,
        "timeZone": 8, "day": "dongzhi", "minPeriod": 5, "maxPeriods": 2, "skyModel": "cie-overcast"}))
    .unwrap();
    assert_eq!(gb.place, StudyPlace::Windows(vec![1], WindowPoint::Sill));
    let rule = gb.gb.unwrap();
    assert_eq!((rule.day.name(), rule.required_hours, rule.min_period_minutes, rule.max_periods), ("dongzhi", 1.0, 5.0, Some(2)));
    assert_eq!(gb.location.map(|l| (l.latitude, l.time_zone)), Some((39.9, 8.0)));
    let given = study(json!({"study": "bre-25deg", "points": [1, 2, 3, 0, -1, 0]})).unwrap();
    assert_eq!(given.place, StudyPlace::Given(vec![1.0, 2.0, 3.0, 0.0, -1.0, 0.0]));
    assert_eq!((given.masks.rows(3), given.names), (vec![], (vec![], vec![])), "no masks, no names by default");
    let report = study(json!({"study": "bre-vsc", "windows": [0, 1, 2], "masks": "all", "modelNames": ["office.glb", "block.gltf"],
        "beforeNames": ["office.glb"]}))
    .unwrap();
    assert_eq!((report.masks.rows(3), report.names.1), (vec![0, 1, 2], vec!["office.glb".to_string()]), "--mask all");
    assert_eq!(study(json!({"study": "bre-vsc", "windows": [0], "masks": [2, 0]})).unwrap().masks, Masks::Rows(vec![2, 0]));
    // EN 17037's day and altitude (`--period 02-21 --min-altitude 15`), and the sills above a
    // floor level (`--window-points sill --floor-level 0.2`).
    let en = study(json!({"study": ["en17037", "gb50180"], "windows": [0], "windowPoints": "sill", "floorLevel": 0.2,
        "latitude": 51.5, "longitude": 0, "timeZone": 0, "period": "02-21", "minAltitude": 15}))
    .unwrap();
    let rule = en.en17037.unwrap();
    assert_eq!((rule.day, rule.min_altitude_deg, en.floor_level), (52, 15.0, Some(0.2)));
    let default = study(json!({"study": "en17037", "windows": [0], "latitude": 51.5, "longitude": 0, "timeZone": 0})).unwrap();
    assert_eq!(default.en17037.map(|r| (r.day, r.min_altitude_deg)), Some((80, 10.0)), "21 March, 10°: the CLI's defaults");
    assert_eq!(default.floor_level, None);
}

#[test]
fn bad_study_options_are_refused_naming_the_option() {
    let named = |o: serde_json::Value| study(o).err().map(|e| (e.code(), e.parameter().map(String::from)));
    let bad = |option: &str| Some(("bad-option", Some(option.to_string())));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": []})), bad("windows"), "no window selected");
    assert_eq!(named(json!({"study": "bre-vsc"})), bad("windows"), "neither windows nor points");
    assert_eq!(named(json!({"windows": [0]})), bad("study"));
    assert_eq!(named(json!({"study": [], "windows": [0]})), bad("study"));
    assert_eq!(named(json!({"study": "bre-ground", "windows": [0]})), bad("study"), "a map study is not a window study");
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "skyModel": "perez-all-weather"})), bad("sky_model"));
    assert_eq!(
        named(json!({"study": "gb50180", "windows": [0], "latitude": 40, "longitude": 116, "timeZone": 8, "skyModel": "cie-overcast"})),
        bad("sky_model")
    );
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "day": "dahan"})), bad("day"), "only gb50180 takes a day");
    assert_eq!(
        named(json!({"study": "gb50180", "windows": [0], "latitude": 40, "longitude": 116, "timeZone": 8, "day": "06-21"})),
        bad("day")
    );
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "windowPoints": "middle"})), bad("window_points"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "points": [0, 0, 0, 0, 0, 1]})), bad("points"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [-1]})), bad("windows"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "grid": 1})), bad("options"));
    assert_eq!(named(json!({"study": "gb50180", "windows": [0], "latitude": 40})), bad("longitude"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "masks": "some"})), bad("masks"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "masks": [-1]})), bad("masks"));
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "modelNames": "office.glb"})), bad("modelNames"));
    let en = |extra: serde_json::Value| {
        let mut o = json!({"study": "en17037", "windows": [0], "latitude": 51.5, "longitude": 0, "timeZone": 0});
        o.as_object_mut().unwrap().extend(extra.as_object().unwrap().clone());
        named(o)
    };
    assert_eq!(named(json!({"study": "bre-vsc", "windows": [0], "period": "03-01"})), bad("period"), "only en17037 takes a period");
    assert_eq!(named(json!({"study": "gb50180", "windows": [0], "minAltitude": 5})), bad("minAltitude"));
    assert_eq!(en(json!({"period": "06-21"})), bad("period"), "outside 1 February – 21 March");
    assert_eq!(en(json!({"period": "02-30"})), bad("period"), "no such day");
    assert_eq!(en(json!({"minAltitude": 95})), bad("min_altitude"));
    assert_eq!(en(json!({"floorLevel": 0})), bad("floor_level"), "a floor level raises sills: windowPoints 'sill' only");
    assert_eq!(en(json!({"windowPoints": "sill", "floorLevel": "low"})), bad("floorLevel"));
}
