//! A small binary glTF 2.0 (GLB) writer for examples, benchmark models and tests.
//!
//! Owns writing geometry only: triangle meshes (positions + `UNSIGNED_INT` indices), root nodes
//! with a name, a mesh, a translation and optional `extras` (e.g. `{"sunlit":{"receiver":true}}`),
//! and one scene listing every node. No materials, normals, textures or animations: sunlit only
//! needs geometry, and glTF viewers shade primitives without a material with the default one.
//!
//! Callers give coordinates in sunlit's world axes (x east, y north, z up, metres); the writer
//! converts them to glTF's (+Y up, −Z north, +X east), so a sunlit point `(x, y, z)` is written
//! as `(x, z, −y)`. That conversion is a proper rotation, so counter-clockwise winding (seen from
//! the outward side) is preserved.
//!
//! Layout: one buffer (the GLB `BIN` chunk); per mesh one `ARRAY_BUFFER` view of `VEC3` floats
//! and one `ELEMENT_ARRAY_BUFFER` view of `u32` indices, every view 4-byte aligned; `POSITION`
//! accessors carry the `min`/`max` the specification requires. Meshes should be non-empty: glTF
//! requires accessors with at least one element, so an empty mesh gives a file that strict
//! validators reject.

use serde_json::{Value, json};

/// `ARRAY_BUFFER` buffer-view target (vertex attributes).
const TARGET_ARRAY_BUFFER: u32 = 34962;
/// `ELEMENT_ARRAY_BUFFER` buffer-view target (indices).
const TARGET_ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Accessor component type `FLOAT`.
const COMPONENT_FLOAT: u32 = 5126;
/// Accessor component type `UNSIGNED_INT`.
const COMPONENT_UNSIGNED_INT: u32 = 5125;
/// Primitive mode `TRIANGLES`.
const MODE_TRIANGLES: u32 = 4;

/// GLB header magic, `"glTF"` little-endian.
const GLB_MAGIC: u32 = 0x4654_6C67;
/// GLB container version.
const GLB_VERSION: u32 = 2;
/// Chunk type of the JSON chunk, `"JSON"`.
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk, `"BIN\0"`.
const CHUNK_BIN: u32 = 0x004E_4942;

/// Converts a point or vector from sunlit axes (x east, y north, z up) to glTF axes
/// (`+ 0.0` turns a negated zero into a plain one, so files show `0` rather than `-0`).
fn to_gltf([x, y, z]: [f32; 3]) -> [f32; 3] {
    [x, z, -y + 0.0]
}

/// A mesh waiting to be written, already in glTF axes.
#[derive(Debug, Clone)]
struct MeshData {
    name: String,
    positions: Vec<[f32; 3]>,
    indices: Vec<u32>,
}

/// A root node waiting to be written, translation already in glTF axes.
#[derive(Debug, Clone)]
struct NodeData {
    name: String,
    mesh: usize,
    translation: [f32; 3],
    extras: Option<Value>,
}

/// Collects meshes and root nodes, then serialises them as one GLB file.
#[derive(Debug, Clone, Default)]
pub struct GlbWriter {
    meshes: Vec<MeshData>,
    nodes: Vec<NodeData>,
}

impl GlbWriter {
    /// An empty model.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a mesh given in SUNLIT axes (x east, y north, z up); converts to glTF axes internally.
    /// Returns the mesh index. `indices` is a triangle list into `positions`.
    pub fn add_mesh(&mut self, name: &str, positions: &[[f32; 3]], indices: &[u32]) -> usize {
        debug_assert!(indices.len().is_multiple_of(3), "mesh '{name}': index count not a multiple of 3");
        debug_assert!(indices.iter().all(|&i| (i as usize) < positions.len()), "mesh '{name}': index out of range");
        self.meshes.push(MeshData {
            name: name.to_owned(),
            positions: positions.iter().copied().map(to_gltf).collect(),
            indices: indices.to_vec(),
        });
        self.meshes.len() - 1
    }

    /// Adds a root node using a mesh, with a translation given in SUNLIT axes (converted), and
    /// optional extras JSON (e.g. `{"sunlit":{"receiver":true}}`). Returns the node index.
    pub fn add_node(&mut self, name: &str, mesh: usize, translation: [f32; 3], extras: Option<Value>) -> usize {
        debug_assert!(mesh < self.meshes.len(), "node '{name}': mesh {mesh} not added yet");
        self.nodes.push(NodeData { name: name.to_owned(), mesh, translation: to_gltf(translation), extras });
        self.nodes.len() - 1
    }

    /// Number of meshes added so far.
    pub fn mesh_count(&self) -> usize {
        self.meshes.len()
    }

    /// Number of nodes added so far.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Serialises to GLB bytes (12-byte header, JSON chunk padded with spaces to 4 bytes, BIN
    /// chunk padded with zeros; the BIN chunk is left out when there is no geometry).
    pub fn to_glb(&self) -> Vec<u8> {
        let mut bin: Vec<u8> = Vec::new();
        let mut views = Vec::new();
        let mut accessors = Vec::new();
        let mut meshes = Vec::new();

        for mesh in &self.meshes {
            // Positions: VEC3 floats, with min/max.
            let (min, max) = bounds(&mesh.positions);
            let offset = bin.len();
            for p in &mesh.positions {
                for c in p {
                    bin.extend_from_slice(&c.to_le_bytes());
                }
            }
            views.push(json!({
                "buffer": 0,
                "byteOffset": offset,
                "byteLength": bin.len() - offset,
                "target": TARGET_ARRAY_BUFFER,
            }));
            let position_accessor = accessors.len();
            accessors.push(json!({
                "bufferView": views.len() - 1,
                "componentType": COMPONENT_FLOAT,
                "count": mesh.positions.len(),
                "type": "VEC3",
                "min": min,
                "max": max,
            }));

            // Indices: u32 scalars (4-byte elements keep every view 4-aligned).
            let offset = bin.len();
            for i in &mesh.indices {
                bin.extend_from_slice(&i.to_le_bytes());
            }
            views.push(json!({
                "buffer": 0,
                "byteOffset": offset,
                "byteLength": bin.len() - offset,
                "target": TARGET_ELEMENT_ARRAY_BUFFER,
            }));
            let index_accessor = accessors.len();
            accessors.push(json!({
                "bufferView": views.len() - 1,
                "componentType": COMPONENT_UNSIGNED_INT,
                "count": mesh.indices.len(),
                "type": "SCALAR",
            }));

            meshes.push(json!({
                "name": mesh.name,
                "primitives": [{
                    "attributes": { "POSITION": position_accessor },
                    "indices": index_accessor,
                    "mode": MODE_TRIANGLES,
                }],
            }));
        }

        let nodes: Vec<Value> = self
            .nodes
            .iter()
            .map(|n| {
                let mut node = json!({ "name": n.name, "mesh": n.mesh });
                if n.translation != [0.0; 3] {
                    node["translation"] = json!(n.translation);
                }
                if let Some(extras) = &n.extras {
                    node["extras"] = extras.clone();
                }
                node
            })
            .collect();

        let mut root = json!({
            "asset": { "version": "2.0", "generator": "sunlit" },
            "scene": 0,
            "scenes": [{ "nodes": (0..self.nodes.len()).collect::<Vec<_>>() }],
            "nodes": nodes,
        });
        if !meshes.is_empty() {
            root["meshes"] = Value::Array(meshes);
            root["accessors"] = Value::Array(accessors);
            root["bufferViews"] = Value::Array(views);
        }
        if !bin.is_empty() {
            root["buffers"] = json!([{ "byteLength": bin.len() }]);
        }

        // `Value`'s Display cannot fail, so this is the infallible serialiser.
        let mut json_bytes = root.to_string().into_bytes();
        pad(&mut json_bytes, b' ');
        pad(&mut bin, 0);

        let bin_chunk_len = if bin.is_empty() { 0 } else { 8 + bin.len() };
        let total = 12 + 8 + json_bytes.len() + bin_chunk_len;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(&GLB_MAGIC.to_le_bytes());
        out.extend_from_slice(&GLB_VERSION.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
        out.extend_from_slice(&json_bytes);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
            out.extend_from_slice(&bin);
        }
        out
    }
}

/// Component-wise min and max of `points` (zeros when empty).
fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let Some(&first) = points.first() else {
        return ([0.0; 3], [0.0; 3]);
    };
    points.iter().fold((first, first), |(mut lo, mut hi), p| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
        (lo, hi)
    })
}

/// Pads `bytes` with `fill` to a multiple of 4.
fn pad(bytes: &mut Vec<u8>, fill: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(fill);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the sunlit ground plane (normal +z) and a triangle standing on it.
    fn sample() -> GlbWriter {
        let mut w = GlbWriter::new();
        let square = w.add_mesh("square", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2, 0, 2, 3]);
        let tri = w.add_mesh("tri", &[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 3.0]], &[0, 1, 2]);
        w.add_node("Floor", square, [0.0; 3], Some(json!({"sunlit": {"receiver": true}})));
        w.add_node("Fin", tri, [1.0, 2.0, 3.0], None);
        w.add_node("Fin2", tri, [5.0, 0.0, 0.0], None);
        w
    }

    #[test]
    fn header_and_chunks_are_well_formed() {
        let bytes = sample().to_glb();
        assert_eq!(&bytes[0..4], b"glTF");
        assert_eq!(u32::from_le_bytes(bytes[4..8].try_into().unwrap()), 2);
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len());
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        assert_eq!(&bytes[16..20], b"JSON");
        assert_eq!(json_len % 4, 0);
        let bin_at = 20 + json_len;
        let bin_len = u32::from_le_bytes(bytes[bin_at..bin_at + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
        assert_eq!(bin_len % 4, 0);
        assert_eq!(bin_at + 8 + bin_len, bytes.len());

        let root: Value = serde_json::from_slice(&bytes[20..bin_at]).unwrap();
        assert_eq!(root["asset"]["version"], "2.0");
        assert_eq!(root["asset"]["generator"], "sunlit");
        assert_eq!(root["scenes"][0]["nodes"], json!([0, 1, 2]));
        for view in root["bufferViews"].as_array().unwrap() {
            assert_eq!(view["byteOffset"].as_u64().unwrap() % 4, 0);
            assert_eq!(view["byteLength"].as_u64().unwrap() % 4, 0);
            assert!(view["target"].is_u64());
        }
    }

    #[test]
    fn round_trips_through_gltf_crate() {
        let bytes = sample().to_glb();
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = gltf.blob.as_deref().unwrap();

        assert_eq!(gltf.meshes().count(), 2);
        let names: Vec<_> = gltf.nodes().map(|n| n.name().unwrap().to_owned()).collect();
        assert_eq!(names, ["Floor", "Fin", "Fin2"]);
        let scene = gltf.default_scene().unwrap();
        assert_eq!(scene.nodes().count(), 3);

        let nodes: Vec<_> = gltf.nodes().collect();
        let extras: Value = serde_json::from_str(nodes[0].extras().as_ref().unwrap().get()).unwrap();
        assert_eq!(extras, json!({"sunlit": {"receiver": true}}));
        assert!(nodes[1].extras().is_none());
        // Shared mesh stays shared.
        assert_eq!(nodes[1].mesh().unwrap().index(), nodes[2].mesh().unwrap().index());
        // Translation (1, 2, 3) in sunlit axes → (1, 3, −2) in glTF axes.
        let (t, _, _) = nodes[1].transform().decomposed();
        assert_eq!(t, [1.0, 3.0, -2.0]);

        // Accessor counts and types.
        let square = gltf.meshes().next().unwrap();
        let prim = square.primitives().next().unwrap();
        assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
        let pos = prim.get(&gltf::Semantic::Positions).unwrap();
        assert_eq!(pos.count(), 4);
        assert_eq!(pos.data_type(), gltf::accessor::DataType::F32);
        let idx = prim.indices().unwrap();
        assert_eq!(idx.count(), 6);
        assert_eq!(idx.data_type(), gltf::accessor::DataType::U32);

        // Known vertex: sunlit (1, 1, 0) → glTF (1, 0, −1); min/max present and converted.
        let reader = prim.reader(|_| Some(blob));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        assert_eq!(positions[2], [1.0, 0.0, -1.0]);
        assert_eq!(pos.min().unwrap(), json!([0.0, 0.0, -1.0]));
        assert_eq!(pos.max().unwrap(), json!([1.0, 0.0, 0.0]));
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(indices, [0, 1, 2, 0, 2, 3]);

        // Winding survives the axis change: the floor's normal (+z up) becomes glTF +Y.
        let [a, b, c] = [positions[0], positions[1], positions[2]].map(glam::Vec3::from);
        let n = (b - a).cross(c - a).normalize();
        assert!((n - glam::Vec3::Y).length() < 1e-6, "normal {n}");

        let tri = gltf.meshes().nth(1).unwrap();
        let prim = tri.primitives().next().unwrap();
        let reader = prim.reader(|_| Some(blob));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        assert_eq!(positions[2], [0.0, 3.0, 0.0]);
        assert_eq!(prim.indices().unwrap().count(), 3);
    }

    #[test]
    fn empty_writer_gives_valid_glb() {
        let bytes = GlbWriter::new().to_glb();
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        assert_eq!(gltf.nodes().count(), 0);
        assert!(gltf.blob.is_none());
    }
}
