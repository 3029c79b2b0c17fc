//! CityJSON writers for tests and benchmarks (feature `fixtures`): a scene's own geometry as a
//! city model (the round trip), and a generated LoD2 district (pitched and flat roofs, courtyards,
//! varied heights and street widths).
//!
//! Both write CityJSON 2.0 with a millimetre `transform` (scale 0.001) and, for the district, a
//! Dutch-style `translate` and `referenceSystem` (EPSG:7415), as the 3D BAG does.

use std::collections::HashMap;

use glam::DVec3;
use serde_json::{Value, json};

use crate::scene::Scene;

/// Vertices on a millimetre grid, deduplicated.
#[derive(Default)]
struct Vertices {
    list: Vec<[i64; 3]>,
    index: HashMap<[i64; 3], usize>,
}

impl Vertices {
    fn add(&mut self, p: DVec3) -> usize {
        let k = [(p.x * 1000.0).round() as i64, (p.y * 1000.0).round() as i64, (p.z * 1000.0).round() as i64];
        *self.index.entry(k).or_insert_with(|| {
            self.list.push(k);
            self.list.len() - 1
        })
    }

    fn ring(&mut self, points: &[DVec3]) -> Vec<usize> {
        points.iter().map(|p| self.add(*p)).collect()
    }
}

fn document(objects: serde_json::Map<String, Value>, vertices: Vertices, translate: [f64; 3], crs: Option<&str>) -> String {
    let mut doc = json!({
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [0.001, 0.001, 0.001], "translate": translate},
        "CityObjects": objects,
        "vertices": vertices.list,
    });
    if let Some(crs) = crs {
        doc["metadata"] = json!({"referenceSystem": crs});
    }
    doc.to_string()
}

/// A semantic type for a surface facing `normal`.
fn kind_of(normal: DVec3) -> &'static str {
    if normal.z > 0.1 {
        "RoofSurface"
    } else if normal.z < -0.9 {
        "GroundSurface"
    } else {
        "WallSurface"
    }
}

/// The scene as CityJSON: receiver `i` is Building `R{i}` with one MultiSurface surface per
/// triangle (typed by its normal); everything else is one `GenericCityObject` that only casts
/// shadows. Coordinates are rounded to the millimetre (exact for geometry on that grid).
pub fn scene_cityjson(scene: &Scene) -> String {
    let mut vertices = Vertices::default();
    let mut objects = serde_json::Map::new();
    for (i, r) in scene.receivers.iter().enumerate() {
        let kind = kind_of(r.normal);
        let boundaries: Vec<Value> = r.triangles.iter().map(|t| json!([vertices.ring(t)])).collect();
        let values = vec![0; boundaries.len()];
        objects.insert(
            format!("R{i}"),
            json!({"type": "Building", "attributes": {"sunlit_name": r.name}, "geometry": [{
                "type": "MultiSurface", "lod": "2.2", "boundaries": boundaries,
                "semantics": {"surfaces": [{"type": kind}], "values": values},
            }]}),
        );
    }
    let context: Vec<Value> = scene.world_triangles().filter(|(_, id)| id.is_none()).map(|(t, _)| json!([vertices.ring(&t)])).collect();
    if !context.is_empty() {
        objects.insert(
            "context".into(),
            json!({"type": "GenericCityObject", "geometry": [{"type": "MultiSurface", "lod": "2", "boundaries": context}]}),
        );
    }
    document(objects, vertices, [0.0, 0.0, 0.0], None)
}

/// A generated district of `columns` × `rows` blocks, one building a block: footprints 10–18 m,
/// heights 6–24 m, streets 8–16 m wide, every third building flat-roofed with a courtyard when
/// large enough, the rest gabled (ridge east–west or north–south). Deterministic for a `seed`.
pub fn district_cityjson(columns: usize, rows: usize, seed: u64) -> String {
    district_cityjson_with(columns, rows, seed, false)
}

/// [`district_cityjson`], with `rooftops`: a stair housing (3 × 3 × 3 m) on every flat roof and a
/// chimney (0.8 × 0.8 m, 0.8 m above the ridge) through one slope of every pitched roof, each cut
/// into its roof as a hole and closed by its own walls and top, so each building's solid stays
/// closed and gains four walls and a roof: about 11 receivers a building instead of 6 (the
/// issue's ~20,000 for 2,000 buildings). The same seed gives the same buildings either way.
pub fn district_cityjson_with(columns: usize, rows: usize, seed: u64, rooftops: bool) -> String {
    let mut vertices = Vertices::default();
    let mut objects = serde_json::Map::new();
    let mut state = seed ^ 0x9e37_79b9_7f4a_7c15;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut y = 0.0;
    for row in 0..rows {
        let mut x = 0.0;
        let depth = 10.0 + 8.0 * random();
        for column in 0..columns {
            let width = 10.0 + 8.0 * random();
            let height = (6.0 + 18.0 * random()).round();
            let id = format!("B{row:03}{column:03}");
            let k = row * columns + column;
            let geometry = if k.is_multiple_of(3) {
                flat_block(&mut vertices, [x, y], [width, depth], height, width > 14.0 && depth > 14.0, rooftops)
            } else {
                gabled(&mut vertices, [x, y], [width, depth], height, 2.0 + 3.0 * random(), k.is_multiple_of(2), rooftops)
            };
            objects.insert(id, json!({"type": "Building", "attributes": {"measuredHeight": height}, "geometry": [geometry]}));
            x += width + 8.0 + 8.0 * random();
        }
        y += depth + 8.0 + 8.0 * random();
    }
    document(objects, vertices, [85000.0, 447000.0, 0.0], Some("https://www.opengis.net/def/crs/EPSG/0/7415"))
}

/// Points of a rectangle at height z, counter-clockwise from above.
fn rect(at: [f64; 2], size: [f64; 2], z: f64) -> Vec<DVec3> {
    let [x, y] = at;
    let [w, d] = size;
    vec![DVec3::new(x, y, z), DVec3::new(x + w, y, z), DVec3::new(x + w, y + d, z), DVec3::new(x, y + d, z)]
}

/// Walls between two rings (counter-clockwise from above) at heights 0 and `top`, facing out of
/// the ring's left side (`outward`: the ring runs counter-clockwise about the outside).
fn walls(v: &mut Vertices, ring: &[DVec3], top: &[f64], outward: bool, surfaces: &mut Vec<Value>, values: &mut Vec<usize>) {
    for i in 0..ring.len() {
        let j = (i + 1) % ring.len();
        let (a, b) = (ring[i], ring[j]);
        let quad = [a, b, DVec3::new(b.x, b.y, top[j]), DVec3::new(a.x, a.y, top[i])];
        let quad: Vec<DVec3> = if outward { quad.to_vec() } else { quad.iter().rev().copied().collect() };
        surfaces.push(json!([v.ring(&quad)]));
        values.push(1);
    }
}

/// A flat-roofed block, with a courtyard (a hole in roof and ground, inner walls) when asked.
fn flat_block(v: &mut Vertices, at: [f64; 2], size: [f64; 2], height: f64, courtyard: bool, housing: bool) -> Value {
    let outer = rect(at, size, 0.0);
    let inner = rect([at[0] + 5.0, at[1] + 5.0], [size[0] - 10.0, size[1] - 10.0], 0.0);
    let up = |ring: &[DVec3]| ring.iter().map(|p| DVec3::new(p.x, p.y, height)).collect::<Vec<_>>();
    let reversed = |ring: &[DVec3]| ring.iter().rev().copied().collect::<Vec<_>>();
    let (mut surfaces, mut values) = (Vec::new(), Vec::new());
    let mut ground = vec![v.ring(&reversed(&outer))];
    let mut roof = vec![v.ring(&up(&outer))];
    if courtyard {
        ground.push(v.ring(&inner));
        roof.push(v.ring(&reversed(&up(&inner))));
    }
    surfaces.push(json!(ground));
    values.push(2);
    surfaces.push(json!(roof));
    values.push(0);
    walls(v, &outer, &[height; 4], true, &mut surfaces, &mut values);
    if courtyard {
        walls(v, &inner, &[height; 4], false, &mut surfaces, &mut values);
    }
    if housing {
        // In the corner of the roof, clear of a courtyard (5 m in) on any block (10 m or more).
        let foot = rect([at[0] + 1.0, at[1] + 1.0], [3.0, 3.0], height);
        rooftop(v, &foot, height + 3.0, 1, &mut surfaces, &mut values);
    }
    solid(surfaces, values)
}

/// A gabled house: eaves at `height`, the ridge `rise` above, along x (`along_x`) or y.
fn gabled(v: &mut Vertices, at: [f64; 2], size: [f64; 2], height: f64, rise: f64, along_x: bool, chimney: bool) -> Value {
    let outer = rect(at, size, 0.0);
    let [x, y] = at;
    let [w, d] = size;
    let ridge = height + rise;
    let (mut surfaces, mut values) = (Vec::new(), Vec::new());
    surfaces.push(json!([v.ring(&outer.iter().rev().copied().collect::<Vec<_>>())]));
    values.push(2);
    let p = |px: f64, py: f64, pz: f64| DVec3::new(px, py, pz);
    if along_x {
        // Long walls south and north; gable walls east and west (pentagons).
        let faces = [
            vec![p(x, y, 0.0), p(x + w, y, 0.0), p(x + w, y, height), p(x, y, height)],
            vec![p(x + w, y, 0.0), p(x + w, y + d, 0.0), p(x + w, y + d, height), p(x + w, y + d / 2.0, ridge), p(x + w, y, height)],
            vec![p(x + w, y + d, 0.0), p(x, y + d, 0.0), p(x, y + d, height), p(x + w, y + d, height)],
            vec![p(x, y + d, 0.0), p(x, y, 0.0), p(x, y, height), p(x, y + d / 2.0, ridge), p(x, y + d, height)],
        ];
        for f in faces {
            surfaces.push(json!([v.ring(&f)]));
            values.push(1);
        }
        for roof in [
            vec![p(x, y, height), p(x + w, y, height), p(x + w, y + d / 2.0, ridge), p(x, y + d / 2.0, ridge)],
            vec![p(x + w, y + d, height), p(x, y + d, height), p(x, y + d / 2.0, ridge), p(x + w, y + d / 2.0, ridge)],
        ] {
            surfaces.push(json!([v.ring(&roof)]));
            values.push(0);
        }
    } else {
        let faces = [
            vec![p(x, y, 0.0), p(x + w, y, 0.0), p(x + w, y, height), p(x + w / 2.0, y, ridge), p(x, y, height)],
            vec![p(x + w, y, 0.0), p(x + w, y + d, 0.0), p(x + w, y + d, height), p(x + w, y, height)],
            vec![p(x + w, y + d, 0.0), p(x, y + d, 0.0), p(x, y + d, height), p(x + w / 2.0, y + d, ridge), p(x + w, y + d, height)],
            vec![p(x, y + d, 0.0), p(x, y, 0.0), p(x, y, height), p(x, y + d, height)],
        ];
        for f in faces {
            surfaces.push(json!([v.ring(&f)]));
            values.push(1);
        }
        for roof in [
            vec![p(x + w, y, height), p(x + w, y + d, height), p(x + w / 2.0, y + d, ridge), p(x + w / 2.0, y, ridge)],
            vec![p(x, y + d, height), p(x, y, height), p(x + w / 2.0, y, ridge), p(x + w / 2.0, y + d, ridge)],
        ] {
            surfaces.push(json!([v.ring(&roof)]));
            values.push(0);
        }
    }
    if chimney {
        // Through the middle of the first roof slope (the last but one surface), from the slope
        // up to 0.8 m above the ridge.
        let (h, run) = (height, if along_x { d / 2.0 } else { w / 2.0 });
        let slope = |px: f64, py: f64| if along_x { h + rise * (py - y) / run } else { h + rise * (x + w - px) / run };
        let (cx, cy) = if along_x { (x + w / 2.0, y + d / 4.0) } else { (x + 3.0 * w / 4.0, y + d / 2.0) };
        let foot: Vec<DVec3> =
            rect([cx - 0.4, cy - 0.4], [0.8, 0.8], 0.0).into_iter().map(|q| DVec3::new(q.x, q.y, slope(q.x, q.y))).collect();
        let roof = surfaces.len() - 2;
        rooftop(v, &foot, ridge + 0.8, roof, &mut surfaces, &mut values);
    }
    solid(surfaces, values)
}

/// A box standing on (or through) a roof: `foot` (counter-clockwise from above, on the roof's
/// plane) is cut out of surface `roof` as a hole, walls rise from it to `top`, and a flat roof
/// closes it.
fn rooftop(v: &mut Vertices, foot: &[DVec3], top: f64, roof: usize, surfaces: &mut Vec<Value>, values: &mut Vec<usize>) {
    let hole: Vec<DVec3> = foot.iter().rev().copied().collect();
    let hole = json!(v.ring(&hole));
    if let Some(rings) = surfaces.get_mut(roof).and_then(Value::as_array_mut) {
        rings.push(hole);
    }
    walls(v, foot, &[top; 4], true, surfaces, values);
    let lid: Vec<DVec3> = foot.iter().map(|p| DVec3::new(p.x, p.y, top)).collect();
    surfaces.push(json!([v.ring(&lid)]));
    values.push(0);
}

/// A Solid's geometry with Roof (0), Wall (1) and Ground (2) semantics.
fn solid(surfaces: Vec<Value>, values: Vec<usize>) -> Value {
    json!({
        "type": "Solid", "lod": "2.2", "boundaries": [surfaces],
        "semantics": {"surfaces": [{"type": "RoofSurface"}, {"type": "WallSurface"}, {"type": "GroundSurface"}], "values": [values]},
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::collections::HashMap;

    use super::*;

    /// Per building: its roof and wall surfaces, and whether its solid is closed (every edge of
    /// every ring, holes included, met once each way).
    fn buildings(doc: &str) -> HashMap<String, (usize, bool)> {
        let doc: Value = serde_json::from_str(doc).unwrap();
        let mut out = HashMap::new();
        for (id, object) in doc["CityObjects"].as_object().unwrap() {
            let geometry = &object["geometry"][0];
            let kinds = &geometry["semantics"]["surfaces"];
            let values = geometry["semantics"]["values"][0].as_array().unwrap();
            let receivers = values.iter().filter(|v| kinds[v.as_u64().unwrap() as usize]["type"] != "GroundSurface").count();
            let mut edges: HashMap<(u64, u64), i64> = HashMap::new();
            for ring in geometry["boundaries"][0].as_array().unwrap().iter().flat_map(|s| s.as_array().unwrap()) {
                let ring: Vec<u64> = ring.as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
                for (k, &a) in ring.iter().enumerate() {
                    let b = ring[(k + 1) % ring.len()];
                    *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
                }
            }
            out.insert(id.clone(), (receivers, edges.values().all(|&n| n == 0)));
        }
        out
    }

    /// Rooftops add a stair housing or a chimney to every building, four walls and a roof each,
    /// keeping the buildings (same ids, same seed) and their solids closed: about 11 receivers a
    /// building instead of 6.
    #[test]
    fn rooftops_add_five_receivers_a_building_and_keep_solids_closed() {
        let (plain, topped) = (buildings(&district_cityjson(6, 5, 3)), buildings(&district_cityjson_with(6, 5, 3, true)));
        assert_eq!(plain.len(), 30);
        for (id, (receivers, closed)) in &topped {
            assert!(*closed, "{id}'s solid is open");
            assert_eq!(*receivers, plain[id].0 + 5, "{id}");
            assert!(plain[id].1);
        }
        let total: usize = topped.values().map(|b| b.0).sum();
        assert!((300..360).contains(&total), "{total} receivers for 30 buildings");
    }
}
