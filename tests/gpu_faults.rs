//! GPU faults: a lost device is reported as [`Error::DeviceLost`], never as a wrong number or a
//! panic, and `annual_recovering` (what the CLI's `annual` runs) survives one loss mid-year by
//! making a new device, giving the same schedule as an undisturbed run. GPU tests: lavapipe in
//! CI, never skipped.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

use sunlit::Error;
use sunlit::count::ViewRequest;
use sunlit::count::gpu::{Counter, CounterOptions};
use sunlit::model::{LoadOptions, load_bytes, office::office};
use sunlit::scene::Scene;
use sunlit::sun::SunPosition;
use sunlit::sun::location::Location;
use sunlit::year::annual::{AnnualOptions, Method, Progress, annual, annual_recovering};
use sunlit::year::samples::{SamplingPlan, Timesteps};
use sunlit::year::season::LeafCalendar;

fn office_scene() -> Scene {
    load_bytes(&[("office.glb".into(), office(2).to_glb())], &LoadOptions::default()).unwrap()
}

fn options() -> AnnualOptions {
    AnnualOptions {
        timesteps: Timesteps::new(1).unwrap(),
        method: Method::Spline(SamplingPlan::new(6, 7).unwrap()),
        refine: 1.0,
        prove_never_dark: false,
        many_casters: Some(false),
        inner_corners: false,
    }
}

/// A small atlas (4 views per submission), so a year takes many submissions and progress reports.
fn counter() -> Counter {
    pollster::block_on(Counter::new(CounterOptions { resolution: 64, max_atlas: 128, accuracy: None, ..Default::default() }))
        .expect("a GPU adapter (lavapipe: apt-get install mesa-vulkan-drivers) — GPU tests never skip")
}

fn golden() -> Location {
    Location::new(39.74, -105.18, -7.0).unwrap()
}

#[test]
fn a_lost_device_is_reported_as_lost() {
    let scene = office_scene();
    let counter = counter();
    let gpu = counter.upload(&scene).unwrap();
    let sun = SunPosition::new(180.0, 30.0).unwrap().direction();
    let requests: Vec<ViewRequest> = (0..scene.receivers.len() as u32).map(|receiver| ViewRequest::new(receiver, sun)).collect();
    assert!(pollster::block_on(counter.fractions(&gpu, &requests)).is_ok());
    counter.device_loss_trigger()();
    let err = pollster::block_on(counter.fractions(&gpu, &requests)).unwrap_err();
    assert!(matches!(err, Error::DeviceLost(_)), "{err:?}");
    assert!(err.to_string().starts_with("GPU device lost (Destroyed"), "{err}");
    // Everything after the loss says so too, rather than failing obscurely.
    assert!(matches!(counter.upload(&scene), Err(Error::DeviceLost(_))));
}

#[test]
fn annual_recovers_from_a_device_lost_mid_year() {
    let scene = office_scene();
    let reference = {
        let counter = counter();
        let gpu = counter.upload(&scene).unwrap();
        pollster::block_on(annual(&counter, &gpu, &scene, &golden(), &options(), &mut |_| Ok(()))).unwrap()
    };
    let counter = counter();
    let gpu = counter.upload(&scene).unwrap();
    let lose = counter.device_loss_trigger();
    let mut lanes = vec![(counter, gpu)];
    let mut reports = Vec::new();
    let schedule = pollster::block_on(annual_recovering(&mut lanes, &scene, &golden(), &options(), &LeafCalendar::evergreen(), &mut |p| {
        // Lose the device at the first report after the start: mid-year, once.
        if p.done > 0 && reports.iter().all(|r: &Progress| r.done == 0) {
            lose();
        }
        reports.push(p);
        Ok(())
    }))
    .unwrap();
    let restarts = reports.windows(2).filter(|w| w[1].done < w[0].done).count();
    assert_eq!(restarts, 1, "counted again from the start once: {reports:?}");
    assert_eq!(schedule.names, reference.names);
    let worst = schedule.values.iter().zip(&reference.values).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(worst <= 1e-6, "the recovered year equals an undisturbed one (max |Δ| {worst})");
    // A device lost between runs is found at the start of the next, and recovered from too.
    lanes[0].0.device_loss_trigger()();
    let again =
        pollster::block_on(annual_recovering(&mut lanes, &scene, &golden(), &options(), &LeafCalendar::evergreen(), &mut |_| Ok(())))
            .unwrap();
    assert_eq!(again, schedule);
}
