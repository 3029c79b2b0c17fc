//! The sun inside rooms: points on the inside faces of a model's zones or free in them (a work
//! plane), the beam through the windows, sun patches at an instant, sums over a period, LEED
//! v4.1's Annual Sunlight Exposure and BRE 209's No-Sky Line.
//!
//! A view through a window is a request to the same engines: the scene is the building with its
//! glazing left out ([`crate::model::inside::inside_scene`]), so an opening is a hole in its wall
//! and the exact engine's shadow rays decide, as outside, whether a point sees the sun; walls,
//! frames, doors, overhangs stay opaque. The glass then weights the beam: a lit point's ray
//! leaves its room through one of the room's openings, and the beam is multiplied by the
//! transmittance of each opening of the room the ray crosses ([`crate::model::inside::Glazing`]).
//! Each transmittance is the glass's at the beam's angle of incidence on it (EnergyPlus's
//! angular dependence, as for the interior beam). `lit` stays geometry (lit through glass is
//! lit); the weights are separate values.
//!
//! Free points (not on an inside face) get a plane of their own: a receiver that is no geometry
//! (no triangle carries its id, so it casts nothing and the GPU cannot draw it), through the
//! points with their normal. The work plane of a floor is that floor's inside face raised by the
//! height. A shadow ray from a point needs only what lies in front of its plane, which is what
//! the engine clips to.
//!
//! Illuminance of the direct sun on a point: the EPW's direct normal illuminance (field 18) ×
//! visible transmittance × cos incidence × visibility, or, for an hour without it, the direct
//! normal irradiance × [`BEAM_EFFICACY`].

use glam::{DVec2, DVec3};

use super::planning::compare;
use super::points::{csv_rows, receiver_under};
use super::{Mapper, Points, Sample, Site, grid};
use crate::count::ViewRequest;
use crate::count::exact::engine::ExactEngine;
use crate::error::{Error, Result};
use crate::geometry::triangle_area;
use crate::model::inside::Rooms;
use crate::scene::{Receiver, ReceiverDraw, Scene};
use crate::sun::weather::Weather;
use crate::year::samples::Timesteps;

/// IES LM-83-12's work plane height (m): 30 in above the floor.
pub const WORK_PLANE_HEIGHT: f64 = 0.76;
/// IES LM-83-12's grid spacing (m): 2 ft.
pub const ASE_SPACING: f64 = 0.6;
/// ASE's direct-sun illuminance threshold (lux): a point counts an hour above it.
pub const ASE_LUX: f64 = 1000.0;
/// ASE's hours: a point is sunlit when it gets more than this many hours above [`ASE_LUX`].
pub const ASE_HOURS: f64 = 250.0;
/// Occupied hours for ASE, local standard time (LM-83: 08:00–18:00 local clock time; no
/// daylight saving shift is applied, see docs/maps.md).
pub const OCCUPIED: (f64, f64) = (8.0, 18.0);
/// Luminous efficacy of the direct beam (lm/W) for hours whose EPW gives no direct normal
/// illuminance: a round mid-range value for clear-sky beam light.
pub const BEAM_EFFICACY: f64 = 100.0;
/// Free points of one room are one plane when their normals agree this closely (cosine)…
const SAME_NORMAL: f64 = 1.0 - 1e-9;
/// …and their heights along it within this (m).
const SAME_PLANE: f64 = 1e-6;
/// A free plane's rectangle reaches this far (m) past its outermost points.
const PLANE_MARGIN: f64 = 0.01;

/// Map points inside rooms, and the room (index into [`Rooms::rooms`]) each lies in.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RoomPoints {
    /// The points (their receivers: inside faces or free planes).
    pub points: Points,
    /// Per point, its room.
    pub room: Vec<u32>,
}

/// A grid at `spacing` on every room's floors, `height` m above them (0: on the floor's inside
/// face). A raised grid lies on a plane of its own per floor, named `FLOOR:work-plane`, added to
/// `scene`. Refuses a room without a floor, naming its zone.
pub fn floor_grid(scene: &mut Scene, rooms: &Rooms, spacing: f64, height: f64) -> Result<RoomPoints> {
    if !(height.is_finite() && height >= 0.0) {
        return Err(Error::argument("work_plane", format!("{height} m: a work plane height must be 0 or more metres")));
    }
    let mut out = RoomPoints::default();
    for (k, room) in rooms.rooms.iter().enumerate() {
        if room.floors.is_empty() {
            return Err(Error::argument("rooms", format!("zone '{}' has no floor to put a grid on", room.name)));
        }
        for floor in &room.floors {
            let (id, r) = scene.receiver(floor).ok_or_else(|| Error::argument("rooms", format!("'{floor}' is not a receiver")))?;
            let id = if height > 0.0 {
                let raised = r.triangles.iter().map(|t| t.map(|p| p + DVec3::Z * height)).collect();
                let (name, origin, normal) = (format!("{}:work-plane", r.name.trim_end_matches(":inside")), r.origin.clone(), r.normal);
                add_plane(scene, name, origin, raised, normal)
            } else {
                id
            };
            let mut points = grid(scene, spacing, &[id])?;
            out.room.extend(std::iter::repeat_n(k as u32, points.len()));
            append(&mut out.points, &mut points);
            out.points.spacing = Some(spacing);
        }
    }
    Ok(out)
}

/// [`floor_grid`]'s points, then a grid at the same `spacing` on every other inside face of each
/// room (walls, roofs, ceilings: the faces a sun patch can reach besides the floors), so that an
/// instant's patch is drawn on each face it lies on. The cells are the floors', and each point
/// stands for `spacing²` of its face, as on the floors.
pub fn face_grid(scene: &mut Scene, rooms: &Rooms, spacing: f64, height: f64) -> Result<RoomPoints> {
    let mut out = floor_grid(scene, rooms, spacing, height)?;
    for (k, room) in rooms.rooms.iter().enumerate() {
        for face in room.inside.iter().filter(|f| !room.floors.contains(f)) {
            let (id, _) = scene.receiver(face).ok_or_else(|| Error::argument("rooms", format!("'{face}' is not a receiver")))?;
            let mut points = grid(scene, spacing, &[id])?;
            out.room.extend(std::iter::repeat_n(k as u32, points.len()));
            append(&mut out.points, &mut points);
        }
    }
    Ok(out)
}

/// Points from a CSV (`x,y,z,nx,ny,nz`, as [`super::from_csv`] reads): a point on a room's
/// inside face (within [`super::points::ON_SURFACE_TOLERANCE`], facing its way) belongs to that
/// face, any other to the room it lies in, on a plane of its own shared with the room's other
/// free points in the same plane. Refuses a point in no room, naming file and line.
pub fn room_points_csv(scene: &mut Scene, rooms: &Rooms, file_label: &str, text: &str) -> Result<RoomPoints> {
    let inside: Vec<(u32, u32)> = rooms
        .rooms
        .iter()
        .enumerate()
        .flat_map(|(k, room)| room.inside.iter().map(move |name| (k as u32, name)))
        .filter_map(|(k, name)| scene.receiver(name).map(|(id, _)| (id, k)))
        .collect();
    let ids: Vec<u32> = inside.iter().map(|(id, _)| *id).collect();
    let mut out = RoomPoints::default();
    // Free points: (room, normal, height along it, [(index in out, position)]).
    let mut free: Vec<(u32, DVec3, f64, Vec<usize>)> = Vec::new();
    for (line, p, n) in csv_rows(file_label, text)? {
        if let Some(id) = receiver_under(scene, &ids, p, n) {
            let room = inside.iter().find(|(r, _)| *r == id).map_or(0, |(_, k)| *k);
            out.points.push(p, n, id);
            out.room.push(room);
            continue;
        }
        let Some(room) = rooms.rooms.iter().position(|r| r.contains(p)) else {
            return Err(Error::object(file_label, format!("line {line}"), format!("point ({}, {}, {}) lies in no zone", p.x, p.y, p.z)));
        };
        let (room, h) = (room as u32, n.dot(p));
        let i = out.points.len();
        out.points.push(p, n, u32::MAX);
        out.room.push(room);
        match free.iter_mut().find(|(r, m, g, _)| *r == room && m.dot(n) >= SAME_NORMAL && (g - h).abs() <= SAME_PLANE) {
            Some((_, _, _, members)) => members.push(i),
            None => free.push((room, n, h, vec![i])),
        }
    }
    for (k, (room, normal, _, members)) in free.into_iter().enumerate() {
        let at: Vec<DVec3> = members.iter().map(|&i| out.points.position(i)).collect();
        let name = format!("{} free plane {}", rooms.rooms[room as usize].name, k + 1);
        let id = add_plane(scene, name, format!("{file_label}: free points"), rectangle_around(&at, normal), normal);
        for i in members {
            out.points.receivers[i] = id;
        }
    }
    Ok(out)
}

/// Two triangles covering `points` (in the plane through them with `normal`), with a margin.
fn rectangle_around(points: &[DVec3], normal: DVec3) -> Vec<[DVec3; 3]> {
    let (e1, e2) = (normal.any_orthonormal_vector(), normal.cross(normal.any_orthonormal_vector()));
    let origin = points[0];
    let flat = |p: &DVec3| DVec2::new((*p - origin).dot(e1), (*p - origin).dot(e2));
    let (lo, hi) = points.iter().map(flat).fold((DVec2::MAX, DVec2::MIN), |(lo, hi), q| (lo.min(q), hi.max(q)));
    let (lo, hi) = (lo - DVec2::splat(PLANE_MARGIN), hi + DVec2::splat(PLANE_MARGIN));
    let at = |u: f64, v: f64| origin + e1 * u + e2 * v;
    let (a, b, c, d) = (at(lo.x, lo.y), at(hi.x, lo.y), at(hi.x, hi.y), at(lo.x, hi.y));
    // Counter-clockwise about `normal` (e1 × e2 = normal).
    vec![[a, b, c], [a, c, d]]
}

/// Adds a receiver that is no geometry (see the module doc); returns its id.
fn add_plane(scene: &mut Scene, name: String, origin: String, triangles: Vec<[DVec3; 3]>, normal: DVec3) -> u32 {
    let id = scene.receivers.len() as u32;
    let area = triangles.iter().map(triangle_area).sum();
    scene.receivers.push(Receiver { name, origin, triangles, normal, area, draw: ReceiverDraw { instance: 0, indices: 0..0 }, gpu_id: id });
    id
}

fn append(into: &mut Points, from: &mut Points) {
    into.positions.append(&mut from.positions);
    into.normals.append(&mut from.normals);
    into.receivers.append(&mut from.receivers);
}

/// What the inside's sweeps read: the points' rays, their rooms and where they lie.
#[derive(Clone, Copy)]
pub struct InsideMap<'a> {
    /// The points indexed for the exact engine's rays (made from `at.points`).
    pub mapper: &'a Mapper,
    /// The zones and their glazing.
    pub rooms: &'a Rooms,
    /// The points and their rooms.
    pub at: &'a RoomPoints,
}

/// Per point, the glass between it and the sun: the product of the transmittances (solar,
/// visible) of its room's openings its ray to the sun crosses, each at the ray's incidence on
/// it ([`crate::model::inside::Glazing::solar_at`], the same curves as the interior beam). A ray
/// that leaves by an interzone window goes on through the next room, whose openings it crosses
/// weight it too (its copy of that window, the same pane, once): a beam that came in through
/// another room's window and an interzone pane has crossed both.
pub fn through_glass(rooms: &Rooms, room: u32, p: DVec3, sun: DVec3) -> (f64, f64) {
    let (mut weights, mut here, mut entered_by) = ((1.0, 1.0), room as usize, None);
    // Each room once at most: a straight ray cannot come back through a pane it crossed.
    for _ in 0..rooms.rooms.len() {
        let Some(at) = rooms.rooms.get(here) else { break };
        let mut next = None;
        for &k in at.glazing.iter().filter(|&&k| Some(k) != entered_by) {
            let g = &rooms.glazing[k];
            if !g.crossed_by(p, sun) {
                continue;
            }
            // Either side's normal: the beam crosses the glass one way or the other.
            let cos = g.plane.normal.dot(sun).abs();
            weights = (weights.0 * g.solar_at(cos), weights.1 * g.visible_at(cos));
            if g.interzone {
                next = rooms.twin_of(k);
            }
        }
        let Some((room, twin)) = next else { break };
        (here, entered_by) = (room, Some(twin));
    }
    weights
}

/// One instant inside: per point its geometric visibility (`lit`: 1 lit, also through glass; 0
/// shaded) and the glass's weights on it (solar, visible; 0 where shaded).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InsideInstant {
    /// 1 lit, 0 shaded (visibility ≥ 0.5, as outside).
    pub lit: Vec<f64>,
    /// Solar transmittance of the glass the beam came through (1 with no glass); 0 shaded.
    pub solar_transmittance: Vec<f64>,
    /// Visible transmittance likewise.
    pub visible_transmittance: Vec<f64>,
}

/// The points' lit state and glass weights for the sun along `sun` at leaf fraction `leaves`.
pub fn instant(map: InsideMap<'_>, sun: DVec3, leaves: f32) -> InsideInstant {
    let InsideMap { mapper, rooms, at } = map;
    let visibility = mapper.visibility(sun, leaves);
    let mut out = InsideInstant::default();
    for (i, v) in visibility.into_iter().enumerate() {
        let lit = v >= 0.5;
        let (s, t) = if lit { through_glass(rooms, at.room[i], at.points.position(i), sun) } else { (0.0, 0.0) };
        out.lit.push(f64::from(u8::from(lit)));
        out.solar_transmittance.push(s * f64::from(v));
        out.visible_transmittance.push(t * f64::from(v));
    }
    out
}

/// One inside face's sun patch at an instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// The inside face (`NAME:inside`).
    pub surface: String,
    /// Its zone.
    pub zone: String,
    /// Sunlit area (m²), geometry (the glass's weight not applied), by the exact engine.
    pub area_m2: f64,
    /// Sunlit fraction of the face's net area.
    pub fraction: f64,
}

/// The sun patch on every inside face of every room (those with a patch), by the exact engine's
/// clipping (the same request as a sunlit fraction outside, the receiver an inside face).
pub fn sun_patches(scene: &Scene, rooms: &Rooms, sun: DVec3, leaves: f32) -> Vec<Patch> {
    let faces: Vec<(u32, &str)> = rooms
        .rooms
        .iter()
        .flat_map(|room| room.inside.iter().map(move |face| (face, room.name.as_str())))
        .filter_map(|(face, zone)| scene.receiver(face).map(|(id, _)| (id, zone)))
        .collect();
    let requests: Vec<ViewRequest> = faces.iter().map(|&(receiver, _)| ViewRequest { receiver, sun, leaves }).collect();
    let fractions = ExactEngine::new(scene).fractions(&requests);
    faces
        .iter()
        .zip(fractions)
        .filter(|(_, f)| *f > 0.0)
        .map(|(&(id, zone), fraction)| {
            let r = &scene.receivers[id as usize];
            Patch { surface: r.name.clone(), zone: zone.to_string(), area_m2: fraction * r.area, fraction }
        })
        .collect()
}

/// One instant inside, as `sunlit map --inside --at` and the page's interior view answer it: the
/// points ([`instant`]) and, with the sun up, every inside face's sun patch ([`sun_patches`]).
pub fn instant_with_patches(scene: &Scene, map: InsideMap<'_>, sun: DVec3, leaves: f32) -> (InsideInstant, Vec<Patch>) {
    let rooms = map.rooms;
    let values = instant(map, sun, leaves);
    let up = sun.z >= crate::count::MIN_COS_INCIDENCE;
    (values, if up { sun_patches(scene, rooms, sun, leaves) } else { Vec::new() })
}

/// Per point sums inside over a period.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InsideValues {
    /// Hours the sun is seen (geometry: through glass counts in full).
    pub sun_hours: Vec<f64>,
    /// Beam irradiation through the glass (kWh/m²): DNI · cos incidence · solar transmittance.
    pub beam_kwh_m2: Option<Vec<f64>>,
    /// Direct-sun illuminance summed over time (klux·h): see the module doc.
    pub direct_klux_h: Option<Vec<f64>>,
    /// Instants in the period.
    pub instants: usize,
    /// Sun-up hours whose EPW had no direct normal illuminance ([`BEAM_EFFICACY`] used).
    pub efficacy_hours: usize,
}

impl InsideValues {
    /// Adds the sums of `other` (another stretch of the same points' period), so a period summed
    /// in chunks (the page's, with progress and abort between them) adds up to the one call.
    pub fn merge(&mut self, other: &InsideValues) {
        super::add_into(&mut self.sun_hours, &other.sun_hours);
        for (mine, theirs) in [(&mut self.beam_kwh_m2, &other.beam_kwh_m2), (&mut self.direct_klux_h, &other.direct_klux_h)] {
            if let (Some(a), Some(b)) = (mine.as_mut(), theirs.as_ref()) {
                super::add_into(a, b);
            }
        }
        self.instants += other.instants;
        self.efficacy_hours += other.efficacy_hours;
    }
}

/// The direct beam at an instant: DNI (W/m²) and direct normal illuminance (lux), the latter
/// from [`BEAM_EFFICACY`] when the EPW has none.
fn beam(weather: &Weather, s: &Sample) -> (f64, f64) {
    let dni = Timesteps::new(1).map_or(0.0, |t| weather.at(t, s.epw_hour).dni);
    match weather.direct_normal_illuminance(s.epw_hour) {
        Some(lux) => (dni, lux),
        None => (dni, dni * BEAM_EFFICACY),
    }
}

/// Instants of `samples` whose EPW hour has no direct normal illuminance ([`BEAM_EFFICACY`]
/// used): a period's and LEED ASE's `efficacy_hours`.
pub fn efficacy_hours(weather: &Weather, samples: &[Sample]) -> usize {
    samples.iter().filter(|s| weather.direct_normal_illuminance(s.epw_hour).is_none()).count()
}

/// Sun hours, and with weather the beam irradiation and direct-sun illuminance through the
/// glass, per point over `samples`.
pub fn accumulate(map: InsideMap<'_>, samples: &[Sample], site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> InsideValues {
    let InsideMap { mapper, rooms, at } = map;
    let n = at.points.len();
    let weather = site.weather;
    let parts = mapper.sweep(
        samples,
        site,
        false,
        progress,
        || (vec![0.0; n], vec![0.0; n], vec![0.0; n]),
        |(hours, beam_sum, lux_sum), _, s, sun, g, vis| {
            let light = weather.map(|w| beam(w, s));
            for (&i, &v) in g.members.iter().zip(vis).filter(|(_, v)| **v > 0.0) {
                let i = i as usize;
                hours[i] += f64::from(v) * s.hours;
                if let Some((dni, lux)) = light {
                    let (ts, tv) = through_glass(rooms, at.room[i], at.points.position(i), sun);
                    let cos = mapper.normals[i].dot(sun).max(0.0) * f64::from(v) * s.hours;
                    beam_sum[i] += dni * cos * ts / 1000.0;
                    lux_sum[i] += lux * cos * tv / 1000.0;
                }
            }
        },
    );
    let mut out = InsideValues {
        sun_hours: vec![0.0; n],
        beam_kwh_m2: weather.map(|_| vec![0.0; n]),
        direct_klux_h: weather.map(|_| vec![0.0; n]),
        instants: samples.len(),
        efficacy_hours: 0,
    };
    for (hours, beam_sum, lux_sum) in parts {
        super::add_into(&mut out.sun_hours, &hours);
        if let (Some(b), Some(l)) = (out.beam_kwh_m2.as_mut(), out.direct_klux_h.as_mut()) {
            super::add_into(b, &beam_sum);
            super::add_into(l, &lux_sum);
        }
    }
    out.efficacy_hours = weather.map_or(0, |w| efficacy_hours(w, samples));
    out
}

/// One room's Annual Sunlight Exposure.
#[derive(Debug, Clone, PartialEq)]
pub struct AseArea {
    /// The zone.
    pub zone: String,
    /// Its points.
    pub points: usize,
    /// Share of its points (so of its area: a grid's points stand for equal areas) with more
    /// than [`ASE_HOURS`] occupied hours above [`ASE_LUX`] of direct sun, in %.
    pub ase: f64,
}

/// ASE1000,250 over a year.
#[derive(Debug, Clone, PartialEq)]
pub struct AseResult {
    /// Per point, occupied hours above [`ASE_LUX`].
    pub hours: Vec<f64>,
    /// Per room with points, in the rooms' order.
    pub areas: Vec<AseArea>,
    /// Occupied instants counted (hourly: 3,650 in a 365-day year).
    pub occupied: usize,
    /// Occupied hours whose EPW had no direct normal illuminance ([`BEAM_EFFICACY`] used).
    pub efficacy_hours: usize,
}

/// The year's occupied instants: EnergyPlus's hourly instants (mid-hour, local standard time)
/// within [`OCCUPIED`].
pub fn occupied_hours(samples: &[Sample]) -> Vec<Sample> {
    samples.iter().filter(|s| s.hour >= OCCUPIED.0 && s.hour < OCCUPIED.1).copied().collect()
}

/// LEED v4.1's ASE1000,250 (IES LM-83-12) per room: per point, the occupied hours of `samples`
/// (see [`occupied_hours`]) when its direct-sun illuminance through the glass (visible
/// transmittance) exceeds [`ASE_LUX`] ([`ase_hours`]); per room the share of its points over
/// [`ASE_HOURS`] ([`ase_areas`]). Refuses a site without weather.
pub fn leed_ase(map: InsideMap<'_>, samples: &[Sample], site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> Result<AseResult> {
    let hours = ase_hours(map, samples, site, progress)?;
    let efficacy_hours = site.weather.map_or(0, |w| efficacy_hours(w, samples));
    Ok(AseResult { areas: ase_areas(map, &hours), hours, occupied: samples.len(), efficacy_hours })
}

/// Per point, the hours of `samples` with more than [`ASE_LUX`] of direct sun through the glass:
/// [`leed_ase`]'s sums, which add over stretches of the year (the page sums them in chunks).
/// Refuses a site without weather.
pub fn ase_hours(map: InsideMap<'_>, samples: &[Sample], site: Site<'_>, progress: &mut dyn FnMut(usize, usize)) -> Result<Vec<f64>> {
    let InsideMap { mapper, rooms, at } = map;
    let Some(weather) = site.weather else {
        return Err(Error::argument("weather", "LEED ASE needs a weather file: its direct normal illuminance"));
    };
    let n = at.points.len();
    let parts = mapper.sweep(
        samples,
        site,
        false,
        progress,
        || vec![0.0; n],
        |over, _, s, sun, g, vis| {
            let (_, lux) = beam(weather, s);
            if lux <= ASE_LUX {
                return;
            }
            for (&i, &v) in g.members.iter().zip(vis).filter(|(_, v)| **v > 0.0) {
                let i = i as usize;
                let cos = mapper.normals[i].dot(sun).max(0.0);
                let (_, tv) = through_glass(rooms, at.room[i], at.points.position(i), sun);
                if lux * cos * tv * f64::from(v) > ASE_LUX {
                    over[i] += s.hours;
                }
            }
        },
    );
    let mut hours = vec![0.0; n];
    for part in parts {
        super::add_into(&mut hours, &part);
    }
    Ok(hours)
}

/// Per room with points, the share of its points whose `hours` ([`ase_hours`] over the year's
/// occupied hours) exceed [`ASE_HOURS`].
pub fn ase_areas(map: InsideMap<'_>, hours: &[f64]) -> Vec<AseArea> {
    let InsideMap { rooms, at, .. } = map;
    rooms
        .rooms
        .iter()
        .enumerate()
        .filter_map(|(k, room)| {
            let mine: Vec<f64> = at.room.iter().zip(hours).filter(|(r, _)| **r == k as u32).map(|(_, h)| *h).collect();
            let over = mine.iter().filter(|&&h| h > ASE_HOURS).count();
            (!mine.is_empty()).then(|| AseArea {
                zone: room.name.clone(),
                points: mine.len(),
                ase: 100.0 * over as f64 / mine.len() as f64,
            })
        })
        .collect()
}

/// BRE 209's working plane height in dwellings (m), where its No-Sky Line is drawn.
pub const NSL_WORK_PLANE: f64 = 0.85;

/// A point sees sky when its view factor to the visible sky exceeds this (a share of the sky
/// hemisphere's, so a sliver of one sub-patch counts).
const SEES_SKY: f64 = 1e-9;

/// One room's No-Sky Line result.
#[derive(Debug, Clone, PartialEq)]
pub struct NslArea {
    /// The zone.
    pub zone: String,
    /// Its points.
    pub points: usize,
    /// Share of its points that see sky (in front of the No-Sky Line), in %.
    pub sees_sky: f64,
}

/// BRE 209's No-Sky Line per room: which points see any of the sky through the openings, by
/// each point's own sky views ([`super::point_sky`]: every sky patch cut into 6 × 6 sub-patches,
/// each asked along its own direction, so a point sees sky when one sub-patch direction is clear;
/// a point within a sub-patch's width of the line may be put on its wrong side). Glass does not
/// matter: a point behind a window sees the sky it sees. Foliage counts in full leaf.
pub fn no_sky_line(
    map: InsideMap<'_>,
    patches: &crate::sky::patches::SkyPatches,
    progress: &mut dyn FnMut(usize, usize),
) -> (Vec<bool>, Vec<NslArea>) {
    let InsideMap { mapper, rooms, at } = map;
    let sky = super::point_sky(mapper, patches, progress);
    let sees: Vec<bool> = (0..at.points.len()).map(|i| sky.isotropic(i, 1.0) > SEES_SKY).collect();
    let areas = rooms
        .rooms
        .iter()
        .enumerate()
        .filter_map(|(k, room)| {
            let mine: Vec<bool> = at.room.iter().zip(&sees).filter(|(r, _)| **r == k as u32).map(|(_, s)| *s).collect();
            let seeing = mine.iter().filter(|&&s| s).count();
            (!mine.is_empty()).then(|| NslArea {
                zone: room.name.clone(),
                points: mine.len(),
                sees_sky: 100.0 * seeing as f64 / mine.len() as f64,
            })
        })
        .collect();
    (sees, areas)
}

/// One room's No-Sky Line before and after a development.
#[derive(Debug, Clone, PartialEq)]
pub struct NslChange {
    /// The room now (the proposed model's).
    pub now: NslArea,
    /// Its share that saw sky in the existing model (%), None where that model has no room of
    /// the name.
    pub before: Option<f64>,
    /// `now.sees_sky / before` ([`compare::ratio`]): None without a former share, or where it
    /// was 0.
    pub ratio: Option<f64>,
    /// BRE 209's daylight distribution test ([`compare::no_sky_line`]): the area seeing sky
    /// is not below 0.8 × its former value. None without a former share.
    pub passes: Option<bool>,
}

/// Each room of `now` with its former share from `before` (rooms matched by name), by the window
/// studies' relative tests ([`super::planning::compare`]).
pub fn nsl_before_after(now: &[NslArea], before: &[NslArea]) -> Vec<NslChange> {
    now.iter()
        .map(|area| {
            let former = before.iter().find(|b| b.zone == area.zone).map(|b| b.sees_sky);
            NslChange {
                now: area.clone(),
                before: former,
                ratio: compare::ratio(area.sees_sky, former),
                passes: former.map(|b| compare::no_sky_line(area.sees_sky, b)),
            }
        })
        .collect()
}
