//! The one resolver of an annual run's settings, for both edges: the CLI fills [`AnnualSettings`]
//! from its flags, the web deserialises it from the JS settings object (camelCase keys, the names
//! `www/sunlit.d.ts` documents; a test holds the two together), and both get the same defaults,
//! ranges and rules from [`AnnualSettings::resolve`]:
//! - the location from an EPW (file or text) or latitude, longitude and time zone;
//! - the sampling plan (27 days × 19 samples a day) or dense counting;
//! - the refinement threshold, default [`DEFAULT_REFINE`], in 0..=1;
//! - the leaf calendar: evergreen, both leaf periods, or neither (then the hemisphere's default);
//! - timesteps per hour: as asked, else the EnergyPlus model's Timestep, else
//!   [`DEFAULT_TIMESTEPS_PER_HOUR`] ([`Resolved::timesteps`], once the model is read);
//! - the sky model ([`SkyModel`], by its name), with an EPW only.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::annual::{AnnualOptions, DEFAULT_REFINE, Method};
use super::samples::{SamplingPlan, Timesteps};
use super::season::{LeafCalendar, parse_period};
use crate::error::{Error, Result};
use crate::sky::model::SkyModel;
use crate::sun::location::Location;
use crate::sun::periods::ShadingPeriods;

/// EnergyPlus's own default Timestep (rows per hour) where neither the caller nor the model says.
pub const DEFAULT_TIMESTEPS_PER_HOUR: u32 = 4;

/// An annual run's settings as a caller gives them: every field optional. Serialised names are
/// the JS API's (`timestepsPerHour`); the library's parameter names are the snake_case ones.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct AnnualSettings {
    /// Degrees north.
    pub latitude: Option<f64>,
    /// Degrees east.
    pub longitude: Option<f64>,
    /// Hours from UTC of the standard time the CSV is in.
    pub time_zone: Option<f64>,
    /// An EPW file's text: its LOCATION line gives the three above.
    pub epw: Option<String>,
    /// A label for the EPW in messages (its file name).
    pub epw_name: Option<String>,
    /// Natively, an EPW file to read instead of `epw` (only its first line is read).
    #[serde(skip)]
    pub epw_file: Option<PathBuf>,
    /// Output timesteps per hour (EnergyPlus's Timestep); default the model's, else 4.
    pub timesteps_per_hour: Option<u32>,
    /// Sampled days (default 27).
    pub days_per_year: Option<usize>,
    /// Samples per day (default 19).
    pub samples_per_day: Option<usize>,
    /// See [`AnnualOptions::refine`] (default [`DEFAULT_REFINE`]).
    pub refine: Option<f64>,
    /// See [`AnnualOptions::prove_never_dark`] (default off).
    pub prove_never_dark: Option<bool>,
    /// See [`AnnualOptions::many_casters`] (default: the year's pilot decides).
    pub many_casters: Option<bool>,
    /// See [`AnnualOptions::inner_corners`] (default off).
    pub inner_corners: Option<bool>,
    /// Count every timestep instead of the spline.
    pub dense: Option<bool>,
    /// Foliage keeps its leaves all year.
    pub evergreen: Option<bool>,
    /// Leaf-out period, `START,END` as `MM-DD` dates or days of the year (default 04-15,05-31,
    /// half a year later south of the equator).
    pub leaf_out: Option<String>,
    /// Leaf-fall period (default 10-01,11-15, likewise).
    pub leaf_fall: Option<String>,
    /// The calendar year (a leap year gives 366 days, 8784 rows per timestep per hour); default:
    /// the EnergyPlus model's RunPeriod year, else the EPW's Feb 29, else a non-leap year
    /// ([`crate::model::run_year::choose`]).
    pub year: Option<i32>,
    /// The sky that weighs the sky patches with an EPW ([`SkyModel`]'s names, `--sky-model`'s):
    /// energyplus (the default), perez-all-weather, cie-overcast or uniform.
    pub sky_model: Option<String>,
}

/// Settings with their defaults applied and every value checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// Where the sun is seen from.
    pub location: Location,
    /// Spline (with its sampling plan) or dense.
    pub method: Method,
    /// The refinement threshold.
    pub refine: f64,
    /// Whether interpolated timesteps must be proved never dark ([`AnnualOptions::prove_never_dark`]).
    pub prove_never_dark: bool,
    /// Whether dark proofs may combine casters, `None` for the year's pilot to decide
    /// ([`AnnualOptions::many_casters`]).
    pub many_casters: Option<bool>,
    /// Whether they may trust a facade at an inner corner ([`AnnualOptions::inner_corners`]).
    pub inner_corners: bool,
    /// When foliage is in leaf.
    pub calendar: LeafCalendar,
    /// Timesteps per hour as asked (checked); `None`: the model's, else the default.
    pub timesteps_per_hour: Option<Timesteps>,
    /// The sky model (the default without one asked).
    pub sky_model: SkyModel,
}

impl AnnualSettings {
    /// Applies the defaults and checks every value, in the order a person reads them: refine,
    /// the sampling plan, the location, the leaf periods, the timesteps asked for.
    pub fn resolve(&self) -> Result<Resolved> {
        let refine = self.refine.unwrap_or(DEFAULT_REFINE);
        if !(0.0..=1.0).contains(&refine) {
            return Err(Error::argument("refine", format!("{refine} is outside 0..=1")));
        }
        let method = if self.dense.unwrap_or(false) {
            Method::Dense
        } else {
            let default = SamplingPlan::default();
            Method::Spline(SamplingPlan::new(self.days_per_year.unwrap_or(default.days), self.samples_per_day.unwrap_or(default.per_day))?)
        };
        let location = self.location()?;
        let calendar = self.calendar(&location)?;
        let timesteps_per_hour = self.timesteps_per_hour.map(Timesteps::new).transpose()?;
        let sky_model = self.sky_model()?;
        let prove_never_dark = self.prove_never_dark.unwrap_or(false);
        let (many_casters, inner_corners) = (self.many_casters, self.inner_corners.unwrap_or(false));
        Ok(Resolved { location, method, refine, prove_never_dark, many_casters, inner_corners, calendar, timesteps_per_hour, sky_model })
    }

    fn location(&self) -> Result<Location> {
        match (&self.epw_file, &self.epw, self.latitude, self.longitude, self.time_zone) {
            (Some(path), ..) => crate::sun::weather::location_from_epw(path),
            (None, Some(epw), ..) => crate::sun::weather::location_from_text(self.epw_name.as_deref().unwrap_or("EPW"), epw),
            (None, None, Some(lat), Some(lon), Some(tz)) => Location::new(lat, lon, tz),
            _ => Err(Error::argument("location", "give an EPW or latitude, longitude and time zone")),
        }
    }

    /// The sky model asked for; refused without an EPW, whose hours give the sky its light.
    pub(crate) fn sky_model(&self) -> Result<SkyModel> {
        let Some(name) = &self.sky_model else { return Ok(SkyModel::default()) };
        let model = SkyModel::parse(name)?;
        if self.epw.is_none() && self.epw_file.is_none() {
            return Err(Error::argument("sky_model", "needs a weather file (an EPW): the sky's light comes from it"));
        }
        Ok(model)
    }

    /// The foliage calendar: evergreen, the given periods, or the defaults for the latitude.
    fn calendar(&self, location: &Location) -> Result<LeafCalendar> {
        if self.evergreen.unwrap_or(false) {
            return Ok(LeafCalendar::evergreen());
        }
        match (&self.leaf_out, &self.leaf_fall) {
            (Some(out), Some(fall)) => LeafCalendar::new(parse_period(out)?, parse_period(fall)?),
            (None, None) => Ok(LeafCalendar::for_latitude(location.latitude)),
            _ => Err(Error::argument("leaf_out/leaf_fall", "give both periods, or neither")),
        }
    }
}

impl Resolved {
    /// Timesteps per hour: as asked, else the EnergyPlus model's Timestep (`model`), else
    /// [`DEFAULT_TIMESTEPS_PER_HOUR`].
    pub fn timesteps(&self, model: Option<u32>) -> Result<Timesteps> {
        match self.timesteps_per_hour {
            Some(asked) => Ok(asked),
            None => Timesteps::new(model.unwrap_or(DEFAULT_TIMESTEPS_PER_HOUR)),
        }
    }

    /// The annual run's options, timesteps as [`Self::timesteps`] gives them.
    pub fn options(&self, model_timesteps: Option<u32>) -> Result<AnnualOptions> {
        Ok(AnnualOptions {
            timesteps: self.timesteps(model_timesteps)?,
            method: self.method,
            refine: self.refine,
            prove_never_dark: self.prove_never_dark,
            many_casters: self.many_casters,
            inner_corners: self.inner_corners,
        })
    }

    /// The options for an EnergyPlus model whose own shading updates periodically (`periods`,
    /// [`crate::model::shading_update::periodic_update`]): its suns, one a period, whatever the
    /// method asked ([`Method::Periodic`]), since those are the suns EnergyPlus's own clipping
    /// and a hooked model keeping that update use.
    pub fn model_options(&self, model_timesteps: Option<u32>, periods: Option<ShadingPeriods>) -> Result<AnnualOptions> {
        let options = self.options(model_timesteps)?;
        Ok(match periods {
            Some(p) => AnnualOptions { method: Method::Periodic(p), ..options },
            None => options,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn golden() -> AnnualSettings {
        AnnualSettings { latitude: Some(39.74), longitude: Some(-105.18), time_zone: Some(-7.0), ..Default::default() }
    }

    #[test]
    fn defaults_come_from_one_place() {
        let r = golden().resolve().unwrap();
        assert_eq!(r.method, Method::Spline(SamplingPlan::default()));
        assert_eq!(r.refine, DEFAULT_REFINE);
        assert_eq!(r.calendar, LeafCalendar::for_latitude(39.74));
        assert_eq!(r.timesteps(None).unwrap().per_hour(), DEFAULT_TIMESTEPS_PER_HOUR);
        assert_eq!(r.timesteps(Some(6)).unwrap().per_hour(), 6, "the model's Timestep");
        let asked = AnnualSettings { timesteps_per_hour: Some(2), ..golden() }.resolve().unwrap();
        assert_eq!(asked.timesteps(Some(6)).unwrap().per_hour(), 2, "what was asked wins");
        let south = AnnualSettings { latitude: Some(-33.9), ..golden() }.resolve().unwrap();
        assert_eq!(south.calendar, LeafCalendar::for_latitude(-33.9), "the southern calendar");
        assert_ne!(south.calendar, r.calendar);
        assert_eq!(r.many_casters, None, "the many-caster proofs left to the year's pilot");
        assert!(!r.prove_never_dark && !r.inner_corners, "the never-dark and inner-corner proofs off");
        let many: AnnualSettings = serde_json::from_str(r#"{"latitude":1,"longitude":2,"timeZone":3,"manyCasters":true}"#).unwrap();
        assert_eq!(many.resolve().unwrap().options(None).unwrap().many_casters, Some(true), "manyCasters: true turns them on");
        let none: AnnualSettings = serde_json::from_str(r#"{"latitude":1,"longitude":2,"timeZone":3,"manyCasters":false}"#).unwrap();
        assert_eq!(none.resolve().unwrap().options(None).unwrap().many_casters, Some(false), "manyCasters: false turns them off");
        let corners: AnnualSettings = serde_json::from_str(r#"{"latitude":1,"longitude":2,"timeZone":3,"innerCorners":true}"#).unwrap();
        assert!(corners.resolve().unwrap().options(None).unwrap().inner_corners, "innerCorners: true turns them on");
    }

    #[test]
    fn out_of_range_values_are_refused_by_parameter() {
        let refused = |s: AnnualSettings| s.resolve().err().map(|e| e.parameter().map(str::to_string));
        assert_eq!(refused(AnnualSettings { refine: Some(2.0), ..golden() }), Some(Some("refine".into())));
        assert_eq!(refused(AnnualSettings { days_per_year: Some(0), ..golden() }), Some(Some("days_per_year".into())));
        assert_eq!(refused(AnnualSettings { timesteps_per_hour: Some(7), ..golden() }), Some(Some("timesteps_per_hour".into())));
        assert_eq!(refused(AnnualSettings { leaf_out: Some("04-15,05-31".into()), ..golden() }), Some(Some("leaf_out/leaf_fall".into())));
        assert_eq!(refused(AnnualSettings { time_zone: None, ..golden() }), Some(Some("location".into())));
        assert_eq!(refused(AnnualSettings { sky_model: Some("perez".into()), ..golden() }), Some(Some("sky_model".into())));
        assert_eq!(refused(AnnualSettings { sky_model: Some("uniform".into()), ..golden() }), Some(Some("sky_model".into())), "no EPW");
    }

    #[test]
    fn the_js_settings_object_deserialises_by_its_camel_case_names() {
        let s: AnnualSettings =
            serde_json::from_str(r#"{"latitude":1,"longitude":2,"timeZone":3,"timestepsPerHour":6,"leafOut":"04-01,05-01"}"#).unwrap();
        assert_eq!((s.time_zone, s.timesteps_per_hour, s.leaf_out.as_deref()), (Some(3.0), Some(6), Some("04-01,05-01")));
        assert!(serde_json::from_str::<AnnualSettings>(r#"{"timezone":3}"#).is_err(), "unknown keys are refused");
    }
}
