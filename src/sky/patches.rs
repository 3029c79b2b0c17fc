//! The sky dome split into patches: Tregenza's 145 (the default) or Reinhart's subdivision of
//! them (MF:n, 144·n² + 1 patches), laid out as Radiance's `gendaymtx` and `reinhart.cal` lay
//! them out, so a patch here is the same patch as in a Radiance sky matrix.
//!
//! Owns the layout and what a receiver makes of it:
//! - bands of equal altitude width α = 90°/(7·n + 0.5) from the horizon up, Tregenza's band
//!   counts 30, 30, 24, 24, 18, 12, 6 times n patches each (each Tregenza band split into n rows),
//!   and one cap of half-angle α/2 around the zenith last;
//! - within a band, patch j is centred on azimuth 360°·j/count, clockwise from north (north,
//!   then towards east); patch 0 of every band is centred on north;
//! - each patch's solid angle (exact: 2π·(sin top − sin bottom)/count; the cap 2π·(1 − cos α/2));
//! - for a receiver's normal, each patch's weight ∫ max(0, cos) dΩ over the patch and the
//!   direction that stands for its part in front of the receiver ([`SkyPatches::weights`]). The
//!   azimuth integral is taken in closed form and the altitude one by the midpoint rule on
//!   [`ALTITUDE_STEPS`] rows, so Σ weights / π is the isotropic view factor (1 + cos tilt)/2 to
//!   well under 0.001 for any tilt, patches cut by the receiver's plane included.

use std::f64::consts::{FRAC_PI_2, TAU};

use glam::DVec3;

use crate::error::{Error, Result};

/// Tregenza's patches per band, horizon first (the cap is separate).
const TREGENZA_BANDS: [usize; 7] = [30, 30, 24, 24, 18, 12, 6];
/// Reinhart subdivisions offered (MF:1 is Tregenza's; MF:6 already has 5,185 patches).
pub const MAX_SUBDIVISION: usize = 6;
/// Midpoint rows across a patch's altitude for its weight: the integrand is smooth in the
/// altitude once the azimuth is integrated, so the rule's error is ~(Δalt/rows)²; 16 rows keep
/// Σ weights/π within 1e-5 of (1 + cos tilt)/2 on Tregenza's 12° bands.
pub const ALTITUDE_STEPS: usize = 16;
/// Samples per side for the direction standing for a patch's lit part (a mean, no accuracy needed).
const DIRECTION_SAMPLES: usize = 6;

/// One patch of the dome.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    /// Altitude range, radians (bottom, top).
    pub altitude: (f64, f64),
    /// Azimuth range, radians clockwise from north (start, end); the cap spans 0..2π.
    pub azimuth: (f64, f64),
    /// Unit vector to the patch's centre, world axes (x east, y north, z up).
    pub direction: DVec3,
    /// Solid angle, steradians.
    pub solid_angle: f64,
    /// Band index from the horizon (0) up; the cap has the last.
    pub band: usize,
}

/// The patch layout of a sky.
#[derive(Debug, Clone, PartialEq)]
pub struct SkyPatches {
    /// Reinhart's MF (1 = Tregenza).
    pub subdivision: usize,
    /// Every patch, in Radiance's order.
    pub patches: Vec<Patch>,
}

/// What one receiver makes of one patch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchWeight {
    /// ∫ max(0, normal·d) dΩ over the patch, steradians (π for the whole hemisphere in front).
    pub weight: f64,
    /// The cos-weighted mean direction of the patch's part in front of the receiver (unit); the
    /// patch's centre where no part is in front (the weight is then 0).
    pub direction: DVec3,
}

impl Default for SkyPatches {
    fn default() -> Self {
        Self::reinhart(1)
    }
}

impl SkyPatches {
    /// Tregenza's 145 patches.
    pub fn tregenza() -> Self {
        Self::reinhart(1)
    }

    /// Reinhart's subdivision MF:`n` (n = 1 is Tregenza); `n` must be 1..=[`MAX_SUBDIVISION`]
    /// ([`Self::parse`] checks it; here it is clamped).
    pub fn reinhart(n: usize) -> Self {
        let n = n.clamp(1, MAX_SUBDIVISION);
        let rows = 7 * n;
        let alpha = FRAC_PI_2 / (rows as f64 + 0.5);
        let mut patches = Vec::with_capacity(144 * n * n + 1);
        for row in 0..rows {
            let count = TREGENZA_BANDS[row / n] * n;
            let (bottom, top) = (alpha * row as f64, alpha * (row + 1) as f64);
            let solid_angle = TAU * (top.sin() - bottom.sin()) / count as f64;
            let width = TAU / count as f64;
            for j in 0..count {
                let centre = width * j as f64;
                patches.push(Patch {
                    altitude: (bottom, top),
                    azimuth: (centre - width / 2.0, centre + width / 2.0),
                    direction: direction(0.5 * (bottom + top), centre),
                    solid_angle,
                    band: row,
                });
            }
        }
        let cap_bottom = alpha * rows as f64;
        patches.push(Patch {
            altitude: (cap_bottom, FRAC_PI_2),
            azimuth: (0.0, TAU),
            direction: DVec3::Z,
            solid_angle: TAU * (1.0 - (FRAC_PI_2 - cap_bottom).cos()),
            band: rows,
        });
        Self { subdivision: n, patches }
    }

    /// Parses a scheme name: `tregenza` or `reinhart:N` (N = 1..=[`MAX_SUBDIVISION`]);
    /// errors name the `sky_patches` parameter.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = |why: String| Error::argument("sky_patches", why);
        let lower = text.trim().to_ascii_lowercase();
        if lower == "tregenza" {
            return Ok(Self::tregenza());
        }
        let Some(n) = lower.strip_prefix("reinhart:").or_else(|| lower.strip_prefix("mf:")) else {
            return Err(bad(format!("'{text}' is not a patch scheme offered: give tregenza or reinhart:N (N = 1..={MAX_SUBDIVISION})")));
        };
        match n.parse::<usize>() {
            Ok(n) if (1..=MAX_SUBDIVISION).contains(&n) => Ok(Self::reinhart(n)),
            _ => Err(bad(format!(
                "Reinhart subdivision '{n}' is not offered: give 1..={MAX_SUBDIVISION} (reinhart:1 is Tregenza's 145 patches)"
            ))),
        }
    }

    /// The scheme's name as [`Self::parse`] reads it.
    pub fn name(&self) -> String {
        if self.subdivision == 1 { "tregenza".into() } else { format!("reinhart:{}", self.subdivision) }
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Never true: a dome has at least its cap.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// The patches of the band nearest the horizon.
    pub fn horizon_band(&self) -> impl Iterator<Item = (usize, &Patch)> {
        self.patches.iter().enumerate().filter(|(_, p)| p.band == 0)
    }

    /// Each patch's weight and lit direction for a receiver facing `normal` (unit).
    pub fn weights(&self, normal: DVec3) -> Vec<PatchWeight> {
        self.patches.iter().map(|p| patch_weight(p, normal)).collect()
    }
}

impl Patch {
    /// The patch cut into `k` rows of altitude by `k` columns of azimuth (the cap into `k` rings
    /// of `k` sectors), each a patch of its own in the same band, their solid angles summing to
    /// the patch's.
    pub fn split(&self, k: usize) -> Vec<Patch> {
        let k = k.max(1);
        let (bottom, top) = self.altitude;
        let (start, end) = self.azimuth;
        let mut out = Vec::with_capacity(k * k);
        for row in 0..k {
            let (lo, hi) = (bottom + (top - bottom) * row as f64 / k as f64, bottom + (top - bottom) * (row + 1) as f64 / k as f64);
            for column in 0..k {
                let (a, b) = (start + (end - start) * column as f64 / k as f64, start + (end - start) * (column + 1) as f64 / k as f64);
                out.push(Patch {
                    altitude: (lo, hi),
                    azimuth: (a, b),
                    direction: direction(0.5 * (lo + hi), 0.5 * (a + b)),
                    solid_angle: (b - a) * (hi.sin() - lo.sin()),
                    band: self.band,
                });
            }
        }
        out
    }

    /// The patch's weight and lit direction for a receiver facing `normal` (unit), as
    /// [`SkyPatches::weights`] gives them.
    pub fn weight(&self, normal: DVec3) -> PatchWeight {
        patch_weight(self, normal)
    }
}

/// Unit vector at `altitude` and `azimuth` (radians, clockwise from north).
pub fn direction(altitude: f64, azimuth: f64) -> DVec3 {
    let (sa, ca) = altitude.sin_cos();
    DVec3::new(azimuth.sin() * ca, azimuth.cos() * ca, sa)
}

fn patch_weight(patch: &Patch, normal: DVec3) -> PatchWeight {
    let (bottom, top) = patch.altitude;
    let (start, end) = patch.azimuth;
    // normal·d = h·cos(az − az₀)·cos(alt) + nz·sin(alt), with h the normal's horizontal length.
    let h = normal.x.hypot(normal.y);
    let az0 = normal.x.atan2(normal.y);
    let step = (top - bottom) / ALTITUDE_STEPS as f64;
    let weight: f64 = (0..ALTITUDE_STEPS)
        .map(|i| {
            let alt = bottom + step * (i as f64 + 0.5);
            let (s, c) = alt.sin_cos();
            positive_cosine_integral(h * c, normal.z * s, start - az0, end - az0) * c * step
        })
        .sum();
    let mut sum = DVec3::ZERO;
    let k = DIRECTION_SAMPLES as f64;
    for i in 0..DIRECTION_SAMPLES {
        let alt = bottom + (top - bottom) * (i as f64 + 0.5) / k;
        for j in 0..DIRECTION_SAMPLES {
            let d = direction(alt, start + (end - start) * (j as f64 + 0.5) / k);
            sum += d * normal.dot(d).max(0.0) * alt.cos();
        }
    }
    let direction = if weight > 0.0 && sum.length_squared() > 0.0 { sum.normalize() } else { patch.direction };
    PatchWeight { weight: weight.max(0.0), direction }
}

/// ∫ max(0, a·cos u + b) du over [u1, u2] (u2 − u1 ≤ 2π), a ≥ 0, in closed form: the integrand
/// is positive on arcs |u − 2πk| < u₀, u₀ = acos(−b/a), with antiderivative a·sin u + b·u.
fn positive_cosine_integral(a: f64, b: f64, u1: f64, u2: f64) -> f64 {
    let antiderivative = |u: f64| a * u.sin() + b * u;
    let over = |lo: f64, hi: f64| if hi > lo { antiderivative(hi) - antiderivative(lo) } else { 0.0 };
    if a <= 1e-15 {
        return (b.max(0.0)) * (u2 - u1);
    }
    let ratio = -b / a;
    if ratio <= -1.0 {
        return over(u1, u2);
    }
    if ratio >= 1.0 {
        return 0.0;
    }
    let u0 = ratio.acos();
    let (k_lo, k_hi) = (((u1 - u0) / TAU).floor() as i64, ((u2 + u0) / TAU).ceil() as i64);
    (k_lo..=k_hi)
        .map(|k| {
            let centre = TAU * k as f64;
            over((centre - u0).max(u1), (centre + u0).min(u2))
        })
        .sum()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn layouts_match_radiance_counts_and_cover_the_dome() {
        for (n, count) in [(1, 145), (2, 577), (4, 2305)] {
            let sky = SkyPatches::reinhart(n);
            assert_eq!(sky.len(), count);
            let total: f64 = sky.patches.iter().map(|p| p.solid_angle).sum();
            assert!((total - TAU).abs() < 1e-12, "MF:{n}: {total}");
        }
        let t = SkyPatches::tregenza();
        // Tregenza's bands are 12° wide; patch 0 faces north, patch 1 is 12° towards east.
        assert!((t.patches[0].altitude.1.to_degrees() - 12.0).abs() < 1e-12);
        assert!(t.patches[0].direction.x.abs() < 1e-12 && t.patches[0].direction.y > 0.0);
        assert!(t.patches[1].direction.x > 0.0);
        assert_eq!(t.horizon_band().count(), 30);
        assert!(SkyPatches::parse("reinhart:7").unwrap_err().to_string().contains("sky_patches"));
        assert!(SkyPatches::parse("klems").is_err() && SkyPatches::parse("reinhart:x").is_err());
        assert_eq!(SkyPatches::parse("Reinhart:2").unwrap().len(), 577);
    }

    #[test]
    fn closed_form_arc_integral_matches_sampling() {
        for (a, b, u1, u2) in [(1.0, 0.2, -0.3, 0.4), (0.5, -0.3, 1.0, 4.0), (0.7, -0.69, -3.0, 3.2), (0.2, 0.5, 0.0, 6.0)] {
            let n = 200_000;
            let du = (u2 - u1) / n as f64;
            let sampled: f64 = (0..n).map(|i| (a * (u1 + du * (i as f64 + 0.5)).cos() + b).max(0.0) * du).sum();
            let exact = positive_cosine_integral(a, b, u1, u2);
            assert!((sampled - exact).abs() < 1e-6, "{a} {b} {u1} {u2}: {sampled} vs {exact}");
        }
    }
}
