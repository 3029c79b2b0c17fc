//! The Perez all-weather sky luminance distribution (Perez, Seals & Michalsky 1993) on the sky
//! patches, as Radiance's `gendaymtx` lays it out, so that Radiance's and Ladybug's users get the
//! sky their numbers come from.
//!
//! Owns the per-timestep patch radiances (W/m²/sr of sky diffuse, the sun left out: `gendaymtx
//! -s`), following gendaymtx 6.0's `ComputeSky`:
//! - the sun's zenith angle Z is held to 3°..90° (a sun above 87° is put at 87°, one below the
//!   horizon on it), which keeps the circumsolar peak off the zenith patch;
//! - clearness ε = ((DHI + DNI)/DHI + 1.041 Z³)/(1 + 1.041 Z³), at most 11.9; brightness
//!   Δ = DHI·m/(1367·E₀), at least 0.01, with Kasten's air mass m (no altitude correction, unlike
//!   EnergyPlus's irradiance model) and the eccentricity E₀ of the day;
//! - ε's bin picks table 1's coefficients; a..e = x₁ + x₂Z + Δ(x₃ + x₄Z), except in the overcast
//!   bin where c and d follow the paper's equations 7 and 8; Δ is raised to 0.2 for
//!   1.065 < ε < 2.8;
//! - each patch's relative luminance at its centre (altitude, azimuth), ζ its zenith angle and γ
//!   its angle to the sun: lv = (1 + a·e^(b/cos ζ))·(1 + c·e^(dγ) + e·cos²γ), at least 0;
//! - normalised so that Σ lv·sin(centre altitude)·Ω = DHI, gendaymtx's sum (0.55 % above the
//!   exact integral on Tregenza's patches: a uniform sky normalised this way gives a horizontal
//!   plane 0.55 % less than DHI, as Radiance does); a sky whose sum is 0 is made uniform.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use crate::sky::patches::SkyPatches;

/// Solar constant gendaymtx uses for Δ, W/m².
const SOLAR_CONSTANT: f64 = 1367.0;
/// Upper bounds of the clearness bins (the last bin is open above).
const CLEARNESS_BINS: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];
/// Clearness is held below this (gendaymtx's limit).
const MAX_CLEARNESS: f64 = 11.9;
/// Brightness is held above this.
const MIN_BRIGHTNESS: f64 = 0.01;
/// Perez, Seals & Michalsky (1993), table 1: per clearness bin, for each of a, b, c, d, e the four
/// coefficients x₁..x₄.
const COEFFICIENTS: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// The five parameters a..e of one timestep's sky.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllWeatherSky {
    /// a, b, c, d, e.
    pub parameters: [f64; 5],
    /// The sun, held to 3°..90° from the zenith (unit; x east, y north, z up).
    pub sun: DVec3,
}

impl AllWeatherSky {
    /// The sky for direct normal `dni` and diffuse horizontal `dhi` (W/m²), the sun towards `sun`
    /// (unit) on day `day` of the year; `None` without diffuse light.
    pub fn new(dni: f64, dhi: f64, sun: DVec3, day: u32) -> Option<Self> {
        if dhi <= 1e-4 {
            return None;
        }
        let altitude = sun.z.clamp(-1.0, 1.0).asin().clamp(0.0, 87f64.to_radians());
        let azimuth = sun.x.atan2(sun.y);
        let zenith = FRAC_PI_2 - altitude;
        let sun = DVec3::new(azimuth.sin() * altitude.cos(), azimuth.cos() * altitude.cos(), altitude.sin());
        let z3 = 1.041 * zenith.powi(3);
        let clearness = (((dhi + dni.max(0.0)) / dhi + z3) / (1.0 + z3)).min(MAX_CLEARNESS);
        let air_mass = 1.0 / (zenith.cos() + 0.15 * (93.885 - zenith.to_degrees()).powf(-1.253));
        let mut brightness = (dhi * air_mass / (SOLAR_CONSTANT * eccentricity(day))).max(MIN_BRIGHTNESS);
        if clearness > 1.065 && clearness < 2.8 {
            brightness = brightness.max(0.2);
        }
        let bin = CLEARNESS_BINS.iter().position(|&upper| clearness < upper).unwrap_or(CLEARNESS_BINS.len());
        let x = &COEFFICIENTS[bin];
        let linear = |k: usize| x[k][0] + x[k][1] * zenith + brightness * (x[k][2] + x[k][3] * zenith);
        let mut parameters = [linear(0), linear(1), linear(2), linear(3), linear(4)];
        if bin == 0 {
            parameters[2] = (brightness * (x[2][0] + x[2][1] * zenith)).powf(x[2][2]).exp() - x[2][3];
            parameters[3] = -(brightness * (x[3][0] + x[3][1] * zenith)).exp() + x[3][2] + brightness * x[3][3];
        }
        Some(Self { parameters, sun })
    }

    /// Relative luminance towards `direction` (unit, above the horizon).
    pub fn relative_luminance(&self, direction: DVec3) -> f64 {
        let [a, b, c, d, e] = self.parameters;
        let cos_zeta = direction.z.max(1e-9);
        let cos_gamma = direction.dot(self.sun).clamp(-1.0, 1.0);
        let gamma = cos_gamma.acos();
        ((1.0 + a * (b / cos_zeta).exp()) * (1.0 + c * (d * gamma).exp() + e * cos_gamma * cos_gamma)).max(0.0)
    }

    /// Each patch's radiance, W/m²/sr, for diffuse horizontal `dhi`, normalised as gendaymtx
    /// normalises (the module doc).
    pub fn radiances(&self, patches: &SkyPatches, dhi: f64) -> Vec<f64> {
        let mut luminance: Vec<f64> = patches.patches.iter().map(|p| self.relative_luminance(p.direction)).collect();
        let sum = |l: &[f64]| -> f64 { patches.patches.iter().zip(l).map(|(p, l)| l * p.direction.z * p.solid_angle).sum() };
        let mut norm = sum(&luminance);
        if norm <= 1e-9 {
            luminance.iter_mut().for_each(|l| *l = 1.0);
            norm = PI;
        }
        luminance.iter().map(|l| l * dhi / norm).collect()
    }
}

/// The earth orbit's eccentricity correction on day `day` (Spencer's series, as gendaymtx).
fn eccentricity(day: u32) -> f64 {
    let angle = (f64::from(day) - 1.0) * 2.0 * PI / 365.0;
    1.00011 + 0.034221 * angle.cos() + 0.00128 * angle.sin() + 0.000719 * (2.0 * angle).cos() + 0.000077 * (2.0 * angle).sin()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Normalised as gendaymtx normalises, the patches' Σ radiance·sin(altitude)·Ω is DHI; a clear
    /// sky is brightest around the sun and an overcast one brighter at the zenith than the horizon.
    #[test]
    fn skies_are_normalised_and_shaped() {
        let patches = SkyPatches::tregenza();
        let sun = crate::sky::patches::direction(35f64.to_radians(), 180f64.to_radians());
        let clear = AllWeatherSky::new(800.0, 90.0, sun, 172).unwrap();
        let r = clear.radiances(&patches, 90.0);
        let sum: f64 = patches.patches.iter().zip(&r).map(|(p, r)| r * p.direction.z * p.solid_angle).sum();
        assert!((sum - 90.0).abs() < 1e-9, "{sum}");
        let near = patches.patches.iter().position(|p| p.direction.dot(sun) > 0.98).unwrap();
        let north = patches.patches.iter().position(|p| p.band == 2 && p.direction.y > 0.86).unwrap();
        assert!(r[near] > 5.0 * r[north], "{} {}", r[near], r[north]);
        let overcast = AllWeatherSky::new(0.0, 120.0, sun, 172).unwrap();
        let r = overcast.radiances(&patches, 120.0);
        assert!(r[patches.len() - 1] > 1.3 * r[0], "zenith {} horizon {}", r[patches.len() - 1], r[0]);
        assert!(AllWeatherSky::new(500.0, 0.0, sun, 172).is_none());
    }
}
