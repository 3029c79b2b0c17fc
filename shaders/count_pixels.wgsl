// Counts, per view tile and per receiver of the tile (its members: a wall and the windows in
// it, or one receiver), the pixels where the receiver is visible (red = its id) and the pixels
// it covers at all (green = its id, from the mask pass; members never overlap). One invocation
// per tile row keeps private counts (cheap on CPU rasterisers); a workgroup tree reduction then
// does one atomicAdd per member per workgroup.
// Occlusion queries are not used: WebGPU only promises them as booleans.

const ROWS_PER_GROUP: u32 = 64u;
// The most members a tile counts (the library's group::MAX_MEMBERS).
const MAX_MEMBERS: u32 = 4u;

struct View {
    view_proj: mat4x4<f32>,
    tile: vec2<u32>,
    // The tile's receivers: members[first_member ..][.. member_count]; their counts go to the
    // same indices of counts.
    first_member: u32,
    member_count: u32,
    leaves: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct Params {
    instance_count: u32,
    resolution: u32,
    _pad0: u32,
    _pad1: u32,
}

// Red: visible surface id; green: the id of the member covering the pixel (NO_RECEIVER if none).
@group(0) @binding(0) var ids: texture_2d<u32>;
@group(0) @binding(1) var<storage, read> views: array<View>;
@group(0) @binding(2) var<uniform> params: Params;
// counts[2 * m] = visible pixels, counts[2 * m + 1] = covered pixels of member entry m.
@group(0) @binding(3) var<storage, read_write> counts: array<atomic<u32>>;
// Receiver ids of every tile's members, tile after tile.
@group(0) @binding(4) var<storage, read> members: array<u32>;

// Member k's partial count of lane l at k * ROWS_PER_GROUP + l.
var<workgroup> visible_part: array<u32, 256>;
var<workgroup> covered_part: array<u32, 256>;

@compute @workgroup_size(64)
fn count_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let view = views[group.y];
    let n = min(view.member_count, MAX_MEMBERS);
    var id: array<u32, MAX_MEMBERS>;
    for (var k = 0u; k < n; k++) {
        id[k] = members[view.first_member + k];
    }
    var visible: array<u32, MAX_MEMBERS>;
    var covered: array<u32, MAX_MEMBERS>;
    let row = group.x * ROWS_PER_GROUP + lane;
    if row < params.resolution {
        for (var x = 0u; x < params.resolution; x++) {
            let p = vec2<i32>(view.tile + vec2<u32>(x, row));
            let texel = textureLoad(ids, p, 0);
            for (var k = 0u; k < n; k++) {
                visible[k] += select(0u, 1u, texel.r == id[k]);
                covered[k] += select(0u, 1u, texel.g == id[k]);
            }
        }
    }
    for (var k = 0u; k < MAX_MEMBERS; k++) {
        visible_part[k * ROWS_PER_GROUP + lane] = visible[k];
        covered_part[k * ROWS_PER_GROUP + lane] = covered[k];
    }
    workgroupBarrier();
    for (var stride = ROWS_PER_GROUP / 2u; stride > 0u; stride >>= 1u) {
        if lane < stride {
            for (var k = 0u; k < n; k++) {
                let at = k * ROWS_PER_GROUP + lane;
                visible_part[at] += visible_part[at + stride];
                covered_part[at] += covered_part[at + stride];
            }
        }
        workgroupBarrier();
    }
    // Lane k adds member k's workgroup total.
    if lane < n {
        let m = view.first_member + lane;
        atomicAdd(&counts[2u * m], visible_part[lane * ROWS_PER_GROUP]);
        atomicAdd(&counts[2u * m + 1u], covered_part[lane * ROWS_PER_GROUP]);
    }
}
