//! The convex objects of a whole scene, for the fast exact engine: every placement's objects
//! ([`super::objects`], found once per mesh) indexed by triangle *position* (the culling's
//! order, in which the engine keeps its world triangles), with each object's triangles, its
//! distinct corners (less those between two others along an axis: never its hull's vertices)
//! and its open caps.
//!
//! Owns the numbering: objects are numbered in the order of their first triangle's position (the
//! order a view's walk meets them); a corner is `3 · position + k`, corner `k` of the triangle at
//! that position, so nothing here copies a point. Built once per scene; read per view.
//!
//! Also their encoding ([`PlacedObjects::to_bytes`]), so that another wasm instance over the same
//! scene (a page's clipping worker) takes them instead of grouping the scene's triangles itself:
//! grouping sets a worker's peak memory (docs/page-speed.md, "Where the memory goes"). Only
//! what cannot be derived cheaply travels: each position's object and each object's caps; the
//! per-object triangle and corner lists are rebuilt from them and the world triangles.

use std::ops::Range;

use glam::DVec3;

use super::objects::{self, MeshObjects};
use crate::error::SceneBytesError;
use crate::scene::codec::{Decoded, Reader, Writer, in_range, invalid};
use crate::scene::{NO_RECEIVER, Scene};

/// The first bytes of encoded objects.
const MAGIC: [u8; 8] = *b"SUNLITOB";
/// The encoding's version; bytes of any other version are refused.
const VERSION: u32 = 1;

/// No object: the triangle casts its own shadow.
const NO_OBJECT: u32 = u32::MAX;

/// Every placement's convex objects, by triangle position.
#[derive(Debug, Default)]
pub(crate) struct PlacedObjects {
    /// Per position: its convex object, or [`NO_OBJECT`].
    of: Vec<u32>,
    /// Per object (only convex ones are numbered): its triangle positions, a range of `triangles`.
    ranges: Vec<Range<u32>>,
    triangles: Vec<u32>,
    /// Per object: its distinct corners (bit for bit), a range of `corners`.
    corner_ranges: Vec<Range<u32>>,
    corners: Vec<u32>,
    /// Per object: its open caps, a range of `caps` (empty for a closed one; see
    /// [`objects::Convexity`]).
    cap_ranges: Vec<Range<u32>>,
    /// Per cap: its corners in order, a range of `cap_corners`.
    caps: Vec<Range<u32>>,
    cap_corners: Vec<u32>,
}

impl PlacedObjects {
    /// The objects of `scene`'s placements; `sources` gives each position's placement and mesh
    /// triangle, `triangles` its world triangle.
    pub(super) fn new(scene: &Scene, sources: &[(usize, u32)], triangles: &[[DVec3; 3]]) -> Self {
        // Objects of each mesh, in mesh coordinates; every placement has its own copies.
        let mesh_objects: Vec<MeshObjects> = scene.meshes.iter().map(mesh_objects).collect();
        let mut object_base = Vec::with_capacity(scene.instances.len());
        let mut total = 0u32;
        for inst in &scene.instances {
            object_base.push(total);
            total += mesh_objects[inst.mesh].convex.len() as u32;
        }
        let (cap_ranges, caps, cap_corners) = object_caps(scene, &mesh_objects, sources);
        let of: Vec<u32> = sources
            .iter()
            .map(|&(i, t)| {
                let objs = &mesh_objects[scene.instances[i].mesh];
                let local = objs.object_of[t as usize];
                let global = object_base[i] + local;
                let caps_known = cap_ranges[global as usize].start != UNKNOWN_CAPS;
                if objs.convex[local as usize] && caps_known { global } else { NO_OBJECT }
            })
            .collect();
        let (of, numbered) = renumber_by_position(of, total as usize);
        let cap_ranges = numbered.iter().map(|&o| cap_ranges[o as usize].clone()).collect();
        Self::assemble(of, cap_ranges, caps, cap_corners, triangles)
    }

    /// The objects from each position's object and each object's caps: their triangle and corner
    /// lists follow.
    fn assemble(of: Vec<u32>, cap_ranges: Vec<Range<u32>>, caps: Vec<Range<u32>>, cap_corners: Vec<u32>, triangles: &[[DVec3; 3]]) -> Self {
        let (ranges, object_triangles) = group_positions(&of, cap_ranges.len());
        let (corner_ranges, corners) = distinct_corners(&ranges, &object_triangles, triangles);
        Self { of, ranges, triangles: object_triangles, corner_ranges, corners, cap_ranges, caps, cap_corners }
    }

    /// The objects as bytes ([`Self::from_bytes`] reads them back): magic, version, then each
    /// position's object, each object's caps, each cap's corners and the corners, as u32 lists.
    pub(super) fn to_bytes(&self) -> Vec<u8> {
        let mut w = Writer(Vec::with_capacity(
            8 + 4 * (self.of.len() + 2 * self.cap_ranges.len() + 2 * self.caps.len() + self.cap_corners.len()) + 64,
        ));
        w.0.extend_from_slice(&MAGIC);
        w.u32(VERSION);
        w.u32s(&self.of);
        w.u32s(&flat(&self.cap_ranges));
        w.u32s(&flat(&self.caps));
        w.u32s(&self.cap_corners);
        w.0
    }

    /// The objects encoded by [`Self::to_bytes`] for the same scene, whose world triangles (in
    /// the culling's order) are `triangles`. Refuses bytes that are not such objects, another
    /// version, truncated ones, or any number past its list (so nothing read can index out of
    /// bounds); objects encoded for another scene with as many triangles are not told apart.
    pub(super) fn from_bytes(bytes: &[u8], triangles: &[[DVec3; 3]]) -> Decoded<Self> {
        let mut r = Reader::new(bytes);
        if r.take(MAGIC.len(), "magic").ok() != Some(&MAGIC[..]) {
            return Err(invalid("convex objects", "not encoded convex objects (no SUNLITOB magic)"));
        }
        let version = r.u32("version")?;
        if version != VERSION {
            return Err(SceneBytesError::Version { found: version, supported: VERSION });
        }
        let of = r.u32s("objects of triangles")?;
        let cap_ranges = ranges(r.u32s("objects' caps")?, "objects' caps")?;
        let caps = ranges(r.u32s("caps")?, "caps")?;
        let cap_corners = r.u32s("cap corners")?;
        r.end()?;
        check_objects(&of, &cap_ranges, &caps, &cap_corners, triangles.len())?;
        Ok(Self::assemble(of, cap_ranges, caps, cap_corners, triangles))
    }

    /// Objects numbered (every convex one): the size of a per-object stamp.
    pub(super) fn len(&self) -> usize {
        self.ranges.len()
    }

    /// Convex objects (those whose shadows are merged).
    pub(super) fn convex(&self) -> usize {
        self.len()
    }

    /// The convex object of the triangle at `position`, if any.
    pub(crate) fn of(&self, position: usize) -> Option<u32> {
        Some(self.of[position]).filter(|&o| o != NO_OBJECT)
    }

    /// Object `o`'s triangle positions.
    pub(super) fn triangles(&self, o: u32) -> &[u32] {
        slice(&self.triangles, &self.ranges[o as usize])
    }

    /// Object `o`'s distinct corners.
    pub(crate) fn corners(&self, o: u32) -> &[u32] {
        slice(&self.corners, &self.corner_ranges[o as usize])
    }

    /// Whether object `o` has open caps.
    pub(crate) fn has_caps(&self, o: u32) -> bool {
        !self.cap_ranges[o as usize].is_empty()
    }

    /// Object `o`'s caps, each its corners in order.
    pub(crate) fn caps(&self, o: u32) -> impl Iterator<Item = &[u32]> {
        let range = &self.cap_ranges[o as usize];
        self.caps[range.start as usize..range.end as usize].iter().map(|cap| slice(&self.cap_corners, cap))
    }
}

/// Ranges as their ends, in order.
fn flat(ranges: &[Range<u32>]) -> Vec<u32> {
    ranges.iter().flat_map(|r| [r.start, r.end]).collect()
}

/// Pairs of ends as ranges; an odd count is refused ([`flat`] writes pairs).
fn ranges(ends: Vec<u32>, what: &str) -> Decoded<Vec<Range<u32>>> {
    if ends.len() % 2 == 1 {
        return Err(invalid(what, format!("{} range ends, an odd number", ends.len())));
    }
    Ok(ends.chunks_exact(2).map(|p| p[0]..p[1]).collect())
}

/// Refuses decoded objects any of whose numbers lies past its list.
fn check_objects(of: &[u32], cap_ranges: &[Range<u32>], caps: &[Range<u32>], cap_corners: &[u32], positions: usize) -> Decoded<()> {
    if of.len() != positions {
        return Err(invalid("convex objects", format!("{} triangles, where the scene has {positions}", of.len())));
    }
    let objects = cap_ranges.len();
    if let Some(p) = of.iter().position(|&o| o != NO_OBJECT && o as usize >= objects) {
        return Err(invalid(format!("triangle {p}"), format!("object {} past the {objects} objects", of[p])));
    }
    if let Some(o) = cap_ranges.iter().position(|r| !in_range(r, caps.len())) {
        return Err(invalid(format!("object {o}"), format!("caps past the {} caps", caps.len())));
    }
    if let Some(c) = caps.iter().position(|r| !in_range(r, cap_corners.len())) {
        return Err(invalid(format!("cap {c}"), format!("corners past the {} cap corners", cap_corners.len())));
    }
    if let Some(k) = cap_corners.iter().position(|&c| c as usize >= 3 * positions) {
        return Err(invalid(format!("cap corner {k}"), format!("corner {} past the {positions} triangles' corners", cap_corners[k])));
    }
    Ok(())
}

fn slice<'a>(items: &'a [u32], range: &Range<u32>) -> &'a [u32] {
    &items[range.start as usize..range.end as usize]
}

/// Objects of one mesh: triangles grouped by shared positions, surface value and veil. A
/// shading-only triangle of one of the mesh's cast parts ([`crate::scene::Mesh::cast_parts`])
/// takes its part as its surface value, so a city surface is grouped alike whether it receives
/// or not (parts count down from below `NO_RECEIVER`, receivers up from 0: they never meet).
fn mesh_objects(mesh: &crate::scene::Mesh) -> MeshObjects {
    let tris: Vec<[[f32; 3]; 3]> = mesh.indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| mesh.positions[t[k] as usize])).collect();
    let part_of = cast_part_of_triangles(mesh);
    let keys: Vec<u64> = mesh
        .indices
        .chunks_exact(3)
        .zip(&part_of)
        .map(|(t, &part)| {
            let v = t[0] as usize;
            let veil = mesh.veils.get(v).copied().unwrap_or_default();
            let surface = match mesh.surfaces[v] {
                NO_RECEIVER => part,
                receiver => receiver,
            } as u64;
            // Surface, leaf rank and whether see-through: an object shares all three.
            (surface << 32) ^ (veil.rank.to_bits() as u64).rotate_left(7) ^ ((veil.transmittance > 0.0) as u64) << 63
        })
        .collect();
    objects::group(&tris, &keys)
}

/// Per triangle of `mesh`: `NO_RECEIVER - 1 - k` inside its cast part `k`, else `NO_RECEIVER`.
fn cast_part_of_triangles(mesh: &crate::scene::Mesh) -> Vec<u32> {
    let mut part_of = vec![NO_RECEIVER; mesh.indices.len() / 3];
    for (k, range) in mesh.cast_parts.iter().enumerate() {
        let part = NO_RECEIVER.saturating_sub(1).saturating_sub(k as u32);
        // The builder keeps ranges within the mesh; a decoded scene is checked for it.
        if let Some(slots) = part_of.get_mut(range.start as usize..range.end as usize) {
            slots.fill(part);
        }
    }
    part_of
}

/// Marks an object whose caps could not be placed (a cap corner's triangle is not indexed): it
/// is not used as convex.
const UNKNOWN_CAPS: u32 = u32::MAX;

/// Per object of every placement (placement by placement, as numbered before
/// [`renumber_by_position`]): its caps as a range of
/// the second list, each cap a range of the third, each corner `3 · position + corner` of a
/// triangle at that position of `sources`.
fn object_caps(scene: &Scene, mesh_objects: &[MeshObjects], sources: &[(usize, u32)]) -> (Vec<Range<u32>>, Vec<Range<u32>>, Vec<u32>) {
    // Where each placement's mesh triangles went.
    let mut first_of_instance = Vec::with_capacity(scene.instances.len() + 1);
    first_of_instance.push(0usize);
    for inst in &scene.instances {
        let last = first_of_instance.last().copied().unwrap_or(0);
        first_of_instance.push(last + scene.meshes[inst.mesh].indices.len() / 3);
    }
    let mut position = vec![u32::MAX; first_of_instance.last().copied().unwrap_or(0)];
    for (p, &(i, t)) in sources.iter().enumerate() {
        position[first_of_instance[i] + t as usize] = p as u32;
    }
    let (mut object_caps, mut caps, mut corners) = (Vec::new(), Vec::new(), Vec::new());
    for (i, inst) in scene.instances.iter().enumerate() {
        let objs = &mesh_objects[inst.mesh];
        for range in &objs.cap_ranges {
            let (first_cap, first_corner) = (caps.len(), corners.len());
            for cap in &objs.caps[range.start as usize..range.end as usize] {
                let start = corners.len() as u32;
                for &(t, k) in &objs.cap_corners[cap.start as usize..cap.end as usize] {
                    corners.push(position[first_of_instance[i] + t as usize].saturating_mul(3).saturating_add(u32::from(k)));
                }
                caps.push(start..corners.len() as u32);
            }
            if corners[first_corner..].iter().any(|&c| c >= u32::MAX - 2) {
                caps.truncate(first_cap);
                corners.truncate(first_corner);
                object_caps.push(UNKNOWN_CAPS..UNKNOWN_CAPS);
            } else {
                object_caps.push(first_cap as u32..caps.len() as u32);
            }
        }
    }
    (object_caps, caps, corners)
}

/// Per convex object its distinct corners (world positions equal bit for bit are one), as a
/// range of the second list, each `3 · position + corner` of a triangle holding it.
fn distinct_corners(objects: &[Range<u32>], object_triangles: &[u32], triangles: &[[DVec3; 3]]) -> (Vec<Range<u32>>, Vec<u32>) {
    let mut ranges = Vec::with_capacity(objects.len());
    let mut corners = Vec::new();
    let mut keyed: Vec<([u64; 3], u32)> = Vec::new();
    for range in objects {
        keyed.clear();
        for &p in &object_triangles[range.start as usize..range.end as usize] {
            for (k, q) in triangles[p as usize].iter().enumerate() {
                keyed.push((q.to_array().map(f64::to_bits), 3 * p + k as u32));
            }
        }
        keyed.sort_unstable();
        keyed.dedup_by_key(|(bits, _)| *bits);
        if keyed.len() > FEW_CORNERS {
            drop_inner_corners(&mut keyed);
        }
        let start = corners.len() as u32;
        corners.extend(keyed.iter().map(|(_, c)| *c));
        ranges.push(start..corners.len() as u32);
    }
    (ranges, corners)
}

/// Objects with more distinct corners than this are thinned ([`drop_inner_corners`]): a box or
/// a rod has fewer, and none between two others.
const FEW_CORNERS: usize = 16;

/// Leaves out of a convex object's corners (keyed by their bits, as [`distinct_corners`] has
/// them) each one lying strictly between two others on a line along a coordinate axis: its
/// other two coordinates equal theirs bit for bit, its third between theirs. Such a corner is
/// exactly a convex combination of the two, so never a vertex of the object's hull, and every
/// vertex of the hull is kept: the hull, and so every shadow, footprint and bound taken from
/// the corners, is the same set (up to rounding: a projected corner on an edge can land a hair
/// off it, where a hull of every corner may keep it; on nyt-blocks' floor 20 two values of
/// 840,960 moved by 3e-8). A panelled block of nyt-blocks has up to 4,096 corners on its
/// faces' grid lines and 8 vertices; every view that reaches it projected and sorted them all.
/// Corners off such lines (a rotated block) stay; so do all where one is not finite.
fn drop_inner_corners(keyed: &mut Vec<([u64; 3], u32)>) {
    if keyed.iter().any(|(bits, _)| bits.iter().any(|b| !f64::from_bits(*b).is_finite())) {
        return;
    }
    let mut inner = vec![false; keyed.len()];
    let mut order: Vec<usize> = (0..keyed.len()).collect();
    for axis in 0..3 {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let line = |i: usize| (keyed[i].0[a], keyed[i].0[b]);
        let along = |i: usize| f64::from_bits(keyed[i].0[axis]);
        order.sort_unstable_by(|&i, &j| line(i).cmp(&line(j)).then(along(i).total_cmp(&along(j))));
        // Within each run of one line, all but its first and last lie between them.
        for run in order.chunk_by(|&i, &j| line(i) == line(j)) {
            if let [_, middle @ .., _] = run {
                middle.iter().for_each(|&i| inner[i] = true);
            }
        }
    }
    let mut flags = inner.iter();
    keyed.retain(|_| !flags.next().copied().unwrap_or(false));
}

/// Numbers the objects in the order their first triangles come by position, as a view's walk
/// meets them, so that what a view reads per object (its stamp, corners, caps) lies close
/// together instead of across the whole scene (1.1× faster on a canopy's sky views); returns the
/// new object of each position and, per new number, the old one (of `objects`). Objects that no
/// position names (not convex) lose their number.
fn renumber_by_position(of: Vec<u32>, objects: usize) -> (Vec<u32>, Vec<u32>) {
    let mut new_of_old = vec![NO_OBJECT; objects];
    let mut numbered = Vec::new();
    let of = of
        .into_iter()
        .map(|o| {
            // `NO_OBJECT` (not convex) lies beyond every number and stays as it is.
            let Some(new) = new_of_old.get_mut(o as usize) else { return NO_OBJECT };
            if *new == NO_OBJECT {
                *new = numbered.len() as u32;
                numbered.push(o);
            }
            *new
        })
        .collect();
    (of, numbered)
}

/// Per convex object its triangle positions (counting sort by object).
fn group_positions(object: &[u32], objects: usize) -> (Vec<Range<u32>>, Vec<u32>) {
    let mut count = vec![0u32; objects + 1];
    for &o in object.iter().filter(|&&o| o != NO_OBJECT) {
        count[o as usize + 1] += 1;
    }
    for k in 0..objects {
        count[k + 1] += count[k];
    }
    let ranges: Vec<Range<u32>> = (0..objects).map(|k| count[k]..count[k + 1]).collect();
    let mut next: Vec<u32> = count[..objects].to_vec();
    let mut out = vec![0u32; count[objects] as usize];
    for (p, &o) in object.iter().enumerate().filter(|(_, o)| **o != NO_OBJECT) {
        out[next[o as usize] as usize] = p as u32;
        next[o as usize] += 1;
    }
    (ranges, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keyed(points: &[[f64; 3]]) -> Vec<([u64; 3], u32)> {
        let mut k: Vec<([u64; 3], u32)> = points.iter().enumerate().map(|(i, p)| (p.map(f64::to_bits), i as u32)).collect();
        k.sort_unstable();
        k
    }

    #[test]
    fn only_corners_between_two_others_along_an_axis_go() {
        // A square's corners, a point on each edge, one inside: the four corners stay.
        let mut square = keyed(&[
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ]);
        drop_inner_corners(&mut square);
        assert_eq!(square.len(), 4);
        assert!(square.iter().all(|k| k.1 < 4), "{square:?}");
        // A point on a diagonal (no two coordinates shared) stays, though it is inside.
        let mut diagonal = keyed(&[[0.0, 0.0, 0.0], [2.0, 2.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0]]);
        drop_inner_corners(&mut diagonal);
        assert_eq!(diagonal.len(), 4);
        // Coordinates one ulp apart are not one line: nothing goes.
        let off = f64::from_bits(1.0f64.to_bits() + 1);
        let mut apart = keyed(&[[0.0, 1.0, 0.0], [1.0, off, 0.0], [2.0, 1.0, 0.0]]);
        drop_inner_corners(&mut apart);
        assert_eq!(apart.len(), 3);
        // A corner not finite: nothing goes.
        let mut broken = keyed(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [f64::NAN, 5.0, 0.0]]);
        drop_inner_corners(&mut broken);
        assert_eq!(broken.len(), 4);
    }
}
