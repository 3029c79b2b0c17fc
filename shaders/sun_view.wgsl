// Sun-view render: draws the scene into an atlas tile with an orthographic camera that looks
// along the sun's rays, writing each fragment's receiver id (or NO_RECEIVER) to the red channel
// of an rg32uint target. The mask pipeline draws the tile's receivers alone (no depth test) into
// the green channel, each its own id: their coverage, the denominators of the sunlit fractions.
//
// Views: the tile being drawn is bound as a uniform at a dynamic offset (one per tile), so a
// draw's vertices share one load of it. Only the render reads the view and the leaf fraction;
// the count pass reads where each tile is and whom it counts (count_pixels.wgsl's View).
// Instances: instance_index is the placement's slot, so one draw_indexed per mesh renders every
// placement of it in one view. The static mesh (single-use
// nodes baked in scene coordinates relative to the origin, receiver ids absolute) has its own
// entry point, vs_static, that reads no instance: its placement is the identity, and on a CPU
// rasteriser the instance's load and transform were a quarter of a view's cost on NYT-like models.
//
// See-through casters: a leaf (rank >= 0) is dropped in the vertex shader when its rank, shifted
// by its instance, is not below the view's leaf fraction (all three vertices of a leaf triangle
// share the rank, so the whole triangle goes); a fragment with transmittance t is discarded when
// a per-pixel hash threshold in [0, 1) falls below t, so on average t of it lets the sun through.

const NO_RECEIVER: u32 = 0xffffffffu;

struct Instance {
    // Mesh coordinates → scene coordinates relative to the scene origin.
    transform: mat4x4<f32>,
    // Added to the per-vertex surface value; NO_RECEIVER for shadow-only placements.
    receiver_base: u32,
    // Added (mod 1) to the leaf ranks of the mesh: each placement of a tree has its own leaves.
    leaf_shift: f32,
    _pad1: u32,
    _pad2: u32,
}

struct TileView {
    view_proj: mat4x4<f32>,
    // Leaf fraction of the view's day: leaves with a lower rank cast shadows.
    leaves: f32,
    // The tile's place in its batch (the GPU culling's view index).
    slot: u32,
    // Subpixels (1/256 pixel) across half the tile: clip x and y are snapped to them (`shade`).
    snap: f32,
    _pad1: u32,
}

struct Params {
    // Read by the count pass only.
    count_edges: u32,
    // The static mesh's instance slot (its dither seeds depend on it, as a placement's do).
    static_slot: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<uniform> params: Params;
@group(1) @binding(0) var<uniform> view: TileView;

struct VertexOut {
    // Invariant: the mask pass and the scene pass must rasterise a receiver identically.
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
    @location(1) @interpolate(flat) transmittance: f32,
    @location(2) @interpolate(flat) seed: u32,
}

// Outside every clip volume: a dropped leaf's vertices all go here, so its triangle is clipped away.
const DROPPED = vec4<f32>(2.0, 2.0, 2.0, 1.0);

// One vertex of a mesh (GpuVertex in gpu.rs).
struct VertexIn {
    @location(0) position: vec3<f32>,
    // Receiver id (relative to the placement's receiver_base), or NO_RECEIVER.
    @location(1) surface: u32,
    // Leaf rank (negative: not a leaf) and transmittance.
    @location(2) veil: vec2<f32>,
    @location(3) seed: u32,
}

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> VertexOut {
    let instance = instances[instance_index];
    let clip = view.view_proj * (instance.transform * vec4<f32>(v.position, 1.0));
    return shade(clip, v, instance.leaf_shift, instance.receiver_base, instance_index);
}

@vertex
fn vs_static(v: VertexIn) -> VertexOut {
    return shade(view.view_proj * vec4<f32>(v.position, 1.0), v, 0.0, 0u, params.static_slot);
}

// What both entry points pass on: the clip position (DROPPED for a leaf not in leaf), the id
// (NO_RECEIVER for shading-only geometry), the transmittance and the dither seed.
fn shade(clip: vec4<f32>, v: VertexIn, leaf_shift: f32, receiver_base: u32, slot: u32) -> VertexOut {
    return shade_at(clip, v, leaf_shift, receiver_base, slot, view.snap, view.leaves);
}

// `shade` for a view's `snap` and `leaves` given (the batch draw reads them from storage).
fn shade_at(clip: vec4<f32>, v: VertexIn, leaf_shift: f32, receiver_base: u32, slot: u32, snap: f32, leaves: f32) -> VertexOut {
    var out: VertexOut;
    // Snapped to 1/256 pixel of the tile (w is 1: the view is orthographic), so the viewport's
    // offset to the tile's slot in the atlas adds whole subpixels and rounds nothing: a triangle
    // gives the same pixels in every slot (subpixels_per_half_tile in pipelines.rs).
    out.position = vec4<f32>(round(clip.xy * snap) / snap, clip.zw);
    if v.veil.x >= 0.0 && fract(v.veil.x + leaf_shift) >= leaves {
        out.position = DROPPED;
    }
    if v.surface == NO_RECEIVER || receiver_base == NO_RECEIVER {
        out.id = NO_RECEIVER;
    } else {
        out.id = receiver_base + v.surface;
    }
    out.transmittance = v.veil.y;
    out.seed = v.seed ^ (slot * 0x9e3779b9u);
    return out;
}

// Drawing the casters the GPU's culling kept (shaders/cull_clusters.wgsl, view_*_main): one
// indirect draw a tile, an instance a kept cluster, three vertices for each triangle a cluster
// may hold. Each vertex pulls its triangle's corner from storage: the cluster's triangle at the
// vertex's position in the culling's order, its run (the static mesh, or a shared mesh's
// placements) telling which mesh's corners and which placement. The clip position is computed
// by the same expressions as vs_static and vs_main, from the same f32 corners and transforms,
// so every pixel is the one the CPU-culled draws give.

struct Cluster {
    lo: vec3<f32>,
    first: u32,
    hi: vec3<f32>,
    count: u32,
}

// A vertex as VertexIn reads it, 4-byte fields only (GpuVertex in pipelines.rs, 28 bytes).
struct PulledVertex {
    x: f32,
    y: f32,
    z: f32,
    surface: u32,
    rank: f32,
    transmittance: f32,
    seed: u32,
}

// A run of triangles placed one way (TriangleRun in cull.rs): `per_instance` triangles a
// placement from position `first` on; corners from `indices[index_base + 3t + k]`, offset by
// `vertex_base` into `vertices`; `placed` 0 for the static mesh (no instance transform).
struct Run {
    first: u32,
    per_instance: u32,
    first_slot: u32,
    index_base: u32,
    vertex_base: u32,
    placed: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(2) @binding(0) var<storage, read> kept: array<vec2<u32>>;
@group(2) @binding(1) var<storage, read> heads: array<u32>;
@group(2) @binding(2) var<storage, read> clusters: array<Cluster>;
@group(2) @binding(3) var<storage, read> cluster_runs: array<u32>;
@group(2) @binding(4) var<storage, read> runs: array<Run>;
@group(2) @binding(5) var<storage, read> pulled_vertices: array<PulledVertex>;
@group(2) @binding(6) var<storage, read> pulled_indices: array<u32>;

@vertex
fn vs_pulled(@builtin(vertex_index) corner: u32, @builtin(instance_index) instance_index: u32) -> VertexOut {
    let c = kept[heads[view.slot] + instance_index].y;
    let cluster = clusters[c];
    let k = corner / 3u;
    if k >= cluster.count {
        // Past the cluster's last triangle: a triangle of DROPPED corners, clipped away.
        return dropped();
    }
    let run = runs[cluster_runs[c]];
    let local = cluster.first + k - run.first;
    let v = pulled_corner(run, local % run.per_instance, corner % 3u);
    return place_pulled(run, local / run.per_instance, v, view.view_proj, view.snap, view.leaves);
}

// A corner outside every clip volume (its triangle is clipped away).
fn dropped() -> VertexOut {
    var out: VertexOut;
    out.position = DROPPED;
    out.id = NO_RECEIVER;
    return out;
}

// Corner `corner` (0..3) of triangle `t` of one placement of `run`.
fn pulled_corner(run: Run, t: u32, corner: u32) -> VertexIn {
    let p = pulled_vertices[run.vertex_base + pulled_indices[run.index_base + 3u * t + corner]];
    return VertexIn(vec3<f32>(p.x, p.y, p.z), p.surface, vec2<f32>(p.rank, p.transmittance), p.seed);
}

// Corner `v` of `run`'s placement `placement` seen by `view_proj`: the expressions of vs_static
// (the static mesh) and vs_main (a placement), so the pixels are theirs.
fn place_pulled(run: Run, placement: u32, v: VertexIn, view_proj: mat4x4<f32>, snap: f32, leaves: f32) -> VertexOut {
    if run.placed == 0u {
        return shade_at(view_proj * vec4<f32>(v.position, 1.0), v, 0.0, 0u, params.static_slot, snap, leaves);
    }
    let slot = run.first_slot + placement;
    let instance = instances[slot];
    let clip = view_proj * (instance.transform * vec4<f32>(v.position, 1.0));
    return shade_at(clip, v, instance.leaf_shift, instance.receiver_base, slot, snap, leaves);
}

// One draw a batch (src/count/gpu/batched.rs): every tile of the batch drawn by one draw with
// the whole atlas as its viewport. The scene draw's instances are the culling's (view, cluster)
// pairs of the whole batch (`kept`, each view's clusters in triangle order, views in slot
// order), the mask draw's the members' triangles in runs of up to 128 (`mask_items`). Each
// corner is placed by `shade_at` as in the tile's own draw, then moved into the view's tile in
// whole subpixels (`in_tile`), and its fragments outside the tile are discarded (`fs_tiled`):
// the same pixels as a draw with the tile's viewport and scissor.

// A view as the batch draw reads it: its clip transform, leaf fraction and snap (TileView's),
// the tile's top-left pixel in the atlas, its side and the atlas's side (GpuBatchView).
struct BatchView {
    view_proj: mat4x4<f32>,
    leaves: f32,
    snap: f32,
    side: f32,
    atlas: f32,
    origin: vec2<f32>,
    _pad: vec2<f32>,
}

// Triangles `first`..`first + count` of `run`'s placement `placement`, a member's mask in view
// `view` (GpuMaskItem).
struct MaskItem {
    view: u32,
    run: u32,
    first: u32,
    count: u32,
    placement: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(1) var<storage, read> batch_views: array<BatchView>;
@group(1) @binding(2) var<storage, read> mask_items: array<MaskItem>;

struct TiledOut {
    @invariant @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
    @location(1) @interpolate(flat) transmittance: f32,
    @location(2) @interpolate(flat) seed: u32,
    // The tile's pixels: x and y from (inclusive) and to (exclusive).
    @location(3) @interpolate(flat) tile: vec4<f32>,
}

// `out` (clip x, y whole subpixels of the tile over `snap`) moved into `bv`'s tile of the atlas.
// In subpixels from the atlas's top-left corner the tile's centre is a whole number and so is the
// corner's offset from it, and the atlas's half side in subpixels is a power of two where the
// atlas's side is: the sum and the division are exact, and the viewport's scale gives back the
// whole subpixels the tile's own viewport gives (the rasterizer's snap, 8 bits, does the rest
// where the atlas's side is not a power of two).
fn in_tile(out: VertexOut, bv: BatchView) -> TiledOut {
    let centre = 256.0 * (bv.origin + 0.5 * bv.side);
    let k = round(out.position.xy * bv.snap);
    let half = 128.0 * bv.atlas;
    var tiled: TiledOut;
    tiled.position = vec4<f32>((centre.x + k.x) / half - 1.0, 1.0 - (centre.y - k.y) / half, out.position.zw);
    tiled.id = out.id;
    tiled.transmittance = out.transmittance;
    tiled.seed = out.seed;
    tiled.tile = vec4<f32>(bv.origin, bv.origin + bv.side);
    return tiled;
}

@vertex
fn vs_batch(@builtin(vertex_index) corner: u32, @builtin(instance_index) pair: u32) -> TiledOut {
    let p = kept[pair];
    let bv = batch_views[p.x];
    let cluster = clusters[p.y];
    let k = corner / 3u;
    if k >= cluster.count {
        return in_tile(dropped(), bv);
    }
    let run = runs[cluster_runs[p.y]];
    let local = cluster.first + k - run.first;
    let v = pulled_corner(run, local % run.per_instance, corner % 3u);
    return in_tile(place_pulled(run, local / run.per_instance, v, bv.view_proj, bv.snap, bv.leaves), bv);
}

@vertex
fn vs_batch_mask(@builtin(vertex_index) corner: u32, @builtin(instance_index) i: u32) -> TiledOut {
    let item = mask_items[i];
    let bv = batch_views[item.view];
    let k = corner / 3u;
    if k >= item.count {
        return in_tile(dropped(), bv);
    }
    let run = runs[item.run];
    let v = pulled_corner(run, item.first + k, corner % 3u);
    return in_tile(place_pulled(run, item.placement, v, bv.view_proj, bv.snap, bv.leaves), bv);
}

// PCG hash (Jarzynski & Olano 2020): well-mixed 32 bits from 32.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Both pipelines share this: the scene pipeline writes only red (the visible id), the mask
// pipeline only green (the covering member's id).
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec2<u32> {
    return receiver_id(in.position.xy, in.id, in.transmittance, in.seed);
}

// The batch draw's: fs_main within the fragment's tile, nothing outside it (what the tile's
// scissor does for a draw of its own).
@fragment
fn fs_tiled(in: TiledOut) -> @location(0) vec2<u32> {
    let p = in.position.xy;
    if p.x < in.tile.x || p.y < in.tile.y || p.x >= in.tile.z || p.y >= in.tile.w {
        discard;
    }
    return receiver_id(p, in.id, in.transmittance, in.seed);
}

// What a fragment at `position` of receiver `id` writes, or discarded where the see-through
// dither lets the sun through.
fn receiver_id(position: vec2<f32>, id: u32, transmittance: f32, seed: u32) -> vec2<u32> {
    if transmittance > 0.0 {
        let pixel = vec2<u32>(position);
        let h = pcg(pixel.x ^ pcg(pixel.y ^ pcg(seed)));
        if f32(h >> 8u) * (1.0 / 16777216.0) < transmittance {
            discard;
        }
    }
    return vec2<u32>(id, id);
}
