//! `sunlit map --study bre-vsc|bre-apsh|gb50180|bre-25deg|bre-45deg`: the window studies' edge.
//! Checks which options each study takes, reads the proposed scene (and with `--before` the
//! existing one), runs the library's studies ([`sunlit::map::planning::run`]) on both, has the
//! library make their tables ([`sunlit::export::planning_tables`]), and writes the points CSV (one value
//! column per study value), `POINTS.study-NAME.json`/`.csv`, the requested sky masks
//! (`POINTS.mask-N.svg`) and `--html`'s report, all at the end.

use serde_json::{Value, json};
use sunlit::export::planning_report::{mask_svg, report_html, study_csv, study_json};
use sunlit::export::planning_tables::{sun_paths, tables};
use sunlit::map::planning::gb50180::Gb50180Rule;
use sunlit::map::planning::window_points::WindowPoint;
use sunlit::map::planning::{mask, run};
use sunlit::map::{Points, Site};
use sunlit::sun::weather::Weather;
use sunlit::year::season::LeafCalendar;

use super::*;

pub(super) use sunlit::map::planning::run::STUDIES;

/// Whether `args` ask for a window study (then [`run`] answers them).
pub(super) fn wanted(args: &MapArgs) -> bool {
    args.study.iter().any(|s| STUDIES.contains(&s.as_str()))
}

/// Refuses what the window studies do not take, naming the option.
fn check_options(args: &MapArgs) -> Result<()> {
    if let Some(at) = &args.window_points {
        WindowPoint::parse(at)?;
    }
    if let Some(other) = args.study.iter().find(|s| !STUDIES.contains(&s.as_str())) {
        return Err(Error::argument(
            "study",
            format!("'{other}' cannot run beside the window studies ({}): give it in a run of its own", STUDIES.join(", ")),
        ));
    }
    let names = args.study.join(", ");
    let not_taken = [
        ("--period", args.period.is_some()),
        ("--from", args.from.is_some()),
        ("--to", args.to.is_some()),
        ("--step", args.step.is_some()),
        ("--min-altitude", args.min_altitude.is_some()),
        ("--albedo", args.albedo.is_some()),
        ("--sky-patches", args.sky_patches.is_some()),
    ];
    if let Some((flag, _)) = not_taken.iter().find(|(_, given)| *given) {
        return Err(Error::argument(*flag, format!("{names} does not take it: each window study fixes its own days and sky")));
    }
    if args.engine == "gpu" {
        return Err(Error::argument("--engine", format!("{names} is answered by the exact rays only; give auto or exact")));
    }
    let gb = args.study.iter().any(|s| s == "gb50180");
    let gb_only = [
        ("--day", args.day.is_some()),
        ("--required-hours", args.required_hours.is_some()),
        ("--min-period", args.min_period.is_some()),
        ("--max-periods", args.max_periods.is_some()),
        ("--window-width", args.window_width.is_some()),
    ];
    if !gb && let Some((flag, _)) = gb_only.iter().find(|(_, given)| *given) {
        return Err(Error::argument(*flag, format!("{names} does not take it: only gb50180 does")));
    }
    run::check_sky_model(&args.study, args.sky_model.as_deref())?;
    if args.study.iter().any(|s| s == "bre-apsh") && args.epw.is_none() {
        return Err(Error::argument(
            "--epw",
            "bre-apsh needs a weather file: its probable sunlight hours come from the hours' direct normal irradiance",
        ));
    }
    if gb && args.epw.is_none() && args.location.is_none() {
        return Err(Error::argument("--location", "gb50180 needs the site (--location LAT,LON,TZ or --epw): its sun is the latitude's"));
    }
    if !args.before.is_empty() && args.points.is_none() && args.window_points.is_none() {
        return Err(Error::argument(
            "--before",
            "needs --points or --window-points: the existing and proposed scenes are compared at the same reference points",
        ));
    }
    Ok(())
}

fn gb_rule(args: &MapArgs) -> Result<Gb50180Rule> {
    Gb50180Rule::from_options(args.day.as_deref(), args.required_hours, args.min_period, args.max_periods, args.window_width)
}

/// The 1-based rows `--mask` asks diagrams for (`all`, or a comma list), as 0-based indices.
fn mask_rows(text: Option<&str>, points: usize) -> Result<Vec<usize>> {
    let Some(text) = text else { return Ok(Vec::new()) };
    if text.trim() == "all" {
        return Ok((0..points).collect());
    }
    text.split(',')
        .map(|t| match t.trim().parse::<usize>() {
            Ok(row) if (1..=points).contains(&row) => Ok(row - 1),
            _ => Err(Error::argument("--mask", format!("'{t}' is not a point row 1..={points} (or give all)"))),
        })
        .collect()
}

/// The existing scene's points: each of the proposed `points` that lies on one of its receivers,
/// and where it sits in `points`. Refuses a scene with none in common, naming `from` (the points'
/// source).
fn before_points(before: &Scene, points: &Points, from: &str) -> Result<(Points, Vec<usize>)> {
    let all: Vec<u32> = (0..before.receivers.len() as u32).collect();
    let (kept, index) = sunlit::map::points::place_on(before, points, &all);
    if index.is_empty() {
        return Err(Error::argument("--before", format!("no point of {from} lies on a receiver of the existing scene")));
    }
    Ok((kept, index))
}

pub(super) fn run(args: MapArgs) -> Result<()> {
    check_options(&args)?;
    let gb = args.study.iter().any(|s| s == "gb50180").then(|| gb_rule(&args)).transpose()?;
    let weather = args.epw.as_ref().map(|p| Weather::from_epw(p)).transpose()?;
    let location = match (&weather, &args.location) {
        (Some(w), _) => Some(w.location.clone()),
        (None, Some(text)) => Some(Location::parse(text)?),
        (None, None) => None,
    };
    check_writable(&args.output)?;
    for path in [&args.glb_out, &args.html].into_iter().flatten() {
        check_writable(path)?;
    }
    let start = Instant::now();
    let scene = args.model.load()?;
    let load_seconds = start.elapsed().as_secs_f64();
    let points = args.points(&scene)?;
    let masks = mask_rows(args.mask.as_deref(), points.len())?;
    let before = if args.before.is_empty() {
        None
    } else {
        let scene = model::load(&args.before, &args.model.options())?;
        let from = match (&args.points, &args.window_points) {
            (Some(path), _) => path.display().to_string(),
            (None, at) => format!("--window-points {}", at.as_deref().unwrap_or_default()),
        };
        let (kept, index) = before_points(&scene, &points, &from)?;
        Some((scene, kept, index))
    };
    let calendar = location.as_ref().map(|l| LeafCalendar::for_latitude(l.latitude));
    let site = location.as_ref().zip(calendar.as_ref()).map(|(location, calendar)| Site {
        location,
        calendar,
        weather: weather.as_ref(),
        sky: None,
    });
    let (now, now_seconds) = timed(|done| run::evaluate(&args.study, &scene, &points, site, gb.as_ref(), done))?;
    let former = before.as_ref().map(|(s, p, _)| timed(|done| run::evaluate(&args.study, s, p, site, gb.as_ref(), done))).transpose()?;
    let tables = tables(
        &now,
        former.as_ref().zip(before.as_ref()).map(|((v, _), (_, _, index))| (v, index.as_slice())),
        points.len(),
        gb.as_ref(),
        location.as_ref(),
    );

    let inputs = json!({
        "models": args.model.models,
        "before": args.before,
        "points": points_input(&args)?,
        "site": location.as_ref().map(|l| json!({"latitude": l.latitude, "longitude": l.longitude, "time_zone": l.time_zone})),
        "epw": args.epw,
    });
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let columns: Vec<(String, Vec<f64>)> = tables.iter().flat_map(|t| t.values.clone()).collect();
    let csv_columns: Vec<Column<'_>> = columns.iter().map(|(name, values)| Column { name, values, decimals: 4 }).collect();
    files.push((args.output.clone(), points_csv(&scene, &points, &csv_columns).into_bytes()));
    for t in &tables {
        files.push((args.study_path(&t.study, "json"), format!("{:#}\n", study_json(&scene, &points, t, inputs.clone())).into_bytes()));
        files.push((args.study_path(&t.study, "csv"), study_csv(&scene, &points, t).into_bytes()));
    }
    let mut svgs = Vec::new();
    if !masks.is_empty() {
        let chosen = subset(&points, &masks);
        let paths = location.as_ref().map(|l| sun_paths(l, gb.as_ref())).unwrap_or_default();
        for (&i, m) in masks.iter().zip(mask::sky_masks(&scene, &chosen)?) {
            let p = points.position(i);
            let svg = mask_svg(&format!("point {} at ({:.2}, {:.2}, {:.2})", i + 1, p.x, p.y, p.z), &m, &paths);
            files.push((args.output.with_file_name(format!("{}.mask-{}.svg", stem(&args.output), i + 1)), svg.clone().into_bytes()));
            svgs.push((i, svg));
        }
    }
    if let Some(html) = &args.html {
        files.push((html.clone(), report_html(&scene, &points, &tables, &svgs, &inputs).into_bytes()));
    }
    if let (Some(glb), Some((name, values))) = (&args.glb_out, columns.first()) {
        let unit = if name.starts_with("hours") {
            "h"
        } else if name.starts_with("angle") {
            "deg"
        } else {
            "%"
        };
        files.push((glb.clone(), map_glb(&scene, &points, values, name, unit)));
    }
    for (path, bytes) in &files {
        write_atomic(path, bytes)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let summary = json!({
        "points": points.len(),
        "points_before": before.as_ref().map(|(_, p, _)| p.len()),
        "seconds": round(seconds, 3),
        "seconds_by_part": {
            "load": round(load_seconds, 3),
            "proposed": now_seconds.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>(),
            "existing": former.as_ref().map(|(_, f)| f.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>()),
        },
        "studies": tables.iter().map(|t| json!({
            "study": t.study,
            "assessed": (0..points.len()).filter(|&i| t.passes(i).is_some()).count(),
            "passing": (0..points.len()).filter(|&i| t.passes(i) == Some(true)).count(),
        })).collect::<Vec<Value>>(),
        "written": files.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>(),
    });
    if args.json {
        println!("{summary:#}");
    } else {
        eprintln!("{} points, {} in {seconds:.2} s → {}", points.len(), args.study.join(", "), args.output.display());
    }
    Ok(())
}

/// Runs `evaluate` with a `done(part)` that records the seconds each part took since the last.
fn timed<T>(evaluate: impl FnOnce(&mut dyn FnMut(&str)) -> Result<T>) -> Result<(T, Vec<(String, f64)>)> {
    let mut seconds = Vec::new();
    let mut since = Instant::now();
    let value = evaluate(&mut |part: &str| {
        seconds.push((part.to_string(), since.elapsed().as_secs_f64()));
        since = Instant::now();
    })?;
    Ok((value, seconds))
}

/// How the points were given, for the reports: a file, the windows' own points, or a grid.
fn points_input(args: &MapArgs) -> Result<Value> {
    Ok(match (&args.points, &args.window_points) {
        (Some(file), _) => json!({"file": file}),
        (None, Some(at)) => {
            let at = WindowPoint::parse(at)?;
            json!({"window_points": at.name(), "at": at.describe(), "offset_m": sunlit::map::planning::window_points::OFFSET})
        }
        (None, None) => json!({"grid_spacing_m": args.grid.unwrap_or(0.5)}),
    })
}

fn subset(points: &Points, rows: &[usize]) -> Points {
    let mut out = Points::default();
    for &i in rows {
        out.positions.extend_from_slice(&points.positions[3 * i..3 * i + 3]);
        out.normals.extend_from_slice(&points.normals[3 * i..3 * i + 3]);
        out.receivers.push(points.receivers[i]);
    }
    out
}

fn stem(path: &std::path::Path) -> String {
    path.file_stem().map_or("map".into(), |s| s.to_string_lossy().into_owned())
}
