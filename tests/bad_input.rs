//! The bad-input corpus: one case per class of input users' tools can produce wrongly, each held
//! to its exact message (file, object or node, reason), exit code 1, no panic, no hang and no
//! file left behind, through the CLI (`sunlit annual … -o out.csv`) and, for model files, through
//! `sunlit::model::load_bytes` (what the JS API calls).

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::runtime_dir;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use base64::Engine as _;
use sunlit::model::glb_write::GlbWriter;
use sunlit::model::office::office;
use sunlit::model::office_idf::{Shading, office_idf};
use sunlit::model::{LoadOptions, load_bytes};

/// A bad input can take no longer than this to be refused (a hang fails the test).
const REFUSE_WITHIN: Duration = Duration::from_secs(120);

/// One input and what it must produce.
struct Case {
    /// Files written into the case's folder: (name, bytes).
    files: Vec<(String, Vec<u8>)>,
    /// Arguments after the model files; `{dir}` is the case's folder. `--location 40,-105,-7`,
    /// `-o {dir}/out.csv` and `--resolution 64` are added unless given (or `--epw` is).
    args: Vec<String>,
    /// The CLI's whole `error:` line after `error: `, paths relative to the case's folder (which
    /// itself reads `{dir}`).
    cli: String,
    /// `load_bytes`'s message for the model files, when the class is the model's.
    api: Option<String>,
}

impl Case {
    fn model(name: &str, bytes: Vec<u8>, message: &str) -> Self {
        Case { files: vec![(name.into(), bytes)], args: vec![], cli: message.into(), api: Some(message.into()) }
    }

    fn args(mut self, args: &[&str]) -> Self {
        self.args = args.iter().map(|s| s.to_string()).collect();
        self
    }

    fn api(mut self, message: Option<&str>) -> Self {
        self.api = message.map(str::to_string);
        self
    }

    fn with_file(mut self, name: &str, bytes: Vec<u8>) -> Self {
        self.files.push((name.into(), bytes));
        self
    }
}

/// Runs `sunlit annual` on the case in a fresh folder and checks everything the CLI promises.
fn check_cli(label: &str, case: &Case) {
    // A label may hold a date ("12/31"): one folder, not a folder inside another left behind.
    let folder = label.replace('/', "-");
    let dir = std::env::temp_dir().join(format!("sunlit-bad-{folder}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut models = Vec::new();
    for (name, bytes) in &case.files {
        std::fs::write(dir.join(name), bytes).unwrap();
        // Companion files (external buffers, weather, schedule files) are not models.
        if ![".bin", ".epw", ".csv"].iter().any(|ext| name.ends_with(ext)) {
            models.push(dir.join(name).display().to_string());
        }
    }
    let d = dir.display().to_string();
    let mut args: Vec<String> = vec!["annual".into()];
    args.extend(models);
    args.extend(case.args.iter().map(|a| a.replace("{dir}", &d)));
    let has = |flags: &[&str]| case.args.iter().any(|a| flags.contains(&a.as_str()));
    if !has(&["--epw", "--location"]) {
        args.extend(["--location".into(), "40,-105,-7".into()]);
    }
    if !has(&["-o"]) {
        args.extend(["-o".into(), format!("{d}/out.csv")]);
    }
    if !has(&["--resolution"]) {
        args.extend(["--resolution".into(), "64".into()]);
    }
    let (code, stderr) = run(&args);
    assert!(!stderr.contains("panicked"), "{label}: {stderr}");
    assert_eq!(code, Some(1), "{label}: exit code; stderr: {stderr}");
    let line = stderr.lines().find(|l| l.starts_with("error: ")).unwrap_or_else(|| panic!("{label}: no error line in: {stderr}"));
    assert_eq!(device_limit(&line.replace(&format!("{d}/"), "").replace(&d, "{dir}")), format!("error: {}", case.cli), "{label}");
    let mut left: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    let mut given: Vec<String> = case.files.iter().map(|(n, _)| n.clone()).collect();
    given.sort();
    assert_eq!(left, given, "{label}: files left behind");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The texture size limit in a `--resolution` message reads `{limit}`: it is the device's.
fn device_limit(message: &str) -> String {
    match message.split_once("16..=") {
        Some((head, tail)) => format!("{head}16..={{limit}}{}", tail.trim_start_matches(|c: char| c.is_ascii_digit())),
        None => message.to_string(),
    }
}

/// Runs the CLI with a time limit; returns (exit code, stderr).
fn run(args: &[String]) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args(args)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > REFUSE_WITHIN {
            let _ = child.kill();
            panic!("sunlit {args:?} did not finish within {REFUSE_WITHIN:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// The same model files through the library's in-memory loader.
fn check_api(label: &str, case: &Case) {
    let Some(expected) = &case.api else { return };
    let models: Vec<(String, Vec<u8>)> =
        case.files.iter().filter(|(n, _)| ![".bin", ".epw", ".csv"].iter().any(|ext| n.ends_with(ext))).cloned().collect();
    let mut options = LoadOptions::default();
    let mut args = case.args.iter();
    while let Some(a) = args.next() {
        if a == "--receivers" {
            options.receivers.push(args.next().unwrap().clone());
        }
    }
    let err = load_bytes(&models, &options).err().unwrap_or_else(|| panic!("{label}: load_bytes accepted it"));
    assert_eq!(&err.to_string(), expected, "{label} (load_bytes)");
}

fn check(label: &str, case: Case) {
    check_api(label, &case);
    check_cli(label, &case);
}

const SQUARE: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]];
const QUAD: [u32; 6] = [0, 1, 2, 0, 2, 3];

/// A node of a test model: name, positions, triangle indices.
type Node<'a> = (&'a str, &'a [[f32; 3]], &'a [u32]);

/// A .glb with one node per entry.
fn glb(nodes: &[Node]) -> Vec<u8> {
    let mut w = GlbWriter::new();
    for (name, positions, indices) in nodes {
        let m = w.add_mesh(name, positions, indices);
        w.add_node(name, m, [0.0; 3], None);
    }
    w.to_glb()
}

/// A .gltf with one triangle-list mesh in an embedded buffer; `node` is the node's JSON, `buffer`
/// the buffer's (its `uri` replaced by the data when it is `"DATA"`).
fn gltf(positions: &[[f32; 3]], indices: &[u32], node: &str, buffer_uri: Option<&str>) -> Vec<u8> {
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let bound = |f: fn(f32, f32) -> f32, start: f32| {
        let b = (0..3).map(|k| positions.iter().fold(start, |a, p| f(a, p[k])).to_string()).collect::<Vec<_>>();
        if positions.is_empty() { "[0,0,0]".to_string() } else { format!("[{}]", b.join(",")) }
    };
    let (min, max) = (bound(f32::min, f32::INFINITY), bound(f32::max, f32::NEG_INFINITY));
    let pos_len = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let uri = match buffer_uri {
        Some(u) => u.to_string(),
        None => format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin)),
    };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":{len}}}],
        "bufferViews":[{{"buffer":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{pos_len},"byteLength":{idx_len}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":{min},"max":{max}}},{{"bufferView":1,"componentType":5125,"count":{m},"type":"SCALAR"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"nodes":[{node}],"scenes":[{{"nodes":[0]}}]}}"#,
        len = bin.len(),
        idx_len = bin.len() - pos_len,
        n = positions.len(),
        m = indices.len(),
    )
    .into_bytes()
}

#[test]
fn broken_gltf_files() {
    let office = office(1).to_glb();
    check(
        "truncated",
        Case::model(
            "cut.glb",
            office[..office.len() / 2].to_vec(),
            "cut.glb: not a valid glTF 2.0 file: could not completely read the object",
        ),
    );
    check(
        "header only",
        Case::model("head.glb", office[..10].to_vec(), "head.glb: not a valid glTF 2.0 file: failed to fill whole buffer"),
    );
    check(
        "wrong magic",
        Case::model(
            "zip.glb",
            b"PK\x03\x04 a zip archive".to_vec(),
            "zip.glb: not a glTF file: expected the binary magic 'glTF' or a JSON object",
        ),
    );
    let mut bad_version = office.clone();
    bad_version[4] = 1;
    check("glb version 1", Case::model("v1.glb", bad_version, "v1.glb: not a valid glTF 2.0 file: unsupported version"));
    check("empty", Case::model("empty.gltf", vec![], "empty.gltf: the file is empty"));
    // Found by fuzzing: the gltf crate subtracted the header size from this length unchecked.
    let mut short = b"glTF\x02\0\0\0\x03\0\0\0".to_vec();
    short.resize(64, 0);
    check(
        "length below header",
        Case::model(
            "short.glb",
            short,
            "short.glb: not a valid glTF 2.0 file: its GLB header declares 3 bytes in all, less than the header itself",
        ),
    );
    check(
        "not json",
        Case::model(
            "bad.gltf",
            b"{\"asset\": ".to_vec(),
            "bad.gltf: not a valid glTF 2.0 file: EOF while parsing a value at line 1 column 10",
        ),
    );
}

#[test]
fn missing_and_external_buffers() {
    let node = r#"{"name":"A","mesh":0}"#;
    let external = gltf(&SQUARE, &QUAD, node, Some("geometry.bin"));
    check(
        "external buffer missing",
        Case::model(
            "ext.gltf",
            external.clone(),
            "ext.gltf: external buffer 'geometry.bin' could not be read: No such file or directory (os error 2)",
        )
        .api(Some(
            "ext.gltf: external buffer 'geometry.bin' was not given (give it with the .gltf, use a .glb, or embed buffers as data: URIs)",
        )),
    );
    // Present beside the file: the CLI reads it, the in-memory loader cannot.
    let bin: Vec<u8> = SQUARE.iter().flatten().flat_map(|c| c.to_le_bytes()).chain(QUAD.iter().flat_map(|i| i.to_le_bytes())).collect();
    check(
        "external buffer short",
        Case::model("ext.gltf", external.clone(), "ext.gltf: buffer 0 is truncated: 20 bytes present, 72 declared")
            .with_file("geometry.bin", bin[..20].to_vec())
            .api(Some("ext.gltf: external buffer 'geometry.bin' was not given (give it with the .gltf, use a .glb, or embed buffers as data: URIs)")),
    );
    // Nodes reached twice: a cycle, and a child shared by two parents (exponential to walk).
    let text = String::from_utf8(gltf(&SQUARE, &QUAD, node, None)).unwrap();
    let cycle =
        text.replace(r#""nodes":[{"name":"A","mesh":0}]"#, r#""nodes":[{"name":"A","mesh":0,"children":[1]},{"name":"B","children":[0]}]"#);
    let message = "cycle.gltf: node 'A': is reached twice in the node hierarchy (a cycle, or more than one parent)";
    check("cycle", Case::model("cycle.gltf", cycle.into_bytes(), message));
    let shared = text.replace(
        r#""nodes":[{"name":"A","mesh":0}],"scenes":[{"nodes":[0]}]"#,
        r#""nodes":[{"name":"A","mesh":0},{"name":"P","children":[0]},{"name":"Q","children":[0]}],"scenes":[{"nodes":[1,2]}]"#,
    );
    let message = "shared.gltf: node 'A': is reached twice in the node hierarchy (a cycle, or more than one parent)";
    check("shared child", Case::model("shared.gltf", shared.into_bytes(), message));
    let no_buffers = String::from_utf8(gltf(&SQUARE, &QUAD, node, None)).unwrap();
    let no_buffers = no_buffers.split("\"buffers\"").next().unwrap().to_string()
        + "\"bufferViews\""
        + no_buffers.split("\"bufferViews\"").nth(1).unwrap();
    check(
        "no buffers array",
        Case::model(
            "nobuf.gltf",
            no_buffers.into_bytes(),
            "nobuf.gltf: not a valid glTF 2.0 file: invalid glTF: bufferViews[0].buffer: Index out of bounds; bufferViews[1].buffer: Index out of bounds;",
        ),
    );
    let bad_uri = gltf(&SQUARE, &QUAD, node, Some("data:application/octet-stream;base64,@@@"));
    check("bad data uri", Case::model("uri.gltf", bad_uri, "uri.gltf: buffer 0: bad base64 data: Invalid symbol 64, offset 0."));
}

#[test]
fn accessors_out_of_range() {
    let node = r#"{"name":"A","mesh":0}"#;
    let text = String::from_utf8(gltf(&SQUARE, &QUAD, node, None)).unwrap();
    let long = text.replacen(r#""count":4"#, r#""count":400"#, 1);
    check(
        "count past view",
        Case::model(
            "count.gltf",
            long.into_bytes(),
            "count.gltf: mesh 0 '': accessor 0 reads bytes 0..4800 beyond its buffer view (ends at 48) or buffer (72 bytes)",
        ),
    );
    check(
        "index past vertices",
        Case::model("index.gltf", gltf(&SQUARE, &[0, 1, 7], node, None), "index.gltf: mesh 0 '': index 7 out of range (4 vertices)"),
    );
    // Found by fuzzing: gltf-json indexed the accessors with a missing POSITION accessor.
    let position = text.replacen(r#""POSITION":0"#, r#""POSITION":32"#, 1);
    let message = "position.gltf: mesh 0: primitive 0: POSITION accessor 32 does not exist (2 accessors)";
    check("position accessor missing", Case::model("position.gltf", position.clone().into_bytes(), message));
    // The same with invalid UTF-8 in a string, which the gltf crate reads anyway (found by fuzzing).
    let mut latin1 = position.replacen(r#""version":"2.0""#, "\"version\":\"2.0\",\"generator\":\"caf\u{1}\"", 1).into_bytes();
    let at = latin1.iter().position(|&b| b == 1).unwrap();
    latin1[at] = 0xE9;
    let message = "latin1.gltf: mesh 0: primitive 0: POSITION accessor 32 does not exist (2 accessors)";
    check("position accessor missing, not UTF-8", Case::model("latin1.gltf", latin1, message));
    let view = text.replacen(r#""byteLength":48}"#, r#""byteLength":4800}"#, 1);
    check(
        "view past buffer",
        Case::model(
            "view.gltf",
            view.into_bytes(),
            "view.gltf: mesh 0 '': accessor 0 reads bytes 0..48 beyond its buffer view (ends at 4800) or buffer (72 bytes)",
        ),
    );
    let huge = text.replacen(r#""count":4"#, r#""count":4294967295"#, 1);
    check(
        "count overflows",
        Case::model(
            "huge.gltf",
            huge.into_bytes(),
            "huge.gltf: mesh 0 '': accessor 0 reads bytes 0..51539607540 beyond its buffer view (ends at 48) or buffer (72 bytes)",
        ),
    );
}

/// Replaces the one occurrence of an f32 in a binary with another value (min/max stay finite).
fn patch_f32(bytes: &mut [u8], from: f32, to: f32) {
    let needle = from.to_le_bytes();
    let at = bytes.windows(4).position(|w| w == needle).expect("value present");
    bytes[at..at + 4].copy_from_slice(&to.to_le_bytes());
}

#[test]
fn absurd_coordinates() {
    for (value, label, shown) in [(f32::NAN, "nan", "NaN"), (f32::INFINITY, "inf", "inf"), (1e30, "far", "1e30")] {
        let mut p = SQUARE;
        p[2][0] = 1234.5;
        let mut bytes = glb(&[("Wall", &p, &QUAD)]);
        patch_f32(&mut bytes, 1234.5, value);
        let message =
            format!("{label}.glb: node 'Wall': vertex 2 has a non-finite or absurd coordinate [{shown}, 1.0, 0.0] (limit ±1e7 m)");
        check(label, Case::model(&format!("{label}.glb"), bytes, &message));
    }
    // Finite vertices and a finite transform can still put a node 1e30 m away.
    let node = r#"{"name":"Far","mesh":0,"scale":[1e30,1e30,1e30]}"#;
    let message = "scale.gltf: node 'Far': vertex 1 is placed at [1000000015047466200000000000000, 0, 0], beyond ±1e7 m (check the node's transform and units)";
    check("far by scale", Case::model("scale.gltf", gltf(&SQUARE, &QUAD, node, None), message));
    let node = r#"{"name":"Flat","mesh":0,"matrix":[0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,1]}"#;
    let message = "matrix.gltf: node 'Flat': receiver has zero area (all its triangles are degenerate)";
    check("singular matrix", Case::model("matrix.gltf", gltf(&SQUARE, &QUAD, node, None), message));
}

#[test]
fn degenerate_duplicate_and_unmatched_receivers() {
    let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    check(
        "collinear",
        Case::model(
            "line.glb",
            glb(&[("Sliver", &line, &[0, 1, 2])]),
            "line.glb: node 'Sliver': receiver has zero area (all its triangles are degenerate)",
        ),
    );
    let point = [[3.0, 3.0, 3.0]; 3];
    check(
        "zero area",
        Case::model(
            "point.glb",
            glb(&[("Dot", &point, &[0, 1, 2])]),
            "point.glb: node 'Dot': receiver has zero area (all its triangles are degenerate)",
        ),
    );
    check(
        "no triangles",
        Case::model(
            "lines.glb",
            glb(&[("Wire", &SQUARE, &[])]),
            "lines.glb: node 'Wire': receiver has zero area (all its triangles are degenerate)",
        ),
    );
    // 1001 parallel triangles 1 cm apart: 1001 planes, past the 1000 a receiver may split into.
    let stack: Vec<[f32; 3]> =
        (0..1001).flat_map(|k| [[0.0, 0.0, k as f32 * 0.01], [1.0, 0.0, k as f32 * 0.01], [0.0, 1.0, k as f32 * 0.01]]).collect();
    let indices: Vec<u32> = (0..stack.len() as u32).collect();
    let message = "many.glb: node 'Stack': receiver is not planar in fewer than 1000 parts (a curved mesh?): leave it out of the receivers";
    check("too many planes", Case::model("many.glb", glb(&[("Stack", &stack, &indices)]), message));
    let twins = glb(&[("Twin", &SQUARE, &QUAD), ("Twin", &SQUARE, &QUAD)]);
    check(
        "duplicate",
        Case::model("twins.glb", twins, "duplicate receiver name 'Twin': twins.glb: node 'Twin' and twins.glb: node 'Twin'"),
    );
    check(
        "no match",
        Case::model("wall.glb", glb(&[("Wall", &SQUARE, &QUAD)]), "no receiving surface: no node name matches --receivers Roof*")
            .args(&["--receivers", "Roof*"])
            .api(Some("no receiving surface: no node name matches receivers Roof*")),
    );
    let node = r#"{"mesh":0}"#;
    check(
        "unnamed only",
        Case::model(
            "anon.gltf",
            gltf(&SQUARE, &QUAD, node, None),
            "no receiving surface: the models have no named node with a mesh (name nodes, mark them in extras, or use --receivers)",
        )
        .api(Some("no receiving surface: the models have no named node with a mesh (name nodes, mark them in extras, or use receivers)")),
    );
    // Two models can clash by name too.
    check(
        "duplicate across files",
        Case::model("a.glb", glb(&[("Wall", &SQUARE, &QUAD)]), "duplicate receiver name 'Wall': a.glb: node 'Wall' and b.glb: node 'Wall'")
            .with_file("b.glb", glb(&[("Wall", &SQUARE, &QUAD)])),
    );
}

/// A receiving node that bends is split into planar receivers `NAME#1`, `NAME#2`, … by design
/// (a sunlit fraction is defined per plane); the API and `info` show the parts.
#[test]
fn non_planar_receivers_are_split_into_planar_parts() {
    let bent = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]];
    let indices = [0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2];
    let scene = load_bytes(&[("bent.glb".into(), glb(&[("Bent", &bent, &indices)]))], &LoadOptions::default()).unwrap();
    let names: Vec<&str> = scene.receivers.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["Bent#1", "Bent#2"]);
    for r in &scene.receivers {
        assert!((r.area - 1.0).abs() < 1e-6, "{}: {}", r.name, r.area);
        assert_eq!(r.origin, "bent.glb: node 'Bent'");
    }
    let normals: Vec<[i32; 3]> = scene.receivers.iter().map(|r| r.normal.round().as_ivec3().to_array()).collect();
    assert_eq!(normals, [[0, -1, 0], [1, 0, 0]], "south-facing and east-facing parts");
}

fn idf() -> String {
    office_idf(1, false, Shading::None)
}

#[test]
fn malformed_idf() {
    let open = format!("{}\nBuildingSurface:Detailed,\n  LOOSE_END,\n  Wall,\n", idf());
    check(
        "unterminated",
        Case::model(
            "open.idf",
            open.into_bytes(),
            "open.idf: object 'BuildingSurface:Detailed' 'LOOSE_END' starting at line 173 is not terminated by ';'",
        ),
    );
    let bad_number = idf().replacen("  10,0,3.5,", "  10,zero,3.5,", 1);
    check(
        "word for number",
        Case::model(
            "number.idf",
            bad_number.into_bytes(),
            "number.idf: BuildingSurface:Detailed 'WALL_E' (line 43): vertex 1 y-coordinate 'zero' is not a number",
        ),
    );
    let misspelled = idf().replacen("BuildingSurface:Detailed,", "BuildingSurface:Detailled,", 1);
    check(
        "misspelled geometry class",
        Case::model(
            "typo.idf",
            misspelled.into_bytes(),
            "typo.idf: BuildingSurface:Detailled 'WALL_S' (line 26): is not a geometry class sunlit knows (misspelt?); reading on would lose its surface",
        ),
    );
    let vertices = idf().replacen("  10,0,3.5,", "  10,0,", 1);
    check(
        "vertex count",
        Case::model(
            "vertices.idf",
            vertices.into_bytes(),
            "vertices.idf: BuildingSurface:Detailed 'WALL_E' (line 43): has 11 vertex coordinates, not x, y, z triples",
        ),
    );
    check(
        "not utf-8",
        Case::model(
            "latin1.idf",
            b"Version,25.2;\nZone,Caf\xe9;\n".to_vec(),
            "latin1.idf: not UTF-8 text: invalid byte 0xE9 at line 2 (re-save the file as UTF-8)",
        ),
    );
    let no_zone = idf().replacen("Zone,", "Zone_Typo,", 1);
    check(
        "missing zone",
        Case::model(
            "nozone.idf",
            no_zone.into_bytes(),
            "nozone.idf: BuildingSurface:Detailed 'WALL_S' (line 26): zone 'OFFICE' does not exist",
        ),
    );
}

/// Unknown classes that are not geometry (the many EnergyPlus classes sunlit has no use for) are
/// ignored: a model with them still loads.
#[test]
fn unknown_non_geometry_classes_are_ignored() {
    let text = format!("{}\nFrobnicator:Settings,\n  F1,\n  42;\n", idf());
    let scene = load_bytes(&[("extra.idf".into(), text.into_bytes())], &LoadOptions::default()).unwrap();
    assert!(!scene.receivers.is_empty());
}

#[test]
fn malformed_epjson() {
    check(
        "truncated",
        Case::model(
            "cut.epJSON",
            b"{\"Version\": {\"Version 1\": ".to_vec(),
            "cut.epJSON: not valid epJSON: EOF while parsing a value at line 1 column 26",
        ),
    );
    check(
        "array",
        Case::model(
            "list.epJSON",
            b"[1, 2]".to_vec(),
            "list.epJSON: not valid epJSON: invalid type: sequence, expected a JSON object at line 1 column 0",
        ),
    );
    let number_as_text = br#"{"Zone": {"Z1": {}}, "Shading:Site:Detailed": {"S1": {"vertices": [{"vertex_x_coordinate": "ten", "vertex_y_coordinate": 0, "vertex_z_coordinate": 0}]}}}"#;
    check(
        "text for number",
        Case::model(
            "text.epJSON",
            number_as_text.to_vec(),
            "text.epJSON: Shading:Site:Detailed 'S1' (line 1): 'vertex_x_coordinate' of vertex 1 must be a number, not the string \"ten\"",
        ),
    );
    let not_object = br#"{"Shading:Site:Detailed": {"S1": 7}}"#;
    check(
        "object is a number",
        Case::model(
            "seven.epJSON",
            not_object.to_vec(),
            "seven.epJSON: Shading:Site:Detailed 'S1' (line 1): must be a JSON object of fields, not the number 7",
        ),
    );
    let misspelled = br#"{"Shading:Site:Detailled": {"S1": {}}}"#;
    check(
        "misspelled geometry class",
        Case::model(
            "typo.epJSON",
            misspelled.to_vec(),
            "typo.epJSON: Shading:Site:Detailled 'S1' (line 1): is not a geometry class sunlit knows (misspelt?); reading on would lose its surface",
        ),
    );
}

fn office_glb() -> Vec<u8> {
    office(1).to_glb()
}

#[test]
fn bad_weather_files() {
    let epw = |name: &str, text: &str, message: &str| {
        Case::model("office.glb", office_glb(), message)
            .with_file(name, text.as_bytes().to_vec())
            .args(&["--epw", &format!("{{dir}}/{name}")])
            .api(None)
    };
    check(
        "no location",
        epw("w.epw", "DESIGN CONDITIONS,0\n", "w.epw: first line is not an EPW LOCATION record (starts with 'DESIGN CONDITIONS,0')"),
    );
    check("empty", epw("w.epw", "", "w.epw: the first line is empty; an EPW weather file starts with its LOCATION record"));
    check(
        "short",
        epw(
            "w.epw",
            "LOCATION,Golden,CO,USA\n",
            "w.epw: LOCATION record has 4 fields, expected 10 (LOCATION,City,State,Country,Source,WMO,Latitude,Longitude,TimeZone,Elevation)",
        ),
    );
    check(
        "word",
        epw(
            "w.epw",
            "LOCATION,Golden,CO,USA,TMY3,724666,north,-105.18,-7.0,1829.0\n",
            "w.epw: LOCATION field 6 (latitude) is not a number: 'north'",
        ),
    );
    check(
        "range",
        epw(
            "w.epw",
            "LOCATION,Golden,CO,USA,TMY3,724666,95,-105.18,-7.0,1829.0\n",
            "w.epw: LOCATION record: latitude 95 is outside -90..90 degrees",
        ),
    );
    check(
        "nan",
        epw(
            "w.epw",
            "LOCATION,Golden,CO,USA,TMY3,724666,39.74,NaN,-7.0,1829.0\n",
            "w.epw: LOCATION field 7 (longitude) is not a number: 'NaN'",
        ),
    );
    let missing = Case::model("office.glb", office_glb(), "none.epw: No such file or directory (os error 2)")
        .args(&["--epw", "{dir}/none.epw"])
        .api(None);
    check("missing", missing);
}

#[test]
fn out_of_range_options() {
    let office = |message: &str, args: &[&str]| Case::model("office.glb", office_glb(), message).args(args).api(None);
    check(
        "resolution 0",
        office("invalid --resolution: 0 is outside 16..={limit} (this device's texture size limit)", &["--resolution", "0"]),
    );
    check(
        "resolution huge",
        office("invalid --resolution: 1000000 is outside 16..={limit} (this device's texture size limit)", &["--resolution", "1000000"]),
    );
    check("days 0", office("invalid --days-per-year: 0 is outside 3..=365", &["--days-per-year", "0"]));
    check("samples 0", office("invalid --samples-per-day: 0 is outside 3..=240", &["--samples-per-day", "0"]));
    check(
        "timesteps 7",
        office(
            "invalid --timesteps-per-hour: 7 is not one EnergyPlus accepts ([1, 2, 3, 4, 5, 6, 10, 12, 15, 20, 30, 60])",
            &["--timesteps-per-hour", "7"],
        ),
    );
    check("refine 2", office("invalid --refine: 2 is outside 0..=1", &["--refine", "2"]));
    check("north nan", office("invalid --north: NaN is not a finite angle", &["--north", "NaN"]));
    check("latitude", office("invalid --location: latitude 91 is outside -90..90 degrees", &["--location", "91,0,0"]));
    check(
        "location words",
        office(
            "invalid --location: expected LAT,LON,TZ (degrees north, degrees east, hours from UTC, e.g. 39.74,-105.18,-7), got 'here'",
            &["--location", "here"],
        ),
    );
    check("hook", office("invalid --hook: 'sideways': expected scheduled or imported", &["--hook", "sideways"]));
    check("output folder", office("invalid --output: {dir} is a folder", &["-o", "{dir}"]));
    check("output in missing folder", office("no/such/out.csv: No such file or directory (os error 2)", &["-o", "{dir}/no/such/out.csv"]));
}

/// glTF extensions: one sunlit does not read is named with what to run; compressed data that
/// does not decode names its view or primitive, the reason, and the same conversion.
#[test]
fn unread_extensions_and_undecodable_compression() {
    let node = r#"{"name":"A","mesh":0}"#;
    let text = String::from_utf8(gltf(&SQUARE, &QUAD, node, None)).unwrap();
    let convert = "convert it to plain glTF, e.g. with glTF Transform: `npx @gltf-transform/cli copy IN.glb OUT.glb` (which writes no compression), or re-export it without that extension";
    let required = |ext: &str| {
        text.replacen(
            r#"{"asset":{"version":"2.0"},"#,
            &format!(r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["{ext}"],"extensionsRequired":["{ext}"],"#),
            1,
        )
    };
    check(
        "unread required extension",
        Case::model(
            "lod.gltf",
            required("MSFT_lod").into_bytes(),
            &format!(
                "lod.gltf: requires the glTF extension 'MSFT_lod', which sunlit does not read (it reads \
                 KHR_mesh_quantization, EXT_meshopt_compression, KHR_meshopt_compression, KHR_draco_mesh_compression, \
                 EXT_mesh_gpu_instancing); {convert}"
            ),
        ),
    );
    // A view claiming meshopt-compressed vertices, whose "compressed" bytes are the plain indices.
    let meshopt = required("EXT_meshopt_compression").replacen(
        r#"{"buffer":0,"byteLength":48}"#,
        r#"{"buffer":0,"byteLength":48,"byteStride":12,"extensions":{"EXT_meshopt_compression":{"buffer":0,"byteOffset":48,"byteLength":24,"byteStride":12,"count":4,"mode":"ATTRIBUTES"}}}"#,
        1,
    );
    check(
        "meshopt data that does not decode",
        Case::model(
            "meshopt.gltf",
            meshopt.into_bytes(),
            &format!(
                "meshopt.gltf: bufferView 0: EXT_meshopt_compression: the attributes data could not be decoded (invalid encoded stream); {convert}"
            ),
        ),
    );
    // A primitive claiming Draco data, whose bytes are the plain positions.
    let draco = required("KHR_draco_mesh_compression").replacen(
        r#""attributes":{"POSITION":0},"indices":1}"#,
        r#""attributes":{"POSITION":0},"indices":1,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":0}}}}"#,
        1,
    );
    check(
        "draco data that does not decode",
        Case::model(
            "draco.gltf",
            draco.into_bytes(),
            &format!(
                "draco.gltf: mesh 0 primitive 0: KHR_draco_mesh_compression: the Draco data in bufferView 0 could not be decoded (General error: Invalid magic); {convert}"
            ),
        ),
    );
    // Unsigned ints are no position type, quantized or not.
    let uint = text.replacen(r#""componentType":5126"#, r#""componentType":5125"#, 1);
    check(
        "positions of unsigned ints",
        Case::model(
            "uint.gltf",
            uint.into_bytes(),
            "uint.gltf: mesh 0 '': POSITION accessor 0 is Vec3 of U32; expected VEC3 of float, or of (normalized) byte or short (KHR_mesh_quantization)",
        ),
    );
}

/// Compressed glTF with its bytes flipped (a fixed-seed sample of what fuzzing does to the
/// quantized, meshopt and Draco seeds): every mutant loads or gives an error; none panics.
#[test]
fn corrupted_compressed_gltf_never_panics() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::SmallRng::seed_from_u64(15);
    let seeds: [&[u8]; 3] = [
        include_bytes!("../fuzz/seeds/gltf/office-quantized.glb"),
        include_bytes!("../fuzz/seeds/gltf/office-meshopt.glb"),
        include_bytes!("../fuzz/seeds/gltf/office-draco.glb"),
    ];
    let (mut loaded, mut refused) = (0, 0);
    for seed in seeds {
        // The binary chunk starts after the 20-byte header and the JSON chunk: mutate data there,
        // where the decoders read, so the JSON stays valid and the decoders see the damage.
        let json_length = u32::from_le_bytes(seed[12..16].try_into().unwrap()) as usize;
        let bin = 20 + json_length + 8;
        for _ in 0..2000 {
            let mut bytes = seed.to_vec();
            for _ in 0..rng.random_range(1..8) {
                let at = rng.random_range(bin..bytes.len());
                bytes[at] = rng.random();
            }
            let result = std::panic::catch_unwind(|| load_bytes(&[("mutant.glb".to_string(), bytes.clone())], &LoadOptions::default()));
            match result {
                Ok(Ok(_)) => loaded += 1,
                Ok(Err(_)) => refused += 1,
                Err(_) => panic!("a mutant of a compressed seed panicked: {bytes:?}"),
            }
        }
    }
    // Both outcomes occur: the mutations reach the decoders and do not all fail the same way.
    assert!(loaded > 0 && refused > 0, "{loaded} loaded, {refused} refused");
}

/// Models the hook would break are refused by name before anything is counted or written: a
/// Timestep other than the CSV's, a RunPeriod EnergyPlus 25.2 stops on (its own messages:
/// "Invalid input start month/day (4/31)", "start year (2021) is after the end year (2020)"),
/// and a receiver named after a surface EnergyPlus never lights (the ground floor, NoSun), which
/// cannot take a sunlit fraction schedule.
#[test]
fn models_the_hook_cannot_take() {
    let hook = ["--idf-out", "{dir}/hooked.idf"];
    check(
        "hook timestep",
        Case::model(
            "ts.idf",
            idf().into_bytes(),
            "ts.idf: Timestep (line 8): the model runs 4 timesteps per hour but the CSV has 6: use --timesteps-per-hour 4",
        )
        .args(&[hook[0], hook[1], "--timesteps-per-hour", "6"])
        .api(None),
    );
    let april31 = idf().replacen("RunPeriod, YEAR, 1, 1, , 12, 31,", "RunPeriod, YEAR, 4, 31, , 12, 31,", 1);
    check(
        "hook run period date",
        Case::model(
            "april.idf",
            april31.into_bytes(),
            "april.idf: RunPeriod 'YEAR' (line 12): Begin Month/Day 4/31 is not a date: EnergyPlus would stop on it",
        )
        .args(&hook)
        .api(None),
    );
    let backwards = idf().replacen("RunPeriod, YEAR, 1, 1, , 12, 31, ,", "RunPeriod, YEAR, 1, 1, 2021, 12, 31, 2020,", 1);
    check(
        "hook run period years",
        Case::model(
            "years.idf",
            backwards.into_bytes(),
            "years.idf: RunPeriod 'YEAR' (line 12): it begins on 2021-01-01, after it ends (2020-12-31): EnergyPlus would stop on it",
        )
        .args(&hook)
        .api(None),
    );
    let floor = glb(&[("FLOOR", &SQUARE, &QUAD)]);
    check(
        "hook dark surface",
        Case::model(
            "office.idf",
            idf().into_bytes(),
            "invalid --hook: receiver 'FLOOR' (floor.glb: node 'FLOOR') is BuildingSurface:Detailed 'FLOOR' (line 111), which EnergyPlus keeps dark or never lights (Outside Boundary Condition 'Ground', Sun Exposure NoSun): it cannot take a sunlit fraction schedule",
        )
        .with_file("floor.glb", floor)
        .args(&[hook[0], hook[1], "--receivers", "FLOOR"])
        .api(None),
    );
}

/// A shade's `Transmittance Schedule Name` that names nothing, a transmittance outside 0..1, a
/// `Schedule:File` that cannot be read or is too short, a `Schedule:Compact` whose `Through`
/// dates stop before 12/31, special days sunlit cannot place, and an nth weekday the month lacks
/// (a 5th Monday of December): each refused by object, field and reason, before anything is
/// counted.
#[test]
fn shade_transmittance_schedules() {
    let base = idf();
    let at = base.lines().count() + 1;
    let with = |schedule: &str, objects: &str| {
        format!("{base}Shading:Site:Detailed, TREE, {schedule}, 3, 0,-5,0, 1,-5,0, 1,-5,1;\n{objects}").into_bytes()
    };
    let tree = format!("Shading:Site:Detailed 'TREE' (line {at})");
    let next = at + 1;
    check(
        "unknown schedule",
        Case::model(
            "unknown.idf",
            with("NOPE", ""),
            &format!("unknown.idf: {tree}: field 'Transmittance Schedule Name': 'NOPE' names no schedule in the model"),
        ),
    );
    check(
        "transmittance above 1",
        Case::model(
            "above.idf",
            with("TAU", "Schedule:Constant, TAU, , 1.5;\n"),
            &format!(
                "above.idf: {tree}: field 'Transmittance Schedule Name': Schedule:Constant 'TAU' (line {next}) takes the value 1.5, outside 0..1 for a transmittance"
            ),
        ),
    );
    let file = |name: &str| with("TAU", &format!("Schedule:File, TAU, , {name}, 1, 0, 8760, Comma, No, 60;\n"));
    let missing = format!(
        "missing.idf: Schedule:File 'TAU' (line {next}): field 'File Name': 'missing.csv' cannot be read (No such file or directory (os error 2))"
    );
    check("missing schedule file", Case::model("missing.idf", file("missing.csv"), &missing));
    let short = format!(
        "short.idf: Schedule:File 'TAU' (line {next}): field 'File Name': 'short.csv' is too short: 3 values after 0 skipped rows, 8760 needed (8760 hours of 60-minute items)"
    );
    let unreadable_here = format!(
        "short.idf: Schedule:File 'TAU' (line {next}): field 'File Name': 'short.csv' cannot be read (No such file or directory (os error 2))"
    );
    check(
        "short schedule file",
        Case::model("short.idf", file("short.csv"), &short).with_file("short.csv", b"0.5\n0.5\n0.5\n".to_vec()).api(Some(&unreadable_here)),
    );
    check(
        "compact short of 12/31",
        Case::model(
            "through.idf",
            with("TAU", "Schedule:Compact, TAU, , Through: 6/30, For: AllDays, Until: 24:00, 0.5;\n"),
            &format!("through.idf: Schedule:Compact 'TAU' (line {next}): field 'Through': its dates end on 06/30, not on 12/31"),
        ),
    );
    // A special day sunlit cannot place would change a schedule's day type for days.
    let special = |day: &str| with("TAU", &format!("Schedule:Constant, TAU, , 0.5;\nRunPeriodControl:SpecialDays, FEST, {day};\n"));
    let fest = format!("RunPeriodControl:SpecialDays 'FEST' (line {})", next + 1);
    for (file, day, why) in [
        (
            "special-type.idf",
            "7/4, 1, Festival",
            "field 'Special Day Type': 'Festival' is not Holiday, SummerDesignDay, WinterDesignDay, CustomDay1 or CustomDay2",
        ),
        ("special-duration.idf", "7/4, 400, Holiday", "field 'Duration': '400' is not a whole number of days from 1 to 366"),
        ("special-date.idf", "Easter, 1, Holiday", "field 'Start Date': 'Easter' is not a date (M/D, Month D, or Nth Weekday in Month)"),
    ] {
        check(file, Case::model(file, special(day), &format!("{file}: {fest}: {why}")));
    }
    // A weekday the month lacks in the run's year (the office's RunPeriod starts on a Sunday in a
    // year of 365 days: December has four Mondays): EnergyPlus stops on it, and so does sunlit,
    // once the run's year is known (loading alone does not know it, so only the CLI's year).
    let nths = "there is no 5th Monday of December in the run's year (EnergyPlus stops on such a date: \"Nth Day of Month, not enough Nths\"); use 'Last' or a date";
    let fifth = format!("fifth.idf: {fest}: field 'Start Date': {nths}");
    check("fifth weekday", Case::model("fifth.idf", special("5th Monday in December, 1, Holiday"), &fifth).api(None));
    let saving =
        with("TAU", "Schedule:Constant, TAU, , 0.5;\nRunPeriodControl:DaylightSavingTime, 2nd Sunday in March, 5th Monday in December;\n");
    let dst = format!("dst.idf: RunPeriodControl:DaylightSavingTime (line {}): field 'End Date': {nths}", next + 1);
    check("fifth weekday ends daylight saving", Case::model("dst.idf", saving, &dst).api(None));
}
