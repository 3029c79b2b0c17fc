//! The EnergyPlus weather (EPW) file: the one reader of it in the crate.
//!
//! Owns everything taken from an EPW and the rules for it:
//! - the site, from the `LOCATION` record on the first line ([`location_from_epw`],
//!   [`location_from_text`]);
//! - a year of hourly solar data ([`Weather`]): direct normal (field 15), diffuse horizontal
//!   (field 16) and global horizontal (field 14) irradiance, W/m² (the EPW's Wh/m² over the hour
//!   ending at the record's stamp), and the albedo (field 33);
//! - the missing-value rules: a radiation field that is missing (9999), negative, not a number or
//!   beyond [`MAX_IRRADIANCE`] is an error naming the file, line and field; an albedo that is
//!   missing (999, or a record too short to hold it) is [`DEFAULT_ALBEDO`]; any other albedo
//!   outside 0..=1 is an error;
//! - which record holds at a schedule's row ([`Weather::at`]): its hour's, held over the hour's
//!   timesteps. A leap-year file's 29 February is kept for a leap-year schedule and skipped for a
//!   365-day one; a 365-day file under a leap-year schedule repeats 28 February's hours;
//! - the direct normal irradiance EnergyPlus's heat balance sees at a row
//!   ([`Weather::dni_as_energyplus`]): interpolated between hours, for what sunlit hands
//!   EnergyPlus in W/m².

use std::io::{BufRead, BufReader};
use std::path::Path;

use crate::error::{Error, Result};
use crate::sun::location::Location;
use crate::year::samples::{DAYS, Timesteps};

/// Lines before the first data record of an EPW (LOCATION … DATA PERIODS).
const EPW_HEADER_LINES: usize = 8;
/// Hours of a 365-day year.
const YEAR_HOURS: usize = (DAYS * 24) as usize;
/// Day of the year of 29 February in a leap year.
const LEAP_DAY: usize = 60;
/// The solar constant, W/m².
const SOLAR_CONSTANT: f64 = 1367.0;
/// No irradiance at the ground exceeds the solar constant by more than 10% (enhancement by
/// cloud edges stays below it); larger values are corrupt data, refused.
pub const MAX_IRRADIANCE: f64 = SOLAR_CONSTANT * 1.1;
/// The EPW dictionary's "missing" value for radiation fields.
const MISSING_RADIATION: f64 = 9999.0;
/// The EPW dictionary's "missing" value for the albedo.
const MISSING_ALBEDO: f64 = 999.0;
/// The albedo used where the EPW has none: EnergyPlus's default ground reflectance
/// (`Site:GroundReflectance`).
pub const DEFAULT_ALBEDO: f64 = 0.2;

/// The data record's fields this module reads (0-based), with the dictionary's 1-based number
/// and name for errors.
const GHI: Field = Field { index: 13, name: "global horizontal irradiance" };
const DNI: Field = Field { index: 14, name: "direct normal irradiance" };
const DHI: Field = Field { index: 15, name: "diffuse horizontal irradiance" };
/// Direct normal illuminance, lux (0-based index of field 18).
const DIRECT_ILLUMINANCE: usize = 17;
/// The EPW's "missing" for illuminance fields.
const MISSING_ILLUMINANCE: f64 = 999_999.0;
const ALBEDO: Field = Field { index: 32, name: "albedo" };

/// The EPW `LOCATION` record's fields (0-based) read here, with the names errors use.
const EPW_LATITUDE: (usize, &str) = (6, "latitude");
const EPW_LONGITUDE: (usize, &str) = (7, "longitude");
const EPW_TIME_ZONE: (usize, &str) = (8, "time zone");
const EPW_ELEVATION: (usize, &str) = (9, "elevation");
/// Fields a `LOCATION` record needs: the keyword and nine values.
const EPW_LOCATION_FIELDS: usize = 10;
/// Accepted elevations in metres, as the EPW data dictionary allows.
const ELEVATION_RANGE: std::ops::RangeInclusive<f64> = -1000.0..=9999.9;

#[derive(Clone, Copy)]
struct Field {
    index: usize,
    name: &'static str,
}

impl Field {
    /// "direct normal irradiance (field 15)".
    fn label(self) -> String {
        format!("{} (field {})", self.name, self.index + 1)
    }
}

/// One hour's solar data, W/m² (and the albedo, 0..=1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hour {
    /// Direct normal irradiance.
    pub dni: f64,
    /// Diffuse horizontal irradiance.
    pub dhi: f64,
    /// Global horizontal irradiance.
    pub ghi: f64,
    /// Ground reflectance ([`DEFAULT_ALBEDO`] where the EPW has none).
    pub albedo: f64,
}

/// A year of hourly solar data and the site it was measured at.
#[derive(Debug, Clone, PartialEq)]
pub struct Weather {
    /// The site from the `LOCATION` record.
    pub location: Location,
    /// 8760 hours of a 365-day year, 1 January 00:00–01:00 first.
    hours: Vec<Hour>,
    /// 29 February's 24 hours, when the file has them.
    leap_day: Option<Vec<Hour>>,
    /// Direct normal illuminance (lux, EPW field 18) per hour of the 365-day year; `None` for an
    /// hour whose field is missing (999999), absent or unreadable, and for a weather made by
    /// [`Weather::constant`]. Kept apart from [`Hour`]: only the sun-inside studies read it.
    direct_lux: Vec<Option<f64>>,
}

impl Weather {
    /// Reads an EPW file.
    pub fn from_epw(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
        // Latin-1 city names must not make the ASCII numbers unreadable.
        Self::from_epw_text(&path.display().to_string(), &String::from_utf8_lossy(&bytes))
    }

    /// Reads EPW text; `file_label` names the source in errors.
    pub fn from_epw_text(file_label: &str, text: &str) -> Result<Self> {
        let location = location_from_text(file_label, text)?;
        let (mut hours, mut leap_day) = (Vec::with_capacity(YEAR_HOURS), Vec::new());
        let mut direct_lux = Vec::with_capacity(YEAR_HOURS);
        for (index, line) in text.lines().enumerate().skip(EPW_HEADER_LINES) {
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            let fail = |reason: String| Error::object(file_label, format!("line {}", index + 1), reason);
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() <= DHI.index {
                return Err(fail(format!("{} fields, expected at least {}", fields.len(), DHI.index + 1)));
            }
            let hour = read_hour(&fields).map_err(fail)?;
            if fields[1] == "2" && fields[2] == "29" {
                leap_day.push(hour);
            } else {
                hours.push(hour);
                direct_lux.push(illuminance(&fields));
            }
        }
        if hours.len() != YEAR_HOURS || !(leap_day.is_empty() || leap_day.len() == 24) {
            return Err(Error::model(
                file_label,
                format!(
                    "{} hourly data records after the {EPW_HEADER_LINES} header lines; an EPW year has {YEAR_HOURS} (8784 with 29 February)",
                    hours.len() + leap_day.len()
                ),
            ));
        }
        Ok(Self { location, hours, leap_day: (!leap_day.is_empty()).then_some(leap_day), direct_lux })
    }

    /// The same hour all year, at `location`: for tests and what-if cases.
    pub fn constant(location: Location, hour: Hour) -> Self {
        Self { location, hours: vec![hour; YEAR_HOURS], leap_day: None, direct_lux: Vec::new() }
    }

    /// Every hour's albedo replaced by `albedo` (a given ground reflectance); refused outside 0..=1.
    pub fn with_albedo(mut self, albedo: f64) -> Result<Self> {
        check_albedo(albedo)?;
        self.hours.iter_mut().chain(self.leap_day.iter_mut().flatten()).for_each(|h| h.albedo = albedo);
        Ok(self)
    }

    /// Direct normal illuminance (lux) of hour `hour` (0..8760) of the 365-day year, where the
    /// EPW gives it (field 18; missing is 999999).
    pub fn direct_normal_illuminance(&self, hour: usize) -> Option<f64> {
        self.direct_lux.get(hour).copied().flatten()
    }

    /// The same weather with every hour's direct normal illuminance set (lux, 8760 of them, or
    /// `None` per hour): what-if cases and tests.
    pub fn with_direct_illuminance(mut self, lux: Vec<Option<f64>>) -> Self {
        self.direct_lux = lux;
        self
    }

    /// The hour that holds at `row` of a schedule with `timesteps` (see the module doc).
    pub fn at(&self, timesteps: Timesteps, row: usize) -> Hour {
        let hour = row / timesteps.per_hour() as usize;
        let index = if timesteps.is_leap() {
            let day = hour / 24 + 1;
            match day.cmp(&LEAP_DAY) {
                std::cmp::Ordering::Less => hour,
                std::cmp::Ordering::Equal => {
                    if let Some(leap) = &self.leap_day {
                        return leap[hour % 24];
                    }
                    hour - 24
                }
                std::cmp::Ordering::Greater => hour - 24,
            }
        } else {
            hour
        };
        self.hours.get(index).copied().unwrap_or(Hour { dni: 0.0, dhi: 0.0, ghi: 0.0, albedo: DEFAULT_ALBEDO })
    }

    /// Direct normal irradiance (W/m²) at the end of `row`'s timestep as EnergyPlus 25.2 gives it
    /// to its heat balance (WeatherManager's `SolarInterpolation` weights). An EPW record is the
    /// mean over its hour, so EnergyPlus pins it to the hour's middle and interpolates linearly
    /// between middles: a timestep ending at fraction `e` of its hour takes `1 − |e − ½|` of its
    /// own hour and the rest from the hour before (`e < ½`) or after. At one timestep an hour
    /// EnergyPlus holds the hour's own value: its interior beam at Timestep 1 agrees with the
    /// hour held within 0.3 % a face and not with a half-and-half blend (38 % off on a wall;
    /// `interior_beam_with_the_models_own_periodic_update_matches_energyplus` in
    /// tests/energyplus_models.rs). The year's first and last hours stand in for
    /// their missing neighbours. (EnergyPlus also sets it to 0 while its sun is down; callers
    /// ask only with the sun up.)
    pub fn dni_as_energyplus(&self, timesteps: Timesteps, row: usize) -> f64 {
        let n = timesteps.per_hour() as usize;
        if n == 1 {
            return self.at(timesteps, row).dni;
        }
        let end = (row % n + 1) as f64 / n as f64;
        let own = 1.0 - (end - 0.5).abs();
        let neighbour = if end < 0.5 { row.checked_sub(n) } else { Some(row + n).filter(|&r| r < timesteps.rows()) };
        let here = self.at(timesteps, row).dni;
        own * here + (1.0 - own) * neighbour.map_or(here, |r| self.at(timesteps, r).dni)
    }
}

/// Refuses an albedo (ground reflectance) outside 0..=1, naming the `albedo` parameter.
pub fn check_albedo(albedo: f64) -> Result<()> {
    if !(0.0..=1.0).contains(&albedo) {
        return Err(Error::argument("albedo", format!("{albedo} is outside 0..=1")));
    }
    Ok(())
}

/// One data record's solar fields, or why not.
fn read_hour(fields: &[&str]) -> std::result::Result<Hour, String> {
    Ok(Hour { dni: irradiance(fields, DNI)?, dhi: irradiance(fields, DHI)?, ghi: irradiance(fields, GHI)?, albedo: albedo(fields)? })
}

/// Direct normal illuminance (EPW field 18, lux): `None` when absent, unreadable, negative or
/// missing (999999). Never an error: only the sun-inside studies read it, and they fall back to a
/// stated luminous efficacy.
fn illuminance(fields: &[&str]) -> Option<f64> {
    let value: f64 = fields.get(DIRECT_ILLUMINANCE)?.parse().ok()?;
    (value.is_finite() && (0.0..MISSING_ILLUMINANCE).contains(&value)).then_some(value)
}

/// A radiation field as W/m², or why not.
fn irradiance(fields: &[&str], field: Field) -> std::result::Result<f64, String> {
    let text = fields.get(field.index).copied().unwrap_or("");
    let value: f64 = text.parse().map_err(|_| format!("{} '{text}' is not a number", field.label()))?;
    if value == MISSING_RADIATION {
        return Err(format!("{} is missing (9999)", field.label()));
    }
    if !value.is_finite() || value < 0.0 {
        return Err(format!("{} {value} is negative", field.label()));
    }
    if value > MAX_IRRADIANCE {
        return Err(format!(
            "{} {value} W/m² is beyond the physical bound of {MAX_IRRADIANCE:.1} W/m² (1.1 × the solar constant)",
            field.label()
        ));
    }
    Ok(value)
}

/// The albedo field: [`DEFAULT_ALBEDO`] when absent, empty or 999; else within 0..=1.
fn albedo(fields: &[&str]) -> std::result::Result<f64, String> {
    let text = fields.get(ALBEDO.index).copied().unwrap_or("");
    if text.is_empty() {
        return Ok(DEFAULT_ALBEDO);
    }
    let value: f64 = text.parse().map_err(|_| format!("{} '{text}' is not a number", ALBEDO.label()))?;
    if value == MISSING_ALBEDO {
        return Ok(DEFAULT_ALBEDO);
    }
    if !(0.0..=1.0).contains(&value) {
        return Err(format!("{} {value} is outside 0..=1 (999 marks it missing)", ALBEDO.label()));
    }
    Ok(value)
}

/// Reads the `LOCATION` record on the first line of an EPW file (only that line is read).
pub fn location_from_epw(path: &Path) -> Result<Location> {
    let io_error = |source| Error::Io { path: path.to_path_buf(), source };
    let file = std::fs::File::open(path).map_err(io_error)?;
    // A whole EPW is a year of hourly records; only the first line is needed. Bytes, not a
    // String: many EPW files spell city names in Latin-1, which must not make the numbers unreadable.
    let mut first_line = Vec::new();
    BufReader::new(file).read_until(b'\n', &mut first_line).map_err(io_error)?;
    location_from_text(&path.display().to_string(), &String::from_utf8_lossy(&first_line))
}

/// Reads the `LOCATION` record from EPW text (only its first line is looked at);
/// `file_label` names the source in errors.
pub fn location_from_text(file_label: &str, text: &str) -> Result<Location> {
    let fail = |reason: String| Error::model(file_label, reason);
    let line = text.lines().next().unwrap_or("").trim_start_matches('\u{feff}').trim();
    let fields: Vec<&str> = line.split(',').map(str::trim).collect();
    if line.is_empty() {
        return Err(fail("the first line is empty; an EPW weather file starts with its LOCATION record".into()));
    }
    if !fields.first().is_some_and(|keyword| keyword.eq_ignore_ascii_case("LOCATION")) {
        return Err(fail(format!("first line is not an EPW LOCATION record (starts with '{}')", excerpt(line))));
    }
    if fields.len() < EPW_LOCATION_FIELDS {
        return Err(fail(format!(
            "LOCATION record has {} fields, expected {EPW_LOCATION_FIELDS} (LOCATION,City,State,Country,Source,WMO,Latitude,Longitude,TimeZone,Elevation)",
            fields.len()
        )));
    }
    let number = |(index, what): (usize, &str)| location_number(&fields, index, what).map_err(fail);
    let (latitude, longitude, time_zone) = (number(EPW_LATITUDE)?, number(EPW_LONGITUDE)?, number(EPW_TIME_ZONE)?);
    let elevation = number(EPW_ELEVATION)?;
    let mut location = Location::new(latitude, longitude, time_zone).map_err(|e| match e {
        Error::Argument { reason, .. } => fail(format!("LOCATION record: {reason}")),
        other => other,
    })?;
    if !ELEVATION_RANGE.contains(&elevation) {
        return Err(fail(format!("LOCATION record: elevation {elevation} m is outside -1000..9999.9 m")));
    }
    location.elevation = elevation;
    location.name = location_name(&fields);
    Ok(location)
}

/// Field `index` of a LOCATION record as a finite number, or why not.
fn location_number(fields: &[&str], index: usize, what: &str) -> std::result::Result<f64, String> {
    let text = fields.get(index).copied().unwrap_or("");
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        _ => Err(format!("LOCATION field {index} ({what}) is not a number: '{}'", excerpt(text))),
    }
}

/// "City, State, Country" from a LOCATION record, leaving out empty and placeholder ("-") parts.
fn location_name(fields: &[&str]) -> String {
    fields.iter().skip(1).take(3).copied().filter(|part| !part.is_empty() && *part != "-").collect::<Vec<_>>().join(", ")
}

/// The start of `text`, short enough for an error message.
fn excerpt(text: &str) -> String {
    const MAX_CHARS: usize = 40;
    if text.chars().count() <= MAX_CHARS { text.to_owned() } else { format!("{}…", text.chars().take(MAX_CHARS).collect::<String>()) }
}

#[cfg(test)]
#[path = "weather_tests.rs"]
mod tests;
