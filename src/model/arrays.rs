//! Scenes from raw typed arrays, for web CAD viewers that already hold their geometry: positions,
//! a triangle list, a receiver index per triangle (−1: casts shadows only) and receiver names.
//!
//! Owns the validation of such arrays (lengths, index range, finite coordinates, names), so a
//! caller's mistake comes back as an error naming the array and the offending element.

use glam::DVec3;

use crate::error::{Error, NoReceivers, Result};
use crate::scene::{Scene, SceneBuilder, SourceMesh};

/// The label errors and receiver origins carry for array input.
const SOURCE: &str = "arrays";

/// Geometry handed over as flat arrays.
#[derive(Debug, Clone, Copy)]
pub struct Arrays<'a> {
    /// x, y, z per vertex, metres.
    pub positions: &'a [f32],
    /// Three vertex indices per triangle.
    pub indices: &'a [u32],
    /// Per triangle: index into `names`, or a negative number for geometry that only shades.
    pub triangle_receivers: &'a [i32],
    /// Receiver names (output columns), unique.
    pub names: &'a [String],
    /// The positions use glTF's axes (+Y up, −Z north) rather than sunlit's (z up, y north).
    pub y_up: bool,
}

/// Builds a scene: one receiver per name (its triangles must be coplanar, or it is split into
/// `NAME#k` parts like a glTF node), the rest as shading geometry.
pub fn scene_from_arrays(arrays: &Arrays) -> Result<Scene> {
    let points = points(arrays)?;
    check_triangles(arrays, points.len())?;
    let mut per_receiver: Vec<SourceMesh> = vec![SourceMesh::default(); arrays.names.len()];
    let mut context = SourceMesh::default();
    for (t, &receiver) in arrays.triangle_receivers.iter().enumerate() {
        let mesh = match usize::try_from(receiver) {
            Ok(r) => per_receiver.get_mut(r).ok_or_else(|| {
                Error::object(
                    SOURCE,
                    format!("triangleReceivers[{t}]"),
                    format!("{receiver} is not below the {} names", arrays.names.len()),
                )
            })?,
            Err(_) => &mut context,
        };
        for &i in &arrays.indices[3 * t..3 * t + 3] {
            let p = points[i as usize];
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push([p.x as f32, p.y as f32, p.z as f32]);
        }
    }
    let mut builder = SceneBuilder::new();
    for (name, mesh) in arrays.names.iter().zip(per_receiver) {
        if name.trim().is_empty() {
            return Err(Error::object(SOURCE, "names", "a receiver name is empty"));
        }
        if mesh.indices.is_empty() {
            return Err(Error::object(SOURCE, format!("receiver '{name}'"), "no triangle carries its index"));
        }
        builder.add_object(SOURCE, name, mesh, true);
    }
    if !context.indices.is_empty() {
        builder.add_object(SOURCE, "context", context, false);
    }
    if arrays.names.is_empty() {
        return Err(Error::NoReceivers(NoReceivers::Other("the arrays name no receiver".into())));
    }
    builder.build()
}

/// The vertices in sunlit's axes, each checked to be finite.
fn points(arrays: &Arrays) -> Result<Vec<DVec3>> {
    if arrays.positions.len() % 3 != 0 {
        return Err(Error::object(SOURCE, "positions", format!("length {} is not a multiple of 3", arrays.positions.len())));
    }
    arrays
        .positions
        .chunks_exact(3)
        .enumerate()
        .map(|(i, c)| {
            let p = DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]));
            if !p.is_finite() || p.abs().max_element() > 1e7 {
                return Err(Error::object(
                    SOURCE,
                    format!("positions[{i}]"),
                    format!("vertex {p} is not finite or is farther than 10,000 km"),
                ));
            }
            Ok(if arrays.y_up { DVec3::new(p.x, -p.z, p.y) } else { p })
        })
        .collect()
}

fn check_triangles(arrays: &Arrays, vertices: usize) -> Result<()> {
    if arrays.indices.len() % 3 != 0 {
        return Err(Error::object(SOURCE, "indices", format!("length {} is not a multiple of 3", arrays.indices.len())));
    }
    let triangles = arrays.indices.len() / 3;
    if arrays.triangle_receivers.len() != triangles {
        return Err(Error::object(
            SOURCE,
            "triangleReceivers",
            format!("has {} entries for {triangles} triangles", arrays.triangle_receivers.len()),
        ));
    }
    if let Some((k, i)) = arrays.indices.iter().enumerate().find(|(_, i)| **i as usize >= vertices) {
        return Err(Error::object(SOURCE, format!("indices[{k}]"), format!("{i} is past the {vertices} vertices")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn square(z: f32) -> Vec<f32> {
        vec![0.0, 0.0, z, 1.0, 0.0, z, 1.0, 1.0, z, 0.0, 1.0, z]
    }

    #[test]
    fn one_receiver_and_context() {
        let mut positions = square(0.0);
        positions.extend(square(2.0));
        let indices = [0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6];
        let names = vec!["roof".to_string()];
        let arrays = Arrays { positions: &positions, indices: &indices, triangle_receivers: &[0, 0, -1, -1], names: &names, y_up: false };
        let scene = scene_from_arrays(&arrays).unwrap();
        assert_eq!(scene.receivers.len(), 1);
        assert_eq!(scene.receivers[0].name, "roof");
        assert!((scene.receivers[0].area - 1.0).abs() < 1e-9);
        assert!((scene.receivers[0].normal - DVec3::Z).length() < 1e-9);
        assert_eq!(scene.triangle_count(), 4);
    }

    #[test]
    fn y_up_turns_gltf_axes() {
        // A square in glTF's x–z plane facing +Y (up) is a roof facing +z in sunlit's axes.
        let positions = [0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, -1.0, 1.0, 0.0, 0.0];
        let (names, indices) = (vec!["r".to_string()], [0, 3, 2, 0, 2, 1]);
        let arrays = Arrays { positions: &positions, indices: &indices, triangle_receivers: &[0, 0], names: &names, y_up: true };
        let scene = scene_from_arrays(&arrays).unwrap();
        assert!((scene.receivers[0].normal - DVec3::Z).length() < 1e-9, "{}", scene.receivers[0].normal);
    }

    #[test]
    fn bad_arrays_name_the_array_and_element() {
        let positions = square(0.0);
        let names = vec!["roof".to_string()];
        let base = Arrays { positions: &positions, indices: &[0, 1, 2], triangle_receivers: &[0], names: &names, y_up: false };
        let message = |a: Arrays| scene_from_arrays(&a).unwrap_err().to_string();
        assert_eq!(message(Arrays { indices: &[0, 1, 9], ..base }), "arrays: indices[2]: 9 is past the 4 vertices");
        assert_eq!(message(Arrays { triangle_receivers: &[3], ..base }), "arrays: triangleReceivers[0]: 3 is not below the 1 names");
        assert_eq!(message(Arrays { triangle_receivers: &[0, 0], ..base }), "arrays: triangleReceivers: has 2 entries for 1 triangles");
        assert_eq!(message(Arrays { positions: &positions[..5], ..base }), "arrays: positions: length 5 is not a multiple of 3");
        let mut nan = positions.clone();
        nan[4] = f32::NAN;
        assert!(message(Arrays { positions: &nan, ..base }).starts_with("arrays: positions[1]: vertex"));
        assert_eq!(message(Arrays { triangle_receivers: &[-1], ..base }), "arrays: receiver 'roof': no triangle carries its index");
    }
}
