//! The annual schedule: the 27×19 spline against counting every sun-up timestep (`--dense`), and
//! the CSV and CLI around it. GPU tests: lavapipe in CI, never skipped.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;

use std::process::Command;

use glam::DVec3;

use common::*;
use sunlit::count::lanes::Lane;
use sunlit::export::Schedule;
use sunlit::model::{LoadOptions, load_bytes, office::office};
use sunlit::scene::Scene;
use sunlit::sun::location::Location;
use sunlit::sun::position::sun_direction;
use sunlit::year::annual::{AnnualOptions, DEFAULT_REFINE, Method, annual, annual_on, compare};
use sunlit::year::samples::{SamplingPlan, Timesteps};

fn golden() -> Location {
    Location::new(39.74, -105.18, -7.0).unwrap()
}

fn year(scene: &Scene, method: Method, refine: f64, resolution: u32) -> Schedule {
    let counter = counter(resolution);
    let gpu = counter.upload(scene).unwrap();
    let options = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method,
        refine,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    };
    pollster::block_on(annual(&counter, &gpu, scene, &golden(), &options, &mut |_| Ok(()))).unwrap()
}

/// Two counters side by side (the CLI's default on lavapipe) count the same year as one, to
/// pixel noise: a view lands in a different atlas tile, whose offset rounds its edges
/// differently. A share coming back out of order would differ by whole fractions.
#[test]
fn two_lanes_count_the_same_year_as_one() {
    let scene = load_bytes(&[("office.glb".into(), office(6).to_glb())], &LoadOptions::default()).unwrap();
    let one = year(&scene, Method::Spline(SamplingPlan::new(9, 7).unwrap()), DEFAULT_REFINE, 64);
    let counters = [counter(64), counter(64)];
    let gpus: Vec<_> = counters.iter().map(|c| c.upload(&scene).unwrap()).collect();
    let lanes: Vec<Lane> = counters.iter().zip(&gpus).map(|(counter, gpu)| Lane { counter, gpu }).collect();
    let options = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method: Method::Spline(SamplingPlan::new(9, 7).unwrap()),
        refine: DEFAULT_REFINE,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    };
    let calendar = sunlit::year::season::LeafCalendar::evergreen();
    let mut reports = 0;
    let two = pollster::block_on(annual_on(&lanes, &scene, &golden(), &options, &calendar, &mut |_| {
        reports += 1;
        Ok(())
    }))
    .unwrap();
    assert!(reports >= 2);
    assert!(one.values.iter().any(|v| *v > 0.0 && *v < 1.0), "the office has partial shade");
    let (mean, _, max) = compare(&one, &two).unwrap();
    println!("two lanes vs one: mean |Δ| {mean:.6}, max {max:.6}");
    assert!(mean < 1e-3 && max < 0.05, "mean {mean}, max {max}");
}

/// A progress callback that returns an error stops the run with that error, after the reports
/// so far: how the page's Cancel button and an `AbortSignal` stop a year.
#[test]
fn a_failing_progress_callback_cancels_the_year() {
    let scene = load_bytes(&[("office.glb".into(), office(6).to_glb())], &LoadOptions::default()).unwrap();
    let counter = counter(128);
    let gpu = counter.upload(&scene).unwrap();
    let options = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method: Method::Dense,
        refine: 1.0,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    };
    let mut reports = Vec::new();
    let result = pollster::block_on(annual(&counter, &gpu, &scene, &golden(), &options, &mut |p| {
        reports.push(p);
        if p.done > 0 { Err(sunlit::Error::Cancelled) } else { Ok(()) }
    }));
    assert!(matches!(result, Err(sunlit::Error::Cancelled)), "{result:?}");
    assert_eq!(reports.len(), 2, "stops at the first report after the start: {reports:?}");
    assert!(reports[1].done < reports[1].total, "cancelled before the end: {reports:?}");
}

/// Spline vs dense over lit timesteps; night rows exactly 0 in both. Returns the pure
/// spline's RMS (no refinement) for the caller to judge.
fn spline_matches_dense(scene: &Scene, label: &str) -> f64 {
    let dense = year(scene, Method::Dense, 1.0, 256);
    let pure = year(scene, Method::Spline(SamplingPlan::default()), 1.0, 256);
    let spline = year(scene, Method::Spline(SamplingPlan::default()), DEFAULT_REFINE, 256);
    let (_, pure_rms, pure_max) = compare(&pure, &dense).unwrap();
    let (mean, rms, max) = compare(&spline, &dense).unwrap();
    println!(
        "{label}: 27×19 spline vs dense over lit hours: RMS {pure_rms:.4}, max {pure_max:.4}; refined at {DEFAULT_REFINE}: mean |Δ| {mean:.4}, RMS {rms:.4}, max {max:.4}"
    );
    assert!(rms <= 0.01, "{label}: RMS {rms}");
    let ts = spline.timesteps;
    let mut night = 0;
    for row in 0..ts.rows() {
        let i = ts.instant(row);
        // Night by the sun EnergyPlus's shading uses on that day (the calendar day's, see
        // `shading_sun_day`), which the schedule follows.
        if sun_direction(&golden(), sunlit::year::annual::shading_sun_day(i.day), i.hour).z < 0.0 {
            night += 1;
            for c in 0..spline.names.len() {
                assert_eq!(spline.get(row, c), 0.0, "{label}: night row {row} must be exactly 0");
                assert_eq!(dense.get(row, c), 0.0);
            }
        }
    }
    assert!(night > 3000, "a year has many night hours: {night}");
    pure_rms
}

#[test]
fn overhang_window_spline_vs_dense() {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.0, 1.0, 2.0, 0.0), true);
    s.polygon("OVERHANG", &flat_rect(-1.0, 3.0, -0.6, 0.0, 2.2), false);
    // An overhang's shadow moves smoothly: the spline alone is within the bound.
    let pure = spline_matches_dense(&s.build(), "overhang");
    assert!(pure <= 0.01, "pure spline RMS {pure}");
}

#[test]
fn example_office_spline_vs_dense() {
    let options = LoadOptions { receivers: vec!["WIN_S1".into(), "WALL_S".into(), "WIN_E".into(), "ROOF".into()], ..Default::default() };
    let scene = load_bytes(&[("office.glb".into(), office(6).to_glb())], &options).unwrap();
    // The neighbour's shadow sweeps the roof and the east window at sunrise faster than 27×19
    // samples follow; refinement (asserted inside) is what brings the office under 0.01.
    spline_matches_dense(&scene, "office");
}

fn sunlit(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args).output().unwrap()
}

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("annual", name)
}

#[test]
fn cli_writes_the_energyplus_csv() {
    let dir = scratch("csv");
    let model = dir.join("office.glb");
    std::fs::write(&model, office(2).to_glb()).unwrap();
    let epw = dir.join("golden.epw");
    std::fs::write(&epw, "LOCATION,Golden,CO,USA,TMY3,724666,39.74,-105.18,-7.0,1829.0\nDESIGN CONDITIONS,0\n").unwrap();
    let csv = dir.join("shading.csv");
    let out = sunlit(&[
        "annual",
        model.to_str().unwrap(),
        "--epw",
        epw.to_str().unwrap(),
        "--days-per-year",
        "14",
        "--samples-per-day",
        "15",
        "--receivers",
        "WIN_*",
        "--resolution",
        "128",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "Surface Name,WIN_S1,WIN_S2,WIN_E,WIN_N,WIN_W,");
    assert_eq!(lines.len(), 1 + 8760 * 4);
    assert_eq!(lines[1].split(',').next(), Some(" 01/01 00:15"));
    assert_eq!(lines[8760 * 4].split(',').next(), Some(" 12/31 24:00"));
    let mut lit = 0;
    for line in &lines[1..] {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), 7, "{line}");
        assert_eq!(fields[6], "", "trailing comma");
        for v in &fields[1..6] {
            let x: f64 = v.parse().unwrap();
            assert!((0.0..=1.0).contains(&x) && v.len() == 10, "{v}");
            lit += (x > 0.0) as usize;
        }
    }
    assert!(lit > 20_000, "windows are lit for much of the year: {lit}");
    // The library's reader takes the file back whole, with the timestep count found from its rows.
    let schedule = sunlit::export::Schedule::from_csv("shading.csv", &text).unwrap();
    assert_eq!((schedule.names.len(), schedule.timesteps.per_hour()), (5, 4));
    assert_eq!(schedule.values.iter().filter(|&&v| v > 0.0).count(), lit);
}

#[test]
fn cli_bad_annual_input() {
    let dir = scratch("bad");
    let model = dir.join("office.glb");
    std::fs::write(&model, office(0).to_glb()).unwrap();
    let m = model.to_str().unwrap();
    let csv = dir.join("out.csv");
    let o = csv.to_str().unwrap();
    let no_location = dir.join("nowhere.epw");
    std::fs::write(&no_location, "DESIGN CONDITIONS,0\n").unwrap();
    let bad_number = dir.join("bad.epw");
    std::fs::write(&bad_number, "LOCATION,X,Y,Z,S,1,north,-105,-7,10\n").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--epw", no_location.to_str().unwrap()], "nowhere.epw"),
        (vec!["--epw", bad_number.to_str().unwrap()], "bad.epw"),
        (vec!["--location", "95,0,0"], "--location"),
        (vec!["--location", "40,200,0"], "--location"),
        (vec!["--location", "40,-105,-20"], "--location"),
        (vec!["--location", "40,-105,-7", "--timesteps-per-hour", "7"], "--timesteps-per-hour"),
        (vec!["--location", "40,-105,-7", "--days-per-year", "2"], "--days-per-year"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["annual", m, "-o", o];
        args.extend(extra);
        let out = sunlit(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle) && !err.contains("panicked"), "{args:?}: {err}");
        assert!(!csv.exists(), "no output after an error");
    }
    let unwritable = dir.join("no/such/folder/out.csv");
    let out = sunlit(&["annual", m, "--location", "40,-105,-7", "-o", unwritable.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("no/such/folder/out.csv"), "{err}");
}

/// The exact engine's year for `scene` at 4 timesteps an hour, and the views it counted;
/// `prove_never_dark` as [`AnnualOptions::prove_never_dark`].
fn exact_year(scene: &Scene, method: Method, prove_never_dark: bool) -> (Schedule, usize) {
    let options = AnnualOptions {
        timesteps: Timesteps::new(4).unwrap(),
        method,
        refine: DEFAULT_REFINE,
        prove_never_dark,
        many_casters: None,
        inner_corners: false,
    };
    let calendar = sunlit::year::season::LeafCalendar::evergreen();
    let mut views = 0;
    let schedule = pollster::block_on(sunlit::year::annual::annual_with(
        &sunlit::count::exact::Exact { scene },
        scene,
        &golden(),
        &options,
        &calendar,
        &mut |p| {
            views = p.counted();
            Ok(())
        },
    ))
    .unwrap();
    (schedule, views)
}

/// The default year against counting every timestep, exact engine, Timestep 4: (views, dense
/// views, steps lit in the dense year, steps dark in one and lit in the other, mean |Δ|).
fn against_dense(scene: &Scene, label: &str, prove_never_dark: bool) -> (usize, usize, usize, usize, f64) {
    let (dense, dense_views) = exact_year(scene, Method::Dense, false);
    let (spline, spline_views) = exact_year(scene, Method::Spline(SamplingPlan::default()), prove_never_dark);
    let (mut disagree, mut lit) = (0, 0);
    for (a, b) in spline.values.iter().zip(&dense.values) {
        disagree += usize::from((*a > 0.0) != (*b > 0.0));
        lit += usize::from(*b > 0.0);
    }
    let (mean, rms, max) = compare(&spline, &dense).unwrap();
    println!(
        "{label}: {spline_views} views against {dense_views} dense; lit steps {lit}; dark/lit disagreements {disagree}; mean |Δ| {mean:.4}, RMS {rms:.4}, max {max:.4}"
    );
    (spline_views, dense_views, lit, disagree, mean)
}

/// A window at the bottom of a street canyon, 6 m from a 12 m wall with a 0.1 m slot in it 1 m
/// east of the window's axis: lit over the wall at summer middays and otherwise only for minutes
/// a day through the slot, mostly between the samples, so many of its sample cells are dark at
/// all four samples and lit in between. The near-dark rule counts those cells' timesteps
/// (`year::annual::NEAR_DARK`), so the year at the defaults tells dark from lit as counting
/// every timestep does. Measured: setting such cells dark instead loses 173 lit steps; probing
/// each cell once at its centre and counting it only if lit there still loses 59.
#[test]
fn a_slot_of_sun_in_a_dark_canyon_is_not_lost() {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(1.8, 2.2, 0.0, 1.0, 0.0), true);
    s.polygon("WALL_W", &south_rect(-30.0, 2.95, 0.0, 12.0, -6.0), false);
    s.polygon("WALL_E", &south_rect(3.05, 30.0, 0.0, 12.0, -6.0), false);
    let (spline_views, dense_views, lit, disagree, mean) = against_dense(&s.build(), "canyon slot", false);
    assert!(spline_views < dense_views);
    assert!(lit > 500, "the window is lit at {lit} steps");
    assert_eq!(disagree, 0, "steps dark in one and lit in the other");
    assert!(mean <= 0.005, "mean |Δ| {mean}");
}

/// A street canyon of convex blocks: three windows at the foot of a south-facing street front,
/// across the street two 12 m blocks with a 0.1 m slot between them, two windows behind the slot
/// (one low, one 3 m up) and one 1 m to the side. Most of the windows' dark cells are proved dark
/// by one block (a convex caster covering the window at every sun of the cell) and not counted;
/// the slot lights them for minutes a day, mostly between samples. The year tells dark from lit
/// as counting every timestep does, with well under half its views. A certificate that enclosed
/// only each cell's four corner suns, not the days' arcs bulging beyond their chords, fails
/// here: 25 steps behind the slot came out dark that are lit (tried by breaking it on purpose).
#[test]
fn certificates_keep_every_minute_of_sun_in_a_canyon_of_blocks() {
    let mut s = TestScene::new();
    s.polygon("LOW", &south_rect(2.8, 3.1, 0.0, 1.0, 0.0), true);
    s.polygon("HIGH", &south_rect(2.8, 3.1, 3.0, 4.0, 0.0), true);
    s.polygon("ASIDE", &south_rect(1.8, 2.2, 0.0, 1.0, 0.0), true);
    s.cuboid("BLOCK_W", DVec3::new(-40.0, -16.0, 0.0), DVec3::new(2.95, -6.0, 12.0));
    s.cuboid("BLOCK_E", DVec3::new(3.05, -16.0, 0.0), DVec3::new(40.0, -6.0, 12.0));
    let (spline_views, dense_views, lit, disagree, mean) = against_dense(&s.build(), "canyon of blocks", false);
    assert!(lit > 10_000, "the windows are lit at {lit} steps");
    assert_eq!(disagree, 0, "steps dark in one and lit in the other");
    assert!(mean <= 0.005, "mean |Δ| {mean}");
    assert!(spline_views * 2 < dense_views, "{spline_views} views against {dense_views} dense");
}

/// A lit window across a street from a row of tall narrow posts: each post's shadow passes
/// over the window once a day and covers it wholly for a step or two, mostly between samples
/// whose cell is lit at all four corners, so neither the spread, the near-dark nor the kink rule
/// counts the dip, and the spline would carry the window lit through it (as 72 steps on
/// `sunlit bench canyon-slots` are at the defaults). With `prove_never_dark` a step is
/// interpolated only where a patch of the window is proved lit at its sun
/// (`year::certified::never_dark`), so the year tells dark from lit as counting every timestep
/// does.
#[test]
fn a_post_passing_the_sun_between_samples_darkens_the_window() {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 0.5, 0.0, 1.0, 0.0), true);
    for (k, x) in [-14.0, -6.0, 3.0, 9.0].into_iter().enumerate() {
        s.cuboid(&format!("POST_{k}"), DVec3::new(x, -8.0, 0.0), DVec3::new(x + 1.5, -6.5, 25.0));
    }
    let scene = s.build();
    let (spline_views, dense_views, lit, disagree, mean) = against_dense(&scene, "posts", true);
    assert!(lit > 10_000, "the window is lit at {lit} steps");
    assert_eq!(disagree, 0, "steps dark in one and lit in the other");
    assert!(mean <= 0.005, "mean |Δ| {mean}");
    assert!(spline_views < dense_views, "{spline_views} views against {dense_views} dense");
    // Without the proof (the default) the same posts are interpolated away at some steps: what
    // the option buys, and that this scene puts it to work.
    let (.., unproved, _) = against_dense(&scene, "posts, unproved", false);
    assert!(unproved > 0, "without the proof no step is lost here, so the test proves nothing");
}

/// An east window 1 m square with a fin 0.3 mm deep and 10 m tall along its south edge: the
/// fin's shadow covers the window only in the last 0.02° of azimuth before the sun passes behind
/// it at noon, between the day's last sample and the end of its lit piece, where the fit
/// extrapolates the window lit. A step falls there once in this year (as the equation of time
/// moves noon across the clock); it is counted (`year::certified::Rule::BeyondSamples`), so the
/// year tells dark from lit as counting every timestep does. Without that rule the fit keeps it
/// lit at 0.94 (tried: 1 disagreement); a fin 0.5–1.5 mm deep darkens the window early enough
/// that the last sample sees it.
#[test]
fn the_last_minute_before_the_sun_passes_behind_a_window_is_counted() {
    let mut s = TestScene::new();
    let east_window = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 1.0), DVec3::new(0.0, 0.0, 1.0)];
    s.polygon("WIN", &east_window, true);
    s.cuboid("FIN", DVec3::new(0.0, -0.01, 0.0), DVec3::new(0.0003, 0.0, 10.0));
    let (spline_views, dense_views, lit, disagree, mean) = against_dense(&s.build(), "fin", false);
    // Every step the sun is in front of the window is counted densely: those not lit are the
    // fin's, or the test would ask nothing of the rule.
    assert!(lit > 8_000 && lit < dense_views, "the window is lit at {lit} of {dense_views} steps in front of the sun");
    assert_eq!(disagree, 0, "steps dark in one and lit in the other");
    assert!(mean <= 0.005, "mean |Δ| {mean}");
    assert!(spline_views < dense_views, "{spline_views} views against {dense_views} dense");
}

/// The exact reference, tallying the views it is asked to count.
struct Tally<'a> {
    exact: sunlit::count::exact::Exact<'a>,
    asked: std::cell::Cell<usize>,
}

impl<'a> Tally<'a> {
    fn new(scene: &'a Scene) -> Self {
        Tally { exact: sunlit::count::exact::Exact { scene }, asked: std::cell::Cell::new(0) }
    }
}

impl sunlit::count::Engine for Tally<'_> {
    fn batch(&self) -> usize {
        self.exact.batch()
    }

    async fn answer(&self, requests: &[sunlit::count::ViewRequest]) -> sunlit::Result<Vec<sunlit::count::ViewAnswer>> {
        self.asked.set(self.asked.get() + requests.len());
        self.exact.answer(requests).await
    }
}

/// Every progress report of the year for `scene` at `method` (hourly, evergreen), and the views
/// the engine was asked for.
fn reported_year(scene: &Scene, method: Method) -> (Vec<sunlit::year::annual::Progress>, usize) {
    let options = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method,
        refine: DEFAULT_REFINE,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    };
    let calendar = sunlit::year::season::LeafCalendar::evergreen();
    let engine = Tally::new(scene);
    let mut reports = Vec::new();
    pollster::block_on(sunlit::year::annual::annual_with(&engine, scene, &golden(), &options, &calendar, &mut |p| {
        reports.push(p);
        Ok(())
    }))
    .unwrap();
    (reports, engine.asked.get())
}

/// A year's progress tells the truth: its total is fixed from the first report (the samples and
/// every facing sun-up timestep, which is what `--dense` counts), `done` never goes back and ends
/// at the total, and the views it says were counted are those the engine was asked for: the
/// timesteps the spline settles are done but not counted.
#[test]
fn a_years_progress_counts_what_the_engine_counted() {
    let mut s = TestScene::new();
    s.polygon("WIN", &south_rect(0.0, 2.0, 1.0, 2.0, 0.0), true);
    s.polygon("FIN", &[DVec3::new(2.2, 0.0, 0.5), DVec3::new(2.2, -1.5, 0.5), DVec3::new(2.2, -1.5, 2.5), DVec3::new(2.2, 0.0, 2.5)], true);
    s.polygon("OVERHANG", &flat_rect(-1.0, 3.0, -0.6, 0.0, 2.2), false);
    let scene = s.build();
    let (dense, dense_asked) = reported_year(&scene, Method::Dense);
    let (spline, spline_asked) = reported_year(&scene, Method::Spline(SamplingPlan::new(9, 7).unwrap()));
    for (reports, asked, what) in [(&dense, dense_asked, "dense"), (&spline, spline_asked, "spline")] {
        let last = reports.last().unwrap();
        println!("{what}: {} reports, last {last:?}, engine asked for {asked}", reports.len());
        assert!(reports.iter().all(|p| p.total == last.total), "{what}: the total is fixed from the start");
        assert!(reports.windows(2).all(|w| w[0].done <= w[1].done && w[0].counted() <= w[1].counted()), "{what}: never goes back");
        assert_eq!((last.done, last.may_settle), (last.total, 0), "{what}: ends at its total");
        assert_eq!(last.counted(), asked, "{what}: the views counted are the engine's");
    }
    let last = spline.last().unwrap();
    assert_eq!(dense.last().unwrap().settled, 0, "dense counts every view");
    assert!(last.settled > 0 && spline_asked < dense_asked, "the spline settles most timesteps: {last:?}");
    // Its total: the samples (counted while every timestep may yet be settled), then every
    // timestep the dense year counts.
    let samples = spline.iter().filter(|p| p.may_settle > 0).map(|p| p.done).max().unwrap();
    assert_eq!(samples + dense_asked, last.total);
    assert!(spline.iter().all(|p| p.may_settle == 0 || p.may_settle == dense_asked));
}

/// With stderr in a file (a Slurm task's log, CI), `sunlit annual` writes plain progress lines
/// (the interval shortened here so a small run shows several), and its closing line's views are
/// those an engine counted over the year, the sky views and EnergyPlus's diffuse directions:
/// what the library's own stages asked of an engine that tallies them.
#[test]
fn cli_progress_goes_to_a_log_and_counts_only_counted_views() {
    let dir = scratch("progress");
    let model = dir.join("office.glb");
    std::fs::write(&model, office(2).to_glb()).unwrap();
    let (csv, summary, log) = (dir.join("out.csv"), dir.join("summary.json"), dir.join("log.txt"));
    let status = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args([
            "annual",
            model.to_str().unwrap(),
            "--location",
            "39.74,-105.18,-7",
            "--receivers",
            "WIN_S1",
            "--receivers",
            "WIN_E",
            "--engine",
            "exact",
        ])
        .args(["--days-per-year", "9", "--samples-per-day", "7", "--timesteps-per-hour", "1", "--summary", summary.to_str().unwrap()])
        .args(["-o", csv.to_str().unwrap()])
        .env("SUNLIT_PROGRESS_EVERY_MS", "0")
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .stderr(std::fs::File::create(&log).unwrap())
        .status()
        .unwrap();
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(status.success(), "{text}");
    let lines = |stage: &str| text.lines().filter(|l| l.starts_with(&format!("{stage}: "))).collect::<Vec<_>>();
    let (year, sky, ratios) = (lines("year"), lines("sky views"), lines("EnergyPlus's diffuse ratios"));
    assert!(year.len() >= 3 && !sky.is_empty() && !ratios.is_empty(), "{text}");
    assert!(year[0].contains(" of ") && year[0].contains("views (") && year[0].contains("elapsed"), "{}", year[0]);
    assert!(year.last().unwrap().contains("(100 %)") && year.last().unwrap().ends_with("done"), "{text}");
    assert!(year.iter().any(|l| l.contains(" to ") && l.ends_with(" left")), "a range while the samples are counted: {text}");
    let closing = text.lines().find(|l| l.contains("views counted")).unwrap();
    let said: usize = closing.rsplit("; ").next().unwrap().split(' ').next().unwrap().parse().unwrap();

    let options = LoadOptions { receivers: vec!["WIN_S1".into(), "WIN_E".into()], ..Default::default() };
    let scene = load_bytes(&[("office.glb".into(), office(2).to_glb())], &options).unwrap();
    let engine = Tally::new(&scene);
    let plan = AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method: Method::Spline(SamplingPlan::new(9, 7).unwrap()),
        refine: DEFAULT_REFINE,
        prove_never_dark: false,
        many_casters: None,
        inner_corners: false,
    };
    let calendar = sunlit::year::season::LeafCalendar::evergreen();
    let mut quiet = |_: sunlit::year::annual::Progress| -> sunlit::Result<()> { Ok(()) };
    pollster::block_on(sunlit::year::annual::annual_with(&engine, &scene, &golden(), &plan, &calendar, &mut quiet)).unwrap();
    let patches = sunlit::sky::patches::SkyPatches::tregenza();
    pollster::block_on(sunlit::sky::views::sky_views(&engine, &scene, &patches, &mut quiet)).unwrap();
    pollster::block_on(sunlit::sky::energyplus::ratios(&engine, &scene, &mut quiet)).unwrap();
    assert_eq!(said, engine.asked.get(), "{closing}");
}

/// A ribbon window in a north wall under a row of ten overhangs 0.76 m deep with gaps between
/// them (the north facade of NREL's 100-zone test file, issue 36). Around the equinoxes the wall
/// sees the sun only for minutes after sunrise and before sunset, pieces of the day that exist on
/// one sample day and not on its neighbour, whose samples the fit then borrows from the nearest
/// day that has them: the spline there is an extrapolation, and was off by up to 0.51 in
/// Chicago on the days the piece first appears. Such cells are counted directly
/// (`year::annual`'s borrowed-day rule).
#[test]
fn short_pieces_near_the_equinoxes_are_counted_not_borrowed() {
    let mut s = TestScene::new();
    let mut window = south_rect(0.0254, 30.4546, 0.76, 1.9812, 0.0);
    window.reverse();
    s.polygon("N_WIN", &window, true);
    for i in 0..10 {
        let x = 0.3048 + 3.048 * f64::from(i);
        s.polygon(&format!("OVERHANG_{i}"), &flat_rect(x, x + 2.4384, 0.0, 0.762, 2.286), false);
    }
    let scene = s.build();
    let (dense, _) = exact_year(&scene, Method::Dense, false);
    let (spline, _) = exact_year(&scene, Method::Spline(SamplingPlan::default()), false);
    let (mean, _, max) = compare(&spline, &dense).unwrap();
    println!("north window under overhangs: mean |Δ| {mean:.4}, max {max:.4}");
    assert!(max <= 0.2, "largest |Δ| {max}");
}
