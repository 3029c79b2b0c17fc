//! `KHR_draco_mesh_compression`: decodes each Draco-compressed primitive (by the pure-Rust
//! `draco-core`, so the web build has it too) before the document is validated.
//!
//! The decoded indices and attributes go to new buffers, and the primitive's accessors (which
//! have no buffer view in such a file) are pointed at them as plain float or u32 data:
//! everything after this module reads plain glTF.

use ::gltf::json;
use ::gltf::json::accessor::{ComponentType, GenericComponentType, Type};
use ::gltf::json::validation::{Checked, USize64};
use serde_json::Value;

use super::gltf_extensions::{CONVERT_HINT, push_buffer};
use crate::error::{Error, Result};

const NAME: &str = "KHR_draco_mesh_compression";

/// The most one primitive may decode to (bytes of attribute values), far past any building model:
/// a tiny stream may legitimately declare millions of points, so only a ceiling stops an absurd one.
const MAX_DECODED_BYTES: u64 = 512 << 20;

/// Decodes every Draco primitive of the document.
pub fn decode_draco(file: &str, root: &mut json::Root, buffers: &mut Vec<Vec<u8>>) -> Result<()> {
    for m in 0..root.meshes.len() {
        for p in 0..root.meshes[m].primitives.len() {
            let primitive = &root.meshes[m].primitives[p];
            let Some(ext) = primitive.extensions.as_ref().and_then(|e| e.others.get(NAME)) else { continue };
            let err = |reason: String| Error::object(file, format!("mesh {m} primitive {p}"), format!("{NAME}: {reason}"));
            let (ext, attributes) = (ext.clone(), primitive.attributes.clone());
            let decoded = decode_primitive(root, buffers, &ext, &attributes).map_err(|r| err(format!("{r}; {CONVERT_HINT}")))?;
            store(root, buffers, m, p, decoded).map_err(err)?;
        }
    }
    Ok(())
}

/// One primitive's decoded Draco mesh: its triangle indices and its attributes by accessor.
struct Decoded {
    indices: Vec<u32>,
    points: usize,
    /// (accessor index, components as f32, point-major).
    attributes: Vec<(usize, Vec<f32>)>,
}

type Attributes = std::collections::BTreeMap<Checked<json::mesh::Semantic>, json::Index<json::Accessor>>;

fn decode_primitive(
    root: &json::Root,
    buffers: &[Vec<u8>],
    ext: &Value,
    primitive_attributes: &Attributes,
) -> std::result::Result<Decoded, String> {
    let view_index = ext.get("bufferView").and_then(Value::as_u64).ok_or_else(|| "bufferView is missing or not an index".to_string())?;
    let view = root.buffer_views.get(view_index as usize).ok_or_else(|| format!("bufferView {view_index} does not exist"))?;
    let start = view.byte_offset.map_or(0, |o| o.0) as usize;
    let bytes = buffers
        .get(view.buffer.value())
        .and_then(|b| b.get(start..start.checked_add(view.byte_length.0 as usize)?))
        .ok_or_else(|| format!("bufferView {view_index} lies outside its buffer"))?;
    let mut buffer =
        draco_core::DecoderBuffer::new(bytes).with_limits(draco_core::DecodeLimits::default().with_max_decoded_bytes(MAX_DECODED_BYTES));
    let mut mesh = draco_core::Mesh::new();
    draco_core::MeshDecoder::new()
        .decode(&mut buffer, &mut mesh)
        .map_err(|e| format!("the Draco data in bufferView {view_index} could not be decoded ({e})"))?;
    let points = mesh.num_points();
    let indices: Vec<u32> = mesh.faces().iter().flat_map(|f| f.map(|p| p.0)).collect();
    if let Some(&bad) = indices.iter().find(|&&i| i as usize >= points) {
        return Err(format!("decoded index {bad} is out of range ({points} points)"));
    }
    let ids = ext.get("attributes").and_then(Value::as_object).ok_or("attributes is missing or not an object")?;
    let mut attributes = Vec::new();
    for (semantic, id) in ids {
        let id = id.as_u64().and_then(|i| u32::try_from(i).ok()).ok_or_else(|| format!("attributes.{semantic} is not an attribute id"))?;
        let Some(accessor) = primitive_attributes.iter().find(|(k, _)| k.to_string() == *semantic).map(|(_, a)| a.value()) else {
            continue; // Compressed but not used by the primitive: nothing reads it.
        };
        let json_accessor = root.accessors.get(accessor).ok_or_else(|| format!("accessor {accessor} does not exist"))?;
        let attribute = mesh.attribute_by_unique_id(id).ok_or_else(|| format!("the Draco data has no attribute {id} ({semantic})"))?;
        let components = match json_accessor.type_ {
            Checked::Valid(t) => t.multiplicity(),
            Checked::Invalid => return Err(format!("accessor {accessor} has an invalid type")),
        };
        let mut values = attribute.read_f32s(points, components);
        if json_accessor.normalized {
            let max = normalized_max(&json_accessor.component_type);
            values.iter_mut().for_each(|v| *v = (*v / max).max(-1.0));
        }
        attributes.push((accessor, values));
    }
    Ok(Decoded { indices, points, attributes })
}

/// The integer range a normalized component maps to [−1, 1] or [0, 1] by (glTF 2.0 §3.11).
fn normalized_max(component: &Checked<GenericComponentType>) -> f32 {
    match component {
        Checked::Valid(GenericComponentType(ComponentType::I8)) => 127.0,
        Checked::Valid(GenericComponentType(ComponentType::U8)) => 255.0,
        Checked::Valid(GenericComponentType(ComponentType::I16)) => 32767.0,
        Checked::Valid(GenericComponentType(ComponentType::U16)) => 65535.0,
        Checked::Valid(GenericComponentType(ComponentType::U32)) => 4294967295.0,
        _ => 1.0,
    }
}

/// Points the primitive's accessors at the decoded data (float attributes, u32 indices).
fn store(root: &mut json::Root, buffers: &mut Vec<Vec<u8>>, m: usize, p: usize, decoded: Decoded) -> std::result::Result<(), String> {
    let indices = root.meshes[m].primitives[p].indices.map(|i| i.value());
    if let Some(accessor) = indices {
        let declared = root.accessors.get(accessor).map(|a| a.count.0).ok_or_else(|| format!("accessor {accessor} does not exist"))?;
        if declared != decoded.indices.len() as u64 {
            return Err(format!("accessor {accessor} declares {declared} indices, the Draco data has {}", decoded.indices.len()));
        }
        let bytes = decoded.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        point(root, buffers, accessor, bytes, ComponentType::U32, Type::Scalar);
    } else if !decoded.indices.is_empty() {
        return Err("the Draco data holds triangles but the primitive has no indices accessor".into());
    }
    for (accessor, values) in decoded.attributes {
        let declared = root.accessors[accessor].count.0;
        if declared != decoded.points as u64 {
            return Err(format!("accessor {accessor} declares {declared} elements, the Draco data has {} points", decoded.points));
        }
        let kind = match root.accessors[accessor].type_ {
            Checked::Valid(t) => t,
            Checked::Invalid => Type::Scalar,
        };
        point(root, buffers, accessor, values.iter().flat_map(|v| v.to_le_bytes()).collect(), ComponentType::F32, kind);
    }
    Ok(())
}

/// Gives `accessor` the tightly packed `bytes` (in a new buffer and view) as `component` data.
fn point(root: &mut json::Root, buffers: &mut Vec<Vec<u8>>, accessor: usize, bytes: Vec<u8>, component: ComponentType, kind: Type) {
    let length = bytes.len() as u64;
    let buffer = push_buffer(&mut root.buffers, buffers, bytes);
    let view = root.buffer_views.len();
    root.buffer_views.push(json::buffer::View {
        buffer,
        byte_length: USize64(length),
        byte_offset: None,
        byte_stride: None,
        name: None,
        target: None,
        extensions: None,
        extras: Default::default(),
    });
    let a = &mut root.accessors[accessor];
    a.buffer_view = Some(json::Index::new(view as u32));
    a.byte_offset = None;
    a.component_type = Checked::Valid(GenericComponentType(component));
    a.type_ = Checked::Valid(kind);
    a.normalized = false;
}
