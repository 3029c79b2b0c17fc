//! The Perez 1990 all-weather sky: diffuse irradiance on a tilted, partly obstructed surface, as
//! EnergyPlus computes it (`AnisoSkyViewFactors` in SolarShading.cc).
//!
//! Owns the brightness coefficients F1 (circumsolar) and F2 (horizon brightening) from the sky's
//! clearness ε and brightness Δ, and how the three parts are shaded:
//! I_sky = DHI·max(0, (1 − F1)·V_iso + F1·max(0, cos θ)/max(cos 85°, cos Z)·f_beam + F2·sin(tilt)·V_hor),
//! the circumsolar ratio cos θ/max(cos 85°, cos Z) taken as 1 on near-horizontal surfaces
//! (sin tilt < 0.1) with the sun below 5°, as EnergyPlus does,
//! V_iso the receiver's view factor to the visible sky (Σ visibility·cos·Ω/π over the patches),
//! f_beam the beam's sunlit fraction (the circumsolar disc is shaded like the sun) and V_hor the
//! horizon band's visibility. Unobstructed, V_iso = (1 + cos tilt)/2 and f_beam = V_hor = 1.

/// Upper bounds of the clearness bins (Perez et al. 1990, table 1).
const EPSILON_LIMITS: [f64; 7] = [1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2];
/// F1 = F11 + F12·Δ + F13·Z and F2 = F21 + F22·Δ + F23·Z per clearness bin (Perez et al. 1990,
/// the coefficients EnergyPlus uses).
const F11: [f64; 8] = [-0.0083117, 0.1299457, 0.3296958, 0.5682053, 0.8730280, 1.1326077, 1.0601591, 0.6777470];
const F12: [f64; 8] = [0.5877285, 0.6825954, 0.4868735, 0.1874525, -0.3920403, -1.2367284, -1.5999137, -0.3272588];
const F13: [f64; 8] = [-0.0620636, -0.1513752, -0.2210958, -0.2951290, -0.3616149, -0.4118494, -0.3589221, -0.2504286];
const F21: [f64; 8] = [-0.0596012, -0.0189325, 0.0554140, 0.1088631, 0.2255647, 0.2877813, 0.2642124, 0.1561313];
const F22: [f64; 8] = [0.0721249, 0.0659650, -0.0639588, -0.1519229, -0.4620442, -0.8230357, -1.1272340, -1.3765031];
const F23: [f64; 8] = [-0.0220216, -0.0288748, -0.0260542, -0.0139754, 0.0012448, 0.0558651, 0.1310694, 0.2506212];
/// Extraterrestrial irradiance EnergyPlus divides by for Δ, W/m².
const EXTRATERRESTRIAL: f64 = 1353.0;
/// cos 85°: the circumsolar ratio's denominator never falls below it.
pub const MIN_COS_ZENITH: f64 = 0.0871557;
/// Below this sine of tilt a surface is a near-horizontal roof, whose circumsolar ratio
/// EnergyPlus sets to 1 with the sun below 5° (so its sky diffuse stays close to DHI there).
const NEAR_HORIZONTAL_SIN_TILT: f64 = 0.1;

/// The sky's brightness coefficients at one timestep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerezSky {
    /// Circumsolar brightening, ≥ 0.
    pub f1: f64,
    /// Horizon brightening (may be negative).
    pub f2: f64,
    /// cos of the sun's zenith angle.
    pub cos_zenith: f64,
}

impl PerezSky {
    /// The coefficients for direct normal `dni` and diffuse horizontal `dhi` (W/m²) with the sun
    /// at `cos_zenith` (> 0), seen from `elevation` metres above sea level; `None` without diffuse
    /// light.
    pub fn new(dni: f64, dhi: f64, cos_zenith: f64, elevation: f64) -> Option<Self> {
        if dhi <= 0.0 || cos_zenith <= 0.0 {
            return None;
        }
        let zenith = cos_zenith.min(1.0).acos();
        let zenith_degrees = zenith.to_degrees();
        // Relative air mass, thinner with altitude: EnergyPlus scales it by 1 − 0.1·elevation/km
        // (AnisoSkyViewFactors' AirMassH); at Golden's 1,829 m leaving it out makes Δ 18% too
        // large and walls' sky diffuse 2–3% too small.
        let air_mass_horizontal = 1.0 - 0.1 * elevation / 1000.0;
        let air_mass = if zenith_degrees <= 75.0 {
            air_mass_horizontal / cos_zenith
        } else {
            air_mass_horizontal / (cos_zenith + 0.15 * (93.9 - zenith_degrees).powf(-1.253))
        };
        let kappa_z3 = 1.041 * zenith.powi(3);
        let epsilon = ((dni + dhi) / dhi + kappa_z3) / (1.0 + kappa_z3);
        let delta = dhi * air_mass / EXTRATERRESTRIAL;
        let bin = EPSILON_LIMITS.iter().position(|&limit| epsilon < limit).unwrap_or(EPSILON_LIMITS.len());
        let f1 = (F11[bin] + F12[bin] * delta + F13[bin] * zenith).max(0.0);
        let f2 = F21[bin] + F22[bin] * delta + F23[bin] * zenith;
        Some(Self { f1, f2, cos_zenith })
    }

    /// Sky diffuse irradiance (W/m²) on a receiver: `dhi` W/m² diffuse horizontal,
    /// `cos_incidence` of the beam, `sky` its view factor to the visible sky, `beam_fraction` its
    /// sunlit fraction, `sin_tilt` the sine of its tilt and `horizon` its horizon-band visibility.
    pub fn diffuse(&self, dhi: f64, cos_incidence: f64, sky: f64, beam_fraction: f64, sin_tilt: f64, horizon: f64) -> f64 {
        self.terms(dhi, cos_incidence, sin_tilt).diffuse(sky, beam_fraction, horizon)
    }

    /// The sky's three parts on a plane (`dhi`, `cos_incidence`, `sin_tilt` as for
    /// [`Self::diffuse`]) before they meet the plane's shading: many points on one plane share
    /// them (a map's grid on a receiver).
    pub fn terms(&self, dhi: f64, cos_incidence: f64, sin_tilt: f64) -> PerezTerms {
        let ratio = if self.cos_zenith < MIN_COS_ZENITH && sin_tilt < NEAR_HORIZONTAL_SIN_TILT {
            1.0
        } else {
            cos_incidence.max(0.0) / self.cos_zenith.max(MIN_COS_ZENITH)
        };
        PerezTerms { isotropic: dhi * (1.0 - self.f1), circumsolar: dhi * self.f1 * ratio, horizon: dhi * self.f2 * sin_tilt }
    }
}

/// The Perez sky on one plane at one timestep, W/m² per unit of each shading factor: sky diffuse
/// is max(0, isotropic·V_iso + circumsolar·f_beam + horizon·V_hor) ([`PerezSky::diffuse`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerezTerms {
    /// DHI·(1 − F1): times the view factor to the visible sky.
    pub isotropic: f64,
    /// DHI·F1·(circumsolar ratio), ≥ 0: times the beam's sunlit fraction.
    pub circumsolar: f64,
    /// DHI·F2·sin tilt: times the horizon band's visibility.
    pub horizon: f64,
}

impl PerezTerms {
    /// Sky diffuse irradiance (W/m²) with view factor `sky`, sunlit fraction `beam_fraction` and
    /// horizon-band visibility `horizon`.
    pub fn diffuse(&self, sky: f64, beam_fraction: f64, horizon: f64) -> f64 {
        (self.isotropic * sky + self.circumsolar * beam_fraction + self.horizon * horizon).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overcast_skies_are_isotropic_and_clear_ones_circumsolar() {
        // ε = 1 (no beam) falls in the first bin: F1 ≈ 0 at small Δ, the sky almost isotropic.
        let overcast = PerezSky::new(0.0, 100.0, 0.8, 0.0).unwrap_or(PerezSky { f1: 9.0, f2: 9.0, cos_zenith: 0.8 });
        assert!(overcast.f1 < 0.05 && overcast.f2.abs() < 0.1, "{overcast:?}");
        let clear = PerezSky::new(900.0, 80.0, 0.8, 0.0).unwrap_or(overcast);
        assert!(clear.f1 > 0.3, "{clear:?}");
        assert!(PerezSky::new(500.0, 0.0, 0.5, 0.0).is_none());
        // A horizontal unobstructed receiver under any sky gets DHI·(1 − F1 + F1·cosZ/cosZ) = DHI
        // (the horizon term has sin 0 = 0).
        let dhi = 120.0;
        let got = clear.diffuse(dhi, 0.8, 1.0, 1.0, 0.0, 1.0);
        assert!((got - dhi).abs() < 1e-9, "{got}");
    }
}
