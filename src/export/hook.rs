//! Hooking a sunlit CSV into an EnergyPlus model, so that stock EnergyPlus really uses it.
//!
//! Owns the two forms EnergyPlus offers and the choice between them:
//! - [`Hook::Scheduled`] (the default): `ShadowCalculation` method `Scheduled`, and per surface a
//!   `Schedule:File` reading its column of the CSV plus a `SurfaceProperty:LocalEnvironment`
//!   naming that schedule as the surface's sunlit fraction schedule. Measured with EnergyPlus
//!   25.2 (tests/energyplus.rs): the fractions are used exactly.
//! - [`Hook::Imported`]: `ShadowCalculation` method `Imported` and one `Schedule:File:Shading`.
//!   EnergyPlus 25.2 silently ignores it (every surface "not found … set to 1.0", a name-lookup
//!   bug fixed upstream later), so it is only written when asked for.
//!
//! Both are written in the `ShadowCalculation` layout EnergyPlus has had since 9.3 (method first);
//! older models are refused by name (9.0–9.2 had the method in another field, before 9.0 there was
//! none). Either way the shading calculation is updated as the CSV was counted: every timestep, or
//! for a CSV counted for the model's own Periodic suns ([`crate::sun::periods`]) with the model's
//! Periodic update (EnergyPlus reads a schedule only on the first day of each period), the schedules are not shifted for daylight saving (the CSV is in standard
//! time, as EnergyPlus's own), and the model's Timestep must match the CSV's.

use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::geometry::{self, Plane, is_convex};
use crate::model::EnergyPlusInput;
use crate::model::idf::IdfObject;
use crate::scene::Scene;
use crate::sun::periods::ShadingPeriods;
use crate::year::samples::Timesteps;

/// How EnergyPlus is told to use the CSV.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hook {
    /// Per-surface `Schedule:File` + `SurfaceProperty:LocalEnvironment` (works in 25.2).
    Scheduled,
    /// One `Schedule:File:Shading` (ignored by 25.2).
    Imported,
}

impl Hook {
    /// Parses `scheduled` / `imported`.
    pub fn parse(text: &str) -> Result<Self> {
        match text.to_ascii_lowercase().as_str() {
            "scheduled" => Ok(Hook::Scheduled),
            "imported" => Ok(Hook::Imported),
            _ => Err(Error::argument("hook", format!("'{text}': expected scheduled or imported"))),
        }
    }

    /// The form for a model's `Version`: Scheduled from 9.3 on. Older models are refused: 9.0–9.2
    /// name the method in a later `ShadowCalculation` field (and EnergyPlus 9.3 and later misread
    /// that layout), and before 9.0 EnergyPlus cannot take external sunlit fractions at all.
    pub fn for_version(file: &str, version: Option<&str>) -> Result<Self> {
        let mut parts = version.unwrap_or("").split('.').map(|p| p.trim().parse::<u32>().ok());
        let (major, minor) = (parts.next().flatten(), parts.next().flatten().unwrap_or(0));
        match major {
            Some(m) if (m, minor) < (9, 3) => Err(Error::model(
                file,
                format!(
                    "a Version {} model cannot be hooked: sunlit writes ShadowCalculation as EnergyPlus 9.3 and later read it \
                     (external sunlit fractions need 9.0; 9.0-9.2 lay the object out differently). Transition the model to \
                     9.3 or later with EnergyPlus's IDFVersionUpdater first (its geometry is read as it is when nothing is hooked)",
                    version.unwrap_or("").trim()
                ),
            )),
            _ => Ok(Hook::Scheduled),
        }
    }
}

/// What EnergyPlus's Scheduled method itself changes, for the model it hooks: one line per cause
/// present, each with what was measured on EnergyPlus's test files (25.2, Chicago TMY3, the hook
/// fed EnergyPlus's own reported fractions against its own clipping; docs/energyplus-fidelity.md).
/// Fed sunlit fractions, EnergyPlus skips its own shadow calculation (SolarShading.cc
/// `FigureSolarBeamAtTimestep`), and with it every term that calculation builds:
/// - the beam solar absorbed in exterior windows' glass (`SunlitFracWithoutReveal` stays 0, so
///   `CalcInteriorSolarDistribution` adds none); transmitted solar is unchanged;
/// - under `FullInteriorAndExterior` (with or without reflections), the back-surface overlaps
///   that send transmitted beam to the surfaces it lands on: it is spread as diffuse instead;
/// - for windows set back in their wall, the reveal terms (beam absorbed by the outside and
///   inside reveals).
///
/// EnergyPlus 25.2 has no input that restores the first for ordinary windows:
/// `ComplexFenestrationProperty:SolarAbsorbedLayers` applies only to
/// `Construction:ComplexFenestrationState` windows, and the `Surface` EMS actuators of a window
/// are construction state, convection coefficients, outdoor air and view factor to ground.
pub fn scheduled_method_gap(ep: &EnergyPlusInput, columns: &[String]) -> Vec<String> {
    let hooked: Vec<&crate::model::building::EpSurface> = columns.iter().filter_map(|c| ep.building.surface(c)).collect();
    let glazed = |s: &&&crate::model::building::EpSurface| ["Window", "GlassDoor"].iter().any(|k| s.kind.eq_ignore_ascii_case(k));
    let windows = hooked.iter().filter(glazed).count();
    let mut out = Vec::new();
    if windows > 0 {
        out.push(format!(
            "EnergyPlus's Scheduled method drops the beam solar absorbed in exterior windows' glass ({windows} here): it skips its \
             own shadow calculation, which that term needs; transmitted solar is unchanged. Fed EnergyPlus's own reported \
             fractions, absorbed solar in glass falls 47% and annual site energy moves +0.49% on 4ZoneWithShading_Simple_1, \
             32% and +0.20% on 5ZoneAirCooled (Chicago); no EnergyPlus 25.2 input restores it for windows that are not BSDF"
        ));
    }
    let distribution = ep.objects.iter().find(|o| o.is("Building")).map(|o| o.field(5).trim().to_ascii_lowercase()).unwrap_or_default();
    if windows > 0 && distribution.starts_with("fullinteriorandexterior") {
        out.push(format!(
            "Solar Distribution {}: under the Scheduled method EnergyPlus builds no back-surface overlaps, so beam through the \
             windows reaches the zone as diffuse instead of landing where it falls (measured on 4ZoneWithShading_Simple_1 set \
             to FullInteriorAndExterior: see docs/energyplus-fidelity.md)",
            ep.objects.iter().find(|o| o.is("Building")).map_or("", |o| o.field(5).trim())
        ));
    }
    let set_back = hooked.iter().filter(|s| ep.building.reveal_depth(s).is_some()).count();
    if set_back > 0 {
        out.push(format!(
            "{set_back} hooked windows or doors are set back in their walls: EnergyPlus's reveal terms (beam absorbed by the outside \
             and inside reveals) come from its own shadow calculation and are dropped too (not measured: no committed test file \
             has a reveal)"
        ));
    }
    out
}

/// What to hook in: the CSV as the model will find it and its columns.
#[derive(Debug, Clone)]
pub struct HookPlan<'a> {
    /// The CSV's path as written into the model (the CLI writes its absolute path).
    pub csv: &'a str,
    /// Surface names, in CSV column order (the CSV's first column is the time stamp).
    pub columns: &'a [String],
    /// The CSV's timesteps per hour.
    pub timesteps: Timesteps,
    /// The form.
    pub hook: Hook,
    /// The model's Periodic shading update when the CSV was counted for its suns
    /// ([`crate::sun::periods`]): the hooked model keeps it. `None`: every timestep.
    pub periods: Option<ShadingPeriods>,
}

/// Schedule type limits of the fraction schedules, so EnergyPlus validates them (0..1).
const LIMITS: &str = "SUNLIT FRACTION";
/// Objects that the hook replaces.
const REPLACED: [&str; 2] = ["ShadowCalculation", "Schedule:File:Shading"];
/// ShadowCalculation fields written when the model has none (IDD order, 25.2).
const DEFAULT_SHADOW_CALCULATION: [&str; 8] =
    ["Scheduled", "Timestep", "1", "15000", "SutherlandHodgman", "512", "SimpleSkyDiffuseModeling", "No"];

/// The IDF text with the hook: the old ShadowCalculation (and any Schedule:File:Shading) removed,
/// the new objects appended. Everything else, comments included, is kept as written.
pub fn patch_idf(file: &str, text: &str, objects: &[IdfObject], plan: &HookPlan) -> Result<String> {
    check_model(file, objects, plan)?;
    let lines: Vec<&str> = text.lines().collect();
    let mut drop = vec![false; lines.len() + 1];
    for o in objects.iter().filter(|o| REPLACED.iter().any(|c| o.is(c))) {
        if shares_lines(o, objects) {
            return Err(Error::object(file, o.label(), "shares a line with another object; put it on lines of its own to be replaced"));
        }
        if let Some(lines) = drop.get_mut(o.line..=o.end_line) {
            lines.fill(true);
        }
    }
    // Non-convex shading surfaces: EnergyPlus's own (sky diffuse) shading pass still reads every
    // caster and calls a non-convex one a severe error, so they go in as convex triangles.
    let mut replace: Vec<(usize, String)> = Vec::new();
    for o in objects.iter().filter(|o| SHADING_VERTICES.iter().any(|(c, _)| o.is(c))) {
        if let Some(text) = convex_split(file, o)? {
            if let Some(lines) = drop.get_mut(o.line..=o.end_line) {
                lines.fill(true);
            }
            replace.push((o.line, text));
        }
    }
    let mut out = String::with_capacity(text.len() + 512 * plan.columns.len());
    for (i, line) in lines.iter().enumerate() {
        if let Some((_, text)) = replace.iter().find(|(l, _)| *l == i + 1) {
            out.push_str(text);
        }
        if !drop[i + 1] {
            out.push_str(line);
            out.push('\n');
        }
    }
    let existing = objects.iter().find(|o| o.is("ShadowCalculation"));
    out.push_str(&hook_objects(existing, plan));
    let has_limits = objects.iter().any(|o| o.is("ScheduleTypeLimits") && o.field(0).eq_ignore_ascii_case(LIMITS));
    if plan.hook == Hook::Scheduled && !has_limits {
        object(&mut out, "ScheduleTypeLimits", &[LIMITS, "0", "1", "Continuous"]);
    }
    Ok(out)
}

/// Shading classes with a vertex list: the index of their "Number of Vertices" field.
const SHADING_VERTICES: [(&str, usize); 3] = [("Shading:Site:Detailed", 2), ("Shading:Building:Detailed", 2), ("Shading:Zone:Detailed", 3)];

/// A non-convex shading object rewritten as triangles `NAME_1`, `NAME_2`, … (same class and
/// leading fields, vertices as written, so relative coordinates stay relative); None if convex.
fn convex_split(file: &str, o: &IdfObject) -> Result<Option<String>> {
    let Some(&(_, count_at)) = SHADING_VERTICES.iter().find(|(c, _)| o.is(c)) else { return Ok(None) };
    let number = |i: usize| {
        o.field(i)
            .trim()
            .parse::<f64>()
            .map_err(|_| Error::object(file, o.label(), format!("field {} '{}' is not a number", i + 1, o.field(i))))
    };
    let coords = o.fields.len().saturating_sub(count_at + 1) / 3;
    let vertices = (0..coords)
        .map(|k| Ok(glam::DVec3::new(number(count_at + 1 + 3 * k)?, number(count_at + 2 + 3 * k)?, number(count_at + 3 + 3 * k)?)))
        .collect::<Result<Vec<_>>>()?;
    if vertices.len() < 4 || is_convex(&vertices) {
        return Ok(None);
    }
    let name = o.name().unwrap_or("SHADING");
    let mut out = format!("! sunlit: non-convex {} split into convex triangles\n", o.label());
    for (k, t) in triangles(&vertices).iter().enumerate() {
        let mut fields: Vec<String> = o.fields[..count_at].to_vec();
        fields[0] = format!("{name}_{}", k + 1);
        fields.push("3".into());
        for &i in t {
            fields
                .extend([o.field(count_at + 1 + 3 * i), o.field(count_at + 2 + 3 * i), o.field(count_at + 3 + 3 * i)].map(str::to_string));
        }
        object(&mut out, &o.class, &fields.iter().map(String::as_str).collect::<Vec<_>>());
    }
    Ok(Some(out))
}

/// Ear-clipped triangles of a planar polygon, as vertex indices keeping its winding.
fn triangles(v: &[glam::DVec3]) -> Vec<[usize; 3]> {
    geometry::triangulate(&Plane::of_polygon(v), v, &[])
}

/// Whether another object starts or ends on one of `o`'s lines.
fn shares_lines(o: &IdfObject, objects: &[IdfObject]) -> bool {
    objects.iter().any(|p| !std::ptr::eq(p, o) && p.end_line >= o.line && p.line <= o.end_line)
}

/// Refuses models the hook would break: an old version, a Timestep that differs from the CSV's,
/// a surface that already has a local environment (EnergyPlus allows one). [`patch_idf`] checks
/// too; callers run it first to refuse before any counting.
pub fn check_model(file: &str, objects: &[IdfObject], plan: &HookPlan) -> Result<()> {
    Hook::for_version(file, crate::model::idf::version(objects).as_deref())?;
    for o in objects.iter().filter(|o| o.is("RunPeriod")) {
        check_run_period(o).map_err(|reason| Error::object(file, o.label(), format!("{reason}: EnergyPlus would stop on it")))?;
    }
    if let Some(ts) = objects.iter().find(|o| o.is("Timestep")) {
        let n: u32 = ts.field(0).trim().parse().unwrap_or(1);
        if n != plan.timesteps.per_hour() {
            return Err(Error::TimestepMismatch { file: file.into(), object: ts.label(), model: n, schedule: plan.timesteps.per_hour() });
        }
    }
    if plan.hook == Hook::Scheduled {
        for o in objects.iter().filter(|o| o.is("SurfaceProperty:LocalEnvironment")) {
            if plan.columns.iter().any(|c| c.eq_ignore_ascii_case(o.field(1))) {
                return Err(Error::object(
                    file,
                    o.label(),
                    "this surface already has a local environment; sunlit would need to add its own",
                ));
            }
        }
    }
    Ok(())
}

/// A RunPeriod's dates as EnergyPlus 25.2 checks them (`GetWeatherInput`, measured): months
/// 1-12, days within their month (Feb 29 only in a leap Begin/End Year or without one), and a
/// Begin Year not after the End Year, nor the begin date after the end date within one year. A
/// period without years may wrap over New Year.
fn check_run_period(o: &IdfObject) -> std::result::Result<(), String> {
    let number = |i: usize, what: &str| -> std::result::Result<Option<i64>, String> {
        let text = o.field(i).trim();
        if text.is_empty() {
            return Ok(None);
        }
        text.parse::<f64>()
            .ok()
            .filter(|v| v.fract() == 0.0)
            .map(|v| Some(v as i64))
            .ok_or_else(|| format!("{what} '{text}' is not a whole number"))
    };
    let date = |first: usize, which: &str| -> std::result::Result<(i64, i64, Option<i64>), String> {
        let month = number(first, &format!("{which} Month"))?.unwrap_or(if which == "Begin" { 1 } else { 12 });
        let day = number(first + 1, &format!("{which} Day of Month"))?.unwrap_or(if which == "Begin" { 1 } else { 31 });
        let year = number(first + 2, &format!("{which} Year"))?;
        let leap = year.is_none_or(|y| crate::model::run_year::is_leap(y as i32));
        let days = match month {
            1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
            4 | 6 | 9 | 11 => 30,
            2 if leap => 29,
            2 => 28,
            _ => return Err(format!("{which} Month {month} is not a month (1-12)")),
        };
        if !(1..=days).contains(&day) {
            return Err(format!("{which} Month/Day {month}/{day} is not a date{}", year.map_or(String::new(), |y| format!(" in {y}"))));
        }
        Ok((month, day, year))
    };
    let (begin, end) = (date(1, "Begin")?, date(4, "End")?);
    if let (Some(by), Some(ey)) = (begin.2, end.2)
        && (by, begin.0, begin.1) > (ey, end.0, end.1)
    {
        return Err(format!("it begins on {by}-{:02}-{:02}, after it ends ({ey}-{:02}-{:02})", begin.0, begin.1, end.0, end.1));
    }
    Ok(())
}

/// The hooked model's update method and frequency: the model's own Periodic update when the
/// CSV was counted for its suns (each period's fractions are the same every day of it, and
/// EnergyPlus reads them on the period's first day, with that period's sun for dark and lit and for
/// the beam's angle), else every timestep (in Periodic mode a schedule is read only on the first
/// day of each period, so a CSV counted for each day's own sun needs Timestep updates).
fn update_fields(plan: &HookPlan) -> (&'static str, u32) {
    match plan.periods {
        Some(p) => ("Periodic", p.days),
        None => ("Timestep", 1),
    }
}

/// The objects the hook adds, as IDF text.
fn hook_objects(existing: Option<&IdfObject>, plan: &HookPlan) -> String {
    let mut fields: Vec<String> = match existing {
        Some(o) => o.fields.clone(),
        None => DEFAULT_SHADOW_CALCULATION.iter().map(|s| s.to_string()).collect(),
    };
    fields.resize(fields.len().max(8), String::new());
    fields[0] = if plan.hook == Hook::Scheduled { "Scheduled" } else { "Imported" }.into();
    let (update, days) = update_fields(plan);
    fields[1] = update.into();
    fields[2] = days.to_string();
    fields[7] = "No".into();
    let mut out = format!("\n! ---- Added by sunlit: EnergyPlus takes its sunlit fractions from {} ----\n", plan.csv);
    object(&mut out, "ShadowCalculation", &fields.iter().map(String::as_str).collect::<Vec<_>>());
    match plan.hook {
        Hook::Imported => object(&mut out, "Schedule:File:Shading", &[plan.csv]),
        Hook::Scheduled => {
            let minutes = (60 / plan.timesteps.per_hour()).to_string();
            let hours = (24 * plan.timesteps.days()).to_string();
            for (k, surface) in plan.columns.iter().enumerate() {
                let schedule = schedule_name(surface);
                let column = (k + 2).to_string();
                object(&mut out, "Schedule:File", &[&schedule, LIMITS, plan.csv, &column, "1", &hours, "Comma", "No", &minutes, "No"]);
                let env = format!("SUNLIT ENV {surface}");
                object(&mut out, "SurfaceProperty:LocalEnvironment", &[&env, surface, &schedule]);
            }
        }
    }
    out
}

/// The schedule that carries `surface`'s column.
pub fn schedule_name(surface: &str) -> String {
    format!("SUNLIT {surface}")
}

/// Writes one IDF object, a field a line.
pub(crate) fn object(out: &mut String, class: &str, fields: &[&str]) {
    let _ = write!(out, "{class},");
    for (i, f) in fields.iter().enumerate() {
        let end = if i + 1 == fields.len() { ';' } else { ',' };
        let _ = write!(out, "\n  {f}{end}");
    }
    out.push_str("\n\n");
}

/// The epJSON text with the hook (the JSON is re-serialised; key order becomes alphabetical).
pub fn patch_epjson(file: &str, text: &str, plan: &HookPlan) -> Result<String> {
    use serde_json::{Map, Value, json};
    let mut root: Value = serde_json::from_str(text).map_err(|e| Error::model(file, format!("not valid JSON: {e}")))?;
    let version = root
        .pointer("/Version")
        .and_then(Value::as_object)
        .and_then(|m| m.values().next())
        .and_then(|v| v["version_identifier"].as_str())
        .map(str::to_string);
    Hook::for_version(file, version.as_deref())?;
    let Some(model) = root.as_object_mut() else { return Err(Error::model(file, "the top level is not a JSON object")) };
    let mut calc = model.get("ShadowCalculation").and_then(Value::as_object).and_then(|m| m.values().next()).cloned().unwrap_or(json!({}));
    calc["shading_calculation_method"] = json!(if plan.hook == Hook::Scheduled { "Scheduled" } else { "Imported" });
    let (update, days) = update_fields(plan);
    calc["shading_calculation_update_frequency_method"] = json!(update);
    calc["shading_calculation_update_frequency"] = json!(days);
    calc["output_external_shading_calculation_results"] = json!("No");
    model.insert("ShadowCalculation".into(), json!({ "ShadowCalculation 1": calc }));
    model.remove("Schedule:File:Shading");
    match plan.hook {
        Hook::Imported => {
            model.insert("Schedule:File:Shading".into(), json!({ "Schedule:File:Shading 1": { "file_name": plan.csv } }));
        }
        Hook::Scheduled => {
            let minutes = 60 / plan.timesteps.per_hour();
            let mut schedules = model.get("Schedule:File").and_then(Value::as_object).cloned().unwrap_or_else(Map::new);
            let mut envs = model.get("SurfaceProperty:LocalEnvironment").and_then(Value::as_object).cloned().unwrap_or_else(Map::new);
            for (k, surface) in plan.columns.iter().enumerate() {
                let schedule = schedule_name(surface);
                schedules.insert(
                    schedule.clone(),
                    json!({"schedule_type_limits_name": LIMITS, "file_name": plan.csv, "column_number": k + 2, "rows_to_skip_at_top": 1, "number_of_hours_of_data": 24 * plan.timesteps.days(),
                           "column_separator": "Comma", "interpolate_to_timestep": "No", "minutes_per_item": minutes,
                           "adjust_schedule_for_daylight_savings": "No"}),
                );
                envs.insert(
                    format!("SUNLIT ENV {surface}"),
                    json!({"exterior_surface_name": surface, "sunlit_fraction_schedule_name": schedule}),
                );
            }
            model.insert("Schedule:File".into(), Value::Object(schedules));
            let mut limits = model.get("ScheduleTypeLimits").and_then(Value::as_object).cloned().unwrap_or_else(Map::new);
            limits.entry(LIMITS).or_insert(json!({"lower_limit_value": 0, "upper_limit_value": 1, "numeric_type": "Continuous"}));
            model.insert("ScheduleTypeLimits".into(), Value::Object(limits));
            model.insert("SurfaceProperty:LocalEnvironment".into(), Value::Object(envs));
        }
    }
    serde_json::to_string_pretty(&root).map_err(|e| Error::model(file, e.to_string()))
}

/// The hook form for a model (`hook`, or the one its version supports), after checking that
/// every receiver is one of its surfaces and that the model can take the hook (version, Timestep,
/// no local environments of its own): all before any counting.
pub fn hook_for(ep: &EnergyPlusInput, scene: &Scene, hook: Option<Hook>, timesteps: Timesteps) -> Result<Hook> {
    let form = match hook {
        Some(h) => h,
        None => Hook::for_version(&ep.file, crate::model::idf::version(&ep.objects).as_deref())?,
    };
    let known = |name: &str| ep.building.surface(name.strip_prefix("Mir-").unwrap_or(name)).is_some();
    if let Some(r) = scene.receivers.iter().find(|r| !known(&r.name)) {
        return Err(Error::argument(
            "hook",
            format!("receiver '{}' ({}) is not a surface of {}; hook only EnergyPlus surfaces", r.name, r.origin, ep.file),
        ));
    }
    // A Scheduled hook gives each column a SurfaceProperty:LocalEnvironment, which EnergyPlus
    // applies only to the surfaces it lets the sun onto (heat-transfer surfaces facing Outdoors,
    // not NoSun): any other column would be ignored (a window in an underground wall) or refused.
    if form == Hook::Scheduled
        && let Some((r, s)) = scene.receivers.iter().find_map(|r| ep.building.surface(&r.name).filter(|s| !s.receiver).map(|s| (r, s)))
    {
        return Err(Error::argument(
            "hook",
            format!(
                "receiver '{}' ({}) is {}, which EnergyPlus keeps dark or never lights (Outside Boundary Condition '{}'{}): it cannot take a sunlit fraction schedule",
                r.name,
                r.origin,
                s.label(),
                s.outside_boundary,
                if s.no_sun { ", Sun Exposure NoSun" } else { "" }
            ),
        ));
    }
    // The model checks (version, Timestep, existing local environments) before any counting.
    let columns: Vec<String> = scene.receivers.iter().map(|r| r.name.clone()).collect();
    check_model(&ep.file, &ep.objects, &HookPlan { csv: "", columns: &columns, timesteps, hook: form, periods: None })?;
    Ok(form)
}

/// The model's text (IDF or epJSON, as it came) with the CSV hooked in.
pub fn patch_model(ep: &EnergyPlusInput, plan: &HookPlan) -> Result<String> {
    if ep.epjson { patch_epjson(&ep.file, &ep.text, plan) } else { patch_idf(&ep.file, &ep.text, &ep.objects, plan) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::idf::parse_idf;

    const MODEL: &str = "Version, 25.2;\n! keep me\nTimestep, 4;\nShadowCalculation,\n  PolygonClipping, Periodic, 20, 15000,\n  SutherlandHodgman, 512, DetailedSkyDiffuseModeling, Yes;\nZone, Z;\n";

    fn plan(columns: &[String]) -> HookPlan<'_> {
        HookPlan { csv: "shading.csv", columns, timesteps: Timesteps::new(4).unwrap(), hook: Hook::Scheduled, periods: None }
    }

    /// A CSV counted for the model's Periodic suns is hooked with the same update (EnergyPlus
    /// reads each period's first day), in IDF and in epJSON; without it, every timestep.
    #[test]
    fn a_periodic_csv_keeps_the_models_update() {
        let columns = vec!["WALL_S".to_string()];
        let periods = Some(ShadingPeriods { days: 7, first_day: 1, run_days: 365 });
        let objects = parse_idf("m.idf", MODEL).unwrap();
        let out = patch_idf("m.idf", MODEL, &objects, &HookPlan { periods, ..plan(&columns) }).unwrap();
        let patched = parse_idf("out.idf", &out).unwrap();
        let calc = patched.iter().find(|o| o.is("ShadowCalculation")).unwrap();
        assert_eq!(&calc.fields[..3], ["Scheduled", "Periodic", "7"]);
        let text = r#"{"Version": {"Version 1": {"version_identifier": "25.2"}}}"#;
        let json: serde_json::Value =
            serde_json::from_str(&patch_epjson("m.epJSON", text, &HookPlan { periods, ..plan(&columns) }).unwrap()).unwrap();
        let calc = &json["ShadowCalculation"]["ShadowCalculation 1"];
        assert_eq!(
            (calc["shading_calculation_update_frequency_method"].as_str(), calc["shading_calculation_update_frequency"].as_u64()),
            (Some("Periodic"), Some(7))
        );
    }

    #[test]
    fn scheduled_hook_replaces_shadow_calculation_and_adds_schedules() {
        let columns = vec!["WALL_S".to_string(), "WIN_S".to_string()];
        let objects = parse_idf("m.idf", MODEL).unwrap();
        let out = patch_idf("m.idf", MODEL, &objects, &plan(&columns)).unwrap();
        let patched = parse_idf("out.idf", &out).unwrap();
        let calc: Vec<_> = patched.iter().filter(|o| o.is("ShadowCalculation")).collect();
        assert_eq!(calc.len(), 1);
        assert_eq!(&calc[0].fields[..3], ["Scheduled", "Timestep", "1"]);
        assert_eq!(calc[0].fields[6], "DetailedSkyDiffuseModeling", "the model's other settings are kept");
        let files: Vec<_> = patched.iter().filter(|o| o.is("Schedule:File")).collect();
        assert_eq!(files[1].fields, ["SUNLIT WIN_S", "SUNLIT FRACTION", "shading.csv", "3", "1", "8760", "Comma", "No", "15", "No"]);
        assert_eq!(patched.iter().filter(|o| o.is("ScheduleTypeLimits")).count(), 1);
        let envs: Vec<_> = patched.iter().filter(|o| o.is("SurfaceProperty:LocalEnvironment")).collect();
        assert_eq!(envs[0].fields, ["SUNLIT ENV WALL_S", "WALL_S", "SUNLIT WALL_S"]);
        assert!(out.contains("! keep me") && out.contains("Zone, Z;"));
    }

    #[test]
    fn models_the_hook_would_break_are_refused() {
        let columns = vec!["WIN_S".to_string()];
        let objects = parse_idf("m.idf", "Version, 25.2;\nTimestep, 6;\n").unwrap();
        let e = patch_idf("m.idf", "", &objects, &plan(&columns)).unwrap_err().to_string();
        assert!(e.contains("Timestep") && e.contains("timesteps_per_hour 6"), "{e}");
        for old in ["8.9", "9.0", "9.2.0"] {
            let objects = parse_idf("m.idf", &format!("Version, {old};\n")).unwrap();
            let e = patch_idf("m.idf", "", &objects, &plan(&columns)).unwrap_err().to_string();
            assert!(e.contains(&format!("Version {old} model")) && e.contains("9.3") && e.contains("IDFVersionUpdater"), "{e}");
        }
        assert_eq!(Hook::for_version("m", Some("9.3")).unwrap(), Hook::Scheduled);
        assert_eq!(Hook::for_version("m", Some("24.1")).unwrap(), Hook::Scheduled);
        let objects = parse_idf("m.idf", "Version, 25.2;\nSurfaceProperty:LocalEnvironment, E, win_s, S;\n").unwrap();
        assert!(patch_idf("m.idf", "", &objects, &plan(&columns)).unwrap_err().to_string().contains("local environment"));
        let text = "Version, 25.2; ShadowCalculation, PolygonClipping;\n";
        let objects = parse_idf("m.idf", text).unwrap();
        assert!(patch_idf("m.idf", text, &objects, &plan(&columns)).unwrap_err().to_string().contains("own"));
        assert_eq!(Hook::for_version("m", Some("25.2")).unwrap(), Hook::Scheduled);
        assert!(Hook::parse("sometimes").is_err());
    }

    #[test]
    fn non_convex_shading_becomes_triangles() {
        let text = "Version, 25.2;\nShading:Building:Detailed, L, ,\n 6, 0,0,3, 2,0,3, 2,2,3, 1,2,3, 1,1,3, 0,1,3;\nShading:Building:Detailed, SQ, , 4, 0,0,4, 1,0,4, 1,1,4, 0,1,4;\n";
        let objects = parse_idf("m.idf", text).unwrap();
        let columns = vec!["WIN_S".to_string()];
        let out = patch_idf("m.idf", text, &objects, &plan(&columns)).unwrap();
        let patched = parse_idf("out.idf", &out).unwrap();
        let shades: Vec<_> = patched.iter().filter(|o| o.is("Shading:Building:Detailed")).collect();
        assert_eq!(shades.iter().filter(|o| o.field(0).starts_with("L_")).count(), 4, "an L of six vertices is four triangles");
        assert!(shades.iter().any(|o| o.field(0) == "SQ"), "convex ones stay");
        assert!(shades.iter().filter(|o| o.field(0).starts_with("L_")).all(|o| o.field(2) == "3"));
    }

    #[test]
    fn epjson_hook() {
        let columns = vec!["WIN_S".to_string()];
        let text = r#"{"Version": {"Version 1": {"version_identifier": "25.2"}}, "ShadowCalculation": {"ShadowCalculation 1": {"shading_calculation_method": "PolygonClipping", "sky_diffuse_modeling_algorithm": "DetailedSkyDiffuseModeling"}}}"#;
        let out: serde_json::Value = serde_json::from_str(&patch_epjson("m.epJSON", text, &plan(&columns)).unwrap()).unwrap();
        assert_eq!(out["ShadowCalculation"]["ShadowCalculation 1"]["shading_calculation_method"], "Scheduled");
        assert_eq!(out["ShadowCalculation"]["ShadowCalculation 1"]["sky_diffuse_modeling_algorithm"], "DetailedSkyDiffuseModeling");
        assert_eq!(out["Schedule:File"]["SUNLIT WIN_S"]["column_number"], 2);
        assert_eq!(out["SurfaceProperty:LocalEnvironment"]["SUNLIT ENV WIN_S"]["exterior_surface_name"], "WIN_S");
    }
}
