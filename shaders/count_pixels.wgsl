// Counts, per view tile and per receiver of the tile (its members: a wall and the windows in
// it, or one receiver), the pixels where the receiver is visible (red = its id), the pixels it
// covers at all (green = its id, from the mask pass; members never overlap), and, when asked,
// its shadow-edge pixel pairs: right or lower neighbours both covered by the member, one visible
// and one not. The edges measure how much of the count is boundary, where rasterisation errs,
// and so pick the views worth counting again at a finer side. One invocation per tile row keeps
// private counts (cheap on CPU rasterisers); a workgroup tree reduction then does one atomicAdd
// per member and count per workgroup.
// Occlusion queries are not used: WebGPU only promises them as booleans.

const ROWS_PER_GROUP: u32 = 64u;
// The most members a tile counts (the library's group::MAX_MEMBERS).
const MAX_MEMBERS: u32 = 4u;
// A texel no member covers (the library's scene::NO_RECEIVER).
const NONE: u32 = 0xffffffffu;

// A tile as the count reads it (its view, for the render, is sun_view.wgsl's TileView).
struct View {
    // Top-left pixel of the tile in the atlas.
    tile: vec2<u32>,
    // The tile's receivers: members[first_member ..][.. member_count]; their counts go to the
    // same indices of counts.
    first_member: u32,
    member_count: u32,
    // The tile's side in pixels (tiles of one batch share it).
    side: u32,
    _pad0: u32,
}

struct Params {
    // Non-zero: count shadow-edge pairs too (adaptive resolution); zero skips their loads.
    count_edges: u32,
    // Read by the render pass only.
    static_slot: u32,
    _pad0: u32,
    _pad1: u32,
}

// Red: visible surface id; green: the id of the member covering the pixel (NO_RECEIVER if none).
@group(0) @binding(0) var ids: texture_2d<u32>;
@group(0) @binding(1) var<storage, read> views: array<View>;
@group(0) @binding(2) var<uniform> params: Params;
// counts[3 * m] = visible pixels, counts[3 * m + 1] = covered pixels, counts[3 * m + 2] = edge
// pairs of member entry m.
@group(0) @binding(3) var<storage, read_write> counts: array<atomic<u32>>;
// Receiver ids of every tile's members, tile after tile.
@group(0) @binding(4) var<storage, read> members: array<u32>;

// Member k's partial count of lane l at k * ROWS_PER_GROUP + l.
var<workgroup> visible_part: array<u32, 256>;
var<workgroup> covered_part: array<u32, 256>;
var<workgroup> edge_part: array<u32, 256>;

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
    var edges: array<u32, MAX_MEMBERS>;
    let side = view.side;
    let row = group.x * ROWS_PER_GROUP + lane;
    if row < side {
        let below = row + 1u < side && params.count_edges != 0u;
        var left = vec2<u32>(NONE, NONE);
        for (var x = 0u; x < side; x++) {
            let p = vec2<i32>(view.tile + vec2<u32>(x, row));
            let texel = textureLoad(ids, p, 0).rg;
            var under = vec2<u32>(NONE, NONE);
            if below {
                under = textureLoad(ids, p + vec2<i32>(0, 1), 0).rg;
            }
            for (var k = 0u; k < n; k++) {
                visible[k] += select(0u, 1u, texel.r == id[k]);
                covered[k] += select(0u, 1u, texel.g == id[k]);
            }
            if params.count_edges != 0u {
                for (var k = 0u; k < n; k++) {
                    edges[k] += edge(texel, left, id[k]) + edge(texel, under, id[k]);
                }
                left = texel;
            }
        }
    }
    for (var k = 0u; k < MAX_MEMBERS; k++) {
        visible_part[k * ROWS_PER_GROUP + lane] = visible[k];
        covered_part[k * ROWS_PER_GROUP + lane] = covered[k];
        edge_part[k * ROWS_PER_GROUP + lane] = edges[k];
    }
    workgroupBarrier();
    for (var stride = ROWS_PER_GROUP / 2u; stride > 0u; stride >>= 1u) {
        if lane < stride {
            for (var k = 0u; k < n; k++) {
                let at = k * ROWS_PER_GROUP + lane;
                visible_part[at] += visible_part[at + stride];
                covered_part[at] += covered_part[at + stride];
                edge_part[at] += edge_part[at + stride];
            }
        }
        workgroupBarrier();
    }
    // Lane k adds member k's workgroup totals.
    if lane < n {
        let m = view.first_member + lane;
        atomicAdd(&counts[3u * m], visible_part[lane * ROWS_PER_GROUP]);
        atomicAdd(&counts[3u * m + 1u], covered_part[lane * ROWS_PER_GROUP]);
        atomicAdd(&counts[3u * m + 2u], edge_part[lane * ROWS_PER_GROUP]);
    }
}

// 1 where two neighbouring texels both lie on the member and exactly one of them is visible.
fn edge(a: vec2<u32>, b: vec2<u32>, id: u32) -> u32 {
    let both = a.g == id && b.g == id;
    return select(0u, 1u, both && ((a.r == id) != (b.r == id)));
}
