//! A window study's report ([`crate::map::planning`]): JSON and CSV tables, each point's sky
//! mask as a stereographic sun-path diagram (SVG), and one self-contained HTML page holding the
//! tables with pass/fail, the masks, and the rules' text and parameters.
//!
//! The JSON keeps the shape of the sun-hours studies' reports ([`super::map_table::study_json`]):
//! `study`, `source`, `rule`, `inputs`, `areas` (per receiver: points, how many pass, whether all
//! do), `points` (in the input's order, one per input row): `receiver`, `position`, `normal`, the
//! study's numeric values (`vsc`, `apsh`, `wpsh` in %, `hours`), with an existing scene their
//! `*_before` (null where the point is not in it) and `*_ratio`, and the verdicts in separate keys
//! (`passes`, `passes_absolute`, `passes_relative`, …).

use std::f64::consts::FRAC_PI_4;
use std::fmt::Write;

use glam::DVec3;
use serde_json::{Value, json};

use crate::map::Points;
use crate::map::planning::compare::{Verdict, ratio};
use crate::map::planning::mask::{ALTITUDE_STEP, AZIMUTH_STEP, Cell, SkyMask};
use crate::scene::Scene;

/// One window study's per point results, ready to write.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyTable {
    /// The study's name (`bre-vsc`, `bre-apsh`, `gb50180`).
    pub study: String,
    /// The rule and its source, in words.
    pub source: String,
    /// The rule's parameters as stated in the report.
    pub rule: Value,
    /// The value keys and their per point values (`vsc`; `apsh`, `wpsh`; `hours`, …).
    pub values: Vec<(String, Vec<f64>)>,
    /// Per value key, per point the existing scene's value (`None`: the point is not in it);
    /// `None` without an existing scene.
    pub before: Option<Vec<Vec<Option<f64>>>>,
    /// Verdict keys (`passes`, `passes_whole_window`) and their per point verdicts; the first
    /// is the study's.
    pub verdicts: Vec<(String, Vec<Verdict>)>,
    /// Per point whether the rule assesses it (`None`: every point).
    pub assessed: Option<Vec<bool>>,
}

impl StudyTable {
    /// Whether point `i` passes (`None` when the rule does not assess it).
    pub fn passes(&self, i: usize) -> Option<bool> {
        if self.assessed.as_ref().is_some_and(|a| !a[i]) {
            return None;
        }
        self.verdicts.first().map(|(_, v)| v[i].passes)
    }
}

fn name_of(scene: &Scene, r: u32) -> String {
    scene.receivers.get(r as usize).map_or(String::new(), |x| x.name.clone())
}

/// The report as JSON (see the module doc); `inputs` as the caller states them.
pub fn study_json(scene: &Scene, points: &Points, table: &StudyTable, inputs: Value) -> Value {
    let mut ids: Vec<u32> = points.receivers.clone();
    ids.sort_unstable();
    ids.dedup();
    let areas: Vec<Value> = ids
        .iter()
        .map(|&r| {
            let mine: Vec<usize> = (0..points.len()).filter(|&i| points.receivers[i] == r).collect();
            let judged: Vec<bool> = mine.iter().filter_map(|&i| table.passes(i)).collect();
            json!({
                "receiver": name_of(scene, r),
                "points": mine.len(),
                "assessed": judged.len(),
                "passing": judged.iter().filter(|&&p| p).count(),
                "passes": judged.iter().all(|&p| p),
            })
        })
        .collect();
    let rows: Vec<Value> = (0..points.len()).map(|i| point_json(scene, points, table, i)).collect();
    json!({"study": table.study, "source": table.source, "rule": table.rule, "inputs": inputs, "areas": areas, "points": rows})
}

fn point_json(scene: &Scene, points: &Points, table: &StudyTable, i: usize) -> Value {
    let mut row = json!({
        "receiver": name_of(scene, points.receivers[i]),
        "position": &points.positions[3 * i..3 * i + 3],
        "normal": &points.normals[3 * i..3 * i + 3],
    });
    for (k, (key, values)) in table.values.iter().enumerate() {
        row[key] = json!(round(values[i]));
        if let Some(before) = &table.before {
            let b = before[k][i];
            row[format!("{key}_before")] = json!(b.map(round));
            row[format!("{key}_ratio")] = json!(ratio(values[i], b).map(|r| (r * 1e4).round() / 1e4));
        }
    }
    if let Some(a) = &table.assessed {
        row["assessed"] = json!(a[i]);
    }
    for (k, (key, verdicts)) in table.verdicts.iter().enumerate() {
        let judged = table.assessed.as_ref().is_none_or(|a| a[i]);
        let v = verdicts[i];
        row[key] = if judged { json!(v.passes) } else { Value::Null };
        if k == 0 {
            row[format!("{key}_absolute")] = json!(v.absolute);
            row[format!("{key}_relative")] = json!(v.relative);
        }
    }
    row
}

/// Four decimals, and never `-0`.
fn round(x: f64) -> f64 {
    let r = (x * 1e4).round() / 1e4;
    if r == 0.0 { 0.0 } else { r }
}

/// The report as CSV: `#` lines with the rule, then `receiver,x,y,z,` the values (and their
/// `_before`), the verdicts.
pub fn study_csv(scene: &Scene, points: &Points, table: &StudyTable) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# study {}: {}", table.study, table.source);
    let _ = writeln!(out, "# rule {}", table.rule);
    out.push_str("receiver,x,y,z");
    for (key, _) in &table.values {
        let _ = write!(out, ",{key}");
        if table.before.is_some() {
            let _ = write!(out, ",{key}_before");
        }
    }
    for (key, _) in &table.verdicts {
        let _ = write!(out, ",{key}");
    }
    out.push('\n');
    for i in 0..points.len() {
        let name = name_of(scene, points.receivers[i]);
        let quoted = if name.contains([',', '"', '\n']) { format!("\"{}\"", name.replace('"', "\"\"")) } else { name };
        let p = &points.positions[3 * i..3 * i + 3];
        let _ = write!(out, "{quoted},{:.4},{:.4},{:.4}", p[0], p[1], p[2]);
        for (k, (_, values)) in table.values.iter().enumerate() {
            let _ = write!(out, ",{}", round(values[i]));
            if let Some(before) = &table.before {
                let _ = write!(out, ",{}", before[k][i].map_or(String::new(), |b| round(b).to_string()));
            }
        }
        let judged = table.assessed.as_ref().is_none_or(|a| a[i]);
        for (_, verdicts) in &table.verdicts {
            let _ = write!(out, ",{}", if judged { verdicts[i].passes.to_string() } else { "not-assessed".into() });
        }
        out.push('\n');
    }
    out
}

/// A sun path to draw on a diagram: its label and the sun's directions along it (sun up only),
/// with hour marks (label, direction).
#[derive(Debug, Clone, PartialEq)]
pub struct SunPath {
    /// E.g. `21 Jun`.
    pub label: String,
    /// Directions along the path, in time order.
    pub line: Vec<DVec3>,
    /// Hour marks.
    pub marks: Vec<(String, DVec3)>,
    /// Drawn emphasised (the study's own day).
    pub emphasis: bool,
}

/// Diagram radius in SVG units.
const RADIUS: f64 = 200.0;
const CENTRE: f64 = 230.0;

/// The stereographic projection (zenith at the centre, horizon on the circle, north up, east
/// right): r = R · tan((90° − altitude)/2), which keeps circles circles.
fn project(altitude: f64, azimuth: f64) -> (f64, f64) {
    let r = RADIUS * (FRAC_PI_4 - altitude / 2.0).tan();
    (CENTRE + r * azimuth.sin(), CENTRE - r * azimuth.cos())
}

fn project_direction(d: DVec3) -> (f64, f64) {
    project(d.z.clamp(-1.0, 1.0).asin(), d.x.atan2(d.y))
}

/// A point's sky mask and sun paths as a stereographic sun-path diagram (SVG): obstructed sky in
/// dark grey, the sky behind the point's own plane hatched light grey, altitude rings every 30°,
/// sun paths with hour marks.
pub fn mask_svg(title: &str, mask: &SkyMask, paths: &[SunPath]) -> String {
    let size = 2.0 * CENTRE;
    let mut out = String::new();
    let _ = write!(
        out,
        r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {size} {h}" width="{size}" height="{h}" font-family="sans-serif" font-size="11">"##,
        h = size + 30.0
    );
    let _ = write!(out, "<title>{}</title>", escape(title));
    let _ = write!(out, r##"<circle cx="{CENTRE}" cy="{CENTRE}" r="{RADIUS}" fill="#dff0ff" stroke="#333"/>"##);
    for (state, fill) in [(Cell::Behind, "#e4e4e4"), (Cell::Obstructed, "#555")] {
        let _ = write!(out, r#"<path fill="{fill}" stroke="none" d=""#);
        for r in 0..mask.rows {
            let mut c = 0;
            while c < mask.columns {
                if mask.cell(r, c) != state {
                    c += 1;
                    continue;
                }
                let start = c;
                while c < mask.columns && mask.cell(r, c) == state {
                    c += 1;
                }
                out.push_str(&cell_run(r, start, c));
            }
        }
        out.push_str(r#""/>"#);
    }
    for altitude in [30.0f64, 60.0] {
        let (_, y) = project(altitude.to_radians(), 0.0);
        let _ = write!(
            out,
            r##"<circle cx="{CENTRE}" cy="{CENTRE}" r="{:.1}" fill="none" stroke="#888" stroke-dasharray="3 3"/>"##,
            CENTRE - y
        );
        let _ = write!(out, r##"<text x="{:.1}" y="{:.1}" fill="#666">{altitude}°</text>"##, CENTRE + 2.0, y - 2.0);
    }
    for (label, az) in [("N", 0.0f64), ("E", 90.0), ("S", 180.0), ("W", 270.0)] {
        let (x, y) = project(-0.12, az.to_radians());
        let _ = write!(out, r#"<text x="{x:.1}" y="{y:.1}" text-anchor="middle" dominant-baseline="middle">{label}</text>"#);
    }
    for path in paths {
        let colour = if path.emphasis { "#d00" } else { "#e80" };
        let points: Vec<String> = path.line.iter().map(|&d| project_direction(d)).map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        if points.len() > 1 {
            let _ = write!(
                out,
                r#"<polyline fill="none" stroke="{colour}" stroke-width="{}" points="{}"/>"#,
                if path.emphasis { 2.5 } else { 1.5 },
                points.join(" ")
            );
        }
        for (label, d) in &path.marks {
            let (x, y) = project_direction(*d);
            let _ = write!(
                out,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="2.5" fill="{colour}"><title>{} {}</title></circle>"#,
                escape(&path.label),
                escape(label)
            );
        }
        if let Some(&last) = path.line.last() {
            let (x, y) = project_direction(last);
            let _ = write!(out, r#"<text x="{x:.1}" y="{:.1}" fill="{colour}">{}</text>"#, y + 12.0, escape(&path.label));
        }
    }
    let _ = write!(out, r#"<text x="10" y="{:.1}">{}</text></svg>"#, size + 20.0, escape(title));
    out
}

/// One run of cells of a row (columns `a..b`) as a closed path: the two arcs of altitude as
/// polylines (each cell's corners), joined.
fn cell_run(row: usize, a: usize, b: usize) -> String {
    let (lo, hi) = ((row as f64 * ALTITUDE_STEP).to_radians(), ((row + 1) as f64 * ALTITUDE_STEP).to_radians());
    let az = |c: usize| (c as f64 * AZIMUTH_STEP).to_radians();
    let mut d = String::new();
    for (k, c) in (a..=b).enumerate() {
        let (x, y) = project(lo, az(c));
        let _ = write!(d, "{}{x:.1} {y:.1}", if k == 0 { "M" } else { "L" });
    }
    for c in (a..=b).rev() {
        let (x, y) = project(hi, az(c));
        let _ = write!(d, "L{x:.1} {y:.1}");
    }
    d.push('Z');
    d
}

/// Text for HTML and SVG.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A self-contained HTML report: per study its rule (source and parameters) and a table of the
/// points with their values and pass/fail (coloured), then the requested points' diagrams.
pub fn report_html(scene: &Scene, points: &Points, tables: &[StudyTable], masks: &[(usize, String)], inputs: &Value) -> String {
    let mut out = String::from(
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>sunlit window studies</title><style>\
         body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}\
         td.pass{background:#c8f0c8}td.fail{background:#f6c0c0}td.na{background:#eee}pre{background:#f6f6f6;padding:.5em;white-space:pre-wrap}\
         figure{display:inline-block;margin:.5em}</style></head><body><h1>Window studies</h1>",
    );
    let _ = write!(out, "<h2>Inputs</h2><pre>{}</pre>", escape(&format!("{inputs:#}")));
    for t in tables {
        let _ = write!(out, "<h2>{}</h2><p>{}</p><pre>{}</pre>", escape(&t.study), escape(&t.source), escape(&format!("{:#}", t.rule)));
        out.push_str("<table><tr><th>#</th><th>receiver</th><th>x</th><th>y</th><th>z</th>");
        for (key, _) in &t.values {
            let _ = write!(out, "<th>{}</th>", escape(key));
            if t.before.is_some() {
                let _ = write!(out, "<th>{} before</th><th>ratio</th>", escape(key));
            }
        }
        for (key, _) in &t.verdicts {
            let _ = write!(out, "<th>{}</th>", escape(key));
        }
        out.push_str("</tr>");
        for i in 0..points.len() {
            let p = &points.positions[3 * i..3 * i + 3];
            let _ = write!(
                out,
                "<tr><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{:.2}</td>",
                i + 1,
                escape(&name_of(scene, points.receivers[i])),
                p[0],
                p[1],
                p[2]
            );
            for (k, (_, values)) in t.values.iter().enumerate() {
                let _ = write!(out, "<td>{:.1}</td>", values[i]);
                if let Some(before) = &t.before {
                    let b = before[k][i];
                    let _ = write!(
                        out,
                        "<td>{}</td><td>{}</td>",
                        b.map_or("–".into(), |b| format!("{b:.1}")),
                        ratio(values[i], b).map_or("–".into(), |r| format!("{r:.2}"))
                    );
                }
            }
            let judged = t.assessed.as_ref().is_none_or(|a| a[i]);
            for (_, verdicts) in &t.verdicts {
                let (class, text) = match (judged, verdicts[i].passes) {
                    (false, _) => ("na", "not assessed"),
                    (true, true) => ("pass", "pass"),
                    (true, false) => ("fail", "fail"),
                };
                let _ = write!(out, "<td class=\"{class}\">{text}</td>");
            }
            out.push_str("</tr>");
        }
        out.push_str("</table>");
    }
    if !masks.is_empty() {
        out.push_str("<h2>Sky masks</h2><p>Stereographic, zenith at the centre, north up; dark: obstructed sky; light grey: behind the window's own plane; orange: sun paths (local standard time marks; red: the study's day).</p>");
        for (i, svg) in masks {
            let _ = write!(out, "<figure>{svg}<figcaption>point {}</figcaption></figure>", i + 1);
        }
    }
    out.push_str("</body></html>\n");
    out
}
