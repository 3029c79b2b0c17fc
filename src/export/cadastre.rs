//! The solar cadastre: per boundary surface of a city model, the year's direct, sky-diffuse,
//! ground-reflected and total irradiation (kWh/m²), sun hours and mean sunlit fraction, written
//! back into the city model (CityJSON), as CSV and as GeoJSON of the roofs.
//!
//! Owns:
//! - surfaces from receivers: a surface the scene split into planar parts (`NAME#1`, `NAME#2`, …)
//!   gets its parts' area-weighted means (for sums per m² and for hours alike);
//! - sun hours: Σ fraction × Δt over the year's timesteps (a timestep with the sun down or behind
//!   the surface has fraction 0), i.e. hours of full sun on the whole surface;
//! - the CityJSON: the input document (a CityJSONSeq merged into one, its vertex indices moved),
//!   each valued surface given a semantic surface of its own, a copy of the one it had with the
//!   values as attributes ([`ATTRIBUTES`]), since a semantic object may be shared by many surfaces.
//!   A surface without a semantic type stays as it was (CityJSON needs a type): its values are in
//!   the CSV;
//! - the GeoJSON: each roof's outline seen from above, in WGS84 when sunlit knows the model's
//!   reference system, else in the model's with a note ([`GeoPlacer`]).

use std::collections::HashMap;
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value, json};

use super::Schedule;
use super::irradiation::SurfaceSummary;
use crate::count::MIN_COS_INCIDENCE;
use crate::error::{Error, Result};
use crate::export::wgs84::ToWgs84;
use crate::model::cityjson::{City, CitySurface, OneDocument};
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// The semantic-surface attributes written, in [`CadastreRow::values`]' order.
pub const ATTRIBUTES: [&str; 6] =
    ["direct_kwh_m2", "sky_diffuse_kwh_m2", "ground_reflected_kwh_m2", "total_kwh_m2", "sun_hours", "mean_sunlit_fraction"];

/// One surface's year.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CadastreRow {
    /// `OBJECT_ID/TYPE/INDEX`.
    pub surface: String,
    /// Its root building.
    pub building: String,
    /// Area, m² (all its planar parts).
    pub area: f64,
    /// Beam, shaded, kWh/m².
    pub direct: f64,
    /// Sky diffuse, shaded, kWh/m².
    pub sky_diffuse: f64,
    /// Ground-reflected, kWh/m².
    pub ground_reflected: f64,
    /// Their sum, kWh/m².
    pub total: f64,
    /// Hours of full sun.
    pub sun_hours: f64,
    /// Mean sunlit fraction over the sun-up timesteps.
    pub mean_fraction: f64,
    /// With a grid and a threshold: the roof's area whose total reaches it, m²
    /// ([`super::cadastre_points`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub usable_area: Option<f64>,
}

impl CadastreRow {
    /// The values in [`ATTRIBUTES`]' order.
    pub fn values(&self) -> [f64; 6] {
        [self.direct, self.sky_diffuse, self.ground_reflected, self.total, self.sun_hours, self.mean_fraction]
    }
}

/// Sun hours per receiver: Σ fraction × Δt over the timesteps with the sun up.
pub fn sun_hours(schedule: &Schedule, location: &Location) -> Vec<f64> {
    let columns = schedule.names.len();
    let step = 1.0 / f64::from(schedule.timesteps.per_hour());
    let mut hours = vec![0.0; columns];
    for (row, instant) in schedule.timesteps.instants().enumerate() {
        if sun_direction(location, shading_sun_day(instant.day), instant.hour).z < MIN_COS_INCIDENCE {
            continue;
        }
        for (c, h) in hours.iter_mut().enumerate() {
            *h += f64::from(schedule.get(row, c)) * step;
        }
    }
    hours
}

/// The surface a receiver stands for: its name, or the name before `#k` of a planar part.
pub(crate) fn surface_of<'a>(receiver: &'a str, surfaces: &HashMap<&str, &CitySurface>) -> Option<&'a str> {
    if surfaces.contains_key(receiver) {
        return Some(receiver);
    }
    let (base, k) = receiver.rsplit_once('#')?;
    (k.chars().all(|c| c.is_ascii_digit()) && surfaces.contains_key(base)).then_some(base)
}

/// One row per city surface that received, in the scene's receiver order: its parts combined by
/// area. `summaries` and `hours` are per receiver of `scene`; they need weather (irradiation).
pub fn rows(city: &City, scene: &Scene, summaries: &[SurfaceSummary], hours: &[f64]) -> Result<Vec<CadastreRow>> {
    let by_name: HashMap<&str, &CitySurface> = city.surfaces.iter().map(|s| (s.name.as_str(), s)).collect();
    let mut order: Vec<&str> = Vec::new();
    let mut sums: HashMap<&str, (f64, [f64; 6])> = HashMap::new();
    for ((receiver, summary), h) in scene.receivers.iter().zip(summaries).zip(hours) {
        let Some(name) = surface_of(&receiver.name, &by_name) else { continue };
        let need = |v: Option<f64>| v.ok_or_else(|| Error::argument("epw", "a solar cadastre needs weather (irradiation)"));
        let values = [
            need(summary.irradiation)?,
            need(summary.sky_diffuse)?,
            need(summary.ground_reflected)?,
            need(summary.total)?,
            *h,
            summary.mean_fraction,
        ];
        let entry = sums.entry(name).or_insert_with(|| {
            order.push(name);
            (0.0, [0.0; 6])
        });
        entry.0 += receiver.area;
        for (sum, v) in entry.1.iter_mut().zip(values) {
            *sum += v * receiver.area;
        }
    }
    Ok(order
        .into_iter()
        .map(|name| {
            let (area, s) = sums[name];
            let mean = |v: f64| if area > 0.0 { v / area } else { 0.0 };
            let surface = by_name[name];
            CadastreRow {
                surface: name.to_string(),
                building: surface.building.clone().unwrap_or_default(),
                area,
                direct: mean(s[0]),
                sky_diffuse: mean(s[1]),
                ground_reflected: mean(s[2]),
                total: mean(s[3]),
                sun_hours: mean(s[4]),
                mean_fraction: mean(s[5]),
                usable_area: None,
            }
        })
        .collect())
}

/// The CSV: a header, then one line per surface (names cannot hold commas: CityJSON ids with
/// one are quoted).
pub fn cadastre_csv(rows: &[CadastreRow]) -> String {
    // The usable area's column only when a grid gave one.
    let usable = rows.iter().any(|r| r.usable_area.is_some());
    let mut text = format!("surface,building,area_m2,{}{}\n", ATTRIBUTES.join(","), if usable { ",usable_area_m2" } else { "" });
    for r in rows {
        let v = r.values();
        let _ = write!(
            text,
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.6}",
            csv_field(&r.surface),
            csv_field(&r.building),
            r.area,
            v[0],
            v[1],
            v[2],
            v[3],
            v[4],
            v[5]
        );
        if usable {
            let _ = write!(text, ",{}", r.usable_area.map(|a| format!("{:.4}", rounded(a))).unwrap_or_default());
        }
        text.push('\n');
    }
    text.replace("-0.0000,", "0.0000,")
}

/// A CSV field: quoted when it holds a comma, quote or line break.
pub(crate) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// The input as one CityJSON document: itself, or a CityJSONSeq's header with every feature's
/// objects and vertices appended (their vertex indices moved past the vertices before them).
pub fn single_document(file: &str, bytes: &[u8]) -> Result<Value> {
    let text = std::str::from_utf8(bytes).map_err(|e| Error::model(file, format!("not UTF-8 text ({e})")))?;
    if let Ok(doc) = serde_json::from_str::<Value>(text) {
        return Ok(doc);
    }
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let parse = |l: &str| serde_json::from_str::<Value>(l).map_err(|e| Error::model(file, format!("not JSON: {e}")));
    let mut one = OneDocument::new(parse(lines.next().unwrap_or(""))?);
    for line in lines {
        one.add(parse(line)?);
    }
    Ok(one.finish())
}

/// A geometry's valued surfaces: surface index → (attribute, value) pairs.
type SurfaceValues<'a> = HashMap<usize, Vec<(&'a str, f64)>>;

/// The city model with the cadastre's values on its surfaces (see the module doc).
pub fn cadastre_cityjson(file: &str, bytes: &[u8], city: &City, rows: &[CadastreRow]) -> Result<Vec<u8>> {
    cadastre_document(file, single_document(file, bytes)?, city, rows)
}

/// [`cadastre_cityjson`] of the input already as one document ([`single_document`]'s); `city`
/// needs only the surfaces `rows` name.
pub fn cadastre_document(file: &str, mut doc: Value, city: &City, rows: &[CadastreRow]) -> Result<Vec<u8>> {
    let by_name: HashMap<&str, &CitySurface> = city.surfaces.iter().map(|s| (s.name.as_str(), s)).collect();
    // (object, geometry) → (surface index → values).
    let mut valued: HashMap<(&str, usize), SurfaceValues> = HashMap::new();
    for r in rows {
        if let Some(s) = by_name.get(r.surface.as_str()).filter(|s| s.kind.is_some()) {
            let mut pairs: Vec<(&str, f64)> = ATTRIBUTES.iter().copied().zip(r.values()).collect();
            pairs.extend(r.usable_area.map(|a| ("usable_area_m2", a)));
            valued.entry((s.object.as_str(), s.geometry)).or_default().insert(s.index, pairs);
        }
    }
    let Some(objects) = doc.get_mut("CityObjects").and_then(Value::as_object_mut) else {
        return Err(Error::model(file, "no \"CityObjects\" object"));
    };
    for ((object, k), values) in valued {
        let geometry = objects.get_mut(object).and_then(|o| o.get_mut("geometry")).and_then(Value::as_array_mut).and_then(|a| a.get_mut(k));
        if let Some(geometry) = geometry {
            put_values(geometry, &values);
        }
    }
    let mut text = serde_json::to_vec(&doc).map_err(|e| Error::model(file, e.to_string()))?;
    text.push(b'\n');
    Ok(text)
}

/// Gives each valued surface of `geometry` a semantic surface of its own with the values.
fn put_values(geometry: &mut Value, values: &SurfaceValues) {
    let depth = match geometry.get("type").and_then(Value::as_str) {
        Some("MultiSurface" | "CompositeSurface") => 0,
        Some("Solid") => 1,
        Some("MultiSolid" | "CompositeSolid") => 2,
        _ => return,
    };
    let Some(semantics) = geometry.get("semantics").cloned() else { return };
    let mut surfaces: Vec<Value> = semantics.get("surfaces").and_then(Value::as_array).cloned().unwrap_or_default();
    let mut flat: Vec<Value> = Vec::new();
    if let Some(v) = semantics.get("values") {
        flatten_values(v, depth, &mut flat);
    }
    let mut keys: Vec<&usize> = values.keys().collect();
    keys.sort();
    for &s in keys {
        let Some(old) = flat.get(s).and_then(Value::as_u64).and_then(|k| surfaces.get(k as usize)) else { continue };
        let mut own = old.as_object().cloned().unwrap_or_default();
        // Indices into the old list would point astray in the new one.
        own.remove("parent");
        own.remove("children");
        for &(key, v) in &values[&s] {
            own.insert(key.to_string(), json!(rounded(v)));
        }
        flat[s] = json!(surfaces.len());
        surfaces.push(Value::Object(own));
    }
    let mut at = 0;
    let nested = geometry.get("boundaries").map(|b| nest_like(b, depth, &flat, &mut at));
    if let (Some(nested), Some(sem)) = (nested, geometry.get_mut("semantics")) {
        sem["surfaces"] = Value::Array(surfaces);
        sem["values"] = nested;
    }
}

/// Six decimals, and never −0.
pub(crate) fn rounded(v: f64) -> f64 {
    let r = (v * 1e6).round() / 1e6;
    if r == 0.0 { 0.0 } else { r }
}

fn flatten_values(v: &Value, depth: usize, out: &mut Vec<Value>) {
    match (v, depth) {
        (Value::Array(items), 0) => out.extend(items.iter().cloned()),
        (Value::Array(items), d) => items.iter().for_each(|i| flatten_values(i, d - 1, out)),
        _ => {}
    }
}

/// `flat` shaped as `boundaries` is down to its surfaces.
fn nest_like(boundaries: &Value, depth: usize, flat: &[Value], at: &mut usize) -> Value {
    let items = boundaries.as_array().map(Vec::as_slice).unwrap_or(&[]);
    if depth == 0 {
        return Value::Array(
            items
                .iter()
                .map(|_| {
                    *at += 1;
                    flat.get(*at - 1).cloned().unwrap_or(Value::Null)
                })
                .collect(),
        );
    }
    Value::Array(items.iter().map(|i| nest_like(i, depth - 1, flat, at)).collect())
}

/// Roofs as GeoJSON: each `RoofSurface` row's outline seen from above (exterior counter-clockwise,
/// holes clockwise, as RFC 7946 asks), its values as properties, in WGS84 when sunlit knows the
/// model's reference system ([`GeoPlacer`]).
pub fn roofs_geojson(city: &City, rows: &[CadastreRow], north_note: &str) -> Result<String> {
    let placer = GeoPlacer::new(city);
    let by_name: HashMap<&str, &CitySurface> = city.surfaces.iter().map(|s| (s.name.as_str(), s)).collect();
    let mut features: Vec<Value> = Vec::new();
    for r in rows {
        let Some(s) = by_name.get(r.surface.as_str()).filter(|s| s.kind.as_deref() == Some("RoofSurface")) else { continue };
        let rings: Vec<Value> = s
            .rings
            .iter()
            .enumerate()
            .map(|(i, ring)| {
                let mut xy: Vec<[f64; 2]> = ring.iter().map(|p| [p.x + city.offset.x, p.y + city.offset.y]).collect();
                let area: f64 = (0..xy.len()).map(|k| xy[k][0] * xy[(k + 1) % xy.len()][1] - xy[(k + 1) % xy.len()][0] * xy[k][1]).sum();
                if (area < 0.0) == (i == 0) {
                    xy.reverse();
                }
                xy.push(xy[0]);
                xy.iter().map(|p| placer.place(p[0], p[1], None)).collect::<Result<Vec<Value>>>().map(Value::Array)
            })
            .collect::<Result<_>>()?;
        let mut properties = Map::new();
        properties.insert("surface".into(), json!(r.surface));
        properties.insert("building".into(), json!(r.building));
        properties.insert("area_m2".into(), json!(rounded(r.area)));
        for (key, v) in ATTRIBUTES.iter().zip(r.values()) {
            properties.insert(key.to_string(), json!(rounded(v)));
        }
        if let Some(a) = r.usable_area {
            properties.insert("usable_area_m2".into(), json!(rounded(a)));
        }
        features.push(json!({"type": "Feature", "geometry": {"type": "Polygon", "coordinates": rings}, "properties": properties}));
    }
    Ok(placer.collection(features, north_note))
}

/// Where a GeoJSON puts a city model's point: WGS84 longitude and latitude (RFC 7946) when sunlit
/// knows the model's reference system ([`ToWgs84`]), else the model's own coordinates with a
/// `crs` member naming its system, as GeoJSON before RFC 7946 did, and a note saying why.
pub struct GeoPlacer<'a> {
    city: &'a City,
    wgs84: std::result::Result<ToWgs84, String>,
}

impl<'a> GeoPlacer<'a> {
    /// The placer for `city`'s reference system.
    pub fn new(city: &'a City) -> Self {
        Self { city, wgs84: ToWgs84::new(city.reference_system.as_deref()).map_err(|e| e.to_string()) }
    }

    /// A position: `[lon, lat]` (degrees) in WGS84, else `[x, y]` or `[x, y, z]` in the model's
    /// system (z only given there: heights are not WGS84's); six decimals.
    pub fn place(&self, x: f64, y: f64, z: Option<f64>) -> Result<Value> {
        match &self.wgs84 {
            Ok(w) => Ok(json!(w.lon_lat(x, y)?.map(rounded))),
            Err(_) => Ok(json!([x, y].into_iter().chain(z).map(rounded).collect::<Vec<f64>>())),
        }
    }

    /// The feature collection with its `sunlit` member (and `crs` when not WGS84), as text.
    pub fn collection(&self, features: Vec<Value>, north_note: &str) -> String {
        let units = json!({"irradiation": "kWh/m2", "sun_hours": "h", "area": "m2"});
        let mut doc = match &self.wgs84 {
            Ok(w) => json!({"type": "FeatureCollection", "sunlit": {
                "note": format!("WGS84 longitude and latitude (RFC 7946), reprojected from EPSG:{} with proj4rs", w.epsg),
                "north": north_note, "units": units}}),
            Err(why) => {
                let crs = self.city.reference_system.clone().unwrap_or_else(|| "unknown (the city model names none)".into());
                json!({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": crs}}, "sunlit": {
                    "note": format!("coordinates in the city model's reference system, not WGS84: {why}"),
                    "north": north_note, "units": units}})
            }
        };
        doc["features"] = Value::Array(features);
        let mut text = doc.to_string();
        text.push('\n');
        text
    }
}

#[cfg(test)]
#[path = "cadastre_tests.rs"]
mod tests;
