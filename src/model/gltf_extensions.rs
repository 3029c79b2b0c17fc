//! glTF extensions before the document is validated: which required extensions sunlit reads,
//! which it may ignore (materials, textures, lights: nothing that casts a shadow), and the named
//! error for any other; and the `EXT_meshopt_compression` / `KHR_meshopt_compression` decoding of
//! buffer views (meshoptimizer's vertex and index codecs and filters, by the pure-Rust
//! `meshoptimizer-rs`, so the web build has them too).
//!
//! Decoded data goes to new buffers appended to the document, and each compressed view is
//! pointed at its decoded bytes: everything after this module reads plain glTF.

use ::gltf::json;
use serde_json::Value;

use crate::error::{Error, Result};

/// The geometry extensions sunlit reads.
pub const READ: [&str; 5] = [
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "KHR_draco_mesh_compression",
    "EXT_mesh_gpu_instancing",
];

/// The meshopt extensions, whose buffer views are decoded here.
const MESHOPT: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// What to run to convert a file whose required extension sunlit cannot read.
pub const CONVERT_HINT: &str = "convert it to plain glTF, e.g. with glTF Transform: `npx @gltf-transform/cli copy IN.glb OUT.glb` \
     (which writes no compression), or re-export it without that extension";

/// Whether a required extension only concerns looks (materials, textures, lights, cameras), which
/// sunlit ignores: a shadow depends on geometry alone.
fn only_looks(name: &str) -> bool {
    name.starts_with("KHR_materials_")
        || name.starts_with("KHR_texture_")
        || name.starts_with("EXT_texture_")
        || name.starts_with("MSFT_texture_")
        || name == "KHR_lights_punctual"
}

/// Checks `extensionsRequired`: an extension sunlit neither reads nor may ignore is a named error;
/// the others are removed from the list, so the gltf crate's validation (which knows none of
/// them) accepts the document.
pub fn accept_required(file: &str, root: &mut json::Root) -> Result<()> {
    if let Some(name) = root.extensions_required.iter().find(|e| !READ.contains(&e.as_str()) && !only_looks(e)) {
        return Err(Error::model(
            file,
            format!("requires the glTF extension '{name}', which sunlit does not read (it reads {}); {CONVERT_HINT}", READ.join(", ")),
        ));
    }
    root.extensions_required.clear();
    Ok(())
}

/// A buffer that only stands in for meshopt-compressed data (`"fallback": true`): it has no
/// bytes of its own (in a GLB, no URI does not mean the binary chunk).
pub fn is_fallback(buffer: &json::Buffer) -> bool {
    let Some(ext) = &buffer.extensions else { return false };
    MESHOPT.iter().any(|name| ext.others.get(*name).and_then(|v| v.get("fallback")).and_then(Value::as_bool) == Some(true))
}

/// Decodes every meshopt-compressed buffer view into a new buffer and points the view at it.
pub fn decode_meshopt(file: &str, root: &mut json::Root, buffers: &mut Vec<Vec<u8>>) -> Result<()> {
    // A ceiling on what one view decodes to (and the decoder's scratch), far past any building model.
    let mut workspace = meshoptimizer_rs::Workspace::new(meshoptimizer_rs::Limits { max_bytes: 512 << 20, ..Default::default() });
    for v in 0..root.buffer_views.len() {
        let view = &root.buffer_views[v];
        let Some((name, ext)) = view.extensions.as_ref().and_then(|e| MESHOPT.iter().find_map(|n| e.others.get(*n).map(|x| (*n, x))))
        else {
            continue;
        };
        let err = |reason: String| Error::object(file, format!("bufferView {v}"), format!("{name}: {reason}"));
        let spec = MeshoptView::parse(ext).map_err(&err)?;
        let source = buffers
            .get(spec.buffer)
            .and_then(|b| b.get(spec.offset..spec.offset.checked_add(spec.length)?))
            .ok_or_else(|| err(format!("bytes {}..+{} of buffer {} do not exist", spec.offset, spec.length, spec.buffer)))?;
        let decoded = spec.decode(name, source, &mut workspace).map_err(|e| err(format!("{e}; {CONVERT_HINT}")))?;
        if decoded.len() as u64 != view.byte_length.0 {
            return Err(err(format!("decodes to {} bytes, but the view declares {}", decoded.len(), view.byte_length.0)));
        }
        let decoded_buffer = push_buffer(&mut root.buffers, buffers, decoded);
        let view = &mut root.buffer_views[v];
        view.buffer = decoded_buffer;
        view.byte_offset = Some(json::validation::USize64(0));
        if spec.mode == "ATTRIBUTES" && view.byte_stride.is_none() {
            // The decoded elements are `byteStride` apart whatever the view says (it must say so).
            view.byte_stride = Some(json::buffer::Stride(spec.stride));
        }
    }
    Ok(())
}

/// Appends decoded bytes as a new buffer (JSON and data); returns its index.
pub fn push_buffer(json_buffers: &mut Vec<json::Buffer>, buffers: &mut Vec<Vec<u8>>, data: Vec<u8>) -> json::Index<json::Buffer> {
    let index = json_buffers.len();
    json_buffers.push(json::Buffer {
        byte_length: json::validation::USize64(data.len() as u64),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    // Buffers beyond the file's own are only ever added here, so the two lists stay aligned.
    buffers.resize(index, Vec::new());
    buffers.push(data);
    json::Index::new(index as u32)
}

/// One view's meshopt extension object.
#[derive(Debug)]
struct MeshoptView {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: String,
    filter: String,
}

impl MeshoptView {
    fn parse(ext: &Value) -> std::result::Result<Self, String> {
        let number = |key: &str, default: Option<u64>| {
            ext.get(key)
                .map(|v| v.as_u64().ok_or_else(|| format!("{key} is {v}, expected a non-negative integer")))
                .unwrap_or_else(|| default.ok_or_else(|| format!("{key} is missing")))
                .and_then(|n| usize::try_from(n).map_err(|_| format!("{key} {n} is too large")))
        };
        let text = |key: &str, default: Option<&str>| match ext.get(key) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(v) => Err(format!("{key} is {v}, expected a string")),
            None => default.map(str::to_string).ok_or_else(|| format!("{key} is missing")),
        };
        Ok(Self {
            buffer: number("buffer", None)?,
            offset: number("byteOffset", Some(0))?,
            length: number("byteLength", None)?,
            stride: number("byteStride", None)?,
            count: number("count", None)?,
            mode: text("mode", None)?,
            filter: text("filter", Some("NONE"))?,
        })
    }

    /// The decoded bytes: `count × byteStride`.
    fn decode(&self, name: &str, source: &[u8], workspace: &mut meshoptimizer_rs::Workspace) -> std::result::Result<Vec<u8>, String> {
        use meshoptimizer_rs::codec::{self, Filter, Mode};
        let mode = Mode::parse(&self.mode).map_err(|_| format!("unknown mode '{}'", self.mode))?;
        let what = |e: meshoptimizer_rs::Error| format!("the {} data could not be decoded ({e})", self.mode.to_ascii_lowercase());
        if name == "EXT_meshopt_compression" {
            let filter = Filter::parse(&self.filter).map_err(|_| format!("unknown filter '{}'", self.filter))?;
            return codec::decode_buffer_view(mode, filter, self.count, self.stride, source, workspace).map_err(what);
        }
        // KHR_meshopt_compression: vertex codec version 1 too, and the COLOR filter.
        let mut data = match mode {
            Mode::Attributes => codec::decode_vertex_buffer(self.count, self.stride, source, workspace),
            Mode::Triangles => codec::decode_index_buffer(self.count, self.stride, source, workspace),
            Mode::Indices => codec::decode_index_sequence(self.count, self.stride, source, workspace),
        }
        .map_err(what)?;
        let filtered = match self.filter.as_str() {
            "NONE" => Ok(()),
            "OCTAHEDRAL" => codec::decode_filter_oct(&mut data, self.count, self.stride, workspace),
            "QUATERNION" => codec::decode_filter_quat(&mut data, self.count, self.stride, workspace),
            "EXPONENTIAL" => codec::decode_filter_exp(&mut data, self.count, self.stride, workspace),
            "COLOR" => codec::decode_filter_color(&mut data, self.count, self.stride, workspace),
            other => return Err(format!("unknown filter '{other}'")),
        };
        filtered.map_err(|e| format!("the {} filter failed ({e})", self.filter))?;
        Ok(data)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn an_unread_required_extension_is_named_with_what_to_run() {
        let mut root: json::Root =
            serde_json::from_str(r#"{"asset":{"version":"2.0"},"extensionsRequired":["KHR_materials_variants","MSFT_lod"]}"#).unwrap();
        let e = accept_required("x.glb", &mut root).unwrap_err().to_string();
        assert!(e.starts_with("x.glb: requires the glTF extension 'MSFT_lod', which sunlit does not read"), "{e}");
        assert!(e.contains("@gltf-transform/cli copy"), "{e}");
    }

    #[test]
    fn read_and_looks_only_extensions_are_accepted() {
        let mut root: json::Root = serde_json::from_str(
            r#"{"asset":{"version":"2.0"},"extensionsRequired":["KHR_mesh_quantization","KHR_draco_mesh_compression","KHR_texture_basisu"]}"#,
        )
        .unwrap();
        accept_required("x.glb", &mut root).unwrap();
        assert!(root.extensions_required.is_empty());
    }

    #[test]
    fn a_meshopt_view_must_name_its_count() {
        let e = MeshoptView::parse(&serde_json::json!({"buffer": 0, "byteLength": 4, "byteStride": 4, "mode": "ATTRIBUTES"})).unwrap_err();
        assert_eq!(e, "count is missing");
    }
}
