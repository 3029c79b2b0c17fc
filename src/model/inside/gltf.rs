//! Rooms from a glTF (or OBJ, CityJSON) model: nodes marked interior by name are rooms, nodes
//! marked glazing are openings with glass, so a mesh model gets sun patches, maps and LEED ASE
//! as an EnergyPlus zone does.
//!
//! - **Glazing** (the loader's `glazing` patterns): each matching node is left out of the scene,
//!   so its place is an opening the beam passes, and weights the beam by its material's glass
//!   where the material's extras describe it (a curve of transmittance by angle, or simple
//!   glazing's U and SHGC: [`super::curve`]), else by one transmittance at every angle. A ray that crosses any of the node's triangles crosses
//!   its glass once: a pane modelled as a thin box is one pane, not two.
//! - **Rooms** (the `interior` patterns): each matching node is one room, named after the node:
//!   a closed shell (its window openings left as holes where the glazing nodes sit). The scene
//!   splits it into planar receivers; a shell wound outwards (a solid, as exporters write them)
//!   gets each part's back face as its inside face `PART:inside`, one wound inwards uses its
//!   parts as they are. The parts whose inside faces look up (within about 25° of the zenith)
//!   are its floors. Every glazing node may weight a room's beam: the beam is multiplied by each
//!   pane it crosses on its way out, whichever room the pane bounds.
//! - **Which room a free point is in**: the parity of the shell's crossings along a ray cast
//!   nearly straight down (the shell's holes are windows in walls, which a downward ray does not
//!   meet), so a room need not be closed at its windows.

use glam::DVec3;

use super::curve::MeshGlass;
use super::{Angular, Glazing, Room, Rooms};
use crate::error::{Error, Result};
use crate::geometry::{Plane, triangle_area, triangle_normal};
use crate::model::gltf_read::GltfModel;
use crate::scene::Scene;

/// A floor's inside face looks up within this cosine of the zenith (about 25°).
const FLOOR_COS: f64 = 0.9;
/// A shell encloses less than this share of its bounding box's volume: not a closed room.
const MIN_VOLUME_SHARE: f64 = 0.01;

/// A node picked out by name, with its triangles in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct MarkedNode {
    /// The node's name.
    pub name: String,
    /// `file: node 'name'`, as the scene's receivers say where they came from.
    pub origin: String,
    /// Its triangles, world axes (sunlit's: x east, y north, z up).
    pub triangles: Vec<[DVec3; 3]>,
    /// The glass its mesh's material describes ([`super::curve`]), if any.
    pub glass: Option<MeshGlass>,
}

/// Case-insensitive globs for the loader option `what`.
fn globs(what: &str, patterns: &[String]) -> Result<Vec<(globset::GlobMatcher, String)>> {
    patterns
        .iter()
        .map(|p| {
            let glob = globset::GlobBuilder::new(p).case_insensitive(true).build();
            glob.map(|g| (g.compile_matcher(), p.clone())).map_err(|e| Error::argument(what, format!("'{p}': {e}")))
        })
        .collect()
}

/// The nodes of `models` whose names match `patterns` (the loader option `what`), with their
/// world triangles; `take` also removes them from the models, so they are no geometry. A
/// pattern that matches no node is refused by name.
pub fn marked_nodes(models: &mut [GltfModel], what: &str, patterns: &[String], take: bool) -> Result<Vec<MarkedNode>> {
    let globs = globs(what, patterns)?;
    let mut used = vec![false; globs.len()];
    let mut out = Vec::new();
    for model in models.iter_mut() {
        let mut keep = Vec::with_capacity(model.nodes.len());
        for node in std::mem::take(&mut model.nodes) {
            let hits: Vec<usize> = (0..globs.len()).filter(|&k| globs[k].0.is_match(&node.name)).collect();
            if hits.is_empty() {
                keep.push(node);
                continue;
            }
            hits.iter().for_each(|&k| used[k] = true);
            let mesh = &model.meshes[node.mesh];
            let p = |i: u32| {
                let v = mesh.positions[i as usize];
                node.transform.transform_point3(DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
            };
            let triangles = mesh.indices.chunks_exact(3).map(|t| [p(t[0]), p(t[1]), p(t[2])]).collect();
            let glass = model.glass.get(node.mesh).cloned().flatten();
            out.push(MarkedNode { name: node.name.clone(), origin: node.origin(&model.file), triangles, glass });
            if !take {
                keep.push(node);
            }
        }
        model.nodes = keep;
    }
    if let Some(k) = used.iter().position(|u| !u) {
        return Err(Error::Unmatched { what: what.to_string(), pattern: globs[k].1.clone() });
    }
    Ok(out)
}

/// The rooms of a mesh model: `interior` nodes (receivers of `scene`, which gains their inside
/// faces) and `glazing` nodes (left out of it) letting `glass` through (0..=1), needed when there
/// is glazing.
pub fn rooms(scene: &mut Scene, interior: &[MarkedNode], glazing: &[MarkedNode], glass: Option<f64>) -> Result<Rooms> {
    if let Some(t) = glass
        && !(0.0..=1.0).contains(&t)
    {
        return Err(Error::argument("glass_transmittance", format!("{t} is outside 0..=1")));
    }
    let panes = glazing.iter().map(|node| pane(node, glass)).collect::<Result<Vec<_>>>()?;
    let every_pane: Vec<usize> = (0..panes.len()).collect();
    let mut out = Rooms { rooms: Vec::new(), glazing: panes };
    for node in interior {
        let (file, object) = node.origin.split_once(": ").unwrap_or(("", &node.origin));
        let volume = signed_volume(&node.triangles);
        // A flat mesh's box has no volume either: a cubic millimetre stands in for it.
        if volume.abs() <= MIN_VOLUME_SHARE * box_volume(&node.triangles).max(1e-9) {
            return Err(Error::object(
                file,
                object,
                "is not a closed room: its triangles enclose no volume (mark a room's whole shell interior)",
            ));
        }
        let parts: Vec<u32> = (0..scene.receivers.len() as u32).filter(|&id| scene.receivers[id as usize].origin == node.origin).collect();
        let mut room = Room {
            name: node.name.clone(),
            inside: Vec::new(),
            floors: Vec::new(),
            glazing: every_pane.clone(),
            shell: node.triangles.clone(),
            probe: DOWN,
        };
        for id in parts {
            // Wound outwards (positive volume): the inside face is the part's back face.
            let face = if volume > 0.0 {
                let name = format!("{}:inside", scene.receivers[id as usize].name);
                scene.push_mirror(id, &name)
            } else {
                id
            };
            let r = &scene.receivers[face as usize];
            if r.normal.z >= FLOOR_COS {
                room.floors.push(r.name.clone());
            }
            room.inside.push(r.name.clone());
        }
        out.rooms.push(room);
    }
    Ok(out)
}

/// Nearly straight down, tilted so it does not run along a wall or through a mesh's vertices.
const DOWN: DVec3 = DVec3::new(0.012_345, 0.016_789, -0.999_783);

/// One glazing node as a pane: crossed where any of its triangles is; its plane (for the angle
/// of incidence) is its largest triangle's. Its glass is its material's ([`super::curve`]),
/// else `glass` at every angle.
fn pane(node: &MarkedNode, glass: Option<f64>) -> Result<Glazing> {
    let (file, object) = node.origin.split_once(": ").unwrap_or(("", &node.origin));
    let (solar, visible, angular) = match (&node.glass, glass) {
        (Some(g), _) => (g.solar, g.visible, g.angular.clone()),
        (None, Some(t)) => (t, t, Angular::Normal),
        (None, None) => {
            return Err(Error::object(
                file,
                object,
                "is glazing but neither its material's extras nor the options give a transmittance: give a glass transmittance",
            ));
        }
    };
    let largest = node.triangles.iter().max_by(|a, b| triangle_area(a).total_cmp(&triangle_area(b)));
    let Some(largest) = largest.filter(|t| triangle_area(t) > 0.0) else {
        return Err(Error::object(file, object, "is glazing without area"));
    };
    let plane = Plane::through(largest[0], triangle_normal(largest));
    Ok(Glazing {
        name: node.name.clone(),
        zone: String::new(),
        vertices: Vec::new(),
        outline: Vec::new(),
        hole: Vec::new(),
        plane,
        solar,
        visible,
        angular,
        interzone: false,
        pane: node.triangles.clone(),
    })
}

/// The volume a shell encloses, positive when its triangles are wound outwards (about its
/// vertices' centre, so far-off coordinates keep their digits).
fn signed_volume(triangles: &[[DVec3; 3]]) -> f64 {
    let n = (triangles.len() * 3).max(1) as f64;
    let centre = triangles.iter().flatten().fold(DVec3::ZERO, |a, &p| a + p) / n;
    triangles.iter().map(|t| (t[0] - centre).dot((t[1] - centre).cross(t[2] - centre)) / 6.0).sum()
}

fn box_volume(triangles: &[[DVec3; 3]]) -> f64 {
    let (lo, hi) = triangles.iter().flatten().fold((DVec3::MAX, DVec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let size = (hi - lo).max(DVec3::ZERO);
    size.x * size.y * size.z
}
