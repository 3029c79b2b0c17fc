//! EnergyPlus building geometry (from IDF or epJSON objects) into world coordinates and the scene.
//!
//! Owns EnergyPlus's geometry rules, as EnergyPlus 25.2 applies them (Input Output Reference,
//! "GlobalGeometryRules"; `SurfaceGeometry.cc`: `GetVertices`, `MakeRectangularVertices`,
//! `MakeRelativeRectangularVertices`, `GetSimpleShdSurfaceData`):
//! - **Relative** coordinates: a zone surface's vertices are rotated by the zone's Direction of
//!   Relative North, translated by the zone origin, then rotated by the Building North Axis (plus
//!   `Compliance:Building`'s Appendix G rotation); `Shading:Building:*` rotates with the building;
//!   `Shading:Site:*` is never moved. Angles are degrees clockwise seen from above, so the
//!   building's own y axis ends up `north_axis` degrees east of true north.
//! - **World** (or Absolute) coordinates: vertices are already world coordinates; zone origins,
//!   zone north and the Building North Axis are *not* applied ("World coordinates do not use these
//!   values", IORef), only the Appendix G rotation is (for zone and building surfaces).
//! - Rectangular surfaces (`Wall:Exterior`, `Roof`, …) place their lower-left corner by the
//!   separate Rectangular Surface Coordinate System; their azimuth turns with the building only
//!   in Relative coordinates. Simple windows and doors sit at (x, z) from their base surface's
//!   second vertex (its lower-left corner once vertices start at the upper-left), in its plane.
//! - Vertex order: converted to counter-clockwise seen from outside (Clockwise input keeps vertex
//!   1 and reverses the rest) and started at the upper-left corner, as EnergyPlus stores them.
//!
//! Receivers: the surfaces EnergyPlus lets the sun onto (its `ExtSolar`): Outside Boundary
//! Condition Outdoors and Sun Exposure not NoSun, with windows, glass doors and doors taking both
//! from their base surface; named exactly as written in the file. The others EnergyPlus keeps
//! dark whatever schedule they get (a door in an underground wall, a NoSun wall, an interzone
//! window), so they get none, and the warnings say why. EnergyPlus upper-cases
//! names internally (and in its outputs); names are matched case-insensitively here but kept in
//! the file's spelling. A window or door is a hole in its base surface, whose receiver is the net
//! area, as EnergyPlus's sunlit fraction of a wall is. Files before 9.6 (no Space Name fields) and
//! before 9.0 (a Shading Control Name field in fenestration) are read by their `Version`; a file
//! without one is read as the current version, as EnergyPlus does.
//!
//! Why one file of ~1,300 lines: about 970 are rules and 320 their tests, and they are one
//! reading of EnergyPlus's `SurfaceGeometry.cc` — the coordinate rules, the rectangular classes
//! and the subsurface frames build on each other, and the tests hold them to EnergyPlus's numbers
//! together. The generic planar geometry they use (Newell, planes, ear clipping) is
//! [`crate::geometry`].

use std::collections::HashMap;

use glam::{DMat4, DVec2, DVec3};

use super::idf::{IdfObject, object_label};
use super::reveal::{self, Placement as SubPlacement};
use crate::error::{Error, Result};
use crate::geometry::{self, Plane, inside_or_on, newell, plane_deviation};
use crate::scene::{NodeVeil, SceneBuilder, SourceMesh, SourceNode};
use frame::{SurfaceFrame, WindowFrame, rectangle};
pub use mesh::inside_name;
use mesh::{hole_problem, reveal_problem};

mod frame;
mod mesh;
#[cfg(test)]
mod tests;

/// A surface found farther than this (m) from its best-fit plane gets a warning.
const PLANAR_TOLERANCE: f64 = 1e-3;
/// Surfaces with less area than this (m²) are refused.
const MIN_AREA: f64 = 1e-6;
/// A subsurface vertex this close (m) to its base's outline counts as inside it.
const EDGE_TOLERANCE: f64 = 1e-4;

/// One surface in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct EpSurface {
    /// The EnergyPlus name, as written in the file.
    pub name: String,
    /// The class it came from, as written (e.g. `BuildingSurface:Detailed`).
    pub class: String,
    /// Wall, Roof, Floor, Ceiling, Window, Door, GlassDoor, Shading, …
    pub kind: String,
    /// Outside Boundary Condition (inherited from the base for fenestration; empty for shading).
    pub outside_boundary: String,
    /// The base surface's name for fenestration and attached shading.
    pub base: Option<String>,
    /// World coordinates, counter-clockwise seen from outside, starting at the upper-left corner.
    pub vertices: Vec<DVec3>,
    /// Line of the object in the file.
    pub line: usize,
    /// Whether it gets a sunlit fraction.
    pub receiver: bool,
    /// Its `Sun Exposure` is `NoSun` (a window or door inherits its base surface's).
    pub no_sun: bool,
    /// The zone it bounds, upper case as EnergyPlus keys it (a window or door takes its base
    /// surface's); `None` for shading.
    pub zone: Option<String>,
}

impl EpSurface {
    /// `Class 'Name' (line N)`, for messages.
    pub fn label(&self) -> String {
        object_label(&self.class, Some(&self.name), self.line)
    }

    /// Whether this is a window, glass door or door (a hole in its base surface).
    pub fn is_fenestration(&self) -> bool {
        FENESTRATION_KINDS.iter().any(|k| self.kind.eq_ignore_ascii_case(k))
    }

    fn is_shading(&self) -> bool {
        self.kind == SHADING
    }

    /// Whether this is a window or glass door: an opening the beam passes through, weighted by
    /// its glass (a door is opaque).
    pub fn is_glazing(&self) -> bool {
        ["Window", "GlassDoor"].iter().any(|k| self.kind.eq_ignore_ascii_case(k))
    }
}

/// An EnergyPlus building read from a file.
#[derive(Debug, Clone, Default)]
pub struct Building {
    /// File label used in messages.
    pub file: String,
    /// The `Version` identifier, if any.
    pub version: Option<String>,
    /// Building North Axis (degrees clockwise from true north). Already applied to the vertices
    /// in Relative coordinates; with World coordinates EnergyPlus does not apply it to geometry.
    pub north_axis: f64,
    /// Every surface, in file order.
    pub surfaces: Vec<EpSurface>,
    /// Classes that were not read (each once, as first written).
    pub skipped: Vec<String>,
    /// Things read but worth a look (non-planar surfaces with their deviation, …).
    pub warnings: Vec<String>,
}

/// Field positions that changed between EnergyPlus versions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IddLayout {
    /// Surfaces have a Space Name field after Zone Name (9.6 and later).
    pub space_name: bool,
    /// `FenestrationSurface:Detailed`, `Window` and `GlazedDoor` have a Shading Control Name
    /// field (before 9.0).
    pub shading_control: bool,
}

impl IddLayout {
    /// The layout of a version identifier such as `25.2` or `9.5.0`; the current one for `None`
    /// or an unreadable identifier.
    pub fn from_version(version: Option<&str>) -> Self {
        match version.and_then(major_minor) {
            Some(v) => IddLayout { space_name: v >= (9, 6), shading_control: v < (9, 0) },
            None => IddLayout { space_name: true, shading_control: false },
        }
    }
}

fn major_minor(version: &str) -> Option<(u32, u32)> {
    let mut parts = version.trim().split(['.', '-']);
    let major = parts.next()?.trim().parse().ok()?;
    let minor = parts.next().map_or(Some(0), |m| m.trim().parse().ok())?;
    Some((major, minor))
}

const SHADING: &str = "Shading";
const BASE_KINDS: [&str; 4] = ["Floor", "Wall", "Ceiling", "Roof"];
const FENESTRATION_KINDS: [&str; 5] = ["Window", "Door", "GlassDoor", "TubularDaylightDome", "TubularDaylightDiffuser"];
const OUTDOORS: &str = "Outdoors";

/// Classes read for settings rather than surfaces.
const SETTINGS: [&str; 5] = ["Version", "Building", "GlobalGeometryRules", "Zone", "Compliance:Building"];

/// Reads the geometry of an EnergyPlus model.
pub fn read_building(file: &str, objects: &[IdfObject]) -> Result<Building> {
    let version = super::idf::version(objects);
    check_unknown_geometry(file, objects)?;
    let mut reader = Reader::new(file, objects, IddLayout::from_version(version.as_deref()))?;
    for object in objects {
        reader.base_surface(object)?;
    }
    for object in objects {
        reader.subsurface(object)?;
    }
    for object in objects {
        reader.attached_shading(object)?;
    }
    let skipped = skipped_classes(objects, &reader.handled);
    reader.finish(version, skipped)
}

/// Class-name prefixes under which every EnergyPlus class is geometry, and every one of them is
/// read here: an unknown class with one of these prefixes is a misspelling (or a class from a
/// newer EnergyPlus), and skipping it would silently lose a surface and its shadow.
const GEOMETRY_PREFIXES: [&str; 6] = ["BuildingSurface:", "FenestrationSurface:", "Shading:", "Wall:", "Floor:", "Ceiling:"];

/// The classes under [`GEOMETRY_PREFIXES`] that are read, besides [`RECT_SURFACES`].
const PREFIXED_GEOMETRY: [&str; 13] = [
    "BuildingSurface:Detailed",
    "FenestrationSurface:Detailed",
    "Shading:Site",
    "Shading:Site:Detailed",
    "Shading:Building",
    "Shading:Building:Detailed",
    "Shading:Zone:Detailed",
    "Shading:Overhang",
    "Shading:Overhang:Projection",
    "Shading:Fin",
    "Shading:Fin:Projection",
    "Wall:Detailed",
    "Floor:Detailed",
];

/// Refuses, before anything is read, an object whose class looks like geometry but is unknown,
/// so the message names it rather than a surface that depended on it.
fn check_unknown_geometry(file: &str, objects: &[IdfObject]) -> Result<()> {
    let prefixed = |class: &str| GEOMETRY_PREFIXES.iter().any(|p| class.get(..p.len()).is_some_and(|c| c.eq_ignore_ascii_case(p)));
    let known = |o: &IdfObject| PREFIXED_GEOMETRY.iter().chain(RECT_SURFACES.iter().map(|r| &r.class)).any(|c| o.is(c));
    match objects.iter().find(|o| prefixed(&o.class) && !known(o)) {
        Some(object) => {
            Err(Error::object(file, object.label(), "is not a geometry class sunlit knows (misspelt?); reading on would lose its surface"))
        }
        None => Ok(()),
    }
}

/// Degrees clockwise (seen from above) → the matching rotation of (x, y), as EnergyPlus's
/// `x·cos(−θ) − y·sin(−θ), x·sin(−θ) + y·cos(−θ)`.
fn rotate(p: DVec3, degrees: f64) -> DVec3 {
    let (s, c) = (-degrees.to_radians()).sin_cos();
    DVec3::new(p.x * c - p.y * s, p.x * s + p.y * c, p.z)
}

/// GlobalGeometryRules, parsed.
#[derive(Debug, Clone, Copy)]
struct Rules {
    /// Starting vertex: 1 upper-left, 2 lower-left, 3 lower-right, 4 upper-right (EnergyPlus's
    /// numbering, which is not the IDD's key order).
    corner: usize,
    clockwise: bool,
    /// Detailed vertices are world coordinates.
    world: bool,
    /// Rectangular surfaces' starting corners are world coordinates.
    rect_world: bool,
}

impl Default for Rules {
    fn default() -> Self {
        Rules { corner: 1, clockwise: false, world: false, rect_world: false }
    }
}

/// A zone's coordinate frame.
#[derive(Debug, Clone)]
struct Zone {
    rel_north: f64,
    origin: DVec3,
}

/// Which frame a surface's coordinates are in.
#[derive(Debug, Clone, Copy)]
enum Frame<'a> {
    Zone(&'a Zone),
    Building,
    Site,
}

/// Where surfaces go, from Building, Compliance:Building and GlobalGeometryRules.
#[derive(Debug, Clone, Copy)]
struct Placement {
    rules: Rules,
    /// Building North Axis + Appendix G rotation (EnergyPlus's `BuildingAzimuth +
    /// BuildingRotationAppendixG`).
    building: f64,
    /// Appendix G rotation alone (the only one World coordinates get).
    appendix_g: f64,
}

impl Placement {
    /// Detailed vertices → world, by the Coordinate System.
    fn vertex(&self, p: DVec3, frame: Frame) -> DVec3 {
        if self.rules.world { self.world_frame(p, frame) } else { self.relative_frame(p, frame) }
    }

    fn relative_frame(&self, p: DVec3, frame: Frame) -> DVec3 {
        match frame {
            Frame::Zone(zone) => {
                let b = rotate(p, zone.rel_north) + DVec3::new(zone.origin.x, zone.origin.y, 0.0);
                rotate(b, self.building) + DVec3::new(0.0, 0.0, zone.origin.z)
            }
            Frame::Building => rotate(p, self.building),
            Frame::Site => p,
        }
    }

    fn world_frame(&self, p: DVec3, frame: Frame) -> DVec3 {
        match frame {
            Frame::Site => p,
            Frame::Zone(_) | Frame::Building => rotate(p, self.appendix_g),
        }
    }

    /// A rectangular surface's starting corner → world, by the Rectangular Surface Coordinate
    /// System (independent of the Coordinate System, as in EnergyPlus).
    fn corner(&self, p: DVec3, frame: Frame) -> DVec3 {
        if self.rules.rect_world { self.world_frame(p, frame) } else { self.relative_frame(p, frame) }
    }

    /// A rectangular surface's azimuth → world: it turns with the building only in Relative
    /// coordinates, with the Appendix G rotation always.
    fn azimuth(&self, azimuth: f64, frame: Frame) -> f64 {
        match frame {
            Frame::Zone(zone) if !self.rules.world => azimuth + self.building + zone.rel_north,
            Frame::Building if !self.rules.world => azimuth + self.building,
            Frame::Zone(_) | Frame::Building => azimuth + self.appendix_g,
            Frame::Site => azimuth,
        }
    }
}

/// Reading state: settings, then surfaces as they are found.
struct Reader<'a> {
    file: &'a str,
    layout: IddLayout,
    place: Placement,
    north_axis: f64,
    zones: HashMap<String, Zone>,
    surfaces: Vec<EpSurface>,
    /// Zone key (upper case) of each surface, for subsurfaces that place themselves by it.
    surface_zones: Vec<Option<String>>,
    /// Upper-case name → index into `surfaces`.
    index: HashMap<String, usize>,
    /// Classes that were read (IDD spelling).
    handled: Vec<&'static str>,
    warnings: Vec<String>,
}

fn key(name: &str) -> String {
    name.to_uppercase()
}

impl<'a> Reader<'a> {
    fn new(file: &'a str, objects: &[IdfObject], layout: IddLayout) -> Result<Self> {
        let mut warnings = Vec::new();
        let rules = match objects.iter().find(|o| o.is("GlobalGeometryRules")) {
            Some(o) => parse_rules(file, o)?,
            None => {
                warnings.push("no GlobalGeometryRules: assuming UpperLeftCorner, Counterclockwise, Relative coordinates".to_string());
                Rules::default()
            }
        };
        let building = objects.iter().find(|o| o.is("Building"));
        let north_axis = match building {
            Some(o) => number(file, o, 1, "North Axis", Some(0.0))?,
            None => 0.0,
        };
        let appendix_g = match objects.iter().find(|o| o.is("Compliance:Building")) {
            Some(o) => number(file, o, 0, "Building Rotation for Appendix G", Some(0.0))?,
            None => 0.0,
        };
        if let Some(o) = objects.iter().find(|o| o.is("GeometryTransform")) {
            warnings.push(format!("{} is ignored: the geometry is read as entered", o.label()));
        }
        let mut zones = HashMap::new();
        for o in objects.iter().filter(|o| o.is("Zone")) {
            let name = o.name().ok_or_else(|| Error::object(file, o.label(), "has no name"))?;
            zones.insert(key(name), parse_zone(file, o)?);
        }
        Ok(Reader {
            file,
            layout,
            place: Placement { rules, building: north_axis + appendix_g, appendix_g },
            north_axis,
            zones,
            surfaces: Vec::new(),
            surface_zones: Vec::new(),
            index: HashMap::new(),
            handled: SETTINGS.to_vec(),
            warnings,
        })
    }

    fn handles(&mut self, object: &IdfObject, classes: &[&'static str]) -> bool {
        match classes.iter().find(|c| object.is(c)) {
            Some(c) => {
                if !self.handled.contains(c) {
                    self.handled.push(c);
                }
                true
            }
            None => false,
        }
    }

    fn error(&self, object: &IdfObject, reason: impl Into<String>) -> Error {
        Error::object(self.file, object.label(), reason)
    }

    /// The Surface Type field (field 2) in its IDD spelling.
    fn surface_type(&self, object: &IdfObject, kinds: &[&'static str]) -> Result<&'static str> {
        let written = object.field(1);
        kinds
            .iter()
            .find(|k| k.eq_ignore_ascii_case(written))
            .copied()
            .ok_or_else(|| self.error(object, format!("Surface Type '{written}' is not one of {}", kinds.join(", "))))
    }

    /// Offset of the fields after Zone Name: one more when the file has Space Name fields.
    fn space(&self) -> usize {
        usize::from(self.layout.space_name)
    }

    fn zone(&self, object: &IdfObject, field: usize) -> Result<(String, &Zone)> {
        let name = object.field(field);
        if name.is_empty() {
            return Err(self.error(object, "has no Zone Name"));
        }
        match self.zones.get(&key(name)) {
            Some(zone) => Ok((key(name), zone)),
            None => Err(self.error(object, format!("zone '{name}' does not exist"))),
        }
    }

    fn base_surface(&mut self, object: &IdfObject) -> Result<()> {
        if self.handles(object, &["BuildingSurface:Detailed"]) {
            let kind = self.surface_type(object, &BASE_KINDS)?;
            let s = self.space();
            return self.detailed_zone_surface(object, kind.to_string(), 3, 4 + s);
        }
        for (class, kind) in [("Wall:Detailed", "Wall"), ("RoofCeiling:Detailed", "Roof"), ("Floor:Detailed", "Floor")] {
            if self.handles(object, &[class]) {
                let s = self.space();
                return self.detailed_zone_surface(object, kind.to_string(), 2, 3 + s);
            }
        }
        for rect in RECT_SURFACES {
            if self.handles(object, &[rect.class]) {
                return self.rectangular_surface(object, rect);
            }
        }
        if self.handles(object, &["Shading:Site:Detailed", "Shading:Building:Detailed"]) {
            let frame = if object.is("Shading:Site:Detailed") { Frame::Site } else { Frame::Building };
            let raw = vertices(self.file, object, 2, 3)?;
            let world: Vec<DVec3> = order(&raw, self.place.rules).iter().map(|&p| self.place.vertex(p, frame)).collect();
            return self.push(object, SHADING, "", None, world, None);
        }
        if self.handles(object, &["Shading:Site", "Shading:Building"]) {
            let frame = if object.is("Shading:Site") { Frame::Site } else { Frame::Building };
            let world = self.rectangle(object, 1, frame, 90.0)?;
            return self.push(object, SHADING, "", None, world, None);
        }
        Ok(())
    }

    /// BuildingSurface:Detailed and Wall/RoofCeiling/Floor:Detailed: zone at `zone_field`,
    /// Outside Boundary Condition at `boundary`, vertex count 5 fields later.
    fn detailed_zone_surface(&mut self, object: &IdfObject, kind: String, zone_field: usize, boundary: usize) -> Result<()> {
        let (zone_key, zone) = self.zone(object, zone_field)?;
        let raw = vertices(self.file, object, boundary + 5, boundary + 6)?;
        let world = order(&raw, self.place.rules).iter().map(|&p| self.place.vertex(p, Frame::Zone(zone))).collect();
        let no_sun = object.field(boundary + 2).trim().eq_ignore_ascii_case("NoSun");
        let boundary = object.field(boundary).to_string();
        self.push_exposed(object, &kind, &boundary, None, world, Some(zone_key), no_sun)
    }

    fn rectangular_surface(&mut self, object: &IdfObject, rect: &RectClass) -> Result<()> {
        let (zone_key, zone) = self.zone(object, 2)?;
        let zone = zone.clone();
        let first = 3 + self.space() + usize::from(rect.boundary_object);
        let world = self.rectangle(object, first, Frame::Zone(&zone), rect.tilt)?;
        self.push(object, rect.kind, rect.boundary, None, world, Some(zone_key))
    }

    /// Azimuth, tilt, starting x, y, z, length, height (or width) from field `first` on, as
    /// EnergyPlus's `MakeRectangularVertices`.
    fn rectangle(&self, object: &IdfObject, first: usize, frame: Frame, default_tilt: f64) -> Result<Vec<DVec3>> {
        let n = |i: usize, what: &str, default: Option<f64>| number(self.file, object, first + i, what, default);
        let azimuth = self.place.azimuth(n(0, "Azimuth Angle", Some(0.0))?, frame);
        let tilt = n(1, "Tilt Angle", Some(default_tilt))?;
        let start =
            DVec3::new(n(2, "Starting X Coordinate", None)?, n(3, "Starting Y Coordinate", None)?, n(4, "Starting Z Coordinate", None)?);
        let (length, height) = (n(5, "Length", None)?, n(6, "Height", None)?);
        Ok(rectangle(self.place.corner(start, frame), azimuth, tilt, length, height))
    }

    fn subsurface(&mut self, object: &IdfObject) -> Result<()> {
        if self.handles(object, &["FenestrationSurface:Detailed"]) {
            let count = 8 + usize::from(self.layout.shading_control);
            let (base, zone) = self.base_of(object, 3)?;
            let zone = zone.clone();
            let raw = vertices(self.file, object, count, count + 1)?;
            let world = order(&raw, self.place.rules).iter().map(|&p| self.place.vertex(p, Frame::Zone(&zone))).collect();
            let kind = self.surface_type(object, &FENESTRATION_KINDS)?;
            return self.push_subsurface(object, kind, base, world);
        }
        let shading_control = usize::from(self.layout.shading_control);
        // The interzone forms (Name, Construction, Building Surface Name, Outside Boundary
        // Condition Object, Multiplier, then the placement) are read too: each is a hole in its
        // interzone wall, so a zone's inside faces have EnergyPlus's net areas and the interior
        // beam can name the window it skips. Facing another zone, none is a receiver.
        for (class, kind, first) in [
            ("Window", "Window", 5 + shading_control),
            ("GlazedDoor", "GlassDoor", 5 + shading_control),
            ("Door", "Door", 4),
            ("Window:Interzone", "Window", 5),
            ("GlazedDoor:Interzone", "GlassDoor", 5),
            ("Door:Interzone", "Door", 5),
        ] {
            if self.handles(object, &[class]) {
                let (base, _) = self.base_of(object, 2)?;
                let frame = SurfaceFrame::of(&self.surfaces[base].vertices);
                let n = |i: usize, what: &str| number(self.file, object, first + i, what, None);
                let (x, z, length, height) =
                    (n(0, "Starting X Coordinate")?, n(1, "Starting Z Coordinate")?, n(2, "Length")?, n(3, "Height")?);
                let world = rectangle(frame.at(x, z), frame.azimuth, frame.tilt, length, height);
                return self.push_subsurface(object, kind, base, world);
            }
        }
        Ok(())
    }

    /// The base surface named in field `field` (an existing heat-transfer surface) and its zone.
    fn base_of(&self, object: &IdfObject, field: usize) -> Result<(usize, &Zone)> {
        let name = object.field(field);
        let Some(&base) = self.index.get(&key(name)) else {
            return Err(self.error(object, format!("base surface '{name}' does not exist")));
        };
        let zone = self.surface_zones[base].as_ref().and_then(|z| self.zones.get(z));
        match zone {
            Some(zone) if !self.surfaces[base].is_fenestration() => Ok((base, zone)),
            _ => Err(self.error(object, format!("'{name}' is not a heat-transfer base surface ({})", self.surfaces[base].label()))),
        }
    }

    fn push_subsurface(&mut self, object: &IdfObject, kind: &str, base: usize, world: Vec<DVec3>) -> Result<()> {
        let zone = self.surface_zones[base].clone();
        let boundary = self.surfaces[base].outside_boundary.clone();
        let base_name = self.surfaces[base].name.clone();
        let no_sun = self.surfaces[base].no_sun;
        self.push_exposed(object, kind, &boundary, Some(base_name), world, zone, no_sun)
    }

    fn attached_shading(&mut self, object: &IdfObject) -> Result<()> {
        if self.handles(object, &["Shading:Zone:Detailed"]) {
            let (base, zone) = self.base_of(object, 1)?;
            let zone = zone.clone();
            let raw = vertices(self.file, object, 3, 4)?;
            let world = order(&raw, self.place.rules).iter().map(|&p| self.place.vertex(p, Frame::Zone(&zone))).collect();
            let base_name = self.surfaces[base].name.clone();
            return self.push(object, SHADING, "", Some(base_name), world, None);
        }
        if self.handles(object, &["Shading:Overhang", "Shading:Overhang:Projection"]) {
            return self.overhang(object);
        }
        if self.handles(object, &["Shading:Fin", "Shading:Fin:Projection"]) {
            return self.fins(object);
        }
        Ok(())
    }

    /// The window or door named in field 1, with its base surface: the frames overhangs and fins
    /// are placed in.
    fn window_of(&self, object: &IdfObject) -> Result<(usize, usize)> {
        let name = object.field(1);
        match self.index.get(&key(name)) {
            Some(&w) if self.surfaces[w].is_fenestration() => {
                let base = self.surfaces[w].base.as_deref().and_then(|b| self.index.get(&key(b)).copied());
                base.map(|b| (w, b)).ok_or_else(|| self.error(object, format!("window or door '{name}' has no base surface")))
            }
            Some(&w) => Err(self.error(object, format!("'{name}' is not a window or door ({})", self.surfaces[w].label()))),
            None => Err(self.error(object, format!("window or door '{name}' does not exist"))),
        }
    }

    /// Shading:Overhang(:Projection), as EnergyPlus's `GetSimpleShdSurfaceData`.
    fn overhang(&mut self, object: &IdfObject) -> Result<()> {
        let (w, b) = self.window_of(object)?;
        let n = |i: usize, what: &str, default: Option<f64>| number(self.file, object, i, what, default);
        let (above, tilt_from) = (n(2, "Height above Window or Door", Some(0.0))?, n(3, "Tilt Angle from Window/Door", Some(90.0))?);
        let (left, right, depth) = (n(4, "Left extension", Some(0.0))?, n(5, "Right extension", Some(0.0))?, n(6, "Depth", None)?);
        let window = WindowFrame::of(&self.surfaces[w].vertices, &self.surfaces[b].vertices);
        let depth = if object.is("Shading:Overhang:Projection") { depth * window.height } else { depth };
        let length = left + right + window.width;
        if length * depth <= 0.0 {
            self.warnings.push(format!("{} has no area (length {length} m, depth {depth} m) and is left out", object.label()));
            return Ok(());
        }
        let corner = window.base.at(window.x - left, window.z + window.height + above);
        let world = rectangle(corner, window.own.azimuth, window.own.tilt + tilt_from, length, depth);
        let base = self.surfaces[b].name.clone();
        self.push(object, SHADING, "", Some(base), world, None)
    }

    /// Shading:Fin(:Projection): two surfaces, `<name> Left` and `<name> Right`, as EnergyPlus.
    fn fins(&mut self, object: &IdfObject) -> Result<()> {
        let (w, b) = self.window_of(object)?;
        let window = WindowFrame::of(&self.surfaces[w].vertices, &self.surfaces[b].vertices);
        let projection = object.is("Shading:Fin:Projection");
        let base = self.surfaces[b].name.clone();
        for (side, first) in [("Left", 2), ("Right", 7)] {
            let n = |i: usize, what: &str, default: Option<f64>| number(self.file, object, first + i, what, default);
            let extension = n(0, "Extension from Window/Door", Some(0.0))?;
            let (above, below) = (n(1, "Distance Above Top of Window", Some(0.0))?, n(2, "Distance Below Bottom of Window", Some(0.0))?);
            let (tilt_from, depth) = (n(3, "Tilt Angle from Window/Door", Some(90.0))?, n(4, "Depth", None)?);
            let depth = if projection { depth * window.width } else { depth };
            let length = above + below + window.height;
            let name = format!("{} {side}", object.field(0));
            if length * depth <= 0.0 {
                self.warnings.push(format!("{side} fin of {} has no area and is left out", object.label()));
                continue;
            }
            let x = if side == "Left" { window.x - extension } else { window.x + window.width + extension };
            let corner = window.base.at(x, window.z - below);
            let azimuth = window.own.azimuth - (180.0 - tilt_from);
            let world = rectangle(corner, azimuth, window.own.tilt, -depth, length);
            let fin = IdfObject { class: object.class.clone(), fields: vec![name], ..object.clone() };
            self.push(&fin, SHADING, "", Some(base.clone()), world, None)?;
        }
        Ok(())
    }

    fn push(
        &mut self,
        object: &IdfObject,
        kind: &str,
        boundary: &str,
        base: Option<String>,
        vertices: Vec<DVec3>,
        zone: Option<String>,
    ) -> Result<()> {
        self.push_exposed(object, kind, boundary, base, vertices, zone, false)
    }

    /// As [`Self::push`], with the surface's `Sun Exposure` (`no_sun`: NoSun, or a window's base
    /// surface's). A surface receives only where EnergyPlus lets the sun onto it (its
    /// `ExtSolar`): Outside Boundary Condition Outdoors (a window's or door's is its base
    /// surface's) and not NoSun. EnergyPlus keeps the others dark whatever schedule they are
    /// given, so an exterior surface, window or door kept dark is said in the warnings.
    #[allow(clippy::too_many_arguments)] // push's fields plus the exposure; a struct would only rename them.
    fn push_exposed(
        &mut self,
        object: &IdfObject,
        kind: &str,
        boundary: &str,
        base: Option<String>,
        vertices: Vec<DVec3>,
        zone: Option<String>,
        no_sun: bool,
    ) -> Result<()> {
        let Some(name) = object.name() else { return Err(self.error(object, "has no name")) };
        if let Some(&other) = self.index.get(&key(name)) {
            let first = self.surfaces[other].label();
            return Err(
                self.error(object, format!("surface name '{name}' is already used by {first} (EnergyPlus names are case-insensitive)"))
            );
        }
        let area = newell(&vertices).length();
        if area < MIN_AREA || !area.is_finite() {
            return Err(self.error(object, format!("has no area ({area:.3e} m²): its vertices are collinear or coincide")));
        }
        let fenestration = FENESTRATION_KINDS.iter().any(|k| kind.eq_ignore_ascii_case(k));
        let outdoors = boundary.eq_ignore_ascii_case(OUTDOORS);
        let receiver = kind != SHADING && outdoors && !no_sun;
        if kind != SHADING && !receiver && (fenestration || outdoors) {
            let why = match (&base, outdoors) {
                (Some(b), false) if fenestration => format!("its base surface '{b}' has Outside Boundary Condition {boundary}"),
                (Some(b), _) if fenestration => format!("its base surface '{b}' has Sun Exposure NoSun"),
                _ => "its Sun Exposure is NoSun".to_string(),
            };
            self.warnings.push(format!(
                "{} gets no sunlit fraction: EnergyPlus keeps it dark ({why}) and ignores any schedule given to it",
                object_label(&object.class, Some(name), object.line)
            ));
        }
        let surface = EpSurface {
            name: name.to_string(),
            class: object.class.clone(),
            kind: kind.to_string(),
            outside_boundary: boundary.to_string(),
            base,
            vertices,
            line: object.line,
            receiver,
            no_sun,
            zone: zone.clone(),
        };
        let deviation = plane_deviation(&surface.vertices);
        if deviation > PLANAR_TOLERANCE {
            let flattened = if receiver { "; as a receiver it is flattened onto that plane" } else { "" };
            self.warnings
                .push(format!("{} is not planar: a vertex is {deviation:.4} m from its best-fit plane{flattened}", surface.label()));
        }
        self.index.insert(key(name), self.surfaces.len());
        self.surfaces.push(surface);
        self.surface_zones.push(zone);
        Ok(())
    }

    fn finish(mut self, version: Option<String>, skipped: Vec<String>) -> Result<Building> {
        // File order for receivers and output columns; fins of one object stay left, right.
        self.surfaces.sort_by_key(|s| s.line);
        let mut building = Building {
            file: self.file.to_string(),
            version,
            north_axis: self.north_axis,
            surfaces: self.surfaces,
            skipped,
            warnings: self.warnings,
        };
        for (i, surface) in building.surfaces.iter().enumerate() {
            if let Some(base) = surface.base.as_deref().filter(|_| surface.is_fenestration()) {
                let base = building.surfaces.iter().find(|b| b.name.eq_ignore_ascii_case(base));
                if let Some(why) = base.and_then(|b| hole_problem(b, surface)) {
                    building.warnings.push(format!("{} {why}; it is not cut out of its base surface", building.surfaces[i].label()));
                }
                if let Some(why) = base.and_then(|b| reveal_problem(b, surface)) {
                    building.warnings.push(format!("{} {why}", building.surfaces[i].label()));
                }
            }
        }
        Ok(building)
    }
}

/// A simple surface class: kind, boundary condition and defaults.
struct RectClass {
    class: &'static str,
    kind: &'static str,
    boundary: &'static str,
    /// Whether an Outside Boundary Condition Object field follows Space Name.
    boundary_object: bool,
    tilt: f64,
}

const fn rect(class: &'static str, kind: &'static str, boundary: &'static str, boundary_object: bool, tilt: f64) -> RectClass {
    RectClass { class, kind, boundary, boundary_object, tilt }
}

const RECT_SURFACES: &[RectClass] = &[
    rect("Wall:Exterior", "Wall", OUTDOORS, false, 90.0),
    rect("Wall:Adiabatic", "Wall", "Adiabatic", false, 90.0),
    rect("Wall:Underground", "Wall", "Ground", false, 90.0),
    rect("Wall:Interzone", "Wall", "Surface", true, 90.0),
    rect("Roof", "Roof", OUTDOORS, false, 0.0),
    rect("Ceiling:Adiabatic", "Ceiling", "Adiabatic", false, 0.0),
    rect("Ceiling:Interzone", "Ceiling", "Surface", true, 0.0),
    rect("Floor:GroundContact", "Floor", "Ground", false, 180.0),
    rect("Floor:Adiabatic", "Floor", "Adiabatic", false, 180.0),
    rect("Floor:Interzone", "Floor", "Surface", true, 180.0),
];

fn skipped_classes(objects: &[IdfObject], handled: &[&str]) -> Vec<String> {
    let mut skipped: Vec<String> = Vec::new();
    for o in objects {
        let known = handled.iter().any(|h| o.is(h)) || skipped.iter().any(|s| o.is(s));
        if !known {
            skipped.push(o.class.clone());
        }
    }
    skipped
}

fn parse_rules(file: &str, o: &IdfObject) -> Result<Rules> {
    let bad = |field: &str, value: &str| Error::object(file, o.label(), format!("{field} '{value}' is not one EnergyPlus knows"));
    let corner_text = o.field(0).to_ascii_uppercase();
    let corner = match corner_text.as_str() {
        "UPPERLEFTCORNER" | "ULC" | "" => 1,
        "LOWERLEFTCORNER" | "LLC" => 2,
        "LOWERRIGHTCORNER" | "LRC" => 3,
        "UPPERRIGHTCORNER" | "URC" => 4,
        _ => return Err(bad("Starting Vertex Position", o.field(0))),
    };
    let clockwise = match o.field(1).to_ascii_uppercase().as_str() {
        "COUNTERCLOCKWISE" | "CCW" | "" => false,
        "CLOCKWISE" | "CW" => true,
        _ => return Err(bad("Vertex Entry Direction", o.field(1))),
    };
    let system = |i: usize, what: &str| -> Result<bool> {
        let value = o.field(i).to_ascii_uppercase();
        if value.is_empty() || value.starts_with("RELATIVE") || value == "RCS" {
            Ok(false)
        } else if value.starts_with("WORLD") || value.starts_with("ABSOLUTE") || value == "WCS" {
            Ok(true)
        } else {
            Err(bad(what, o.field(i)))
        }
    };
    Ok(Rules { corner, clockwise, world: system(2, "Coordinate System")?, rect_world: system(4, "Rectangular Surface Coordinate System")? })
}

fn parse_zone(file: &str, o: &IdfObject) -> Result<Zone> {
    let n = |i: usize, what: &str| number(file, o, i, what, Some(0.0));
    Ok(Zone {
        rel_north: n(1, "Direction of Relative North")?,
        origin: DVec3::new(n(2, "X Origin")?, n(3, "Y Origin")?, n(4, "Z Origin")?),
    })
}

/// Numeric field `i`; blank gives `default` (an error when there is none).
fn number(file: &str, o: &IdfObject, i: usize, what: &str, default: Option<f64>) -> Result<f64> {
    let text = o.field(i);
    if text.is_empty() {
        return default.ok_or_else(|| Error::object(file, o.label(), format!("field {} ({what}) is missing", i + 1)));
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(Error::object(file, o.label(), format!("field {} ({what}) '{text}' is not a number", i + 1))),
    }
}

/// The vertex list: Number of Vertices at field `count` (blank or autocalculate: as many as
/// given), x, y, z triples from field `first`.
fn vertices(file: &str, o: &IdfObject, count: usize, first: usize) -> Result<Vec<DVec3>> {
    let err = |reason: String| Error::object(file, o.label(), reason);
    let mut coords: &[String] = o.fields.get(first..).unwrap_or(&[]);
    while coords.last().is_some_and(|c| c.is_empty()) {
        coords = &coords[..coords.len() - 1];
    }
    if !coords.len().is_multiple_of(3) {
        return Err(err(format!("has {} vertex coordinates, not x, y, z triples", coords.len())));
    }
    let given = coords.len() / 3;
    let stated = o.field(count);
    if !stated.is_empty() && !stated.eq_ignore_ascii_case("autocalculate") {
        match stated.parse::<f64>() {
            Ok(n) if n == given as f64 => {}
            Ok(n) => return Err(err(format!("Number of Vertices is {n} but {given} vertices are given"))),
            Err(_) => return Err(err(format!("Number of Vertices '{stated}' is not a number"))),
        }
    }
    if given < 3 {
        return Err(err(format!("has {given} vertices; a surface needs at least 3")));
    }
    coords
        .chunks_exact(3)
        .enumerate()
        .map(|(k, xyz)| {
            let c = |j: usize| {
                xyz[j]
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| err(format!("vertex {} {}-coordinate '{}' is not a number", k + 1, ["x", "y", "z"][j], xyz[j])))
            };
            Ok(DVec3::new(c(0)?, c(1)?, c(2)?))
        })
        .collect()
}

/// Counter-clockwise from outside, starting at the upper-left corner (EnergyPlus's storage order:
/// a Clockwise list keeps vertex 1 and reverses the rest; then the list is rotated left by
/// `(n − corner + 1) mod n`).
fn order(raw: &[DVec3], rules: Rules) -> Vec<DVec3> {
    let mut v: Vec<DVec3> = raw.to_vec();
    if rules.clockwise && v.len() > 1 {
        v[1..].reverse();
    }
    let n = v.len();
    if n > 0 {
        v.rotate_left((n + 1 - rules.corner.min(n + 1)) % n);
    }
    v
}
