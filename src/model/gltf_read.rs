//! glTF 2.0 reader (.gltf and .glb, from a path or from bytes) into [`SourceNode`]s and meshes.
//!
//! Owns: resolving buffers (GLB chunk, `data:` URIs, files beside a `.gltf`), the order of the
//! extension passes (`gltf_extensions`, `gltf_draco`) before validation, meshes from primitives
//! (every triangle mode; points and lines left out), the scene's node walk with transforms, the
//! glTF → sunlit axis change (x, y, z) = (gx, −gz, gy) and the north rotation. Accessors are read
//! in `gltf_accessor`, with explicit bounds checks (a hostile file gives an error, never a panic).

use std::path::Path;

use base64::Engine as _;
use glam::{DMat4, DVec4};

use super::{gltf_accessor, gltf_draco, gltf_extensions, gltf_instancing};
use crate::error::{Error, Result};
use crate::model::inside::curve::{MeshGlass, glass_from_extras};
use crate::scene::{NodeVeil, SourceMesh, SourceNode};

/// One glTF file, read: its meshes (one per glTF mesh, primitives merged) and mesh nodes.
#[derive(Debug, Clone)]
pub struct GltfModel {
    /// File label used in messages.
    pub file: String,
    /// Meshes in glTF mesh order.
    pub meshes: Vec<SourceMesh>,
    /// Nodes that place a mesh, with world transforms; `receiver` is the extras mark.
    pub nodes: Vec<GltfNode>,
    /// Per mesh (glTF mesh order; empty for a model without materials), the glass its
    /// primitives' material describes in its extras ([`mesh_glass`]).
    pub glass: Vec<Option<MeshGlass>>,
}

/// A mesh node of a glTF file.
#[derive(Debug, Clone)]
pub struct GltfNode {
    /// The node's name, or `node<index>` when it has none.
    pub name: String,
    /// Whether the file named it (default receivers are the named nodes).
    pub named: bool,
    /// Marked `{"sunlit": {"receiver": true}}` in its extras.
    pub marked: bool,
    /// Foliage and transmittance from its extras: `{"sunlit": {"foliage": true, "transmittance": T}}`.
    pub veil: NodeVeil,
    /// Index into [`GltfModel::meshes`].
    pub mesh: usize,
    /// Mesh → world (sunlit axes).
    pub transform: DMat4,
    /// What a city model says of the surface (CityJSON); `None` for glTF and OBJ.
    pub city: Option<CityTags>,
}

/// A city model surface's building and semantic type, which receiver rules select by.
#[derive(Debug, Clone, PartialEq)]
pub struct CityTags {
    /// Its root `Building`, `None` for what is not a building (it never receives).
    pub building: Option<String>,
    /// The CityObject holding it (a `BuildingPart`, or the building itself).
    pub object: String,
    /// Semantic type (`RoofSurface`, …).
    pub kind: Option<String>,
    /// Its attributes, which `where` rules select by.
    pub attributes: super::cityjson::SurfaceAttributes,
}

impl GltfNode {
    /// `file: node 'name'`.
    pub fn origin(&self, file: &str) -> String {
        format!("{file}: node '{}'", self.name)
    }
}

/// glTF axes → sunlit axes: (x, y, z) = (gx, −gz, gy).
pub fn gltf_to_world() -> DMat4 {
    DMat4::from_cols(DVec4::X, DVec4::Z, -DVec4::Y, DVec4::W)
}

/// Reads a .gltf or .glb file; external buffers are looked up beside it.
pub fn read_path(path: &Path, north_deg: f64) -> Result<GltfModel> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    read_bytes_beside(&path.display().to_string(), &bytes, &dir, north_deg)
}

/// Reads glTF bytes whose external buffers are files in `dir`.
pub fn read_bytes_beside(file: &str, bytes: &[u8], dir: &Path, north_deg: f64) -> Result<GltfModel> {
    read_with(file, bytes, north_deg, |uri| {
        std::fs::read(dir.join(uri)).map_err(|e| format!("external buffer '{uri}' could not be read: {e}"))
    })
}

/// Reads glTF from bytes (the web path): external buffers are not available and give an error.
pub fn read_bytes(file: &str, bytes: &[u8], north_deg: f64) -> Result<GltfModel> {
    read_with(file, bytes, north_deg, |uri| {
        Err(format!("external buffer '{uri}' was not given (use a .glb, or embed buffers as data: URIs)"))
    })
}

/// Reads glTF from bytes whose external buffers may be among `given` (name, bytes): the files
/// dropped on the page together, matched by file name (a .gltf with its .bin).
pub fn read_bytes_among(file: &str, bytes: &[u8], north_deg: f64, given: &[(String, Vec<u8>)]) -> Result<GltfModel> {
    read_with(file, bytes, north_deg, |uri| {
        let wanted = uri.rsplit('/').next().unwrap_or(uri);
        given.iter().find(|(name, _)| name.rsplit(['/', '\\']).next() == Some(wanted)).map(|(_, b)| b.clone()).ok_or_else(|| {
            format!("external buffer '{uri}' was not given (give it with the .gltf, use a .glb, or embed buffers as data: URIs)")
        })
    })
}

fn read_with(
    file: &str,
    bytes: &[u8],
    north_deg: f64,
    external: impl Fn(&str) -> std::result::Result<Vec<u8>, String>,
) -> Result<GltfModel> {
    check_magic(file, bytes)?;
    check_position_accessors(file, bytes)?;
    let invalid = |e: ::gltf::Error| Error::model(file, format!("not a valid glTF 2.0 file: {e}"));
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(invalid)?;
    // Extensions are resolved on the JSON before the gltf crate validates it: compressed views
    // and primitives are decoded into plain buffers, so the rest reads plain glTF.
    let mut root = document.into_json();
    gltf_extensions::accept_required(file, &mut root)?;
    let mut buffers = load_buffers(file, &root, blob, external)?;
    gltf_extensions::decode_meshopt(file, &mut root, &mut buffers)?;
    gltf_draco::decode_draco(file, &mut root, &mut buffers)?;
    let document = ::gltf::Document::from_json(root).map_err(invalid)?;
    let meshes = document.meshes().map(|m| read_mesh(file, &m, &buffers)).collect::<Result<Vec<_>>>()?;
    let glass = document.meshes().map(|m| mesh_glass(file, &m)).collect::<Result<Vec<_>>>()?;
    warn_skipped_primitives(file, &document);
    let world = DMat4::from_rotation_z(-north_deg.to_radians()) * gltf_to_world();
    let mut nodes = Vec::new();
    let mut walked = vec![false; document.nodes().len()];
    for root in scene_roots(&document) {
        collect_nodes(file, &root, world, (&document, &buffers), &mut nodes, &mut walked)?;
    }
    Ok(GltfModel { file: file.to_string(), meshes, nodes, glass })
}

/// The glass a mesh's primitives' materials describe in their extras
/// ([`glass_from_extras`]): refused by file, material and field where a value cannot be taken,
/// and by mesh where its primitives describe different glass.
fn mesh_glass(file: &str, mesh: &::gltf::Mesh) -> Result<Option<MeshGlass>> {
    let mut found: Option<MeshGlass> = None;
    for material in mesh.primitives().map(|p| p.material()) {
        let (Some(index), Some(extras)) = (material.index(), material.extras()) else { continue };
        let label = format!("material {index} '{}'", material.name().unwrap_or(""));
        let glass = glass_from_extras(&label, extras.get())
            .map_err(|(field, reason)| Error::object(file, label.clone(), format!("extras {field}: {reason}")))?;
        match (&found, glass) {
            (Some(a), Some(b)) if (a.solar, a.visible, &a.angular) != (b.solar, b.visible, &b.angular) => {
                let object = format!("mesh {} '{}'", mesh.index(), mesh.name().unwrap_or(""));
                return Err(Error::object(
                    file,
                    object,
                    format!("its primitives' materials {} and {} describe different glass", a.material, b.material),
                ));
            }
            (None, Some(b)) => found = Some(b),
            _ => {}
        }
    }
    Ok(found)
}

/// Points and lines cast no shadow and have no area: they are left out, and the user told once.
fn warn_skipped_primitives(file: &str, document: &::gltf::Document) {
    use ::gltf::mesh::Mode;
    let skipped = document
        .meshes()
        .flat_map(|m| m.primitives())
        .filter(|p| matches!(p.mode(), Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip))
        .count();
    if skipped > 0 {
        log::warn!("{file}: {skipped} point or line primitive(s) left out (they cast no shadow)");
    }
}

fn check_magic(file: &str, bytes: &[u8]) -> Result<()> {
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace()).copied();
    if bytes.starts_with(b"glTF") {
        return check_glb_length(file, bytes);
    }
    if first == Some(b'{') {
        return Ok(());
    }
    if bytes.is_empty() {
        return Err(Error::model(file, "the file is empty"));
    }
    Err(Error::model(file, "not a glTF file: expected the binary magic 'glTF' or a JSON object"))
}

fn load_buffers(
    file: &str,
    root: &::gltf::json::Root,
    blob: Option<Vec<u8>>,
    external: impl Fn(&str) -> std::result::Result<Vec<u8>, String>,
) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for (index, buffer) in root.buffers.iter().enumerate() {
        if gltf_extensions::is_fallback(buffer) {
            // Stands in for meshopt-compressed data; its views are decoded into new buffers.
            out.push(Vec::new());
            continue;
        }
        let data = match &buffer.uri {
            None => blob.clone().ok_or_else(|| Error::model(file, "buffer 0 refers to the GLB binary chunk, which is missing"))?,
            Some(uri) => match uri.strip_prefix("data:") {
                Some(rest) => decode_data_uri(rest).map_err(|r| Error::model(file, format!("buffer {index}: {r}")))?,
                None => external(uri).map_err(|r| Error::model(file, r))?,
            },
        };
        let declared = buffer.byte_length.0;
        if (data.len() as u64) < declared {
            return Err(Error::model(file, format!("buffer {index} is truncated: {} bytes present, {declared} declared", data.len())));
        }
        out.push(data);
    }
    Ok(out)
}

fn decode_data_uri(rest: &str) -> std::result::Result<Vec<u8>, String> {
    let (_, payload) = rest.split_once(";base64,").ok_or("data: URI is not base64")?;
    base64::engine::general_purpose::STANDARD.decode(payload).map_err(|e| format!("bad base64 data: {e}"))
}

/// A GLB header's total length must cover the 12-byte header itself: the gltf crate subtracts
/// 12 from it unchecked (a panic in builds with overflow checks; found by fuzzing).
fn check_glb_length(file: &str, bytes: &[u8]) -> Result<()> {
    match bytes.get(8..12) {
        Some(&[a, b, c, d]) if u32::from_le_bytes([a, b, c, d]) < 12 => Err(Error::model(
            file,
            format!(
                "not a valid glTF 2.0 file: its GLB header declares {} bytes in all, less than the header itself",
                u32::from_le_bytes([a, b, c, d])
            ),
        )),
        _ => Ok(()),
    }
}

/// gltf-json 1.4's validation indexes `accessors` with each primitive's POSITION before checking
/// that it exists (a panic; found by fuzzing): check it first, on the JSON (chunk).
fn check_position_accessors(file: &str, bytes: &[u8]) -> Result<()> {
    let json = if bytes.starts_with(b"glTF") {
        let length = bytes.get(12..16).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        bytes.get(20..20usize.saturating_add(length)).unwrap_or(&[])
    } else {
        bytes
    };
    // Anything unreadable here is left for the gltf crate to report.
    // Lossy: the gltf crate reads strings holding invalid UTF-8, so this check must too.
    let Ok(root) = serde_json::from_str::<serde_json::Value>(&String::from_utf8_lossy(json)) else { return Ok(()) };
    let accessors = root.get("accessors").and_then(serde_json::Value::as_array).map_or(0, Vec::len);
    let meshes = root.get("meshes").and_then(serde_json::Value::as_array).map_or(&[][..], Vec::as_slice);
    for (m, mesh) in meshes.iter().enumerate() {
        let primitives = mesh.get("primitives").and_then(serde_json::Value::as_array).map_or(&[][..], Vec::as_slice);
        for (p, primitive) in primitives.iter().enumerate() {
            match primitive.pointer("/attributes/POSITION").and_then(serde_json::Value::as_u64) {
                Some(i) if i as usize >= accessors => {
                    let reason = format!("primitive {p}: POSITION accessor {i} does not exist ({accessors} accessors)");
                    return Err(Error::object(file, format!("mesh {m}"), reason));
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// The nodes to walk: the default scene's, else the first scene's, else every parentless node.
fn scene_roots<'a>(doc: &'a ::gltf::Document) -> Vec<::gltf::Node<'a>> {
    if let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) {
        return scene.nodes().collect();
    }
    let mut has_parent = vec![false; doc.nodes().len()];
    for n in doc.nodes() {
        for c in n.children() {
            has_parent[c.index()] = true;
        }
    }
    doc.nodes().filter(|n| !has_parent[n.index()]).collect()
}

/// glTF gives a node at most one parent. A hostile file may give it several, or a cycle: walking
/// such a graph would repeat nodes without end, or exponentially often (a DAG of shared children).
/// The walk keeps its own stack, so a deep (valid) chain cannot overflow the thread's.
fn collect_nodes<'a>(
    file: &str,
    root: &::gltf::Node<'a>,
    parent: DMat4,
    (document, buffers): (&::gltf::Document, &[Vec<u8>]),
    out: &mut Vec<GltfNode>,
    walked: &mut [bool],
) -> Result<()> {
    let mut stack = vec![(root.clone(), parent)];
    while let Some((node, parent)) = stack.pop() {
        let name = node.name().map(str::to_string).unwrap_or_else(|| format!("node{}", node.index()));
        match walked.get_mut(node.index()) {
            Some(seen) if !*seen => *seen = true,
            _ => {
                return Err(Error::object(
                    file,
                    format!("node '{name}'"),
                    "is reached twice in the node hierarchy (a cycle, or more than one parent)",
                ));
            }
        }
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            let err = |reason: String| Error::object(file, format!("node '{name}'"), reason);
            let veil = extras_veil(&node).map_err(err)?;
            let (named, marked, mesh) = (node.name().is_some(), is_marked(&node), mesh.index());
            match gltf_instancing::instance_transforms(&node, document, buffers).map_err(err)? {
                // One node per instance, `NAME[k]`: each may be a receiver of its own.
                Some(instances) => out.extend(instances.into_iter().enumerate().map(|(k, instance)| GltfNode {
                    name: format!("{name}[{k}]"),
                    named,
                    marked,
                    veil,
                    mesh,
                    transform: world * instance,
                    city: None,
                })),
                None => out.push(GltfNode { name, named, marked, veil, mesh, transform: world, city: None }),
            }
        }
        // Reversed onto the stack: children are walked in file order.
        let children: Vec<_> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world)));
    }
    Ok(())
}

fn is_marked(node: &::gltf::Node) -> bool {
    let Some(raw) = node.extras() else { return false };
    let value: serde_json::Value = serde_json::from_str(raw.get()).unwrap_or_default();
    value.pointer("/sunlit/receiver").and_then(serde_json::Value::as_bool).unwrap_or(false)
}

/// Foliage and transmittance marks in a node's extras; a mark of the wrong type is an error.
fn extras_veil(node: &::gltf::Node) -> std::result::Result<NodeVeil, String> {
    let Some(raw) = node.extras() else { return Ok(NodeVeil::default()) };
    let value: serde_json::Value = serde_json::from_str(raw.get()).unwrap_or_default();
    let foliage = match value.pointer("/sunlit/foliage") {
        None => false,
        Some(v) => v.as_bool().ok_or_else(|| format!("extras sunlit.foliage is {v}, expected true or false"))?,
    };
    let transmittance = match value.pointer("/sunlit/transmittance") {
        None => 0.0,
        Some(v) => v.as_f64().ok_or_else(|| format!("extras sunlit.transmittance is {v}, expected a number in [0, 1)"))?,
    };
    Ok(NodeVeil { foliage, transmittance })
}

fn read_mesh(file: &str, mesh: &::gltf::Mesh, buffers: &[Vec<u8>]) -> Result<SourceMesh> {
    let object = format!("mesh {} '{}'", mesh.index(), mesh.name().unwrap_or(""));
    let err = |reason: String| Error::object(file, object.clone(), reason);
    let mut out = SourceMesh::default();
    for prim in mesh.primitives() {
        let Some(pos) = prim.get(&::gltf::Semantic::Positions) else {
            return Err(err(format!("primitive {} has no POSITION attribute", prim.index())));
        };
        let positions = gltf_accessor::read_positions(&pos, buffers).map_err(&err)?;
        let indices = match prim.indices() {
            Some(acc) => gltf_accessor::read_indices(&acc, buffers).map_err(&err)?,
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(err(format!("index {bad} out of range ({} vertices)", positions.len())));
        }
        let base = out.positions.len() as u32;
        let tris = triangles(prim.mode(), &indices).map_err(&err)?;
        out.indices.extend(tris.iter().map(|i| i + base));
        out.positions.extend(positions);
    }
    Ok(out)
}

/// Triangle list from a primitive's index stream; points and lines cast no shadow.
fn triangles(mode: ::gltf::mesh::Mode, idx: &[u32]) -> std::result::Result<Vec<u32>, String> {
    use ::gltf::mesh::Mode;
    Ok(match mode {
        Mode::Triangles => idx[..idx.len() - idx.len() % 3].to_vec(),
        Mode::TriangleStrip => (2..idx.len())
            .flat_map(|i| if i % 2 == 0 { [idx[i - 2], idx[i - 1], idx[i]] } else { [idx[i - 1], idx[i - 2], idx[i]] })
            .collect(),
        Mode::TriangleFan => (2..idx.len()).flat_map(|i| [idx[0], idx[i - 1], idx[i]]).collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => Vec::new(),
    })
}

impl GltfModel {
    /// Adds this model's meshes and nodes to a scene builder, choosing receivers with `is_receiver`
    /// and what each node lets through with `veil`.
    pub fn add_to(
        self,
        builder: &mut crate::scene::SceneBuilder,
        mut is_receiver: impl FnMut(&GltfNode) -> bool,
        mut veil: impl FnMut(&GltfNode) -> NodeVeil,
    ) {
        let file = self.file;
        let base: Vec<usize> = self.meshes.into_iter().enumerate().map(|(i, m)| builder.add_mesh(format!("{file}: mesh {i}"), m)).collect();
        for node in self.nodes {
            let receiver = is_receiver(&node);
            let veil = veil(&node);
            if !veil.is_opaque() {
                builder.set_node_veil(builder.node_count(), veil);
            }
            if node.city.is_some() {
                // A city surface receives in one run and is a tile's context in another.
                builder.cast_by_parts(builder.node_count());
            }
            builder.add_node(SourceNode {
                origin: node.origin(&file),
                mesh: base[node.mesh],
                transform: node.transform,
                receiver,
                name: node.name,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use glam::DVec3;

    #[test]
    fn axes_map_gltf_up_and_north() {
        let m = gltf_to_world();
        // glTF +Y (up) → z; glTF −Z (north) → +y; glTF +X (east) → +x.
        assert_eq!(m.transform_point3(DVec3::Y), DVec3::Z);
        assert_eq!(m.transform_point3(-DVec3::Z), DVec3::Y);
        assert_eq!(m.transform_point3(DVec3::X), DVec3::X);
        // A determinant of +1: a rotation, so triangle winding (outward normals) is kept.
        assert!((m.determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn garbage_is_refused_with_the_file_named() {
        for (bytes, needle) in [(&b""[..], "empty"), (b"PK\x03\x04", "not a glTF"), (b"glTF\x02\x00\x00\x00", "not a valid glTF")] {
            let e = read_bytes("x.glb", bytes, 0.0).unwrap_err().to_string();
            assert!(e.starts_with("x.glb: ") && e.contains(needle), "{e}");
        }
    }

    /// A unit square in the ground plane as a strip, a fan and a list; its positions stored
    /// sparse (no buffer view: zeros, then three substituted vertices).
    fn square(mode: u32, indices: &[u8]) -> Vec<u8> {
        // Sparse: vertices 1, 2, 3 of four (vertex 0 stays at the origin).
        let mut bin: Vec<u8> = vec![1, 2, 3, 0];
        for p in [[1.0f32, 0.0, 0.0], [1.0, 0.0, -1.0], [0.0, 0.0, -1.0]] {
            bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
        }
        bin.extend(indices);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let data = base64::engine::general_purpose::STANDARD.encode(&bin);
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":{len}}}],
            "bufferViews":[{{"buffer":0,"byteLength":4}},{{"buffer":0,"byteOffset":4,"byteLength":36}},{{"buffer":0,"byteOffset":40,"byteLength":{n}}}],
            "accessors":[{{"componentType":5126,"count":4,"type":"VEC3","min":[0,0,-1],"max":[1,0,0],
                "sparse":{{"count":3,"indices":{{"bufferView":0,"componentType":5121}},"values":{{"bufferView":1}}}}}},
                {{"bufferView":2,"componentType":5121,"count":{n},"type":"SCALAR"}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"mode":{mode}}}]}}],
            "nodes":[{{"name":"sq","mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
            len = bin.len(),
            n = indices.len()
        )
        .into_bytes()
    }

    /// The area of a mesh's triangles (sunlit axes do not matter for an area).
    fn area(mesh: &SourceMesh) -> f64 {
        mesh.indices
            .chunks_exact(3)
            .map(|t| {
                let p = |i: u32| glam::Vec3::from(mesh.positions[i as usize]).as_dvec3();
                (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length() / 2.0
            })
            .sum()
    }

    #[test]
    fn strips_fans_lists_and_sparse_positions_give_the_same_square() {
        // glTF modes: 4 TRIANGLES, 5 TRIANGLE_STRIP, 6 TRIANGLE_FAN.
        for (mode, indices) in [(4, &[0u8, 1, 2, 0, 2, 3][..]), (5, &[1, 2, 0, 3][..]), (6, &[0, 1, 2, 3][..])] {
            let model = read_bytes("sq.gltf", &square(mode, indices), 0.0).unwrap();
            let mesh = &model.meshes[0];
            assert_eq!(mesh.indices.len(), 6, "mode {mode}");
            assert!((area(mesh) - 1.0).abs() < 1e-9, "mode {mode}: area {}", area(mesh));
            // Every triangle faces up (+Y in glTF): strips alternate their winding back.
            for t in mesh.indices.chunks_exact(3) {
                let p = |i: u32| glam::Vec3::from(mesh.positions[i as usize]);
                assert!((p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).y > 0.0, "mode {mode}: {t:?} faces down");
            }
        }
    }

    #[test]
    fn points_and_lines_are_left_out() {
        for mode in [0, 1, 2, 3] {
            let model = read_bytes("sq.gltf", &square(mode, &[0, 1, 2, 3]), 0.0).unwrap();
            assert!(model.meshes[0].indices.is_empty(), "mode {mode}");
        }
    }

    #[test]
    fn a_required_texture_extension_is_ignored() {
        // A KTX2 texture has no `source` of its own: fine, sunlit reads no texture.
        let text = String::from_utf8(square(4, &[0, 1, 2, 0, 2, 3])).unwrap().replacen(
            r#"{"asset":{"version":"2.0"},"#,
            r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_texture_basisu"],"extensionsRequired":["KHR_texture_basisu"],
            "textures":[{"extensions":{"KHR_texture_basisu":{"source":0}}}],"images":[{"uri":"wall.ktx2"}],"#,
            1,
        );
        let model = read_bytes("ktx2.gltf", text.as_bytes(), 0.0).unwrap();
        assert_eq!(model.meshes[0].indices.len(), 6);
    }
}
