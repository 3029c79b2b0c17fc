//! The GPU pixel counter (wgpu; Vulkan/lavapipe natively, WebGPU in the browser).
//!
//! Owns the device, the pipelines and the atlas. For each (receiver, sun) view it renders, into
//! one tile of an atlas, the receiver alone (coverage mask, no depth test) and then the scene
//! (depth-tested receiver ids; only what lies in the prism in front of it, see [`super::cull`]);
//! a compute pass counts per tile the pixels where the receiver is visible and where it is covered. The sunlit fraction is visible / covered: the covered
//! count is the pixel estimate of the projected area A·cosθ/Ap of the paper's formula, measured
//! with the same rasterisation rule, so edge aliasing on unshaded edges cancels and an unshaded
//! surface gives exactly 1. Many views share one submission (tiles of the atlas).
//!
//! Requests for receivers of one view group ([`super::group`]: a wall and the windows in it) at
//! the same sun and leaf fraction share a tile: the mask pass draws each requested member with its
//! own id, the scene is drawn once, and the count pass counts each member apart.
//!
//! Foliage and see-through casters ([`crate::scene::Veil`]) are decided on the GPU, so one upload
//! serves every day: each view carries its day's leaf fraction and the vertex shader drops the
//! leaves whose rank is not below it; a see-through fragment is discarded (lets the sun through)
//! where a per-pixel hash threshold falls below its transmittance.
//!
//! Adaptive resolution ([`CounterOptions::accuracy`]): every tile is first counted at a small
//! side; the count pass also counts each member's shadow-edge pixel pairs, from which
//! [`error_estimate`] predicts the count's error, and tiles predicted worse than the target are
//! counted again at the side predicted to reach it (up to `resolution`). Fully lit and fully
//! shaded views, most of a year, then cost a small tile; views crossed by many shadow edges get
//! the full side.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use glam::{DMat4, DVec3};

use super::cull::{CPU_LEAF_TRIANGLES, Culling, DrawList, LEAF_TRIANGLES, Target};
use super::group::{MAX_MEMBERS, ViewGroups};
use super::view::{self, SunView};
use super::{ViewRequest, cos_incidence, is_dark};
use crate::error::{Error, Result};
use crate::platform;
use crate::scene::{Mesh, Scene};

const SUN_VIEW_WGSL: &str = include_str!("../../shaders/sun_view.wgsl");
const COUNT_PIXELS_WGSL: &str = include_str!("../../shaders/count_pixels.wgsl");
/// Rows of a tile per compute workgroup (the shader's `ROWS_PER_GROUP`).
const ROWS_PER_GROUP: u32 = 64;
/// One target, two channels: red = the visible surface's id (scene pass), green = the target
/// receiver's own coverage (mask pass). Per-channel write masks keep the passes apart, and the
/// count reads one texel per pixel.
const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// How the uncaptured-error sink records an out-of-memory error, for the hint in its message.
const OUT_OF_MEMORY: &str = "out of GPU memory";
/// Batches read back per map: bounds latency and memory while keeping the GPU fed.
const BATCHES_PER_READBACK: usize = 32;

/// The side adaptive counting starts at: ~2,000 pixels on the receiver, enough that a view
/// without shadow edges is within 0.001 and the edge count is a fair guide for the others.
pub const ADAPTIVE_FIRST_SIDE: u32 = 64;

/// Settings of a [`Counter`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CounterOptions {
    /// Tile size in pixels (square); 512 gives about three decimals. With `accuracy`, the
    /// largest side a view gets.
    pub resolution: u32,
    /// Largest atlas side in pixels; tiles per submission = (atlas / resolution)².
    pub max_atlas: u32,
    /// Target |error| of each fraction: `Some` counts every view at
    /// [`ADAPTIVE_FIRST_SIDE`] first and again, at a side up to `resolution`, only where the
    /// estimated error is larger ([`error_estimate`]). `None`: every view at `resolution`.
    pub accuracy: Option<f64>,
}

impl Default for CounterOptions {
    fn default() -> Self {
        Self { resolution: 512, max_atlas: 2048, accuracy: None }
    }
}

/// Estimated |error| of a fraction counted from `covered` pixels with `edges` shadow-edge pixel
/// pairs: each boundary pixel is decided by its centre and is off by up to half a pixel. Were
/// these errors independent they would add like a random walk, sqrt(edges/12) pixels; along a
/// straight edge they are not (a nearly axis-aligned edge repeats its sub-pixel offsets), and on
/// louvre shadows, many parallel straight edges, the exact reference showed errors up to
/// 2.6·sqrt(edges) pixels. The estimate takes 3·sqrt(edges), plus one pixel for the receiver's
/// own outline, over the covered pixels.
pub fn error_estimate(covered: u32, edges: u32) -> f64 {
    if covered == 0 {
        return f64::INFINITY;
    }
    (3.0 * (edges as f64).sqrt() + 1.0) / covered as f64
}

/// One counted view. A view that needed no render (sun down, facing away, or nothing in front
/// of the receiver) has `covered == 0`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Counted {
    /// Sunlit fraction in [0, 1].
    pub fraction: f64,
    /// Cosine of incidence (normal · sun).
    pub cos_incidence: f64,
    /// Pixels where the receiver is visible from the sun (0 when not rendered).
    pub visible: u32,
    /// Pixels the receiver covers in its tile (0 when not rendered).
    pub covered: u32,
    /// Area per pixel on the view plane (m²; 0 when not rendered).
    pub pixel_area: f64,
    /// Side of the tile it was counted in (0 when not rendered).
    pub side: u32,
    /// Shadow-edge pixel pairs on the receiver (counted only with an accuracy target).
    pub edges: u32,
}

impl Counted {
    /// [`error_estimate`] of this count (0 when not rendered: exact by construction).
    pub fn error_estimate(&self) -> f64 {
        if self.side == 0 { 0.0 } else { error_estimate(self.covered, self.edges) }
    }
}

/// The device, pipelines and atlas; reusable across scenes.
pub struct Counter {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    options: CounterOptions,
    /// The atlas's side in pixels: a whole number of tiles at every side used.
    atlas_side: u32,
    render_layout: wgpu::BindGroupLayout,
    count_layout: wgpu::BindGroupLayout,
    pipelines: ViewPipelines,
    count_pipeline: wgpu::ComputePipeline,
    atlas: Atlas,
    views: wgpu::Buffer,
    /// The same views as the vertex shaders read them: one uniform per tile, `tile_stride` apart,
    /// bound at a dynamic offset by `tile_bind`.
    tile_views: wgpu::Buffer,
    tile_bind: wgpu::BindGroup,
    tile_stride: u32,
    /// Receiver ids of the tiles' members (the count pass's `members`).
    members: wgpu::Buffer,
    counts: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Tiles rendered and triangles drawn in them since the counter was made (benchmarks).
    tiles_rendered: AtomicU64,
    triangles_drawn: AtomicU64,
    errors: Arc<Mutex<Vec<String>>>,
    /// Why the device was lost, once it is (set by wgpu's device-lost callback).
    lost: Arc<Mutex<Option<String>>>,
}

struct Atlas {
    ids: wgpu::TextureView,
    depth: wgpu::TextureView,
}

/// A scene uploaded to a [`Counter`]'s device.
pub struct GpuScene {
    meshes: Vec<GpuMesh>,
    /// The static mesh's triangles in the culling's spatial order, in buffers within the device's
    /// size limit, each indexed into its distinct vertices (the scene pass draws ranges of it).
    static_chunks: Vec<StaticChunk>,
    receivers: Vec<ReceiverView>,
    groups: ViewGroups,
    bounds: (DVec3, DVec3),
    origin: DVec3,
    culling: Culling,
    render_bind: wgpu::BindGroup,
    count_bind: wgpu::BindGroup,
}

/// Part of the static mesh: a range of triangles in the culling's order, indexed into the
/// distinct vertices they use.
struct StaticChunk {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    triangles: Range<u32>,
}

struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// What a view of one receiver needs: where to draw it alone, and how to fit the camera.
struct ReceiverView {
    /// The id its pixels carry (its own, or the mirrored surface's).
    gpu_id: u32,
    mesh: usize,
    indices: Range<u32>,
    /// For a receiver in the static mesh: its triangles' ranges in the culling's order.
    static_triangles: Vec<Range<u32>>,
    slot: u32,
    points: Vec<DVec3>,
    normal: DVec3,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuInstance {
    transform: [[f32; 4]; 4],
    receiver_base: u32,
    leaf_shift: f32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuView {
    tile: [u32; 2],
    first_member: u32,
    member_count: u32,
    side: u32,
    _pad: u32,
}

/// A tile's view as the vertex shaders read it (`TileView` in sun_view.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuTileView {
    view_proj: [[f32; 4]; 4],
    leaves: f32,
    _pad: [u32; 3],
}

/// One tile to render: requests of one view group at one sun and leaf fraction.
struct Tile {
    /// Request indices, their receivers distinct, the group's owner first.
    requests: Vec<usize>,
    view: SunView,
    draws: DrawList,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuParams {
    count_edges: u32,
    static_slot: u32,
    _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuVertex {
    position: [f32; 3],
    surface: u32,
    /// Leaf rank (negative: not a leaf) and transmittance.
    veil: [f32; 2],
    seed: u32,
}

/// Vertex `v` of `mesh` as the shaders read it: position, surface id, and its leaf rank,
/// transmittance and dither seed (defaults when the mesh has no see-through parts).
fn gpu_vertex(mesh: &Mesh, v: usize) -> GpuVertex {
    let veil = mesh.veils.get(v).copied().unwrap_or_default();
    GpuVertex { position: mesh.positions[v], surface: mesh.surfaces[v], veil: [veil.rank, veil.transmittance], seed: veil.seed }
}

/// Vertices `range` of `mesh`, in order.
fn gpu_vertices(mesh: &Mesh, range: Range<usize>) -> Vec<GpuVertex> {
    range.map(|v| gpu_vertex(mesh, v)).collect()
}

impl Counter {
    /// Opens a device and builds the pipelines and atlas.
    pub async fn new(options: CounterOptions) -> Result<Self> {
        let instance = platform::instance();
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
            .map_err(|e| Error::Gpu(format!("{} ({e})", platform::no_adapter_hint())))?;
        let limits = adapter.limits();
        let resolution = options.resolution;
        if !(16..=limits.max_texture_dimension_2d).contains(&resolution) {
            return Err(Error::argument(
                "--resolution",
                format!("{resolution} is outside 16..={} (this device's texture size limit)", limits.max_texture_dimension_2d),
            ));
        }
        if let Some(a) = options.accuracy
            && !(a > 0.0 && a < 1.0)
        {
            return Err(Error::argument("--accuracy", format!("{a} is not a fraction error in (0, 1)")));
        }
        let tiles_per_side = options.max_atlas.clamp(resolution, limits.max_texture_dimension_2d) / resolution;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor { label: Some("sunlit"), required_limits: limits, ..Default::default() })
            .await
            .map_err(|e| Error::Gpu(format!("could not open the GPU device: {e}")))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            if let Ok(mut list) = sink.lock() {
                list.push(if matches!(e, wgpu::Error::OutOfMemory { .. }) { OUT_OF_MEMORY.to_string() } else { e.to_string() });
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut slot) = lost_sink.lock() {
                *slot = Some(format!("{reason:?}: {message}"));
            }
        });
        let render_layout = render_bind_layout(&device);
        let tile_layout = tile_bind_layout(&device);
        let count_layout = count_bind_layout(&device);
        let pipelines = render_pipelines(&device, &render_layout, &tile_layout);
        let count_pipeline = count_pipeline(&device, &count_layout);
        let atlas_side = tiles_per_side * resolution;
        let atlas = Atlas {
            ids: attachment(&device, "ids", atlas_side, ID_FORMAT, true),
            depth: attachment(&device, "depth", atlas_side, DEPTH_FORMAT, false),
        };
        // Buffers hold a batch at the smallest side used.
        let smallest = sides(&options).first().copied().unwrap_or(resolution);
        let tiles = ((atlas_side / smallest) as u64).pow(2);
        let entries = tiles * MAX_MEMBERS as u64;
        let views =
            buffer(&device, "views", tiles * size_of::<GpuView>() as u64, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
        let tile_stride = (size_of::<GpuTileView>() as u32).next_multiple_of(device.limits().min_uniform_buffer_offset_alignment);
        let tile_views =
            buffer(&device, "tile views", tiles * tile_stride as u64, wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let tile_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tile view"),
            layout: &tile_layout,
            entries: &[entry(
                0,
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &tile_views,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<GpuTileView>() as u64),
                }),
            )],
        });
        let members = buffer(&device, "members", entries * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
        let counts = buffer(
            &device,
            "counts",
            entries * COUNTS_PER_MEMBER * 4,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let readback = buffer(
            &device,
            "readback",
            entries * COUNTS_PER_MEMBER * 4 * BATCHES_PER_READBACK as u64,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let counter = Self {
            device,
            queue,
            info: adapter.get_info(),
            options,
            atlas_side,
            render_layout,
            count_layout,
            pipelines,
            count_pipeline,
            atlas,
            views,
            tile_views,
            tile_bind,
            tile_stride,
            members,
            counts,
            readback,
            tiles_rendered: AtomicU64::new(0),
            triangles_drawn: AtomicU64::new(0),
            errors,
            lost,
        };
        counter.check_errors("setting up the GPU")?;
        Ok(counter)
    }

    /// The adapter in use (name, backend, device type).
    pub fn adapter_info(&self) -> &wgpu::AdapterInfo {
        &self.info
    }

    /// The options it was made with.
    pub fn options(&self) -> CounterOptions {
        self.options
    }

    /// Tile resolution in pixels.
    pub fn resolution(&self) -> u32 {
        self.options.resolution
    }

    /// Views rendered per submission at `resolution`.
    pub fn tiles_per_batch(&self) -> usize {
        self.tiles_at(self.options.resolution)
    }

    /// Tiles per submission at side `side`.
    fn tiles_at(&self, side: u32) -> usize {
        ((self.atlas_side / side) as usize).pow(2)
    }

    /// Tiles rendered since this counter was made (a tile counts one request, or several of one
    /// view group), and the triangles drawn in them by the scene pass.
    pub fn rendered(&self) -> (u64, u64) {
        (self.tiles_rendered.load(Ordering::Relaxed), self.triangles_drawn.load(Ordering::Relaxed))
    }

    fn check_errors(&self, doing: &str) -> Result<()> {
        self.check_lost()?;
        let mut list = self.errors.lock().map_err(|_| Error::Gpu("error log poisoned".into()))?;
        if list.is_empty() {
            return Ok(());
        }
        let out_of_memory = list.iter().any(|e| e == OUT_OF_MEMORY);
        let all = list.join("; ");
        list.clear();
        if out_of_memory {
            let hint = format!("lower --resolution (now {}) or count fewer triangles (split the model)", self.options.resolution);
            return Err(Error::Gpu(format!("{doing}: out of GPU memory; {hint}")));
        }
        Err(Error::Gpu(format!("{doing}: {all}")))
    }

    /// Refuses, before allocating, a scene whose buffers exceed this device's limits: wgpu would
    /// otherwise fail with a validation error, or the driver run out of memory. The static mesh
    /// (mesh 0) is exempt: it is split over as many buffers as it needs.
    fn check_fits(&self, scene: &Scene) -> Result<()> {
        let limits = self.device.limits();
        let mesh_bytes = |m: &crate::scene::Mesh| (m.positions.len() * size_of::<GpuVertex>()).max(m.indices.len() * 4);
        let vertices = scene.meshes.iter().skip(1).map(mesh_bytes).max().unwrap_or(0) as u64;
        let instances = (scene.instances.len() * size_of::<GpuInstance>()) as u64;
        let (need, limit) = if vertices > limits.max_buffer_size {
            (vertices, limits.max_buffer_size)
        } else if instances > limits.max_storage_buffer_binding_size {
            (instances, limits.max_storage_buffer_binding_size)
        } else {
            return Ok(());
        };
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        Err(Error::Gpu(format!(
            "the scene needs a {:.0} MiB buffer, more than this GPU's {:.0} MiB limit: count fewer triangles or placements (split the model, or leave out far context)",
            mib(need),
            mib(limit)
        )))
    }

    /// [`Error::DeviceLost`] once the device is gone: every later error is a consequence of it.
    fn check_lost(&self) -> Result<()> {
        match self.lost.lock().map(|l| l.clone()) {
            Ok(Some(why)) => Err(Error::DeviceLost(why)),
            _ => Ok(()),
        }
    }

    /// A new counter with the same options on a new device (after [`Error::DeviceLost`]).
    pub async fn recreate(&self) -> Result<Counter> {
        Counter::new(self.options).await
    }

    /// Tests only: a function that destroys this counter's device, as a driver reset would lose
    /// it, from wherever it is called (a progress callback, mid-run).
    #[doc(hidden)]
    pub fn device_loss_trigger(&self) -> impl Fn() + 'static {
        let device = self.device.clone();
        move || device.destroy()
    }

    /// Uploads a scene's geometry once; views of it then cost only draws. The static mesh goes
    /// into as many vertex buffers as the device's buffer size limit needs.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene> {
        let per_triangle = 3 * size_of::<GpuVertex>() as u64;
        let limit = (self.device.limits().max_buffer_size / per_triangle).clamp(1, u32::MAX as u64) as u32;
        self.upload_in_chunks(scene, limit)
    }

    /// [`Self::upload`] with at most `max_triangles` static triangles a vertex buffer (tests
    /// exercise the split with small values).
    pub fn upload_in_chunks(&self, scene: &Scene, max_triangles: u32) -> Result<GpuScene> {
        use wgpu::util::DeviceExt as _;
        // wgpu's create_buffer_init panics on a lost device (its mapped range is invalid).
        self.check_lost()?;
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
        // Slots: instances grouped by mesh and ordered spatially within it, so each BVH node of
        // a mesh's placements is one instance range; the static mesh's triangles likewise.
        let leaf = if self.info.device_type == wgpu::DeviceType::Cpu { CPU_LEAF_TRIANGLES } else { LEAF_TRIANGLES };
        let culling = Culling::new(scene, leaf);
        let order = culling.slot_order().to_vec();
        let mut slot_of = vec![0u32; order.len()];
        for (slot, &i) in order.iter().enumerate() {
            slot_of[i] = slot as u32;
        }
        let static_chunks = self.static_chunks(scene, culling.static_order(), max_triangles.max(1));
        let mut position = vec![0u32; culling.static_order().len()];
        for (p, &t) in culling.static_order().iter().enumerate() {
            position[t as usize] = p as u32;
        }
        let to_scene = DMat4::from_translation(-scene.origin);
        let instances: Vec<GpuInstance> = order
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
        let receivers = scene
            .receivers
            .iter()
            .map(|r| ReceiverView {
                gpu_id: r.gpu_id,
                mesh: scene.instances[r.draw.instance].mesh,
                indices: r.draw.indices.clone(),
                static_triangles: if r.draw.instance == 0 { static_ranges(&position, &r.draw.indices) } else { Vec::new() },
                slot: slot_of[r.draw.instance],
                points: r.triangles.iter().flatten().copied().collect(),
                normal: r.normal,
            })
            .collect();
        let render_bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("render"),
            layout: &self.render_layout,
            entries: &[entry(0, instance_buffer.as_entire_binding()), entry(2, params_buffer.as_entire_binding())],
        });
        let count_bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("count"),
            layout: &self.count_layout,
            entries: &[
                entry(0, wgpu::BindingResource::TextureView(&self.atlas.ids)),
                entry(1, self.views.as_entire_binding()),
                entry(2, params_buffer.as_entire_binding()),
                entry(3, self.counts.as_entire_binding()),
                entry(4, self.members.as_entire_binding()),
            ],
        });
        self.check_errors("uploading the scene")?;
        Ok(GpuScene {
            meshes,
            static_chunks,
            receivers,
            groups: ViewGroups::find(scene),
            bounds: scene.bounds,
            origin: scene.origin,
            culling,
            render_bind,
            count_bind,
        })
    }

    /// Sunlit fractions for many (receiver, sun) pairs; dark views (sun down, facing away) cost
    /// nothing, the others are rendered in batches of atlas tiles. Every leaf is on.
    pub async fn fractions(&self, scene: &GpuScene, requests: &[ViewRequest]) -> Result<Vec<Counted>> {
        self.fractions_with_leaves(scene, requests, &[]).await
    }

    /// As [`Self::fractions`], with `leaves[i]` the leaf fraction (0..=1) for request `i`: the
    /// leaves whose rank is below it cast shadows. An empty `leaves` means every leaf is on.
    pub async fn fractions_with_leaves(&self, scene: &GpuScene, requests: &[ViewRequest], leaves: &[f32]) -> Result<Vec<Counted>> {
        if !leaves.is_empty() && leaves.len() != requests.len() {
            return Err(Error::argument("leaves", format!("{} leaf fractions for {} views", leaves.len(), requests.len())));
        }
        let leaves_of = |i: usize| leaves.get(i).copied().unwrap_or(1.0);
        let mut out = vec![Counted::default(); requests.len()];
        let ladder = sides(&self.options);
        let first = ladder.first().copied().unwrap_or(self.options.resolution);
        let tiles = self.plan_tiles(scene, requests, &leaves_of, first, &mut out)?;
        // Tiles waiting to be counted, by side; each round counts the smallest side waiting.
        let mut waiting: BTreeMap<u32, Vec<Tile>> = BTreeMap::from([(first, tiles)]);
        while let Some((side, tiles)) = waiting.pop_first() {
            self.count_tiles(scene, requests, &leaves_of, &tiles, side, &mut out).await?;
            let Some(target) = self.options.accuracy else { continue };
            for tile in tiles {
                let worst = tile.requests.iter().map(|&i| out[i].error_estimate()).fold(0.0, f64::max);
                if let Some(next) = finer_side(&ladder, side, worst, target) {
                    let view = self.fit_tile(scene, requests, &tile.requests, next);
                    waiting.entry(next).or_default().push(Tile { view, ..tile });
                }
            }
        }
        Ok(out)
    }

    /// Renders and counts `tiles` at side `side` and writes their members' counts into `out`.
    async fn count_tiles(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        leaves_of: &dyn Fn(usize) -> f32,
        tiles: &[Tile],
        side: u32,
        out: &mut [Counted],
    ) -> Result<()> {
        let per_batch = self.tiles_at(side);
        for chunk in tiles.chunks(per_batch * BATCHES_PER_READBACK) {
            // Each batch's counts land in the readback right after the previous batch's.
            let mut entries = 0;
            for batch in chunk.chunks(per_batch) {
                entries += self.submit_batch(scene, requests, leaves_of, batch, side, entries)?;
            }
            let counts = platform::read_buffer(&self.device, &self.readback, entries as u64 * COUNTS_PER_MEMBER * 4).await;
            // A failed read on a lost device is the loss, not a read error.
            self.check_errors("counting pixels")?;
            let counts = counts?;
            let counts: &[u32] = bytemuck::try_cast_slice(&counts).map_err(|e| Error::Gpu(format!("bad readback: {e}")))?;
            let members = chunk.iter().flat_map(|t| t.requests.iter().map(move |&i| (i, t.view.pixel_area)));
            for ((i, pixel_area), c) in members.zip(counts.chunks_exact(COUNTS_PER_MEMBER as usize)) {
                let (visible, covered, edges) = (c[0], c[1], c[2]);
                let o = &mut out[i];
                o.visible = visible;
                o.covered = covered;
                o.edges = edges;
                o.side = side;
                o.pixel_area = pixel_area;
                o.fraction = if covered == 0 { 0.0 } else { (visible as f64 / covered as f64).clamp(0.0, 1.0) };
            }
            let drawn: usize = chunk.iter().map(|t| t.draws.triangles(&scene.culling)).sum();
            self.tiles_rendered.fetch_add(chunk.len() as u64, Ordering::Relaxed);
            self.triangles_drawn.fetch_add(drawn as u64, Ordering::Relaxed);
        }
        Ok(())
    }

    /// The view of a tile's members (the union of their outlines) at side `side`.
    fn fit_tile(&self, scene: &GpuScene, requests: &[ViewRequest], members: &[usize], side: u32) -> SunView {
        let points = tile_points(scene, requests, members);
        view::fit(&points, requests[members[0]].sun, scene.bounds, scene.origin, side)
    }

    /// Sorts the requests into tiles: dark ones get their cosine only, the others join the tile
    /// of their view group, sun and leaf fraction (bitwise: the sampler asks for a wall and its
    /// windows at the very same sun vectors). Each tile's view is fitted to its requested
    /// members; a tile with nothing in front of any member gets fraction 1 without a render.
    fn plan_tiles(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        leaves_of: &dyn Fn(usize) -> f32,
        side: u32,
        out: &mut [Counted],
    ) -> Result<Vec<Tile>> {
        let mut open: HashMap<(u32, [u64; 3], u32), usize> = HashMap::new();
        let mut pending: Vec<Vec<usize>> = Vec::new();
        for (i, req) in requests.iter().enumerate() {
            let r = scene.receivers.get(req.receiver as usize).ok_or_else(|| {
                Error::argument("receiver", format!("id {} out of range ({} receivers)", req.receiver, scene.receivers.len()))
            })?;
            out[i].cos_incidence = cos_incidence(r.normal, req.sun);
            if is_dark(r.normal, req.sun) {
                continue;
            }
            let (group, _) = scene.groups.place(req.receiver);
            let key = (group, req.sun.to_array().map(f64::to_bits), leaves_of(i).to_bits());
            // A receiver asked for twice (or a full tile) opens another tile.
            let joins = |t: &Vec<usize>| t.len() < MAX_MEMBERS && t.iter().all(|&j| requests[j].receiver != req.receiver);
            match open.get(&key) {
                Some(&t) if joins(&pending[t]) => pending[t].push(i),
                _ => {
                    open.insert(key, pending.len());
                    pending.push(vec![i]);
                }
            }
        }
        let mut tiles = Vec::with_capacity(pending.len());
        for mut members in pending {
            // The owner (largest outline) first: its plane and id guide the culling.
            members.sort_by_key(|&i| scene.groups.place(requests[i].receiver).1);
            let owner = &scene.receivers[requests[members[0]].receiver as usize];
            let points = tile_points(scene, requests, &members);
            let sun = requests[members[0]].sun;
            let view = view::fit(&points, sun, scene.bounds, scene.origin, side);
            // The union of the members: the draw list covers every member's prism.
            let target = Target { points: &points, normal: owner.normal, gpu_id: owner.gpu_id };
            match scene.culling.select(&view.view_proj, &target, sun) {
                Some(draws) => tiles.push(Tile { requests: members, view, draws }),
                // Nothing in the prism in front of any member: all fully sunlit, no render needed.
                None => members.iter().for_each(|&i| out[i].fraction = 1.0),
            }
        }
        Ok(tiles)
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

    fn tile_origin(&self, slot: usize, side: u32) -> [u32; 2] {
        let (t, per_row) = (slot as u32, self.atlas_side / side);
        [(t % per_row) * side, (t / per_row) * side]
    }

    /// Renders and counts one batch of tiles; their member counts land in `readback` from entry
    /// `first_entry` on. Returns the number of member entries.
    fn submit_batch(
        &self,
        scene: &GpuScene,
        requests: &[ViewRequest],
        leaves: &dyn Fn(usize) -> f32,
        batch: &[Tile],
        side: u32,
        first_entry: usize,
    ) -> Result<usize> {
        // Each tile twice, for its two readers: where and whom to count (the count pass), and the
        // view to draw it with (the render, a uniform per tile at `tile_stride`).
        let mut members: Vec<u32> = Vec::with_capacity(batch.len());
        let mut views: Vec<GpuView> = Vec::with_capacity(batch.len());
        let stride = self.tile_stride as usize;
        let mut tile_views = vec![0u8; batch.len() * stride];
        for ((slot, tile), at) in batch.iter().enumerate().zip(tile_views.chunks_exact_mut(stride)) {
            let first_member = members.len() as u32;
            members.extend(tile.requests.iter().map(|&i| scene.receivers[requests[i].receiver as usize].gpu_id));
            let tile_origin = self.tile_origin(slot, side);
            views.push(GpuView { tile: tile_origin, first_member, member_count: tile.requests.len() as u32, side, _pad: 0 });
            let view =
                GpuTileView { view_proj: tile.view.view_proj.as_mat4().to_cols_array_2d(), leaves: leaves(tile.requests[0]), _pad: [0; 3] };
            at[..size_of::<GpuTileView>()].copy_from_slice(bytemuck::bytes_of(&view));
        }
        self.queue.write_buffer(&self.views, 0, bytemuck::cast_slice(&views));
        self.queue.write_buffer(&self.tile_views, 0, &tile_views);
        self.queue.write_buffer(&self.members, 0, bytemuck::cast_slice(&members));
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("batch") });
        encoder.clear_buffer(&self.counts, 0, None);
        self.render_tiles(&mut encoder, scene, requests, batch, side);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("count"), timestamp_writes: None });
            pass.set_pipeline(&self.count_pipeline);
            pass.set_bind_group(0, &scene.count_bind, &[]);
            pass.dispatch_workgroups(side.div_ceil(ROWS_PER_GROUP), batch.len() as u32, 1);
        }
        let entry_bytes = COUNTS_PER_MEMBER * 4;
        let bytes = members.len() as u64 * entry_bytes;
        encoder.copy_buffer_to_buffer(&self.counts, 0, &self.readback, first_entry as u64 * entry_bytes, bytes);
        self.queue.submit([encoder.finish()]);
        Ok(members.len())
    }

    fn render_tiles(&self, encoder: &mut wgpu::CommandEncoder, scene: &GpuScene, requests: &[ViewRequest], batch: &[Tile], side: u32) {
        let no_receiver = crate::scene::NO_RECEIVER as f64;
        // Green too starts at NO_RECEIVER: receiver 0 is a valid id there.
        let clear_id = wgpu::Color { r: no_receiver, g: no_receiver, b: 0.0, a: 0.0 };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sun views"),
            color_attachments: &[color(&self.atlas.ids, clear_id)],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.atlas.depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_bind_group(0, &scene.render_bind, &[]);
        for (slot, tile) in batch.iter().enumerate() {
            let [x, y] = self.tile_origin(slot, side);
            pass.set_viewport(x as f32, y as f32, side as f32, side as f32, 0.0, 1.0);
            pass.set_scissor_rect(x, y, side, side);
            pass.set_bind_group(1, &self.tile_bind, &[slot as u32 * self.tile_stride]);
            // The members alone, each writing its id: their coverage, the denominators.
            for &i in &tile.requests {
                let r = &scene.receivers[requests[i].receiver as usize];
                if r.static_triangles.is_empty() {
                    pass.set_pipeline(&self.pipelines.mask);
                    let mesh = &scene.meshes[r.mesh];
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(r.indices.clone(), 0, r.slot..r.slot + 1);
                } else {
                    pass.set_pipeline(&self.pipelines.static_mask);
                    draw_static(&mut pass, &scene.static_chunks, &r.static_triangles, r.slot);
                }
            }
            // What lies in the prisms in front of them, depth-tested: where a member's id
            // survives, it is sunlit.
            let draws = &tile.draws;
            pass.set_pipeline(&self.pipelines.static_scene);
            draw_static(&mut pass, &scene.static_chunks, &draws.static_triangles, scene.culling.static_slot());
            pass.set_pipeline(&self.pipelines.scene);
            let mut bound = None;
            for (m, slots) in &draws.instances {
                let mesh = &scene.meshes[*m];
                if mesh.index_count == 0 {
                    continue;
                }
                if bound != Some(*m) {
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    bound = Some(*m);
                }
                pass.draw_indexed(0..mesh.index_count, 0, slots.clone());
            }
        }
    }

    /// Reads back the red channel of the id atlas: the visible surface ids (for tests comparing
    /// the compute count with a CPU count).
    pub async fn read_ids(&self) -> Result<(u32, Vec<u32>)> {
        let (side, texels) = self.read_atlas().await?;
        Ok((side, texels.iter().map(|t| t[0]).collect()))
    }

    /// Reads back the id atlas: per pixel the visible surface id (red) and the covering member's
    /// id (green, `NO_RECEIVER` where no member covers it).
    pub async fn read_atlas(&self) -> Result<(u32, Vec<[u32; 2]>)> {
        let side = self.atlas_side;
        let bytes_per_row = side * 8;
        let size = (bytes_per_row * side) as u64;
        let target = buffer(&self.device, "ids readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("read ids") });
        let texture = self.atlas.ids.texture();
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &target,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(bytes_per_row), rows_per_image: None },
            },
            texture.size(),
        );
        self.queue.submit([encoder.finish()]);
        let bytes = platform::read_buffer(&self.device, &target, size).await?;
        self.check_errors("reading the id atlas")?;
        let texels: &[[u32; 2]] = bytemuck::try_cast_slice(&bytes).map_err(|e| Error::Gpu(format!("bad readback: {e}")))?;
        Ok((side, texels.to_vec()))
    }

    /// Where tile `slot` of the last batch was drawn (top-left pixel) when its side was `side`.
    /// Tiles follow the order of their first request.
    pub fn tile_of(&self, slot: usize, side: u32) -> [u32; 2] {
        self.tile_origin(slot, side)
    }
}

impl GpuScene {
    /// World origin the GPU coordinates are relative to.
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// The receivers that share a view (a wall and the windows in it).
    pub fn view_groups(&self) -> &ViewGroups {
        &self.groups
    }

    /// The spatial index that picks what each view draws (benchmarks report what it saves).
    pub fn culling(&self) -> &Culling {
        &self.culling
    }
}

/// Counts the count pass writes per member: visible, covered, edge pairs.
const COUNTS_PER_MEMBER: u64 = 3;

/// The sides views are counted at: with an accuracy target, ADAPTIVE_FIRST_SIDE doubling up to
/// `resolution` (which ends the ladder whatever it is); without, `resolution` alone.
fn sides(options: &CounterOptions) -> Vec<u32> {
    let mut ladder = Vec::new();
    if options.accuracy.is_some() {
        let mut side = ADAPTIVE_FIRST_SIDE;
        while side < options.resolution {
            ladder.push(side);
            side *= 2;
        }
    }
    ladder.push(options.resolution);
    ladder
}

/// The side to count a tile again at, or None when its worst member's estimate meets the target
/// or it already had the largest side. The estimate falls about as side^1.5 (edge pixels grow as
/// the side, covered pixels as its square), so the predicted side is side·(worst/target)^(2/3);
/// at least the next step of the ladder, so every round makes progress.
fn finer_side(ladder: &[u32], side: u32, worst: f64, target: f64) -> Option<u32> {
    if worst <= target {
        return None;
    }
    let predicted = side as f64 * (worst / target).powf(2.0 / 3.0);
    let mut finer = ladder.iter().copied().filter(|&s| s > side);
    let next = finer.clone().next()?;
    Some(finer.find(|&s| s as f64 >= predicted).unwrap_or_else(|| ladder.last().copied().unwrap_or(next)).max(next))
}

/// The outline points of a tile's members: the owner's alone, or the union of several.
fn tile_points<'a>(scene: &'a GpuScene, requests: &[ViewRequest], members: &[usize]) -> Cow<'a, [DVec3]> {
    if let [only] = members {
        Cow::Borrowed(&scene.receivers[requests[*only].receiver as usize].points)
    } else {
        Cow::Owned(members.iter().flat_map(|&i| scene.receivers[requests[i].receiver as usize].points.iter().copied()).collect())
    }
}

/// The distinct vertices of a triangle list and its indices into them. The static mesh stores
/// each triangle's corners apart (so receivers' parts can carry their own ids), and models often
/// arrive that way too; on a CPU rasterizer the vertex work is most of a triangle-bound view's
/// cost, and indexed draws let it shade a vertex shared by several triangles once per batch of
/// indices: `nyt-rods` has about one distinct vertex a triangle instead of three, and counts its
/// views ~1.5× faster.
fn distinct_vertices(corners: impl Iterator<Item = GpuVertex>) -> (Vec<GpuVertex>, Vec<u32>) {
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

/// Draws ranges of the static mesh's triangles (culling order), split across its buffers.
fn draw_static(pass: &mut wgpu::RenderPass<'_>, chunks: &[StaticChunk], ranges: &[Range<u32>], slot: u32) {
    let mut bound = None;
    for r in ranges {
        for (c, chunk) in chunks.iter().enumerate() {
            let (a, b) = (r.start.max(chunk.triangles.start), r.end.min(chunk.triangles.end));
            if a >= b {
                continue;
            }
            if bound != Some(c) {
                pass.set_vertex_buffer(0, chunk.vertices.slice(..));
                pass.set_index_buffer(chunk.indices.slice(..), wgpu::IndexFormat::Uint32);
                bound = Some(c);
            }
            let o = chunk.triangles.start;
            pass.draw_indexed(3 * (a - o)..3 * (b - o), 0, slot..slot + 1);
        }
    }
}

/// A static receiver's triangles (an index range of the static mesh) as ranges of positions in
/// the culling's order.
fn static_ranges(position: &[u32], indices: &Range<u32>) -> Vec<Range<u32>> {
    let mut at: Vec<u32> = (indices.start / 3..indices.end / 3).map(|t| position[t as usize]).collect();
    at.sort_unstable();
    let mut ranges: Vec<Range<u32>> = Vec::new();
    for p in at {
        match ranges.last_mut() {
            Some(r) if r.end == p => r.end = p + 1,
            _ => ranges.push(p..p + 1),
        }
    }
    ranges
}

fn color(view: &wgpu::TextureView, clear: wgpu::Color) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
    })
}

/// wgpu refuses zero-sized buffer initialisation in some paths; an empty mesh gets 16 bytes.
fn non_empty(bytes: &[u8]) -> &[u8] {
    if bytes.is_empty() { &[0u8; 16] } else { bytes }
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

fn buffer(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size: size.max(16), usage, mapped_at_creation: false })
}

fn attachment(device: &wgpu::Device, label: &str, side: u32, format: wgpu::TextureFormat, sampled: bool) -> wgpu::TextureView {
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if sampled {
        usage |= wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
    }
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor::default())
}

fn storage_entry(binding: u32, visibility: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    }
}

fn uint_texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

fn render_bind_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let vs = wgpu::ShaderStages::VERTEX;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("render"),
        entries: &[storage_entry(0, vs, true), uniform_entry(2, vs)],
    })
}

/// The tile's view, one uniform at a dynamic offset per tile.
fn tile_bind_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("tile view"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(size_of::<GpuTileView>() as u64),
            },
            count: None,
        }],
    })
}

fn count_bind_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let cs = wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("count"),
        entries: &[
            uint_texture_entry(0),
            storage_entry(1, cs, true),
            uniform_entry(2, cs),
            storage_entry(3, cs, false),
            storage_entry(4, cs, true),
        ],
    })
}

/// The scene pipeline (depth-tested ids) and the mask pipeline (the receiver alone, always
/// passing, no depth write); they differ only in depth state and the channel they write.
/// The sun-view pipelines: scene (depth-tested ids into red) and mask (coverage into green),
/// each for placed meshes (`vs_main`) and for the static mesh (`vs_static`, no instance to read).
struct ViewPipelines {
    scene: wgpu::RenderPipeline,
    mask: wgpu::RenderPipeline,
    static_scene: wgpu::RenderPipeline,
    static_mask: wgpu::RenderPipeline,
}

fn render_pipelines(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, tile_layout: &wgpu::BindGroupLayout) -> ViewPipelines {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("sun_view.wgsl"),
        source: wgpu::ShaderSource::Wgsl(SUN_VIEW_WGSL.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("sun view"),
        bind_group_layouts: &[Some(layout), Some(tile_layout)],
        immediate_size: 0,
    });
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32, 2 => Float32x2, 3 => Uint32];
    let make = |label: &str, vertex: &str, depth_write: bool, compare: wgpu::CompareFunction, channels: wgpu::ColorWrites| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vertex),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: size_of::<GpuVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(depth_write),
                depth_compare: Some(compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState { format: ID_FORMAT, blend: None, write_mask: channels })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let scene = |label, vertex| make(label, vertex, true, wgpu::CompareFunction::Less, wgpu::ColorWrites::RED);
    let mask = |label, vertex| make(label, vertex, false, wgpu::CompareFunction::Always, wgpu::ColorWrites::GREEN);
    ViewPipelines {
        scene: scene("scene", "vs_main"),
        mask: mask("mask", "vs_main"),
        static_scene: scene("scene, static mesh", "vs_static"),
        static_mask: mask("mask, static mesh", "vs_static"),
    }
}

fn count_pipeline(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::ComputePipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("count_pixels.wgsl"),
        source: wgpu::ShaderSource::Wgsl(COUNT_PIXELS_WGSL.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("count"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("count"),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some("count_main"),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// WGSL sources, for validation in tests.
pub const SHADERS: [(&str, &str); 2] = [("sun_view.wgsl", SUN_VIEW_WGSL), ("count_pixels.wgsl", COUNT_PIXELS_WGSL)];

#[cfg(test)]
mod tests {
    use super::*;

    fn options(resolution: u32, accuracy: Option<f64>) -> CounterOptions {
        CounterOptions { resolution, accuracy, ..Default::default() }
    }

    #[test]
    fn sides_double_from_the_first_up_to_the_resolution() {
        assert_eq!(sides(&options(512, None)), [512]);
        assert_eq!(sides(&options(512, Some(0.002))), [64, 128, 256, 512]);
        assert_eq!(sides(&options(300, Some(0.002))), [64, 128, 256, 300]);
        assert_eq!(sides(&options(48, Some(0.002))), [48]);
    }

    #[test]
    fn a_finer_side_is_predicted_from_the_estimate_and_always_progresses() {
        let ladder = sides(&options(512, Some(0.002)));
        assert_eq!(finer_side(&ladder, 64, 0.001, 0.002), None, "within the target");
        assert_eq!(finer_side(&ladder, 64, 0.0021, 0.002), Some(128), "just above: the next step");
        // 64·(0.015/0.002)^(2/3) = 245: the first side at least that.
        assert_eq!(finer_side(&ladder, 64, 0.015, 0.002), Some(256));
        assert_eq!(finer_side(&ladder, 64, f64::INFINITY, 0.002), Some(512), "no pixels: straight to the largest");
        assert_eq!(finer_side(&ladder, 512, 0.1, 0.002), None, "nothing finer");
    }

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

    #[test]
    fn the_error_estimate_falls_with_fewer_edges_and_more_pixels() {
        assert_eq!(error_estimate(0, 0), f64::INFINITY);
        assert_eq!(error_estimate(1000, 0), 0.001, "one pixel of outline");
        assert!(error_estimate(4000, 200) < error_estimate(1000, 100));
    }
}
