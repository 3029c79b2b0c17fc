//! `engine.study`'s options object (`StudyOptions` in `www/sunlit.d.ts`) read into the library's
//! terms: which window studies ([`run::WINDOW_STUDIES`]), where (the windows' own points, found by
//! [`WindowPoint`], the sills raised above a ground-floor level as `--floor-level` raises them,
//! or given points), the site (a location or an EPW), GB 50180's rule
//! ([`Gb50180Rule::from_options`], with each window's own 满窗 sill: `windowWidth: 'sill'` measured
//! from the geometry, or `windowWidths` given by name), EN 17037's ([`En17037Rule::new`]), the sky model ([`run::check_sky_model`]), and what the report
//! draws and states (`masks`, the files' names). `before`, the existing scene, is a model, not
//! JSON: sunlit.js hands it to the wasm call beside the options. The studies
//! themselves are the library's ([`crate::map::planning::run`]); this only reads names. Plain
//! JSON in, so it is tested natively too (`js_api`).

use serde_json::{Map, Value};

use crate::error::{Error, Result};
use crate::map::Points;
use crate::map::period::parse_date;
use crate::map::planning::en17037::En17037Rule;
use crate::map::planning::gb50180::Gb50180Rule;
use crate::map::planning::run;
use crate::map::planning::sill_lines::sill_lines;
use crate::map::planning::sill_widths::{WholeWindow, named_widths, sill_widths};
use crate::map::planning::window_points::WindowPoint;
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::weather::Weather;

/// The keys of the options object.
pub const STUDY_KEYS: [&str; 23] = [
    "study",
    "windows",
    "windowPoints",
    "floorLevel",
    "points",
    "latitude",
    "longitude",
    "timeZone",
    "epw",
    "epwName",
    "skyModel",
    "day",
    "requiredHours",
    "minPeriod",
    "maxPeriods",
    "windowWidth",
    "windowWidths",
    "period",
    "minAltitude",
    "before",
    "masks",
    "modelNames",
    "beforeNames",
];

/// GB 50180's own keys: refused beside the other studies, as `sunlit map` refuses `--day`….
const GB_KEYS: [&str; 6] = ["day", "requiredHours", "minPeriod", "maxPeriods", "windowWidth", "windowWidths"];

/// EN 17037's own keys (`--period`, `--min-altitude`): refused without en17037.
const EN17037_KEYS: [&str; 2] = ["period", "minAltitude"];

/// Where the studies' points are.
#[derive(Debug, Clone, PartialEq)]
pub enum StudyPlace {
    /// One point on each of these receivers (indices into the model's receivers), as
    /// `sunlit map --window-points` puts it.
    Windows(Vec<u32>, WindowPoint),
    /// Given points, 6 numbers each (x y z nx ny nz).
    Given(Vec<f64>),
}

/// A study request read from the JS options.
pub struct StudyRequest {
    /// The window studies asked, in order.
    pub studies: Vec<String>,
    /// Where the points are.
    pub place: StudyPlace,
    /// The site (none given: only the studies that need none can run).
    pub location: Option<Location>,
    /// The EPW's hours, for bre-apsh.
    pub weather: Option<Weather>,
    /// The EPW's name (`epwName`, or `EPW`), as the report states it; none without an EPW.
    pub epw_name: Option<String>,
    /// GB 50180's rule, when gb50180 is asked (each window's own sill is set on it once the
    /// points are placed: [`Self::whole_window_of_each`]).
    pub gb: Option<Gb50180Rule>,
    /// `windowWidth: 'sill'`: each window's own sill line, measured from its geometry.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // read by the page's study (web only)
    pub sill_of_each: bool,
    /// `windowWidths`: each window's own sill width, by its name.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // read by the page's study (web only)
    pub window_widths: Option<GivenWidths>,
    /// EN 17037's rule, when en17037 is asked.
    pub en17037: Option<En17037Rule>,
    /// The ground floor's level (m, the model's heights) that the windows' sills are raised
    /// above, as `--floor-level` (with `windowPoints: 'sill'` only).
    pub floor_level: Option<f64>,
    /// The points (0-based rows) whose sky masks the report draws, as `--mask`.
    pub masks: Masks,
    /// The proposed and the existing model's file names, as the report states them (the CLI's
    /// `MODEL...` and `--before MODEL...`).
    pub names: (Vec<String>, Vec<String>),
}

/// Each window's own 满窗 width, as `windowWidths` gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum GivenWidths {
    /// The text of a `receiver,width` CSV, as `--window-widths FILE.csv` reads it.
    Csv(String),
    /// Width (m) by window name: `{ WIN_S1: 1.5, … }`.
    Named(Vec<(String, f64)>),
}

/// Which points' sky masks are drawn.
#[derive(Debug, Clone, PartialEq)]
pub enum Masks {
    /// Every point's (`--mask all`).
    All,
    /// These rows' (0-based).
    Rows(Vec<usize>),
}

impl Masks {
    /// The rows, 0-based, of `n` points.
    pub fn rows(&self, n: usize) -> Vec<usize> {
        match self {
            Self::All => (0..n).collect(),
            Self::Rows(rows) => rows.clone(),
        }
    }
}

impl StudyRequest {
    /// The options object (as JSON), checked: the studies' names, where, the site, the rule.
    pub fn from_value(options: Value) -> Result<Self> {
        let Value::Object(all) = options else {
            return Err(Error::argument("options", "give an object with at least a study and the windows (or points)"));
        };
        if let Some(key) = all.keys().find(|k| !STUDY_KEYS.contains(&k.as_str())) {
            return Err(Error::argument("options", format!("'{key}' is not a study option ({})", STUDY_KEYS.join(", "))));
        }
        let studies = studies(all.get("study"))?;
        let gb = studies.iter().any(|s| s == "gb50180");
        if !gb && let Some(key) = GB_KEYS.iter().find(|k| all.contains_key(**k)) {
            return Err(Error::argument(*key, format!("{} does not take it: only gb50180 does", studies.join(", "))));
        }
        let en17037 = studies.iter().any(|s| s == "en17037");
        if !en17037 && let Some(key) = EN17037_KEYS.iter().find(|k| all.contains_key(**k)) {
            return Err(Error::argument(*key, format!("{} does not take it: only en17037 does", studies.join(", "))));
        }
        run::check_sky_model(&studies, text_of(&all, "skyModel")?.as_deref())?;
        let place = place(&all)?;
        let epw_name = text_of(&all, "epw")?
            .map(|text| Ok::<_, Error>((text_of(&all, "epwName")?.unwrap_or_else(|| "EPW".into()), text)))
            .transpose()?;
        let weather = epw_name.as_ref().map(|(name, text)| Weather::from_epw_text(name, text)).transpose()?;
        let epw_name = epw_name.map(|(name, _)| name);
        let location = match (&weather, number(&all, "latitude")?) {
            (Some(w), _) => Some(w.location.clone()),
            (None, Some(latitude)) => {
                let coordinate =
                    |key: &str| number(&all, key)?.ok_or_else(|| Error::argument(key, "give latitude, longitude and timeZone"));
                Some(Location::new(latitude, coordinate("longitude")?, coordinate("timeZone")?)?)
            }
            (None, None) => None,
        };
        let whole = whole_window(&all)?;
        let window_widths = given_widths(&all)?;
        let gb = gb
            .then(|| {
                let max_periods = match number(&all, "maxPeriods")? {
                    Some(n) if n >= 0.0 && n.fract() == 0.0 => Some(n as usize),
                    Some(n) => return Err(Error::argument("max_periods", format!("{n} is not a whole number"))),
                    None => None,
                };
                Gb50180Rule::from_options(
                    text_of(&all, "day")?.as_deref(),
                    number(&all, "requiredHours")?,
                    number(&all, "minPeriod")?,
                    max_periods,
                    whole.and_then(WholeWindow::width),
                )
            })
            .transpose()?;
        let en17037 = en17037
            .then(|| {
                let day = text_of(&all, "period")?.map(|text| parse_date("period", &text)).transpose()?;
                En17037Rule::new(day, number(&all, "minAltitude")?)
            })
            .transpose()?;
        let floor_level = floor_level(&all, &place)?;
        let masks = masks(all.get("masks"))?;
        let names = (names_of(&all, "modelNames")?, names_of(&all, "beforeNames")?);
        let sill_of_each = whole == Some(WholeWindow::Sill);
        Ok(Self { studies, place, location, weather, epw_name, gb, sill_of_each, window_widths, en17037, floor_level, masks, names })
    }

    /// `rule` with each window's own 满窗 sill at `points` of `scene`, where asked: `windowWidths`'
    /// widths, or `windowWidth: 'sill'`'s sill lines (the points must be the windows' sills);
    /// checked.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))] // read by the page's study (web only)
    pub fn whole_window_of_each(&self, rule: &mut Gb50180Rule, scene: &Scene, points: &Points) -> Result<()> {
        rule.window_widths = match &self.window_widths {
            Some(GivenWidths::Csv(text)) => Some(sill_widths(scene, points, "windowWidths", text)?),
            Some(GivenWidths::Named(widths)) => Some(named_widths(scene, points, widths)?),
            None => None,
        };
        if self.sill_of_each {
            let at = match &self.place {
                StudyPlace::Windows(_, at) => Some(*at),
                StudyPlace::Given(_) => None,
            };
            rule.sill_lines = Some(sill_lines(scene, points, at, self.floor_level)?);
        }
        rule.check()
    }
}

/// `windowWidth`: a width in metres for every window, or `'sill'` (each window's own, measured).
fn whole_window(all: &Map<String, Value>) -> Result<Option<WholeWindow>> {
    match all.get("windowWidth") {
        None => Ok(None),
        Some(Value::String(text)) => WholeWindow::parse(text).map(Some),
        Some(Value::Number(n)) => {
            let width = n.as_f64().ok_or_else(|| Error::argument("window_width", format!("{n} is not a number")))?;
            Ok(Some(WholeWindow::Width(width)))
        }
        Some(other) => Err(Error::argument("window_width", format!("{other} is neither a width in metres nor 'sill'"))),
    }
}

/// `windowWidths`: a `receiver,width` CSV's text, or an object of widths by window name.
fn given_widths(all: &Map<String, Value>) -> Result<Option<GivenWidths>> {
    match all.get("windowWidths") {
        None => Ok(None),
        Some(Value::String(text)) => Ok(Some(GivenWidths::Csv(text.clone()))),
        Some(Value::Object(named)) => named
            .iter()
            .map(|(name, w)| {
                w.as_f64()
                    .map(|w| (name.clone(), w))
                    .ok_or_else(|| Error::argument("window_widths", format!("'{name}': {w} is not a width in metres")))
            })
            .collect::<Result<_>>()
            .map(|widths| Some(GivenWidths::Named(widths))),
        Some(other) => {
            Err(Error::argument("window_widths", format!("{other} is neither a receiver,width CSV nor an object of widths by window")))
        }
    }
}

/// `floorLevel`, taken only with the windows' sills (`--floor-level` beside `--window-points
/// sill`), naming `floor_level` otherwise.
fn floor_level(all: &Map<String, Value>, place: &StudyPlace) -> Result<Option<f64>> {
    let Some(level) = number(all, "floorLevel")? else { return Ok(None) };
    if !level.is_finite() || !matches!(place, StudyPlace::Windows(_, WindowPoint::Sill)) {
        return Err(Error::argument("floor_level", "raises the windows' sills: give it with windowPoints: 'sill' and a finite level"));
    }
    Ok(Some(level))
}

/// `masks`: `'all'` or an array of 0-based point rows; none by default.
fn masks(value: Option<&Value>) -> Result<Masks> {
    match value {
        None => Ok(Masks::Rows(Vec::new())),
        Some(Value::String(all)) if all == "all" => Ok(Masks::All),
        Some(rows) => serde_json::from_value(rows.clone())
            .map(Masks::Rows)
            .map_err(|_| Error::argument("masks", "give 'all' or an array of point rows (whole numbers from 0)")),
    }
}

/// A list of file names, if given.
fn names_of(all: &Map<String, Value>, key: &str) -> Result<Vec<String>> {
    all.get(key)
        .map_or(Ok(Vec::new()), |v| serde_json::from_value(v.clone()).map_err(|_| Error::argument(key, "must be an array of file names")))
}

/// `study`: one name or an array of names, each a window study.
fn studies(value: Option<&Value>) -> Result<Vec<String>> {
    let names: Vec<String> = match value {
        None => return Err(Error::argument("study", format!("give one of {}", run::WINDOW_STUDIES.join(", ")))),
        Some(Value::String(name)) => vec![name.clone()],
        Some(Value::Array(names)) => names
            .iter()
            .map(|n| n.as_str().map(String::from).ok_or_else(|| Error::argument("study", format!("{n} is not a study's name"))))
            .collect::<Result<_>>()?,
        Some(other) => return Err(Error::argument("study", format!("{other} is not a study's name or an array of them"))),
    };
    if names.is_empty() {
        return Err(Error::argument("study", format!("no study asked: give one of {}", run::WINDOW_STUDIES.join(", "))));
    }
    if let Some(other) = names.iter().find(|s| !run::WINDOW_STUDIES.contains(&s.as_str())) {
        return Err(Error::argument("study", format!("'{other}' is not a window study ({})", run::WINDOW_STUDIES.join(", "))));
    }
    Ok(names)
}

/// `windows` (with `windowPoints`) or `points`: one of them, not empty.
fn place(all: &Map<String, Value>) -> Result<StudyPlace> {
    let at = text_of(all, "windowPoints")?;
    match (all.get("windows"), all.get("points")) {
        (Some(_), Some(_)) => Err(Error::argument("points", "give windows or points, not both")),
        (None, Some(points)) => {
            if at.is_some() {
                return Err(Error::argument("window_points", "puts a point on each of `windows`: give windows, not points"));
            }
            let numbers: Vec<f64> =
                serde_json::from_value(points.clone()).map_err(|_| Error::argument("points", "must be an array of numbers"))?;
            if numbers.is_empty() {
                return Err(Error::argument("points", "no point given: give 6 numbers a point (x, y, z, nx, ny, nz)"));
            }
            Ok(StudyPlace::Given(numbers))
        }
        (windows, None) => {
            let ids: Vec<u32> = match windows {
                Some(w) => serde_json::from_value(w.clone())
                    .map_err(|_| Error::argument("windows", "must be an array of receiver indices (whole numbers from 0)"))?,
                None => Vec::new(),
            };
            if ids.is_empty() {
                return Err(Error::argument("windows", "no window selected: select at least one window (a receiver) or give points"));
            }
            Ok(StudyPlace::Windows(ids, WindowPoint::parse(at.as_deref().unwrap_or("centre"))?))
        }
    }
}

/// A number option, if given.
fn number(all: &Map<String, Value>, key: &str) -> Result<Option<f64>> {
    all.get(key).map(|v| v.as_f64().ok_or_else(|| Error::argument(key, format!("{v} is not a number")))).transpose()
}

/// A text option, if given.
fn text_of(all: &Map<String, Value>, key: &str) -> Result<Option<String>> {
    all.get(key).map(|v| v.as_str().map(String::from).ok_or_else(|| Error::argument(key, format!("{v} is not text")))).transpose()
}
