//! Scenes from meshes and their placements, as a scene graph (three.js, a CAD viewer) holds
//! them: each mesh once in its own coordinates, each placement a 4×4 matrix onto a mesh, so a
//! mesh placed many times (an InstancedMesh, a repeated louvre) stays one mesh drawn instanced.
//!
//! Owns the validation of such input (ranges, lengths, finite matrices, names), so a caller's
//! mistake comes back as an error naming the array and the offending element. Mirroring
//! placements (negative determinant) get their mesh's winding flipped, so a receiver's outward
//! normal stays the side its front faces show.

use std::collections::HashMap;

use glam::{DMat4, DVec4};

use crate::error::{Error, NoReceivers, Result};
use crate::scene::{Scene, SceneBuilder, SourceMesh, SourceNode};

/// The label errors and receiver origins carry for this input.
const SOURCE: &str = "meshes";

/// Meshes and placements handed over as flat arrays.
#[derive(Debug, Clone, Copy)]
pub struct Placed<'a> {
    /// x, y, z per vertex, all meshes one after another, each in its own coordinates.
    pub positions: &'a [f32],
    /// Mesh m's vertices are `vertex_starts[m]..vertex_starts[m + 1]` (a vertex index, not a float
    /// index); meshes + 1 entries, the last the vertex count.
    pub vertex_starts: &'a [u32],
    /// Triangle lists, each relative to its own mesh's first vertex, one after another.
    pub indices: &'a [u32],
    /// Mesh m's indices are `index_starts[m]..index_starts[m + 1]`; meshes + 1 entries.
    pub index_starts: &'a [u32],
    /// Per placement: its mesh.
    pub placement_meshes: &'a [u32],
    /// Per placement: 16 numbers, the mesh → world matrix in column-major order (three.js's
    /// `Matrix4.elements`).
    pub matrices: &'a [f64],
    /// Per placement: its name (receivers' names are output columns).
    pub names: &'a [String],
    /// Per placement: non-zero when it receives.
    pub receivers: &'a [u8],
    /// World coordinates are glTF's / three.js's (+Y up, −Z north) rather than sunlit's (z up).
    pub y_up: bool,
}

/// Builds the scene: every placement casts shadows, those flagged receive (a receiver whose
/// triangles lie in several planes is split into `NAME#k` parts, as a glTF node).
pub fn scene_from_placed(input: &Placed) -> Result<Scene> {
    let meshes = meshes(input)?;
    check_placements(input, meshes.len())?;
    let axes = if input.y_up { gltf_to_sunlit() } else { DMat4::IDENTITY };
    let mut builder = SceneBuilder::new();
    // (mesh, mirrored) → index in the builder: a mesh is added once per winding.
    let mut added: HashMap<(usize, bool), usize> = HashMap::new();
    for (p, name) in input.names.iter().enumerate() {
        let mesh = input.placement_meshes[p] as usize;
        let transform = axes * DMat4::from_cols_array(&matrix(input, p));
        let mirrored = transform.determinant() < 0.0;
        let index = *added.entry((mesh, mirrored)).or_insert_with(|| {
            let source = if mirrored { flipped(&meshes[mesh]) } else { meshes[mesh].clone() };
            builder.add_mesh(format!("mesh {mesh}"), source)
        });
        builder.add_node(SourceNode {
            name: name.clone(),
            origin: format!("{SOURCE}: placement '{name}'"),
            mesh: index,
            transform,
            receiver: input.receivers[p] != 0,
        });
    }
    if !input.receivers.iter().any(|r| *r != 0) {
        return Err(Error::NoReceivers(NoReceivers::Other("no placement is marked as a receiver".into())));
    }
    builder.build()
}

/// (gx, gy, gz) → (gx, −gz, gy): glTF's +Y up, −Z north to sunlit's z up, y north.
fn gltf_to_sunlit() -> DMat4 {
    DMat4::from_cols(DVec4::X, DVec4::Z, -DVec4::Y, DVec4::W)
}

fn matrix(input: &Placed, placement: usize) -> [f64; 16] {
    let mut m = [0.0; 16];
    m.copy_from_slice(&input.matrices[16 * placement..16 * placement + 16]);
    m
}

/// The same triangles wound the other way.
fn flipped(mesh: &SourceMesh) -> SourceMesh {
    let indices = mesh.indices.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]).collect();
    SourceMesh { positions: mesh.positions.clone(), indices }
}

/// Each mesh's vertices and local triangle list, checked.
fn meshes(input: &Placed) -> Result<Vec<SourceMesh>> {
    if !input.positions.len().is_multiple_of(3) {
        return Err(Error::object(SOURCE, "positions", format!("length {} is not a multiple of 3", input.positions.len())));
    }
    if let Some(i) = input.positions.iter().position(|v| !v.is_finite()) {
        return Err(Error::object(SOURCE, format!("positions[{i}]"), format!("{} is not a finite number", input.positions[i])));
    }
    let vertices = (input.positions.len() / 3) as u32;
    check_starts("vertexStarts", input.vertex_starts, vertices)?;
    check_starts("indexStarts", input.index_starts, input.indices.len() as u32)?;
    let count = input.vertex_starts.len() - 1;
    if input.index_starts.len() - 1 != count {
        return Err(Error::object(
            SOURCE,
            "indexStarts",
            format!("describes {} meshes, vertexStarts {count}", input.index_starts.len() - 1),
        ));
    }
    (0..count)
        .map(|m| {
            let (v0, v1) = (input.vertex_starts[m] as usize, input.vertex_starts[m + 1] as usize);
            let (i0, i1) = (input.index_starts[m] as usize, input.index_starts[m + 1] as usize);
            if (i1 - i0) % 3 != 0 {
                return Err(Error::object(SOURCE, format!("mesh {m}"), format!("{} indices is not a multiple of 3", i1 - i0)));
            }
            let indices = &input.indices[i0..i1];
            if let Some(k) = indices.iter().position(|&i| i as usize >= v1 - v0) {
                return Err(Error::object(
                    SOURCE,
                    format!("mesh {m}"),
                    format!("index {} (at {}) is past its {} vertices", indices[k], i0 + k, v1 - v0),
                ));
            }
            let positions = input.positions[3 * v0..3 * v1].chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            Ok(SourceMesh { positions, indices: indices.to_vec() })
        })
        .collect()
}

/// `starts` must begin at 0, never decrease, and end at `total`.
fn check_starts(what: &str, starts: &[u32], total: u32) -> Result<()> {
    if starts.len() < 2 {
        return Err(Error::object(SOURCE, what, "needs one entry per mesh plus the end (at least 2)"));
    }
    if starts[0] != 0 || starts.windows(2).any(|w| w[1] < w[0]) || starts[starts.len() - 1] != total {
        return Err(Error::object(SOURCE, what, format!("must rise from 0 to {total}, got {starts:?}")));
    }
    Ok(())
}

fn check_placements(input: &Placed, meshes: usize) -> Result<()> {
    let count = input.names.len();
    let lengths = [
        ("placementMeshes", input.placement_meshes.len(), 1),
        ("matrices", input.matrices.len(), 16),
        ("receivers", input.receivers.len(), 1),
    ];
    for (what, len, per) in lengths {
        if len != count * per {
            return Err(Error::object(SOURCE, what, format!("has {len} entries for {count} placements ({per} each)")));
        }
    }
    for (p, name) in input.names.iter().enumerate() {
        if name.trim().is_empty() {
            return Err(Error::object(SOURCE, format!("placement {p}"), "has an empty name"));
        }
        let mesh = input.placement_meshes[p] as usize;
        if mesh >= meshes {
            return Err(Error::object(SOURCE, format!("placement '{name}'"), format!("mesh {mesh} is not below the {meshes} meshes")));
        }
        let m = matrix(input, p);
        if m.iter().any(|v| !v.is_finite()) || DMat4::from_cols_array(&m).determinant().abs() < 1e-18 {
            return Err(Error::object(SOURCE, format!("placement '{name}'"), "its matrix is not finite or is singular"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use glam::DVec3;

    /// A unit square in a mesh's x–y plane (facing +z).
    const SQUARE: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    const SQUARE_INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];

    fn translation(x: f64, y: f64, z: f64) -> [f64; 16] {
        DMat4::from_translation(DVec3::new(x, y, z)).to_cols_array()
    }

    #[test]
    fn one_mesh_placed_three_times_is_drawn_instanced() {
        let names: Vec<String> = ["a", "b", "shade"].map(String::from).to_vec();
        let matrices: Vec<f64> = [translation(0.0, 0.0, 0.0), translation(5.0, 0.0, 0.0), translation(0.0, 0.0, 2.0)].concat();
        let input = Placed {
            positions: &SQUARE,
            vertex_starts: &[0, 4],
            indices: &SQUARE_INDICES,
            index_starts: &[0, 6],
            placement_meshes: &[0, 0, 0],
            matrices: &matrices,
            names: &names,
            receivers: &[1, 1, 0],
            y_up: false,
        };
        let scene = scene_from_placed(&input).unwrap();
        assert_eq!(scene.receivers.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["a", "b"]);
        assert_eq!(scene.triangle_count(), 6);
        // The shared mesh is stored once (plus the empty static mesh) and placed three times.
        assert_eq!(scene.meshes.len(), 2, "{:?}", scene.meshes.iter().map(|m| &m.label).collect::<Vec<_>>());
        assert!((scene.receivers[1].triangles[0][1] - DVec3::new(6.0, 0.0, 0.0)).length() < 1e-9);
    }

    #[test]
    fn y_up_and_mirrors_keep_outward_normals() {
        // three.js: a square rotated −90° about X faces +Y (up); mirrored in X it still faces up.
        let rotate = DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2);
        let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)) * rotate;
        let matrices = [rotate.to_cols_array(), mirror.to_cols_array()].concat();
        let names = vec!["roof".to_string(), "mirrored".to_string()];
        let input = Placed {
            positions: &SQUARE,
            vertex_starts: &[0, 4],
            indices: &SQUARE_INDICES,
            index_starts: &[0, 6],
            placement_meshes: &[0, 0],
            matrices: &matrices,
            names: &names,
            receivers: &[1, 1],
            y_up: true,
        };
        let scene = scene_from_placed(&input).unwrap();
        for r in &scene.receivers {
            assert!((r.normal - DVec3::Z).length() < 1e-9, "{}: {}", r.name, r.normal);
        }
    }

    #[test]
    fn bad_input_names_the_array_and_element() {
        let names = vec!["roof".to_string()];
        let identity = DMat4::IDENTITY.to_cols_array();
        let base = Placed {
            positions: &SQUARE,
            vertex_starts: &[0, 4],
            indices: &SQUARE_INDICES,
            index_starts: &[0, 6],
            placement_meshes: &[0],
            matrices: &identity,
            names: &names,
            receivers: &[1],
            y_up: false,
        };
        let message = |p: Placed| scene_from_placed(&p).unwrap_err().to_string();
        assert_eq!(message(Placed { vertex_starts: &[0, 3], ..base }), "meshes: vertexStarts: must rise from 0 to 4, got [0, 3]");
        assert_eq!(message(Placed { indices: &[0, 1, 7, 0, 2, 3], ..base }), "meshes: mesh 0: index 7 (at 2) is past its 4 vertices");
        assert_eq!(message(Placed { placement_meshes: &[2], ..base }), "meshes: placement 'roof': mesh 2 is not below the 1 meshes");
        assert_eq!(message(Placed { matrices: &identity[..12], ..base }), "meshes: matrices: has 12 entries for 1 placements (16 each)");
        let zero = [0.0; 16];
        assert_eq!(message(Placed { matrices: &zero, ..base }), "meshes: placement 'roof': its matrix is not finite or is singular");
        assert_eq!(message(Placed { receivers: &[0], ..base }), "no receiving surface: no placement is marked as a receiver");
        let twice = vec!["roof".to_string(), "roof".to_string()];
        let two = [identity, DMat4::from_translation(DVec3::X * 3.0).to_cols_array()].concat();
        let e = message(Placed { names: &twice, matrices: &two, placement_meshes: &[0, 0], receivers: &[1, 1], ..base });
        assert!(e.starts_with("duplicate receiver name 'roof'"), "{e}");
    }
}
