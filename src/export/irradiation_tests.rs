//! Tests of the irradiation summary (a file of its own to keep `irradiation.rs` short).
#![allow(clippy::unwrap_used)]

use super::*;
use crate::count::exact::Exact;
use crate::scene::{SceneBuilder, SourceMesh};
use crate::sky::patches::SkyPatches;
use crate::sky::views::sky_views;
use crate::sun::position::declination_and_equation_of_time;
use crate::sun::weather::Hour;
use crate::year::samples::{DAYS, Timesteps};

/// A 1 m² horizontal roof (facing up).
fn roof_scene() -> Scene {
    let mesh =
        SourceMesh { positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], indices: vec![0, 1, 2, 0, 2, 3] };
    let mut builder = SceneBuilder::new();
    builder.add_object("test", "ROOF", mesh, true);
    builder.build().unwrap()
}

fn filled(scene: &Scene, timesteps: Timesteps, value: f32) -> Schedule {
    let names = scene.receivers.iter().map(|r| r.name.clone()).collect();
    let mut s = Schedule::zeros(names, timesteps);
    s.values.iter_mut().for_each(|v| *v = value);
    s
}

fn views(scene: &Scene) -> SkyViews {
    pollster::block_on(sky_views(&Exact { scene }, scene, &SkyPatches::tregenza(), &mut |_| Ok(()))).unwrap()
}

fn beam_only(location: &Location, dni: f64) -> Weather {
    Weather::constant(location.clone(), Hour { dni, dhi: 0.0, ghi: 0.0, albedo: 0.2 })
}

/// Closed form, independent of the timestep code: a horizontal surface under a constant beam
/// B gets B·∫ sin(altitude) dt a day = B·(24/π)·(ω₀·sin φ·sin δ + cos φ·cos δ·sin ω₀) Wh/m²,
/// ω₀ the sunset hour angle, δ that of the day whose sun the fractions use (held over the day).
fn closed_form_roof_kwh(latitude: f64, beam: f64) -> f64 {
    let phi = latitude.to_radians();
    (1..=DAYS)
        .map(|day| {
            let (sin_delta, _) = declination_and_equation_of_time(shading_sun_day(day));
            let delta = sin_delta.asin();
            let omega0 = (-phi.tan() * delta.tan()).clamp(-1.0, 1.0).acos();
            beam * 24.0 / std::f64::consts::PI * (omega0 * phi.sin() * delta.sin() + phi.cos() * delta.cos() * omega0.sin())
        })
        .sum::<f64>()
        / 1000.0
}

#[test]
fn unshaded_roof_matches_the_closed_form() {
    let scene = roof_scene();
    let sky = views(&scene);
    let calendar = LeafCalendar::default();
    let location = Location::new(39.74, -105.18, -7.0).unwrap();
    let expected = closed_form_roof_kwh(39.74, 800.0);
    let weather = beam_only(&location, 800.0);
    for per_hour in [1, 4, 60] {
        let timesteps = Timesteps::new(per_hour).unwrap();
        let summary = summarize(&scene, &filled(&scene, timesteps, 1.0), &location, Some((&sky, &calendar)), Some(&weather), &[]).unwrap();
        let (got, unshaded) = (summary[0].irradiation.unwrap(), summary[0].unshaded_irradiation.unwrap());
        assert_eq!(got, unshaded, "fraction 1 everywhere: shaded = unshaded");
        // Timestep sums vs the integral: within 0.5 % at N = 1 (mid-hour rule), closer finer.
        let tolerance = if per_hour == 1 { 0.005 } else { 0.002 };
        assert!((got / expected - 1.0).abs() < tolerance, "N={per_hour}: {got} kWh/m² vs closed form {expected}");
        assert_eq!(summary[0].mean_fraction, 1.0);
        assert!((summary[0].area - 1.0).abs() < 1e-9);
        // No diffuse, no ground light: the total is the beam.
        assert!((summary[0].total.unwrap() - got).abs() < 1e-9 && summary[0].sky_diffuse == Some(0.0));
        assert!((summary[0].sky_view_factor.unwrap() - 1.0).abs() < 1e-4, "{:?}", summary[0].sky_view_factor);
    }
}

#[test]
fn half_shaded_roof_gets_half() {
    let scene = roof_scene();
    let sky = views(&scene);
    let calendar = LeafCalendar::default();
    let location = Location::new(-33.87, 151.21, 10.0).unwrap();
    let timesteps = Timesteps::new(4).unwrap();
    let weather = beam_only(&location, 500.0);
    let summary = summarize(&scene, &filled(&scene, timesteps, 0.5), &location, Some((&sky, &calendar)), Some(&weather), &[]).unwrap();
    let expected = closed_form_roof_kwh(-33.87, 500.0);
    let (got, unshaded) = (summary[0].irradiation.unwrap(), summary[0].unshaded_irradiation.unwrap());
    assert!((got - unshaded / 2.0).abs() < 1e-9 && (unshaded / expected - 1.0).abs() < 0.002, "{got} {unshaded} {expected}");
    assert!((summary[0].mean_fraction - 0.5).abs() < 1e-6);
    // Without weather: mean fraction (and the sky view factor) only.
    let bare = summarize(&scene, &filled(&scene, timesteps, 0.5), &location, Some((&sky, &calendar)), None, &[]).unwrap();
    assert_eq!((bare[0].irradiation, bare[0].unshaded_irradiation, bare[0].total), (None, None, None));
    assert!(bare[0].sky_view_factor.is_some());
}

#[test]
fn diffuse_and_ground_light_add_up_on_an_open_roof() {
    // A horizontal open roof under DHI and GHI all day: sky diffuse = DHI but for the
    // circumsolar part at low sun (sky::perez), ground-reflected 0 ((1 − cos 0)/2 = 0), over the
    // sun-up timesteps.
    let scene = roof_scene();
    let sky = views(&scene);
    let calendar = LeafCalendar::default();
    let location = Location::new(39.74, -105.18, -7.0).unwrap();
    let weather = Weather::constant(location.clone(), Hour { dni: 300.0, dhi: 100.0, ghi: 400.0, albedo: 0.3 });
    let timesteps = Timesteps::new(1).unwrap();
    let schedule = filled(&scene, timesteps, 1.0);
    let s = summarize(&scene, &schedule, &location, Some((&sky, &calendar)), Some(&weather), &[]).unwrap();
    // Each sun-up timestep: DHI·((1 − F1)·1 + F1·cos Z/max(cos 85°, cos Z)): the whole DHI but
    // for the circumsolar part below 5° of altitude.
    let expected: f64 = timesteps
        .instants()
        .map(|i| sun_direction(&location, shading_sun_day(i.day), i.hour))
        .filter(|sun| sun.z >= MIN_COS_INCIDENCE)
        .map(|sun| {
            let p = PerezSky::new(300.0, 100.0, sun.z).unwrap();
            100.0 * (1.0 - p.f1 + p.f1 * sun.z / sun.z.max(crate::sky::perez::MIN_COS_ZENITH)) / 1000.0
        })
        .sum();
    let diffuse = s[0].sky_diffuse.unwrap();
    assert!((diffuse - expected).abs() < 1e-3 * diffuse, "{diffuse} vs {expected}");
    assert!(s[0].ground_reflected.unwrap().abs() < 1e-9);
    assert!((s[0].total.unwrap() - s[0].unshaded_total.unwrap()).abs() < 1e-3);
    // The irradiance CSV's rows sum to the same total.
    let csv = String::from_utf8(
        irradiance_csv(&scene, &schedule, &location, &Solar { weather: &weather, sky: &sky, calendar: &calendar }).unwrap(),
    )
    .unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("Surface Name,ROOF,"));
    let sum: f64 = lines.map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap()).sum();
    assert!((sum / 1000.0 - s[0].total.unwrap()).abs() < 1e-4 * sum / 1000.0, "{sum} Wh vs {:?} kWh", s[0].total);
}

#[test]
fn summary_formats() {
    let scene = roof_scene();
    let sky = views(&scene);
    let calendar = LeafCalendar::default();
    let location = Location::new(39.74, -105.18, -7.0).unwrap();
    let schedule = filled(&scene, Timesteps::new(1).unwrap(), 0.25);
    let weather = beam_only(&location, 100.0);
    let ratios = [Some(EnergyPlusRatios { iso_sky: 0.75, horizon: 0.5 })];
    let s = summarize(&scene, &schedule, &location, Some((&sky, &calendar)), Some(&weather), &ratios).unwrap();
    let json: serde_json::Value = serde_json::from_str(&summary_json(&s)).unwrap();
    let roof = &json["surfaces"][0];
    assert_eq!(roof["name"], "ROOF");
    assert!((roof["mean_fraction"].as_f64().unwrap() - 0.25).abs() < 1e-6);
    assert_eq!(roof["direct"], roof["irradiation"]);
    assert_eq!((roof["energyplus_iso_sky_ratio"].as_f64(), roof["energyplus_horizon_ratio"].as_f64()), (Some(0.75), Some(0.5)));
    for key in ["sky_diffuse", "ground_reflected", "total", "unshaded_total", "sky_view_factor"] {
        assert!(roof[key].is_number(), "{key}: {roof}");
    }
    let csv = summary_csv(&s);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], SUMMARY_CSV_HEADER);
    assert!(lines[0].starts_with("name,area_m2,mean_fraction,irradiation_kwh_m2,unshaded_irradiation_kwh_m2,"));
    assert!(lines[1].starts_with("ROOF,1.000000,0.250000,"), "{}", lines[1]);
    assert!(lines[1].ends_with(",0.750000,0.500000"), "{}", lines[1]);
    let bare = summary_csv(&summarize(&scene, &schedule, &location, None, None, &[]).unwrap());
    assert!(bare.lines().nth(1).unwrap().ends_with("0.250000,,,,,,,,,,"), "{bare}");
}
