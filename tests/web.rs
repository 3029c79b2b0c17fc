//! The counting pass on the browser's WebGPU: in headless Chromium (WebGPU on SwiftShader) through
//! wasm-bindgen-test, against the exact CPU polygon-clipping reference and an analytic case, both
//! through the library and through the bindings the page uses (`sunlit::web`).
//! Run by scripts/test.sh: `cargo test --target wasm32-unknown-unknown --test web`.

#![cfg(target_arch = "wasm32")]
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use glam::DVec3;
use sunlit::count::gpu::{Counter, CounterOptions};
use sunlit::count::{ViewRequest, exact};
use sunlit::model::arrays::{Arrays, scene_from_arrays};
use sunlit::scene::Scene;
use sunlit::web::Engine;
use wasm_bindgen::JsValue;
use wasm_bindgen_futures::JsFuture;
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

/// Overhang depth, window height (m).
const DEPTH: f64 = 0.5;
const HEIGHT: f64 = 1.5;

/// A south window (x 0..2, z 0..1.5, facing −y) under a wide overhang of depth 0.5 at its top
/// edge, a fin on its east side, and an L-shaped (concave) terrace beside it.
fn arrays() -> (Vec<f32>, Vec<u32>, Vec<i32>, Vec<String>) {
    let h = HEIGHT as f32;
    let d = DEPTH as f32;
    #[rustfmt::skip]
    let positions = vec![
        // window 0..4
        0.0, 0.0, 0.0,  2.0, 0.0, 0.0,  2.0, 0.0, h,  0.0, 0.0, h,
        // overhang 4..8
        -5.0, -d, h,  7.0, -d, h,  7.0, 0.0, h,  -5.0, 0.0, h,
        // fin 8..12 (x = 2.3, from the wall 0.6 out, full height)
        2.3, 0.0, 0.0,  2.3, -0.6, 0.0,  2.3, -0.6, 2.0,  2.3, 0.0, 2.0,
        // L terrace on the ground east of the fin, z = 0.01 (facing up) 12..18
        3.0, -3.0, 0.01,  6.0, -3.0, 0.01,  6.0, -2.0, 0.01,  4.0, -2.0, 0.01,  4.0, 0.0, 0.01,  3.0, 0.0, 0.01,
    ];
    #[rustfmt::skip]
    let indices = vec![
        0, 1, 2, 0, 2, 3,
        4, 5, 6, 4, 6, 7,
        8, 9, 10, 8, 10, 11,
        12, 13, 14, 12, 14, 15, 12, 15, 16, 12, 16, 17,
    ];
    let receivers = vec![0, 0, -1, -1, -1, -1, 1, 1, 1, 1];
    (positions, indices, receivers, vec!["window".into(), "terrace".into()])
}

fn scene() -> Scene {
    let (positions, indices, triangle_receivers, names) = arrays();
    scene_from_arrays(&Arrays {
        positions: &positions,
        indices: &indices,
        triangle_receivers: &triangle_receivers,
        names: &names,
        y_up: false,
    })
    .unwrap()
}

fn sun(azimuth: f64, altitude: f64) -> DVec3 {
    let (a, h) = (azimuth.to_radians(), altitude.to_radians());
    DVec3::new(a.sin() * h.cos(), a.cos() * h.cos(), h.sin())
}

#[wasm_bindgen_test]
async fn webgpu_counts_match_the_exact_reference() {
    let scene = scene();
    let counter = Counter::new(CounterOptions { resolution: 512, ..Default::default() }).await.unwrap();
    let gpu = counter.upload(&scene).unwrap();
    let mut requests = Vec::new();
    for azimuth in (100..=260).step_by(20) {
        for altitude in (10..=70).step_by(15) {
            for receiver in 0..scene.receivers.len() as u32 {
                requests.push(ViewRequest::new(receiver, sun(f64::from(azimuth), f64::from(altitude))));
            }
        }
    }
    let counted = counter.fractions(&gpu, &requests).await.unwrap();
    let reference = exact::sunlit_fractions(&scene, &requests);
    let mut partial = 0;
    for ((r, c), e) in requests.iter().zip(&counted).zip(&reference) {
        assert!((c.fraction - e).abs() < 0.005, "{r:?}: WebGPU {:.4} vs exact {e:.4}", c.fraction);
        partial += usize::from(*e > 0.05 && *e < 0.95);
    }
    assert!(partial >= 20, "the cases must exercise partial shading ({partial} did)");
}

#[wasm_bindgen_test]
async fn adaptive_webgpu_counts_meet_their_accuracy() {
    // The edge count and the recounts at finer sides on another rasteriser (SwiftShader): every
    // view within the target of the exact reference, at more than one side.
    let scene = scene();
    let target = 0.002;
    let counter = Counter::new(CounterOptions { resolution: 512, accuracy: Some(target), ..Default::default() }).await.unwrap();
    let gpu = counter.upload(&scene).unwrap();
    let requests: Vec<ViewRequest> = (100..=260)
        .step_by(40)
        .flat_map(|azimuth| (10..=70).step_by(20).map(move |altitude| ViewRequest::new(0, sun(f64::from(azimuth), f64::from(altitude)))))
        .collect();
    let counted = counter.fractions(&gpu, &requests).await.unwrap();
    let reference = exact::sunlit_fractions(&scene, &requests);
    let mut sides = std::collections::BTreeSet::new();
    for ((r, c), e) in requests.iter().zip(&counted).zip(&reference) {
        assert!((c.fraction - e).abs() <= target, "{r:?}: WebGPU {:.4} vs exact {e:.4} at {}²", c.fraction, c.side);
        if c.side > 0 {
            sides.insert(c.side);
        }
    }
    assert!(sides.len() >= 2, "one side for every view: {sides:?}");
}

#[wasm_bindgen_test]
async fn the_page_bindings_give_the_analytic_overhang_shadow() {
    let engine = Engine::create(Some(512), None, Some("gpu".into()), None).await.map_err(|e| format!("{e:?}")).unwrap();
    let (positions, indices, receivers, names) = arrays();
    let model = engine.from_arrays(&positions, &indices, &receivers, names, false).map_err(|e| format!("{e:?}")).unwrap();
    for altitude in [20.0f64, 35.0, 50.0] {
        // Due south: the overhang's edge throws a horizontal line d·tan h below the window's top.
        let s = sun(180.0, altitude);
        let promise = engine.fractions(&model, s.x, s.y, s.z, JsValue::UNDEFINED);
        let fractions = js_sys::Float64Array::new(&JsFuture::from(promise).await.unwrap()).to_vec();
        let analytic = (1.0 - DEPTH * altitude.to_radians().tan() / HEIGHT).clamp(0.0, 1.0);
        assert!((fractions[0] - analytic).abs() < 0.005, "altitude {altitude}: {:.4} vs analytic {analytic:.4}", fractions[0]);
    }
}

/// `createEngine({ engine })`: the exact engine (one thread in the wasm), the GPU and `auto`
/// give the same fractions (the GPU within its pixels' tolerance), the exact one the reference's;
/// another name is refused naming the option.
#[wasm_bindgen_test]
async fn the_engine_option_picks_exact_gpu_or_auto_and_they_agree() {
    let (positions, indices, receivers, names) = arrays();
    let scene = scene();
    let suns = [sun(180.0, 35.0), sun(120.0, 20.0), sun(240.0, 50.0)];
    let mut answers = Vec::new();
    for kind in ["exact", "gpu", "auto"] {
        let engine = Engine::create(Some(512), None, Some(kind.into()), None).await.map_err(|e| format!("{e:?}")).unwrap();
        assert_eq!(engine.engine(), kind);
        let model = engine.from_arrays(&positions, &indices, &receivers, names.clone(), false).map_err(|e| format!("{e:?}")).unwrap();
        let mut fractions = Vec::new();
        for s in suns {
            let promise = engine.fractions(&model, s.x, s.y, s.z, JsValue::UNDEFINED);
            fractions.extend(js_sys::Float64Array::new(&JsFuture::from(promise).await.unwrap()).to_vec());
        }
        answers.push(fractions);
    }
    let requests: Vec<ViewRequest> = suns.iter().flat_map(|&s| (0..2).map(move |r| ViewRequest::new(r, s))).collect();
    let reference = exact::sunlit_fractions(&scene, &requests);
    for (i, r) in reference.iter().enumerate() {
        assert!((answers[0][i] - r).abs() < 1e-6, "exact {i}: {} vs reference {r}", answers[0][i]);
        assert!((answers[1][i] - r).abs() < 0.005, "gpu {i}: {} vs reference {r}", answers[1][i]);
        // The light views of this small scene are all clipped under `auto`'s rule.
        assert!((answers[2][i] - r).abs() < 1e-6, "auto {i}: {} vs reference {r}", answers[2][i]);
    }
    let error = match Engine::create(Some(512), None, Some("fastest".into()), None).await {
        Ok(_) => panic!("an unknown engine was accepted"),
        Err(e) => e,
    };
    let get = |key: &str| js_sys::Reflect::get(&error, &key.into()).unwrap().as_string();
    assert_eq!(get("code").as_deref(), Some("bad-option"));
    assert_eq!(get("option").as_deref(), Some("engine"));
    assert!(get("message").unwrap().contains("fastest"), "{:?}", get("message"));
}

#[wasm_bindgen_test]
fn bad_arrays_are_refused_with_the_element_named() {
    let (positions, mut indices, receivers, names) = arrays();
    indices[4] = 99;
    let error =
        scene_from_arrays(&Arrays { positions: &positions, indices: &indices, triangle_receivers: &receivers, names: &names, y_up: false })
            .unwrap_err()
            .to_string();
    assert_eq!(error, "arrays: indices[4]: 99 is past the 18 vertices");
}

#[wasm_bindgen_test]
async fn a_lost_webgpu_device_is_reported_and_a_new_one_counts() {
    let scene = scene();
    let counter = Counter::new(CounterOptions { resolution: 128, ..Default::default() }).await.unwrap();
    let gpu = counter.upload(&scene).unwrap();
    let request = [ViewRequest::new(0, sun(180.0, 35.0))];
    let before = counter.fractions(&gpu, &request).await.unwrap()[0].fraction;
    counter.device_loss_trigger()();
    let error = counter.fractions(&gpu, &request).await.map(|c| c[0].fraction);
    let message = format!("{error:?}");
    assert!(matches!(error, Err(sunlit::Error::DeviceLost(_))), "a lost device is reported as such: {message}");
    let fresh = counter.recreate().await.unwrap();
    let gpu = fresh.upload(&scene).unwrap();
    let after = fresh.fractions(&gpu, &request).await.unwrap()[0].fraction;
    assert_eq!(before, after, "the new device counts the same");
}

/// The glTF decoders are pure Rust, so the wasm build reads what glTF Transform writes: the
/// office quantized, meshopt- and Draco-compressed (the fuzz seeds, made by
/// `gltf-transform quantize|meshopt|draco examples/office.glb`) gives the original's exact
/// fractions within 0.002 here too (tests/gltf_variants.rs checks the same natively).
#[wasm_bindgen_test]
fn compressed_gltf_reads_in_wasm() {
    use sunlit::model::{LoadOptions, load_bytes};
    let load = |name: &str, bytes: &[u8]| load_bytes(&[(name.to_string(), bytes.to_vec())], &LoadOptions::default()).unwrap();
    let original = load("office.glb", include_bytes!("../examples/office.glb"));
    let requests: Vec<ViewRequest> = [(200.0, 35.0), (120.0, 20.0), (250.0, 50.0)]
        .iter()
        .flat_map(|&(a, h)| (0..original.receivers.len() as u32).map(move |receiver| ViewRequest::new(receiver, sun(a, h))))
        .collect();
    let reference = exact::sunlit_fractions(&original, &requests);
    for (name, bytes) in [
        ("office-quantized.glb", &include_bytes!("../fuzz/seeds/gltf/office-quantized.glb")[..]),
        ("office-meshopt.glb", &include_bytes!("../fuzz/seeds/gltf/office-meshopt.glb")[..]),
        ("office-draco.glb", &include_bytes!("../fuzz/seeds/gltf/office-draco.glb")[..]),
    ] {
        let scene = load(name, bytes);
        let names = |s: &Scene| s.receivers.iter().map(|r| r.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(&scene), names(&original), "{name}");
        for ((r, f), e) in requests.iter().zip(exact::sunlit_fractions(&scene, &requests)).zip(&reference) {
            assert!((f - e).abs() <= 0.002, "{name} {r:?}: {f:.4} against the original's {e:.4}");
        }
    }
}
