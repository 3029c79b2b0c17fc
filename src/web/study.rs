//! `engine.study`: the window studies in the browser ([`crate::map::planning`]), translated to
//! and from JS. Its options are read by [`super::study_options`]; the points are the library's
//! (each window's by [`window_points`], its sill raised above a floor level by [`floor_sills`],
//! or given ones, as `sunlit map --window-points`, `--floor-level` and `--points` take them), GB
//! 50180's 满窗 sills each window's own where asked (measured or given, as `--window-width sill`
//! and `--window-widths`), the studies [`run::before_after`]'s (with an existing scene, `--before`),
//! the tables, their CSV, the sky masks and the HTML report the library's writers', so a study's
//! CSV is `sunlit map`'s `POINTS.study-NAME.csv` and its report `--html`'s, byte for byte. No
//! study logic lives here or in JS.

use serde_json::json;
use wasm_bindgen::prelude::*;

use super::map_options::points_csv as given_points;
use super::study_options::{StudyPlace, StudyRequest};
use super::{Engine, Model, js_error};
use crate::error::{Error, Result};
use crate::export::planning_report::{StudyTable, report_html, study_csv};
use crate::export::planning_tables::{compared_tables, mask_svgs, points_input, report_inputs};
use crate::map::planning::compare::ratio;
use crate::map::planning::run::{self, Rules};
use crate::map::planning::window_points::{floor_sills, window_points};
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
    /// The sky masks asked for: (point row, SVG).
    masks: Vec<(usize, String)>,
    /// The HTML report, as `sunlit map --html` writes it.
    html: String,
}

#[wasm_bindgen]
impl Study {
    /// The answer as JSON text (sunlit.js parses it into `SunlitStudy`'s typed arrays and
    /// tables): `points` and `normals` (3 numbers a point, the f32 values exactly), `receivers`,
    /// and per study asked `study`, `source`, `rule`, `values` (per key, per point), `passes`
    /// (per point: true, false, or null where the rule does not assess it), `verdicts` (per
    /// verdict key, per point), `absolute` and `relative` (the study's own verdict's absolute
    /// and relative tests per point; `relative` null without a former value), and with an
    /// existing scene `before` and `ratio` (per key, per point, null where the point is not in
    /// it); and `masks`: `[row, svg]` per sky mask drawn.
    pub fn json(&self) -> String {
        let n = self.points.len();
        let tables: Vec<_> = self
            .tables
            .iter()
            .map(|t| {
                let verdicts = t.verdicts.iter().map(|(k, v)| (k.clone(), json!(v.iter().map(|x| x.passes).collect::<Vec<_>>())));
                let own = t.verdicts.first().map(|(_, v)| v.as_slice()).unwrap_or_default();
                let former = t.before.as_ref().map(|before| {
                    let per_key = |f: &dyn Fn(usize, usize) -> Option<f64>| -> serde_json::Map<String, serde_json::Value> {
                        t.values
                            .iter()
                            .enumerate()
                            .map(|(k, (key, _))| (key.clone(), json!((0..n).map(|i| f(k, i)).collect::<Vec<_>>())))
                            .collect()
                    };
                    (per_key(&|k, i| before[k][i]), per_key(&|k, i| ratio(t.values[k].1[i], before[k][i])))
                });
                json!({
                    "study": t.study,
                    "source": t.source,
                    "rule": t.rule,
                    "values": t.values.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "passes": (0..n).map(|i| t.passes(i)).collect::<Vec<_>>(),
                    "verdicts": verdicts.collect::<serde_json::Map<_, _>>(),
                    "absolute": own.iter().map(|v| v.absolute).collect::<Vec<_>>(),
                    "relative": own.iter().map(|v| v.relative).collect::<Vec<_>>(),
                    "before": former.as_ref().map(|f| &f.0),
                    "ratio": former.as_ref().map(|f| &f.1),
                })
            })
            .collect();
        let p = &self.points;
        json!({"points": p.positions, "normals": p.normals, "receivers": p.receivers, "tables": tables, "masks": self.masks}).to_string()
    }

    /// The report as `sunlit map --study … --html REPORT.html` writes it: the inputs, each
    /// study's rule and table (with the existing scene's values), the sky masks asked for.
    pub fn html(&self) -> String {
        self.html.clone()
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
        run_study(model, None, &options)
    }

    /// [`Self::study`] on `model` (the proposed scene) and on `before` (the existing one) at
    /// the same points, as `sunlit map --study … --before MODEL`: each table has the former
    /// values and BRE's relative tests.
    #[wasm_bindgen(js_name = studyBeforeAfter)]
    pub fn study_before_after(&self, model: &Model, before: &Model, options: JsValue) -> Result<Study, JsValue> {
        run_study(model, Some(before), &options)
    }
}

/// The studies of `options` on `model`, and on `before` at the same points when given.
fn run_study(model: &Model, before: Option<&Model>, options: &JsValue) -> Result<Study, JsValue> {
    let model = model.inner.clone();
    let before = before.map(|m| m.inner.clone());
    let request = request_from_js(options).map_err(study_error)?;
    let points = points_of(&model.scene, &request.place, request.floor_level).map_err(study_error)?;
    let mut gb = request.gb.clone();
    if let Some(rule) = gb.as_mut() {
        request.whole_window_of_each(rule, &model.scene, &points).map_err(study_error)?;
    }
    let calendar = request.location.as_ref().map(|l| LeafCalendar::for_latitude(l.latitude));
    let site = request.location.as_ref().zip(calendar.as_ref()).map(|(location, calendar)| Site {
        location,
        calendar,
        weather: request.weather.as_ref(),
        sky: None,
    });
    let from = match &request.place {
        StudyPlace::Windows(_, at) => format!("the windows' {}s", at.name()),
        StudyPlace::Given(_) => "points".into(),
    };
    let (now, former) = run::before_after(
        &request.studies,
        &model.scene,
        &points,
        before.as_ref().map(|b| (&b.scene, from.as_str())),
        site,
        Rules { gb: gb.as_ref(), en17037: request.en17037.as_ref() },
        &mut |_| {},
        &mut |_| {},
    )
    .map_err(study_error)?;
    let (gb, location) = (gb.as_ref(), request.location.as_ref());
    let tables = compared_tables(&now, former.as_ref(), points.len(), gb, location);
    let masks = mask_svgs(&model.scene, &points, &request.masks.rows(points.len()), location, gb).map_err(study_error)?;
    let place = match &request.place {
        StudyPlace::Windows(_, at) => points_input(Some(*at), None, request.floor_level),
        StudyPlace::Given(_) => points_input(None, Some("points"), None),
    };
    let (models, befores) = &request.names;
    let inputs = report_inputs(models, befores, place, location, request.epw_name.as_deref());
    let html = report_html(&model.scene, &points, &tables, &masks, &inputs);
    Ok(Study { model, points, tables, masks, html })
}

/// The studies' points on `scene`: one on each window asked (the sills raised above
/// `floor_level` where given), or the given ones (each on a receiver).
fn points_of(scene: &Scene, place: &StudyPlace, floor_level: Option<f64>) -> Result<Points> {
    match place {
        StudyPlace::Windows(ids, at) => {
            if let Some(id) = ids.iter().find(|&&id| id as usize >= scene.receivers.len()) {
                return Err(Error::argument(
                    "windows",
                    format!("{id} is not a receiver's index (the model has {})", scene.receivers.len()),
                ));
            }
            match floor_level {
                Some(floor) => floor_sills(scene, ids, floor),
                None => window_points(scene, ids, *at),
            }
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
