//! The `sunlit` command line: output shapes, and a clear error (file, object, reason; exit 1, no
//! panic) for every class of bad input.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::runtime_dir;

use std::path::Path;
use std::process::{Command, Output};

use sunlit::model::glb_write::GlbWriter;
use sunlit::model::office::office;

fn sunlit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).env("XDG_RUNTIME_DIR", runtime_dir()).output().expect("run sunlit")
}

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("cli", name)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path.display().to_string()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts a clean failure: exit code 1, an `error:` line containing every needle, no panic.
fn fails_with(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "expected '{n}' in: {err}");
    }
}

fn office_file(dir: &Path) -> String {
    write(dir, "office.glb", &office(6).to_glb())
}

#[test]
fn fraction_json_matches_exact_and_has_the_documented_shape() {
    let dir = scratch("json");
    let model = office_file(&dir);
    let run = |extra: &[&str]| {
        let mut args = vec!["fraction", model.as_str(), "--sun", "200,35", "--json"];
        args.extend_from_slice(extra);
        let out = sunlit(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    // The GPU alone (the default, auto, may clip these few views exactly).
    let gpu = run(&["--engine", "gpu"]);
    let exact = run(&["--exact"]);
    assert_eq!(gpu["sun"]["azimuth"], 200.0);
    assert_eq!(gpu["sun"]["altitude"], 35.0);
    assert_eq!(gpu["resolution"], 512);
    let (g, e) = (gpu["surfaces"].as_array().unwrap(), exact["surfaces"].as_array().unwrap());
    assert_eq!(g.len(), 10);
    let mut partly = 0;
    for (a, b) in g.iter().zip(e) {
        assert_eq!(a["name"], b["name"]);
        let (fa, fb) = (a["fraction"].as_f64().unwrap(), b["fraction"].as_f64().unwrap());
        assert!((fa - fb).abs() <= 0.005, "{}: gpu {fa} exact {fb}", a["name"]);
        assert!(a["area"].as_f64().unwrap() > 0.0 && a["cos_incidence"].is_number());
        partly += (fb > 0.01 && fb < 0.99) as usize;
    }
    assert!(partly >= 2, "the louvres and overhang shade the south facade partly");
    // With an accuracy target: within it of the exact fractions, each surface at its own side.
    let adaptive = run(&["--engine", "gpu", "--accuracy", "0.002"]);
    assert_eq!(adaptive["accuracy"], 0.002);
    let mut sides = std::collections::BTreeSet::new();
    for (a, b) in adaptive["surfaces"].as_array().unwrap().iter().zip(e) {
        let (fa, fb) = (a["fraction"].as_f64().unwrap(), b["fraction"].as_f64().unwrap());
        assert!((fa - fb).abs() <= 0.002, "{}: adaptive {fa} exact {fb}", a["name"]);
        sides.insert(a["side"].as_u64().unwrap());
    }
    assert!(sides.iter().any(|s| (64..=512).contains(s)), "rendered surfaces report their side: {sides:?}");
}

#[test]
fn table_and_info_list_the_receivers() {
    let dir = scratch("table");
    let model = office_file(&dir);
    let out = sunlit(&["fraction", &model, "--sun", "180,40", "--receivers", "WIN_*"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("WIN_S1") && !text.contains("WALL_S"), "{text}");
    let out = sunlit(&["info", &model]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("10 receivers"), "{text}");
    assert!(text.contains("ROOF") && text.contains("+1.000)"), "{text}");
}

#[test]
fn unreadable_truncated_and_foreign_files() {
    let dir = scratch("files");
    let missing = dir.join("nope.glb").display().to_string();
    fails_with(&sunlit(&["info", &missing]), &["nope.glb", "No such file"]);
    let glb = office(1).to_glb();
    let cut = write(&dir, "cut.glb", &glb[..glb.len() / 2]);
    fails_with(&sunlit(&["info", &cut]), &["cut.glb: ", "not a valid glTF"]);
    let text = write(&dir, "notes.glb", b"hello, I am not a model");
    fails_with(&sunlit(&["info", &text]), &["notes.glb: not a glTF file"]);
    let empty = write(&dir, "empty.gltf", b"");
    fails_with(&sunlit(&["info", &empty]), &["empty.gltf: the file is empty"]);
}

#[test]
fn gltf_with_missing_external_buffer() {
    let dir = scratch("external");
    let gltf = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"geometry.bin","byteLength":36}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"name":"A","mesh":0}],"scenes":[{"nodes":[0]}]}"#;
    let path = write(&dir, "model.gltf", gltf.as_bytes());
    fails_with(&sunlit(&["info", &path]), &["model.gltf: ", "external buffer 'geometry.bin'"]);
    // With the buffer present but too short: truncated.
    write(&dir, "geometry.bin", &[0u8; 20]);
    fails_with(&sunlit(&["info", &path]), &["model.gltf: buffer 0 is truncated"]);
    // Present and complete, but an accessor reads past its view.
    let bad = gltf.replace(r#""count":3"#, r#""count":30"#);
    write(&dir, "geometry.bin", &[0u8; 36]);
    let path = write(&dir, "model.gltf", bad.as_bytes());
    fails_with(&sunlit(&["info", &path]), &["model.gltf: mesh 0", "beyond its buffer view"]);
}

/// Replaces the first occurrence of an f32 in the binary with another value.
fn patch_f32(bytes: &mut [u8], from: f32, to: f32) {
    let needle = from.to_le_bytes();
    let at = bytes.windows(4).position(|w| w == needle).expect("value present");
    bytes[at..at + 4].copy_from_slice(&to.to_le_bytes());
}

#[test]
fn bad_geometry_is_named() {
    let dir = scratch("geometry");
    let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let quad = [0u32, 1, 2, 0, 2, 3];
    let receiver = Some(serde_json::json!({"sunlit": {"receiver": true}}));

    for (value, label) in [(f32::NAN, "nan"), (f32::INFINITY, "inf")] {
        let mut w = GlbWriter::new();
        let m = w.add_mesh("m", &[[0.0, 0.0, 0.0], [1234.5, 0.0, 0.0], [1.0, 1.0, 0.0]], &[0, 1, 2]);
        w.add_node("Broken", m, [0.0; 3], None);
        let mut bytes = w.to_glb();
        patch_f32(&mut bytes, 1234.5, value);
        let path = write(&dir, &format!("{label}.glb"), &bytes);
        fails_with(&sunlit(&["info", &path]), &[&format!("{label}.glb: node 'Broken'"), "non-finite"]);
    }

    let mut w = GlbWriter::new();
    let m = w.add_mesh("line", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[0, 1, 2]);
    w.add_node("Sliver", m, [0.0; 3], receiver.clone());
    let path = write(&dir, "sliver.glb", &w.to_glb());
    fails_with(&sunlit(&["info", &path]), &["sliver.glb: node 'Sliver'", "zero area"]);

    let mut w = GlbWriter::new();
    let m = w.add_mesh("sq", &square, &quad);
    w.add_node("Twin", m, [0.0; 3], None);
    w.add_node("Twin", m, [0.0, 0.0, 3.0], None);
    let path = write(&dir, "twins.glb", &w.to_glb());
    fails_with(&sunlit(&["info", &path]), &["duplicate receiver name 'Twin'", "twins.glb: node 'Twin'"]);

    let mut w = GlbWriter::new();
    let m = w.add_mesh("sq", &square, &quad);
    w.add_node("Roof", m, [0.0; 3], None);
    let path = write(&dir, "roof.glb", &w.to_glb());
    fails_with(&sunlit(&["info", &path, "--receivers", "Wall*"]), &["no receiving surface", "--receivers Wall*"]);
    // The library names its parameter (`foliage`); the CLI names its flag.
    fails_with(&sunlit(&["info", &path, "--foliage", "pine*"]), &["invalid --foliage pine*: no glTF node name matches it"]);
    let out = sunlit(&["info", &path, "--receivers", "ROO?"]);
    assert!(out.status.success(), "globs are case-insensitive: {}", stderr(&out));
}

#[test]
fn malformed_sun_and_options() {
    let dir = scratch("sun");
    let model = office_file(&dir);
    fails_with(&sunlit(&["fraction", &model, "--sun", "180"]), &["--sun", "AZ,ALT"]);
    fails_with(&sunlit(&["fraction", &model, "--sun", "south,40"]), &["--sun"]);
    fails_with(&sunlit(&["fraction", &model, "--sun", "180,120"]), &["--sun", "altitude 120"]);
    fails_with(&sunlit(&["fraction", &model, "--sun", "180,40", "--resolution", "1000000"]), &["--resolution", "texture size limit"]);
    fails_with(&sunlit(&["fraction", &model, "--sun", "180,40", "--accuracy", "2"]), &["--accuracy", "not a fraction error"]);
    fails_with(&sunlit(&["fraction", &model, "--sun", "180,40", "--accuracy", "0"]), &["--accuracy"]);
    // A negative altitude is a valid request: every fraction is 0.
    let out = sunlit(&["fraction", &model, "--sun", "180,-10", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["surfaces"].as_array().unwrap().iter().all(|s| s["fraction"] == 0.0));
}

#[test]
fn committed_example_is_what_the_code_generates() {
    // examples/office.glb is generated by `cargo run --example make_office`; keep them in step.
    let committed = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/office.glb")).unwrap();
    assert!(committed == office(6).to_glb(), "regenerate with: cargo run --example make_office");
}

#[test]
fn bad_energyplus_models_are_named_with_object_and_line() {
    let dir = scratch("idf");
    let good = sunlit::model::office_idf::office_idf(2, false, sunlit::model::office_idf::Shading::None);
    let unterminated = write(&dir, "open.idf", format!("{good}\nBuildingSurface:Detailed,\n  LOOSE_END,\n  Wall,\n").as_bytes());
    fails_with(&sunlit(&["info", &unterminated]), &["open.idf: ", "LOOSE_END", "not terminated"]);
    let bad_number = good.replacen("  10,0,3.5,", "  10,zero,3.5,", 1);
    assert_ne!(bad_number, good);
    let path = write(&dir, "number.idf", bad_number.as_bytes());
    fails_with(&sunlit(&["info", &path]), &["number.idf: ", "BuildingSurface:Detailed 'WALL_E' (line ", "'zero' is not a number"]);
    let json = write(&dir, "broken.epJSON", b"{\"Version\": {\"Version 1\": ");
    fails_with(&sunlit(&["info", &json]), &["broken.epJSON: "]);
    // --idf-out needs an EnergyPlus model; nothing is written when it is refused.
    let glb = office_file(&dir);
    let csv = dir.join("out.csv");
    let idf_out = dir.join("hooked.idf");
    let out = sunlit(&["annual", &glb, "--location", "40,-105,-7", "-o", csv.to_str().unwrap(), "--idf-out", idf_out.to_str().unwrap()]);
    fails_with(&out, &["--idf-out", "EnergyPlus model"]);
    assert!(!csv.exists() && !idf_out.exists());
    // A model whose Timestep differs from the CSV's is refused before anything is written.
    let model = write(&dir, "model.idf", good.as_bytes());
    let out = sunlit(&[
        "annual",
        &model,
        "--location",
        "40,-105,-7",
        "--timesteps-per-hour",
        "6",
        "--days-per-year",
        "3",
        "--samples-per-day",
        "3",
        "--resolution",
        "64",
        "-o",
        csv.to_str().unwrap(),
        "--idf-out",
        idf_out.to_str().unwrap(),
    ]);
    fails_with(&out, &["Timestep", "--timesteps-per-hour 4"]);
    assert!(!csv.exists() && !idf_out.exists());
}

#[test]
fn bench_lists_writes_and_times_generated_models() {
    let out = sunlit(&["bench", "--list"]);
    let list = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && list.contains("blaas-louvres") && list.contains("nyt-blocks"), "{list}");
    // The written model is an ordinary glb: its 62 receivers are read back.
    let dir = scratch("bench");
    let path = dir.join("blaas-louvres.glb").display().to_string();
    let out = sunlit(&["bench", "blaas-louvres", "--write", &path]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = sunlit(&["info", &path, "--json"]);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["receivers"].as_array().map(Vec::len), Some(62), "{info}");
    assert_eq!((info["triangles"].as_u64(), info["instances"].as_u64()), (Some(5828), Some(468)), "slats stay instanced");
    // A timed run of a few views prints the documented JSON.
    let out = sunlit(&["bench", "blaas-buildings", "--samples", "3x3", "--resolution", "64", "--views", "40", "--check", "5"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["seconds", "views", "views_rendered", "views_skipped", "views_per_second", "peak_memory_mib", "mean_abs_error"] {
        assert!(!line[key].is_null(), "{key} missing in {line}");
    }
    assert_eq!(line["shading_polygons"], 1045);
    assert!(line["max_abs_error"].as_f64().unwrap() < 0.05, "{line}");
    // The compute rasterizer counts the same views by name, checked alike.
    let out = sunlit(&[
        "bench",
        "blaas-buildings",
        "--engine",
        "compute",
        "--samples",
        "3x3",
        "--resolution",
        "64",
        "--views",
        "40",
        "--check",
        "5",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let compute: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(compute["engine"], "compute", "{compute}");
    let rendered = compute["views_rendered"].as_u64().unwrap();
    assert!(rendered > 0 && rendered + compute["views_skipped"].as_u64().unwrap() == compute["views_timed"].as_u64().unwrap(), "{compute}");
    assert_eq!(compute["bin_pool_reruns"], 0, "{compute}");
    assert!(compute["max_abs_error"].as_f64().unwrap() < 0.05, "{compute}");
    let help = String::from_utf8_lossy(&sunlit(&["bench", "--help"]).stdout).to_string();
    assert!(help.contains("--engine <auto|gpu|exact|compute>"), "{help}");
    fails_with(&sunlit(&["bench", "blaas-self", "--engine", "pixels"]), &["--engine", "auto, gpu, exact, compute"]);
    fails_with(&sunlit(&["bench", "no-such-model"]), &["no-such-model", "blaas-self"]);
    fails_with(&sunlit(&["bench", "--samples", "27by19", "blaas-self"]), &["--samples", "27by19"]);
    fails_with(&sunlit(&["bench", "--write", &path]), &["--write", "one generated model"]);
}

/// `sunlit info MODEL | head -1`: the reader closes the pipe while sunlit still prints its table;
/// sunlit ends quietly (SIGPIPE's default action), not with a panic.
#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    let dir = scratch("pipe");
    let path = dir.join("trees.glb").display().to_string();
    assert!(sunlit(&["bench", "blaas-trees-summer", "--write", &path]).status.success());
    for _ in 0..3 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sunlit"))
            .args(["info", &path])
            .env("XDG_RUNTIME_DIR", runtime_dir())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Read nothing: the first write past the pipe's buffer meets a closed pipe.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked") && out.status.code() != Some(101), "{:?}: {err}", out.status);
    }
}

/// `bench --backend noop` times the host alone: it plans and records the same views as a real
/// device (the same views rendered, tiles and triangles), reports the host's stages, and refuses
/// what would act on the zeros it reads back. `--limits` asks a real device for less.
#[test]
fn bench_on_the_noop_backend_times_the_same_views_on_the_host() {
    let quick = ["bench", "blaas-buildings", "--engine", "gpu", "--samples", "3x3", "--resolution", "64", "--views", "40", "--lanes", "1"];
    let line = |extra: &[&str]| -> serde_json::Value {
        let out = sunlit(&[&quick[..], extra].concat());
        assert!(out.status.success(), "{}", stderr(&out));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let real = line(&[]);
    let noop = line(&["--backend", "noop"]);
    for key in ["views_rendered", "tiles_rendered", "mean_triangles_per_tile"] {
        assert!(real[key].as_f64().unwrap() > 0.0, "{key} in {real}");
        assert_eq!(noop[key], real[key], "{key}: noop {noop} against {real}");
    }
    let stages = &noop["host_stages_seconds"];
    for stage in ["planning", "encoding", "submitting", "waiting", "unpacking"] {
        assert!(stages[stage].as_f64().is_some_and(|s| s >= 0.0), "{stage} in {noop}");
    }
    assert!(stages["planning"].as_f64().unwrap() > 0.0, "{noop}");
    // The culling is a part of the planning, the recording of the encoding.
    for (part, whole) in [("culling", "planning"), ("recording", "encoding")] {
        let (part, whole) = (stages[part].as_f64().unwrap(), stages[whole].as_f64().unwrap());
        assert!(part > 0.0 && part <= whole, "{noop}");
    }
    // The GPU's culling pass over the same views: it keeps some clusters of every lit view.
    let culled = line(&["--gpu-cull"]);
    let cull = &culled["gpu_cull"];
    assert!(cull["views"].as_u64().unwrap() >= real["views_rendered"].as_u64().unwrap(), "{cull}");
    assert!(cull["pairs_per_view"].as_f64().unwrap() >= 1.0 && cull["triangles_per_view"].as_f64().unwrap() > 0.0, "{cull}");
    fails_with(&sunlit(&["bench", "blaas-buildings", "--gpu-cull"]), &["--gpu-cull", "--engine gpu"]);
    // WebGPU's core limits on lavapipe: a smaller atlas at most, the same views.
    assert_eq!(line(&["--limits", "webgpu"])["views_rendered"], real["views_rendered"]);
    fails_with(&sunlit(&[&quick[..], &["--backend", "noop", "--check", "5"]].concat()), &["--check", "noop"]);
    fails_with(&sunlit(&[&quick[..], &["--backend", "noop", "--accuracy", "0.01"]].concat()), &["--accuracy", "noop"]);
    fails_with(&sunlit(&["bench", "blaas-buildings", "--backend", "noop"]), &["--backend", "--engine gpu"]);
    fails_with(&sunlit(&[&quick[..], &["--backend", "vulkan"]].concat()), &["--backend", "'vulkan'"]);
    fails_with(&sunlit(&[&quick[..], &["--limits", "huge"]].concat()), &["--limits", "'huge'"]);
}

/// An EnergyPlus model's own Site:Location is its location when neither --epw nor --location is
/// given: the CLI says so, and the CSV is the one --location with the same coordinates gives.
#[test]
fn energyplus_site_location_is_used_and_named() {
    let dir = scratch("site");
    let idf = sunlit::model::office_idf::office_idf(1, false, sunlit::model::office_idf::Shading::None);
    let with_site = write(&dir, "site.idf", format!("{idf}\nSite:Location, Chicago Test, 41.99, -87.91, -6.0, 205;\n").as_bytes());
    let quick = ["--days-per-year", "3", "--samples-per-day", "3", "--resolution", "64", "--refine", "1"];
    let (a, b) = (dir.join("site.csv"), dir.join("given.csv"));
    let out = sunlit(&[&["annual", &with_site, "-o", a.to_str().unwrap()][..], &quick].concat());
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("Site:Location 'Chicago Test' (41.99° N, -87.91° E, UTC-6)"), "{err}");
    let out = sunlit(&[&["annual", &with_site, "--location", "41.99,-87.91,-6", "-o", b.to_str().unwrap()][..], &quick].concat());
    assert!(out.status.success() && !stderr(&out).contains("Site:Location"), "{}", stderr(&out));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // Without one, the refusal says what to give.
    let bare = write(&dir, "bare.idf", idf.as_bytes());
    fails_with(&sunlit(&["annual", &bare, "-o", dir.join("c.csv").to_str().unwrap()]), &["--epw", "--location", "has no Site:Location"]);
}
