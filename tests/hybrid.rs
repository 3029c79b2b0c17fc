//! The hybrid engine: `auto`, `exact` and `gpu` agree (the GPU within its tolerance), a profile
//! that favours either engine gives the same answers, the same profile gives the same CSV byte
//! for byte, and the GPU path still answers alone.
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use std::path::Path;
use std::process::Command;

use glam::{DMat4, DVec3};
use sunlit::count::gpu::CounterOptions;
use sunlit::count::hybrid::{Cost, EngineKind, HybridEngine, Profile, ProfileSource, write_profile};
use sunlit::count::{ViewAnswer, ViewRequest, exact};
use sunlit::scene::{Scene, SceneBuilder, SourceMesh, SourceNode};

mod common;
use common::Scratch;

/// |GPU − exact| allowed at 256² (the GPU tests' bound at 512² is 0.005 on random scenes).
const GPU_TOLERANCE: f64 = 0.01;

fn cuboid(lo: [f32; 3], hi: [f32; 3]) -> SourceMesh {
    let c =
        |i: u32| [if i & 1 == 0 { lo[0] } else { hi[0] }, if i & 2 == 0 { lo[1] } else { hi[1] }, if i & 4 == 0 { lo[2] } else { hi[2] }];
    let quads: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    SourceMesh { positions: (0..8).map(c).collect(), indices: quads.iter().flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]]).collect() }
}

fn quad(x0: f32, x1: f32, z0: f32, z1: f32) -> SourceMesh {
    SourceMesh { positions: vec![[x0, 0., z0], [x1, 0., z0], [x1, 0., z1], [x0, 0., z1]], indices: vec![0, 1, 2, 0, 2, 3] }
}

/// Two south walls, one under 30 instanced slats and a fin, one bare.
fn louvred_walls() -> Scene {
    let mut b = SceneBuilder::new();
    b.add_object("test", "LOUVRED", quad(0.0, 4.0, 0.0, 3.0), true);
    b.add_object("test", "BARE", quad(10.0, 14.0, 0.0, 3.0), true);
    b.add_object("test", "FIN", cuboid([4.0, -1.0, 0.0], [4.1, 0.0, 3.0]), false);
    let slat = b.add_mesh("slat", cuboid([-0.5, -0.4, 0.0], [4.5, -0.1, 0.03]));
    for k in 0..30 {
        let transform = DMat4::from_translation(DVec3::new(0.0, 0.0, 0.1 * k as f64));
        let name = format!("S{k}");
        b.add_node(SourceNode { origin: name.clone(), name, mesh: slat, transform, receiver: false });
    }
    b.build().unwrap()
}

fn requests(scene: &Scene) -> Vec<ViewRequest> {
    let mut out = Vec::new();
    for az in [100.0f64, 140.0, 180.0, 220.0, 260.0] {
        for alt in [8.0f64, 25.0, 45.0, 70.0] {
            let (a, h) = (az.to_radians(), alt.to_radians());
            let sun = DVec3::new(h.cos() * a.sin(), h.cos() * a.cos(), h.sin());
            out.extend((0..scene.receivers.len() as u32).map(|r| ViewRequest::new(r, sun)));
        }
    }
    out
}

fn options() -> CounterOptions {
    CounterOptions { resolution: 256, ..Default::default() }
}

/// A test's scratch folder (profiles, caches, CSVs): removed when it passes, kept when it fails.
fn scratch(name: &str) -> Scratch {
    Scratch::new("hybrid", name)
}

fn answers(scene: &Scene, kind: EngineKind, source: ProfileSource) -> (Vec<ViewAnswer>, usize) {
    let engine = HybridEngine::new(scene, kind, options(), Some(1), source).unwrap();
    let out = pollster::block_on(engine.count(&requests(scene))).unwrap();
    (out, engine.stats().gpu_views)
}

/// A pinned profile, written into `dir`: `gpu_cheap` makes every loaded view cheaper on the GPU,
/// else on the CPU.
fn pinned(dir: &Path, gpu_cheap: bool) -> ProfileSource {
    let (exact, gpu) = if gpu_cheap { (1e6, 1.0) } else { (1.0, 1e6) };
    let profile = Profile {
        device: "test".into(),
        exact: Cost { per_view_us: exact, per_triangle_us: 0.0 },
        gpu: Some(Cost { per_view_us: gpu, per_triangle_us: 0.0 }),
        gpu_startup_seconds: Some(0.0),
        compute: None,
        compute_startup_seconds: None,
    };
    let path = dir.join(if gpu_cheap { "gpu.json" } else { "exact.json" });
    write_profile(&path, &profile).unwrap();
    ProfileSource::File(path)
}

#[test]
fn auto_exact_and_gpu_agree_and_either_calibration_gives_the_same_answers() {
    let dir = scratch("agree");
    let scene = louvred_walls();
    let reference = exact::sunlit_fractions(&scene, &requests(&scene));
    let (exact_answers, exact_gpu_views) = answers(&scene, EngineKind::Exact, ProfileSource::Probe);
    let (gpu_answers, _) = answers(&scene, EngineKind::Gpu, ProfileSource::Probe);
    let (auto_cpu, cpu_routed) = answers(&scene, EngineKind::Auto, pinned(&dir, false));
    let (auto_gpu, gpu_routed) = answers(&scene, EngineKind::Auto, pinned(&dir, true));
    assert_eq!(exact_gpu_views, 0);
    assert_eq!(cpu_routed, 0, "a profile with a dear GPU routes nothing to it");
    assert!(gpu_routed > 0, "a profile with a cheap GPU routes the loaded views to it");
    let mut partly = 0;
    for (i, want) in reference.iter().enumerate() {
        assert!(
            (exact_answers[i].fraction - want).abs() < 1e-6,
            "view {i}: exact engine {} vs reference {want}",
            exact_answers[i].fraction
        );
        assert!((gpu_answers[i].fraction - want).abs() < GPU_TOLERANCE, "view {i}: gpu {} vs reference {want}", gpu_answers[i].fraction);
        assert_eq!(auto_cpu[i].fraction, exact_answers[i].fraction, "view {i}: auto on the CPU is the exact engine");
        // Routed to the GPU, a view gets the GPU's pixels; the schedule agrees within their tolerance.
        assert!((auto_gpu[i].fraction - want).abs() < GPU_TOLERANCE, "view {i}: auto (GPU-favouring) {} vs {want}", auto_gpu[i].fraction);
        assert_eq!(auto_gpu[i].side.is_some(), gpu_answers[i].side.is_some(), "view {i}: the loaded views go to the GPU");
        partly += usize::from(*want > 0.02 && *want < 0.98);
    }
    assert!(partly >= 10, "only {partly} views partly shaded");
}

/// A profile whose compute rasterizer is the cheapest engine routes the loaded views to it, and
/// they get its counts: the same as `--engine compute` gives them, within the tolerance of the
/// exact reference.
#[test]
fn auto_routes_to_the_compute_kernel_where_it_is_cheapest() {
    let dir = scratch("compute");
    let scene = louvred_walls();
    let profile = Profile {
        device: "test".into(),
        exact: Cost { per_view_us: 1e6, per_triangle_us: 0.0 },
        gpu: Some(Cost { per_view_us: 1e5, per_triangle_us: 0.0 }),
        gpu_startup_seconds: Some(0.0),
        compute: Some(Cost { per_view_us: 1.0, per_triangle_us: 0.0 }),
        compute_startup_seconds: Some(0.0),
    };
    let path = dir.join("compute.json");
    write_profile(&path, &profile).unwrap();
    let auto = HybridEngine::new(&scene, EngineKind::Auto, options(), Some(1), ProfileSource::File(path)).unwrap();
    let routed = pollster::block_on(auto.count(&requests(&scene))).unwrap();
    let stats = auto.stats();
    assert!(stats.compute_views > 0 && stats.gpu_views == 0, "{stats:?}");
    let alone = HybridEngine::new(&scene, EngineKind::Compute, options(), Some(1), ProfileSource::Probe).unwrap();
    let by_compute = pollster::block_on(alone.count(&requests(&scene))).unwrap();
    let reference = exact::sunlit_fractions(&scene, &requests(&scene));
    for (i, want) in reference.iter().enumerate() {
        if routed[i].side.is_some() {
            assert_eq!(routed[i], by_compute[i], "view {i}: routed to the compute kernel, its answer");
        }
        assert!((by_compute[i].fraction - want).abs() < GPU_TOLERANCE, "view {i}: compute {} vs {want}", by_compute[i].fraction);
    }
}

/// Sky views are priced on views of their own kind: a pinned profile that sends every loaded sun
/// view to the GPU does not route the sky pass, which measures its own profile (on this small
/// scene the exact engine alone, no GPU worth its start-up) and pins it beside the sun's; the sun
/// views after it are routed by the sun's profile again.
#[test]
fn sky_views_are_routed_by_a_profile_of_their_own() {
    let dir = scratch("sky");
    let scene = louvred_walls();
    let ProfileSource::File(sun_file) = pinned(&dir, true) else { unreachable!() };
    let sky_file = sunlit::count::hybrid::profile_file(&sun_file, sunlit::count::ViewKind::Sky);
    assert_eq!(sky_file, sun_file.with_file_name("gpu.sky.json"));
    let _ = std::fs::remove_file(&sky_file);
    let sun_before = std::fs::read(&sun_file).unwrap();
    let engine = HybridEngine::new(&scene, EngineKind::Auto, options(), Some(1), ProfileSource::File(sun_file.clone())).unwrap();
    let patches = sunlit::sky::patches::SkyPatches::tregenza();
    let sky = pollster::block_on(sunlit::sky::views::sky_views(&engine, &scene, &patches, &mut |_| Ok(()))).unwrap();
    assert_eq!(engine.stats().gpu_views, 0, "the sky pass followed the sun's GPU-favouring profile");
    let exact_engine = HybridEngine::new(&scene, EngineKind::Exact, options(), Some(1), ProfileSource::Probe).unwrap();
    let exact_sky = pollster::block_on(sunlit::sky::views::sky_views(&exact_engine, &scene, &patches, &mut |_| Ok(()))).unwrap();
    assert_eq!(sky, exact_sky, "routed to the exact engine, the sky views are the exact engine's");
    let pinned_sky: Profile = serde_json::from_str(&std::fs::read_to_string(&sky_file).expect("the sky profile is pinned")).unwrap();
    assert!(pinned_sky.device.ends_with("; sky views") && pinned_sky.gpu.is_none(), "{pinned_sky:?}");
    assert_eq!(std::fs::read(&sun_file).unwrap(), sun_before, "the sun's pinned profile is left as it was");
    pollster::block_on(engine.count(&requests(&scene))).unwrap();
    assert!(engine.stats().gpu_views > 0, "sun views after the sky pass are routed by the sun's profile");
}

fn sunlit(args: &[&str], cache: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).env("XDG_CACHE_HOME", cache).output().expect("run sunlit")
}

#[test]
fn the_same_profile_gives_the_same_csv_byte_for_byte() {
    let dir = scratch("csv");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/office.glb");
    let profile = dir.join("profile.json");
    let mut csvs = Vec::new();
    for run in 0..2 {
        let csv = dir.join(format!("run{run}.csv"));
        let args = [
            "annual",
            glb,
            "--location",
            "40,-105,-7",
            "--days-per-year",
            "6",
            "--samples-per-day",
            "7",
            "--resolution",
            "128",
            "--engine-profile",
            profile.to_str().unwrap(),
            "-o",
            csv.to_str().unwrap(),
        ];
        let out = sunlit(&args, &dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        csvs.push(std::fs::read(&csv).unwrap());
    }
    assert!(profile.exists(), "the first run measured and pinned the profile");
    assert!(csvs[0] == csvs[1], "two runs with one profile differ");
}

/// A model no GPU is worth its start-up for gets a profile kept without an adapter (finding it
/// again asks for none), and the run that finds it writes the same CSV.
#[test]
fn an_exact_only_profile_is_cached_without_the_adapter() {
    let dir = scratch("cached");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/office.glb");
    let mut csvs = Vec::new();
    for run in 0..2 {
        let csv = dir.join(format!("cached{run}.csv"));
        let args =
            ["annual", glb, "--location", "40,-105,-7", "--days-per-year", "6", "--samples-per-day", "7", "-o", csv.to_str().unwrap()];
        let out = sunlit(&args, &dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        csvs.push(std::fs::read(&csv).unwrap());
    }
    let cache = std::fs::read_to_string(dir.join("sunlit/engine-profiles.json")).expect("the first run cached its profile");
    let keys: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&cache).unwrap();
    assert_eq!(keys.len(), 1, "one profile, found again by the second run: {cache}");
    let (key, profile) = keys.iter().next().unwrap();
    assert!(key.starts_with("exact only; ") && profile["gpu"].is_null(), "{cache}");
    assert!(csvs[0] == csvs[1], "the probing run and the cached run differ");
}

#[test]
fn the_gpu_engine_answers_alone() {
    let dir = scratch("alone");
    let glb = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/office.glb");
    let run = |engine: &str| {
        let out = sunlit(&["fraction", glb, "--sun", "200,35", "--resolution", "256", "--engine", engine, "--json"], &dir);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (gpu, exact) = (run("gpu"), run("exact"));
    assert_eq!(gpu["method"], "gpu");
    let surfaces = |v: &serde_json::Value| v["surfaces"].as_array().unwrap().clone();
    let mut rendered = 0;
    for (g, e) in surfaces(&gpu).iter().zip(surfaces(&exact)) {
        assert_eq!(e["side"], 0, "the exact engine counts no pixels");
        rendered += usize::from(g["side"] == 256);
        let (g, e) = (g["fraction"].as_f64().unwrap(), e["fraction"].as_f64().unwrap());
        assert!((g - e).abs() < GPU_TOLERANCE, "gpu {g} vs exact {e}");
    }
    assert!(rendered > 0, "the GPU rendered no view");
    let bad = sunlit(&["fraction", glb, "--sun", "200,35", "--engine", "pixels"], &dir);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--engine"), "{}", String::from_utf8_lossy(&bad.stderr));
}
