//! `EXT_mesh_gpu_instancing`: a node that draws its mesh once per instance, each placed by a
//! translation, rotation and scale read from accessors, relative to the node (what glTF
//! Transform's `instance`, and so its `optimize`, write for repeated meshes such as louvres).
//!
//! Owns reading the instance transforms; the node walk in `gltf_read` makes one node per instance.

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

use super::gltf_accessor::read_values;

/// The extension's name.
pub const NAME: &str = "EXT_mesh_gpu_instancing";

/// The most instances one node may have (each becomes a node of the scene).
const MAX_INSTANCES: usize = 1 << 20;

/// The node's instance transforms (instance → node), or `None` when it is not instanced.
pub fn instance_transforms(node: &::gltf::Node, document: &::gltf::Document, buffers: &[Vec<u8>]) -> Result<Option<Vec<DMat4>>, String> {
    let Some(ext) = node.extension_value(NAME) else { return Ok(None) };
    let attributes = ext.get("attributes").and_then(Value::as_object).ok_or_else(|| format!("{NAME}: attributes is missing"))?;
    let read = |key: &str, width: usize| -> Result<Option<Vec<f64>>, String> {
        let Some(index) = attributes.get(key) else { return Ok(None) };
        let index = index.as_u64().ok_or_else(|| format!("{NAME}: attributes.{key} is {index}, not an accessor index"))?;
        let acc = document.accessors().nth(index as usize).ok_or_else(|| format!("{NAME}: accessor {index} does not exist"))?;
        if acc.dimensions().multiplicity() != width {
            return Err(format!("{NAME}: {key} accessor {index} has {:?} elements, expected {width} components", acc.dimensions()));
        }
        if acc.count() > MAX_INSTANCES {
            return Err(format!("{NAME}: {key} accessor {index} has {} instances (at most {MAX_INSTANCES})", acc.count()));
        }
        Ok(Some(read_values(&acc, buffers)?))
    };
    let translation = read("TRANSLATION", 3)?;
    let rotation = read("ROTATION", 4)?;
    let scale = read("SCALE", 3)?;
    let counts: Vec<usize> =
        [(&translation, 3), (&rotation, 4), (&scale, 3)].iter().filter_map(|(v, w)| v.as_ref().map(|v| v.len() / w)).collect();
    let Some(&count) = counts.first() else { return Err(format!("{NAME}: none of TRANSLATION, ROTATION, SCALE is given")) };
    if counts.iter().any(|&c| c != count) {
        return Err(format!("{NAME}: TRANSLATION, ROTATION and SCALE have different counts ({counts:?})"));
    }
    (0..count)
        .map(|i| {
            let t = translation.as_ref().map_or(DVec3::ZERO, |v| DVec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]));
            let s = scale.as_ref().map_or(DVec3::ONE, |v| DVec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2]));
            let r = match &rotation {
                None => DQuat::IDENTITY,
                Some(v) => {
                    let q = DQuat::from_xyzw(v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]);
                    let length = q.length();
                    if !length.is_finite() || length <= 1e-6 {
                        return Err(format!("{NAME}: instance {i} has a zero or non-finite rotation"));
                    }
                    q.normalize()
                }
            };
            Ok(DMat4::from_scale_rotation_translation(s, r, t))
        })
        .collect::<Result<Vec<_>, String>>()
        .map(Some)
}
