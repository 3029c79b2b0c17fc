// The CPU culling's shading test (Culling::may_be_shaded, src/count/cull.rs) on the GPU: per
// view, can anything the view draws shade its receiver? A view that nothing can shade gets
// fraction 1 without its render's count (a rendered view at a grazing sun can lose an edge pixel
// to a neighbour), so the counts stay the CPU path's exactly.
//
// The CPU decides in f64 on the scene's f32 corners (relative to the origin); this pass reads the
// same f32 corners and ids, but computes in f32. So it answers in three ways, each with an error
// bound on every f32 quantity:
// - NOTHING: every triangle in a cluster that may reach the view certainly cannot shade (the
//   CPU's test is certainly false);
// - SHADED: a triangle whose own box certainly reaches into the clip volume (so its BVH leaf's
//   box does) certainly can (the CPU's test is certainly true);
// - UNDECIDED: neither is certain; the host runs the CPU's test for that view.
//
// A workgroup a view; each lane takes a cluster (its box: the BVH node it was cut from, which
// holds every leaf box its triangles belong to) and, where that box may reach into the clip
// volume, each of its triangles. The workgroup stops at the first SHADED.

struct Cluster {
    lo: vec3<f32>,
    first: u32,
    hi: vec3<f32>,
    count: u32,
}

// ShadeTest (cull.rs) in f32: the clip rows, the receiver's plane (p0, normal), its axes (u, v)
// and box (lo, hi) in them, the sun, along = normal · sun, eps, the receiver's own id, and
// `box_size`, the largest |lo|, |hi| component (for the error bound).
struct ShadeView {
    x: vec4<f32>,
    y: vec4<f32>,
    z: vec4<f32>,
    p0: vec3<f32>,
    own: u32,
    normal: vec3<f32>,
    along: f32,
    u: vec3<f32>,
    eps: f32,
    v: vec3<f32>,
    box_size: f32,
    sun: vec3<f32>,
    _pad: u32,
    lo: vec2<f32>,
    hi: vec2<f32>,
}

struct Params {
    views: u32,
    clusters: u32,
    _pad0: u32,
    _pad1: u32,
}

const NOTHING: u32 = 0u;
const UNDECIDED: u32 = 1u;
const SHADED: u32 = 2u;
const NO_RECEIVER: u32 = 0xffffffffu;
const GROUP: u32 = 64u;
// The CPU culling's CLIP_SLACK.
const CLIP_SLACK: f32 = 1e-4;
// f32's unit roundoff: WGSL's f32 +, -, * are correctly rounded, / within 2.5 ulp.
const U: f32 = 5.9604645e-8;
// Error bounds, in U times the magnitudes involved, at least twice what the roundings add up to
// (derivation in src/count/gpu/shade.rs); they only widen UNDECIDED.
const K_CLIP: f32 = 32.0;
// Below this, along's division magnifies every error past use: the host decides.
const MIN_ALONG: f32 = 1e-3;

@group(0) @binding(0) var<storage, read> clusters: array<Cluster>;
// Nine floats a triangle (three corners), in the culling's triangle order.
@group(0) @binding(1) var<storage, read> corners: array<f32>;
@group(0) @binding(2) var<storage, read> ids: array<u32>;
@group(0) @binding(3) var<storage, read> views: array<ShadeView>;
@group(0) @binding(4) var<uniform> params: Params;
@group(0) @binding(5) var<storage, read_write> verdicts: array<u32>;

var<workgroup> verdict: atomic<u32>;
var<workgroup> settled: u32;

fn max_abs(p: vec3<f32>) -> f32 {
    let a = abs(p);
    return max(a.x, max(a.y, a.z));
}

// A clip row's interval over a box (centre ± |row|·half) and the error bound of its ends.
fn span(row: vec4<f32>, centre: vec3<f32>, half: vec3<f32>) -> vec3<f32> {
    let c = dot(row.xyz, centre) + row.w;
    let r = dot(abs(row.xyz), half);
    let err = K_CLIP * U * (dot(abs(row.xyz), abs(centre) + half) + abs(row.w)) + 1e-30;
    return vec3<f32>(c - r, c + r, err);
}

// Whether the box reaches into the clip volume: `grow` 1 asks "may it?" (every error against
// the test), -1 "certainly?" (every error for it).
fn reaches(view: ShadeView, lo: vec3<f32>, hi: vec3<f32>, grow: f32) -> bool {
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let x = span(view.x, centre, half);
    let y = span(view.y, centre, half);
    let z = span(view.z, centre, half);
    let s = CLIP_SLACK;
    return x.x <= 1.0 + s + grow * x.z && x.y >= -1.0 - s - grow * x.z && y.x <= 1.0 + s + grow * y.z
        && y.y >= -1.0 - s - grow * y.z && z.x <= 1.0 + s + grow * z.z && z.y >= -s - grow * z.z;
}

fn corner(t: u32, k: u32) -> vec3<f32> {
    let at = 9u * t + 3u * k;
    return vec3<f32>(corners[at], corners[at + 1u], corners[at + 2u]);
}

// Prism::may_shade (cull.rs) of triangle t, with its error bounds: NOTHING, UNDECIDED or SHADED.
fn triangle_verdict(view: ShadeView, t: u32) -> u32 {
    let id = ids[t];
    if id == view.own && view.own != NO_RECEIVER {
        return NOTHING;
    }
    let p = array<vec3<f32>, 3>(corner(t, 0u), corner(t, 1u), corner(t, 2u));
    var h: array<f32, 3>;
    var near = 0.0;
    for (var k = 0u; k < 3u; k += 1u) {
        let d = p[k] - view.p0;
        h[k] = dot(d, view.normal);
        near = max(near, max_abs(d));
    }
    let base = max_abs(view.p0);
    let top = max(h[0], max(h[1], h[2]));
    let err_h = U * (4.0 * base + 20.0 * near + 2.0 * view.eps) + 1e-30;
    if top <= view.eps - err_h {
        return NOTHING;
    }
    var lo = vec2<f32>(3.0e38);
    var hi = vec2<f32>(-3.0e38);
    var far = 0.0;
    for (var k = 0u; k < 3u; k += 1u) {
        let s = h[k] / view.along;
        let w = (p[k] - view.p0) - view.sun * s;
        let q = vec2<f32>(dot(w, view.u), dot(w, view.v));
        lo = min(lo, q);
        hi = max(hi, q);
        far = max(far, abs(s));
    }
    let err = 2.0 * err_h / view.along + U * (4.0 * base + 24.0 * near + 42.0 * far + 4.0 * view.box_size) + 1e-30;
    if lo.x > view.hi.x + err || hi.x < view.lo.x - err || lo.y > view.hi.y + err || hi.y < view.lo.y - err {
        return NOTHING;
    }
    let meets = lo.x <= view.hi.x - err && hi.x >= view.lo.x + err && lo.y <= view.hi.y - err && hi.y >= view.lo.y + err;
    if top > view.eps + err_h && meets {
        return SHADED;
    }
    return UNDECIDED;
}

// A cluster's verdict: NOTHING where its box certainly misses the view, else the strongest of its
// triangles', a SHADED triangle counting only where its own box certainly reaches the view.
fn cluster_verdict(view: ShadeView, c: u32) -> u32 {
    let cluster = clusters[c];
    if !reaches(view, cluster.lo, cluster.hi, 1.0) {
        return NOTHING;
    }
    var best = NOTHING;
    for (var t = cluster.first; t < cluster.first + cluster.count; t += 1u) {
        var x = triangle_verdict(view, t);
        if x == SHADED {
            let a = corner(t, 0u);
            let b = corner(t, 1u);
            let d = corner(t, 2u);
            if reaches(view, min(a, min(b, d)), max(a, max(b, d)), -1.0) {
                return SHADED;
            }
            x = UNDECIDED;
        }
        best = max(best, x);
    }
    return best;
}

@compute @workgroup_size(64)
fn may_shade_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let v = group.x;
    let view = views[v];
    let decidable = view.along >= MIN_ALONG;
    let clusters_to_test = select(0u, params.clusters, decidable);
    for (var start = 0u; start < clusters_to_test; start += GROUP) {
        let c = start + lane;
        if c < params.clusters {
            let x = cluster_verdict(view, c);
            if x != NOTHING {
                atomicMax(&verdict, x);
            }
        }
        workgroupBarrier();
        if lane == 0u {
            settled = atomicLoad(&verdict);
        }
        if workgroupUniformLoad(&settled) == SHADED {
            break;
        }
    }
    if lane == 0u {
        verdicts[v] = select(UNDECIDED, atomicLoad(&verdict), decidable);
    }
}
