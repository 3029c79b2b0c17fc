//! A map's tables: the points CSV (`receiver,x,y,z,nx,ny,nz` then the values) and a study's
//! report as JSON and CSV (the rule, its inputs, per point and per area results).
//!
//! A period's value columns ([`value_columns`]) are `sun_hours`, then with weather
//! `direct_kwh_m2`, then with the points' sky views `sky_diffuse_kwh_m2`,
//! `ground_reflected_kwh_m2`, `total_kwh_m2` and `sky_view_factor` (the per-surface summary's
//! names, [`crate::export::irradiation::SUMMARY_CSV_HEADER`]).

use std::fmt::Write;

use serde_json::{Value, json};

use crate::map::study::StudyResult;
use crate::map::{MapValues, Points};
use crate::scene::Scene;
use crate::year::samples::month_day;

/// One named column of per point values, and the decimals it is written with.
pub struct Column<'a> {
    /// Header name (`sun_hours`, `direct_kwh_m2`, `lit`).
    pub name: &'a str,
    /// One value per point.
    pub values: &'a [f64],
    /// Decimals written.
    pub decimals: usize,
}

/// An inside instant's value columns ([`crate::map::inside::InsideInstant`]): `lit`, then the
/// glass's solar and visible weights.
pub fn inside_instant_columns(values: &crate::map::inside::InsideInstant) -> [Column<'_>; 3] {
    [
        Column { name: "lit", values: &values.lit, decimals: 0 },
        Column { name: "solar_transmittance", values: &values.solar_transmittance, decimals: 4 },
        Column { name: "visible_transmittance", values: &values.visible_transmittance, decimals: 4 },
    ]
}

/// An inside period's value columns ([`crate::map::inside::InsideValues`]): `sun_hours`, then
/// with weather `beam_kwh_m2` and `direct_klux_h`.
pub fn inside_period_columns(values: &crate::map::inside::InsideValues) -> Vec<Column<'_>> {
    let mut columns = vec![Column { name: "sun_hours", values: &values.sun_hours, decimals: 4 }];
    if let (Some(b), Some(l)) = (&values.beam_kwh_m2, &values.direct_klux_h) {
        columns.push(Column { name: "beam_kwh_m2", values: b, decimals: 4 });
        columns.push(Column { name: "direct_klux_h", values: l, decimals: 4 });
    }
    columns
}

/// What an inside period's map glb is coloured by (name, unit, values): the beam through the
/// glass where the weather gives it, else the sun hours.
pub fn inside_period_shown(values: &crate::map::inside::InsideValues) -> (&'static str, &'static str, &[f64]) {
    match &values.beam_kwh_m2 {
        Some(b) => ("beam_kwh_m2", "kWh/m²", b),
        None => ("sun_hours", "h", &values.sun_hours),
    }
}

/// LEED ASE's value column ([`crate::map::inside::AseResult`]): occupied hours over 1,000 lux.
pub fn ase_column(result: &crate::map::inside::AseResult) -> Column<'_> {
    Column { name: "hours_over_1000_lux", values: &result.hours, decimals: 1 }
}

/// A period's sums as the points CSV's value columns, in the order the module doc gives.
pub fn value_columns(values: &MapValues) -> Vec<Column<'_>> {
    let mut columns = vec![Column { name: "sun_hours", values: &values.sun_hours, decimals: 4 }];
    let energy = [
        ("direct_kwh_m2", &values.direct_kwh_m2),
        ("sky_diffuse_kwh_m2", &values.sky_diffuse_kwh_m2),
        ("ground_reflected_kwh_m2", &values.ground_reflected_kwh_m2),
        ("total_kwh_m2", &values.total_kwh_m2),
    ];
    for (name, v) in energy {
        if let Some(v) = v {
            columns.push(Column { name, values: v, decimals: 4 });
        }
    }
    if let Some(v) = &values.sky_view_factor {
        columns.push(Column { name: "sky_view_factor", values: v, decimals: 6 });
    }
    columns
}

/// The points CSV: `receiver,x,y,z,nx,ny,nz` then `columns`, one row per point in order.
pub fn points_csv(scene: &Scene, points: &Points, columns: &[Column<'_>]) -> String {
    let mut out = String::with_capacity(80 * points.len() + 64);
    out.push_str("receiver,x,y,z,nx,ny,nz");
    for c in columns {
        out.push(',');
        out.push_str(c.name);
    }
    out.push('\n');
    for i in 0..points.len() {
        let name = scene.receivers.get(points.receivers[i] as usize).map_or("", |r| r.name.as_str());
        out.push_str(&csv_field(name));
        for v in &points.positions[3 * i..3 * i + 3] {
            push_fixed(&mut out, f64::from(*v), 4);
        }
        for v in &points.normals[3 * i..3 * i + 3] {
            push_fixed(&mut out, f64::from(*v), 5);
        }
        for c in columns {
            push_fixed(&mut out, c.values.get(i).copied().unwrap_or(f64::NAN), c.decimals);
        }
        out.push('\n');
    }
    out
}

/// `,v` at `decimals` places, never `-0.000` (a mirrored normal's −0, or a tiny negative that
/// rounds to zero, prints as 0).
fn push_fixed(out: &mut String, v: f64, decimals: usize) {
    let text = format!("{v:.decimals$}");
    out.push(',');
    match text.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => out.push_str(rest),
        _ => out.push_str(&text),
    }
}

/// A CSV field, quoted when it holds a comma, quote or line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}

fn date(day: u32) -> String {
    let (m, d) = month_day(day);
    format!("{m:02}-{d:02}")
}

/// A study's report as JSON: the rule and its source, the inputs (`inputs`, as the caller states
/// them), per area results and per point hours with levels.
pub fn study_json(scene: &Scene, points: &Points, study: &StudyResult, inputs: Value) -> Value {
    let rule = &study.rule;
    let name = |r: u32| scene.receivers.get(r as usize).map_or(String::new(), |x| x.name.clone());
    json!({
        "study": rule.name,
        "source": rule.source,
        "rule": {
            "day": date(study.day),
            "min_altitude_deg": rule.min_altitude_deg,
            "min_period_minutes": rule.min_period_minutes,
            "longest_periods": rule.longest,
            "levels": rule.levels.iter().map(|(n, h)| json!({"level": n, "hours": h})).collect::<Vec<_>>(),
            "area_share": rule.share,
        },
        "inputs": inputs,
        "areas": study.areas.iter().map(|a| json!({
            "receiver": name(a.receiver),
            "points": a.points,
            "shares": rule.levels.iter().zip(&a.shares).map(|((n, _), s)| json!({"level": n, "share": s})).collect::<Vec<_>>(),
            "passes": a.passes,
        })).collect::<Vec<_>>(),
        "points": (0..points.len()).map(|i| json!({
            "receiver": name(points.receivers[i]),
            "position": &points.positions[3 * i..3 * i + 3],
            "hours": study.hours[i],
            "level": rule.level(study.hours[i]),
        })).collect::<Vec<_>>(),
    })
}

/// A study's report as CSV: `#` lines with the rule, then one row per area
/// (`area,receiver,points,share_<level>...,passes`) and one per point
/// (`point,receiver,x,y,z,hours,level`).
pub fn study_csv(scene: &Scene, points: &Points, study: &StudyResult) -> String {
    let rule = &study.rule;
    let name = |r: u32| scene.receivers.get(r as usize).map_or(String::new(), |x| csv_field(&x.name));
    let mut out = String::new();
    let _ = writeln!(out, "# study {}: {}", rule.name, rule.source);
    let _ = writeln!(
        out,
        "# day {}, sun above {}°, periods of at least {} min, longest {}, area passes when {} of its points reach {} h",
        date(study.day),
        rule.min_altitude_deg,
        rule.min_period_minutes,
        rule.longest.map_or("all".to_string(), |n| n.to_string()),
        rule.share,
        rule.levels.first().map_or(0.0, |l| l.1)
    );
    out.push_str("kind,receiver,points_or_x,y,z,hours_or_passes");
    for (n, _) in &rule.levels {
        let _ = write!(out, ",share_{n}");
    }
    out.push_str(",level\n");
    for a in &study.areas {
        let _ = write!(out, "area,{},{},,,{}", name(a.receiver), a.points, a.passes);
        for s in &a.shares {
            let _ = write!(out, ",{s:.4}");
        }
        out.push_str(",\n");
    }
    for i in 0..points.len() {
        let p = &points.positions[3 * i..3 * i + 3];
        let _ = write!(out, "point,{},{:.4},{:.4},{:.4},{:.4}", name(points.receivers[i]), p[0], p[1], p[2], study.hours[i]);
        for _ in &rule.levels {
            out.push(',');
        }
        let _ = writeln!(out, ",{}", rule.level(study.hours[i]).unwrap_or("none"));
    }
    out
}
