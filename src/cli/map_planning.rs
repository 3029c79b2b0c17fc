//! `sunlit map --study bre-vsc|bre-apsh|gb50180`: the window studies' edge. Checks which options
//! each study takes, reads the proposed scene (and with `--before` the existing one), runs the
//! library's studies ([`sunlit::map::planning`]) on both, and writes the points CSV (one value
//! column per study value), `POINTS.study-NAME.json`/`.csv`, the requested sky masks
//! (`POINTS.mask-N.svg`) and `--html`'s report, all at the end.

use serde_json::{Value, json};
use sunlit::export::planning_report::{StudyTable, SunPath, mask_svg, report_html, study_csv, study_json};
use sunlit::map::planning::compare::{self, Verdict};
use sunlit::map::planning::gb50180::{self, Gb50180Rule, StandardDay};
use sunlit::map::planning::{SceneRays, Windows, apsh, bre_lines, mask, vsc};
use sunlit::map::{Points, Site};
use sunlit::sun::weather::Weather;
use sunlit::year::season::LeafCalendar;

use super::*;

/// The window studies' names.
pub(super) const STUDIES: [&str; 5] = ["bre-vsc", "bre-apsh", "gb50180", "bre-25deg", "bre-45deg"];

/// Whether `args` ask for a window study (then [`run`] answers them).
pub(super) fn wanted(args: &MapArgs) -> bool {
    args.study.iter().any(|s| STUDIES.contains(&s.as_str()))
}

/// Refuses what the window studies do not take, naming the option.
fn check_options(args: &MapArgs) -> Result<()> {
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
    if let Some(model) = &args.sky_model {
        let vsc = args.study.iter().any(|s| s == "bre-vsc");
        if !vsc {
            return Err(Error::argument("--sky-model", format!("{names} counts the sun alone and takes no sky model")));
        }
        if model != "cie-overcast" {
            return Err(Error::argument(
                "--sky-model",
                format!("'{model}': bre-vsc is defined under the CIE standard overcast sky and takes only cie-overcast"),
            ));
        }
    }
    if args.study.iter().any(|s| s == "bre-apsh") && args.epw.is_none() {
        return Err(Error::argument(
            "--epw",
            "bre-apsh needs a weather file: its probable sunlight hours come from the hours' direct normal irradiance",
        ));
    }
    if gb && args.epw.is_none() && args.location.is_none() {
        return Err(Error::argument("--location", "gb50180 needs the site (--location LAT,LON,TZ or --epw): its sun is the latitude's"));
    }
    if !args.before.is_empty() && args.points.is_none() {
        return Err(Error::argument(
            "--before",
            "needs --points: the existing and proposed scenes are compared at the same reference points",
        ));
    }
    Ok(())
}

fn gb_rule(args: &MapArgs) -> Result<Gb50180Rule> {
    let day = StandardDay::parse(args.day.as_deref().unwrap_or("dahan"))?;
    let mut rule = Gb50180Rule::new(day);
    if let Some(h) = args.required_hours {
        rule.required_hours = h;
    }
    if let Some(m) = args.min_period {
        rule.min_period_minutes = m;
    }
    rule.max_periods = args.max_periods;
    rule.whole_window = args.window_width;
    rule.check()?;
    Ok(rule)
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

/// The existing scene's points: each of `points`' CSV rows that lies on one of its receivers,
/// and where it sits in `points`. Refuses a scene with none in common.
fn before_points(before: &Scene, path: &std::path::Path, text: &str, points: usize) -> Result<(Points, Vec<usize>)> {
    let all: Vec<u32> = (0..before.receivers.len() as u32).collect();
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header = lines.next().unwrap_or_default();
    let mut kept = Points::default();
    let mut index = Vec::new();
    for (i, line) in lines.enumerate().take(points) {
        // One row at a time: a row on no receiver of the existing scene is simply not in it.
        if let Ok(one) = sunlit::map::from_csv(before, &path.display().to_string(), &format!("{header}\n{line}\n"), &all) {
            kept.positions.extend_from_slice(&one.positions);
            kept.normals.extend_from_slice(&one.normals);
            kept.receivers.extend_from_slice(&one.receivers);
            index.push(i);
        }
    }
    if index.is_empty() {
        return Err(Error::argument("--before", format!("no point of {} lies on a receiver of the existing scene", path.display())));
    }
    Ok((kept, index))
}

/// One scene's values per study, in [`STUDIES`]' keys, and the seconds each took.
#[derive(Default)]
struct Values {
    vsc: Option<vsc::VscValues>,
    apsh: Option<apsh::ApshValues>,
    gb: Option<gb50180::Gb50180Values>,
    lines: Option<bre_lines::LineValues>,
    /// The studies asked for, in order.
    asked: Vec<String>,
    seconds: Vec<(String, f64)>,
}

fn evaluate(args: &MapArgs, scene: &Scene, points: &Points, site: Option<Site<'_>>, gb: Option<&Gb50180Rule>) -> Result<Values> {
    let start = Instant::now();
    // One tree for the scene; gb50180 places its own points (with its sill samples) on it, and
    // the BRE studies share these.
    let tree = SceneRays::new(scene);
    let windows = args.study.iter().any(|s| s == "bre-vsc" || s == "bre-apsh").then(|| Windows::on(scene, &tree, points)).transpose()?;
    let mut values =
        Values { seconds: vec![("index".into(), start.elapsed().as_secs_f64())], asked: args.study.clone(), ..Values::default() };
    for study in &args.study {
        let start = Instant::now();
        match (study.as_str(), &windows) {
            ("bre-vsc", Some(windows)) => values.vsc = Some(vsc::vsc(windows, &mut |_, _| {})),
            ("bre-25deg" | "bre-45deg", _) => {
                if values.lines.is_none() {
                    let positions: Vec<_> = (0..points.len()).map(|i| points.position(i)).collect();
                    let normals: Vec<_> = (0..points.len()).map(|i| points.normal(i)).collect();
                    values.lines = Some(bre_lines::evaluate(scene, &positions, &normals));
                }
            }
            ("bre-apsh", Some(windows)) => {
                let site = site.ok_or_else(|| Error::argument("--epw", "bre-apsh needs a weather file"))?;
                values.apsh = Some(apsh::apsh(windows, site, &mut |_, _| {})?);
            }
            _ => {
                let (site, rule) = site.zip(gb).ok_or_else(|| Error::argument("--location", "gb50180 needs the site"))?;
                values.gb = Some(gb50180::evaluate_on(scene, &tree, points, site.location, rule, &mut |_, _| {})?);
            }
        }
        values.seconds.push((study.clone(), start.elapsed().as_secs_f64()));
    }
    Ok(values)
}

/// 1.0 for true, 0.0 for false (the report's values are numbers).
fn zero_one(flags: &[bool]) -> Vec<f64> {
    flags.iter().map(|&f| if f { 1.0 } else { 0.0 }).collect()
}

/// Spreads the existing scene's values (at `index` of the proposed points) over all `n` points.
fn spread(values: &[f64], index: &[usize], n: usize) -> Vec<Option<f64>> {
    let mut out = vec![None; n];
    for (&i, &v) in index.iter().zip(values) {
        out[i] = Some(v);
    }
    out
}

fn tables(
    now: &Values,
    before: Option<(&Values, &[usize])>,
    n: usize,
    gb: Option<&Gb50180Rule>,
    location: Option<&Location>,
) -> Vec<StudyTable> {
    let mut out = Vec::new();
    if let Some(v) = &now.vsc {
        let former = before.and_then(|(b, index)| b.vsc.as_ref().map(|b| spread(&b.vsc, index, n)));
        let verdicts = (0..n).map(|i| compare::vsc(v.vsc[i], former.as_ref().and_then(|f| f[i]))).collect();
        out.push(StudyTable {
            study: "bre-vsc".into(),
            source: "BRE 209, 3rd ed. (2022), 2.2: vertical sky component at the window's reference point under the CIE standard overcast sky; a window keeps enough skylight at VSC ≥ 27 % or ≥ 0.8 × its former value".into(),
            rule: json!({
                "sky_model": "cie-overcast",
                "luminance": "L = Lz (1 + 2 sin γ)/3",
                "unobstructed_horizontal": "7π Lz/9",
                "target_percent": compare::VSC_TARGET,
                "former_ratio": compare::FORMER_RATIO,
                "sky_patches": format!("tregenza, each cut {0}×{0}", vsc::SUBDIVISION),
                "unobstructed_percent": v.unobstructed.first().map(|u| (u * 100.0).round() / 100.0),
            }),
            values: vec![("vsc".into(), v.vsc.clone())],
            before: former.map(|f| vec![f]),
            verdicts: vec![("passes".into(), verdicts)],
            assessed: None,
        });
    }
    if let Some(v) = &now.apsh {
        let former = before.and_then(|(b, index)| b.apsh.as_ref().map(|b| (spread(&b.apsh, index, n), spread(&b.wpsh, index, n))));
        let verdicts = (0..n).map(|i| compare::apsh(v.apsh[i], v.wpsh[i], former.as_ref().and_then(|(a, w)| a[i].zip(w[i])))).collect();
        out.push(StudyTable {
            study: "bre-apsh".into(),
            source: "BRE 209, 3rd ed. (2022), 3.2: annual and winter (21 Sep – 21 Mar) probable sunlight hours at the window's reference point, for windows facing within 90° of due south; enough at APSH ≥ 25 % with WPSH ≥ 5 %; affected only when below those, below 0.8 × the former value in either period, and losing over 4 points of APSH. Probable sunlight hours approximated from the EPW: hours with direct normal irradiance ≥ 120 W/m² (WMO sunshine threshold), not BRE's sunshine records".into(),
            rule: json!({
                "sunshine_threshold_w_m2": apsh::SUNSHINE_THRESHOLD,
                "annual_probable_hours": v.annual_hours,
                "winter_probable_hours": v.winter_hours,
                "winter": "09-21..03-21",
                "apsh_target_percent": compare::APSH_TARGET,
                "wpsh_target_percent": compare::WPSH_TARGET,
                "former_ratio": compare::FORMER_RATIO,
                "max_annual_loss_points": compare::APSH_LOSS,
                "approximation": "EPW hours with DNI ≥ 120 W/m² stand for BRE's probable sunlight hours",
            }),
            values: vec![("apsh".into(), v.apsh.clone()), ("wpsh".into(), v.wpsh.clone())],
            before: former.map(|(a, w)| vec![a, w]),
            verdicts: vec![("passes".into(), verdicts)],
            assessed: Some(v.assessed.clone()),
        });
    }
    if let Some(v) = &now.lines {
        let former = before
            .and_then(|(b, index)| b.lines.as_ref().map(|b| (spread(&b.angle_deg, index, n), spread(&zero_one(&b.within_45), index, n))));
        let line = |study: &str,
                    source: &str,
                    rule: Value,
                    key: &str,
                    values: Vec<f64>,
                    before: Option<Vec<Option<f64>>>,
                    verdicts: Vec<Verdict>| StudyTable {
            study: study.into(),
            source: source.into(),
            rule,
            values: vec![(key.into(), values)],
            before: before.map(|b| vec![b]),
            verdicts: vec![("passes".into(), verdicts)],
            assessed: None,
        };
        for study in [&"bre-25deg", &"bre-45deg"].into_iter().filter(|s| now.asked.iter().any(|a| a == *s)) {
            out.push(if *study == "bre-25deg" {
                line(
                    study,
                    "BRE 209, 3rd ed. (2022), 2.2.5: in the section perpendicular to the window wall, from the centre of the lowest window, a new development subtending more than 25° to the horizontal may affect the diffuse daylight (check the VSC)",
                    json!({"line_deg": bre_lines::LINE_25_DEG, "section": "vertical, through the point, along its normal's horizontal part", "reference_point": "the points given (BRE: the centre of the lowest window)"}),
                    "angle_deg",
                    v.angle_deg.clone(),
                    former.as_ref().map(|(a, _)| a.clone()),
                    v.angle_deg.iter().map(|&a| compare::line_25(a)).collect(),
                )
            } else {
                line(
                    study,
                    "BRE 209, 3rd ed. (2022), 2.2.16: for an extension beside the window, a window whose centre lies within 45° lines drawn on plan (from the extension's far end) and in elevation (down from its top) is likely to be affected",
                    json!({"line_deg": 45.0, "plan": "obstruction within 45° of the window's normal", "elevation": "obstruction above 45° lines up from the window's centre", "value": "1 within both lines, 0 not"}),
                    "within_45deg",
                    zero_one(&v.within_45),
                    former.as_ref().map(|(_, w)| w.clone()),
                    v.within_45.iter().map(|&w| compare::line_45(w)).collect(),
                )
            });
        }
    }
    if let (Some(v), Some(rule)) = (&now.gb, gb) {
        let former = before.and_then(|(b, index)| b.gb.as_ref().map(|b| spread(&b.hours, index, n)));
        let mut verdicts: Vec<(String, Vec<Verdict>)> =
            vec![("passes".into(), v.hours.iter().map(|&h| compare::hours(h, rule.required_hours)).collect())];
        let mut values = vec![("hours".into(), v.hours.clone())];
        let mut before_values = former.map(|f| vec![f]);
        if let Some(whole) = &v.whole_window_hours {
            verdicts.push(("passes_whole_window".into(), whole.iter().map(|&h| compare::hours(h, rule.required_hours)).collect()));
            values.push(("hours_whole_window".into(), whole.clone()));
            if let Some(b) = before_values.as_mut() {
                let former_whole =
                    before.and_then(|(b, index)| b.gb.as_ref().and_then(|g| g.whole_window_hours.as_ref()).map(|w| spread(w, index, n)));
                b.push(former_whole.unwrap_or_else(|| vec![None; n]));
            }
        }
        let (from, to) = rule.day.window();
        let clock = |h: f64| format!("{:02}:{:02}", (h * 60.0).round() as i64 / 60, (h * 60.0).round() as i64 % 60);
        let standard = location.map(|l| {
            let day = rule.day.day_of_year();
            json!({"from": clock(gb50180::standard_time(l, day, from)), "to": clock(gb50180::standard_time(l, day, to))})
        });
        out.push(StudyTable {
            study: "gb50180".into(),
            source: "GB 50180-2018, 4.0.9: sunlight hours at the ground-floor window sill on the standard day in true solar time (大寒日 8–16 h, 冬至日 9–15 h); table 4.0.9: 大寒日 ≥ 2 h or ≥ 3 h, 冬至日 ≥ 1 h; housing for the elderly ≥ 2 h on 冬至日; new dwellings in old districts ≥ 1 h on 大寒日".into(),
            rule: json!({
                "day": rule.day.chinese(),
                "day_name": rule.day.name(),
                "declination_deg": (rule.day.declination_deg() * 1e4).round() / 1e4,
                "ecliptic_longitude_deg": rule.day.ecliptic_longitude_deg(),
                "true_solar_window": [clock(from), clock(to)],
                "standard_time_window": standard,
                "required_hours": rule.required_hours,
                "min_period_minutes": rule.min_period_minutes,
                "max_periods": rule.max_periods,
                "whole_window_width_m": rule.whole_window,
                "step_minutes": gb50180::STEP_MINUTES,
            }),
            values,
            before: before_values,
            verdicts,
            assessed: None,
        });
    }
    out
}

/// Sun paths for a diagram at `location`: 21 June, 21 March and 21 December in sunlit's sun
/// (hour marks in local standard time), and GB 50180's standard day when it is studied.
fn sun_paths(location: &Location, gb: Option<&Gb50180Rule>) -> Vec<SunPath> {
    let mut paths: Vec<SunPath> = [("21 Jun", 172u32), ("21 Mar", 80), ("21 Dec", 355)]
        .iter()
        .map(|&(label, day)| {
            let at = |h: f64| sunlit::sun::position::sun_direction(location, sunlit::year::annual::shading_sun_day(day), h);
            SunPath {
                label: label.into(),
                line: (0..=24 * 12).map(|k| at(f64::from(k) / 12.0)).filter(|d| d.z > 0.0).collect(),
                marks: (0..=24).map(|h| (format!("{h:02}:00"), at(f64::from(h)))).filter(|(_, d)| d.z > 0.0).collect(),
                emphasis: false,
            }
        })
        .collect();
    if let Some(rule) = gb {
        let (from, to) = rule.day.window();
        let at = |h: f64| gb50180::sun_at_true_solar_time(location.latitude, rule.day.declination_deg(), h);
        paths.push(SunPath {
            label: format!("{} (true solar time)", rule.day.chinese()),
            line: (0..=((to - from) * 12.0) as u32).map(|k| at(from + f64::from(k) / 12.0)).filter(|d| d.z > 0.0).collect(),
            marks: (from as u32..=to as u32).map(|h| (format!("{h:02}:00 TST"), at(f64::from(h)))).filter(|(_, d)| d.z > 0.0).collect(),
            emphasis: true,
        });
    }
    paths
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
        let path = args.points.clone().unwrap_or_default();
        let text = std::fs::read_to_string(&path).map_err(|source| Error::Io { path: path.clone(), source })?;
        let (kept, index) = before_points(&scene, &path, &text, points.len())?;
        Some((scene, kept, index))
    };
    let calendar = location.as_ref().map(|l| LeafCalendar::for_latitude(l.latitude));
    let site = location.as_ref().zip(calendar.as_ref()).map(|(location, calendar)| Site {
        location,
        calendar,
        weather: weather.as_ref(),
        sky: None,
    });
    let now = evaluate(&args, &scene, &points, site, gb.as_ref())?;
    let former = before.as_ref().map(|(s, p, _)| evaluate(&args, s, p, site, gb.as_ref())).transpose()?;
    let tables = tables(
        &now,
        former.as_ref().zip(before.as_ref()).map(|(v, (_, _, index))| (v, index.as_slice())),
        points.len(),
        gb.as_ref(),
        location.as_ref(),
    );

    let inputs = json!({
        "models": args.model.models,
        "before": args.before,
        "points": args.points.as_ref().map_or(json!({"grid_spacing_m": args.grid.unwrap_or(0.5)}), |p| json!({"file": p})),
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
            "proposed": now.seconds.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>(),
            "existing": former.as_ref().map(|f| f.seconds.iter().map(|(k, v)| (k.clone(), json!(round(*v, 3)))).collect::<serde_json::Map<_, _>>()),
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
