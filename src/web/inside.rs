//! `engine.map` with `inside: true`: the sun inside a model's rooms, as `sunlit map --inside`
//! answers it ([`crate::map::inside`]): an EnergyPlus model's zones, or the rooms and panes a
//! mesh model's nodes are marked as (`interior`, `glazing`: the CLI's `--interior`, `--glazing`,
//! read by the same loader from the model's files); points on the rooms' floors (or given ones)
//! and at an instant each lit or not through the windows with the glass's weights and every
//! inside face's sun patch; over a period the sun hours, and with an EPW the beam and direct-sun
//! illuminance through the glass; or a study (`study`: LEED ASE, BRE 209's No-Sky Line) with its
//! per-room shares. No inside logic lives here or in JS, and the CSV is written by the CLI's
//! column writers.
//!
//! The inside scene (the building with its glazing left out, the rooms, the points and their
//! shadow-ray index) is kept on the model for the last rooms, glass and points asked
//! ([`InsideKey`]), so a time slider's moves and a study after a map of the same points pay for
//! it once. A period or LEED ASE is summed in chunks of instants with a turn of the event loop
//! between them ([`super::map::in_chunks`]): progress is reported and an abort is seen, and an
//! aborted map returns nothing.

use std::rc::Rc;

use js_sys::{Array, Uint8Array};
use serde_json::json;

use super::ModelInner;
use super::map::{Run, in_chunks};
use super::map_options::{InsideAsk, InsideStudy, MapRequest, MapValue, Where, points_csv as given_points};
use crate::error::{Error, Result};
use crate::export::map_glb::map_glb;
use crate::export::map_table::{Column, ase_column, inside_instant_columns, inside_period_columns, inside_period_shown, points_csv};
use crate::map::inside::{self as rooms_map, AseResult, InsideInstant, InsideMap, InsideValues, NslArea, Patch, RoomPoints};
use crate::map::{Mapper, Points, Site};
use crate::model::inside::curve::TransmittanceCurve;
use crate::model::inside::gltf::rooms as gltf_rooms;
use crate::model::inside::{Rooms, UnreadGlass, inside_scene, rooms_with};
use crate::model::{LoadOptions, load_bytes_all};
use crate::scene::Scene;
use crate::sky::patches::SkyPatches;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// A mesh model's files as `loadFiles` got them (references to the caller's bytes, not copies in
/// wasm memory) and its load options: its rooms are read again from them with `interior` and
/// `glazing` marked, as the CLI reads them.
pub(super) struct Source {
    pub(super) names: Vec<String>,
    pub(super) contents: Array,
    pub(super) options: LoadOptions,
}

impl Source {
    /// The files' bytes, copied into wasm memory for one read.
    fn files(&self) -> Vec<(String, Vec<u8>)> {
        self.names.iter().cloned().zip(self.contents.iter().map(|bytes| Uint8Array::new(&bytes).to_vec())).collect()
    }
}

/// What the inside scene depends on: the rooms and glass asked (the study aside) and the points.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct InsideKey {
    ask: InsideAsk,
    place: Where,
}

impl InsideKey {
    fn new(ask: &InsideAsk, place: &Where) -> Self {
        Self { ask: InsideAsk { study: None, ..ask.clone() }, place: place.clone() }
    }
}

/// The inside scene of one model for one [`InsideKey`]: the scene with the glazing left out and
/// the points' planes added, the rooms, the points and their shadow-ray index.
pub(super) struct InsideScene {
    scene: Scene,
    rooms: Rooms,
    at: RoomPoints,
    mapper: Mapper,
}

impl InsideScene {
    fn map(&self) -> InsideMap<'_> {
        InsideMap { mapper: &self.mapper, rooms: &self.rooms, at: &self.at }
    }
}

/// The inside scene for `key`: the model's kept one when it was made for the same key, else made
/// now (and kept in its place).
fn inside_scene_for(model: &ModelInner, key: InsideKey) -> Result<Rc<InsideScene>> {
    if let Some((_, kept)) = model.inside.borrow().as_ref().filter(|(k, _)| *k == key) {
        return Ok(kept.clone());
    }
    // The old one goes first: two large inside scenes need not be held at once.
    *model.inside.borrow_mut() = None;
    let made = Rc::new(build(model, &key)?);
    *model.inside.borrow_mut() = Some((key, made.clone()));
    Ok(made)
}

/// The rooms of `model` as `key` asks them, their points and shadow-ray index.
fn build(model: &ModelInner, key: &InsideKey) -> Result<InsideScene> {
    let ask = &key.ask;
    let (mut scene, rooms) = match (&model.energyplus, ask.interior.is_empty()) {
        (Some(ep), true) => {
            let curve =
                ask.curve.as_deref().map(TransmittanceCurve::parse).transpose().map_err(|why| Error::argument("glassCurve", why))?;
            (inside_scene(ep)?, rooms_with(ep, &UnreadGlass { transmittance: ask.glass, curve })?)
        }
        (Some(ep), false) => {
            return Err(Error::model(&ep.file, "'interior' picks the rooms of mesh models: an EnergyPlus model's zones are its rooms"));
        }
        (None, true) => {
            return Err(Error::argument(
                "inside",
                "maps the zones of an EnergyPlus model (IDF or epJSON), or the rooms a mesh model's nodes are: give 'interior' (and 'glazing')",
            ));
        }
        (None, false) => mesh_rooms(model, ask)?,
    };
    let at = match &key.place {
        Where::Grid(spacing) if ask.faces => rooms_map::face_grid(&mut scene, &rooms, *spacing, ask.work_plane)?,
        Where::Grid(spacing) => rooms_map::floor_grid(&mut scene, &rooms, *spacing, ask.work_plane)?,
        Where::Given(_) if ask.faces => return Err(Error::argument("faces", "puts a grid on the faces: give 'grid', not 'points'")),
        Where::Given(numbers) => rooms_map::room_points_csv(&mut scene, &rooms, "points", &given_points(numbers)?)?,
    };
    let mapper = Mapper::new(&scene, &at.points)?;
    Ok(InsideScene { scene, rooms, at, mapper })
}

/// A mesh model's rooms (`interior`) and panes (`glazing`), read again from its files with them
/// marked, by the loader and [`gltf_rooms`] as `sunlit map --inside --interior` reads them.
fn mesh_rooms(model: &ModelInner, ask: &InsideAsk) -> Result<(Scene, Rooms)> {
    let Some(source) = &model.source else {
        return Err(Error::argument("interior", "marks nodes of a model read from files (loadFiles); this model was made from arrays"));
    };
    let options = LoadOptions { interior: ask.interior.clone(), glazing: ask.glazing.clone(), ..source.options.clone() };
    let mut loaded = load_bytes_all(&source.files(), &options)?;
    let rooms = gltf_rooms(&mut loaded.scene, &loaded.interior, &loaded.glazing, ask.glass)?;
    Ok((loaded.scene, rooms))
}

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
    inside: Rc<InsideScene>,
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
        points_csv(&self.inside.scene, points, &self.columns())
    }

    /// The map glb as `--glb-out` writes it (coloured by the value the CLI colours by).
    pub(super) fn glb(&self, points: &Points) -> Vec<u8> {
        let (name, unit, values) = match &self.answer {
            Answer::At { values, .. } => ("lit", "", values.lit.as_slice()),
            Answer::Period { values, .. } => inside_period_shown(values),
            Answer::Ase(result) => ("hours_over_1000_lux", "h", result.hours.as_slice()),
            Answer::Nsl { sees, .. } => ("sees_sky", "", sees.as_slice()),
        };
        map_glb(&self.inside.scene, points, values, name, unit)
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
        self.inside.scene.receivers.iter().map(|r| r.name.clone()).collect()
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

/// The inside of `model`'s rooms as `request` asks it: an instant, a period or a study; a period
/// and LEED ASE in chunks (`run`: progress, abort).
pub(super) async fn inside_map(model: &ModelInner, request: &MapRequest, ask: &InsideAsk, run: Run<'_>) -> Result<(Points, Inside)> {
    let inside = inside_scene_for(model, InsideKey::new(ask, &request.place))?;
    let answer = answer(&inside, request, ask.study, run).await?;
    Ok((inside.at.points.clone(), Inside { inside, answer }))
}

/// What `request` asks of the points `inside` holds.
async fn answer(inside: &InsideScene, request: &MapRequest, study: Option<InsideStudy>, run: Run<'_>) -> Result<Answer> {
    let map = inside.map();
    let site = Site { location: &request.site.location, calendar: &request.site.calendar, weather: request.weather.as_ref(), sky: None };
    let samples = request.period.samples();
    Ok(match study {
        Some(InsideStudy::LeedAse) => {
            let occupied = rooms_map::occupied_hours(&samples);
            let hours_in = |chunk: &[_]| rooms_map::ase_hours(map, chunk, site, &mut |_, _| {});
            let add = |total: &mut Vec<f64>, part: Vec<f64>| total.iter_mut().zip(part).for_each(|(t, p)| *t += p);
            let summed = in_chunks(&occupied, run, hours_in, add).await?;
            let hours = summed.unwrap_or_else(|| vec![0.0; inside.at.points.len()]);
            let efficacy_hours = site.weather.map_or(0, |w| rooms_map::efficacy_hours(w, &occupied));
            Answer::Ase(AseResult { areas: rooms_map::ase_areas(map, &hours), hours, occupied: occupied.len(), efficacy_hours })
        }
        Some(InsideStudy::BreNsl) => {
            let (sees, areas) = rooms_map::no_sky_line(map, &SkyPatches::tregenza(), &mut |_, _| {});
            Answer::Nsl { sees: sees.iter().map(|&s| f64::from(u8::from(s))).collect(), areas }
        }
        None if request.value == MapValue::Lit => {
            let s = samples.first().copied().ok_or_else(|| Error::argument("at", "no instant"))?;
            let sun = sun_direction(&request.site.location, shading_sun_day(s.day), s.hour);
            let leaves = request.site.calendar.fraction(f64::from(s.day)) as f32;
            let (values, patches) = rooms_map::instant_with_patches(&inside.scene, map, sun, leaves);
            Answer::At { values, patches }
        }
        None => {
            let sum = |chunk: &[_]| Ok(rooms_map::accumulate(map, chunk, site, &mut |_, _| {}));
            let summed = in_chunks(&samples, run, sum, |total: &mut InsideValues, part| total.merge(&part)).await?;
            let values = match summed {
                Some(values) => values,
                None => rooms_map::accumulate(map, &[], site, &mut |_, _| {}),
            };
            Answer::Period { values, shown: request.value }
        }
    })
}
