//! The exact CPU reference for sunlit fractions: polygon clipping, no pixels.
//!
//! Owns the truth that the GPU pixel counter ([`super::gpu`]) is tested against. It is slow
//! compared with the GPU (every receiver looks at every triangle) but has no resolution error,
//! so tests can hold the counter to a tolerance that only depends on its pixel size.
//!
//! Algorithm, for receiver `r` (unit outward normal `n`, a vertex `p0`) and sun direction `s`:
//! 1. if the surface faces away from the sun or the sun is down ([`is_dark`]), the fraction is 0;
//! 2. an orthonormal basis `(e1, e2)` of the receiver plane, right-handed with `n`, maps the
//!    plane to 2D so that counter-clockwise about `n` stays counter-clockwise;
//! 3. every world triangle that is not part of `r` is clipped to the half-space in front of the
//!    plane (`h(p) = n·(p − p0) > 0`, heights within a tiny `eps` of the plane count as on it),
//!    so geometry behind or coplanar with the receiver never shades it; what is left is projected
//!    along the sun onto the plane (`q = p − s·h(p)/(n·s)`) and clipped to a box slightly larger
//!    than the receiver (outside it a shadow changes nothing);
//! 4. the sunlit part is `receiver − ∪ shadows`, one boolean operation with i_overlay (non-zero
//!    fill, all contours counter-clockwise, 64-bit integer grid), and the fraction is its area
//!    over the area of the union of the receiver's triangles.
//!
//! Foliage: a leaf casts a shadow when its rank is below the request's leaf fraction, the same
//! f32 test the GPU makes, so both see the same leaves. See-through casters count as opaque here
//! (the reference has no transmittance).
//!
//! Point queries ([`rays`]) test points against the same shadows the fast engine casts.
//!
//! Degenerate cases: an unknown receiver id, a non-finite sun vector or a receiver without area
//! give 0 (nothing can be lit); a receiver that nothing shades gives exactly 1.

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use i_overlay::core::extract::BooleanExtractionBuffer;
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::overlay::FloatOverlay;

use super::{Engine, ViewAnswer, ViewRequest, check_receivers, cos_incidence, is_dark};
use crate::error::Result;
use crate::scene::{Receiver, Scene};

mod boundary;
pub mod engine;
mod objects;
pub(crate) mod placed;
pub mod rays;
mod reach;

/// A closed 2D polygon as i_overlay takes and returns it (no repeated first point).
type Contour = Vec<[f64; 2]>;

/// Heights above the plane within this many scene extents count as on the plane.
const PLANE_EPS: f64 = 1e-9;
/// Projected shadows with less area than this many squared scene extents are dropped.
const AREA_EPS: f64 = 1e-15;
/// The box shadows are clipped to exceeds the receiver's by this part of its size.
const WINDOW_MARGIN: f64 = 0.01;

/// Sunlit fraction of one receiver for one sun direction (at the request's leaf fraction), by
/// exact polygon clipping.
pub fn sunlit_fraction(scene: &Scene, request: ViewRequest) -> f64 {
    Casters::new(scene, request.leaves).fraction(scene, request)
}

/// Many at once, each at its own leaf fraction; the world triangles are collected once per
/// distinct leaf fraction.
pub fn sunlit_fractions(scene: &Scene, requests: &[ViewRequest]) -> Vec<f64> {
    let mut casters: HashMap<u32, Casters> = HashMap::new();
    requests
        .iter()
        .map(|&request| {
            casters.entry(request.leaves.to_bits()).or_insert_with(|| Casters::new(scene, request.leaves)).fraction(scene, request)
        })
        .collect()
}

/// The exact reference as an [`Engine`]: answers every view of its scene by polygon clipping.
#[derive(Clone, Copy)]
pub struct Exact<'a> {
    /// The scene the views are of.
    pub scene: &'a Scene,
}

/// Views the exact reference answers per call of [`Engine::answer`] when a caller chunks: a few
/// seconds of clipping on a large scene, so progress and cancellation stay responsive.
const EXACT_BATCH: usize = 64;

impl Engine for Exact<'_> {
    fn batch(&self) -> usize {
        EXACT_BATCH
    }

    async fn answer(&self, requests: &[ViewRequest]) -> Result<Vec<ViewAnswer>> {
        check_receivers(self.scene.receivers.len(), requests)?;
        let fractions = sunlit_fractions(self.scene, requests);
        Ok(requests
            .iter()
            .zip(fractions)
            .map(|(request, fraction)| ViewAnswer {
                fraction,
                cos_incidence: cos_incidence(self.scene.receivers[request.receiver as usize].normal, request.sun),
                error_estimate: Some(0.0),
                ..Default::default()
            })
            .collect())
    }
}

/// The scene's world triangles, collected once, with the tolerances that fit the scene's size.
struct Casters {
    /// World triangle and the receiver it belongs to, if any.
    triangles: Vec<([DVec3; 3], Option<u32>)>,
    /// Distance (m) within which a point counts as on a receiver plane.
    eps: f64,
    /// Area (m²) below which a projected shadow is noise.
    area_eps: f64,
}

impl Casters {
    fn new(scene: &Scene, leaves: f32) -> Self {
        let extent = (scene.bounds.1 - scene.bounds.0).length();
        let scale = if extent.is_finite() { 1.0 + extent } else { 1.0 };
        let triangles = scene.veiled_triangles().filter(|(_, _, veil)| veil.present(0.0, leaves)).map(|(t, id, _)| (t, id)).collect();
        Self { triangles, eps: PLANE_EPS * scale, area_eps: AREA_EPS * scale * scale }
    }

    fn fraction(&self, scene: &Scene, request: ViewRequest) -> f64 {
        let sun = request.sun;
        let Some(receiver) = scene.receivers.get(request.receiver as usize) else { return 0.0 };
        if !sun.is_finite() || is_dark(receiver.normal, sun) {
            return 0.0;
        }
        let Some(frame) = PlaneFrame::new(receiver, sun, self.eps) else { return 0.0 };
        let lit: Vec<Contour> = receiver.triangles.iter().filter_map(|t| frame.receiver_contour(t)).collect();
        let Some(bounds) = Rect::around(lit.iter().flatten().map(|&[x, y]| DVec2::new(x, y))) else { return 0.0 };
        let window = bounds.expanded(WINDOW_MARGIN * bounds.size().length() + self.eps);
        let shadows: Vec<Contour> = self
            .triangles
            .iter()
            .filter(|(_, id)| *id != Some(receiver.gpu_id))
            .filter_map(|(tri, _)| frame.shadow(tri, &bounds, &window, self.area_eps))
            .collect();
        sunlit_ratio(&lit, &shadows, self.area_eps)
    }
}

/// The receiver plane as a 2D frame, plus the sun's projection onto it.
struct PlaneFrame {
    origin: DVec3,
    normal: DVec3,
    e1: DVec3,
    e2: DVec3,
    /// 2D displacement of a point's projection per metre of height above the plane:
    /// `−(s·e1, s·e2)/(n·s)`.
    shift_per_height: DVec2,
    eps: f64,
}

impl PlaneFrame {
    /// `None` for a receiver without triangles or normal (cannot come out of `SceneBuilder`).
    fn new(receiver: &Receiver, sun: DVec3, eps: f64) -> Option<Self> {
        let origin = receiver.triangles.first()?[0];
        let normal = receiver.normal.normalize_or_zero();
        if normal == DVec3::ZERO {
            return None;
        }
        let e1 = normal.any_orthonormal_vector();
        // e1 × e2 = n: counter-clockwise about the outward normal is counter-clockwise in 2D.
        let e2 = normal.cross(e1);
        // n·s > MIN_COS_INCIDENCE here (not dark), so the division is safe.
        let shift_per_height = -DVec2::new(sun.dot(e1), sun.dot(e2)) / normal.dot(sun);
        Some(Self { origin, normal, e1, e2, shift_per_height, eps })
    }

    /// Height above the plane; within `eps` of it counts as exactly on it, so geometry touching
    /// the receiver (an overhang at the top of a window) is clipped where it touches, not `eps`
    /// away, and coplanar geometry is recognised despite rounding.
    fn height(&self, p: DVec3) -> f64 {
        let h = self.normal.dot(p - self.origin);
        if h.abs() <= self.eps { 0.0 } else { h }
    }

    /// Orthogonal projection into plane coordinates.
    fn to_2d(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.e1), d.dot(self.e2))
    }

    /// Where the sun ray through `p` meets the plane, in plane coordinates.
    fn project_along_sun(&self, p: DVec3) -> DVec2 {
        self.to_2d(p) + self.shift_per_height * self.height(p)
    }

    /// One receiver triangle in 2D, counter-clockwise; `None` if not finite.
    fn receiver_contour(&self, t: &[DVec3; 3]) -> Option<Contour> {
        counter_clockwise(t.iter().map(|&p| self.to_2d(p)).collect(), 0.0)
    }

    /// The shadow of one triangle on the plane, clipped to `window`; `None` when it casts none
    /// on the receiver (behind or coplanar, outside `bounds`, degenerate).
    fn shadow(&self, tri: &[DVec3; 3], bounds: &Rect, window: &Rect, area_eps: f64) -> Option<Contour> {
        if tri.iter().all(|&p| self.height(p) <= 0.0) {
            return None;
        }
        let in_front = clip_half_space(&tri[..], |&p| self.height(p));
        let projected: Vec<DVec2> = in_front.iter().map(|&p| self.project_along_sun(p)).collect();
        if !Rect::around(projected.iter().copied())?.overlaps(bounds) {
            return None;
        }
        counter_clockwise(window.clip(&projected), area_eps)
    }
}

/// An axis-aligned 2D box.
#[derive(Debug, Clone, Copy)]
struct Rect {
    min: DVec2,
    max: DVec2,
}

impl Rect {
    /// Bounding box of some points; `None` if there are none or one is not finite.
    fn around(points: impl Iterator<Item = DVec2>) -> Option<Self> {
        let mut rect: Option<Rect> = None;
        for p in points {
            if !p.is_finite() {
                return None;
            }
            rect = Some(match rect {
                None => Rect { min: p, max: p },
                Some(r) => Rect { min: r.min.min(p), max: r.max.max(p) },
            });
        }
        rect
    }

    fn size(&self) -> DVec2 {
        self.max - self.min
    }

    fn expanded(&self, margin: f64) -> Self {
        Rect { min: self.min - DVec2::splat(margin), max: self.max + DVec2::splat(margin) }
    }

    fn overlaps(&self, other: &Rect) -> bool {
        self.min.x <= other.max.x && other.min.x <= self.max.x && self.min.y <= other.max.y && other.min.y <= self.max.y
    }

    /// A convex polygon clipped to the box (keeps the overlay's input, and so its integer grid,
    /// at the receiver's scale even when a grazing sun stretches shadows far away).
    fn clip(&self, polygon: &[DVec2]) -> Vec<DVec2> {
        let p = clip_half_space(polygon, |p| p.x - self.min.x);
        let p = clip_half_space(&p, |p| self.max.x - p.x);
        let p = clip_half_space(&p, |p| p.y - self.min.y);
        clip_half_space(&p, |p| self.max.y - p.y)
    }
}

/// Sutherland–Hodgman against one half-space: keeps the part of a convex polygon where
/// `dist ≥ 0`. New vertices are made only where an edge strictly crosses, so a vertex on the
/// boundary is not doubled.
fn clip_half_space<P>(polygon: &[P], dist: impl Fn(&P) -> f64) -> Vec<P>
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    let mut out = Vec::with_capacity(polygon.len() + 2);
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (da, db) = (dist(&a), dist(&b));
        if da >= 0.0 {
            out.push(a);
        }
        if da > 0.0 && db < 0.0 {
            out.push(crossing(a, da, b, db));
        } else if da < 0.0 && db > 0.0 {
            out.push(crossing(b, db, a, da));
        }
    }
    out
}

/// Where the edge from `inside` (`d_in > 0`) to `outside` (`d_out < 0`) meets the boundary.
/// Always computed from the inside end, so two triangles sharing an edge (walking it in
/// opposite directions) get bit-identical points and leave no sliver between their shadows.
fn crossing<P>(inside: P, d_in: f64, outside: P, d_out: f64) -> P
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<f64, Output = P>,
{
    inside + (outside - inside) * (d_in / (d_in - d_out))
}

/// Twice the signed area (positive counter-clockwise).
fn doubled_area(points: impl Iterator<Item = DVec2> + Clone) -> f64 {
    let next = points.clone().cycle().skip(1);
    points.zip(next).map(|(a, b)| a.perp_dot(b)).sum()
}

/// The polygon as a counter-clockwise contour; `None` when its area is at most `min_area` or a
/// coordinate is not finite (i_overlay refuses those).
fn counter_clockwise(mut polygon: Vec<DVec2>, min_area: f64) -> Option<Contour> {
    if polygon.len() < 3 || !polygon.iter().all(|p| p.is_finite()) {
        return None;
    }
    let area = 0.5 * doubled_area(polygon.iter().copied());
    if area.abs() <= min_area {
        return None;
    }
    if area < 0.0 {
        polygon.reverse();
    }
    Some(polygon.iter().map(|p| p.to_array()).collect())
}

/// Area of i_overlay shapes: outer contours come counter-clockwise and holes clockwise, so the
/// signed areas of all contours add up to the covered area.
fn shapes_area(shapes: &[Vec<Contour>]) -> f64 {
    let contour_area = |c: &Contour| 0.5 * doubled_area(c.iter().map(|&p| DVec2::from(p)));
    shapes.iter().flatten().map(contour_area).sum()
}

/// `area(receiver − ∪ shadows) / area(∪ receiver)`, clamped to [0, 1]; 0 without receiver area.
fn sunlit_ratio(receiver: &[Contour], shadows: &[Contour], area_eps: f64) -> f64 {
    if receiver.is_empty() {
        return 0.0;
    }
    if shadows.is_empty() {
        return 1.0;
    }
    // One graph for both areas: numerator and denominator share the same integer rounding.
    // 64-bit integers keep the grid far finer than the tests' 1e-9 tolerance.
    let mut overlay = FloatOverlay::<[f64; 2], i64>::from_subj_and_clip(receiver, shadows);
    let Some(graph) = overlay.build_graph_view(FillRule::NonZero) else { return 0.0 };
    let mut buffer = BooleanExtractionBuffer::default();
    let whole = shapes_area(&graph.extract_shapes(OverlayRule::Subject, &mut buffer));
    if whole <= area_eps {
        return 0.0;
    }
    let lit = shapes_area(&graph.extract_shapes(OverlayRule::Difference, &mut buffer));
    // Rounding can leave hairline gaps between shadows that meet along T-junctions; a lit area
    // below the noise level is none.
    if lit <= area_eps {
        return 0.0;
    }
    (lit / whole).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SceneBuilder, SourceMesh, SourceNode};
    use glam::DMat4;

    const TOL: f64 = 1e-9;

    /// Unit vector towards the sun: azimuth clockwise from north, altitude above the horizon.
    fn sun(azimuth_deg: f64, altitude_deg: f64) -> DVec3 {
        let (az, alt) = (azimuth_deg.to_radians(), altitude_deg.to_radians());
        DVec3::new(alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin())
    }

    /// The 4 corners of the parallelogram `o, o+a, o+a+b, o+b`; its triangles have normal `a × b`.
    fn rect(o: [f32; 3], a: [f32; 3], b: [f32; 3]) -> Vec<[f32; 3]> {
        let add = |p: [f32; 3], q: [f32; 3]| [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
        vec![o, add(o, a), add(add(o, a), b), add(o, b)]
    }

    /// A mesh of quads given as 4 corners each (counter-clockwise about their normal).
    fn quads(quads: &[Vec<[f32; 3]>]) -> SourceMesh {
        let mut mesh = SourceMesh::default();
        for q in quads {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend_from_slice(q);
            mesh.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
        }
        mesh
    }

    /// Collects nodes; every node has its own mesh (so it is baked, in world coordinates).
    #[derive(Default)]
    struct TestScene {
        builder: SceneBuilder,
    }

    impl TestScene {
        fn add(mut self, name: &str, mesh: SourceMesh, receiver: bool) -> Self {
            self.builder.add_object("test", name, mesh, receiver);
            self
        }

        fn build(self) -> Scene {
            self.builder.build().unwrap()
        }
    }

    /// The reference's fraction, after checking that the fast engine gives the same.
    fn fraction(scene: &Scene, name: &str, sun: DVec3) -> f64 {
        let (receiver, _) = scene.receiver(name).unwrap();
        let want = sunlit_fraction(scene, ViewRequest::new(receiver, sun));
        let fast = engine::ExactEngine::new(scene).fractions(&[ViewRequest::new(receiver, sun)]);
        // The fast engine's grid (2^30 over the receiver's window) rounds each vertex to ~10⁻⁹ of
        // the window; over many edges that adds up to ~10⁻⁸ of a fraction (blaas-louvres: 2e-8).
        assert!((fast[0] - want).abs() < 1e-6, "fast engine {} against the reference {want}", fast[0]);
        want
    }

    fn assert_close(got: f64, want: f64) {
        assert!((got - want).abs() < TOL, "got {got}, want {want}");
    }

    /// The 2 m × 1 m window x ∈ [0, 2], z ∈ [0, 1] in the plane y = 0, facing south (−y):
    /// a = +x, b = +z and x × z = −y.
    fn window() -> SourceMesh {
        quads(&[rect([0., 0., 0.], [2., 0., 0.], [0., 0., 1.])])
    }

    /// A horizontal overhang at height z from the wall (y = 0) out to y = −depth, x ∈ [x0, x1].
    fn overhang(z: f32, depth: f32, x0: f32, x1: f32) -> SourceMesh {
        quads(&[rect([x0, -depth, z], [x1 - x0, 0., 0.], [0., depth, 0.])])
    }

    #[test]
    fn unshaded_window_is_fully_lit_and_dark_when_facing_away_or_at_night() {
        let s = TestScene::default().add("Window", window(), true).build();
        assert_eq!(fraction(&s, "Window", sun(180.0, 30.0)), 1.0);
        assert_eq!(fraction(&s, "Window", sun(0.0, 30.0)), 0.0, "sun in the north: back-facing");
        assert_eq!(fraction(&s, "Window", sun(180.0, -5.0)), 0.0, "sun below the horizon");
        assert_eq!(sunlit_fraction(&s, ViewRequest::new(7, sun(180.0, 30.0))), 0.0, "unknown receiver");
        assert_eq!(fraction(&s, "Window", DVec3::NAN), 0.0);
    }

    #[test]
    fn overhang_with_sun_due_south() {
        // Overhang of depth d = 0.5 on top of the window (z = 1), long enough to have no ends.
        // An edge point (x, −d, 1) is d in front of the wall; with s = (0, −cos α, sin α) and
        // n·s = cos α it lands at (x, 0, 1 − d tan α): the top d·tan α of the 1 m window is
        // shaded, so the fraction is 1 − min(1, d tan α / 1).
        let s = TestScene::default().add("Window", window(), true).add("Overhang", overhang(1.0, 0.5, -10.0, 12.0), false).build();
        for alt in [10.0_f64, 30.0, 45.0, 60.0, 70.0, 85.0] {
            let want = 1.0 - (0.5 * alt.to_radians().tan()).min(1.0);
            assert_close(fraction(&s, "Window", sun(180.0, alt)), want);
        }
    }

    #[test]
    fn overhang_with_oblique_sun() {
        // Sun at azimuth 200°: γ = 20° off the wall normal (azimuth 180°), altitude α = 40°.
        // s = (−cos α sin γ, −cos α cos γ, sin α), n·s = cos α cos γ. A point t in front of
        // the wall moves by −s·t/(n·s) = (t tan γ, ·, −t tan α / cos γ): down by
        // D = d tan α / cos γ and east by t tan γ.
        let (alt, gamma, d) = (40.0_f64, 20.0_f64, 0.5);
        let depth = d * alt.to_radians().tan() / gamma.to_radians().cos();
        let shift = d * gamma.to_radians().tan();
        assert!(depth < 1.0 && shift < 2.0);

        // A long overhang: its ends are far away; a band of depth D over the full width.
        let long = TestScene::default().add("Window", window(), true).add("Overhang", overhang(1.0, 0.5, -10.0, 12.0), false).build();
        assert_close(fraction(&long, "Window", sun(200.0, alt)), 1.0 - depth);

        // An overhang exactly as wide as the window (x ∈ [0, 2]): its shadow is the
        // parallelogram (0, 1), (2, 1), (2 + shift, 1 − D), (shift, 1 − D), area 2·D. The part
        // east of x = 2 is the triangle (2, 1), (2 + shift, 1 − D), (2, 1 − D), area shift·D/2,
        // and misses the window. Shaded: 2D − shift·D/2 of 2 m².
        let finite = TestScene::default().add("Window", window(), true).add("Overhang", overhang(1.0, 0.5, 0.0, 2.0), false).build();
        let shaded = 2.0 * depth - 0.5 * shift * depth;
        assert_close(fraction(&finite, "Window", sun(200.0, alt)), 1.0 - shaded / 2.0);
    }

    #[test]
    fn side_fin_east_of_the_window() {
        // A vertical fin in the plane x = 2 (the window's east edge), from the wall out to
        // y = −f, f = 0.5, tall enough (z ∈ [−1, 3]) that its top and bottom do not matter.
        // Its points (2, −t, z) lie t in front of the wall. Sun at azimuth 180° − γ (from the
        // south-east): s_x = cos α sin γ, n·s = cos α cos γ, so they move west by t tan γ; the
        // shadow is the strip x ∈ [2 − f tan γ, 2] over the full height: fraction 1 − f tan γ / 2.
        let fin = quads(&[rect([2., 0., -1.], [0., -0.5, 0.], [0., 0., 4.])]);
        let s = TestScene::default().add("Window", window(), true).add("Fin", fin, false).build();
        for (gamma, alt) in [(45.0_f64, 30.0), (30.0, 30.0), (60.0, 20.0)] {
            let want = 1.0 - 0.5 * gamma.to_radians().tan() / 2.0;
            assert_close(fraction(&s, "Window", sun(180.0 - gamma, alt)), want);
        }
        // Sun from the south-west: the fin's shadow falls east of it, off the window.
        assert_close(fraction(&s, "Window", sun(225.0, 30.0)), 1.0);
    }

    /// The L-shaped roof [0, 2] × [0, 1] ∪ [0, 1] × [0, 2] at z = 0 (area 3), as a fan from the
    /// origin (which sees the whole L), facing up.
    fn l_shape() -> SourceMesh {
        SourceMesh {
            positions: vec![[0., 0., 0.], [2., 0., 0.], [2., 1., 0.], [1., 1., 0.], [1., 2., 0.], [0., 2., 0.]],
            indices: vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5],
        }
    }

    /// A horizontal 1 m square plate [0.5, 1.5]² at z = 1.
    fn plate() -> SourceMesh {
        quads(&[rect([0.5, 0.5, 1.], [1., 0., 0.], [0., 1., 0.])])
    }

    #[test]
    fn concave_l_shaped_receiver() {
        let s = TestScene::default().add("Roof", l_shape(), true).add("Plate", plate(), false).build();
        // Sun at the zenith: the shadow is the plate's footprint [0.5, 1.5]². It covers
        // [0.5, 1.5] × [0.5, 1] (0.5 m²) and [0.5, 1] × [1, 1.5] (0.25 m²) of the L; the part in
        // the L's notch [1, 1.5]² shades nothing. Fraction 1 − 0.75/3.
        assert_close(fraction(&s, "Roof", DVec3::Z), 0.75);
        // Sun in the east at 45°: h = 1, n·s = sin 45°, the shadow moves by −s/sin 45° =
        // (−1, 0, −1): footprint [−0.5, 0.5] × [0.5, 1.5], of which [0, 0.5] × [0.5, 1.5]
        // (0.5 m²) is on the L. Fraction 1 − 0.5/3.
        assert_close(fraction(&s, "Roof", sun(90.0, 45.0)), 1.0 - 0.5 / 3.0);
    }

    #[test]
    fn overlapping_receiver_triangles_count_once() {
        // The same L with its first triangle twice: the union (3 m²) is the denominator, and
        // the doubled triangle does not change the shaded part.
        let mut twice = l_shape();
        twice.indices.extend([0, 1, 2]);
        let s = TestScene::default().add("Roof", twice, true).add("Plate", plate(), false).build();
        assert_close(fraction(&s, "Roof", DVec3::Z), 0.75);
    }

    #[test]
    fn shadow_inside_the_receiver_leaves_a_hole() {
        // A plate parallel to the window, 0.5 m in front (y = −0.5), x ∈ [0.5, 1], z ∈ [0.5, 0.75].
        // Sun due south at 30°: it moves down by 0.5 tan 30° ≈ 0.289, to z ∈ [0.211, 0.461],
        // inside the window: a 0.5 × 0.25 hole in the lit area, fraction 1 − 0.125/2.
        // (Checks that i_overlay's clockwise holes are subtracted.)
        let plate = quads(&[rect([0.5, -0.5, 0.5], [0.5, 0., 0.], [0., 0., 0.25])]);
        let s = TestScene::default().add("Window", window(), true).add("Plate", plate, false).build();
        assert_close(fraction(&s, "Window", sun(180.0, 30.0)), 1.0 - 0.125 / 2.0);
    }

    #[test]
    fn wall_with_a_window_hole() {
        // Wall x ∈ [−1, 3], z ∈ [−1, 2] in the plane y = 0 minus the window's hole
        // x ∈ [0, 2], z ∈ [0, 1], as four rectangles (area 12 − 2 = 10 m²), facing south.
        let wall = quads(&[
            rect([-1., 0., -1.], [4., 0., 0.], [0., 0., 1.]),
            rect([-1., 0., 1.], [4., 0., 0.], [0., 0., 1.]),
            rect([-1., 0., 0.], [1., 0., 0.], [0., 0., 1.]),
            rect([2., 0., 0.], [1., 0., 0.], [0., 0., 1.]),
        ]);
        // Overhang at z = 1.5, depth 0.5, as wide as the wall. Sun due south with tan α = 2: the
        // shadow is the band z ∈ [0.5, 1.5] across x ∈ [−1, 3].
        // Window: z ∈ [0.5, 1] shaded, half of it. Wall: [1, 1.5] of the top part (4 × 0.5)
        // plus [0.5, 1] beside the hole (2 × 1 × 0.5): 3 of 10 m².
        // The window and the wall are coplanar: they never shade each other.
        let s = TestScene::default()
            .add("Wall", wall, true)
            .add("Window", window(), true)
            .add("Overhang", overhang(1.5, 0.5, -1.0, 3.0), false)
            .build();
        let sun = DVec3::new(0.0, -1.0, 2.0).normalize();
        let (wall_id, _) = s.receiver("Wall").unwrap();
        let (window_id, _) = s.receiver("Window").unwrap();
        let requests = [ViewRequest::new(wall_id, sun), ViewRequest::new(window_id, sun)];
        let got = sunlit_fractions(&s, &requests);
        assert_close(got[0], 0.7);
        assert_close(got[1], 0.5);
        for (r, g) in requests.iter().zip(&got) {
            assert_eq!(sunlit_fraction(&s, *r), *g, "batch and single agree");
        }
        let (_, receiver) = s.receiver("Wall").unwrap();
        assert!((receiver.area - 10.0).abs() < TOL);
    }

    #[test]
    fn geometry_behind_the_receiver_never_shades_it() {
        // A big box-like slab north of the wall plane (y ∈ [0.5, 5]), covering the window in
        // x and z: entirely behind, so no shadow whatever the (southern) sun.
        let slab = quads(&[rect([-5., 0.5, -5.], [10., 0., 0.], [0., 0., 10.]), rect([-5., 0.5, 5.], [10., 0., 0.], [0., 4.5, 0.])]);
        let s = TestScene::default().add("Window", window(), true).add("Slab", slab, false).build();
        for az in [120.0, 180.0, 240.0] {
            assert_eq!(fraction(&s, "Window", sun(az, 30.0)), 1.0);
        }
    }

    #[test]
    fn geometry_straddling_the_plane_is_clipped() {
        // A horizontal plate at z = 0.5 through the window's plane, from y = −0.25 (in front)
        // to y = 0.5 (behind), long in x. Sun due south at 45° (tan α = 1): the front part
        // shades z ∈ [0.25, 0.5] (fraction 0.75). Unclipped, the back part would shade
        // z ∈ [0.5, 1] as well (fraction 0.25).
        let plate = quads(&[rect([-10., -0.25, 0.5], [22., 0., 0.], [0., 0.75, 0.])]);
        let s = TestScene::default().add("Window", window(), true).add("Plate", plate, false).build();
        assert_close(fraction(&s, "Window", sun(180.0, 45.0)), 0.75);
    }

    #[test]
    fn fully_covering_occluder_and_coplanar_occluders() {
        // A large plate parallel to the window 1 m in front: its shadow moves by at most
        // tan 30° in z and still covers the window.
        let cover = quads(&[rect([-10., -1., -10.], [22., 0., 0.], [0., 0., 21.])]);
        let s = TestScene::default().add("Window", window(), true).add("Cover", cover, false).build();
        assert_eq!(fraction(&s, "Window", sun(180.0, 30.0)), 0.0);

        // Only coplanar geometry: a larger panel in the window's own plane (either facing),
        // overlapping it. Coplanar geometry never shades.
        let panel = quads(&[rect([-1., 0., -1.], [4., 0., 0.], [0., 0., 3.]), rect([-1., 0., -1.], [0., 0., 3.], [4., 0., 0.])]);
        let s = TestScene::default().add("Window", window(), true).add("Panel", panel, false).build();
        for az in [150.0, 180.0, 210.0] {
            assert_eq!(fraction(&s, "Window", sun(az, 30.0)), 1.0);
        }
    }

    #[test]
    fn instanced_occluders_shade_like_baked_ones() {
        // The long overhang of `overhang_with_sun_due_south` as two halves sharing one mesh
        // (drawn instanced, placed by f64 transforms): same shadow, fraction 1 − 0.5 tan 30°.
        let mut b = SceneBuilder::new();
        let w = b.add_mesh("window", window());
        let half = b.add_mesh("half", overhang(1.0, 0.5, 0.0, 11.0));
        let node = |name: &str, mesh: usize, transform: DMat4, receiver: bool| SourceNode {
            name: name.into(),
            origin: format!("test: node '{name}'"),
            mesh,
            transform,
            receiver,
        };
        b.add_node(node("Window", w, DMat4::IDENTITY, true));
        b.add_node(node("West", half, DMat4::from_translation(DVec3::new(-10.0, 0.0, 0.0)), false));
        b.add_node(node("East", half, DMat4::from_translation(DVec3::new(1.0, 0.0, 0.0)), false));
        let s = b.build().unwrap();
        assert_eq!(s.instances.len(), 3, "static mesh + two instances");
        assert_close(fraction(&s, "Window", sun(180.0, 30.0)), 1.0 - 0.5 * 30.0_f64.to_radians().tan());
    }
}
