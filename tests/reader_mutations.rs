//! The city model readers (CityJSON, CityJSONSeq, OBJ) under a few thousand deterministic
//! mutations of the committed fixtures, a cheap stand-in for the cargo-fuzz targets
//! (fuzz/fuzz_targets/cityjson.rs, obj.rs) that runs in seconds in every `cargo test`.
//!
//! Each mutant (fixed seeds, so a failure is reproducible by its number) is read the way the
//! fuzz targets read it: into a scene (`load_bytes`, both OBJ up axes, with and without a level
//! of detail), and a city that reads is written back as a cadastre. Every read must return `Ok`
//! or a typed error whose message names the file (and so never an empty or anonymous one), and
//! must neither panic nor take more than [`DEADLINE`]. A failing mutant is saved under the
//! scratch folder with its seed, for `cargo fuzz run cityjson FILE` or `sunlit info FILE`.
//!
//! A longer run (a bounded fuzzing pass, docs/reliability.md) reads mutants from seed 0 on until
//! `SUNLIT_MUTATION_SECONDS` have passed (and at least the usual [`MUTANTS`]):
//! `SUNLIT_MUTATION_SECONDS=600 cargo test --test reader_mutations obj -- --nocapture`.
//!
//! The mutations are what the bad-input list and a reader's usual crashes are made of:
//! truncations, values of the wrong type, huge and negative indices, NaN, infinity and numbers
//! past f64, a missing `transform`, cycles in `parents`, empty rings, surfaces and shells,
//! deleted and duplicated members, and byte flips.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use serde_json::{Value, json};
use sunlit::model::obj::ObjUp;
use sunlit::model::{LoadOptions, load_bytes};

/// The longest a read may take (a debug build, on a loaded machine).
const DEADLINE: Duration = Duration::from_secs(20);

/// Mutants per kind of input.
const MUTANTS: u64 = 2_000;

/// The seeds to read: `0..MUTANTS`, or, with `SUNLIT_MUTATION_SECONDS` set, from 0 on until that
/// many seconds have passed since the first (never fewer than `MUTANTS`).
fn seeds() -> impl Iterator<Item = u64> {
    let seconds: Option<f64> = std::env::var("SUNLIT_MUTATION_SECONDS").ok().and_then(|s| s.parse().ok());
    let start = std::time::Instant::now();
    (0..).take_while(move |&seed| match seconds {
        Some(s) => seed < MUTANTS || start.elapsed().as_secs_f64() < s,
        None => seed < MUTANTS,
    })
}

const BLOCK: &str = include_str!("city/block.city.json");
const HOUSE: &str = include_str!("../fuzz/seeds/obj/house.obj");

/// xorshift64*: a tiny deterministic generator.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Values a mutated slot gets: wrong types, huge and negative indices, floats where indices go,
/// empty containers.
fn odd_value(rng: &mut Rng) -> Value {
    let values = [
        json!(null),
        json!(true),
        json!("x"),
        json!(""),
        json!([]),
        json!([[]]),
        json!([[[]]]),
        json!({}),
        json!(-1),
        json!(0),
        json!(1.5),
        json!(u64::MAX),
        json!(i64::MIN),
        json!(4_294_967_296u64),
        json!(1e300),
        json!(-1e300),
        json!(5e-324),
        json!([0, 0, 0]),
        json!([1e300, -1e300, 1e300]),
        json!("RoofSurface"),
        json!({"type": "RoofSurface"}),
    ];
    rng.pick(&values).clone()
}

/// Every path into a JSON value (keys and indices), so a mutation can land anywhere.
fn paths(v: &Value, at: &mut Vec<Vec<Value>>, here: &mut Vec<Value>) {
    at.push(here.clone());
    match v {
        Value::Object(m) => {
            for (k, child) in m {
                here.push(json!(k));
                paths(child, at, here);
                here.pop();
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                here.push(json!(i));
                paths(child, at, here);
                here.pop();
            }
        }
        _ => {}
    }
}

fn at_path<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |v, step| match step {
        Value::String(k) => &mut v[k.as_str()],
        _ => &mut v[step.as_u64().unwrap() as usize],
    })
}

/// One structural mutation somewhere in `doc`: replace a value, delete or duplicate a member, or
/// empty a container.
fn mutate_tree(doc: &mut Value, rng: &mut Rng) {
    let mut all = Vec::new();
    paths(doc, &mut all, &mut Vec::new());
    let path = rng.pick(&all[1..]).clone();
    let (last, parent) = path.split_last().unwrap();
    let parent = at_path(doc, parent);
    match (rng.below(4), parent) {
        (0, Value::Object(m)) => {
            m.remove(last.as_str().unwrap());
        }
        (0, Value::Array(a)) => {
            a.remove(last.as_u64().unwrap() as usize);
        }
        (1, Value::Array(a)) => {
            let i = last.as_u64().unwrap() as usize;
            let copy = a[i].clone();
            a.insert(i, copy);
        }
        (2, parent) => {
            let slot = match last {
                Value::String(k) => &mut parent[k.as_str()],
                _ => &mut parent[last.as_u64().unwrap() as usize],
            };
            match slot {
                Value::Array(a) => a.clear(),
                Value::Object(m) => m.clear(),
                other => *other = odd_value(rng),
            }
        }
        (_, parent) => {
            let slot = match last {
                Value::String(k) => &mut parent[k.as_str()],
                _ => &mut parent[last.as_u64().unwrap() as usize],
            };
            *slot = odd_value(rng);
        }
    }
}

/// The mutations the issue names, aimed at CityJSON's own members.
fn mutate_city(doc: &mut Value, rng: &mut Rng) {
    // Only the objects still objects: an earlier mutation of the same document may have made one
    // a number, which cannot take `parents`.
    let ids: Vec<String> = doc["CityObjects"]
        .as_object()
        .map(|m| m.iter().filter(|(_, v)| v.is_object()).map(|(k, _)| k.clone()).collect())
        .unwrap_or_default();
    match rng.below(8) {
        0 => {
            doc.as_object_mut().unwrap().remove("transform");
        }
        1 if !ids.is_empty() => {
            // A cycle in parents (and children), of one to three objects.
            let n = 1 + rng.below(3.min(ids.len()));
            for k in 0..n {
                let (me, parent) = (&ids[k], &ids[(k + 1) % n]);
                doc["CityObjects"][me]["parents"] = json!([parent]);
                doc["CityObjects"][parent]["children"] = json!([me]);
            }
        }
        2 => {
            // A huge or negative vertex index somewhere in the boundaries.
            let mut all = Vec::new();
            paths(doc, &mut all, &mut Vec::new());
            let indices: Vec<&Vec<Value>> =
                all.iter().filter(|p| p.iter().any(|s| s == "boundaries") && p.last().is_some_and(Value::is_u64)).collect();
            if !indices.is_empty() {
                let path = (*rng.pick(&indices)).clone();
                *at_path(doc, &path) = rng.pick(&[json!(u64::MAX), json!(1_000_000_000), json!(-3), json!(2.5), json!(null)]).clone();
            }
        }
        3 => {
            // A vertex of NaN's kind: numbers JSON cannot hold, as text, replaced below.
            if let Some(v) = doc["vertices"].as_array_mut().filter(|v| !v.is_empty()) {
                let i = rng.below(v.len());
                v[i] = json!(["__NAN__", 0, "__INF__"]);
            }
        }
        4 => {
            // Scale and translate of every extreme.
            let t = &mut doc["transform"];
            let key = *rng.pick(&["scale", "translate"]);
            t[key] =
                rng.pick(&[json!([0, 0, 0]), json!([1e300, 1e300, 1e300]), json!([5e-324, 1, 1]), json!([-1, 1, 1]), json!("x")]).clone();
        }
        5 => {
            // The version, or the type.
            let (key, value) = rng.pick(&[("version", json!("3.0")), ("version", json!(2.0)), ("type", json!("CityJSONFeature"))]).clone();
            doc[key] = value;
        }
        _ => mutate_tree(doc, rng),
    }
}

/// Text mutations every reader meets: truncation, byte flips, a line dropped or repeated.
fn mutate_text(text: &str, rng: &mut Rng) -> Vec<u8> {
    let mut bytes = text.as_bytes().to_vec();
    match rng.below(4) {
        0 => bytes.truncate(rng.below(bytes.len())),
        1 => {
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(bytes.len());
                bytes[i] = *rng.pick(b"0123456789-.eE,[]{}\":/ \n\x00\xff");
            }
        }
        2 => {
            let lines: Vec<&str> = text.lines().collect();
            let drop = rng.below(lines.len());
            bytes = lines.iter().enumerate().filter(|(i, _)| *i != drop).map(|(_, l)| *l).collect::<Vec<_>>().join("\n").into_bytes();
        }
        _ => {
            let lines: Vec<&str> = text.lines().collect();
            let k = rng.below(lines.len());
            let mut out: Vec<&str> = lines.clone();
            out.insert(k, lines[rng.below(lines.len())]);
            bytes = out.join("\n").into_bytes();
        }
    }
    bytes
}

/// JSON text with the NaN markers as the bare words some writers emit.
fn with_non_numbers(text: String) -> String {
    text.replace("\"__NAN__\"", "NaN").replace("\"__INF__\"", "1e999")
}

/// The block as CityJSONSeq: a header, then each CityObject a feature with the vertices.
fn block_seq(doc: &Value) -> String {
    let mut header = doc.clone();
    let m = header.as_object_mut().unwrap();
    let objects = m.remove("CityObjects").unwrap();
    m.insert("CityObjects".into(), json!({}));
    m.insert("vertices".into(), json!([]));
    let mut lines = vec![header.to_string()];
    for (id, object) in objects.as_object().unwrap() {
        let feature = json!({"type": "CityJSONFeature", "id": id, "CityObjects": {id.clone(): object}, "vertices": doc["vertices"]});
        lines.push(feature.to_string());
    }
    lines.join("\n") + "\n"
}

/// Reads `bytes` as `name` the ways the fuzz targets do: whether the first read gave a scene, or
/// `Err` saying what went wrong.
fn read_all(name: &str, bytes: &[u8]) -> Result<bool, String> {
    let files = [(name.to_string(), bytes.to_vec())];
    let mut options = vec![LoadOptions::default(), LoadOptions { lod: Some("2".into()), ..Default::default() }];
    if name.ends_with(".obj") {
        options = vec![LoadOptions { up: ObjUp::Y, ..Default::default() }, LoadOptions { up: ObjUp::Z, ..Default::default() }];
    }
    let mut first = None;
    for o in &options {
        let read = load_bytes(&files, o);
        if let Err(e) = &read {
            let text = e.to_string();
            if !text.contains(name) {
                return Err(format!("an error that does not name the file: {text:?}"));
            }
        }
        first.get_or_insert(read.is_ok());
    }
    if !name.ends_with(".obj")
        && let Ok(city) = sunlit::model::cityjson::read_city(name, bytes, None)
    {
        let _ = sunlit::export::cadastre::cadastre_cityjson(name, bytes, &city, &[]);
    }
    Ok(first == Some(true))
}

/// Reads every mutant in a thread of its own, failing on a panic, an anonymous error or a read
/// past the deadline; a failing mutant is saved for a rerun.
fn check_all(kind: &str, extension: &str, mutants: impl Iterator<Item = (u64, Vec<u8>)>) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("reader-mutations");
    let mut failures = Vec::new();
    let (mut read, mut scenes) = (0, 0);
    for (seed, bytes) in mutants {
        let name = format!("mutant-{seed}{extension}");
        let (tx, rx) = mpsc::channel();
        let (n, b) = (name.clone(), bytes.clone());
        std::thread::spawn(move || {
            let _ = tx.send(read_all(&n, &b));
        });
        let problem = match rx.recv_timeout(DEADLINE) {
            Ok(Ok(scene)) => {
                scenes += usize::from(scene);
                None
            }
            Ok(Err(e)) => Some(e),
            Err(mpsc::RecvTimeoutError::Timeout) => Some(format!("no answer within {DEADLINE:?} (a hang?)")),
            Err(mpsc::RecvTimeoutError::Disconnected) => Some("panicked".to_string()),
        };
        read += 1;
        if let Some(p) = problem {
            std::fs::create_dir_all(&dir).unwrap();
            let path = dir.join(&name);
            std::fs::write(&path, &bytes).unwrap();
            failures.push(format!("{kind} {}: {p}", path.display()));
        }
    }
    println!("{kind}: {read} mutants, {scenes} read into a scene, the rest refused");
    assert!(read >= MUTANTS as usize, "{read} mutants");
    // Mutants that all fail at the first byte would test nothing past the parser.
    assert!(scenes > read / 20 && scenes < read * 19 / 20, "{scenes} of {read} {kind} mutants read: too few or too many refused");
    assert!(failures.is_empty(), "{} of {read} {kind} mutants failed:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn cityjson_mutants_read_or_are_refused_by_name() {
    let doc: Value = serde_json::from_str(BLOCK).unwrap();
    check_all(
        "CityJSON",
        ".city.json",
        seeds().map(|seed| {
            let mut rng = Rng::new(seed);
            if rng.below(5) == 0 {
                return (seed, mutate_text(BLOCK, &mut rng));
            }
            let mut d = doc.clone();
            for _ in 0..1 + rng.below(3) {
                mutate_city(&mut d, &mut rng);
            }
            (seed, with_non_numbers(d.to_string()).into_bytes())
        }),
    );
}

#[test]
fn cityjson_seq_mutants_read_or_are_refused_by_name() {
    let doc: Value = serde_json::from_str(BLOCK).unwrap();
    let seq = block_seq(&doc);
    check_all(
        "CityJSONSeq",
        ".city.jsonl",
        seeds().map(|seed| {
            let mut rng = Rng::new(seed ^ 0x5EC);
            let mut lines: Vec<Value> = seq.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
            match rng.below(4) {
                0 => return (seed, mutate_text(&seq, &mut rng)),
                1 => {
                    let k = rng.below(lines.len());
                    mutate_city(&mut lines[k], &mut rng);
                }
                2 => {
                    // A feature's vertex indices past its own vertices, or the header's mutated.
                    let k = rng.below(lines.len());
                    mutate_tree(&mut lines[k], &mut rng);
                }
                _ => {
                    let k = 1 + rng.below(lines.len() - 1);
                    lines[k]["vertices"] = json!([]);
                }
            }
            let text: Vec<String> = lines.iter().map(|l| with_non_numbers(l.to_string())).collect();
            (seed, (text.join("\n") + "\n").into_bytes())
        }),
    );
}

#[test]
fn obj_mutants_read_or_are_refused_by_name() {
    let words = [
        "0",
        "-1",
        "-100",
        "99999999999999999999",
        "18446744073709551615",
        "nan",
        "inf",
        "-inf",
        "1e400",
        "1e300",
        "",
        "1/",
        "/1",
        "1//",
        "x",
        "f",
        "v",
        "g",
        "o",
    ];
    check_all(
        "OBJ",
        ".obj",
        seeds().map(|seed| {
            let mut rng = Rng::new(seed ^ 0x0B1);
            if rng.below(3) == 0 {
                return (seed, mutate_text(HOUSE, &mut rng));
            }
            let mut lines: Vec<Vec<String>> = HOUSE.lines().map(|l| l.split_whitespace().map(String::from).collect()).collect();
            for _ in 0..1 + rng.below(3) {
                let k = rng.below(lines.len());
                match rng.below(4) {
                    0 if lines[k].len() > 1 => {
                        let w = 1 + rng.below(lines[k].len() - 1);
                        lines[k][w] = rng.pick(&words).to_string();
                    }
                    1 if lines[k].len() > 1 => {
                        let keep = 1 + rng.below(lines[k].len() - 1);
                        lines[k].truncate(keep);
                    }
                    2 => lines.push(vec!["f".into(), rng.pick(&words).to_string(), "1".into(), "2".into()]),
                    _ => {
                        // A degenerate face: one vertex thrice, or a line of collinear ones.
                        let face = rng.pick(&[["1", "1", "1", "1"], ["1", "2", "1", "2"], ["1", "2", "2", "1"]]);
                        lines.push(std::iter::once("f").chain(face.iter().copied()).map(String::from).collect());
                    }
                }
            }
            let text: Vec<String> = lines.iter().map(|l| l.join(" ")).collect();
            (seed, (text.join("\n") + "\n").into_bytes())
        }),
    );
}
