//! The scene: the triangles that cast shadows and the planar surfaces that receive sun.
//!
//! Owns the step from "nodes read from model files" to a render-ready layout:
//! - world axes are EnergyPlus's: x east, y north, z up, metres;
//! - a mesh used by one node is baked into world coordinates and merged with the others into
//!   one static mesh (one draw per view); a mesh used by several nodes stays shared and is drawn
//!   instanced, so instanced geometry is never copied per instance;
//! - every receiving node is split into planar parts (one receiver each), because a sunlit
//!   fraction is only defined for a plane; every receiver also casts shadows.
//!
//! GPU surface ids: a vertex carries a `surface` value, an instance a `receiver_base`; the id a
//! triangle writes is `receiver_base + surface`, or [`NO_RECEIVER`] when either is [`NO_RECEIVER`].
//! The merged static mesh has base 0 and absolute receiver ids in its vertices.
//!
//! See-through casters ([`Veil`], per vertex): a *leaf* (a connected group of triangles of a
//! foliage node) carries a fixed random rank in [0, 1) and casts a shadow only on days whose leaf
//! fraction exceeds it, so one upload serves every day; a node with transmittance t lets t of
//! the beam through (a stochastic per-pixel threshold on the GPU). Receivers are always opaque.

use std::collections::{HashMap, HashSet};
use std::ops::Range;

use glam::{DMat4, DVec3};

use crate::error::{Error, NoReceivers, Result};
use crate::geometry::{triangle_area, triangle_normal};

pub mod codec;

/// Surface id of geometry that only casts shadows.
pub const NO_RECEIVER: u32 = u32::MAX;

/// Two triangles are coplanar when their normals are within this angle (radians)…
pub(crate) const COPLANAR_ANGLE: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// …and every vertex lies within this distance (metres) of the part's plane.
pub(crate) const COPLANAR_DISTANCE: f64 = 1e-3;
/// Triangles with less area than this (m²) are ignored when building receivers.
const DEGENERATE_AREA: f64 = 1e-10;

/// Triangle geometry in one coordinate frame, with a per-vertex surface value.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// For messages: where the mesh came from.
    pub label: String,
    /// Vertex positions (world, relative to nothing, for the static mesh; local for shared ones).
    pub positions: Vec<[f32; 3]>,
    /// Per vertex: receiver part or absolute receiver id (see the module doc), or [`NO_RECEIVER`].
    pub surfaces: Vec<u32>,
    /// Triangle list.
    pub indices: Vec<u32>,
    /// Per vertex: leaf rank and transmittance ([`Veil::OPAQUE`] for ordinary geometry).
    pub veils: Vec<Veil>,
    /// Shading-only geometry laid out as receivers are ([`SceneBuilder::cast_by_parts`]): each
    /// range (of triangles, numbered as in `indices` / 3, in order and disjoint) one planar part
    /// of a node, which the exact engine groups into objects as it would the part received.
    pub cast_parts: Vec<Range<u32>>,
}

/// How a caster's vertex lets the sun through: see the module doc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Veil {
    /// Leaf rank in [0, 1): the leaf casts a shadow when its rank is below the day's leaf
    /// fraction. Negative for geometry that is not foliage (always casts).
    pub rank: f32,
    /// Fraction of the beam let through, in [0, 1); 0 is opaque.
    pub transmittance: f32,
    /// Decorrelates the per-pixel thresholds of different see-through nodes, so two screens of
    /// transmittance t behind each other let t² through, not t.
    pub seed: u32,
}

impl Veil {
    /// Ordinary geometry: casts a shadow every day, lets nothing through.
    pub const OPAQUE: Veil = Veil { rank: -1.0, transmittance: 0.0, seed: 0 };

    /// Whether this vertex's leaf is present when the leaf fraction is `leaves` (the test the GPU
    /// makes, in the same f32 arithmetic, with the instance's rank shift applied).
    pub fn present(&self, shift: f32, leaves: f32) -> bool {
        self.rank < 0.0 || shifted_rank(self.rank, shift) < leaves
    }
}

impl Default for Veil {
    fn default() -> Self {
        Self::OPAQUE
    }
}

/// A leaf's rank after an instance's shift: `fract(rank + shift)`, so every placement of a shared
/// tree has its own leaves while ranks stay uniform on [0, 1). Same f32 operations as the shader.
pub fn shifted_rank(rank: f32, shift: f32) -> f32 {
    let x = rank + shift;
    x - x.floor()
}

/// What a node lets through: set with [`SceneBuilder::set_node_veil`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NodeVeil {
    /// Its leaves come and go with the seasons.
    pub foliage: bool,
    /// Fraction of the beam it lets through (0 = opaque).
    pub transmittance: f64,
}

impl NodeVeil {
    /// Whether this is plain opaque, all-year geometry.
    pub fn is_opaque(&self) -> bool {
        !self.foliage && self.transmittance == 0.0
    }

    fn key(&self) -> (bool, u64) {
        (self.foliage, self.transmittance.to_bits())
    }
}

/// One placement of a mesh in the world.
#[derive(Debug, Clone)]
pub struct Instance {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Mesh coordinates → world coordinates.
    pub transform: DMat4,
    /// Added to the mesh's per-vertex surface values, or [`NO_RECEIVER`].
    pub receiver_base: u32,
    /// Added (mod 1) to the leaf ranks of its mesh: see [`shifted_rank`].
    pub leaf_shift: f32,
}

/// A planar receiving surface.
#[derive(Debug, Clone)]
pub struct Receiver {
    /// Unique name (an output column).
    pub name: String,
    /// Where it came from, for messages: `file: node 'name'`.
    pub origin: String,
    /// Its triangles in world coordinates (few: receivers are building surfaces).
    pub triangles: Vec<[DVec3; 3]>,
    /// Outward unit normal (from the triangles' counter-clockwise winding).
    pub normal: DVec3,
    /// Area in m² (sum of its triangles; overlapping triangles are not expected).
    pub area: f64,
    /// Which instance draws it and which index range of that instance's mesh holds it.
    pub draw: ReceiverDraw,
    /// The id its triangles carry on the GPU and in [`Scene::world_triangles`]: its own index,
    /// or, for a mirror (the back face of a shading surface), the index of the surface it mirrors.
    pub gpu_id: u32,
}

/// Where a receiver's triangles sit in the GPU layout, so a view can draw it alone.
#[derive(Debug, Clone)]
pub struct ReceiverDraw {
    /// Index into [`Scene::instances`].
    pub instance: usize,
    /// Index range (into the instance mesh's `indices`).
    pub indices: Range<u32>,
}

/// A render-ready scene. Build one with [`SceneBuilder`].
#[derive(Debug, Clone, Default)]
pub struct Scene {
    /// Geometry; index 0 is the merged static mesh (possibly empty).
    pub meshes: Vec<Mesh>,
    /// Placements; index 0 places the static mesh with the identity.
    pub instances: Vec<Instance>,
    /// Receiving surfaces; a receiver's id is its index here.
    pub receivers: Vec<Receiver>,
    /// World-space bounds of everything (min, max).
    pub bounds: (DVec3, DVec3),
    /// Centre of the input's bounds. The static mesh is stored relative to it (instance 0 adds it
    /// back) so f32 vertices keep millimetres even in georeferenced coordinates.
    pub origin: DVec3,
    /// Leaves of all foliage placements (see the module doc).
    pub leaves: usize,
    /// Triangles of all see-through placements.
    pub see_through_triangles: usize,
}

impl Scene {
    /// Total triangles drawn per full view (instances counted).
    pub fn triangle_count(&self) -> usize {
        self.instances.iter().map(|i| self.meshes[i.mesh].indices.len() / 3).sum()
    }

    /// Every triangle in world coordinates with the receiver it belongs to (if any).
    pub fn world_triangles(&self) -> impl Iterator<Item = ([DVec3; 3], Option<u32>)> + '_ {
        self.veiled_triangles().map(|(t, id, _)| (t, id))
    }

    /// Every triangle as [`Self::world_triangles`], with its veil (the rank already shifted by
    /// its instance, so [`Veil::present`] takes shift 0).
    pub fn veiled_triangles(&self) -> impl Iterator<Item = ([DVec3; 3], Option<u32>, Veil)> + '_ {
        self.instances.iter().flat_map(move |inst| {
            let mesh = &self.meshes[inst.mesh];
            mesh.indices.chunks_exact(3).map(move |tri| {
                let p = |i: u32| inst.transform.transform_point3(to_dvec(mesh.positions[i as usize]));
                let surface = mesh.surfaces[tri[0] as usize];
                let id = (surface != NO_RECEIVER && inst.receiver_base != NO_RECEIVER).then(|| inst.receiver_base + surface);
                let mut veil = mesh.veils.get(tri[0] as usize).copied().unwrap_or_default();
                if veil.rank >= 0.0 {
                    veil.rank = shifted_rank(veil.rank, inst.leaf_shift);
                }
                ([p(tri[0]), p(tri[1]), p(tri[2])], id, veil)
            })
        })
    }

    /// Whether any geometry is foliage (its shading changes with the leaf fraction).
    pub fn has_foliage(&self) -> bool {
        self.instances.iter().any(|i| self.meshes[i.mesh].veils.iter().any(|v| v.rank >= 0.0))
    }

    /// Leaves (connected groups of foliage triangles) and triangles of see-through geometry, over all placements.
    pub fn veil_counts(&self) -> (usize, usize) {
        (self.leaves, self.see_through_triangles)
    }

    /// Looks a receiver up by name.
    pub fn receiver(&self, name: &str) -> Option<(u32, &Receiver)> {
        self.receivers.iter().enumerate().find(|(_, r)| r.name == name).map(|(i, r)| (i as u32, r))
    }

    /// Appends the back face of receiver `of` as a receiver named `name` (see
    /// [`SceneBuilder::add_mirror`]), for callers that learn which faces they need once the
    /// scene is built (a glTF room's inside faces); returns its id. The caller keeps names unique.
    pub fn push_mirror(&mut self, of: u32, name: &str) -> u32 {
        let original = self.receivers[of as usize].clone();
        let id = self.receivers.len() as u32;
        self.receivers.push(Receiver {
            name: name.to_string(),
            origin: format!("{} (mirrored)", original.origin),
            normal: -original.normal,
            ..original
        });
        id
    }
}

fn to_dvec(p: [f32; 3]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// Mesh data as read from a model file, in the mesh's own coordinates.
#[derive(Debug, Clone, Default)]
pub struct SourceMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

/// One node as read from a model file.
#[derive(Debug, Clone)]
pub struct SourceNode {
    /// Node name used for receiver names (already made unique-ish by the reader if unnamed).
    pub name: String,
    /// `file: node 'name'`, for messages.
    pub origin: String,
    /// Index into the model's meshes.
    pub mesh: usize,
    /// Mesh → world transform (world axes as in the module doc).
    pub transform: DMat4,
    /// Whether this node receives (and so gets sunlit fractions).
    pub receiver: bool,
}

impl SourceNode {
    fn veil_error(&self, reason: &str) -> Error {
        let (file, object) = split_origin(&self.origin);
        Error::object(file, object, reason)
    }
}

/// Collects meshes and nodes from one or more model files, then lays them out ([`Self::build`]).
#[derive(Debug, Default)]
pub struct SceneBuilder {
    meshes: Vec<(String, SourceMesh)>,
    nodes: Vec<SourceNode>,
    /// (receiver name, mirror name) pairs: see [`SceneBuilder::add_mirror`].
    mirrors: Vec<(String, String)>,
    /// See-through nodes, by node index: see [`SceneBuilder::set_node_veil`].
    veils: HashMap<usize, NodeVeil>,
    /// The static mesh's origin when set ([`SceneBuilder::set_origin`]).
    origin: Option<DVec3>,
    /// Nodes cast by their planar parts when they do not receive: see
    /// [`SceneBuilder::cast_by_parts`].
    by_parts: HashSet<usize>,
}

impl SceneBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a mesh; returns its index for [`SourceNode::mesh`].
    pub fn add_mesh(&mut self, label: impl Into<String>, mesh: SourceMesh) -> usize {
        self.meshes.push((label.into(), mesh));
        self.meshes.len() - 1
    }

    /// Adds a node placing a mesh added earlier.
    pub fn add_node(&mut self, node: SourceNode) {
        self.nodes.push(node);
    }

    /// Adds a mesh placed once, as it is (identity transform), labelled `source: node 'name'`
    /// in messages: the common case for generated geometry (benchmarks, tests).
    pub fn add_object(&mut self, source: &str, name: &str, mesh: SourceMesh, receiver: bool) {
        let mesh = self.add_mesh(name, mesh);
        self.add_node(SourceNode {
            name: name.into(),
            origin: format!("{source}: node '{name}'"),
            mesh,
            transform: DMat4::IDENTITY,
            receiver,
        });
    }

    /// Adds a receiver that is the back face of receiver `of`: same triangles, opposite normal.
    /// EnergyPlus keeps such `Mir-` copies of shading surfaces; the geometry is drawn once and
    /// the mirror counts the original's pixels whenever the sun is behind the original.
    pub fn add_mirror(&mut self, of: &str, name: &str) {
        self.mirrors.push((of.to_string(), name.to_string()));
    }

    /// Makes node `index` (in the order added) foliage and/or see-through. Checked at
    /// [`Self::build`]: transmittance in [0, 1), and never on a receiver.
    pub fn set_node_veil(&mut self, index: usize, veil: NodeVeil) {
        self.veils.insert(index, veil);
    }

    /// Makes node `index` (in the order added), when it does not receive, cast its shadows as it
    /// would if it received: its triangles laid out and grouped by the same planar parts
    /// ([`Mesh::cast_parts`]). The exact engine merges a connected group of triangles into one
    /// convex object's shadow; a receiver's parts are never merged with other geometry, so
    /// without this a surface's shadow would be cast as its building's hull in one run and face
    /// by face in another, the same region rounded differently, and a receiver's answer would
    /// depend on which other surfaces receive beside it (a district tile's context against the
    /// one-process run). For city surfaces, which receive in one run and are context in the
    /// next. Foliage and see-through nodes (which never receive) are cast as they are.
    pub fn cast_by_parts(&mut self, index: usize) {
        self.by_parts.insert(index);
    }

    /// Stores the static mesh relative to `origin` (world) instead of the input's centre: scenes
    /// cut from one larger model (a district's tiles) then round their f32 vertices alike, so a
    /// receiver's answers do not depend on which cut it was counted in.
    pub fn set_origin(&mut self, origin: DVec3) {
        self.origin = Some(origin);
    }

    /// Number of nodes added so far.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Lays the scene out: bakes single-use meshes, splits receivers into planar parts, checks names.
    pub fn build(self) -> Result<Scene> {
        let mut uses = vec![0usize; self.meshes.len()];
        for node in &self.nodes {
            uses[node.mesh] += 1;
        }
        for (i, node) in self.nodes.iter().enumerate() {
            check_finite(node, &self.meshes[node.mesh].1)?;
            check_veil(node, &self.veil_of(i))?;
        }
        let origin = self.origin.unwrap_or_else(|| input_centre(&self.nodes, &self.meshes));
        let mut scene = Scene {
            meshes: vec![Mesh { label: "static".into(), ..Default::default() }],
            instances: vec![Instance { mesh: 0, transform: DMat4::from_translation(origin), receiver_base: 0, leaf_shift: 0.0 }],
            origin,
            ..Default::default()
        };
        // Shared meshes are copied once into the scene; parts are found per (mesh, receiving node).
        // A shared mesh placed with different veils is kept once per veil.
        let mut shared: HashMap<(usize, (bool, u64)), usize> = HashMap::new();
        let mut names: HashMap<String, String> = HashMap::new();
        for (i, node) in self.nodes.iter().enumerate() {
            let (label, source) = &self.meshes[node.mesh];
            let veil = self.veil_of(i);
            if veil.foliage {
                scene.leaves += leaf_count(source);
            }
            if veil.transmittance > 0.0 {
                scene.see_through_triangles += source.indices.len() / 3;
            }
            if uses[node.mesh] == 1 {
                let by_parts = self.by_parts.contains(&i) && veil.is_opaque();
                bake_node(&mut scene, node, source, &veil, i as u32, by_parts)?;
            } else {
                let mesh_index = *shared.entry((node.mesh, veil.key())).or_insert_with(|| {
                    scene.meshes.push(shared_mesh(label, source, &veil, i as u32));
                    scene.meshes.len() - 1
                });
                instance_node(&mut scene, node, mesh_index, i as u32)?;
            }
        }
        for (of, name) in &self.mirrors {
            let Some((id, _)) = scene.receiver(of) else {
                return Err(Error::NoReceivers(NoReceivers::Other(format!("'{name}' mirrors '{of}', which is not a receiver"))));
            };
            scene.push_mirror(id, name);
        }
        for r in &scene.receivers {
            if let Some(first) = names.insert(r.name.clone(), r.origin.clone()) {
                return Err(Error::DuplicateReceiver { name: r.name.clone(), first, second: r.origin.clone() });
            }
        }
        scene.bounds = bounds(&scene);
        Ok(scene)
    }
}

impl SceneBuilder {
    fn veil_of(&self, node: usize) -> NodeVeil {
        self.veils.get(&node).copied().unwrap_or_default()
    }
}

fn check_veil(node: &SourceNode, veil: &NodeVeil) -> Result<()> {
    if !(0.0..1.0).contains(&veil.transmittance) {
        return Err(node.veil_error(&format!("transmittance {} is outside [0, 1)", veil.transmittance)));
    }
    if node.receiver && !veil.is_opaque() {
        return Err(node.veil_error("is both a receiver and foliage or see-through; a receiving surface must be opaque"));
    }
    Ok(())
}

/// Per-vertex veils of one node's mesh. Leaves are the connected groups of triangles (sharing
/// vertex indices), each with a rank drawn from a hash of (node, leaf), so a model gives the same
/// leaves every run.
fn node_veils(mesh: &SourceMesh, veil: &NodeVeil, node: u32) -> Vec<Veil> {
    let seed = splitmix(node as u64 ^ 0x5eed) as u32;
    let base = Veil { rank: -1.0, transmittance: veil.transmittance as f32, seed };
    let mut out = vec![base; mesh.positions.len()];
    if veil.foliage {
        let leaf = leaf_of_vertex(mesh);
        for (v, l) in out.iter_mut().zip(leaf) {
            v.rank = unit_f32(splitmix(((node as u64) << 32) | l as u64));
        }
    }
    out
}

/// Leaves of a foliage mesh: the connected groups its triangles use.
fn leaf_count(mesh: &SourceMesh) -> usize {
    let leaf = leaf_of_vertex(mesh);
    let mut used: Vec<u32> = mesh.indices.iter().map(|&v| leaf[v as usize]).collect();
    used.sort_unstable();
    used.dedup();
    used.len()
}

/// Connected components of a mesh by shared vertex indices (union–find), as a leaf number per vertex.
fn leaf_of_vertex(mesh: &SourceMesh) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for tri in mesh.indices.chunks_exact(3) {
        let a = find(&mut parent, tri[0]);
        for &v in &tri[1..] {
            let b = find(&mut parent, v);
            parent[b as usize] = a;
        }
    }
    (0..parent.len() as u32).map(|v| find(&mut parent, v)).collect()
}

/// SplitMix64: a well-mixed hash of a counter, for ranks and seeds.
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A hash mapped to [0, 1) in f32 (24 bits, exactly representable, never 1).
fn unit_f32(h: u64) -> f32 {
    (h >> 40) as f32 / (1u64 << 24) as f32
}

fn input_centre(nodes: &[SourceNode], meshes: &[(String, SourceMesh)]) -> DVec3 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for node in nodes {
        for p in &meshes[node.mesh].1.positions {
            let w = node.transform.transform_point3(to_dvec(*p));
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    if lo.x > hi.x { DVec3::ZERO } else { (lo + hi) * 0.5 }
}

fn check_finite(node: &SourceNode, mesh: &SourceMesh) -> Result<()> {
    let bad_transform = !node.transform.is_finite();
    let bad_vertex = mesh.positions.iter().position(|p| p.iter().any(|c| !c.is_finite() || c.abs() > 1e7));
    if bad_transform || bad_vertex.is_some() {
        let (file, object) = split_origin(&node.origin);
        let what = match bad_vertex {
            Some(i) => format!("vertex {i} has a non-finite or absurd coordinate {:?} (limit ±1e7 m)", mesh.positions[i]),
            None => "its transform is not finite".to_string(),
        };
        return Err(Error::object(file, object, what));
    }
    // Finite vertices under a finite transform can still land absurdly far away (a scale of 1e30).
    let world = |p: &[f32; 3]| node.transform.transform_point3(to_dvec(*p));
    if let Some((i, w)) = mesh.positions.iter().map(world).enumerate().find(|(_, w)| w.abs().max_element() > 1e7) {
        let (file, object) = split_origin(&node.origin);
        return Err(Error::object(
            file,
            object,
            format!("vertex {i} is placed at {w}, beyond ±1e7 m (check the node's transform and units)"),
        ));
    }
    let n = mesh.positions.len() as u32;
    if let Some(i) = mesh.indices.iter().find(|&&i| i >= n) {
        let (file, object) = split_origin(&node.origin);
        return Err(Error::object(file, object, format!("index {i} out of range ({n} vertices)")));
    }
    if !mesh.indices.len().is_multiple_of(3) {
        let (file, object) = split_origin(&node.origin);
        return Err(Error::object(file, object, "index count is not a multiple of 3"));
    }
    Ok(())
}

/// `origin` reads `file: object`; errors want the two apart.
fn split_origin(origin: &str) -> (String, String) {
    match origin.rsplit_once(": ") {
        Some((f, o)) => (f.to_string(), o.to_string()),
        None => (String::new(), origin.to_string()),
    }
}

fn world_tris(node: &SourceNode, mesh: &SourceMesh) -> Vec<[DVec3; 3]> {
    let p = |i: u32| node.transform.transform_point3(to_dvec(mesh.positions[i as usize]));
    mesh.indices.chunks_exact(3).map(|t| [p(t[0]), p(t[1]), p(t[2])]).collect()
}

/// A planar group of a receiving node's triangles (indices into its triangle list).
struct Part {
    normal: DVec3,
    offset: f64,
    triangles: Vec<usize>,
}

/// Groups triangles by plane, largest triangles first so each part's plane is a large triangle's.
/// A receiving node splitting into more planar parts than this is not a building surface (a
/// curved or organic mesh), and finding its parts would take tris × parts steps.
const MAX_PARTS: usize = 1000;

fn too_many_parts(node: &SourceNode) -> Error {
    let (file, object) = split_origin(&node.origin);
    let reason = format!("receiver is not planar in fewer than {MAX_PARTS} parts (a curved mesh?): leave it out of the receivers");
    Error::object(file, object, reason)
}

/// Planar parts of a receiver's triangles, or `None` past [`MAX_PARTS`].
fn planar_parts(tris: &[[DVec3; 3]]) -> Option<Vec<Part>> {
    let mut order: Vec<usize> = (0..tris.len()).filter(|&i| triangle_area(&tris[i]) > DEGENERATE_AREA).collect();
    order.sort_by(|&a, &b| triangle_area(&tris[b]).total_cmp(&triangle_area(&tris[a])));
    let cos_tol = COPLANAR_ANGLE.cos();
    let mut parts: Vec<Part> = Vec::new();
    for i in order {
        let t = &tris[i];
        let n = triangle_normal(t);
        // A sliver (thinner than the coplanar distance) has a normal rounding decides: e.g. where a
        // door's edge meets its wall's edge, exactly in line in world coordinates but a few µm apart
        // once a north axis turns them. It belongs to the part its vertices lie on.
        let sliver = is_sliver(t);
        let on_plane = |p: &Part| t.iter().all(|v| (v.dot(p.normal) - p.offset).abs() <= COPLANAR_DISTANCE);
        let fits = |p: &Part| (sliver || n.dot(p.normal) >= cos_tol) && on_plane(p);
        match parts.iter().position(fits) {
            Some(k) => parts[k].triangles.push(i),
            None if parts.len() == MAX_PARTS => return None,
            None => parts.push(Part { normal: n, offset: n.dot(t[0]), triangles: vec![i] }),
        }
    }
    // Deterministic numbering: by first triangle's position in the source.
    for p in &mut parts {
        p.triangles.sort_unstable();
    }
    parts.sort_by_key(|p| p.triangles[0]);
    Some(parts)
}

/// Whether a triangle is thinner than [`COPLANAR_DISTANCE`] (its height over its longest side).
fn is_sliver(t: &[DVec3; 3]) -> bool {
    let longest = (t[1] - t[0]).length().max((t[2] - t[1]).length()).max((t[0] - t[2]).length());
    longest > 0.0 && 2.0 * triangle_area(t) / longest < COPLANAR_DISTANCE
}

fn part_name(node: &str, k: usize, count: usize) -> String {
    if count == 1 { node.to_string() } else { format!("{node}#{}", k + 1) }
}

fn no_area_error(node: &SourceNode) -> Error {
    let (file, object) = split_origin(&node.origin);
    Error::object(file, object, "receiver has zero area (all its triangles are degenerate)")
}

/// Appends a single-use node to the static mesh, in world coordinates; `by_parts`: a node that
/// does not receive is laid out by its planar parts ([`SceneBuilder::cast_by_parts`]).
fn bake_node(scene: &mut Scene, node: &SourceNode, source: &SourceMesh, veil: &NodeVeil, index: u32, by_parts: bool) -> Result<()> {
    let tris = world_tris(node, source);
    let scene_origin = scene.origin;
    if !node.receiver {
        let veils = node_veils(source, veil, index);
        let tri_veils = |i: usize| [0, 1, 2].map(|c| veils[source.indices[3 * i + c] as usize]);
        // A node that would not split as a receiver (none, or too many parts) would be refused
        // as one: it can only ever cast, so it is cast as it is.
        let parts = if by_parts { planar_parts(&tris).filter(|p| !p.is_empty()) } else { None };
        let Some(parts) = parts else {
            for (i, t) in tris.iter().enumerate() {
                push_tri(&mut scene.meshes[0], t, scene_origin, NO_RECEIVER, tri_veils(i));
            }
            return Ok(());
        };
        let mesh = &mut scene.meshes[0];
        let mut in_part = vec![false; tris.len()];
        for part in &parts {
            let start = (mesh.indices.len() / 3) as u32;
            for &i in &part.triangles {
                push_tri(mesh, &tris[i], scene_origin, NO_RECEIVER, tri_veils(i));
                in_part[i] = true;
            }
            mesh.cast_parts.push(start..(mesh.indices.len() / 3) as u32);
        }
        // Last, as a receiver's degenerate leftovers go.
        for (i, t) in tris.iter().enumerate().filter(|(i, _)| !in_part[*i]) {
            push_tri(mesh, t, scene_origin, NO_RECEIVER, tri_veils(i));
        }
        return Ok(());
    }
    let parts = planar_parts(&tris).ok_or_else(|| too_many_parts(node))?;
    if parts.is_empty() {
        return Err(no_area_error(node));
    }
    let mut in_part = vec![false; tris.len()];
    for (k, part) in parts.iter().enumerate() {
        let id = scene.receivers.len() as u32;
        let start = scene.meshes[0].indices.len() as u32;
        for &i in &part.triangles {
            push_tri(&mut scene.meshes[0], &tris[i], scene_origin, id, [Veil::OPAQUE; 3]);
            in_part[i] = true;
        }
        let end = scene.meshes[0].indices.len() as u32;
        let r = receiver(node, part, k, parts.len(), &tris, ReceiverDraw { instance: 0, indices: start..end }, scene.receivers.len());
        scene.receivers.push(r);
    }
    // Degenerate leftovers still go in (harmless), as shadow casters only.
    for (i, t) in tris.iter().enumerate() {
        if !in_part[i] {
            push_tri(&mut scene.meshes[0], t, scene_origin, NO_RECEIVER, [Veil::OPAQUE; 3]);
        }
    }
    Ok(())
}

fn receiver(node: &SourceNode, part: &Part, k: usize, count: usize, tris: &[[DVec3; 3]], draw: ReceiverDraw, id: usize) -> Receiver {
    let triangles: Vec<[DVec3; 3]> = part.triangles.iter().map(|&i| tris[i]).collect();
    Receiver {
        name: part_name(&node.name, k, count),
        origin: node.origin.clone(),
        area: triangles.iter().map(triangle_area).sum(),
        triangles,
        normal: part.normal,
        draw,
        gpu_id: id as u32,
    }
}

fn push_tri(mesh: &mut Mesh, t: &[DVec3; 3], origin: DVec3, surface: u32, veils: [Veil; 3]) {
    for (v, veil) in t.iter().zip(veils) {
        let v = *v - origin;
        mesh.indices.push(mesh.positions.len() as u32);
        mesh.positions.push([v.x as f32, v.y as f32, v.z as f32]);
        mesh.surfaces.push(surface);
        mesh.veils.push(veil);
    }
}

fn shared_mesh(label: &str, source: &SourceMesh, veil: &NodeVeil, node: u32) -> Mesh {
    Mesh {
        label: label.to_string(),
        positions: source.positions.clone(),
        surfaces: vec![NO_RECEIVER; source.positions.len()],
        indices: source.indices.clone(),
        veils: node_veils(source, veil, node),
        cast_parts: Vec::new(),
    }
}

/// Places a shared mesh. A receiving instance needs per-vertex part values in the mesh; since an
/// affine transform keeps coplanar triangles coplanar, the parts are a property of the mesh and
/// are assigned once, on the first receiving instance.
fn instance_node(scene: &mut Scene, node: &SourceNode, mesh_index: usize, index: u32) -> Result<()> {
    let instance = scene.instances.len();
    if !node.receiver {
        let leaf_shift = unit_f32(splitmix(index as u64 ^ 0x1eaf));
        scene.instances.push(Instance { mesh: mesh_index, transform: node.transform, receiver_base: NO_RECEIVER, leaf_shift });
        return Ok(());
    }
    let local = SourceMesh { positions: scene.meshes[mesh_index].positions.clone(), indices: scene.meshes[mesh_index].indices.clone() };
    let tris = world_tris(node, &local);
    let parts = planar_parts(&tris).ok_or_else(|| too_many_parts(node))?;
    if parts.is_empty() {
        return Err(no_area_error(node));
    }
    let ranges = assign_parts(&mut scene.meshes[mesh_index], &parts);
    let base = scene.receivers.len() as u32;
    for (k, part) in parts.iter().enumerate() {
        let draw = ReceiverDraw { instance, indices: ranges[k].clone() };
        let r = receiver(node, part, k, parts.len(), &tris, draw, scene.receivers.len());
        scene.receivers.push(r);
    }
    scene.instances.push(Instance { mesh: mesh_index, transform: node.transform, receiver_base: base, leaf_shift: 0.0 });
    Ok(())
}

/// Rewrites a shared mesh so each part's triangles are contiguous with their own vertices
/// carrying the part number; returns each part's index range. Idempotent for the same parts.
fn assign_parts(mesh: &mut Mesh, parts: &[Part]) -> Vec<Range<u32>> {
    let old = std::mem::take(mesh);
    let mut new = Mesh { label: old.label.clone(), ..Default::default() };
    let mut ranges = Vec::with_capacity(parts.len());
    let mut used = vec![false; old.indices.len() / 3];
    let copy_tri = |new: &mut Mesh, t: usize, surface: u32| {
        for c in 0..3 {
            let v = old.indices[3 * t + c] as usize;
            new.indices.push(new.positions.len() as u32);
            new.positions.push(old.positions[v]);
            new.surfaces.push(surface);
            new.veils.push(old.veils.get(v).copied().unwrap_or_default());
        }
    };
    for (k, part) in parts.iter().enumerate() {
        let start = new.indices.len() as u32;
        for &t in &part.triangles {
            copy_tri(&mut new, t, k as u32);
            used[t] = true;
        }
        ranges.push(start..new.indices.len() as u32);
    }
    for (t, &u) in used.iter().enumerate() {
        if !u {
            copy_tri(&mut new, t, NO_RECEIVER);
        }
    }
    *mesh = new;
    ranges
}

fn bounds(scene: &Scene) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for inst in &scene.instances {
        for p in &scene.meshes[inst.mesh].positions {
            let w = inst.transform.transform_point3(to_dvec(*p));
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    if lo.x > hi.x { (DVec3::ZERO, DVec3::ZERO) } else { (lo, hi) }
}

#[cfg(test)]
#[path = "scene_tests.rs"]
mod tests;
