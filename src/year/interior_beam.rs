//! EnergyPlus's interior beam, computed by sunlit: at every timestep, the beam each exterior
//! window lets onto each inside face of its zone, in W/m² of that face.
//!
//! Under the `Scheduled` shading method EnergyPlus builds no back-surface overlaps (they come
//! only from its own clipping), so `FullInteriorAndExterior` sends all transmitted beam into the
//! zone as diffuse. This module gives the distribution it lost, for
//! `SurfaceProperty:SolarIncidentInside` schedules (see [`crate::export::interior_beam`] for how they
//! are written and what EnergyPlus does with them).
//!
//! A view through a window is a request to the same exact engine as outside: the scene is the
//! building with only that window open ([`inside_scene_through`]; every other window casts as if
//! opaque), the receiver an inside face, the sun the timestep's. The lit share `f` of face `s`
//! through window `w` gives `DNI · τ_w · cos θ_s · f` on the face (θ_s between the sun and the
//! face's inside normal): the beam's cross-section is the same on the window and on the patch.
//! `τ_w` is the glass's solar transmittance at the window's incidence ([`Glazing::solar_at`]: one
//! uncoated pane's angular dependence, else the normal-incidence value; EnergyPlus's curves for
//! simple glazing are not applied).
//!
//! Interzone windows are no source of interior beam: their beam is what another zone's exterior
//! window let in, which EnergyPlus passes on as diffuse. They are skipped by name.
//!
//! The hour's DNI holds over its timesteps (EnergyPlus interpolates weather between hours for
//! sub-hourly timesteps); the sun is EnergyPlus's at each timestep (`shading_sun_day`,
//! [`Timesteps::instant`]). Foliage counts in full leaf (EnergyPlus has none).

use glam::DVec3;

use crate::count::exact::engine::ExactEngine;
use crate::count::{MIN_COS_INCIDENCE, ViewRequest};
use crate::error::Result;
use crate::geometry::newell;
use crate::model::EnergyPlusInput;
use crate::model::inside::{Glazing, Rooms, construction_of, inside_scene_through};
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::sun::weather::Weather;
use crate::year::annual::shading_sun_day;
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

/// A zone's balance: the beam put on its faces, taken back out of the zone's diffuse.
#[derive(Debug, Clone, PartialEq)]
pub struct ZoneBalance {
    /// The zone.
    pub zone: String,
    /// The exterior window that carries it (any window of the zone would do).
    pub window: String,
    /// The window's construction.
    pub construction: String,
    /// Per timestep (W/m² of the window, ≤ 0): minus the faces' beam (W) over the window's area.
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

/// The interior beam of every zone with exterior windows, at every timestep of `timesteps`.
pub fn interior_beam(
    input: &EnergyPlusInput,
    rooms: &Rooms,
    weather: &Weather,
    location: &Location,
    timesteps: Timesteps,
) -> Result<InteriorBeam> {
    let mut out =
        InteriorBeam { skipped: rooms.glazing.iter().filter(|g| g.interzone).map(|g| g.name.clone()).collect(), ..Default::default() };
    let rows = timesteps.rows();
    // Per row: the sun when it is up and the hour has beam.
    let suns: Vec<Option<(DVec3, f64)>> = (0..rows)
        .map(|r| {
            let at = timesteps.instant(r);
            let sun = sun_direction(location, shading_sun_day(at.day), at.hour);
            let dni = weather.at(timesteps, r).dni;
            (sun.z >= MIN_COS_INCIDENCE && dni > 0.0).then_some((sun, dni))
        })
        .collect();
    for room in &rooms.rooms {
        let windows: Vec<&Glazing> = room.glazing.iter().map(|&g| &rooms.glazing[g]).filter(|g| !g.interzone).collect();
        let Some(first) = windows.first() else { continue };
        let start = out.faces.len();
        for face in &room.inside {
            let name = face.trim_end_matches(":inside");
            let Some(s) = input.building.surface(name) else { continue };
            let construction = construction_of(input, s).unwrap_or_default();
            out.faces.push(InsideFace {
                surface: s.name.clone(),
                construction,
                zone: room.name.clone(),
                area: 0.0,
                watts_m2: vec![0.0; rows],
            });
        }
        for window in &windows {
            out.views += through_window(input, window, &suns, &mut out.faces[start..])?;
        }
        let area = newell(&first.vertices).length();
        let balance = (0..rows).map(|r| -out.faces[start..].iter().map(|f| f.watts_m2[r] * f.area).sum::<f64>() / area).collect();
        let construction = input.building.surface(&first.name).and_then(|s| construction_of(input, s)).unwrap_or_default();
        out.balances.push(ZoneBalance { zone: room.name.clone(), window: first.name.clone(), construction, watts_m2: balance });
    }
    Ok(out)
}

/// Adds to `faces` the beam `window` lets onto them at every row with a sun; returns the views
/// asked. A face takes the beam only when its inside faces the sun and the window's outside does.
fn through_window(input: &EnergyPlusInput, window: &Glazing, suns: &[Option<(DVec3, f64)>], faces: &mut [InsideFace]) -> Result<usize> {
    let scene = inside_scene_through(input, &window.name)?;
    let outward = newell(&window.vertices).normalize_or_zero();
    let ids: Vec<Option<(u32, DVec3, f64)>> = faces
        .iter()
        .map(|f| scene.receiver(&crate::model::building::inside_name(&f.surface)).map(|(id, r)| (id, r.normal, r.area)))
        .collect();
    for (face, id) in faces.iter_mut().zip(&ids) {
        if let Some((_, _, area)) = id {
            face.area = *area;
        }
    }
    let mut requests = Vec::new();
    let mut targets = Vec::new();
    for (row, sun) in suns.iter().enumerate() {
        let Some((sun, dni)) = *sun else { continue };
        if outward.dot(sun) < MIN_COS_INCIDENCE {
            continue;
        }
        for (k, id) in ids.iter().enumerate() {
            let Some((receiver, normal, _)) = *id else { continue };
            let cos = normal.dot(sun);
            if cos < MIN_COS_INCIDENCE {
                continue;
            }
            requests.push(ViewRequest { receiver, sun, leaves: 1.0 });
            targets.push((row, k, dni * window.solar_at(outward.dot(sun)) * cos));
        }
    }
    let fractions = ExactEngine::new(&scene).fractions(&requests);
    for ((row, k, scale), f) in targets.into_iter().zip(fractions) {
        faces[k].watts_m2[row] += scale * f;
    }
    Ok(requests.len())
}
