//! EnergyPlus's own diffuse shading ratios, `DifShdgRatioIsoSky` and `DifShdgRatioHoriz`, as its
//! `SkyDifSolarShading` (SolarShading.cc) defines them, so a modeller sees per surface what
//! EnergyPlus will compute from the casters it can see.
//!
//! Owns EnergyPlus's sky and weights, which differ from the patches of [`crate::sky::patches`]:
//! 144 directions, 6 altitudes φ = 7.5°, 22.5°, …, 82.5° times 24 azimuths θ = 0°, 15°, …, 345°
//! (counter-clockwise from east, as its direction cosines cos φ·cos θ, cos φ·sin θ, sin φ run),
//! each weighted cos φ·Δθ·Δφ·cos α, α the angle of incidence, where cos α ≥ 0. The iso-sky ratio
//! is Σ weight·sunlit fraction / Σ weight over all 144, the horizon ratio the same over the
//! lowest band (φ = 7.5°); EnergyPlus divides by (Σ weight + 1e-10) where the sum is not above
//! 1e-10, so a surface that sees none of them gets 0.
//!
//! The fractions come from the same engines as everything else, one [`ViewRequest`] per
//! direction, so the clipping matches EnergyPlus's (the exact engine clips polygons as it does).
//! Which casters count is the caller's: EnergyPlus sees only its input file's surfaces (building
//! and shading surfaces alike, never a glTF context), so the CLI counts these on a scene loaded
//! from the EnergyPlus model alone.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::DVec3;

use crate::count::{Engine, ViewRequest};
use crate::error::Result;
use crate::scene::Scene;
use crate::sky::views::count;
use crate::year::annual::Progress;

/// EnergyPlus's diffuse shading ratios for one receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyPlusRatios {
    /// `DifShdgRatioIsoSky`.
    pub iso_sky: f64,
    /// `DifShdgRatioHoriz`.
    pub horizon: f64,
}

/// Altitude steps (`NPhi`).
const ALTITUDES: usize = 6;
/// Azimuth steps (`NTheta`).
const AZIMUTHS: usize = 24;
/// EnergyPlus's small number (`Eps`) in the ratios' denominators.
const EPS: f64 = 1e-10;

/// EnergyPlus's 144 sky directions, lowest band first, and each one's cos φ·Δθ·Δφ.
pub fn directions() -> Vec<(DVec3, f64, bool)> {
    let d_phi = FRAC_PI_2 / ALTITUDES as f64;
    let d_theta = TAU / AZIMUTHS as f64;
    let mut out = Vec::with_capacity(ALTITUDES * AZIMUTHS);
    for i in 0..ALTITUDES {
        let phi = d_phi * (i as f64 + 0.5);
        for j in 0..AZIMUTHS {
            let theta = d_theta * j as f64;
            let direction = DVec3::new(phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin());
            out.push((direction, phi.cos() * d_theta * d_phi, i == 0));
        }
    }
    out
}

/// Each receiver's ratios from `engine`'s fractions over `scene`.
pub async fn ratios(
    engine: &impl Engine,
    scene: &Scene,
    progress: &mut dyn FnMut(Progress) -> Result<()>,
) -> Result<Vec<EnergyPlusRatios>> {
    let sky = directions();
    let mut requests = Vec::new();
    let mut weights = Vec::new();
    for (r, receiver) in scene.receivers.iter().enumerate() {
        for &(direction, base, horizon) in &sky {
            let cos = receiver.normal.dot(direction);
            if cos >= 0.0 {
                requests.push(ViewRequest::new(r as u32, direction));
                weights.push((r, base * cos, horizon));
            }
        }
    }
    let fractions = count(engine, &requests, progress).await?;
    // (shaded, unshaded) sums per receiver: all directions, and the lowest band.
    let mut iso = vec![(0.0f64, 0.0f64); scene.receivers.len()];
    let mut low = iso.clone();
    for (&(r, w, horizon), f) in weights.iter().zip(fractions) {
        iso[r].0 += w * f;
        iso[r].1 += w;
        if horizon {
            low[r].0 += w * f;
            low[r].1 += w;
        }
    }
    let ratio = |(shaded, unshaded): (f64, f64)| if unshaded > EPS { shaded / unshaded } else { shaded / (unshaded + EPS) };
    Ok(iso.into_iter().zip(low).map(|(i, h)| EnergyPlusRatios { iso_sky: ratio(i), horizon: ratio(h) }).collect())
}
