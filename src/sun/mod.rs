//! Sun directions: azimuth/altitude in degrees to a unit vector in world axes (x east, y north, z up).
//!
//! Owns the convention every other stage uses: the vector points *towards* the sun.
//! Where the sun is at a given place and time lives in the submodules:
//! - [`location`]: the site (latitude, longitude, time zone) and its ranges;
//! - [`periods`]: the one sun EnergyPlus's Periodic shading update uses for every day of a period;
//! - [`position`]: solar declination, equation of time, sun directions and daylight hours as EnergyPlus computes them.
//! - [`weather`]: the EPW weather file: the site, hourly direct normal, diffuse and global horizontal irradiance and albedo.

pub mod location;
pub mod periods;
pub mod position;
pub mod weather;

use glam::DVec3;

use crate::error::{Error, Result};

/// A sun position as the CLI takes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunPosition {
    /// Degrees clockwise from north (0 = north, 90 = east).
    pub azimuth: f64,
    /// Degrees above the horizon.
    pub altitude: f64,
}

impl SunPosition {
    /// Checks ranges: azimuth any finite value (wrapped), altitude in [-90, 90].
    pub fn new(azimuth: f64, altitude: f64) -> Result<Self> {
        if !azimuth.is_finite() || !altitude.is_finite() {
            return Err(Error::argument("sun", format!("azimuth and altitude must be finite numbers, got {azimuth},{altitude}")));
        }
        if !(-90.0..=90.0).contains(&altitude) {
            return Err(Error::argument("sun", format!("altitude {altitude} is outside -90..90 degrees")));
        }
        Ok(Self { azimuth: azimuth.rem_euclid(360.0), altitude })
    }

    /// Parses `AZ,ALT` (degrees).
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || Error::argument("sun", format!("expected AZ,ALT in degrees (e.g. 180,45), got '{text}'"));
        let (a, b) = text.split_once(',').ok_or_else(bad)?;
        let az: f64 = a.trim().parse().map_err(|_| bad())?;
        let alt: f64 = b.trim().parse().map_err(|_| bad())?;
        Self::new(az, alt).map_err(|e| match e {
            Error::Argument { reason, .. } => Error::argument("sun", reason),
            other => other,
        })
    }

    /// Unit vector towards the sun.
    pub fn direction(&self) -> DVec3 {
        let (az, alt) = (self.azimuth.to_radians(), self.altitude.to_radians());
        DVec3::new(az.sin() * alt.cos(), az.cos() * alt.cos(), alt.sin())
    }

    /// Whether the sun is above the horizon (fractions are 0 otherwise).
    pub fn is_up(&self) -> bool {
        self.altitude > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_follow_compass() {
        let south = SunPosition::new(180.0, 0.0).unwrap().direction();
        assert!((south - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12);
        let east_up = SunPosition::new(90.0, 45.0).unwrap().direction();
        assert!((east_up - DVec3::new(0.5f64.sqrt(), 0.0, 0.5f64.sqrt())).length() < 1e-12);
    }

    #[test]
    fn malformed_sun_is_refused() {
        for bad in ["", "180", "a,b", "180,95", "nan,10", "180,inf"] {
            let e = SunPosition::parse(bad).unwrap_err().to_string();
            assert!(e.contains("invalid sun"), "{bad}: {e}");
        }
        assert_eq!(SunPosition::parse(" 190 , 30 ").unwrap().azimuth, 190.0);
    }
}
