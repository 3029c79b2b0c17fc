//! A mesh's glass, from its glTF material's extras: what a mesh cannot say by geometry, so that a
//! glTF pane falls off with the angle of incidence as an EnergyPlus window does.
//!
//! Two forms, under the material's `extras.sunlit` (either, not both):
//! - `transmittance_curve`: `[[angle, transmittance], …]`, the angle of incidence in degrees
//!   from the glass's normal (the first pair at 0°, angles rising within 0..=90) and the beam's
//!   solar transmittance there (0..=1, never rising with the angle: glass passes less the more
//!   obliquely it is crossed). Between pairs the transmittance is linear in the angle; past the
//!   last pair it falls linearly to 0 at 90°, where a beam grazing the glass passes none (a curve
//!   ending at 90° says so itself).
//! - `simple_glazing`: `{"u": W/m²K, "shgc": 0..1}`: EnergyPlus's simple glazing, its normal
//!   transmittance from U and SHGC and its curves A–J ([`super::Angular::Simple`]).
//!
//! Either may add `visible_transmittance` (0..=1, at normal incidence), which falls off with the
//! angle in the same proportion as the solar one; without it the visible value is the solar one.
//! A value of the wrong type or outside its range is refused by file, material and field, so
//! the glass never weights a beam by a curve sunlit guessed.

use serde_json::Value;

use super::{Angular, solar_transmittance};

/// Incidence angle (degrees) and solar transmittance there: a glass's measured curve.
#[derive(Debug, Clone, PartialEq)]
pub struct TransmittanceCurve {
    /// (angle in degrees, transmittance), angles rising from 0.
    points: Vec<(f64, f64)>,
}

impl TransmittanceCurve {
    /// A curve from `(angle in degrees, transmittance)` pairs; refuses (saying why) a curve
    /// with no pair, a first angle other than 0, angles not rising within 0..=90, a
    /// transmittance outside 0..=1 or one that rises with the angle.
    pub fn new(points: Vec<(f64, f64)>) -> std::result::Result<Self, String> {
        let Some(&(first, _)) = points.first() else { return Err("has no pair".to_string()) };
        if first != 0.0 {
            return Err(format!("starts at {first}°: its first pair is normal incidence, 0°"));
        }
        for (k, &(angle, t)) in points.iter().enumerate() {
            if !(0.0..=90.0).contains(&angle) {
                return Err(format!("pair {}: angle {angle}° is outside 0..=90", k + 1));
            }
            if !(0.0..=1.0).contains(&t) {
                return Err(format!("pair {}: transmittance {t} is outside 0..=1", k + 1));
            }
            if let Some(&(before, t_before)) = k.checked_sub(1).and_then(|j| points.get(j)) {
                if angle <= before {
                    return Err(format!("pair {}: angle {angle}° does not rise from {before}°", k + 1));
                }
                if t > t_before {
                    return Err(format!(
                        "pair {}: transmittance {t} at {angle}° rises from {t_before} at {before}° (a curve never rises with the angle)",
                        k + 1
                    ));
                }
            }
        }
        Ok(TransmittanceCurve { points })
    }

    /// A curve written `ANGLE:T,ANGLE:T,…` (degrees, transmittance; `--glass-curve`), checked as
    /// [`Self::new`] checks one; the error says why.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        let pair = |item: &str| -> std::result::Result<(f64, f64), String> {
            let (angle, t) = item.split_once(':').ok_or_else(|| format!("'{item}' is not ANGLE:T"))?;
            let number = |v: &str| v.trim().parse::<f64>().map_err(|_| format!("'{}' in '{item}' is not a number", v.trim()));
            Ok((number(angle)?, number(t)?))
        };
        Self::new(text.split(',').map(|item| pair(item.trim())).collect::<std::result::Result<_, _>>()?)
    }

    /// The transmittance at normal incidence.
    pub fn normal(&self) -> f64 {
        self.points.first().map_or(0.0, |p| p.1)
    }

    /// The transmittance for a beam at `cos_incidence` to the glass's normal (see the module doc).
    pub fn at(&self, cos_incidence: f64) -> f64 {
        let angle = cos_incidence.clamp(0.0, 1.0).acos().to_degrees();
        let last = self.points.last().copied().unwrap_or((0.0, 0.0));
        // Past the last pair the curve runs on to 0 at 90°.
        let end = (90.0, 0.0);
        let pairs = self.points.windows(2).map(|w| (w[0], w[1])).chain((last.0 < 90.0).then_some((last, end)));
        for ((a0, t0), (a1, t1)) in pairs {
            if angle <= a1 {
                return t0 + (t1 - t0) * ((angle - a0) / (a1 - a0)).clamp(0.0, 1.0);
            }
        }
        last.1
    }
}

/// What a glTF material's extras say of its glass: normal-incidence transmittances (solar,
/// visible) and how they fall off.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshGlass {
    /// The material, as messages name it (`material 0 'Pane'`).
    pub material: String,
    /// Solar transmittance at normal incidence.
    pub solar: f64,
    /// Visible transmittance at normal incidence.
    pub visible: f64,
    /// Its angular dependence.
    pub angular: Angular,
}

/// The glass a material's `extras` (raw JSON) describe, None when they say nothing of glass;
/// `Err((field, reason))` for a field sunlit cannot take.
pub fn glass_from_extras(material: &str, extras: &str) -> std::result::Result<Option<MeshGlass>, (String, String)> {
    let value: Value = serde_json::from_str(extras).unwrap_or_default();
    let (curve, simple) = (value.pointer("/sunlit/transmittance_curve"), value.pointer("/sunlit/simple_glazing"));
    let (solar, angular) = match (curve, simple) {
        (None, None) => return Ok(None),
        (Some(_), Some(_)) => {
            return Err(("sunlit".to_string(), "gives both transmittance_curve and simple_glazing: give one".to_string()));
        }
        (Some(curve), None) => {
            let field = || "sunlit.transmittance_curve".to_string();
            let curve = TransmittanceCurve::new(
                pairs(curve).ok_or_else(|| (field(), format!("is {curve}, expected [[angle, transmittance], …]")))?,
            )
            .map_err(|reason| (field(), reason))?;
            (curve.normal(), Angular::Curve(curve))
        }
        (None, Some(simple)) => {
            let number = |key: &str, unit: bool| -> std::result::Result<f64, (String, String)> {
                let field = format!("sunlit.simple_glazing.{key}");
                let v = simple
                    .get(key)
                    .and_then(Value::as_f64)
                    .ok_or_else(|| (field.clone(), format!("is {}, expected a number", simple.get(key).unwrap_or(&Value::Null))))?;
                let ok = if unit { (0.0..=1.0).contains(&v) } else { v.is_finite() && v > 0.0 };
                if ok { Ok(v) } else { Err((field, format!("{v} is outside {}", if unit { "0..=1" } else { "(0, ∞) W/m²K" }))) }
            };
            let (u, shgc) = (number("u", false)?, number("shgc", true)?);
            (solar_transmittance(u, shgc).clamp(0.0, 1.0), Angular::Simple { u, shgc })
        }
    };
    let visible = match value.pointer("/sunlit/visible_transmittance") {
        None => solar,
        Some(v) => v
            .as_f64()
            .filter(|v| (0.0..=1.0).contains(v))
            .ok_or_else(|| ("sunlit.visible_transmittance".to_string(), format!("is {v}, expected a number in 0..=1")))?,
    };
    Ok(Some(MeshGlass { material: material.to_string(), solar, visible, angular }))
}

/// `[[a, t], …]` as pairs of numbers.
fn pairs(value: &Value) -> Option<Vec<(f64, f64)>> {
    value
        .as_array()?
        .iter()
        .map(|pair| match pair.as_array()?.as_slice() {
            [a, t] => Some((a.as_f64()?, t.as_f64()?)),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{TransmittanceCurve, glass_from_extras};

    #[test]
    fn a_curve_is_read_from_angle_and_transmittance_pairs() {
        let curve = TransmittanceCurve::parse("0:0.8, 40:0.76,60:0.6").unwrap();
        assert_eq!(curve, TransmittanceCurve::new(vec![(0.0, 0.8), (40.0, 0.76), (60.0, 0.6)]).unwrap());
        for (text, why) in
            [("0.8", "is not ANGLE:T"), ("0:x", "'x' in '0:x' is not a number"), ("10:0.8", "starts at 10°"), ("0:0.7,40:0.75", "rises")]
        {
            let error = TransmittanceCurve::parse(text).unwrap_err();
            assert!(error.contains(why), "{text}: {error}");
        }
    }

    #[test]
    fn a_curve_interpolates_in_angle_and_runs_on_to_zero_at_grazing() {
        let curve = TransmittanceCurve::new(vec![(0.0, 0.8), (40.0, 0.76), (60.0, 0.6)]).unwrap();
        let cos = |deg: f64| deg.to_radians().cos();
        for (deg, t) in [(0.0, 0.8), (20.0, 0.78), (40.0, 0.76), (50.0, 0.68), (60.0, 0.6), (75.0, 0.3), (90.0, 0.0)] {
            assert!((curve.at(cos(deg)) - t).abs() < 1e-9, "{deg}°: {} against {t}", curve.at(cos(deg)));
        }
        assert_eq!(curve.normal(), 0.8);
    }

    #[test]
    fn bad_curves_are_refused_saying_why() {
        for (points, needle) in [
            (vec![], "no pair"),
            (vec![(10.0, 0.8)], "0°"),
            (vec![(0.0, 0.8), (30.0, 0.82)], "rises"),
            (vec![(0.0, 0.8), (30.0, 0.7), (30.0, 0.6)], "does not rise"),
            (vec![(0.0, 1.2)], "outside 0..=1"),
            (vec![(0.0, 0.8), (95.0, 0.0)], "outside 0..=90"),
        ] {
            let err = TransmittanceCurve::new(points.clone()).unwrap_err();
            assert!(err.contains(needle), "{points:?}: {err}");
        }
        for (extras, field) in [
            (r#"{"sunlit": {"transmittance_curve": [[0, 0.8], [30]]}}"#, "sunlit.transmittance_curve"),
            (r#"{"sunlit": {"simple_glazing": {"u": 2.0, "shgc": 1.5}}}"#, "sunlit.simple_glazing.shgc"),
            (r#"{"sunlit": {"simple_glazing": {"shgc": 0.5}}}"#, "sunlit.simple_glazing.u"),
            (r#"{"sunlit": {"transmittance_curve": [[0, 0.8]], "visible_transmittance": 2}}"#, "sunlit.visible_transmittance"),
        ] {
            let (got, _) = glass_from_extras("material 0 'Pane'", extras).unwrap_err();
            assert_eq!(got, field, "{extras}");
        }
        assert_eq!(glass_from_extras("m", r#"{"sunlit": {"receiver": true}}"#), Ok(None));
    }
}
