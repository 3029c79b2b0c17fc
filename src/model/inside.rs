//! The rooms of an EnergyPlus model, for the sun inside: each zone with the inside faces of its
//! surfaces, and its windows as openings with glass.
//!
//! Owns what the model says about the inside: which zone a surface bounds, which openings are
//! glazing (windows and glass doors; a door is opaque), and the glass's normal-incidence
//! transmittances, solar and visible. A window's construction of one
//! `WindowMaterial:SimpleGlazingSystem` layer gives them: visible from its Visible Transmittance
//! field (the solar value where it is blank), solar from its U-factor and SHGC by EnergyPlus's
//! simple glazing correlation (Engineering Reference, "Simple Window Model", step 4: one formula
//! for U > 4.5 W/m²K, one for U < 3.4, linear in U between). Any other construction takes the
//! caller's `glass` value for both ([`UnreadGlass`], with an angular curve of the caller's if it
//! gives one), except one `WindowMaterial:Glazing` pane given by spectral averages, whose
//! normal-incidence fields are read as they are. The solar transmittance's
//! angular dependence ([`Glazing::solar_at`], [`Glazing::visible_at`]: the interior beam and the
//! maps alike) is EnergyPlus's: its curves A–J chosen by U and SHGC for simple glazing
//! ([`super::simple_glazing`]), Fresnel's physics for one pane; a glTF pane's own, from its
//! material's extras ([`curve`]).
//!
//! The scene ([`inside_scene`]) is the building's surfaces with the glazing left out, so an
//! opening is a hole in its wall: the engines see the beam pass and the map weights it by the
//! glass ([`Rooms`]); walls, frames and doors stay opaque.

use glam::{DVec2, DVec3};

use super::EnergyPlusInput;
use super::building::{EpSurface, inside_name};
use super::simple_glazing::angular_factor;
use crate::error::{Error, Result};
use crate::geometry::{Plane, inside_or_on, newell, triangulate};
use crate::scene::{Scene, SceneBuilder};

pub mod curve;
pub mod gltf;

use curve::TransmittanceCurve;

/// A ray within this distance (m) of an opening's outline crosses it: the engine counts a point
/// whose ray grazes an edge as lit, and map points are f32 (about 1e-5 m at 100 m).
const CROSSING_TOLERANCE: f64 = 1e-4;
/// Barycentric slack of a crossing of a mesh pane's triangle (a ray through its edge crosses it).
const EDGE_SLACK: f64 = 1e-7;
/// The direction [`Room::contains`] counts an EnergyPlus zone's crossings along: an
/// irrational-looking one, so the ray does not graze edges of axis-aligned rooms.
const ZONE_PROBE: DVec3 = DVec3::new(0.577_3, 0.587_9, 0.566_4);

/// An opening with glass, in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Glazing {
    /// The EnergyPlus name.
    pub name: String,
    /// The zone it lets the sun into (its base surface's).
    pub zone: String,
    /// Its outline (counter-clockwise seen from outside).
    pub vertices: Vec<DVec3>,
    /// Its plane, for ray crossings.
    pub plane: Plane,
    /// Its outline in `plane`'s coordinates.
    pub outline: Vec<DVec2>,
    /// Its outline moved onto its base surface's plane: the hole cut in the wall (the same as
    /// `vertices` unless the window is set back).
    pub hole: Vec<DVec3>,
    /// Solar transmittance at normal incidence (beam irradiation).
    pub solar: f64,
    /// Visible transmittance at normal incidence (illuminance).
    pub visible: f64,
    /// How the solar transmittance falls off with the angle of incidence ([`Glazing::solar_at`]).
    pub angular: Angular,
    /// Its base surface's other side is another zone (Outside Boundary Condition Surface or Zone).
    pub interzone: bool,
    /// A mesh's glazing node ([`gltf`]): its triangles, crossed once wherever the ray meets one;
    /// empty for an EnergyPlus window, whose `outline` is crossed.
    pub pane: Vec<[DVec3; 3]>,
}

/// The angular dependence of a glass's solar transmittance.
#[derive(Debug, Clone, PartialEq)]
pub enum Angular {
    /// The normal-incidence value at every angle (a construction sunlit cannot read).
    Normal,
    /// One uncoated pane given by spectral averages, with its front solar reflectance at normal
    /// incidence: Fresnel's physics ([`pane_transmittance`]).
    Pane {
        /// Front solar reflectance at normal incidence.
        reflectance: f64,
    },
    /// A `WindowMaterial:SimpleGlazingSystem`: EnergyPlus's curves chosen by U and SHGC
    /// ([`angular_factor`]).
    Simple {
        /// U-factor (W/m²K).
        u: f64,
        /// Solar heat gain coefficient.
        shgc: f64,
    },
    /// A glTF pane's measured curve of transmittance by angle ([`curve`]); the glazing's
    /// `solar` is its value at normal incidence.
    Curve(TransmittanceCurve),
}

impl Glazing {
    /// Solar transmittance for a beam at `cos_incidence` to the glass's normal, by its
    /// [`Angular`] dependence.
    pub fn solar_at(&self, cos_incidence: f64) -> f64 {
        match &self.angular {
            Angular::Pane { reflectance } => pane_transmittance(self.solar, *reflectance, cos_incidence),
            Angular::Simple { u, shgc } => (self.solar * angular_factor(*u, *shgc, cos_incidence)).clamp(0.0, 1.0),
            Angular::Curve(curve) => curve.at(cos_incidence),
            Angular::Normal => self.solar,
        }
    }

    /// Visible transmittance for a beam at `cos_incidence`: the normal value scaled by the same
    /// angular dependence as the solar one. EnergyPlus runs simple glazing's curves (and an
    /// uncoated pane's physics) over each of its optical passes alike, solar and visible; for a
    /// pane sunlit has only the solar reflectance, so the solar curve's share stands in for the
    /// visible one; so for a measured curve, which is of the solar transmittance.
    pub fn visible_at(&self, cos_incidence: f64) -> f64 {
        match &self.angular {
            Angular::Pane { .. } | Angular::Curve(_) if self.solar > 0.0 => {
                (self.visible * self.solar_at(cos_incidence) / self.solar).clamp(0.0, 1.0)
            }
            Angular::Pane { .. } | Angular::Curve(_) => 0.0,
            Angular::Simple { u, shgc } => (self.visible * angular_factor(*u, *shgc, cos_incidence)).clamp(0.0, 1.0),
            Angular::Normal => self.visible,
        }
    }

    /// Whether the ray from `p` along `dir` crosses this opening (ahead of `p`).
    pub fn crossed_by(&self, p: DVec3, dir: DVec3) -> bool {
        if !self.pane.is_empty() {
            return self.pane.iter().any(|t| ray_hits_triangle(p, dir, t, EDGE_SLACK));
        }
        let across = self.plane.normal.dot(dir);
        if across.abs() < 1e-12 {
            return false;
        }
        let t = self.plane.normal.dot(self.plane.origin - p) / across;
        t > 0.0 && inside_or_on(self.plane.project(p + dir * t), &self.outline, CROSSING_TOLERANCE)
    }
}

/// One zone.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    /// The zone's name, upper case as EnergyPlus reports it.
    pub name: String,
    /// Receiver names of its surfaces' inside faces (`NAME:inside`).
    pub inside: Vec<String>,
    /// Those of its floors.
    pub floors: Vec<String>,
    /// Indices into [`Rooms::glazing`] of its openings with glass.
    pub glazing: Vec<usize>,
    /// Its boundary as triangles (an EnergyPlus zone's openings filled): which points lie in it.
    shell: Vec<[DVec3; 3]>,
    /// The direction along which [`Room::contains`] counts the shell's crossings.
    probe: DVec3,
}

impl Room {
    /// Whether `p` lies inside the zone's boundary (a ray's crossings counted; a point on the
    /// boundary may go either way).
    pub fn contains(&self, p: DVec3) -> bool {
        let dir = self.probe.normalize();
        self.shell.iter().filter(|t| ray_hits_triangle(p, dir, t, 0.0)).count() % 2 == 1
    }
}

/// The zones and openings of a model.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Rooms {
    /// Zones in the order their first surface is written.
    pub rooms: Vec<Room>,
    /// Every window and glass door.
    pub glazing: Vec<Glazing>,
}

/// The building's surfaces with glazing left out and every zone surface's inside face a
/// receiver (`NAME:inside`): see [`super::building::Building::add_inside_to`].
pub fn inside_scene(input: &EnergyPlusInput) -> Result<Scene> {
    let mut builder = SceneBuilder::new();
    input.building.add_inside_to(&mut builder)?;
    builder.build()
}

/// As [`inside_scene`] with every opening glazed (see
/// [`super::building::Building::add_inside_glazed`]): each window's glass is a receiver under
/// the window's name, for views that see through it alone.
pub fn inside_scene_glazed(input: &EnergyPlusInput) -> Result<Scene> {
    let mut builder = SceneBuilder::new();
    input.building.add_inside_glazed(&mut builder)?;
    builder.build()
}

/// What the caller says of glazing whose construction sunlit cannot read (several layers,
/// spectral data, a window construction from a file): its normal-incidence transmittance, and
/// how its solar transmittance falls off with the angle of incidence.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnreadGlass {
    /// Normal-incidence transmittance: solar and visible without a curve, visible with one
    /// (the curve's normal value then without it).
    pub transmittance: Option<f64>,
    /// The solar transmittance by angle (its value at 0° the normal one), the visible one
    /// falling off in the same proportion; without it the value is the same at every angle.
    pub curve: Option<TransmittanceCurve>,
}

/// The model's zones and openings. `glass` is the transmittance of glazing whose construction
/// gives none (see the module doc); refused outside 0..=1, and needed only when such glazing
/// exists (the error names the window).
pub fn rooms(input: &EnergyPlusInput, glass: Option<f64>) -> Result<Rooms> {
    rooms_with(input, &UnreadGlass { transmittance: glass, curve: None })
}

/// [`rooms`], glazing whose construction sunlit cannot read taking `glass`: its transmittance
/// and, with a curve, the curve's angular dependence ([`Angular::Curve`]).
pub fn rooms_with(input: &EnergyPlusInput, glass: &UnreadGlass) -> Result<Rooms> {
    if let Some(t) = glass.transmittance
        && !(0.0..=1.0).contains(&t)
    {
        return Err(Error::argument("glass_transmittance", format!("{t} is outside 0..=1")));
    }
    let surfaces = &input.building.surfaces;
    let mut rooms: Vec<Room> = Vec::new();
    for zone in surfaces.iter().filter(|s| !s.is_fenestration()).filter_map(|s| s.zone.as_ref()) {
        if !rooms.iter().any(|r| r.name == *zone) {
            let name = zone.clone();
            rooms.push(Room { name, inside: Vec::new(), floors: Vec::new(), glazing: Vec::new(), shell: Vec::new(), probe: ZONE_PROBE });
        }
    }
    let mut glazing = Vec::new();
    for s in surfaces {
        let Some(room) = s.zone.as_ref().and_then(|z| rooms.iter_mut().find(|r| r.name == *z)) else { continue };
        if s.is_glazing() {
            room.glazing.push(glazing.len());
            glazing.push(glazing_of(input, s, glass)?);
            continue;
        }
        room.inside.push(inside_name(&s.name));
        if s.kind.eq_ignore_ascii_case("Floor") {
            room.floors.push(inside_name(&s.name));
        }
        // Openings are cut from their walls but fill them again here: the shell is closed.
        if !s.is_fenestration() {
            room.shell.extend(fan(&s.vertices));
        }
    }
    Ok(Rooms { rooms, glazing })
}

/// How close (m) the centres of an interzone window's two copies lie: EnergyPlus asks each
/// zone for its own copy of the pane, the same outline wound the other way.
const TWIN_DISTANCE: f64 = 0.01;

impl Rooms {
    /// The other copy of interzone window `k` (the same pane as the next zone sees it): that
    /// zone's index into [`Rooms::rooms`] and the copy's into [`Rooms::glazing`]. None where
    /// the model gives it no copy (its beam then stops at the pane, as the map's geometry has it).
    pub fn twin_of(&self, k: usize) -> Option<(usize, usize)> {
        let this = self.glazing.get(k).filter(|g| g.interzone)?;
        let centre = |g: &Glazing| g.vertices.iter().sum::<DVec3>() / g.vertices.len().max(1) as f64;
        let twin = |j: usize| {
            let g = &self.glazing[j];
            j != k
                && g.interzone
                && g.plane.normal.dot(this.plane.normal).abs() > 1.0 - 1e-6
                && centre(g).distance(centre(this)) < TWIN_DISTANCE
        };
        self.rooms.iter().enumerate().find_map(|(r, room)| room.glazing.iter().find(|&&j| twin(j)).map(|&j| (r, j)))
    }
}

/// A polygon's triangles (ear clipping in its plane).
fn fan(vertices: &[DVec3]) -> Vec<[DVec3; 3]> {
    let plane = Plane::of_polygon(vertices);
    triangulate(&plane, vertices, &[]).into_iter().map(|t| t.map(|i| vertices[i])).collect()
}

/// Möller–Trumbore: whether the ray from `p` along `dir` crosses triangle `t` ahead of `p`, its
/// edges widened by `slack` (barycentric).
fn ray_hits_triangle(p: DVec3, dir: DVec3, t: &[DVec3; 3], slack: f64) -> bool {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let h = dir.cross(e2);
    let a = e1.dot(h);
    if a.abs() < 1e-12 {
        return false;
    }
    let s = p - t[0];
    let u = s.dot(h) / a;
    let q = s.cross(e1);
    let v = dir.dot(q) / a;
    u >= -slack && v >= -slack && u + v <= 1.0 + slack && e2.dot(q) / a > 0.0
}

fn glazing_of(input: &EnergyPlusInput, s: &EpSurface, glass: &UnreadGlass) -> Result<Glazing> {
    let (solar, visible, angular) = match (simple_glazing(input, s)?, glass) {
        (Some(t), _) => t,
        (None, UnreadGlass { transmittance, curve: Some(curve) }) => {
            (curve.normal(), transmittance.unwrap_or(curve.normal()), Angular::Curve(curve.clone()))
        }
        (None, UnreadGlass { transmittance: Some(t), curve: None }) => (*t, *t, Angular::Normal),
        (None, UnreadGlass { transmittance: None, curve: None }) => {
            return Err(Error::object(
                &input.file,
                s.label(),
                "has no WindowMaterial:SimpleGlazingSystem construction to take a transmittance from: give a glass transmittance",
            ));
        }
    };
    let base = input.building.surface(s.base.as_deref().unwrap_or_default());
    let interzone =
        base.is_some_and(|b| b.outside_boundary.eq_ignore_ascii_case("Surface") || b.outside_boundary.eq_ignore_ascii_case("Zone"));
    let hole = match base {
        Some(b) => {
            let wall = Plane::of_polygon(&b.vertices);
            s.vertices.iter().map(|&p| wall.flatten(p)).collect()
        }
        None => s.vertices.clone(),
    };
    let plane = Plane::through(s.vertices[0], newell(&s.vertices));
    let outline = s.vertices.iter().map(|&p| plane.project(p)).collect();
    Ok(Glazing {
        name: s.name.clone(),
        zone: s.zone.clone().unwrap_or_default(),
        vertices: s.vertices.clone(),
        plane,
        outline,
        hole,
        solar,
        visible,
        angular,
        interzone,
        pane: Vec::new(),
    })
}

/// (solar, visible) normal-incidence transmittance and the solar one's angular dependence from a
/// window's construction, when it is one `WindowMaterial:SimpleGlazingSystem` layer or one
/// spectral-average pane; refuses values outside 0..=1, naming the material.
fn simple_glazing(input: &EnergyPlusInput, s: &EpSurface) -> Result<Option<(f64, f64, Angular)>> {
    let Some(name) = construction_of(input, s) else { return Ok(None) };
    let named = |class: &str, name: &str| {
        input.objects.iter().find(|o| o.is(class) && o.name().is_some_and(|n| n.eq_ignore_ascii_case(name.trim())))
    };
    let Some(construction) = named("Construction", &name) else { return Ok(None) };
    let layers: Vec<&str> = (1..).map(|i| construction.field(i)).take_while(|f| !f.trim().is_empty()).collect();
    let [layer] = layers.as_slice() else { return Ok(None) };
    if let Some(glass) = named("WindowMaterial:Glazing", layer) {
        return one_pane(input, glass);
    }
    let Some(material) = named("WindowMaterial:SimpleGlazingSystem", layer) else { return Ok(None) };
    let value = |i: usize, what: &str| -> Result<Option<f64>> {
        let text = material.field(i).trim();
        if text.is_empty() {
            return Ok(None);
        }
        text.parse::<f64>().map(Some).map_err(|_| Error::object(&input.file, material.label(), format!("{what} '{text}' is not a number")))
    };
    let in_unit = |v: f64, what: &str| -> Result<f64> {
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(Error::object(&input.file, material.label(), format!("{what} {v} is outside 0..=1")))
        }
    };
    let u = value(1, "U-Factor")?.unwrap_or(0.0);
    let shgc = in_unit(value(2, "Solar Heat Gain Coefficient")?.unwrap_or(0.0), "Solar Heat Gain Coefficient")?;
    let solar = solar_transmittance(u, shgc).clamp(0.0, 1.0);
    let visible = match value(3, "Visible Transmittance")? {
        Some(v) => in_unit(v, "Visible Transmittance")?,
        None => solar,
    };
    Ok(Some((solar, visible, Angular::Simple { u, shgc })))
}

/// The construction a surface names, as written (None for a surface read from no object with
/// one, such as a shading surface).
pub fn construction_of(input: &EnergyPlusInput, s: &EpSurface) -> Option<String> {
    let object = input.objects.iter().find(|o| o.is(&s.class) && o.name().is_some_and(|n| n.eq_ignore_ascii_case(&s.name)))?;
    // Construction Name: the third field of the two classes that name a surface type first, the
    // second of every other surface class (Wall:Detailed, Window, Door, Window:Interzone, …).
    let field = if object.is("FenestrationSurface:Detailed") || object.is("BuildingSurface:Detailed") { 2 } else { 1 };
    Some(object.field(field).trim().to_string()).filter(|c| !c.is_empty())
}

/// (solar, visible) normal-incidence transmittance and front solar reflectance of one
/// `WindowMaterial:Glazing` pane given by its spectral averages; None for spectral data, which
/// sunlit does not integrate.
fn one_pane(input: &EnergyPlusInput, glass: &crate::model::idf::IdfObject) -> Result<Option<(f64, f64, Angular)>> {
    if !glass.field(1).trim().eq_ignore_ascii_case("SpectralAverage") {
        return Ok(None);
    }
    let value = |i: usize, what: &str| -> Result<f64> {
        let text = glass.field(i).trim();
        text.parse::<f64>()
            .ok()
            .filter(|v| (0.0..=1.0).contains(v))
            .ok_or_else(|| Error::object(&input.file, glass.label(), format!("{what} '{text}' is not a number in 0..=1")))
    };
    Ok(Some((
        value(4, "Solar Transmittance at Normal Incidence")?,
        value(7, "Visible Transmittance at Normal Incidence")?,
        Angular::Pane { reflectance: value(5, "Front Side Solar Reflectance at Normal Incidence")? },
    )))
}

/// The beam transmittance at `cos_incidence` of an uncoated pane whose normal-incidence
/// transmittance and reflectance are `tau` and `rho`: the slab's one-interface reflectance `r`
/// and internal transmittance `t` are solved from them (τ = (1−r)²t / (1−r²t²), ρ = r + rτt),
/// the refractive index follows from `r`, and at the angle each polarisation's Fresnel
/// reflectance and the longer path through the glass give the slab's transmittance again; the
/// two polarisations are averaged. This is the physics of EnergyPlus's uncoated glass
/// (WindowManager `TransAndReflAtPhi`), which fits a polynomial through it.
pub fn pane_transmittance(tau: f64, rho: f64, cos_incidence: f64) -> f64 {
    let c = cos_incidence.clamp(0.0, 1.0);
    if tau <= 0.0 || c <= 0.0 {
        return 0.0;
    }
    let beta = tau * tau - rho * rho + 2.0 * rho + 1.0;
    let r = (beta - (beta * beta - 4.0 * (2.0 - rho) * rho).max(0.0).sqrt()) / (2.0 * (2.0 - rho));
    if r <= 1e-9 {
        return tau;
    }
    let q = (1.0 - r) * (1.0 - r);
    let t = ((q * q + 4.0 * r * r * tau * tau).sqrt() - q) / (2.0 * r * r * tau);
    let n = (1.0 + r.sqrt()) / (1.0 - r.sqrt());
    let ct = (1.0 - (1.0 - c * c) / (n * n)).sqrt();
    let path = t.powf(1.0 / ct);
    let slab = |reflectance: f64| (1.0 - reflectance).powi(2) * path / (1.0 - (reflectance * path).powi(2));
    let (rs, rp) = (((c - n * ct) / (c + n * ct)).powi(2), ((n * c - ct) / (n * c + ct)).powi(2));
    0.5 * (slab(rs) + slab(rp))
}

/// EnergyPlus's simple glazing solar transmittance at normal incidence from U (W/m²K) and SHGC.
pub fn solar_transmittance(u: f64, shgc: f64) -> f64 {
    let high_u = if shgc < 0.7206 { 0.939998 * shgc * shgc + 0.20332 * shgc } else { 1.30415 * shgc - 0.30515 };
    let low_u = if shgc <= 0.15 { 0.41040 * shgc } else { 0.085775 * shgc * shgc + 0.963954 * shgc - 0.084958 };
    if u > 4.5 {
        high_u
    } else if u < 3.4 {
        low_u
    } else {
        low_u + (high_u - low_u) * (u - 3.4) / (4.5 - 3.4)
    }
}

#[cfg(test)]
mod tests {
    use super::pane_transmittance;

    /// A slab with interface reflectance `r` and internal transmittance `t`, seen at normal
    /// incidence: (τ, ρ) by the multiple-reflection sums.
    fn slab(r: f64, t: f64) -> (f64, f64) {
        let tau = (1.0 - r).powi(2) * t / (1.0 - r * r * t * t);
        (tau, r + r * tau * t)
    }

    #[test]
    fn a_pane_gives_back_its_normal_transmittance_and_falls_off_with_angle() {
        // EnergyPlus's CLEAR 6MM-like pane (τ 0.775, ρ 0.071) and a slab made from known r, t.
        for (tau, rho) in [(0.775, 0.071), slab(0.0426, 0.92)] {
            assert!((pane_transmittance(tau, rho, 1.0) - tau).abs() < 1e-9, "{tau} {rho}");
            let mut last = tau;
            for k in (0..10).rev() {
                let at = pane_transmittance(tau, rho, f64::from(k) / 10.0);
                assert!(at <= last + 1e-12 && at >= 0.0, "{tau}: not falling at cos {}", f64::from(k) / 10.0);
                last = at;
            }
            assert_eq!(pane_transmittance(tau, rho, 0.0), 0.0);
        }
        // Glass of index 1.526 (r 0.04336) without absorption: at 60° Fresnel's reflectances are
        // 0.18548 (s) and 0.00145 (p), the slab lets (1−R)/(1+R) of each through, 0.68708 and
        // 0.99711, their mean 0.84210 (worked by hand from Snell's and Fresnel's laws).
        let (tau, rho) = slab(0.043_361_55, 1.0 - 1e-12);
        let at60 = pane_transmittance(tau, rho, 0.5);
        assert!((at60 - 0.842_10).abs() < 1e-3, "{at60}");
    }
}
