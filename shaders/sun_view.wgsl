// Sun-view render: draws the scene into an atlas tile with an orthographic camera that looks
// along the sun's rays, writing each fragment's receiver id (or NO_RECEIVER) to the red channel
// of an rg32uint target. The mask pipeline draws the target receiver alone (no depth test) into
// the green channel: its coverage, the denominator of the sunlit fraction.
//
// Instances: a draw covers instance_index = view * instance_count + instance, so one
// draw_indexed per mesh renders every placement of it for one view.

const NO_RECEIVER: u32 = 0xffffffffu;

struct Instance {
    // Mesh coordinates → scene coordinates relative to the scene origin.
    transform: mat4x4<f32>,
    // Added to the per-vertex surface value; NO_RECEIVER for shadow-only placements.
    receiver_base: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct View {
    view_proj: mat4x4<f32>,
    // Top-left pixel of the view's tile in the atlas.
    tile: vec2<u32>,
    // The receiver whose pixels this view counts.
    target_id: u32,
    _pad: u32,
}

struct Params {
    instance_count: u32,
    resolution: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> instances: array<Instance>;
@group(0) @binding(1) var<storage, read> views: array<View>;
@group(0) @binding(2) var<uniform> params: Params;

struct VertexOut {
    // Invariant: the mask pass and the scene pass must rasterise a receiver identically.
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) surface: u32, @builtin(instance_index) instance_index: u32) -> VertexOut {
    let view = views[instance_index / params.instance_count];
    let instance = instances[instance_index % params.instance_count];
    var out: VertexOut;
    out.position = view.view_proj * (instance.transform * vec4<f32>(position, 1.0));
    if surface == NO_RECEIVER || instance.receiver_base == NO_RECEIVER {
        out.id = NO_RECEIVER;
    } else {
        out.id = instance.receiver_base + surface;
    }
    return out;
}

// Both pipelines share this: the scene pipeline writes only red, the mask pipeline only green.
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec2<u32> {
    return vec2<u32>(in.id, 1u);
}
