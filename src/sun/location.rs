//! The site the sun is seen from: latitude, longitude, time zone and elevation.
//!
//! Owns the ranges a site must satisfy and the two ways one comes in: the CLI's
//! `LAT,LON,TZ` text (the `location` parameter) and the `LOCATION` record on the first line of an EnergyPlus
//! weather (EPW) file.

use std::io::{BufRead, BufReader};
use std::path::Path;

use crate::error::{Error, Result};

/// A site on Earth, with the time zone its clock (standard time, no daylight saving) keeps.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    /// Degrees north (negative south), in [-90, 90].
    pub latitude: f64,
    /// Degrees east (negative west), in [-180, 180].
    pub longitude: f64,
    /// Hours from UTC of local standard time (e.g. -7 for US Mountain), in [-12, 14].
    pub time_zone: f64,
    /// Metres above sea level (0 unless read from a weather file).
    pub elevation: f64,
    /// A label for reports: "City, State, Country" from a weather file, empty otherwise.
    pub name: String,
}

/// Accepted latitudes in degrees.
const LATITUDE_RANGE: std::ops::RangeInclusive<f64> = -90.0..=90.0;
/// Accepted longitudes in degrees.
const LONGITUDE_RANGE: std::ops::RangeInclusive<f64> = -180.0..=180.0;
/// Accepted time zones in hours, as EnergyPlus's Site:Location allows.
const TIME_ZONE_RANGE: std::ops::RangeInclusive<f64> = -12.0..=14.0;
/// Accepted elevations in metres, as the EPW data dictionary allows.
const ELEVATION_RANGE: std::ops::RangeInclusive<f64> = -1000.0..=9999.9;

/// The EPW `LOCATION` record's fields (0-based) this module reads, with the names errors use.
const EPW_LATITUDE: (usize, &str) = (6, "latitude");
const EPW_LONGITUDE: (usize, &str) = (7, "longitude");
const EPW_TIME_ZONE: (usize, &str) = (8, "time zone");
const EPW_ELEVATION: (usize, &str) = (9, "elevation");
/// Fields a `LOCATION` record needs: the keyword and nine values.
const EPW_LOCATION_FIELDS: usize = 10;

impl Location {
    /// A site at sea level with no name; refuses non-finite or out-of-range values.
    pub fn new(latitude: f64, longitude: f64, time_zone: f64) -> Result<Self> {
        check_coordinates(latitude, longitude, time_zone).map_err(|reason| Error::argument("location", reason))?;
        Ok(Self { latitude, longitude, time_zone, elevation: 0.0, name: String::new() })
    }

    /// Parses the CLI's `LAT,LON,TZ` (degrees north, degrees east, hours from UTC).
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            Error::argument(
                "location",
                format!("expected LAT,LON,TZ (degrees north, degrees east, hours from UTC, e.g. 39.74,-105.18,-7), got '{text}'"),
            )
        };
        let parts: Vec<&str> = text.split(',').collect();
        let [lat, lon, tz] = parts.as_slice() else { return Err(bad()) };
        let number = |part: &str| part.trim().parse::<f64>().map_err(|_| bad());
        let (latitude, longitude, time_zone) = (number(lat)?, number(lon)?, number(tz)?);
        check_coordinates(latitude, longitude, time_zone).map_err(|reason| Error::argument("location", reason))?;
        Ok(Self { latitude, longitude, time_zone, elevation: 0.0, name: String::new() })
    }

    /// Reads the `LOCATION` record on the first line of an EPW weather file.
    pub fn from_epw(path: &Path) -> Result<Self> {
        let io_error = |source| Error::Io { path: path.to_path_buf(), source };
        let file = std::fs::File::open(path).map_err(io_error)?;
        // Only the first line is needed, and a whole EPW is a year of hourly records.
        // Read bytes, not a String: many EPW files spell city names in Latin-1, which
        // must not make the (ASCII) numbers unreadable.
        let mut first_line = Vec::new();
        BufReader::new(file).read_until(b'\n', &mut first_line).map_err(io_error)?;
        Self::from_epw_text(&path.display().to_string(), &String::from_utf8_lossy(&first_line))
    }

    /// Reads the `LOCATION` record from EPW text (only its first line is looked at);
    /// `file_label` names the source in errors.
    pub fn from_epw_text(file_label: &str, text: &str) -> Result<Self> {
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
        let number = |(index, what): (usize, &str)| epw_number(&fields, index, what).map_err(fail);
        let (latitude, longitude, time_zone) = (number(EPW_LATITUDE)?, number(EPW_LONGITUDE)?, number(EPW_TIME_ZONE)?);
        let elevation = number(EPW_ELEVATION)?;
        check_coordinates(latitude, longitude, time_zone).map_err(|reason| fail(format!("LOCATION record: {reason}")))?;
        if !ELEVATION_RANGE.contains(&elevation) {
            return Err(fail(format!("LOCATION record: elevation {elevation} m is outside -1000..9999.9 m")));
        }
        Ok(Self { latitude, longitude, time_zone, elevation, name: epw_name(&fields) })
    }

    /// The meridian (degrees east) whose mean solar time the site's standard clock keeps:
    /// 15° per hour of time zone (EnergyPlus's `TimeZoneMeridian`).
    pub fn time_zone_meridian(&self) -> f64 {
        15.0 * self.time_zone
    }
}

/// Why a latitude, longitude and time zone are unacceptable, if they are.
fn check_coordinates(latitude: f64, longitude: f64, time_zone: f64) -> std::result::Result<(), String> {
    if !latitude.is_finite() || !longitude.is_finite() || !time_zone.is_finite() {
        return Err(format!("latitude, longitude and time zone must be finite numbers, got {latitude},{longitude},{time_zone}"));
    }
    if !LATITUDE_RANGE.contains(&latitude) {
        return Err(format!("latitude {latitude} is outside -90..90 degrees"));
    }
    if !LONGITUDE_RANGE.contains(&longitude) {
        return Err(format!("longitude {longitude} is outside -180..180 degrees"));
    }
    if !TIME_ZONE_RANGE.contains(&time_zone) {
        return Err(format!("time zone {time_zone} is outside -12..14 hours"));
    }
    Ok(())
}

/// Field `index` of a LOCATION record as a finite number, or why not.
fn epw_number(fields: &[&str], index: usize, what: &str) -> std::result::Result<f64, String> {
    let text = fields.get(index).copied().unwrap_or("");
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        _ => Err(format!("LOCATION field {index} ({what}) is not a number: '{}'", excerpt(text))),
    }
}

/// "City, State, Country" from a LOCATION record, leaving out empty and placeholder ("-") parts.
fn epw_name(fields: &[&str]) -> String {
    fields.iter().skip(1).take(3).copied().filter(|part| !part.is_empty() && *part != "-").collect::<Vec<_>>().join(", ")
}

/// The start of `text`, short enough for an error message.
fn excerpt(text: &str) -> String {
    const MAX_CHARS: usize = 40;
    if text.chars().count() <= MAX_CHARS { text.to_owned() } else { format!("{}…", text.chars().take(MAX_CHARS).collect::<String>()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DENVER: &str = "LOCATION,Denver Centennial,CO,USA,TMY3,724666,39.74,-105.18,-7.0,1793.0\r\nDESIGN CONDITIONS,0\r\n";

    #[test]
    fn new_checks_ranges() {
        let site = Location::new(39.74, -105.18, -7.0).unwrap();
        assert_eq!((site.latitude, site.longitude, site.time_zone, site.elevation), (39.74, -105.18, -7.0, 0.0));
        assert_eq!(site.time_zone_meridian(), -105.0);
        for (lat, lon, tz, needle) in [
            (91.0, 0.0, 0.0, "latitude 91"),
            (-90.5, 0.0, 0.0, "latitude -90.5"),
            (0.0, 180.5, 0.0, "longitude 180.5"),
            (0.0, 0.0, -12.5, "time zone -12.5"),
            (0.0, 0.0, 14.5, "time zone 14.5"),
            (f64::NAN, 0.0, 0.0, "finite"),
            (0.0, f64::INFINITY, 0.0, "finite"),
        ] {
            let e = Location::new(lat, lon, tz).unwrap_err().to_string();
            assert!(e.contains("location") && e.contains(needle), "{lat},{lon},{tz}: {e}");
        }
        assert!(Location::new(-90.0, 180.0, 14.0).is_ok() && Location::new(90.0, -180.0, -12.0).is_ok());
    }

    #[test]
    fn parse_reads_cli_triples() {
        let site = Location::parse(" -33.87 , 151.21,10 ").unwrap();
        assert_eq!((site.latitude, site.longitude, site.time_zone), (-33.87, 151.21, 10.0));
        for bad in ["", "40", "40,-105", "40,-105,-7,0", "a,-105,-7", "40,,-7", "95,-105,-7", "40,-105,15", "nan,0,0"] {
            let e = Location::parse(bad).unwrap_err().to_string();
            assert!(e.contains("invalid location"), "{bad}: {e}");
        }
        assert!(Location::parse("40,-105,15").unwrap_err().to_string().contains("time zone 15"));
    }

    #[test]
    fn epw_location_record_is_read() {
        let site = Location::from_epw_text("denver.epw", DENVER).unwrap();
        assert_eq!((site.latitude, site.longitude, site.time_zone, site.elevation), (39.74, -105.18, -7.0, 1793.0));
        assert_eq!(site.name, "Denver Centennial, CO, USA");
        // A byte-order mark and a placeholder state are tolerated.
        let site = Location::from_epw_text("x.epw", "\u{feff}LOCATION,Sydney,-,AUS,IWEC,947670,-33.95,151.18,10.0,3.0").unwrap();
        assert_eq!((site.latitude, site.name.as_str()), (-33.95, "Sydney, AUS"));
    }

    #[test]
    fn epw_errors_name_file_and_reason() {
        let cases = [
            ("", "the first line is empty; an EPW weather file starts with its LOCATION record"),
            ("DESIGN CONDITIONS,0\nLOCATION,A,B,C,D,1,40,-105,-7,1600", "starts with 'DESIGN CONDITIONS,0'"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18", "has 8 fields, expected 10"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,north,-105.18,-7.0,1793.0", "field 6 (latitude) is not a number: 'north'"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,,-7.0,1793.0", "field 7 (longitude) is not a number: ''"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,MST,1793.0", "field 8 (time zone) is not a number: 'MST'"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-7.0,inf", "field 9 (elevation) is not a number: 'inf'"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,139.74,-105.18,-7.0,1793.0", "latitude 139.74 is outside"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-205.18,-7.0,1793.0", "longitude -205.18 is outside"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-17.0,1793.0", "time zone -17 is outside"),
            ("LOCATION,Denver,CO,USA,TMY3,724666,39.74,-105.18,-7.0,12000", "elevation 12000 m is outside"),
        ];
        for (text, needle) in cases {
            let e = Location::from_epw_text("weather/denver.epw", text).unwrap_err().to_string();
            assert!(e.starts_with("weather/denver.epw: ") && e.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn epw_file_is_read_from_disk() {
        let dir = std::env::temp_dir().join(format!("sunlit-location-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("latin1.epw");
        // "Zürich" in Latin-1: not UTF-8, yet the numbers must still be read.
        let mut bytes = b"LOCATION,Z\xfcrich,-,CHE,IWEC,066600,47.38,8.57,1.0,556.0\r\n".to_vec();
        bytes.extend_from_slice(b"DESIGN CONDITIONS,0\r\n");
        std::fs::write(&path, bytes).unwrap();
        let site = Location::from_epw(&path).unwrap();
        assert_eq!((site.latitude, site.longitude, site.time_zone, site.elevation), (47.38, 8.57, 1.0, 556.0));
        let missing = dir.join("missing.epw");
        let e = Location::from_epw(&missing).unwrap_err();
        assert!(matches!(e, Error::Io { .. }) && e.to_string().contains("missing.epw"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
