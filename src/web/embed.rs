//! The bindings for embedding sunlit in a web viewer: scenes from meshes and placements (a
//! three.js scene graph, instancing kept), a year's irradiation on [`Annual`] (direct, sky
//! diffuse, ground-reflected, total, unshaded total, sky view factor), its
//! fractions at any instant (for a time slider: the fitted surfaces, or the schedule's rows
//! interpolated), and an EPW's location for a form.

use js_sys::{Float64Array, Object, Reflect};
use wasm_bindgen::prelude::*;

use super::{Annual, Engine, Model, js_error};
use crate::error::{Error, Result};
use crate::export::Schedule;
use crate::export::irradiation::{SurfaceSummary, summarize};
use crate::model::placed::{Placed, scene_from_placed};
use crate::scene::Scene;
use crate::sky::views::SkyViews;
use crate::sun::location::Location;
use crate::sun::position::sun_direction;
use crate::sun::weather::{Weather, location_from_text};
use crate::year::fitted::FittedYear;
use crate::year::samples::DAYS;
use crate::year::season::LeafCalendar;

#[wasm_bindgen]
impl Engine {
    /// Builds a scene from meshes and their placements (see `model::placed`) and uploads it.
    /// `receivers[p]` is 1 where placement `p` receives; `matrices` holds 16 numbers per
    /// placement, column-major.
    #[wasm_bindgen(js_name = fromMeshes)]
    #[allow(clippy::too_many_arguments)]
    pub fn from_meshes(
        &self,
        positions: &[f32],
        vertex_starts: &[u32],
        indices: &[u32],
        index_starts: &[u32],
        placement_meshes: &[u32],
        matrices: &[f64],
        names: Vec<String>,
        receivers: &[u8],
        y_up: bool,
    ) -> Result<Model, JsValue> {
        let input = Placed { positions, vertex_starts, indices, index_starts, placement_meshes, matrices, names: &names, receivers, y_up };
        self.model(scene_from_placed(&input).map_err(js_error)?, None, Vec::new())
    }
}

/// What a year adds for viewers: the site, the per-surface summary (or why the weather's
/// irradiance could not be read) and the fitted surfaces (None for a dense year).
pub(super) struct Extra {
    location: Location,
    summary: std::result::Result<Vec<SurfaceSummary>, String>,
    fitted: Option<FittedYear>,
}

impl Extra {
    /// The summary of `schedule`, with irradiation when `weather` (read from the EPW) is given
    /// and readable; `sky` the receivers' sky views (counted when the weather is readable).
    pub(super) fn new(
        scene: &Scene,
        schedule: &Schedule,
        location: &Location,
        weather: Option<Result<Weather>>,
        sky: Option<(&SkyViews, &LeafCalendar)>,
        fitted: Option<FittedYear>,
    ) -> Self {
        let summary = (|| -> Result<Vec<SurfaceSummary>> {
            let weather = weather.transpose()?;
            summarize(scene, schedule, location, sky, weather.as_ref(), &[])
        })()
        .map_err(|e| e.to_string());
        Self { location: location.clone(), summary, fitted }
    }
}

#[wasm_bindgen]
impl Annual {
    /// Each receiver's annual direct (beam) irradiation Σ DNI·cos θ·fraction·Δt in kWh/m², from
    /// the EPW's direct normal irradiance; `undefined` when the run had a location, not an EPW.
    /// Throws (naming the file and line) when the EPW's hourly records are unreadable.
    #[wasm_bindgen(getter)]
    pub fn irradiation(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.irradiation)
    }

    /// The same as `irradiation`: the beam part of the total, kWh/m².
    #[wasm_bindgen(getter)]
    pub fn direct(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.irradiation)
    }

    /// Sky diffuse irradiation (Perez sky, shaded by the visible sky patches), kWh/m².
    #[wasm_bindgen(getter, js_name = skyDiffuse)]
    pub fn sky_diffuse(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.sky_diffuse)
    }

    /// Ground-reflected irradiation (GHI·albedo·(1 − cos tilt)/2, unobstructed), kWh/m².
    #[wasm_bindgen(getter, js_name = groundReflected)]
    pub fn ground_reflected(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.ground_reflected)
    }

    /// Direct + sky diffuse + ground-reflected, shaded, kWh/m².
    #[wasm_bindgen(getter)]
    pub fn total(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.total)
    }

    /// The total with nothing in the way, kWh/m².
    #[wasm_bindgen(getter, js_name = unshadedTotal)]
    pub fn unshaded_total(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.unshaded_total)
    }

    /// Each receiver's view factor to the visible sky ((1 + cos tilt)/2 unobstructed); with an EPW only.
    #[wasm_bindgen(getter, js_name = skyViewFactor)]
    pub fn sky_view_factor(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.sky_view_factor)
    }

    /// The same without shading: Σ DNI·cos θ·Δt (cos θ > 0), kWh/m².
    #[wasm_bindgen(getter, js_name = unshadedIrradiation)]
    pub fn unshaded_irradiation(&self) -> Result<Option<Float64Array>, JsValue> {
        self.summary_column(|s| s.unshaded_irradiation)
    }

    fn summary_column(&self, value: impl Fn(&SurfaceSummary) -> Option<f64>) -> Result<Option<Float64Array>, JsValue> {
        let summary = self.extra.summary.as_ref().map_err(|e| JsValue::from(JsError::new(e)))?;
        let values: Option<Vec<f64>> = summary.iter().map(value).collect();
        Ok(values.map(|v| Float64Array::from(v.as_slice())))
    }

    /// Every receiver's fraction at day of year `day` (1..=365, fractional allowed: the hour
    /// then comes from it when `hour` is undefined) and local standard `hour` (0..24): linear
    /// between the schedule's rows, 0 where the sun is down.
    #[wasm_bindgen(js_name = fractionsAt)]
    pub fn fractions_at(&self, day: f64, hour: Option<f64>) -> Result<Float64Array, JsValue> {
        let (day, hour) = match hour {
            Some(h) => (day, h),
            None => (day.floor(), (day - day.floor()) * 24.0),
        };
        if !(1.0..f64::from(DAYS) + 1.0).contains(&day) || !day.is_finite() {
            return Err(js_error(Error::argument("day", format!("{day} is outside 1..=365"))));
        }
        if !(0.0..=24.0).contains(&hour) {
            return Err(js_error(Error::argument("hour", format!("{hour} is outside 0..=24"))));
        }
        let columns = self.schedule.names.len();
        if sun_direction(&self.extra.location, day.floor(), hour).z <= 0.0 {
            return Ok(Float64Array::from(vec![0.0; columns].as_slice()));
        }
        Ok(Float64Array::from(interpolated_row(&self.schedule, (day.floor() - 1.0) * 24.0 + hour).as_slice()))
    }
}

#[wasm_bindgen]
impl Annual {
    /// Every receiver's fraction at day of year `day` (1..=365, fractional allowed) and local
    /// standard `hour` (0..=24) from the year's fitted spline surfaces, evaluated here: smooth
    /// between timesteps, the schedule's value at a timestep's instant except where the run
    /// counted that timestep directly (refinement), exactly 0 with the sun down or behind the
    /// surface. A dense year (`dense: true`) has no surfaces: an error naming `dense`.
    #[wasm_bindgen(js_name = splineFractionsAt)]
    pub fn spline_fractions_at(&self, day: f64, hour: f64) -> Result<Float64Array, JsValue> {
        let Some(fitted) = &self.extra.fitted else {
            return Err(js_error(Error::argument("dense", "a dense year has no fitted surfaces; use fractionsAt")));
        };
        let values = fitted.fractions_at(day, hour).map_err(js_error)?;
        Ok(Float64Array::from(values.as_slice()))
    }
}

/// The schedule's values at `time` hours since 1 January 00:00, linear between the rows'
/// instants (clamped at the year's ends).
fn interpolated_row(schedule: &Schedule, time: f64) -> Vec<f64> {
    let timesteps = schedule.timesteps;
    let step = 1.0 / f64::from(timesteps.per_hour());
    let instant_of = |row: usize| {
        let i = timesteps.instant(row);
        f64::from(i.day - 1) * 24.0 + i.hour
    };
    let first = instant_of(0);
    let position = ((time - first) / step).clamp(0.0, (timesteps.rows() - 1) as f64);
    let below = position.floor() as usize;
    let above = (below + 1).min(timesteps.rows() - 1);
    let weight = position - below as f64;
    (0..schedule.names.len())
        .map(|c| f64::from(schedule.get(below, c)) * (1.0 - weight) + f64::from(schedule.get(above, c)) * weight)
        .collect()
}

/// An EPW's LOCATION record as `{ latitude, longitude, timeZone, elevation, name }`, so a form
/// can show the site the weather file sets. Throws naming `name` and the reason.
#[wasm_bindgen(js_name = epwLocation)]
pub fn epw_location(name: &str, text: &str) -> Result<Object, JsValue> {
    let location = location_from_text(name, text).map_err(js_error)?;
    let object = Object::new();
    for (key, value) in [
        ("latitude", JsValue::from(location.latitude)),
        ("longitude", JsValue::from(location.longitude)),
        ("timeZone", JsValue::from(location.time_zone)),
        ("elevation", JsValue::from(location.elevation)),
        ("name", JsValue::from(location.name.as_str())),
    ] {
        Reflect::set(&object, &JsValue::from(key), &value)?;
    }
    Ok(object)
}
