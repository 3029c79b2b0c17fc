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

// The draw path's form of the pass: each view's kept clusters in cluster order (which is the
// order of the scene's triangles, so a view draws its casters in the order the CPU's culling
// draws them and depth ties resolve alike), one segment of `pairs` a view, and one indirect draw a
// view. Three passes: count what each view keeps (a workgroup a view), lay the segments out and
// write the draws (one invocation), write each view's clusters at its segment (a workgroup a
// view, compacted in order by a prefix sum over the workgroup). A list too small still counts
// every pair it needed (`needed`); views past it get no instances, and the host counts the batch
// again with the CPU's culling.

// wgpu's DrawIndirectArgs.
struct Draw {
    vertex_count: u32,
    instance_count: u32,
    first_vertex: u32,
    first_instance: u32,
}

@group(0) @binding(5) var<storage, read_write> view_kept: array<u32>;
@group(0) @binding(6) var<storage, read_write> heads: array<u32>;
@group(0) @binding(7) var<storage, read_write> draws: array<Draw>;

var<workgroup> kept_total: atomic<u32>;
var<workgroup> scan: array<u32, GROUP>;

@compute @workgroup_size(64)
fn view_count_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let v = group.x;
    var n = 0u;
    for (var c = lane; c < params.clusters; c += GROUP) {
        if touches(views[v], clusters[c]) {
            n += 1u;
        }
    }
    atomicAdd(&kept_total, n);
    workgroupBarrier();
    if lane == 0u {
        view_kept[v] = atomicLoad(&kept_total);
    }
}

@compute @workgroup_size(1)
fn view_layout_main() {
    var at = 0u;
    for (var v = 0u; v < params.views; v += 1u) {
        let n = view_kept[v];
        heads[v] = at;
        // A view whose segment does not fit draws nothing; the host sees `needed` and recounts.
        let fits = at + n <= params.capacity;
        draws[v] = Draw(params.vertices, select(0u, n, fits), 0u, 0u);
        at += n;
    }
    atomicStore(&args.needed, at);
    // The batch draw (src/count/gpu/batched.rs): every pair an instance, none where the list
    // overflowed (the host counts that batch again).
    args.vertex_count = params.vertices;
    args.instance_count = select(0u, at, at <= params.capacity);
    args.first_vertex = 0u;
    args.first_instance = 0u;
}

@compute @workgroup_size(64)
fn view_write_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let v = group.x;
    var base = heads[v];
    for (var start = 0u; start < params.clusters; start += GROUP) {
        let c = start + lane;
        var keep = 0u;
        if c < params.clusters && touches(views[v], clusters[c]) {
            keep = 1u;
        }
        // Inclusive prefix sum of `keep` over the workgroup (Hillis-Steele).
        scan[lane] = keep;
        workgroupBarrier();
        for (var d = 1u; d < GROUP; d *= 2u) {
            var add = 0u;
            if lane >= d {
                add = scan[lane - d];
            }
            workgroupBarrier();
            scan[lane] += add;
            workgroupBarrier();
        }
        let at = base + scan[lane] - keep;
        if keep == 1u && at < params.capacity {
            pairs[at] = vec2<u32>(v, c);
        }
        base += scan[GROUP - 1u];
        workgroupBarrier();
    }
}
