//! `engine.map`'s options object (`MapOptions` in `www/sunlit.d.ts`) read into the library's
//! terms: the site and leaf calendar as an annual run resolves them ([`AnnualSettings`]), where
//! (a grid or given points), when ([`Period`], with `sunlit map`'s defaults) and what
//! ([`MapValue`]), and whether inside rooms ([`InsideAsk`], `sunlit map --inside --at`). Plain
//! JSON in, so it is tested natively too (`js_api`).

use serde_json::Value;

use crate::error::{Error, Result};
use crate::map::Period;
use crate::map::period::{parse_clock, parse_date};
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
pub const INSIDE_KEYS: [&str; 3] = ["inside", "workPlane", "glassTransmittance"];

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
}

impl MapValue {
    /// The JS API's names, as `value` takes them.
    pub const NAMES: [&str; 5] = ["sunHours", "direct", "skyDiffuse", "total", "lit"];

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
        Self::NAMES[self as usize]
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

/// The inside map asked (`sunlit map --inside --at`): points on the zones' floors (a grid at
/// `work_plane` m above them) or given ones, the beam through the windows.
#[derive(Debug, Clone, PartialEq)]
pub struct InsideAsk {
    /// Height of the grid above the floors (m): 0, on the floors' inside faces (`--work-plane`).
    pub work_plane: f64,
    /// Transmittance of glazing whose construction gives none (`--glass-transmittance`).
    pub glass: Option<f64>,
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
        let inside = inside_ask(all.remove("inside"), all.remove("workPlane"), all.remove("glassTransmittance"))?;
        let mut take = |key: &str| all.remove(key);
        let (grid, points, period, step, from, to, at, value) =
            (take("grid"), take("points"), take("period"), take("step"), take("from"), take("to"), take("at"), take("value"));
        let settings: AnnualSettings = serde_json::from_value(Value::Object(all)).map_err(|e| Error::argument("options", e.to_string()))?;
        let site = settings.resolve()?;
        let place = match (number("grid", grid)?, points) {
            (Some(_), Some(_)) => return Err(Error::argument("points", "give a grid spacing or points, not both")),
            (spacing, None) => Where::Grid(spacing.unwrap_or(DEFAULT_GRID)),
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
        let weather = match (value.needs_weather(), &settings.epw) {
            (true, Some(epw)) => Some(Weather::from_epw_text(settings.epw_name.as_deref().unwrap_or("EPW"), epw)?),
            (true, None) => return Err(Error::argument("value", format!("'{}' needs an EPW (its solar irradiance)", value.name()))),
            (false, _) => None,
        };
        if inside.is_some() && value != MapValue::Lit {
            return Err(Error::argument("inside", "the inside is mapped at an instant here: give 'at' (MM-DD HH:MM)"));
        }
        Ok(Self { site, weather, place, period, value, inside })
    }
}

/// `inside`, `workPlane` and `glassTransmittance`: the inside asked, or none (the latter two
/// need the first).
fn inside_ask(inside: Option<Value>, work_plane: Option<Value>, glass: Option<Value>) -> Result<Option<InsideAsk>> {
    let inside = match inside {
        None | Some(Value::Bool(false)) => false,
        Some(Value::Bool(true)) => true,
        Some(other) => return Err(Error::argument("inside", format!("{other} is not true or false"))),
    };
    let (work_plane, glass) = (number("workPlane", work_plane)?, number("glassTransmittance", glass)?);
    if !inside {
        if let Some(name) = [("workPlane", work_plane), ("glassTransmittance", glass)].iter().find(|(_, v)| v.is_some()).map(|(n, _)| *n) {
            return Err(Error::argument(name, "maps the inside of rooms: add inside: true"));
        }
        return Ok(None);
    }
    Ok(Some(InsideAsk { work_plane: work_plane.unwrap_or(0.0), glass }))
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
