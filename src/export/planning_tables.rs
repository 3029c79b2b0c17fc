//! The window studies' tables for their reports ([`StudyTable`]): each rule's source in words,
//! every parameter, the values per point, with an existing scene its values and BRE's relative
//! tests; the sun paths drawn on the sky masks, and the masks themselves; and the inputs a
//! report states. The rules' texts live here, once, for every edge that reports a study, so the
//! CLI's report and the page's are the same bytes.

use serde_json::{Value, json};

use super::planning_report::{StudyTable, SunPath, mask_svg};
use crate::error::{Error, Result};
use crate::map::Points;
use crate::map::planning::compare::{self, Verdict};
use crate::map::planning::gb50180::{self, Gb50180Rule};
use crate::map::planning::run::{Former, StudyValues};
use crate::map::planning::window_points::{OFFSET, SILL_HEIGHT, WindowPoint};
use crate::map::planning::{apsh, bre_lines, en17037, mask, vsc};
use crate::scene::Scene;
use crate::sun::location::Location;

/// How gb50180's 满窗 rule takes each window's sill from its geometry, as the report states it.
pub const SILL_LINE_RULE: &str = "each window's own sill line, from its geometry: its lowest edge (the vertices within 1 mm of its lowest height, from the leftmost to the rightmost along the wall), or with a ground-floor level where the window reaches below the sill height, its chord at that height; sampled from end to end every 0.1 m or less, a minute counting only when every sample sees the sun";

/// 1.0 for true, 0.0 for false (the report's values are numbers).
pub fn zero_one(flags: &[bool]) -> Vec<f64> {
    flags.iter().map(|&f| if f { 1.0 } else { 0.0 }).collect()
}

/// Spreads the existing scene's values (at `index` of the proposed points) over all `n` points.
pub fn spread(values: &[f64], index: &[usize], n: usize) -> Vec<Option<f64>> {
    let mut out = vec![None; n];
    for (&i, &v) in index.iter().zip(values) {
        out[i] = Some(v);
    }
    out
}

/// Each study's table of `now` (the proposed scene's values at `n` points), beside `before`'s
/// (the existing scene's, at `index` of the points) when given: the rule's source and every
/// parameter (gb50180's `gb` rule; its window in standard time at `location`), the values, the
/// former values, and the verdicts, in the order the studies were asked.
pub fn tables(
    now: &StudyValues,
    before: Option<(&StudyValues, &[usize])>,
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
                let source = "BRE 209, 3rd ed. (2022), 2.2.5: in the section perpendicular to the window wall, from the centre of the lowest window, a new development subtending more than 25° to the horizontal may affect the diffuse daylight (check the VSC)";
                let rule = json!({
                    "line_deg": bre_lines::LINE_25_DEG,
                    "section": "vertical, through the point, along its normal's horizontal part",
                    "reference_point": "the points given (BRE: the centre of the lowest window)",
                    "development": if v.development_deg.is_some() {
                        "the proposed scene's triangles the existing scene lacks (corners matched within 1 mm): the window's own building, its overhangs and fins, stands in both and is not the development; angle_deg_all is everything in the section"
                    } else {
                        "everything in the section: without an existing scene to compare with, the window's own building cannot be told from the development"
                    },
                });
                match &v.development_deg {
                    // The development did not exist before: it subtended nothing at the points
                    // the existing scene holds.
                    Some(dev) => StudyTable {
                        study: study.to_string(),
                        source: source.into(),
                        rule,
                        values: vec![("angle_deg".into(), dev.clone()), ("angle_deg_all".into(), v.angle_deg.clone())],
                        before: before.map(|(_, index)| vec![spread(&vec![0.0; index.len()], index, n)]).map(|mut b| {
                            b.push(former.as_ref().map_or_else(|| vec![None; n], |(a, _)| a.clone()));
                            b
                        }),
                        verdicts: vec![("passes".into(), dev.iter().map(|&a| compare::line_25(a)).collect())],
                        assessed: None,
                    },
                    None => line(
                        study,
                        source,
                        rule,
                        "angle_deg",
                        v.angle_deg.clone(),
                        former.as_ref().map(|(a, _)| a.clone()),
                        v.angle_deg.iter().map(|&a| compare::line_25(a)).collect(),
                    ),
                }
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
        let mut rule_json = json!({
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
        });
        // Each window's own width, per point in order, only where each has one (the reports
        // stay as they were with one width); measured sills to the 0.1 mm.
        if let Some(widths) = rule.own_widths() {
            rule_json["whole_window_widths_m"] = json!(widths.iter().map(|w| (w * 1e4).round() / 1e4).collect::<Vec<_>>());
        }
        if rule.sill_lines.is_some() {
            rule_json["whole_window_sill"] = json!(SILL_LINE_RULE);
        }
        out.push(StudyTable {
            study: "gb50180".into(),
            source: "GB 50180-2018, 4.0.9: sunlight hours at the ground-floor window sill on the standard day in true solar time (大寒日 8–16 h, 冬至日 9–15 h); table 4.0.9: 大寒日 ≥ 2 h or ≥ 3 h, 冬至日 ≥ 1 h; housing for the elderly ≥ 2 h on 冬至日; new dwellings in old districts ≥ 1 h on 大寒日".into(),
            rule: rule_json,
            values,
            before: before_values,
            verdicts,
            assessed: None,
        });
    }
    if let Some(v) = &now.en17037 {
        out.push(en17037_table(v, before.and_then(|(b, index)| b.en17037.as_ref().map(|b| spread(&b.hours, index, n)))));
    }
    out
}

/// EN 17037's table: `hours`, and a verdict per level (`passes` the minimum, `passes_medium`,
/// `passes_high`); the standard has no relative test.
fn en17037_table(v: &en17037::En17037Values, former: Option<Vec<Option<f64>>>) -> StudyTable {
    let rule = v.rule.sun_rule();
    let verdicts = rule
        .levels
        .iter()
        .enumerate()
        .map(|(k, (name, need))| {
            let key = if k == 0 { "passes".to_string() } else { format!("passes_{name}") };
            (key, v.hours.iter().map(|&h| compare::hours(h, *need)).collect())
        })
        .collect();
    let (month, day) = crate::year::samples::month_day(v.rule.day);
    StudyTable {
        study: "en17037".into(),
        source: "EN 17037:2018 (+A1:2021), 5.4 and Annex A.6: exposure to sunlight at the window's reference point on one day from 1 February to 21 March, the sun counted at or above a minimum altitude; minimum 1.5 h, medium 3 h, high 4 h".into(),
        rule: json!({
            "day": format!("{month:02}-{day:02}"),
            "levels_hours": rule.levels.iter().map(|(name, h)| (name.clone(), json!(h))).collect::<serde_json::Map<_, _>>(),
            "min_altitude_deg": v.rule.min_altitude_deg,
            "min_altitude_source": "a parameter (default 10°): EN 17037 tabulates it by site; give your national annex's value",
            "time": "every minute of the day, local standard time; sunlit's sun (EnergyPlus's)",
            "step_minutes": en17037::STEP_MINUTES,
        }),
        values: vec![("hours".into(), v.hours.clone())],
        before: former.map(|f| vec![f]),
        verdicts,
        assessed: None,
    }
}

/// Sun paths for a diagram at `location`: 21 June, 21 March and 21 December in sunlit's sun
/// (hour marks in local standard time), and GB 50180's standard day when it is studied.
pub fn sun_paths(location: &Location, gb: Option<&Gb50180Rule>) -> Vec<SunPath> {
    let mut paths: Vec<SunPath> = [("21 Jun", 172u32), ("21 Mar", 80), ("21 Dec", 355)]
        .iter()
        .map(|&(label, day)| {
            let at = |h: f64| crate::sun::position::sun_direction(location, crate::year::annual::shading_sun_day(day), h);
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

/// [`tables`] of a [`crate::map::planning::run::before_after`] run: the proposed values at `n`
/// points beside the existing scene's, if any.
pub fn compared_tables(
    now: &StudyValues,
    former: Option<&Former>,
    n: usize,
    gb: Option<&Gb50180Rule>,
    location: Option<&Location>,
) -> Vec<StudyTable> {
    tables(now, former.map(|f| (&f.values, f.index.as_slice())), n, gb, location)
}

/// The sky mask diagrams (SVG) of `points` at `rows` (0-based), each titled with its 1-based
/// row and position, the sun paths drawn at `location` (none without a site). Refuses a row
/// outside the points, naming `masks`.
pub fn mask_svgs(
    scene: &Scene,
    points: &Points,
    rows: &[usize],
    location: Option<&Location>,
    gb: Option<&Gb50180Rule>,
) -> Result<Vec<(usize, String)>> {
    if let Some(&row) = rows.iter().find(|&&r| r >= points.len()) {
        return Err(Error::argument("masks", format!("row {} is not a point row 1..={}", row + 1, points.len())));
    }
    if rows.is_empty() {
        return Ok(Vec::new());
    }
    let mut chosen = Points::default();
    for &i in rows {
        chosen.positions.extend_from_slice(&points.positions[3 * i..3 * i + 3]);
        chosen.normals.extend_from_slice(&points.normals[3 * i..3 * i + 3]);
        chosen.receivers.push(points.receivers[i]);
    }
    let paths = location.map(|l| sun_paths(l, gb)).unwrap_or_default();
    Ok(rows
        .iter()
        .zip(mask::sky_masks(scene, &chosen)?)
        .map(|(&i, m)| {
            let p = points.position(i);
            (i, mask_svg(&format!("point {} at ({:.2}, {:.2}, {:.2})", i + 1, p.x, p.y, p.z), &m, &paths))
        })
        .collect())
}

/// How a report states its points: one on each window (`window_points`, what it is, its offset
/// out of the window, and the ground floor's level its sills were raised above with the sill
/// height, where one was given), or from a file.
pub fn points_input(window: Option<WindowPoint>, file: Option<&str>, floor_level: Option<f64>) -> Value {
    let mut input = match (window, file) {
        (Some(at), _) => json!({"window_points": at.name(), "at": at.describe(), "offset_m": OFFSET}),
        (None, Some(file)) => json!({"file": file}),
        (None, None) => return Value::Null,
    };
    if let Some(floor) = floor_level {
        input["floor_level_m"] = json!(floor);
        input["sill_height_m"] = json!(SILL_HEIGHT);
    }
    input
}

/// A report's inputs: the proposed and existing models (as their files are named), the points
/// ([`points_input`], or a grid's), the site and the EPW's name.
pub fn report_inputs(models: &[String], before: &[String], points: Value, location: Option<&Location>, epw: Option<&str>) -> Value {
    json!({
        "models": models,
        "before": before,
        "points": points,
        "site": location.map(|l| json!({"latitude": l.latitude, "longitude": l.longitude, "time_zone": l.time_zone})),
        "epw": epw,
    })
}
