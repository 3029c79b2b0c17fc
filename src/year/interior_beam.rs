//! EnergyPlus's interior beam, computed by sunlit: at every timestep, the beam each exterior
//! window lets onto each inside face of its zone, in W/m² of that face.
//!
//! Under the `Scheduled` shading method EnergyPlus builds no back-surface overlaps (they come
//! only from its own clipping), so `FullInteriorAndExterior` sends all transmitted beam into the
//! zone as diffuse. This module gives the distribution it lost, for
//! `SurfaceProperty:SolarIncidentInside` schedules (see [`crate::export::interior_beam`] for how they
//! are written and what EnergyPlus does with them).
//!
//! A view through a window is a request to the same exact engine as outside: one scene for the
//! whole model, every opening glazed ([`inside_scene_glazed`]), and a view through window `w`
//! leaves `w`'s glass out ([`ExactEngine::fractions_through`]; every other window casts as if
//! opaque), the receiver an inside face, the sun the timestep's. A view is asked only where the
//! window's outline, cast along the sun onto the face's plane, can meet the face ([`may_light`]):
//! a zone is closed but for its openings, so elsewhere the answer is 0. About two thirds of the
//! views a year asks are such (4ZoneWithShading_Simple_1: 223,533 before this test). The lit share `f` of face `s`
//! through window `w` gives `DNI · τ_w · cos θ_s · f` on the face (θ_s between the sun and the
//! face's inside normal): the beam's cross-section is the same on the window and on the patch.
//! `τ_w` is the glass's solar transmittance at the window's incidence ([`Glazing::solar_at`]:
//! EnergyPlus's curves for simple glazing, one uncoated pane's Fresnel physics, else the
//! normal-incidence value).
//!
//! Interzone windows are no source of interior beam: their beam is what another zone's exterior
//! window let in, which EnergyPlus passes on as diffuse. They are skipped by name.
//!
//! Each zone's balance takes back all the beam its exterior windows let in (each glass's sunlit
//! share seen from outside × DNI · τ · cos θ · area: EnergyPlus's `BTOTZone`), not only what its
//! faces got: EnergyPlus's FullInterior books the beam landing on the back of a window (another
//! exterior window, an interzone pane) as leaving the zone (`BABSZone += BOverlap *
//! (AbsBeamTotWin + TransBeamWin)`), and left in the zone's diffuse it put 0.078 points of site
//! energy a year on 4ZoneWithShading_Simple_1 (docs/energyplus-fidelity.md).
//!
//! The DNI is the one EnergyPlus's heat balance sees at the timestep
//! ([`Weather::dni_as_energyplus`]: interpolated between hour middles), not the hour's: held
//! over the hour, it missed the morning's first beam (the hour ending 08:00 at 0 where
//! EnergyPlus already has half the next hour's) and kept the evening's too long, so walls lit in
//! the morning took too little and walls lit in the evening too much (2–11 % a year on
//! 4ZoneWithShading_Simple_1's walls against EnergyPlus's own distribution). The sun is
//! EnergyPlus's at each timestep ([`shaded_sun`]: under a `Periodic` update the period's, whose
//! back-surface overlaps EnergyPlus's own interior distribution uses, while whether the sun is up
//! is the calendar day's). Foliage counts in full leaf (EnergyPlus has none).

use glam::{DVec2, DVec3};

use crate::count::exact::engine::ExactEngine;
use crate::count::{MIN_COS_INCIDENCE, ViewRequest};
use crate::error::Result;
use crate::geometry::{Plane, convex_apart, is_convex, newell};
use crate::model::EnergyPlusInput;
use crate::model::building::inside_name;
use crate::model::inside::{Glazing, Rooms, construction_of, inside_scene_glazed};
use crate::scene::{Receiver, Scene};
use crate::sun::location::Location;
use crate::sun::periods::ShadingPeriods;
use crate::sun::position::sun_direction;
use crate::sun::weather::Weather;
use crate::year::annual::{shaded_sun, shading_sun_day};
use crate::year::samples::Timesteps;

/// One inside face that receives interior beam.
#[derive(Debug, Clone, PartialEq)]
pub struct InsideFace {
    /// The EnergyPlus surface.
    pub surface: String,
    /// Its construction, as the model names it (EnergyPlus keys the schedule on the pair).
    pub construction: String,
    /// Its zone.
    pub zone: String,
    /// Its net area (m²; openings cut out, as EnergyPlus's `Surface.Area`).
    pub area: f64,
    /// Incident beam on its inside face (W/m²), per timestep.
    pub watts_m2: Vec<f64>,
}

/// A zone's balance: the beam its exterior windows let in, taken back out of the zone's diffuse.
/// EnergyPlus's own FullInterior takes it all out (`DBZone = BTOTZone − BABSZone`): what lands on
/// an opaque face is that face's (the face schedules put it back), and what lands on the back of
/// another window leaves the zone (through an exterior window, into its glass, or through an
/// interzone pane into the next zone), so none of the beam stays in the zone as diffuse but the
/// faces' reflected share.
#[derive(Debug, Clone, PartialEq)]
pub struct ZoneBalance {
    /// The zone.
    pub zone: String,
    /// The exterior window that carries it (any window of the zone would do).
    pub window: String,
    /// The window's construction.
    pub construction: String,
    /// Per timestep (W/m² of the window, ≤ 0): minus the beam through the zone's exterior windows
    /// (W) over the window's area.
    pub watts_m2: Vec<f64>,
}

/// Interior beam over a year of timesteps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InteriorBeam {
    /// Every opaque inside face of a zone with an exterior window.
    pub faces: Vec<InsideFace>,
    /// One per zone with faces.
    pub balances: Vec<ZoneBalance>,
    /// Interzone windows, skipped by name.
    pub skipped: Vec<String>,
    /// Views asked of the exact engine.
    pub views: usize,
}

/// The interior beam of every zone with exterior windows, at every timestep of `timesteps`, for
/// the sun of the model's shading update (`periods`).
pub fn interior_beam(
    input: &EnergyPlusInput,
    rooms: &Rooms,
    weather: &Weather,
    location: &Location,
    timesteps: Timesteps,
    periods: Option<ShadingPeriods>,
) -> Result<InteriorBeam> {
    let mut out =
        InteriorBeam { skipped: rooms.glazing.iter().filter(|g| g.interzone).map(|g| g.name.clone()).collect(), ..Default::default() };
    let rows = timesteps.rows();
    // Per row: the shading's sun when the calendar day's is up, the shading's too, and the hour
    // has beam.
    let suns: Vec<Option<(DVec3, f64)>> = (0..rows)
        .map(|r| {
            let at = timesteps.instant(r);
            let up = sun_direction(location, shading_sun_day(at.day), at.hour).z >= MIN_COS_INCIDENCE;
            let sun = shaded_sun(location, timesteps, periods, r);
            let dni = weather.dni_as_energyplus(timesteps, r);
            (up && sun.z >= MIN_COS_INCIDENCE && dni > 0.0).then_some((sun, dni))
        })
        .collect();
    // One scene for every window: a view through a window leaves that window's glass out.
    let scene = inside_scene_glazed(input)?;
    let mut views = Views::default();
    let mut zones = Vec::new();
    for room in &rooms.rooms {
        let windows: Vec<&Glazing> = room.glazing.iter().map(|&g| &rooms.glazing[g]).filter(|g| !g.interzone).collect();
        let Some(first) = windows.first() else { continue };
        let start = out.faces.len();
        for face in &room.inside {
            let name = face.trim_end_matches(":inside");
            let Some(s) = input.building.surface(name) else { continue };
            let construction = construction_of(input, s).unwrap_or_default();
            let area = scene.receiver(face).map_or(0.0, |(_, r)| r.area);
            out.faces.push(InsideFace { surface: s.name.clone(), construction, zone: room.name.clone(), area, watts_m2: vec![0.0; rows] });
        }
        for window in &windows {
            views.through_window(&scene, window, &suns, start, &out.faces[start..]);
            views.entering_zone(&scene, window, &suns, zones.len());
        }
        zones.push((room, *first));
    }
    out.views = views.requests.len();
    let fractions = ExactEngine::new(&scene).fractions_through(&views.requests, &views.open);
    let mut entering = vec![vec![0.0; rows]; zones.len()];
    for ((to, row, scale), f) in views.targets.into_iter().zip(fractions) {
        match to {
            Target::Face(k) => out.faces[k].watts_m2[row] += scale * f,
            Target::Zone(z) => entering[z][row] += scale * f,
        }
    }
    for ((room, first), entering) in zones.into_iter().zip(entering) {
        let area = newell(&first.vertices).length();
        let balance = entering.iter().map(|w| -w / area).collect();
        let construction = input.building.surface(&first.name).and_then(|s| construction_of(input, s)).unwrap_or_default();
        out.balances.push(ZoneBalance { zone: room.name.clone(), window: first.name.clone(), construction, watts_m2: balance });
    }
    Ok(out)
}

/// Where a view's lit share goes: a face's beam (W/m² per unit share), or the beam a zone's
/// window lets in (W per unit share).
enum Target {
    Face(usize),
    Zone(usize),
}

/// The views asked of the exact engine: per view the glass it sees through, and where, at which
/// row and scaled by what its fraction goes.
#[derive(Default)]
struct Views {
    requests: Vec<ViewRequest>,
    open: Vec<Option<u32>>,
    targets: Vec<(Target, usize, f64)>,
}

impl Views {
    /// Asks for the beam `window` lets onto `faces` (indices from `first`) at every row with a
    /// sun. A face takes the beam only when its inside faces the sun, the window's outside does,
    /// and the window's outline cast along the sun onto the face's plane can meet the face: its
    /// zone is closed but for its openings, and the others' glass casts, so the beam through this
    /// window reaches no other face (the engine would answer 0 there, at a view's cost).
    fn through_window(&mut self, scene: &Scene, window: &Glazing, suns: &[Option<(DVec3, f64)>], first: usize, faces: &[InsideFace]) {
        // Every opening receives in the glazed scene; one too small to make a receiver lets no beam in.
        let Some((_, glass)) = scene.receiver(&window.name) else { return };
        let open = Some(glass.gpu_id);
        let outward = newell(&window.vertices).normalize_or_zero();
        let receivers: Vec<Option<(u32, &Receiver)>> = faces.iter().map(|f| scene.receiver(&inside_name(&f.surface))).collect();
        for (row, sun) in suns.iter().enumerate() {
            let Some((sun, dni)) = *sun else { continue };
            if outward.dot(sun) < MIN_COS_INCIDENCE {
                continue;
            }
            for (k, face) in receivers.iter().enumerate() {
                let Some((receiver, r)) = *face else { continue };
                let cos = r.normal.dot(sun);
                if cos < MIN_COS_INCIDENCE || !may_light(window, r, sun) {
                    continue;
                }
                self.requests.push(ViewRequest { receiver, sun, leaves: 1.0 });
                self.open.push(open);
                self.targets.push((Target::Face(first + k), row, dni * window.solar_at(outward.dot(sun)) * cos));
            }
        }
    }

    /// Asks for the beam `window` lets into zone `zone` (W) at every row with a sun: its glass's
    /// sunlit share from outside (the view of its own receiver, its glass left out so that only
    /// what lies outside shades it) × DNI · τ · cos θ · area, as EnergyPlus's `BTOTZone` counts it.
    fn entering_zone(&mut self, scene: &Scene, window: &Glazing, suns: &[Option<(DVec3, f64)>], zone: usize) {
        let Some((receiver, glass)) = scene.receiver(&window.name) else { return };
        let outward = newell(&window.vertices).normalize_or_zero();
        let area = newell(&window.vertices).length();
        for (row, sun) in suns.iter().enumerate() {
            let Some((sun, dni)) = *sun else { continue };
            let cos = outward.dot(sun);
            if cos < MIN_COS_INCIDENCE {
                continue;
            }
            self.requests.push(ViewRequest { receiver, sun, leaves: 1.0 });
            self.open.push(Some(glass.gpu_id));
            self.targets.push((Target::Zone(zone), row, dni * window.solar_at(cos) * cos * area));
        }
    }
}

/// Rays nearer than this (m) to the window's cast outline still count as meeting the face.
const CAST_SLACK: f64 = 1e-4;

/// Whether the beam through `window` along `sun` can meet `face` (its inside normal towards the
/// sun): false when the window's outline cast along the sun onto the face's plane lies apart
/// from every triangle of the face, both as the window is and as the hole in its wall (a
/// set-back window's are not the same). Where that cannot be told cheaply (an outline not
/// convex, or reaching behind the face's plane), true: the engine answers.
fn may_light(window: &Glazing, face: &Receiver, sun: DVec3) -> bool {
    let Some(first) = face.triangles.first() else { return false };
    let plane = Plane::through(first[0], face.normal);
    let along = face.normal.dot(sun);
    let cast = |outline: &[DVec3]| -> Option<Vec<DVec2>> {
        if along <= 0.0 || !is_convex(outline) {
            return None;
        }
        outline
            .iter()
            .map(|&q| {
                let h = plane.height(q);
                (h > CAST_SLACK).then(|| plane.project(q - sun * (h / along)))
            })
            .collect()
    };
    let triangles: Vec<[DVec2; 3]> = face.triangles.iter().map(|t| t.map(|p| plane.project(p))).collect();
    [&window.vertices, &window.hole].into_iter().any(|outline| match cast(outline) {
        Some(shadow) => triangles.iter().any(|t| !convex_apart(&shadow, t, CAST_SLACK)),
        None => true,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::model::inside::{inside_scene, rooms};
    use crate::model::{LoadOptions, load_bytes_all};

    /// tests/inside/glass.idf: a 4 × 5 × 3 m box, window Win in its south wall, Win2 in its north.
    fn glass_box() -> EnergyPlusInput {
        let text = include_str!("../../tests/inside/glass.idf");
        load_bytes_all(&[("glass.idf".to_string(), text.as_bytes().to_vec())], &LoadOptions::default()).unwrap().energyplus.unwrap()
    }

    /// Suns over the upper hemisphere: 12 azimuths × 6 altitudes.
    fn suns() -> Vec<DVec3> {
        (0..12)
            .flat_map(|a| (1..7).map(move |e| (f64::from(a) * 30.0 + 7.0, f64::from(e) * 12.0)))
            .map(|(az, el): (f64, f64)| {
                let (az, el) = (az.to_radians(), el.to_radians());
                DVec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
            })
            .collect()
    }

    /// A view through Win in the glazed scene (Win's glass left out, Win2's casting) answers what
    /// the scene with every opening left out answers for a southern sun, which cannot reach
    /// Win2 from inside; with no glass left out the glass casts and every face is dark.
    #[test]
    fn a_view_through_one_window_leaves_only_its_glass_out() {
        let input = glass_box();
        let (glazed, open) = (inside_scene_glazed(&input).unwrap(), inside_scene(&input).unwrap());
        let win = glazed.receiver("Win").unwrap().1.gpu_id;
        let faces = ["Floor:inside", "North:inside", "East:inside", "West:inside", "Roof:inside"];
        let mut lit = 0;
        for sun in suns().into_iter().filter(|s| s.y < -0.1) {
            let ask =
                |scene: &Scene| -> Vec<ViewRequest> { faces.iter().map(|f| ViewRequest::new(scene.receiver(f).unwrap().0, sun)).collect() };
            let engine = ExactEngine::new(&glazed);
            let through = engine.fractions_through(&ask(&glazed), &[Some(win); 5]);
            let closed = engine.fractions_through(&ask(&glazed), &[None; 5]);
            let all_open = ExactEngine::new(&open).fractions(&ask(&open));
            for k in 0..faces.len() {
                assert!((through[k] - all_open[k]).abs() < 1e-9, "{} at {sun}: {} vs {}", faces[k], through[k], all_open[k]);
                assert_eq!(closed[k], 0.0, "{} lit through closed glass", faces[k]);
                lit += usize::from(through[k] > 0.0);
            }
        }
        assert!(lit > 20, "too few lit views ({lit}) to tell");
    }

    /// Where [`may_light`] says the beam through a window cannot meet a face, the engine's view
    /// through that window finds the face dark, for every face, window and sun; and the test
    /// spares views (else it would be no test of anything).
    #[test]
    fn may_light_spares_only_views_the_engine_finds_dark() {
        let input = glass_box();
        let scene = inside_scene_glazed(&input).unwrap();
        let engine = ExactEngine::new(&scene);
        let rooms = rooms(&input, None).unwrap();
        let (mut spared, mut asked) = (0, 0);
        for window in &rooms.glazing {
            let open = Some(scene.receiver(&window.name).unwrap().1.gpu_id);
            let outward = newell(&window.vertices).normalize();
            for face in &rooms.rooms[0].inside {
                let (id, r) = scene.receiver(face).unwrap();
                for sun in suns().into_iter().filter(|s| outward.dot(*s) > 1e-3 && r.normal.dot(*s) > 1e-3) {
                    let f = engine.fractions_through(&[ViewRequest::new(id, sun)], &[open])[0];
                    if may_light(window, r, sun) {
                        asked += 1;
                    } else {
                        spared += 1;
                        assert_eq!(f, 0.0, "{face} through {} at {sun}: spared but lit ({f})", window.name);
                    }
                }
            }
        }
        assert!(spared > 50 && asked > 50, "spared {spared}, asked {asked}");
    }
}
