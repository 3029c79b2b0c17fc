// Counts, per view tile, the pixels where the target receiver is visible (red = its id) and the
// pixels it covers at all (green = 1). One invocation per tile row keeps a private count
// (cheap on CPU rasterisers); a workgroup tree reduction then does one atomicAdd per workgroup.
// Occlusion queries are not used: WebGPU only promises them as booleans.

const ROWS_PER_GROUP: u32 = 64u;

struct View {
    view_proj: mat4x4<f32>,
    tile: vec2<u32>,
    target_id: u32,
    leaves: f32,
}

struct Params {
    instance_count: u32,
    resolution: u32,
    _pad0: u32,
    _pad1: u32,
}

// Red: visible surface id; green: 1 where the target receiver covers the pixel.
@group(0) @binding(0) var ids: texture_2d<u32>;
@group(0) @binding(1) var<storage, read> views: array<View>;
@group(0) @binding(2) var<uniform> params: Params;
// counts[2 * view] = visible pixels, counts[2 * view + 1] = covered pixels.
@group(0) @binding(3) var<storage, read_write> counts: array<atomic<u32>>;

var<workgroup> visible_part: array<u32, ROWS_PER_GROUP>;
var<workgroup> covered_part: array<u32, ROWS_PER_GROUP>;

@compute @workgroup_size(64)
fn count_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let view_index = group.y;
    let view = views[view_index];
    let row = group.x * ROWS_PER_GROUP + lane;
    var visible = 0u;
    var covered = 0u;
    if row < params.resolution {
        for (var x = 0u; x < params.resolution; x++) {
            let p = vec2<i32>(view.tile + vec2<u32>(x, row));
            let texel = textureLoad(ids, p, 0);
            visible += select(0u, 1u, texel.r == view.target_id);
            covered += texel.g;
        }
    }
    visible_part[lane] = visible;
    covered_part[lane] = covered;
    workgroupBarrier();
    for (var stride = ROWS_PER_GROUP / 2u; stride > 0u; stride >>= 1u) {
        if lane < stride {
            visible_part[lane] += visible_part[lane + stride];
            covered_part[lane] += covered_part[lane + stride];
        }
        workgroupBarrier();
    }
    if lane == 0u {
        atomicAdd(&counts[2u * view_index], visible_part[0]);
        atomicAdd(&counts[2u * view_index + 1u], covered_part[0]);
    }
}
