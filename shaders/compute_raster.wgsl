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
// 2. raster_main, a workgroup per raster tile: lanes 0..31 and 32..63 walk the view's member
//    list, then its large list and then the tile's list (skipping boxes that miss the tile),
//    taking every other triangle; each lane owns one row and steps across it. With every
//    member drawn first, a tile stops walking as soon as no pixel of it shows a member: a tile no
//    member covers, at once, and a tile a caster has shaded whole, after that caster's chunk of
//    the walk (checked every WALK_CHUNK steps). What it has not drawn then could only lower
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
// Heads a view has after its raster tiles': the large list's, then the member list's.
const LARGE_LIST: u32 = 0u;
const MEMBER_LIST: u32 = 1u;
// The raster pass's walk, counted with params.walk (the library's compute::WalkStats), each as
// 64 bits (low, high words): tiles walked, list entries visited and triangles set up (a half of
// the workgroup's each), rows drawn (a lane's each), pixel centres tested.
const WALK_COUNTERS: u32 = 5u;
const WALK_WORDS: u32 = 10u;
// Where the views' list heads start in heads: after the pool's count and the walk's counters.
const FIRST_HEAD: u32 = 1u + WALK_WORDS;
// Steps of the walk (two triangles each, one per half of the workgroup) between two checks
// whether any pixel of the tile still shows a member. 4, not 16: a tile a caster shades whole
// stops 24 triangles sooner, and the check is cheap (docs/benchmarks-gpu.md: blaas-trees-summer
// 0.85× the time on an H200, nyt-blocks unchanged).
const WALK_CHUNK: u32 = 4u;

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
    // Where the view's list heads start in heads (after heads[0], the pool count): one per
    // raster tile, row by row, then its large list's and its member list's.
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
    // Non-zero (benchmarks): count the raster pass's walk into heads[1 ..][.. WALK_WORDS].
    walk: u32,
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
// heads[0]: pool nodes asked for; heads[1 ..][.. WALK_WORDS]: the walk's counters (with
// params.walk); heads[FIRST_HEAD + first_head + raster tile] (the large list after the view's
// raster tiles): 1 + its first node, 0 if none.
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
    for (var ty = t0.y; ty <= t1.y; ty++) {
        for (var tx = t0.x; tx <= t1.x; tx++) {
            let n = atomicAdd(&heads[0], 1u);
            if n >= params.capacity {
                continue;
            }
            let head = FIRST_HEAD + view.first_head + u32(ty) * per_row + u32(tx);
            let next = atomicExchange(&heads[head], n + 1u);
            nodes[n] = vec2<u32>(t, next);
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
    let next = atomicExchange(&heads[FIRST_HEAD + view.first_head + list], n + 1u);
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

var<workgroup> depth: array<atomic<u32>, 1024>;
var<workgroup> cover: array<atomic<u32>, 1024>;
// Per member: visible, covered, edge pairs.
var<workgroup> totals: array<atomic<u32>, 12>;
// Each lane's vote after a chunk of the walk (SHOWS_MEMBER | MORE_TO_WALK), and their union.
var<workgroup> votes: array<u32, 64>;
var<workgroup> decision: u32;
const SHOWS_MEMBER: u32 = 1u;
const MORE_TO_WALK: u32 = 2u;

// This lane's share of the walk's counters (params.walk): list entries visited, triangles set
// up, rows drawn, pixel centres tested; summed into walk_sums at the end of the tile. Counted
// only when asked for, so that a timed run does no more than before they existed.
var<private> walked: array<u32, 4>;
var<workgroup> walk_sums: array<atomic<u32>, 5>;

// PCG hash (Jarzynski & Olano 2020), as sun_view.wgsl's.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Draws triangle t's pixels in one row of a raster tile: row `row` of tile (tx, ty).
fn draw_row(t: u32, view: View, s: Setup, tile0: vec2<u32>, row: u32) {
    let y = tile0.y + row;
    let py = i32(y * 256u + 128u);
    // Only the pixel centres within the triangle's bounding box: the row, and its first and last
    // columns (floor and ceiling divisions by 256 as arithmetic shifts).
    let lo = vec2<i32>(min(s.x.x, min(s.x.y, s.x.z)), min(s.y.x, min(s.y.y, s.y.z)));
    let hi = vec2<i32>(max(s.x.x, max(s.x.y, s.x.z)), max(s.y.x, max(s.y.y, s.y.z)));
    if py < lo.y || py > hi.y || y >= view.side {
        return;
    }
    let first = max(-((128 - lo.x) >> 8u) - i32(tile0.x), 0);
    let last = min(((hi.x - 128) >> 8u) - i32(tile0.x), i32(min(TILE, view.side - tile0.x)) - 1);
    if first > last {
        return;
    }
    if params.walk != 0u {
        walked[2] += 1u;
        walked[3] += u32(last - first + 1);
    }
    let px0 = (i32(tile0.x) + first) * 256 + 128;
    let a = attributes[t];
    let kind = class_of(t, view);
    let transmittance = bitcast<f32>(a.z);
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
    for (var x = u32(first); x <= u32(last); x++) {
        let inside = !negative64(e[0]) && !negative64(e[1]) && !negative64(e[2]);
        let lx = tile0.x + x;
        if inside {
            let cx = f32(lx) + 0.5 - f32(s.x.x) / 256.0;
            let cy = f32(y) + 0.5 - f32(s.y.x) / 256.0;
            let z = s.z0 + s.dzdx * cx + s.dzdy * cy;
            var kept = z >= 0.0 && z <= 1.0;
            if kept && transmittance > 0.0 {
                let h = pcg((view.tile.x + lx) ^ pcg((view.tile.y + y) ^ pcg(a.w)));
                kept = f32(h >> 8u) * (1.0 / 16777216.0) >= transmittance;
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

// Where a half of the workgroup starts walking a list that starts at `head`: lanes 0..31 at its
// first triangle, lanes 32..63 at its second (each half then takes every other triangle).
fn first_of_half(head: u32, lane: u32) -> u32 {
    if lane >= TILE {
        return next_node(head);
    }
    return head;
}

// Draws this lane's row of the triangle at boxed node `node` (a member or large list's), if its
// box holds raster tile `at` (the box is the next node: nodes[node], the triangle nodes[node - 1]).
fn draw_boxed(node: u32, view: View, at: vec2<u32>, tile0: vec2<u32>, row: u32) {
    let box = nodes[node];
    if params.walk != 0u {
        walked[0] += 1u;
    }
    if at.x >= (box.x & 0xffffu) && at.y >= (box.x >> 16u) && at.x <= (box.y & 0xffffu) && at.y <= (box.y >> 16u) {
        let t = nodes[node - 1u].x;
        if params.walk != 0u {
            walked[1] += 1u;
        }
        let s = setup(t, view);
        if s.live {
            draw_row(t, view, s, tile0, row);
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

// The next node after n (0: the end).
fn next_node(n: u32) -> u32 {
    if n == 0u {
        return 0u;
    }
    return nodes[n - 1u].y;
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
    if lane < WALK_COUNTERS {
        atomicStore(&walk_sums[lane], 0u);
    }
    workgroupBarrier();
    let row = lane % TILE;
    let at = vec2<u32>(group.x % per_row, group.x / per_row);
    let lists = FIRST_HEAD + view.first_head + per_row * per_row;
    // The members first, whole (few triangles: a view's receivers).
    var node = first_of_half(atomicLoad(&heads[lists + MEMBER_LIST]), lane);
    while node != 0u {
        draw_boxed(node, view, at, tile0, row);
        node = next_node(next_node(node));
    }
    // Then the large list and the tile's list, a chunk at a time, until nothing of the tile
    // shows a member or nothing is left.
    var small = first_of_half(atomicLoad(&heads[FIRST_HEAD + view.first_head + group.x]), lane);
    var large = first_of_half(atomicLoad(&heads[lists + LARGE_LIST]), lane);
    loop {
        workgroupBarrier();
        votes[lane] = select(0u, SHOWS_MEMBER, shows_member(lane)) | select(0u, MORE_TO_WALK, small != 0u || large != 0u);
        workgroupBarrier();
        if lane == 0u {
            var all = 0u;
            for (var i = 0u; i < 64u; i++) {
                all |= votes[i];
            }
            decision = all;
        }
        let now = workgroupUniformLoad(&decision);
        // A test's dump walks everything: the classes of pixels no member shows are kept too.
        if (now & MORE_TO_WALK) == 0u || ((now & SHOWS_MEMBER) == 0u && params.dump == 0u) {
            break;
        }
        // Large triangles first: they are the ones likely to shade a tile whole.
        for (var step = 0u; step < WALK_CHUNK; step++) {
            if large != 0u {
                draw_boxed(large, view, at, tile0, row);
                large = next_node(next_node(large));
            } else if small != 0u {
                let t = nodes[small - 1u].x;
                if params.walk != 0u {
                    walked[0] += 1u;
                    walked[1] += 1u;
                }
                let s = setup(t, view);
                if s.live {
                    draw_row(t, view, s, tile0, row);
                }
                small = next_node(next_node(small));
            } else {
                break;
            }
        }
    }
    workgroupBarrier();
    if params.dump != 0u {
        dump_tile(view, tile0, lane, group.y);
    }
    if params.walk != 0u {
        count_walk(lane);
    }
    count_tile(view, tile0, lane);
}

// Adds this tile's walk to the counters in heads (params.walk): every lane's rows and pixels, the
// entries and set-ups of one lane a half (its 32 lanes walk the same triangles), and the tile.
fn count_walk(lane: u32) {
    if lane % TILE == 0u {
        atomicAdd(&walk_sums[1], walked[0]);
        atomicAdd(&walk_sums[2], walked[1]);
    }
    atomicAdd(&walk_sums[3], walked[2]);
    atomicAdd(&walk_sums[4], walked[3]);
    workgroupBarrier();
    if lane == 0u {
        atomicStore(&walk_sums[0], 1u);
        for (var k = 0u; k < WALK_COUNTERS; k++) {
            add_walk(k, atomicLoad(&walk_sums[k]));
        }
    }
}

// Adds v to walk counter k, 64 bits as two words of heads (low, then high).
fn add_walk(k: u32, v: u32) {
    let old = atomicAdd(&heads[1u + 2u * k], v);
    if old + v < old {
        atomicAdd(&heads[2u + 2u * k], 1u);
    }
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
