//! Uploading a scene: its meshes, instances and the static mesh, in the culling's order, into
//! device buffers within the device's limits, and the bind groups the passes read them through.
//!
//! The static mesh (everything not instanced) can exceed one buffer's size limit; it is split
//! into chunks of whole triangles, each indexed into its own distinct vertices.

use std::collections::HashMap;
use std::ops::Range;

use glam::DMat4;

use super::pipelines::{GpuInstance, GpuParams, GpuVertex, entry};
use super::plan::SceneLayout;
use super::{Counter, GpuScene};
use crate::count::cull::{CPU_LEAF_TRIANGLES, LEAF_TRIANGLES};
use crate::error::{GpuError, Result};
use crate::scene::{Mesh, Scene};

/// Part of the static mesh: a range of triangles in the culling's order, indexed into the
/// distinct vertices they use.
pub(super) struct StaticChunk {
    pub(super) vertices: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) triangles: Range<u32>,
}

pub(super) struct GpuMesh {
    pub(super) vertices: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) index_count: u32,
}

/// Vertex `v` of `mesh` as the shaders read it: position, surface id, and its leaf rank,
/// transmittance and dither seed (defaults when the mesh has no see-through parts).
pub(super) fn gpu_vertex(mesh: &Mesh, v: usize) -> GpuVertex {
    let veil = mesh.veils.get(v).copied().unwrap_or_default();
    GpuVertex { position: mesh.positions[v], surface: mesh.surfaces[v], veil: [veil.rank, veil.transmittance], seed: veil.seed }
}

/// Vertices `range` of `mesh`, in order.
pub(super) fn gpu_vertices(mesh: &Mesh, range: Range<usize>) -> Vec<GpuVertex> {
    range.map(|v| gpu_vertex(mesh, v)).collect()
}

impl Counter {
    /// Uploads a scene's geometry once; views of it then cost only draws. The static mesh goes
    /// into as many vertex buffers as the device's buffer size limit needs.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene> {
        self.upload_chunked(scene, self.static_chunk_triangles())
    }

    /// Static triangles a vertex buffer holds within the device's buffer size limit.
    pub(super) fn static_chunk_triangles(&self) -> u32 {
        let per_triangle = 3 * size_of::<GpuVertex>() as u64;
        (self.device.limits().max_buffer_size / per_triangle).clamp(1, u32::MAX as u64) as u32
    }

    /// [`Self::upload`] with at most `max_triangles` static triangles a vertex buffer.
    pub(super) fn upload_chunked(&self, scene: &Scene, max_triangles: u32) -> Result<GpuScene> {
        self.upload_with(scene, max_triangles, None)
    }

    /// [`Self::upload_chunked`], the GPU's culling with room for `pairs` pairs a batch where
    /// given (tests force its overflow with few).
    pub(super) fn upload_with(&self, scene: &Scene, max_triangles: u32, pairs: Option<u32>) -> Result<GpuScene> {
        use wgpu::util::DeviceExt as _;
        // wgpu's create_buffer_init panics on a lost device (its mapped range is invalid).
        self.faults.check_lost()?;
        self.check_fits(scene)?;
        let meshes: Vec<GpuMesh> = scene
            .meshes
            .iter()
            .enumerate()
            .map(|(index, m)| {
                // The static mesh (0) is stored in the culling's order below instead.
                let vertices: Vec<GpuVertex> = if index == 0 { Vec::new() } else { gpu_vertices(m, 0..m.positions.len()) };
                let indices: &[u32] = if index == 0 { &[] } else { &m.indices };
                GpuMesh {
                    vertices: self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&m.label),
                        contents: non_empty(bytemuck::cast_slice(&vertices)),
                        usage: wgpu::BufferUsages::VERTEX,
                    }),
                    indices: self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&m.label),
                        contents: non_empty(bytemuck::cast_slice(indices)),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    index_count: indices.len() as u32,
                }
            })
            .collect();
        let leaf = if self.info.device_type == wgpu::DeviceType::Cpu { CPU_LEAF_TRIANGLES } else { LEAF_TRIANGLES };
        let layout = SceneLayout::new(scene, leaf);
        let culling = &layout.culling;
        let static_chunks = self.static_chunks(scene, culling.static_order(), max_triangles.max(1));
        let to_scene = DMat4::from_translation(-scene.origin);
        let instances: Vec<GpuInstance> = culling
            .slot_order()
            .iter()
            .map(|&i| {
                let inst = &scene.instances[i];
                GpuInstance {
                    transform: (to_scene * inst.transform).as_mat4().to_cols_array_2d(),
                    receiver_base: inst.receiver_base,
                    leaf_shift: inst.leaf_shift,
                    _pad: [0; 2],
                }
            })
            .collect();
        let instance_buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("instances"),
            contents: non_empty(bytemuck::cast_slice(&instances)),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let params = GpuParams { count_edges: self.options.accuracy.is_some() as u32, static_slot: culling.static_slot(), _pad: [0; 2] };
        let params_buffer = self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let render_bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("render"),
            layout: &self.pipelines.render_layout,
            entries: &[entry(0, instance_buffer.as_entire_binding()), entry(2, params_buffer.as_entire_binding())],
        });
        let count_bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("count"),
            layout: &self.pipelines.count_layout,
            entries: &[
                entry(0, wgpu::BindingResource::TextureView(&self.batch.atlas.ids)),
                entry(1, self.batch.views.as_entire_binding()),
                entry(2, params_buffer.as_entire_binding()),
                entry(3, self.batch.counts.as_entire_binding()),
                entry(4, self.batch.members.as_entire_binding()),
            ],
        });
        self.check_errors("uploading the scene")?;
        let compute = self.upload_compute(scene, &layout);
        let pulled = self.upload_pulled(scene, &layout, pairs);
        self.check_errors("uploading the scene for the GPU's culling")?;
        Ok(GpuScene { meshes, static_chunks, layout, render_bind, count_bind, compute, pulled })
    }

    /// Refuses, before allocating, a scene whose buffers exceed this device's limits: wgpu would
    /// otherwise fail with a validation error, or the driver run out of memory. The static mesh
    /// (mesh 0) is exempt: it is split over as many buffers as it needs.
    fn check_fits(&self, scene: &Scene) -> Result<()> {
        let limits = self.device.limits();
        let mesh_bytes = |m: &crate::scene::Mesh| (m.positions.len() * size_of::<GpuVertex>()).max(m.indices.len() * 4);
        let vertices = scene.meshes.iter().skip(1).map(mesh_bytes).max().unwrap_or(0) as u64;
        let instances = (scene.instances.len() * size_of::<GpuInstance>()) as u64;
        let (limit_name, need, limit) = if vertices > limits.max_buffer_size {
            ("max_buffer_size", vertices, limits.max_buffer_size)
        } else if instances > limits.max_storage_buffer_binding_size {
            ("max_storage_buffer_binding_size", instances, limits.max_storage_buffer_binding_size)
        } else {
            return Ok(());
        };
        Err(GpuError::OverLimit { limit_name, need, limit }.into())
    }

    /// The static mesh's triangles in the culling's order, `max_triangles` a buffer, each indexed
    /// into its distinct vertices.
    fn static_chunks(&self, scene: &Scene, order: &[u32], max_triangles: u32) -> Vec<StaticChunk> {
        use wgpu::util::DeviceExt as _;
        let Some(mesh) = scene.meshes.first() else { return Vec::new() };
        let vertex = |v: u32| gpu_vertex(mesh, v as usize);
        order
            .chunks(max_triangles as usize)
            .enumerate()
            .map(|(c, part)| {
                let (vertices, indices) =
                    distinct_vertices(part.iter().flat_map(|&t| (0..3).map(move |k| mesh.indices[3 * t as usize + k])).map(vertex));
                let start = c as u32 * max_triangles;
                StaticChunk {
                    vertices: self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("static, spatial order"),
                        contents: non_empty(bytemuck::cast_slice(&vertices)),
                        usage: wgpu::BufferUsages::VERTEX,
                    }),
                    indices: self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("static indices, spatial order"),
                        contents: non_empty(bytemuck::cast_slice(&indices)),
                        usage: wgpu::BufferUsages::INDEX,
                    }),
                    triangles: start..start + part.len() as u32,
                }
            })
            .collect()
    }
}

/// The distinct vertices of a triangle list and its indices into them. The static mesh stores
/// each triangle's corners apart (so receivers' parts can carry their own ids), and models often
/// arrive that way too; on a CPU rasterizer the vertex work is most of a triangle-bound view's
/// cost, and indexed draws let it shade a vertex shared by several triangles once per batch of
/// indices: `nyt-rods` has about one distinct vertex a triangle instead of three, and counts its
/// views ~1.5× faster.
pub(super) fn distinct_vertices(corners: impl Iterator<Item = GpuVertex>) -> (Vec<GpuVertex>, Vec<u32>) {
    let mut index: HashMap<[u32; 7], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let indices = corners
        .map(|v| {
            *index.entry(bytemuck::cast(v)).or_insert_with(|| {
                vertices.push(v);
                vertices.len() as u32 - 1
            })
        })
        .collect();
    (vertices, indices)
}

/// wgpu refuses zero-sized buffer initialisation in some paths; an empty mesh gets 16 bytes.
fn non_empty(bytes: &[u8]) -> &[u8] {
    if bytes.is_empty() { &[0u8; 16] } else { bytes }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_corners_become_one_indexed_vertex() {
        let v = |x: f32, surface: u32| GpuVertex { position: [x, 0.0, 1.0], surface, veil: [-1.0, 0.0], seed: 0 };
        // Two triangles sharing an edge, and a corner of a third at the same place but another id.
        let corners = [v(0.0, 7), v(1.0, 7), v(2.0, 7), v(1.0, 7), v(3.0, 7), v(2.0, 7), v(0.0, 8), v(1.0, 7), v(2.0, 7)];
        let (vertices, indices) = distinct_vertices(corners.into_iter());
        assert_eq!(vertices.len(), 5);
        assert_eq!(indices, [0, 1, 2, 1, 3, 2, 4, 1, 2]);
        for (i, c) in indices.iter().zip(&corners) {
            assert_eq!(bytemuck::bytes_of(&vertices[*i as usize]), bytemuck::bytes_of(c));
        }
    }
}
