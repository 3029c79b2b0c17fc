//! Sky luminance distributions that do not depend on the weather: the CIE standard overcast sky
//! (CIE S 011/E:2003 type 16, Moon & Spencer 1942), which BRE 209's vertical sky component is
//! defined under, and the uniform sky.
//!
//! Each gives the luminance of a direction relative to the zenith's (L/Lz) and the illuminance
//! the whole unobstructed sky gives a horizontal plane per unit zenith luminance, so a study can
//! state what a point sees as a share of the unobstructed horizontal:
//! - CIE overcast: L(γ) = Lz (1 + 2 sin γ)/3 at altitude γ; horizontal ∫ L sin γ dΩ = 7π Lz/9;
//! - uniform: L = Lz; horizontal π Lz.

use std::f64::consts::PI;

/// A weather-free sky luminance distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LuminanceSky {
    /// The CIE standard overcast sky.
    CieOvercast,
    /// A sky of the same luminance everywhere.
    Uniform,
}

impl LuminanceSky {
    /// The name a study's report and the CLI use.
    pub fn name(self) -> &'static str {
        match self {
            Self::CieOvercast => "cie-overcast",
            Self::Uniform => "uniform",
        }
    }

    /// Luminance of a direction `sin_altitude` (the sine of its altitude, ≥ 0) over the zenith's.
    pub fn relative_luminance(self, sin_altitude: f64) -> f64 {
        match self {
            Self::CieOvercast => (1.0 + 2.0 * sin_altitude.max(0.0)) / 3.0,
            Self::Uniform => 1.0,
        }
    }

    /// Illuminance of the whole unobstructed sky on a horizontal plane per unit zenith luminance:
    /// ∫ (L/Lz) sin γ dΩ over the upper hemisphere.
    pub fn horizontal_illuminance(self) -> f64 {
        match self {
            Self::CieOvercast => 7.0 * PI / 9.0,
            Self::Uniform => PI,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed forms against a midpoint sum over altitude (the azimuth integral is 2π).
    #[test]
    fn horizontal_illuminance_is_the_integral_of_the_luminance() {
        for sky in [LuminanceSky::CieOvercast, LuminanceSky::Uniform] {
            let n = 100_000;
            let d = PI / 2.0 / n as f64;
            let sum: f64 = (0..n)
                .map(|i| {
                    let g = (i as f64 + 0.5) * d;
                    2.0 * PI * sky.relative_luminance(g.sin()) * g.sin() * g.cos() * d
                })
                .sum();
            assert!((sum - sky.horizontal_illuminance()).abs() < 1e-8, "{}: {sum}", sky.name());
        }
    }
}
