//! The annual sunlit-fraction surface: a tensor-product B-spline over (day of year, normalised
//! time of day) that passes through a grid of sampled sunlit fractions, as in Jones, Greenberg &
//! Reinhart (2011). This module owns the knot placement, the interpolation solves and the cheap
//! evaluation; it knows nothing about suns or surfaces.
//!
//! # The surface
//!
//! Samples lie on a grid of `D` days `t_d = day0 + d·h`, `h = period / D`, spread uniformly over a
//! periodic year, times `S` normalised times of day `τ_j ∈ [0, 1]` (strictly increasing, any
//! spacing; 0 is sunrise, 1 is sunset). The surface is
//!
//! ```text
//! s(t, τ) = Σ_k Σ_i C[k][i] · P_k(t) · Q_i(τ)        k < D, i < S
//! ```
//!
//! with one control point per sample in each direction, so the interpolation conditions
//! `s(t_d, τ_j) = v[d][j]` form a square system.
//!
//! **Day direction, `P_k`:** periodic uniform quadratic B-splines with knot spacing `h`. The knots
//! sit halfway *between* sample days, at `day0 + (k − ½)·h`, so every sample falls in the middle of
//! a knot interval, where the three non-zero basis functions weigh `(1/8, 3/4, 1/8)` on control
//! points `d − 1, d, d + 1` (indices modulo `D`). The interpolation matrix is therefore circulant,
//! strictly diagonally dominant, with eigenvalues `3/4 + 1/4·cos(2πm/D) ∈ [1/2, 1]`: condition
//! number at most 2 for every `D`. (Samples *on* the knots would give rows `(1/2, 1/2)`, whose
//! circulant is singular for even `D`.) The construction needs no special cases: for `D = 1` the
//! one wrapped basis function sums to 1 everywhere, so the surface is constant over days; for
//! `D = 2` the two wrapped basis functions give the matrix `[[3/4, 1/4], [1/4, 3/4]]`, a periodic
//! C¹ piecewise quadratic through both samples. The surface is C¹ in `t` everywhere, including
//! across the year's wrap.
//!
//! **Time-of-day direction, `Q_i`:** a clamped (open) B-spline basis on `[0, 1]` of degree
//! `p = min(2, S − 1)`: constant for one sample, linear for two, quadratic from three on. The knot
//! vector has `p + 1` copies of 0 and of 1 and, for `p = 2`, the `S − 3` interior knots
//! `ξ_j = (τ_j + τ_{j+1}) / 2`, `j = 1 … S − 3` — the midpoints between consecutive interior
//! samples, which is de Boor's knot averaging for degree 2. With these knots every sample `τ_i`
//! lies strictly inside the support of its own basis function, `t_i < τ_i < t_{i+3}` (with the
//! allowed equality at a clamped end), which is the Schoenberg–Whitney condition: the collocation
//! matrix is non-singular for any strictly increasing samples, however unevenly spaced, and each
//! knot span holds one or two samples so no span is left unconstrained. The space contains every
//! quadratic in `τ`, so quadratic data is reproduced exactly.
//!
//! # Fitting
//!
//! In matrix form the conditions are `V = M_day · C · M_τᵀ` (`V` is `D × S`). The problem is
//! separable: solve `M_τ` for each day's row, then `M_day` for each τ-control column. Each matrix
//! is factorised once (dense LU with partial pivoting: at the sizes used, up to ~60, that costs
//! microseconds and is simpler to get right than banded or FFT solvers). [`AnnualGrid`] keeps the
//! two factorisations so that many surfaces sampled on the same grid share them.
//!
//! # Evaluation
//!
//! [`AnnualSpline::eval`] finds the day span directly from the uniform spacing, the τ span by a
//! binary search over the interior knots, evaluates the 3 + 3 basis functions and sums the 3 × 3
//! control points. It allocates nothing.

use crate::error::{Error, Result};

/// Largest supported τ degree: the fixed-size basis arrays below are sized for it.
const MAX_DEGREE: usize = 2;

/// Pivots below this magnitude mean a singular interpolation matrix. The matrices' entries are
/// basis values in [0, 1] with rows summing to 1, so an absolute threshold is meaningful.
const SINGULAR_PIVOT: f64 = 1e-13;

/// The sample grid of an annual surface, with its interpolation matrices factorised once so that
/// any number of surfaces sampled on it can be fitted cheaply.
#[derive(Debug, Clone)]
pub struct AnnualGrid {
    day0: f64,
    period: f64,
    day_count: usize,
    tau_degree: usize,
    tau_knots: Vec<f64>,
    tau_count: usize,
    day_lu: Lu,
    tau_lu: Lu,
}

/// A fitted annual surface of sunlit fractions: periodic quadratic over the day of year, clamped
/// quadratic over the normalised time of day, passing through every sample.
#[derive(Debug, Clone)]
pub struct AnnualSpline {
    day0: f64,
    /// Knot intervals per day, `D / period`: multiplying beats dividing in `eval`.
    inverse_spacing: f64,
    day_count: usize,
    tau_degree: usize,
    tau_knots: Vec<f64>,
    tau_count: usize,
    /// Control net, `control[k * tau_count + i]` for day control `k` and τ control `i`.
    control: Vec<f64>,
}

impl AnnualGrid {
    /// Validates a grid of `day_count` days from `day0` over a periodic year of `period` days and
    /// the times of day `taus`, and factorises both interpolation matrices.
    pub fn new(day0: f64, period: f64, day_count: usize, taus: &[f64]) -> Result<Self> {
        check_days(day0, period, day_count)?;
        check_taus(taus)?;
        let tau_degree = (taus.len() - 1).min(MAX_DEGREE);
        let tau_knots = tau_knot_vector(taus, tau_degree)?;
        let day_lu = Lu::new(day_matrix(day_count), day_count, "spline day grid")?;
        let tau_lu = Lu::new(tau_matrix(taus, &tau_knots, tau_degree), taus.len(), "spline taus")?;
        Ok(AnnualGrid { day0, period, day_count, tau_degree, tau_knots, tau_count: taus.len(), day_lu, tau_lu })
    }

    /// Fits the surface through `values[d * S + j]`, the sample at day `t_d` and time `taus[j]`.
    pub fn fit(&self, values: &[f64]) -> Result<AnnualSpline> {
        self.check_values(values)?;
        let (days, taus) = (self.day_count, self.tau_count);
        let mut control = values.to_vec();
        // τ direction first: each day's row of samples becomes that day's τ control points.
        for row in control.chunks_exact_mut(taus) {
            self.tau_lu.solve(row);
        }
        // Then across days, one periodic solve per τ control index (a strided column).
        let mut column = vec![0.0; days];
        for i in 0..taus {
            for (k, c) in column.iter_mut().enumerate() {
                *c = control[k * taus + i];
            }
            self.day_lu.solve(&mut column);
            for (k, c) in column.iter().enumerate() {
                control[k * taus + i] = *c;
            }
        }
        Ok(AnnualSpline {
            day0: self.day0,
            inverse_spacing: days as f64 / self.period,
            day_count: days,
            tau_degree: self.tau_degree,
            tau_knots: self.tau_knots.clone(),
            tau_count: taus,
            control,
        })
    }

    /// Refuses sample arrays of the wrong length or with non-finite entries.
    fn check_values(&self, values: &[f64]) -> Result<()> {
        let expected = self.day_count * self.tau_count;
        if values.len() != expected {
            return Err(Error::argument(
                "spline values",
                format!("{} samples for {} days × {} times of day (expected {expected})", values.len(), self.day_count, self.tau_count),
            ));
        }
        if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::argument("spline values", format!("sample {bad} is {}", values[bad])));
        }
        Ok(())
    }
}

impl AnnualSpline {
    /// Fits the surface through `values[d * taus.len() + j]`, the sample at day
    /// `day0 + d · period / day_count` and time of day `taus[j]`. For fitting many surfaces on the
    /// same grid, build an [`AnnualGrid`] once and call [`AnnualGrid::fit`].
    pub fn fit(day0: f64, period: f64, day_count: usize, taus: &[f64], values: &[f64]) -> Result<Self> {
        AnnualGrid::new(day0, period, day_count, taus)?.fit(values)
    }

    /// The surface at any `day` (wrapped periodically) and `tau` (clamped to [0, 1]). The value is
    /// not clamped: between samples an interpolating spline may overshoot [0, 1] slightly, and
    /// the caller decides what to do about it. Allocation-free.
    pub fn eval(&self, day: f64, tau: f64) -> f64 {
        let (day_controls, day_weights) = self.day_basis(day);
        let tau = tau.clamp(0.0, 1.0);
        let span = tau_span(&self.tau_knots, self.tau_degree, self.tau_count, tau);
        let tau_weights = tau_basis(&self.tau_knots, self.tau_degree, span, tau);
        let first = span - self.tau_degree;
        let mut sum = 0.0;
        for (k, day_weight) in day_controls.iter().zip(day_weights) {
            let start = k * self.tau_count + first;
            let row = &self.control[start..=start + self.tau_degree];
            let along_tau: f64 = row.iter().zip(&tau_weights).map(|(c, w)| c * w).sum();
            sum += day_weight * along_tau;
        }
        sum
    }

    /// The three day control indices that act at `day` and their basis weights.
    fn day_basis(&self, day: f64) -> ([usize; 3], [f64; 3]) {
        let days = self.day_count as f64;
        // Knots at day0 + (k − ½)h: shifting by ½ puts knot k at integer k, so the span is the
        // integer part and the local coordinate the fraction.
        let knot_coordinate = ((day - self.day0) * self.inverse_spacing + 0.5).rem_euclid(days);
        let floor = knot_coordinate.floor();
        // `rem_euclid` may round up to exactly `days` for tiny negative inputs; that is span 0 at
        // local coordinate 0 by periodicity. A NaN day gives span 0 and a NaN value.
        let span = if floor < days { floor as usize } else { 0 };
        let local = knot_coordinate - floor;
        (cyclic_neighbours(span, self.day_count), uniform_quadratic_weights(local))
    }
}

/// Control points `span − 1, span, span + 1` modulo `count`: the ones acting on a periodic
/// quadratic span.
fn cyclic_neighbours(span: usize, count: usize) -> [usize; 3] {
    let previous = if span == 0 { count - 1 } else { span - 1 };
    let next = if span + 1 == count { 0 } else { span + 1 };
    [previous, span, next]
}

/// The three uniform quadratic B-spline weights at local coordinate `x ∈ [0, 1)` of a span.
fn uniform_quadratic_weights(x: f64) -> [f64; 3] {
    let y = 1.0 - x;
    [0.5 * y * y, 0.5 + x * y, 0.5 * x * x]
}

/// Refuses an empty, non-finite or degenerate day grid.
fn check_days(day0: f64, period: f64, day_count: usize) -> Result<()> {
    if day_count == 0 {
        return Err(Error::argument("spline day_count", "at least one sample day is needed"));
    }
    if !day0.is_finite() {
        return Err(Error::argument("spline day0", format!("{day0} is not finite")));
    }
    if !(period.is_finite() && period > 0.0) {
        return Err(Error::argument("spline period", format!("{period} is not a positive number of days")));
    }
    Ok(())
}

/// Refuses times of day that are missing, outside [0, 1] or not strictly increasing.
fn check_taus(taus: &[f64]) -> Result<()> {
    if taus.is_empty() {
        return Err(Error::argument("spline taus", "at least one time of day is needed"));
    }
    if let Some(bad) = taus.iter().position(|t| !(0.0..=1.0).contains(t)) {
        return Err(Error::argument("spline taus", format!("taus[{bad}] = {} is outside [0, 1]", taus[bad])));
    }
    if let Some(bad) = taus.windows(2).position(|pair| pair[0] >= pair[1]) {
        return Err(Error::argument(
            "spline taus",
            format!("not strictly increasing: taus[{bad}] = {} ≥ taus[{}] = {}", taus[bad], bad + 1, taus[bad + 1]),
        ));
    }
    Ok(())
}

/// The clamped knot vector on [0, 1] for `degree` and the samples `taus` (see the module doc):
/// `degree + 1` zeros, the midpoints between consecutive interior samples, `degree + 1` ones.
fn tau_knot_vector(taus: &[f64], degree: usize) -> Result<Vec<f64>> {
    let interior = taus.len() - degree - 1;
    let mut knots = Vec::with_capacity(taus.len() + degree + 1);
    knots.extend(std::iter::repeat_n(0.0, degree + 1));
    // Only degree 2 has interior knots (degree < 2 means taus.len() = degree + 1).
    knots.extend(taus.windows(2).skip(1).take(interior).map(|pair| 0.5 * (pair[0] + pair[1])));
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    // Exact midpoints of strictly increasing samples are strictly increasing and inside (0, 1);
    // rounding can merge them only for samples a few ulps apart, which would leave an empty span.
    let spans_ok = knots[degree..=degree + interior + 1].windows(2).all(|pair| pair[0] < pair[1]);
    if !spans_ok {
        return Err(Error::argument("spline taus", "samples too close together to place distinct knots between them"));
    }
    Ok(knots)
}

/// The knot span `s` (`degree ≤ s < count`) with `knots[s] ≤ tau < knots[s + 1]`, the last span
/// being closed at 1. A NaN `tau` lands in the first span (and evaluates to NaN).
fn tau_span(knots: &[f64], degree: usize, count: usize, tau: f64) -> usize {
    let interior = &knots[degree + 1..count];
    degree + interior.partition_point(|&knot| knot <= tau)
}

/// The `degree + 1` non-zero basis functions at `tau` in `span` (Cox–de Boor, as in Piegl & Tiller
/// algorithm A2.2), padded with zeros to three.
fn tau_basis(knots: &[f64], degree: usize, span: usize, tau: f64) -> [f64; 3] {
    let mut basis = [1.0, 0.0, 0.0];
    let mut left = [0.0; MAX_DEGREE + 1];
    let mut right = [0.0; MAX_DEGREE + 1];
    for j in 1..=degree {
        left[j] = tau - knots[span + 1 - j];
        right[j] = knots[span + j] - tau;
        let mut saved = 0.0;
        for r in 0..j {
            // Denominators are span widths, positive because the knots of every span in use are
            // distinct (checked when the knot vector is built).
            let share = basis[r] / (right[r + 1] + left[j - r]);
            basis[r] = saved + right[r + 1] * share;
            saved = left[j - r] * share;
        }
        basis[j] = saved;
    }
    basis
}

/// The circulant day interpolation matrix (row-major `D × D`): weights `(1/8, 3/4, 1/8)` on
/// controls `d − 1, d, d + 1` modulo `D`, accumulated so that coinciding indices (`D < 3`) add up.
fn day_matrix(day_count: usize) -> Vec<f64> {
    let mut matrix = vec![0.0; day_count * day_count];
    let weights = uniform_quadratic_weights(0.5);
    for d in 0..day_count {
        for (k, w) in cyclic_neighbours(d, day_count).iter().zip(weights) {
            matrix[d * day_count + k] += w;
        }
    }
    matrix
}

/// The τ collocation matrix (row-major `S × S`): row `j` holds the basis functions at `taus[j]`.
fn tau_matrix(taus: &[f64], knots: &[f64], degree: usize) -> Vec<f64> {
    let count = taus.len();
    let mut matrix = vec![0.0; count * count];
    for (j, &tau) in taus.iter().enumerate() {
        let span = tau_span(knots, degree, count, tau);
        let basis = tau_basis(knots, degree, span, tau);
        for (offset, b) in basis.iter().take(degree + 1).enumerate() {
            matrix[j * count + span - degree + offset] = *b;
        }
    }
    matrix
}

/// A dense LU factorisation with partial pivoting, `P·A = L·U`, stored in place (unit `L` below
/// the diagonal, `U` on and above), with the row swaps in the order they were made.
#[derive(Debug, Clone)]
struct Lu {
    size: usize,
    factors: Vec<f64>,
    swaps: Vec<usize>,
}

impl Lu {
    /// Factorises the row-major `size × size` matrix; `what` names it in the error if singular.
    fn new(mut a: Vec<f64>, size: usize, what: &str) -> Result<Self> {
        let n = size;
        let mut swaps = Vec::with_capacity(n);
        for col in 0..n {
            let pivot = (col..n).max_by(|&r, &s| a[r * n + col].abs().total_cmp(&a[s * n + col].abs())).unwrap_or(col);
            let pivot_value = a[pivot * n + col];
            if pivot_value.is_nan() || pivot_value.abs() <= SINGULAR_PIVOT {
                return Err(Error::argument(what, "the interpolation matrix is singular"));
            }
            if pivot != col {
                for c in 0..n {
                    a.swap(col * n + c, pivot * n + c);
                }
            }
            swaps.push(pivot);
            for r in col + 1..n {
                let factor = a[r * n + col] / pivot_value;
                a[r * n + col] = factor;
                // Both matrices are banded (apart from the circulant corners): skip zero rows.
                if factor != 0.0 {
                    for c in col + 1..n {
                        a[r * n + c] -= factor * a[col * n + c];
                    }
                }
            }
        }
        Ok(Lu { size, factors: a, swaps })
    }

    /// Solves `A·x = b` in place.
    fn solve(&self, b: &mut [f64]) {
        let n = self.size;
        for (row, &pivot) in self.swaps.iter().enumerate() {
            b.swap(row, pivot);
        }
        for r in 0..n {
            let lower: f64 = self.factors[r * n..r * n + r].iter().zip(&b[..r]).map(|(l, x)| l * x).sum();
            b[r] -= lower;
        }
        for r in (0..n).rev() {
            let upper: f64 = self.factors[r * n + r + 1..(r + 1) * n].iter().zip(&b[r + 1..]).map(|(u, x)| u * x).sum();
            b[r] = (b[r] - upper) / self.factors[r * n + r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::SmallRng;
    use rand::{Rng, SeedableRng};
    use std::f64::consts::PI;

    const PERIOD: f64 = 365.0;
    const DAY0: f64 = 0.5;

    /// Non-uniform times of day: cosine-clustered towards sunrise and sunset, with a jitter.
    fn clustered_taus(count: usize) -> Vec<f64> {
        (0..count)
            .map(|j| {
                let u = j as f64 / (count - 1) as f64;
                let jitter = if j == 0 || j == count - 1 { 0.0 } else { 0.002 * (7.0 * j as f64).sin() };
                0.5 - 0.5 * (PI * u).cos() + jitter
            })
            .collect()
    }

    /// Times of day that do not reach the ends and are unevenly spaced.
    fn inner_taus(count: usize) -> Vec<f64> {
        (0..count).map(|j| 0.03 + 0.94 * (j as f64 / (count - 1) as f64).powf(1.3)).collect()
    }

    fn sample_day(d: usize, day_count: usize) -> f64 {
        DAY0 + d as f64 * PERIOD / day_count as f64
    }

    /// Samples `f(day, tau)` on the grid.
    fn grid_values(day_count: usize, taus: &[f64], f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        (0..day_count).flat_map(|d| taus.iter().map(move |&tau| (d, tau))).map(|(d, tau)| f(sample_day(d, day_count), tau)).collect()
    }

    /// The cardinal quadratic B-spline on [0, 3].
    fn cardinal_quadratic(s: f64) -> f64 {
        match s {
            s if !(0.0..3.0).contains(&s) => 0.0,
            s if s < 1.0 => 0.5 * s * s,
            s if s < 2.0 => 0.5 * (-2.0 * s * s + 6.0 * s - 3.0),
            s => 0.5 * (3.0 - s) * (3.0 - s),
        }
    }

    /// A periodic quadratic spline with knots halfway between the sample days, written
    /// independently of the module: control `k` is centred on sample day `k`.
    fn periodic_quadratic(controls: &[f64], day: f64) -> f64 {
        let count = controls.len() as f64;
        let u = ((day - DAY0) / (PERIOD / count)).rem_euclid(count);
        let mut sum = 0.0;
        for (k, c) in controls.iter().enumerate() {
            for wrap in [-count, 0.0, count] {
                sum += c * cardinal_quadratic(u - k as f64 + 1.5 + wrap);
            }
        }
        sum
    }

    #[test]
    fn reproduces_every_sample() {
        let mut rng = SmallRng::seed_from_u64(7);
        for taus in [clustered_taus(19), inner_taus(19)] {
            let values: Vec<f64> = (0..27 * 19).map(|_| rng.random_range(0.0..1.0)).collect();
            let spline = AnnualSpline::fit(DAY0, PERIOD, 27, &taus, &values).unwrap();
            for d in 0..27 {
                for (j, &tau) in taus.iter().enumerate() {
                    let error = spline.eval(sample_day(d, 27), tau) - values[d * 19 + j];
                    assert!(error.abs() < 1e-12, "day {d} tau {j}: error {error}");
                }
            }
        }
    }

    #[test]
    fn reproduces_quadratics_in_tau_and_periodic_splines_in_day() {
        let mut rng = SmallRng::seed_from_u64(11);
        let taus = clustered_taus(19);
        let (a, b, c) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let quadratic = |tau: f64| a + b * tau + c * tau * tau;
        let amplitude: Vec<f64> = (0..27).map(|_| rng.random_range(0.5..1.5)).collect();
        let constant_over_days = AnnualSpline::fit(DAY0, PERIOD, 27, &taus, &grid_values(27, &taus, |_, tau| quadratic(tau))).unwrap();
        let product = |day: f64, tau: f64| periodic_quadratic(&amplitude, day) * quadratic(tau);
        let modulated = AnnualSpline::fit(DAY0, PERIOD, 27, &taus, &grid_values(27, &taus, product)).unwrap();
        for _ in 0..2000 {
            let day = rng.random_range(-400.0..800.0);
            let tau = rng.random_range(0.0..1.0);
            let error = constant_over_days.eval(day, tau) - quadratic(tau);
            assert!(error.abs() < 1e-12, "constant over days at ({day}, {tau}): error {error}");
            let error = modulated.eval(day, tau) - product(day, tau);
            assert!(error.abs() < 1e-12, "modulated at ({day}, {tau}): error {error}");
        }
    }

    #[test]
    fn continuous_with_continuous_slope_across_the_year_wrap_and_every_knot() {
        let mut rng = SmallRng::seed_from_u64(3);
        let taus = inner_taus(19);
        let values: Vec<f64> = (0..27 * 19).map(|_| rng.random_range(0.0..1.0)).collect();
        let spline = AnnualSpline::fit(DAY0, PERIOD, 27, &taus, &values).unwrap();
        let (epsilon, step) = (1e-7, 1e-4);
        let h = PERIOD / 27.0;
        for &tau in &[0.0, 0.17, 0.5, 0.93, 1.0] {
            let f = |day: f64| spline.eval(day, tau);
            // 31 Dec → 1 Jan, and the knot where the span index wraps from D − 1 to 0.
            let wrap = DAY0 + PERIOD;
            let before = f(wrap - epsilon);
            assert!((before - f(wrap + epsilon)).abs() < 1e-6);
            assert!((before - f(DAY0 + epsilon)).abs() < 1e-6);
            let knots = (0..=27).map(|k| DAY0 + (k as f64 - 0.5) * h);
            for x in knots.chain([wrap, DAY0]) {
                let value_jump = f(x + epsilon) - f(x - epsilon);
                assert!(value_jump.abs() < 1e-6, "value jump {value_jump} at day {x}");
                let left_slope = (f(x) - f(x - step)) / step;
                let right_slope = (f(x + step) - f(x)) / step;
                assert!((left_slope - right_slope).abs() < 1e-4, "slope {left_slope} vs {right_slope} at day {x}");
            }
            for _ in 0..100 {
                let day = rng.random_range(-PERIOD..2.0 * PERIOD);
                assert!((f(day) - f(day + PERIOD)).abs() < 1e-12);
                assert!((f(day) - f(day - 3.0 * PERIOD)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn continuous_with_continuous_slope_across_tau_knots() {
        let mut rng = SmallRng::seed_from_u64(5);
        let taus = clustered_taus(19);
        let values: Vec<f64> = (0..27 * 19).map(|_| rng.random_range(0.0..1.0)).collect();
        let grid = AnnualGrid::new(DAY0, PERIOD, 27, &taus).unwrap();
        let spline = grid.fit(&values).unwrap();
        let step = 1e-7;
        for &knot in &grid.tau_knots[3..19] {
            let f = |tau: f64| spline.eval(100.0, tau);
            assert!((f(knot + step) - f(knot - step)).abs() < 1e-4);
            let left_slope = (f(knot) - f(knot - step)) / step;
            let right_slope = (f(knot + step) - f(knot)) / step;
            assert!((left_slope - right_slope).abs() < 1e-2 * (1.0 + left_slope.abs()), "slope {left_slope} vs {right_slope} at τ {knot}");
        }
    }

    #[test]
    fn approximates_a_smooth_periodic_function() {
        let bump = |day: f64, tau: f64| 0.5 + 0.4 * (2.0 * PI * day / PERIOD).sin() * tau * (1.0 - tau) * 4.0;
        let arch = |day: f64, tau: f64| 0.5 + 0.4 * (2.0 * PI * day / PERIOD).cos() * (PI * tau).sin();
        for taus in [clustered_taus(19), inner_taus(19)] {
            for f in [&bump as &dyn Fn(f64, f64) -> f64, &arch] {
                let spline = AnnualSpline::fit(DAY0, PERIOD, 27, &taus, &grid_values(27, &taus, f)).unwrap();
                let mut worst: f64 = 0.0;
                for i in 0..731 {
                    for k in 0..=101 {
                        let (day, tau) = (i as f64 * 0.5 + 0.123, k as f64 / 101.0);
                        worst = worst.max((spline.eval(day, tau) - f(day, tau)).abs());
                    }
                }
                assert!(worst < 1e-3, "worst error {worst}");
            }
        }
    }

    #[test]
    fn degrades_gracefully_for_few_samples() {
        // One time of day: constant in τ.
        let one = AnnualSpline::fit(DAY0, PERIOD, 5, &[0.4], &[0.1, 0.2, 0.3, 0.4, 0.5]).unwrap();
        assert!((one.eval(sample_day(2, 5), 0.0) - 0.3).abs() < 1e-12);
        assert!((one.eval(sample_day(2, 5), 1.0) - 0.3).abs() < 1e-12);
        // Two times of day: linear in τ.
        let two = AnnualSpline::fit(DAY0, PERIOD, 1, &[0.2, 0.6], &[0.3, 0.7]).unwrap();
        for tau in [0.0, 0.2, 0.45, 0.6, 1.0] {
            assert!((two.eval(123.0, tau) - (0.1 + tau)).abs() < 1e-12);
        }
        // One day: constant over the year.
        let taus = clustered_taus(4);
        let single = AnnualSpline::fit(DAY0, PERIOD, 1, &taus, &[0.1, 0.5, 0.6, 0.2]).unwrap();
        for day in [-50.0, 0.0, 77.0, 364.9] {
            for (tau, v) in taus.iter().zip([0.1, 0.5, 0.6, 0.2]) {
                assert!((single.eval(day, *tau) - v).abs() < 1e-12);
            }
        }
        // Two days: periodic, through both samples, different in between.
        let pair = AnnualSpline::fit(DAY0, PERIOD, 2, &[0.5], &[0.2, 0.8]).unwrap();
        assert!((pair.eval(sample_day(0, 2), 0.5) - 0.2).abs() < 1e-12);
        assert!((pair.eval(sample_day(1, 2), 0.5) - 0.8).abs() < 1e-12);
        assert!((pair.eval(sample_day(1, 2) + PERIOD, 0.5) - 0.8).abs() < 1e-12);
        assert!((pair.eval(DAY0 + 0.25 * PERIOD, 0.5) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_input() {
        let taus = [0.0, 0.5, 1.0];
        let ok = vec![0.5; 6];
        let refused = |result: Result<AnnualSpline>| matches!(result, Err(Error::Argument { .. }));
        assert!(!refused(AnnualSpline::fit(DAY0, PERIOD, 2, &taus, &ok)));
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &taus, &ok[..5])), "length mismatch");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 3, &taus, &ok)), "length mismatch");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &taus, &[0.5, 0.5, f64::NAN, 0.5, 0.5, 0.5])), "NaN value");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &taus, &[0.5, 0.5, f64::INFINITY, 0.5, 0.5, 0.5])), "infinite value");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[0.0, 0.5, 0.5], &ok)), "repeated τ");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[0.0, 0.7, 0.5], &ok)), "decreasing τ");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[-0.1, 0.5, 1.0], &ok)), "τ below 0");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[0.0, 0.5, 1.1], &ok)), "τ above 1");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[0.0, f64::NAN, 1.0], &ok)), "NaN τ");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 2, &[], &[])), "no τ");
        assert!(refused(AnnualSpline::fit(DAY0, PERIOD, 0, &taus, &[])), "day_count 0");
        assert!(refused(AnnualSpline::fit(DAY0, 0.0, 2, &taus, &ok)), "zero period");
        assert!(refused(AnnualSpline::fit(DAY0, f64::NAN, 2, &taus, &ok)), "NaN period");
        assert!(refused(AnnualSpline::fit(f64::INFINITY, PERIOD, 2, &taus, &ok)), "infinite day0");
    }

    #[test]
    fn eval_tolerates_out_of_range_arguments() {
        let taus = clustered_taus(5);
        let spline = AnnualSpline::fit(DAY0, PERIOD, 4, &taus, &grid_values(4, &taus, |_, tau| tau)).unwrap();
        assert!((spline.eval(10.0, -3.0) - spline.eval(10.0, 0.0)).abs() < 1e-15);
        assert!((spline.eval(10.0, 7.0) - spline.eval(10.0, 1.0)).abs() < 1e-15);
        assert!((spline.eval(-1e-300, 0.3) - spline.eval(0.0, 0.3)).abs() < 1e-12);
        assert!(spline.eval(f64::NAN, 0.3).is_nan());
        assert!(spline.eval(10.0, f64::NAN).is_nan());
        assert!(spline.eval(f64::INFINITY, 0.3).is_nan());
    }
}
