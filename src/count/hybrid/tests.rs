//! The hybrid engine's routing and cost-model tests (no device needed).

use super::*;

fn load(triangles: usize) -> ViewLoad {
    ViewLoad { triangles, see_through: 0 }
}

#[test]
fn coarse_to_fine_visits_each_once_ends_first_then_halves() {
    let items: Vec<usize> = (0..10).collect();
    let order = coarse_to_fine(&items);
    assert_eq!(&order[..4], &[0, 9, 8, 4], "ends, then the middle of 16 positions (8), then a quarter (4)");
    let mut sorted = order.clone();
    sorted.sort();
    assert_eq!(sorted, items, "each item once");
    assert_eq!(coarse_to_fine(&[7, 8]), vec![7, 8]);
    assert!(coarse_to_fine::<u8>(&[]).is_empty());
    // After the ends, every prefix of a power-of-two length's order halves the largest gap.
    let order = coarse_to_fine(&(0..17).collect::<Vec<usize>>());
    assert_eq!(&order[..5], &[0, 16, 8, 4, 12]);
}

#[test]
fn routing_follows_the_cheaper_modelled_cost() {
    let profile = Profile {
        device: "test".into(),
        exact: Cost { per_view_us: 10.0, per_triangle_us: 1.0 },
        gpu: Some(Cost { per_view_us: 500.0, per_triangle_us: 0.1 }),
        gpu_startup_seconds: Some(0.0),
        compute: None,
        compute_startup_seconds: None,
    };
    // Break-even at 10 + n = 500 + 0.1 n, n ≈ 544.
    let loads = [load(0), load(100), load(544), load(545), load(5_000), ViewLoad { triangles: 3, see_through: 1 }];
    let routes = profile.route(&loads, 0);
    assert_eq!(routes, vec![Route::Exact, Route::Exact, Route::Exact, Route::Gpu, Route::Gpu, Route::Gpu]);
    // A GPU start-up the saving does not pay: all exact, but see-through views need the GPU.
    let slow_start = Profile { gpu_startup_seconds: Some(10.0), ..profile.clone() };
    assert_eq!(slow_start.route(&loads[..5], 0), vec![Route::Exact; 5]);
    assert_eq!(slow_start.route(&loads, 0)[5], Route::Gpu);
    // The same batch in a run long enough that its saving, run-wide, pays the start-up:
    // 4,010.5 µs saved a batch (4,010 on the heaviest view, 0.5 at 545), × 20,000/5 ≥ 10 s.
    assert_eq!(slow_start.route(&loads[..5], 20_000), vec![Route::Exact, Route::Exact, Route::Exact, Route::Gpu, Route::Gpu]);
    assert_eq!(slow_start.route(&loads[..5], 10_000), vec![Route::Exact; 5], "4,010.5 µs × 2,000 < 10 s");
    // No GPU measured: all exact.
    let exact_only = Profile { gpu: None, ..profile };
    assert!(exact_only.route(&loads[..5], 1_000_000).iter().all(|r| *r == Route::Exact));
}

#[test]
fn a_line_fits_its_samples() {
    let c = fit_line(&[(0.0, 5.0), (10.0, 25.0), (20.0, 45.0)]);
    assert!((c.per_view_us - 5.0).abs() < 1e-9 && (c.per_triangle_us - 2.0).abs() < 1e-9, "{c:?}");
    let through_origin = fit_line(&[(10.0, 10.0), (20.0, 30.0)]);
    assert_eq!(through_origin.per_view_us, 0.0);
    assert!(through_origin.per_triangle_us > 0.0);
}

#[test]
fn engine_names_parse() {
    for kind in [EngineKind::Auto, EngineKind::Gpu, EngineKind::Exact, EngineKind::Compute] {
        assert_eq!(EngineKind::parse(kind.name()).unwrap(), kind);
    }
    assert!(EngineKind::parse("pixels").unwrap_err().to_string().contains("auto, gpu, exact, compute"));
}

#[test]
fn routing_picks_the_cheapest_of_three_engines() {
    let profile = Profile {
        device: "test".into(),
        exact: Cost { per_view_us: 10.0, per_triangle_us: 1.0 },
        gpu: Some(Cost { per_view_us: 500.0, per_triangle_us: 0.1 }),
        gpu_startup_seconds: Some(0.0),
        compute: Some(Cost { per_view_us: 100.0, per_triangle_us: 0.5 }),
        compute_startup_seconds: Some(0.0),
    };
    // exact < compute below 180 triangles (10 + n = 100 + 0.5 n); compute < gpu below 1,000
    // (100 + 0.5 n = 500 + 0.1 n); gpu above.
    let loads = [load(100), load(179), load(181), load(999), load(1_001), ViewLoad { triangles: 50, see_through: 2 }];
    let want = [Route::Exact, Route::Exact, Route::Compute, Route::Compute, Route::Gpu, Route::Compute];
    assert_eq!(profile.route(&loads, 0), want, "see-through: the cheaper GPU kernel");
    // A compute start-up its saving does not pay: its views go where they would without it
    // (999 triangles: the raster kernel, 599.9 µs against 1,009 clipped; the see-through view
    // still needs a GPU kernel: the raster one).
    let slow_compute = Profile { compute_startup_seconds: Some(10.0), ..profile.clone() };
    let want = [Route::Exact, Route::Exact, Route::Exact, Route::Gpu, Route::Gpu, Route::Gpu];
    assert_eq!(slow_compute.route(&loads, 0), want);
    // A profile kept before the compute kernel existed reads without it and routes as before.
    let old = r#"{"device":"d","exact":{"per_view_us":10.0,"per_triangle_us":1.0},"gpu":null,"gpu_startup_seconds":null}"#;
    let read: Profile = serde_json::from_str(old).unwrap();
    assert_eq!(read.compute, None);
    assert!(read.route(&loads[..5], 1_000_000).iter().all(|r| *r == Route::Exact));
}

#[test]
fn a_profile_reads_back_to_the_same_text() {
    // A cached profile must be the profile that was measured, to the last digit: the page compares
    // them, and a route decided by a cost one ulp off is a different route at a tie. serde_json's
    // fast float parser is one ulp off on this value (the CI run of 5249a2f); `float_roundtrip` is not.
    let text = r#"{"device":"d","exact":{"per_view_us":111.11100514729817,"per_triangle_us":0.0},"gpu":null,"gpu_startup_seconds":null,"compute":null,"compute_startup_seconds":null}"#;
    let read: Profile = serde_json::from_str(text).unwrap();
    assert_eq!(serde_json::to_string(&read).unwrap(), text);
}
