//! Every window study asked, run on one scene at one set of points, sharing the scene's one
//! shadow-ray tree: what `sunlit map --study` runs on the proposed scene and again on the
//! existing one, so that the edges only read their options and write the reports
//! ([`crate::export::planning_tables`] makes the tables). [`before_after`] is that pair of runs,
//! the proposed scene and the existing one at the same points, for every edge that compares them.

use glam::DVec3;

use super::en17037::{self, En17037Rule};
use super::gb50180::{self, Gb50180Rule};
use super::{SceneRays, Windows, apsh, bre_lines, vsc};
use crate::error::{Error, Result};
use crate::map::{Points, Site, points};
use crate::scene::Scene;

/// The studies that are window studies wherever they are asked; `en17037` is one beside them,
/// at windows' own points or against an existing scene, and alone on given points or a grid the
/// CLI's area study ([`crate::map::study`]).
pub const STUDIES: [&str; 5] = ["bre-vsc", "bre-apsh", "gb50180", "bre-25deg", "bre-45deg"];

/// Every window study's name: [`STUDIES`] and `en17037` (what the page's `engine.study` runs).
pub const WINDOW_STUDIES: [&str; 6] = ["bre-vsc", "bre-apsh", "gb50180", "bre-25deg", "bre-45deg", "en17037"];

/// The rules whose parameters a run sets: gb50180's and en17037's (each needed only when its
/// study is asked).
#[derive(Debug, Clone, Copy, Default)]
pub struct Rules<'a> {
    /// gb50180's.
    pub gb: Option<&'a Gb50180Rule>,
    /// en17037's.
    pub en17037: Option<&'a En17037Rule>,
}

/// Refuses a sky model the studies do not take, naming `sky_model`: only bre-vsc looks at the
/// sky, and it is defined under the CIE standard overcast sky; the others count the sun alone.
pub fn check_sky_model(studies: &[String], sky_model: Option<&str>) -> Result<()> {
    let Some(model) = sky_model else { return Ok(()) };
    if !studies.iter().any(|s| s == "bre-vsc") {
        return Err(Error::argument("sky_model", format!("{} counts the sun alone and takes no sky model", studies.join(", "))));
    }
    if model != "cie-overcast" {
        return Err(Error::argument(
            "sky_model",
            format!("'{model}': bre-vsc is defined under the CIE standard overcast sky and takes only cie-overcast"),
        ));
    }
    Ok(())
}

/// One scene's values per study asked ([`STUDIES`]' names).
#[derive(Default)]
pub struct StudyValues {
    /// `bre-vsc`'s.
    pub vsc: Option<vsc::VscValues>,
    /// `bre-apsh`'s.
    pub apsh: Option<apsh::ApshValues>,
    /// `gb50180`'s.
    pub gb: Option<gb50180::Gb50180Values>,
    /// `bre-25deg`'s and `bre-45deg`'s (one pass gives both).
    pub lines: Option<bre_lines::LineValues>,
    /// `en17037`'s.
    pub en17037: Option<en17037::En17037Values>,
    /// The studies asked for, in order.
    pub asked: Vec<String>,
}

/// Every study of `studies` ([`WINDOW_STUDIES`]' names, in order) at `points` of `scene`: `site`
/// for bre-apsh (with its weather), gb50180 and en17037, `rules` the rules' parameters.
/// `done(part)` is called once the scene is indexed (`index`) and after each study (its name), so
/// a caller can time the parts. Refuses a study it does not know, and a study without what it
/// needs, by name.
pub fn evaluate(
    studies: &[String],
    scene: &Scene,
    points: &Points,
    site: Option<Site<'_>>,
    rules: Rules<'_>,
    done: &mut dyn FnMut(&str),
) -> Result<StudyValues> {
    if let Some(other) = studies.iter().find(|s| !WINDOW_STUDIES.contains(&s.as_str())) {
        return Err(Error::argument("study", format!("'{other}' is not a window study ({})", WINDOW_STUDIES.join(", "))));
    }
    // One tree for the scene; gb50180 places its own points (with its sill samples) on it, and
    // the other sun and sky studies share these.
    let tree = SceneRays::new(scene);
    let shared = studies.iter().any(|s| matches!(s.as_str(), "bre-vsc" | "bre-apsh" | "en17037"));
    let windows = shared.then(|| Windows::on(scene, &tree, points)).transpose()?;
    let mut values = StudyValues { asked: studies.to_vec(), ..StudyValues::default() };
    done("index");
    for study in studies {
        match (study.as_str(), &windows) {
            ("bre-vsc", Some(windows)) => values.vsc = Some(vsc::vsc(windows, &mut |_, _| {})),
            ("bre-25deg" | "bre-45deg", _) => {
                if values.lines.is_none() {
                    let (positions, normals) = placed(points);
                    values.lines = Some(bre_lines::evaluate(scene, &positions, &normals));
                }
            }
            ("bre-apsh", Some(windows)) => {
                let site = site.ok_or_else(|| Error::argument("epw", "bre-apsh needs a weather file"))?;
                values.apsh = Some(apsh::apsh(windows, site, &mut |_, _| {})?);
            }
            ("en17037", Some(windows)) => {
                let (site, rule) = site.zip(rules.en17037).ok_or_else(|| Error::argument("location", "en17037 needs the site"))?;
                values.en17037 = Some(en17037::evaluate(windows, site, rule, &mut |_, _| {})?);
            }
            _ => {
                let (site, rule) = site.zip(rules.gb).ok_or_else(|| Error::argument("location", "gb50180 needs the site"))?;
                values.gb = Some(gb50180::evaluate_on(scene, &tree, points, site.location, rule, &mut |_, _| {})?);
            }
        }
        done(study);
    }
    Ok(values)
}

/// Each point's position and normal.
fn placed(points: &Points) -> (Vec<DVec3>, Vec<DVec3>) {
    (0..points.len()).map(|i| (points.position(i), points.normal(i))).unzip()
}

/// The existing scene's points: each of the proposed `points` that lies on one of its
/// receivers, and where it sits in `points`. Refuses a scene with none in common, naming
/// `before` and `from` (where the points came from, for the message).
pub fn points_in(before: &Scene, points: &Points, from: &str) -> Result<(Points, Vec<usize>)> {
    let all: Vec<u32> = (0..before.receivers.len() as u32).collect();
    let (kept, index) = points::place_on(before, points, &all);
    if index.is_empty() {
        return Err(Error::argument("before", format!("no point of {from} lies on a receiver of the existing scene")));
    }
    Ok((kept, index))
}

/// The existing scene's side of a comparison: its values at its points, which are the proposed
/// points at `index`.
pub struct Former {
    /// The studies' values on the existing scene.
    pub values: StudyValues,
    /// The proposed points that lie on the existing scene's receivers.
    pub points: Points,
    /// Where each of them sits among the proposed points.
    pub index: Vec<usize>,
}

/// The studies of `studies` ([`WINDOW_STUDIES`], [`evaluate`]) on the proposed scene and, with
/// `before` (the existing scene, and where the points came from for [`points_in`]'s message), on
/// the existing one at the same points: what `sunlit map --study … --before` and the page's
/// before/after run. The existing scene's points are checked before anything is computed.
/// `done_now` and `done_before` are [`evaluate`]'s `done` for each scene.
#[allow(clippy::too_many_arguments)]
pub fn before_after(
    studies: &[String],
    scene: &Scene,
    points: &Points,
    before: Option<(&Scene, &str)>,
    site: Option<Site<'_>>,
    rules: Rules<'_>,
    done_now: &mut dyn FnMut(&str),
    done_before: &mut dyn FnMut(&str),
) -> Result<(StudyValues, Option<Former>)> {
    let existing = before.map(|(s, from)| points_in(s, points, from).map(|p| (s, p))).transpose()?;
    let mut now = evaluate(studies, scene, points, site, rules, done_now)?;
    // BRE's 25° line is drawn to the new development alone: what the existing scene lacks.
    if let (Some(lines), Some((old, _))) = (now.lines.as_mut(), before)
        && studies.iter().any(|s| s == "bre-25deg")
    {
        let (positions, normals) = placed(points);
        lines.development_deg = Some(bre_lines::section_angles(&bre_lines::development(scene, old), &positions, &normals));
    }
    let former = existing
        .map(|(s, (kept, index))| {
            // Each window keeps its own 满窗 width at its row among the existing scene's points.
            let gb = rules.gb.map(|g| g.at_points(&index));
            let rules = Rules { gb: gb.as_ref(), ..rules };
            evaluate(studies, s, &kept, site, rules, done_before).map(|values| Former { values, points: kept, index })
        })
        .transpose()?;
    Ok((now, former))
}
