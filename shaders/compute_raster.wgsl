// The compute rasterizer: counts the same pixels as sun_view.wgsl + count_pixels.wgsl without the
// graphics pipeline, in two compute passes over a batch of views (hundreds a batch: there is no
// atlas to fill, only buffers):
//
// 1. bin_main, a workgroup per job: a job is up to JOB consecutive triangles of one view's culled
//    list (the host cuts each view's list into jobs, so a view's binning spreads over as many
//    workgroups as its triangles need, not one). Each lane transforms and snaps its triangles as
//    the raster path's hardware would and appends each to the list of every 32×32 raster tile
//    its bounding box touches (a singly linked list per raster tile, nodes from one pool taken
//    with one atomicAdd). A triangle whose box touches more raster tiles than large_tiles (a
//    quarter of the view's, at least LARGE_TILES) goes once into its view's list of large
//    triangles instead (two nodes: the triangle, and its box in raster tiles), so a triangle
//    takes at most large_tiles nodes and the pool a batch needs is bounded by that × its
//    triangles (large triangles, the usual case on a view fitted to a window, no longer take a
//    node per tile). Every raster tile walks the large list, so only triangles over a quarter of
//    the view go there: a tile then rejects at most ~3 boxes for each it draws. A pool too small for the batch still counts
//    what it needed in heads[0] and drops the rest: the host reads that count and runs the batch
//    again with a pool that large, so a list is never truncated.
//    The view's members' own triangles (its receivers') go, whatever their size, into a third
//    list of the view, with their boxes, so that a raster tile can draw them first.
// 2. raster_main, a workgroup per raster tile: the view's member list first, then its large list
//    (skipping boxes that miss the tile) and the tile's own list, in rounds of 64 triangles, each
//    set up once by one lane into workgroup memory and drawn a (triangle, row) pair a lane (see
//    the pass's own note below). With every member drawn first, a tile stops walking as soon as
//    no pixel of it shows a member: a tile no member covers, at once, and a tile a caster has
//    shaded whole, after that caster's round. What it has not drawn then could only lower
//    casters' depths or cover pixels no member covers, which changes no count (atomicMin keeps
//    a member's word only where it is the nearest). Tests that dump every pixel's class walk
//    everything, so the dump stays the whole picture. Per pixel an
//    atomicMin in workgroup memory on a word packing quantized depth (high 29 bits) and class
//    (low 3 bits: member k of the view, or CASTER), so the nearest triangle wins and, at equal
//    quantized depth, a member beats a caster. Members also set their bit of the pixel's
//    coverage (no depth test, as the raster path's mask pass). Then the tile's visible, covered
//    and shadow-edge pixels are counted per member, with one global atomicAdd a count a tile.
//    Which order the lists hold their triangles in changes no pixel (atomicMin and atomicOr).
//
// Raster rules as the hardware's (Vulkan, as lavapipe and D3D/Metal do it): the viewport
// transform into atlas pixels, vertices snapped to 1/256 pixel (8 subpixel bits, round to
// nearest even), coverage sampled at pixel centres, a pixel on an edge drawn only when the edge
// is a top or left edge, depth clipped to [0, 1] per pixel. Edge functions are evaluated exactly
// in 64-bit integers, emulated on two u32 words (core WGSL has no i64), so no pixel depends on
// float rounding; only the depth does (a plane in f32, like the hardware's interpolation).
// Depth: z in [0, 1] × 2^29, truncated: two surfaces closer than 2^-29 of the view's depth range
// (the scene's extent along the sun: 2 nm on a 1 km scene) count as tied, and the member wins.

const TILE: u32 = 32u;
const NONE: u32 = 0xffffffffu;
const CASTER: u32 = 7u;
// The most members a view counts (the library's group::MAX_MEMBERS).
const MAX_MEMBERS: u32 = 4u;
// Snapped coordinates are clamped to ±2^29 subpixels (±2^21 pixels), so differences fit an i32.
const CLAMP: f32 = 536870912.0;
// Triangles a binning job takes (4 a lane); the library's compute::JOB_TRIANGLES.
const JOB: u32 = 256u;
// The fewest raster tiles a triangle's box may touch and go to its view's large list; the
// library's compute::LARGE_TILES (see large_tiles).
const LARGE_TILES: u32 = 8u;
// Lists a view has after its raster tiles': the large list, then the member list.
const LARGE_LIST: u32 = 0u;
const MEMBER_LIST: u32 = 1u;
// Chains a list is kept in (a triangle t goes to chain t % SUBLISTS; the library's
// compute::SUBLISTS): walking a chain is one dependent load a triangle, so a raster tile walks
// its lists with SUBLISTS lanes at once.
const SUBLISTS: u32 = 8u;

// Raster tiles a triangle's box may touch and be binned into each, in a view of `per_row`²
// raster tiles: a quarter of them, at least LARGE_TILES (the library's compute::node_bound).
fn large_tiles(per_row: u32) -> u32 {
    return max(LARGE_TILES, per_row * per_row / 4u);
}

struct View {
    view_proj: mat4x4<f32>,
    // Top-left pixel of the view's tile in the (virtual) atlas: the raster path's viewport.
    tile: vec2<u32>,
    side: u32,
    // Leaf fraction: leaves of a lower (shifted) rank cast shadows.
    leaves: f32,
    first_member: u32,
    member_count: u32,
    // The view's culled triangles: ranges[first_range ..][.. range_count], each (first triangle,
    // the view's triangles in the ranges before it), `triangles` in all.
    first_range: u32,
    range_count: u32,
    // Where the view's list heads start in heads (after heads[0], the pool count): SUBLISTS per
    // list, the raster tiles' lists row by row, then its large list's and its member list's.
    first_head: u32,
    triangles: u32,
    _pad1: u32,
    _pad2: u32,
}

struct Params {
    // Nodes the pool holds.
    capacity: u32,
    // Non-zero: count shadow-edge pairs too.
    count_edges: u32,
    // Non-zero (tests only): where in heads each pixel's class and coverage are also written,
    // view after view, row by row: the class (member k, CASTER, or 6 for nothing) | cover << 3.
    dump: u32,
    // The batch's jobs: ranges[first_job ..][.. jobs], (view, the first of its triangles) each.
    first_job: u32,
    jobs: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: u32,
}

// Triangle t's corners at positions[9t ..][.. 9], scene coordinates relative to the origin.
@group(0) @binding(0) var<storage, read> positions: array<f32>;
// Triangle t: (receiver id or NONE, leaf rank shifted by its placement as f32 bits (negative: not
// a leaf), transmittance bits, dither seed).
@group(0) @binding(1) var<storage, read> attributes: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read> views: array<View>;
// The views' ranges of triangles, then the jobs (one array: WebGPU guarantees 8 storage buffers).
@group(0) @binding(3) var<storage, read> ranges: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read> members: array<u32>;
// counts[3m], counts[3m + 1], counts[3m + 2]: visible, covered, edge pairs of member entry m.
@group(0) @binding(5) var<storage, read_write> counts: array<atomic<u32>>;
// heads[0]: pool nodes asked for; heads[sublist_head(view, list, chain)] (lists numbered raster
// tile by raster tile, then the large list and the member list): 1 + its first node, 0 if none.
@group(0) @binding(6) var<storage, read_write> heads: array<atomic<u32>>;
// Node n: (triangle, 1 + next node or 0); a large triangle's node n + 1: its box in raster tiles,
// (x0 | y0 << 16, x1 | y1 << 16).
@group(0) @binding(7) var<storage, read_write> nodes: array<vec2<u32>>;
@group(0) @binding(8) var<uniform> params: Params;

// ---- 64-bit integers as (low, high) u32 words, two's complement ----

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

fn neg64(a: vec2<u32>) -> vec2<u32> {
    return add64(vec2<u32>(~a.x, ~a.y), vec2<u32>(1u, 0u));
}

// a · b exactly, |a|, |b| < 2^31.
fn mul64(a: i32, b: i32) -> vec2<u32> {
    let ua = u32(abs(a));
    let ub = u32(abs(b));
    let a0 = ua & 0xffffu;
    let a1 = ua >> 16u;
    let b0 = ub & 0xffffu;
    let b1 = ub >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let mid = p01 + p10;
    let mid_carry = select(0u, 1u, mid < p01);
    let lo = p00 + (mid << 16u);
    let hi = a1 * b1 + (mid >> 16u) + (mid_carry << 16u) + select(0u, 1u, lo < p00);
    let p = vec2<u32>(lo, hi);
    if (a < 0) != (b < 0) {
        return neg64(p);
    }
    return p;
}

fn negative64(a: vec2<u32>) -> bool {
    return i32(a.y) < 0;
}

// ---- a triangle as the hardware sees it ----

struct Setup {
    // Snapped corners, subpixels relative to the view's tile, in [0, 1, 2] order with positive area.
    x: vec3<i32>,
    y: vec3<i32>,
    // Depth plane: z = z0 + dzdx (px - x0) + dzdy (py - y0), pixels.
    z0: f32,
    dzdx: f32,
    dzdy: f32,
    // False: dropped (a leaf not in leaf, zero area, or wholly outside depth [0, 1]).
    live: bool,
}

// Clip → subpixels (1/256 pixel) from the tile's corner, as the raster path places a corner:
// snapped from the tile's centre (sun_view.wgsl's `shade`), then offset by half the tile.
fn snap(clip: vec4<f32>, view: View) -> vec3<f32> {
    let half = f32(view.side) * 128.0;
    let sx = clamp(round(clip.x * half), -CLAMP, CLAMP) + half;
    let sy = clamp(round(-clip.y * half), -CLAMP, CLAMP) + half;
    return vec3<f32>(sx, sy, clip.z);
}

fn setup(t: u32, view: View) -> Setup {
    var s: Setup;
    s.live = false;
    let a = attributes[t];
    let rank = bitcast<f32>(a.y);
    if rank >= 0.0 && rank >= view.leaves {
        return s;
    }
    var p: array<vec3<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let o = 9u * t + 3u * k;
        let world = vec4<f32>(positions[o], positions[o + 1u], positions[o + 2u], 1.0);
        p[k] = snap(view.view_proj * world, view);
    }
    if max(p[0].z, max(p[1].z, p[2].z)) < 0.0 || min(p[0].z, min(p[1].z, p[2].z)) > 1.0 {
        return s;
    }
    var x = vec3<i32>(i32(p[0].x), i32(p[1].x), i32(p[2].x));
    var y = vec3<i32>(i32(p[0].y), i32(p[1].y), i32(p[2].y));
    var z = vec3<f32>(p[0].z, p[1].z, p[2].z);
    let area = add64(mul64(x.y - x.x, y.z - y.x), neg64(mul64(y.y - y.x, x.z - x.x)));
    if area.x == 0u && area.y == 0u {
        return s;
    }
    if negative64(area) {
        x = x.xzy;
        y = y.xzy;
        z = z.xzy;
    }
    // The depth plane from the snapped corners, in pixels.
    let e1 = vec3<f32>(f32(x.y - x.x) / 256.0, f32(y.y - y.x) / 256.0, z.y - z.x);
    let e2 = vec3<f32>(f32(x.z - x.x) / 256.0, f32(y.z - y.x) / 256.0, z.z - z.x);
    let n = cross(e1, e2);
    s.x = x;
    s.y = y;
    s.z0 = z.x;
    s.dzdx = -n.x / n.z;
    s.dzdy = -n.y / n.z;
    s.live = true;
    return s;
}

// ---- pass 1: binning ----

// Where chain `chain` of the view's list `list` starts (list: a raster tile, row by row, then
// per_row² + LARGE_LIST or MEMBER_LIST).
fn sublist_head(view: View, list: u32, chain: u32) -> u32 {
    return 1u + view.first_head + list * SUBLISTS + chain;
}

// Triangle k of a view's culled list: the last range starting at or before k (binary search).
fn triangle_at(view: View, k: u32) -> u32 {
    var lo = view.first_range;
    var hi = view.first_range + view.range_count;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if ranges[mid].y <= k {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let range = ranges[lo];
    return range.x + k - range.y;
}

@compute @workgroup_size(64)
fn bin_main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let index = group.x + group.y * groups.x;
    if index >= params.jobs {
        return;
    }
    let job = ranges[params.first_job + index];
    let view = views[job.x];
    let end = min(job.y + JOB, view.triangles);
    for (var k = job.y + lane; k < end; k += 64u) {
        bin(triangle_at(view, k), view);
    }
}

// Appends triangle t to the lists of the raster tiles its box touches, or to its view's large list.
fn bin(t: u32, view: View) {
    let s = setup(t, view);
    if !s.live {
        return;
    }
    let per_row = (view.side + TILE - 1u) / TILE;
    let span = i32(TILE * 256u);
    // Raster tiles the bounding box touches (pixel centres lie at 128 + 256·k).
    let lo = vec2<i32>(min(s.x.x, min(s.x.y, s.x.z)), min(s.y.x, min(s.y.y, s.y.z)));
    let hi = vec2<i32>(max(s.x.x, max(s.x.y, s.x.z)), max(s.y.x, max(s.y.y, s.y.z)));
    let last = i32(per_row) - 1;
    if hi.x < 0 || hi.y < 0 || lo.x / span > last || lo.y / span > last {
        return;
    }
    let t0 = clamp(lo / span, vec2<i32>(0), vec2<i32>(last));
    let t1 = clamp(hi / span, vec2<i32>(0), vec2<i32>(last));
    let box = t1 - t0 + vec2<i32>(1);
    if class_of(t, view) != CASTER {
        push_boxed(t, view, per_row * per_row + MEMBER_LIST, t0, t1);
        return;
    }
    if u32(box.x * box.y) > large_tiles(per_row) {
        push_boxed(t, view, per_row * per_row + LARGE_LIST, t0, t1);
        return;
    }
    // Its nodes in one go: every node of a batch comes from the one counter, heads[0], so an
    // atomicAdd a node would queue every lane of the GPU on one word.
    let needed = u32(box.x * box.y);
    var n = atomicAdd(&heads[0], needed);
    if n + needed > params.capacity {
        return;
    }
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let head = sublist_head(view, u32(ty) * per_row + u32(tx), t % SUBLISTS);
            let next = atomicExchange(&heads[head], n + 1u);
            nodes[n] = vec2<u32>(t, next);
            n++;
        }
    }
}

// Appends triangle t with its box in raster tiles (t0 to t1) to the view's list `list` (a head
// after its raster tiles'): two nodes, the triangle and the box.
fn push_boxed(t: u32, view: View, list: u32, t0: vec2<i32>, t1: vec2<i32>) {
    let n = atomicAdd(&heads[0], 2u);
    if n + 1u >= params.capacity {
        return;
    }
    let next = atomicExchange(&heads[sublist_head(view, list, t % SUBLISTS)], n + 1u);
    nodes[n] = vec2<u32>(t, next);
    nodes[n + 1u] = vec2<u32>(u32(t0.x) | (u32(t0.y) << 16u), u32(t1.x) | (u32(t1.y) << 16u));
}

// Member k of the view that triangle t belongs to, or CASTER.
fn class_of(t: u32, view: View) -> u32 {
    let id = attributes[t].x;
    var kind = CASTER;
    for (var k = 0u; k < view.member_count; k++) {
        if id == members[view.first_member + k] {
            kind = k;
        }
    }
    return kind;
}

// ---- pass 2: rasterizing and counting a raster tile ----
//
// The walk goes in rounds of up to ROUND triangles. Lanes 0 .. SUBLISTS each fetch up to
// PER_WALKER from their chain of the view's member list (while it has any, so that every member
// is drawn before the first check whether the tile may stop) or else of its large list; lanes
// HALF .. HALF + SUBLISTS as many from their chain of the tile's own list, all at once (a chain
// is one dependent load a triangle: 16 walkers wait for 4 loads a round, not 64). Each lane then sets
// up one fetched triangle (transform, snap, its rows and columns in the tile) into workgroup
// memory, once; and the round's (triangle, row) pairs are drawn one a lane, stepping across the
// row. A triangle is set up once a tile, not once a lane, and a lane draws a row only where the
// triangle has one, so small triangles (most of a city's) no longer leave most lanes idle.

var<workgroup> depth: array<atomic<u32>, 1024>;
var<workgroup> cover: array<atomic<u32>, 1024>;
// Per member: visible, covered, edge pairs.
var<workgroup> totals: array<atomic<u32>, 12>;
// The lanes' votes before a round (SHOWS_MEMBER | MORE_TO_WALK), or'ed together, and their
// union as lane 0 read it (which every lane then loads as one uniform value).
var<workgroup> votes: atomic<u32>;
var<workgroup> decision: u32;
const SHOWS_MEMBER: u32 = 1u;
const MORE_TO_WALK: u32 = 2u;

const ROUND: u32 = 64u;
const HALF: u32 = 32u;
// Triangles a walker fetches a round: the walkers of each half fill its HALF slots.
const PER_WALKER: u32 = HALF / SUBLISTS;
// A fetched triangle: (triangle, its boxed node or 0 for a tile list's triangle).
var<workgroup> fetched: array<vec2<u32>, 64>;
// Triangles each walker fetched this round (the first half's walkers, then the second's).
var<workgroup> taken: array<u32, 16>;
// Each member walker's cursor, and non-zero while any of them has triangles not yet fetched.
var<workgroup> pending: array<u32, 8>;
var<workgroup> members_left: u32;
// A set-up triangle of the round, as draw_item reads it.
struct Ready {
    x: vec3<i32>,
    y: vec3<i32>,
    z0: f32,
    dzdx: f32,
    dzdy: f32,
    // Its first and last column and first row in the tile, and its class: c0 | c1 << 8 | r0 << 16 | class << 24.
    span: u32,
    transmittance: f32,
    seed: u32,
}
var<workgroup> ready: array<Ready, 64>;
// Rows each slot's triangle has in the tile, then (scanned) the rows of the slots up to it.
var<workgroup> rows_to: array<u32, 64>;

// PCG hash (Jarzynski & Olano 2020), as sun_view.wgsl's.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Sets up fetched triangle `entry` for raster tile `at` (pixel tile0) into ready[slot]; returns
// the rows it has in the tile, 0 where it draws nothing there (its box misses the tile, or it is
// dropped, or no pixel centre of the tile lies in its bounding box).
fn prepare(entry: vec2<u32>, view: View, at: vec2<u32>, tile0: vec2<u32>, slot: u32) -> u32 {
    if entry.y != 0u {
        let box = nodes[entry.y];
        if at.x < (box.x & 0xffffu) || at.y < (box.x >> 16u) || at.x > (box.y & 0xffffu) || at.y > (box.y >> 16u) {
            return 0u;
        }
    }
    let t = entry.x;
    let s = setup(t, view);
    if !s.live {
        return 0u;
    }
    // The pixel centres (at 128 + 256·k subpixels) within the bounding box, within the tile and
    // the view: ceilings and floors of divisions by 256 as arithmetic shifts.
    let lo = vec2<i32>(min(s.x.x, min(s.x.y, s.x.z)), min(s.y.x, min(s.y.y, s.y.z)));
    let hi = vec2<i32>(max(s.x.x, max(s.x.y, s.x.z)), max(s.y.x, max(s.y.y, s.y.z)));
    let first = max(-((vec2<i32>(128) - lo) >> vec2<u32>(8u)) - vec2<i32>(tile0), vec2<i32>(0));
    let last = min(((hi - vec2<i32>(128)) >> vec2<u32>(8u)) - vec2<i32>(tile0), vec2<i32>(min(vec2<u32>(TILE), vec2<u32>(view.side) - tile0)) - vec2<i32>(1));
    if first.x > last.x || first.y > last.y {
        return 0u;
    }
    let a = attributes[t];
    let span = u32(first.x) | (u32(last.x) << 8u) | (u32(first.y) << 16u) | (class_of(t, view) << 24u);
    ready[slot] = Ready(s.x, s.y, s.z0, s.dzdx, s.dzdy, span, bitcast<f32>(a.z), a.w);
    return u32(last.y - first.y + 1);
}

// Draws row `r` (counted from its first) of the round's triangle in slot `slot` in the tile at
// pixel tile0: each pixel centre of the row inside the triangle by the fill rule, within depth
// [0, 1] and not dithered away, takes atomicMin on its word; a member's also sets its cover bit.
fn draw_item(slot: u32, r: u32, view: View, tile0: vec2<u32>) {
    let s = ready[slot];
    let first = s.span & 0xffu;
    let last = (s.span >> 8u) & 0xffu;
    let row = ((s.span >> 16u) & 0xffu) + r;
    let kind = s.span >> 24u;
    let y = tile0.y + row;
    let py = i32(y * 256u + 128u);
    let px0 = i32((tile0.x + first) * 256u + 128u);
    // Edge functions at the row's first pixel centre and their step a pixel right; a pixel is
    // in when all three are >= 0 after a bias of -1 on edges that are neither top nor left.
    var e: array<vec2<u32>, 3>;
    var step: array<vec2<u32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let k1 = (k + 1u) % 3u;
        let dx = s.x[k1] - s.x[k];
        let dy = s.y[k1] - s.y[k];
        let top_left = (dy == 0 && dx > 0) || dy < 0;
        e[k] = add64(mul64(dx, py - s.y[k]), neg64(mul64(dy, px0 - s.x[k])));
        if !top_left {
            e[k] = add64(e[k], vec2<u32>(NONE, NONE));
        }
        step[k] = neg64(mul64(dy, 256));
    }
    for (var x = first; x <= last; x++) {
        let inside = !negative64(e[0]) && !negative64(e[1]) && !negative64(e[2]);
        let lx = tile0.x + x;
        if inside {
            let cx = f32(lx) + 0.5 - f32(s.x.x) / 256.0;
            let cy = f32(y) + 0.5 - f32(s.y.x) / 256.0;
            let z = s.z0 + s.dzdx * cx + s.dzdy * cy;
            var kept = z >= 0.0 && z <= 1.0;
            if kept && s.transmittance > 0.0 {
                let h = pcg((view.tile.x + lx) ^ pcg((view.tile.y + y) ^ pcg(s.seed)));
                kept = f32(h >> 8u) * (1.0 / 16777216.0) >= s.transmittance;
            }
            if kept {
                let q = min(u32(z * 536870912.0), 0x1fffffffu);
                let at = row * TILE + x;
                atomicMin(&depth[at], (q << 3u) | kind);
                if kind != CASTER {
                    atomicOr(&cover[at], 1u << kind);
                }
            }
        }
        for (var k = 0u; k < 3u; k++) {
            e[k] = add64(e[k], step[k]);
        }
    }
}

// Whether any of this lane's pixels of the tile shows a member (its nearest word is a member's).
fn shows_member(lane: u32) -> bool {
    var any = false;
    for (var i = lane; i < TILE * TILE; i += 64u) {
        let word = atomicLoad(&depth[i]);
        any = any || (word != NONE && (word & 7u) != CASTER);
    }
    return any;
}

// Walker `walker` (0 .. 2 SUBLISTS: the first half's, then the second's) fetches up to
// PER_WALKER triangles into its slots from the chain whose next node is `cursor` (boxed: a member
// or large list's, whose entries are two nodes); returns the cursor after them and leaves the
// count in taken[walker].
fn fetch(cursor: u32, walker: u32, boxed: bool) -> u32 {
    let first = walker * PER_WALKER;
    var node = cursor;
    var n = 0u;
    while n < PER_WALKER && node != 0u {
        let entry = nodes[node - 1u];
        fetched[first + n] = vec2<u32>(entry.x, select(0u, node, boxed));
        n++;
        node = entry.y;
    }
    taken[walker] = n;
    return node;
}

// Lane 0 sums the member walkers' cursors into members_left (after a barrier).
fn gather_members_left(lane: u32) {
    if lane == 0u {
        var any = 0u;
        for (var w = 0u; w < SUBLISTS; w++) {
            any |= pending[w];
        }
        members_left = any;
    }
}

// Sums rows_to in place (inclusive prefix sums over the round's slots; a barrier a step, and
// one first: every lane's own count must be written before any lane reads its neighbour's).
fn scan_rows(lane: u32) {
    workgroupBarrier();
    for (var d = 1u; d < ROUND; d *= 2u) {
        var add = 0u;
        if lane >= d {
            add = rows_to[lane - d];
        }
        workgroupBarrier();
        rows_to[lane] += add;
        workgroupBarrier();
    }
}

// The slot whose scanned rows first pass `item` (binary search over rows_to).
fn slot_of(item: u32) -> u32 {
    var lo = 0u;
    var hi = ROUND - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if rows_to[mid] > item {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

@compute @workgroup_size(64)
fn raster_main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let view = views[group.y];
    let per_row = (view.side + TILE - 1u) / TILE;
    if group.x >= per_row * per_row {
        return;
    }
    let tile0 = vec2<u32>(group.x % per_row, group.x / per_row) * TILE;
    for (var i = lane; i < TILE * TILE; i += 64u) {
        atomicStore(&depth[i], NONE);
        atomicStore(&cover[i], 0u);
    }
    if lane < 12u {
        atomicStore(&totals[lane], 0u);
    }
    if lane == 0u {
        atomicStore(&votes, 0u);
    }
    let at = vec2<u32>(group.x % per_row, group.x / per_row);
    let tiles = per_row * per_row;
    // Lane w < SUBLISTS walks chain w of the member list, then of the large list; lane HALF + w
    // chain w of the tile's list. Walker w of a half fills slots w·PER_WALKER of that half.
    let chain = lane % HALF;
    let walker = (lane / HALF) * SUBLISTS + chain;
    var member_cursor = 0u;
    var large_cursor = 0u;
    var small_cursor = 0u;
    if chain < SUBLISTS {
        if lane < HALF {
            member_cursor = atomicLoad(&heads[sublist_head(view, tiles + MEMBER_LIST, chain)]);
            large_cursor = atomicLoad(&heads[sublist_head(view, tiles + LARGE_LIST, chain)]);
            pending[chain] = member_cursor;
        } else {
            small_cursor = atomicLoad(&heads[sublist_head(view, group.x, chain)]);
        }
    }
    workgroupBarrier();
    gather_members_left(lane);
    var members_drawn = workgroupUniformLoad(&members_left) == 0u;
    loop {
        // Once every member is drawn: stop when nothing of the tile shows a member (a tile no
        // member covers, at once), or nothing is left. What is left undrawn then could only
        // lower casters' depths or cover pixels no member covers. A test's dump walks everything.
        if members_drawn {
            workgroupBarrier();
            let more = large_cursor != 0u || small_cursor != 0u;
            let vote = select(0u, SHOWS_MEMBER, shows_member(lane)) | select(0u, MORE_TO_WALK, more);
            if vote != 0u {
                atomicOr(&votes, vote);
            }
            workgroupBarrier();
            if lane == 0u {
                // Cleared for the next round's votes, which come after two more barriers.
                decision = atomicExchange(&votes, 0u);
            }
            let now = workgroupUniformLoad(&decision);
            if (now & MORE_TO_WALK) == 0u || ((now & SHOWS_MEMBER) == 0u && params.dump == 0u) {
                break;
            }
        }
        workgroupBarrier();
        if chain < SUBLISTS {
            if lane < HALF {
                if member_cursor != 0u {
                    member_cursor = fetch(member_cursor, walker, true);
                } else {
                    large_cursor = fetch(large_cursor, walker, true);
                }
                pending[chain] = member_cursor;
            } else if members_drawn {
                small_cursor = fetch(small_cursor, walker, false);
            } else {
                // The tile's own triangles wait until every member is drawn, so a tile no
                // member covers draws none of them.
                taken[walker] = 0u;
            }
        }
        workgroupBarrier();
        gather_members_left(lane);
        var rows = 0u;
        if lane % PER_WALKER < taken[lane / PER_WALKER] {
            rows = prepare(fetched[lane], view, at, tile0, lane);
        }
        rows_to[lane] = rows;
        scan_rows(lane);
        let items = rows_to[ROUND - 1u];
        for (var item = lane; item < items; item += 64u) {
            let slot = slot_of(item);
            let before = select(0u, rows_to[max(slot, 1u) - 1u], slot > 0u);
            draw_item(slot, item - before, view, tile0);
        }
        members_drawn = workgroupUniformLoad(&members_left) == 0u;
    }
    workgroupBarrier();
    if params.dump != 0u {
        dump_tile(view, tile0, lane, group.y);
    }
    count_tile(view, tile0, lane);
}

// Counts the tile's pixels per member into totals, then adds them to the view's counts.
fn count_tile(view: View, tile0: vec2<u32>, lane: u32) {
    let n = min(view.member_count, MAX_MEMBERS);
    var visible: array<u32, MAX_MEMBERS>;
    var covered: array<u32, MAX_MEMBERS>;
    var edges: array<u32, MAX_MEMBERS>;
    for (var i = lane; i < TILE * TILE; i += 64u) {
        let x = i % TILE;
        let y = i / TILE;
        if tile0.x + x >= view.side || tile0.y + y >= view.side {
            continue;
        }
        let word = atomicLoad(&depth[i]);
        let bits = atomicLoad(&cover[i]);
        var right_word = NONE;
        var right_bits = 0u;
        if x + 1u < TILE {
            right_word = atomicLoad(&depth[i + 1u]);
            right_bits = atomicLoad(&cover[i + 1u]);
        }
        var below_word = NONE;
        var below_bits = 0u;
        if y + 1u < TILE {
            below_word = atomicLoad(&depth[i + TILE]);
            below_bits = atomicLoad(&cover[i + TILE]);
        }
        for (var k = 0u; k < n; k++) {
            let lit = is_visible(word, k);
            visible[k] += select(0u, 1u, lit);
            let on = (bits & (1u << k)) != 0u;
            covered[k] += select(0u, 1u, on);
            if params.count_edges != 0u && on {
                let right_on = (right_bits & (1u << k)) != 0u;
                let below_on = (below_bits & (1u << k)) != 0u;
                edges[k] += select(0u, 1u, right_on && lit != is_visible(right_word, k));
                edges[k] += select(0u, 1u, below_on && lit != is_visible(below_word, k));
            }
        }
    }
    for (var k = 0u; k < n; k++) {
        atomicAdd(&totals[3u * k], visible[k]);
        atomicAdd(&totals[3u * k + 1u], covered[k]);
        atomicAdd(&totals[3u * k + 2u], edges[k]);
    }
    workgroupBarrier();
    if lane < 3u * n {
        let total = atomicLoad(&totals[lane]);
        if total != 0u {
            atomicAdd(&counts[3u * view.first_member + lane], total);
        }
    }
}

fn dump_tile(view: View, tile0: vec2<u32>, lane: u32, slot: u32) {
    for (var i = lane; i < TILE * TILE; i += 64u) {
        let x = tile0.x + i % TILE;
        let y = tile0.y + i / TILE;
        if x < view.side && y < view.side {
            let word = atomicLoad(&depth[i]);
            let kind = select(word & 7u, 6u, word == NONE);
            atomicStore(&heads[params.dump + (slot * view.side + y) * view.side + x], kind | (atomicLoad(&cover[i]) << 3u));
        }
    }
}

fn is_visible(word: u32, k: u32) -> bool {
    return word != NONE && (word & 7u) == k;
}
