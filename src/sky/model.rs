//! Which sky weighs the patches: the choice `sky_model` names, the same for annual irradiation,
//! maps and sweeps.
//!
//! - `energyplus` (the default): EnergyPlus's Perez 1990 irradiance model ([`crate::sky::perez`]),
//!   an isotropic part over the visible sky, a circumsolar part shaded like the beam and a
//!   horizon band: what EnergyPlus computes, kept to its own values;
//! - `perez-all-weather`: Radiance's `gendaymtx` sky ([`crate::sky::all_weather`]), what
//!   Ladybug's and Radiance's annual studies use;
//! - `cie-overcast`: the CIE standard overcast distribution ([`LuminanceSky::CieOvercast`]),
//!   scaled each hour to the weather's diffuse horizontal;
//! - `uniform`: the same luminance everywhere, scaled likewise (the isotropic sky).
//!
//! The last three are luminance distributions over the same patches: each hour every patch has a
//! radiance (W/m²/sr), and a receiver's sky diffuse is Σ radiance × its visible ∫cos dΩ over the
//! patch ([`crate::sky::views::SkyViews`] keeps those per patch for them). `cie-overcast` and
//! `uniform` are normalised on the exact patch integrals, so an open roof gets the hour's DHI;
//! `perez-all-weather` as gendaymtx normalises.

use glam::DVec3;

use crate::error::{Error, Result};
use crate::sky::all_weather::AllWeatherSky;
use crate::sky::luminance::LuminanceSky;
use crate::sky::patches::SkyPatches;

/// A sky model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SkyModel {
    /// EnergyPlus's Perez 1990 irradiance model.
    #[default]
    EnergyPlus,
    /// The Perez all-weather luminance distribution, as Radiance's gendaymtx.
    PerezAllWeather,
    /// The CIE standard overcast sky.
    CieOvercast,
    /// The uniform sky.
    Uniform,
}

impl SkyModel {
    /// Every model, the default first.
    pub const ALL: [SkyModel; 4] = [Self::EnergyPlus, Self::PerezAllWeather, Self::CieOvercast, Self::Uniform];

    /// The model's name, as [`Self::parse`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Self::EnergyPlus => "energyplus",
            Self::PerezAllWeather => "perez-all-weather",
            Self::CieOvercast => LuminanceSky::CieOvercast.name(),
            Self::Uniform => LuminanceSky::Uniform.name(),
        }
    }

    /// Reads a model's name; errors name the `sky_model` parameter and list the models.
    pub fn parse(text: &str) -> Result<Self> {
        let lower = text.trim().to_ascii_lowercase();
        Self::ALL.into_iter().find(|m| m.name() == lower).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            Error::argument("sky_model", format!("'{text}' is not a sky model: give {}", names.join(", ")))
        })
    }

    /// Whether the model is a luminance distribution over the patches (all but `energyplus`).
    pub fn is_distribution(self) -> bool {
        self != Self::EnergyPlus
    }

    /// The model on `patches`, ready to give each timestep's patch radiances; `None` for
    /// `energyplus`, which is not a distribution.
    pub fn on(self, patches: &SkyPatches) -> Option<PatchSky> {
        let fixed = match self {
            Self::EnergyPlus => return None,
            Self::PerezAllWeather => None,
            Self::CieOvercast => Some(LuminanceSky::CieOvercast),
            Self::Uniform => Some(LuminanceSky::Uniform),
        };
        // A fixed distribution's shape per unit of DHI: luminance over Σ luminance·∫sin dΩ.
        let shape = fixed.map(|sky| {
            let luminance: Vec<f64> = patches.patches.iter().map(|p| sky.relative_luminance(p.direction.z)).collect();
            let horizontal: f64 = patches.patches.iter().zip(&luminance).map(|(p, l)| l * p.weight(DVec3::Z).weight).sum();
            luminance.into_iter().map(|l| l / horizontal).collect()
        });
        Some(PatchSky { patches: patches.clone(), shape })
    }
}

/// A luminance distribution on a patch layout ([`SkyModel::on`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PatchSky {
    patches: SkyPatches,
    /// For a weather-free distribution, each patch's radiance per W/m² of DHI; `None` for the
    /// all-weather sky, which changes with the hour.
    shape: Option<Vec<f64>>,
}

impl PatchSky {
    /// Each patch's radiance (W/m²/sr) for one timestep: direct normal `dni`, diffuse horizontal
    /// `dhi`, the sun towards `sun` (unit) on day `day` of the year. `None` without diffuse light.
    pub fn radiances(&self, dni: f64, dhi: f64, sun: DVec3, day: u32) -> Option<Vec<f64>> {
        if dhi <= 0.0 {
            return None;
        }
        match &self.shape {
            Some(shape) => Some(shape.iter().map(|s| s * dhi).collect()),
            None => AllWeatherSky::new(dni, dhi, sun, day).map(|sky| sky.radiances(&self.patches, dhi)),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_name_the_parameter() {
        for model in SkyModel::ALL {
            assert_eq!(SkyModel::parse(model.name()).unwrap(), model);
        }
        assert_eq!(SkyModel::parse(" Perez-All-Weather ").unwrap(), SkyModel::PerezAllWeather);
        let error = SkyModel::parse("perez").unwrap_err().to_string();
        assert!(error.contains("sky_model") && error.contains("perez-all-weather"), "{error}");
        assert!(SkyModel::EnergyPlus.on(&SkyPatches::tregenza()).is_none());
    }

    /// An open roof gets the hour's DHI from the fixed skies; an open wall the closed forms:
    /// (1 + cos tilt)/2·DHI under the uniform sky, and under the CIE overcast sky a vertical plane
    /// gets 39.6 % of the horizontal (BRE 209's unobstructed VSC) — here within the patches' error.
    #[test]
    fn fixed_skies_give_their_closed_forms() {
        let patches = SkyPatches::tregenza();
        let up = DVec3::Z;
        let wall = DVec3::new(0.0, -1.0, 0.0);
        let on = |model: SkyModel, normal: DVec3| -> f64 {
            let r = model.on(&patches).unwrap().radiances(0.0, 100.0, up, 1).unwrap();
            patches.patches.iter().zip(&r).map(|(p, r)| r * p.weight(normal).weight).sum()
        };
        assert!((on(SkyModel::Uniform, up) - 100.0).abs() < 1e-9);
        assert!((on(SkyModel::CieOvercast, up) - 100.0).abs() < 1e-9);
        assert!((on(SkyModel::Uniform, wall) - 50.0).abs() < 0.01, "{}", on(SkyModel::Uniform, wall));
        assert!((on(SkyModel::CieOvercast, wall) - 39.6).abs() < 0.3, "{}", on(SkyModel::CieOvercast, wall));
    }
}
