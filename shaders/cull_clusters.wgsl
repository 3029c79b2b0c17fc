// Culling on the GPU: every (view, cluster) pair of a batch tested at once. A cluster is a run of
// at most 128 of the scene's triangles with its box (src/count/cull.rs, Culling::clusters); a view
// is the first three rows of its orthographic clip transform. A cluster is kept where its box may
// reach into the view's clip volume (x, y in [-1, 1], depth in [0, 1], plus CLIP_SLACK), the test
// Culling::select makes on the CPU for BVH nodes. Kept pairs are compacted into one list by one
// atomicAdd each, and `finish_main` writes the indirect draw that makes each pair one instance.
// A list too small still counts every pair it needed (`needed`) and stores only what fits; the
// host reads `needed` and runs the batch again with a list that large: never truncated.

struct Cluster {
    lo: vec3<f32>,
    first: u32,
    hi: vec3<f32>,
    count: u32,
}

// Rows x, y and z of the view's clip transform (scene coordinates relative to the origin).
struct ClipRows {
    x: vec4<f32>,
    y: vec4<f32>,
    z: vec4<f32>,
}

struct Params {
    views: u32,
    clusters: u32,
    capacity: u32,
    // Vertices an instance draws: three for each triangle a cluster may hold.
    vertices: u32,
}

// The indirect draw (wgpu's DrawIndirectArgs) and, after it, the pairs the batch needed.
struct Args {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
    needed: atomic<u32>,
}

const CLIP_SLACK: f32 = 1e-4;
const GROUP: u32 = 64u;

@group(0) @binding(0) var<storage, read> clusters: array<Cluster>;
@group(0) @binding(1) var<storage, read> views: array<ClipRows>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read_write> pairs: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> args: Args;

// The interval a clip row spans over a box (the view is affine: centre ± |row|·half extent).
fn span(row: vec4<f32>, centre: vec3<f32>, half: vec3<f32>) -> vec2<f32> {
    let c = dot(row.xyz, centre) + row.w;
    let r = dot(abs(row.xyz), half);
    return vec2<f32>(c - r, c + r);
}

fn touches(view: ClipRows, cluster: Cluster) -> bool {
    let centre = 0.5 * (cluster.lo + cluster.hi);
    let half = 0.5 * (cluster.hi - cluster.lo);
    let x = span(view.x, centre, half);
    let y = span(view.y, centre, half);
    let z = span(view.z, centre, half);
    let s = CLIP_SLACK;
    return x.x <= 1.0 + s && x.y >= -1.0 - s && y.x <= 1.0 + s && y.y >= -1.0 - s && z.x <= 1.0 + s && z.y >= -s;
}

// One invocation a (cluster, view): x over clusters (rows of workgroups where they pass one
// dimension's limit), y over views.
@compute @workgroup_size(64)
fn cull_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let c = (group.x + group.z * groups.x) * GROUP + lane;
    let v = group.y;
    if c >= params.clusters || v >= params.views {
        return;
    }
    if !touches(views[v], clusters[c]) {
        return;
    }
    let at = atomicAdd(&args.needed, 1u);
    if at < params.capacity {
        pairs[at] = vec2<u32>(v, c);
    }
}

// One invocation: the indirect draw over the pairs stored.
@compute @workgroup_size(1)
fn finish_main() {
    args.vertex_count = params.vertices;
    args.instance_count = min(atomicLoad(&args.needed), params.capacity);
    args.first_vertex = 0u;
    args.first_instance = 0u;
}
