// Point masks: per map point and view, is the sun seen? Reads the same id atlas the count pass
// reads (count_pixels.wgsl), after the same render: red = the id of the surface the sun sees at
// the texel (depth-tested), green = the id of the tile member covering it (the mask pass).
//
// A view's points (all on one receiver, a member of the tile) are projected with the tile's own
// view-projection into the tile; a point is lit when the red id at its texel is its receiver's
// id. The texel is the one whose centre is nearest the point, the sample the rasteriser took
// there. Near the receiver's outline that texel may belong to another member or to nothing
// (green is not the receiver's id): the first of its 8 neighbours that the receiver covers
// answers instead, and a point with none is shaded.
//
// One invocation writes one 32-bit word of a view's mask: bit b of word w is point 32·w + b of
// the view, so no two invocations write the same word and no atomics or clearing are needed.
// Occlusion queries are not used: WebGPU only promises them as booleans per draw, not per point.

// One view's points, as the pass reads it (GpuMaskView in the library).
struct MaskView {
    // Scene coordinates relative to the scene origin → clip space: the tile's own camera.
    view_proj: mat4x4<f32>,
    // Top-left pixel of the tile in the atlas, and its side in pixels.
    tile: vec2<u32>,
    side: u32,
    // The id the receiver's pixels carry (scene::Receiver::gpu_id).
    id: u32,
    // The view's points: points[first_point ..][.. point_count]; its mask:
    // masks[first_word ..][.. ceil(point_count / 32)].
    first_point: u32,
    point_count: u32,
    first_word: u32,
    _pad0: u32,
}

@group(0) @binding(0) var ids: texture_2d<u32>;
@group(0) @binding(1) var<storage, read> views: array<MaskView>;
// Points relative to the scene origin (w unused), grouped by receiver.
@group(0) @binding(2) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> masks: array<u32>;

// Workgroups along x share a view's words (strided), one row of workgroups per view.
const WORDS_PER_GROUP: u32 = 64u;

@compute @workgroup_size(64)
fn mask_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32,
             @builtin(num_workgroups) groups: vec3<u32>) {
    let view = views[group.y];
    let words = (view.point_count + 31u) / 32u;
    let stride = groups.x * WORDS_PER_GROUP;
    for (var w = group.x * WORDS_PER_GROUP + lane; w < words; w += stride) {
        var bits = 0u;
        let first = 32u * w;
        let last = min(first + 32u, view.point_count);
        for (var p = first; p < last; p++) {
            if lit(view, points[view.first_point + p].xyz) {
                bits |= 1u << (p - first);
            }
        }
        masks[view.first_word + w] = bits;
    }
}

// The texel (atlas coordinates) whose centre is nearest `position` in `view`'s tile: clip x, y
// in [−1, 1] map to the tile's pixels, y downwards, as the viewport maps them.
fn texel_of(view: MaskView, position: vec3<f32>) -> vec2<i32> {
    let clip = view.view_proj * vec4<f32>(position, 1.0);
    let ndc = clip.xy / clip.w;
    let side = f32(view.side);
    let pixel = vec2<f32>((ndc.x * 0.5 + 0.5) * side, (0.5 - ndc.y * 0.5) * side);
    let inside = clamp(floor(pixel), vec2<f32>(0.0), vec2<f32>(side - 1.0));
    return vec2<i32>(view.tile) + vec2<i32>(inside);
}

fn lit(view: MaskView, position: vec3<f32>) -> bool {
    let at = texel_of(view, position);
    let texel = textureLoad(ids, at, 0).rg;
    if texel.g == view.id {
        return texel.r == view.id;
    }
    // Off the receiver's raster: the first neighbour on it answers (row by row, top left first).
    let lo = vec2<i32>(view.tile);
    let hi = lo + vec2<i32>(i32(view.side) - 1);
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = at + vec2<i32>(dx, dy);
            if (dx == 0 && dy == 0) || any(q < lo) || any(q > hi) {
                continue;
            }
            let n = textureLoad(ids, q, 0).rg;
            if n.g == view.id {
                return n.r == view.id;
            }
        }
    }
    return false;
}
