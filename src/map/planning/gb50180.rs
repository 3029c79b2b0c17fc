//! GB 50180-2018 (urban residential area planning and design standard), 4.0.9: a dwelling's
//! sunlight hours on its standard day, counted at the ground-floor window sill (底层窗台面).
//!
//! Table 4.0.9: 大寒日 (Greater Cold) ≥ 2 h or ≥ 3 h, counted 8:00–16:00 true solar time, or 冬至日
//! (winter solstice) ≥ 1 h, counted 9:00–15:00, by climate zone and city size; its notes add
//! housing for the elderly ≥ 2 h on 冬至日 and new dwellings in old districts ≥ 1 h on 大寒日.
//! Local rules add a minimum continuous period (often 5 or 10 min) and a maximum number of
//! periods summed: [`Gb50180Rule::min_period_minutes`] and [`Gb50180Rule::max_periods`] (the
//! longest ones count, as [`SunRule::hours`] counts them).
//!
//! The standard day is a solar term, the day the sun reaches ecliptic longitude 300° (大寒) or
//! 270° (冬至); its sun is computed as Chinese sunlight software does, from the term's declination
//! sin δ = sin ε · sin λ (ε = [`OBLIQUITY_DEG`]) and the hour angle 15° · (t − 12) of true solar
//! time t, every minute (the middle of each, [`STEP_MINUTES`]). The window in local standard time,
//! for the report, is t − EoT − (longitude − 15° · zone)/15 with the equation of time of the
//! day in a 365-day year (EnergyPlus's SUN3 fit, [`declination_and_equation_of_time`]).
//!
//! 满窗 (whole window): the window's sill is sampled across its width ([`sill_points`]) and an
//! instant counts only when every sample sees the sun; one width for every window
//! ([`Gb50180Rule::whole_window`]), each window's own ([`Gb50180Rule::window_widths`], read by
//! [`super::sill_widths`]), both centred on the point, or each window's own sill line measured
//! from its geometry ([`Gb50180Rule::sill_lines`], by [`super::sill_lines`]).

use std::ops::Range;

use glam::DVec3;

use super::sill_lines::SillLine;
use super::sill_widths;
use crate::error::{Error, Result};
use crate::map::study::SunRule;
use crate::map::{LitSeries, Points, Sample};
use crate::scene::Scene;
use crate::sun::location::Location;
use crate::sun::position::declination_and_equation_of_time;
use crate::year::season::LeafCalendar;

/// The obliquity of the ecliptic, degrees (J2000, 23°26′).
pub const OBLIQUITY_DEG: f64 = 23.44;
/// Minutes between instants; each stands for its minute.
pub const STEP_MINUTES: u32 = 1;
/// Most spacing between a whole window's sill samples, metres.
pub const SILL_SPACING: f64 = 0.1;

/// GB 50180's standard days.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StandardDay {
    /// 大寒日, about 20 January: ecliptic longitude 300°.
    Dahan,
    /// 冬至日, about 21 December: ecliptic longitude 270°.
    Dongzhi,
}

impl StandardDay {
    /// Reads `dahan`/`大寒日`/`大寒` or `dongzhi`/`冬至日`/`冬至`; refuses another day, naming `day`.
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim().to_ascii_lowercase().as_str() {
            "dahan" | "大寒日" | "大寒" => Ok(Self::Dahan),
            "dongzhi" | "冬至日" | "冬至" => Ok(Self::Dongzhi),
            other => Err(Error::argument("day", format!("'{other}': GB 50180 evaluates 大寒日 (dahan) or 冬至日 (dongzhi) only"))),
        }
    }

    /// The ASCII name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dahan => "dahan",
            Self::Dongzhi => "dongzhi",
        }
    }

    /// The standard's name.
    pub fn chinese(self) -> &'static str {
        match self {
            Self::Dahan => "大寒日",
            Self::Dongzhi => "冬至日",
        }
    }

    /// The sun's ecliptic longitude on the day, degrees.
    pub fn ecliptic_longitude_deg(self) -> f64 {
        match self {
            Self::Dahan => 300.0,
            Self::Dongzhi => 270.0,
        }
    }

    /// The sun's declination on the day, degrees (大寒 −20.15°, 冬至 −23.44°).
    pub fn declination_deg(self) -> f64 {
        (OBLIQUITY_DEG.to_radians().sin() * self.ecliptic_longitude_deg().to_radians().sin()).asin().to_degrees()
    }

    /// The effective sunlight window, hours of true solar time.
    pub fn window(self) -> (f64, f64) {
        match self {
            Self::Dahan => (8.0, 16.0),
            Self::Dongzhi => (9.0, 15.0),
        }
    }

    /// The day of a 365-day year it falls on (20 January, 21 December).
    pub fn day_of_year(self) -> u32 {
        match self {
            Self::Dahan => 20,
            Self::Dongzhi => 355,
        }
    }

    /// Table 4.0.9's hours for the day (大寒日 ≥ 2 h for large cities of zones I, II, III, VII;
    /// 冬至日 ≥ 1 h).
    pub fn default_hours(self) -> f64 {
        match self {
            Self::Dahan => 2.0,
            Self::Dongzhi => 1.0,
        }
    }
}

/// The rule as evaluated.
#[derive(Debug, Clone, PartialEq)]
pub struct Gb50180Rule {
    /// The standard day.
    pub day: StandardDay,
    /// Hours a point must reach.
    pub required_hours: f64,
    /// Only continuous periods at least this long count (minutes).
    pub min_period_minutes: f64,
    /// Only the longest N periods count (`None`: all).
    pub max_periods: Option<usize>,
    /// 满窗: the sill's width (m) over which every sample must see the sun.
    pub whole_window: Option<f64>,
    /// 满窗 with each point's own sill width (m, in the points' order) instead of
    /// [`Self::whole_window`]'s one.
    pub window_widths: Option<Vec<f64>>,
    /// 满窗 along each point's window's own sill line (in the points' order), measured from the
    /// geometry, instead of a width centred on the point.
    pub sill_lines: Option<Vec<SillLine>>,
}

impl Gb50180Rule {
    /// The day's rule with its default hours and no local additions.
    pub fn new(day: StandardDay) -> Self {
        Self {
            day,
            required_hours: day.default_hours(),
            min_period_minutes: 0.0,
            max_periods: None,
            whole_window: None,
            window_widths: None,
            sill_lines: None,
        }
    }

    /// The rule as asked: `day` (default 大寒日, by [`StandardDay::parse`]), then each local
    /// addition given, checked ([`Self::check`]); what the edges (`--day`…, `day`…) hand in.
    pub fn from_options(
        day: Option<&str>,
        required_hours: Option<f64>,
        min_period_minutes: Option<f64>,
        max_periods: Option<usize>,
        whole_window: Option<f64>,
    ) -> Result<Self> {
        let mut rule = Self::new(StandardDay::parse(day.unwrap_or("dahan"))?);
        if let Some(h) = required_hours {
            rule.required_hours = h;
        }
        if let Some(m) = min_period_minutes {
            rule.min_period_minutes = m;
        }
        rule.max_periods = max_periods;
        rule.whole_window = whole_window;
        rule.check()?;
        Ok(rule)
    }

    /// Refuses parameters outside their sense, naming them.
    pub fn check(&self) -> Result<()> {
        if !(self.required_hours.is_finite() && self.required_hours > 0.0 && self.required_hours <= 8.0) {
            return Err(Error::argument("required_hours", format!("{} h is not in (0, 8]", self.required_hours)));
        }
        if !(self.min_period_minutes.is_finite() && (0.0..=480.0).contains(&self.min_period_minutes)) {
            return Err(Error::argument("min_period", format!("{} min is not in 0..=480", self.min_period_minutes)));
        }
        if self.max_periods == Some(0) {
            return Err(Error::argument("max_periods", "0: at least one period must count"));
        }
        if let Some(w) = self.whole_window
            && !sill_widths::valid(w)
        {
            return Err(Error::argument("window_width", format!("{w} m is not in (0, {}]", sill_widths::MAX_WIDTH)));
        }
        if let Some(widths) = &self.window_widths {
            if self.whole_window.is_some() {
                return Err(Error::argument("window_widths", "give one width for every window or each window's own, not both"));
            }
            if let Some((i, w)) = widths.iter().enumerate().find(|(_, w)| !sill_widths::valid(**w)) {
                return Err(Error::argument("window_widths", format!("point {}: {w} m is not in (0, {}]", i + 1, sill_widths::MAX_WIDTH)));
            }
        }
        if self.sill_lines.is_some() {
            if self.whole_window.is_some() {
                return Err(Error::argument("window_width", "give one width for every window or each window's own sill, not both"));
            }
            if self.window_widths.is_some() {
                return Err(Error::argument("window_widths", "give each window's width or measure its sill (window_width sill), not both"));
            }
        }
        Ok(())
    }

    /// The rule at the points `index` of the points it was given (the existing scene's share of
    /// them): each keeps its own sill width.
    pub fn at_points(&self, index: &[usize]) -> Self {
        let window_widths = self.window_widths.as_ref().map(|w| index.iter().filter_map(|&i| w.get(i).copied()).collect());
        let sill_lines = self.sill_lines.as_ref().map(|l| index.iter().filter_map(|&i| l.get(i).copied()).collect());
        Self { window_widths, sill_lines, ..self.clone() }
    }

    /// Whether the rule asks for the whole window (满窗).
    pub fn asks_whole_window(&self) -> bool {
        self.whole_window.is_some() || self.window_widths.is_some() || self.sill_lines.is_some()
    }

    /// Each point's 满窗 width (m, in the points' order), where each window has its own: given
    /// ([`Self::window_widths`]) or its sill line's ([`Self::sill_lines`]).
    pub fn own_widths(&self) -> Option<Vec<f64>> {
        match (&self.window_widths, &self.sill_lines) {
            (Some(widths), _) => Some(widths.clone()),
            (None, Some(lines)) => Some(lines.iter().map(SillLine::width).collect()),
            (None, None) => None,
        }
    }

    /// Point `i`'s sill, at `points`, if the rule asks for the whole window: its window's sill
    /// line, or a width centred on the point (horizontal in its plane).
    fn sill_of(&self, points: &Points, i: usize) -> Option<SillLine> {
        if let Some(lines) = &self.sill_lines {
            return lines.get(i).copied();
        }
        let width = match &self.window_widths {
            Some(widths) => widths.get(i).copied(),
            None => self.whole_window,
        }?;
        Some(centred(points.position(i), points.normal(i), width))
    }

    /// The period rule of [`SunRule::hours`] with this rule's minimum and longest periods.
    fn periods(&self) -> SunRule {
        SunRule {
            name: "gb50180".into(),
            source: String::new(),
            min_altitude_deg: 0.0,
            min_period_minutes: self.min_period_minutes,
            longest: self.max_periods,
            levels: vec![("pass".into(), self.required_hours)],
            share: 1.0,
            days: (1, 365),
            default_day: self.day.day_of_year(),
        }
    }
}

/// The sun (unit, x east, y north, z up) at `latitude_deg`, declination `declination_deg` and
/// `true_solar_hour` (12 at the meridian).
pub fn sun_at_true_solar_time(latitude_deg: f64, declination_deg: f64, true_solar_hour: f64) -> DVec3 {
    let (sp, cp) = latitude_deg.to_radians().sin_cos();
    let (sd, cd) = declination_deg.to_radians().sin_cos();
    let (sh, ch) = (15.0 * (true_solar_hour - 12.0)).to_radians().sin_cos();
    DVec3::new(-cd * sh, cp * sd - sp * cd * ch, sp * sd + cp * cd * ch)
}

/// Local standard time (hours) of `true_solar_hour` on `day_of_year` at `location`: true solar
/// time − equation of time − (longitude − time-zone meridian)/15.
pub fn standard_time(location: &Location, day_of_year: u32, true_solar_hour: f64) -> f64 {
    let (_, equation_of_time) = declination_and_equation_of_time(f64::from(day_of_year));
    true_solar_hour - equation_of_time - (location.longitude - location.time_zone_meridian()) / 15.0
}

/// The day's instants: the middle of each minute of the window, in true solar time.
pub fn instants(day: StandardDay) -> Vec<Sample> {
    let (from, to) = day.window();
    let count = ((to - from) * 60.0 / f64::from(STEP_MINUTES)).round() as usize;
    let hours = f64::from(STEP_MINUTES) / 60.0;
    (0..count).map(|k| Sample { day: day.day_of_year(), hour: from + (k as f64 + 0.5) * hours, hours, epw_hour: 0 }).collect()
}

/// A sill `width` m wide centred on `p` (normal `n`), horizontal in its plane.
fn centred(p: DVec3, n: DVec3, width: f64) -> SillLine {
    let across = if n.z.abs() < 0.9 { DVec3::Z.cross(n).normalize() } else { DVec3::X };
    SillLine { from: p - across * (width / 2.0), to: p + across * (width / 2.0) }
}

/// `points` with, per point, samples along its sill `sill(i)` from end to end (every
/// [`SILL_SPACING`] or less, at least 3, on the point's receiver) appended in order, and where
/// each point's samples are among them.
pub fn sill_points(points: &Points, sill: impl Fn(usize) -> SillLine) -> (Points, Vec<Range<usize>>) {
    let mut out = points.clone();
    let mut ranges = Vec::with_capacity(points.len());
    for i in 0..points.len() {
        let (line, n) = (sill(i), points.normal(i));
        let samples = ((line.width() / SILL_SPACING).ceil() as usize + 1).max(3);
        ranges.push(out.len()..out.len() + samples);
        for k in 0..samples {
            let t = k as f64 / (samples - 1) as f64;
            out.push(line.from + (line.to - line.from) * t, n, points.receivers[i]);
        }
    }
    (out, ranges)
}

/// Each point's hours under the rule, and with [`Gb50180Rule::whole_window`] its 满窗 hours.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gb50180Values {
    /// Hours per point (at the point itself).
    pub hours: Vec<f64>,
    /// 满窗 hours per point (every sill sample lit), when asked.
    pub whole_window_hours: Option<Vec<f64>>,
}

/// Evaluates `rule` at `points` of `scene` at `location`; `progress(done, total)` counts minutes.
pub fn evaluate(
    scene: &Scene,
    points: &Points,
    location: &Location,
    rule: &Gb50180Rule,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Gb50180Values> {
    evaluate_on(scene, &super::SceneRays::new(scene), points, location, rule, progress)
}

/// [`evaluate`] with the scene's tree already built (shared with the other window studies).
pub fn evaluate_on(
    scene: &Scene,
    tree: &super::SceneRays,
    points: &Points,
    location: &Location,
    rule: &Gb50180Rule,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Gb50180Values> {
    rule.check()?;
    let n = points.len();
    if let Some(widths) = rule.window_widths.as_ref().filter(|w| w.len() != n) {
        return Err(Error::argument("window_widths", format!("{} widths for {n} points", widths.len())));
    }
    if let Some(lines) = rule.sill_lines.as_ref().filter(|l| l.len() != n) {
        return Err(Error::argument("window_width", format!("{} sill lines for {n} points", lines.len())));
    }
    let whole = rule.asks_whole_window();
    let (all, ranges) = if whole {
        sill_points(points, |i| rule.sill_of(points, i).unwrap_or(SillLine { from: points.position(i), to: points.position(i) }))
    } else {
        (points.clone(), Vec::new())
    };
    let windows = super::Windows::on(scene, tree, &all)?;
    let samples = instants(rule.day);
    let leaves = LeafCalendar::for_latitude(location.latitude).fraction(f64::from(rule.day.day_of_year())) as f32;
    let declination = rule.day.declination_deg();
    let asks: Vec<super::Ask> =
        samples.iter().map(|s| super::Ask { direction: sun_at_true_solar_time(location.latitude, declination, s.hour), leaves }).collect();
    let lit = super::lit_bits(&windows, &asks, progress);
    let periods = rule.periods();
    let hours = (0..n).map(|i| periods.hours(&samples, &lit, i)).collect();
    let whole_window_hours = whole.then(|| {
        let words = samples.len().div_ceil(64);
        let mut bits = vec![0u64; n * words];
        for (i, range) in ranges.iter().enumerate() {
            for k in 0..samples.len() {
                if range.clone().all(|j| lit.lit(j, k)) {
                    bits[i * words + k / 64] |= 1 << (k % 64);
                }
            }
        }
        let window = LitSeries { words, instants: samples.len(), bits };
        (0..n).map(|i| periods.hours(&samples, &window, i)).collect()
    });
    Ok(Gb50180Values { hours, whole_window_hours })
}
