//! The year's sampling and fit, tested on small scenes and on its helpers alone.

use super::*;
use crate::scene::{SceneBuilder, SourceMesh};

/// Five receivers facing south, east, north-west, up and a tilted north-east.
fn facets() -> Scene {
    let mut b = SceneBuilder::new();
    let quads: [[[f32; 3]; 4]; 5] = [
        [[0., 0., 0.], [1., 0., 0.], [1., 0., 1.], [0., 0., 1.]],
        [[1., 0., 0.], [1., 1., 0.], [1., 1., 1.], [1., 0., 1.]],
        [[1., 1., 0.], [0., 2., 0.], [0., 2., 1.], [1., 1., 1.]],
        [[0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]],
        [[2., 2., 0.], [3., 1., 0.], [2.5, 0.5, 1.], [1.5, 1.5, 1.]],
    ];
    for (k, q) in quads.iter().enumerate() {
        b.add_object("test", &format!("R{k}"), SourceMesh { positions: q.to_vec(), indices: vec![0, 1, 2, 0, 2, 3] }, true);
    }
    b.build().unwrap()
}

/// Every sample cell gets a view whose sun is the one its own day and time would give, and
/// twin days share views except where their pieces differ (polar day, New Year).
#[test]
fn twin_days_share_views_with_the_same_sun() {
    let scene = facets();
    let plan = SamplingPlan::new(27, 7).unwrap();
    let taus = plan.taus();
    for (latitude, at_least) in [(40.0, 0.45), (-33.9, 0.45), (75.0, 0.2)] {
        let location = Location::new(latitude, 10.0, 1.0).unwrap();
        let regimes = vec![Regime::year(plan, &taus, 1.0).unwrap()];
        let views = sample_views(&scene, 0..scene.receivers.len(), &location, &regimes, &taus);
        let per_piece = plan.days * taus.len();
        for &(request, _, cell) in &views.cells {
            let (id, rest) = (cell / (MAX_PIECES * per_piece), cell % (MAX_PIECES * per_piece));
            let (p, d, j) = (rest / per_piece, (rest % per_piece) / taus.len(), rest % taus.len());
            let day = sun_day(regimes[0].days[d]);
            let (start, end) = lit_intervals(&location, scene.receivers[id].normal, day, MIN_COS_INCIDENCE)[p];
            let own = sun_direction(&location, day, start + taus[j] * (end - start));
            let used = views.requests[request];
            assert_eq!(used.receiver as usize, id);
            assert!(own.distance(used.sun) < 1e-7, "{latitude}: receiver {id} day {day} τ {}: {own} vs {}", taus[j], used.sun);
        }
        let saved = 1.0 - views.requests.len() as f64 / views.cells.len() as f64;
        assert!(saved >= at_least && saved < 0.5, "{latitude}: shared {saved:.3} of the views");
    }
}

#[test]
fn dark_samples_take_the_nearest_lit_value() {
    let s = [None, Some(0.2), None, Some(0.8), None, None, None, None];
    let filled = fill_dark(&s, 2, 4).unwrap();
    assert_eq!(filled, vec![0.2, 0.2, 0.2, 0.8, 0.2, 0.2, 0.2, 0.8]);
    assert_eq!(fill_dark(&[None, None, None], 1, 3), None);
}

/// A year counted a batch of receivers at a time ([`annual_receivers_with`]) is the whole year's
/// ([`annual_with`]), column for column and bit for bit, on a generated district with stair
/// housings and chimneys (self-shading, steps refined and certified, interpolated ones proved
/// never dark): uneven batches, the last shorter, and one batch of all.
#[test]
fn a_year_by_batches_of_receivers_is_the_whole_year() {
    use crate::count::gpu::CounterOptions;
    use crate::count::hybrid::{EngineKind, HybridEngine, ProfileSource};

    let text = crate::model::city_write::district_cityjson_with(2, 1, 3, true);
    let city = crate::model::cityjson::read_city("district.city.json", text.as_bytes(), None).unwrap();
    let scene = crate::model::load_city(&city, &crate::model::LoadOptions::default()).unwrap().scene;
    let engine = HybridEngine::new(&scene, EngineKind::Exact, CounterOptions::default(), None, ProfileSource::Cache).unwrap();
    let location = Location::new(39.74, -105.18, -7.0).unwrap();
    let options = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method: Method::Spline(SamplingPlan::new(13, 9).unwrap()),
        refine: DEFAULT_REFINE,
        prove_never_dark: true,
        // On: the batches share the index's composite casters.
        many_casters: Some(true),
        inner_corners: false,
    };
    let calendar = LeafCalendar::evergreen();
    let year = |receivers: Range<usize>| {
        pollster::block_on(annual_receivers_with(&engine, &scene, receivers, &location, &options, &calendar, &mut |_| Ok(()))).unwrap()
    };
    let whole = pollster::block_on(annual_with(&engine, &scene, &location, &options, &calendar, &mut |_| Ok(()))).unwrap();
    let n = scene.receivers.len();
    assert!(n > 10, "{n} receivers");
    for batch in [7, n] {
        let mut stages = YearStages::default();
        for first in (0..n).step_by(batch) {
            let (part, s) = year(first..(first + batch).min(n));
            stages.add(&s);
            assert_eq!(part.names, whole.names[first..(first + batch).min(n)]);
            for row in 0..whole.timesteps.rows() {
                for (c, name) in part.names.iter().enumerate() {
                    let (a, b) = (part.get(row, c), whole.get(row, first + c));
                    assert_eq!(a.to_bits(), b.to_bits(), "batches of {batch}: {name} at row {row}: {a} against {b}");
                }
            }
        }
        // The batches went through every stage: samples, refined steps counted.
        assert!(stages.sample_views > 0 && stages.refined_views > 0, "batches of {batch}: {stages:?}");
    }
    // A range past the scene is refused, naming the parameter.
    let past = pollster::block_on(annual_receivers_with(&engine, &scene, n - 1..n + 1, &location, &options, &calendar, &mut |_| Ok(())));
    assert!(past.is_err_and(|e| e.to_string().contains("receivers")));
}
