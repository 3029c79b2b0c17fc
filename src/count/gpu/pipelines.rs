//! The GPU programs and their interfaces: the WGSL sources (`shaders/`), the layouts of what
//! they read (vertices, instances, per-tile views, counts), the bind group layouts and the
//! render and compute pipelines. Nothing here touches a scene or a view: only shapes.
//!
//! The `Gpu*` structs mirror the shaders' structs byte for byte (`#[repr(C)]`, `Pod`); a field
//! changed here must change in the WGSL too (tests/shaders.rs validates the WGSL on its own).

pub(super) const SUN_VIEW_WGSL: &str = include_str!("../../../shaders/sun_view.wgsl");
pub(super) const COUNT_PIXELS_WGSL: &str = include_str!("../../../shaders/count_pixels.wgsl");
pub(super) const POINT_MASKS_WGSL: &str = include_str!("../../../shaders/point_masks.wgsl");
/// Mask words per compute workgroup (the shader's `WORDS_PER_GROUP`).
pub(super) const WORDS_PER_MASK_GROUP: u32 = 64;
/// Rows of a tile per compute workgroup (the shader's `ROWS_PER_GROUP`).
pub(super) const ROWS_PER_GROUP: u32 = 64;
/// One target, two channels: red = the visible surface's id (scene pass), green = the target
/// receiver's own coverage (mask pass). Per-channel write masks keep the passes apart, and the
/// count reads one texel per pixel.
pub(super) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
pub(super) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Counts the count pass writes per member: visible, covered, edge pairs.
pub(super) const COUNTS_PER_MEMBER: u64 = 3;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuInstance {
    pub(super) transform: [[f32; 4]; 4],
    pub(super) receiver_base: u32,
    pub(super) leaf_shift: f32,
    pub(super) _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuView {
    pub(super) tile: [u32; 2],
    pub(super) first_member: u32,
    pub(super) member_count: u32,
    pub(super) side: u32,
    pub(super) _pad: u32,
}

/// A tile's view as the vertex shaders read it (`TileView` in sun_view.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuTileView {
    pub(super) view_proj: [[f32; 4]; 4],
    pub(super) leaves: f32,
    /// The tile's place in its batch: which of the GPU culling's per-view lists it draws.
    pub(super) slot: u32,
    /// Subpixels across half the tile ([`subpixels_per_half_tile`]): clip x and y are snapped
    /// to 1/256 pixel of the tile before the viewport places it.
    pub(super) snap: f32,
    pub(super) _pad: u32,
}

/// What `shade` in sun_view.wgsl snaps clip x and y by at tile side `side`: 1/256 pixel, the
/// finest subpixel step a rasterizer keeps (8 bits; lavapipe and desktop GPUs). A corner snapped
/// so is a whole number of subpixels from the tile's centre, so the viewport's scale and offset
/// (a whole pixel) add nothing to round: the same triangle gives the same pixels in every atlas
/// slot. Unsnapped, the offset's rounding grows with the slot's distance from the atlas's
/// corner, and a corner near a subpixel's edge snapped one way in one slot and the other way in
/// another: counts then depended on which tiles shared a batch (the GPU's culling renders tiles
/// the CPU's skips, and lanes split a run differently).
pub(super) fn subpixels_per_half_tile(side: u32) -> f32 {
    side as f32 * 128.0
}

/// One view's map points as the mask pass reads them (`MaskView` in point_masks.wgsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuMaskView {
    pub(super) view_proj: [[f32; 4]; 4],
    pub(super) tile: [u32; 2],
    pub(super) side: u32,
    pub(super) id: u32,
    pub(super) first_point: u32,
    pub(super) point_count: u32,
    pub(super) first_word: u32,
    pub(super) _pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuParams {
    pub(super) count_edges: u32,
    pub(super) static_slot: u32,
    pub(super) _pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct GpuVertex {
    pub(super) position: [f32; 3],
    pub(super) surface: u32,
    /// Leaf rank (negative: not a leaf) and transmittance.
    pub(super) veil: [f32; 2],
    pub(super) seed: u32,
}

/// Every layout and pipeline a counter uses, made once per device.
pub(super) struct Pipelines {
    /// Instances and parameters, for the vertex shaders.
    pub(super) render_layout: wgpu::BindGroupLayout,
    /// The tile's view, at a dynamic offset per tile.
    pub(super) tile_layout: wgpu::BindGroupLayout,
    /// The id atlas, tile views, parameters, counts and members, for the count pass.
    pub(super) count_layout: wgpu::BindGroupLayout,
    /// The id atlas, mask views, map points and masks, for the mask pass.
    pub(super) mask_layout: wgpu::BindGroupLayout,
    pub(super) view: ViewPipelines,
    pub(super) count: wgpu::ComputePipeline,
    pub(super) mask: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let render_layout = render_bind_layout(device);
        let tile_layout = tile_bind_layout(device);
        let count_layout = count_bind_layout(device);
        let mask_layout = mask_bind_layout(device);
        let view = render_pipelines(device, &render_layout, &tile_layout);
        let count = compute_pipeline(device, &count_layout, "count_pixels.wgsl", COUNT_PIXELS_WGSL, "count_main");
        let mask = compute_pipeline(device, &mask_layout, "point_masks.wgsl", POINT_MASKS_WGSL, "mask_main");
        Self { render_layout, tile_layout, count_layout, mask_layout, view, count, mask }
    }
}

/// The sun-view pipelines: scene (depth-tested ids into red) and mask (coverage into green),
/// each for placed meshes (`vs_main`) and for the static mesh (`vs_static`, no instance to read).
/// Scene and mask differ only in depth state (the mask always passes and writes no depth) and
/// the channel they write.
pub(super) struct ViewPipelines {
    pub(super) scene: wgpu::RenderPipeline,
    pub(super) mask: wgpu::RenderPipeline,
    pub(super) static_scene: wgpu::RenderPipeline,
    pub(super) static_mask: wgpu::RenderPipeline,
}

fn render_pipelines(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, tile_layout: &wgpu::BindGroupLayout) -> ViewPipelines {
    let module = sun_view_module(device);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("sun view"),
        bind_group_layouts: &[Some(layout), Some(tile_layout)],
        immediate_size: 0,
    });
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32, 2 => Float32x2, 3 => Uint32];
    let vertices = [Some(wgpu::VertexBufferLayout {
        array_stride: size_of::<GpuVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &attributes,
    })];
    let make = |label: &str, vertex: &str, depth_write: bool, compare: wgpu::CompareFunction, channels: wgpu::ColorWrites| {
        view_pipeline(device, &module, &pipeline_layout, (label, vertex, &vertices), depth_write, compare, channels)
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

fn sun_view_module(device: &wgpu::Device) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("sun_view.wgsl"),
        source: wgpu::ShaderSource::Wgsl(SUN_VIEW_WGSL.into()),
    })
}

/// The scene pipeline that draws what the GPU's culling kept (`vs_pulled`: no vertex buffer,
/// corners pulled from `pulled_layout`'s storage); otherwise as the scene pipeline.
pub(super) fn pulled_scene_pipeline(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    pulled_layout: &wgpu::BindGroupLayout,
) -> wgpu::RenderPipeline {
    let module = sun_view_module(device);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("sun view, pulled"),
        bind_group_layouts: &[Some(&pipelines.render_layout), Some(&pipelines.tile_layout), Some(pulled_layout)],
        immediate_size: 0,
    });
    let entry = ("scene, GPU-culled", "vs_pulled", &[][..]);
    view_pipeline(device, &module, &pipeline_layout, entry, true, wgpu::CompareFunction::Less, wgpu::ColorWrites::RED)
}

/// A pipeline of the batch draw ([`super::batched`]): `vertex` with groups 1 and 2 of `layouts`,
/// the scene's depth state and channel where `scene`, else the mask's; fragments clipped to their
/// tile by `fs_tiled`.
pub(super) fn batch_view_pipeline(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    layouts: [&wgpu::BindGroupLayout; 2],
    vertex: &str,
    scene: bool,
) -> wgpu::RenderPipeline {
    let module = sun_view_module(device);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(vertex),
        bind_group_layouts: &[Some(&pipelines.render_layout), Some(layouts[0]), Some(layouts[1])],
        immediate_size: 0,
    });
    let (compare, channels) = if scene {
        (wgpu::CompareFunction::Less, wgpu::ColorWrites::RED)
    } else {
        (wgpu::CompareFunction::Always, wgpu::ColorWrites::GREEN)
    };
    let entry = ((vertex, vertex, &[][..]), "fs_tiled");
    tiled_view_pipeline(device, &module, &pipeline_layout, entry, scene, compare, channels)
}

/// A sun-view pipeline: `(label, vertex entry point, vertex buffers)`, its depth state and the
/// channel it writes.
fn view_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    pipeline_layout: &wgpu::PipelineLayout,
    entry: (&str, &str, &[Option<wgpu::VertexBufferLayout<'_>>]),
    depth_write: bool,
    compare: wgpu::CompareFunction,
    channels: wgpu::ColorWrites,
) -> wgpu::RenderPipeline {
    tiled_view_pipeline(device, module, pipeline_layout, (entry, "fs_main"), depth_write, compare, channels)
}

/// [`view_pipeline`] with the fragment entry point named.
fn tiled_view_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    pipeline_layout: &wgpu::PipelineLayout,
    ((label, vertex, buffers), fragment): ((&str, &str, &[Option<wgpu::VertexBufferLayout<'_>>]), &str),
    depth_write: bool,
    compare: wgpu::CompareFunction,
    channels: wgpu::ColorWrites,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(pipeline_layout),
        vertex: wgpu::VertexState { module, entry_point: Some(vertex), compilation_options: Default::default(), buffers },
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
            module,
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState { format: ID_FORMAT, blend: None, write_mask: channels })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

pub(super) fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    source: &str,
    entry: &str,
) -> wgpu::ComputePipeline {
    let module =
        device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(source.into()) });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
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

fn mask_bind_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let cs = wgpu::ShaderStages::COMPUTE;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("masks"),
        entries: &[uint_texture_entry(0), storage_entry(1, cs, true), storage_entry(2, cs, true), storage_entry(3, cs, false)],
    })
}

pub(super) fn storage_entry(binding: u32, visibility: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
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

pub(super) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
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

pub(super) fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

pub(super) fn buffer(device: &wgpu::Device, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size: size.max(16), usage, mapped_at_creation: false })
}

pub(super) fn attachment(device: &wgpu::Device, label: &str, side: u32, format: wgpu::TextureFormat, sampled: bool) -> wgpu::TextureView {
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

/// WGSL sources, for validation in tests.
pub const SHADERS: [(&str, &str); 6] = [
    ("sun_view.wgsl", SUN_VIEW_WGSL),
    ("count_pixels.wgsl", COUNT_PIXELS_WGSL),
    ("point_masks.wgsl", POINT_MASKS_WGSL),
    ("compute_raster.wgsl", super::compute::COMPUTE_RASTER_WGSL),
    ("cull_clusters.wgsl", super::cluster_cull::CULL_CLUSTERS_WGSL),
    ("may_shade.wgsl", super::shade::MAY_SHADE_WGSL),
];
