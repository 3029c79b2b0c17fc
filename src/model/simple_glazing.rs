//! EnergyPlus's angular dependence of `WindowMaterial:SimpleGlazingSystem`: the share of its
//! normal-incidence transmittance a beam keeps at an angle, as EnergyPlus 25.2 derives it.
//!
//! EnergyPlus does not give the equivalent pane of a simple glazing an uncoated pane's Fresnel
//! physics: WindowManager's `TransAndReflAtPhi` takes, for a construction built from simple
//! glazing, ten fitted curves of cos θ (A to J, quartics from the Engineering Reference's "Simple
//! Window Model", after the LBNL study of typical glazings), picks one by the glazing's U-factor
//! and SHGC in a grid of 28 cells, and interpolates linearly (or bilinearly) between curves in the
//! cells that border two or four others. Transmittance at θ is then the normal value times the
//! curve (1 at normal incidence). The band edges (U 1.4195, 1.7034, 3.4068, 4.5424 W/m²K; SHGC
//! 0.25 … 0.65) are EnergyPlus's, from the same source.
//!
//! EnergyPlus then fits a sixth-order polynomial in cos θ through the curve at 0°, 10°, …, 90°
//! and uses that fit in the simulation; the fit follows these smooth quartics within about 0.001
//! of transmittance (`tests/inside.rs` measures the whole chain against EnergyPlus's reported
//! transmitted beam).

/// Coefficients of cos θ, cos² θ, cos³ θ and cos⁴ θ of the transmittance curves A to J (their
/// constant term is 0).
#[allow(clippy::approx_constant)] // F's 3.14 is EnergyPlus's fitted coefficient, not π.
const CURVES: [[f64; 4]; 10] = [
    [3.36, -3.85, 1.49, 0.01],  // A
    [2.83, -2.42, 0.04, 0.55],  // B
    [2.45, -1.58, -0.64, 0.77], // C
    [2.85, -2.58, 0.40, 0.35],  // D
    [1.51, 2.49, -5.87, 2.88],  // E
    [1.21, 3.14, -6.37, 3.03],  // F
    [1.09, 3.54, -6.84, 3.23],  // G
    [0.98, 3.83, -7.13, 3.33],  // H
    [0.79, 3.93, -6.86, 3.15],  // I
    [0.08, 6.02, -8.84, 3.74],  // J
];

/// The curves and the blends EnergyPlus names after the curves they average.
#[derive(Clone, Copy)]
struct Curves {
    a: f64,
    d: f64,
    e: f64,
    j: f64,
    /// (F + G + H + I) / 4.
    fghi: f64,
    /// (F + H) / 2.
    fh: f64,
    /// (B + D + C + D) / 4, as EnergyPlus writes it.
    bdcd: f64,
}

impl Curves {
    fn at(cos: f64) -> Self {
        let v: Vec<f64> = CURVES.iter().map(|k| cos * (k[0] + cos * (k[1] + cos * (k[2] + cos * k[3])))).collect();
        let [a, b, c, d, e, f, g, h, i, j] = [v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9]];
        Curves { a, d, e, j, fghi: (f + g + h + i) / 4.0, fh: (f + h) / 2.0, bdcd: (b + d + c + d) / 4.0 }
    }
}

/// `f0` at `x0` to `f1` at `x1`, linearly.
fn between(x: f64, x0: f64, x1: f64, f0: f64, f1: f64) -> f64 {
    f0 + (x - x0) / (x1 - x0) * (f1 - f0)
}

/// Bilinear over the cell [x0, x1] × [y0, y1] with corner values (x0 y0, x0 y1, x1 y0, x1 y1).
#[allow(clippy::too_many_arguments)] // EnergyPlus's InterpolateBetweenFourValues, argument for argument.
fn between4(x: f64, y: f64, x0: f64, x1: f64, y0: f64, y1: f64, corners: [f64; 4]) -> f64 {
    let low = between(x, x0, x1, corners[0], corners[2]);
    let high = between(x, x0, x1, corners[1], corners[3]);
    between(y, y0, y1, low, high)
}

/// The share of the normal-incidence transmittance a simple glazing of `u` (W/m²K) and `shgc`
/// lets through at `cos_incidence` (1 at normal incidence, 0 at grazing), EnergyPlus's cells
/// 1 to 28 in order. EnergyPlus clamps the product with the normal value to 0..=1, not this.
pub fn angular_factor(u: f64, shgc: f64, cos_incidence: f64) -> f64 {
    let cos = cos_incidence.clamp(0.0, 1.0);
    if cos >= 1.0 {
        return 1.0;
    }
    let c = Curves::at(cos);
    let s = shgc;
    let factor = if u < 1.4195 {
        if s > 0.45 {
            c.e
        } else if s >= 0.35 {
            between(s, 0.35, 0.45, c.j, c.e)
        } else {
            c.j
        }
    } else if u <= 1.7034 {
        let (u0, u1) = (1.4195, 1.7034);
        if s > 0.55 {
            c.e
        } else if s > 0.5 {
            between4(u, s, u0, u1, 0.50, 0.55, [c.e, c.e, c.fghi, c.e])
        } else if s > 0.45 {
            between(u, u0, u1, c.e, c.fghi)
        } else if s > 0.35 {
            between4(u, s, u0, u1, 0.35, 0.45, [c.j, c.e, c.fghi, c.fghi])
        } else if s > 0.3 {
            between(u, u0, u1, c.j, c.fghi)
        } else if s > 0.25 {
            between4(u, s, u0, u1, 0.25, 0.3, [c.j, c.j, c.fh, c.fghi])
        } else {
            between(u, u0, u1, c.j, c.fh)
        }
    } else if u < 3.4068 {
        if s > 0.55 {
            c.e
        } else if s >= 0.5 {
            between(s, 0.5, 0.55, c.fghi, c.e)
        } else if s > 0.3 {
            c.fghi
        } else if s >= 0.25 {
            between(s, 0.25, 0.30, c.fh, c.fghi)
        } else {
            c.fh
        }
    } else if u <= 4.5424 {
        let (u0, u1) = (3.4068, 4.5424);
        if s > 0.65 {
            between(u, u0, u1, c.e, c.a)
        } else if s > 0.6 {
            between4(u, s, u0, u1, 0.6, 0.65, [c.e, c.e, c.bdcd, c.a])
        } else if s > 0.55 {
            between(u, u0, u1, c.e, c.bdcd)
        } else if s > 0.5 {
            between4(u, s, u0, u1, 0.5, 0.55, [c.fghi, c.e, c.bdcd, c.bdcd])
        } else if s > 0.45 {
            between(u, u0, u1, c.fghi, c.bdcd)
        } else if s > 0.3 {
            between4(u, s, u0, u1, 0.3, 0.45, [c.fghi, c.fghi, c.d, c.bdcd])
        } else if s > 0.25 {
            between4(u, s, u0, u1, 0.25, 0.3, [c.fh, c.fghi, c.d, c.d])
        } else {
            between(u, u0, u1, c.fh, c.d)
        }
    } else if s > 0.65 {
        c.a
    } else if s >= 0.6 {
        between(s, 0.6, 0.65, c.bdcd, c.a)
    } else if s > 0.45 {
        c.bdcd
    } else if s >= 0.3 {
        between(s, 0.3, 0.45, c.d, c.bdcd)
    } else {
        c.d
    };
    factor.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_curve_is_one_at_normal_incidence_and_zero_at_grazing() {
        // The fitted curves reach within 2 % of 1 at normal incidence (D: 1.02), which is why
        // EnergyPlus sets 1 there.
        for k in CURVES {
            let sum: f64 = k.iter().sum();
            assert!((sum - 1.0).abs() <= 0.021, "{k:?} sums to {sum}");
        }
        for (u, shgc) in [(1.0, 0.5), (1.5, 0.52), (2.0, 0.6), (4.0, 0.4), (5.0, 0.4), (5.8, 0.8)] {
            assert_eq!(angular_factor(u, shgc, 1.0), 1.0);
            assert_eq!(angular_factor(u, shgc, 0.0), 0.0);
            let mid = angular_factor(u, shgc, 0.5);
            assert!(mid > 0.5 && mid < 1.0, "{u} {shgc}: {mid}");
        }
        // Cell 11 (U 2.0, SHGC 0.6) is curve E itself: at 60° 1.51/2 + 2.49/4 − 5.87/8 + 2.88/16.
        let e60 = 1.51 / 2.0 + 2.49 / 4.0 - 5.87 / 8.0 + 2.88 / 16.0;
        assert!((angular_factor(2.0, 0.6, 0.5) - e60).abs() < 1e-12);
    }
}
