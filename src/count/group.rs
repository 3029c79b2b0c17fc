//! View groups: receivers that one sun view can count together.
//!
//! A window or door is a hole in its wall: coplanar with it, inside the wall's outline, and the
//! annual sampler asks for both at the very same sun vectors (sample times depend only on the
//! normal). One tile fitted to the wall shows the window too, so everything in front of the
//! facade is drawn once instead of once per receiver; the mask pass writes each member's id and
//! the count shader counts each member apart.
//!
//! A group is found once per uploaded scene:
//! - its *owner* is the receiver with the largest outline (bounding rectangle in its plane: a
//!   wall's, not its net area, which can be smaller than its window's); members are receivers on
//!   the owner's plane (the scene's coplanar tolerances, same facing) whose bounding rectangle in
//!   that plane lies inside the owner's, with a small tolerance;
//! - members must not overlap (each pixel of the mask holds one id) and must carry distinct GPU
//!   ids; a window drawn over an unholed wall stays on its own;
//! - a member must cover at least [`MIN_MEMBER_SHARE`] of the owner's rectangle: in the owner's
//!   tile it gets that share of the pixels, and a tiny window would lose its accuracy;
//! - at most [`MAX_MEMBERS`] members a group.
//!
//! Receivers not grouped are groups of one, counted exactly as before.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::geometry;
use crate::scene::{COPLANAR_ANGLE, COPLANAR_DISTANCE, Receiver, Scene};

/// Most receivers one tile counts (the count shader's `MAX_MEMBERS`). The count shader keeps
/// private counts per member and reduces them in workgroup memory (2 × 4 × 64 words), the mask
/// pass draws each member, and members are disjoint with at least [`MIN_MEMBER_SHARE`] of the
/// outline each, so more would hardly fit anyway. A wall with more windows keeps the first
/// ones; the others are counted in views of their own.
pub const MAX_MEMBERS: usize = 4;

/// Smallest share of the owner's in-plane bounding rectangle a member may cover. In the owner's
/// tile a member gets about this share of the pixels it would get in a view of its own, and its
/// pixel noise grows about as 1/√share: at a quarter it at most doubles. On the Blaas-like
/// model (windows 13% of their wall's outline) 1/16 let windows drop from ~12,000 to ~1,000
/// pixels at 128², and the worst error against the exact reference went from 0.007 to 0.026;
/// the NYT-like facades' windows (55%) stay well inside.
pub const MIN_MEMBER_SHARE: f64 = 0.25;

/// How far (m) a member's rectangle may stick out of the owner's: rounding of f32 vertices.
const CONTAIN_TOLERANCE: f64 = COPLANAR_DISTANCE;

/// Overlap (m, along the separating axis) below which two members' triangles count as touching,
/// not overlapping: a window shares its edges with the wall's hole.
const OVERLAP_TOLERANCE: f64 = 1e-4;

/// Normal quantisation for the candidate search: cells of 1/64 are wider than the coplanar
/// angle's normal difference (2·sin(0.25°) ≈ 0.009), so a cell and its neighbours hold every
/// normal within it.
const NORMAL_CELLS: f64 = 64.0;

/// The scene's view groups.
#[derive(Debug, Clone, Default)]
pub struct ViewGroups {
    /// Receiver → (its group, its rank in the group: 0 for the owner).
    place: Vec<(u32, u32)>,
    /// Group → its receivers, the owner (largest outline) first.
    members: Vec<Vec<u32>>,
}

/// A receiver's plane and in-plane frame.
struct Plane {
    /// Through the receiver's first vertex; flat coordinates are relative to it.
    plane: geometry::Plane,
    offset: f64,
}

impl Plane {
    fn of(r: &Receiver) -> Option<Self> {
        let p0 = *r.triangles.first()?.first()?;
        let normal = r.normal.try_normalize()?;
        Some(Self { plane: geometry::Plane::through(p0, normal), offset: normal.dot(p0) })
    }

    fn normal(&self) -> DVec3 {
        self.plane.normal
    }

    fn flat(&self, p: DVec3) -> DVec2 {
        self.plane.project(p)
    }

    fn rectangle(&self, r: &Receiver) -> (DVec2, DVec2) {
        r.triangles.iter().flatten().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), p| (lo.min(self.flat(*p)), hi.max(self.flat(*p))))
    }

    fn flat_triangles(&self, r: &Receiver) -> Vec<[DVec2; 3]> {
        r.triangles.iter().map(|t| t.map(|p| self.flat(p))).collect()
    }

    /// Whether every vertex of `r` lies on this plane and `r` faces the same way.
    fn holds(&self, r: &Receiver) -> bool {
        r.normal.dot(self.normal()) >= COPLANAR_ANGLE.cos()
            && r.triangles.iter().flatten().all(|p| (p.dot(self.normal()) - self.offset).abs() <= COPLANAR_DISTANCE)
    }
}

impl ViewGroups {
    /// Every receiver on its own.
    pub fn singletons(receivers: usize) -> Self {
        Self { place: (0..receivers as u32).map(|r| (r, 0)).collect(), members: (0..receivers as u32).map(|r| vec![r]).collect() }
    }

    /// Finds the groups of a scene: largest outlines first, each taking the unclaimed receivers
    /// on its plane and inside its outline (see the module docs).
    pub fn find(scene: &Scene) -> Self {
        Self::find_with(scene, MIN_MEMBER_SHARE)
    }

    /// [`Self::find`] with another smallest member share (tests).
    fn find_with(scene: &Scene, min_share: f64) -> Self {
        let receivers = &scene.receivers;
        let planes: Vec<Option<Plane>> = receivers.iter().map(Plane::of).collect();
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, plane) in planes.iter().enumerate() {
            if let Some(p) = plane {
                cells.entry(cell(p.normal())).or_default().push(i as u32);
            }
        }
        let outline: Vec<f64> = receivers
            .iter()
            .zip(&planes)
            .map(|(r, p)| {
                p.as_ref().map_or(0.0, |p| {
                    let (lo, hi) = p.rectangle(r);
                    (hi - lo).x * (hi - lo).y
                })
            })
            .collect();
        let mut order: Vec<u32> = (0..receivers.len() as u32).collect();
        order.sort_by(|&a, &b| outline[b as usize].total_cmp(&outline[a as usize]).then(a.cmp(&b)));
        let mut claimed = vec![false; receivers.len()];
        let mut groups = Self { place: vec![(0, 0); receivers.len()], members: Vec::new() };
        for owner in order {
            if claimed[owner as usize] {
                continue;
            }
            claimed[owner as usize] = true;
            let members = match &planes[owner as usize] {
                Some(plane) => gather(receivers, plane, owner, &neighbours(&cells, plane.normal()), min_share, &mut claimed),
                None => vec![owner],
            };
            let g = groups.members.len() as u32;
            for (rank, &m) in members.iter().enumerate() {
                groups.place[m as usize] = (g, rank as u32);
            }
            groups.members.push(members);
        }
        groups
    }

    /// The group of `receiver` and its rank there (0: the owner, the largest outline).
    pub fn place(&self, receiver: u32) -> (u32, u32) {
        self.place[receiver as usize]
    }

    /// The receivers of group `g`, the owner first.
    pub fn members(&self, g: u32) -> &[u32] {
        &self.members[g as usize]
    }

    /// Number of groups (singletons included).
    pub fn len(&self) -> usize {
        self.members.len()
    }

    /// Whether there are no groups (no receivers).
    pub fn is_empty(&self) -> bool {
        self.members.is_empty()
    }

    /// The groups of more than one receiver.
    pub fn shared(&self) -> impl Iterator<Item = &[u32]> {
        self.members.iter().filter(|m| m.len() > 1).map(|m| m.as_slice())
    }
}

fn cell(normal: DVec3) -> [i64; 3] {
    (normal * NORMAL_CELLS).round().as_i64vec3().to_array()
}

/// Receivers whose normal lies in the cell of `normal` or a neighbouring one, in id order.
fn neighbours(cells: &HashMap<[i64; 3], Vec<u32>>, normal: DVec3) -> Vec<u32> {
    let [x, y, z] = cell(normal);
    let mut out: Vec<u32> = Vec::new();
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                if let Some(list) = cells.get(&[x + dx, y + dy, z + dz]) {
                    out.extend(list);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

/// The owner and the unclaimed candidates that can share its view, claiming them.
fn gather(receivers: &[Receiver], plane: &Plane, owner: u32, candidates: &[u32], min_share: f64, claimed: &mut [bool]) -> Vec<u32> {
    let own = &receivers[owner as usize];
    let (lo, hi) = plane.rectangle(own);
    let (lo, hi) = (lo - CONTAIN_TOLERANCE, hi + CONTAIN_TOLERANCE);
    let min_area = min_share * (hi - lo).x * (hi - lo).y;
    let mut members = vec![owner];
    let mut shapes = vec![plane.flat_triangles(own)];
    for &c in candidates {
        if members.len() == MAX_MEMBERS {
            break;
        }
        let r = &receivers[c as usize];
        if claimed[c as usize] || r.area < min_area || !plane.holds(r) {
            continue;
        }
        let (a, b) = plane.rectangle(r);
        let inside = a.x >= lo.x && a.y >= lo.y && b.x <= hi.x && b.y <= hi.y;
        if !inside || members.iter().any(|&m| receivers[m as usize].gpu_id == r.gpu_id) {
            continue;
        }
        let shape = plane.flat_triangles(r);
        if shapes.iter().any(|s| overlaps(s, &shape)) {
            continue;
        }
        claimed[c as usize] = true;
        members.push(c);
        shapes.push(shape);
    }
    members
}

/// Whether two sets of in-plane triangles overlap by more than [`OVERLAP_TOLERANCE`].
fn overlaps(a: &[[DVec2; 3]], b: &[[DVec2; 3]]) -> bool {
    a.iter().any(|s| b.iter().any(|t| triangles_overlap(s, t)))
}

/// Separating-axis test: two triangles overlap unless an edge normal of either separates them
/// (or leaves them less than the tolerance deep in each other).
fn triangles_overlap(a: &[DVec2; 3], b: &[DVec2; 3]) -> bool {
    for tri in [a, b] {
        for i in 0..3 {
            let Some(axis) = (tri[(i + 1) % 3] - tri[i]).perp().try_normalize() else { continue };
            let span = |t: &[DVec2; 3]| t.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.dot(axis)), hi.max(p.dot(axis))));
            let ((a0, a1), (b0, b1)) = (span(a), span(b));
            if a1.min(b1) - a0.max(b0) <= OVERLAP_TOLERANCE {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SceneBuilder, SourceMesh};

    /// A rectangle in the plane y = `y` (facing −y, south), x0..x1 × z0..z1.
    fn south(x0: f32, x1: f32, z0: f32, z1: f32, y: f32) -> SourceMesh {
        SourceMesh { positions: vec![[x0, y, z0], [x1, y, z0], [x1, y, z1], [x0, y, z1]], indices: vec![0, 1, 2, 0, 2, 3] }
    }

    /// A 4 × 3 south wall (x 10..14, z 0..3) at y = 0 with a 3 × 2 hole (x 10.5..13.5, z 0.5..2.5).
    fn holed_wall() -> SourceMesh {
        SourceMesh {
            positions: [(10., 0.), (14., 0.), (14., 3.), (10., 3.), (10.5, 0.5), (13.5, 0.5), (13.5, 2.5), (10.5, 2.5)]
                .iter()
                .map(|&(x, z)| [x as f32, 0.0, z as f32])
                .collect(),
            indices: vec![0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7],
        }
    }

    fn names(scene: &Scene, groups: &ViewGroups) -> Vec<Vec<String>> {
        groups.shared().map(|m| m.iter().map(|&r| scene.receivers[r as usize].name.clone()).collect()).collect()
    }

    #[test]
    fn a_wall_and_its_windows_share_a_view() {
        let mut b = SceneBuilder::new();
        b.add_object("t", "WIN", south(10.5, 13.5, 0.5, 2.5, 0.0), true);
        b.add_object("t", "WALL", holed_wall(), true);
        // Parallel, 0.5 m in front: not coplanar.
        b.add_object("t", "SCREEN", south(10.5, 13.5, 0.5, 2.5, -0.5), true);
        // Coplanar but beside the wall: not inside its outline.
        b.add_object("t", "NEXT", south(14.0, 16.0, 0.0, 3.0, 0.0), true);
        // Coplanar, inside, but facing the other way (the wall's back).
        let mut back = south(10.5, 13.5, 0.5, 2.5, 0.0);
        back.indices = vec![0, 2, 1, 0, 3, 2];
        b.add_object("t", "BACK", back, true);
        let scene = b.build().unwrap();
        let groups = ViewGroups::find(&scene);
        assert_eq!(names(&scene, &groups), vec![vec!["WALL".to_string(), "WIN".to_string()]]);
        assert_eq!(groups.len(), scene.receivers.len() - 1);
        let (wall, _) = scene.receiver("WALL").unwrap();
        let (win, _) = scene.receiver("WIN").unwrap();
        assert_eq!(groups.place(wall).1, 0, "the largest member owns the view");
        assert_eq!(groups.place(win), (groups.place(wall).0, 1));
    }

    #[test]
    fn a_frame_wall_owns_the_window_that_outweighs_it() {
        // A 3 × 3 wall with a 2.6 × 2.6 hole: the window has three times the wall's net area,
        // but the wall's outline holds it, so the wall owns the view.
        let frame = SourceMesh {
            positions: [(0., 0.), (3., 0.), (3., 3.), (0., 3.), (0.2, 0.2), (2.8, 0.2), (2.8, 2.8), (0.2, 2.8)]
                .iter()
                .map(|&(x, z)| [x as f32, 0.0, z as f32])
                .collect(),
            indices: vec![0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7],
        };
        let mut b = SceneBuilder::new();
        b.add_object("t", "GLASS", south(0.2, 2.8, 0.2, 2.8, 0.0), true);
        b.add_object("t", "FRAME", frame, true);
        let scene = b.build().unwrap();
        assert_eq!(names(&scene, &ViewGroups::find(&scene)), vec![vec!["FRAME".to_string(), "GLASS".to_string()]]);
    }

    #[test]
    fn side_by_side_overlapping_and_tiny_receivers_stay_alone() {
        let mut b = SceneBuilder::new();
        // Two coplanar walls side by side, each outside the other's outline.
        b.add_object("t", "LEFT", south(0.0, 4.0, 0.0, 3.0, 0.0), true);
        b.add_object("t", "RIGHT", south(4.0, 8.0, 0.0, 3.0, 0.0), true);
        // A window drawn over the left wall without a hole: they overlap.
        b.add_object("t", "PAINTED", south(1.0, 3.0, 1.0, 2.0, 0.0), true);
        // A 0.1 m² vent on the right wall: too small to share its view (and not in a hole).
        b.add_object("t", "VENT", south(5.0, 5.1, 1.0, 2.0, 0.0), true);
        let scene = b.build().unwrap();
        let groups = ViewGroups::find(&scene);
        assert_eq!(names(&scene, &groups), Vec::<Vec<String>>::new());
        assert_eq!(groups.len(), scene.receivers.len());
    }

    #[test]
    fn a_group_holds_at_most_max_members() {
        // A 15.3 m × 3 m wall with ten 1.2 × 2.7 m windows in holes (0.3 m mullions), each 7% of
        // the wall's outline: none share its view; at a 5% share, the wall and the first
        // MAX_MEMBERS − 1 windows do, and the other windows, side by side, stay alone.
        let mut b = SceneBuilder::new();
        let mut wall = SourceMesh::default();
        let quad = |m: &mut SourceMesh, x0: f32, x1: f32, z0: f32, z1: f32| {
            let s = south(x0, x1, z0, z1, 0.0);
            m.indices.extend(s.indices.iter().map(|i| i + m.positions.len() as u32));
            m.positions.extend(s.positions);
        };
        quad(&mut wall, 0.0, 15.3, 0.0, 0.15);
        quad(&mut wall, 0.0, 15.3, 2.85, 3.0);
        for k in 0..=10 {
            let x = 1.5 * k as f32;
            quad(&mut wall, x, x + 0.3, 0.15, 2.85);
        }
        b.add_object("t", "WALL", wall, true);
        for k in 0..10 {
            let x = 1.5 * k as f32 + 0.3;
            b.add_object("t", &format!("WIN{k}"), south(x, x + 1.2, 0.15, 2.85, 0.0), true);
        }
        let scene = b.build().unwrap();
        assert_eq!(ViewGroups::find(&scene).shared().count(), 0);
        let groups = ViewGroups::find_with(&scene, 0.05);
        let shared: Vec<&[u32]> = groups.shared().collect();
        assert_eq!(shared.len(), 1);
        assert_eq!(shared[0].len(), MAX_MEMBERS);
        assert_eq!(groups.len(), 1 + 10 - (MAX_MEMBERS - 1));
    }

    #[test]
    fn separating_axes() {
        let t = |p: [(f64, f64); 3]| p.map(|(x, y)| DVec2::new(x, y));
        let a = t([(0., 0.), (1., 0.), (0., 1.)]);
        assert!(triangles_overlap(&a, &t([(0.2, 0.2), (0.6, 0.2), (0.2, 0.6)])));
        // Sharing the hypotenuse only.
        assert!(!triangles_overlap(&a, &t([(1., 0.), (1., 1.), (0., 1.)])));
        assert!(!triangles_overlap(&a, &t([(2., 0.), (3., 0.), (2., 1.)])));
    }
}
