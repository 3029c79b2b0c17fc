//! epJSON reader: turns `{ "Class": { "Name": { "field": value } } }` into the positional
//! [`IdfObject`] form of the IDF reader, so [`super::building`] reads both formats the same way.
//!
//! Owns the epJSON field names, in IDD order, of the classes the building reader understands
//! (taken from Energy+.idd / Energy+.schema.epJSON, version 25.2): epJSON keys its fields by name,
//! the IDF by position. Missing optional fields become `""`, as a blank IDF field would. Classes
//! not listed here keep only their name (so the building reader reports them as skipped).
//! Objects keep the file's order (serde_json's default map would sort them), and each object's
//! line is that of its name key in the text.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{Deserialize, Deserializer, MapAccess, Visitor};
use serde_json::Value;

use super::idf::{IdfObject, object_label};
use crate::error::{Error, Result};

/// What JSON type a field takes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// A string (names, choices).
    Text,
    /// A number (coordinates, angles).
    Number,
    /// A number or a keyword such as `autocalculate`.
    Either,
}

use Kind::{Either, Number, Text};

/// How one class maps from epJSON to IDD positions.
struct ClassSpec {
    class: &'static str,
    /// Whether the IDD's first field is the object's name (then the epJSON key is that name).
    named: bool,
    /// The fields after the name, in IDD order.
    fields: &'static [(&'static str, Kind)],
    /// Whether an extensible `vertices` array of x, y, z follows the fields.
    vertices: bool,
    /// An extensible array (its key, and each item's fields in IDD order) that follows the fields.
    list: Option<(&'static str, &'static [(&'static str, Kind)])>,
}

const VERTEX_KEYS: [&str; 3] = ["vertex_x_coordinate", "vertex_y_coordinate", "vertex_z_coordinate"];

const HEAT_TRANSFER_TAIL: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    ("outside_boundary_condition", Text),
    ("outside_boundary_condition_object", Text),
    ("sun_exposure", Text),
    ("wind_exposure", Text),
    ("view_factor_to_ground", Either),
    ("number_of_vertices", Either),
];

const BUILDING_SURFACE: &[(&str, Kind)] = &[
    ("surface_type", Text),
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    ("outside_boundary_condition", Text),
    ("outside_boundary_condition_object", Text),
    ("sun_exposure", Text),
    ("wind_exposure", Text),
    ("view_factor_to_ground", Either),
    ("number_of_vertices", Either),
];

const FENESTRATION: &[(&str, Kind)] = &[
    ("surface_type", Text),
    ("construction_name", Text),
    ("building_surface_name", Text),
    ("outside_boundary_condition_object", Text),
    ("view_factor_to_ground", Either),
    ("frame_and_divider_name", Text),
    ("multiplier", Number),
    ("number_of_vertices", Either),
    // FenestrationSurface:Detailed is not extensible: its (at most) four vertices are fields.
    ("vertex_1_x_coordinate", Number),
    ("vertex_1_y_coordinate", Number),
    ("vertex_1_z_coordinate", Number),
    ("vertex_2_x_coordinate", Number),
    ("vertex_2_y_coordinate", Number),
    ("vertex_2_z_coordinate", Number),
    ("vertex_3_x_coordinate", Number),
    ("vertex_3_y_coordinate", Number),
    ("vertex_3_z_coordinate", Number),
    ("vertex_4_x_coordinate", Number),
    ("vertex_4_y_coordinate", Number),
    ("vertex_4_z_coordinate", Number),
];

const DETACHED_SHADING: &[(&str, Kind)] = &[("transmittance_schedule_name", Text), ("number_of_vertices", Either)];

const ZONE_SHADING: &[(&str, Kind)] = &[("base_surface_name", Text), ("transmittance_schedule_name", Text), ("number_of_vertices", Either)];

const RECT_PLACEMENT: [(&str, Kind); 5] = [
    ("azimuth_angle", Number),
    ("tilt_angle", Number),
    ("starting_x_coordinate", Number),
    ("starting_y_coordinate", Number),
    ("starting_z_coordinate", Number),
];

const RECT_WALL: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    RECT_PLACEMENT[0],
    RECT_PLACEMENT[1],
    RECT_PLACEMENT[2],
    RECT_PLACEMENT[3],
    RECT_PLACEMENT[4],
    ("length", Number),
    ("height", Number),
];

const RECT_HORIZONTAL: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    RECT_PLACEMENT[0],
    RECT_PLACEMENT[1],
    RECT_PLACEMENT[2],
    RECT_PLACEMENT[3],
    RECT_PLACEMENT[4],
    ("length", Number),
    ("width", Number),
];

const RECT_INTERZONE_WALL: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    ("outside_boundary_condition_object", Text),
    RECT_PLACEMENT[0],
    RECT_PLACEMENT[1],
    RECT_PLACEMENT[2],
    RECT_PLACEMENT[3],
    RECT_PLACEMENT[4],
    ("length", Number),
    ("height", Number),
];

const RECT_INTERZONE_HORIZONTAL: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("zone_name", Text),
    ("space_name", Text),
    ("outside_boundary_condition_object", Text),
    RECT_PLACEMENT[0],
    RECT_PLACEMENT[1],
    RECT_PLACEMENT[2],
    RECT_PLACEMENT[3],
    RECT_PLACEMENT[4],
    ("length", Number),
    ("width", Number),
];

const RECT_DETACHED: &[(&str, Kind)] = &[
    RECT_PLACEMENT[0],
    RECT_PLACEMENT[1],
    RECT_PLACEMENT[2],
    RECT_PLACEMENT[3],
    RECT_PLACEMENT[4],
    ("length", Number),
    ("height", Number),
];

const RECT_GLAZED: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("building_surface_name", Text),
    ("frame_and_divider_name", Text),
    ("multiplier", Number),
    ("starting_x_coordinate", Number),
    ("starting_z_coordinate", Number),
    ("length", Number),
    ("height", Number),
];

const RECT_DOOR: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("building_surface_name", Text),
    ("multiplier", Number),
    ("starting_x_coordinate", Number),
    ("starting_z_coordinate", Number),
    ("length", Number),
    ("height", Number),
];

const RECT_INTERZONE_SUB: &[(&str, Kind)] = &[
    ("construction_name", Text),
    ("building_surface_name", Text),
    ("outside_boundary_condition_object", Text),
    ("multiplier", Number),
    ("starting_x_coordinate", Number),
    ("starting_z_coordinate", Number),
    ("length", Number),
    ("height", Number),
];

const OVERHANG: &[(&str, Kind)] = &[
    ("window_or_door_name", Text),
    ("height_above_window_or_door", Number),
    ("tilt_angle_from_window_door", Number),
    ("left_extension_from_window_door_width", Number),
    ("right_extension_from_window_door_width", Number),
    ("depth", Number),
];

const OVERHANG_PROJECTION: &[(&str, Kind)] = &[
    ("window_or_door_name", Text),
    ("height_above_window_or_door", Number),
    ("tilt_angle_from_window_door", Number),
    ("left_extension_from_window_door_width", Number),
    ("right_extension_from_window_door_width", Number),
    ("depth_as_fraction_of_window_door_height", Number),
];

const FIN: &[(&str, Kind)] = &[
    ("window_or_door_name", Text),
    ("left_extension_from_window_door", Number),
    ("left_distance_above_top_of_window", Number),
    ("left_distance_below_bottom_of_window", Number),
    ("left_tilt_angle_from_window_door", Number),
    ("left_depth", Number),
    ("right_extension_from_window_door", Number),
    ("right_distance_above_top_of_window", Number),
    ("right_distance_below_bottom_of_window", Number),
    ("right_tilt_angle_from_window_door", Number),
    ("right_depth", Number),
];

const FIN_PROJECTION: &[(&str, Kind)] = &[
    ("window_or_door_name", Text),
    ("left_extension_from_window_door", Number),
    ("left_distance_above_top_of_window", Number),
    ("left_distance_below_bottom_of_window", Number),
    ("left_tilt_angle_from_window_door", Number),
    ("left_depth_as_fraction_of_window_door_width", Number),
    ("right_extension_from_window_door", Number),
    ("right_distance_above_top_of_window", Number),
    ("right_distance_below_bottom_of_window", Number),
    ("right_tilt_angle_from_window_door", Number),
    ("right_depth_as_fraction_of_window_door_width", Number),
];

const fn spec(class: &'static str, named: bool, fields: &'static [(&'static str, Kind)], vertices: bool) -> ClassSpec {
    ClassSpec { class, named, fields, vertices, list: None }
}

const fn listed(
    class: &'static str,
    fields: &'static [(&'static str, Kind)],
    key: &'static str,
    items: &'static [(&'static str, Kind)],
) -> ClassSpec {
    ClassSpec { class, named: true, fields, vertices: false, list: Some((key, items)) }
}

const HOURS: &[(&str, Kind)] = &[
    ("schedule_type_limits_name", Text),
    ("hour_1", Number),
    ("hour_2", Number),
    ("hour_3", Number),
    ("hour_4", Number),
    ("hour_5", Number),
    ("hour_6", Number),
    ("hour_7", Number),
    ("hour_8", Number),
    ("hour_9", Number),
    ("hour_10", Number),
    ("hour_11", Number),
    ("hour_12", Number),
    ("hour_13", Number),
    ("hour_14", Number),
    ("hour_15", Number),
    ("hour_16", Number),
    ("hour_17", Number),
    ("hour_18", Number),
    ("hour_19", Number),
    ("hour_20", Number),
    ("hour_21", Number),
    ("hour_22", Number),
    ("hour_23", Number),
    ("hour_24", Number),
];

const WEEK_DAILY: &[(&str, Kind)] = &[
    ("sunday_schedule_day_name", Text),
    ("monday_schedule_day_name", Text),
    ("tuesday_schedule_day_name", Text),
    ("wednesday_schedule_day_name", Text),
    ("thursday_schedule_day_name", Text),
    ("friday_schedule_day_name", Text),
    ("saturday_schedule_day_name", Text),
    ("holiday_schedule_day_name", Text),
    ("summerdesignday_schedule_day_name", Text),
    ("winterdesignday_schedule_day_name", Text),
    ("customday1_schedule_day_name", Text),
    ("customday2_schedule_day_name", Text),
];

const SCHEDULE_FILE: &[(&str, Kind)] = &[
    ("schedule_type_limits_name", Text),
    ("file_name", Text),
    ("column_number", Number),
    ("rows_to_skip_at_top", Number),
    ("number_of_hours_of_data", Number),
    ("column_separator", Text),
    ("interpolate_to_timestep", Text),
    ("minutes_per_item", Number),
    ("adjust_schedule_for_daylight_savings", Text),
    ("translate_file_with_relative_path", Text),
];

const LIMITS_ONLY: &[(&str, Kind)] = &[("schedule_type_limits_name", Text)];

/// The schedule classes a shade's transmittance may use ([`super::schedule`]).
const SCHEDULE_CLASSES: &[ClassSpec] = &[
    spec(
        "ScheduleTypeLimits",
        true,
        &[("lower_limit_value", Number), ("upper_limit_value", Number), ("numeric_type", Text), ("unit_type", Text)],
        false,
    ),
    spec("Schedule:Constant", true, &[("schedule_type_limits_name", Text), ("hourly_value", Number)], false),
    listed("Schedule:Compact", LIMITS_ONLY, "data", &[("field", Either)]),
    listed(
        "Schedule:Year",
        LIMITS_ONLY,
        "schedule_weeks",
        &[("schedule_week_name", Text), ("start_month", Number), ("start_day", Number), ("end_month", Number), ("end_day", Number)],
    ),
    spec("Schedule:Week:Daily", true, WEEK_DAILY, false),
    listed("Schedule:Week:Compact", &[], "data", &[("daytype_list", Text), ("schedule_day_name", Text)]),
    spec("Schedule:Day:Hourly", true, HOURS, false),
    listed(
        "Schedule:Day:Interval",
        &[("schedule_type_limits_name", Text), ("interpolate_to_timestep", Text)],
        "data",
        &[("time", Text), ("value_until_time", Number)],
    ),
    listed(
        "Schedule:Day:List",
        &[("schedule_type_limits_name", Text), ("interpolate_to_timestep", Text), ("minutes_per_item", Number)],
        "extensions",
        &[("value", Number)],
    ),
    spec("Schedule:File", true, SCHEDULE_FILE, false),
];

/// The classes read by [`super::building`], with their epJSON field names in IDD order.
const CLASSES: &[ClassSpec] = &[
    spec("Version", false, &[("version_identifier", Text)], false),
    // Its update, for EnergyPlus's Periodic sun (`super::shading_update`).
    spec(
        "ShadowCalculation",
        false,
        &[
            ("shading_calculation_method", Text),
            ("shading_calculation_update_frequency_method", Text),
            ("shading_calculation_update_frequency", Number),
            // Read by `export::glitches` (the figure overflow).
            ("maximum_figures_in_shadow_overlap_calculations", Number),
        ],
        false,
    ),
    // Daylight saving shifts schedules by an hour, and special days set a day's type
    // (`super::calendar`).
    spec("RunPeriodControl:DaylightSavingTime", false, &[("start_date", Text), ("end_date", Text)], false),
    spec("RunPeriodControl:SpecialDays", true, &[("start_date", Text), ("duration", Number), ("special_day_type", Text)], false),
    spec(
        "RunPeriod",
        true,
        &[
            ("begin_month", Number),
            ("begin_day_of_month", Number),
            ("begin_year", Number),
            ("end_month", Number),
            ("end_day_of_month", Number),
            ("end_year", Number),
            ("day_of_week_for_start_day", Text),
            ("use_weather_file_holidays_and_special_days", Text),
            ("use_weather_file_daylight_saving_period", Text),
            ("apply_weekend_holiday_rule", Text),
        ],
        false,
    ),
    spec("Site:Location", true, &[("latitude", Number), ("longitude", Number), ("time_zone", Number), ("elevation", Number)], false),
    spec(
        "Building",
        true,
        &[
            ("north_axis", Number),
            ("terrain", Text),
            ("loads_convergence_tolerance_value", Number),
            ("temperature_convergence_tolerance_value", Number),
            ("solar_distribution", Text),
            ("maximum_number_of_warmup_days", Number),
            ("minimum_number_of_warmup_days", Number),
        ],
        false,
    ),
    spec(
        "GlobalGeometryRules",
        false,
        &[
            ("starting_vertex_position", Text),
            ("vertex_entry_direction", Text),
            ("coordinate_system", Text),
            ("daylighting_reference_point_coordinate_system", Text),
            ("rectangular_surface_coordinate_system", Text),
        ],
        false,
    ),
    spec("Compliance:Building", false, &[("building_rotation_for_appendix_g", Number)], false),
    spec(
        "Zone",
        true,
        &[
            ("direction_of_relative_north", Number),
            ("x_origin", Number),
            ("y_origin", Number),
            ("z_origin", Number),
            ("type", Number),
            ("multiplier", Number),
            ("ceiling_height", Either),
            ("volume", Either),
            ("floor_area", Either),
            ("zone_inside_convection_algorithm", Text),
            ("zone_outside_convection_algorithm", Text),
            ("part_of_total_floor_area", Text),
        ],
        false,
    ),
    spec("BuildingSurface:Detailed", true, BUILDING_SURFACE, true),
    spec("Wall:Detailed", true, HEAT_TRANSFER_TAIL, true),
    spec("RoofCeiling:Detailed", true, HEAT_TRANSFER_TAIL, true),
    spec("Floor:Detailed", true, HEAT_TRANSFER_TAIL, true),
    spec("FenestrationSurface:Detailed", true, FENESTRATION, false),
    spec("Shading:Site:Detailed", true, DETACHED_SHADING, true),
    spec("Shading:Building:Detailed", true, DETACHED_SHADING, true),
    spec("Shading:Zone:Detailed", true, ZONE_SHADING, true),
    spec("Wall:Exterior", true, RECT_WALL, false),
    spec("Wall:Adiabatic", true, RECT_WALL, false),
    spec("Wall:Underground", true, RECT_WALL, false),
    spec("Wall:Interzone", true, RECT_INTERZONE_WALL, false),
    spec("Roof", true, RECT_HORIZONTAL, false),
    spec("Ceiling:Adiabatic", true, RECT_HORIZONTAL, false),
    spec("Ceiling:Interzone", true, RECT_INTERZONE_HORIZONTAL, false),
    spec("Floor:GroundContact", true, RECT_HORIZONTAL, false),
    spec("Floor:Adiabatic", true, RECT_HORIZONTAL, false),
    spec("Floor:Interzone", true, RECT_INTERZONE_HORIZONTAL, false),
    spec("Window", true, RECT_GLAZED, false),
    spec("GlazedDoor", true, RECT_GLAZED, false),
    spec("Door", true, RECT_DOOR, false),
    spec("Window:Interzone", true, RECT_INTERZONE_SUB, false),
    spec("GlazedDoor:Interzone", true, RECT_INTERZONE_SUB, false),
    spec("Door:Interzone", true, RECT_INTERZONE_SUB, false),
    spec("Shading:Site", true, RECT_DETACHED, false),
    spec("Shading:Building", true, RECT_DETACHED, false),
    spec("Shading:Overhang", true, OVERHANG, false),
    spec("Shading:Overhang:Projection", true, OVERHANG_PROJECTION, false),
    spec("Shading:Fin", true, FIN, false),
    spec("Shading:Fin:Projection", true, FIN_PROJECTION, false),
];

/// Reads epJSON text into objects in IDD field order (for the file's version, see
/// [`super::building::IddLayout`]: files older than 9.6 have no Space Name fields).
pub fn parse_epjson(file: &str, text: &str) -> Result<Vec<IdfObject>> {
    let top: Ordered<Ordered<Value>> = serde_json::from_str(text).map_err(|e| Error::model(file, format!("not valid epJSON: {e}")))?;
    let layout = super::building::IddLayout::from_version(epjson_version(&top.0).as_deref());
    let mut objects = Vec::new();
    let mut cursor = 0;
    for (class, members) in &top.0 {
        let spec = CLASSES.iter().chain(SCHEDULE_CLASSES).find(|s| s.class.eq_ignore_ascii_case(class));
        let class_line;
        (class_line, cursor) = locate(text, cursor, class);
        for (key, value) in &members.0 {
            // Objects are searched for in order, each after the previous one's key.
            let (found, after) = locate(text, cursor, key);
            cursor = after;
            let line = if found > 0 { found } else { class_line };
            let object = match spec {
                Some(spec) => convert(file, spec, key, value, line, layout)?,
                None => IdfObject { class: class.clone(), fields: vec![key.clone()], line, end_line: line },
            };
            objects.push(object);
        }
    }
    Ok(objects)
}

/// The Version object's identifier, needed before the other classes are converted.
fn epjson_version(top: &[(String, Ordered<Value>)]) -> Option<String> {
    let (_, members) = top.iter().find(|(c, _)| c.eq_ignore_ascii_case("Version"))?;
    members.0.first()?.1.get("version_identifier")?.as_str().map(str::to_string)
}

fn convert(file: &str, spec: &ClassSpec, key: &str, value: &Value, line: usize, layout: super::building::IddLayout) -> Result<IdfObject> {
    let label = object_label(spec.class, spec.named.then_some(key), line);
    let Some(members) = value.as_object() else {
        return Err(Error::object(file, label, format!("must be a JSON object of fields, not {}", describe(value))));
    };
    let mut fields: Vec<String> = Vec::new();
    if spec.named {
        fields.push(key.to_string());
    }
    for &(name, kind) in spec.fields {
        // Files older than 9.6 have no Space Name; dropping it keeps their IDD positions.
        if name == "space_name" && !layout.space_name {
            continue;
        }
        fields.push(field_text(members.get(name), kind).map_err(|why| Error::object(file, &label, format!("field '{name}' {why}")))?);
    }
    if spec.vertices {
        append_vertices(file, &label, members.get("vertices"), &mut fields)?;
    }
    if let Some((key, items)) = spec.list {
        append_list(file, &label, key, items, members.get(key), &mut fields)?;
    }
    // Omitted trailing fields are blank in IDF too; trimming them lets "autocalculate" vertex
    // counts see only the coordinates that were given.
    while fields.last().is_some_and(String::is_empty) {
        fields.pop();
    }
    Ok(IdfObject { class: spec.class.to_string(), fields, line, end_line: line })
}

fn append_vertices(file: &str, label: &str, vertices: Option<&Value>, fields: &mut Vec<String>) -> Result<()> {
    let Some(vertices) = vertices else { return Ok(()) };
    let Some(list) = vertices.as_array() else {
        return Err(Error::object(file, label, format!("field 'vertices' must be an array, not {}", describe(vertices))));
    };
    for (i, vertex) in list.iter().enumerate() {
        for key in VERTEX_KEYS {
            let value = vertex.get(key);
            if value.is_none() {
                return Err(Error::object(file, label, format!("vertex {} has no '{key}'", i + 1)));
            }
            fields.push(field_text(value, Number).map_err(|why| Error::object(file, label, format!("'{key}' of vertex {} {why}", i + 1)))?);
        }
    }
    Ok(())
}

/// An extensible array's items, each's fields in IDD order (a missing one blank).
fn append_list(file: &str, label: &str, key: &str, items: &[(&str, Kind)], list: Option<&Value>, fields: &mut Vec<String>) -> Result<()> {
    let Some(list) = list else { return Ok(()) };
    let Some(list) = list.as_array() else {
        return Err(Error::object(file, label, format!("field '{key}' must be an array, not {}", describe(list))));
    };
    for (i, item) in list.iter().enumerate() {
        for &(name, kind) in items {
            let text = field_text(item.get(name), kind)
                .map_err(|why| Error::object(file, label, format!("'{name}' of {key} item {} {why}", i + 1)))?;
            fields.push(text);
        }
    }
    Ok(())
}

/// A field's value as IDF text, or why its JSON type is wrong.
fn field_text(value: Option<&Value>, kind: Kind) -> std::result::Result<String, String> {
    match (value, kind) {
        (None | Some(Value::Null), _) => Ok(String::new()),
        (Some(Value::String(s)), Text | Either) => Ok(s.trim().to_string()),
        (Some(Value::Number(n)), Number | Either) => Ok(number_text(n)),
        (Some(other), Text) => Err(format!("must be a string, not {}", describe(other))),
        (Some(other), _) => Err(format!("must be a number, not {}", describe(other))),
    }
}

fn number_text(n: &serde_json::Number) -> String {
    match (n.as_i64(), n.as_f64()) {
        (Some(i), _) => i.to_string(),
        (None, Some(f)) => f.to_string(),
        (None, None) => n.to_string(),
    }
}

fn describe(value: &Value) -> String {
    match value {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("the boolean {b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the string \"{s}\""),
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}

/// Line (1-based) and byte offset of the first `"key":` at or after `from`; `(0, from)` when the
/// key is written with escapes the search does not reproduce.
fn locate(text: &str, from: usize, key: &str) -> (usize, usize) {
    let Ok(quoted) = serde_json::to_string(key) else { return (0, from) };
    let mut start = from;
    while let Some(found) = text.get(start..).and_then(|t| t.find(&quoted)) {
        let at = start + found;
        let after = at + quoted.len();
        if text[after..].trim_start().starts_with(':') {
            return (1 + text[..at].matches('\n').count(), after);
        }
        start = after;
    }
    (0, from)
}

/// A JSON object's members in file order (serde_json's own map is sorted by key).
struct Ordered<T>(Vec<(String, T)>);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Ordered<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        deserializer.deserialize_map(OrderedVisitor(PhantomData))
    }
}

struct OrderedVisitor<T>(PhantomData<T>);

impl<'de, T: Deserialize<'de>> Visitor<'de> for OrderedVisitor<T> {
    type Value = Ordered<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON object")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<Self::Value, A::Error> {
        let mut members = Vec::new();
        while let Some(entry) = map.next_entry::<String, T>()? {
            members.push(entry);
        }
        Ok(Ordered(members))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODEL: &str = r#"{
  "Version": { "Version 1": { "version_identifier": "25.2" } },
  "Zone": { "Z1": { "direction_of_relative_north": 15, "x_origin": 1.5, "ceiling_height": "Autocalculate" } },
  "BuildingSurface:Detailed": {
    "WALL_S": {
      "surface_type": "Wall", "construction_name": "C", "zone_name": "Z1",
      "outside_boundary_condition": "Outdoors", "number_of_vertices": 3,
      "vertices": [
        { "vertex_x_coordinate": 0, "vertex_y_coordinate": 0, "vertex_z_coordinate": 3 },
        { "vertex_x_coordinate": 0, "vertex_y_coordinate": 0, "vertex_z_coordinate": 0 },
        { "vertex_x_coordinate": 4.25, "vertex_y_coordinate": 0, "vertex_z_coordinate": 0 }
      ]
    },
    "A_WALL": { "surface_type": "Wall", "zone_name": "Z1", "outside_boundary_condition": "Ground" }
  },
  "Material": { "Brick": { "thickness": 0.1 } }
}"#;

    #[test]
    fn classes_become_positional_objects_in_file_order() {
        let objects = parse_epjson("m.epJSON", MODEL).unwrap();
        let summary: Vec<_> = objects.iter().map(|o| (o.class.as_str(), o.name(), o.line)).collect();
        assert_eq!(
            summary,
            [
                ("Version", Some("25.2"), 2),
                ("Zone", Some("Z1"), 3),
                ("BuildingSurface:Detailed", Some("WALL_S"), 5),
                ("BuildingSurface:Detailed", Some("A_WALL"), 14),
                ("Material", Some("Brick"), 16),
            ]
        );
        assert_eq!(objects[1].fields, ["Z1", "15", "1.5", "", "", "", "", "Autocalculate"]);
        let wall = &objects[2].fields;
        assert_eq!(&wall[..11], ["WALL_S", "Wall", "C", "Z1", "", "Outdoors", "", "", "", "", "3"]);
        assert_eq!(&wall[11..], ["0", "0", "3", "0", "0", "0", "4.25", "0", "0"]);
        assert_eq!(objects[3].fields, ["A_WALL", "Wall", "", "Z1", "", "Ground"]);
        assert_eq!(objects[4].fields, ["Brick"]);
    }

    #[test]
    fn old_versions_have_no_space_name() {
        let text = MODEL.replace("\"25.2\"", "\"9.5\"");
        let objects = parse_epjson("m.epJSON", &text).unwrap();
        assert_eq!(objects[3].fields, ["A_WALL", "Wall", "", "Z1", "Ground"]);
    }

    #[test]
    fn fenestration_vertices_are_fields() {
        let text = r#"{"FenestrationSurface:Detailed": {"W1": {"surface_type": "Window", "building_surface_name": "WALL_S",
            "vertex_1_x_coordinate": 1, "vertex_1_y_coordinate": 0, "vertex_1_z_coordinate": 2,
            "vertex_2_x_coordinate": 1, "vertex_2_y_coordinate": 0, "vertex_2_z_coordinate": 1,
            "vertex_3_x_coordinate": 2, "vertex_3_y_coordinate": 0, "vertex_3_z_coordinate": 1}}}"#;
        let objects = parse_epjson("m.epJSON", text).unwrap();
        assert_eq!(objects[0].fields.len(), 9 + 9, "trailing blank vertex 4 trimmed: {:?}", objects[0].fields);
        assert_eq!(objects[0].field(8), "");
    }

    #[test]
    fn errors_name_class_object_and_field() {
        let e = parse_epjson("m.epJSON", "{\"Zone\": {\"Z1\": {\"x_origin\": 1,}}}").unwrap_err().to_string();
        assert!(e.starts_with("m.epJSON: not valid epJSON") && e.contains("line 1 column"), "{e}");
        let e = parse_epjson("m.epJSON", r#"{"Zone": {"Z1": {"x_origin": "east"}}}"#).unwrap_err().to_string();
        assert_eq!(e, "m.epJSON: Zone 'Z1' (line 1): field 'x_origin' must be a number, not the string \"east\"");
        let e = parse_epjson("m.epJSON", "{\"Building\": {\n\"B\": {\"terrain\": 3}}}").unwrap_err().to_string();
        assert_eq!(e, "m.epJSON: Building 'B' (line 2): field 'terrain' must be a string, not the number 3");
        let text = r#"{"Shading:Site:Detailed": {"S": {"vertices": [{"vertex_x_coordinate": 0, "vertex_y_coordinate": "a", "vertex_z_coordinate": 0}]}}}"#;
        let e = parse_epjson("m.epJSON", text).unwrap_err().to_string();
        assert!(e.contains("Shading:Site:Detailed 'S'") && e.contains("'vertex_y_coordinate' of vertex 1 must be a number"), "{e}");
        let text = r#"{"Shading:Site:Detailed": {"S": {"vertices": [{"vertex_x_coordinate": 0, "vertex_z_coordinate": 0}]}}}"#;
        let e = parse_epjson("m.epJSON", text).unwrap_err().to_string();
        assert!(e.contains("vertex 1 has no 'vertex_y_coordinate'"), "{e}");
        let e = parse_epjson("m.epJSON", r#"{"Zone": {"Z1": 5}}"#).unwrap_err().to_string();
        assert!(e.contains("Zone 'Z1' (line 1): must be a JSON object"), "{e}");
        let e = parse_epjson("m.epJSON", r#"{"Zone": [1]}"#).unwrap_err().to_string();
        assert!(e.contains("expected a JSON object"), "{e}");
    }
}
