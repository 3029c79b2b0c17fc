//! `engine.map`'s options object (`MapOptions` in `www/sunlit.d.ts`) read into the library's
//! terms: the site and leaf calendar as an annual run resolves them ([`AnnualSettings`]), where
//! (a grid or given points), when ([`Period`], with `sunlit map`'s defaults) and what
//! ([`MapValue`]), and whether inside rooms ([`InsideAsk`], `sunlit map --inside` at an instant,
//! over a period or for a study). Plain JSON in, so it is tested natively too (`js_api`).

use serde_json::Value;

use crate::error::{Error, Result};
use crate::map::Period;
use crate::map::inside::{ASE_SPACING, NSL_WORK_PLANE, WORK_PLANE_HEIGHT};
use crate::map::period::{parse_clock, parse_date};
use crate::model::inside::curve::TransmittanceCurve;
use crate::sun::weather::Weather;
use crate::year::settings::{AnnualSettings, Resolved};

/// The grid spacing (m) when neither `grid` nor `points` is given.
pub const DEFAULT_GRID: f64 = 0.5;

/// Minutes between the instants of days (the year, a range) when `step` is not given: hourly.
pub const DEFAULT_STEP: u32 = 60;

/// Minutes between one day's instants when `step` is not given (as `sunlit map`).
pub const DEFAULT_DAY_STEP: u32 = 10;

/// The keys of the options object that say where, when and what.
pub const MAP_KEYS: [&str; 8] = ["grid", "points", "period", "step", "from", "to", "at", "value"];

/// The keys that map the inside of an EnergyPlus model's zones instead of its outside.
pub const INSIDE_KEYS: [&str; 8] = ["inside", "workPlane", "glassTransmittance", "glassCurve", "study", "interior", "glazing", "faces"];

/// The annual settings' keys a map also takes: the site, the foliage's calendar and the sky model
/// ([`AnnualSettings`], resolved as an annual run resolves them).
pub const SITE_KEYS: [&str; 9] = ["latitude", "longitude", "timeZone", "epw", "epwName", "evergreen", "leafOut", "leafFall", "skyModel"];

/// What a map holds per point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapValue {
    /// Hours of sun seen over the period.
    SunHours,
    /// Direct irradiation over the period, kWh/m² (needs an EPW).
    Direct,
    /// Sky-diffuse irradiation over the period, kWh/m² (needs an EPW; each point's sky views).
    SkyDiffuse,
    /// Direct + sky diffuse + ground-reflected irradiation over the period, kWh/m² (needs an EPW).
    Total,
    /// Sun seen (1) or not (0) at one instant.
    Lit,
    /// Inside, LEED ASE: occupied hours over 1,000 lux of direct sun (`study: 'leed-ase'`).
    AseHours,
    /// Inside, BRE 209's No-Sky Line: sees sky (1) or not (0) (`study: 'bre-nsl'`).
    SeesSky,
}

impl MapValue {
    /// The JS API's names, as `value` takes them.
    pub const NAMES: [&str; 5] = ["sunHours", "direct", "skyDiffuse", "total", "lit"];

    /// The names of the values an inside study gives (not asked by `value`: the study decides).
    pub const STUDY_NAMES: [&str; 2] = ["aseHours", "seesSky"];

    fn parse(text: &str) -> Result<Self> {
        match text {
            "sunHours" => Ok(Self::SunHours),
            "direct" => Ok(Self::Direct),
            "skyDiffuse" => Ok(Self::SkyDiffuse),
            "total" => Ok(Self::Total),
            "lit" => Ok(Self::Lit),
            other => Err(Error::argument("value", format!("'{other}' is not one of {}", Self::NAMES.join(", ")))),
        }
    }

    /// The JS API's name.
    pub fn name(self) -> &'static str {
        match self {
            Self::AseHours => Self::STUDY_NAMES[0],
            Self::SeesSky => Self::STUDY_NAMES[1],
            other => Self::NAMES[other as usize],
        }
    }

    /// Whether the value is an irradiation: it needs the EPW, and the map then sums every part
    /// (direct, sky diffuse with each point's sky views, ground-reflected, total), as
    /// `sunlit map --epw` does, so that its CSV is the CLI's.
    pub fn needs_weather(self) -> bool {
        matches!(self, Self::Direct | Self::SkyDiffuse | Self::Total)
    }

    /// The legend's title and the unit.
    pub fn title(self) -> (&'static str, &'static str) {
        match self {
            Self::SunHours => ("Sun hours", "h"),
            Self::Direct => ("Direct irradiation", "kWh/m²"),
            Self::SkyDiffuse => ("Sky-diffuse irradiation", "kWh/m²"),
            Self::Total => ("Total irradiation", "kWh/m²"),
            Self::Lit => ("Sunlit at the instant", ""),
            Self::AseHours => ("Occupied hours over 1000 lux of direct sun", "h"),
            Self::SeesSky => ("Sees sky (No-Sky Line)", ""),
        }
    }
}

/// Where the points come from (the key of the model's cached points).
#[derive(Debug, Clone, PartialEq)]
pub enum Where {
    /// A grid at this spacing (m) on every receiver.
    Grid(f64),
    /// Given points, 6 numbers each (x y z nx ny nz).
    Given(Vec<f64>),
}

/// A map request read from the JS options.
pub struct MapRequest {
    /// The site and the leaf calendar.
    pub site: Resolved,
    /// The EPW's solar data, for the irradiation values.
    pub weather: Option<Weather>,
    /// Where the points are.
    pub place: Where,
    /// When.
    pub period: Period,
    /// What.
    pub value: MapValue,
    /// Inside the zones (`inside: true`), at an instant only.
    pub inside: Option<InsideAsk>,
}

/// The inside map asked (`sunlit map --inside`): points on the zones' floors (a grid at
/// `work_plane` m above them) or given ones, the beam through the windows; at an instant, over a
/// period, or a study. The rooms are an EnergyPlus model's zones, or the mesh nodes `interior`
/// picks with the panes `glazing` picks (`--interior`, `--glazing`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InsideAsk {
    /// Height of the grid above the floors (m) (`--work-plane`): by default 0, on the floors'
    /// inside faces; a study's own work plane for a study.
    pub work_plane: f64,
    /// Transmittance of glazing whose construction gives none (`--glass-transmittance`).
    pub glass: Option<f64>,
    /// The solar transmittance by angle of glazing whose construction gives none
    /// (`--glass-curve`, as its text: `ANGLE:T,...`); an EnergyPlus model's only.
    pub curve: Option<String>,
    /// Globs over mesh node names: each matching node is a room (`--interior`); empty: the
    /// EnergyPlus model's zones.
    pub interior: Vec<String>,
    /// Globs over mesh node names: each matching node is glass (`--glazing`).
    pub glazing: Vec<String>,
    /// A study of the inside (`--study leed-ase` or `bre-nsl`), or none.
    pub study: Option<InsideStudy>,
    /// The grid on every inside face of the rooms besides the floors (`--faces`), so that a sun
    /// patch is mapped on each face it falls on.
    pub faces: bool,
}

/// A study of the inside, as `sunlit map --inside --study` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InsideStudy {
    /// LEED v4.1's Annual Sunlight Exposure (needs an EPW; the year's occupied hours).
    LeedAse,
    /// BRE 209's No-Sky Line (geometry: no period).
    BreNsl,
}

impl InsideStudy {
    /// The names `study` takes (the CLI's).
    pub const NAMES: [&str; 2] = ["leed-ase", "bre-nsl"];

    fn parse(text: &str) -> Result<Self> {
        match text {
            "leed-ase" => Ok(Self::LeedAse),
            "bre-nsl" => Ok(Self::BreNsl),
            other => Err(Error::argument("study", format!("'{other}' is not a study of the inside (known: {})", Self::NAMES.join(", ")))),
        }
    }

    /// The name, as `study` takes it.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The grid spacing (m) and work plane height (m) when not given, as the CLI's.
    fn defaults(self) -> (f64, f64) {
        match self {
            Self::LeedAse => (ASE_SPACING, WORK_PLANE_HEIGHT),
            Self::BreNsl => (DEFAULT_GRID, NSL_WORK_PLANE),
        }
    }

    /// The value the study gives per point.
    pub fn value(self) -> MapValue {
        match self {
            Self::LeedAse => MapValue::AseHours,
            Self::BreNsl => MapValue::SeesSky,
        }
    }
}

/// Given points (6 numbers each) as the `x,y,z,nx,ny,nz` text the library reads, so a JS array
/// and a CSV file are checked alike (on a receiver, a normal of non-zero length).
pub fn points_csv(numbers: &[f64]) -> Result<String> {
    if numbers.is_empty() || !numbers.len().is_multiple_of(6) {
        return Err(Error::argument("points", format!("{} numbers: give 6 per point (x, y, z, nx, ny, nz)", numbers.len())));
    }
    let mut text = String::from("x,y,z,nx,ny,nz\n");
    for row in numbers.chunks(6) {
        let fields: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&fields.join(","));
        text.push('\n');
    }
    Ok(text)
}

impl MapRequest {
    /// The options object (as JSON), checked: the site as the annual settings read it, then
    /// where, when and what.
    pub fn from_value(options: Value) -> Result<Self> {
        let Value::Object(mut all) = options else {
            return Err(Error::argument("options", "give an object with at least a location (latitude, longitude, timeZone) or an EPW"));
        };
        let known = |k: &String| MAP_KEYS.contains(&k.as_str()) || SITE_KEYS.contains(&k.as_str()) || INSIDE_KEYS.contains(&k.as_str());
        if let Some(key) = all.keys().find(|k| !known(k)) {
            return Err(Error::argument(
                "options",
                format!("'{key}' is not a map option ({}, {}, {})", SITE_KEYS.join(", "), MAP_KEYS.join(", "), INSIDE_KEYS.join(", ")),
            ));
        }
        let inside = inside_ask(&mut all)?;
        let study = inside.as_ref().and_then(|i| i.study);
        let mut take = |key: &str| all.remove(key);
        let (grid, points, period, step, from, to, at, value) =
            (take("grid"), take("points"), take("period"), take("step"), take("from"), take("to"), take("at"), take("value"));
        let settings: AnnualSettings = serde_json::from_value(Value::Object(all)).map_err(|e| Error::argument("options", e.to_string()))?;
        let site = settings.resolve()?;
        let place = match (number("grid", grid)?, points) {
            (Some(_), Some(_)) => return Err(Error::argument("points", "give a grid spacing or points, not both")),
            (spacing, None) => Where::Grid(spacing.unwrap_or(study.map_or(DEFAULT_GRID, |s| s.defaults().0))),
            (None, Some(points)) => {
                Where::Given(serde_json::from_value(points).map_err(|_| Error::argument("points", "must be an array of numbers"))?)
            }
        };
        let (period, step, from, to, at, value) = (
            text_of("period", period)?,
            number("step", step)?,
            text_of("from", from)?,
            text_of("to", to)?,
            text_of("at", at)?,
            text_of("value", value)?,
        );
        let value = value.as_deref().map(MapValue::parse).transpose()?;
        let epw = |asked: bool| match (asked, &settings.epw) {
            (true, Some(epw)) => Weather::from_epw_text(settings.epw_name.as_deref().unwrap_or("EPW"), epw).map(Some),
            _ => Ok(None),
        };
        if let Some(study) = study {
            let given = [("at", at.is_some()), ("period", period.is_some()), ("step", step.is_some())];
            let given = given.into_iter().chain([("from", from.is_some()), ("to", to.is_some()), ("value", value.is_some())]);
            if let Some((name, _)) = given.into_iter().find(|(_, g)| *g) {
                return Err(Error::argument(name, format!("the {} study sets its own period and value: drop '{name}'", study.name())));
            }
            if study == InsideStudy::LeedAse && settings.epw.is_none() {
                return Err(Error::argument("study", "leed-ase needs an EPW (direct normal illuminance, or irradiance)"));
            }
            // The year at hourly steps, as `--study leed-ase` (the occupied hours are the study's).
            let (weather, period) = (epw(true)?, Period::annual(1)?);
            return Ok(Self { site, weather, place, period, value: study.value(), inside });
        }
        let period = match at {
            Some(at) => {
                if let Some((name, _)) =
                    [("period", period.is_some()), ("step", step.is_some()), ("from", from.is_some()), ("to", to.is_some())]
                        .iter()
                        .find(|(_, given)| *given)
                {
                    return Err(Error::argument(*name, "an instant ('at') has no period, step or window"));
                }
                instant(&at)?
            }
            None => span(period.as_deref().unwrap_or("annual"), step, from.as_deref(), to.as_deref())?,
        };
        let is_instant = matches!(period, Period::At { .. });
        let value = match (value, is_instant) {
            (None, true) | (Some(MapValue::Lit), true) => MapValue::Lit,
            (None, false) => MapValue::SunHours,
            (Some(MapValue::Lit), false) => return Err(Error::argument("value", "'lit' needs an instant: give 'at' (MM-DD HH:MM)")),
            (Some(_), true) => {
                return Err(Error::argument("value", "at an instant the value is 'lit'; sun hours and irradiation need a period"));
            }
            (Some(v), false) => v,
        };
        if value.needs_weather() && settings.epw.is_none() {
            return Err(Error::argument("value", format!("'{}' needs an EPW (its solar irradiance)", value.name())));
        }
        if inside.is_some() && matches!(value, MapValue::SkyDiffuse | MapValue::Total) {
            return Err(Error::argument("value", "inside, a period's value is 'sunHours' or 'direct' (the beam through the glass)"));
        }
        // Inside, an EPW adds the beam and the direct-sun illuminance, as `--inside --epw` does.
        let weather = epw(value.needs_weather() || (inside.is_some() && !is_instant))?;
        Ok(Self { site, weather, place, period, value, inside })
    }
}

/// The inside keys ([`INSIDE_KEYS`]): the inside asked, or none (the others need `inside`).
fn inside_ask(all: &mut serde_json::Map<String, Value>) -> Result<Option<InsideAsk>> {
    let inside = match all.remove("inside") {
        None | Some(Value::Bool(false)) => false,
        Some(Value::Bool(true)) => true,
        Some(other) => return Err(Error::argument("inside", format!("{other} is not true or false"))),
    };
    let (work_plane, glass) =
        (number("workPlane", all.remove("workPlane"))?, number("glassTransmittance", all.remove("glassTransmittance"))?);
    let curve = text_of("glassCurve", all.remove("glassCurve"))?;
    let study = text_of("study", all.remove("study"))?.as_deref().map(InsideStudy::parse).transpose()?;
    let (interior, glazing) = (globs_of("interior", all.remove("interior"))?, globs_of("glazing", all.remove("glazing"))?);
    let faces = match all.remove("faces") {
        None | Some(Value::Bool(false)) => false,
        Some(Value::Bool(true)) => true,
        Some(other) => return Err(Error::argument("faces", format!("{other} is not true or false"))),
    };
    if !inside {
        let given = [
            ("workPlane", work_plane.is_some()),
            ("glassTransmittance", glass.is_some()),
            ("glassCurve", curve.is_some()),
            ("study", study.is_some()),
            ("interior", !interior.is_empty()),
            ("glazing", !glazing.is_empty()),
            ("faces", faces),
        ];
        if let Some((name, _)) = given.iter().find(|(_, g)| *g) {
            return Err(Error::argument(*name, "maps the inside of rooms: add inside: true"));
        }
        return Ok(None);
    }
    if interior.is_empty() && !glazing.is_empty() {
        return Err(Error::argument("glazing", "picks the panes of a mesh model's rooms: give the rooms too ('interior')"));
    }
    if let Some(text) = &curve {
        if !interior.is_empty() {
            return Err(Error::argument(
                "glassCurve",
                "is for an EnergyPlus model's glazing: a glTF pane's curve is its material's extras",
            ));
        }
        TransmittanceCurve::parse(text).map_err(|why| Error::argument("glassCurve", why))?;
    }
    if faces && study.is_some() {
        return Err(Error::argument("faces", "a study's share is of the work plane alone: leave faces out"));
    }
    let work_plane = work_plane.unwrap_or(study.map_or(0.0, |s| s.defaults().1));
    Ok(Some(InsideAsk { work_plane, glass, curve, interior, glazing, study, faces }))
}

/// Globs over node names, as a comma-separated text (as `loadFiles`' `receivers`) or an array
/// of texts; empty when not given.
fn globs_of(name: &str, value: Option<Value>) -> Result<Vec<String>> {
    let texts: Vec<String> = match value {
        None => return Ok(Vec::new()),
        Some(Value::String(text)) => vec![text],
        Some(Value::Array(items)) => items
            .into_iter()
            .map(|v| v.as_str().map(String::from).ok_or_else(|| Error::argument(name, format!("{v} is not a glob (text)"))))
            .collect::<Result<_>>()?,
        Some(other) => return Err(Error::argument(name, format!("{other} is not globs: give 'Room*, Hall*' or ['Room*']"))),
    };
    Ok(texts.iter().flat_map(|t| t.split(',')).map(str::trim).filter(|g| !g.is_empty()).map(String::from).collect())
}

/// A number option, if given.
fn number(name: &str, value: Option<Value>) -> Result<Option<f64>> {
    value.map(|v| v.as_f64().ok_or_else(|| Error::argument(name, format!("{v} is not a number")))).transpose()
}

/// A text option, if given.
fn text_of(name: &str, value: Option<Value>) -> Result<Option<String>> {
    value.map(|v| v.as_str().map(String::from).ok_or_else(|| Error::argument(name, format!("{v} is not text")))).transpose()
}

/// `MM-DD HH:MM` as one instant.
fn instant(text: &str) -> Result<Period> {
    let (date, time) = text.trim().split_once(' ').ok_or_else(|| Error::argument("at", format!("'{text}' is not 'MM-DD HH:MM'")))?;
    Period::at(parse_date("at", date)?, parse_clock("at", time)?)
}

/// `annual`, `MM-DD` or `MM-DD..MM-DD` with its step (minutes; default [`DEFAULT_STEP`] over
/// days, [`DEFAULT_DAY_STEP`] on one day, as `sunlit map`) and, for one day, its window.
fn span(period: &str, step: Option<f64>, from: Option<&str>, to: Option<&str>) -> Result<Period> {
    let step = match step {
        None => None,
        Some(s) if s.fract() == 0.0 && (1.0..=60.0).contains(&s) => Some(s as u32),
        Some(s) => return Err(Error::argument("step", format!("{s} min: give a whole number of minutes, 1 to 60"))),
    };
    if period == "annual" || period.contains("..") {
        if let Some((name, _)) = [("from", from), ("to", to)].iter().find(|(_, t)| t.is_some()) {
            return Err(Error::argument(*name, "a window within the day needs a one-day period (MM-DD)"));
        }
        let step = step.unwrap_or(DEFAULT_STEP);
        if !60u32.is_multiple_of(step) {
            return Err(Error::argument(
                "step",
                format!("{step} min: over days the step must divide the hour as an EnergyPlus timestep does"),
            ));
        }
        return match period.split_once("..") {
            None => Period::annual(60 / step),
            Some((first, last)) => Period::days(parse_date("period", first)?, parse_date("period", last)?, 60 / step),
        };
    }
    let from = from.map(|t| parse_clock("from", t)).transpose()?.unwrap_or(0);
    let to = to.map(|t| parse_clock("to", t)).transpose()?.unwrap_or(24 * 60);
    Period::day(parse_date("period", period)?, from, to, step.unwrap_or(DEFAULT_DAY_STEP))
}
