//! `engine.study`: the window studies in the browser ([`crate::map::planning`]), translated to
//! and from JS. Its options are read by [`super::study_options`]; the points are the library's
//! (each window's by [`window_points`], or given ones, as `sunlit map --window-points` and
//! `--points` take them), the studies [`run::evaluate`]'s and the tables and their CSV the
//! library's writers', so a study's CSV is `sunlit map`'s `POINTS.study-NAME.csv` byte for byte.
//! No study logic lives here or in JS.

use serde_json::json;
use wasm_bindgen::prelude::*;

use super::map_options::points_csv as given_points;
use super::study_options::{StudyPlace, StudyRequest};
use super::{Engine, Model, js_error};
use crate::error::{Error, Result};
use crate::export::planning_report::{StudyTable, study_csv};
use crate::export::planning_tables::tables;
use crate::map::planning::run;
use crate::map::planning::window_points::window_points;
use crate::map::{Points, Site, from_csv};
use crate::scene::Scene;
use crate::year::season::LeafCalendar;

/// A study's answer: the points, and per study its table (values and verdicts per point) and
/// CSV.
#[wasm_bindgen]
pub struct Study {
    model: std::rc::Rc<super::ModelInner>,
    points: Points,
    tables: Vec<StudyTable>,
}

#[wasm_bindgen]
impl Study {
    /// The answer as JSON text (sunlit.js parses it into `SunlitStudy`'s typed arrays and
    /// tables): `points` and `normals` (3 numbers a point, the f32 values exactly), `receivers`,
    /// and per study asked `study`, `source`, `rule`, `values` (per key, per point), `passes`
    /// (per point: true, false, or null where the rule does not assess it) and `verdicts` (per
    /// verdict key, per point).
    pub fn json(&self) -> String {
        let n = self.points.len();
        let tables: Vec<_> = self
            .tables
            .iter()
            .map(|t| {
                let verdicts = t.verdicts.iter().map(|(k, v)| (k.clone(), json!(v.iter().map(|x| x.passes).collect::<Vec<_>>())));
                json!({
                    "study": t.study,
                    "source": t.source,
                    "rule": t.rule,
                    "values": t.values.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "passes": (0..n).map(|i| t.passes(i)).collect::<Vec<_>>(),
                    "verdicts": verdicts.collect::<serde_json::Map<_, _>>(),
                })
            })
            .collect();
        let p = &self.points;
        json!({"points": p.positions, "normals": p.normals, "receivers": p.receivers, "tables": tables}).to_string()
    }

    /// `study`'s table as `sunlit map --study STUDY` writes `POINTS.study-STUDY.csv`.
    pub fn csv(&self, study: &str) -> Result<String, JsValue> {
        let table = self.tables.iter().find(|t| t.study == study).ok_or_else(|| {
            let asked: Vec<&str> = self.tables.iter().map(|t| t.study.as_str()).collect();
            js_error(Error::argument("study", format!("'{study}' was not studied here ({})", asked.join(", "))))
        })?;
        Ok(study_csv(&self.model.scene, &self.points, table))
    }
}

#[wasm_bindgen]
impl Engine {
    /// The window studies of `options` (`StudyOptions` in sunlit.d.ts) on `model`, answered by
    /// the exact shadow rays on the CPU (no GPU): a [`Study`].
    pub fn study(&self, model: &Model, options: JsValue) -> Result<Study, JsValue> {
        let model = model.inner.clone();
        let request = request_from_js(&options).map_err(study_error)?;
        let points = points_of(&model.scene, &request.place).map_err(study_error)?;
        let calendar = request.location.as_ref().map(|l| LeafCalendar::for_latitude(l.latitude));
        let site = request.location.as_ref().zip(calendar.as_ref()).map(|(location, calendar)| Site {
            location,
            calendar,
            weather: request.weather.as_ref(),
            sky: None,
        });
        let values = run::evaluate(&request.studies, &model.scene, &points, site, request.gb.as_ref(), &mut |_| {}).map_err(study_error)?;
        let tables = tables(&values, None, points.len(), request.gb.as_ref(), request.location.as_ref());
        Ok(Study { model, points, tables })
    }
}

/// The studies' points on `scene`: one on each window asked, or the given ones (each on a
/// receiver).
fn points_of(scene: &Scene, place: &StudyPlace) -> Result<Points> {
    match place {
        StudyPlace::Windows(ids, at) => {
            if let Some(id) = ids.iter().find(|&&id| id as usize >= scene.receivers.len()) {
                return Err(Error::argument(
                    "windows",
                    format!("{id} is not a receiver's index (the model has {})", scene.receivers.len()),
                ));
            }
            window_points(scene, ids, *at)
        }
        StudyPlace::Given(numbers) => {
            let all: Vec<u32> = (0..scene.receivers.len() as u32).collect();
            from_csv(scene, "points", &given_points(numbers)?, &all)
        }
    }
}

/// The JS options object as a [`StudyRequest`].
fn request_from_js(options: &JsValue) -> Result<StudyRequest> {
    if options.is_undefined() || options.is_null() {
        return Err(Error::argument("options", "give at least a study and the windows (or points)"));
    }
    let text = js_sys::JSON::stringify(options).map_err(|_| Error::argument("options", "not a plain object"))?;
    StudyRequest::from_value(serde_json::from_str(&String::from(text)).map_err(|e| Error::argument("options", e.to_string()))?)
}

/// A library error as a JS one, the site named as this API spells it (`latitude`, not
/// `location`).
fn study_error(error: Error) -> JsValue {
    js_error(match error {
        Error::Argument { what, reason } if what == "location" => Error::Argument { what: "latitude".into(), reason },
        other => other,
    })
}
