//! A map as a glb: each point a small square on its receiver, its corners coloured by the
//! point's value (`COLOR_0`), over the receivers' own triangles in grey; the legend (value,
//! unit, range, colour stops) in the scene's `extras.sunlit_map`.
//!
//! Axes as [`crate::model::glb_write`] writes them (sunlit's x east, y north, z up become glTF's
//! `(x, z, −y)`). Squares stand 1 mm in front of their receiver so viewers do not z-fight them;
//! a grid's squares are its cells (`spacing` wide), a CSV's points get 0.1 m squares.

use glam::DVec3;
use serde_json::{Value, json};

use crate::map::Points;
use crate::scene::Scene;

/// Side (m) of the square drawn for a point that is not on a grid.
const POINT_SQUARE: f64 = 0.1;
/// How far (m) a square stands in front of its receiver.
const LIFT: f64 = 0.001;

/// The legend's colour stops: a sequential ramp from dark blue (low) through teal and green to
/// yellow (high), as value fractions 0..1 and linear RGB.
const RAMP: [(f32, [f32; 3]); 5] =
    [(0.0, [0.02, 0.01, 0.2]), (0.25, [0.05, 0.15, 0.45]), (0.5, [0.05, 0.45, 0.45]), (0.75, [0.3, 0.7, 0.15]), (1.0, [0.98, 0.85, 0.1])];

/// The ramp's colour at `t` in 0..1.
fn colour(t: f32) -> [f32; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    for w in RAMP.windows(2) {
        let ((a, ca), (b, cb)) = (w[0], w[1]);
        if t <= b {
            let k = if b > a { (t - a) / (b - a) } else { 0.0 };
            return std::array::from_fn(|i| ca[i] + (cb[i] - ca[i]) * k);
        }
    }
    RAMP[RAMP.len() - 1].1
}

fn to_gltf(p: DVec3) -> [f32; 3] {
    [p.x as f32, p.z as f32, -p.y as f32 + 0.0]
}

/// The map glb: `values` one per point, named `value` in `unit` for the legend.
pub fn map_glb(scene: &Scene, points: &Points, values: &[f64], value: &str, unit: &str) -> Vec<u8> {
    let (lo, hi) = values.iter().filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
    let span = if hi > lo { hi - lo } else { 1.0 };
    let side = points.spacing.unwrap_or(POINT_SQUARE);

    // The receivers in grey.
    let mut base: Vec<[f32; 3]> = Vec::new();
    for r in &scene.receivers {
        for t in &r.triangles {
            base.extend(t.iter().map(|p| to_gltf(*p)));
        }
    }
    // One square per point: two triangles, four corners of the point's colour.
    let mut tiles: Vec<[f32; 3]> = Vec::with_capacity(4 * points.len());
    let mut colours: Vec<[f32; 4]> = Vec::with_capacity(4 * points.len());
    let mut indices: Vec<u32> = Vec::with_capacity(6 * points.len());
    for (i, &v) in values.iter().enumerate().take(points.len()) {
        let n = points.normal(i);
        let e1 = if n.z.abs() < 0.9 { DVec3::Z.cross(n).normalize() } else { (DVec3::X - n * n.x).normalize() };
        let e2 = n.cross(e1);
        let c = points.position(i) + n * LIFT;
        let k = tiles.len() as u32;
        for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            tiles.push(to_gltf(c + e1 * (a * side) + e2 * (b * side)));
        }
        let rgb = colour(((v - lo) / span) as f32);
        colours.extend([[rgb[0], rgb[1], rgb[2], 1.0]; 4]);
        indices.extend([k, k + 1, k + 2, k, k + 2, k + 3]);
    }

    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut push_view = |bin: &mut Vec<u8>, bytes: Vec<u8>, target: u32| {
        let offset = bin.len();
        bin.extend(bytes);
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bin.len() - offset, "target": target}));
        views.len() - 1
    };
    let floats = |v: &[[f32; 3]]| v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let bounds = |v: &[[f32; 3]]| {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in v {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        (lo, hi)
    };
    let mut meshes: Vec<Value> = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    if !base.is_empty() {
        let (min, max) = bounds(&base);
        let view = push_view(&mut bin, floats(&base), 34962);
        accessors.push(json!({"bufferView": view, "componentType": 5126, "count": base.len(), "type": "VEC3", "min": min, "max": max}));
        meshes.push(
            json!({"name": "receivers", "primitives": [{"attributes": {"POSITION": accessors.len() - 1}, "material": 0, "mode": 4}]}),
        );
        nodes.push(json!({"name": "receivers", "mesh": meshes.len() - 1}));
    }
    if !tiles.is_empty() {
        let (min, max) = bounds(&tiles);
        let view = push_view(&mut bin, floats(&tiles), 34962);
        accessors.push(json!({"bufferView": view, "componentType": 5126, "count": tiles.len(), "type": "VEC3", "min": min, "max": max}));
        let position = accessors.len() - 1;
        let view = push_view(&mut bin, colours.iter().flatten().flat_map(|f| f.to_le_bytes()).collect(), 34962);
        accessors.push(json!({"bufferView": view, "componentType": 5126, "count": colours.len(), "type": "VEC4"}));
        let colour = accessors.len() - 1;
        let view = push_view(&mut bin, indices.iter().flat_map(|i| i.to_le_bytes()).collect(), 34963);
        accessors.push(json!({"bufferView": view, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}));
        meshes.push(json!({"name": "map", "primitives": [{"attributes": {"POSITION": position, "COLOR_0": colour}, "indices": accessors.len() - 1, "material": 1, "mode": 4}]}));
        nodes.push(json!({"name": "map", "mesh": meshes.len() - 1}));
    }
    let legend = json!({
        "value": value,
        "unit": unit,
        "min": lo,
        "max": hi,
        "points": points.len(),
        "stops": RAMP.iter().map(|(t, c)| json!({"value": lo + f64::from(*t) * span, "color": c})).collect::<Vec<_>>(),
    });
    let mut root = json!({
        "asset": {"version": "2.0", "generator": "sunlit map"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>(), "extras": {"sunlit_map": legend}}],
        "nodes": nodes,
        "materials": [
            {"name": "receiver", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 0.0}, "doubleSided": true},
            {"name": "map", "pbrMetallicRoughness": {"metallicFactor": 0.0}, "doubleSided": true},
        ],
    });
    if !meshes.is_empty() {
        root["meshes"] = Value::Array(meshes);
        root["accessors"] = Value::Array(accessors);
        root["bufferViews"] = Value::Array(views);
        root["buffers"] = json!([{"byteLength": bin.len()}]);
    }
    glb_bytes(&root.to_string(), &bin)
}

/// The GLB container: header, JSON chunk padded with spaces, BIN chunk padded with zeros.
fn glb_bytes(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut text = json.as_bytes().to_vec();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut data = bin.to_vec();
    while !data.len().is_multiple_of(4) {
        data.push(0);
    }
    let total = 12 + 8 + text.len() + if data.is_empty() { 0 } else { 8 + data.len() };
    let mut out = Vec::with_capacity(total);
    out.extend(0x4654_6C67u32.to_le_bytes());
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(text);
    if !data.is_empty() {
        out.extend((data.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(data);
    }
    out
}
