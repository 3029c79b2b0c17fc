//! `sunlit map --study bre-vsc|bre-apsh|gb50180|bre-25deg|bre-45deg|en17037`: the window studies'
//! edge (`en17037` is one beside another window study, or with `--window-points` or `--before`;
//! alone it is the area study of [`sunlit::map::study`]).
//! Checks which options each study takes, reads the proposed scene (and with `--before` the
//! existing one), runs the library's studies ([`sunlit::map::planning::run`]) on both, has the
//! library make their tables ([`sunlit::export::planning_tables`]), and writes the points CSV (one value
//! column per study value), `POINTS.study-NAME.json`/`.csv`, the requested sky masks
//! (`POINTS.mask-N.svg`) and `--html`'s report, all at the end.

use serde_json::{Value, json};
use sunlit::export::planning_report::{report_html, study_csv, study_json};
use sunlit::export::planning_tables::{compared_tables, mask_svgs, points_input as planning_points_input, report_inputs};
use sunlit::map::Site;
use sunlit::map::planning::en17037::En17037Rule;
use sunlit::map::planning::gb50180::Gb50180Rule;
use sunlit::map::planning::run::{self, Rules, WINDOW_STUDIES};
use sunlit::map::planning::sill_lines::sill_lines;
use sunlit::map::planning::sill_widths::{WholeWindow, sill_widths};
use sunlit::map::planning::window_points::WindowPoint;
use sunlit::sun::weather::Weather;
use sunlit::year::season::LeafCalendar;

use super::*;

pub(super) use sunlit::map::planning::run::STUDIES;

/// Whether `args` ask for a window study (then [`run`] answers them): one of [`STUDIES`], or
/// `en17037` at the windows' own points or against an existing scene (alone on given points or a
/// grid it stays the area study).
pub(super) fn wanted(args: &MapArgs) -> bool {
    let en17037 = args.study.iter().any(|s| s == "en17037") && (args.window_points.is_some() || !args.before.is_empty());
    en17037 || args.study.iter().any(|s| STUDIES.contains(&s.as_str()))
}

/// Refuses what the window studies do not take, naming the option.
fn check_options(args: &MapArgs) -> Result<()> {
    if let Some(at) = &args.window_points {
        WindowPoint::parse(at)?;
    }
    if args.floor_level.is_some() && args.window_points.as_deref().map(WindowPoint::parse).transpose()? != Some(WindowPoint::Sill) {
        return Err(Error::argument("--floor-level", "places the sill of --window-points sill: give --window-points sill with it"));
    }
    if let Some(other) = args.study.iter().find(|s| !WINDOW_STUDIES.contains(&s.as_str())) {
        return Err(Error::argument(
            "study",
            format!("'{other}' cannot run beside the window studies ({}): give it in a run of its own", WINDOW_STUDIES.join(", ")),
        ));
    }
    let names = args.study.join(", ");
    let en17037 = args.study.iter().any(|s| s == "en17037");
    let not_taken = [
        ("--period", args.period.is_some() && !en17037),
        ("--from", args.from.is_some()),
        ("--to", args.to.is_some()),
        ("--step", args.step.is_some()),
        ("--min-altitude", args.min_altitude.is_some() && !en17037),
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
        ("--window-widths", args.window_widths.is_some()),
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
    if en17037 && args.epw.is_none() && args.location.is_none() {
        return Err(Error::argument("--location", "en17037 needs the site (--location LAT,LON,TZ or --epw): its sun is the site's"));
    }
    if !args.before.is_empty() && args.points.is_none() && args.window_points.is_none() {
        return Err(Error::argument(
            "--before",
            "needs --points or --window-points: the existing and proposed scenes are compared at the same reference points",
        ));
    }
    Ok(())
}

/// gb50180's rule as the flags give it; `--window-width sill`'s sill lines are measured once the
/// points are placed ([`whole_window_of_each`]).
fn gb_rule(args: &MapArgs) -> Result<Gb50180Rule> {
    let width = args.window_width.as_deref().map(WholeWindow::parse).transpose()?.and_then(WholeWindow::width);
    Gb50180Rule::from_options(args.day.as_deref(), args.required_hours, args.min_period, args.max_periods, width)
}

/// Each window's own 满窗 sill: `--window-widths`' rows, or `--window-width sill`'s sill lines
/// measured from the windows at their sill points.
fn whole_window_of_each(args: &MapArgs, rule: &mut Gb50180Rule, scene: &Scene, points: &Points) -> Result<()> {
    if let Some(path) = &args.window_widths {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io { path: path.clone(), source })?;
        rule.window_widths = Some(sill_widths(scene, points, &path.display().to_string(), &text)?);
    }
    if args.window_width.as_deref().map(WholeWindow::parse).transpose()? == Some(WholeWindow::Sill) {
        let at = args.window_points.as_deref().map(WindowPoint::parse).transpose()?;
        rule.sill_lines = Some(sill_lines(scene, points, at, args.floor_level)?);
    }
    rule.check()
}

/// en17037's rule: `--period MM-DD` (one day, 1 February – 21 March) and `--min-altitude`.
fn en17037_rule(args: &MapArgs) -> Result<En17037Rule> {
    let day = args.period.as_deref().map(|text| parse_date("period", text)).transpose()?;
    En17037Rule::new(day, args.min_altitude)
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

pub(super) fn run(args: MapArgs) -> Result<()> {
    check_options(&args)?;
    let mut gb = args.study.iter().any(|s| s == "gb50180").then(|| gb_rule(&args)).transpose()?;
    let en17037 = args.study.iter().any(|s| s == "en17037").then(|| en17037_rule(&args)).transpose()?;
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
    if let Some(rule) = gb.as_mut() {
        whole_window_of_each(&args, rule, &scene, &points)?;
    }
    let masks = mask_rows(args.mask.as_deref(), points.len())?;
    let before = (!args.before.is_empty()).then(|| model::load(&args.before, &args.model.options())).transpose()?;
    let from = match (&args.points, &args.window_points) {
        (Some(path), _) => path.display().to_string(),
        (None, at) => format!("--window-points {}", at.as_deref().unwrap_or_default()),
    };
    let calendar = location.as_ref().map(|l| LeafCalendar::for_latitude(l.latitude));
    let site = location.as_ref().zip(calendar.as_ref()).map(|(location, calendar)| Site {
        location,
        calendar,
        weather: weather.as_ref(),
        sky: None,
    });
    // The parts' seconds, each since the last part ended (the existing scene's run follows the
    // proposed one's, so its index is timed from the proposed one's last study).
    let since = std::cell::Cell::new(Instant::now());
    let part = |seconds: &mut Vec<(String, f64)>, name: &str| {
        seconds.push((name.to_string(), since.get().elapsed().as_secs_f64()));
        since.set(Instant::now());
    };
    let (mut now_seconds, mut former_seconds) = (Vec::new(), Vec::new());
    let (now, former) = run::before_after(
        &args.study,
        &scene,
        &points,
        before.as_ref().map(|s| (s, from.as_str())),
        site,
        Rules { gb: gb.as_ref(), en17037: en17037.as_ref() },
        &mut |name| part(&mut now_seconds, name),
        &mut |name| part(&mut former_seconds, name),
    )?;
    let tables = compared_tables(&now, former.as_ref(), points.len(), gb.as_ref(), location.as_ref());

    let names = |paths: &[PathBuf]| paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>();
    let inputs = report_inputs(
        &names(&args.model.models),
        &names(&args.before),
        points_input(&args)?,
        location.as_ref(),
        args.epw.as_ref().map(|p| p.display().to_string()).as_deref(),
    );
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let columns = point_columns(&tables);
    let csv_columns: Vec<Column<'_>> = columns.iter().map(|(name, values)| Column { name, values, decimals: 4 }).collect();
    files.push((args.output.clone(), points_csv(&scene, &points, &csv_columns).into_bytes()));
    for t in &tables {
        files.push((args.study_path(&t.study, "json"), format!("{:#}\n", study_json(&scene, &points, t, inputs.clone())).into_bytes()));
        files.push((args.study_path(&t.study, "csv"), study_csv(&scene, &points, t).into_bytes()));
    }
    let svgs = mask_svgs(&scene, &points, &masks, location.as_ref(), gb.as_ref())?;
    for (i, svg) in &svgs {
        files.push((args.output.with_file_name(format!("{}.mask-{}.svg", stem(&args.output), i + 1)), svg.clone().into_bytes()));
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
        "points_before": former.as_ref().map(|f| f.points.len()),
        "seconds": round(seconds, 3),
        "seconds_by_part": {
            "load": round(load_seconds, 3),
            "proposed": now_seconds.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>(),
            "existing": former.as_ref().map(|_| former_seconds.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>()),
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

/// The points CSV's value columns, each study's values in order; a key an earlier study already
/// wrote (en17037's `hours` beside gb50180's) takes its study's name: `hours_en17037`.
fn point_columns(tables: &[sunlit::export::planning_report::StudyTable]) -> Vec<(String, Vec<f64>)> {
    let mut columns: Vec<(String, Vec<f64>)> = Vec::new();
    for t in tables {
        for (key, values) in &t.values {
            let name = if columns.iter().any(|(k, _)| k == key) { format!("{key}_{}", t.study) } else { key.clone() };
            columns.push((name, values.clone()));
        }
    }
    columns
}

/// How the points were given, for the reports: a file, the windows' own points, or a grid.
fn points_input(args: &MapArgs) -> Result<Value> {
    let window = args.window_points.as_deref().map(WindowPoint::parse).transpose()?;
    let file = args.points.as_ref().map(|p| p.display().to_string());
    Ok(match (window, file) {
        (None, None) => json!({"grid_spacing_m": args.grid.unwrap_or(0.5)}),
        (window, file) => planning_points_input(window, file.as_deref(), args.floor_level),
    })
}

fn stem(path: &std::path::Path) -> String {
    path.file_stem().map_or("map".into(), |s| s.to_string_lossy().into_owned())
}
