//! glTF as the web ships it, made by the real tools: glTF Transform (npm `@gltf-transform/cli`,
//! what web pipelines run) writes quantized, meshopt- and Draco-compressed, instanced, optimized,
//! welded, unwelded, deduplicated, flattened and .gltf+.bin variants of `examples/office.glb`, and
//! each must give the original's sunlit fractions within 0.002 for several suns (exact reference;
//! one GPU run).
//! Khronos's glTF-Validator (npm `gltf-validator`) must find no error in sunlit's own glb output.
//!
//! The tools come from `npm ci` (scripts/setup.sh runs it); without them these tests fail and say so.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::runtime_dir;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The largest |Δ fraction| a variant may show against the original (the bound).
const TOLERANCE: f64 = 0.002;

/// Sun positions (azimuth, altitude): low and high, from the east, south and west.
const SUNS: [(f64, f64); 5] = [(200.0, 35.0), (120.0, 20.0), (250.0, 50.0), (160.0, 65.0), (95.0, 12.0)];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn original() -> PathBuf {
    root().join("examples/office.glb")
}

/// A program from node_modules/.bin, or a failure that says how to get it.
fn npm_tool(name: &str) -> PathBuf {
    let path = root().join("node_modules/.bin").join(name);
    assert!(
        path.exists(),
        "{} is missing: run `npm ci` in {} (scripts/setup.sh does it; `npm test` runs setup.sh) to install the npm devDependencies \
         @gltf-transform/cli and gltf-validator",
        path.display(),
        root().display()
    );
    path
}

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("gltf-variants", name)
}

/// `gltf-transform COMMAND original OUT [OPTIONS]`; returns OUT.
fn transform(dir: &Path, command: &str, out: &str, options: &[&str]) -> PathBuf {
    transform_file(&original(), dir, command, out, options)
}

/// `gltf-transform COMMAND input OUT [OPTIONS]`; returns OUT.
fn transform_file(input: &Path, dir: &Path, command: &str, out: &str, options: &[&str]) -> PathBuf {
    let target = dir.join(out);
    let result = Command::new(npm_tool("gltf-transform")).arg(command).arg(input).arg(&target).args(options).output().unwrap();
    assert!(result.status.success(), "gltf-transform {command}: {}", String::from_utf8_lossy(&result.stderr));
    target
}

/// Every receiver's fraction from `sunlit fraction --json` (exact reference, or the GPU at `resolution`).
fn fractions(model: &Path, (azimuth, altitude): (f64, f64), gpu_resolution: Option<u32>) -> BTreeMap<String, f64> {
    let sun = format!("{azimuth},{altitude}");
    let mut args = vec!["fraction".to_string(), model.display().to_string(), "--sun".into(), sun, "--json".into()];
    match gpu_resolution {
        Some(r) => args.extend(["--resolution".to_string(), r.to_string()]),
        None => args.push("--exact".into()),
    }
    let out = Command::new(env!("CARGO_BIN_EXE_sunlit")).args(&args).env("XDG_RUNTIME_DIR", runtime_dir()).output().unwrap();
    assert!(out.status.success(), "sunlit {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    json["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["name"].as_str().unwrap().to_string(), s["fraction"].as_f64().unwrap()))
        .collect()
}

/// The same receivers, each within [`TOLERANCE`]; returns the largest |Δ|.
fn assert_close(label: &str, original: &BTreeMap<String, f64>, variant: &BTreeMap<String, f64>) -> f64 {
    assert_within(label, original, variant, TOLERANCE)
}

/// The same receivers, each within `tolerance`; returns the largest |Δ|.
fn assert_within(label: &str, original: &BTreeMap<String, f64>, variant: &BTreeMap<String, f64>, tolerance: f64) -> f64 {
    assert_eq!(original.keys().collect::<Vec<_>>(), variant.keys().collect::<Vec<_>>(), "{label}: receivers");
    let mut worst = 0.0f64;
    for (name, f) in original {
        let delta = (variant[name] - f).abs();
        assert!(delta <= tolerance, "{label}: {name} {} against the reference's {f} (|Δ| {delta} > {tolerance})", variant[name]);
        worst = worst.max(delta);
    }
    worst
}

/// The JSON's `extensionsRequired` of a .glb, so each variant is known to use what it is meant to.
fn required_extensions(glb: &Path) -> Vec<String> {
    let bytes = std::fs::read(glb).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    json["extensionsRequired"].as_array().map_or(vec![], |a| a.iter().map(|e| e.as_str().unwrap().to_string()).collect())
}

/// glTF Transform 4.5 writes only EXT_meshopt_compression. KHR_meshopt_compression reads the
/// same bitstreams (version 0 is common to both), so its meshopt file with the extension renamed
/// (same length: the GLB stays valid) is a KHR_meshopt_compression file.
fn khr_meshopt(dir: &Path) -> PathBuf {
    let ext = transform(dir, "meshopt", "meshopt-for-khr.glb", &[]);
    let bytes = std::fs::read(ext).unwrap();
    let (from, to) = (b"EXT_meshopt_compression", b"KHR_meshopt_compression");
    let mut renamed = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            renamed.extend_from_slice(to);
            i += from.len();
        } else {
            renamed.push(bytes[i]);
            i += 1;
        }
    }
    let path = dir.join("meshopt-khr.glb");
    std::fs::write(&path, renamed).unwrap();
    path
}

#[test]
fn gltf_transform_variants_give_the_originals_fractions() {
    let dir = scratch("exact");
    let variants = [
        ("quantize (14-bit shorts)", transform(&dir, "quantize", "quantize.glb", &[]), vec!["KHR_mesh_quantization"]),
        (
            "quantize (one scene volume)",
            transform(&dir, "quantize", "quantize-scene.glb", &["--quantization-volume", "scene"]),
            vec!["KHR_mesh_quantization"],
        ),
        ("meshopt", transform(&dir, "meshopt", "meshopt.glb", &[]), vec!["EXT_meshopt_compression", "KHR_mesh_quantization"]),
        (
            "meshopt (medium)",
            transform(&dir, "meshopt", "meshopt-medium.glb", &["--level", "medium"]),
            vec!["EXT_meshopt_compression", "KHR_mesh_quantization"],
        ),
        ("meshopt as KHR_meshopt_compression", khr_meshopt(&dir), vec!["KHR_meshopt_compression", "KHR_mesh_quantization"]),
        ("draco", transform(&dir, "draco", "draco.glb", &[]), vec!["KHR_draco_mesh_compression"]),
        // Speed 0: Draco's slowest, most compressed coding (Blender's default level is a low speed too).
        (
            "draco (speed 0)",
            transform(&dir, "draco", "draco-slow.glb", &["--encode-speed", "0", "--decode-speed", "0"]),
            vec!["KHR_draco_mesh_compression"],
        ),
        ("draco (sequential)", transform(&dir, "draco", "draco-seq.glb", &["--method", "sequential"]), vec!["KHR_draco_mesh_compression"]),
        (
            "draco of the quantized office",
            transform_file(&transform(&dir, "quantize", "to-draco.glb", &[]), &dir, "draco", "quantized-draco.glb", &[]),
            vec!["KHR_draco_mesh_compression", "KHR_mesh_quantization"],
        ),
        // The louvre slats become one node with 6 instances (EXT_mesh_gpu_instancing, used but
        // not required: a reader that ignored it would silently lose them).
        ("instance", transform(&dir, "instance", "instance.glb", &[]), vec![]),
        // `optimize` as a web pipeline runs it, less what changes names or geometry on purpose
        // (joining meshes, flattening, simplifying): instancing, meshopt, quantization, pruning.
        (
            "optimize (no join, flatten or simplify)",
            transform(&dir, "optimize", "optimize.glb", &["--join", "false", "--flatten", "false", "--simplify", "false"]),
            vec!["EXT_meshopt_compression", "KHR_mesh_quantization"],
        ),
        ("weld", transform(&dir, "weld", "weld.glb", &[]), vec![]),
        ("unweld", transform(&dir, "unweld", "unweld.glb", &[]), vec![]),
        ("dedup", transform(&dir, "dedup", "dedup.glb", &[]), vec![]),
        ("flatten", transform(&dir, "flatten", "flatten.glb", &[]), vec![]),
        ("copy to .gltf + .bin", transform(&dir, "copy", "copy.gltf", &[]), vec![]),
    ];
    let originals: Vec<_> = SUNS.iter().map(|&sun| fractions(&original(), sun, None)).collect();
    for (label, path, extensions) in &variants {
        if path.extension().is_some_and(|e| e == "glb") {
            let mut found = required_extensions(path);
            found.sort();
            let mut expected: Vec<String> = extensions.iter().map(|e| e.to_string()).collect();
            expected.sort();
            assert_eq!(found, expected, "{label}: extensionsRequired");
        }
        let mut worst = 0.0f64;
        for (sun, original) in SUNS.iter().zip(&originals) {
            worst = worst.max(assert_close(&format!("{label} at sun {sun:?}"), original, &fractions(path, *sun, None)));
        }
        println!("{label}: max |Δ fraction| {worst:.6} over {} suns (exact)", SUNS.len());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// 8-bit positions move vertices by up to half a step of a mesh's bounding box / 255 (a few cm on
/// the office): a different geometry, whose fractions differ from the original's by more than
/// 0.002. What sunlit must get right is reading it: its fractions must equal those of the same
/// file dequantized to floats by glTF Transform itself.
#[test]
fn byte_positions_read_as_gltf_transform_dequantizes_them() {
    let dir = scratch("bytes");
    let bytes = transform(&dir, "quantize", "quantize8.glb", &["--quantize-position", "8"]);
    let floats = transform_file(&bytes, &dir, "dequantize", "dequantized8.glb", &[]);
    assert_eq!(required_extensions(&bytes), ["KHR_mesh_quantization"]);
    assert_eq!(required_extensions(&floats), Vec::<String>::new());
    let mut worst = 0.0f64;
    for sun in SUNS {
        let reference = fractions(&floats, sun, None);
        worst = worst.max(assert_within(&format!("8-bit at sun {sun:?}"), &reference, &fractions(&bytes, sun, None), 1e-5));
    }
    println!("8-bit positions: max |Δ fraction| {worst:.2e} against glTF Transform's dequantization (exact)");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn compressed_variants_give_the_originals_fractions_on_the_gpu() {
    let dir = scratch("gpu");
    let sun = SUNS[0];
    let original = fractions(&original(), sun, Some(256));
    for (label, path) in
        [("meshopt", transform(&dir, "meshopt", "meshopt.glb", &[])), ("draco", transform(&dir, "draco", "draco.glb", &[]))]
    {
        let worst = assert_close(&format!("{label} (GPU, 256²)"), &original, &fractions(&path, sun, Some(256)));
        println!("{label}: max |Δ fraction| {worst:.6} against the original, GPU at 256²");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Errors and warnings from Khronos's glTF-Validator (tests/gltf/validate.mjs), per file.
fn validate(files: &[&Path]) -> Vec<serde_json::Value> {
    npm_tool("gltf-transform"); // the same `npm ci` installs gltf-validator
    assert!(root().join("node_modules/gltf-validator").exists(), "node_modules/gltf-validator is missing: run `npm ci`");
    let out = Command::new("node").arg(root().join("tests/gltf/validate.mjs")).args(files).output().unwrap();
    assert!(out.status.success(), "validate.mjs: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

#[test]
fn sunlits_own_glb_output_passes_gltf_validator() {
    let dir = scratch("validator");
    let bench = dir.join("blaas-louvres.glb");
    let out = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args(["bench", "blaas-louvres", "--write"])
        .arg(&bench)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .unwrap();
    assert!(out.status.success(), "sunlit bench --write: {}", String::from_utf8_lossy(&out.stderr));
    let office = original();
    let reports = validate(&[office.as_path(), bench.as_path()]);
    assert_eq!(reports.len(), 2);
    for report in &reports {
        assert_eq!(report["errors"], 0, "gltf-validator: {report}");
        println!("{}: {} errors, {} warnings", report["file"], report["errors"], report["warnings"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
