//! `engine.map`: per-point maps in the browser ([`crate::map`]), translated to and from JS.
//!
//! Owns the call (its options are read by [`super::map_options`]) and the answer as typed
//! arrays and as `sunlit map`'s files. The points and their shadow-ray index
//! ([`Mapper`]) are kept on the model for the last grid asked, so a time slider that maps the
//! same grid at instant after instant pays for them once. A period's instants are summed in
//! chunks, between which the worker's event loop runs: progress is reported and an abort is
//! seen.

use std::cell::RefCell;
use std::rc::Rc;

use js_sys::{Float32Array, Function, Promise, Uint8Array, Uint32Array};
use wasm_bindgen::prelude::*;
use wasm_bindgen_futures::{JsFuture, future_to_promise};

use super::inside::{Inside, inside_map};
use super::map_options::{MapRequest, MapValue, Where, points_csv as given_points};
use super::{Engine, Model, ModelInner, js_error};
use crate::error::{Error, Result};
use crate::export::map_glb::map_glb;
use crate::export::map_table::{Column, points_csv, value_columns};
use crate::map::{MapValues, Mapper, Points, Sample, Site, from_csv, grid, point_sky_for};
use crate::sky::model::SkyModel;
use crate::sky::patches::SkyPatches;
use crate::sky::views::SkyViews;
use crate::sun::position::sun_direction;
use crate::year::annual::shading_sun_day;

/// Chunks a period's instants are summed in (each followed by a turn of the event loop).
const CHUNKS: usize = 50;

/// The last points asked of a model, indexed for shadow rays.
pub(super) struct MapCache {
    place: Where,
    points: Rc<Points>,
    mapper: Rc<Mapper>,
    /// The points' sky views (Tregenza's patches, as the annual run's), once asked.
    sky: Option<Rc<SkyViews>>,
}

/// The model's points and mapper for `place`, made once per place.
fn points_for(model: &ModelInner, place: &Where) -> Result<(Rc<Points>, Rc<Mapper>)> {
    let cache: &RefCell<Option<MapCache>> = &model.maps;
    if let Some(c) = cache.borrow().as_ref().filter(|c| c.place == *place) {
        return Ok((c.points.clone(), c.mapper.clone()));
    }
    let all: Vec<u32> = (0..model.scene.receivers.len() as u32).collect();
    let points = match place {
        Where::Grid(spacing) => grid(&model.scene, *spacing, &all)?,
        Where::Given(numbers) => from_csv(&model.scene, "points", &given_points(numbers)?, &all)?,
    };
    let mapper = Rc::new(Mapper::new(&model.scene, &points)?);
    let points = Rc::new(points);
    *cache.borrow_mut() = Some(MapCache { place: place.clone(), points: points.clone(), mapper: mapper.clone(), sky: None });
    Ok((points, mapper))
}

/// The points' sky views for `place` (whose mapper is `mapper`) under `sky_model`, counted once
/// per place and model.
fn sky_for(model: &ModelInner, place: &Where, mapper: &Mapper, sky_model: SkyModel) -> Rc<SkyViews> {
    let mut cache = model.maps.borrow_mut();
    if let Some(sky) = cache.as_ref().filter(|c| c.place == *place).and_then(|c| c.sky.clone()).filter(|s| s.model() == sky_model) {
        return sky;
    }
    let sky = Rc::new(point_sky_for(mapper, &SkyPatches::tregenza(), sky_model, &mut |_, _| {}));
    if let Some(c) = cache.as_mut().filter(|c| c.place == *place) {
        c.sky = Some(sky.clone());
    }
    sky
}

/// A map's answer, handed to JS as typed arrays (sunlit.js copies them into a plain object),
/// and as the CLI's files: the points CSV and the map glb, by the library's own writers.
#[wasm_bindgen]
pub struct PointMap {
    model: Rc<ModelInner>,
    points: Rc<Points>,
    value: MapValue,
    /// The value asked, per point.
    values: Vec<f64>,
    /// A period's sums (None for an instant), as `sunlit map` writes them.
    sums: Option<MapValues>,
    instants: usize,
    /// Inside rooms (`inside: true`): the inside scene the points lie on, the glass's weights
    /// and the sun patches.
    inside: Option<Inside>,
}

impl PointMap {
    /// The CSV's value columns, as `sunlit map` writes them: `lit` for an instant, else
    /// `sun_hours` and, with an EPW, the irradiation computed ([`value_columns`]).
    fn columns(&self) -> Vec<Column<'_>> {
        match &self.sums {
            None => vec![Column { name: "lit", values: &self.values, decimals: 0 }],
            Some(sums) => value_columns(sums),
        }
    }
}

#[wasm_bindgen]
impl PointMap {
    /// `sunHours`, `direct`, `skyDiffuse`, `total` or `lit`.
    #[wasm_bindgen(getter)]
    pub fn value(&self) -> String {
        self.value.name().into()
    }

    /// The legend's title.
    #[wasm_bindgen(getter)]
    pub fn title(&self) -> String {
        self.value.title().0.into()
    }

    /// The value's unit (empty for lit).
    #[wasm_bindgen(getter)]
    pub fn unit(&self) -> String {
        self.value.title().1.into()
    }

    /// The grid spacing (m); 0 for given points.
    #[wasm_bindgen(getter)]
    pub fn spacing(&self) -> f64 {
        self.points.spacing.unwrap_or(0.0)
    }

    /// Instants counted per point.
    #[wasm_bindgen(getter)]
    pub fn instants(&self) -> usize {
        self.instants
    }

    /// x y z per point (world axes: x east, y north, z up).
    #[wasm_bindgen(getter)]
    pub fn points(&self) -> Float32Array {
        Float32Array::from(self.points.positions.as_slice())
    }

    /// The outward unit normal per point.
    #[wasm_bindgen(getter)]
    pub fn normals(&self) -> Float32Array {
        Float32Array::from(self.points.normals.as_slice())
    }

    /// The receiver (index into `receiverNames`) per point.
    #[wasm_bindgen(getter)]
    pub fn receivers(&self) -> Uint32Array {
        Uint32Array::from(self.points.receivers.as_slice())
    }

    /// The value per point.
    #[wasm_bindgen(getter)]
    pub fn values(&self) -> Float32Array {
        to_f32(&self.values)
    }

    /// A period's sun hours per point (undefined for an instant or an inside study).
    #[wasm_bindgen(getter, js_name = sunHours)]
    pub fn sun_hours(&self) -> Option<Float32Array> {
        let inside = || self.inside.as_ref().and_then(Inside::sums).map(|(hours, _)| to_f32(hours));
        self.sums.as_ref().map(|s| to_f32(&s.sun_hours)).or_else(inside)
    }

    /// A period's direct irradiation per point, kWh/m² (undefined without an EPW or for an
    /// instant); inside rooms, the beam through the glass.
    #[wasm_bindgen(getter)]
    pub fn direct(&self) -> Option<Float32Array> {
        let inside = || self.inside.as_ref().and_then(Inside::sums).and_then(|(_, beam)| beam).map(to_f32);
        self.sums.as_ref().and_then(|s| s.direct_kwh_m2.as_deref()).map(to_f32).or_else(inside)
    }

    /// A period's sky-diffuse irradiation per point, kWh/m² (with an irradiation value: `direct`, `skyDiffuse` or `total`).
    #[wasm_bindgen(getter, js_name = skyDiffuse)]
    pub fn sky_diffuse(&self) -> Option<Float32Array> {
        self.sums.as_ref().and_then(|s| s.sky_diffuse_kwh_m2.as_deref()).map(to_f32)
    }

    /// A period's ground-reflected irradiation per point, kWh/m² (with an irradiation value: `direct`, `skyDiffuse` or `total`).
    #[wasm_bindgen(getter, js_name = groundReflected)]
    pub fn ground_reflected(&self) -> Option<Float32Array> {
        self.sums.as_ref().and_then(|s| s.ground_reflected_kwh_m2.as_deref()).map(to_f32)
    }

    /// A period's total irradiation per point, kWh/m² (with an irradiation value: `direct`, `skyDiffuse` or `total`).
    #[wasm_bindgen(getter)]
    pub fn total(&self) -> Option<Float32Array> {
        self.sums.as_ref().and_then(|s| s.total_kwh_m2.as_deref()).map(to_f32)
    }

    /// Each point's view factor to the visible sky (with an irradiation value: `direct`, `skyDiffuse` or `total`).
    #[wasm_bindgen(getter, js_name = skyViewFactor)]
    pub fn sky_view_factor(&self) -> Option<Float32Array> {
        self.sums.as_ref().and_then(|s| s.sky_view_factor.as_deref()).map(to_f32)
    }

    /// The legend's low end: 0.
    #[wasm_bindgen(getter)]
    pub fn min(&self) -> f64 {
        0.0
    }

    /// The legend's high end: the largest value (1 when all are 0); 1 for lit.
    #[wasm_bindgen(getter)]
    pub fn max(&self) -> f64 {
        let top = self.values.iter().copied().fold(0.0, f64::max);
        if self.value == MapValue::Lit || top <= 0.0 { 1.0 } else { top }
    }

    /// Inside rooms: per point the glass's solar transmittance on its beam (0 shaded; undefined
    /// outside).
    #[wasm_bindgen(getter, js_name = solarTransmittance)]
    pub fn solar_transmittance(&self) -> Option<Float32Array> {
        self.inside.as_ref().and_then(Inside::weights).map(|(solar, _)| to_f32(solar))
    }

    /// Inside rooms: per point the glass's visible transmittance likewise.
    #[wasm_bindgen(getter, js_name = visibleTransmittance)]
    pub fn visible_transmittance(&self) -> Option<Float32Array> {
        self.inside.as_ref().and_then(Inside::weights).map(|(_, visible)| to_f32(visible))
    }

    /// Inside rooms: the inside scene's receiver names, which `receivers` index (undefined
    /// outside: the model's `receiverNames`).
    #[wasm_bindgen(getter, js_name = insideNames)]
    pub fn inside_names(&self) -> Option<Vec<String>> {
        self.inside.as_ref().map(Inside::receiver_names)
    }

    /// Inside rooms: each inside face's sun patch, as JSON (`surface`, `zone`, `areaM2`,
    /// `fraction`), as `map --inside --at --json` reports `sun_patches`.
    #[wasm_bindgen(getter)]
    pub fn patches(&self) -> Option<String> {
        self.inside.as_ref().and_then(Inside::patches_json)
    }

    /// Inside rooms, a study: each room's share, as JSON (`zone`, `points`, and `ase` or
    /// `seesSky` in %), as the study's report gives its `areas`.
    #[wasm_bindgen(getter)]
    pub fn areas(&self) -> Option<String> {
        self.inside.as_ref().and_then(Inside::areas_json)
    }

    /// The points CSV as `sunlit map -o POINTS.csv` writes it for the same options.
    pub fn csv(&self) -> String {
        match &self.inside {
            Some(inside) => inside.csv(&self.points),
            None => points_csv(&self.model.scene, &self.points, &self.columns()),
        }
    }

    /// The map glb as `sunlit map --glb-out` writes it, coloured by the value asked.
    pub fn glb(&self) -> Uint8Array {
        let (name, unit) = match self.value {
            MapValue::SunHours => ("sun_hours", "h"),
            MapValue::Direct => ("direct_kwh_m2", "kWh/m²"),
            MapValue::SkyDiffuse => ("sky_diffuse_kwh_m2", "kWh/m²"),
            MapValue::Total => ("total_kwh_m2", "kWh/m²"),
            MapValue::Lit | MapValue::AseHours | MapValue::SeesSky => ("lit", ""),
        };
        match &self.inside {
            Some(inside) => Uint8Array::from(inside.glb(&self.points).as_slice()),
            None => Uint8Array::from(map_glb(&self.model.scene, &self.points, &self.values, name, unit).as_slice()),
        }
    }
}

fn to_f32(values: &[f64]) -> Float32Array {
    let v: Vec<f32> = values.iter().map(|&x| x as f32).collect();
    Float32Array::from(v.as_slice())
}

#[wasm_bindgen]
impl Engine {
    /// Promise of a per-point map ([`PointMap`]) of `model`; `options` is a plain object
    /// (`MapOptions` in sunlit.d.ts). `progress(done, total)` is called between chunks of a
    /// period's instants; an aborted `signal` rejects with `code: 'cancelled'`.
    pub fn map(&self, model: &Model, options: JsValue, progress: Option<Function>, signal: Option<web_sys::AbortSignal>) -> Promise {
        let model = model.inner.clone();
        future_to_promise(async move {
            let request = request_from_js(&options).map_err(map_error)?;
            let run = Run { progress: progress.as_ref(), signal: signal.as_ref() };
            if let Some(ask) = &request.inside {
                let (points, inside) = inside_map(&model, &request, ask, run).await.map_err(map_error)?;
                let ((value, values), instants, points) = (inside.values(), inside.instants(), Rc::new(points));
                return Ok(PointMap { model, points, value, values, sums: None, instants, inside: Some(inside) }.into());
            }
            let (points, mapper) = points_for(&model, &request.place).map_err(map_error)?;
            let sky = request.value.needs_weather().then(|| sky_for(&model, &request.place, &mapper, request.site.sky_model));
            let site = Site {
                location: &request.site.location,
                calendar: &request.site.calendar,
                weather: request.weather.as_ref(),
                sky: sky.as_deref(),
            };
            let samples = request.period.samples();
            let value = request.value;
            let map = if value == MapValue::Lit {
                let values = lit_at(&mapper, site, &samples, points.len()).into_iter().map(f64::from).collect();
                PointMap { model, points, value, values, sums: None, instants: samples.len(), inside: None }
            } else {
                let sums = summed(&mapper, site, &samples, run).await.map_err(map_error)?;
                let values = match value {
                    MapValue::Direct => sums.direct_kwh_m2.clone(),
                    MapValue::SkyDiffuse => sums.sky_diffuse_kwh_m2.clone(),
                    MapValue::Total => sums.total_kwh_m2.clone(),
                    MapValue::SunHours | MapValue::Lit | MapValue::AseHours | MapValue::SeesSky => Some(sums.sun_hours.clone()),
                }
                .unwrap_or_default();
                PointMap { model, points, value, values, instants: sums.instants, sums: Some(sums), inside: None }
            };
            Ok(map.into())
        })
    }
}

/// The JS options object as a [`MapRequest`].
fn request_from_js(options: &JsValue) -> Result<MapRequest> {
    if options.is_undefined() || options.is_null() {
        return Err(Error::argument("options", "give at least a location (latitude, longitude, timeZone) or an EPW"));
    }
    let text = js_sys::JSON::stringify(options).map_err(|_| Error::argument("options", "not a plain object"))?;
    MapRequest::from_value(serde_json::from_str(&String::from(text)).map_err(|e| Error::argument("options", e.to_string()))?)
}

/// A library error as a JS one, its `spacing` named as this API spells it: `grid`.
fn map_error(error: Error) -> JsValue {
    js_error(match error {
        Error::Argument { what, reason } if what == "spacing" => Error::Argument { what: "grid".into(), reason },
        Error::Argument { what, reason } if what == "work_plane" => Error::Argument { what: "workPlane".into(), reason },
        Error::Argument { what, reason } if what == "glass_transmittance" => Error::Argument { what: "glassTransmittance".into(), reason },
        other => other,
    })
}

/// Each point's visibility at the period's one instant, as `sunlit map --at` finds it (0 with
/// the sun down or behind the point's surface).
fn lit_at(mapper: &Mapper, site: Site<'_>, samples: &[Sample], points: usize) -> Vec<f32> {
    let Some(s) = samples.first() else { return vec![0.0; points] };
    let sun = sun_direction(site.location, shading_sun_day(s.day), s.hour);
    mapper.visibility(sun, site.calendar.fraction(f64::from(s.day)) as f32)
}

/// What a call hands its long sums: the progress callback and the abort signal.
#[derive(Clone, Copy)]
pub(super) struct Run<'a> {
    pub(super) progress: Option<&'a Function>,
    pub(super) signal: Option<&'a web_sys::AbortSignal>,
}

/// `samples` summed in [`CHUNKS`] stretches: each by `part`, folded into the first by `add`,
/// with progress (instants done, of all) and a turn of the event loop after each, where an abort
/// is seen: then nothing is returned but [`Error::Cancelled`]. None for no samples.
pub(super) async fn in_chunks<S, T>(
    samples: &[S],
    run: Run<'_>,
    mut part: impl FnMut(&[S]) -> Result<T>,
    mut add: impl FnMut(&mut T, T),
) -> Result<Option<T>> {
    let mut total: Option<T> = None;
    let size = samples.len().div_ceil(CHUNKS).max(1);
    let mut done = 0usize;
    for chunk in samples.chunks(size) {
        let sums = part(chunk)?;
        done += chunk.len();
        match total.as_mut() {
            None => total = Some(sums),
            Some(t) => add(t, sums),
        }
        if let Some(f) = run.progress {
            // A throwing progress callback is the caller's bug, not a reason to stop.
            let _ = f.call2(&JsValue::NULL, &JsValue::from(done as f64), &JsValue::from(samples.len() as f64));
        }
        next_turn().await;
        if run.signal.is_some_and(|s| s.aborted()) {
            return Err(Error::Cancelled);
        }
    }
    Ok(total)
}

/// The period's sums, chunk by chunk with a turn of the event loop between (progress, abort).
async fn summed(mapper: &Mapper, site: Site<'_>, samples: &[Sample], run: Run<'_>) -> Result<MapValues> {
    let total = in_chunks(samples, run, |chunk| mapper.accumulate(chunk, site, &mut |_, _| {}), |t: &mut MapValues, p| t.merge(&p)).await?;
    match total {
        Some(t) => Ok(t),
        None => mapper.accumulate(&[], site, &mut |_, _| {}),
    }
}

/// Resolves after the event loop's next turn (a zero `setTimeout`), so that messages (a cancel)
/// reach the worker between chunks.
async fn next_turn() {
    let promise = Promise::new(&mut |resolve, _| {
        let global = js_sys::global();
        if let Ok(set_timeout) = js_sys::Reflect::get(&global, &"setTimeout".into()).and_then(|f| f.dyn_into::<Function>()) {
            let _ = set_timeout.call2(&global, &resolve, &JsValue::from(0));
        } else {
            let _ = resolve.call0(&JsValue::NULL);
        }
    });
    let _ = JsFuture::from(promise).await;
}
