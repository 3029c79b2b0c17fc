//! The site the sun is seen from: latitude, longitude, time zone and elevation.
//!
//! Owns the ranges a site must satisfy and the CLI's `LAT,LON,TZ` text (the `location`
//! parameter). The other way a site comes in, an EnergyPlus weather (EPW) file's `LOCATION`
//! record, is read by [`crate::sun::weather`].

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
