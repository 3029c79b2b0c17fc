//! Wavefront OBJ reader into the readers' common [`GltfModel`]: one node per name, the faces
//! under an `o` and/or `g` line (`OBJECT/GROUP` with both, else the one given, else `default`),
//! so `receivers` globs select them as they select glTF nodes.
//!
//! Owns OBJ's missing conventions: which axis is up ([`ObjUp`]; y, as most exporters write) and
//! the unit ([`ObjUnit`]; metres unless told). Vertices are read in f64, the first vertex
//! subtracted before they become f32 and added back by the node's transform, so georeferenced
//! OBJ keeps millimetres. Polygons are ear-clipped about their plane. Texture and normal indices
//! (`v/vt/vn`) are read past; negative (relative) indices are resolved. Everything else
//! (materials, lines, points, smoothing) is ignored. A face indexing a missing vertex is an error
//! naming the file, the line and the name it belongs to.

use std::collections::HashMap;

use glam::{DMat4, DVec3};

use super::gltf_read::{GltfModel, GltfNode, gltf_to_world};
use crate::error::{Error, Result};
use crate::geometry::{Plane, triangulate};
use crate::scene::{NodeVeil, SourceMesh};

/// Which OBJ axis points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ObjUp {
    /// +y up, −z north (as glTF).
    #[default]
    Y,
    /// +z up, +y north (as sunlit and EnergyPlus).
    Z,
}

impl ObjUp {
    /// `y` or `z`.
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "y" => Ok(ObjUp::Y),
            "z" => Ok(ObjUp::Z),
            _ => Err(Error::argument("up", format!("'{text}' is not y or z"))),
        }
    }
}

/// The length an OBJ unit stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjUnit(pub f64);

impl Default for ObjUnit {
    fn default() -> Self {
        ObjUnit(1.0)
    }
}

impl ObjUnit {
    /// `m`, `cm`, `mm`, `ft` or `in`.
    pub fn parse(text: &str) -> Result<Self> {
        let metres = match text.trim().to_ascii_lowercase().as_str() {
            "m" => 1.0,
            "cm" => 0.01,
            "mm" => 0.001,
            "ft" => 0.3048,
            "in" => 0.0254,
            _ => return Err(Error::argument("unit", format!("'{text}' is not one of m, cm, mm, ft, in"))),
        };
        Ok(ObjUnit(metres))
    }
}

/// Whether a file name is an OBJ model.
pub fn is_obj(name: &str) -> bool {
    name.to_ascii_lowercase().ends_with(".obj")
}

/// Reads an OBJ file.
pub fn read_obj(file: &str, bytes: &[u8], up: ObjUp, unit: ObjUnit, north_deg: f64) -> Result<GltfModel> {
    let text = String::from_utf8_lossy(bytes);
    let mut vertices: Vec<DVec3> = Vec::new();
    let (mut object, mut group) = (String::new(), String::new());
    let mut names: Vec<String> = Vec::new();
    let mut faces: HashMap<String, Vec<Vec<usize>>> = HashMap::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        let at = || format!("line {}", n + 1);
        match keyword {
            "v" => vertices.push(vertex(&rest).ok_or_else(|| Error::model(file, format!("{}: 'v' needs three numbers", at())))?),
            "o" => {
                object = rest.join(" ");
                group.clear();
            }
            "g" => group = rest.join(" "),
            "f" => {
                let name = node_name(&object, &group);
                let face = rest
                    .iter()
                    .map(|w| face_index(w, vertices.len()))
                    .collect::<std::result::Result<Vec<usize>, String>>()
                    .map_err(|reason| Error::object(file, format!("'{name}' ({})", at()), reason))?;
                if face.len() < 3 {
                    return Err(Error::object(file, format!("'{name}' ({})", at()), "a face needs at least 3 vertices"));
                }
                if !faces.contains_key(&name) {
                    names.push(name.clone());
                }
                faces.entry(name).or_default().push(face);
            }
            _ => {}
        }
    }
    let offset = vertices.first().copied().unwrap_or_default();
    let axes = match up {
        ObjUp::Y => gltf_to_world(),
        ObjUp::Z => DMat4::IDENTITY,
    };
    let transform =
        DMat4::from_rotation_z(-north_deg.to_radians()) * axes * DMat4::from_scale(DVec3::splat(unit.0)) * DMat4::from_translation(offset);
    let mut model = GltfModel { file: file.to_string(), meshes: Vec::new(), nodes: Vec::new(), glass: Vec::new() };
    for name in names {
        let mesh = polygons_mesh(&vertices, &faces[&name], offset);
        model.nodes.push(GltfNode {
            name,
            named: true,
            marked: false,
            veil: NodeVeil::default(),
            mesh: model.meshes.len(),
            transform,
            city: None,
        });
        model.meshes.push(mesh);
    }
    if model.nodes.is_empty() {
        return Err(Error::model(file, "no face ('f' line): nothing to count"));
    }
    Ok(model)
}

fn node_name(object: &str, group: &str) -> String {
    match (object.is_empty(), group.is_empty()) {
        (false, false) => format!("{object}/{group}"),
        (false, true) => object.to_string(),
        (true, false) => group.to_string(),
        (true, true) => "default".to_string(),
    }
}

fn vertex(words: &[&str]) -> Option<DVec3> {
    let n: Vec<f64> = words.iter().take(3).map(|w| w.parse().ok()).collect::<Option<_>>()?;
    let p = (n.len() == 3).then(|| DVec3::new(n[0], n[1], n[2]))?;
    p.is_finite().then_some(p)
}

/// A face word (`v`, `v/vt`, `v//vn`, `v/vt/vn`) as a 0-based vertex index; negative counts back
/// from the vertices read so far.
fn face_index(word: &str, count: usize) -> std::result::Result<usize, String> {
    let first = word.split('/').next().unwrap_or("");
    let i: i64 = first.parse().map_err(|_| format!("'{word}' is not a vertex index"))?;
    let index = if i > 0 { i - 1 } else { count as i64 + i };
    if i == 0 || index < 0 || index as usize >= count {
        return Err(format!("vertex index {i} is missing ({count} vertices read so far)"));
    }
    Ok(index as usize)
}

/// Faces as triangles; vertices stored relative to `offset` (f64 before f32).
fn polygons_mesh(vertices: &[DVec3], faces: &[Vec<usize>], offset: DVec3) -> SourceMesh {
    let mut mesh = SourceMesh::default();
    for face in faces {
        let points: Vec<DVec3> = face.iter().map(|&i| vertices[i] - offset).collect();
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(points.iter().map(|p| [p.x as f32, p.y as f32, p.z as f32]));
        let triangles = if points.len() == 3 { vec![[0, 1, 2]] } else { triangulate(&Plane::of_polygon(&points), &points, &[]) };
        mesh.indices.extend(triangles.iter().flatten().map(|&k| base + k as u32));
    }
    mesh
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const TWO: &str = "# two squares\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nv 0 2 0\nv 1 2 0\nv 1 2 -1\nv 0 2 -1\no block\ng Roof\nf -4 -3 -2 -1\ng Base\nf 1/1/1 2//1 3 4\n";

    #[test]
    fn groups_are_names_and_y_is_up() {
        let m = read_obj("a.obj", TWO.as_bytes(), ObjUp::Y, ObjUnit::default(), 0.0).unwrap();
        let names: Vec<&str> = m.nodes.iter().map(|n| n.name.as_str()).collect();
        assert_eq!(names, ["block/Roof", "block/Base"]);
        // The roof: OBJ y = 2 is z = 2 in sunlit's axes, and its counter-clockwise winding seen
        // from +y faces up.
        let roof = &m.meshes[0];
        let p = |i: u32| m.nodes[0].transform.transform_point3(DVec3::from_array(roof.positions[i as usize].map(f64::from)));
        assert!((p(0).z - 2.0).abs() < 1e-9, "{}", p(0));
        let tri = [p(roof.indices[0]), p(roof.indices[1]), p(roof.indices[2])];
        assert!(crate::geometry::triangle_normal(&tri).z > 0.99);
    }

    #[test]
    fn units_and_z_up() {
        let m = read_obj("a.obj", b"v 0 0 100\nv 100 0 100\nv 0 100 100\nf 1 2 3\n", ObjUp::Z, ObjUnit::parse("cm").unwrap(), 0.0).unwrap();
        let p = m.nodes[0].transform.transform_point3(DVec3::from_array(m.meshes[0].positions[1].map(f64::from)));
        assert!((p - DVec3::new(1.0, 0.0, 1.0)).length() < 1e-9, "{p}");
        assert_eq!(m.nodes[0].name, "default");
    }

    #[test]
    fn a_missing_vertex_names_file_line_and_name() {
        let e = read_obj("a.obj", b"v 0 0 0\nv 1 0 0\ng wall\nf 1 2 3\n", ObjUp::Y, ObjUnit::default(), 0.0).unwrap_err().to_string();
        assert_eq!(e, "a.obj: 'wall' (line 4): vertex index 3 is missing (2 vertices read so far)");
        assert!(ObjUp::parse("x").is_err() && ObjUnit::parse("yd").is_err());
    }
}
