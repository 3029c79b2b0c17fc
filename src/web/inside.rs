//! `engine.map` with `inside: true`: the sun inside an EnergyPlus model's zones, as `sunlit map
//! --inside` answers it ([`crate::map::inside`]): points on the zones' floors (or given ones) and
//! at an instant each lit or not through the windows with the glass's weights and every inside
//! face's sun patch; over a period the sun hours, and with an EPW the beam and direct-sun
//! illuminance through the glass; or a study (`study`: LEED ASE, BRE 209's No-Sky Line) with its
//! per-room shares. The scene is the model's inside ([`inside_scene`]: the glazing left out),
//! made per call; no inside logic lives here or in JS, and the CSV is written by the CLI's
//! column writers.

use serde_json::json;

use super::ModelInner;
use super::map_options::{InsideAsk, InsideStudy, MapRequest, MapValue, Where, points_csv as given_points};
use crate::error::{Error, Result};
use crate::export::map_glb::map_glb;
use crate::export::map_table::{Column, ase_column, inside_instant_columns, inside_period_columns, inside_period_shown, points_csv};
use crate::map::inside::{self as rooms_map, AseResult, InsideInstant, InsideMap, InsideValues, NslArea, Patch};
use crate::map::{Mapper, Points, Site};
use crate::model::inside::{inside_scene, rooms};
use crate::scene::Scene;
use crate::sky::patches::SkyPatches;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// What was asked inside, answered.
pub(super) enum Answer {
    /// One instant: per point lit and the glass's weights; each inside face's sun patch.
    At { values: InsideInstant, patches: Vec<Patch> },
    /// Sums over a period, and the value shown (sun hours or the beam).
    Period { values: InsideValues, shown: MapValue },
    /// LEED ASE over the year's occupied hours.
    Ase(AseResult),
    /// BRE 209's No-Sky Line: per point sees sky (1) or not (0); per room the share.
    Nsl { sees: Vec<f64>, areas: Vec<NslArea> },
}

/// The inside answered: the inside scene the points lie on, and what was asked of it.
pub(super) struct Inside {
    scene: Scene,
    pub(super) answer: Answer,
}

impl Inside {
    /// The points CSV's value columns, as `sunlit map --inside` writes them for the same ask.
    fn columns(&self) -> Vec<Column<'_>> {
        match &self.answer {
            Answer::At { values, .. } => inside_instant_columns(values).into(),
            Answer::Period { values, .. } => inside_period_columns(values),
            Answer::Ase(result) => vec![ase_column(result)],
            Answer::Nsl { sees, .. } => vec![Column { name: "sees_sky", values: sees, decimals: 0 }],
        }
    }

    /// The points CSV as `sunlit map --inside -o POINTS.csv` writes it.
    pub(super) fn csv(&self, points: &Points) -> String {
        points_csv(&self.scene, points, &self.columns())
    }

    /// The map glb as `--glb-out` writes it (coloured by the value the CLI colours by).
    pub(super) fn glb(&self, points: &Points) -> Vec<u8> {
        let (name, unit, values) = match &self.answer {
            Answer::At { values, .. } => ("lit", "", values.lit.as_slice()),
            Answer::Period { values, .. } => inside_period_shown(values),
            Answer::Ase(result) => ("hours_over_1000_lux", "h", result.hours.as_slice()),
            Answer::Nsl { sees, .. } => ("sees_sky", "", sees.as_slice()),
        };
        map_glb(&self.scene, points, values, name, unit)
    }

    /// The value held per point, and its name.
    pub(super) fn values(&self) -> (MapValue, Vec<f64>) {
        match &self.answer {
            Answer::At { values, .. } => (MapValue::Lit, values.lit.clone()),
            Answer::Period { values, shown: MapValue::Direct } => (MapValue::Direct, values.beam_kwh_m2.clone().unwrap_or_default()),
            Answer::Period { values, .. } => (MapValue::SunHours, values.sun_hours.clone()),
            Answer::Ase(result) => (MapValue::AseHours, result.hours.clone()),
            Answer::Nsl { sees, .. } => (MapValue::SeesSky, sees.clone()),
        }
    }

    /// Instants counted per point (a study: its hours; the No-Sky Line, geometry: 0).
    pub(super) fn instants(&self) -> usize {
        match &self.answer {
            Answer::At { .. } => 1,
            Answer::Period { values, .. } => values.instants,
            Answer::Ase(result) => result.occupied,
            Answer::Nsl { .. } => 0,
        }
    }

    /// At an instant: the glass's solar and visible weights per point.
    pub(super) fn weights(&self) -> Option<(&[f64], &[f64])> {
        match &self.answer {
            Answer::At { values, .. } => Some((&values.solar_transmittance, &values.visible_transmittance)),
            _ => None,
        }
    }

    /// Over a period: the sun hours, and with an EPW the beam through the glass (kWh/m²).
    pub(super) fn sums(&self) -> Option<(&[f64], Option<&[f64]>)> {
        match &self.answer {
            Answer::Period { values, .. } => Some((&values.sun_hours, values.beam_kwh_m2.as_deref())),
            _ => None,
        }
    }

    /// The inside scene's receiver names (inside faces, work planes), which the points index.
    pub(super) fn receiver_names(&self) -> Vec<String> {
        self.scene.receivers.iter().map(|r| r.name.clone()).collect()
    }

    /// At an instant, each inside face's sun patch as JSON: `surface`, `zone`, `areaM2`,
    /// `fraction`.
    pub(super) fn patches_json(&self) -> Option<String> {
        let Answer::At { patches, .. } = &self.answer else { return None };
        let rows: Vec<serde_json::Value> =
            patches.iter().map(|p| json!({"surface": p.surface, "zone": p.zone, "areaM2": p.area_m2, "fraction": p.fraction})).collect();
        Some(serde_json::Value::Array(rows).to_string())
    }

    /// A study's rooms as JSON, as its report's `areas` (`zone`, `points`, and `ase` or
    /// `seesSky` in %).
    pub(super) fn areas_json(&self) -> Option<String> {
        let rows: Vec<serde_json::Value> = match &self.answer {
            Answer::Ase(result) => result.areas.iter().map(|a| json!({"zone": a.zone, "points": a.points, "ase": a.ase})).collect(),
            Answer::Nsl { areas, .. } => areas.iter().map(|a| json!({"zone": a.zone, "points": a.points, "seesSky": a.sees_sky})).collect(),
            _ => return None,
        };
        Some(serde_json::Value::Array(rows).to_string())
    }
}

/// The inside of `model`'s zones as `request` asks it: an instant, a period or a study.
pub(super) fn inside_map(model: &ModelInner, request: &MapRequest, ask: &InsideAsk) -> Result<(Points, Inside)> {
    let Some(ep) = model.energyplus.as_ref() else {
        return Err(Error::argument("inside", "maps the zones of an EnergyPlus model (IDF or epJSON); this model has none"));
    };
    let (mut scene, rooms) = (inside_scene(ep)?, rooms(ep, ask.glass)?);
    let at = match &request.place {
        Where::Grid(spacing) => rooms_map::floor_grid(&mut scene, &rooms, *spacing, ask.work_plane)?,
        Where::Given(numbers) => rooms_map::room_points_csv(&mut scene, &rooms, "points", &given_points(numbers)?)?,
    };
    let mapper = Mapper::new(&scene, &at.points)?;
    let answer = answer(&scene, InsideMap { mapper: &mapper, rooms: &rooms, at: &at }, request, ask.study)?;
    Ok((at.points, Inside { scene, answer }))
}

/// What `request` asks of the points `map` holds.
fn answer(scene: &Scene, map: InsideMap<'_>, request: &MapRequest, study: Option<InsideStudy>) -> Result<Answer> {
    let site = Site { location: &request.site.location, calendar: &request.site.calendar, weather: request.weather.as_ref(), sky: None };
    let samples = request.period.samples();
    Ok(match study {
        Some(InsideStudy::LeedAse) => Answer::Ase(rooms_map::leed_ase(map, &rooms_map::occupied_hours(&samples), site, &mut |_, _| {})?),
        Some(InsideStudy::BreNsl) => {
            let (sees, areas) = rooms_map::no_sky_line(map, &SkyPatches::tregenza(), &mut |_, _| {});
            Answer::Nsl { sees: sees.iter().map(|&s| f64::from(u8::from(s))).collect(), areas }
        }
        None if request.value == MapValue::Lit => {
            let s = samples.first().copied().ok_or_else(|| Error::argument("at", "no instant"))?;
            let sun = sun_direction(&request.site.location, shading_sun_day(s.day), s.hour);
            let leaves = request.site.calendar.fraction(f64::from(s.day)) as f32;
            let (values, patches) = rooms_map::instant_with_patches(scene, map, sun, leaves);
            Answer::At { values, patches }
        }
        None => Answer::Period { values: rooms_map::accumulate(map, &samples, site, &mut |_, _| {}), shown: request.value },
    })
}
