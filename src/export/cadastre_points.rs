//! The solar cadastre's per-point maps on roofs (`sunlit district --grid`): each grid point's
//! year, and each roof's usable area (its area whose total irradiation reaches a threshold).
//!
//! Owns:
//! - [`PointRow`]: one grid point's annual sums, at its place in the city model's coordinates
//!   (the model's reference system, as the roofs' GeoJSON);
//! - a roof's usable area: the share of its grid points whose total reaches the threshold times
//!   its area (each point stands for an equal share of its roof; a roof too small to hold a
//!   point has none: `None`, an empty cell);
//! - the points' CSV and GeoJSON.

use std::collections::HashMap;
use std::fmt::Write as _;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value, json};

use super::cadastre::{CadastreRow, GeoPlacer, rounded, surface_of};
use crate::error::{Error, Result};
use crate::map::{MapValues, Points};
use crate::model::cityjson::{City, CitySurface};
use crate::scene::Scene;

/// One grid point's year.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointRow {
    /// The surface it lies on (`OBJECT_ID/TYPE/INDEX`).
    pub surface: String,
    /// Its root building.
    pub building: String,
    /// Where, in the city model's coordinates (m).
    pub position: [f64; 3],
    /// Beam, shaded, kWh/m².
    pub direct: f64,
    /// Sky diffuse, shaded, kWh/m².
    pub sky_diffuse: f64,
    /// Ground-reflected, kWh/m².
    pub ground_reflected: f64,
    /// Their sum, kWh/m².
    pub total: f64,
    /// Hours of sun.
    pub sun_hours: f64,
}

/// The point columns, in [`PointRow`]'s value order.
pub const POINT_COLUMNS: [&str; 5] = ["direct_kwh_m2", "sky_diffuse_kwh_m2", "ground_reflected_kwh_m2", "total_kwh_m2", "sun_hours"];

impl PointRow {
    fn values(&self) -> [f64; 5] {
        [self.direct, self.sky_diffuse, self.ground_reflected, self.total, self.sun_hours]
    }
}

/// The points' rows, and each row's usable area set from them when `min_kwh_m2` is given.
/// `to_model` takes a scene position to the city model's coordinates.
pub fn point_rows(
    city: &City,
    scene: &Scene,
    points: &Points,
    values: &MapValues,
    min_kwh_m2: Option<f64>,
    rows: &mut [CadastreRow],
    to_model: impl Fn(DVec3) -> DVec3,
) -> Result<Vec<PointRow>> {
    let need = |v: &Option<Vec<f64>>| v.clone().ok_or_else(|| Error::argument("epw", "a roof's map needs weather (irradiation)"));
    let (direct, sky, ground, total) = (
        need(&values.direct_kwh_m2)?,
        need(&values.sky_diffuse_kwh_m2)?,
        need(&values.ground_reflected_kwh_m2)?,
        need(&values.total_kwh_m2)?,
    );
    let by_name: HashMap<&str, &CitySurface> = city.surfaces.iter().map(|s| (s.name.as_str(), s)).collect();
    let mut out = Vec::with_capacity(points.len());
    // surface → (points, points at or above the threshold).
    let mut counts: HashMap<String, (usize, usize)> = HashMap::new();
    for i in 0..points.len() {
        let receiver = &scene.receivers[points.receivers[i] as usize];
        let Some(name) = surface_of(&receiver.name, &by_name) else { continue };
        let p = to_model(points.position(i));
        let row = PointRow {
            surface: name.to_string(),
            building: by_name[name].building.clone().unwrap_or_default(),
            position: p.to_array(),
            direct: direct[i],
            sky_diffuse: sky[i],
            ground_reflected: ground[i],
            total: total[i],
            sun_hours: values.sun_hours[i],
        };
        let c = counts.entry(row.surface.clone()).or_default();
        c.0 += 1;
        c.1 += usize::from(min_kwh_m2.is_some_and(|m| row.total >= m));
        out.push(row);
    }
    if min_kwh_m2.is_some() {
        for r in rows.iter_mut() {
            r.usable_area = counts.get(&r.surface).map(|&(n, above)| r.area * above as f64 / n as f64);
        }
    }
    Ok(out)
}

/// `surface,building,x,y,z,` then [`POINT_COLUMNS`]: one line per point.
pub fn points_csv(points: &[PointRow]) -> String {
    let mut text = format!("surface,building,x,y,z,{}\n", POINT_COLUMNS.join(","));
    for p in points {
        let _ = write!(text, "{},{}", super::cadastre::csv_field(&p.surface), super::cadastre::csv_field(&p.building));
        for v in p.position.iter().chain(&p.values()) {
            let _ = write!(text, ",{:.4}", rounded(*v));
        }
        text.push('\n');
    }
    text
}

/// The points as GeoJSON `Point`s, placed as the roofs' ([`GeoPlacer`]: WGS84 when the model's
/// system is known), their values as properties.
pub fn points_geojson(points: &[PointRow], placer: &GeoPlacer, north_note: &str) -> Result<String> {
    let features: Vec<Value> = points
        .iter()
        .map(|p| {
            let mut properties = Map::new();
            properties.insert("surface".into(), json!(p.surface));
            properties.insert("building".into(), json!(p.building));
            for (key, v) in POINT_COLUMNS.iter().zip(p.values()) {
                properties.insert(key.to_string(), json!(rounded(v)));
            }
            let [x, y, z] = p.position;
            Ok(json!({"type": "Feature", "geometry": {"type": "Point", "coordinates": placer.place(x, y, Some(z))?}, "properties": properties}))
        })
        .collect::<Result<_>>()?;
    Ok(placer.collection(features, north_note))
}
