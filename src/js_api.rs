//! Holds `www/sunlit.d.ts`, the hand-written types of the JS API, to the Rust types behind it
//! (tests only): the annual settings' keys are [`AnnualSettings`]'s serialised names, and the
//! error codes are [`Error::code`]'s and [`GpuError::code`]'s. A field or code added on one side
//! only fails here.

use std::collections::BTreeSet;

use crate::count::hybrid::EngineKind;
use crate::error::{Error, GpuError, NoReceivers};
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
            | Error::Cancelled => {}
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
    // Thrown by sunlit.js itself, before the wasm is reached.
    rust.insert("no-webgpu".into());
    assert_eq!(union(body, "code"), rust);
    let gpu: BTreeSet<String> = every_gpu_error().iter().map(|e| e.code().to_string()).collect();
    assert_eq!(union(body, "gpu"), gpu);
    assert_eq!(fields(body), ["code", "file", "gpu", "object", "option"].map(String::from).into());
}

/// The string literals after the first `marker` in the file, up to its `;`.
fn literals_after(marker: &str) -> BTreeSet<String> {
    let start = DTS.find(marker).unwrap_or_else(|| panic!("no {marker} in sunlit.d.ts"));
    let rest = &DTS[start..];
    rest[..rest.find(';').unwrap()].split('\'').skip(1).step_by(2).map(str::to_string).collect()
}

#[test]
fn the_engine_names_are_the_same_on_both_sides() {
    let rust: BTreeSet<String> = [EngineKind::Auto, EngineKind::Gpu, EngineKind::Exact]
        .iter()
        .map(|k| EngineKind::parse(k.name()).unwrap().name().to_string())
        .collect();
    assert_eq!(literals_after("  engine?: "), rust, "createEngine's option");
    assert_eq!(literals_after("  readonly engine: "), rust, "SunlitEngine.engine");
    let error = EngineKind::parse("fast").unwrap_err();
    assert_eq!((error.code(), error.parameter()), ("bad-option", Some("engine")));
}
